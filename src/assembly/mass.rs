//! The mass matrix: the consistent element blocks (or their row sums, lumped) formed once on
//! the initial configuration, the product M x, and M added into K*.

use super::{ElementFailure, Kernel, System};
use crate::mesh::Cells;
use crate::scene::spec::MassKind;
use crate::scene::{Body, Model};

/// The mass matrix. In the updated-Lagrangian description rho dV is invariant, so the mass
/// is computed once on the initial configuration and never changes.
pub struct Mass {
    pub kind: MassKind,
    /// Per body, per element: the scalar nn x nn matrix (the same for x and y), row-major.
    elements: Vec<Vec<f64>>,
    /// Row sums per DOF (the lumped mass; also used by the explicit method).
    pub lumped: Vec<f64>,
}

impl Mass {
    pub fn new(model: &Model, kind: MassKind) -> Result<Mass, ElementFailure> {
        let coords = model.coordinates();
        let mut lumped = vec![0.0; model.dofs()];
        let mut elements = Vec::with_capacity(model.bodies.len());
        for body in &model.bodies {
            let kernel = Kernel::of(body);
            let nn = body.mesh.cells.nodes_per_cell();
            let mut body_m = Vec::with_capacity(body.elements() * nn * nn);
            for e in 0..body.elements() {
                let nodes = body.mesh.cells.nodes_of(e);
                let failure = |error| ElementFailure {
                    body: body.name.clone(),
                    element: e,
                    error,
                };
                let mut m = kernel.mass(body, &coords, e).map_err(failure)?;
                if kind == MassKind::DispersionFree {
                    dispersion_free(&mut m, nn);
                }
                for (i, n) in nodes.iter().enumerate() {
                    let row: f64 = m[i * nn..(i + 1) * nn].iter().sum();
                    lumped[2 * body.global(*n)] += row;
                    lumped[2 * body.global(*n) + 1] += row;
                }
                body_m.extend(m);
            }
            elements.push(body_m);
        }
        Ok(Mass {
            kind,
            elements,
            lumped,
        })
    }

    /// The same mass with the nodes flagged in `massless` (per node) carrying none: in each
    /// element their rows and columns are removed and the mass they held goes onto the
    /// element's other nodes in proportion to those nodes' row sums, so every element keeps
    /// its mass (Khenous, Laborde & Renard 2008). An element whose nodes are all flagged
    /// keeps its mass as it is.
    pub fn redistributed(mut self, model: &Model, massless: &[bool]) -> Mass {
        self.lumped.iter_mut().for_each(|m| *m = 0.0);
        for (b, body) in model.bodies.iter().enumerate() {
            let nn = body.mesh.cells.nodes_per_cell();
            for e in 0..body.elements() {
                let nodes = body.mesh.cells.nodes_of(e);
                let flagged: Vec<bool> = nodes.iter().map(|n| massless[body.global(*n)]).collect();
                let m = &mut self.elements[b][e * nn * nn..(e + 1) * nn * nn];
                if flagged.iter().any(|f| *f) && !flagged.iter().all(|f| *f) {
                    redistribute(m, nn, &flagged);
                }
                for (i, n) in nodes.iter().enumerate() {
                    let row: f64 = m[i * nn..(i + 1) * nn].iter().sum();
                    self.lumped[2 * body.global(*n)] += row;
                    self.lumped[2 * body.global(*n) + 1] += row;
                }
            }
        }
        self
    }

    /// M x over all DOFs.
    pub fn product(&self, model: &Model, x: &[f64]) -> Vec<f64> {
        match self.kind {
            MassKind::Lumped => self.lumped.iter().zip(x).map(|(m, v)| m * v).collect(),
            MassKind::Consistent | MassKind::DispersionFree => {
                let mut y = vec![0.0; x.len()];
                for (b, body) in model.bodies.iter().enumerate() {
                    // the node count fixed at compile time: the loops unroll (the products
                    // of the residual, the reactions and the kinetic energy run several
                    // times a step)
                    match &body.mesh.cells {
                        Cells::Quad4(cells) => {
                            block_product(body, cells, &self.elements[b], x, &mut y)
                        }
                        Cells::Rod2(cells) => {
                            block_product(body, cells, &self.elements[b], x, &mut y)
                        }
                    }
                }
                y
            }
        }
    }

