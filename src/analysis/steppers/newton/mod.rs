//! One nonlinear step by Newton-Raphson, shared by static load stepping (no inertia) and the
//! implicit integrators (see `integrator` for the step form).
//!
//! Legend
//! ```text
//! D          solved increment since the last converged configuration (all DOFs; prescribed
//!            DOFs hold their prescribed increments)
//! R(D)       f_ext - M a*(D) - C v*(D) - w f_int(D) - (1 - w) f_int,n    on the free DOFs
//! K*         ca M + cv C + w K_T,   C = a_R M + b_R K_0 (K_0: tangent at the step start)
//! eps_1      ||delta D|| / ||D||                          (Erklig 2.1.2 (viii))
//! eps_2      ||R|| / max(||f_ext||, ||M a*||, ||f*||)  (Erklig 2.1.2 (viii)); the last two over
//!            all DOFs, so the reactions give the scale when only displacements are prescribed
//! ```
//! Factorization policy: `full` every iteration; otherwise the caller says whether the step
//! starts with a fresh factorization, and the iteration refactors only when it stops
//! contracting (||R_k|| > contraction ||R_k-1||) or when, at its current rate, it would need
//! more than half of the iterations left to reach the force tolerance. Between
//! factorizations, `updates = "bfgs"` corrects the factored matrix by BFGS updates (`secant`).

mod active_set;
mod constrained;
mod line_search;
mod secant;

use crate::assembly::{self, Evaluation, Mass, State, StepIncrement, System};
use crate::contact::{ConstrainedSolution, ContactPair, Inside, Settled, Tangential, Unsettled};
use crate::element::Strain;
use crate::integrator::StepForm;
use crate::profile::{self, Phase};
use crate::scene::Model;
use crate::scene::spec::{ActiveSetSolve, NewtonSpec, Strategy, Tangent, Updates};
use crate::solver::{Solver, SolverError};
use active_set::ActiveSet;
pub use constrained::Bordered;
use constrained::{Rows, add_constraint_forces, constrained_solve};
use secant::Secant;

/// Whether a run decides its contact active set inside Newton's iteration (`active_set`,
/// theory 8.3b): as the scene says, else where the model has a mortar pair.
pub fn active_set_inside(model: &Model, newton: &NewtonSpec) -> bool {
    match newton.active_set {
        Some(ActiveSetSolve::Newton) => true,
        Some(ActiveSetSolve::Passes) => false,
        None => model.contacts.iter().any(|pair| pair.mortar().is_some()),
    }
}

/// Counters of the nonlinear solution.
#[derive(Debug, Clone, Copy, Default, serde::Serialize, serde::Deserialize)]
pub struct Counters {
    pub iterations: usize,
    pub cuts: usize,
    /// Steps taken again shorter because their error estimate was above the tolerance
    /// (implicit `dt = "auto"`); `cuts` counts those cut after a failed Newton.
    pub rejected: usize,
}

/// The free equation `index` of `system` in the user's words: the body, node and component.
pub(super) fn free_dof(model: &Model, system: &System, index: usize) -> String {
    match system.equation.iter().position(|e| *e == Some(index)) {
        Some(dof) => format!(
            "the {} DOF of {}",
            ["x", "y"][dof % 2],
            model.describe_node(dof / 2)
        ),
        None => format!("free DOF {index}"),
    }
}

/// The step failed to converge: why (reported after the last cut).
#[derive(Debug, Clone)]
pub struct StepFailure(pub String);

/// How the message of an iteration that ran out of iterations begins.
const NOT_CONVERGED: &str = "no convergence in";

/// How the message of a singular tangent begins.
pub const SINGULAR_STIFFNESS: &str = "the stiffness matrix is singular at";

impl StepFailure {
    /// Whether the iteration ran out of iterations (rather than meeting an inverted element,
    /// a singular matrix or a non-finite residual).
    pub fn ran_out(&self) -> bool {
        self.0.starts_with(NOT_CONVERGED)
    }

    /// Whether the tangent was singular (a mechanism, or a body that its contact alone
    /// would hold).
    pub fn singular(&self) -> bool {
        self.0.starts_with(SINGULAR_STIFFNESS)
    }

