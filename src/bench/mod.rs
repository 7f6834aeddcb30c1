//! `impact bench`: generated scenes of growing size, run one per process, with the time each
//! spends per phase (summary.json's `timing`), written as bench.json and a table.
//!
//! The scene: a plane-strain J2 block (steel-like: E = 200 GPa, nu = 0.3, rho = 7850 kg/m^3,
//! yield 250 MPa, hardening 1 GPa) of W x W/2 with n x n/2 quads, moving at 10 m/s (1 m/s in the elastic cases) onto a
//! rigid wall it touches at t = 0, so its whole bottom edge (n + 1 slaves) closes in the first
//! step. Implicit: Newmark average, modified Newton, dt = 2 h / c (Courant number 2);
//! explicit: central difference at dt = 0.5 h / c (below its limit h / c for these squares).
//! Each case is a child `impact run` so that its peak memory is its own.

pub mod bound;
mod scenes;
mod taylor;

pub use scenes::cases as scene_cases;

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
    pub bottom: Bottom,
    /// Write a VTK frame every this many steps (0: none).
    pub frame_every: usize,
    /// Rayon threads of the run (None: rayon's default, one per core).
    pub threads: Option<usize>,
    /// Impact speed (m/s): 10 crushes the block's edge plastically (rho c V = 460 MPa against
    /// a yield stress of 250 MPa); 1 stays elastic.
    pub speed: f64,
    /// Implicit: `analysis.newton.strategy` ("modified": factor each step; "initial": factor
    /// once, as Hughes et al. 1975 do).
    pub strategy: &'static str,
    /// A scene file of models/ run with `--set` overrides instead of the generated block.
    pub scene: Option<SceneCase>,
}

/// A case that runs a scene of models/.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneCase {
    pub file: PathBuf,
    pub overrides: Vec<String>,
}

/// What holds the block's bottom edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bottom {
    /// The rigid wall it strikes (n + 1 contact slaves).
    Wall,
    /// Supports at y = 0 in the wall's place: the same deformation as the closed wall (no
    /// release within the run) without the contact machinery, the baseline of the cost of
    /// contact.
    Supported,
    /// Nothing: free flight, a rigid motion.
    Free,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Newmark average acceleration, modified Newton.
    Implicit,
    /// Central difference, 2x2 Gauss Quad4 (the general path).
    Explicit,
    /// Central difference, one-point Quad4 with hourglass control over structure-of-arrays
    /// data (`analysis.quadrature = "reduced"`, the fast path).
    ExplicitReduced,
}

/// A measured case: bench.json's rows.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Row {
    pub name: String,
    pub method: Method,
    pub elements: usize,
    pub dofs: usize,
    /// The bottom edge against the wall (`Bottom::Wall`).
    pub contact: bool,
    /// The bottom edge held by supports (`Bottom::Supported`).
    #[serde(default)]
    pub supported: bool,
    pub frame_every: usize,
    pub threads: Option<usize>,
    /// The scene file of a case that runs one of models/ (else the generated block).
    #[serde(default)]
    pub scene: Option<String>,
    pub status: String,
    pub steps: usize,
    pub wall_seconds: f64,
    /// Before the first step (model arrays, symbolic analysis, mass, first frame).
    pub setup_seconds: f64,
    /// Steps per second after the setup.
    pub steps_per_second: f64,
    pub element_updates_per_second: f64,
    /// Element updates per second of the assembly phase alone (evaluation and scatter): the
    /// element cost, where `element_updates_per_second` is the throughput of whole steps.
    pub assembly_updates_per_second: f64,
    /// One-point explicit rows: the memory bound of the same step on this machine
    /// (`bound`: the bytes of one update, the copy rate, the updates a second it allows).
    #[serde(default)]
    pub memory_bound: Option<bound::Bound>,
    pub newton_iterations: usize,
    pub factorizations: usize,
    pub back_substitutions: usize,
    pub peak_memory_bytes: Option<u64>,
    /// Shares of the wall time: assembly (with the constitutive update), constitutive,
    /// factorization, solve, contact, output, and what none of them nor the setup covers.
    pub share: Shares,
}

