//! J2 plasticity verification: uniaxial cycles against the closed form, Hill's thick
//! cylinder, and a plane-stress plate with a hole under refinement.

mod common;

use common::column;

use impact::reference;

const CYCLE: &str = r#"
[[curve]]
name = "cycle"
points = [[0.0, 0.0], [1.0, 1.0], [3.0, -1.0], [4.0, 0.0]]

[[material]]
name = "steel"
young = 200.0
poisson = 0.3
yield_stress = 0.5
hardening_modulus = 10.0

[analysis]
type = "static"
steps = 40
end_time = 4.0
geometry = "linear"
newton = { strategy = "full", tol_displacement = 1e-12, tol_force = 1e-12 }

[output]
frame_every = 0

[[output.probe]]
quantity = "u_x"
set = "end_nodes"

[[output.probe]]
quantity = "s_xx"
set = "all"
"#;

const ROD: &str = r#"
[[body]]
name = "bar"
material = "steel"
formulation = "rod"
area = 1.0
mesh = { type = "line", start = [0.0, 0.0], end = [1.0, 0.0], n = 4 }

[[support]]
set = "start"
fix = ["x", "y"]

[[support]]
set = "all"
fix = ["y"]

[[load]]
type = "displacement"
set = "end"
x = 0.0075
curve = "cycle"
"#;

const QUAD: &str = r#"
[[body]]
name = "bar"
material = "steel"
formulation = "plane_stress"
mesh = { type = "rectangle", width = 1.0, height = 1.0, nx = 1, ny = 1 }

[[support]]
set = "left"
fix = ["x"]

[[support]]
set = "bottom_left"
fix = ["y"]

[[load]]
type = "displacement"
set = "right"
x = 0.0075
curve = "cycle"
"#;

/// Goal: the stress-strain path of tension, unloading and reverse loading is the closed form.
/// Setup: a 4-rod bar and a single plane-stress Quad4 (free to contract) pulled to 3 eps_y,
/// pushed to -3 eps_y and back to 0 in 40 steps, small strain; isotropic (H = 10) and
/// kinematic (H_kin = 10) hardening, E = 200, sigma_y = 0.5. Reference: the piecewise-linear
/// closed form (reference::uniaxial_bar_stress) at each step's strain. Tolerance 1e-8
/// relative (the required accuracy): the return is exact for linear hardening, Newton stops at 1e-12.
#[test]
fn uniaxial_cycle_matches_closed_form_isotropic_and_kinematic() {
    for (body, end_set) in [(ROD, "end"), (QUAD, "right")] {
        for (hardening, h_iso, h_kin) in [
            ("hardening_modulus = 10.0", 10.0, 0.0),
            ("kinematic_modulus = 10.0", 0.0, 10.0),
        ] {
            let text = format!(
                "{}\n{body}",
                CYCLE.replace("hardening_modulus = 10.0", hardening)
            )
            .replace("end_nodes", end_set);
            let model = common::model("cycle", &text, &[]);
            let name = format!("cycle_{}_{h_kin}", if body == ROD { "rod" } else { "quad" });
            let dir = common::out_dir(&name);
            impact::analysis::run(&model, &dir, Default::default()).unwrap();
            let strain = column(&dir, &format!("u_x[{end_set}]"));
            let stress = column(&dir, "s_xx[all]");
            let exact = reference::uniaxial_bar_stress(200.0, 0.5, h_iso, h_kin, &strain);
            let peak = exact.iter().fold(0.0f64, |m, s| m.max(s.abs()));
            assert!(peak > 0.5, "the path must yield");
            for (k, (s, e)) in stress.iter().zip(&exact).enumerate() {
                assert!(
                    (s - e).abs() <= 1e-8 * peak,
                    "{name} step {k}: {s} vs closed form {e}"
                );
            }
        }
    }
}

