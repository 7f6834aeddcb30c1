//! What a run writes: VTK frames (every `frame_every` steps, and the last), history.csv rows
//! at the scene's cadence (`output::thinning`: with the extremes between them, and at every
//! frame), summary.json at the end (also after a failure).

use super::columns::{
    body_columns, bulk_viscosity_column, columns, error_column, friction_column, hourglass_column,
    load_factor_column, mass_scaling_columns, pair_columns,
};
use super::contact_record::{ContactCarry, ContactRecord};
use super::frame::{PointArrays, cell_fields, point_body_ids};
pub use super::probes::Snapshot;
use super::probes::{is_reaction, probe_value, reactions};
use crate::analysis::steppers::energies::{Energies, Motion};
use crate::analysis::summary::Summary;
use crate::assembly::State;
use crate::contact::Friction;
use crate::contact::Interfaces;
use crate::contact::fold_passes;
use crate::contact::{ContactPair, ContactState, Master};
use crate::mesh::Cells;
use crate::output::history::History;
use crate::output::thinning::{Thinning, Window};
use crate::output::vtk::{Fields, Grid, Polyline, Series};
use crate::output::{OutputError, write_atomic};
use crate::scene::Model;
use crate::scene::model::Probe;
use crate::scene::spec::FramePoints;
use std::path::{Path, PathBuf};

pub struct Recorder {
    dir: PathBuf,
    /// The cells, and the points of the frame being written.
    grid: Grid,
    /// The initial coordinates (the `reference_coordinates` array).
    reference: Vec<[f64; 2]>,
    /// Per cell of `grid`, its body's index (the `body` cell array), and per point.
    body_ids: Vec<i64>,
    point_body_ids: Vec<i64>,
    /// The contact surfaces, for the frames' tractions (None without contact pairs).
    interfaces: Option<Interfaces>,
    /// Where an obstacle moves and frames are written: the obstacle frames written (time,
    /// file), each frame adding one; None otherwise.
    obstacle_frames: Option<Vec<(f64, String)>>,
    series: Option<Series>,
    history: History,
    /// Which steps' rows history.csv gets.
    thinning: Thinning,
    frame_every: usize,
    steps_since_frame: usize,
    last_frame_time: Option<f64>,
    /// Whether history.csv has the `tangent_negative_pivots` column.
    pivots_column: bool,
    /// Its value for the next row (the buckling check sets it before each step is recorded).
    pub negative_pivots: Option<usize>,
    /// Whether history.csv ends with the `hourglass_energy` column (quadrature `reduced`).
    hourglass_column: bool,
    /// Its value for the next row (the reduced explicit kernel sets it before each step).
    pub hourglass_energy: f64,
    /// Whether history.csv has the `error_estimate` column (implicit Newmark family).
    error_column: bool,
    /// Its value for the next row (the implicit stepper's last estimate).
    pub error_estimate: f64,
    /// The mass the mass scaling has added, for the next row's `added_mass` (the column is
    /// there with `analysis.mass_scaling`).
    pub added_mass: f64,
    /// The arc-length path's load factor for the next row (`load_factor`, arc length only).
    pub load_factor: f64,
    /// The length of the step the next row ends (column `dt`; 0 on the first row).
    pub step_length: f64,
    /// Each body's kinetic energy for the next row (the per-body columns of a model of two
    /// bodies or more; `body_columns`).
    pub body_kinetic: Vec<f64>,
    /// The probes' values in the last row written (summary.json `probes`).
    last_probes: Vec<f64>,
    /// Point probes the stepper has answered from its own point values for the next row (an
    /// explicit kernel's arrays, so the state's points need no copy), by probe; None (or
    /// missing): read from the state.
    pub point_probes: Vec<Option<f64>>,
    /// The averaged contact forces, the widest contact, the deepest node (with contact).
    pub contact: Option<ContactRecord>,
}