    /// Whether the contact active set did not settle (`Unsettled`).
    pub fn unsettled(&self) -> bool {
        self.0 == Unsettled.to_string()
    }
}

impl From<Unsettled> for StepFailure {
    fn from(e: Unsettled) -> StepFailure {
        StepFailure(e.to_string())
    }
}

/// Inertia and damping of a dynamic problem.
pub struct Inertia<'a> {
    pub mass: &'a Mass,
    pub rayleigh: [f64; 2],
}

pub struct Step<'a> {
    pub model: &'a Model,
    /// The time step the increment spans (the strain rate of rate-dependent materials).
    pub dt: f64,
    pub geometry: Strain,
    pub newton: &'a NewtonSpec,
    pub inertia: Option<Inertia<'a>>,
    pub form: &'a StepForm,
    /// External force at the load point, all DOFs.
    pub external: &'a [f64],
    /// Internal force of the committed state (for w < 1), all DOFs.
    pub internal_start: &'a [f64],
    /// Factor at the first iteration (else the solver's factorization is reused).
    pub factor_first: bool,
    /// Start from the tangent predictor where the step prescribes motion (`Predictor`).
    pub predictor: bool,
    /// Implicit `dt = "auto"`: a correction size (the largest DOF's, a displacement) below
    /// which the iteration has converged, a fraction of the local error the step may make
    /// (theory 8.2a); the force test still holds. None: Erklig's tests alone.
    pub error_target: Option<f64>,
    /// Active contact constraints, enforced by Lagrange multipliers.
    pub contact: Option<Constraints<'a>>,
}

/// The contact constraints a step enforces (its input): (pair, slave node) entries, gaps
/// measured at start + d. Their multipliers start from `forces` (the last step's).
pub struct Constraints<'a> {
    pub pairs: &'a [ContactPair],
    pub active: &'a [(usize, usize)],
    pub start: &'a [[f64; 2]],
    pub forces: Vec<f64>,
    /// Friction on some of the active entries.
    pub tangential: &'a [Tangential],
    /// The gap an entry (pair, slave node) must have at the end of the step where it is not
    /// 0: the start gap plus the persistency increment for velocity-level persistency.
    pub targets: Vec<((usize, usize), f64)>,
    /// How the step may change the active set: `Inside::Fixed` solves with `active` and
    /// `tangential` as given; otherwise they are where Newton's active set starts.
    pub inside: Inside,
    /// A global node in the user's words (`Model::describe_node`), for messages.
    pub describe: &'a dyn Fn(usize) -> String,
}

/// A converged step: the increment, its evaluation, the contact multipliers (tau, the
/// compressive normal forces of the active entries, in their order) and the tangential
/// forces of the `tangential` conditions (in theirs).
pub struct Solution {
    pub d: Vec<f64>,
    pub evaluation: Evaluation,
    pub forces: Vec<f64>,
    pub tangential: Vec<f64>,
    /// The active set Newton settled on, when it decided it (`Inside::Releases`,
    /// `Inside::Closures`).
    pub settled: Option<Settled>,
}

impl ConstrainedSolution for Solution {
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
        self.settled.as_ref()
    }
}

/// Whether the residual norms `norms` (the last ones since the correction was last
/// relaxed) show a two-iterate cycle: Newton's step from each of two iterates lands on the
/// other, so the last four norms repeat in pairs (within 5 %) without falling by half. Seen
/// at the hot axis elements of Johnson-Cook rods under contact (theory 8.1-1), where the
/// full correction overshoots the plastic flow's answer by about its own size; half of it
/// lands between the two iterates. A converging iteration (norms falling by more than 5 %
/// over two iterations) never shows it.
fn cycling(norms: &[f64]) -> bool {
    let k = norms.len();
    if k < 5 {
        return false;
    }
    let close = |a: f64, b: f64| (a - b).abs() < 0.05 * a;
    close(norms[k - 1], norms[k - 3])
        && close(norms[k - 2], norms[k - 4])
        && norms[k - 1] > 0.5 * norms[k - 2]
        && norms[k - 2] > 0.5 * norms[k - 1]
}

