//! Arc-length continuation for load-driven statics (Riks 1979; Crisfield 1981): the load
//! factor is an unknown beside the displacements, tied to them by the length of the
//! increment, so the run follows its equilibrium path through a limit point (collapse,
//! snap-through) where load stepping stops (docs/theory.md 5b).
//!
//! Legend
//! ```text
//! q          the scene's loads at end_time on the free DOFs (pressures on the edges of the
//!            last converged configuration)
//! lambda     the load factor: the state carries lambda q; Delta lambda the increment's
//! Delta u    the increment's displacement on the free DOFs
//! Delta l    the arc: Crisfield's cylindrical constraint ||Delta u|| = Delta l
//! u_t        K^-1 q, the tangent displacement of the whole load
//! R          lambda q - f_int(Delta u), the residual on the free DOFs
//! ```
//! Each iteration factors the current tangent (full Newton; L D L^T past a limit point) and
//! solves K du_R = R and K u_t = q; the correction du_R + d lambda u_t takes the root
//! d lambda of ||Delta u + du_R + d lambda u_t|| = Delta l that turns the increment least
//! (Crisfield 1981). The predictor Delta lambda u_t keeps the last increment's direction
//! (Delta u_n . u_t >= 0: the load rises; below zero the path has turned at a limit point,
//! and the load falls). The first arc is the tangent displacement of 1 / steps of the load;
//! the next is the last one times sqrt(iterations / taken), within [1/2, 2] and at most
//! four times the first; a failed
//! increment is tried again on half its arc, `max_cuts` times in a row. An increment that
//! would pass lambda = 1 rising is taken at lambda = 1 instead (load control for that one),
//! and the path ends there, or after `max_increments`.
//!
//! The history's `time` is the path's pseudo time (the first increment end_time / steps,
//! each later one in proportion to its arc, so it grows as the path goes), `load_factor`
//! is lambda; the loads' curves are ramps from zero (the scene refuses others).

use super::carry::{ArcLengthCarry, Carry};
use super::energies::{Energies, Motion};
use super::newton::{Bordered, Constraints, Counters, SINGULAR_STIFFNESS, StepFailure};
use super::{About, Report, Resume, RowFeatures, RunFeatures, StepError, Stepper, loads};
use crate::analysis::summary::{ArcLengthSummary, RECENT};
use crate::assembly::{self, Evaluation, State, StepIncrement, System};
use crate::contact::{
    ConstrainedSolution, ContactResult, ContactState, Inside, Interfaces, Pass, Settled,
};
use crate::output::readable;
use crate::scene::model::ArcLength as Settings;
use crate::scene::spec::Tangent;
use crate::scene::{Model, StaticAnalysis};
use crate::solver::{Solver, SolverError};

/// Pivots down to this share of their column's diagonal are taken (the solver's own limit,
/// for a mechanism, is 1e-11): at a perfectly plastic plateau the consistent tangent is
/// singular up to the elastic remainder, and the arc's bordered solve goes through it.
const NEAR_SINGULAR: f64 = 1e-15;

/// An increment whose load factor changes by less than this share of what the first
/// increment's stiffness would give over its arc stands still; `FLAT_INCREMENTS` of them in
/// a row are a collapse plateau (a perfectly plastic mechanism), where the path ends: along
/// it the load does not change, and the tangent's near-zero pivot makes the direction of
/// the next increment a matter of round-off. One increment across a smooth limit point can
/// stand still by symmetry; three in a row cannot.
const FLAT: f64 = 1e-6;

/// The longest arc, in first arcs: `steps` sets how finely the path is drawn, so the arcs
/// grow where Newton converges fast, but not past this (Abaqus' maximum arc length
/// increment, here tied to the first).
const LONGEST: f64 = 4.0;
const FLAT_INCREMENTS: usize = 3;

