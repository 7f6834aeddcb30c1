//! The probes' values of a history row: nodal quantities and their statistics, extents,
//! momenta, support reactions, and the points' quantities over the state (the explicit
//! kernels answer a point probe from their own arrays: `ExplicitKernel::point_probe`).

use crate::analysis::steppers::energies::{Energies, Motion};
use crate::analysis::steppers::loads;
use crate::assembly::State;
use crate::contact::ContactState;
use crate::material::PointState;
use crate::scene::Model;
use crate::scene::model::{PointFold, Probe, RUN_PART, in_parts};
use crate::scene::spec::{Quantity, Statistic};
use rayon::prelude::*;
use std::ops::Range;

/// What a history row and a frame read of the run at a converged step.
#[derive(Clone, Copy)]
pub struct Snapshot<'a> {
    pub state: &'a State,
    pub motion: &'a Motion<'a>,
    pub energies: &'a Energies,
    /// The contact status (None before the first step).
    pub contact: Option<&'a ContactState>,
    /// The contact status for the frames: before the first step too (the initial gaps).
    pub frame_contact: Option<&'a ContactState>,
}

pub(super) fn is_reaction(quantity: Quantity) -> bool {
    matches!(quantity, Quantity::ReactionX | Quantity::ReactionY)
}

/// The support reactions of the committed state, per DOF (zero at free DOFs):
/// ```text
/// R = f_int(sigma) - f_ext(t) + m a     at the constrained DOFs
/// ```
/// f_int the internal force the step converged with, f_ext the loads at the state's time, m
/// the lumped mass (dynamics; absent in statics). Contact forces on constrained nodes and
/// Rayleigh damping are not part of it.
pub(super) fn reactions(model: &Model, state: &State, motion: &Motion) -> Vec<f64> {
    let mut external = vec![0.0; model.dofs()];
    loads::add_external_force(
        model,
        state,
        &model.coordinates(),
        state.time,
        &mut external,
    );
    let mut reaction = vec![0.0; model.dofs()];
    for dof in model.constrained_dofs() {
        let inertia = motion
            .mass
            .get(dof)
            .map_or(0.0, |m| m * motion.acceleration[dof]);
        reaction[dof] = motion.internal_force[dof] - external[dof] + inertia;
    }
    reaction
}

/// The smallest and the largest of `x` over `members`, in the probes' parts (`in_parts`: in
/// parallel on several threads; an extent over a whole body is a serial pass per step
/// otherwise; min and max are exact, so the parts give the one fold's answer).
fn span(members: &[usize], x: impl Fn(usize) -> f64 + Sync) -> (f64, f64) {
    in_parts(members, |part| span_lanes(part, &x))
        .into_iter()
        .fold(EMPTY_SPAN, |(low, high), (l, h)| (low.min(l), high.max(h)))
}

/// The smallest and the largest of initial + displacement in component `c` over the nodes
/// `nodes` (consecutive; `initial` theirs): what `span` gives over their ids (min and max are
/// exact), read from contiguous arrays, in parallel parts on several threads for a long run.
fn span_of_run(
    initial: &[[f64; 2]],
    displacement: &[f64],
    nodes: &Range<usize>,
    c: usize,
) -> (f64, f64) {
    let u = &displacement[2 * nodes.start..2 * nodes.end];
    let part = |(x, u): (&[[f64; 2]], &[f64])| {
        x.iter()
            .zip(u.chunks_exact(2))
            .map(|(x, u)| x[c] + u[c])
            .fold(EMPTY_SPAN, |(low, high), v| (low.min(v), high.max(v)))
    };
    let spans: Vec<(f64, f64)> = if initial.len() > RUN_PART && rayon::current_num_threads() > 1 {
        initial
            .par_chunks(RUN_PART)
            .zip(u.par_chunks(2 * RUN_PART))
            .map(part)
            .collect()
    } else {
        vec![part((initial, u))]
    };
    spans
        .into_iter()
        .fold(EMPTY_SPAN, |(low, high), (l, h)| (low.min(l), high.max(h)))
}

/// The span of no value.
const EMPTY_SPAN: (f64, f64) = (f64::INFINITY, f64::NEG_INFINITY);

/// The smallest and the largest of `x` over `members`, in four independent lanes (the lanes
/// let the comparisons of a long set overlap instead of waiting each on the last).
fn span_lanes(members: &[usize], x: impl Fn(usize) -> f64) -> (f64, f64) {
    let mut low = [f64::INFINITY; 4];
    let mut high = [f64::NEG_INFINITY; 4];
    let chunks = members.chunks_exact(4);
    let rest = chunks.remainder();
    for chunk in chunks {
        for lane in 0..4 {
            let v = x(chunk[lane]);
            low[lane] = low[lane].min(v);
            high[lane] = high[lane].max(v);
        }
    }
    for (lane, &m) in rest.iter().enumerate() {
        let v = x(m);
        low[lane] = low[lane].min(v);
        high[lane] = high[lane].max(v);
    }
    let low = low.into_iter().fold(f64::INFINITY, f64::min);
    let high = high.into_iter().fold(f64::NEG_INFINITY, f64::max);
    (low, high)
}

