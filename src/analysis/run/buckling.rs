//! The buckling check of a run (Erklig 2.1.3): the inertia of K_T after each
//! converged state, the linearized buckling load factors of the scene's loads, and the
//! imperfection (a buckling mode added to the coordinates). The numerics are in the crate's `buckling` module.
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

use super::record;
use crate::analysis::steppers::loads;
use crate::analysis::summary::BucklingSummary;
use crate::assembly::{self, State, StepIncrement, System};
use crate::buckling::{self, BucklingError, InertiaCounter, Mode};
use crate::element::Strain;
use crate::output::OutputError;
use crate::output::vtk::{Fields, Series};
use crate::scene::Model;
use crate::scene::spec::OnCritical;
use crate::scene::spec::Tangent;
use crate::solver::Solver;
use std::path::{Path, PathBuf};

/// The prebuckling state (see the legend).
pub fn prebuckling_state(model: &Model) -> Result<State, BucklingError> {
    let end = match &model.analysis {
        crate::scene::model::Analysis::Static(s) => s.end_time,
        crate::scene::model::Analysis::Dynamic(s) => s.end_time,
    };
    let initial = model.coordinates();
    let mut state = State::initial(model);
    let mut system = System::new(model, &model.constrained_dofs());
    let mut d = vec![0.0; model.dofs()];
    for (dof, value) in loads::prescribed(model, &initial, end) {
        d[dof] = value;
    }
    let linear = |d: &[f64], system: Option<&mut System>| {
        // the linear prebuckling state: no time step (rate-dependent laws at no rate)
        assembly::evaluate(
            model,
            &state,
            StepIncrement {
                d,
                dt: f64::INFINITY,
                geometry: Strain::Small,
            },
            system,
            Tangent::Elastic,
        )
    };
    let evaluation = linear(&d, Some(&mut system))?;
    let mut solver = Solver::new(&system.pattern)?;
    solver
        .factor(&system.values)
        .map_err(|_| BucklingError::MaterialStiffness)?;
    let external = loads::external_force(model, &state, &initial, end);
    let mut residual = system.gather(&external);
    residual
        .iter_mut()
        .zip(system.gather(&evaluation.force))
        .for_each(|(r, f)| *r -= f);
    solver.solve(&mut residual);
    system.scatter_add(&residual, &mut d);
    let evaluation = linear(&d, None)?;
    assembly::commit(model, &mut state, &d, evaluation, Strain::Small);
    state.time = end;
    Ok(state)
}

/// The lowest `count` linearized buckling modes of the scene's end loads (at the prebuckling
/// state), ascending load factors.
pub fn linear_modes(model: &Model, count: usize) -> Result<Vec<Mode>, BucklingError> {
    let state = prebuckling_state(model)?;
    let mut system = System::new(model, &model.constrained_dofs());
    buckling::eigen_buckling(model, &state, &mut system, count)
}

/// The lowest `count` buckling modes at a committed state of a run.
pub fn modes_at(model: &Model, state: &State, count: usize) -> Result<Vec<Mode>, BucklingError> {
    let mut system = System::new(model, &model.constrained_dofs());
    buckling::eigen_buckling(model, state, &mut system, count)
}

/// The inertia check of a run: K_T at each committed state, its negative pivots counted.
pub struct InertiaCheck {
    system: System,
    counter: InertiaCounter,
}

impl InertiaCheck {
    pub fn new(model: &Model) -> Result<InertiaCheck, BucklingError> {
        let system = System::new(model, &model.constrained_dofs());
        let counter = InertiaCounter::new(&system.pattern)?;
        Ok(InertiaCheck { system, counter })
    }