impl Recorder {
    /// Creates the output folder, the .pvd series and history.csv with its header; the
    /// contact forces are averaged over `window` (`contact_record::window`).
    pub fn create(
        model: &Model,
        dir: &Path,
        frames: bool,
        window: Option<f64>,
    ) -> Result<Recorder, OutputError> {
        std::fs::create_dir_all(dir).map_err(|source| OutputError::Io {
            path: dir.to_path_buf(),
            action: "create folder",
            source,
        })?;
        let wanted = model.output.frame_every() > 0 || !model.output.frame_times.is_empty();
        let mut obstacle_frames = None;
        let series = if frames && wanted {
            let mut series = Series::create(dir, &model.name, model.output.compression)?;
            obstacle_frames = write_obstacles(model, dir, None)?;
            // frames are encoded and written off the stepping thread
            series.set_background(true);
            Some(series)
        } else {
            None
        };
        let (columns, pivots_column) = columns(model);
        let history = History::create(&dir.join("history.csv"), &columns)?;
        Ok(Recorder {
            dir: dir.to_path_buf(),
            grid: grid(model),
            body_ids: body_ids(model),
            point_body_ids: point_body_ids(model),
            interfaces: (!model.contacts.is_empty()).then(|| model.interfaces()),
            obstacle_frames,
            reference: model.coordinates(),
            series,
            history,
            thinning: Thinning::new(model.history_cadence()),
            frame_every: model.output.frame_every(),
            steps_since_frame: 0,
            last_frame_time: None,
            pivots_column,
            negative_pivots: None,
            hourglass_column: hourglass_column(model),
            hourglass_energy: 0.0,
            error_column: error_column(model),
            error_estimate: 0.0,
            added_mass: 0.0,
            load_factor: 0.0,
            step_length: 0.0,
            body_kinetic: Vec::new(),
            last_probes: Vec::new(),
            point_probes: Vec::new(),
            contact: contact_record(
                model,
                ContactCarry {
                    window,
                    ..ContactCarry::default()
                },
            ),
        })
    }

    /// Where the output stands, for a checkpoint.
    pub fn position(&self) -> Result<RecorderPosition, OutputError> {
        // the frames the checkpoint lists are on disk before it is written
        if let Some(series) = &self.series {
            series.flush()?;
        }
        Ok(RecorderPosition {
            series: self.series.as_ref().map(Series::position),
            history_bytes: self.history.byte_len()?,
            history_window: self.thinning.window().clone(),
            steps_since_frame: self.steps_since_frame,
            last_frame_time: self.last_frame_time,
            negative_pivots: self.negative_pivots,
            probes: self.last_probes.clone(),
            contact: self.contact.as_ref().map(|c| c.carry.clone()),
        })
    }

