//! Numerical faults stop the run with exit 3 and a status in summary.json; the message names
//! the element or node, the time and the quantity; every frame listed and every history row
//! written before the fault stays readable.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

const BEAM: &str = r#"
[[material]]
name = "steel"
young = 1000.0
poisson = 0.3
density = 1.0

[[body]]
name = "beam"
material = "steel"
formulation = "plane_strain"
mesh = { type = "rectangle", width = 4.0, height = 1.0, nx = 8, ny = 2 }

[[support]]
set = "left"
fix = ["x", "y"]

[[curve]]
name = "ramp_free"
points = [[0.0, 0.0], [1.0, 1.0]]

[[curve]]
name = "late"
points = [[0.0, 0.0], [0.5, 0.01], [1.0, 1.0]]

[[load]]
type = "displacement"
set = "right"
x = -1.0
curve = "late"

[analysis]
type = "static"
steps = 4

[[output.probe]]
quantity = "u_x"
set = "right"
"#;

/// Runs the binary on a scene text; returns (exit code, stderr, output folder).
fn run(name: &str, text: &str, set: &[&str]) -> (i32, String, PathBuf) {
    let dir = common::out_dir(&format!("fault_{name}"));
    let scene = dir.join(format!("{name}.toml"));
    std::fs::write(&scene, text).unwrap();
    let out = dir.join("out");
    let mut args = vec![
        "run".to_string(),
        scene.display().to_string(),
        "--out".into(),
        out.display().to_string(),
        "--quiet".into(),
    ];
    for s in set {
        args.push("--set".into());
        args.push(s.to_string());
    }
    let o = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(&args)
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        out,
    )
}

/// summary.json has `status` and a message with all `needles`; every listed frame loads;
/// history.csv has one whole row per converged step plus the initial one.
fn assert_fault(out: &Path, name: &str, status: &str, needles: &[&str]) -> serde_json::Value {
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], status, "{summary}");
    let message = summary["message"].as_str().unwrap();
    for n in needles {
        assert!(message.contains(n), "`{n}` missing in: {message}");
    }
    let frames = impact::output::vtk::read_pvd(&out.join(format!("{name}.pvd"))).unwrap();
    assert!(!frames.is_empty());
    for (time, path) in &frames {
        impact::output::vtu::read_frame(path)
            .unwrap_or_else(|e| panic!("frame at t = {time}: {e}"));
    }
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(history.ends_with('\n'), "whole rows only");
    let steps = summary["steps"].as_u64().unwrap() as usize;
    // the explicit driver counts the step that blew up but writes only its frame
    let unrecorded = usize::from(status == "unstable");
    assert_eq!(
        history.lines().count() + unrecorded,
        steps + 2,
        "header, initial row, steps"
    );
    summary
}

/// Goal: an inverted element (det J <= 0) after the allowed cuts stops `diverged`, exit 3,
/// naming the body, the element, the Gauss point, det J and the time. Setup: the beam's
/// free end pushed back by 3.9 of its 4.0 length in one increment, one cut allowed.
#[test]
fn inverted_element_exits_3_naming_element_and_time() {
    let (code, stderr, out) = run(
        "inverted",
        BEAM,
        &[
            "analysis.newton.max_cuts=1",
            "analysis.steps=1",
            "load.0.x=-3.9",
            "load.0.curve=ramp_free",
        ],
    );
    assert_eq!(code, 3, "{stderr}");
    for n in ["element", "det J", "t = "] {
        assert!(stderr.contains(n), "{n}: {stderr}");
    }
    assert_fault(
        &out,
        "inverted",
        "diverged",
        &[
            "body `beam`, element",
            "non-positive Jacobian",
            "increment to t = ",
        ],
    );
}

