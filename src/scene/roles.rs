//! The roles of a one-pass pair between two bodies when the scene names none (docs/theory.md
//! 8.3d, "Roles chosen by the code"): on the implicit and static paths, where a pair is
//! one pass, the code picks the slave by a rule that reads the two surfaces alike, so the
//! run does not depend on which of them the scene calls the slave (Abaqus/Standard's general
//! contact likewise assigns pure master-slave roles itself).
//!
//! A mortar pair of an implicit dynamic run, whose master nodes a hold pair can keep out of
//! the slave body (8.3a-4), first reads the meshes:
//! 0. where both surfaces are closed (a body's whole boundary, the default set) and one
//!    surface's mean edge is below `UNLIKE` of the other's, the finer surface is the slave
//!    (mortar's own choice: the side that carries the multipliers; a coarser slave lets the
//!    finer master's nodes through between its own) and its master's nodes are held (the
//!    coarse master's corners are what would enter it: the block on a plate three times
//!    finer, exit 3 on Newmark with either surface the slave alone, completes so; validation
//!    4.15). An open set ends at its body's corner with the flank beside it left out, and
//!    there the hold made energy: the block's bottom over the finer plate's top stopped at
//!    4.0 us, the rod's end over a plate twice as fine at 200 m/s at 2.5 us (exit 3), where
//!    the length rule runs to 12.7 and 48 us; such pairs keep the rule below.
//!
//! Then, and on every other path, each step deciding when its measures differ by more than
//! 1 %:
//! 1. the shorter surface (total length of its edges) is the slave: its ends lie within the
//!    other's span, so the other's corners never enter it, while the longer surface's
//!    corners would enter a slave that runs past them (the block on the plate: with the
//!    plate the slave, its corners sank 0.17-0.39 mm into the plate on Newmark);
//! 2. the finer surface (shorter mean edge) is the slave;
//! 3. the body listed later in the scene is the slave (Abaqus/Standard: the lower-numbered
//!    component is the master).

use super::InputError;
use super::context::{Context, edge_lengths, edge_set, edge_sets_on_both};
use super::model::Body;
use super::spec::{AnalysisKind, ContactDiscretization, ContactSpec, IntegratorKind, Roles, Scene};
use crate::output::readable;
use std::borrow::Cow;

/// Two measures differ when one is below this fraction of the other.
const DIFFERS: f64 = 0.99;

/// Two meshes are of unlike size when one surface's mean edge is below this fraction of the
/// other's (step 0): 20 % apart, well beyond the spread of a graded or fitted mesh's edges
/// on meshes the scene means alike, and below the 3x of the unlike meshes.
const UNLIKE: f64 = 0.8;

/// Pair `k` (`spec`) with the roles it runs with, and why where the code chose them: the
/// scene's spec (None) where its roles stand, or the one the rule gives (swapped or not).
pub(super) fn with_roles<'s>(
    cx: &Context,
    bodies: &[Body],
    (k, spec): (usize, &'s ContactSpec),
    scene: &Scene,
) -> Result<(Cow<'s, ContactSpec>, Option<String>), InputError> {
    if !chosen_by_the_code(cx, bodies, spec, scene) {
        return Ok((Cow::Borrowed(spec), None));
    }
    let Some(master) = &spec.master else {
        return Ok((Cow::Borrowed(spec), None));
    };
    let key = format!("contact[{k}] (`{}`)", spec.name);
    let slave = Surface::of(cx, bodies, &spec.slave, &format!("{key}.slave"))?;
    let master = Surface::of(cx, bodies, master, &format!("{key}.master"))?;
    let may_hold = holds_master_nodes(spec, scene) && slave.closed && master.closed;
    let (swap, why, hold) = rule(&slave, &master, may_hold);
    let (s, m) = if swap {
        (&master, &slave)
    } else {
        (&slave, &master)
    };
    let hold_said = if hold {
        "; the master's nodes held where they enter the slave (`hold_master_nodes`)"
    } else {
        ""
    };
    let why = format!(
        "the roles chosen by the code (one pass): slave `{}` (set `{}`), master `{}` (set \
         `{}`): {why}{hold_said}; `roles = \"as_written\"` keeps the scene's",
        s.name, s.set, m.name, m.set
    );
    if !swap && !hold {
        return Ok((Cow::Borrowed(spec), Some(why)));
    }
    let mut chosen = spec.clone();
    if swap && let Some(master) = chosen.master.as_mut() {
        std::mem::swap(&mut chosen.slave, master);
    }
    if hold {
        chosen.hold_master_nodes = Some(true);
    }
    Ok((Cow::Owned(chosen), Some(why)))
}

