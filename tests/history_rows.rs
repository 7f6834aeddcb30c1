//! history.csv at a cadence (`output.history_every`, `output.history_interval`, the default
//! grid of `end_time / 1e4`): the rows written are steps' rows, the peaks between them are
//! kept, the frames and the last step are rows, summary.json reads every step.

mod common;

use std::path::Path;

/// The rows of a history.csv as text lines (the header first).
fn lines(dir: &Path) -> Vec<String> {
    std::fs::read_to_string(dir.join("history.csv"))
        .unwrap()
        .lines()
        .map(String::from)
        .collect()
}

/// A row's numbers.
fn numbers(line: &str) -> Vec<f64> {
    line.split(',').map(|x| x.parse().unwrap()).collect()
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// Goal: thinned rows are a subset of the every-step run's rows, byte for byte, in order; the
/// first, the last and one at each frame time are there; every column's largest and smallest
/// value over all steps is a row to 1e-4 of the column's scale (the module's rule); summary.json
/// is the same whatever the cadence (its peaks read every step). Setup: steel_block_wall
/// (central difference, automatic step, a frame every microsecond to 30 us, ~650 steps)
/// once with a row every step and once with a row every 3 us (10 rows on the grid).
/// Reference: the every-step run (the steps are the same: the cadence must not change them).
#[test]
fn thinned_rows_are_steps_rows_with_every_peak() {
    let every = common::run_scene(
        "history_every_step",
        "steel_block_wall",
        &["output.history_every=1"],
    );
    let thin = common::run_scene(
        "history_thin",
        "steel_block_wall",
        &["output.history_interval=3e-6"],
    );
    let (all, some) = (lines(&every.dir), lines(&thin.dir));
    assert_eq!(all[0], some[0], "header");
    assert_eq!(
        all.len() as u64,
        every.summary.steps as u64 + 2,
        "a row per step"
    );
    // a subsequence of the full rows, with the first and the last
    let mut k = 1;
    for row in &some[1..] {
        while k < all.len() && &all[k] != row {
            k += 1;
        }
        assert!(
            k < all.len(),
            "row {row} is not a step's row (or out of order)"
        );
    }
    assert_eq!(some[1], all[1]);
    assert_eq!(some.last(), all.last());
    // a row at each frame time (the automatic step ends on them)
    let times: Vec<f64> = some[1..].iter().map(|r| numbers(r)[0]).collect();
    for j in 1..=30 {
        let t = j as f64 * 1e-6;
        assert!(
            times.iter().any(|x| (x - t).abs() <= 1e-9 * t),
            "no row at the frame time {t}"
        );
    }
    // few rows beside the grid's and the frames'
    assert!(
        some.len() < all.len() / 3,
        "{} of {} rows",
        some.len(),
        all.len()
    );
    // every column's extremes
    let full: Vec<Vec<f64>> = all[1..].iter().map(|r| numbers(r)).collect();
    let kept: Vec<Vec<f64>> = some[1..].iter().map(|r| numbers(r)).collect();
    let names: Vec<&str> = all[0].split(',').collect();
    for (c, name) in names.iter().enumerate() {
        let max = |v: &[Vec<f64>]| v.iter().map(|r| r[c]).fold(f64::MIN, f64::max);
        let min = |v: &[Vec<f64>]| v.iter().map(|r| r[c]).fold(f64::MAX, f64::min);
        let scale = max(&full).abs().max(min(&full).abs());
        assert!(max(&full) - max(&kept) <= 1e-4 * scale, "{name}: max");
        assert!(min(&kept) - min(&full) <= 1e-4 * scale, "{name}: min");
    }
    // summary.json does not depend on the cadence
    let (a, b) = (summary(&every.dir), summary(&thin.dir));
    for key in ["steps", "contact", "energy", "dt_min", "dt_max", "probes"] {
        assert_eq!(a[key], b[key], "summary.json `{key}`");
    }
}

/// Goal: the default cadence writes every step of a run shorter than 1e4 steps and at most
/// ~1e4 rows on the grid of a longer one. Setup: bar_wall (implicit, 1e2-1e3 steps) at the
/// default; steel_block_wall forced to 2e4 fixed steps (dt = 1.5e-9, below its stable step)
/// without frames. Reference: the counts by the rule (1e4 grid rows plus the first, and the
/// steps where a column peaks between them).
#[test]
fn default_cadence_is_every_step_or_the_grid() {
    let short = common::run_scene("history_default_short", "bar_wall", &[]);
    assert_eq!(
        lines(&short.dir).len() as u64,
        short.summary.steps as u64 + 2,
        "a row per step and the initial one"
    );
    let long = common::run_scene(
        "history_default_long",
        "steel_block_wall",
        &["analysis.dt=1.5e-9", "output.frame_interval=3e-5"],
    );
    assert_eq!(long.summary.steps, 20_000);
    // impact check says so beforehand: the grid's end_time / (end_time / 1e4) rows
    let check = common::impact(&[
        "check",
        "models/steel_block_wall.toml",
        "--set",
        "analysis.dt=1.5e-9",
    ]);
    let stdout = String::from_utf8_lossy(&check.stdout);
    assert!(
        stdout.contains("history.csv: a row at every multiple of 3e-9")
            && stdout.contains("about 10000 rows"),
        "{stdout}"
    );
    let rows = lines(&long.dir).len() - 1;
    // the grid's 1e4 rows and the first; peaks of the contact force and the probes between
    // them (a block settling on a wall: its energies are monotone or smooth between rows)
    assert!((10_001..15_000).contains(&rows), "{rows} rows");
}

/// Goal: a cadence that is no cadence is refused with the key named, exit 2.
#[test]
fn bad_cadence_is_refused() {
    common::check_refuses(&[
        (
            "models/bar_wall.toml",
            "output.history_every=0",
            "output.history_every",
        ),
        (
            "models/bar_wall.toml",
            "output.history_interval=-1",
            "output.history_interval",
        ),
        (
            "models/bar_wall.toml",
            "output.history_interval=0",
            "output.history_interval",
        ),
    ]);
}