#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Shares {
    pub assembly: f64,
    pub constitutive: f64,
    pub factorization: f64,
    pub solve: f64,
    pub contact: f64,
    pub output: f64,
    /// The wall time outside the setup and the phases above: the drivers' own vector work
    /// (predictors, updates, energy sums, the impact and release conditions).
    pub other: f64,
}

/// The plan: `quick` keeps the cases under ten seconds in all; the full plan spans 1e3 to
/// 1e6 DOFs (n = 32 to 1000 elements across) and has the cases of the speed targets: the
/// fast explicit path at 1e5 elements on one and two threads and with frames every 10 steps,
/// and the implicit step with and without ~100 contact pairs (n = 100: 101 slaves).
pub fn plan(quick: bool) -> Vec<Case> {
    let case = |method: Method, n: usize| Case {
        name: format!("{}_{n}", name(method)),
        method,
        n,
        steps: match method {
            Method::Implicit => 10,
            Method::Explicit | Method::ExplicitReduced => 100,
        },
        bottom: Bottom::Wall,
        frame_every: 0,
        threads: None,
        speed: 10.0,
        strategy: "modified",
        scene: None,
    };
    // the cost of contact alone: an elastic impact, K* factored once, with the wall (n + 1
    // active pairs), with supports in its place (the same deformation, no contact) and in
    // free flight (a rigid motion)
    let elastic = |n: usize, bottom: Bottom| Case {
        name: format!(
            "implicit_{n}_elastic{}",
            match bottom {
                Bottom::Wall => "",
                Bottom::Supported => "_supported",
                Bottom::Free => "_free",
            }
        ),
        bottom,
        speed: 1.0,
        strategy: "initial",
        ..case(Method::Implicit, n)
    };
    let mut cases = Vec::new();
    if quick {
        for n in [20, 60] {
            for method in [Method::Implicit, Method::Explicit, Method::ExplicitReduced] {
                cases.push(case(method, n));
            }
        }
        for method in [Method::Implicit, Method::ExplicitReduced] {
            cases.push(Case {
                name: format!("{}_60_free", name(method)),
                bottom: Bottom::Free,
                ..case(method, 60)
            });
        }
        for bottom in [Bottom::Wall, Bottom::Supported, Bottom::Free] {
            cases.push(elastic(60, bottom));
        }
        cases.push(Case {
            name: "explicit_reduced_60_frames".into(),
            frame_every: 10,
            ..case(Method::ExplicitReduced, 60)
        });
        return cases;
    }
    for n in [32, 100, 316, 1000] {
        // the plastic impact with modified Newton: each factorization pays one
        // back-substitution per active pair for the Schur complement (n + 1 of them), which
        // makes n = 1000 (1e6 DOFs) an hour; its free flight is below
        if n <= 316 {
            cases.push(case(Method::Implicit, n));
        }
        if n <= 316 {
            cases.push(case(Method::Explicit, n));
        }
        cases.push(case(Method::ExplicitReduced, n));
    }
    for n in [32, 100, 316, 1000] {
        cases.push(Case {
            name: format!("implicit_{n}_free"),
            bottom: Bottom::Free,
            ..case(Method::Implicit, n)
        });
    }
    for n in [100, 316] {
        for bottom in [Bottom::Wall, Bottom::Supported, Bottom::Free] {
            cases.push(elastic(n, bottom));
        }
    }
    cases.extend(taylor::cases());
    // 448 x 224 = 100 352 elements
    let fast = |name: &str| Case {
        name: name.into(),
        steps: 200,
        ..case(Method::ExplicitReduced, 448)
    };
    cases.push(Case {
        threads: Some(1),
        ..fast("explicit_reduced_448_1thread")
    });
    cases.push(Case {
        threads: Some(2),
        ..fast("explicit_reduced_448_2threads")
    });
    cases.push(Case {
        threads: Some(2),
        bottom: Bottom::Free,
        ..fast("explicit_reduced_448_free")
    });
    cases.push(Case {
        threads: Some(2),
        frame_every: 10,
        ..fast("explicit_reduced_448_frames")
    });
    // one stepping thread: the frame writer has the other core to itself
    cases.push(Case {
        threads: Some(1),
        frame_every: 10,
        ..fast("explicit_reduced_448_frames_1thread")
    });
    cases
}

