//! `impact sweep`: runs the cross product of `--vary` variations of a scene in parallel
//! across cases, measures each against the scene's `[reference]` (or the finest case), and
//! writes sweep.csv and the charts.
//!
//! ```text
//! DIR/sweep.json         the plan (scene, --set, --vary); a rerun must have the same plan
//! DIR/case-HASH/         one case: history.csv, summary.json (analysis::run; VTK frames only
//!                        with `frames`),
//!                        case.json written last and atomically: the case is finished
//! DIR/sweep.csv          one row per case (measure::csv)
//! DIR/reference.json     the reference the errors are measured against
//! DIR/measures.json      each --measure per series: levels, observed order, extrapolated
//!                        value and GCI, or why not (qoi.rs)
//! DIR/*.png, DIR/*.svg   charts (charts.rs)
//! ```
//! A rerun skips finished cases, and a rerun whose --vary adds values runs only the new
//! cases. `--shard i/n` runs the cases k with k mod n = i; `merge`
//! joins the case folders of several DIRs (shards, or a study and a level run apart) into one
//! table and charts. Each case runs on one
//! thread (its element loops in a one-thread pool), so results do not depend on `--jobs`.

pub mod charts;
pub mod measure;
pub mod plan;
pub mod qoi;

use crate::analysis::progress::Mode;
use crate::analysis::{self, RunError, RunOptions};
use crate::output::{OutputError, console, write_atomic};
use crate::scene::{self, InputError, Model};
use indicatif::{ProgressBar, ProgressStyle};
use measure::CaseRecord;
pub use plan::{Case, Plan, Variation};
pub use qoi::Measure;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of a sweep that are not part of its plan.
#[derive(Debug, Clone, Copy, Default)]
pub struct SweepOptions {
    /// Cases run at once; 0: one per core.
    pub jobs: usize,
    /// (i, n): run only the cases k with k mod n = i.
    pub shard: Option<(usize, usize)>,
    /// A bar over the cases (with a line per finished case above it), a line per finished
    /// case, or nothing.
    pub progress: Mode,
    /// Write each case's VTK frames as its scene asks (off: no frames, whatever the scene).
    pub frames: bool,
}

/// What a sweep did.
#[derive(Debug, Clone)]
pub struct Report {
    /// Cases in the plan.
    pub cases: usize,
    /// Cases of this shard (all without a shard).
    pub in_shard: usize,
    /// Cases run now.
    pub executed: usize,
    /// Cases of this shard finished before (skipped).
    pub skipped: usize,
    /// Rows whose status is not `ok` (including `missing`).
    pub not_ok: usize,
    pub rows: Vec<measure::Row>,
    pub csv: PathBuf,
    pub charts: Vec<PathBuf>,
    /// What some columns measure (reference.json `notes`), and why a measure has no
    /// extrapolated value, for the closing lines.
    pub notes: Vec<String>,
    /// Each `--measure` per series (measures.json).
    pub scores: Vec<qoi::MeasureScore>,
}

fn output_error(path: &Path, action: &'static str, e: std::io::Error) -> RunError {
    RunError::Output(OutputError::io(path, action, e))
}

/// Builds every case's model (bad keys and values are input errors before anything runs),
/// and checks that each measure names a column of the cases' history.
fn models(plan: &Plan, cases: &[Case], measures: &[Measure]) -> Result<Vec<Model>, RunError> {
    plan.validate()
        .map_err(|m| InputError::new(&plan.scene, format!("--vary: {m}")))?;
    let models: Vec<Model> = cases
        .iter()
        .map(|case| {
            scene::load(&plan.scene, &plan.overrides(case)).map_err(|e| {
                let values: Vec<String> = case
                    .values
                    .iter()
                    .map(|(k, v)| format!("{k}={v}"))
                    .collect();
                RunError::Input(InputError {
                    file: e.file,
                    message: format!("case {} ({}): {}", case.index, values.join(" "), e.message),
                })
            })
        })
        .collect::<Result<_, _>>()?;
    for model in &models {
        qoi::check(measures, model).map_err(|m| InputError::new(&plan.scene, m))?;
    }
    Ok(models)
}

