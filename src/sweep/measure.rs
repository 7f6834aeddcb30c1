//! Errors of each case against the scene's `[reference]`, or else against the finest case
//! (scalar measures Richardson-extrapolated from the three finest), and the sweep.csv table.
//!
//! ```text
//! F_h(t_k)      the case's contact force history (history.csv `contact_force[PAIR]`)
//! F_ref(t)      the reference force: a pulse F_0 on 0 < t < T (mean of the limits at a jump),
//!               or the finest case's history interpolated linearly
//! force_l2      sqrt( int (F_h - F_ref)^2 dt / int F_ref^2 dt ), trapezoid rule on the t_k
//! force_l2_smooth  the same over the t_k farther than T/8 from the pulse's jumps (t = 0, T)
//! release_error    last release time minus T (pulse), Hertz duration, or the extrapolation
//! peak_force_error, duration_error, radius_error: relative, (value - reference) / reference
//! energy_drift  summary.json energy.max_relative_drift (the balance error)
//! energy_change (energy.final - energy.initial) / energy.initial
//! h             the shortest element edge of the initial mesh
//! ```
//!
//! A jump in F_ref limits the L2 error to order 1/2 under refinement (an O(dt) shift of the
//! jump or an O(1) ripple over a fixed number of steps costs O(dt) in the squared norm);
//! force_l2_smooth shows the order of the scheme away from the jumps (docs/validation.md 6).

use super::plan::{Case, Plan};
use crate::analysis::steppers::stable::critical_time_step;
use crate::scene::model::{Analysis, Reference};
use crate::scene::spec::ReferenceKind;
use crate::scene::{InputError, Model};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// DIR/CASE/case.json: written last, atomically; a case is finished when it exists.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CaseRecord {
    pub index: usize,
    pub values: Vec<(String, String)>,
    /// `ok`, `diverged`, `unstable` (summary.json) or `refused` (the run rejected the input,
    /// e.g. central difference above dt_crit without `analysis.allow_unstable`).
    pub status: String,
    pub message: Option<String>,
    pub wall_seconds: f64,
    /// The CPU time of the thread the case ran on (its own work, whatever else ran beside it
    /// under `--jobs`); absent in records written before it was kept.
    #[serde(default)]
    pub cpu_seconds: Option<f64>,
}

/// What one case measured (None where it does not apply or is unknown).
#[derive(Debug, Clone, Default)]
pub struct Measures {
    pub force_l2: Option<f64>,
    pub force_l2_smooth: Option<f64>,
    /// With a declared (closed-form) reference, the force L2 error and the peak force error
    /// against the converged one as well (the finest case, or Richardson's extrapolation):
    /// the discretization error without the closed form's own model error.
    pub converged_force_l2: Option<f64>,
    pub converged_peak_force_error: Option<f64>,
    pub release_time: Option<f64>,
    pub release_error: Option<f64>,
    pub peak_force: Option<f64>,
    pub peak_force_error: Option<f64>,
    pub duration_error: Option<f64>,
    pub radius_error: Option<f64>,
    pub energy_drift: Option<f64>,
    /// (energy.final - energy.initial) / energy.initial: negative when the method (or the
    /// impact conditions) dissipated energy.
    pub energy_change: Option<f64>,
    pub steps: Option<f64>,
    pub newton_iterations: Option<f64>,
    pub factorizations: Option<f64>,
}

/// One row of sweep.csv.
#[derive(Debug, Clone)]
pub struct Row {
    pub case: Case,
    pub folder: String,
    pub status: String,
    /// The integrator's scene name (`average`, `hu`, ..., `static`).
    pub integrator: String,
    pub dt: Option<f64>,
    pub h: f64,
    pub dt_crit: Option<f64>,
    pub wall_seconds: Option<f64>,
    pub cpu_seconds: Option<f64>,
    pub measures: Measures,
    /// The `--measure` values of the case, in the order given (qoi::score).
    pub quantities: Vec<Option<f64>>,
    /// Their errors against the series' converged value (qoi::score).
    pub quantity_errors: Vec<Option<f64>>,
}

