//! `impact bench`: generated scenes of growing size, run one per process, with the time each
//! spends per phase (summary.json's `timing`), written as bench.json and a table.
//!
//! The scene: a plane-strain J2 block (steel-like: E = 200 GPa, nu = 0.3, rho = 7850 kg/m^3,
//! yield 250 MPa, hardening 1 GPa) of W x W/2 with n x n/2 quads, moving at 10 m/s onto a
//! rigid wall it touches at t = 0, so its whole bottom edge (n + 1 slaves) closes in the first
//! step. Implicit: Newmark average, modified Newton, dt = 2 h / c (Courant number 2);
//! explicit: central difference at dt = 0.5 h / c (below its limit h / c for these squares).
//! Each case is a child `impact run` so that its peak memory is its own.

use crate::output::plot::{self, Chart, Series, SeriesStyle};
use crate::output::{OutputError, write_atomic};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;

/// One case of the bench.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    pub name: String,
    pub method: Method,
    /// Elements across the block (n); the block has n x n/2 quads.
    pub n: usize,
    pub steps: usize,
    pub contact: bool,
    /// Write a VTK frame every this many steps (0: none).
    pub frame_every: usize,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Newmark average acceleration, modified Newton.
    Implicit,
    /// Central difference.
    Explicit,
}

/// A measured case: bench.json's rows.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Row {
    pub name: String,
    pub method: Method,
    pub elements: usize,
    pub dofs: usize,
    pub contact: bool,
    pub frame_every: usize,
    pub status: String,
    pub steps: usize,
    pub wall_seconds: f64,
    pub steps_per_second: f64,
    pub element_updates_per_second: f64,
    pub newton_iterations: usize,
    pub factorizations: usize,
    pub back_substitutions: usize,
    pub peak_memory_bytes: Option<u64>,
    /// Shares of the wall time: assembly (with the constitutive update), constitutive,
    /// factorization, solve, contact, output.
    pub share: Shares,
    /// Implicit: the time of an iteration without factorization over (one residual
    /// evaluation + one back-substitution), from the phase times.
    pub iteration_cost_ratio: Option<f64>,
}

#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Shares {
    pub assembly: f64,
    pub constitutive: f64,
    pub factorization: f64,
    pub solve: f64,
    pub contact: f64,
    pub output: f64,
}

/// The plan: `quick` keeps the cases under a few seconds in all.
pub fn plan(quick: bool) -> Vec<Case> {
    let sizes: &[usize] = if quick {
        &[20, 60]
    } else {
        &[20, 64, 200, 632]
    };
    let mut cases = Vec::new();
    for &n in sizes {
        for method in [Method::Implicit, Method::Explicit] {
            let steps = match method {
                Method::Implicit => 10,
                Method::Explicit => 100,
            };
            cases.push(Case {
                name: format!("{}_{n}", name(method)),
                method,
                n,
                steps,
                contact: true,
                frame_every: 0,
            });
        }
    }
    // the cost of contact (the same block in free flight) and of output (frames every 10)
    let n = if quick { 60 } else { 200 };
    for method in [Method::Implicit, Method::Explicit] {
        let steps = if method == Method::Implicit { 10 } else { 100 };
        cases.push(Case {
            name: format!("{}_{n}_free", name(method)),
            method,
            n,
            steps,
            contact: false,
            frame_every: 0,
        });
    }
    cases.push(Case {
        name: format!("explicit_{n}_frames"),
        method: Method::Explicit,
        n,
        steps: 100,
        contact: true,
        frame_every: 10,
    });
    cases
}

fn name(method: Method) -> &'static str {
    match method {
        Method::Implicit => "implicit",
        Method::Explicit => "explicit",
    }
}