/// Runs the plan's cases (of the shard) not finished in `dir`, then writes sweep.csv, the
/// reference and the charts of the cases found in `dir`.
pub fn run(
    plan: &Plan,
    dir: &Path,
    options: SweepOptions,
    measures: &[Measure],
) -> Result<Report, RunError> {
    let cases = plan.cases();
    let models = models(plan, &cases, measures)?;
    crate::analysis::create_output_folder(dir)?;
    let plan_path = dir.join("sweep.json");
    let existing: Option<Option<Plan>> = std::fs::read_to_string(&plan_path)
        .ok()
        .map(|text| serde_json::from_str(&text).ok());
    if let Some(existing) = existing {
        if !existing.as_ref().is_some_and(|e| plan.extends(e)) {
            return Err(InputError::new(
                &plan_path,
                "this folder holds another sweep (the scene, --set or the varied keys differ, \
                 or values were dropped; a sweep may add values to its --vary, as a finer \
                 level); choose another --out",
            )
            .into());
        }
        if existing.as_ref() != Some(plan) {
            // a finer level added: the finished cases keep their folders
            let text = serde_json::to_string_pretty(plan).expect("the plan serializes");
            write_atomic(&plan_path, text.as_bytes())?;
        }
    } else {
        let text = serde_json::to_string_pretty(plan).expect("the plan serializes");
        write_atomic(&plan_path, text.as_bytes())?;
    }
    let mine: Vec<usize> = (0..cases.len())
        .filter(|k| options.shard.is_none_or(|(i, n)| k % n == i))
        .collect();
    let todo: Vec<usize> = mine
        .iter()
        .copied()
        .filter(|&k| !dir.join(plan.folder(&cases[k])).join("case.json").is_file())
        .collect();
    let bar = if options.progress == Mode::Bar && !todo.is_empty() {
        let bar = ProgressBar::new(todo.len() as u64);
        bar.set_style(
            ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} cases {msg}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    // `jobs` workers take the cases one at a time from a shared counter. Not a rayon pool
    // over the cases: a case runs inside its own one-thread pool, and a rayon thread that
    // waits on another pool steals more cases of its own meanwhile, so `--jobs 1` ran every
    // case at once.
    let jobs = if options.jobs == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        options.jobs
    };
    let next = std::sync::atomic::AtomicUsize::new(0);
    let run_next = || {
        let mut done = Vec::new();
        loop {
            let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let Some(&k) = todo.get(i) else {
                return done;
            };
            let result = run_case(plan, &cases[k], &models[k], dir, options.frames);
            if options.progress != Mode::Off
                && let Ok(record) = &result
            {
                let line = case_line(record, cases.len());
                if bar.is_hidden() {
                    console::err(format_args!("{line}"));
                } else {
                    bar.println(line);
                }
            }
            bar.inc(1);
            done.push(result.map(|_| ()));
        }
    };
    let results: Vec<Result<(), RunError>> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..jobs.min(todo.len()))
            .map(|_| scope.spawn(run_next))
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().expect("a sweep worker panicked"))
            .collect()
    });
    bar.finish_and_clear();
    for result in results {
        result?;
    }
    let folders: Vec<Option<PathBuf>> = cases
        .iter()
        .map(|c| Some(dir.join(plan.folder(c))).filter(|f| f.join("case.json").is_file()))
        .collect();
    let mut report = write_results(plan, (&cases, &models, &folders), dir, measures)?;
    report.in_shard = mine.len();
    report.executed = todo.len();
    report.skipped = mine.len() - todo.len();
    Ok(report)
}