/// The share of each Newton correction taken: 1, halved at each two-iterate cycle of the
/// residual norms (`cycling`, theory 8.1-1), and back to 1 once the relaxed iteration shows
/// that the full correction was right (`linear_at_share`).
struct Relaxation {
    /// The residual norms of the iterates.
    norms: Vec<f64>,
    share: f64,
    /// The iterate from which the next cycle is looked for (the last halving's).
    since: usize,
}

impl Relaxation {
    fn new() -> Relaxation {
        Relaxation {
            norms: Vec::new(),
            share: 1.0,
            since: 0,
        }
    }

    /// Forgets the norms so far: the contact rows changed, and a two-iterate cycle across
    /// the change is the active set's, not the plastic flow's.
    fn restart(&mut self) {
        self.since = self.norms.len();
    }

    /// Takes an iterate's residual norm; halves the share when the norms since the last
    /// halving cycle.
    fn observe(&mut self, residual_norm: f64) {
        self.norms.push(residual_norm);
        if cycling(&self.norms[self.since..]) {
            self.share *= 0.5;
            self.since = self.norms.len();
        } else if self.linear_at_share() {
            self.share = 1.0;
            self.since = self.norms.len();
        }
    }

    /// Whether the last two iterations since the last change of the share each took the
    /// residual down by 1 - share (within a tenth of it): the signature of a correction that
    /// is right but cut by the share, once the cycle it broke is behind (the residual halves
    /// at every iteration at share 1/2, where the whole correction would have converged).
    fn linear_at_share(&self) -> bool {
        let norms = &self.norms[self.since..];
        let k = norms.len();
        if self.share >= 1.0 || k < 3 {
            return false;
        }
        let expected = 1.0 - self.share;
        let near = |ratio: f64| (ratio - expected).abs() < 0.1 * expected;
        near(norms[k - 1] / norms[k - 2]) && near(norms[k - 2] / norms[k - 3])
    }

    /// A solve's correction `delta` (scaled in place) and multipliers `tau`, relaxed: the
    /// multipliers moved the share of the way from `forces`, the ones before the solve.
    fn relax(&self, delta: &mut [f64], forces: &[f64], tau: Vec<f64>) -> Vec<f64> {
        if self.share >= 1.0 {
            return tau;
        }
        delta.iter_mut().for_each(|v| *v *= self.share);
        tau.iter()
            .enumerate()
            .map(|(i, t)| {
                let old = forces.get(i).copied().unwrap_or(0.0);
                old + self.share * (t - old)
            })
            .collect()
    }
}

/// A residual this share of the force tolerance is round-off: the step has converged.
const ROUND_OFF: f64 = 1e-4;

/// The force measure of an iterate: eps_2 against its scale, and the residual against the
/// forces in play for the round-off exit.
struct Convergence {
    residual_norm: f64,
    forces_scale: f64,
    /// ||F||, floored by what the stiffness makes of the increment.
    scale: f64,
    eps_force: f64,
}

impl Convergence {
    fn of(residual_norm: f64, forces_scale: f64, d: &[f64], diagonal_max: f64) -> Convergence {
        // the force scale cannot fall below what the stiffness makes of the increment: a
        // rigid motion has no loads and no reactions, only round-off to compare with
        let d_max = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let scale = forces_scale.max(diagonal_max * d_max);
        let eps_force = if scale > 0.0 {
            residual_norm / scale
        } else {
            0.0
        };
        Convergence {
            residual_norm,
            forces_scale,
            scale,
            eps_force,
        }
    }

    /// Both measures of Erklig 2.1.2 (viii) under their tolerances, or the residual at
    /// round-off of the forces in play, whatever the last correction was: at rest (a bar
    /// stopped against a wall) the increment is round-off too, and the displacement ratio
    /// compares round-off with round-off. (Not against the stiffness floor of the scale:
    /// past a limit load the increment grows without bound and would make any residual look
    /// small.)
    fn passed(&self, newton: &NewtonSpec, eps_displacement: f64) -> bool {
        (eps_displacement < newton.tol_displacement && self.eps_force < newton.tol_force)
            || self.residual_norm <= ROUND_OFF * newton.tol_force * self.forces_scale
    }
}