impl Row {
    pub fn dt_over_dt_crit(&self) -> Option<f64> {
        Some(self.dt? / self.dt_crit?)
    }

    /// The error the charts plot: force_l2 (pulse or finest-case reference), else |peak
    /// force error| (Hertz).
    pub fn primary_error(&self) -> Option<f64> {
        self.measures
            .force_l2
            .or(self.measures.peak_force_error.map(f64::abs))
    }

    /// The same against the converged reference (declared references only).
    pub fn converged_error(&self) -> Option<f64> {
        self.measures
            .converged_force_l2
            .or(self.measures.converged_peak_force_error.map(f64::abs))
    }
}

/// The reference used, for the report.
#[derive(Debug, Clone, Serialize)]
pub struct ReferenceUsed {
    /// `bars`, `rod_wall`, `hertz_impact`, or `finest case` / `richardson`.
    pub kind: String,
    pub pair: Option<String>,
    pub force: Option<f64>,
    pub release_time: Option<f64>,
    pub peak_force: Option<f64>,
    pub radius: Option<f64>,
    pub duration: Option<f64>,
    /// The finest case's folder (finest-case references).
    pub finest: Option<String>,
    /// The observed order of the Richardson extrapolation of the peak force.
    pub richardson_order: Option<f64>,
    /// What a column measures when it is not a discretization error (printed by the sweep).
    pub notes: Vec<String>,
    /// The same, in a line short enough for the charts of the force errors.
    #[serde(skip)]
    pub chart_notes: Vec<String>,
    /// Beside a declared reference: the converged one the `converged_` columns use.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub converged: Option<Box<ReferenceUsed>>,
}

/// Why `peak_force_error` against a force pulse does not converge.
pub const PULSE_PEAK_NOTE: &str = "peak_force_error against a force pulse measures the overshoot \
    where the exact force jumps at t = 0 (the integrator's first steps), which does not shrink \
    with dt or h: it is no discretization error; force_l2 and force_l2_smooth are";

/// A finished case's files.
struct Loaded {
    summary: serde_json::Value,
    time: Vec<f64>,
    force: Option<Vec<f64>>,
}

fn read_json<T: for<'de> Deserialize<'de>>(path: &Path) -> Option<T> {
    serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()
}

/// The cases' rows, measured against the scene's reference or the finest case. `folders`
/// gives the folder holding each case (None: missing). `models` are the cases' models.
pub fn tabulate(
    plan: &Plan,
    cases: &[Case],
    models: &[Model],
    folders: &[Option<PathBuf>],
) -> Result<(Vec<Row>, ReferenceUsed), InputError> {
    let reference = models.first().and_then(|m| m.reference.clone());
    let pair = reference
        .as_ref()
        .map(|r| r.pair().to_string())
        .or_else(|| models.first()?.contacts.first().map(|c| c.name.clone()));
    let column = pair.as_ref().map(|p| format!("contact_force[{p}]"));
    let mut rows = Vec::with_capacity(cases.len());
    let mut loaded = Vec::with_capacity(cases.len());
    for ((case, model), folder) in cases.iter().zip(models).zip(folders) {
        let record: Option<CaseRecord> = folder
            .as_ref()
            .and_then(|f| read_json(&f.join("case.json")));
        let files = folder.as_ref().and_then(|f| load(f, column.as_deref()));
        rows.push(row(plan, case, model, record.as_ref(), files.as_ref())?);
        loaded.push((files, record));
    }
    let used = match &reference {
        Some(Reference::ForcePulse {
            kind,
            pair,
            force,
            duration,
        }) => pulse_reference(&mut rows, &loaded, kind, pair, (*force, *duration)),
        Some(Reference::Hertz {
            pair,
            peak_force,
            radius,
            duration,
        }) => hertz_reference(&mut rows, &loaded, pair, (*peak_force, *radius, *duration)),
        None => {
            let mut used = finest_reference(&mut rows, &loaded, pair.clone());
            let series = series_indices(plan, &rows);
            if let Some(note) = not_decreasing(&rows, &series) {
                used.notes.push(note);
                used.chart_notes.push(
                    "force L2 against the finest case does not fall under refinement: no converging measure"
                        .into(),
                );
            }
            used
        }
    };
    let used = match reference {
        Some(_) => with_converged(used, &mut rows, &loaded, pair),
        None => used,
    };
    Ok((rows, used))
}