fn name(method: Method) -> &'static str {
    match method {
        Method::Implicit => "implicit",
        Method::Explicit => "explicit",
        Method::ExplicitReduced => "explicit_reduced",
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
        Method::Explicit | Method::ExplicitReduced => ("central_difference", 0.5 * h / c),
    };
    let quadrature = match case.method {
        Method::ExplicitReduced => "reduced",
        Method::Implicit | Method::Explicit => "full",
    };
    let contact = match case.bottom {
        Bottom::Wall => {
            r#"
[[obstacle]]
name = "wall"
points = [[1.0, 0.0], [-1.0, 0.0]]

[[contact]]
name = "wall"
slave = { set = "bottom" }
obstacle = "wall"
"#
        }
        Bottom::Supported => {
            r#"
[[support]]
set = "bottom"
fix = ["y"]
"#
        }
        Bottom::Free => "",
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
velocity = [0.0, {speed:?}]
mesh = {{ type = "rectangle", origin = [{x0}, 0.0], width = {width}, height = {height}, nx = {n}, ny = {ny} }}
{contact}
[analysis]
type = "dynamic"
integrator = "{integrator}"
quadrature = "{quadrature}"
dt = {dt:e}
end_time = {end:e}
newton = {{ strategy = "{strategy}" }}

[output]
frame_every = {frames}
compression = "{compression}"
"#,
        name = case.name,
        x0 = -width / 2.0,
        height = h * ny as f64,
        end = dt * case.steps as f64,
        frames = case.frame_every,
        speed = -case.speed,
        // LZ4 halves the time of a large frame (CRATES.md: 0.054 s against 0.115 s plain)
        compression = if case.frame_every > 0 { "lz4" } else { "none" },
        strategy = case.strategy,
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
        let out = dir.join(&case.name);
        let mut command = Command::new(exe);
        if let Some(threads) = case.threads {
            command.env("RAYON_NUM_THREADS", threads.to_string());
        }
        command.arg("run");
        match &case.scene {
            Some(scene) => {
                command.arg(&scene.file);
                for set in &scene.overrides {
                    command.arg("--set").arg(set);
                }
            }
            None => {
                let scene_path = dir.join(format!("{}.toml", case.name));
                write_atomic(&scene_path, scene(case).as_bytes())?;
                command.arg(&scene_path);
            }
        }
        let status = command
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
    // timed after the children, on this thread alone: nothing runs beside the copy
    for row in rows.iter_mut() {
        if row.method == Method::ExplicitReduced && row.status == "ok" {
            row.memory_bound = Some(bound::measure(row.elements, row.dofs / 2, 5));
        }
    }
    let text = serde_json::to_string_pretty(&rows).expect("rows serialize");
    write_atomic(&dir.join("bench.json"), text.as_bytes())?;
    charts(dir, &rows)?;
    taylor::charts(dir, &rows)?;
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
    // the steady rate: the steps after the setup
    let stepping = (s.wall_seconds - t.setup).max(1e-12);
    let share = Shares {
        assembly: t.assembly / wall,
        constitutive: t.constitutive / wall,
        factorization: t.factorization / wall,
        solve: t.solve / wall,
        contact: t.contact / wall,
        output: t.output / wall,
        // (the setup overlaps the phases: its own evaluation, first frame, factorization)
        other: ((s.wall_seconds - t.setup.max(0.0))
            - (t.assembly + t.factorization + t.solve + t.contact + t.output))
            .max(0.0)
            / wall,
    };
    Ok(Row {
        name: case.name.clone(),
        method: case.method,
        elements: s.elements,
        dofs: s.dofs,
        contact: case.bottom == Bottom::Wall,
        supported: case.bottom == Bottom::Supported,
        frame_every: case.frame_every,
        threads: case.threads,
        scene: case.scene.as_ref().map(|s| s.file.display().to_string()),
        status: match code {
            Some(0) => "ok".into(),
            Some(c) => format!("exit {c}"),
            None => "killed".into(),
        },
        steps: s.steps,
        wall_seconds: s.wall_seconds,
        setup_seconds: t.setup,
        steps_per_second: s.steps as f64 / stepping,
        element_updates_per_second: t.element_updates as f64 / stepping,
        assembly_updates_per_second: if t.assembly > 0.0 {
            t.element_updates as f64 / t.assembly
        } else {
            0.0
        },
        memory_bound: None,
        newton_iterations: s.newton_iterations,
        factorizations: s.factorizations,
        back_substitutions: s.back_substitutions,
        peak_memory_bytes: t.peak_memory_bytes,
        share,
    })
}