/// The arc-length stepper: the state, the solver and where the path has got to.
pub struct ArcLength<'a> {
    model: &'a Model,
    spec: &'a StaticAnalysis,
    settings: Settings,
    interfaces: Interfaces,
    initial: Vec<[f64; 2]>,
    system: System,
    solver: Solver,
    zeros: Vec<f64>,
    state: State,
    energies: Energies,
    /// The internal force of the committed state (all DOFs).
    last_force: Vec<f64>,
    contact: ContactState,
    /// lambda of the committed state, and the highest on the path.
    factor: f64,
    peak: f64,
    /// The next increment's arc (None before the first) and the first one's (the pseudo
    /// time's unit).
    arc: Option<f64>,
    first_arc: f64,
    /// The share of the load the first increment takes (1 / steps, halved at each cut).
    first_share: f64,
    /// The last increment's Delta u (free DOFs; empty before the first).
    direction: Vec<f64>,
    increments: usize,
    cuts_in_a_row: usize,
    last_step: f64,
    /// The tangent of the committed state is factored (the next increment's predictor).
    factored_at_start: bool,
    /// Increments in a row on which the load factor stood still (`FLAT`).
    flat_in_a_row: usize,
    /// The path stops at a collapse: a perfectly plastic mechanism (the load stood still
    /// for `FLAT_INCREMENTS` increments) or a tangent singular at a committed state.
    collapsed: bool,
    /// The load factors of the last `RECENT` increments and the state before them.
    recent: Vec<f64>,
    /// The bands of resting slaves a held body's first increment has closed
    /// (`statics::widen_resting`).
    bands_tried: usize,
}

/// Why an assembly and factorization failed: a singular tangent (a mechanism, or a limit
/// point met exactly) or another failure (an inverted element), in the user's words.
struct Failure {
    singular: bool,
    message: String,
}

/// A converged increment (one pass of its contact step).
struct Converged {
    /// Delta u on the free DOFs, and on all DOFs.
    du: Vec<f64>,
    d: Vec<f64>,
    dlambda: f64,
    evaluation: Evaluation,
    iterations: usize,
    /// Taken at lambda = 1 (load control), not on its arc.
    landing: bool,
    /// The arc it was taken on (None: the first increment, whose arc is its length).
    arc: Option<f64>,
    /// The normal multipliers of the active contact entries, and the tangential forces of
    /// the pass's friction conditions (in their order).
    forces: Vec<f64>,
    tangential: Vec<f64>,
}

impl ConstrainedSolution for Converged {
    fn increment(&self) -> &[f64] {
        &self.d
    }
    fn normal_forces(&self) -> &[f64] {
        &self.forces
    }
    fn tangential_forces(&self) -> &[f64] {
        &self.tangential
    }
    fn settled(&self) -> Option<&Settled> {
        None
    }
}

