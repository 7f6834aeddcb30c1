//! Rigid projectiles in the central-difference driver (docs/theory.md 8.3g): each has a node
//! of its own past the model's nodes, its carrier, with the projectile's mass on both DOFs
//! and its translation u_R as position; a projectile with a moment of inertia has a second,
//! its spin node, whose first DOF is the rotation theta with the moment of inertia as its
//! mass (the second DOF held). The driver's vectors hold these DOFs after the model's, so the
//! predictor moves a projectile with its velocities, the step's end gives it v_{n+1} (no
//! force but the contact acts on it), and the kinetic energy counts it. The contact rows
//! against a projectile hold its DOFs (`contact::projectile`), so the forward-increment
//! correction solves its rows together and its impulse is the opposite of the bodies': the
//! total momentum is kept.
//!
//! The element kernels, the loads and what the record reads (`Report::motion`) see the
//! model's DOFs only; the record places a projectile at its `Flight`, which the driver
//! keeps in the contact status after every step.

use crate::contact::{Flight, Interfaces, Master, Projectile};
use crate::scene::Model;
use std::borrow::Cow;

/// The model's projectiles, in the order of their index (`Projectile::index`).
pub(super) struct Carriers {
    /// Per projectile: its carrier node (the spin node, where it rotates, follows it), its
    /// mass and velocity at t = 0, and its moment of inertia and angular velocity.
    list: Vec<Carried>,
    /// An axisymmetric scene: a carrier's radial DOF is held (a ring moves along the axis).
    axisymmetric: bool,
}

struct Carried {
    node: usize,
    mass: f64,
    velocity: [f64; 2],
    spin: Option<(f64, f64)>,
}

impl Carriers {
    pub(super) fn of(model: &Model) -> Carriers {
        let mut projectiles: Vec<&Projectile> = (model.obstacles.iter())
            .filter_map(|o| o.projectile.as_ref())
            .collect();
        projectiles.sort_by_key(|p| p.index);
        let mut node = model.dofs() / 2;
        let mut list = Vec::new();
        for p in projectiles {
            let spin = (p.spin.as_ref()).map(|s| (s.inertia, s.angular_velocity));
            list.push(Carried {
                node,
                mass: p.mass,
                velocity: p.velocity,
                spin,
            });
            node += if spin.is_some() { 2 } else { 1 };
        }
        let axisymmetric = model.bodies.iter().any(|b| b.is_axisymmetric());
        Carriers { list, axisymmetric }
    }

    /// The carrier and spin nodes, ascending (all past the model's nodes).
    pub(super) fn nodes(&self) -> impl Iterator<Item = u32> + '_ {
        (self.list.iter()).flat_map(|c| {
            let spin = c.spin.map(|_| c.node as u32 + 1);
            std::iter::once(c.node as u32).chain(spin)
        })
    }

    /// The carriers' DOFs appended to the driver's free flags and lumped masses: the
    /// translation's two with the mass; a spin node's rotation with the moment of inertia,
    /// its second DOF held.
    pub(super) fn extend_masses(&self, free: &mut Vec<bool>, mass: &mut Vec<f64>) {
        for c in &self.list {
            free.extend([!self.axisymmetric, true]);
            mass.extend([c.mass, c.mass]);
            if let Some((inertia, _)) = c.spin {
                free.extend([true, false]);
                mass.extend([inertia, inertia]);
            }
        }
    }

    /// The carriers' velocities at t = 0 appended to the model's.
    pub(super) fn extend_velocity(&self, v: &mut Vec<f64>) {
        for c in &self.list {
            v.extend(c.velocity);
            if let Some((_, omega)) = c.spin {
                v.extend([omega, 0.0]);
            }
        }
    }

    /// Points each projectile of `interfaces` at its carrier (and spin) node.
    pub(super) fn attach(&self, interfaces: &mut Interfaces) {
        for pair in &mut interfaces.pairs {
            if let Master::Obstacle(o) = &mut pair.master
                && let Some(p) = &mut o.projectile
            {
                let node = self.list[p.index].node;
                p.carrier = Some(node);
                if let Some(spin) = &mut p.spin {
                    spin.node = Some(node + 1);
                }
            }
        }
    }

    /// The flights at t = 0: where the points are, at the initial velocities.
    pub(super) fn initial_flights(&self) -> Vec<Flight> {
        (self.list.iter())
            .map(|c| Flight {
                displacement: [0.0; 2],
                velocity: c.velocity,
                rotation: 0.0,
                angular_velocity: c.spin.map_or(0.0, |(_, omega)| omega),
            })
            .collect()
    }

    /// The carriers' positions (translation; rotation and 0) appended to the model's
    /// `positions` (borrowed still where there is no projectile).
    pub(super) fn extend_positions(&self, positions: &mut Cow<[[f64; 2]]>, flights: &[Flight]) {
        if self.list.is_empty() {
            return;
        }
        let positions = positions.to_mut();
        for (c, f) in self.list.iter().zip(flights) {
            positions.push(f.displacement);
            if c.spin.is_some() {
                positions.push([f.rotation, 0.0]);
            }
        }
    }

    /// The flights after a step that moved the carriers by `du`, ending at velocities `v`
    /// (the driver's vectors).
    pub(super) fn track(&self, flights: &mut [Flight], du: &[f64], v: &[f64]) {
        for (c, flight) in self.list.iter().zip(flights.iter_mut()) {
            let d = 2 * c.node;
            flight.displacement[0] += du[d];
            flight.displacement[1] += du[d + 1];
            flight.velocity = [v[d], v[d + 1]];
            if c.spin.is_some() {
                flight.rotation += du[d + 2];
                flight.angular_velocity = v[d + 2];
            }
        }
    }

    pub(super) fn is_empty(&self) -> bool {
        self.list.is_empty()
    }
}