/// The table printed by `impact bench`.
pub fn table(rows: &[Row]) -> String {
    let mut s = format!(
        "{:<36} {:>8} {:>8} {:>9} {:>6} {:>8} {:>7} {:>6} {:>5} {:>8} {:>9} | {:>5} {:>5} {:>5} {:>5} {:>5} {:>5} {:>5}\n",
        "case",
        "DOFs",
        "steps/s",
        "elem/s",
        "of mem",
        "wall s",
        "setup s",
        "iter",
        "fact",
        "backsub",
        "MB",
        "asm",
        "const",
        "fact",
        "solve",
        "cont",
        "out",
        "other"
    );
    for r in rows {
        let p = |x: f64| format!("{:>4.0}%", 100.0 * x);
        s.push_str(&format!(
            "{:<36} {:>8} {:>8.1} {:>9.2e} {:>6} {:>8.2} {:>7.2} {:>6} {:>5} {:>8} {:>9} | {} {} {} {} {} {} {}{}\n",
            r.name,
            r.dofs,
            r.steps_per_second,
            r.element_updates_per_second,
            // (the copy is one thread's: rows that step on more threads are not set
            // against it)
            r.memory_bound
                .filter(|_| r.threads == Some(1))
                .map_or("-".into(), |b| format!(
                    "{:.3}",
                    r.element_updates_per_second / b.updates_per_second
                )),
            r.wall_seconds,
            r.setup_seconds,
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
            p(r.share.other),
            if r.status == "ok" {
                String::new()
            } else {
                format!("  ({})", r.status)
            }
        ));
    }
    if let Some(b) = rows.iter().filter_map(|r| r.memory_bound).next_back() {
        s.push_str(&format!(
            "of mem (one-thread rows): element updates/s over the memory bound of the one-point step, a copy of its {:.0} bytes an update on one thread ({:.1} GB/s here: {:.2e} updates/s; src/bench/bound.rs)\n",
            b.bytes_per_update,
            b.copy_bytes_per_second / 1e9,
            b.updates_per_second
        ));
    }
    s.push_str(&format!(
        "registers: {} (the build of the loops compiled twice that this processor runs; docs/performance.md, \"Wider registers where the processor has them\")\n",
        crate::profile::registers()
    ));
    s
}

/// bench_throughput.svg (steps/s and element updates/s against DOFs, log-log) and
/// bench_time_breakdown.svg (phase shares against DOFs).
fn charts(dir: &Path, rows: &[Row]) -> Result<(), OutputError> {
    let sized: Vec<&Row> = rows
        .iter()
        .filter(|r| {
            r.scene.is_none()
                && r.contact
                && r.frame_every == 0
                && r.threads.is_none()
                && r.status == "ok"
        })
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
    for method in [Method::Implicit, Method::Explicit, Method::ExplicitReduced] {
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
                x_limits: Default::default(),
                y_limits: Default::default(),
                notes: Vec::new(),
            },
            &dir.join("bench_throughput.svg"),
        )?;
    }
    let mut shares = Vec::new();
    for method in [Method::Implicit, Method::Explicit, Method::ExplicitReduced] {
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
                x_limits: Default::default(),
                y_limits: Default::default(),
                notes: Vec::new(),
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