/// A case's row with what it measured on its own (summary.json), before the comparison
/// with a reference.
fn row(
    plan: &Plan,
    case: &Case,
    model: &Model,
    record: Option<&CaseRecord>,
    files: Option<&Loaded>,
) -> Result<Row, InputError> {
    let dt_crit = if model.bodies.iter().all(|b| b.material.density > 0.0) {
        Some(critical_time_step(model)?.dt)
    } else {
        None
    };
    let (integrator, dt) = match &model.analysis {
        Analysis::Dynamic(d) => (
            serde_json::to_value(d.integrator)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default(),
            d.fixed_dt(),
        ),
        Analysis::Static(_) => ("static".to_string(), None),
    };
    let mut measures = Measures::default();
    if let Some(files) = files {
        let s = &files.summary;
        let num = |path: &[&str]| {
            path.iter()
                .try_fold(s, |v, k| v.get(k))
                .and_then(serde_json::Value::as_f64)
        };
        measures.release_time = num(&["contact", "last_release_time"]);
        measures.peak_force = num(&["contact", "peak_force"]);
        measures.energy_drift = num(&["energy", "max_relative_drift"]);
        if let (Some(initial), Some(last)) =
            (num(&["energy", "initial"]), num(&["energy", "final"]))
            && initial > 0.0
        {
            measures.energy_change = Some(last / initial - 1.0);
        }
        measures.steps = num(&["steps"]);
        measures.newton_iterations = num(&["newton_iterations"]);
        measures.factorizations = num(&["factorizations"]);
    }
    Ok(Row {
        case: case.clone(),
        folder: plan.folder(case),
        status: record.map_or("missing".to_string(), |r| r.status.clone()),
        integrator,
        dt,
        h: shortest_edge(model, &refined_bodies(&plan.keys())),
        dt_crit,
        wall_seconds: record.map(|r| r.wall_seconds),
        cpu_seconds: record.and_then(|r| r.cpu_seconds),
        measures,
        quantities: Vec::new(),
        quantity_errors: Vec::new(),
    })
}

/// Against a force pulse F_0 on 0 < t < T (rod impacts; `(F_0, T)`): the force history's L2
/// errors, the release time against T and the peak force against F_0.
fn pulse_reference(
    rows: &mut [Row],
    loaded: &[(Option<Loaded>, Option<CaseRecord>)],
    kind: &ReferenceKind,
    pair: &str,
    (force, duration): (f64, f64),
) -> ReferenceUsed {
    for (row, (files, _)) in rows.iter_mut().zip(loaded) {
        let m = &mut row.measures;
        if let Some(Loaded {
            time,
            force: Some(f),
            ..
        }) = files
        {
            let pulse = |t: f64| pulse(t, force, duration);
            m.force_l2 = relative_l2(time, f, &pulse, |_| true);
            let margin = duration / 8.0;
            m.force_l2_smooth = relative_l2(time, f, &pulse, |t| {
                t.abs() >= margin && (t - duration).abs() >= margin
            });
        }
        m.release_error = m.release_time.map(|t| t - duration);
        m.peak_force_error = m.peak_force.map(|p| p / force - 1.0);
        m.duration_error = m.release_time.map(|t| t / duration - 1.0);
    }
    ReferenceUsed {
        kind: serde_json::to_value(kind)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default(),
        pair: Some(pair.to_string()),
        force: Some(force),
        release_time: Some(duration),
        peak_force: Some(force),
        radius: None,
        duration: Some(duration),
        finest: None,
        richardson_order: None,
        notes: vec![PULSE_PEAK_NOTE.to_string()],
        chart_notes: Vec::new(),
        converged: None,
    }
}