/// Goal: a residual that is not finite (stresses near the largest f64: E = 1e306) stops
/// `diverged`, exit 3, naming the node, the component and the time.
#[test]
fn non_finite_residual_exits_3_naming_node() {
    let (code, stderr, out) = run(
        "overflow",
        BEAM,
        &["material.steel.young=1e306", "analysis.newton.max_cuts=1"],
    );
    assert_eq!(code, 3, "{stderr}");
    assert_fault(
        &out,
        "overflow",
        "diverged",
        &["residual", "not finite", "at node", "t = "],
    );
}

/// Goal: Newton divergence after the allowed cuts: one iteration allowed, two cuts, a load
/// that needs more: `diverged`, exit 3, the message says how many cuts and the step length.
#[test]
fn newton_divergence_after_cuts_exits_3() {
    let (code, stderr, out) = run(
        "diverges",
        BEAM,
        &[
            "analysis.newton.max_iterations=1",
            "analysis.newton.max_cuts=2",
            "load.0.x=-0.3",
        ],
    );
    assert_eq!(code, 3, "{stderr}");
    assert_fault(
        &out,
        "diverges",
        "diverged",
        &["did not converge after 2 cuts", "dt = ", "t = "],
    );
}

/// Goal: an explicit run above the stability limit (allowed by the scene) stops `unstable`,
/// exit 3, with the energy, the time and the limit in the message.
#[test]
fn explicit_blow_up_exits_3_unstable() {
    let text = BEAM.replace("type = \"static\"\nsteps = 4", "type = \"dynamic\"\nintegrator = \"central_difference\"\ndt = 0.5\nend_time = 50.0\nallow_unstable = true");
    let (code, stderr, out) = run("blowup", &text, &["load.0.x=-0.01"]);
    assert_eq!(code, 3, "{stderr}");
    assert_fault(
        &out,
        "blowup",
        "unstable",
        &["energy grew", "at t = ", "stability limit"],
    );
}

/// Goal: the runaway-penetration check names the pair, the node, the gap and the limit
/// (half the slave spacing). Setup: a block whose bottom lies 0.2 inside a rigid floor
/// (slave spacing 1/6, limit 1/12). Lagrange multipliers close every active gap to the
/// tolerance, so no scene of the suite reaches this state by itself: the check is the
/// guard for a contact search that lost a node, tested here on the configuration.
#[test]
fn runaway_penetration_is_named() {
    let text = r#"
[[material]]
name = "m"
young = 100.0
poisson = 0.3
density = 1.0

[[body]]
name = "block"
material = "m"
formulation = "plane_strain"
mesh = { type = "rectangle", origin = [0.0, 0.0], width = 1.0, height = 0.5, nx = 6, ny = 3 }

[[obstacle]]
name = "floor"
points = [[10.0, 0.0], [-10.0, 0.0]]

[[contact]]
name = "floor"
slave = { set = "bottom" }
obstacle = "floor"

[analysis]
type = "dynamic"
dt = 0.01
end_time = 0.1
"#;
    let model = common::model("penetration", text, &[]);
    use impact::contact::{penetration_limits, runaway_penetration};
    let mut x = model.coordinates();
    let limits = penetration_limits(&model.contacts, &x);
    approx::assert_relative_eq!(limits[0], 0.5 / 6.0, max_relative = 1e-12);
    assert!(runaway_penetration(&model.contacts, &x, &limits).is_none());
    x[3][1] -= 0.05;
    assert!(runaway_penetration(&model.contacts, &x, &limits).is_none());
    x[2][1] -= 0.2;
    let message = runaway_penetration(&model.contacts, &x, &limits).unwrap();
    for n in ["contact `floor`", "node 2", "gap = -2e-1", "beyond -8.3"] {
        assert!(message.contains(n), "`{n}` missing in {message}");
    }
}

