//! `impact sweep`: convergence of the contact force on the Hughes bar problems
//! against the exact (d'Alembert) solutions, the stability of the integrators against the
//! central-difference limit, reruns that do no work, shards that merge into the whole.

mod common;

use impact::sweep::{self, Plan, SweepOptions, plan::parse_variation};
use std::path::{Path, PathBuf};
use std::process::Command;

fn plan(scene: &str, sets: &[&str], vary: &[&str]) -> Plan {
    Plan {
        scene: PathBuf::from(format!("models/{scene}.toml")),
        sets: sets.iter().map(|s| s.to_string()).collect(),
        variations: vary.iter().map(|v| parse_variation(v).unwrap()).collect(),
    }
}

fn options(jobs: usize, shard: Option<(usize, usize)>) -> SweepOptions {
    SweepOptions {
        jobs,
        shard,
        progress: impact::analysis::progress::Mode::Off,
        frames: false,
    }
}

/// Least-squares slope of log e against log dt.
fn observed_order(points: &[(f64, f64)]) -> f64 {
    impact::sweep::charts::fitted_slope(points).unwrap().0
}

/// Goal: on two_bars (Newmark average, impact and release conditions),
/// refining h and dt together (Courant number 0.7) makes the contact-force error fall.
/// Setup: a zipped --vary over n = 14, 28, 56 rods per bar with dt = 0.005, 0.0025, 0.00125.
/// Reference (exact, reference::equal_bars_impact): F = rho c A V / 2 = 0.05 on 0 < t < 0.2.
/// Asserted: (a) the L2 error away from the jumps (|t| and |t - 0.2| >= 0.025, the window of
/// tests/contact.rs) falls with observed order >= 1 (measured 1.46 over these three levels,
/// 1.5 with a fourth); (b) the whole-history L2 error falls with an order in [0.3, 0.7]:
/// a jump in the exact force caps it at 1/2 (measured 0.46); (c) the release time lies
/// within one dt of 0.2 on every level; (d) the converged-reference columns name the finest
/// case as that reference.
#[test]
fn two_bars_force_error_converges_with_h_and_dt_together() {
    let dir = common::out_dir("sweep_two_bars_convergence");
    let p = plan(
        "two_bars",
        &[],
        &["body.bar1.mesh.n,body.bar2.mesh.n,analysis.dt=14,14,0.005;28,28,0.0025;56,56,0.00125"],
    );
    let report = sweep::run(&p, &dir, options(2, None), &[]).unwrap();
    assert_eq!(report.executed, 3);
    let mut smooth = Vec::new();
    let mut whole = Vec::new();
    for row in &report.rows {
        assert_eq!(row.status, "ok");
        let dt = row.dt.unwrap();
        let m = &row.measures;
        smooth.push((dt, m.force_l2_smooth.unwrap()));
        whole.push((dt, m.force_l2.unwrap()));
        let release = m.release_time.unwrap();
        assert!(
            (release - 0.2).abs() <= dt + 1e-12,
            "release at {release} with dt = {dt}"
        );
    }
    let (p_smooth, p_whole) = (observed_order(&smooth), observed_order(&whole));
    assert!(
        p_smooth >= 1.0,
        "order away from jumps {p_smooth}: {smooth:?}"
    );
    assert!(
        (0.3..=0.7).contains(&p_whole),
        "order of the whole history {p_whole}: {whole:?}"
    );
    assert!(report.csv.is_file());
    // (d) beside the declared reference, the converged one is the finest case (n = 56): it
    // has no error against itself, the two coarser levels have one
    let converged: Vec<Option<f64>> = report
        .rows
        .iter()
        .map(|r| r.measures.converged_force_l2)
        .collect();
    assert!(converged[2].is_none(), "{converged:?}");
    assert!(converged[..2].iter().all(|e| e.is_some_and(|e| e > 0.0)));
    for chart in [
        "error_vs_dt.png",
        "error_vs_h.svg",
        "error_vs_cpu.svg",
        "error_vs_cpu_converged.svg",
    ] {
        assert!(dir.join(chart).is_file(), "{chart}");
    }
}