/// Goal: the energy bookkeeping of a uniaxial J2 cycle, term by term. Setup: the 4-rod bar
/// of the cycle above (volume 1), isotropic and kinematic hardening. References:
/// - stored elastic energy (history `internal_energy`) = sigma^2 / (2 E) times the volume at
///   every step, from the closed-form stress: the bookkeeping takes work and dissipation by
///   the same trapezoidal rule, so their difference telescopes to it exactly (1e-10 relative
///   to the largest value: round-off of 40 steps);
/// - plastic dissipation (`plastic_work`) = the integral of sigma d eps_p along the closed-form
///   path, integrated here over 40 000 sub-steps per step: the trapezoidal rule is exact on the
///   linear hardening branches and errs only in the steps where the path starts to yield, which
///   weight their plastic increment with the mean of an elastic start stress and the flow
///   stress instead of the flow stress: at most 1/2 (sigma_y - sigma_n) d eps_p per such step,
///   largest at the reversal (from +1.5 sigma_y through zero); measured 2.6e-3 (isotropic) and
///   4.1e-3 (kinematic) of the totals 8.2e-3 and 7.6e-3, asserted 5e-3. Never decreasing, and
///   never above the external work.
#[test]
fn uniaxial_cycle_energy_terms_match_the_closed_form() {
    let young = 200.0;
    for (hardening, h_iso, h_kin) in [
        ("hardening_modulus = 10.0", 10.0, 0.0),
        ("kinematic_modulus = 10.0", 0.0, 10.0),
    ] {
        let text = format!(
            "{}\n{ROD}",
            CYCLE.replace("hardening_modulus = 10.0", hardening)
        )
        .replace("end_nodes", "end");
        let model = common::model("cycle_energy", &text, &[]);
        let dir = common::out_dir(&format!("cycle_energy_{h_kin}"));
        impact::analysis::run(&model, &dir, Default::default()).unwrap();
        let strain = column(&dir, "u_x[end]");
        let stored = column(&dir, "internal_energy");
        let plastic = column(&dir, "plastic_work");
        let external = column(&dir, "external_work");
        let exact = reference::uniaxial_bar_stress(young, 0.5, h_iso, h_kin, &strain);
        let largest = stored.iter().fold(0.0f64, |m, w| m.max(*w));
        for (k, (w, s)) in stored.iter().zip(&exact).enumerate() {
            let expected = s * s / (2.0 * young);
            assert!(
                (w - expected).abs() <= 1e-10 * largest,
                "step {k}: {w} vs {expected}"
            );
        }
        // the dissipation along the path, fine sub-steps between the recorded strains
        let mut dissipation = vec![0.0];
        for k in 1..strain.len() {
            let n = 40_000;
            let sub: Vec<f64> = (0..=n)
                .map(|i| strain[k - 1] + (strain[k] - strain[k - 1]) * i as f64 / n as f64)
                .collect();
            let path: Vec<f64> = strain[..k].iter().chain(&sub[1..]).copied().collect();
            let sigma = reference::uniaxial_bar_stress(young, 0.5, h_iso, h_kin, &path);
            let tail = &sigma[k - 1..];
            let mut w = *dissipation.last().unwrap();
            for i in 0..n {
                let d_plastic = (sub[i + 1] - sub[i]) - (tail[i + 1] - tail[i]) / young;
                w += 0.5 * (tail[i] + tail[i + 1]) * d_plastic;
            }
            dissipation.push(w);
        }
        let total = *dissipation.last().unwrap();
        assert!(total > 5e-3, "the cycle must dissipate: {total}");
        let worst = (0..strain.len())
            .map(|k| (plastic[k] - dissipation[k]).abs())
            .fold(0.0, f64::max);
        println!(
            "kinematic {h_kin}: dissipation {total:.6e}, largest error {:.2e} relative",
            worst / total
        );
        for k in 0..strain.len() {
            assert!(
                (plastic[k] - dissipation[k]).abs() <= 5e-3 * total,
                "step {k}: {} vs {}",
                plastic[k],
                dissipation[k]
            );
            assert!(
                k == 0 || plastic[k] >= plastic[k - 1],
                "step {k}: dissipation decreased"
            );
            assert!(plastic[k] <= external[k] + 1e-12, "step {k}");
        }
    }
}