/// Whether the code chooses pair `spec`'s roles: `roles = "automatic"`, or `roles` left out
/// on the implicit and static paths (central difference balances such a pair instead), for
/// a pair between two bodies' edge sets that is not two-pass.
fn chosen_by_the_code(cx: &Context, bodies: &[Body], spec: &ContactSpec, scene: &Scene) -> bool {
    let two_bodies = edge_sets_on_both(cx, bodies, spec).is_some_and(|(s, m)| s != m);
    let explicit = scene.analysis.integrator == Some(IntegratorKind::CentralDifference);
    let asked = match spec.roles {
        Some(Roles::Automatic) => true,
        None => !explicit,
        Some(_) => false,
    };
    asked && two_bodies && !spec.two_pass
}

/// Whether pair `spec`, its roles chosen by the code, may hold its master nodes (step 0): a
/// mortar pair (the default between two bodies in dynamics, unless the scene asks for node
/// to segment or Greco's return) of an implicit dynamic run whose scene leaves
/// `hold_master_nodes` out. Statics holds the weighted gaps alone, and central difference
/// balances such a pair instead.
fn holds_master_nodes(spec: &ContactSpec, scene: &Scene) -> bool {
    let implicit_dynamics = scene.analysis.kind == AnalysisKind::Dynamic
        && scene.analysis.integrator != Some(IntegratorKind::CentralDifference);
    let mortar = spec
        .discretization
        .is_none_or(|d| d == ContactDiscretization::Mortar)
        && spec.return_coefficient.is_none();
    implicit_dynamics && mortar && spec.hold_master_nodes.is_none()
}

/// A contact surface as the rule reads it: its body's name and index, its edge set, its
/// total length and its mean edge length in the initial configuration, and whether it is
/// closed (every node of the set on two of its edges: no end).
struct Surface<'s> {
    name: &'s str,
    body: usize,
    set: &'s str,
    length: f64,
    mean_edge: f64,
    closed: bool,
}

impl<'s> Surface<'s> {
    fn of(
        cx: &Context,
        bodies: &'s [Body],
        spec: &'s super::spec::SurfaceSpec,
        key: &str,
    ) -> Result<Surface<'s>, InputError> {
        // the set checked (and a missing one named) as everywhere else
        let (body, _) = edge_set(cx, bodies, spec.body.as_deref(), &spec.set, key)?;
        let b = &bodies[body];
        let (length, count) = edge_lengths(b, &spec.set)
            .into_iter()
            .flatten()
            .fold((0.0, 0usize), |(sum, n), l| (sum + l, n + 1));
        Ok(Surface {
            name: &b.name,
            body,
            set: &spec.set,
            length,
            mean_edge: length / count.max(1) as f64,
            closed: closed(b.mesh.edge_sets.get(&spec.set).map_or(&[], Vec::as_slice)),
        })
    }
}

/// Whether the edges `edges` close on themselves: each of their nodes on exactly two of them.
fn closed(edges: &[[usize; 2]]) -> bool {
    let mut nodes: Vec<usize> = edges.iter().flatten().copied().collect();
    nodes.sort_unstable();
    !nodes.is_empty() && nodes.chunk_by(|a, b| a == b).all(|run| run.len() == 2)
}

/// One step of the rule: the measure it reads, the fraction below which two of them differ,
/// what it says of the two values (smaller, larger), and whether it holds the master's nodes.
struct Step {
    measure: fn(&Surface) -> f64,
    differs: f64,
    why: fn(String, String) -> String,
    holds: bool,
}

/// The rule's steps in order (module docs): step 0 first, read only where the pair may hold.
const STEPS: [Step; 3] = [
    Step {
        measure: |s| s.mean_edge,
        differs: UNLIKE,
        why: |small, large| {
            format!(
                "the meshes are unlike; the finer is the slave (edges of {small} against {large})"
            )
        },
        holds: true,
    },
    Step {
        measure: |s| s.length,
        differs: DIFFERS,
        why: |small, large| {
            format!("the shorter surface is the slave ({small} long against {large})")
        },
        holds: false,
    },
    Step {
        measure: |s| s.mean_edge,
        differs: DIFFERS,
        why: |small, large| {
            format!(
                "the surfaces are as long; the finer is the slave (edges of {small} against {large})"
            )
        },
        holds: false,
    },
];

