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
    let report = sweep::run(&p, &dir, options(2, None)).unwrap();
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
        impact::analysis::stable::critical_time_step(
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
    let report = sweep::run(&p, &dir, options(2, None)).unwrap();
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
    let first = sweep::run(&p, &whole, options(2, None)).unwrap();
    assert_eq!((first.executed, first.skipped), (4, 0));
    let again = sweep::run(&p, &whole, options(2, None)).unwrap();
    assert_eq!((again.executed, again.skipped), (0, 4));
    let (a, b) = (
        common::out_dir("sweep_shard0"),
        common::out_dir("sweep_shard1"),
    );
    let s0 = sweep::run(&p, &a, options(1, Some((0, 2)))).unwrap();
    let s1 = sweep::run(&p, &b, options(1, Some((1, 2)))).unwrap();
    assert_eq!((s0.executed, s1.executed), (2, 2));
    let merged = common::out_dir("sweep_merged");
    let m = sweep::merge(&[a, b], &merged).unwrap();
    assert_eq!(m.not_ok, 0);
    assert_eq!(deterministic(&m.csv), deterministic(&first.csv));
}

/// Goal: bad input to `impact sweep` exits 2 with a message naming what is wrong, before
/// anything runs; never a panic.
#[test]
fn sweep_bad_input_exits_2() {
    let dir = common::out_dir("sweep_bad_input");
    let out = dir.join("out");
    let cases: [(&[&str], &str); 5] = [
        (&["--vary", "analysis.dtt=0.1,0.2"], "dtt"),
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