/// Goal: the stability map. Setup: bar_wall (dt_crit = h / c = 1/140 for
/// the lumped rod, reference: the element bound 2 / omega_max with omega_max = 2 c / h),
/// to t = 0.4 as in the scene (a shorter run catches Wilson's known first-steps overshoot,
/// Hilber and Hughes 1978, as an energy gain: +43 % at t = 0.1 with 10 dt_crit, -18 % by the
/// end). Reference: central difference is stable for dt <= dt_crit and not
/// above (von Neumann); Newmark average, Hu, Houbolt and Wilson 1.4 are unconditionally
/// stable. Asserted: central difference `ok` at 0.95 dt_crit and `unstable` at 1.05 dt_crit;
/// the four implicit methods `ok` (bounded: no energy gain over 5 %) at 10 dt_crit.
#[test]
fn stability_map_central_difference_fails_just_above_dt_crit() {
    let dt_crit = 10.0 / 14.0 / 100.0;
    approx::assert_relative_eq!(
        impact::analysis::steppers::stable::critical_time_step(
            &impact::scene::load(Path::new("models/bar_wall.toml"), &[]).unwrap()
        )
        .unwrap()
        .dt,
        dt_crit,
        max_relative = 1e-9
    );
    let dir = common::out_dir("sweep_stability");
    let dts: Vec<String> = [0.95, 1.05, 10.0]
        .iter()
        .map(|r| format!("{}", r * dt_crit))
        .collect();
    let p = plan(
        "bar_wall",
        &[],
        &[
            "analysis.integrator,analysis.allow_unstable,analysis.mass=central_difference,true,lumped;average,false,consistent;hu,false,consistent;houbolt,false,consistent;wilson,false,consistent",
            &format!("analysis.dt={}", dts.join(",")),
        ],
    );
    let report = sweep::run(&p, &dir, options(2, None), &[]).unwrap();
    let cell = |integrator: &str, ratio: f64| {
        let row = report
            .rows
            .iter()
            .find(|r| {
                r.integrator == integrator && (r.dt_over_dt_crit().unwrap() - ratio).abs() < 1e-6
            })
            .unwrap();
        (row.status.clone(), impact::sweep::charts::cell(row).kind)
    };
    use impact::output::plot::CellKind;
    assert_eq!(cell("central_difference", 0.95).0, "ok");
    assert_eq!(cell("central_difference", 1.05).1, CellKind::Unstable);
    for integrator in ["average", "hu", "houbolt", "wilson"] {
        let (status, kind) = cell(integrator, 10.0);
        assert_eq!(status, "ok", "{integrator}");
        assert!(
            matches!(kind, CellKind::Stable | CellKind::Damped),
            "{integrator}: {kind:?}"
        );
    }
    assert!(dir.join("stability_map.png").is_file());
}

