//! The explicit fast path: the one-point Quad4 of `element::quad4_one_point` over element
//! data as structure of arrays, internal forces in parallel (docs/theory.md, "Reduced
//! explicit Quad4"). The element's kinematics, hourglass control and forces are the
//! kernel's; here the material updates the rotated stress between them.
//!
//! Legend (one element; see `element::quad4_one_point` for the kinematics)
//! ```text
//! sigma      sigma_{n+1} = material(R sigma_n R^T, d)   (back stress rotated alike)
//! W_int      t A_mid 1/2 (R sigma_n R^T + sigma_{n+1}) . d;  W_hg = 1/2 (R Q_n + Q_{n+1}) . q
//! ```
//! Parallel and deterministic: elements are processed in fixed chunks (rayon), each writes
//! its own 8 force entries; nodes then gather their elements' entries in element order, and
//! the chunk sums of the work are added in chunk order. The bits do not depend on the thread
//! count.

use super::{ElementFailure, State};
use crate::element::quad4_one_point::{self as one_point, Nodes, rotate};
use crate::element::{Formulation, KernelError, Voigt};
use crate::material::{FlowStart, Material, PointState, StressCondition, UpdateContext};
use crate::scene::{BodyKind, Model};
use rayon::prelude::*;

/// Elements per parallel task (fixed, so the work sums do not depend on the thread count).
const CHUNK: usize = 256;

/// What the kernel needs of a body.
#[derive(Debug, Clone)]
struct BodyParameters {
    name: String,
    material: Material,
    plane_stress: bool,
    lambda: f64,
    mu: f64,
    /// kappa (lambda + 3 mu) / 24
    hourglass_modulus: f64,
    first_element: usize,
}

/// The committed state of one element as the kernel reads it.
#[derive(Debug, Clone, Copy)]
pub struct ElementState {
    /// Cauchy stress [xx yy zz xy].
    pub stress: [f64; 4],
    pub back_stress: [f64; 4],
    pub eq_plastic_strain: f64,
    /// Temperature (0 for materials that carry none).
    pub temperature: f64,
    /// Current thickness (plane stress), else 1.
    pub thickness: f64,
    /// Hourglass forces Q [x y].
    pub hourglass: [f64; 2],
}

/// The new state of one element after a step, with its forces and work.
#[derive(Debug, Clone, Copy)]
pub struct ElementStep {
    pub state: ElementState,
    /// Internal force [f1x f1y ... f4x f4y] on the end configuration.
    pub force: [f64; 8],
    /// Work of the stresses (hourglass excluded).
    pub work: f64,
    pub plastic_work: f64,
    pub hourglass_work: f64,
}

