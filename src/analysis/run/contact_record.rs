//! What the run keeps of its contact row by row beyond the contact status: the pairs' forces
//! averaged over a window of time (history.csv `contact_force_avg[PAIR]`, summary.json
//! `contact.peak_force`), the most slaves each pair held closed at once, and where the
//! deepest penetration of a body into an obstacle or another body was, and the first slave
//! that went past the open end of its obstacle.
//!
//! Legend
//! ```text
//! F_k      a pair's force of the row k (the multipliers' total), held over the step that
//!          ended at t_k: (t_k - h_k, t_k], zero before t = 0; for central difference the
//!          step's impulse over its span, so that sum F_k h_k is the impulse
//! T        the window: output.contact_force_window, default 10 first steps of central
//!          difference (none for the other integrators)
//! F_avg    (1 / T) int_{t_k - T}^{t_k} F dt: the impulse of the last T over T (trailing,
//!          so it lags the force by about T / 2)
//! ```

use crate::contact::penetration::{self, DeepestNode, Intruded, PastEnd, PastEndNode};
use crate::contact::{ContactState, ContactSummary, Interfaces, Master};
use crate::scene::Model;
use std::borrow::Cow;
use std::collections::VecDeque;

/// The default window of central difference, in first steps: it spans the step-to-step
/// ripple of the explicit multipliers (a first step's spike of four times the mean, single
/// steps off by 0.4 to 1.7 times the force, on a rod striking a plate) and stays far below a
/// contact's duration (hundreds of steps).
pub const DEFAULT_WINDOW_STEPS: f64 = 10.0;

/// Whether a run of `model` averages its contact forces (its history has the
/// `contact_force_avg` columns).
pub fn averages(model: &Model) -> bool {
    !model.contacts.is_empty()
        && match model.output.contact_force_window {
            Some(window) => window > 0.0,
            None => model.is_explicit(),
        }
}

/// The window of a run of `model` whose first step is `first_step` (None: no averaging).
pub fn window(model: &Model, first_step: f64) -> Option<f64> {
    if !averages(model) {
        return None;
    }
    Some(
        model
            .output
            .contact_force_window
            .unwrap_or(DEFAULT_WINDOW_STEPS * first_step),
    )
}

/// The record, as a checkpoint carries it.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct ContactCarry {
    pub window: Option<f64>,
    /// The rows within the window: (start, end, the pairs' forces).
    pub recent: VecDeque<(f64, f64, Vec<f64>)>,
    /// The largest total of the averaged forces.
    pub peak_average: f64,
    /// Per pair, the most slaves closed at once.
    pub closed_at_widest: Vec<usize>,
    /// The deepest penetration so far (history.csv `penetration`), and where it was when a
    /// body's node went into an obstacle or another body.
    pub deepest_depth: f64,
    pub deepest: Option<DeepestNode>,
    /// The first slave found past the open end of its obstacle (after a row's step).
    pub past_end: Option<PastEndNode>,
    /// The largest total of the pairs' raw forces of a row, and the row's time.
    pub peak_raw: Option<(f64, f64)>,
}

/// See the module.
pub struct ContactRecord {
    interfaces: Interfaces,
    /// Whether a pair meets an open obstacle (whose ends the record watches).
    open_ends: bool,
    pub carry: ContactCarry,
}

impl ContactRecord {
    pub fn new(model: &Model, carry: ContactCarry) -> ContactRecord {
        let interfaces = model.interfaces();
        let open_ends = (interfaces.pairs.iter())
            .any(|p| matches!(&p.master, Master::Obstacle(o) if !o.closed));
        ContactRecord {
            interfaces,
            open_ends,
            carry,
        }
    }