impl<'a> ArcLength<'a> {
    pub fn new(
        model: &'a Model,
        spec: &'a StaticAnalysis,
        settings: Settings,
    ) -> Result<ArcLength<'a>, String> {
        let system = System::new(model, &model.constrained_dofs());
        let solver = Solver::new(&system.pattern).map_err(|e| e.to_string())?;
        Ok(ArcLength {
            model,
            spec,
            settings,
            interfaces: model.interfaces(),
            initial: model.coordinates(),
            zeros: vec![0.0; model.dofs()],
            state: State::initial(model),
            energies: Energies::default(),
            last_force: vec![0.0; model.dofs()],
            contact: ContactState::new(&model.contacts),
            factor: 0.0,
            peak: 0.0,
            arc: None,
            first_arc: 0.0,
            first_share: 1.0 / spec.steps as f64,
            direction: Vec::new(),
            increments: 0,
            cuts_in_a_row: 0,
            last_step: 0.0,
            factored_at_start: false,
            flat_in_a_row: 0,
            collapsed: false,
            recent: vec![0.0],
            bands_tried: 0,
            system,
            solver,
        })
    }

    /// The pseudo time of an arc `arc`: the first increment's is its share of end_time.
    fn pseudo_time(&self, arc: f64) -> f64 {
        self.spec.end_time * self.first_share * arc / self.first_arc
    }

    /// One increment on the next arc (`landing`: at lambda = 1 instead), with the contact
    /// pairs' passes where the scene has any (`ContactState::step`: the active set changes
    /// between passes, and an event inside the increment shortens its arc to the event).
    fn attempt(
        &mut self,
        landing: bool,
        counters: &mut Counters,
    ) -> Result<ContactResult<Converged>, StepFailure> {
        let positions = self.state.positions(self.spec.geometry);
        let increment = Increment {
            model: self.model,
            spec: self.spec,
            state: &self.state,
            initial: &self.initial,
            positions: &positions,
            factor: self.factor,
            direction: &self.direction,
            first_share: self.first_share,
            arc: self.arc,
            first_arc: self.first_arc,
            landing,
        };
        let (system, solver) = (&mut self.system, &mut self.solver);
        let fresh = &mut self.factored_at_start;
        let solve = |pass: Pass<'_>| {
            let length = pass.length;
            increment.solve(Some(pass), length, (system, solver), fresh, counters)
        };
        if self.model.contacts.is_empty() {
            let converged = increment.solve(None, 1.0, (system, solver), fresh, counters)?;
            return Ok(ContactResult {
                solution: converged,
                length: 1.0,
                active: Vec::new(),
                forces: Vec::new(),
                tangential: Vec::new(),
                sliding: Vec::new(),
                events: Default::default(),
            });
        }
        // the pass's length is the share of the arc (1, or the fraction to an event)
        let pairs = (&self.model.contacts[..], self.state.time);
        self.contact.step(pairs, &positions, 1.0, solve)
    }

    /// Commits a converged increment (`step`, its contact outcome with it).
    fn commit(&mut self, mut step: ContactResult<Converged>) {
        let c = &mut step.solution;
        let arc = c.arc.unwrap_or_else(|| norm(&c.du));
        let d = std::mem::take(&mut c.d);
        let evaluation = std::mem::take(&mut c.evaluation);
        let force = evaluation.force.clone();
        assembly::commit(
            self.model,
            &mut self.state,
            &d,
            evaluation,
            self.spec.geometry,
        );
        if self.arc.is_none() {
            self.first_arc = arc;
            // a first increment ended early by a contact event took that share of the load
            self.first_share *= step.length;
        }
        let c = &step.solution;
        let length = norm(&c.du);
        self.last_step = self.pseudo_time(if c.landing { length } else { arc });
        self.state.time += self.last_step;
        self.factor += c.dlambda;
        self.peak = self.peak.max(self.factor);
        self.recent.push(self.factor);
        if self.recent.len() > RECENT + 1 {
            self.recent.remove(0);
        }
        let stiffness = self.first_share / self.first_arc;
        if c.dlambda.abs() < FLAT * stiffness * arc {
            self.flat_in_a_row += 1;
        } else {
            self.flat_in_a_row = 0;
        }
        self.collapsed = self.flat_in_a_row >= FLAT_INCREMENTS;
        if !self.model.contacts.is_empty() {
            let positions = self.state.positions(self.spec.geometry);
            self.contact
                .commit(&self.interfaces, &step, self.state.time, &positions);
        }
        self.energies.external_work += super::trapezoid_work(&d, &force, &self.last_force);
        self.energies.internal = self.state.internal_work - self.state.plastic_work;
        self.energies.plastic_work = self.state.plastic_work;
        self.last_force = force;
        let target = self.settings.iterations as f64;
        let grow = (target / step.solution.iterations as f64)
            .sqrt()
            .clamp(0.5, 2.0);
        self.direction = step.solution.du;
        self.arc = Some((arc * grow).min(LONGEST * self.first_arc));
        self.increments += 1;
    }
}

/// Assembles the tangent (`tangent`) of `state` at the increment `d` (all DOFs) into
/// `system` and factors it; the evaluation's internal force comes back.
fn factor_at(
    (model, spec, state): (&Model, &StaticAnalysis, &State),
    (system, solver): (&mut System, &mut Solver),
    (d, dt): (&[f64], f64),
    tangent: Tangent,
) -> Result<Evaluation, Failure> {
    let step = StepIncrement {
        d,
        dt,
        geometry: spec.geometry,
    };
    let evaluation =
        assembly::evaluate(model, state, step, Some(&mut *system), tangent).map_err(|e| {
            Failure {
                singular: false,
                message: e.to_string(),
            }
        })?;
    system.regularize();
    solver
        .factor_indefinite_down_to(&system.values, NEAR_SINGULAR)
        .map_err(|e| match e {
            SolverError::Singular { index } => Failure {
                singular: true,
                message: format!(
                    "{SINGULAR_STIFFNESS} {}: a mechanism or missing supports",
                    super::newton::free_dof(model, system, index)
                ),
            },
            other => Failure {
                singular: false,
                message: other.to_string(),
            },
        })?;
    Ok(evaluation)
}