/// One element over one step of length dt: positions x at the start, increment u (see the
/// legend).
#[inline(always)]
fn element_step(
    p: &BodyParameters,
    x: &Nodes,
    u: &Nodes,
    committed: &ElementState,
    dt: f64,
) -> Result<ElementStep, KernelError> {
    let step = one_point::increment(x, u)?;
    let (c, s) = (step.cos, step.sin);
    let stress_n = rotate(&committed.stress, c, s);
    let back_n = rotate(&committed.back_stress, c, s);
    let mut strain = step.strain;
    let t = committed.thickness;
    let (stress, back_stress, eq_plastic_strain, plastic_density, thickness) = if p.plane_stress {
        let r = p.material.update(
            &PointState {
                stress: Voigt::from(stress_n),
                eq_plastic_strain: committed.eq_plastic_strain,
                back_stress: Voigt::from(back_n),
                temperature: committed.temperature,
            },
            &Voigt::from(strain),
            UpdateContext {
                condition: StressCondition::PlaneStress,
                dt,
            },
        );
        strain[2] = r.strain_zz;
        (
            r.state.stress.into(),
            r.state.back_stress.into(),
            r.state.eq_plastic_strain,
            r.plastic_work,
            t * r.strain_zz.exp(),
        )
    } else {
        let (lambda, mu) = (p.lambda, p.mu);
        let volumetric = lambda * (strain[0] + strain[1]);
        let trial = [
            stress_n[0] + volumetric + 2.0 * mu * strain[0],
            stress_n[1] + volumetric + 2.0 * mu * strain[1],
            stress_n[2] + volumetric,
            stress_n[3] + mu * strain[3],
        ];
        let plastic = p.material.plasticity.as_ref().and_then(|j2| {
            j2.radial(
                &Voigt::from(trial),
                mu,
                &Voigt::from(back_n),
                FlowStart {
                    eq_plastic_strain: committed.eq_plastic_strain,
                    temperature: committed.temperature,
                    dt,
                },
            )
            .map(|r| {
                let work = r.plastic_work();
                (
                    r.stress.into(),
                    r.back_stress.into(),
                    r.eq_plastic_strain,
                    work,
                )
            })
        });
        match plastic {
            None => (trial, back_n, committed.eq_plastic_strain, 0.0, t),
            Some((stress, back, eps_p, work)) => (stress, back, eps_p, work, t),
        }
    };
    // adiabatic heating by the step's plastic work (Johnson-Cook; the others keep theirs)
    let temperature = p.material.heated(committed.temperature, plastic_density);
    let volume = step.gradient.area * t;
    let work = volume
        * 0.5
        * (0..4)
            .map(|k| (stress_n[k] + stress[k]) * strain[k])
            .sum::<f64>();
    let hourglass = one_point::hourglass(&step, u, &committed.hourglass, p.hourglass_modulus, t);
    let state = ElementState {
        stress,
        back_stress,
        eq_plastic_strain,
        temperature,
        thickness,
        hourglass: hourglass.forces,
    };
    let force = one_point::force(&step.end, &state.stress, state.thickness, &state.hourglass)?;
    Ok(ElementStep {
        state,
        force,
        work,
        plastic_work: volume * plastic_density,
        hourglass_work: hourglass.work,
    })
}

/// The sums of one step.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepWork {
    /// Work of the stresses and the hourglass forces (includes both below).
    pub internal: f64,
    pub plastic: f64,
    pub hourglass: f64,
}

/// Element data of all Quad4 bodies as flat arrays (element-major, global element index
/// over the bodies in order).
#[derive(Debug, Clone)]
pub struct Reduced {
    bodies: Vec<BodyParameters>,
    /// Body of each element.
    body: Vec<u32>,
    /// Global nodes of each element, counter-clockwise.
    nodes: Vec<[u32; 4]>,
    /// Cauchy stress, 4 per element [xx yy zz xy].
    pub stress: Vec<f64>,
    /// Back stress, 4 per element.
    pub back_stress: Vec<f64>,
    pub eq_plastic_strain: Vec<f64>,
    /// Temperature per element (0 for materials that carry none).
    pub temperature: Vec<f64>,
    /// Current thickness per element (plane stress), else 1.
    pub thickness: Vec<f64>,
    /// Hourglass forces Q, 2 per element.
    pub hourglass: Vec<f64>,
    /// Element forces of the last evaluation, 8 per element.
    element_forces: Vec<f64>,
    /// Node -> its entries in `element_forces` (CSR, element order).
    node_start: Vec<usize>,
    node_entries: Vec<u32>,
    /// Accumulated hourglass work.
    pub hourglass_energy: f64,
}

