//! What a committed implicit step books (theory 7): the external work, the contact's and
//! the friction's, in total and pair by pair, with what a moving obstacle supplies (theory
//! 8.3f): the work of its contact forces over its travel and of its impulses at its
//! velocity, external work that the interface does not take.

use super::Dynamics;
use crate::contact::energy::{ImplicitStepWork, PairForces};
use crate::contact::{ContactPair, ObstacleMotion};

/// What `Dynamics::commit` hands the booking of its step.
pub(super) struct Booked {
    /// The step's displacement increment.
    pub increment: Vec<f64>,
    /// Per DOF, a moving obstacle's translation over the step at its slaves (None: none
    /// moves).
    pub travel: Option<Vec<f64>>,
    /// The contact force at the step's end as the integrator applied it (before the
    /// conditions).
    pub applied: Vec<f64>,
    /// The internal force at the step's end.
    pub internal: Vec<f64>,
    /// The velocity before the step's impact and release conditions (None: none was met).
    pub velocity_before: Option<Vec<f64>>,
    /// The friction forces at the step's start, in total and the pairs' force terms.
    pub friction_start: Option<Vec<f64>>,
    pub pair_start: (PairForces, PairForces),
}

impl Dynamics<'_> {
    /// Books the energies of the committed step `booked`, the nodes at `positions`, and
    /// keeps the forces the next step starts from.
    pub(super) fn book_step(&mut self, booked: Booked, positions: &[[f64; 2]]) {
        let Booked {
            increment: d,
            travel,
            applied,
            internal,
            velocity_before,
            friction_start,
            pair_start,
        } = booked;
        // the kinetic energy the conditions removed, DOF by DOF, with what a moving
        // obstacle's impulses supplied; and the work of its contact forces over its travel
        let conditions = velocity_before.is_some();
        let (removed, impulses) = match velocity_before {
            Some(before) => {
                let (taken, supplied) = self.taken_by_conditions(&before);
                (Some(taken), supplied)
            }
            None => (None, 0.0),
        };
        let supplied = travel.as_ref().map(|travel| {
            (travel.iter().zip(applied.iter().zip(&self.last_contact)))
                .map(|(x, (a, b))| 0.5 * x * (a + b))
                .collect::<Vec<f64>>()
        });
        // the next step starts from the motion the conditions left
        let next_start = match conditions {
            true => self.motion_contact_force(&internal),
            false => applied.clone(),
        };
        let total = self.total_force(&internal);
        // the friction's share of the contact forces' work: minus the work of the friction
        // forces alone, theirs at the step's start and end (theory 7), on the slip along a
        // moving obstacle (the slave's less the obstacle's travel)
        let slip: Vec<f64> = match &travel {
            Some(travel) => d.iter().zip(travel).map(|(u, x)| u - x).collect(),
            None => d.clone(),
        };
        let friction = friction_start.map_or(0.0, |start| {
            let end = (self.contact)
                .friction_forces(&self.interfaces.pairs, positions)
                .expect("a friction pair");
            -super::super::trapezoid_work(&slip, &end, &start)
        });
        let obstacle_work: f64 = supplied.iter().flatten().sum();
        let energies = &mut self.energies;
        energies.external_work +=
            super::super::trapezoid_work(&d, &total, &self.last_total) + obstacle_work + impulses;
        energies.kinetic = self.mass.kinetic_energy(self.model, &self.kin.velocity);
        // energy taken up by the interface: minus the work of the contact forces on the
        // bodies, plus what the impact/release conditions removed, plus what a moving
        // obstacle supplied; the friction's share apart
        energies.contact_work += -super::super::trapezoid_work(&d, &applied, &self.last_contact)
            + removed.as_ref().map_or(0.0, |r| r.iter().sum())
            + obstacle_work
            - friction;
        energies.friction_work += friction;
        energies.internal = self.state.internal_work - self.state.plastic_work;
        energies.plastic_work = self.state.plastic_work;
        let conditions = match (removed, supplied) {
            (Some(r), Some(s)) => Some(r.iter().zip(&s).map(|(a, b)| a + b).collect()),
            (r, s) => r.or(s),
        };
        let work = ImplicitStepWork {
            increment: &d,
            slip: &slip,
            applied: (&applied, &self.last_contact),
            conditions,
            start: pair_start,
        };
        (self.contact).book_implicit_step(&self.interfaces.pairs, positions, work);
        self.last_total = total;
        self.last_internal = internal;
        self.last_contact = next_start;
    }

    /// Per DOF, what the impact and release conditions that moved the velocity from
    /// `before` to the present one took from the bodies: the kinetic energy they removed,
    /// plus, at a moving obstacle's slaves, the work of its impulse M dv at its velocity w,
    /// which it supplies (the energy the conditions take in the obstacle's frame; theory
    /// 8.3f); and the impulses' work alone, which is external work.
    pub(super) fn taken_by_conditions(&self, before: &[f64]) -> (Vec<f64>, f64) {
        let after = &self.kin.velocity;
        let mut taken = (self.mass).kinetic_removed_by_dof(self.model, before, after);
        let mut supplied = 0.0;
        let pairs = &self.interfaces.pairs;
        let velocity = |m: &ObstacleMotion| m.velocity(m.placed);
        if let Some(w) = crate::contact::obstacle_by_dof(pairs, before.len(), velocity) {
            let lumped = &self.mass.lumped;
            for (d, t) in taken.iter_mut().enumerate() {
                let work = lumped[d] * (after[d] - before[d]) * w[d];
                *t += work;
                supplied += work;
            }
        }
        (taken, supplied)
    }
}

/// A copy of `pairs` with their moving obstacles placed at time `t`.
pub(super) fn placed_at(pairs: &[ContactPair], t: f64) -> Vec<ContactPair> {
    let mut moved = pairs.to_vec();
    crate::contact::place_obstacles(&mut moved, t);
    moved
}
