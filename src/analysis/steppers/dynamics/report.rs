//! What an implicit dynamic run tells the scaffold (`Report`: its state, motion, energies,
//! contact and solver for the records) and what a checkpoint carries of it (`Resume`).

use super::Dynamics;
use crate::analysis::steppers::carry::{Carry, DynamicCarry};
use crate::analysis::steppers::energies::{Energies, Motion};
use crate::analysis::steppers::{About, Report, Resume, RowFeatures};
use crate::assembly::State;
use crate::contact::ContactState;
use crate::scene::Model;
use crate::solver::Solver;

impl Report for Dynamics<'_> {
    fn about(&self) -> About {
        About {
            integrator: self.method.name(),
            dt: self.nominal,
            end_time: self.spec.end_time,
            free_dofs: self.system.free,
            checks_buckling: true,
        }
    }
    fn state(&self) -> &State {
        &self.state
    }
    fn motion(&self) -> Motion<'_> {
        Motion {
            velocity: &self.kin.velocity,
            acceleration: &self.kin.acceleration,
            mass: &self.mass.lumped,
            internal_force: &self.last_internal,
        }
    }
    fn energies(&self) -> &Energies {
        &self.energies
    }
    fn body_kinetic(&self, model: &Model) -> Vec<f64> {
        self.mass.body_kinetic_energies(model, &self.kin.velocity)
    }
    fn initial_kinetic(&self) -> f64 {
        self.initial_kinetic
    }
    fn contact(&self) -> &ContactState {
        &self.contact
    }
    fn solver(&self) -> Option<&Solver> {
        Some(&self.solver)
    }
    fn last_step(&self) -> f64 {
        self.last_step
    }
    fn row_features(&self) -> RowFeatures {
        RowFeatures {
            error_watch: self.error.constant.map(|_| self.watch),
            ..RowFeatures::default()
        }
    }
}

impl Resume for Dynamics<'_> {
    fn kind(&self) -> &'static str {
        "implicit dynamic"
    }

    fn restore(&mut self, carry: Carry) -> bool {
        let Carry::Dynamic(carry) = carry else {
            return false;
        };
        self.state = carry.state;
        self.kin = carry.kinematics;
        self.method.restore(carry.method);
        self.energies = carry.energies;
        self.initial_kinetic = carry.initial_kinetic;
        self.last_total = carry.last_total;
        self.last_internal = carry.last_internal;
        self.last_contact = carry.last_contact;
        self.control = carry.control;
        self.increments = carry.increments;
        self.contact = carry.contact;
        self.mean_velocity = carry.mean_velocity;
        self.previous_acceleration = carry.previous_acceleration;
        self.last_step = carry.last_step;
        self.watch = carry.watch;
        true
    }

    fn carry(&self) -> Result<Carry, &'static str> {
        Ok(Carry::Dynamic(DynamicCarry {
            state: self.state.clone(),
            kinematics: self.kin.clone(),
            method: self.method.history(),
            energies: self.energies,
            initial_kinetic: self.initial_kinetic,
            last_total: self.last_total.clone(),
            last_internal: self.last_internal.clone(),
            last_contact: self.last_contact.clone(),
            control: self.control.clone(),
            increments: self.increments,
            contact: self.contact.clone(),
            mean_velocity: self.mean_velocity.clone(),
            previous_acceleration: self.previous_acceleration.clone(),
            last_step: self.last_step,
            watch: self.watch,
        }))
    }

    fn after_checkpoint(&mut self) {
        self.factored_for = None;
    }
    fn solver_mut(&mut self) -> Option<&mut Solver> {
        Some(&mut self.solver)
    }
}