impl Reduced {
    /// The kernel for the Quad4 bodies of `model` (plane strain or plane stress; the scene
    /// validation refuses the rest), starting from the committed `state`; `kappa` is the
    /// hourglass coefficient.
    pub fn new(model: &Model, state: &State, kappa: f64) -> Reduced {
        let mut bodies = Vec::new();
        let mut body = Vec::new();
        let mut nodes = Vec::new();
        let (mut stress, mut back_stress, mut eq_plastic_strain, mut thickness) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut temperature = Vec::new();
        for (b, spec) in model.bodies.iter().enumerate() {
            let BodyKind::Continuum { formulation, .. } = spec.kind else {
                continue;
            };
            let plane_stress = formulation == Formulation::PlaneStress;
            let (mut lambda, mu) = spec.material.elastic.lame();
            if plane_stress {
                lambda = 2.0 * lambda * mu / (lambda + 2.0 * mu);
            }
            bodies.push(BodyParameters {
                name: spec.name.clone(),
                material: spec.material.clone(),
                plane_stress,
                lambda: spec.material.elastic.lame().0,
                mu,
                hourglass_modulus: kappa * (lambda + 3.0 * mu) / 24.0,
                first_element: body.len(),
            });
            let index = (bodies.len() - 1) as u32;
            let committed = &state.bodies[b];
            for e in 0..spec.elements() {
                let n = spec.mesh.cells.nodes_of(e);
                body.push(index);
                nodes.push(std::array::from_fn(|a| spec.global(n[a]) as u32));
                let p = &committed.points[4 * e];
                stress.extend(p.stress.iter());
                back_stress.extend(p.back_stress.iter());
                eq_plastic_strain.push(p.eq_plastic_strain);
                temperature.push(p.temperature);
                thickness.push(committed.thickness[4 * e]);
            }
        }
        let count = body.len();
        let mut node_start = vec![0usize; state.coordinates.len() + 1];
        for element in &nodes {
            for n in element {
                node_start[*n as usize + 1] += 1;
            }
        }
        for n in 0..state.coordinates.len() {
            node_start[n + 1] += node_start[n];
        }
        let mut fill = node_start.clone();
        let mut node_entries = vec![0u32; node_start[state.coordinates.len()]];
        for (e, element) in nodes.iter().enumerate() {
            for (a, n) in element.iter().enumerate() {
                node_entries[fill[*n as usize]] = (8 * e + 2 * a) as u32;
                fill[*n as usize] += 1;
            }
        }
        Reduced {
            bodies,
            body,
            nodes,
            stress,
            back_stress,
            eq_plastic_strain,
            temperature,
            thickness,
            hourglass: vec![0.0; 2 * count],
            element_forces: vec![0.0; 8 * count],
            node_start,
            node_entries,
            hourglass_energy: 0.0,
        }
    }

    pub fn elements(&self) -> usize {
        self.body.len()
    }

    fn failure(&self, element: usize, error: KernelError) -> ElementFailure {
        let p = &self.bodies[self.body[element] as usize];
        ElementFailure {
            body: p.name.clone(),
            element: element - p.first_element,
            error,
        }
    }

    fn state_of(&self, e: usize) -> ElementState {
        ElementState {
            stress: std::array::from_fn(|k| self.stress[4 * e + k]),
            back_stress: std::array::from_fn(|k| self.back_stress[4 * e + k]),
            eq_plastic_strain: self.eq_plastic_strain[e],
            temperature: self.temperature[e],
            thickness: self.thickness[e],
            hourglass: [self.hourglass[2 * e], self.hourglass[2 * e + 1]],
        }
    }

    /// Sums the element forces into the nodes: `force` over all DOFs (overwritten; nodes
    /// of no Quad4 get zero).
    fn gather(&self, force: &mut [f64]) {
        let ef = &self.element_forces;
        force
            .par_chunks_mut(2 * CHUNK)
            .enumerate()
            .for_each(|(k, chunk)| {
                for (i, f) in chunk.chunks_exact_mut(2).enumerate() {
                    let n = k * CHUNK + i;
                    let (mut fx, mut fy) = (0.0, 0.0);
                    for entry in &self.node_entries[self.node_start[n]..self.node_start[n + 1]] {
                        fx += ef[*entry as usize];
                        fy += ef[*entry as usize + 1];
                    }
                    f[0] = fx;
                    f[1] = fy;
                }
            });
    }