    /// Continues the output of a checkpointed run in `dir`: history.csv cut back to its
    /// rows at the checkpoint, frames after it removed, the .pvd listing the rest.
    pub fn resume(
        model: &Model,
        dir: &Path,
        position: RecorderPosition,
    ) -> Result<Recorder, OutputError> {
        let mut obstacle_frames = None;
        let series = match position.series {
            Some(p) => {
                let mut series = Series::resume(dir, &model.name, model.output.compression, p)?;
                obstacle_frames = write_obstacles(model, dir, position.last_frame_time)?;
                series.set_background(true);
                Some(series)
            }
            _ => None,
        };
        let (columns, pivots_column) = columns(model);
        let history = History::resume(&dir.join("history.csv"), &columns, position.history_bytes)?;
        Ok(Recorder {
            dir: dir.to_path_buf(),
            grid: grid(model),
            body_ids: body_ids(model),
            point_body_ids: point_body_ids(model),
            interfaces: (!model.contacts.is_empty()).then(|| model.interfaces()),
            obstacle_frames,
            reference: model.coordinates(),
            series,
            history,
            thinning: Thinning::resume(model.history_cadence(), position.history_window),
            frame_every: model.output.frame_every(),
            steps_since_frame: position.steps_since_frame,
            last_frame_time: position.last_frame_time,
            pivots_column,
            negative_pivots: position.negative_pivots,
            hourglass_column: hourglass_column(model),
            hourglass_energy: 0.0,
            error_column: error_column(model),
            error_estimate: 0.0,
            added_mass: 0.0,
            load_factor: 0.0,
            step_length: 0.0,
            body_kinetic: Vec::new(),
            last_probes: position.probes,
            point_probes: Vec::new(),
            contact: contact_record(model, position.contact.unwrap_or_default()),
        })
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Records a converged step: a history row, and a frame when due (`force_frame` for the
    /// first and last); the contact status (None before the first step) fills the contact
    /// columns and fields.
    pub fn step(
        &mut self,
        model: &Model,
        snapshot: Snapshot,
        force_frame: bool,
    ) -> Result<(), OutputError> {
        let Snapshot {
            state,
            motion,
            energies,
            contact,
            frame_contact,
        } = snapshot;
        let start = std::time::Instant::now();
        let mut row = vec![
            state.time,
            energies.kinetic,
            energies.internal,
            energies.plastic_work,
            energies.external_work,
            energies.contact_work,
            self.step_length,
        ];
        let pairs = &model.contacts;
        let friction: Vec<bool> = pairs
            .iter()
            .filter(|c| c.balances.is_none())
            .map(|c| c.options.friction != Friction::None)
            .collect();
        let forces = match contact {
            Some(c) => fold_passes(pairs, &c.pair_forces()),
            None => vec![0.0; friction.len()],
        };
        let averages = match &mut self.contact {
            Some(record) => record.row(
                model,
                (state.time, self.step_length),
                (&forces, contact),
                || state.positions(model.analysis.geometry()),
            ),
            None => Vec::new(),
        };
        match contact {
            Some(c) => {
                row.extend(forces);
                row.extend(
                    fold_passes(pairs, &c.pair_tangential_forces())
                        .into_iter()
                        .zip(&friction)
                        .filter_map(|(f, on)| on.then_some(f)),
                );
            }
            None => row.extend(std::iter::repeat_n(
                0.0,
                friction.len() + friction.iter().filter(|f| **f).count(),
            )),
        }
        let reaction = if model.probes.iter().any(|p| is_reaction(p.quantity)) {
            Some(reactions(model, state, motion))
        } else {
            None
        };
        self.last_probes.clear();
        let answered = &self.point_probes;
        self.last_probes
            .extend(model.probes.iter().enumerate().map(|(i, p)| {
                match answered.get(i).copied().flatten() {
                    Some(value) => value,
                    None => probe_value(model, &snapshot, reaction.as_deref(), &self.reference, p),
                }
            }));
        row.extend_from_slice(&self.last_probes);
        if self.pivots_column {
            row.push(self.negative_pivots.map_or(f64::NAN, |n| n as f64));
        }
        if self.hourglass_column {
            row.push(self.hourglass_energy);
        }
        if self.error_column {
            row.push(self.error_estimate);
        }
        if !model.contacts.is_empty() {
            row.push(contact.map_or(0.0, |c| c.penetration));
        }
        row.extend(averages);
        self.push_feature_columns(model, state, energies, &mut row);
        if pair_columns(model) {
            row.extend(pair_energies(model, contact));
        }
        row.extend(obstacle_values(model, state, contact));
        let frame = self.frame_due(model, state.time, force_frame, 1);
        let history = &mut self.history;
        self.thinning
            .offer(&row, force_frame || frame, |r| history.append(r))?;
        crate::profile::add(crate::profile::Phase::Output, start);
        self.steps_since_frame += 1;
        if frame {
            self.frame(model, state, motion, frame_contact)?;
        }
        Ok(())
    }

    /// The row's columns after the contact averages, those of the features the scene
    /// turned on (columns::columns' order).
    fn push_feature_columns(
        &self,
        model: &Model,
        state: &State,
        energies: &Energies,
        row: &mut Vec<f64>,
    ) {
        if bulk_viscosity_column(model) {
            row.push(energies.bulk_viscosity_work);
        }
        if mass_scaling_columns(model) {
            row.push(energies.mass_scaling_loss);
            row.push(self.added_mass);
        }
        if model.analysis.ale().is_some() {
            row.push(energies.remap_loss);
        }
        if friction_column(model) {
            row.push(energies.friction_work);
        }
        if load_factor_column(model) {
            row.push(self.load_factor);
        }
        if body_columns(model) {
            for (body, kinetic) in state.bodies.iter().zip(&self.body_kinetic) {
                row.extend([
                    *kinetic,
                    body.work.internal - body.work.plastic,
                    body.work.plastic,
                ]);
            }
        }
    }

    /// Whether recording the step that ends at `time` reads the element stresses: a stress
    /// probe, or a frame due. Call it before `step`.
    pub fn reads_stresses(&self, model: &Model, time: f64, force_frame: bool) -> bool {
        let unanswered = |(i, p): (usize, &Probe)| {
            !p.quantity.is_nodal() && self.point_probes.get(i).copied().flatten().is_none()
        };
        model.probes.iter().enumerate().any(unanswered)
            || (self.series.is_some() && self.frame_due(model, time, force_frame, 1))
    }

    /// `pending`: steps not yet counted in `steps_since_frame`. A listed frame time is due at
    /// the step that ends there, or (a step that jumps over it: fixed central-difference steps,
    /// static increments) at the first step past it; `step_length` is the step's length.
    fn frame_due(&self, model: &Model, time: f64, force_frame: bool, pending: usize) -> bool {
        let tolerance = 1e-9 * time.abs().max(1e-300);
        let previous = time - self.step_length;
        // the listed times within the tolerance of `time`, or inside the step just taken
        let listed = model.output.any_frame_in(
            (time - tolerance).min(previous + tolerance),
            time + tolerance,
            |t| (t - time).abs() <= tolerance || (t < time && t > previous + tolerance),
        );
        force_frame
            || listed
            || (self.frame_every > 0 && self.steps_since_frame + pending >= self.frame_every)
    }

    /// Writes a frame of the state unless one was written at this time already.
    pub fn frame(
        &mut self,
        model: &Model,
        state: &State,
        motion: &Motion,
        contact: Option<&ContactState>,
    ) -> Result<(), OutputError> {
        let Some(series) = self.series.as_mut() else {
            return Ok(());
        };
        if self.last_frame_time == Some(state.time) {
            return Ok(());
        }
        let _timer = crate::profile::Timer::new(crate::profile::Phase::Output);
        let cells = cell_fields(model, state);
        let vectors =
            |v: &[f64]| -> Vec<[f64; 2]> { v.chunks_exact(2).map(|c| [c[0], c[1]]).collect() };
        let n = state.coordinates.len();
        let positions = state.positions(model.analysis.geometry());
        let (contact_force, gap, status) = match contact {
            Some(c) => {
                let pairs = c.placed(&model.contacts, state.time);
                let nodal = c.nodal_status(&pairs, &positions);
                (c.nodal_forces(&pairs, &positions), nodal.gap, nodal.status)
            }
            None => (vec![0.0; 2 * n], vec![0.0; n], vec![0.0; n]),
        };
        // the obstacles where the run has them (a run without contact: their motions alone)
        let at_rest = ContactState::new(&[]);
        let placing = contact.unwrap_or(&at_rest);
        if let Some(interfaces) = self.interfaces.as_mut() {
            placing.place(&mut interfaces.pairs, state.time);
        }
        let tractions = contact
            .zip(self.interfaces.as_ref())
            .map(|(c, interfaces)| c.tractions(interfaces, &positions));
        let strain = cell_strains(model, &self.reference, state);
        let points = PointArrays::of(&self.grid, &cells);
        let fields = Fields {
            displacement: &vectors(&state.displacement),
            velocity: &vectors(motion.velocity),
            acceleration: &vectors(motion.acceleration),
            contact_force: &vectors(&contact_force),
            gap: &gap,
            contact_status: &status,
            reference_coordinates: &self.reference,
            stress: &cells.stress,
            von_mises: &cells.von_mises,
            eq_plastic_strain: &cells.eq_plastic_strain,
            pressure: &cells.pressure,
            temperature: cells.temperature.as_deref(),
            body: Some(&self.body_ids),
            nodal: Some(points.values(&self.point_body_ids)),
            traction: tractions.as_ref().map(|t| (&t.pressure[..], &t.shear[..])),
            strain: Some(&strain),
        };
        let points = match model.output.points {
            FramePoints::Current => &positions[..],
            FramePoints::Reference => &self.reference[..],
        };
        self.grid.points.clear();
        self.grid.points.extend_from_slice(points);
        series.write_frame(state.time, &self.grid, &fields)?;
        if let Some(listed) = self.obstacle_frames.as_mut() {
            let mut obstacles = model.obstacles.clone();
            for o in &mut obstacles {
                placing.place_obstacle(o, state.time);
            }
            let frame = (listed.len(), state.time);
            let options = (model.output.compression, listed);
            let lines = polylines(&obstacles);
            crate::output::vtk::write_obstacle_frame(
                &self.dir,
                &model.name,
                frame,
                &lines,
                options,
            )?;
        }
        self.steps_since_frame = 0;
        self.last_frame_time = Some(state.time);
        Ok(())
    }

    /// Writes summary.json: the summary, then `max_temperature` and the probes' final values
    /// (`probes`, by column) when there are any.
    pub fn write_summary(&mut self, model: &Model, summary: &Summary) -> Result<(), OutputError> {
        // every frame and row on disk (and the frames listed) before the summary says how
        // the run ended: the last step's row too when the run ended between two rows
        if let Some(series) = &self.series {
            series.flush()?;
        }
        let history = &mut self.history;
        self.thinning.finish(|r| history.append(r))?;
        self.history.flush()?;
        let path = self.dir.join("summary.json");
        let file = SummaryFile {
            summary,
            max_temperature: summary.max_temperature,
            mass_scaling: summary.mass_scaling.as_ref(),
            subcycling: summary.subcycling.as_ref(),
            ale: summary.ale.as_ref(),
            arc_length: summary.arc_length.as_ref(),
            probes: FinalProbes {
                columns: &model.probes,
                values: &self.last_probes,
            },
        };
        let text = serde_json::to_string_pretty(&file).expect("the summary serializes");
        write_atomic(&path, text.as_bytes())
    }
}

/// summary.json: the summary's fields, then `max_temperature` when there is one, then
/// `mass_scaling` with the mass scaling, `subcycling` with the subcycling, `ale` with the ALE
/// steps, `arc_length` with arc length, then the probes' last values when the scene has probes.
#[derive(serde::Serialize)]
struct SummaryFile<'a> {
    #[serde(flatten)]
    summary: &'a Summary,
    #[serde(skip_serializing_if = "Option::is_none")]
    max_temperature: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mass_scaling: Option<&'a crate::analysis::summary::MassScalingSummary>,
    #[serde(skip_serializing_if = "Option::is_none")]
    subcycling: Option<&'a crate::analysis::summary::SubcyclingSummary>,
    #[serde(skip_serializing_if = "Option::is_none")]
    ale: Option<&'a crate::analysis::summary::AleSummary>,
    #[serde(skip_serializing_if = "Option::is_none")]
    arc_length: Option<&'a crate::analysis::summary::ArcLengthSummary>,
    #[serde(skip_serializing_if = "FinalProbes::is_empty")]
    probes: FinalProbes<'a>,
}

/// `"probes": {"COLUMN": value, ...}` in the scene's order: the last history row's probe
/// values (none before the first row).
struct FinalProbes<'a> {
    columns: &'a [crate::scene::model::Probe],
    values: &'a [f64],
}

