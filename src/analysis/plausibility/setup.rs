//! The warnings the scene alone gives, before a step is taken (`impact check` prints them,
//! a run repeats them): too few steps or too short a run for a wave (with the likely unit
//! mistake), an obstacle no pair uses, axisymmetric axis nodes left free, the bodies' start
//! (`initial`), too many frames.

use super::slaves::slave_surface_warnings;
use super::units::{MAX_STEPS, body_size, unit_hint, unit_warnings};
use super::{model_size, some_nodes};
use crate::analysis::steppers::explicit::Start;
use crate::analysis::steppers::stable::{implicit_first_step, wave_speed};
use crate::contact::Master;
use crate::output::readable;
use crate::scene::model::Analysis;
use crate::scene::spec::TimeStep;
use crate::scene::{Body, Model};

/// A dynamic run of fewer steps than this warns: a central-difference or Newmark step
/// resolves a period of at least about ten steps (the period error of the trapezoidal rule
/// is (omega dt)^2 / 12: 3 % at ten steps per period, 33 % at three), and an impact needs
/// steps for the force to rise and fall. Far fewer steps than that is mostly a sign of
/// mixed units: the step comes from the wave speed, the end time from the user.
pub const MIN_STEPS: f64 = 10.0;

/// The warnings the scene alone gives, before a step is taken: `impact check` prints them and
/// a run repeats them in summary.json. A dynamic run of fewer than [`MIN_STEPS`] steps, and
/// one shorter than a wave transit of its smallest body, each with the likely unit mistake.
pub fn setup_warnings(model: &Model) -> Vec<String> {
    setup_warnings_given(model, None)
}

/// [`setup_warnings`] with the run's first step `first_step` where the run reports it (the
/// automatic step of the initial mesh is then not found again: a whole explicit set-up).
pub(super) fn setup_warnings_given(model: &Model, first_step: Option<f64>) -> Vec<String> {
    let mut out = Vec::new();
    for obstacle in &model.obstacles {
        let used = model
            .contacts
            .iter()
            .any(|pair| matches!(&pair.master, Master::Obstacle(o) if o.name == obstacle.name));
        if !used {
            out.push(format!(
                "obstacle `{0}` is used by no contact pair: it stops nothing, and bodies pass \
                 through it; add a [[contact]] with obstacle = \"{0}\" and the slave set that \
                 meets it (or remove the obstacle)",
                obstacle.name
            ));
        }
    }
    out.extend(unit_warnings(model));
    out.extend(slave_surface_warnings(model));
    out.extend(axis_warnings(model));
    out.extend(super::initial::initial_warnings(model));
    // the automatic step of the initial mesh, found once (a run's whole explicit set-up)
    let auto_step = match &model.analysis {
        Analysis::Dynamic(d) if matches!(d.step, TimeStep::Auto { .. }) => {
            first_step.or_else(|| explicit_first_step(model, d))
        }
        _ => None,
    };
    out.extend(frames_warning(model, auto_step));
    let Analysis::Dynamic(d) = &model.analysis else {
        return out;
    };
    let step = match d.step {
        TimeStep::Fixed(dt) => Some((dt, "analysis.dt".to_string())),
        TimeStep::Auto { scale, .. } => auto_step.map(|dt| {
            (
                dt,
                format!(
                    "the automatic step (time_step_scale = {} x the stable step of the initial mesh)",
                    readable(scale)
                ),
            )
        }),
        // the error control lengthens the steps as far as the answer allows: no count
        TimeStep::Adaptive(_) => None,
    };
    if let Some((dt, what)) = &step {
        let steps = d.end_time / dt;
        if steps > MAX_STEPS {
            out.push(format!(
                "analysis.end_time = {} spans {} steps of {what} = {}: more than {} steps is days \
                 of computing and mostly an end time in other units than the step (microseconds \
                 meant, seconds given?); shorten analysis.end_time, or check the units: {}",
                readable(d.end_time),
                readable(steps.round()),
                readable(*dt),
                readable(MAX_STEPS),
                unit_hint(model)
            ));
        }
    }
    if let Some((dt, what)) = step {
        let steps = d.end_time / dt;
        if steps < MIN_STEPS {
            let change = match d.step {
                TimeStep::Fixed(_) => "lower analysis.dt",
                TimeStep::Auto { .. } | TimeStep::Adaptive(_) => "lengthen analysis.end_time",
            };
            out.push(format!(
                "analysis.end_time = {} spans {} step(s) of {what} = {}: fewer than {} \
                steps cannot follow a wave or an impact (a step clipped to end_time or to a \
                frame time hides it: the run still ends on time); {change}, or check the \
                units: {}",
                readable(d.end_time),
                readable(steps),
                readable(dt),
                MIN_STEPS,
                unit_hint(model)
            ));
        }
    }
    let transit = model
        .bodies
        .iter()
        .filter_map(|b| wave_speed(b).map(|c| (b, body_size(b), c.speed)))
        .filter(|(_, size, c)| *size > 0.0 && *c > 0.0)
        .map(|(b, size, c)| (b, size, c, size / c))
        .min_by(|x, y| x.3.total_cmp(&y.3));
    if let Some((body, size, c, time)) = transit
        && d.end_time < time
    {
        out.push(format!(
            "analysis.end_time = {} is shorter than one wave transit of the smallest body, \
                `{}` (size {} / wave speed {} = {}): no wave crosses any body in the run; lengthen \
                analysis.end_time, or check the units: {}",
            readable(d.end_time),
            body.name,
            readable(size),
            readable(c),
            readable(time),
            unit_hint(model)
        ));
    }
    out
}

