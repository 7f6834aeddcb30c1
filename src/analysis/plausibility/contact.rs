//! What a finished run says of its contact pairs: a pair that never closed (and how its
//! slaves moved at the start), a penetration beyond the discretization's own.

use super::model_size;
use crate::analysis::Summary;
use crate::analysis::steppers::energies::Energies;
use crate::contact::{ContactPair, penetration_limits};
use crate::output::readable;
use crate::scene::Model;

/// A penetration deeper than this share of the slave node spacing warns: one-pass
/// node-to-segment contact lets master nodes into the slave body by a geometric error of
/// the discretization (a few per cent of an element at a curved tip: 3.8 % on round_bar),
/// and a body sinking into the other (the roles swapped: more than an element) is far
/// beyond it. Never below the pair's TOL.
pub const PENETRATION_SHARE: f64 = 0.05;

/// The warnings of the pairs that never closed, in a run where something moved (initial
/// kinetic energy or external work).
pub(super) fn never_closed_warnings(
    model: &Model,
    summary: &Summary,
    energies: &Energies,
) -> Vec<String> {
    let moved = summary.energy.initial > 0.0 || energies.external_work.abs() > 0.0;
    if !moved {
        return Vec::new();
    }
    summary
        .contact
        .never_closed
        .iter()
        .filter_map(|name| model.contacts.iter().find(|p| &p.name == name))
        .map(|pair| never_closed_warning(model, pair))
        .collect()
}

/// A penetration deeper than [`PENETRATION_SHARE`] of the slave node spacing (a lone
/// slave's element) and than the pairs' TOL.
pub(super) fn penetration_warning(model: &Model, summary: &Summary) -> Option<String> {
    let depth = summary.contact.max_penetration?;
    {
        let coords = model.coordinates();
        let limits = penetration_limits(&model.contacts, &coords);
        // a pair with one slave (a rod's end) has no spacing: the length of its elements
        let spacing = model
            .contacts
            .iter()
            .zip(&limits)
            .map(|(pair, limit)| match pair.slaves.as_slice() {
                [single] => shortest_edge_at(model, &coords, *single),
                _ => 2.0 * limit,
            })
            .fold(f64::INFINITY, f64::min);
        let tolerance = model
            .contacts
            .iter()
            .map(|c| c.options.tolerance)
            .fold(0.0, f64::max);
        let share = if spacing.is_finite() {
            PENETRATION_SHARE * spacing
        } else {
            0.0
        };
        let bound = tolerance.max(share);
        if depth > bound {
            return Some(format!(
                "contact: a node went {} deep into the other body, beyond {} (the larger of TOL \
                 and {} % of the slave node spacing, or of a lone slave's element); history.csv `penetration` shows when (a \
                 master node sinking into the slave body is not seen by one-pass contact: swap \
                 the roles or refine the slave surface)",
                readable(depth),
                readable(bound),
                100.0 * PENETRATION_SHARE
            ));
        }
    }
    None
}

/// A pair that never closed in a run where something moved, with the way its slaves moved
/// relative to the master at the start: the gap rate dg/dt of the slave nearest the master
/// under the initial velocities (a small advance of every node along its velocity, master
/// nodes included, so the rate is the relative one).
fn never_closed_warning(model: &Model, pair: &ContactPair) -> String {
    let coords = model.coordinates();
    let velocity = |n: usize| {
        [
            model.initial_velocity[2 * n],
            model.initial_velocity[2 * n + 1],
        ]
    };
    let speed = (0..model.node_count)
        .map(|n| velocity(n)[0].hypot(velocity(n)[1]))
        .fold(0.0, f64::max);
    let at = |x: &dyn Fn(usize) -> [f64; 2]| {
        pair.slaves
            .iter()
            .filter_map(|s| pair.gap(*s, x).map(|g| (*s, g.gap)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    };
    let start = at(&|n: usize| coords[n]);
    let name = &pair.name;
    let Some((slave, gap)) = start else {
        return format!(
            "contact `{name}` never closed: no slave node came within its search distance of \
             the master at the start; check the pair's slave and master sets (or obstacle) and \
             where the bodies are"
        );
    };
    // an advance of a millionth of the gap (or of the model's size) along the velocities
    let size = model_size(&coords);
    let h = if speed > 0.0 {
        1e-6 * gap.abs().max(1e-3 * size) / speed
    } else {
        0.0
    };
    let rate = if h > 0.0 {
        pair.gap(slave, &|n: usize| {
            let v = velocity(n);
            [coords[n][0] + h * v[0], coords[n][1] + h * v[1]]
        })
        .map(|g| (g.gap - gap) / h)
        .unwrap_or(0.0)
    } else {
        0.0
    };
    if rate > 0.0 {
        format!(
            "contact `{name}` never closed: at the start its slaves move away from the master \
             (gap {} opening at {}): check the sign of the body's velocity (or which side of \
             the master the slaves are on)",
            readable(gap),
            readable(rate)
        )
    } else if rate < 0.0 {
        format!(
            "contact `{name}` never closed although its slaves approach the master at the start \
             (gap {} closing at {}): the run ended before they met (lengthen analysis.end_time) \
             or they passed beside it (check the pair's sets and the master's extent)",
            readable(gap),
            readable(-rate)
        )
    } else {
        format!(
            "contact `{name}` never closed (gap {} at the start, no initial motion towards or \
             away from the master): the loads never brought the slaves onto it; check the \
             loads, analysis.end_time and the pair's sets",
            readable(gap)
        )
    }
}

/// The shortest element edge that ends at global node `node`.
fn shortest_edge_at(model: &Model, coords: &[[f64; 2]], node: usize) -> f64 {
    let mut shortest = f64::INFINITY;
    for body in &model.bodies {
        for e in 0..body.elements() {
            let nodes: Vec<usize> = body
                .mesh
                .cells
                .nodes_of(e)
                .iter()
                .map(|n| body.global(*n))
                .collect();
            for (i, a) in nodes.iter().enumerate() {
                let b = nodes[(i + 1) % nodes.len()];
                if (*a == node || b == node) && *a != b {
                    let (p, q) = (coords[*a], coords[b]);
                    shortest = shortest.min((q[0] - p[0]).hypot(q[1] - p[1]));
                }
            }
        }
    }
    shortest
}
