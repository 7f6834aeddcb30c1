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
use super::newton::Counters;
use super::{About, Report, Resume, RowFeatures, RunFeatures, StepError, Stepper, loads};
use crate::analysis::summary::ArcLengthSummary;
use crate::assembly::{self, Evaluation, State, StepIncrement, System};
use crate::contact::ContactState;
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
}

/// Why an assembly and factorization failed: a singular tangent (a mechanism, or a limit
/// point met exactly) or another failure (an inverted element), in the user's words.
struct Failure {
    singular: bool,
    message: String,
}

/// A converged increment.
struct Converged {
    du: Vec<f64>,
    dlambda: f64,
    evaluation: Evaluation,
    iterations: usize,
    /// Taken at lambda = 1 (load control), not on its arc.
    landing: bool,
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
            system,
            solver,
        })
    }

    /// The pseudo time of an arc `arc`: the first increment's is its share of end_time.
    fn pseudo_time(&self, arc: f64) -> f64 {
        self.spec.end_time * self.first_share * arc / self.first_arc
    }

    /// Assembles the tangent (`tangent`) at the increment `d` (all DOFs) and factors it; the
    /// evaluation's internal force comes back.
    fn factor_at(&mut self, d: &[f64], dt: f64, tangent: Tangent) -> Result<Evaluation, Failure> {
        let step = StepIncrement {
            d,
            dt,
            geometry: self.spec.geometry,
        };
        let evaluation = assembly::evaluate(
            self.model,
            &self.state,
            step,
            Some(&mut self.system),
            tangent,
        )
        .map_err(|e| Failure {
            singular: false,
            message: e.to_string(),
        })?;
        self.solver
            .factor_indefinite_down_to(&self.system.values, NEAR_SINGULAR)
            .map_err(|e| match e {
                SolverError::Singular { index } => Failure {
                    singular: true,
                    message: format!(
                        "the stiffness matrix is singular at {}: a mechanism or missing supports",
                        super::newton::free_dof(self.model, &self.system, index)
                    ),
                },
                other => Failure {
                    singular: false,
                    message: other.to_string(),
                },
            })?;
        Ok(evaluation)
    }

    /// K^-1 b with the factored tangent.
    fn solve(&mut self, b: &[f64]) -> Vec<f64> {
        let mut x = b.to_vec();
        self.solver.solve(&mut x);
        x
    }

    /// One increment on the arc `arc` (the first: `None`, 1 / steps of the load): Newton on
    /// (Delta u, Delta lambda) from the tangent predictor; `landing`: at lambda = 1 instead
    /// (Newton on Delta u alone, load control).
    fn increment(
        &mut self,
        arc: Option<f64>,
        landing: bool,
        counters: &mut Counters,
    ) -> Result<Converged, String> {
        let newton = self.spec.newton.clone();
        let q = {
            let end = self.spec.end_time;
            let all = loads::external_force(self.model, &self.state, &self.initial, end);
            self.system.gather(&all)
        };
        let q_norm = norm(&q);
        if q_norm == 0.0 {
            return Err("the loads vanish on the free DOFs: nothing to scale".into());
        }
        let zero = vec![0.0; self.model.dofs()];
        let nominal = self.spec.end_time / self.spec.steps as f64;
        if !std::mem::take(&mut self.factored_at_start) {
            self.factor_at(&zero, nominal, newton.tangent)
                .map_err(|f| f.message)?;
        }
        let mut ut = self.solve(&q);
        let arc = arc.unwrap_or_else(|| norm(&ut) * self.first_share);
        let rising = dot(&self.direction, &ut) >= 0.0;
        let step = arc / norm(&ut);
        let mut dlambda = if landing {
            1.0 - self.factor
        } else if rising {
            step
        } else {
            -step
        };
        let mut du: Vec<f64> = ut.iter().map(|v| dlambda * v).collect();
        let dt = if self.arc.is_some() {
            self.pseudo_time(arc)
        } else {
            nominal * self.first_share * self.spec.steps as f64
        };
        for iteration in 1..=newton.max_iterations {
            counters.iterations += 1;
            let mut d = zero.clone();
            self.system.scatter_add(&du, &mut d);
            // a singular consistent tangent at an iterate (a plastic zone past its collapse
            // mechanism, overshot) is passed with the elastic moduli and K_sigma for that
            // iteration, not cut
            let evaluation = match self.factor_at(&d, dt, newton.tangent) {
                Err(f) if f.singular && newton.tangent == Tangent::Consistent => {
                    self.factor_at(&d, dt, Tangent::ElasticGeometric)
                }
                other => other,
            }
            .map_err(|f| f.message)?;
            let lambda = self.factor + dlambda;
            let internal = self.system.gather(&evaluation.force);
            let r: Vec<f64> = q
                .iter()
                .zip(&internal)
                .map(|(q, f)| lambda * q - f)
                .collect();
            let scale = q_norm * lambda.abs().max(dlambda.abs()).max(1e-3);
            if norm(&r) <= newton.tol_force * scale {
                return Ok(Converged {
                    du,
                    dlambda,
                    evaluation,
                    iterations: iteration,
                    landing,
                });
            }
            let du_r = self.solve(&r);
            ut = self.solve(&q);
            let dl = if landing {
                0.0
            } else {
                constrained_step(&du, &du_r, &ut, arc)
            };
            for ((u, r), t) in du.iter_mut().zip(&du_r).zip(&ut) {
                *u += r + dl * t;
            }
            dlambda += dl;
        }
        Err(format!(
            "no convergence in {} iterations",
            newton.max_iterations
        ))
    }

    /// Commits a converged increment on the arc `arc`.
    fn commit(&mut self, c: Converged, arc: f64) {
        let mut d = vec![0.0; self.model.dofs()];
        self.system.scatter_add(&c.du, &mut d);
        let force = c.evaluation.force.clone();
        assembly::commit(
            self.model,
            &mut self.state,
            &d,
            c.evaluation,
            self.spec.geometry,
        );
        if self.arc.is_none() {
            self.first_arc = arc;
        }
        let length = norm(&c.du);
        self.last_step = self.pseudo_time(if c.landing { length } else { arc });
        self.state.time += self.last_step;
        self.factor += c.dlambda;
        self.peak = self.peak.max(self.factor);
        let stiffness = self.first_share / self.first_arc;
        if c.dlambda.abs() < FLAT * stiffness * arc {
            self.flat_in_a_row += 1;
        } else {
            self.flat_in_a_row = 0;
        }
        self.collapsed = self.flat_in_a_row >= FLAT_INCREMENTS;
        self.energies.external_work += super::trapezoid_work(&d, &force, &self.last_force);
        self.energies.internal = self.state.internal_work - self.state.plastic_work;
        self.energies.plastic_work = self.state.plastic_work;
        self.last_force = force;
        self.direction = c.du;
        let target = self.settings.iterations as f64;
        let grow = (target / c.iterations as f64).sqrt().clamp(0.5, 2.0);
        self.arc = Some((arc * grow).min(LONGEST * self.first_arc));
        self.increments += 1;
    }
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

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