/// What the passes of one increment share: the committed path and the increment's arc.
struct Increment<'s> {
    model: &'s Model,
    spec: &'s StaticAnalysis,
    state: &'s State,
    initial: &'s [[f64; 2]],
    /// The committed positions (the contact rows' start).
    positions: &'s [[f64; 2]],
    factor: f64,
    direction: &'s [f64],
    first_share: f64,
    /// The next arc (None before the first increment) and the first (the pseudo time's
    /// unit).
    arc: Option<f64>,
    first_arc: f64,
    landing: bool,
}

/// Where an increment's Newton iteration stands: Delta u on the free DOFs, Delta lambda and
/// the contact multipliers.
struct Iterate {
    du: Vec<f64>,
    dlambda: f64,
    forces: Vec<f64>,
}

impl Increment<'_> {
    /// Newton on (Delta u, Delta lambda) from the tangent predictor on `share` of the arc
    /// (the first increment: of 1 / steps of the load), with the contact rows of `pass`
    /// (theory 5b); `landing`: at lambda = 1 instead (Newton on Delta u alone, load control).
    /// `fresh`: the tangent of the committed state is factored already.
    fn solve(
        &self,
        pass: Option<Pass<'_>>,
        share: f64,
        (system, solver): (&mut System, &mut Solver),
        fresh: &mut bool,
        counters: &mut Counters,
    ) -> Result<Converged, StepFailure> {
        let (model, spec, state) = (self.model, self.spec, self.state);
        let newton = &spec.newton;
        let q = self.load(system)?;
        let q_norm = norm(&q);
        let describe = |node: usize| model.describe_node(node);
        let constraints = pass.as_ref().map(|p| Constraints {
            pairs: p.pairs,
            active: p.active,
            start: self.positions,
            forces: p.forces.clone(),
            tangential: p.tangential,
            targets: Vec::new(),
            inside: Inside::Fixed,
            describe: &describe,
        });
        let tangential = pass.as_ref().map_or(&[][..], |p| p.tangential);
        let mut forces = pass.map_or(Vec::new(), |p| p.forces);
        let zero = vec![0.0; model.dofs()];
        let nominal = spec.end_time / spec.steps as f64;
        let parts = (model, spec, state);
        if !std::mem::take(fresh) {
            factor_at(parts, (system, solver), (&zero, nominal), newton.tangent)
                .map_err(|f| StepFailure(f.message))?;
        }
        let mut bordered = Bordered::at(constraints.as_ref(), &zero, system)?;
        // the sticking entries' tangential multipliers start from zero
        forces.resize(bordered.len(), 0.0);
        let (ut, tau_t) = bordered.solve_load(solver, q.clone(), &forces)?;
        let arc = match self.arc {
            Some(arc) => arc * share,
            None => norm(&ut) * self.first_share * share,
        };
        // with contact the first increment takes its share of the load (load control): its
        // arc would be sized on a stiffness that the closures inside it change (a body held
        // at one node at the start, by many at the end)
        let first_load = (self.arc.is_none() && constraints.is_some()).then_some(self.first_share);
        let load_controlled = self.landing || first_load.is_some();
        let mut at = self.predictor((ut, tau_t), forces, (arc, share), first_load);
        let dt = match self.arc {
            Some(_) => spec.end_time * self.first_share * arc / self.first_arc,
            None => nominal * self.first_share * spec.steps as f64,
        };
        for iteration in 1..=newton.max_iterations {
            counters.iterations += 1;
            let mut d = zero.clone();
            system.scatter_add(&at.du, &mut d);
            let evaluation = factor_iterate(parts, (system, solver), (&d, dt))?;
            let lambda = self.factor + at.dlambda;
            let internal = system.gather(&evaluation.force);
            let mut r: Vec<f64> = (q.iter().zip(&internal))
                .map(|(q, f)| lambda * q - f)
                .collect();
            bordered = Bordered::at(constraints.as_ref(), &d, system)?;
            // sliding friction: known forces from the last solve's normal multipliers
            bordered.add_sliding_forces(&at.forces, &mut r);
            let scale = q_norm * lambda.abs().max(at.dlambda.abs()).max(1e-3);
            let residual = norm(&bordered.balance(&r, &at.forces));
            self.log(
                iteration,
                (residual, newton.tol_force * scale),
                lambda,
                &bordered,
            );
            if residual <= newton.tol_force * scale && bordered.hold() {
                let Iterate {
                    du,
                    dlambda,
                    mut forces,
                } = at;
                let tangential = bordered.tangential_forces(tangential, &forces);
                forces.truncate(bordered.normal());
                return Ok(Converged {
                    du,
                    d,
                    dlambda,
                    evaluation,
                    iterations: iteration,
                    landing: self.landing,
                    arc: self.arc.map(|_| arc),
                    forces,
                    tangential,
                });
            }
            let (du_r, tau_r) = bordered.solve(solver, r, &at.forces)?;
            let (ut, tau_t) = bordered.solve_load(solver, q.clone(), &at.forces)?;
            let dl = if load_controlled {
                0.0
            } else {
                constrained_step(&at.du, &du_r, &ut, arc)
            };
            for ((u, r), t) in at.du.iter_mut().zip(&du_r).zip(&ut) {
                *u += r + dl * t;
            }
            at.dlambda += dl;
            at.forces = (tau_r.iter().zip(&tau_t))
                .map(|(r, t)| r + dl * t)
                .collect();
        }
        Err(StepFailure(format!(
            "no convergence in {} iterations",
            newton.max_iterations
        )))
    }

    /// q: the scene's loads at end_time on the free DOFs (refused when they vanish there).
    fn load(&self, system: &System) -> Result<Vec<f64>, StepFailure> {
        let (model, end) = (self.model, self.spec.end_time);
        let q = system.gather(&loads::external_force(model, self.state, self.initial, end));
        if norm(&q) == 0.0 {
            return Err(StepFailure(
                "the loads vanish on the free DOFs: nothing to scale".into(),
            ));
        }
        Ok(q)
    }

    /// The predictor Delta lambda u_t from the constrained tangent displacement `ut` and its
    /// multipliers `tau_t` (`(ut, tau_t)`), on the arc `arc` (`share` of the increment's):
    /// Delta lambda |u_t| = arc, rising where u_t goes the way of the last increment; at
    /// lambda = 1 when landing, the share `first_load` of the load for a first increment
    /// with contact. The multipliers `forces` move with it by Delta lambda tau_t.
    fn predictor(
        &self,
        (ut, tau_t): (Vec<f64>, Vec<f64>),
        forces: Vec<f64>,
        (arc, share): (f64, f64),
        first_load: Option<f64>,
    ) -> Iterate {
        let rising = dot(self.direction, &ut) >= 0.0;
        let step = arc / norm(&ut);
        let dlambda = if self.landing {
            (1.0 - self.factor) * share
        } else if let Some(first) = first_load {
            first * share
        } else if rising {
            step
        } else {
            -step
        };
        Iterate {
            du: ut.iter().map(|v| dlambda * v).collect(),
            dlambda,
            forces: (forces.iter().zip(&tau_t))
                .map(|(f, t)| f + dlambda * t)
                .collect(),
        }
    }

    /// The `--verbose` line of an iteration: the residual with the contact forces against
    /// its tolerance (`(residual, tolerance)`), the load factor, the contact rows.
    fn log(&self, iteration: usize, (residual, tolerance): (f64, f64), lambda: f64, b: &Bordered) {
        crate::output::console::iteration(format_args!(
            "  arc length: increment from load factor {}, iteration {iteration}: |R| = \
             {residual:.3e} (tol {tolerance:.1e}), load factor {}, {} contact rows{}",
            readable(self.factor),
            readable(lambda),
            b.normal(),
            if b.hold() {
                ""
            } else {
                ", a gap open beyond TOL"
            }
        ));
    }
}