/// The scene text of a case.
pub fn scene(case: &Case) -> String {
    let (young, nu, rho): (f64, f64, f64) = (200e9, 0.3, 7850.0);
    let width = 0.1;
    let n = case.n.max(2);
    let h = width / n as f64;
    let ny = (n / 2).max(1);
    let modulus = young * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let c = (modulus / rho).sqrt();
    let (integrator, dt) = match case.method {
        Method::Implicit => ("average", 2.0 * h / c),
        Method::Explicit => ("central_difference", 0.5 * h / c),
    };
    let contact = if case.contact {
        r#"
[[obstacle]]
name = "wall"
points = [[1.0, 0.0], [-1.0, 0.0]]

[[contact]]
name = "wall"
slave = { set = "bottom" }
obstacle = "wall"
"#
    } else {
        ""
    };
    format!(
        r#"title = "bench {name}: J2 block striking a rigid wall"

[[material]]
name = "steel"
young = {young:e}
poisson = {nu}
density = {rho}
yield_stress = 250e6
hardening_modulus = 1e9

[[body]]
name = "block"
material = "steel"
formulation = "plane_strain"
velocity = [0.0, -10.0]
mesh = {{ type = "rectangle", origin = [{x0}, 0.0], width = {width}, height = {height}, nx = {n}, ny = {ny} }}
{contact}
[analysis]
type = "dynamic"
integrator = "{integrator}"
dt = {dt:e}
end_time = {end:e}
newton = {{ strategy = "modified" }}

[output]
frame_every = {frames}
"#,
        name = case.name,
        x0 = -width / 2.0,
        height = h * ny as f64,
        end = dt * case.steps as f64,
        frames = case.frame_every,
    )
}

/// Runs the cases one child process each (the executable `exe`, i.e. this `impact`), in
/// `dir`; returns the rows and writes bench.json and the charts.
pub fn run(
    exe: &Path,
    dir: &Path,
    cases: &[Case],
    mut progress: impl FnMut(&Row),
) -> Result<Vec<Row>, OutputError> {
    std::fs::create_dir_all(dir).map_err(|e| OutputError::io(dir, "create", e))?;
    let mut rows = Vec::new();
    for case in cases {
        let scene_path = dir.join(format!("{}.toml", case.name));
        write_atomic(&scene_path, scene(case).as_bytes())?;
        let out = dir.join(&case.name);
        let status = Command::new(exe)
            .arg("run")
            .arg(&scene_path)
            .arg("--quiet")
            .arg("--out")
            .arg(&out)
            .env("IMPACT_PROFILE_FINE", "1")
            .status()
            .map_err(|e| OutputError::io(exe, "start", e))?;
        let row = read_row(case, &out, status.code())?;
        progress(&row);
        rows.push(row);
    }
    let text = serde_json::to_string_pretty(&rows).expect("rows serialize");
    write_atomic(&dir.join("bench.json"), text.as_bytes())?;
    charts(dir, &rows)?;
    Ok(rows)
}

fn read_row(case: &Case, out: &Path, code: Option<i32>) -> Result<Row, OutputError> {
    let path = out.join("summary.json");
    let text = std::fs::read_to_string(&path).map_err(|e| OutputError::io(&path, "read", e))?;
    let s: crate::analysis::Summary =
        serde_json::from_str(&text).map_err(|e| OutputError::Invalid {
            path: path.clone(),
            reason: e.to_string(),
        })?;
    let wall = s.wall_seconds.max(1e-12);
    let t = &s.timing;
    let share = Shares {
        assembly: t.assembly / wall,
        constitutive: t.constitutive / wall,
        factorization: t.factorization / wall,
        solve: t.solve / wall,
        contact: t.contact / wall,
        output: t.output / wall,
    };
    // an iteration without factorization: (wall - factorizations - output - the first
    // evaluation of each step) / iterations, against one evaluation + one back-substitution
    let iteration_cost_ratio =
        (case.method == Method::Implicit && s.newton_iterations > 0).then(|| {
            let evaluations = (t.element_updates as f64 / s.elements.max(1) as f64).max(1.0);
            let per_evaluation = t.assembly / evaluations;
            let per_solve = t.solve / s.back_substitutions.max(1) as f64;
            let iteration = (wall - t.factorization - t.output) / s.newton_iterations as f64;
            iteration / (per_evaluation + per_solve)
        });
    Ok(Row {
        name: case.name.clone(),
        method: case.method,
        elements: s.elements,
        dofs: s.dofs,
        contact: case.contact,
        frame_every: case.frame_every,
        status: match code {
            Some(0) => "ok".into(),
            Some(c) => format!("exit {c}"),
            None => "killed".into(),
        },
        steps: s.steps,
        wall_seconds: s.wall_seconds,
        steps_per_second: s.steps as f64 / wall,
        element_updates_per_second: t.element_updates as f64 / wall,
        newton_iterations: s.newton_iterations,
        factorizations: s.factorizations,
        back_substitutions: s.back_substitutions,
        peak_memory_bytes: t.peak_memory_bytes,
        share,
        iteration_cost_ratio,
    })
}