impl Stepper for ArcLength<'_> {
    fn start(&mut self) -> Result<(), String> {
        Ok(())
    }

    fn done(&self) -> bool {
        self.factor >= 1.0 - 1e-12
            || self.increments >= self.settings.max_increments
            || self.collapsed
    }

    fn advance(&mut self, counters: &mut Counters) -> Result<(), StepError> {
        loop {
            let arc = self.arc;
            // an arc that carries the path past the scene's load rising is taken again
            // to land on it
            let attempt = self.increment(arc, false, counters).and_then(|c| {
                if c.dlambda > 0.0 && self.factor + c.dlambda > 1.0 {
                    self.increment(arc, true, counters)
                } else {
                    Ok(c)
                }
            });
            match attempt {
                Ok(converged) => {
                    let arc = arc.unwrap_or_else(|| norm(&converged.du));
                    self.commit(converged, arc);
                    self.cuts_in_a_row = 0;
                    // the next predictor's tangent, factored now (where there is a next
                    // increment): singular, the path ends
                    if !self.done() {
                        let zero = vec![0.0; self.model.dofs()];
                        let nominal = self.spec.end_time / self.spec.steps as f64;
                        match self.factor_at(&zero, nominal, self.spec.newton.tangent) {
                            Ok(_) => self.factored_at_start = true,
                            Err(f) if f.singular => self.collapsed = true,
                            Err(_) => {}
                        }
                    }
                    return Ok(());
                }
                Err(reason) => {
                    self.cuts_in_a_row += 1;
                    counters.cuts += 1;
                    if self.cuts_in_a_row > self.spec.newton.max_cuts {
                        return Err(StepError::diverged(format!(
                            "arc-length increment {} from load factor {} did not converge \
                             after {} cuts: {reason}",
                            self.increments + 1,
                            readable(self.factor),
                            self.spec.newton.max_cuts
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