    /// The eigenvector of the K_T last counted whose eigenvalue lies nearest zero, on all
    /// DOFs (zero on the prescribed ones), scaled to a largest nodal value of 1; None when it
    /// cannot be found. Where the count has just changed, the critical mode.
    pub fn critical_mode(&self, dofs: usize) -> Option<Vec<f64>> {
        // inverse iteration: 30 steps take a neighbour's share down by (lambda_1 /
        // lambda_2)^30, 1e-9 for a ratio of 1/2 (a column's first two modes: 1/4)
        let free = self.counter.nearly_null(30)?;
        let mut shape = vec![0.0; dofs];
        self.system.scatter_add(&free, &mut shape);
        let largest = (shape.chunks_exact(2))
            .map(|c| c[0].hypot(c[1]))
            .fold(0.0, f64::max);
        (largest > 0.0).then(|| shape.iter().map(|v| v / largest).collect())
    }

    /// Negative pivots of K_T (no mass) at the committed state, its diagonal raised by the
    /// share `held` as the run raises its own (a body held by its contact alone, theory 5c:
    /// its rigid motion's pivot is round-off otherwise, of either sign).
    pub fn negative_pivots(
        &mut self,
        model: &Model,
        state: &State,
        held: f64,
    ) -> Result<usize, BucklingError> {
        buckling::assemble_tangent(model, state, &mut self.system)?;
        self.system.held = held;
        self.system.regularize();
        Ok(self.counter.negative_pivots(&self.system.values)?)
    }
}

/// The check of a run: set up from `[analysis.buckling]`, fed every committed state.
pub struct Monitor {
    check: Option<InertiaCheck>,
    on_critical: OnCritical,
    /// The run's folder (the critical mode's frame goes there).
    dir: PathBuf,
    pub summary: BucklingSummary,
    /// The diagonal shift the count's baseline (`initial_negative_pivots`) was taken with.
    baseline_held: f64,
}

impl Monitor {
    /// None without `[analysis.buckling]`. Computes the requested modes and writes them into
    /// `dir` (NAME_buckling.pvd).
    pub fn new(model: &Model, dir: &Path) -> Result<Option<Monitor>, MonitorError> {
        let Some(spec) = model.analysis.buckling() else {
            return Ok(None);
        };
        let mut summary = BucklingSummary::default();
        if spec.modes > 0 {
            let modes = linear_modes(model, spec.modes)?;
            summary.load_factors = modes.iter().map(|m| m.lambda).collect();
            summary.critical_load_factor = summary.load_factors.first().copied();
            write_modes(model, &modes, dir)?;
        }
        let check = if spec.check {
            Some(InertiaCheck::new(model)?)
        } else {
            None
        };
        Ok(Some(Monitor {
            check,
            on_critical: spec.on_critical,
            dir: dir.to_path_buf(),
            summary,
            baseline_held: 0.0,
        }))
    }

    /// Goes on from a checkpoint's `summary`, its baseline taken with the shift `held` the
    /// resumed run factors with.
    pub fn resume(&mut self, summary: BucklingSummary, held: f64) {
        self.summary = summary;
        self.baseline_held = held;
    }

    /// Checks a committed state, at the load factor `load_factor` on an arc-length path:
    /// the negative-pivot count (None when `check` is off), and whether the run should stop
    /// here. Where the count first changes, the critical mode is written as the one frame of
    /// NAME_critical.pvd at that time. `held`: the run's diagonal shift (`System::held`);
    /// where it changes (a body found held by its contact in the first increment), the
    /// count's baseline is taken again, with the tangent as the run now factors it.
    pub fn observe(
        &mut self,
        model: &Model,
        state: &State,
        load_factor: Option<f64>,
        held: f64,
    ) -> Result<(Option<usize>, bool), MonitorError> {
        let Some(check) = &mut self.check else {
            return Ok((None, false));
        };
        let count = check.negative_pivots(model, state, held)?;
        let s = &mut self.summary;
        if held != self.baseline_held {
            self.baseline_held = held;
            s.initial_negative_pivots = Some(count);
        }
        let initial = *s.initial_negative_pivots.get_or_insert(count);
        s.final_negative_pivots = Some(count);
        let mut stop = false;
        if count != initial && s.inertia_change_time.is_none() {
            s.inertia_change_time = Some(state.time);
            s.negative_pivots_at_change = Some(count);
            s.load_factor_at_change = load_factor;
            stop = self.on_critical == OnCritical::Stop;
            s.stopped = stop;
            if let Some(shape) = check.critical_mode(model.dofs()) {
                let name = format!("{}_critical", model.name);
                write_shapes(model, &name, &[(state.time, &shape)], &self.dir)?;
                s.critical_mode = Some(format!("{name}.pvd"));
            }
        }
        Ok((Some(count), stop))
    }
}

