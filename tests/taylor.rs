//! Taylor impacts: an aluminium rod (Wilkins & Guinan 1973, the 478 m/s shot, as run in the
//! ANSYS Mechanical APDL Verification Manual, benchmark VMC8; models/taylor_aluminum.toml) and
//! a 42CrMo4 Johnson-Cook rod (DynELA v4 and Abaqus/Explicit; models/taylor_jc.toml), explicit
//! central difference with the automatic stable step, one-point and 2x2 Quad4, and implicit
//! Newmark.

mod common;

use common::column;
use std::path::Path;

/// The experiment's final length (Wilkins & Guinan 1973) and the manual's finite-element
/// results (VMC8: 1.067 to 1.078 times the experiment), in metres.
const EXPERIMENT: f64 = 13.19e-3;
const MANUAL: [f64; 2] = [14.07e-3, 14.22e-3];
const L0: f64 = 23.47e-3;
const R0: f64 = 3.81e-3;

/// The final length (the top of the axis) and impact-face radius (its outer node) of a run
/// of the scene with a mesh of `nx` x `6 nx` quads and `quadrature`.
fn taylor(nx: usize, quadrature: &str) -> (f64, f64, f64) {
    let name = format!("taylor_{quadrature}_{nx}");
    let overrides = [
        format!("body.rod.mesh.nx={nx}"),
        format!("body.rod.mesh.ny={}", 6 * nx),
        format!("analysis.quadrature={quadrature}"),
        "output.frame_every=0".to_string(),
    ];
    let model = impact::scene::load(Path::new("models/taylor_aluminum.toml"), &overrides).unwrap();
    let dir = common::out_dir(&name);
    let summary = impact::analysis::run(&model, &dir, Default::default()).unwrap();
    let last = |c: &str| *column(&dir, c).last().unwrap();
    let length = L0 + last("u_y[top_axis]");
    let radius = R0 + last("u_x[foot_edge]");
    println!(
        "{name}: L_f = {:.3} mm, R_f = {:.3} mm, {} steps, dt {:.2e}..{:.2e}, {:.2} s",
        length * 1e3,
        radius * 1e3,
        summary.steps,
        summary.dt_min.unwrap(),
        summary.dt_max.unwrap(),
        summary.wall_seconds
    );
    (length, radius, summary.wall_seconds)
}

/// Goal: the Taylor bar converges under refinement and lands where bilinear models land.
/// Setup: models/taylor_aluminum.toml, 5 x 30 and 10 x 60 quads with the one-point kernel,
/// 5 x 30 with the 2x2 B-bar kernel (the 20 x 120 meshes are in the study below and in
/// docs/validation.md: too slow for the suite). References:
/// - convergence: the final length changes by less than 1 % between the two meshes
///   (measured 0.1 %; 0.3 % between 10 x 60 and 20 x 120, and 0.02 % for the 2x2 kernel);
/// - the two kernels agree within 1.5 % on the final length (measured 0.4 %) and 5 % on the
///   impact-face radius (measured 3 %: the one-point foot is softer at its edge);
/// - the experiment, 13.19 mm: a bilinear model without rate effects overpredicts it; the
///   manual's own finite-element results are 6.7 % to 7.8 % long, and ours are asserted
///   within 10 % (measured 9.0 % to 9.4 %) and within 2.5 % of the manual's 14.07-14.22 mm
///   (measured +1.1 % to +1.5 % above its upper end).
#[test]
fn taylor_aluminum_converges_and_lands_with_the_bilinear_models() {
    let (coarse, coarse_r, _) = taylor(5, "reduced");
    let (fine, _, _) = taylor(10, "reduced");
    let (full, full_r, _) = taylor(5, "full");
    assert!((fine / coarse - 1.0).abs() < 0.01, "{coarse} -> {fine}");
    assert!((full / coarse - 1.0).abs() < 0.015, "{full} vs {coarse}");
    assert!(
        (full_r / coarse_r - 1.0).abs() < 0.05,
        "{full_r} vs {coarse_r}"
    );
    for length in [coarse, fine, full] {
        assert!(
            length > EXPERIMENT && length < 1.10 * EXPERIMENT,
            "{length}"
        );
        assert!(length > MANUAL[0] && length < 1.025 * MANUAL[1], "{length}");
    }
}

