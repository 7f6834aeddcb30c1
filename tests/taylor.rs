//! Taylor impact of an aluminium rod (Wilkins & Guinan 1973, the 478 m/s shot, as run in the
//! ANSYS Mechanical APDL Verification Manual, benchmark VMC8): models/taylor_aluminum.toml,
//! explicit central difference with the automatic stable step, one-point and 2x2 Quad4.

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