#[derive(Debug, thiserror::Error)]
pub enum MonitorError {
    #[error("buckling modes: {0}")]
    Modes(#[from] BucklingError),
    #[error("{0}")]
    Output(#[from] OutputError),
}

/// Writes the modes as the frames of DIR/NAME_buckling.pvd: frame i (its "time") is mode i,
/// the points the reference configuration and the `displacement` field the mode shape
/// (largest nodal value 1). A mode's amplitude is arbitrary, so the points do not move by
/// it: Warp By Vector shows the shape at the scale the viewer picks.
pub fn write_modes(model: &Model, modes: &[Mode], dir: &Path) -> Result<(), OutputError> {
    let frames: Vec<(f64, &[f64])> = (modes.iter().enumerate())
        .map(|(i, mode)| ((i + 1) as f64, &mode.shape[..]))
        .collect();
    write_shapes(model, &format!("{}_buckling", model.name), &frames, dir)
}

/// Writes shapes (all DOFs) as the frames of DIR/NAME.pvd at their times: the points the
/// reference configuration, the `displacement` field the shape.
fn write_shapes(
    model: &Model,
    name: &str,
    frames: &[(f64, &[f64])],
    dir: &Path,
) -> Result<(), OutputError> {
    std::fs::create_dir_all(dir).map_err(|e| OutputError::io(dir, "create folder", e))?;
    let mut series = Series::create(dir, name, model.output.compression)?;
    let grid = record::grid(model);
    let points = grid.points.len();
    let cells = grid.cells();
    let zeros2 = vec![[0.0; 2]; points];
    let zeros = vec![0.0; points];
    let cell_zeros = vec![0.0; cells];
    let stress = vec![[0.0; 6]; cells];
    let body_ids = record::body_ids(model);
    for (time, values) in frames {
        let shape: Vec<[f64; 2]> = values.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
        let fields = Fields {
            displacement: &shape,
            velocity: &zeros2,
            acceleration: &zeros2,
            contact_force: &zeros2,
            gap: &zeros,
            contact_status: &zeros,
            reference_coordinates: &grid.points,
            stress: &stress,
            von_mises: &cell_zeros,
            eq_plastic_strain: &cell_zeros,
            pressure: &cell_zeros,
            temperature: None,
            body: Some(&body_ids),
            nodal: None,
            traction: None,
            strain: None,
        };
        series.write_frame(*time, &grid, &fields)?;
    }
    Ok(())
}

/// The model with `amplitude` times mode `mode` of the end loads added to its initial
/// coordinates (`[analysis.buckling.imperfection]`); None without an imperfection.
pub fn with_imperfection(model: &Model) -> Result<Option<Model>, BucklingError> {
    let Some(imperfection) = model
        .analysis
        .buckling()
        .and_then(|b| b.imperfection.as_ref())
    else {
        return Ok(None);
    };
    let modes = linear_modes(model, imperfection.mode)?;
    let mode = modes
        .get(imperfection.mode - 1)
        .ok_or(BucklingError::NoMode)?;
    let mut imperfect = model.clone();
    for body in &mut imperfect.bodies {
        let offset = body.node_offset;
        for (i, x) in body.mesh.nodes.iter_mut().enumerate() {
            x[0] += imperfection.amplitude * mode.shape[2 * (offset + i)];
            x[1] += imperfection.amplitude * mode.shape[2 * (offset + i) + 1];
        }
    }
    Ok(Some(imperfect))
}