/// The table printed by `impact bench`.
pub fn table(rows: &[Row]) -> String {
    let mut s = format!(
        "{:<22} {:>8} {:>8} {:>9} {:>10} {:>6} {:>5} {:>8} {:>9} | {:>5} {:>5} {:>5} {:>5} {:>5} {:>5}\n",
        "case",
        "DOFs",
        "steps/s",
        "elem/s",
        "wall s",
        "iter",
        "fact",
        "backsub",
        "MB",
        "asm",
        "const",
        "fact",
        "solve",
        "cont",
        "out"
    );
    for r in rows {
        let p = |x: f64| format!("{:>4.0}%", 100.0 * x);
        s.push_str(&format!(
            "{:<22} {:>8} {:>8.1} {:>9.2e} {:>10.3} {:>6} {:>5} {:>8} {:>9} | {} {} {} {} {} {}{}\n",
            r.name,
            r.dofs,
            r.steps_per_second,
            r.element_updates_per_second,
            r.wall_seconds,
            r.newton_iterations,
            r.factorizations,
            r.back_substitutions,
            r.peak_memory_bytes
                .map_or("-".into(), |b| format!("{:.0}", b as f64 / 1e6)),
            p(r.share.assembly),
            p(r.share.constitutive),
            p(r.share.factorization),
            p(r.share.solve),
            p(r.share.contact),
            p(r.share.output),
            if r.status == "ok" {
                String::new()
            } else {
                format!("  ({})", r.status)
            }
        ));
    }
    s
}

/// bench_throughput.svg (steps/s and element updates/s against DOFs, log-log) and
/// bench_time_breakdown.svg (phase shares against DOFs).
fn charts(dir: &Path, rows: &[Row]) -> Result<(), OutputError> {
    let sized: Vec<&Row> = rows
        .iter()
        .filter(|r| r.contact && r.frame_every == 0 && r.status == "ok")
        .collect();
    let series_of = |method: Method, f: &dyn Fn(&Row) -> f64, label: &str| Series {
        label: format!("{label} ({})", name(method)),
        points: sized
            .iter()
            .filter(|r| r.method == method)
            .map(|r| (r.dofs as f64, f(r)))
            .filter(|(_, y)| *y > 0.0 && y.is_finite())
            .collect(),
        style: SeriesStyle::LineAndMarkers,
    };
    let mut throughput = Vec::new();
    for method in [Method::Implicit, Method::Explicit] {
        throughput.push(series_of(
            method,
            &|r| r.element_updates_per_second,
            "element updates / s",
        ));
        throughput.push(series_of(method, &|r| r.steps_per_second, "steps / s"));
    }
    throughput.retain(|s| !s.points.is_empty());
    if !throughput.is_empty() {
        plot::write(
            &Chart {
                title: "impact bench: throughput against size (J2 block striking a wall)".into(),
                x_label: "DOFs".into(),
                y_label: "per second".into(),
                series: throughput,
                log_x: true,
                log_y: true,
            },
            &dir.join("bench_throughput.svg"),
        )?;
    }
    let mut shares = Vec::new();
    for method in [Method::Implicit, Method::Explicit] {
        for (label, f) in [
            ("assembly", (|r: &Row| r.share.assembly) as fn(&Row) -> f64),
            ("constitutive", |r: &Row| r.share.constitutive),
            ("factorization", |r: &Row| r.share.factorization),
            ("solve", |r: &Row| r.share.solve),
            ("contact", |r: &Row| r.share.contact),
        ] {
            let s = series_of(method, &f, label);
            if s.points.len() > 1 {
                shares.push(s);
            }
        }
    }
    if !shares.is_empty() {
        plot::write(
            &Chart {
                title: "impact bench: share of the wall time per phase".into(),
                x_label: "DOFs".into(),
                y_label: "share of wall time".into(),
                series: shares,
                log_x: true,
                log_y: false,
            },
            &dir.join("bench_time_breakdown.svg"),
        )?;
    }
    Ok(())
}

/// Default output folder.
pub fn default_dir() -> PathBuf {
    PathBuf::from("output").join("bench")
}