const HILL: &str = include_str!("../models/hill_cylinder.toml");

/// Pressure-bore displacement pairs of a Hill run.
fn hill_curve(
    name: &str,
    overrides: &[&str],
) -> (
    Vec<f64>,
    Vec<f64>,
    Result<impact::analysis::Summary, impact::analysis::RunError>,
) {
    let model = common::model("hill", HILL, overrides);
    let impact::scene::Load::Pressure { pressure, .. } = model.loads[0] else {
        unreachable!()
    };
    let dir = common::out_dir(name);
    let result = impact::analysis::run(&model, &dir, Default::default());
    let p = column(&dir, "time").iter().map(|t| t * pressure).collect();
    (p, column(&dir, "u_x[bore]"), result)
}

/// Goal: Hill's elastic-perfectly plastic thick cylinder (plane strain, Mises), and locking
/// without B-bar. Setup: a = 1, b = 2, E = 1000, nu = 0.4999 (Hill's solution is for the
/// incompressible material), sigma_y = 1; quarter ring 20 x 16 with B-bar, pressure in 20
/// steps to 0.98 of the limit. Reference: Hill's p(c), u(a) (reference::hill_cylinder): the
/// bore displacement within 1 % at every step (measured max 0.5 %, most of it the polygonal
/// bore). Without B-bar the same mesh locks: the bore moves less than half of Hill's value.
#[test]
fn hill_cylinder_pressure_displacement_and_bbar_locking() {
    let (a, b, sy, g) = (1.0, 2.0, 1.0, 1000.0 / (2.0 * 1.4999));
    let (p, u, result) = hill_curve("hill_bbar", &[]);
    result.unwrap();
    for (p, u) in p.iter().zip(&u).skip(1) {
        let exact = reference::hill_bore_displacement(a, b, sy, g, *p);
        approx::assert_relative_eq!(*u, exact, max_relative = 0.01);
    }
    let (p, u, result) = hill_curve("hill_locking", &["body.cylinder.bbar=false"]);
    result.unwrap();
    let exact = reference::hill_bore_displacement(a, b, sy, g, *p.last().unwrap());
    assert!(
        *u.last().unwrap() < 0.5 * exact,
        "no locking without B-bar? {} vs {exact}",
        u.last().unwrap()
    );
}

/// Goal: the computed limit pressure. Setup: as above, the pressure driven to 1.1 of the
/// limit in 0.02 steps, halved up to 8 times on failure. Reference: Hill's limit
/// (2/sqrt 3) sigma_y ln(b/a). The run must stop `diverged` (exit 3) with the last converged
/// pressure within 1 % of it.
#[test]
fn hill_cylinder_limit_pressure() {
    let limit = reference::hill_limit_pressure(1.0, 2.0, 1.0);
    let (p, _, result) = hill_curve(
        "hill_limit",
        &[
            &format!("load.0.pressure={}", 1.1 * limit),
            "analysis.steps=55",
            "analysis.newton.max_cuts=8",
        ],
    );
    assert_eq!(result.unwrap_err().exit_code(), 3);
    approx::assert_relative_eq!(*p.last().unwrap(), limit, max_relative = 0.01);
}

const PLATE: &str = include_str!("../models/plate_with_hole.toml");