/// The tangent at the iterate `d` assembled and factored (`factor_at` with the scene's
/// tangent): a singular consistent tangent (a plastic zone past its collapse mechanism,
/// overshot) is passed with the elastic moduli and K_sigma for that iteration, not cut.
fn factor_iterate(
    parts: (&Model, &StaticAnalysis, &State),
    (system, solver): (&mut System, &mut Solver),
    (d, dt): (&[f64], f64),
) -> Result<Evaluation, StepFailure> {
    let tangent = parts.1.newton.tangent;
    let mut factor = |tangent| factor_at(parts, (&mut *system, &mut *solver), (d, dt), tangent);
    match factor(tangent) {
        Err(f) if f.singular && tangent == Tangent::Consistent => factor(Tangent::ElasticGeometric),
        other => other,
    }
    .map_err(|f| StepFailure(f.message))
}

/// The root d lambda of ||du + du_r + d lambda ut|| = arc that keeps the corrected increment
/// closest in direction to `du` (Crisfield 1981); where the quadratic has no real root (the
/// correction du_r alone leaves the arc's cylinder far behind, as on a perfectly plastic
/// plateau), the d lambda that comes closest to it (the quadratic's vertex), as the
/// iteration's next iterate rather than a failure.
fn constrained_step(du: &[f64], du_r: &[f64], ut: &[f64], arc: f64) -> f64 {
    let w: Vec<f64> = du.iter().zip(du_r).map(|(a, b)| a + b).collect();
    let a = dot(ut, ut);
    let b = 2.0 * dot(ut, &w);
    let c = dot(&w, &w) - arc * arc;
    let discriminant = b * b - 4.0 * a * c;
    if discriminant < 0.0 {
        return -b / (2.0 * a);
    }
    let root = discriminant.sqrt();
    let roots = [(-b + root) / (2.0 * a), (-b - root) / (2.0 * a)];
    // the cosine of the angle to du, without the common norms: du . (w + s ut)
    let (du_w, du_ut) = (dot(du, &w), dot(du, ut));
    let angle = |s: f64| du_w + s * du_ut;
    if angle(roots[0]) >= angle(roots[1]) {
        roots[0]
    } else {
        roots[1]
    }
}