/// The study of docs/validation.md (not run by default: about two minutes): three meshes,
/// each twice as fine, both kernels; prints the final length and radius against wall time.
/// `cargo test --release --test taylor -- --ignored --nocapture`
#[test]
#[ignore]
fn taylor_aluminum_mesh_study() {
    for quadrature in ["reduced", "full"] {
        let lengths: Vec<f64> = [5, 10, 20]
            .iter()
            .map(|&nx| taylor(nx, quadrature).0)
            .collect();
        println!(
            "{quadrature}: changes {:.2} %, {:.2} %",
            100.0 * (lengths[1] / lengths[0] - 1.0),
            100.0 * (lengths[2] / lengths[1] - 1.0)
        );
        assert!((lengths[2] / lengths[1] - 1.0).abs() < 0.01);
    }
}

/// The Johnson-Cook Taylor rod of the DynELA v4 documentation (Pantale), 42CrMo4 at 287 m/s:
/// final length L_f and impact-face diameter D_f (mm), temperature (C) and equivalent
/// plastic strain of the element on the axis at the wall, as DynELA and Abaqus/Explicit give
/// them on the same 5 x 50 mesh.
const DYNELA: [f64; 4] = [26.52, 11.15, 582.34, 1.78];
const ABAQUS: [f64; 4] = [26.56, 11.16, 590.96, 1.81];

/// The run of models/taylor_jc.toml with `overrides` and its [L_f, D_f, T, eps_p].
fn taylor_jc(name: &str, overrides: &[&str]) -> ([f64; 4], impact::analysis::Summary) {
    let mut all = vec!["output.frame_every=0".to_string()];
    all.extend(overrides.iter().map(|s| s.to_string()));
    let model = impact::scene::load(Path::new("models/taylor_jc.toml"), &all).unwrap();
    let dir = common::out_dir(name);
    let summary = impact::analysis::run(&model, &dir, Default::default()).unwrap();
    let finals = jc_finals(&dir);
    println!(
        "{name}: L_f {:.3} mm, D_f {:.3} mm, T {:.1} C, eps_p {:.3}; {} steps, {} iterations, {:.2} s",
        finals[0],
        finals[1],
        finals[2],
        finals[3],
        summary.steps,
        summary.newton_iterations,
        summary.wall_seconds
    );
    (finals, summary)
}

/// [L_f, D_f, T, eps_p] of a Johnson-Cook rod's run in `dir` (its history's last row).
fn jc_finals(dir: &Path) -> [f64; 4] {
    let last = |c: &str| *column(dir, c).last().unwrap();
    [
        (32.4e-3 + last("u_y[top_axis]")) * 1e3,
        2.0 * (3.2e-3 + last("u_x[face_edge]")) * 1e3,
        last("temperature[face_centre]"),
        last("eq_plastic_strain[face_centre]"),
    ]
}

/// The relative deviations of `finals` from `reference`.
fn deviations(finals: &[f64; 4], reference: &[f64; 4]) -> [f64; 4] {
    std::array::from_fn(|k| finals[k] / reference[k] - 1.0)
}

/// Goal: the explicit Johnson-Cook Taylor impact lands on the published results.
/// Setup: models/taylor_jc.toml as it ships (5 x 50, 2x2 B-bar like DynELA's ElQua4NAx,
/// automatic stable step), then the one-point kernel on the same mesh.
/// Reference: Abaqus/Explicit and DynELA (above). Bands: L_f and D_f within 0.5 %, T and eps_p
/// within 3 % of Abaqus (the goal; measured -0.11 %, -0.11 %, -0.19 %, -0.15 %; DynELA and
/// Abaqus themselves differ by 0.15 %, 0.09 %, 1.5 %, 1.7 %). The one-point kernel (kappa 0.1)
/// gets L_f within 0.5 % (measured 0.0 %) but a narrower foot and a cooler, less strained axis
/// element: D_f within 6 % (measured -5.1 %), eps_p within 20 % (measured -15 %); they converge
/// towards the 2x2 values under refinement (docs/validation.md).
#[test]
fn taylor_jc_explicit_matches_abaqus() {
    let (full, summary) = taylor_jc("taylor_jc_full", &[]);
    assert_eq!(summary.status, impact::analysis::Status::Ok);
    let d = deviations(&full, &ABAQUS);
    assert!(d[0].abs() < 0.005 && d[1].abs() < 0.005, "{d:?}");
    assert!(d[2].abs() < 0.03 && d[3].abs() < 0.03, "{d:?}");
    let dynela = deviations(&full, &DYNELA);
    assert!(dynela.iter().all(|x| x.abs() < 0.03), "{dynela:?}");
    let (reduced, _) = taylor_jc("taylor_jc_reduced", &["analysis.quadrature=reduced"]);
    let d = deviations(&reduced, &ABAQUS);
    assert!(d[0].abs() < 0.005, "{d:?}");
    assert!(d[1].abs() < 0.06 && d[3].abs() < 0.20, "{d:?}");
}