/// The first step of a central-difference run of `model` (None: the run would refuse it).
fn explicit_first_step(model: &Model, spec: &crate::scene::DynamicAnalysis) -> Option<f64> {
    Start::new(model, spec).ok().map(|start| start.first_step())
}

/// A node of an axisymmetric body counts as on the axis, or across it, beyond this share of
/// the body's size from r = 0: round-off of coordinates written in decimal, not geometry.
pub const AXIS_TOLERANCE: f64 = 1e-9;

/// The nodes of the axisymmetric bodies at positions `x`: per body, those at r < 0 beyond
/// the tolerance and those on the axis, r = 0 within it.
struct AxisNodes<'a> {
    body: &'a Body,
    across: Vec<usize>,
    on_axis: Vec<usize>,
    /// The smallest r of the body.
    min_r: f64,
}

fn axis_nodes<'a>(model: &'a Model, x: &[[f64; 2]]) -> Vec<AxisNodes<'a>> {
    model
        .bodies
        .iter()
        .filter(|b| b.is_axisymmetric())
        .map(|body| {
            let tolerance = AXIS_TOLERANCE * body_extent(body);
            let nodes = (0..body.mesh.nodes.len()).map(|n| body.global(n));
            let r = |n: usize| x[n][0];
            AxisNodes {
                body,
                across: nodes.clone().filter(|n| r(*n) < -tolerance).collect(),
                on_axis: nodes.clone().filter(|n| r(*n).abs() <= tolerance).collect(),
                min_r: nodes.map(r).fold(f64::INFINITY, f64::min),
            }
        })
        .collect()
}

/// Axisymmetric bodies in the initial mesh: nodes at r < 0, and axis nodes free in x (the
/// hoop strain u_r / r needs u_r = 0 on the axis; nothing else keeps them there).
fn axis_warnings(model: &Model) -> Vec<String> {
    let coords = model.coordinates();
    let constrained = model.constrained_dofs();
    let mut out = Vec::new();
    for a in axis_nodes(model, &coords) {
        let name = &a.body.name;
        if !a.across.is_empty() {
            out.push(format!(
                "axisymmetric body `{name}` has {} node(s) at r = x < 0 (down to {}; global \
                 nodes {}): the axis is x = 0 and the body must lie at x >= 0; move its mesh",
                a.across.len(),
                readable(a.min_r),
                some_nodes(&a.across)
            ));
        }
        let free: Vec<usize> = a
            .on_axis
            .iter()
            .copied()
            .filter(|n| constrained.binary_search(&(2 * n)).is_err())
            .collect();
        if !free.is_empty() {
            // the body's own set of exactly its axis nodes, when it has one (`axis`, `left`)
            let mut on_axis: Vec<usize> =
                a.on_axis.iter().map(|n| n - a.body.node_offset).collect();
            on_axis.sort_unstable();
            let set = a.body.mesh.node_sets.iter().find_map(|(set, nodes)| {
                let mut nodes = nodes.clone();
                nodes.sort_unstable();
                nodes.dedup();
                (nodes == on_axis).then_some(set)
            });
            let support = match set {
                Some(set) => format!(
                    "add a [[support]] with body = \"{name}\", set = \"{set}\", fix = [\"x\"]"
                ),
                None => "add a [[support]] with fix = [\"x\"] on a set of the axis nodes".into(),
            };
            out.push(format!(
                "axisymmetric body `{name}` has {} node(s) on the axis (r = 0) free in x (global \
                 nodes {}): nothing holds them on the axis, and they can cross it to r < 0; \
                 {support}",
                free.len(),
                some_nodes(&free)
            ));
        }
    }
    out
}