    /// The internal force on the positions `x` from the stored state (no update).
    pub fn internal_force(
        &mut self,
        x: &[[f64; 2]],
        force: &mut [f64],
    ) -> Result<(), ElementFailure> {
        let mut forces = std::mem::take(&mut self.element_forces);
        let this = &*self;
        let error = forces
            .par_chunks_mut(8 * CHUNK)
            .enumerate()
            .map(|(k, chunk)| {
                for (i, f) in chunk.chunks_exact_mut(8).enumerate() {
                    let e = k * CHUNK + i;
                    let xe: Nodes = this.nodes[e].map(|n| x[n as usize]);
                    let state = this.state_of(e);
                    match one_point::force(&xe, &state.stress, state.thickness, &state.hourglass) {
                        Ok(v) => f.copy_from_slice(&v),
                        Err(err) => return Some((e, err)),
                    }
                }
                None
            })
            .collect::<Vec<_>>()
            .into_iter()
            .flatten()
            .next();
        self.element_forces = forces;
        if let Some((e, err)) = error {
            return Err(self.failure(e, err));
        }
        self.gather(force);
        Ok(())
    }

    /// One step: from positions `x` (the start of the step) by the increment `du` (2 per
    /// node); updates the element state and writes the internal force on x + du into
    /// `force`. After an error the element state is partly updated and the run must stop.
    /// `dt` is the step's length (the strain rate of rate-dependent materials).
    pub fn step(
        &mut self,
        x: &[[f64; 2]],
        du: &[f64],
        dt: f64,
        force: &mut [f64],
    ) -> Result<StepWork, ElementFailure> {
        let bodies = &self.bodies;
        let body = &self.body;
        let nodes = &self.nodes;
        let results: Vec<(StepWork, Option<(usize, KernelError)>)> = (
            self.stress.par_chunks_mut(4 * CHUNK),
            self.back_stress.par_chunks_mut(4 * CHUNK),
            self.eq_plastic_strain.par_chunks_mut(CHUNK),
            self.temperature.par_chunks_mut(CHUNK),
            self.thickness.par_chunks_mut(CHUNK),
            self.hourglass.par_chunks_mut(2 * CHUNK),
            self.element_forces.par_chunks_mut(8 * CHUNK),
        )
            .into_par_iter()
            .enumerate()
            .map(|(k, chunks)| {
                let (stress, back, eps_p, temperature, thickness, hourglass, forces) = chunks;
                let mut sums = StepWork::default();
                for i in 0..eps_p.len() {
                    let e = k * CHUNK + i;
                    let element = nodes[e];
                    let xe: Nodes = element.map(|n| x[n as usize]);
                    let ue: Nodes = element.map(|n| [du[2 * n as usize], du[2 * n as usize + 1]]);
                    let committed = ElementState {
                        stress: std::array::from_fn(|c| stress[4 * i + c]),
                        back_stress: std::array::from_fn(|c| back[4 * i + c]),
                        eq_plastic_strain: eps_p[i],
                        temperature: temperature[i],
                        thickness: thickness[i],
                        hourglass: [hourglass[2 * i], hourglass[2 * i + 1]],
                    };
                    let p = &bodies[body[e] as usize];
                    let r = match element_step(p, &xe, &ue, &committed, dt) {
                        Ok(r) => r,
                        Err(err) => return (sums, Some((e, err))),
                    };
                    stress[4 * i..4 * i + 4].copy_from_slice(&r.state.stress);
                    back[4 * i..4 * i + 4].copy_from_slice(&r.state.back_stress);
                    eps_p[i] = r.state.eq_plastic_strain;
                    temperature[i] = r.state.temperature;
                    thickness[i] = r.state.thickness;
                    hourglass[2 * i..2 * i + 2].copy_from_slice(&r.state.hourglass);
                    forces[8 * i..8 * i + 8].copy_from_slice(&r.force);
                    sums.internal += r.work + r.hourglass_work;
                    sums.plastic += r.plastic_work;
                    sums.hourglass += r.hourglass_work;
                }
                (sums, None)
            })
            .collect();
        let mut total = StepWork::default();
        for (sums, error) in results {
            if let Some((e, err)) = error {
                return Err(self.failure(e, err));
            }
            total.internal += sums.internal;
            total.plastic += sums.plastic;
            total.hourglass += sums.hourglass;
        }
        self.gather(force);
        self.hourglass_energy += total.hourglass;
        Ok(total)
    }

