//! The start of a central-difference run, formed once: the stability limit a fixed step is
//! checked against (with its refusal), the element masses, the initial state, the explicit
//! kernel, the step rule and the subcycling levels. The run (`Explicit::new`) starts from
//! it, and `impact check` and the set-up warnings read the first step, the mass scaling and
//! the levels from the same [`Start`], so what they print is what the run does.

use super::subcycling::{Levels, Subcycler};
use crate::analysis::steppers::clock::Clock;
use crate::analysis::steppers::stable::{checked_step, explicit_clock};
use crate::assembly::explicit::{ExplicitKernel, kernel_for};
use crate::assembly::mass_scaling::MassScalingReport;
use crate::assembly::{ElementMasses, State};
use crate::scene::DynamicAnalysis;
use crate::scene::{InputError, Model};

/// What a central-difference run of a model starts from.
pub struct Start<'a> {
    /// The stability limit of the initial configuration (element eigenvalues), which a
    /// fixed step is checked against; None with the automatic step, which steps on the
    /// kernel's own limit (the run finds dt_crit only to name it in an instability).
    pub dt_crit: Option<f64>,
    pub masses: ElementMasses,
    pub state: State,
    /// The kernel that steps the run.
    pub kernel: Box<dyn ExplicitKernel + 'a>,
    /// The step rule, with the stable step of the initial mesh.
    pub clock: Clock,
    /// Subcycling's levels formed on the initial mesh (None: every element steps together).
    pub(super) subcycler: Option<Subcycler>,
}

impl<'a> Start<'a> {
    /// The start of a run of `model` under `spec`: refuses a fixed dt above the stability
    /// limit (unless the scene asks to watch it blow up) and loads subcycling cannot follow.
    pub fn new(model: &'a Model, spec: &'a DynamicAnalysis) -> Result<Start<'a>, InputError> {
        // an 8x8 eigenproblem per element: a third of the set-up of a 5e5-element mesh
        let dt_crit = match spec.fixed_dt() {
            Some(_) => Some(checked_step(model, spec)?.dt),
            None => None,
        };
        let masses = ElementMasses::new(model)
            .map_err(|err| InputError::new(&model.file, err.to_string()))?;
        let state = State::initial(model);
        let mut kernel = kernel_for(model, spec, &state, &masses);
        let exact = dt_crit.unwrap_or(f64::NAN);
        let mut clock = explicit_clock(model, spec, exact, &state, kernel.as_ref())?;
        let subcycler = match spec.subcycling {
            Some(rule) => {
                let sub = Subcycler::new(model, rule, kernel.as_mut(), &state.coordinates)?;
                clock.take_together(sub.substeps_per_step());
                Some(sub)
            }
            None => None,
        };
        Ok(Start {
            dt_crit,
            masses,
            state,
            kernel,
            clock,
            subcycler,
        })
    }

    /// The first step the run takes: the fixed dt, or the automatic step of the kernel.
    pub fn first_step(&self) -> f64 {
        self.clock.dt0
    }

    /// The mass scaling the run starts with (None: off): the elements below the target on
    /// the initial mesh, per body of `model`.
    pub fn mass_scaling(&self, model: &Model) -> Option<MassScalingReport> {
        let kernel = &self.kernel;
        kernel
            .mass_scaling()
            .map(|s| s.report(model.bodies.len(), |e| kernel.locate(e)))
    }

    /// The subcycling levels the run starts with (None: no subcycling).
    pub fn levels(&self) -> Option<&Levels> {
        self.subcycler.as_ref().map(|s| &s.levels)
    }
}