/// (largest - smallest) / |last| of the load factors `factors` (0 for a path at zero).
fn recent_change(factors: &[f64]) -> f64 {
    let last = factors.last().copied().unwrap_or(0.0);
    if last == 0.0 {
        return 0.0;
    }
    let (low, high) = factors
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), f| {
            (l.min(*f), h.max(*f))
        });
    (high - low) / last.abs()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

impl Stepper for ArcLength<'_> {
    /// A body that its contact alone holds closes its touching slaves before the path
    /// starts (`statics::hold_by_contact`): the bordered solves need a tangent to factor.
    /// A regular tangent found so is the first predictor's, factored already.
    fn start(&mut self) -> Result<(), String> {
        let spec = self.spec;
        let hold = super::statics::hold_by_contact(
            (self.model, &self.state, spec.end_time / spec.steps as f64),
            (spec.geometry, spec.newton.tangent),
            (&mut self.system, &mut self.solver),
            &mut self.contact,
        );
        self.factored_at_start = hold == super::statics::Hold::Regular;
        Ok(())
    }

    fn done(&self) -> bool {
        self.factor >= 1.0 - 1e-12
            || self.increments >= self.settings.max_increments
            || self.collapsed
    }

    fn advance(&mut self, counters: &mut Counters) -> Result<(), StepError> {
        loop {
            // an arc that carries the path past the scene's load rising is taken again
            // to land on it
            let attempt = self.attempt(false, counters).and_then(|c| {
                let dlambda = c.solution.dlambda;
                if dlambda > 0.0 && self.factor + dlambda > 1.0 {
                    self.attempt(true, counters)
                } else {
                    Ok(c)
                }
            });
            match attempt {
                Ok(converged) => {
                    self.commit(converged);
                    self.cuts_in_a_row = 0;
                    // the next predictor's tangent, factored now (where there is a next
                    // increment): singular, the path ends
                    if !self.done() {
                        let zero = vec![0.0; self.model.dofs()];
                        let nominal = self.spec.end_time / self.spec.steps as f64;
                        let parts = (self.model, self.spec, &self.state);
                        let solving = (&mut self.system, &mut self.solver);
                        match factor_at(parts, solving, (&zero, nominal), self.spec.newton.tangent)
                        {
                            Ok(_) => self.factored_at_start = true,
                            Err(f) if f.singular => self.collapsed = true,
                            Err(_) => {}
                        }
                    }
                    return Ok(());
                }
                Err(StepFailure(reason)) => {
                    // a held body's first increment: more of its resting slaves closed
                    if self.increments == 0
                        && self.system.held > 0.0
                        && super::statics::widen_resting(
                            (self.model, &self.state, self.spec.geometry),
                            &mut self.contact,
                            &mut self.bands_tried,
                        )
                    {
                        continue;
                    }
                    self.cuts_in_a_row += 1;
                    counters.cuts += 1;
                    if self.cuts_in_a_row > self.spec.newton.max_cuts {
                        return Err(StepError::diverged(format!(
                            "arc-length increment {} from load factor {} did not converge \
                             after {} cuts: {reason}{}",
                            self.increments + 1,
                            readable(self.factor),
                            self.spec.newton.max_cuts,
                            super::statics::held_hint(&self.system)
                        )));
                    }
                    // the first arc is not known until its predictor: its share of the
                    // load is halved instead
                    match &mut self.arc {
                        Some(a) => *a *= 0.5,
                        None => self.first_share *= 0.5,
                    }
                }
            }
        }
    }
}