/// `case 3 of 12 (analysis.dt=0.005): ok, 0.52 s` (and the message of a case not ok).
fn case_line(record: &CaseRecord, cases: usize) -> String {
    let values: Vec<String> = record
        .values
        .iter()
        .map(|(key, value)| format!("{key}={value}"))
        .collect();
    let mut line = format!(
        "case {} of {cases} ({}): {}, {:.2} s",
        record.index + 1,
        values.join(", "),
        record.status,
        record.wall_seconds
    );
    if let Some(message) = &record.message {
        line.push_str(&format!(": {message}"));
    }
    line
}

/// Runs one case into DIR/FOLDER (cleared first) on one thread, with its frames only when
/// `frames`; writes case.json last and returns it.
fn run_case(
    plan: &Plan,
    case: &Case,
    model: &Model,
    dir: &Path,
    frames: bool,
) -> Result<CaseRecord, RunError> {
    let folder = dir.join(plan.folder(case));
    if folder.exists() {
        std::fs::remove_dir_all(&folder).map_err(|e| output_error(&folder, "clear", e))?;
    }
    std::fs::create_dir_all(&folder).map_err(|e| output_error(&folder, "create", e))?;
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| output_error(&folder, "start the thread of", std::io::Error::other(e)))?;
    let start = Instant::now();
    // the case runs on the single pool's thread: its CPU time is the case's own
    let (result, cpu_seconds) = single.install(|| {
        let cpu = cpu_time::ThreadTime::now();
        let options = RunOptions {
            no_frames: !frames,
            ..Default::default()
        };
        let result = analysis::run(model, &folder, options);
        (result, cpu.elapsed().as_secs_f64())
    });
    let wall = start.elapsed().as_secs_f64();
    let (status, message, wall_seconds) = match result {
        Ok(summary) => ("ok".to_string(), None, summary.wall_seconds),
        // analysis::run never gives Warnings (only the CLI's --strict does)
        Err(RunError::Warnings { summary, .. }) => ("ok".to_string(), None, summary.wall_seconds),
        Err(RunError::Numerical { message, summary }) => {
            let status = serde_json::to_value(summary.status)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_else(|| "diverged".into());
            (status, Some(message), summary.wall_seconds)
        }
        Err(RunError::Input(e)) => ("refused".to_string(), Some(e.message), wall),
        // an interrupted case writes no record: a rerun runs it again
        Err(e @ (RunError::Output(_) | RunError::Interrupted { .. })) => return Err(e),
    };
    let record = CaseRecord {
        index: case.index,
        values: case.values.clone(),
        status,
        message,
        wall_seconds,
        cpu_seconds: Some(cpu_seconds),
    };
    let text = serde_json::to_string_pretty(&record).expect("the record serializes");
    write_atomic(&folder.join("case.json"), text.as_bytes())?;
    Ok(record)
}

/// The characters of a scene's title the charts keep: an 800-pixel chart holds about 78 of
/// the title font, and the charts add up to 30 (": error against CPU time").
const TITLE_CHARACTERS: usize = 48;

