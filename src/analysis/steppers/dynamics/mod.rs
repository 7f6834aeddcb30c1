//! Implicit direct time integration: any `Integrator` in effective-stiffness form, each step
//! solved by Newton (see `newton`), K* factored once while dt and the strategy allow.
//!
//! Legend
//! ```text
//! u, v, a      committed displacement (total), velocity, acceleration, all DOFs
//! D            the step's solved increment (at t_n + s dt; s = 1 except for Wilson)
//! f_int,n      internal force of the committed state
//! F            total external force: f_ext on free DOFs, reactions M a + C v + f_int on
//!              prescribed ones (so W_ext includes the work of supports and prescribed motion)
//! ```
//! Prescribed DOFs follow their curves; their velocity and acceleration come from the same
//! integrator formulas as the free ones. A step that fails is halved (at most `max_cuts`
//! times in a row); a slave that touches its master at the start of a step closes with the
//! impact conditions, and the step is split at the first contact event inside it.

mod energy;
mod report;

use energy::{Booked, placed_at};

use super::control::{
    ErrorControl, ErrorWatch, StepControl, WatchedPoint, on_ladder, snap, step_factor, step_length,
    weighted_jump,
};
use super::energies::Energies;
use super::newton::{Constraints, Counters, Inertia, Solution, Step, StepFailure};
use super::{StepError, Stepper, loads};
use crate::analysis::summary::RunError;
use crate::assembly::{self, Evaluation, Mass, State, StepIncrement, System, check_mass};
use crate::contact::{ContactResult, ContactState, ImpactMotion, Interfaces, LumpedMass, Pass};
use crate::integrator::{
    Advance, GeneralizedAlpha, Houbolt, Integrator, MotionState, StepForm, Wilson,
};
use crate::output::readable;
use crate::scene::DynamicAnalysis;
use crate::scene::spec::{AdaptiveStep, ContactDynamics, IntegratorKind, Strategy};
use crate::scene::{InputError, Model};
use crate::solver::{Solver, SolverError};
use std::path::Path;

/// The integrator a scene asks for (implicit ones); the Newmark family's beta and gamma are
/// the scene's (its presets for `average`, `linear` and `hu`).
pub fn integrator(spec: &DynamicAnalysis) -> Box<dyn Integrator> {
    let newmark = |label| Box::new(GeneralizedAlpha::newmark(label, spec.beta, spec.gamma));
    match spec.integrator {
        IntegratorKind::Average => newmark("average"),
        IntegratorKind::Linear => newmark("linear"),
        IntegratorKind::Hu => newmark("hu"),
        IntegratorKind::Newmark => newmark("newmark"),
        IntegratorKind::Wilson => Box::new(Wilson { theta: spec.theta }),
        IntegratorKind::Houbolt => Box::new(Houbolt::default()),
        IntegratorKind::Hht => Box::new(GeneralizedAlpha::hht(spec.alpha)),
        IntegratorKind::GeneralizedAlpha => {
            Box::new(GeneralizedAlpha::chung_hulbert(spec.rho_infinity))
        }
        IntegratorKind::CentralDifference => {
            unreachable!("the explicit stepper runs central difference")
        }
    }
}

/// Implicit time stepping: the state, the motion, the solver and what the loop carries.
pub struct Dynamics<'a> {
    model: &'a Model,
    spec: &'a DynamicAnalysis,
    /// The contact pairs and surfaces; under `persistency` and `mass_redistribution` the
    /// pairs' impact and release conditions and fraction rule are off (see `new`).
    interfaces: Interfaces,
    initial: Vec<[f64; 2]>,
    system: System,
    solver: Solver,
    mass: Mass,
    /// 1 / the lumped mass on the free DOFs, 0 on prescribed ones (the impact conditions of
    /// mortar pairs move only free DOFs).
    inverse_mass: Vec<f64>,
    method: Box<dyn Integrator>,
    state: State,
    kin: MotionState,
    energies: Energies,
    initial_kinetic: f64,
    last_total: Vec<f64>,
    last_internal: Vec<f64>,
    last_contact: Vec<f64>,
    control: StepControl,
    /// K* = ca M + cv C + w K_T: a factorization serves while these coefficients stay (the
    /// step after a checkpoint factors afresh: a resumed run has no factorization).
    factored_for: Option<[f64; 3]>,
    increments: usize,
    contact: ContactState,
    /// The length of the last step.
    last_step: f64,
    /// The acceleration at the start of the last step (a_{n-1}; None before the first
    /// step): the error estimate reads the change of a over the last two steps (theory 8.2a).
    previous_acceleration: Option<Vec<f64>>,
    /// The mean velocity of the last step (its increment over its length): the next step's
    /// predictor. None before the first step.
    mean_velocity: Option<Vec<f64>>,
    /// The fixed step, or the first of an adaptive run (`stable::implicit_first_step`).
    nominal: f64,
    /// `dt = "auto"`: the error tolerance, the shortest and longest step, and the method's
    /// local error constant (control.rs).
    error: ErrorControl,
    /// Per DOF, whether the estimate reads it: the free DOFs off the contact surfaces
    /// (theory 8.2a).
    estimated: Vec<bool>,
    watch: ErrorWatch,
    /// `dt = "auto"`: the point values the user probes that the step must resolve.
    watched: Vec<WatchedPoint>,
}

