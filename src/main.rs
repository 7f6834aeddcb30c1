//! The `impact` command line: subcommands only, no mechanics.

use clap::{Parser, Subcommand};
use impact::analysis::progress::Mode as Progress;
use impact::analysis::{self, RunError, RunOptions};
use impact::output::plot::{self, Chart, Limits, Series, SeriesStyle};
use impact::output::{OutputError, console, readable};
use impact::scene::{self, InputError};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

/// A line on stdout that a closed reader (`| head`) cannot turn into a panic.
macro_rules! outln {
    ($($arg:tt)*) => {
        console::out(format_args!($($arg)*))
    };
}

/// A line on stderr that a closed reader cannot turn into a panic.
macro_rules! errln {
    ($($arg:tt)*) => {
        console::err(format_args!($($arg)*))
    };
}

#[derive(Parser)]
#[command(
    name = "impact",
    version,
    about = "Finite-strain elastoplastic contact-impact in 2D and 1D"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene: VTK frames, history.csv and summary.json in the output folder.
    Run {
        scene: PathBuf,
        /// Output folder. Default: output/<scene name>/
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene value before it is read, e.g. --set analysis.steps=20
        /// or --set body.beam.velocity=[0,-1] (arrays of tables addressed by name).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// No progress bar and no closing line.
        #[arg(long)]
        quiet: bool,
        /// When stderr is not a terminal (a batch log), a progress line every SECONDS.
        #[arg(long, value_name = "SECONDS", default_value_t = 5.0)]
        progress_every: f64,
        /// Write DIR/checkpoint.bin every N steps (same as --set analysis.checkpoint_every=N).
        #[arg(long, value_name = "N")]
        checkpoint_every: Option<usize>,
        /// Exit 3 when the finished run has warnings (summary.json `warnings`).
        #[arg(long)]
        strict: bool,
        /// A line per Newton iteration on stderr: the step's end time, the residual and its
        /// share of the force tolerance, the displacement criterion, whether it refactors;
        /// and why a step or increment is cut.
        #[arg(long)]
        verbose: bool,
    },
    /// Continue a run from DIR/checkpoint.bin (written with analysis.checkpoint_every, or when
    /// a run is interrupted by Ctrl-C / SIGTERM). The scene is the one stored in the checkpoint.
    Resume {
        dir: PathBuf,
        /// No progress bar and no closing line.
        #[arg(long)]
        quiet: bool,
        /// When stderr is not a terminal (a batch log), a progress line every SECONDS.
        #[arg(long, value_name = "SECONDS", default_value_t = 5.0)]
        progress_every: f64,
    },
    /// Validate a scene and print the model's size; warn of what the scene alone shows to be
    /// implausible (the same warnings the run repeats in summary.json).
    Check {
        scene: PathBuf,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Exit 3 when the scene has warnings.
        #[arg(long)]
        strict: bool,
    },
    /// Linearized buckling of the scene's end loads: prints the load factors lambda_i (the
    /// end loads times lambda_i are the critical loads) and writes the mode shapes as the
    /// frames of DIR/NAME_buckling.pvd.
    Buckle {
        scene: PathBuf,
        /// How many modes. Default: `analysis.buckling.modes` of the scene, else 3.
        #[arg(long)]
        modes: Option<usize>,
        /// Output folder. Default: output/<scene name>/
        #[arg(long)]
        out: Option<PathBuf>,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Run the cross product of `--vary` variations of a scene (in parallel across cases),
    /// measure each against the scene's [reference] (else the finest case), write
    /// sweep.csv and charts. A rerun skips finished cases.
    Sweep(SweepArgs),
    /// Generated scenes of growing size (a J2 block striking a rigid wall), implicit and
    /// explicit, one child process each: a table of DOFs, steps/s, element updates/s,
    /// factorizations, back-substitutions, peak memory and the time per phase; bench.json and
    /// charts in the output folder.
    Bench {
        /// Two small sizes only (seconds in all).
        #[arg(long)]
        quick: bool,
        /// Only the cases whose name contains this text (repeatable), e.g.
        /// `--case 448 --case elastic`.
        #[arg(long = "case", value_name = "TEXT")]
        cases: Vec<String>,
        /// Output folder. Default: output/bench/
        #[arg(long)]
        out: Option<PathBuf>,
        /// Instead of the generated plan: every scene of models/ (in the current folder) as
        /// shipped, frames off, one child process each.
        #[arg(long)]
        scenes: bool,
    },
    /// Plot columns of a history.csv against time (or another column) as SVG or PNG; or a
    /// frame's point arrays (a .vtu: columns x, y and the point arrays, one row per point)
    /// against a column, e.g. the contact pressure along the interface.
    Plot {
        history: PathBuf,
        /// A column to plot (repeat for more; one series each).
        #[arg(long = "y", value_name = "COLUMN", required = true)]
        y: Vec<String>,
        /// The column on the horizontal axis.
        #[arg(long = "x", value_name = "COLUMN", default_value = "time")]
        x: String,
        /// Chart file, .svg or .png. Default: plot_<columns>.svg next to the history.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Chart title. Default: the history's path.
        #[arg(long)]
        title: Option<String>,
        /// Frames only: the points where this column is not 0 (e.g. `contact_status`: the
        /// touching nodes), sorted by the x column.
        #[arg(long = "where", value_name = "COLUMN")]
        keep: Option<String>,
        /// Another run's history.csv whose same columns are overlaid, labelled with its name
        /// (its folder's when the file names agree). Repeat for more runs.
        #[arg(long)]
        reference: Vec<PathBuf>,
        /// One panel per --y column, stacked, each with its own vertical axis (columns of
        /// different magnitude stay readable).
        #[arg(long)]
        panels: bool,
        /// Ends of the axes (default: from the data).
        #[arg(long, allow_hyphen_values = true)]
        xmin: Option<f64>,
        #[arg(long, allow_hyphen_values = true)]
        xmax: Option<f64>,
        #[arg(long, allow_hyphen_values = true)]
        ymin: Option<f64>,
        #[arg(long, allow_hyphen_values = true)]
        ymax: Option<f64>,
        /// A logarithmic horizontal axis (values > 0).
        #[arg(long)]
        log_x: bool,
        /// A logarithmic vertical axis (values > 0).
        #[arg(long)]
        log_y: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run {
            scene,
            out,
            set,
            quiet,
            progress_every,
            checkpoint_every,
            strict,
            verbose,
        } => {
            impact::output::console::set_verbose(verbose);
            let mut set = set;
            if let Some(n) = checkpoint_every {
                set.push(format!("analysis.checkpoint_every={n}"));
            }
            progress_mode(quiet, progress_every).and_then(|p| run(&scene, out, &set, p, strict))
        }
        Command::Resume {
            dir,
            quiet,
            progress_every,
        } => progress_mode(quiet, progress_every).and_then(|p| resume(&dir, p)),
        Command::Check { scene, set, strict } => match check(&scene, &set) {
            // the warnings are on stderr above; like `run --strict`, they exit 3
            Ok(warnings) if strict && warnings > 0 => return ExitCode::from(3),
            other => other.map(|_| ()),
        },
        Command::Buckle {
            scene,
            modes,
            out,
            set,
        } => buckle(&scene, modes, out, &set),
        Command::Sweep(args) => sweep(args),
        Command::Bench {
            quick,
            cases,
            out,
            scenes,
        } => bench(quick, scenes, &cases, out),
        Command::Plot {
            history,
            y,
            x,
            out,
            title,
            keep,
            reference,
            panels,
            xmin,
            xmax,
            ymin,
            ymax,
            log_x,
            log_y,
        } => plot_history(
            &history,
            (&x, &y, keep.as_deref()),
            out,
            PlotLook {
                title,
                panels,
                log: (log_x, log_y),
                x_limits: Limits {
                    low: xmin,
                    high: xmax,
                },
                y_limits: Limits {
                    low: ymin,
                    high: ymax,
                },
            },
            &reference,
        ),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            errln!("error: {e}");
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

/// `n` and the noun, plural unless n is 1: "1 factorization", "3 factorizations".
fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// The progress of a run on stderr: nothing with --quiet, a bar on a terminal, else a line
/// every `every` seconds.
fn progress_mode(quiet: bool, every: f64) -> Result<Progress, RunError> {
    let every = std::time::Duration::try_from_secs_f64(every).map_err(|_| {
        InputError::new(
            Path::new("--progress-every"),
            format!("needs a number of seconds >= 0, got {every}"),
        )
    })?;
    Ok(Progress::for_stderr(quiet, every))
}

/// Options of a run, with SIGINT and SIGTERM turned into a request to stop after the step in
/// progress (a second signal while that step finishes is the same request).
fn run_options(progress: Progress) -> RunOptions {
    let flag: &'static Arc<AtomicBool> = Box::leak(Box::new(Arc::new(AtomicBool::new(false))));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        // without a handler the default action still stops the run, only less tidily
        if let Err(e) = signal_hook::flag::register(signal, Arc::clone(flag)) {
            errln!("warning: cannot catch signal {signal}: {e}");
        }
    }
    RunOptions {
        progress,
        interrupt: Some(&**flag),
        halt_after_steps: None,
        no_frames: false,
    }
}

fn bench(quick: bool, scenes: bool, only: &[String], out: Option<PathBuf>) -> Result<(), RunError> {
    let exe = std::env::current_exe().map_err(|e| {
        RunError::Output(OutputError::Io {
            path: PathBuf::from("impact"),
            action: "find the executable of",
            source: e,
        })
    })?;
    let dir = out.unwrap_or_else(impact::bench::default_dir);
    let plan = if scenes {
        let models = Path::new("models");
        impact::bench::scene_cases(models).map_err(|message| {
            RunError::Input(impact::scene::InputError::new(
                Path::new("impact bench --scenes"),
                message,
            ))
        })?
    } else {
        impact::bench::plan(quick)
    };
    let cases: Vec<_> = plan
        .into_iter()
        .filter(|c| only.is_empty() || only.iter().any(|text| c.name.contains(text.as_str())))
        .collect();
    if cases.is_empty() {
        return Err(RunError::Input(impact::scene::InputError::new(
            Path::new("impact bench"),
            format!(
                "no case of the plan matches --case {}",
                only.join(", --case ")
            ),
        )));
    }
    outln!("impact bench: {} cases -> {}", cases.len(), dir.display());
    let rows = impact::bench::run(&exe, &dir, &cases, |row| {
        outln!(
            "  {}: {} DOFs, {:.3} s",
            row.name,
            row.dofs,
            row.wall_seconds
        )
    })?;
    console::out_text(&impact::bench::table(&rows));
    Ok(())
}

fn run(
    path: &Path,
    out: Option<PathBuf>,
    set: &[String],
    progress: Progress,
    strict: bool,
) -> Result<(), RunError> {
    let quiet = progress == Progress::Off;
    if std::env::var_os("IMPACT_PROFILE_FINE").is_some() {
        impact::profile::set_fine(true);
    }
    let model = scene::load(path, set)?;
    let dir = out.unwrap_or_else(|| PathBuf::from("output").join(&model.name));
    let summary = match analysis::run(&model, &dir, run_options(progress)) {
        Ok(summary) => summary,
        Err(e) => {
            // a failed run's warnings say what it set out with (mixed units, a slave set
            // that misses the surface, ...): printed before its error
            if let RunError::Numerical { summary, .. } = &e {
                for warning in &summary.warnings {
                    errln!("warning: {warning}");
                }
            }
            return Err(e);
        }
    };
    if !quiet {
        let median = summary
            .newton_iterations_median
            .map_or(String::new(), |m| format!(" (median {m} a step)"));
        outln!(
            "{}: {}, {}{median}, {}, t = {}, {:.2} s -> {}",
            model.name,
            count(summary.steps, "step"),
            count(summary.newton_iterations, "Newton iteration"),
            count(summary.factorizations, "factorization"),
            readable(summary.end_time),
            summary.wall_seconds,
            dir.display()
        );
    }
    // warnings are printed even with --quiet: they are about the answer
    for warning in &summary.warnings {
        errln!("warning: {warning}");
    }
    if strict && !summary.warnings.is_empty() {
        return Err(RunError::Warnings {
            count: summary.warnings.len(),
            summary: Box::new(summary),
        });
    }
    Ok(())
}

fn resume(dir: &Path, progress: Progress) -> Result<(), RunError> {
    let quiet = progress == Progress::Off;
    let summary = analysis::resume(dir, run_options(progress))?;
    if !quiet {
        outln!(
            "resumed {}: {} in all, t = {} -> {}",
            summary.scene,
            count(summary.steps, "step"),
            readable(summary.end_time),
            dir.display()
        );
    }
    Ok(())
}

/// Checks the scene and returns the number of its warnings.
fn check(path: &Path, set: &[String]) -> Result<usize, RunError> {
    let model = scene::load(path, set)?;
    // the refusals a run makes before its first step (a central-difference dt above the
    // stability limit) come first: a scene `check` calls valid runs
    let report = analysis::check::report(&model)?;
    outln!("{}: valid", path.display());
    for body in &model.bodies {
        outln!(
            "  body `{}`: {} nodes, {} elements, {}, material `{}`",
            body.name,
            body.mesh.nodes.len(),
            body.elements(),
            body.kind.in_words(),
            body.material.name
        );
    }
    outln!(
        "  total: {} nodes, {} elements, {} DOFs",
        model.node_count,
        model.elements(),
        model.dofs()
    );
    outln!(
        "  threads: {} of {}, registers: {} (docs/user-guide.md, \"Threads\")",
        analysis::run_threads(&model),
        rayon::current_num_threads(),
        impact::profile::registers()
    );
    for line in analysis::check::roles(&model).into_iter().chain(report) {
        outln!("  {line}");
    }
    if model.bodies.iter().all(|b| b.material.density > 0.0) {
        let analysis::steppers::stable::StableStep {
            dt: dt_crit,
            body: b,
            element: e,
        } = analysis::steppers::stable::critical_time_step(&model)?;
        outln!(
            "  central-difference stability limit: dt_crit = {} (element eigenvalue bound{}; body `{}`, element {e})",
            readable(dt_crit),
            match model.analysis.bulk_viscosity() {
                Some(_) => ", without the bulk viscosity's damping",
                None => "",
            },
            model.bodies[b].name
        );
    }
    let warnings = analysis::plausibility::setup_warnings(&model);
    for warning in &warnings {
        errln!("warning: {warning}");
    }
    Ok(warnings.len())
}

fn buckle(
    path: &Path,
    modes: Option<usize>,
    out: Option<PathBuf>,
    set: &[String],
) -> Result<(), RunError> {
    let model = scene::load(path, set)?;
    let count = modes
        .or(model
            .analysis
            .buckling()
            .map(|b| b.modes)
            .filter(|m| *m > 0))
        .unwrap_or(3);
    if count == 0 {
        return Err(InputError::new(path, "--modes: ask for at least one mode").into());
    }
    let dir = out.unwrap_or_else(|| PathBuf::from("output").join(&model.name));
    analysis::create_output_folder(&dir)?;
    let found = analysis::run::buckling::linear_modes(&model, count)
        .map_err(|e| InputError::new(path, format!("linearized buckling: {e}")))?;
    analysis::run::buckling::write_modes(&model, &found, &dir)?;
    outln!(
        "{}: linearized buckling of the loads at t = {} ({} free DOFs)",
        model.name,
        readable(model.analysis.end_time()),
        model.dofs() - model.constrained_dofs().len()
    );
    for (i, mode) in found.iter().enumerate() {
        outln!("  mode {}: lambda = {:.6e}", i + 1, mode.lambda);
    }
    if found.len() < count {
        outln!("  ({} of {count} modes converged)", found.len());
    }
    outln!(
        "  mode shapes: {}",
        dir.join(format!("{}_buckling.pvd", model.name)).display()
    );
    Ok(())
}

/// `impact sweep`: its arguments.
#[derive(clap::Args)]
struct SweepArgs {
    /// The scene (not with --merge).
    scene: Option<PathBuf>,
    /// KEY=v1,v2,... or KEY1,KEY2=a1,a2;b1,b2 (keys varied together); repeat for a
    /// cross product, the first outermost.
    #[arg(long = "vary", value_name = "KEYS=VALUES")]
    vary: Vec<String>,
    /// Override a scene value in every case.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Score each case on a history.csv column: [NAME=]COLUMN (its final value) or
    /// [NAME=]STAT(COLUMN), STAT one of final, max, min, time_of_max, time_of_min,
    /// integral; e.g. --measure L_f=extent_y[all]. Repeat for several. Each gets a sweep.csv
    /// column, its error against the extrapolated value (Richardson, with the grid
    /// convergence index) and charts.
    #[arg(long = "measure", value_name = "MEASURE")]
    measure: Vec<String>,
    /// A value a measure is scored against instead of its extrapolation: NAME=VALUE (a
    /// published or closed-form value), e.g. --reference L_f=26.56e-3. Repeat for several.
    #[arg(long = "reference", value_name = "NAME=VALUE")]
    reference: Vec<String>,
    /// Write each case's VTK frames as its scene asks (default: none).
    #[arg(long)]
    frames: bool,
    /// Cases run at once. Default: one per core.
    #[arg(long, default_value_t = 0)]
    jobs: usize,
    /// Run only the cases k with k mod n = i (0 <= i < n), e.g. --shard $SLURM_ARRAY_TASK_ID/8.
    #[arg(long, value_name = "i/n")]
    shard: Option<String>,
    /// Join the case folders of these sweep folders (shards) into --out.
    #[arg(long, value_name = "DIR", num_args = 1..)]
    merge: Vec<PathBuf>,
    /// Output folder. Default: output/<scene name>_sweep/
    #[arg(long)]
    out: Option<PathBuf>,
    /// No progress bar and no closing lines.
    #[arg(long)]
    quiet: bool,
}

fn sweep(args: SweepArgs) -> Result<(), RunError> {
    use impact::sweep::{self, Measure, Plan, SweepOptions, plan};
    let SweepArgs {
        scene,
        vary,
        set,
        measure,
        reference,
        frames,
        jobs,
        shard,
        merge,
        out,
        quiet,
    } = args;
    let shard = shard.as_deref();
    let here = scene
        .clone()
        .unwrap_or_else(|| PathBuf::from("impact sweep"));
    let mut measures = measure
        .iter()
        .map(|m| Measure::parse(m).map_err(|e| InputError::new(&here, format!("--measure {e}"))))
        .collect::<Result<Vec<_>, _>>()?;
    Measure::with_references(&mut measures, &reference).map_err(|e| InputError::new(&here, e))?;
    let report = if !merge.is_empty() {
        let here = Path::new("--merge");
        if scene.is_some() || !vary.is_empty() || !set.is_empty() || shard.is_some() {
            return Err(InputError::new(
                here,
                "--merge takes the sweep folders only (their sweep.json holds the scene, --set and --vary)",
            )
            .into());
        }
        let out = out.ok_or_else(|| InputError::new(here, "--merge needs --out DIR"))?;
        sweep::merge(&merge, &out, &measures)?
    } else {
        let scene = scene.ok_or_else(|| {
            InputError::new(
                Path::new("impact sweep"),
                "name a scene (or --merge DIR...)",
            )
        })?;
        let variations = vary
            .iter()
            .map(|v| {
                plan::parse_variation(v)
                    .map_err(|m| InputError::new(&scene, format!("--vary {v}: {m}")))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let shard = shard
            .map(plan::parse_shard)
            .transpose()
            .map_err(|m| InputError::new(&scene, m))?;
        let stem = scene
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".into());
        let out = out.unwrap_or_else(|| PathBuf::from("output").join(format!("{stem}_sweep")));
        let plan = Plan {
            scene,
            sets: set.to_vec(),
            variations,
        };
        let options = SweepOptions {
            jobs,
            shard,
            progress: Progress::for_stderr(quiet, std::time::Duration::ZERO),
            frames,
        };
        sweep::run(&plan, &out, options, &measures)?
    };
    if !quiet {
        outln!(
            "sweep: {} cases, {} in this shard, {} executed, {} skipped (finished before), {} not ok -> {}",
            report.cases,
            report.in_shard,
            report.executed,
            report.skipped,
            report.not_ok,
            report.csv.display()
        );
        for chart in &report.charts {
            outln!("  {}", chart.display());
        }
        for score in &report.scores {
            for line in sweep::qoi::summary_lines(score) {
                outln!("  {line}");
            }
        }
        for note in &report.notes {
            outln!("  note: {note}");
        }
    }
    Ok(())
}

/// How `impact plot` draws: the title, one panel per column or one axis, the axis ends.
struct PlotLook {
    title: Option<String>,
    panels: bool,
    /// Logarithmic axes (x, y).
    log: (bool, bool),
    x_limits: Limits,
    y_limits: Limits,
}

fn plot_history(
    history: &Path,
    (x, y, keep): (&str, &[String], Option<&str>),
    out: Option<PathBuf>,
    look: PlotLook,
    references: &[PathBuf],
) -> Result<(), RunError> {
    let names: Vec<&str> = std::iter::once(x)
        .chain(y.iter().map(String::as_str))
        .collect();
    // a frame's point arrays, or a history's columns
    let load = |path: &Path| -> Result<Vec<Vec<f64>>, RunError> {
        let frame = path.extension().is_some_and(|e| e == "vtu");
        match (frame, keep) {
            (true, _) => plot::frame_columns(path, &names, keep),
            (false, None) => plot::history_columns(path, &names),
            (false, Some(_)) => Err(OutputError::Invalid {
                path: path.to_path_buf(),
                reason: "--where selects the points of a frame (.vtu), not rows of a history"
                    .into(),
            }),
        }
        .map_err(bad_input)
    };
    let columns = load(history)?;
    let file_name = |p: &Path| p.file_name().map(|n| n.to_string_lossy().into_owned());
    // runs' files are usually all history.csv: then their folders tell them apart
    let run_name = |p: &Path| -> String {
        match file_name(p) {
            Some(name) if file_name(history).as_ref() != Some(&name) => name,
            _ => p
                .parent()
                .and_then(file_name)
                .unwrap_or_else(|| p.display().to_string()),
        }
    };
    let own = (!references.is_empty()).then(|| run_name(history));
    let mut series = history_series(&columns, y, own.as_deref());
    for reference in references {
        let columns = load(reference)?;
        series.extend(history_series(&columns, y, Some(&run_name(reference))));
    }
    let out = out.unwrap_or_else(|| {
        let stem: String = y
            .join("_")
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        history.with_file_name(format!("plot_{stem}.svg"))
    });
    let title = look.title.unwrap_or_else(|| history.display().to_string());
    let units = column_units_beside(history);
    let labelled = |column: &str| {
        impact::sweep::qoi::with_unit(column, units.get(column).map_or("", String::as_str))
    };
    let chart = |title: String, y_label: String, series: Vec<Series>| Chart {
        title,
        x_label: labelled(x),
        y_label,
        series,
        log_x: look.log.0,
        log_y: look.log.1,
        x_limits: look.x_limits,
        y_limits: look.y_limits,
        notes: Vec::new(),
    };
    let charts = if look.panels {
        // the series of column k are the k-th of every run's group (own run, then references)
        y.iter()
            .enumerate()
            .map(|(k, column)| {
                let own: Vec<Series> = series.iter().skip(k).step_by(y.len()).cloned().collect();
                let heading = if k == 0 { title.clone() } else { String::new() };
                chart(heading, labelled(column), own)
            })
            .collect()
    } else {
        // one unit after the columns when they share it, else each column's own
        let unit_of = |c: &String| units.get(c).cloned().unwrap_or_default();
        let label = if y.iter().all(|c| unit_of(c) == unit_of(&y[0])) {
            impact::sweep::qoi::with_unit(&y.join(", "), &unit_of(&y[0]))
        } else {
            y.iter().map(|c| labelled(c)).collect::<Vec<_>>().join(", ")
        };
        vec![chart(title, label, series)]
    };
    plot::write_panels(&charts, &out).map_err(|e| match e {
        OutputError::Invalid { .. } => bad_input(e),
        other => RunError::Output(other),
    })?;
    outln!("{}", out.display());
    Ok(())
}

/// The units of the history.csv columns of the run whose history is `history`: summary.json
/// `column_units` in the same folder; none when there is no such summary (a frame's point
/// arrays, a history moved on its own, a summary of an older run).
fn column_units_beside(history: &Path) -> std::collections::BTreeMap<String, String> {
    let summary = history.with_file_name("summary.json");
    let is_history = history.extension().is_some_and(|e| e == "csv");
    std::fs::read_to_string(&summary)
        .ok()
        .filter(|_| is_history)
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .and_then(|json| serde_json::from_value(json.get("column_units")?.clone()).ok())
        .unwrap_or_default()
}

/// One line series per y column of `columns` (x first, then the y columns in order).
fn history_series(columns: &[Vec<f64>], y: &[String], run: Option<&str>) -> Vec<Series> {
    let (x, ys) = columns.split_first().expect("the x column is asked first");
    y.iter()
        .zip(ys)
        .map(|(name, values)| Series {
            label: match run {
                Some(run) => format!("{name} ({run})"),
                None => name.clone(),
            },
            points: x.iter().copied().zip(values.iter().copied()).collect(),
            style: SeriesStyle::Line,
        })
        .collect()
}

/// A history that cannot be read, lacks a column or cannot be plotted is bad input (exit 2).
fn bad_input(e: OutputError) -> RunError {
    match e {
        OutputError::Io {
            path,
            action,
            source,
        } => InputError::new(&path, format!("cannot {action}: {source}")).into(),
        OutputError::Invalid { path, reason } => InputError::new(&path, reason).into(),
        OutputError::Length {
            path,
            what,
            expected,
            found,
        } => InputError::new(
            &path,
            format!("{what} has {found} entries, expected {expected}"),
        )
        .into(),
        other => RunError::Output(other),
    }
}