    /// Takes the row that ends at `time` after a step of length `step` with the pairs'
    /// forces `forces` and the contact status `contact` (None before the first step), the
    /// nodes at `positions()`; returns the averaged forces of the row (empty without a
    /// window).
    pub fn row<'s>(
        &mut self,
        model: &Model,
        (time, step): (f64, f64),
        (forces, contact): (&[f64], Option<&ContactState>),
        positions: impl FnOnce() -> Cow<'s, [[f64; 2]]>,
    ) -> Vec<f64> {
        let carry = &mut self.carry;
        let total: f64 = forces.iter().sum();
        if total > carry.peak_raw.map_or(0.0, |(f, _)| f) {
            carry.peak_raw = Some((total, time));
        }
        if let Some(contact) = contact {
            carry
                .closed_at_widest
                .resize(contact.active.len().max(carry.closed_at_widest.len()), 0);
            for (widest, active) in carry.closed_at_widest.iter_mut().zip(&contact.active) {
                *widest = (*widest).max(active.iter().filter(|a| **a).count());
            }
            let deeper = contact.penetration > carry.deepest_depth;
            let watch = self.open_ends && carry.past_end.is_none();
            if deeper || watch {
                contact.place(&mut self.interfaces.pairs, time);
                let x = positions();
                if deeper {
                    carry.deepest_depth = contact.penetration;
                    if let Some(d) = penetration::deepest(&self.interfaces, &|n| x[n]) {
                        carry.deepest = Some(named(model, &d, time));
                    }
                }
                if watch && let Some(p) = penetration::past_an_end(&self.interfaces, &|n| x[n]) {
                    carry.past_end = Some(past_end_named(model, &p, x[p.node], time));
                }
            }
        }
        let Some(window) = carry.window else {
            return Vec::new();
        };
        if step > 0.0 {
            carry.recent.push_back((time - step, time, forces.to_vec()));
        }
        let from = time - window;
        while carry.recent.front().is_some_and(|(_, end, _)| *end <= from) {
            carry.recent.pop_front();
        }
        let mut average = vec![0.0; forces.len()];
        for (start, end, f) in &carry.recent {
            let span = end.min(time) - start.max(from);
            for (a, f) in average.iter_mut().zip(f) {
                *a += f * span / window;
            }
        }
        carry.peak_average = carry.peak_average.max(average.iter().sum());
        average
    }

    /// The contact block of summary.json with what this record adds: `peak_force` from the
    /// averaged force when there is a window (the raw peak kept as `peak_force_raw`), the
    /// slaves closed at the widest, the pairs closed at the end (from `contact`), the
    /// deepest node.
    pub fn fill(&self, model: &Model, summary: &mut ContactSummary, contact: &ContactState) {
        let carry = &self.carry;
        summary.peak_force_raw = summary.peak_force;
        summary.force_window = carry.window;
        if carry.window.is_some() {
            summary.peak_force = carry.peak_average;
        }
        summary.closed_at_widest = carry.closed_at_widest.clone();
        // a balanced pair's reverse pass under the pair's name, once
        let mut closed_at_end: Vec<String> = Vec::new();
        for (pair, active) in model.contacts.iter().zip(&contact.active) {
            let name = match pair.balances {
                Some(first) => &model.contacts[first].name,
                None => &pair.name,
            };
            if active.iter().any(|a| *a) && !closed_at_end.contains(name) {
                closed_at_end.push(name.clone());
            }
        }
        summary.closed_at_end = closed_at_end;
        summary.deepest = carry.deepest.clone();
        summary.past_end = carry.past_end.clone();
        summary.peak_force_time = carry.peak_raw.map(|(_, t)| t);
    }
}

/// A slave past an obstacle's end in the words of summary.json: the pair, the obstacle and
/// the body by name, the node by its number in the body.
fn past_end_named(model: &Model, p: &PastEnd, position: [f64; 2], time: f64) -> PastEndNode {
    let pair = &model.contacts[p.pair];
    let body = &model.bodies[pair.slave_body];
    let obstacle = match &pair.master {
        Master::Obstacle(o) => o.name.clone(),
        _ => String::new(),
    };
    PastEndNode {
        time,
        pair: pair.name.clone(),
        obstacle,
        body: body.name.clone(),
        node: p.node - body.node_offset,
        position,
        end: p.end,
    }
}

/// A deepest node in the words of summary.json: the body by name, its node by its number
/// in the body, what it went into by name, whether a pair names it as a slave or holds it as
/// a master node.
fn named(model: &Model, d: &penetration::Deepest, time: f64) -> DeepestNode {
    let body = &model.bodies[d.body];
    DeepestNode {
        depth: d.depth,
        time,
        body: body.name.clone(),
        node: d.node - body.node_offset,
        into: match &d.into {
            Intruded::Obstacle(name) => format!("obstacle `{name}`"),
            Intruded::Body(b) => format!("body `{}`", model.bodies[*b].name),
        },
        slave: (model.contacts.iter()).any(|p| !p.is_hold() && p.slaves.contains(&d.node)),
        held: (model.contacts.iter()).any(|p| p.is_hold() && p.slaves.contains(&d.node)),
    }
}