impl FinalProbes<'_> {
    fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
}

impl serde::Serialize for FinalProbes<'_> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(Some(self.values.len()))?;
        for (probe, value) in self.columns.iter().zip(self.values) {
            map.serialize_entry(&probe.column, value)?;
        }
        map.end()
    }
}

/// The highest point temperature of the state, when some material carries one.
pub fn max_temperature(model: &Model, state: &State) -> Option<f64> {
    model.carries_temperature().then(|| {
        model
            .bodies
            .iter()
            .zip(&state.bodies)
            .filter(|(b, _)| b.material.carries_temperature())
            .flat_map(|(_, s)| s.points.iter().map(|p| p.temperature))
            .fold(f64::NEG_INFINITY, f64::max)
    })
}

/// Per cell of [`grid`] (quads first, then rods), the Green-Lagrange strain of the total
/// displacement from the initial configuration at the cell's centre, [XX YY ZZ XY YZ XZ]
/// with the tensor shear E_xy:
/// ```text
/// quads   H = grad_X u at the centre (xi = eta = 0), E = (H + H^T + H^T H) / 2
///         ZZ: plane strain 0; axisymmetric (r^2 / R^2 - 1) / 2 with R, r the centre's
///         initial and current radius; plane stress (lambda^2 - 1) / 2 with lambda the mean
///         thickness stretch of the points
/// rods    XX = (l^2 / L^2 - 1) / 2 along the rod, the rest 0
/// ```
pub(crate) fn cell_strains(model: &Model, initial: &[[f64; 2]], state: &State) -> Vec<[f64; 6]> {
    use crate::element::{Formulation, quad4, rod2};
    use crate::scene::Continuum;
    let u = &state.displacement;
    let at = |n: usize| {
        (
            initial[n],
            [initial[n][0] + u[2 * n], initial[n][1] + u[2 * n + 1]],
        )
    };
    let mut out = Vec::with_capacity(model.elements());
    for (b, body) in model.bodies.iter().enumerate() {
        let Cells::Quad4(quads) = &body.mesh.cells else {
            continue;
        };
        for (e, q) in quads.iter().enumerate() {
            let nodes = q.map(|n| at(body.global(n)));
            let reference = nodes.map(|n| n.0);
            let current = nodes.map(|n| n.1);
            let [xx, yy, xy] = quad4::centre_green_strain(&reference, &current);
            let zz = match body.kind.continuum() {
                Some(Continuum {
                    formulation: Formulation::Axisymmetric,
                    ..
                }) => {
                    let radius = |x: &[[f64; 2]; 4]| x.iter().map(|p| p[0]).sum::<f64>() / 4.0;
                    let (initial_r, current_r) = (radius(&reference), radius(&current));
                    if initial_r > 0.0 {
                        0.5 * ((current_r / initial_r).powi(2) - 1.0)
                    } else {
                        0.0
                    }
                }
                Some(Continuum {
                    formulation: Formulation::PlaneStress,
                    thickness,
                    ..
                }) => {
                    let ppe = body.points_per_element();
                    let now = &state.bodies[b].thickness[e * ppe..(e + 1) * ppe];
                    let stretch = now.iter().sum::<f64>() / ppe as f64 / thickness;
                    0.5 * (stretch * stretch - 1.0)
                }
                _ => 0.0,
            };
            out.push([xx, yy, zz, xy, 0.0, 0.0]);
        }
    }
    for body in &model.bodies {
        let Cells::Rod2(rods) = &body.mesh.cells else {
            continue;
        };
        for r in rods {
            let [(a0, a1), (b0, b1)] = r.map(|n| at(body.global(n)));
            let xx = rod2::green_strain(&[a0, b0], &[a1, b1]);
            out.push([xx, 0.0, 0.0, 0.0, 0.0, 0.0]);
        }
    }
    out
}

