//! `impact bench --quick`: every case runs, and the solver counters obey the design's rules
//! (contact through the Schur complement on a K* factored once). No
//! timing is asserted: speed is measured by `impact bench` itself (docs/performance.md).

use impact::bench::Row;
use std::path::Path;
use std::process::Command;

/// Runs `impact bench --quick ARGS --out DIR` (DIR emptied first) and reads its bench.json.
fn quick_bench(dir: &Path, args: &[&str]) -> Vec<Row> {
    let _ = std::fs::remove_dir_all(dir);
    let o = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(["bench", "--quick"])
        .args(args)
        .arg("--out")
        .arg(dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_str(&std::fs::read_to_string(dir.join("bench.json")).unwrap()).unwrap()
}

/// Goal: the quick bench runs end to end and its counters show the factor-once contact.
/// Setup: `impact bench --quick` (2 sizes, implicit / explicit / fast explicit, free flight,
/// frames, the elastic contact pair with K* factored once), about a second of runs.
/// Reference: the design rule, counted independently of the run: with `strategy = "initial"`
/// and a constant dt, one factorization for the whole run (a contact status change never
/// refactors; only a stalled iteration or a step cut would, and this elastic run has
/// neither); the Schur complement needs no whole back-substitution (K*^-1 among the
/// constrained equations comes from forward solves along the elimination tree), and an
/// iteration with active constraints costs one, as without (the constrained correction is
/// added between its forward and backward halves): one back-substitution per Newton
/// iteration in all three runs (wall, supports in its place, free flight).
/// Tolerance: exact counts.
#[test]
fn quick_bench_runs_and_contact_never_refactors() {
    let dir = std::env::temp_dir().join(format!("impact_bench_test_{}", std::process::id()));
    let rows = quick_bench(&dir, &[]);
    assert_eq!(rows.len(), impact::bench::plan(true).len());
    for r in &rows {
        // speeds are measured by `impact bench`, not asserted here
        assert_eq!(r.status, "ok", "{}", r.name);
        let shares = [
            r.share.assembly,
            r.share.factorization,
            r.share.solve,
            r.share.contact,
            r.share.output,
        ];
        // phases are disjoint parts of the wall time (the constitutive update is inside
        // assembly)
        assert!(
            shares.iter().sum::<f64>() <= 1.0 + 1e-9,
            "{}: {shares:?}",
            r.name
        );
    }
    let row = |name: &str| rows.iter().find(|r| r.name == name).unwrap();
    let contact = row("implicit_60_elastic");
    let free = row("implicit_60_elastic_free");
    assert_eq!(contact.factorizations, 1);
    assert_eq!(free.factorizations, 1);
    assert_eq!(contact.back_substitutions, contact.newton_iterations);
    assert_eq!(free.back_substitutions, free.newton_iterations);
    let supported = row("implicit_60_elastic_supported");
    assert_eq!(supported.factorizations, 1);
    assert_eq!(supported.back_substitutions, supported.newton_iterations);
    for chart in ["bench_throughput.svg", "bench_time_breakdown.svg"] {
        assert!(dir.join(chart).is_file(), "{chart}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Goal: `--case` keeps the matching cases only, and a filter that matches none is bad input
/// (exit 2 naming it), not an empty bench. Reference: the plan's own names.
#[test]
fn bench_case_filter_runs_matching_cases_and_rejects_an_empty_selection() {
    let dir = std::env::temp_dir().join(format!("impact_bench_case_{}", std::process::id()));
    let rows = quick_bench(&dir, &["--case", "implicit_20"]);
    let names: Vec<&str> = rows.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["implicit_20"]);
    let o = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(["bench", "--quick", "--case", "no_such_case", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no_such_case"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Goal: `impact bench --scenes` runs the shipped scenes as they are. Setup: `--scenes --case
/// scene_two_bars --case scene_bar_wall` from the repository root (which also picks their
/// `_smooth` variants). Reference: the scenes' own steps, end_time / dt = 0.4 / 0.005 = 80
/// each (Newmark at a fixed step, no cut), status ok.
#[test]
fn bench_scenes_runs_the_shipped_scenes() {
    let dir = std::env::temp_dir().join(format!("impact_bench_scenes_{}", std::process::id()));
    let o = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args([
            "bench",
            "--scenes",
            "--case",
            "scene_two_bars",
            "--case",
            "scene_bar_wall",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows: Vec<impact::bench::Row> =
        serde_json::from_str(&std::fs::read_to_string(dir.join("bench.json")).unwrap()).unwrap();
    let names: Vec<&str> = rows.iter().map(|r| r.name.as_str()).collect();
    // `--case` picks the cases whose name contains it: the smooth variants come along
    assert_eq!(
        names,
        [
            "scene_bar_wall",
            "scene_bar_wall_smooth",
            "scene_two_bars",
            "scene_two_bars_smooth"
        ]
    );
    for row in &rows {
        assert_eq!(row.status, "ok");
        assert_eq!(row.steps, 80, "{}", row.name);
        assert!(row.scene.as_deref().is_some_and(|s| s.ends_with(".toml")));
    }
    let _ = std::fs::remove_dir_all(&dir);
}