impl Report for ArcLength<'_> {
    fn about(&self) -> About {
        About {
            integrator: "static".into(),
            dt: self.spec.end_time / self.spec.steps as f64,
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
            velocity: &self.zeros,
            acceleration: &self.zeros,
            mass: &[],
            internal_force: &self.last_force,
        }
    }
    fn energies(&self) -> &Energies {
        &self.energies
    }
    fn initial_kinetic(&self) -> f64 {
        0.0
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
    fn held(&self) -> f64 {
        self.system.held
    }
    fn row_features(&self) -> RowFeatures {
        RowFeatures {
            load_factor: Some(self.factor),
            ..RowFeatures::default()
        }
    }
    fn run_features(&self) -> RunFeatures {
        RunFeatures {
            arc_length: Some(ArcLengthSummary {
                increments: self.increments,
                peak_load_factor: self.peak,
                final_load_factor: self.factor,
                reached_load: self.factor >= 1.0 - 1e-12,
                collapsed: self.collapsed,
                recent_change: recent_change(&self.recent),
            }),
            ..RunFeatures::default()
        }
    }
}

impl Resume for ArcLength<'_> {
    fn kind(&self) -> &'static str {
        "arc-length"
    }

    fn restore(&mut self, carry: Carry) -> bool {
        let Carry::ArcLength(c) = carry else {
            return false;
        };
        self.state = c.state;
        self.energies = c.energies;
        self.last_force = c.last_force;
        self.contact = c.contact;
        self.factor = c.factor;
        self.peak = c.peak;
        self.arc = c.arc;
        self.first_arc = c.first_arc;
        self.first_share = c.first_share;
        self.direction = c.direction;
        self.increments = c.increments;
        self.last_step = c.last_step;
        self.flat_in_a_row = c.flat_in_a_row;
        self.collapsed = c.collapsed;
        self.system.held = c.held;
        self.recent = c.recent;
        // the committed state's tangent, the next predictor's, is factored again
        self.factored_at_start = false;
        true
    }

    fn carry(&self) -> Result<Carry, &'static str> {
        Ok(Carry::ArcLength(ArcLengthCarry {
            state: self.state.clone(),
            energies: self.energies,
            last_force: self.last_force.clone(),
            contact: self.contact.clone(),
            factor: self.factor,
            peak: self.peak,
            arc: self.arc,
            first_arc: self.first_arc,
            first_share: self.first_share,
            direction: self.direction.clone(),
            increments: self.increments,
            last_step: self.last_step,
            flat_in_a_row: self.flat_in_a_row,
            collapsed: self.collapsed,
            held: self.system.held,
            recent: self.recent.clone(),
        }))
    }

    /// A resumed run factors the committed tangent again (`restore`), with a fresh solver;
    /// so does the run that wrote the checkpoint, so both go on from the same factor and
    /// the same counts.
    fn after_checkpoint(&mut self) {
        self.factored_at_start = false;
        self.solver.forget_inertia();
    }

    fn solver_mut(&mut self) -> Option<&mut Solver> {
        Some(&mut self.solver)
    }
}