/// Joins the finished cases of sweeps run into `dirs` and writes the table and charts into
/// `out`: shards of one plan, or a study and its extensions (one plan extends every other,
/// `Plan::extends`: a finer level run apart), under the widest plan.
pub fn merge(dirs: &[PathBuf], out: &Path, measures: &[Measure]) -> Result<Report, RunError> {
    let mut plans: Vec<(PathBuf, Plan)> = Vec::new();
    for dir in dirs {
        let path = dir.join("sweep.json");
        let text = std::fs::read_to_string(&path)
            .map_err(|e| InputError::new(&path, format!("cannot read the sweep's plan: {e}")))?;
        let this: Plan = serde_json::from_str(&text)
            .map_err(|e| InputError::new(&path, format!("not a sweep plan: {e}")))?;
        plans.push((path, this));
    }
    let widest = plans
        .iter()
        .find(|(_, p)| plans.iter().all(|(_, q)| p.extends(q)));
    let plan = match (widest, plans.first()) {
        (Some((_, plan)), _) => plan.clone(),
        (None, None) => {
            return Err(InputError::new(out, "--merge: name at least one folder").into());
        }
        (None, Some((first, p))) => {
            let (path, _) = (plans.iter())
                .find(|(_, q)| !p.extends(q) && !q.extends(p))
                .unwrap_or(&plans[plans.len() - 1]);
            return Err(InputError::new(
                path,
                format!(
                    "another sweep than {} (scene, --set or the varied keys differ, or neither \
                     plan holds the other's values; a study and a finer level run apart merge)",
                    first.display()
                ),
            )
            .into());
        }
    };
    let cases = plan.cases();
    let models = models(&plan, &cases, measures)?;
    let folders: Vec<Option<PathBuf>> = cases
        .iter()
        .map(|c| {
            dirs.iter()
                .map(|d| d.join(plan.folder(c)))
                .find(|f| f.join("case.json").is_file())
        })
        .collect();
    crate::analysis::create_output_folder(out)?;
    let text = serde_json::to_string_pretty(&plan).expect("the plan serializes");
    write_atomic(&out.join("sweep.json"), text.as_bytes())?;
    write_results(&plan, (&cases, &models, &folders), out, measures)
}

/// Measures the cases, writes sweep.csv, reference.json, measures.json and the charts into
/// `out`.
fn write_results(
    plan: &Plan,
    (cases, models, folders): (&[Case], &[Model], &[Option<PathBuf>]),
    out: &Path,
    measures: &[Measure],
) -> Result<Report, RunError> {
    let (mut rows, reference) = measure::tabulate(plan, cases, models, folders)?;
    let scores = match models.first() {
        Some(model) => {
            let series = measure::series_indices(plan, &rows);
            qoi::score(
                measures,
                &qoi::Units::of(model),
                model,
                (&mut rows, folders),
                &series,
            )
        }
        None => Vec::new(),
    };
    let csv = out.join("sweep.csv");
    write_atomic(&csv, measure::csv(plan, &rows, measures).as_bytes())?;
    let text = serde_json::to_string_pretty(&reference).expect("the reference serializes");
    write_atomic(&out.join("reference.json"), text.as_bytes())?;
    let text = serde_json::to_string_pretty(&scores).expect("the scores serialize");
    write_atomic(&out.join("measures.json"), text.as_bytes())?;
    // the scene's title (its first TITLE_CHARACTERS: the charts add what they show, up to 30
    // more, and a title wider than the chart is cut at both ends), else its name (the stem)
    let title = models
        .first()
        .map(|m| {
            if m.title.is_empty() {
                m.name.clone()
            } else if m.title.chars().count() > TITLE_CHARACTERS {
                let cut: String = m.title.chars().take(TITLE_CHARACTERS - 1).collect();
                format!("{}…", cut.trim_end())
            } else {
                m.title.clone()
            }
        })
        .unwrap_or_default();
    let units = models.first().map(qoi::Units::of);
    // the notes of the reference, and of the converged one beside a declared reference
    let converged = reference.converged.as_deref();
    let chart_notes: Vec<String> = reference
        .chart_notes
        .iter()
        .chain(converged.map_or(&[][..], |c| &c.chart_notes[..]))
        .cloned()
        .collect();
    let table = (plan, &rows[..]);
    let mut charts = charts::write_all(table, &title, units.as_ref(), &chart_notes, out)?;
    if let Some(units) = &units {
        charts.extend(charts::write_measures(table, &scores, &title, units, out)?);
    }
    let mut notes = reference.notes.clone();
    notes.extend(converged.map_or(Vec::new(), |c| c.notes.clone()));
    notes.extend(scores.iter().flat_map(qoi::MeasureScore::notes));
    Ok(Report {
        cases: cases.len(),
        in_shard: cases.len(),
        executed: 0,
        skipped: 0,
        not_ok: rows.iter().filter(|r| r.status != "ok").count(),
        rows,
        csv,
        charts,
        notes,
        scores,
    })
}
