//! Rigid projectiles in the central-difference driver (docs/theory.md 8.3g): each is a node of
//! its own past the model's nodes, its carrier, with the projectile's mass on both DOFs and
//! its translation u_R as position. The driver's vectors hold the carriers' DOFs after the
//! model's, so the predictor moves a projectile with its velocity, the step's end gives it
//! v_{n+1} (no force but the contact acts on it), and the kinetic energy counts it. The
//! contact rows against a projectile hold its carrier's DOFs with weight 1
//! (`Projectile::carrier`), so the forward-increment correction solves its rows together
//! and its impulse is the opposite of the bodies': the total momentum is kept.
//!
//! The element kernels, the loads and what the record reads (`Report::motion`) see the
//! model's DOFs only; the record places a projectile at its `Flight`, which the driver
//! keeps in the contact status after every step.

use crate::contact::{Flight, Interfaces, Master};
use crate::scene::Model;
use crate::scene::model::BodyKind;
use std::borrow::Cow;

/// The model's projectiles, in the order of their index (`Projectile::index`).
pub(super) struct Carriers {
    /// The carrier node of the first projectile: the model's node count.
    first: usize,
    /// Per projectile: its mass and its velocity at t = 0.
    list: Vec<(f64, [f64; 2])>,
    /// An axisymmetric scene: a carrier's radial DOF is held (a ring moves along the axis).
    axisymmetric: bool,
}

impl Carriers {
    pub(super) fn of(model: &Model) -> Carriers {
        let mut list: Vec<(usize, f64, [f64; 2])> = (model.obstacles.iter())
            .filter_map(|o| o.projectile.as_ref())
            .map(|p| (p.index, p.mass, p.velocity))
            .collect();
        list.sort_by_key(|p| p.0);
        let axisymmetric = model.bodies.iter().any(|b| {
            matches!(
                b.kind,
                BodyKind::Continuum {
                    formulation: crate::element::Formulation::Axisymmetric,
                    ..
                }
            )
        });
        Carriers {
            first: model.dofs() / 2,
            list: list.into_iter().map(|(_, m, v)| (m, v)).collect(),
            axisymmetric,
        }
    }

    /// The carrier nodes, ascending (all past the model's nodes).
    pub(super) fn nodes(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.list.len()).map(|r| (self.first + r) as u32)
    }

    /// The carriers' DOFs appended to the driver's free flags and lumped masses.
    pub(super) fn extend_masses(&self, free: &mut Vec<bool>, mass: &mut Vec<f64>) {
        for (m, _) in &self.list {
            free.extend([!self.axisymmetric, true]);
            mass.extend([*m, *m]);
        }
    }

    /// The carriers' velocities at t = 0 appended to the model's.
    pub(super) fn extend_velocity(&self, v: &mut Vec<f64>) {
        for (_, velocity) in &self.list {
            v.extend(velocity);
        }
    }

    /// Points each projectile of `interfaces` at its carrier node.
    pub(super) fn attach(&self, interfaces: &mut Interfaces) {
        for pair in &mut interfaces.pairs {
            if let Master::Obstacle(o) = &mut pair.master
                && let Some(p) = &mut o.projectile
            {
                p.carrier = Some(self.first + p.index);
            }
        }
    }

    /// The flights at t = 0: at rest where the points are, at the initial velocity.
    pub(super) fn initial_flights(&self) -> Vec<Flight> {
        (self.list.iter())
            .map(|(_, velocity)| Flight {
                displacement: [0.0; 2],
                velocity: *velocity,
            })
            .collect()
    }

    /// The carriers' positions (their translations) appended to the model's `positions`
    /// (borrowed still where there is no projectile).
    pub(super) fn extend_positions(&self, positions: &mut Cow<[[f64; 2]]>, flights: &[Flight]) {
        if !self.list.is_empty() {
            positions
                .to_mut()
                .extend(flights.iter().map(|f| f.displacement));
        }
    }

    /// The flights after a step that moved the carriers by `du`, ending at velocities `v`
    /// (the driver's vectors).
    pub(super) fn track(&self, flights: &mut [Flight], du: &[f64], v: &[f64]) {
        for (r, flight) in flights.iter_mut().enumerate() {
            let d = 2 * (self.first + r);
            flight.displacement[0] += du[d];
            flight.displacement[1] += du[d + 1];
            flight.velocity = [v[d], v[d + 1]];
        }
    }

    pub(super) fn is_empty(&self) -> bool {
        self.list.is_empty()
    }
}