impl<'a> Dynamics<'a> {
    pub fn new(
        model: &'a Model,
        spec: &'a DynamicAnalysis,
        dir: &Path,
    ) -> Result<Dynamics<'a>, RunError> {
        let system = System::new(model, &model.constrained_dofs());
        let mut mass =
            Mass::new(model, spec.mass).map_err(|e| InputError::new(&model.file, e.to_string()))?;
        let free: Vec<bool> = system.equation.iter().map(Option::is_some).collect();
        check_mass(model, &mass, &free)?;
        let mut interfaces = model.interfaces();
        if spec.contact_dynamics != ContactDynamics::Hughes {
            // no velocity jumps; a pair releases when its multiplier turns to tension
            for pair in &mut interfaces.pairs {
                pair.options.impact_conditions = false;
                pair.options.release_conditions = false;
                pair.options.release_fraction = 0.0;
                pair.options.persistency = spec.contact_dynamics == ContactDynamics::Persistency;
            }
        }
        if spec.contact_dynamics == ContactDynamics::MassRedistribution {
            mass = mass.redistributed(model, &model.contact_surface_nodes());
        }
        let inverse_mass = mass
            .lumped
            .iter()
            .zip(&system.equation)
            .map(|(m, e)| {
                if e.is_some() && *m > 0.0 {
                    1.0 / m
                } else {
                    0.0
                }
            })
            .collect();
        let solver = Solver::new(&system.pattern).map_err(|e| RunError::setup(dir, e))?;
        let n = model.dofs();
        let nominal = super::stable::implicit_first_step(model, spec)?;
        let method = integrator(spec);
        let on_surface = model.contact_surface_nodes();
        let estimated: Vec<bool> = system
            .equation
            .iter()
            .enumerate()
            .map(|(dof, e)| e.is_some() && !on_surface[dof / 2])
            .collect();
        let error_constant = method.error_constant();
        Ok(Dynamics {
            model,
            spec,
            interfaces,
            initial: model.coordinates(),
            estimated,
            method,
            nominal,
            // with contact, dt_min defaults to the first step: shorter steps made the impact
            // conditions' forces (a momentum over the step) run away on every contact scene
            // (validation 10.3a)
            error: ErrorControl {
                adaptive: spec.adaptive().map(|a| AdaptiveStep {
                    min: a.min.or((!model.contacts.is_empty()).then_some(nominal)),
                    ..a
                }),
                constant: error_constant,
            },
            watch: ErrorWatch::default(),
            watched: match spec.adaptive() {
                Some(_) => WatchedPoint::of(model),
                None => Vec::new(),
            },
            state: State::initial(model),
            kin: MotionState {
                displacement: vec![0.0; n],
                velocity: vec![0.0; n],
                acceleration: vec![0.0; n],
            },
            energies: Energies::default(),
            initial_kinetic: 0.0,
            last_total: vec![0.0; n],
            last_internal: vec![0.0; n],
            last_contact: vec![0.0; n],
            control: StepControl::new(nominal, spec.newton.max_cuts),
            factored_for: None,
            increments: 0,
            contact: ContactState::new(&model.contacts),
            last_step: 0.0,
            previous_acceleration: None,
            mean_velocity: None,
            system,
            solver,
            mass,
            inverse_mass,
        })
    }

    /// The initial acceleration M a_0 = f_ext(0) - f_int(0) - C v_0 on the free DOFs (zero
    /// on prescribed DOFs); solved with the mass matrix only when the right side is not zero.
    fn initial_acceleration(&mut self, velocity: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        let (model, spec) = (self.model, self.spec);
        let external = loads::external_force(model, &self.state, &self.initial, 0.0);
        let evaluation = assembly::evaluate(
            model,
            &self.state,
            StepIncrement {
                d: &vec![0.0; model.dofs()],
                dt: self.nominal,
                geometry: spec.geometry,
            },
            None,
            spec.newton.tangent,
        )
        .map_err(|e| e.to_string())?;
        let damping = self.mass.product(model, velocity);
        let rhs: Vec<f64> = external
            .iter()
            .zip(evaluation.force.iter().zip(&damping))
            .map(|(f, (fi, c))| f - fi - spec.rayleigh[0] * c)
            .collect();
        let mut free = self.system.gather(&rhs);
        let mut a = vec![0.0; model.dofs()];
        if free.iter().any(|v| *v != 0.0) {
            self.system.values.iter_mut().for_each(|v| *v = 0.0);
            // massless contact nodes would leave M singular: their acceleration at t = 0 is
            // the one of the mass before redistribution
            if spec.contact_dynamics == ContactDynamics::MassRedistribution {
                let full = Mass::new(model, spec.mass).map_err(|e| e.to_string())?;
                full.add_to(model, &mut self.system, 1.0);
            } else {
                self.mass.add_to(model, &mut self.system, 1.0);
            }
            self.solver
                .factor(&self.system.values)
                .map_err(|e| match e {
                    SolverError::NotPositiveDefinite { index }
                    | SolverError::Singular { index } => {
                        format!(
                            "the mass matrix of the initial accelerations is not positive definite \
                         at {}: a free DOF without mass",
                            super::newton::free_dof(model, &self.system, index)
                        )
                    }
                    other => other.to_string(),
                })?;
            self.solver.solve(&mut free);
            self.system.scatter_add(&free, &mut a);
        }
        Ok((a, evaluation.force))
    }

    /// The end of the step this step attempt aims at, and its nominal length.
    fn target(&self) -> (f64, f64) {
        let (spec, time) = (self.spec, self.state.time);
        // an adaptive run's current step (whose steps land on no grid of multiples)
        let dt = match self.error.adaptive {
            Some(_) => self.control.nominal,
            None => self.nominal,
        };
        // steps end at the listed frame times
        let next_frame = self
            .model
            .output
            .next_frame_after(time * (1.0 + 1e-9) + 1e-12 * dt)
            .unwrap_or(f64::INFINITY);
        // a remainder shorter than the shortest step the control takes joins this step: a
        // step of 1e-7 dt (end_time written with a few digits) does not converge
        let stop = spec.end_time.min(next_frame);
        let mut end = (time + self.control.length).min(stop);
        if stop - end < self.control.shortest() {
            end = stop;
        }
        // a step that reaches end_time or a frame time ends on it exactly, as the scene wrote
        // it (k dt in floating point is not always that time: 100 x 1e-6 is 9.999999999999999e-5);
        // other steps end on the multiple of dt they are within round-off of
        let target = if stop - end <= 1e-9 * dt {
            stop
        } else if self.error.adaptive.is_some() {
            end
        } else {
            snap(end, dt)
        };
        (target, step_length(target - time, dt))
    }

    /// One attempt at the step of nominal length `nominal` (shortened at a contact event).
    fn attempt(
        &mut self,
        nominal: f64,
        positions: &[[f64; 2]],
        counters: &mut Counters,
    ) -> Result<(ContactResult<Solution>, Advance), StepFailure> {
        let attempt = Attempt {
            model: self.model,
            spec: self.spec,
            method: self.method.as_ref(),
            kin: &self.kin,
            state: &self.state,
            initial: &self.initial,
            mass: &self.mass,
            last_internal: &self.last_internal,
            positions,
            increments: self.increments,
            pairs: &self.interfaces.pairs,
            persistent: self.persistent_entries(),
            mean_velocity: self.mean_velocity.as_deref(),
            error_target: self
                .error
                .adaptive
                .map(|a| NEWTON_SHARE * a.tolerance * self.watch.speed),
        };
        let (system, solver, factored_for) =
            (&mut self.system, &mut self.solver, &mut self.factored_for);
        let solve = |pass: Pass<'_>| attempt.solve(pass, system, solver, factored_for, counters);
        let pairs = (&self.interfaces.pairs[..], self.state.time);
        let mut step = if super::newton::active_set_inside(self.model, &self.spec.newton) {
            self.contact.step_inside(pairs, positions, nominal, solve)?
        } else {
            self.contact.step(pairs, positions, nominal, solve)?
        };
        let h = step.length;
        let form = self.method.form(h, &self.kin);
        let advance = self.method.advance(h, &self.kin, &step.solution.d);
        if form.solve_fraction != 1.0 {
            // Wilson: the state at t_{n+1} from the interpolated increment
            let mut du = advance.increment.clone();
            for (dof, value) in loads::prescribed(self.model, &self.initial, self.state.time + h) {
                du[dof] = value - self.kin.displacement[dof];
            }
            step.solution.evaluation = assembly::evaluate(
                self.model,
                &self.state,
                StepIncrement {
                    d: &du,
                    dt: h,
                    geometry: self.spec.geometry,
                },
                None,
                self.spec.newton.tangent,
            )
            .map_err(|e| StepFailure(e.to_string()))?;
            step.solution.d = du;
        }
        Ok((step, advance))
    }

    /// Takes a converged step: the state, the motion, the contact status and the energies.
    fn commit(
        &mut self,
        mut step: ContactResult<Solution>,
        advance: Advance,
        target: f64,
        nominal: f64,
    ) {
        let (model, spec) = (self.model, self.spec);
        let h = step.length;
        // the friction forces the step starts from (the committed contact, start positions)
        let pairs = &self.interfaces.pairs;
        let start_positions = self.state.positions(spec.geometry);
        let friction_start = self.contact.friction_forces(pairs, &start_positions);
        let pair_start = (
            self.contact.pair_force_vectors(pairs, &start_positions),
            self.contact.pair_friction_forces(pairs, &start_positions),
        );
        drop(start_positions);
        let d = std::mem::take(&mut step.solution.d);
        let evaluation = std::mem::take(&mut step.solution.evaluation);
        let internal = evaluation.force.clone();
        assembly::commit(model, &mut self.state, &d, evaluation, spec.geometry);
        let start = self.state.time;
        self.state.time = if h == nominal {
            target
        } else {
            self.state.time + h
        };
        self.last_step = self.state.time - start;
        // a moving obstacle where the conditions below read it, and its travel in the step
        self.interfaces.place_obstacles(self.state.time);
        let travel = crate::contact::obstacle_by_dof(&self.interfaces.pairs, d.len(), |m| {
            let (a, b) = (m.at(start), m.at(self.state.time));
            [b[0] - a[0], b[1] - a[1]]
        });
        // the next step's predictor (theory 8.2)
        self.mean_velocity = Some(d.iter().map(|x| x / h).collect());
        let kin = &mut self.kin;
        let previous_velocity = std::mem::replace(&mut kin.velocity, advance.velocity);
        self.previous_acceleration = Some(std::mem::replace(
            &mut kin.acceleration,
            advance.acceleration,
        ));
        for (u, du) in kin.displacement.iter_mut().zip(&d) {
            *u += du;
        }
        // the contact force of the step's end as the integrator applied it (before the
        // conditions below change the motion)
        let applied = self.motion_contact_force(&internal);
        let kin = &mut self.kin;
        // the impact and release conditions change velocities only at a step's events
        let events = &step.events;
        let conditions = !events.closed.is_empty() || !events.released.is_empty();
        let velocity_before = conditions.then(|| kin.velocity.clone());
        let positions = self.state.positions(spec.geometry).into_owned();
        let mass = LumpedMass {
            mass: &self.mass.lumped,
            inverse: &self.inverse_mass,
        };
        let motion = ImpactMotion {
            previous_velocity: &previous_velocity,
            velocity: &mut kin.velocity,
            acceleration: &mut kin.acceleration,
        };
        crate::contact::apply_conditions(&self.interfaces, &mut step, &positions, mass, motion);
        self.contact
            .commit(&self.interfaces, &step, self.state.time, &positions);
        let booked = Booked {
            increment: d,
            travel,
            applied,
            internal,
            velocity_before,
            friction_start,
            pair_start,
        };
        self.book_step(booked, &positions);
        self.increments += 1;
        self.control.accept(true);
    }

    /// The largest speed of the free DOFs of `velocity`, and the run's so far.
    fn top_speed(&self, velocity: &[f64]) -> f64 {
        velocity
            .iter()
            .zip(&self.system.equation)
            .filter(|(_, e)| e.is_some())
            .fold(self.watch.speed, |m, (v, _)| m.max(v.abs()))
    }

    /// The local error estimate of a step of length `h` ending in `end` (ErrorWatch), and
    /// the run's top speed with the step's end velocities (kept only if the step is); 0 for
    /// a method without an estimate. The change of the acceleration over the step is read
    /// over the last two steps, scaled to this one, (a_{n+1} - a_{n-1}) h / (h + h_prev)
    /// (theory 8.2a): it is the step's own change where the motion is smooth, and the
    /// alternation a_{n+1} - a_n = -(a_n - a_{n-1}) of a mode at the trapezoidal rule's
    /// period of two steps (the constrained nodes' rattle under a held contact) cancels out
    /// of it; and it is measured in the mass-weighted root mean square over the DOFs read,
    /// so that the few light nodes of a mesh graded to a contact point, ringing at the
    /// mesh's highest frequencies, do not set the step of the whole body.
    fn estimate(&self, h: f64, end: &Advance) -> (f64, f64) {
        let speed = self.top_speed(&end.velocity);
        if self.error.constant.is_none() {
            return (0.0, speed);
        }
        let (start, scale) = match &self.previous_acceleration {
            Some(a) if self.last_step > 0.0 => (&a[..], h / (h + self.last_step)),
            _ => (&self.kin.acceleration[..], 1.0),
        };
        let read = (&self.estimated[..], &self.mass.lumped[..]);
        let jump = weighted_jump(&end.acceleration, start, read) * scale;
        (self.error.estimate(h, jump, speed), speed)
    }

    /// The largest share of the watched point values (0 when none is watched).
    fn point_estimate(&self, evaluation: &Evaluation) -> f64 {
        self.watched
            .iter()
            .map(|w| w.estimate(self.model, &self.state, &evaluation.trial))
            .fold(0.0, f64::max)
    }

    /// Velocity-level persistency: the (pair, slave node) entries closed at the start of the
    /// step, which keep their relative normal velocity at zero; none for the other methods.
    fn persistent_entries(&self) -> Vec<(usize, usize)> {
        if self.spec.contact_dynamics != ContactDynamics::Persistency {
            return Vec::new();
        }
        let pairs = &self.interfaces.pairs;
        self.contact
            .active
            .iter()
            .enumerate()
            .flat_map(|(p, flags)| {
                flags
                    .iter()
                    .enumerate()
                    .filter(|(_, a)| **a)
                    .map(move |(k, _)| (p, pairs[p].slaves[k]))
            })
            .collect()
    }

    /// F: f_ext on the free DOFs, the reaction M a + a_R M v + f_int on the prescribed ones.
    /// M a + a_r M v + f_int over all DOFs, and f_ext, at the present time.
    fn motion_terms(&self, internal: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let model = self.model;
        let external = loads::external_force(model, &self.state, &self.initial, self.state.time);
        let mut f = self.mass.product(model, &self.kin.acceleration);
        let a_r = self.spec.rayleigh[0];
        if a_r != 0.0 {
            let mv = self.mass.product(model, &self.kin.velocity);
            f.iter_mut().zip(mv).for_each(|(f, mv)| *f += a_r * mv);
        }
        f.iter_mut().zip(internal).for_each(|(f, fi)| *f += fi);
        (f, external)
    }

    fn total_force(&self, internal: &[f64]) -> Vec<f64> {
        let (motion, external) = self.motion_terms(internal);
        let prescribed = |i: usize| self.system.equation[i].is_none();
        (0..self.model.dofs())
            .map(|i| {
                if prescribed(i) {
                    motion[i]
                } else {
                    external[i]
                }
            })
            .collect()
    }

    /// The contact force the motion implies on the contact nodes' free DOFs, M a + a_r M v +
    /// f_int - f_ext (zero elsewhere): the force the integrator's step applied, whatever the
    /// impact conditions then do to the entries' multipliers (theory 7).
    fn motion_contact_force(&self, internal: &[f64]) -> Vec<f64> {
        let (motion, external) = self.motion_terms(internal);
        let on = self.model.contact_surface_nodes();
        let free = |i: usize| self.system.equation[i].is_some() && on[i / 2];
        (0..self.model.dofs())
            .map(|i| {
                if free(i) {
                    motion[i] - external[i]
                } else {
                    0.0
                }
            })
            .collect()
    }
}

