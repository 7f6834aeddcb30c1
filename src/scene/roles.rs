//! The roles of a one-pass pair between two bodies when the scene names none (docs/theory.md
//! 8.3d, "Roles chosen by the code"): on the implicit and static paths, where a pair is
//! one pass, the code picks the slave by a rule that reads the two surfaces alike, so the
//! run does not depend on which of them the scene calls the slave (Abaqus/Standard's general
//! contact likewise assigns pure master-slave roles itself).
//!
//! The rule, in order, each step deciding when its measures differ by more than 1 %:
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
use super::spec::{ContactSpec, IntegratorKind, Roles, Scene};
use crate::output::readable;
use std::borrow::Cow;

/// Two measures differ when one is below this fraction of the other.
const DIFFERS: f64 = 0.99;

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
    let (swap, why) = rule(&slave, &master);
    let (s, m) = if swap {
        (&master, &slave)
    } else {
        (&slave, &master)
    };
    let why = format!(
        "the roles chosen by the code (one pass): slave `{}` (set `{}`), master `{}` (set \
         `{}`): {why}; `roles = \"as_written\"` keeps the scene's",
        s.name, s.set, m.name, m.set
    );
    if !swap {
        return Ok((Cow::Borrowed(spec), Some(why)));
    }
    let mut swapped = spec.clone();
    if let Some(master) = swapped.master.as_mut() {
        std::mem::swap(&mut swapped.slave, master);
    }
    Ok((Cow::Owned(swapped), Some(why)))
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

/// A contact surface as the rule reads it: its body's name and index, its edge set, its
/// total length and its mean edge length in the initial configuration.
struct Surface<'s> {
    name: &'s str,
    body: usize,
    set: &'s str,
    length: f64,
    mean_edge: f64,
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
        })
    }
}

/// Whether the rule swaps the scene's `slave` and `master`, and why: the first measure
/// (length, then mean edge) on which the two differ makes the smaller one's surface the slave.
fn rule(slave: &Surface, master: &Surface) -> (bool, String) {
    type Why = fn(String, String) -> String;
    let steps: [(fn(&Surface) -> f64, Why); 2] = [
        (
            |s| s.length,
            |small, large| {
                format!("the shorter surface is the slave ({small} long against {large})")
            },
        ),
        (
            |s| s.mean_edge,
            |small, large| {
                format!(
                    "the surfaces are as long; the finer is the slave (edges of {small} against \
                 {large})"
                )
            },
        ),
    ];
    for (measure, why) in steps {
        let (a, b) = (measure(slave), measure(master));
        if a < DIFFERS * b || b < DIFFERS * a {
            let swap = b < a;
            let (small, large) = if swap { (b, a) } else { (a, b) };
            return (swap, why(readable(small), readable(large)));
        }
    }
    (
        master.body > slave.body,
        "the surfaces are alike; the body listed later in the scene is the slave".into(),
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
            let (swap, _) = rule(&a, &b);
            let chosen = if swap { b.body } else { a.body };
            assert_eq!(chosen, slave, "as written");
            let (swap, _) = rule(&b, &a);
            let chosen = if swap { a.body } else { b.body };
            assert_eq!(chosen, slave, "swapped");
        }
    }
}
