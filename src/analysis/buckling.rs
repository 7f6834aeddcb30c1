//! The buckling check of a run (Erklig 2.1.3, DESIGN section 3): the inertia of K_T after each
//! converged state, the linearized buckling load factors of the scene's loads, and the
//! imperfection (a buckling mode added to the coordinates). The numerics are in `stability`.
//!
//! Legend
//! ```text
//! prebuckling state   the small-strain linear-elastic solution for the loads at end_time
//!                     (one solve with K_0 of the initial configuration)
//! lambda_i            load factors of (K_0 + lambda K_sigma) phi = 0 at that state: the
//!                     scene's end loads times lambda_1 are the linearized critical loads
//! ```
//! Contact constraints are not part of the checked tangent (the check sees the bodies with
//! their supports and prescribed displacements only).

use super::loads;
use crate::assembly::{self, State, System};
use crate::element::Geometry;
use crate::scene::Model;
use crate::scene::spec::Tangent;
use crate::solver::Solver;
use crate::stability::{self, InertiaCounter, Mode, StabilityError};

/// The prebuckling state (see the legend).
pub fn prebuckling_state(model: &Model) -> Result<State, StabilityError> {
    let end = match &model.analysis {
        crate::scene::model::Analysis::Static(s) => s.end_time,
        crate::scene::model::Analysis::Dynamic(s) => s.end_time,
    };
    let initial = model.coordinates();
    let mut state = State::initial(model);
    let mut system = System::new(model, &loads::constrained_dofs(model));
    let mut d = vec![0.0; model.dofs()];
    for (dof, value) in loads::prescribed(model, &initial, end) {
        d[dof] = value;
    }
    let linear = |d: &[f64], system: Option<&mut System>| {
        assembly::evaluate(model, &state, d, Geometry::Linear, system, Tangent::Elastic)
    };
    let evaluation = linear(&d, Some(&mut system))?;
    let mut solver = Solver::new(&system.pattern)?;
    solver
        .factor(&system.values)
        .map_err(|_| StabilityError::MaterialStiffness)?;
    let external = loads::external_force(model, &state, &initial, end);
    let mut residual = system.gather(&external);
    residual
        .iter_mut()
        .zip(system.gather(&evaluation.force))
        .for_each(|(r, f)| *r -= f);
    solver.solve(&mut residual);
    system.scatter_add(&residual, &mut d);
    let evaluation = linear(&d, None)?;
    assembly::commit(model, &mut state, &d, evaluation, Geometry::Linear);
    state.time = end;
    Ok(state)
}

/// The lowest `count` linearized buckling modes of the scene's end loads (at the prebuckling
/// state), ascending load factors.
pub fn linear_modes(model: &Model, count: usize) -> Result<Vec<Mode>, StabilityError> {
    let state = prebuckling_state(model)?;
    let mut system = System::new(model, &loads::constrained_dofs(model));
    stability::eigen_buckling(model, &state, &mut system, count)
}

/// The lowest `count` buckling modes at a committed state of a run.
pub fn modes_at(model: &Model, state: &State, count: usize) -> Result<Vec<Mode>, StabilityError> {
    let mut system = System::new(model, &loads::constrained_dofs(model));
    stability::eigen_buckling(model, state, &mut system, count)
}

/// The inertia check of a run: K_T at each committed state, its negative pivots counted.
pub struct InertiaCheck {
    system: System,
    counter: InertiaCounter,
}

impl InertiaCheck {
    pub fn new(model: &Model) -> Result<InertiaCheck, StabilityError> {
        let system = System::new(model, &loads::constrained_dofs(model));
        let counter = InertiaCounter::new(&system.pattern)?;
        Ok(InertiaCheck { system, counter })
    }

    /// Negative pivots of K_T (no mass) at the committed state.
    pub fn negative_pivots(
        &mut self,
        model: &Model,
        state: &State,
    ) -> Result<usize, StabilityError> {
        stability::assemble_tangent(model, state, &mut self.system)?;
        Ok(self.counter.negative_pivots(&self.system.values)?)
    }
}