/// What the attempts of one step share.
struct Attempt<'s> {
    model: &'s Model,
    spec: &'s DynamicAnalysis,
    method: &'s dyn Integrator,
    kin: &'s MotionState,
    state: &'s State,
    initial: &'s [[f64; 2]],
    mass: &'s Mass,
    last_internal: &'s [f64],
    positions: &'s [[f64; 2]],
    increments: usize,
    pairs: &'s [crate::contact::ContactPair],
    /// Entries held by velocity-level persistency (see `Dynamics::persistent_entries`).
    persistent: Vec<(usize, usize)>,
    mean_velocity: Option<&'s [f64]>,
    /// `dt = "auto"`: the Newton correction that counts as converged, per unit step length
    /// (NEWTON_SHARE x tolerance x the top speed: a tenth of the error the step may make).
    error_target: Option<f64>,
}

/// Under `dt = "auto"` Newton stops when its remaining correction is this share of the
/// local error the step may make (the iteration error then stays below the step's own
/// discretization error), unless Erklig's tests pass first.
const NEWTON_SHARE: f64 = 0.1;

impl Attempt<'_> {
    /// The end-of-step gap of each persistent entry (pair, slave node), where the others'
    /// is 0 (the gap constraint): the start gap plus the increment that makes the relative
    /// normal velocity at the solve point zero: with v* = c_v D + v_hat,
    /// n . (c_v D_rel + v_hat_rel) = 0, so g_end = g_start - n . v_hat_rel / c_v. Against an
    /// obstacle moving at w, which travels dx to the solve time `t_solve`, the relative
    /// velocity is the slave's less w and the gap also loses n . dx:
    /// g_end = g_start - n . (v_hat_s - w) / c_v - n . dx.
    fn targets(&self, form: &StepForm, t_solve: f64) -> Vec<((usize, usize), f64)> {
        let x = |n: usize| self.positions[n];
        self.persistent
            .iter()
            .filter_map(|&(pair, slave)| {
                let gap = self.pairs[pair].gap(slave, &x)?;
                let mut relative: f64 = gap
                    .row(slave)
                    .iter()
                    .map(|(dof, c)| c * form.velocity_offset[*dof])
                    .sum();
                let n = gap.normal;
                let mut travel = 0.0;
                if let Some(m) = self.pairs[pair].moving_obstacle() {
                    let (w, a, b) = (m.velocity(t_solve), m.at(self.state.time), m.at(t_solve));
                    relative -= n[0] * w[0] + n[1] * w[1];
                    travel = n[0] * (b[0] - a[0]) + n[1] * (b[1] - a[1]);
                }
                let target = gap.gap - relative / form.damping_coefficient - travel;
                Some(((pair, slave), target))
            })
            .collect()
    }

    /// Solves the step with a given length and active contact set; K* is factored again
    /// when its coefficients changed or the strategy asks.
    fn solve(
        &self,
        pass: Pass<'_>,
        system: &mut System,
        solver: &mut Solver,
        factored_for: &mut Option<[f64; 3]>,
        counters: &mut Counters,
    ) -> Result<Solution, StepFailure> {
        let Pass {
            pairs,
            length: h,
            active,
            forces,
            tangential,
            warm,
            inside,
        } = pass;
        let (model, spec, state) = (self.model, self.spec, self.state);
        let form = self.method.form(h, self.kin);
        let solve_time = state.time + form.solve_fraction * h;
        // Wilson's extrapolated solve meets a moving obstacle where it is at the solve time
        let moved: Vec<crate::contact::ContactPair>;
        let pairs = if form.solve_fraction != 1.0 && crate::contact::obstacles_move(pairs) {
            moved = placed_at(pairs, solve_time);
            &moved[..]
        } else {
            pairs
        };
        // the predictor: the last step's mean velocity over this step (the end velocity at
        // the first step, and for Wilson's extrapolated solve; theory 8.2), or the increment
        // the last active set converged to
        let predictor = match self.mean_velocity {
            Some(v) if form.solve_fraction == 1.0 => v,
            _ => &self.kin.velocity,
        };
        let mut d: Vec<f64> = match warm {
            Some(d) => d.to_vec(),
            None => predictor
                .iter()
                .map(|v| form.solve_fraction * h * v)
                .collect(),
        };
        for (dof, value) in loads::prescribed(model, self.initial, solve_time) {
            d[dof] = value - self.kin.displacement[dof];
        }
        let external = loads::external_force(
            model,
            state,
            self.initial,
            state.time + form.load_fraction * h,
        );
        let coefficients = [
            form.mass_coefficient,
            form.damping_coefficient,
            form.internal_weight,
        ];
        let factor_first = *factored_for != Some(coefficients)
            || match spec.newton.strategy {
                Strategy::Full => true,
                Strategy::Modified => spec
                    .newton
                    .refactor_every
                    .is_some_and(|n| self.increments.is_multiple_of(n)),
                Strategy::Initial => !solver.is_factored(),
            };
        let step = Step {
            model,
            dt: form.solve_fraction * h,
            geometry: spec.geometry,
            newton: &spec.newton,
            inertia: Some(Inertia {
                mass: self.mass,
                rayleigh: spec.rayleigh,
            }),
            form: &form,
            external: &external,
            internal_start: self.last_internal,
            factor_first,
            predictor: false,
            error_target: self.error_target.map(|fraction| fraction * h),
            contact: Some(Constraints {
                // (a moving obstacle placed at the pass's end)
                pairs,
                active,
                start: self.positions,
                forces,
                tangential,
                targets: self.targets(&form, solve_time),
                inside,
                describe: &|node| model.describe_node(node),
            }),
        };
        let result = step.solve(state, d, system, solver, counters);
        *factored_for = if solver.is_factored() {
            Some(coefficients)
        } else {
            None
        };
        result
    }
}