/// Nodes of an axisymmetric body at r < 0 in `positions`, a warning per body.
pub(super) fn axis_crossings(model: &Model, positions: &[[f64; 2]]) -> Vec<String> {
    axis_nodes(model, positions)
        .into_iter()
        .filter(|a| !a.across.is_empty())
        .map(|a| {
            format!(
                "axisymmetric body `{}` ends with {} node(s) at r = x < 0 (down to {}; global \
                 nodes {}): they crossed the axis; hold the axis nodes in x (a [[support]] with \
                 fix = [\"x\"] on them)",
                a.body.name,
                a.across.len(),
                readable(a.min_r),
                some_nodes(&a.across)
            )
        })
        .collect()
}

/// The larger side of the body's bounding box.
fn body_extent(body: &Body) -> f64 {
    model_size(&body.mesh.nodes)
}

/// A run that writes more frames than this warns (check and run): each frame is a file and
/// an entry of the .pvd, which is rewritten after every frame so that a crash leaves a
/// valid series, so the writing grows with the square of the count; and a series of
/// thousands of frames is more than one looks at in ParaView. The shipped scenes write at
/// most 131 (taylor_aluminum).
pub const MANY_FRAMES: f64 = 1000.0;

/// The size of an uncompressed frame per node of the model (measured: 376 to 616 bytes on
/// the last frames of the shipped scenes, most 400 to 421; the point fields, the cell fields
/// and the connectivity of a Quad4 mesh). `lz4` and `zlib` compression write less.
pub const FRAME_BYTES_PER_NODE: f64 = 400.0;

/// The frames a run of `model` writes, estimated before it starts: the listed frame times
/// (`frame_times` and the multiples of `frame_interval`), the first, and one every
/// `frame_every` steps of the nominal step (the fixed step, or the automatic step of the
/// initial mesh, `auto_step`, found by the caller; the steps of a static analysis).
pub fn expected_frames(model: &Model, auto_step: Option<f64>) -> f64 {
    let output = &model.output;
    let steps = match &model.analysis {
        Analysis::Static(s) => s.steps as f64,
        Analysis::Dynamic(d) => match d.step {
            TimeStep::Fixed(dt) => d.end_time / dt,
            TimeStep::Auto { .. } => auto_step.map(|dt| d.end_time / dt).unwrap_or(0.0),
            // the first step's count: the error control may lengthen them
            TimeStep::Adaptive(_) => implicit_first_step(model, d)
                .map(|dt| d.end_time / dt)
                .unwrap_or(0.0),
        },
    };
    let every = if output.frame_every() > 0 {
        (steps / output.frame_every() as f64).ceil()
    } else {
        0.0
    };
    1.0 + output.frame_times.len() as f64 + every
}

/// More than [`MANY_FRAMES`] frames, with the disk they will take.
fn frames_warning(model: &Model, auto_step: Option<f64>) -> Option<String> {
    let frames = expected_frames(model, auto_step);
    if frames <= MANY_FRAMES {
        return None;
    }
    let bytes = frames * FRAME_BYTES_PER_NODE * model.node_count as f64;
    Some(format!(
        "the run will write about {} VTK frames (output.frame_interval, output.frame_times and \
         output.frame_every together), some {} on disk uncompressed ({} nodes): more than {} \
         frames is more than ParaView shows usefully, and every frame rewrites the .pvd; \
         lengthen output.frame_interval (or raise output.frame_every)",
        readable(frames.round()),
        bytes_in_words(bytes),
        model.node_count,
        MANY_FRAMES
    ))
}

/// `12 kB`, `3.4 MB`, `1.2 GB`, `5 TB` (powers of 1000).
fn bytes_in_words(bytes: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB"];
    let mut value = bytes;
    let mut unit = 0;
    while value >= 1000.0 && unit + 1 < units.len() {
        value /= 1000.0;
        unit += 1;
    }
    format!("{value:.1} {}", units[unit])
}