/// Per moving obstacle (`columns::moving_obstacles`), its displacement and velocity at the
/// state's time (a projectile's: where the run has it) and the force the bodies exert on it
/// through the pairs against it (zeros before any contact).
fn obstacle_values(model: &Model, state: &State, contact: Option<&ContactState>) -> Vec<f64> {
    let mut values = Vec::new();
    if super::columns::moving_obstacles(model).next().is_none() {
        return values;
    }
    let at_rest = ContactState::new(&[]);
    let c = contact.unwrap_or(&at_rest);
    let pairs = c.placed(&model.contacts, state.time);
    let positions = state.positions(model.analysis.geometry());
    for obstacle in super::columns::moving_obstacles(model) {
        let (u, v) = c.obstacle_motion(obstacle, state.time);
        let mut force = [0.0; 2];
        if let Some(c) = contact {
            let against = |p: &ContactPair| matches!(&p.master, Master::Obstacle(o) if o.name == obstacle.name);
            for (p, _) in pairs.iter().enumerate().filter(|(_, p)| against(p)) {
                let f = c.master_force(&pairs, p, &positions);
                force = [force[0] + f[0], force[1] + f[1]];
            }
        }
        values.extend([u[0], u[1], v[0], v[1], force[0], force[1]]);
        if let Some(p) = obstacle.projectile.as_ref()
            && let Some(spin) = &p.spin
        {
            let flight = c.flights.get(p.index);
            values.extend(flight.map_or([0.0, spin.angular_velocity], |f| {
                [f.rotation, f.angular_velocity]
            }));
        }
    }
    values
}