/// Erklig's eps_1 measures the last correction; what is left to the solution is the sum of the
/// corrections still to come. While the iteration contracts at `ratio` (the residual's, which
/// the next correction K*^-1 R follows) that sum is the last correction times
/// ratio / (1 - ratio), smaller than it for ratio < 1/2: the test takes it there, and the
/// last correction itself otherwise (never looser than Erklig's measure on a slow iteration).
fn remaining(eps_last: f64, ratio: f64) -> f64 {
    if ratio < 0.5 {
        eps_last * ratio / (1.0 - ratio)
    } else {
        eps_last
    }
}

/// The tangent predictor of a step that prescribes motion (theory 5a; the first iteration
/// of a displacement-controlled increment in Abaqus): the prescribed increment u_p
/// enters the first correction through the tangent at the step's start,
/// K_ff delta_f = R_f(0) - K_fp u_p, not through the residual at (0, u_p), where only the
/// elements beside the prescribed nodes deform: their strain there is u_p over one element,
/// a spike a mesh-refinement makes larger (the homogeneous J2 block compressed between
/// rollers yielded in its top row of elements and did not converge from it on 20 x 20
/// elements, however short the increment). K_fp u_p is the residual's directional
/// derivative, R_f(0) - (R_f(eps u_p) - R_f(0)) / eps: one evaluation without a matrix.
struct Predictor {
    /// The step's start: the prescribed increments zeroed.
    start: Vec<f64>,
    /// The start moved by the share `PROBE` of the prescribed increments.
    probe: Vec<f64>,
}

/// The share of the prescribed increment the directional derivative moves by: its
/// truncation error is this share of the increment's strain (1e-8 at 1 % strain), its
/// round-off 1e-16 |f_int| / (PROBE |K u_p|), below 1e-9 while the stresses stay below
/// a tenth of E and the increment's strain above 1e-7 of them.
const PROBE: f64 = 1e-6;

impl Predictor {
    /// The predictor of the start value `d`, where its free DOFs are zero (not a warm start)
    /// and some prescribed DOF moves.
    fn of(d: &[f64], system: &System) -> Option<Predictor> {
        let free = |dof: usize| system.equation[dof].is_some();
        let cold = d.iter().enumerate().all(|(dof, v)| !free(dof) || *v == 0.0);
        if !cold || d.iter().all(|v| *v == 0.0) {
            return None;
        }
        Some(Predictor {
            start: vec![0.0; d.len()],
            probe: d.iter().map(|v| PROBE * v).collect(),
        })
    }

    /// Turns R_f(0) in `residual` into R_f(0) - K_fp u_p from `moved` = R_f(PROBE u_p).
    fn extrapolate(&self, residual: &mut [f64], moved: &[f64]) {
        for (r, m) in residual.iter_mut().zip(moved) {
            *r += (m - *r) / PROBE;
        }
    }
}

/// Stiffness-proportional damping matrix of the step (the tangent at D = 0), free DOFs.
struct Damping {
    values: Vec<f64>,
}

/// Names the first DOF whose residual (or displacement) is NaN or infinite.
fn non_finite(system: &System, residual: &[f64], d: &[f64]) -> String {
    let name = |dof: usize| format!("node {} {}", dof / 2, ["x", "y"][dof % 2]);
    if let Some(dof) = d.iter().position(|v| !v.is_finite()) {
        return format!("the displacement is {} at {}", d[dof], name(dof));
    }
    // a NaN or infinite entry, else the largest one (whose square overflowed the norm)
    let equation = residual.iter().position(|v| !v.is_finite()).or_else(|| {
        (0..residual.len()).max_by(|a, b| residual[*a].abs().total_cmp(&residual[*b].abs()))
    });
    let dof = equation.and_then(|eq| system.equation.iter().position(|e| *e == Some(eq)));
    match (equation, dof) {
        (Some(eq), Some(dof)) if !residual[eq].is_finite() => {
            format!("the residual is {} at {}", residual[eq], name(dof))
        }
        (Some(eq), Some(dof)) => format!(
            "the residual norm overflows (not finite); its largest entry is {:e} at {}",
            residual[eq],
            name(dof)
        ),
        _ => "the residual norm is not finite (NaN or Inf)".into(),
    }
}