/// Goal: implicit Newmark (average acceleration, modified Newton, B-bar 2x2) survives the
/// crushed foot and lands where the explicit run does.
/// Setup: models/taylor_jc.toml with `integrator = "average"`, dt = 1e-7 s (800 steps; about
/// 2.5 times the explicit stable step at the start, 10 times the smallest one at the end).
/// Reference: Abaqus/Explicit within the bands of the explicit test (measured -0.35 %,
/// +0.25 %, +0.55 %, +0.6 %) and the explicit run of the same mesh within 1 % on L_f and D_f
/// (measured -0.23 %, +0.36 %); no step is cut at this dt.
#[test]
fn taylor_jc_implicit_average_lands_with_the_explicit_run() {
    let (implicit, summary) = taylor_jc(
        "taylor_jc_average",
        &["analysis.integrator=average", "analysis.dt=1e-7"],
    );
    assert_eq!(summary.status, impact::analysis::Status::Ok);
    assert_eq!(summary.step_cuts, 0);
    let d = deviations(&implicit, &ABAQUS);
    assert!(d[0].abs() < 0.005 && d[1].abs() < 0.005, "{d:?}");
    assert!(d[2].abs() < 0.03 && d[3].abs() < 0.03, "{d:?}");
    let (explicit, _) = taylor_jc("taylor_jc_explicit_for_average", &[]);
    let d = deviations(&implicit, &explicit);
    assert!(d[0].abs() < 0.01 && d[1].abs() < 0.01, "{d:?}");
}

/// The Johnson-Cook rod of models/taylor_jc.toml on a frictionless rigid wall (an obstacle
/// with contact) in place of the held impact face: the face slides out and its nodes are
/// released and struck again as the rod rebounds.
fn taylor_jc_on_contact_wall(
    name: &str,
    overrides: &[&str],
) -> ([f64; 4], impact::analysis::Summary) {
    let text = std::fs::read_to_string("models/taylor_jc.toml").unwrap();
    let held = "[[support]]\nset = \"bottom\"\nfix = [\"y\"]\n";
    assert!(
        text.contains(held),
        "models/taylor_jc.toml holds its face with a support"
    );
    let wall = "[[obstacle]]\nname = \"wall\"\npoints = [[0.02, 0.0], [-0.01, 0.0]]\n\n\
                [[contact]]\nname = \"wall\"\nslave = { set = \"bottom\" }\nobstacle = \"wall\"\n";
    let mut all = vec!["output.frame_every=0"];
    all.extend(overrides);
    let model = common::model(name, &text.replace(held, wall), &all);
    let dir = common::out_dir(name);
    let summary = impact::analysis::run(&model, &dir, Default::default()).unwrap();
    (jc_finals(&dir), summary)
}

/// Goal: implicit Newmark survives the release of the node on the axis. The release
/// condition adds tau / Z_s to a released slave's velocity, Z_s = rho c A with A the node's
/// tributary area; in axisymmetry that area was taken as half-edges times 2 pi r of the node
/// itself, zero on the axis, so the axis node's velocity became infinite when the rebounding
/// rod let go of the wall (at 34.5 of 80 microseconds on this rod; at 29.8 of 45 on the
/// aluminium rod) and the run stopped six step cuts later on a NaN Jacobian.
/// Setup: the Johnson-Cook rod on a contact wall (above), Newmark average, dt = 1e-7 s, 2x2
/// B-bar; the explicit run of the same scene with the automatic step. Reference: the explicit
/// run within 1 % on L_f and D_f (the implicit-against-explicit criterion of the held-face
/// test; measured -0.22 % and +0.59 %), status ok to 80 microseconds.
#[test]
fn taylor_jc_on_a_contact_wall_runs_implicit_through_the_release() {
    let (implicit, summary) = taylor_jc_on_contact_wall(
        "taylor_jc_contact_average",
        &["analysis.integrator=average", "analysis.dt=1e-7"],
    );
    assert_eq!(
        summary.status,
        impact::analysis::Status::Ok,
        "{:?}",
        summary.message
    );
    assert!(summary.contact.last_release_time.is_some());
    let (explicit, _) = taylor_jc_on_contact_wall("taylor_jc_contact_explicit", &[]);
    let d = deviations(&implicit, &explicit);
    assert!(d[0].abs() < 0.01 && d[1].abs() < 0.01, "{d:?}");
}