/// Against the Hertz impact (`(peak force, contact radius, duration)`): peak force, contact
/// duration (first contact to last release) and largest contact radius.
fn hertz_reference(
    rows: &mut [Row],
    loaded: &[(Option<Loaded>, Option<CaseRecord>)],
    pair: &str,
    (peak_force, radius, duration): (f64, f64, f64),
) -> ReferenceUsed {
    for (row, (files, _)) in rows.iter_mut().zip(loaded) {
        let m = &mut row.measures;
        m.peak_force_error = m.peak_force.map(|p| p / peak_force - 1.0);
        m.release_error = m.release_time.map(|t| t - duration);
        if let Some(files) = files {
            let s = &files.summary["contact"];
            if let (Some(first), Some(last)) = (
                s["first_contact_time"].as_f64(),
                s["last_release_time"].as_f64(),
            ) {
                m.duration_error = Some((last - first) / duration - 1.0);
            }
            m.radius_error = s["peak_contact_radius"].as_f64().map(|a| a / radius - 1.0);
        }
    }
    ReferenceUsed {
        kind: "hertz_impact".into(),
        pair: Some(pair.to_string()),
        force: None,
        release_time: Some(duration),
        peak_force: Some(peak_force),
        radius: Some(radius),
        duration: Some(duration),
        finest: None,
        richardson_order: None,
        notes: Vec::new(),
        chart_notes: Vec::new(),
        converged: None,
    }
}

/// Beside a declared reference, the errors against the converged one (the finest case or
/// Richardson's extrapolation, `finest_reference` on a copy of the rows) in the `converged_`
/// measures.
fn with_converged(
    mut used: ReferenceUsed,
    rows: &mut [Row],
    loaded: &[(Option<Loaded>, Option<CaseRecord>)],
    pair: Option<String>,
) -> ReferenceUsed {
    let mut copy = rows.to_vec();
    let converged = finest_reference(&mut copy, loaded, pair);
    for (row, measured) in rows.iter_mut().zip(&copy) {
        // the finest case is the reference's own history: no error to measure
        if converged.finest.as_ref() == Some(&row.folder) {
            continue;
        }
        row.measures.converged_force_l2 = measured.measures.force_l2;
        row.measures.converged_peak_force_error = measured.measures.peak_force_error;
    }
    used.converged = Some(Box::new(converged));
    used
}