/// The scene's rigid obstacles beside the frames, when it has any: at rest, written once
/// (`vtk::write_obstacles`, None); where one moves, each frame writes them
/// (`write_obstacle_frame`): the list of obstacle frames already written (up to
/// `resumed_at`, read back from the .pvd, when a run resumes).
fn write_obstacles(
    model: &Model,
    dir: &Path,
    resumed_at: Option<f64>,
) -> Result<Option<Vec<(f64, String)>>, OutputError> {
    if model.obstacles.is_empty() {
        return Ok(None);
    }
    if (model.obstacles.iter()).any(|o| o.motion.is_some() || o.projectile.is_some()) {
        let Some(until) = resumed_at else {
            return Ok(Some(Vec::new()));
        };
        let pvd = dir.join(format!("{}_obstacles.pvd", model.name));
        let listed = crate::output::vtk::read_pvd(&pvd).unwrap_or_default();
        let relative = |p: &Path| {
            p.file_name()
                .map(|f| format!("vtk/{}", f.to_string_lossy()))
        };
        return Ok(Some(
            (listed.iter())
                .filter(|(t, _)| *t <= until)
                .filter_map(|(t, p)| relative(p).map(|f| (*t, f)))
                .collect(),
        ));
    }
    let polylines = polylines(&model.obstacles);
    crate::output::vtk::write_obstacles(dir, &model.name, &polylines, model.output.compression)?;
    Ok(None)
}