/// Goal: the plane-stress J2 solution converges under refinement.
/// Setup: quarter of a square plate (half width 5) with a hole (radius 1), plane stress, J2
/// with linear hardening, uniform tension on the top edge to 0.75 sigma_y (net-section yield
/// at 0.8), meshes n = 4, 8, 16 (elements per half arc and radially). Reference: convergence
/// itself (the differences between successive meshes fall by more than 1.5 at every load
/// level past first yield). The plane-stress condition is checked where it can fail: the
/// material's unit tests replay the 3D update at the returned out-of-plane strain, and
/// tests/explicit_fast.rs compares the thickness strain with the width strain of a strip.
#[test]
fn plate_with_hole_plane_stress_converges() {
    let mut curves = Vec::new();
    for n in [4, 8, 16] {
        let set_n = format!("body.plate.mesh.n={n}");
        let set_radial = format!("body.plate.mesh.n_radial={n}");
        let model = common::model("plate", PLATE, &[&set_n, &set_radial]);
        let dir = common::out_dir(&format!("plate_{n}"));
        let (summary, state) =
            impact::analysis::run_to_state(&model, &dir, Default::default()).unwrap();
        assert!(
            summary.energy.plastic_dissipation > 0.0,
            "the plate must yield"
        );
        assert!(
            state.bodies[0]
                .points
                .iter()
                .any(|p| p.eq_plastic_strain > 0.0)
        );
        // the values at the nominal steps (cut steps add rows in between)
        let times = column(&dir, "time");
        let u = column(&dir, "u_y[top]");
        let at = |t: f64| {
            u[times
                .iter()
                .position(|s| (s - t).abs() < 1e-12)
                .expect("a nominal step")]
        };
        curves.push((0..=15).map(|k| at(k as f64 / 15.0)).collect::<Vec<f64>>());
    }
    for k in 8..curves[0].len() {
        let coarse = (curves[0][k] - curves[1][k]).abs();
        let fine = (curves[1][k] - curves[2][k]).abs();
        assert!(
            fine * 1.5 < coarse,
            "step {k}: differences {coarse:e} then {fine:e}"
        );
    }
}

/// Goal: the Newton strategies and tangents reach the same answer at the same tolerance
/// (the table of strategies and tangents). Setup: models/hill_cylinder.toml with modified, full and initial
/// strategies on the consistent tangent, and modified with Erklig's elastic tangent (the
/// initial-stress method proper, which needs many iterations near the limit: 400 allowed),
/// and the initial-stress method with BFGS updates within the default 30 iterations (without
/// them it stops `diverged` after t = 0.8 of the ramp to 0.98 p_lim, i.e. at 0.78 p_lim).
/// Reference: the full-Newton bore displacement; agreement within 1e-6 relative (the
/// convergence tolerances are 1e-8).
#[test]
fn newton_strategies_and_tangents_agree() {
    let bore = |name: &str, overrides: &[&str]| {
        let model = common::model("hill", HILL, overrides);
        let dir = common::out_dir(name);
        let summary = impact::analysis::run(&model, &dir, Default::default()).unwrap();
        (*column(&dir, "u_x[bore]").last().unwrap(), summary)
    };
    let (reference, full) = bore("hill_full", &["analysis.newton.strategy=full"]);
    assert_eq!(
        full.factorizations, full.newton_iterations,
        "full Newton factors every iteration"
    );
    for (name, overrides) in [
        ("hill_modified", vec!["analysis.newton.strategy=modified"]),
        ("hill_initial", vec!["analysis.newton.strategy=initial"]),
        (
            "hill_elastic",
            vec![
                "analysis.newton.strategy=modified",
                "analysis.newton.tangent=elastic",
                "analysis.newton.max_iterations=400",
            ],
        ),
        (
            "hill_elastic_bfgs",
            vec![
                "analysis.newton.strategy=initial",
                "analysis.newton.tangent=elastic",
                "analysis.newton.updates=bfgs",
            ],
        ),
    ] {
        let (u, summary) = bore(name, &overrides);
        approx::assert_relative_eq!(u, reference, max_relative = 1e-6);
        assert!(
            summary.factorizations < full.factorizations,
            "{name} factors less than full Newton"
        );
    }
}
