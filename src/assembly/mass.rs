//! The mass matrix: the consistent element blocks (or their row sums, lumped) formed once on
//! the initial configuration, the product M x, and M added into K*.

use super::{ElementFailure, Kernel, System};
use crate::mesh::Cells;
use crate::scene::spec::MassKind;
use crate::scene::{Body, InputError, Model};

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

    /// Each body's mass: the sum of its nodes' lumped masses in x (per unit depth in plane
    /// strain, through the thickness in plane stress, the full ring's in axisymmetry).
    pub fn of_bodies(&self, model: &Model) -> Vec<f64> {
        model
            .bodies
            .iter()
            .map(|body| {
                (0..body.mesh.nodes.len())
                    .map(|n| self.lumped[2 * body.global(n)])
                    .sum()
            })
            .collect()
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

    /// The kinetic energy a change of the velocities from `before` to `after` removed, DOF
    /// by DOF: 1/2 b.M b - 1/2 a.M a = -(a - b).M (a + b) / 2 (M symmetric), whose terms
    /// are zero where the velocity did not change (under a consistent mass too, where
    /// 1/2 v_d (M v)_d would move with its neighbours).
    pub fn kinetic_removed_by_dof(&self, model: &Model, before: &[f64], after: &[f64]) -> Vec<f64> {
        let mean: Vec<f64> = before
            .iter()
            .zip(after)
            .map(|(b, a)| 0.5 * (a + b))
            .collect();
        let momentum = self.product(model, &mean);
        (before.iter().zip(after).zip(momentum))
            .map(|((b, a), p)| if a == b { 0.0 } else { -(a - b) * p })
            .collect()
    }

    /// Each body's 1/2 v . M v over its own nodes (model order; the bodies share no node,
    /// so they sum to `kinetic_energy`).
    pub fn body_kinetic_energies(&self, model: &Model, v: &[f64]) -> Vec<f64> {
        let momentum = self.product(model, v);
        body_sums(model, |dof| 0.5 * momentum[dof] * v[dof])
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

/// Refuses a dynamic model without mass on some free DOF (`free`: per DOF; zero density).
pub fn check_mass(model: &Model, mass: &Mass, free: &[bool]) -> Result<(), InputError> {
    for (dof, free) in free.iter().enumerate() {
        if *free && !(mass.lumped[dof] > 0.0) {
            let node = dof / 2;
            let body = model
                .bodies
                .iter()
                .rev()
                .find(|b| b.node_offset <= node)
                .expect("node in a body");
            return Err(InputError::new(
                &model.file,
                format!(
                    "material `{}`.density: a dynamic analysis needs density > 0 (body `{}`)",
                    body.material.name, body.name
                ),
            ));
        }
    }
    Ok(())
}

/// Per body (model order), the sum of `value` over the body's DOFs.
pub fn body_sums(model: &Model, value: impl Fn(usize) -> f64) -> Vec<f64> {
    (model.bodies.iter())
        .map(|body| {
            let first = 2 * body.global(0);
            (first..first + 2 * body.mesh.nodes.len()).map(&value).sum()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// Two unit squares side by side (density 3, plane strain: mass per unit depth), and a
    /// lone square to the right of them whose lower-left node alone is flagged below.
    const SQUARES: &str = r#"
[[material]]
name = "m"
young = 1.0
poisson = 0.25
density = 3.0

[[body]]
name = "pair"
material = "m"
formulation = "plane_strain"
mesh = { type = "rectangle", width = 2.0, height = 1.0, nx = 2, ny = 1 }

[[body]]
name = "lone"
material = "m"
formulation = "plane_strain"
mesh = { type = "rectangle", origin = [5.0, 0.0], width = 1.0, height = 1.0, nx = 1, ny = 1 }

[analysis]
type = "dynamic"
dt = 0.1
end_time = 1.0
"#;

    /// The consistent mass of a unit square with density 3 between its nodes at `a` and
    /// `b` (by hand: rho A / 36 times 4 on the diagonal, 2 along an edge, 1 across).
    fn square(a: [f64; 2], b: [f64; 2]) -> f64 {
        let differ = (a[0] != b[0]) as usize + (a[1] != b[1]) as usize;
        3.0 / 36.0 * [4.0, 2.0, 1.0][differ]
    }

    /// Goal: each body's kinetic energy under the consistent mass is its own 1/2 v . M v.
    /// Setup: SQUARES, the pair (mass 6) translating at (1, -2), the lone square (mass 3) at
    /// (0, 3). Reference: a rigid translation's kinetic energy 1/2 m |v|^2 (the consistent
    /// matrix's rows sum to the lumped masses): 15 and 13.5; their sum is the model's
    /// `kinetic_energy`. Tolerance 1e-13: sums of a few O(1) numbers.
    #[test]
    fn each_body_has_its_own_kinetic_energy() {
        let model = crate::scene::from_str(SQUARES, Path::new("squares.toml"), &[]).unwrap();
        let mass = Mass::new(&model, MassKind::Consistent).unwrap();
        let mut v = vec![0.0; model.dofs()];
        for (body, velocity) in model.bodies.iter().zip([[1.0, -2.0], [0.0, 3.0]]) {
            for n in 0..body.mesh.nodes.len() {
                v[2 * body.global(n)..2 * body.global(n) + 2].copy_from_slice(&velocity);
            }
        }
        let energies = mass.body_kinetic_energies(&model, &v);
        assert!((energies[0] - 15.0).abs() < 1e-13, "{energies:?}");
        assert!((energies[1] - 13.5).abs() < 1e-13, "{energies:?}");
        assert!((mass.kinetic_energy(&model, &v) - 28.5).abs() < 1e-13);
    }

    /// Goal: `Mass::redistributed` leaves the flagged nodes massless, keeps every element's
    /// mass, and moves the removed mass onto the other nodes' diagonals in proportion to
    /// their row sums (Khenous, Laborde & Renard 2008).
    /// Setup: SQUARES with the nodes at y = 0 of the pair and the lone square's node at
    /// (5, 0) flagged: each square of the pair loses two adjacent nodes, the lone one one.
    /// Reference (by hand from the closed-form square matrix rho A / 36 [4 2 1 2; ...] with
    /// rho A = 3): a pair square keeps [4 2; 2 4] / 12 (sum 1), its removed 2 goes half and
    /// half (equal row sums 3/4) onto the two top diagonals: [16 2; 2 16] / 12, rows 3/2
    /// each; the pair's top corners carry 3/2, its top middle node 3. The lone square keeps
    /// the 3 x 3 block (sum 22 / 12), its removed 14 / 12 goes in thirds (equal row sums)
    /// onto the three diagonals: 38 / 36 at the node across, 35 / 36 beside. Tolerance 1e-14:
    /// sums of a few O(1) numbers.
    #[test]
    fn redistributed_mass_leaves_flagged_nodes_massless_and_keeps_element_totals() {
        let model = crate::scene::from_str(SQUARES, Path::new("squares.toml"), &[]).unwrap();
        let coords = model.coordinates();
        let flagged: Vec<bool> = coords
            .iter()
            .map(|p| p[1] == 0.0 && (p[0] < 3.0 || p[0] == 5.0))
            .collect();
        assert_eq!(flagged.iter().filter(|f| **f).count(), 4);
        let mass = Mass::new(&model, MassKind::Consistent)
            .unwrap()
            .redistributed(&model, &flagged);
        for (b, body) in model.bodies.iter().enumerate() {
            for e in 0..body.elements() {
                let nodes: Vec<usize> = body
                    .mesh
                    .cells
                    .nodes_of(e)
                    .iter()
                    .map(|n| body.global(*n))
                    .collect();
                let m = &mass.elements[b][e * 16..(e + 1) * 16];
                let kept: Vec<bool> = nodes.iter().map(|n| !flagged[*n]).collect();
                let removed: f64 = (0..4)
                    .flat_map(|i| (0..4).map(move |j| (i, j)))
                    .filter(|(i, j)| !kept[*i] || !kept[*j])
                    .map(|(i, j)| square(coords[nodes[i]], coords[nodes[j]]))
                    .sum();
                let share = removed / kept.iter().filter(|k| **k).count() as f64;
                for i in 0..4 {
                    for j in 0..4 {
                        let expected = if !kept[i] || !kept[j] {
                            0.0
                        } else {
                            square(coords[nodes[i]], coords[nodes[j]])
                                + if i == j { share } else { 0.0 }
                        };
                        assert!(
                            (m[4 * i + j] - expected).abs() < 1e-14,
                            "body {b} element {e} entry ({i}, {j}): {} vs {expected}",
                            m[4 * i + j]
                        );
                    }
                }
                let total: f64 = m.iter().sum();
                assert!((total - 3.0).abs() < 1e-14, "element total {total}");
            }
        }
        for (node, p) in coords.iter().enumerate() {
            let expected = match (flagged[node], p[0] < 3.0, p[0]) {
                (true, _, _) => 0.0,
                (false, true, 1.0) => 3.0,
                (false, true, _) => 1.5,
                // the lone square: a kept row (8 / 36 across from the flagged node, 7 / 36
                // beside it, times 3) plus its third of 14 / 12
                (false, false, _) if p == &[6.0, 1.0] => 38.0 / 36.0,
                (false, false, _) => 35.0 / 36.0,
            };
            for dof in [2 * node, 2 * node + 1] {
                assert!(
                    (mass.lumped[dof] - expected).abs() < 1e-14,
                    "node {node} at {p:?}: {} vs {expected}",
                    mass.lumped[dof]
                );
            }
        }
    }
}