impl Stepper for Dynamics<'_> {
    fn start(&mut self) -> Result<(), String> {
        let free: Vec<bool> = self.system.equation.iter().map(Option::is_some).collect();
        let velocity = super::initial_velocity(self.model, &free, self.nominal);
        let (acceleration, internal) = self
            .initial_acceleration(&velocity)
            .map_err(|reason| format!("initial acceleration: {reason}"))?;
        self.kin.velocity = velocity;
        self.kin.acceleration = acceleration;
        self.last_internal = internal;
        self.energies.kinetic = self.mass.kinetic_energy(self.model, &self.kin.velocity);
        self.initial_kinetic = self.energies.kinetic;
        self.watch.speed = self.top_speed(&self.kin.velocity);
        self.last_total = self.total_force(&self.last_internal.clone());
        Ok(())
    }

    fn done(&self) -> bool {
        self.state.time >= self.spec.end_time * (1.0 - 1e-12)
    }

    fn advance(&mut self, counters: &mut Counters) -> Result<(), StepError> {
        loop {
            let (target, nominal) = self.target();
            // (a moving obstacle where the closures read it)
            self.interfaces.place_obstacles(self.state.time);
            let positions = self.state.positions(self.spec.geometry).into_owned();
            let velocity_before = self.kin.velocity.clone();
            let mass = LumpedMass {
                mass: &self.mass.lumped,
                inverse: &self.inverse_mass,
            };
            let motion = (&mut self.kin.velocity[..], &mut self.kin.acceleration[..]);
            let closed = self
                .contact
                .close_touching(&self.interfaces, &positions, mass, motion);
            if !closed.is_empty() {
                // their impact conditions changed the motion the step starts from
                self.last_contact = self.motion_contact_force(&self.last_internal);
            }
            // the kinetic energy their impact conditions removed, booked to the pairs
            // whose surfaces hold the nodes
            if !closed.is_empty() {
                let (removed, supplied) = self.taken_by_conditions(&velocity_before);
                self.energies.contact_work += removed.iter().sum::<f64>();
                self.energies.external_work += supplied;
                (self.contact).book_by_owner(&self.interfaces.pairs, &removed, &[]);
            }
            match self.attempt(nominal, &positions, counters) {
                Ok((step, advance)) => {
                    self.contact.accept_cycles = false;
                    let h = step.length;
                    let (estimate, speed) = self.estimate(h, &advance);
                    let estimate = estimate.max(self.point_estimate(&step.solution.evaluation));
                    if (self.error).refuses((h, nominal, estimate), self.control.shortest()) {
                        self.method.reject();
                        counters.rejected += 1;
                        let shorter = h * step_factor(self.error.tolerance(), estimate);
                        self.control
                            .retry(on_ladder(self.nominal, shorter).max(self.error.floor()));
                        continue;
                    }
                    let clipped = h < self.control.length * (1.0 - 1e-9);
                    self.commit(step, advance, target, nominal);
                    self.watch.speed = speed;
                    self.watch.last = estimate;
                    self.watch.largest = self.watch.largest.max(estimate);
                    if let Some(next) = self.error.next_step(self.nominal, h, estimate, clipped) {
                        self.control.propose(next);
                    }
                    return Ok(());
                }
                Err(failure) => {
                    crate::output::console::iteration(format_args!(
                        "  newton: the step to t = {} is cut: {}",
                        readable(target),
                        failure.0
                    ));
                    self.method.reject();
                    if let Err(why) = self.control.reject(nominal, counters) {
                        if failure.unsettled() && !self.contact.accept_cycles {
                            // the last resort, at the same length: an entry cycling between
                            // tension and penetration stays open (theory 8.3)
                            self.contact.accept_cycles = true;
                            continue;
                        }
                        let message =
                            format!("step to t = {} {why}: {}", readable(target), failure.0);
                        return Err(StepError::diverged(message));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::spec::MassKind;

    /// A 4 x 2 block (density 2) 1 mm above a clamped 6 x 2 one, the upper block's bottom
    /// edge the slave surface and the lower block's top edge the master.
    const STACK: &str = r#"
[[material]]
name = "m"
young = 100.0
poisson = 0.3
density = 2.0

[[body]]
name = "upper"
material = "m"
formulation = "plane_strain"
velocity = [0.0, -1.0]
mesh = { type = "rectangle", origin = [0.5, 0.001], width = 2.0, height = 1.0, nx = 4, ny = 2 }

[[body]]
name = "lower"
material = "m"
formulation = "plane_strain"
mesh = { type = "rectangle", origin = [0.0, -1.0], width = 3.0, height = 1.0, nx = 6, ny = 2 }

[[support]]
body = "lower"
set = "bottom"
fix = ["x", "y"]

[[contact]]
name = "stack"
slave = { body = "upper", set = "bottom" }
master = { body = "lower", set = "top" }

[analysis]
type = "dynamic"
contact_dynamics = "mass_redistribution"
dt = 0.01
end_time = 0.1
"#;

    /// Goal: under `mass_redistribution` the nodes of both contact surfaces carry no mass
    /// and each body keeps its own. Setup: STACK. Reference (by hand): the slave nodes are
    /// the upper block's five at y = 0.001, the master nodes the lower block's seven at
    /// y = 0; the bodies weigh rho A = 2 x 2 x 1 = 4 and 2 x 3 x 1 = 6 (per unit depth).
    /// Tolerance 1e-13: sums of 8 and 12 element masses of O(1).
    #[test]
    fn mass_redistribution_leaves_both_contact_surfaces_massless() {
        let model = crate::scene::from_str(STACK, Path::new("stack.toml"), &[]).unwrap();
        let mass = Mass::new(&model, MassKind::Consistent)
            .unwrap()
            .redistributed(&model, &model.contact_surface_nodes());
        let coords = model.coordinates();
        for (body, surface_y, nodes_on_surface, total) in [(0, 0.001, 5, 4.0), (1, 0.0, 7, 6.0)] {
            let b = &model.bodies[body];
            let nodes = b.node_offset..b.node_offset + b.mesh.nodes.len();
            let on_surface = nodes.clone().filter(|n| coords[*n][1] == surface_y);
            assert_eq!(on_surface.clone().count(), nodes_on_surface);
            for n in on_surface {
                assert_eq!(mass.lumped[2 * n], 0.0, "node {n} of body {body}");
                assert_eq!(mass.lumped[2 * n + 1], 0.0, "node {n} of body {body}");
            }
            let carried: f64 = nodes.map(|n| mass.lumped[2 * n]).sum();
            assert!((carried - total).abs() < 1e-13, "body {body}: {carried}");
        }
    }
}