/// Without a declared reference: the finest ok case (smallest dt, then the most elements
/// by the shortest edge) gives the force history; peak force and release time are
/// Richardson-extrapolated from the three finest dt when they are in a constant ratio.
fn finest_reference(
    rows: &mut [Row],
    loaded: &[(Option<Loaded>, Option<CaseRecord>)],
    pair: Option<String>,
) -> ReferenceUsed {
    let mut ok: Vec<usize> = (0..rows.len())
        .filter(|&k| rows[k].status == "ok" && loaded[k].0.is_some())
        .collect();
    ok.sort_by(|&a, &b| {
        let key = |k: usize| (rows[k].dt.unwrap_or(0.0), rows[k].h);
        key(a)
            .partial_cmp(&key(b))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let mut used = ReferenceUsed {
        kind: "finest case".into(),
        pair,
        force: None,
        release_time: None,
        peak_force: None,
        radius: None,
        duration: None,
        finest: None,
        richardson_order: None,
        notes: Vec::new(),
        chart_notes: Vec::new(),
        converged: None,
    };
    let Some(&finest) = ok.first() else {
        return used;
    };
    used.finest = Some(rows[finest].folder.clone());
    // the three finest distinct dt
    let mut levels: Vec<usize> = Vec::new();
    for &k in &ok {
        if levels
            .last()
            .is_none_or(|&l| rows[k].dt.unwrap_or(0.0) > rows[l].dt.unwrap_or(0.0) * (1.0 + 1e-9))
        {
            levels.push(k);
        }
    }
    let scalar = |get: &dyn Fn(&Measures) -> Option<f64>| -> (Option<f64>, Option<f64>) {
        let finest_value = get(&rows[finest].measures);
        if levels.len() < 3 {
            return (finest_value, None);
        }
        let (a, b, c) = (levels[0], levels[1], levels[2]);
        let (Some(f1), Some(f2), Some(f3)) = (
            get(&rows[a].measures),
            get(&rows[b].measures),
            get(&rows[c].measures),
        ) else {
            return (finest_value, None);
        };
        let dt = |k: usize| rows[k].dt.unwrap_or(0.0);
        let (r1, r2) = (dt(b) / dt(a), dt(c) / dt(b));
        match richardson(f1, f2, f3, r1, r2) {
            Some((value, order)) => (Some(value), Some(order)),
            None => (finest_value, None),
        }
    };
    let (peak, order) = scalar(&|m: &Measures| m.peak_force);
    let (release, _) = scalar(&|m: &Measures| m.release_time);
    if order.is_some() {
        used.kind = "richardson".into();
    }
    used.peak_force = peak;
    used.release_time = release;
    used.richardson_order = order;
    let reference_history = loaded[finest]
        .0
        .as_ref()
        .and_then(|l| Some((l.time.clone(), l.force.clone()?)));
    for (k, row) in rows.iter_mut().enumerate() {
        // the finest case is the reference history (and, without an extrapolation, the
        // reference peak and release): it is not scored against itself
        if k == finest && order.is_none() {
            continue;
        }
        let m = &mut row.measures;
        if let (Some(p), Some(p_ref)) = (m.peak_force, peak)
            && p_ref != 0.0
        {
            m.peak_force_error = Some(p / p_ref - 1.0);
        }
        if let (Some(t), Some(t_ref)) = (m.release_time, release) {
            m.release_error = Some(t - t_ref);
        }
        if k == finest {
            continue;
        }
        if let (
            Some((t_ref, f_ref)),
            Some(Loaded {
                time,
                force: Some(f),
                ..
            }),
        ) = (&reference_history, &loaded[k].0)
        {
            let interpolate = |t: f64| interpolate(t_ref, f_ref, t);
            m.force_l2 = relative_l2(time, f, &interpolate, |_| true);
        }
    }
    used
}

/// A note when, in some series, force_l2 against the finest case does not fall as the cases
/// get finer (by dt, then h, as the finest case is chosen; cases of one level compared by
/// nothing): the force history is then no converging measure.
fn not_decreasing(rows: &[Row], series: &[(String, Vec<usize>)]) -> Option<String> {
    series.iter().find_map(|(label, members)| {
        let mut levels: Vec<((f64, f64), f64)> = members
            .iter()
            .filter(|&&k| rows[k].status == "ok")
            .filter_map(|&k| {
                let r = &rows[k];
                Some(((r.dt.unwrap_or(0.0), r.h), r.measures.force_l2?))
            })
            .collect();
        levels.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap_or(std::cmp::Ordering::Equal));
        levels.dedup_by(|a, b| a.0 == b.0);
        let rising = levels.windows(2).any(|w| w[0].1 > w[1].1 * (1.0 + 1e-9));
        (levels.len() >= 2 && rising).then(|| {
            let listed: Vec<String> = levels.iter().rev().map(|l| format!("{:.3}", l.1)).collect();
            format!(
                "force_l2 against the finest case does not fall as the cases of {label} get finer ({}, coarse to fine): the contact force history is not a converging measure of this scene; score the cases on a quantity with --measure",
                listed.join(", ")
            )
        })
    })
}

/// Richardson extrapolation from values on three levels f1 (finest), f2, f3 with step
/// ratios r = h2/h1 = h3/h2 (within 1 %): p = ln((f3 - f2) / (f2 - f1)) / ln r,
/// f = f1 + (f1 - f2) / (r^p - 1). None when the ratios differ or the differences do not
/// shrink monotonically (no asymptotic range).
pub fn richardson(f1: f64, f2: f64, f3: f64, r1: f64, r2: f64) -> Option<(f64, f64)> {
    if r1 <= 1.0 || (r1 / r2 - 1.0).abs() > 0.01 {
        return None;
    }
    let ratio = (f3 - f2) / (f2 - f1);
    if !(ratio.is_finite() && ratio > 1.0) {
        return None;
    }
    let p = ratio.ln() / r1.ln();
    Some((f1 + (f1 - f2) / (r1.powf(p) - 1.0), p))
}

/// The pulse F_0 on 0 < t < T, the mean of the one-sided limits at t = 0 and t = T.
fn pulse(t: f64, force: f64, duration: f64) -> f64 {
    let eps = 1e-9 * duration;
    if (t.abs() <= eps) || ((t - duration).abs() <= eps) {
        0.5 * force
    } else if t > 0.0 && t < duration {
        force
    } else {
        0.0
    }
}

/// Linear interpolation in a sampled history (constant beyond its ends).
fn interpolate(time: &[f64], value: &[f64], t: f64) -> f64 {
    let k = time.partition_point(|s| *s < t);
    if k == 0 {
        return value[0];
    }
    if k >= time.len() {
        return value[value.len() - 1];
    }
    let (t0, t1) = (time[k - 1], time[k]);
    if t1 <= t0 {
        return value[k];
    }
    value[k - 1] + (t - t0) / (t1 - t0) * (value[k] - value[k - 1])
}

/// sqrt(int (f - g)^2 dt / int g^2 dt) by the trapezoid rule over the samples, counting only
/// the intervals whose both ends pass `keep`. None if the reference norm is zero.
fn relative_l2(
    time: &[f64],
    value: &[f64],
    reference: &dyn Fn(f64) -> f64,
    keep: impl Fn(f64) -> bool,
) -> Option<f64> {
    let (mut error, mut norm) = (0.0, 0.0);
    for k in 1..time.len() {
        let (t0, t1) = (time[k - 1], time[k]);
        if !(keep(t0) && keep(t1)) {
            continue;
        }
        let (g0, g1) = (reference(t0), reference(t1));
        let h = t1 - t0;
        error += 0.5 * h * ((value[k - 1] - g0).powi(2) + (value[k] - g1).powi(2));
        norm += 0.5 * h * (g0 * g0 + g1 * g1);
    }
    (norm > 0.0).then(|| (error / norm).sqrt())
}

/// summary.json and the time and force columns of a finished case.
fn load(folder: &Path, column: Option<&str>) -> Option<Loaded> {
    let summary: serde_json::Value = read_json(&folder.join("summary.json"))?;
    let history = folder.join("history.csv");
    let time = crate::output::plot::history_columns(&history, &["time"])
        .ok()?
        .remove(0);
    let force = column.and_then(|c| {
        crate::output::plot::history_columns(&history, &[c])
            .ok()
            .map(|mut v| v.remove(0))
    });
    Some(Loaded {
        summary,
        time,
        force,
    })
}

/// The shortest element edge of the initial mesh over the bodies named `bodies` (all bodies
/// when none is named).
pub fn shortest_edge(model: &Model, bodies: &[String]) -> f64 {
    let counted = |name: &String| bodies.is_empty() || bodies.contains(name);
    (model.bodies.iter())
        .filter(|b| counted(&b.name))
        .flat_map(|b| (0..b.mesh.cells.len()).flat_map(|e| b.mesh.edge_lengths(e)))
        .fold(f64::INFINITY, f64::min)
}

/// The bodies whose meshes a sweep refines: the names of `body.NAME.mesh.*` when every
/// varied key is one of those (a study of one body's mesh, the rest kept), else none (h is
/// then the whole model's shortest edge).
pub fn refined_bodies(keys: &[String]) -> Vec<String> {
    let body_of = |key: &String| {
        let rest = key.strip_prefix("body.")?;
        let (name, tail) = rest.split_once('.')?;
        tail.starts_with("mesh.").then(|| name.to_string())
    };
    let names: Option<Vec<String>> = keys.iter().map(body_of).collect();
    let mut names = names.unwrap_or_default();
    names.sort();
    names.dedup();
    names
}

/// sweep.csv: one row per case; the varied values as given, then the measures, then per
/// `--measure` its value and its error (`NAME`, `NAME_error`). Numbers in shortest
/// round-trip exponent form; empty where not applicable.
pub fn csv(plan: &Plan, rows: &[Row], quantities: &[super::Measure]) -> String {
    let keys = plan.keys();
    let mut header: Vec<String> = vec!["case".into(), "folder".into()];
    header.extend(keys.iter().cloned());
    header.extend(
        [
            "status",
            "integrator",
            "dt",
            "h",
            "dt_crit",
            "dt_over_dt_crit",
            "force_l2",
            "force_l2_smooth",
            "release_time",
            "release_error",
            "peak_force",
            "peak_force_error",
            "duration_error",
            "radius_error",
            "energy_drift",
            "energy_change",
            "converged_force_l2",
            "converged_peak_force_error",
            "steps",
            "newton_iterations",
            "factorizations",
            "wall_seconds",
            "cpu_seconds",
        ]
        .map(String::from),
    );
    for q in quantities {
        header.push(q.name.clone());
        header.push(format!("{}_error", q.name));
    }
    let mut text = header.join(",");
    text.push('\n');
    let num = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:e}"));
    for row in rows {
        let m = &row.measures;
        let mut cells = vec![row.case.index.to_string(), row.folder.clone()];
        cells.extend(row.case.values.iter().map(|(_, v)| quote(v)));
        cells.extend([row.status.clone(), row.integrator.clone()]);
        cells.extend(
            [
                row.dt,
                Some(row.h),
                row.dt_crit,
                row.dt_over_dt_crit(),
                m.force_l2,
                m.force_l2_smooth,
                m.release_time,
                m.release_error,
                m.peak_force,
                m.peak_force_error,
                m.duration_error,
                m.radius_error,
                m.energy_drift,
                m.energy_change,
                m.converged_force_l2,
                m.converged_peak_force_error,
            ]
            .map(num),
        );
        let count = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.0}"));
        cells.extend([m.steps, m.newton_iterations, m.factorizations].map(count));
        cells.push(num(row.wall_seconds));
        cells.push(num(row.cpu_seconds));
        for k in 0..quantities.len() {
            cells.push(num(row.quantities.get(k).copied().flatten()));
            cells.push(num(row.quantity_errors.get(k).copied().flatten()));
        }
        text.push_str(&cells.join(","));
        text.push('\n');
    }
    text
}