    /// Copies the element state into the 4 points of each element of `state` (what the
    /// recorder and the probes read).
    pub fn write_points(&self, model: &Model, state: &mut State) {
        let mut e0 = 0;
        for (b, spec) in model.bodies.iter().enumerate() {
            if !matches!(spec.kind, BodyKind::Continuum { .. }) {
                continue;
            }
            let bs = &mut state.bodies[b];
            bs.points
                .par_chunks_mut(4)
                .zip(bs.thickness.par_chunks_mut(4))
                .enumerate()
                .for_each(|(e, (points, thickness))| {
                    let s = self.state_of(e0 + e);
                    let point = PointState {
                        stress: Voigt::from(s.stress),
                        eq_plastic_strain: s.eq_plastic_strain,
                        back_stress: Voigt::from(s.back_stress),
                        temperature: s.temperature,
                    };
                    points.fill(point);
                    thickness.fill(s.thickness);
                });
            e0 += spec.elements();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Elastic;

    fn parameters() -> BodyParameters {
        let material = Material {
            name: "m".into(),
            density: 1.0,
            elastic: Elastic {
                young: 200.0,
                poisson: 0.3,
            },
            plasticity: None,
        };
        let (lambda, mu) = material.elastic.lame();
        BodyParameters {
            name: "b".into(),
            material,
            plane_stress: false,
            lambda,
            mu,
            hourglass_modulus: 0.1 * (lambda + 3.0 * mu) / 24.0,
            first_element: 0,
        }
    }

    const SQUARE: Nodes = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.5], [0.0, 1.5]];

    /// A rigid rotation by 0.3 rad in 100 increments leaves a stressed element's stress
    /// invariants unchanged (Hughes-Winget is exactly orthogonal) and its forces in
    /// equilibrium with the rotated stress.
    #[test]
    fn rigid_rotation_keeps_the_invariants() {
        let p = parameters();
        let mut x = SQUARE;
        let mut state = ElementState {
            stress: [1.0, -0.5, 0.2, 0.3],
            back_stress: [0.0; 4],
            eq_plastic_strain: 0.0,
            temperature: 0.0,
            thickness: 1.0,
            hourglass: [0.0; 2],
        };
        let step: f64 = 0.003;
        let (c, s) = (step.cos(), step.sin());
        for _ in 0..100 {
            let u: Nodes = std::array::from_fn(|a| {
                let [px, py] = x[a];
                [c * px - s * py - px, s * px + c * py - py]
            });
            state = element_step(&p, &x, &u, &state, 1.0).unwrap().state;
            x = std::array::from_fn(|a| [x[a][0] + u[a][0], x[a][1] + u[a][1]]);
        }
        // round-off: E ~ 200 times strains of ~1e-16 per step
        let [a, b, zz, t] = state.stress;
        assert!((a + b - 0.5).abs() < 1e-11, "trace {}", a + b);
        assert!((a * b - t * t - (-0.5 - 0.09)).abs() < 1e-11);
        assert!((zz - 0.2).abs() < 1e-11, "zz {zz}");
        // and it turned with the body (counter-clockwise by phi = 0.3):
        // sigma_xy = (a0 - b0)/2 sin 2 phi + t0 cos 2 phi
        let expected = 0.5 * (1.0 + 0.5) * 0.6f64.sin() + 0.3 * 0.6f64.cos();
        assert!((t - expected).abs() < 1e-11, "xy {t} vs {expected}");
    }
}