/// The sweep.csv columns that do not depend on timing (all but wall_seconds and
/// cpu_seconds).
fn deterministic(csv: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(csv).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let timing: Vec<usize> = ["wall_seconds", "cpu_seconds"]
        .iter()
        .map(|c| header.iter().position(|h| h == c).unwrap())
        .collect();
    text.lines()
        .map(|l| {
            l.split(',')
                .enumerate()
                .filter(|(k, _)| !timing.contains(k))
                .map(|(_, v)| v)
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect()
}

/// Goal: a rerun of a finished sweep does no work, and two shards merged
/// equal the unsharded sweep. Setup: two_bars to t = 0.05, 2 integrators x 2 dt (4 cases).
/// Reference: the report's count of executed runs (0 on the rerun); the merged sweep.csv
/// equals the unsharded one in every column but the timings (each case runs on one thread:
/// bitwise the same numbers).
#[test]
fn rerun_does_no_work_and_merged_shards_equal_the_whole() {
    let p = plan(
        "two_bars",
        &["analysis.end_time=0.05"],
        &[
            "analysis.integrator=average,wilson",
            "analysis.dt=0.005,0.0025",
        ],
    );
    let whole = common::out_dir("sweep_whole");
    let first = sweep::run(&p, &whole, options(2, None), &[]).unwrap();
    assert_eq!((first.executed, first.skipped), (4, 0));
    let again = sweep::run(&p, &whole, options(2, None), &[]).unwrap();
    assert_eq!((again.executed, again.skipped), (0, 4));
    let (a, b) = (
        common::out_dir("sweep_shard0"),
        common::out_dir("sweep_shard1"),
    );
    let s0 = sweep::run(&p, &a, options(1, Some((0, 2))), &[]).unwrap();
    let s1 = sweep::run(&p, &b, options(1, Some((1, 2))), &[]).unwrap();
    assert_eq!((s0.executed, s1.executed), (2, 2));
    let merged = common::out_dir("sweep_merged");
    let m = sweep::merge(&[a, b], &merged, &[]).unwrap();
    assert_eq!(m.not_ok, 0);
    assert_eq!(deterministic(&m.csv), deterministic(&first.csv));
}

/// Goal: a finished study takes a finer level: rerun with the value added, it runs only the
/// new case; a level run apart merges with the study. Setup: two_bars to t = 0.05, Newmark
/// at dt = 0.005 and 0.0025 (2 cases), then dt = 0.00125 added; apart: the 2-case study in
/// one folder and the 3-case plan's shard 2/3 (its dt = 0.00125 case alone) in another.
/// Reference: the reports' counts of runs (1 executed and 2 skipped on the extension: a
/// case's folder hashes its own overrides, so the finished ones are found); the merged
/// table equals the extended study's in every column but the timings (each case runs on one
/// thread: bitwise the same numbers). Without the extension, the rerun was refused ("this
/// folder holds another sweep") and so was the merge.
#[test]
fn a_study_extended_by_a_level_runs_only_that_level_and_merges() {
    let two = plan(
        "two_bars",
        &["analysis.end_time=0.05"],
        &["analysis.dt=0.005,0.0025"],
    );
    let three = plan(
        "two_bars",
        &["analysis.end_time=0.05"],
        &["analysis.dt=0.005,0.0025,0.00125"],
    );
    let study = common::out_dir("sweep_extended");
    let first = sweep::run(&two, &study, options(1, None), &[]).unwrap();
    assert_eq!((first.executed, first.skipped), (2, 0));
    let extended = sweep::run(&three, &study, options(1, None), &[]).unwrap();
    assert_eq!((extended.executed, extended.skipped), (1, 2));
    assert_eq!(extended.not_ok, 0);
    let (apart, level) = (
        common::out_dir("sweep_apart_study"),
        common::out_dir("sweep_apart_level"),
    );
    sweep::run(&two, &apart, options(1, None), &[]).unwrap();
    let finer = sweep::run(&three, &level, options(1, Some((2, 3))), &[]).unwrap();
    assert_eq!(finer.executed, 1);
    let merged = common::out_dir("sweep_apart_merged");
    let m = sweep::merge(&[apart, level], &merged, &[]).unwrap();
    assert_eq!((m.cases, m.not_ok), (3, 0));
    assert_eq!(deterministic(&m.csv), deterministic(&extended.csv));
}

/// Goal: bad input to `impact sweep` exits 2 with a message naming what is wrong, before
/// anything runs; never a panic.
#[test]
fn sweep_bad_input_exits_2() {
    let dir = common::out_dir("sweep_bad_input");
    let out = dir.join("out");
    let cases: [(&[&str], &str); 9] = [
        (&["--vary", "analysis.dtt=0.1,0.2"], "dtt"),
        (
            &[
                "--vary",
                "analysis.dt=0.01",
                "--measure",
                "max(nothing[all])",
            ],
            "nothing[all]",
        ),
        (
            &[
                "--vary",
                "analysis.dt=0.01",
                "--measure",
                "mean(v_x[bar1.all])",
            ],
            "unknown statistic",
        ),
        (
            &[
                "--vary",
                "analysis.dt=0.01",
                "--measure",
                "v=v_x[bar1.all]",
                "--reference",
                "w=1",
            ],
            "no --measure is named `w`",
        ),
        (
            &[
                "--vary",
                "analysis.dt=0.01",
                "--measure",
                "v=v_x[bar1.all]",
                "--measure",
                "v=max(v_x[bar2.all])",
            ],
            "two measures are named `v`",
        ),
        (&["--vary", "analysis.dt=0.1,abc"], "analysis.dt"),
        (&["--vary", "analysis.dt"], "--vary"),
        (&["--vary", "analysis.dt=0.01", "--shard", "2/2"], "--shard"),
        (&["--vary", "body.bar9.mesh.n=3"], "bar9"),
    ];
    for (args, needle) in cases {
        let o = Command::new(env!("CARGO_BIN_EXE_impact"))
            .args(["sweep", "models/two_bars.toml", "--quiet", "--out"])
            .arg(&out)
            .args(args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    let o = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(["sweep", "--merge"])
        .arg(dir.join("nothing"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// Runs a sweep of the scene `text` (written into the test's folder) with `vary` and one
/// `--measure` (scored against `reference` when given); returns the measure's score of the
/// only series and the rows.
fn measured(
    name: &str,
    text: &str,
    vary: &str,
    measure: &str,
    reference: Option<f64>,
) -> (
    impact::sweep::qoi::SeriesScore,
    Vec<impact::sweep::measure::Row>,
) {
    let dir = common::out_dir(name);
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, text).unwrap();
    let p = Plan {
        scene,
        sets: Vec::new(),
        variations: vec![parse_variation(vary).unwrap()],
    };
    let mut measures = [impact::sweep::Measure::parse(measure).unwrap()];
    measures[0].reference = reference;
    let report = sweep::run(&p, &dir.join("sweep"), options(2, None), &measures).unwrap();
    assert_eq!(report.not_ok, 0);
    assert_eq!(report.scores[0].series.len(), 1);
    (report.scores[0].series[0].clone(), report.rows)
}

/// Goal: the extrapolated value of a measure and its grid convergence index bracket the
/// exact value, with the method's order observed, in dt and in h.
/// Setup and references:
/// - the unit oscillator with Newmark average to t = 10 at dt = 0.2, 0.1, 0.05, measure
///   u(10), exact sin 10; the trapezoidal rule is second order (its phase error is
///   (omega dt)^2 / 12 per radian, Hughes 1987, 9.3), and the energy it conserves keeps the
///   amplitude exact;
/// - Lame's cylinder with 8, 16, 32 elements through the wall, measure the bore's u_r, exact
///   reference::lame_radial_displacement; bilinear quads converge as h^2 in displacement.
/// Asserted: the observed order within 0.2 of 2 (Celik et al. 2008: three levels at ratio 2),
/// the exact value inside the GCI band of the finest value, f1 (1 +- GCI), and inside
/// f_ext +- GCI |f1|; the extrapolation closer to the exact value than the finest case.
/// Measured: oscillator p = 2.006, f_ext 1.4e-5 from exact (finest 3.2e-3), GCI 4.0e-3;
/// Lame p = 1.986, f_ext 1.6e-6 (finest 1.6e-4), GCI 2.0e-4.
#[test]
fn extrapolation_and_gci_bracket_the_exact_value() {
    let lame = impact::reference::lame_radial_displacement(1.0, (1.0, 2.0), (1000.0, 0.3), 1.0);
    // the bore's mean u_r (plain Q4: B-bar is off for an elastic material by default)
    let cylinder = format!(
        "{}\n[[output.probe]]\nquantity = \"u_x\"\nset = \"left\"\n",
        common::LAME_CYLINDER_AXISYMMETRIC
    );
    let studies = [
        (
            "sweep_gci_oscillator",
            common::UNIT_OSCILLATOR,
            "analysis.dt=0.2,0.1,0.05",
            "u=u_x[end]",
            10f64.sin(),
        ),
        (
            "sweep_gci_lame",
            cylinder.as_str(),
            "body.cylinder.mesh.nx=8,16,32",
            "u=u_x[left]",
            lame,
        ),
    ];
    for (name, text, vary, measure, exact) in studies {
        let (score, rows) = measured(name, text, vary, measure, None);
        let e = score.extrapolation.expect("three levels");
        let (order, value, gci) = (e.order.unwrap(), e.value.unwrap(), e.gci.unwrap());
        let f1 = e.values[0];
        println!(
            "{name}: values {:?}, order {order:.3}, extrapolated {value:.8e} (exact {exact:.8e}), GCI {:.3e}, finest error {:.3e}",
            e.values,
            gci,
            (f1 - exact).abs() / exact.abs()
        );
        assert!((order - 2.0).abs() <= 0.2, "{name}: order {order}");
        assert!((f1 - exact).abs() <= gci * f1.abs(), "{name}");
        assert!((value - exact).abs() <= gci * f1.abs(), "{name}");
        assert!((value - exact).abs() < (f1 - exact).abs(), "{name}");
        // every case, the finest included, has an error against the extrapolation
        assert!(
            rows.iter()
                .all(|r| r.quantity_errors[0].is_some_and(|e| e != 0.0)),
            "{name}"
        );
    }
}

/// Goal: without a reference, no case is scored against itself and no zero error reaches
/// sweep.csv or a fitted slope. Setup: models/two_bars.toml with its [reference] removed,
/// dt = 0.005 and 0.0025 (n = 14 rods per bar), and a measure of the first bar's final
/// velocity: two levels, so nothing can be extrapolated.
/// Asserted: the finest case (the reference history) has no force_l2 and no peak force
/// error; every error that is reported is nonzero; the measure falls back to the finest
/// case, which then has no error of its own.
#[test]
fn a_sweep_without_reference_never_scores_a_case_against_itself() {
    let text = std::fs::read_to_string("models/two_bars.toml").unwrap();
    let text = text.split("[reference]").next().unwrap().to_string();
    let (score, rows) = measured(
        "sweep_no_reference",
        &text,
        "analysis.dt=0.005,0.0025",
        "v=v_x[bar1.all]",
        None,
    );
    let finest = rows
        .iter()
        .min_by(|a, b| a.dt.unwrap().total_cmp(&b.dt.unwrap()))
        .unwrap();
    assert!(finest.measures.force_l2.is_none());
    assert!(finest.measures.peak_force_error.is_none());
    for row in &rows {
        let m = &row.measures;
        for e in [m.force_l2, m.peak_force_error, row.quantity_errors[0]]
            .into_iter()
            .flatten()
        {
            assert!(e != 0.0, "{}: a zero error", row.folder);
        }
    }
    assert_eq!(score.reference_kind, Some("finest case"));
    assert_eq!(score.finest.as_deref(), Some(finest.folder.as_str()));
    assert!(finest.quantity_errors[0].is_none());
}

/// Goal: a measure with a given reference (`--reference NAME=VALUE`, a closed form or a
/// published value) is scored against it, every case, the finest included, while the
/// extrapolation is still reported. Setup: the oscillator at dt = 0.2, 0.1, 0.05, u(10).
/// Reference: sin 10 (exact); each error is (u - sin 10) / |sin 10| from the case's own value.
#[test]
fn a_given_reference_scores_every_case() {
    let exact = 10f64.sin();
    let (score, rows) = measured(
        "sweep_given_reference",
        common::UNIT_OSCILLATOR,
        "analysis.dt=0.2,0.1,0.05",
        "u=u_x[end]",
        Some(exact),
    );
    assert_eq!(score.reference_kind, Some("given"));
    assert!(score.extrapolation.is_some_and(|e| e.value.is_some()));
    for row in &rows {
        let u = row.quantities[0].unwrap();
        let error = row.quantity_errors[0].unwrap();
        approx::assert_relative_eq!(error, (u - exact) / exact.abs(), max_relative = 1e-12);
    }
}

/// Goal: two methods' fronts are scored against one answer, and a series that cannot
/// extrapolate keeps its finest case on the charts. Setup: the unit oscillator to t = 10,
/// u(10), Newmark average at dt = 0.2, 0.1, 0.05 (three levels: extrapolated) beside
/// Wilson-theta at dt = 0.1, 0.05 (two levels: none). Reference: sin 10, exact. Before, each
/// series was scored against its own reference: Wilson's finest case against itself (no
/// error, off the chart), its other case against it. Now both series carry the same
/// reference, the average's extrapolation (within its GCI of sin 10, as the GCI study above
/// shows), and every case has an error against it: Wilson's finest one within that GCI of
/// its error against sin 10 itself.
#[test]
fn two_methods_are_scored_against_one_reference() {
    let dir = common::out_dir("sweep_common_reference");
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, common::UNIT_OSCILLATOR).unwrap();
    let p = Plan {
        scene,
        sets: Vec::new(),
        variations: vec![
            parse_variation(
                "analysis.integrator,analysis.dt=average,0.2;average,0.1;average,0.05;wilson,0.1;wilson,0.05",
            )
            .unwrap(),
        ],
    };
    let measures = [impact::sweep::Measure::parse("u=u_x[end]").unwrap()];
    let report = sweep::run(&p, &dir.join("sweep"), options(2, None), &measures).unwrap();
    assert_eq!(report.not_ok, 0);
    let series = &report.scores[0].series;
    assert_eq!(series.len(), 2);
    let (average, wilson) = (&series[0], &series[1]);
    let e = average.extrapolation.as_ref().unwrap();
    let (value, gci) = (e.value.unwrap(), e.gci.unwrap());
    assert!(
        wilson
            .extrapolation
            .as_ref()
            .is_none_or(|e| e.value.is_none())
    );
    let exact = 10f64.sin();
    assert!((value - exact).abs() <= gci * exact.abs());
    for s in series {
        assert_eq!(s.reference, Some(value), "{}", s.series);
        assert_eq!(s.reference_kind, Some("extrapolated"));
        assert_eq!(s.reference_series.as_deref(), Some(average.series.as_str()));
    }
    for row in &report.rows {
        let (u, error) = (row.quantities[0].unwrap(), row.quantity_errors[0]);
        let error = error.unwrap_or_else(|| panic!("{}: no error", row.folder));
        approx::assert_relative_eq!(error, (u - value) / value.abs(), max_relative = 1e-12);
        if row.integrator == "wilson" && row.dt == Some(0.05) {
            assert!((error - (u - exact) / exact.abs()).abs() <= gci, "{error}");
        }
    }
}

/// Goal: `--jobs 1` runs one case at a time (it once ran every case at once: a rayon thread
/// waiting on a case's own one-thread pool stole the next cases meanwhile). Setup: three
/// two_bars cases (n = 300, 400, 500 rods per bar, 0.1-0.3 s each, well above the sweep's
/// own work) with `jobs = 1`. Reference: cases run one
/// after another take, together, no more wall time than the sweep around them (each case's
/// wall is measured inside it); run at once, their walls overlap and add up to more (the
/// three-case sweep of taylor_jc: 1.31 s around 0.22 + 0.61 + 1.24 s).
#[test]
fn one_job_runs_one_case_at_a_time() {
    let dir = common::out_dir("sweep_one_job");
    let p = plan(
        "two_bars",
        &[],
        &[
            "body.bar1.mesh.n,body.bar2.mesh.n,analysis.dt=300,300,0.0008;400,400,0.0006;500,500,0.0005",
        ],
    );
    let start = std::time::Instant::now();
    let report = sweep::run(&p, &dir, options(1, None), &[]).unwrap();
    let around = start.elapsed().as_secs_f64();
    assert_eq!(report.executed, 3);
    let cases: f64 = report.rows.iter().map(|r| r.wall_seconds.unwrap()).sum();
    eprintln!("cases {cases} around {around}");
    assert!(
        cases <= around,
        "cases {cases} s inside a sweep of {around} s"
    );
}