/// Whether the rule swaps the scene's `slave` and `master`, why, and whether the master's
/// nodes are held: step 0 where `may_hold` (the pair may hold them) and the meshes are unlike,
/// else the first measure (length, then mean edge) on which the two differ makes the smaller
/// one's surface the slave.
fn rule(slave: &Surface, master: &Surface, may_hold: bool) -> (bool, String, bool) {
    for step in STEPS.iter().skip(usize::from(!may_hold)) {
        let (a, b) = ((step.measure)(slave), (step.measure)(master));
        if a < step.differs * b || b < step.differs * a {
            let swap = b < a;
            let (small, large) = if swap { (b, a) } else { (a, b) };
            return (
                swap,
                (step.why)(readable(small), readable(large)),
                step.holds,
            );
        }
    }
    (
        master.body > slave.body,
        "the surfaces are alike; the body listed later in the scene is the slave".into(),
        false,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn surface(body: usize, length: f64, edges: usize) -> Surface<'static> {
        Surface {
            name: "b",
            body,
            set: "s",
            length,
            mean_edge: length / edges as f64,
            closed: true,
        }
    }

    /// Goal: the rule reads the two surfaces alike: whichever the scene calls the slave, the
    /// same surface ends up the slave. Reference: the rule's three steps (module docs) on
    /// surfaces that differ in length, in fineness alone, and in nothing but their order.
    #[test]
    fn the_rule_does_not_depend_on_the_names() {
        let cases = [
            // the block's bottom (10 mm, 20 edges) and the plate's top (40 mm, 80 edges)
            (surface(0, 10e-3, 20), surface(1, 40e-3, 80), 0),
            // the same with the plate 3x finer: still the shorter surface
            (surface(0, 10e-3, 20), surface(1, 40e-3, 240), 0),
            // as long, the second finer
            (surface(0, 10e-3, 20), surface(1, 10e-3, 60), 1),
            // alike: the later body
            (surface(0, 10e-3, 20), surface(1, 10e-3, 20), 1),
        ];
        for (a, b, slave) in cases {
            let (swap, _, hold) = rule(&a, &b, false);
            let chosen = if swap { b.body } else { a.body };
            assert_eq!(chosen, slave, "as written");
            assert!(!hold, "statics holds no master node");
            let (swap, _, _) = rule(&b, &a, false);
            let chosen = if swap { a.body } else { b.body };
            assert_eq!(chosen, slave, "swapped");
        }
    }

    /// Goal: where the pair can hold its master's nodes (implicit dynamics, mortar), unlike
    /// meshes make the finer surface the slave with the hold, whichever name it has, and
    /// meshes within `UNLIKE` of each other keep the length rule without it. Reference: step 0
    /// of the module docs on the block's 10 mm bottom (20 edges) against the plate's 40 mm top
    /// three times finer (240 edges), and the plate's like mesh (80 edges).
    #[test]
    fn unlike_meshes_make_the_finer_surface_the_slave_where_its_master_is_held() {
        let cases = [
            (surface(0, 10e-3, 20), surface(1, 40e-3, 240), 1, true),
            (surface(0, 10e-3, 60), surface(1, 40e-3, 80), 0, true),
            (surface(0, 10e-3, 20), surface(1, 40e-3, 80), 0, false),
            // 10 % apart: alike, the shorter
            (surface(0, 10e-3, 22), surface(1, 40e-3, 80), 0, false),
        ];
        for (a, b, slave, held) in cases {
            for (x, y) in [(&a, &b), (&b, &a)] {
                let (swap, _, hold) = rule(x, y, true);
                let chosen = if swap { y.body } else { x.body };
                assert_eq!(
                    (chosen, hold),
                    (slave, held),
                    "{} edges slave",
                    x.length / x.mean_edge
                );
            }
        }
    }

    /// Goal: a body's whole boundary reads as closed and a facing set as open, so that only
    /// pairs of whole boundaries take the hold. Reference: a unit square's four edges (each
    /// corner on two) and its bottom edge alone (two ends on one each).
    #[test]
    fn a_whole_boundary_is_closed_and_a_face_is_not() {
        assert!(closed(&[[0, 1], [1, 2], [2, 3], [3, 0]]));
        assert!(!closed(&[[0, 1]]));
        assert!(!closed(&[[0, 1], [1, 2]]));
        assert!(!closed(&[]));
    }
}