/// The obstacles as the frames draw them.
fn polylines(obstacles: &[crate::contact::Obstacle]) -> Vec<Polyline<'_>> {
    (obstacles.iter())
        .map(|o| Polyline {
            points: &o.points,
            closed: o.closed,
        })
        .collect()
}

/// Per cell of [`grid`], the index of its body in the scene (quads first, then rods).
pub(crate) fn body_ids(model: &Model) -> Vec<i64> {
    let of = |quads: bool| {
        model
            .bodies
            .iter()
            .enumerate()
            .filter(move |(_, b)| matches!(b.mesh.cells, Cells::Quad4(_)) == quads)
            .flat_map(|(i, b)| std::iter::repeat_n(i as i64, b.elements()))
    };
    of(true).chain(of(false)).collect()
}

/// All bodies in one grid: initial coordinates, quads first, then rods.
pub(crate) fn grid(model: &Model) -> Grid {
    let mut quads = Vec::new();
    let mut lines = Vec::new();
    for body in &model.bodies {
        match &body.mesh.cells {
            Cells::Quad4(q) => quads.extend(q.iter().map(|c| c.map(|n| body.global(n)))),
            Cells::Rod2(r) => lines.extend(r.iter().map(|c| c.map(|n| body.global(n)))),
        }
    }
    Grid {
        points: model.coordinates(),
        quads,
        lines,
    }
}

/// The contact record of a model with contact pairs, starting from `carry`.
fn contact_record(model: &Model, carry: ContactCarry) -> Option<ContactRecord> {
    (!model.contacts.is_empty()).then(|| ContactRecord::new(model, carry))
}

/// Where a run's output stands at a checkpoint: the frames listed, the bytes of
/// history.csv (whole rows), and the frame cadence.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct RecorderPosition {
    pub series: Option<crate::output::vtk::SeriesPosition>,
    pub history_bytes: u64,
    /// The steps since the last row written, and that row.
    pub history_window: Window,
    pub steps_since_frame: usize,
    pub last_frame_time: Option<f64>,
    pub negative_pivots: Option<usize>,
    /// The probes' values in the last row (summary.json `probes`).
    #[serde(default)]
    pub probes: Vec<f64>,
    /// The contact record (with contact).
    #[serde(default)]
    pub contact: Option<ContactCarry>,
}

/// Each reported pair's contact work and, with Coulomb friction, its friction work, in the
/// order of `columns::pair_columns`' columns (zeros before any contact).
fn pair_energies(model: &Model, contact: Option<&ContactState>) -> Vec<f64> {
    let reported = model.contacts.iter().filter(|c| c.balances.is_none());
    let energies = contact.map(|c| c.pair_energies(&model.contacts));
    let mut row = Vec::new();
    for (p, pair) in reported.enumerate() {
        let e = energies.as_ref().map(|e| &e[p]);
        row.push(e.map_or(0.0, |e| e.contact_work));
        if matches!(pair.options.friction, Friction::Coulomb { .. }) {
            row.push(e.map_or(0.0, |e| e.friction_work));
        }
    }
    row
}