/// A CSV field: quoted when it holds a comma or a quote.
fn quote(v: &str) -> String {
    if v.contains([',', '"']) {
        format!("\"{}\"", v.replace('"', "\"\""))
    } else {
        v.to_string()
    }
}

/// Whether a key is a refinement or the method: dt, the implicit error tolerance, the
/// integrator, a mesh parameter.
fn is_method_or_refinement(key: &str) -> bool {
    key == "analysis.dt"
        || key == "analysis.error_tolerance"
        || key == "analysis.integrator"
        || key.contains(".mesh.")
}

/// Keys that do not name a series: those varied together with a refinement or the method
/// (`--vary "analysis.integrator,analysis.mass=..."`).
fn unlabelled_keys(plan: &Plan) -> Vec<String> {
    plan.variations
        .iter()
        .filter(|v| v.keys.iter().any(|k| is_method_or_refinement(k)))
        .flat_map(|v| v.keys.iter().cloned())
        .collect()
}

/// The series a row belongs to: its integrator and the varied values that are not dt,
/// the integrator, a mesh parameter or varied together with one of those.
pub fn series_label(row: &Row, unlabelled: &[String]) -> String {
    let mut label = row.integrator.clone();
    for (key, value) in &row.case.values {
        if unlabelled.contains(key) {
            continue;
        }
        let short = key.rsplit('.').next().unwrap_or(key);
        label.push_str(&format!(", {short}={value}"));
    }
    label
}