    /// 1/2 v . M v
    pub fn kinetic_energy(&self, model: &Model, v: &[f64]) -> f64 {
        0.5 * self
            .product(model, v)
            .iter()
            .zip(v)
            .map(|(a, b)| a * b)
            .sum::<f64>()
    }

    /// Adds `coefficient` M into the free-DOF matrix of `system`.
    pub fn add_to(&self, model: &Model, system: &mut System, coefficient: f64) {
        for (b, body) in model.bodies.iter().enumerate() {
            let nn = body.mesh.cells.nodes_per_cell();
            for e in 0..body.elements() {
                let m = &self.elements[b][e * nn * nn..(e + 1) * nn * nn];
                let values = &mut system.values;
                // DOF a is node a / 2's component a % 2; the mass couples equal components only
                system.scatter[b].for_each(e, |p, a, b| {
                    let (i, j) = (a / 2, b / 2);
                    if a % 2 != b % 2 {
                        return;
                    }
                    let value = match self.kind {
                        MassKind::Consistent | MassKind::DispersionFree => m[i * nn + j],
                        // the element's own row sum: summed over elements, the lumped diagonal
                        MassKind::Lumped if i == j => m[i * nn..(i + 1) * nn].iter().sum(),
                        MassKind::Lumped => 0.0,
                    };
                    values[p] += coefficient * value;
                });
            }
        }
    }
}

/// y += M x over one body's elements, each an nn x nn scalar block (row-major in `blocks`)
/// acting on both components.
fn block_product<const NN: usize>(
    body: &Body,
    cells: &[[usize; NN]],
    blocks: &[f64],
    x: &[f64],
    y: &mut [f64],
) {
    for (nodes, m) in cells.iter().zip(blocks.chunks_exact(NN * NN)) {
        let g: [usize; NN] = std::array::from_fn(|i| 2 * body.global(nodes[i]));
        for i in 0..NN {
            for j in 0..NN {
                y[g[i]] += m[i * NN + j] * x[g[j]];
                y[g[i] + 1] += m[i * NN + j] * x[g[j] + 1];
            }
        }
    }
}

/// The rod blend 3/2 consistent - 1/2 lumped in place (an nn x nn element matrix): for the
/// two-node rod rho A h / 4 [[1, 1], [1, 1]], with which the trapezoidal rule is free of
/// dispersion at Courant number 1 (docs/theory.md "Contact in implicit dynamics").
fn dispersion_free(m: &mut [f64], nn: usize) {
    let rows: Vec<f64> = (0..nn)
        .map(|i| m[i * nn..(i + 1) * nn].iter().sum())
        .collect();
    for i in 0..nn {
        for j in 0..nn {
            let lumped = if i == j { rows[i] } else { 0.0 };
            m[i * nn + j] = 1.5 * m[i * nn + j] - 0.5 * lumped;
        }
    }
}

/// Removes the rows and columns of the `flagged` nodes of an element matrix and puts the
/// mass they held on the diagonal of the others, in proportion to their row sums.
fn redistribute(m: &mut [f64], nn: usize, flagged: &[bool]) {
    let total: f64 = m.iter().sum();
    let rows: Vec<f64> = (0..nn)
        .map(|i| m[i * nn..(i + 1) * nn].iter().sum())
        .collect();
    for i in 0..nn {
        for j in 0..nn {
            if flagged[i] || flagged[j] {
                m[i * nn + j] = 0.0;
            }
        }
    }
    let kept: f64 = m.iter().sum();
    let weight: f64 = (0..nn).filter(|i| !flagged[*i]).map(|i| rows[i]).sum();
    for i in (0..nn).filter(|i| !flagged[*i]) {
        m[i * nn + i] += (total - kept) * rows[i] / weight;
    }
}