/// A probe's statistic over the state's points.
struct StatePoints<'a> {
    probe: &'a Probe,
    points: &'a [PointState],
    points_per_element: usize,
}

impl PointFold for StatePoints<'_> {
    #[inline]
    fn fold(self, value: impl Fn(&PointState) -> f64 + Sync) -> f64 {
        (self.probe).of_points(self.points, self.points_per_element, value)
    }
}

/// The value of probe `probe` at `snapshot` (`reaction`: the support reactions, where a
/// probe reads them; `initial`: the nodes' initial positions).
pub(super) fn probe_value(
    model: &Model,
    snapshot: &Snapshot,
    reaction: Option<&[f64]>,
    initial: &[[f64; 2]],
    probe: &crate::scene::model::Probe,
) -> f64 {
    let (state, motion) = (snapshot.state, snapshot.motion);
    let nodal = |v: &[f64], c: usize| match probe.statistic {
        Statistic::MassMean => mass_mean(&probe.members, motion.mass, |m| v[2 * m + c], c),
        _ => probe.combine(|members| members.iter().map(move |m| v[2 * m + c])),
    };
    let ppe = model.bodies[probe.body].points_per_element();
    let body_points = &state.bodies[probe.body].points;
    match probe.quantity {
        Quantity::DisplacementX => nodal(&state.displacement, 0),
        Quantity::DisplacementY => nodal(&state.displacement, 1),
        Quantity::VelocityX => nodal(motion.velocity, 0),
        Quantity::VelocityY => nodal(motion.velocity, 1),
        Quantity::AccelerationX => nodal(motion.acceleration, 0),
        Quantity::AccelerationY => nodal(motion.acceleration, 1),
        Quantity::MomentumX | Quantity::MomentumY => {
            let c = (probe.quantity == Quantity::MomentumY) as usize;
            probe
                .members
                .iter()
                .map(|m| {
                    motion
                        .mass
                        .get(2 * m + c)
                        .map_or(0.0, |mass| mass * motion.velocity[2 * m + c])
                })
                .sum()
        }
        Quantity::ReactionX | Quantity::ReactionY => {
            let c = (probe.quantity == Quantity::ReactionY) as usize;
            let reaction = reaction.expect("computed when a reaction probe exists");
            probe.members.iter().map(|m| reaction[2 * m + c]).sum()
        }
        Quantity::CoordinateX | Quantity::CoordinateY => {
            let c = (probe.quantity == Quantity::CoordinateY) as usize;
            let x = |m: usize| initial[m][c] + state.displacement[2 * m + c];
            match probe.statistic {
                Statistic::MassMean => mass_mean(&probe.members, motion.mass, x, c),
                _ => probe.combine(|members| members.iter().map(|&m| x(m))),
            }
        }
        Quantity::ExtentX | Quantity::ExtentY => {
            let c = (probe.quantity == Quantity::ExtentY) as usize;
            let (low, high) = match &probe.consecutive {
                Some(nodes) => span_of_run(&initial[nodes.clone()], &state.displacement, nodes, c),
                None => span(&probe.members, |m| {
                    initial[m][c] + state.displacement[2 * m + c]
                }),
            };
            if c == 0 && model.bodies[probe.body].is_axisymmetric() {
                // the body of revolution spans -r_max .. r_max
                2.0 * high
            } else {
                high - low
            }
        }
        _ => {
            // every other quantity is a point's
            let points = StatePoints {
                probe,
                points: body_points,
                points_per_element: ppe,
            };
            probe.fold_points(points).unwrap_or(f64::NAN)
        }
    }
}

/// sum m q / sum m over the nodes `members`, q = `value(node)` of component `c` and m the
/// node's lumped mass (NaN without masses: a static analysis, which the scene refuses).
fn mass_mean(members: &[usize], mass: &[f64], value: impl Fn(usize) -> f64, c: usize) -> f64 {
    let (weighted, total) = members.iter().fold((0.0, 0.0), |(w, t), &m| {
        let mass = mass.get(2 * m + c).copied().unwrap_or(f64::NAN);
        (w + mass * value(m), t + mass)
    });
    weighted / total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_span_of_a_long_run_of_nodes_is_its_ends() {
        // more nodes than two parts, on three threads, against the ends of the sorted
        // positions, in each component, over the run of nodes 5..n
        let n = 2 * RUN_PART + 400;
        let initial: Vec<[f64; 2]> = (0..n)
            .map(|k| [(k % 97) as f64, -((k % 89) as f64)])
            .collect();
        let displacement: Vec<f64> = (0..2 * n).map(|i| ((i * 31) % 53) as f64 * 0.01).collect();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        for c in 0..2 {
            let mut x: Vec<f64> = (5..n)
                .map(|m| initial[m][c] + displacement[2 * m + c])
                .collect();
            x.sort_by(f64::total_cmp);
            let span = pool.install(|| span_of_run(&initial[5..], &displacement, &(5..n), c));
            assert_eq!(span, (x[0], x[x.len() - 1]));
        }
    }
}