/// Goal: a fixed explicit step that becomes too large stops the run `unstable`, naming the
/// body, the element, the time, dt and the current limit, before any element inverts; and
/// the failing run reports its contact (the summary's contact block is filled in the same
/// place whatever the stepper and however the run ends). Setup: models/round_bar_wall.toml
/// with central difference at dt = 4e-4 (below the initial stability limit, 5.1e-4): the tip
/// elements crush as the bar strikes the wall, and their stable step falls below dt (this
/// run used to go on until an element inverted at t = 0.0476). Reference: the run's own
/// history.csv, written row by row before the stop: the summary's first contact time is the
/// first row with a contact force, its raw peak (`peak_force_raw`) the largest in the
/// `contact_force` column and its `peak_force` the largest of `contact_force_avg`; the stop
/// comes before t = 0.0476.
#[test]
fn fixed_explicit_step_too_large_stops_unstable_and_reports_contact() {
    let model = impact::scene::load(
        Path::new("models/round_bar_wall.toml"),
        &[
            "analysis.integrator=central_difference".to_string(),
            "analysis.dt=0.0004".to_string(),
        ],
    )
    .unwrap();
    let dir = common::out_dir("explicit_contact_failure");
    let err = impact::analysis::run(&model, &dir, Default::default()).unwrap_err();
    assert_eq!(err.exit_code(), 3, "{err}");
    let message = err.to_string();
    for needle in [
        "body `bar`",
        "element",
        "dt = 4e-4",
        "stability limit",
        "at t = ",
    ] {
        assert!(message.contains(needle), "`{needle}` missing: {message}");
    }
    assert!(!message.contains("Jacobian"), "{message}");
    let summary: impact::analysis::Summary =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary.status, impact::analysis::Status::Unstable);
    let time = common::column(&dir, "time");
    assert!(*time.last().unwrap() < 0.0476);
    let force = common::column(&dir, "contact_force[tip]");
    let first = time
        .iter()
        .zip(&force)
        .find(|(_, f)| **f > 0.0)
        .map(|(t, _)| *t)
        .expect("the bar reaches the wall before it stops");
    assert_eq!(summary.contact.first_contact_time, Some(first));
    // the raw multipliers' peak; `peak_force`, of the force averaged over ten first steps
    // (central difference's default window), lies at or below it
    let peak = force.iter().copied().fold(0.0, f64::max);
    assert_eq!(summary.contact.peak_force_raw, peak);
    let average = common::column(&dir, "contact_force_avg[tip]");
    assert_eq!(
        summary.contact.peak_force,
        average.iter().copied().fold(0.0, f64::max)
    );
    assert!(summary.contact.peak_force <= peak);
}

/// Goal: an automatic step that falls below `analysis.dt_min` stops the run `diverged`,
/// naming the element that sets the limit, with nothing mass-scaled. Setup:
/// models/round_bar_wall.toml with central difference, dt = "auto" and dt_min = 2e-4: the
/// stable step of the crushed tip falls from 3.6e-4 to ~1.1e-4 (measured without the bound).
/// Reference: the rule itself: every step taken is at least dt_min (history.csv's dt
/// column), the last row is before the step would have fallen below it, and the message
/// names body `bar`, an element and dt_min.
#[test]
fn automatic_step_below_dt_min_stops_diverged_naming_the_element() {
    let model = impact::scene::load(
        Path::new("models/round_bar_wall.toml"),
        &[
            "analysis.integrator=central_difference".to_string(),
            "analysis.dt=auto".to_string(),
            "analysis.dt_min=2e-4".to_string(),
            // the bound's step, which follows the crushed tip element by element
            "analysis.stable_step=bound".to_string(),
        ],
    )
    .unwrap();
    let dir = common::out_dir("dt_min");
    let err = impact::analysis::run(&model, &dir, Default::default()).unwrap_err();
    assert_eq!(err.exit_code(), 3, "{err}");
    let message = err.to_string();
    for needle in ["analysis.dt_min", "body `bar`", "element"] {
        assert!(message.contains(needle), "`{needle}` missing: {message}");
    }
    let summary: impact::analysis::Summary =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary.status, impact::analysis::Status::Diverged);
    let dt = common::column(&dir, "dt");
    assert!(dt[1..].iter().all(|h| *h >= 2e-4), "{dt:?}");
    assert!(summary.dt_min.unwrap() >= 2e-4);
}
