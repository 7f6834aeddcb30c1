//! Two elastic-perfectly-plastic spheres striking each other (models/sphere_pair.toml) against
//! one sphere striking a rigid wall: the plane between the pair is a plane of symmetry, so
//! each sphere of the pair rebounds as the sphere on the wall at the same speed, on every
//! path. The restitution e = -p_y(end) / p_y(0) of a sphere (its momentum: the mass-weighted
//! velocity, p_y over the body's nodes).

mod common;

/// One sphere of models/sphere_pair.toml (R 5 mm, steel, yield 1 GPa, n = 40 graded 20 to the
/// pole) at 1 m/s onto a rigid wall, its step and integrator as the pair's.
const WALL: &str = r#"
[[material]]
name = "steel"
young = 210.0e9
poisson = 0.3
density = 7850.0
yield_stress = 1.0e9

[[body]]
name = "sphere"
material = "steel"
formulation = "axisymmetric"
velocity = [0.0, -1.0]
mesh = { type = "half_disc", center = [0.0, 5.0e-3], radius = 5.0e-3, n = 40, grading = 20.0 }

[[support]]
set = "axis"
fix = ["x"]

[[obstacle]]
name = "wall"
points = [[0.02, 0.0], [-0.01, 0.0]]

[[contact]]
name = "wall"
slave = { set = "arc" }
obstacle = "wall"

[analysis]
type = "dynamic"
integrator = "average"
dt = 1.0e-7
end_time = 40.0e-6

[output]
frame_every = 0

[[output.probe]]
quantity = "p_y"
set = "all"
"#;

/// The restitution of the body whose momentum column is `column`.
fn restitution(dir: &std::path::Path, column: &str) -> f64 {
    let p = common::column(dir, column);
    -p.last().unwrap() / p[0]
}

/// The wall run with `overrides`: its restitution and Newton iterations.
fn wall(name: &str, overrides: &[&str]) -> (f64, usize) {
    let model = common::model(name, WALL, overrides);
    let (summary, _) = common::run(name, &model);
    assert_eq!(summary.status, impact::analysis::Status::Ok, "{name}");
    let e = restitution(&common::out_dir_of(name), "p_y[all]");
    (e, summary.newton_iterations)
}

/// The pair's run with `overrides`: the restitutions of the upper and lower sphere and the
/// Newton iterations.
fn pair(name: &str, overrides: &[&str]) -> (f64, f64, usize) {
    let run = common::run_scene(name, "sphere_pair", overrides);
    assert_eq!(run.summary.status, impact::analysis::Status::Ok, "{name}");
    assert_eq!(run.summary.step_cuts, 0, "{name}");
    (
        restitution(&run.dir, "p_y[upper.all]"),
        restitution(&run.dir, "p_y[lower.all]"),
        run.summary.newton_iterations,
    )
}

/// Goal: two spheres at +-1 m/s rebound as one sphere at 1 m/s on a rigid wall (exact by
/// symmetry), on Newmark at a fixed step and with the step chosen by its error, and on
/// central difference; the implicit and explicit answers agree.
/// Setup: models/sphere_pair.toml (Newmark average, dt = 1e-7; mortar contact, the active set
/// inside Newton) and the same with dt = "auto"; central difference on n = 24 (the explicit
/// pair on n = 40 takes 9.6 s); the wall runs of the same mesh and path.
/// Reference: the symmetry (pair = wall, band 0.5 %: measured identical to 1e-5 on every
/// path: 0.71084 fixed, 0.71153 / 0.71151 auto, 0.71108 explicit on n = 40), and the explicit
/// wall run on n = 40 for the implicit ones (0.5 %: measured -0.03 % fixed, +0.06 % auto).
/// The automatic step costs at most twice the fixed step's Newton iterations (the issue's
/// twice the wall time; measured 2 224 against 1 615: before, the error estimate chased the
/// multipliers' rattle and took 29 388 steps at the explicit limit).
#[test]
fn sphere_pair_rebounds_as_one_sphere_on_the_wall_on_every_path() {
    let (upper, lower, fixed_iterations) = pair("pair_fixed", &[]);
    let (wall_fixed, _) = wall("wall_fixed", &[]);
    let (explicit_wall, _) = wall(
        "wall_explicit",
        &["analysis.integrator=central_difference", "analysis.dt=auto"],
    );
    for e in [upper, lower] {
        assert!(
            (e / wall_fixed - 1.0).abs() < 0.005,
            "{e} against {wall_fixed}"
        );
        assert!(
            (e / explicit_wall - 1.0).abs() < 0.005,
            "{e} against {explicit_wall}"
        );
    }
    let (upper, lower, auto_iterations) = pair("pair_auto", &["analysis.dt=auto"]);
    let (wall_auto, _) = wall("wall_auto", &["analysis.dt=auto"]);
    for e in [upper, lower] {
        assert!(
            (e / wall_auto - 1.0).abs() < 0.005,
            "{e} against {wall_auto}"
        );
        assert!(
            (e / explicit_wall - 1.0).abs() < 0.005,
            "{e} against {explicit_wall}"
        );
    }
    assert!(
        auto_iterations <= 2 * fixed_iterations,
        "{auto_iterations} iterations against {fixed_iterations}"
    );
    let coarse = [
        "analysis.integrator=central_difference",
        "analysis.dt=auto",
        "body.upper.mesh.n=24",
        "body.lower.mesh.n=24",
    ];
    let (upper, lower, _) = pair("pair_explicit", &coarse);
    let (wall_coarse, _) = wall(
        "wall_explicit_coarse",
        &[coarse[0], coarse[1], "body.sphere.mesh.n=24"],
    );
    for e in [upper, lower] {
        assert!(
            (e / wall_coarse - 1.0).abs() < 0.005,
            "{e} against {wall_coarse}"
        );
    }
}

/// Goal: the automatic implicit step is robust: impact speeds within 0.05 % of each other
/// give restitutions within 0.3 % of each other, and within 0.5 % of the explicit run.
/// Setup: the wall sphere at about ten times Thornton's yield velocity (0.3744 to 0.3746 m/s,
/// V_y = 0.034 m/s), Newmark average with dt = "auto" at its default tolerance, 50 us.
/// Reference: the explicit run at 0.3744 m/s (e = 0.82367). Measured: 0.82465, 0.82459,
/// 0.82445 (0.024 % apart, +0.12 % from explicit) in 298 steps; the estimate at the worst DOF
/// took 11 000 steps for the same speeds.
#[test]
fn adaptive_step_gives_one_restitution_at_nearby_speeds() {
    let end = "analysis.end_time=5.0e-5";
    let (explicit, _) = wall(
        "wall_v10_explicit",
        &[
            "analysis.integrator=central_difference",
            "analysis.dt=auto",
            "body.sphere.velocity=[0.0, -0.3744]",
            end,
        ],
    );
    let speeds = ["0.3744", "0.374457", "0.3746"];
    let restitutions: Vec<f64> = speeds
        .iter()
        .map(|v| {
            let velocity = format!("body.sphere.velocity=[0.0, -{v}]");
            wall(
                &format!("wall_v10_{v}"),
                &["analysis.dt=auto", &velocity, end],
            )
            .0
        })
        .collect();
    let (low, high) = restitutions
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), e| (l.min(*e), h.max(*e)));
    assert!(high / low - 1.0 < 0.003, "{restitutions:?}");
    for e in &restitutions {
        assert!((e / explicit - 1.0).abs() < 0.005, "{e} against {explicit}");
    }
}