/// The series of the rows: each label with the indices of its rows, in order of appearance.
pub fn series_indices(plan: &Plan, rows: &[Row]) -> Vec<(String, Vec<usize>)> {
    let unlabelled = unlabelled_keys(plan);
    let mut groups: Vec<(String, Vec<usize>)> = Vec::new();
    for (k, row) in rows.iter().enumerate() {
        let label = series_label(row, &unlabelled);
        match groups.iter_mut().find(|(l, _)| *l == label) {
            Some((_, members)) => members.push(k),
            None => groups.push((label, vec![k])),
        }
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: a sweep of one body's mesh measures h on that body. Reference: the keys
    /// themselves: `body.plate.mesh.*` alone names the plate; a key of anything else (the
    /// step, another body's material) leaves the whole model; two bodies' meshes name both.
    #[test]
    fn a_sweep_of_one_bodys_mesh_refines_that_body() {
        let keys = |k: &[&str]| k.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let plate = keys(&["body.plate.mesh.nx", "body.plate.mesh.ny"]);
        assert_eq!(refined_bodies(&plate), ["plate"]);
        let mixed = keys(&["body.plate.mesh.nx", "analysis.dt"]);
        assert!(refined_bodies(&mixed).is_empty());
        let velocity = keys(&["body.plate.velocity"]);
        assert!(refined_bodies(&velocity).is_empty());
        let both = keys(&["body.plate.mesh.nx", "body.block.mesh.nx"]);
        assert_eq!(refined_bodies(&both), ["block", "plate"]);
    }

    /// Richardson on f(h) = 1 + h^2 recovers 1 and order 2 exactly.
    #[test]
    fn richardson_recovers_a_quadratic() {
        let f = |h: f64| 1.0 + h * h;
        let (value, order) = richardson(f(0.25), f(0.5), f(1.0), 2.0, 2.0).unwrap();
        approx::assert_abs_diff_eq!(value, 1.0, epsilon = 1e-12);
        approx::assert_abs_diff_eq!(order, 2.0, epsilon = 1e-12);
        assert!(richardson(1.0, 1.0, 1.0, 2.0, 2.0).is_none());
        assert!(richardson(f(0.25), f(0.5), f(1.0), 2.0, 3.0).is_none());
    }

    /// Goal: the L2 measure of a pulse released one sample late. Reference (by hand): the
    /// differences are F/2 at t = T and at T + h (the mean of the limits at each jump), so
    /// the trapezoid rule gives int e^2 = h F^2 / 2 against int g^2 = F^2 T (to O(h)):
    /// e = sqrt(h / (2 T)); 1 % for the O(h) end weights of the norm.
    #[test]
    fn relative_l2_of_a_pulse_released_one_sample_late() {
        let (force, duration, h) = (2.0, 1.0, 0.01);
        let time: Vec<f64> = (0..=200).map(|k| k as f64 * h).collect();
        let value: Vec<f64> = time
            .iter()
            .map(|&t| pulse(t, force, duration + h))
            .collect();
        let e = relative_l2(&time, &value, &|t| pulse(t, force, duration), |_| true).unwrap();
        let exact = (h / (2.0 * duration)).sqrt();
        approx::assert_relative_eq!(e, exact, max_relative = 0.01);
    }
}
