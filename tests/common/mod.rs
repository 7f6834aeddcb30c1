//! Shared by the integration tests: run a scene given as text, in a fresh output folder.
#![allow(dead_code)]

use impact::analysis::{self, RunOptions, Summary};
use impact::assembly::State;
use impact::scene::{self, Model};
use std::path::{Path, PathBuf};

/// The folder of this test binary's outputs: `impact-tests/<binary>` under the system temp
/// dir, one per test binary and build (its file name carries cargo's hash), so that a run
/// replaces the last run's outputs, left for inspection, instead of piling up beside them
/// (one folder per process had filled a development disk with 55 GB).
pub fn tests_root() -> PathBuf {
    let binary = std::env::current_exe()
        .ok()
        .and_then(|exe| exe.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .unwrap_or_else(|| std::process::id().to_string());
    std::env::temp_dir().join("impact-tests").join(binary)
}

/// A fresh, empty output folder under `tests_root`, unique per test name.
pub fn out_dir(name: &str) -> PathBuf {
    let dir = tests_root().join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The output folder of `run(name, ..)`, as it is (not emptied).
pub fn out_dir_of(name: &str) -> PathBuf {
    tests_root().join(name)
}

/// Builds the model of a scene text as if it were the file `tests/<name>.toml` (so mesh
/// files resolve against tests/), with `--set` overrides.
pub fn model(name: &str, text: &str, overrides: &[&str]) -> Model {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    scene::from_str(
        text,
        &Path::new("tests").join(format!("{name}.toml")),
        &overrides,
    )
    .unwrap_or_else(|e| panic!("scene `{name}` is invalid: {e}"))
}

/// Runs a model and returns its summary and final state.
pub fn run(name: &str, model: &Model) -> (Summary, State) {
    analysis::run_to_state(model, &out_dir(name), RunOptions::default())
        .unwrap_or_else(|e| panic!("run `{name}` failed: {e}"))
}

/// One column of a run's history.csv, by name.
pub fn column(dir: &Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    lines
        .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
        .collect()
}

/// A finished run of a shipped scene: its output folder and summary.
pub struct SceneRun {
    pub dir: PathBuf,
    pub summary: Summary,
}

/// Runs models/SCENE.toml with `--set` overrides through the library into a fresh folder
/// named `name`.
pub fn run_scene(name: &str, scene: &str, overrides: &[&str]) -> SceneRun {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let path = PathBuf::from(format!("models/{scene}.toml"));
    let model = scene::load(&path, &overrides).unwrap_or_else(|e| panic!("{e}"));
    let dir = out_dir(name);
    let summary = analysis::run(&model, &dir, RunOptions::default())
        .unwrap_or_else(|e| panic!("run `{name}` failed: {e}"));
    SceneRun { dir, summary }
}

/// The values of a history.csv column for time in [from, to] (1e-12 either side).
pub fn window(dir: &Path, name: &str, from: f64, to: f64) -> Vec<f64> {
    column(dir, "time")
        .iter()
        .zip(column(dir, name))
        .filter(|(t, _)| **t >= from - 1e-12 && **t <= to + 1e-12)
        .map(|(_, v)| v)
        .collect()
}

/// The arithmetic mean.
pub fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Runs the impact binary with `args` and returns its exit status and output.
pub fn impact(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// A 10 x 10 mm plane-strain J2 block (E 70 GPa, nu 0.3, sigma_y 100 MPa, H 500 MPa) on
/// rollers at its bottom and left edges, its top pushed down by a prescribed displacement:
/// a homogeneous plane-strain compression (sigma_xx = 0, eps_zz = 0).
pub const J2_BLOCK_ON_ROLLERS: &str = r#"
title = "homogeneous J2 compression between rollers"

[[material]]
name = "al"
young = 70e9
poisson = 0.3
density = 2700
yield_stress = 100e6
hardening_modulus = 500e6

[[body]]
name = "block"
material = "al"
formulation = "plane_strain"
mesh = { type = "rectangle", width = 0.01, height = 0.01, nx = 20, ny = 20 }

[[support]]
set = "bottom"
fix = ["y"]

[[support]]
set = "left"
fix = ["x"]

[[load]]
type = "displacement"
set = "top"
y = -0.002

[analysis]
type = "static"
steps = 20

[output]
frame_every = 0

[[output.probe]]
quantity = "reaction_y"
set = "top"
"#;

/// One rod, node `start` fixed, node `end` free along x: lumped m = rho A L / 2 = 1,
/// k = E A / L = 1, so omega = 1 and T = 2 pi. Started with v = 1: u = sin t.
pub const UNIT_OSCILLATOR: &str = r#"
[[material]]
name = "spring"
young = 1.0
poisson = 0.0
density = 2.0

[[body]]
name = "rod"
material = "spring"
formulation = "rod"
area = 1.0
mesh = { type = "line", start = [0.0, 0.0], end = [1.0, 0.0], n = 1 }

[[support]]
set = "start"
fix = ["x", "y"]

[[support]]
set = "end"
fix = ["y"]

[[initial_velocity]]
set = "end"
velocity = [1.0, 0.0]

[analysis]
type = "dynamic"
geometry = "linear"
mass = "lumped"
dt = 0.1
end_time = 10.0
newton = { strategy = "initial", tol_displacement = 1e-12, tol_force = 1e-12 }

[output]
frame_every = 0

[[output.probe]]
quantity = "u_x"
set = "end"
"#;

/// Lame's thick cylinder (a = 1, b = 2, p = 1 on the bore, E = 1000, nu = 0.3), axisymmetric
/// with u_z = 0 (plane strain), small strain, one element high: `nx` elements through the wall.
pub const LAME_CYLINDER_AXISYMMETRIC: &str = r#"
[[material]]
name = "m"
young = 1000.0
poisson = 0.3

[[body]]
name = "cylinder"
material = "m"
formulation = "axisymmetric"
mesh = { type = "rectangle", origin = [1.0, 0.0], width = 1.0, height = 0.25, nx = 4, ny = 1 }

[[support]]
set = "bottom"
fix = ["y"]

[[support]]
set = "top"
fix = ["y"]

[[load]]
type = "pressure"
set = "left"
pressure = 1.0

[analysis]
type = "static"
steps = 1
geometry = "linear"
newton = { strategy = "full" }
"#;

/// `impact check SCENE --set SET` of each (scene, set, words) exits 2 (bad input) with
/// `words` in its message.
pub fn check_refuses(cases: &[(&str, &str, &str)]) {
    for (scene, set, expected) in cases {
        check_refuses_with(scene, &[set], &[expected]);
    }
}

/// `impact check SCENE --set S` for every S of `sets` exits 2 (bad input) with each of
/// `words` in its message.
pub fn check_refuses_with(scene: &str, sets: &[&str], words: &[&str]) {
    let mut args = vec!["check", scene];
    for set in sets {
        args.extend(["--set", set]);
    }
    let output = impact(&args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{scene} {sets:?}: {stderr}");
    for word in words {
        assert!(
            stderr.contains(word),
            "{scene} {sets:?}: `{word}` not in {stderr}"
        );
    }
}