/// The largest entry of a correction `delta` and Erklig's eps_1, ||delta|| / ||d|| (0 for
/// d = 0), `d` the increment it was added to.
fn correction_sizes(delta: &[f64], d: &[f64]) -> (f64, f64) {
    let d_norm = norm(d);
    let largest = delta.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let ratio = if d_norm > 0.0 {
        norm(delta) / d_norm
    } else {
        0.0
    };
    (largest, ratio)
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

impl Step<'_> {
    fn evaluate(
        &self,
        state: &State,
        d: &[f64],
        system: Option<&mut System>,
    ) -> Result<Evaluation, StepFailure> {
        assembly::evaluate(
            self.model,
            state,
            StepIncrement {
                d,
                dt: self.dt,
                geometry: self.geometry,
            },
            system,
            self.newton.tangent,
        )
        .map_err(|e| StepFailure(e.to_string()))
    }

    /// Turns the assembled K_T in `system.values` into K*.
    fn effective(&self, system: &mut System, damping: &Option<Damping>) {
        let Some(inertia) = &self.inertia else { return };
        let w = self.form.internal_weight;
        system.values.iter_mut().for_each(|v| *v *= w);
        let [a_r, b_r] = inertia.rayleigh;
        let f = self.form;
        inertia.mass.add_to(
            self.model,
            system,
            f.mass_coefficient + f.damping_coefficient * a_r,
        );
        if let Some(dm) = damping {
            for (v, k) in system.values.iter_mut().zip(&dm.values) {
                *v += f.damping_coefficient * b_r * k;
            }
        }
    }

    /// Solves the step from the start value `d` (prescribed DOFs already set).
    pub fn solve(
        &self,
        state: &State,
        mut d: Vec<f64>,
        system: &mut System,
        solver: &mut Solver,
        counters: &mut Counters,
    ) -> Result<Solution, StepFailure> {
        let newton = self.newton;
        // (L D L^T at once only after this solve's own indefinite factors: a solve never
        // spans a checkpoint, so a resumed run factors as the run straight through)
        solver.forget_inertia();
        let mut forces = self.initial_multipliers();
        let mut active_set = self.contact.as_ref().and_then(|c| match c.inside {
            Inside::Fixed => None,
            inside => Some(ActiveSet::new(c, inside == Inside::Closures)),
        });
        let damping = self.damping(state, d.len(), system)?;
        let external_norm = norm(&system.gather(self.external));
        let mut secant =
            Secant::new(newton.updates == Updates::Bfgs && newton.strategy != Strategy::Full);
        // the last correction and the residual it was solved from: a BFGS pair with the next
        let mut last: Option<(Vec<f64>, Vec<f64>)> = None;
        let mut previous_residual = f64::INFINITY;
        let mut eps_displacement = f64::INFINITY;
        // the remaining correction in absolute terms, for the error target
        let mut correction = f64::INFINITY;
        let mut relaxation = Relaxation::new();
        let mut search = line_search::LineSearch::new(self.inertia.is_none());
        let mut predictor = self.predictor.then(|| Predictor::of(&d, system)).flatten();
        for iteration in 0..=newton.max_iterations {
            let refactor = newton.strategy == Strategy::Full
                || (iteration == 0 && (self.factor_first || predictor.is_some()));
            let iterate = (&d[..], predictor.as_ref());
            let (evaluation, mut residual, forces_scale) =
                self.iterate_residual(state, iterate, refactor, system, (&damping, external_norm))?;
            let (rows, settled) = self.contact_rows(&d, system, &mut active_set, &mut forces)?;
            // R alone, without the contact and friction forces: K* is its derivative
            let own = secant.enabled().then(|| residual.clone());
            // sliding friction: known forces from the last solve's normal multipliers
            rows.add_sliding_forces(&forces, &mut residual);
            // the equilibrium residual includes the contact forces of the last solve
            let mut balance = residual.clone();
            add_constraint_forces(&rows, &forces, &mut balance);
            let residual_norm = norm(&balance);
            if !residual_norm.is_finite() {
                return Err(StepFailure(non_finite(system, &balance, &d)));
            }
            let test = Convergence::of(residual_norm, forces_scale, &d, system.diagonal_max);
            self.log_iteration(state.time, iteration, &test, eps_displacement, settled);
            if iteration > 0 {
                let ratio = residual_norm / previous_residual;
                eps_displacement = remaining(eps_displacement, ratio);
                correction = remaining(correction, ratio);
            }
            let within_error = self
                .error_target
                .is_some_and(|target| correction <= target && test.eps_force < newton.tol_force);
            // the active constraints hold within their tolerance too
            if iteration > 0
                && (test.passed(newton, eps_displacement) || within_error)
                && rows.worst_gap <= 1.0
                && settled
            {
                return Ok(self.solution((d, evaluation), &rows, forces, active_set));
            }
            // not the answer: its trial states need not sit beside the factor about to be made
            drop(evaluation);
            if iteration == newton.max_iterations {
                break;
            }
            let iterate = (&mut d[..], &mut forces, &mut active_set);
            if search.search(residual_norm, settled, iterate, system) {
                // the BFGS pair of the whole correction is not the step taken
                last = None;
                continue;
            }
            let ratio = residual_norm / previous_residual;
            let stalled =
                iteration > 0 && self.stalled(iteration, ratio, residual_norm, test.scale);
            if refactor || stalled || !solver.is_factored() {
                if !refactor {
                    // the same state again, now with the tangent assembled
                    self.evaluate(state, &d, Some(&mut *system))?;
                }
                self.factor(system, solver, &damping)?;
                secant.clear();
            } else if let (Some((s, start)), Some(now)) = (last.take(), &own) {
                secant.learn(solver, s, &start, now);
            }
            if settled {
                relaxation.observe(residual_norm);
            } else {
                relaxation.restart();
            }
            let (mut delta, tau) = constrained_solve(solver, &rows, residual, &forces, &secant)?;
            let before = search.watches(iteration).then(|| forces.clone());
            forces = relaxation.relax(&mut delta, &forces, tau);
            if let Some(set) = &mut active_set {
                set.take(&forces);
            }
            counters.iterations += 1;
            predictor = None;
            system.scatter_add(&delta, &mut d);
            search.took(&delta, residual_norm, before);
            (correction, eps_displacement) = correction_sizes(&delta, &d);
            previous_residual = residual_norm;
            last = own.map(|r| (delta, r));
        }
        Err(StepFailure(format!(
            "{NOT_CONVERGED} {} iterations",
            newton.max_iterations
        )))
    }

    /// The converged step at `d` with its `evaluation`: the normal multipliers of `forces`
    /// (the last solve's, on `rows`), the tangential forces of the fixed conditions and the
    /// active set Newton settled on.
    fn solution(
        &self,
        (d, evaluation): (Vec<f64>, Evaluation),
        rows: &Rows,
        mut forces: Vec<f64>,
        active_set: Option<ActiveSet>,
    ) -> Solution {
        let tangential = match (&self.contact, &active_set) {
            (Some(c), None) => rows.tangential_forces(c.tangential, &forces),
            _ => Vec::new(),
        };
        forces.truncate(rows.normal);
        Solution {
            d,
            evaluation,
            forces,
            tangential,
            settled: active_set.map(|set| set.settled()),
        }
    }

    /// The evaluation of the iterate `d`, its residual and force scale (`residual`); the
    /// first iteration of a predicted step linearizes about the step's start and takes the
    /// predictor's jump (`predict`). `refactor`: the tangent assembled into `system` too.
    fn iterate_residual(
        &self,
        state: &State,
        (d, predictor): (&[f64], Option<&Predictor>),
        refactor: bool,
        system: &mut System,
        (damping, external_norm): (&Option<Damping>, f64),
    ) -> Result<(Evaluation, Vec<f64>, f64), StepFailure> {
        let at = predictor.map_or(d, |p| &p.start[..]);
        let evaluation = self.evaluate(state, at, refactor.then_some(&mut *system))?;
        let (mut residual, forces_scale) =
            self.residual(at, &evaluation, system, damping, external_norm);
        if let Some(p) = predictor {
            self.predict(state, p, system, damping, &mut residual)?;
        }
        Ok((evaluation, residual, forces_scale))
    }

    /// Turns the first residual of a predicted step, R_f at its start, into
    /// R_f(0) - K_fp u_p (`Predictor`).
    fn predict(
        &self,
        state: &State,
        p: &Predictor,
        system: &System,
        damping: &Option<Damping>,
        residual: &mut [f64],
    ) -> Result<(), StepFailure> {
        let probe = self.evaluate(state, &p.probe, None)?;
        // (the force scale, which the external norm enters, is not needed)
        let (moved, _) = self.residual(&p.probe, &probe, system, damping, 0.0);
        p.extrapolate(residual, &moved);
        Ok(())
    }

    /// The stiffness-proportional damping matrix of the step (the tangent at the start),
    /// when the Rayleigh coefficient b_R asks for one.
    fn damping(
        &self,
        state: &State,
        dofs: usize,
        system: &mut System,
    ) -> Result<Option<Damping>, StepFailure> {
        match &self.inertia {
            Some(i) if i.rayleigh[1] > 0.0 => {
                self.evaluate(state, &vec![0.0; dofs], Some(&mut *system))?;
                Ok(Some(Damping {
                    values: system.values.clone(),
                }))
            }
            _ => Ok(None),
        }
    }

    /// The contact rows of the iterate `d` and whether the active set is the one the last
    /// solve had: the given set's rows (`Inside::Fixed`), or the statuses `active_set`
    /// decides from the last solve's multipliers, whose rows start from `forces` (theory
    /// 8.3b).
    fn contact_rows(
        &self,
        d: &[f64],
        system: &System,
        active_set: &mut Option<ActiveSet>,
        forces: &mut Vec<f64>,
    ) -> Result<(Rows, bool), StepFailure> {
        let Some(c) = &self.contact else {
            return Ok((Rows::empty(), true));
        };
        // dynamics: v* = c_v D + v_hat at the solve point, for velocity-level stick
        let motion = self.inertia.as_ref().map(|_| {
            let form = self.form;
            (&form.velocity_offset[..], form.damping_coefficient)
        });
        profile::time(Phase::Contact, || match active_set {
            Some(set) => {
                let changed = set.update(c, d, motion);
                let (rows, start) = set.rows(c, d, system, motion)?;
                *forces = start;
                Ok((rows, !changed))
            }
            None => Ok((c.rows(d, system)?, true)),
        })
    }

    /// The multipliers the iteration starts from: the normal ones given, then the fixed
    /// tangential rows' (which start from zero).
    fn initial_multipliers(&self) -> Vec<f64> {
        self.contact.as_ref().map_or(Vec::new(), |c| {
            let fixed = c
                .tangential
                .iter()
                .filter(|t| matches!(t, Tangential::Fixed { .. }))
                .count();
            let mut f = c.forces.clone();
            f.resize(f.len() + fixed, 0.0);
            f
        })
    }

    /// Factors K* from the tangent assembled in `system`: in statics an indefinite tangent is
    /// accepted (past a limit point, theory 5a); in dynamics K* = K + M / (beta h^2) is
    /// positive definite at any step short enough, so an indefinite one fails the step and
    /// the step is cut (accepting it let a crushed element invert on the round bar's mesh
    /// refined 4 times, where the cuts find the step that holds).
    fn factor(
        &self,
        system: &mut System,
        solver: &mut Solver,
        damping: &Option<Damping>,
    ) -> Result<(), StepFailure> {
        // the stiffness alone sets the floor of the force scale (K*'s mass term would make
        // any residual look small next to a rigid motion)
        system.diagonal_max = system.diagonal().fold(0.0, f64::max);
        self.effective(system, damping);
        let result = match self.inertia {
            Some(_) => solver.factor(&system.values),
            None => {
                system.regularize();
                solver.factor_indefinite(&system.values)
            }
        };
        result.map_err(|e| match e {
            SolverError::Singular { index } => StepFailure(format!(
                "{SINGULAR_STIFFNESS} {}: a mechanism or missing supports",
                free_dof(self.model, system, index)
            )),
            SolverError::NotPositiveDefinite { index } if self.inertia.is_some() => {
                StepFailure(format!(
                    "the effective stiffness K* (the mass term plus K_T) is not positive \
                     definite at {}: the tangent stiffness there is more negative than the \
                     mass term holds (a crushed element, a softening material, or a node \
                     without mass: `contact_dynamics = \"mass_redistribution\"` leaves the \
                     contact surfaces' nodes none); a shorter analysis.dt raises the mass term",
                    free_dof(self.model, system, index)
                ))
            }
            SolverError::NotPositiveDefinite { index } => StepFailure(format!(
                "the stiffness matrix is not positive definite at {}: a mechanism, missing \
                 supports or a buckled state",
                free_dof(self.model, system, index)
            )),
            other => StepFailure(other.to_string()),
        })
    }

    /// Whether the iteration should refactor: the residual stops contracting (`ratio` of the
    /// last two), or contracts too slowly to reach the tolerance within the iterations left
    /// (predicted from that ratio). Refactoring cannot help where the factorized matrix would
    /// not change: an elastic tangent on linear kinematics. Said in the `--verbose` log.
    fn stalled(&self, iteration: usize, ratio: f64, residual_norm: f64, scale: f64) -> bool {
        let newton = self.newton;
        let needed = (newton.tol_force * scale / residual_norm).ln() / ratio.ln();
        let left = (newton.max_iterations - iteration) as f64;
        let refactor_helps =
            newton.tangent == Tangent::Consistent || self.geometry == Strain::Finite;
        let stalled = refactor_helps && (ratio > newton.contraction || needed > 0.5 * left);
        if stalled {
            crate::output::console::iteration(format_args!(
                "  newton: the residual contracted by {ratio:.3e}: K* refactored"
            ));
        }
        stalled
    }

    /// The `--verbose` line of an iteration (`console::iteration`): the residual, eps_force
    /// against its tolerance, eps_disp, and with contact whether its statuses settled.
    fn log_iteration(
        &self,
        time: f64,
        iteration: usize,
        test: &Convergence,
        eps_disp: f64,
        settled: bool,
    ) {
        crate::output::console::iteration(format_args!(
            "  newton: step from t = {}, iteration {iteration}: |R| = {:.3e}, eps_force = \
             {:.3e} (tol {:.1e}), eps_disp = {:.3e}{}",
            crate::output::readable(time),
            test.residual_norm,
            test.eps_force,
            self.newton.tol_force,
            eps_disp,
            match (&self.contact, settled) {
                (None, _) => "",
                (Some(_), true) => ", contact settled",
                (Some(_), false) => ", contact statuses changed",
            }
        ));
    }

    /// R on the free DOFs and the force scale of eps_2.
    fn residual(
        &self,
        d: &[f64],
        evaluation: &Evaluation,
        system: &System,
        damping: &Option<Damping>,
        external_norm: f64,
    ) -> (Vec<f64>, f64) {
        let w = self.form.internal_weight;
        let mut total: Vec<f64> = evaluation
            .force
            .iter()
            .zip(self.internal_start)
            .map(|(f1, f0)| w * f1 + (1.0 - w) * f0)
            .collect();
        // over all DOFs: with only prescribed displacements the reactions carry the scale
        let internal_norm = norm(&total);
        let mut inertia_norm = 0.0;
        if let Some(inertia) = &self.inertia {
            let (a, v) = self.form.motion(d);
            let ma = inertia.mass.product(self.model, &a);
            inertia_norm = norm(&ma);
            let [a_r, b_r] = inertia.rayleigh;
            if a_r > 0.0 {
                let mv = inertia.mass.product(self.model, &v);
                for (t, (m_a, m_v)) in total.iter_mut().zip(ma.iter().zip(&mv)) {
                    *t += m_a + a_r * m_v;
                }
            } else {
                for (t, m_a) in total.iter_mut().zip(&ma) {
                    *t += m_a;
                }
            }
            if let Some(dm) = damping {
                let v_free = system.gather(&v);
                let mut kv = vec![0.0; v_free.len()];
                system
                    .pattern
                    .symmetric_product(&dm.values, &v_free, &mut kv);
                let mut kv_all = vec![0.0; v.len()];
                system.scatter_add(&kv, &mut kv_all);
                total
                    .iter_mut()
                    .zip(&kv_all)
                    .for_each(|(t, k)| *t += b_r * k);
            }
        }
        for (t, f) in total.iter_mut().zip(self.external) {
            *t = f - *t;
        }
        let residual = system.gather(&total);
        (residual, external_norm.max(internal_norm).max(inertia_norm))
    }
}
