//! The static Newton at finite strain: a homogeneous J2 block compressed between rollers
//! with every key at its default, and the tangent of its residual (docs/validation.md 2.6).

mod common;

use impact::analysis::{self, RunOptions, Status};

use common::J2_BLOCK_ON_ROLLERS as BLOCK;

const YOUNG: f64 = 70e9;
const POISSON: f64 = 0.3;
const YIELD: f64 = 100e6;
const HARDENING: f64 = 500e6;

/// The stress (xx, yy, zz) and equivalent plastic strain after a strain increment `de`
/// (principal, logarithmic) from `(stress, ep)`: isotropic elasticity and a radial return
/// on the von Mises surface with linear isotropic hardening.
fn radial_return(stress: [f64; 3], ep: f64, de: [f64; 3]) -> ([f64; 3], f64) {
    let g = YOUNG / (2.0 * (1.0 + POISSON));
    let k = YOUNG / (3.0 * (1.0 - 2.0 * POISSON));
    let tr = de.iter().sum::<f64>();
    let trial: Vec<f64> = (0..3)
        .map(|i| stress[i] + 2.0 * g * de[i] + (k - 2.0 * g / 3.0) * tr)
        .collect();
    let mean = trial.iter().sum::<f64>() / 3.0;
    let dev: Vec<f64> = trial.iter().map(|s| s - mean).collect();
    let q = (1.5 * dev.iter().map(|s| s * s).sum::<f64>()).sqrt();
    let f = q - (YIELD + HARDENING * ep);
    if f <= 0.0 {
        return ([trial[0], trial[1], trial[2]], ep);
    }
    let dgamma = f / (3.0 * g + HARDENING);
    let scale = 1.0 - 3.0 * g * dgamma / q;
    let s = |i: usize| mean + scale * dev[i];
    ([s(0), s(1), s(2)], ep + dgamma)
}

/// The compressive force per unit depth on a block of initial width and height `size`
/// pushed down by `u`, integrated in 4000 logarithmic strain steps in the principal axes
/// (the axes do not turn: every objective rate is the material one), each step's transverse
/// strain found by the secant method so that sigma_xx = 0, with eps_zz = 0. Independent of
/// the code: no element, no Green-Lagrange strain, no push-forward.
fn plane_strain_compression(size: f64, u: f64) -> f64 {
    let steps = 4000;
    let eyy = ((size - u) / size).ln() / steps as f64;
    let (mut stress, mut ep, mut exx) = ([0.0; 3], 0.0, 0.0);
    for _ in 0..steps {
        let sxx = |dx: f64| radial_return(stress, ep, [dx, eyy, 0.0]).0[0];
        let (mut a, mut b) = (0.0, -0.5 * eyy);
        let (mut fa, mut fb) = (sxx(a), sxx(b));
        for _ in 0..60 {
            if fb.abs() < 1e-6 || fb == fa {
                break;
            }
            let c = b - fb * (b - a) / (fb - fa);
            (a, fa) = (b, fb);
            b = c;
            fb = sxx(b);
        }
        (stress, ep) = radial_return(stress, ep, [b, eyy, 0.0]);
        exx += b;
    }
    -stress[1] * size * exx.exp()
}

/// Goal: the static Newton takes a finite-strain elastic-plastic compression with the
/// defaults (`geometry = "nonlinear"`, consistent tangent, modified Newton): every increment
/// converges at its nominal size (no step cut), in a few iterations, and the force converges
/// to the closed form as the increments shrink. Before the tangent predictor (theory 5a)
/// the first increment failed (6 cuts, exit 3): the top row of elements took the whole
/// prescribed increment at the first iterate and yielded; before the L D L^T fallback
/// (theory 5a) the run to 40 % in 20 increments cut 339 times: mid-increment tangents have
/// negative pivots.
/// Setup: BLOCK, 20 % compression (u = 2 mm) in 10, 20 and 40 increments.
/// Reference: `plane_strain_compression` (3.266e6 N/m). The seeds' updated-Lagrangian
/// update returns the stress in the increment's reference configuration and then pushes it
/// forward, F S F^T / J: the stress leaves the yield surface by the increment's stretch
/// ratio, an error of first order in the increment (-7.0, -3.8, -2.1 %). Tolerances: the
/// error's ratio over successive halvings within [1.6, 2.5] (first order: 2); the
/// Richardson extrapolation 2 F_40 - F_20 within 0.5 % of the reference (the rate form's own
/// difference, sigma / E ~ 0.4 %, plus the O(h^2) remainder); at most 8 Newton iterations
/// an increment on average (5.9, 5.3, 4.7 measured from the extrapolated start; 7.6, 6.45,
/// 6.47 from zero).
#[test]
fn homogeneous_j2_compression_at_finite_strain() {
    let reference = plane_strain_compression(0.01, 0.002);
    let mut forces = Vec::new();
    for steps in [10, 20, 40] {
        let name = format!("compression_{steps}");
        let set = format!("analysis.steps={steps}");
        let model = common::model(&name, BLOCK, &[&set]);
        let (summary, _) = common::run(&name, &model);
        assert_eq!(summary.status, Status::Ok, "{:?}", summary.message);
        assert_eq!(summary.step_cuts, 0, "{steps} increments");
        let per_increment = summary.newton_iterations as f64 / summary.steps as f64;
        assert!(per_increment <= 8.0, "{steps}: {per_increment} iterations");
        let dir = common::out_dir_of(&name);
        let force = -*common::column(&dir, "reaction_y[top]").last().unwrap();
        eprintln!(
            "{steps} increments: F = {force:.6e} ({:+.3} %), {per_increment:.2} iterations",
            100.0 * (force / reference - 1.0)
        );
        forces.push(force);
    }
    let ratio = (forces[0] - forces[1]) / (forces[1] - forces[2]);
    assert!((1.6..=2.5).contains(&ratio), "error ratio {ratio}");
    let extrapolated = 2.0 * forces[2] - forces[1];
    approx::assert_relative_eq!(extrapolated, reference, max_relative = 0.005);
}

/// Goal: a static scene with a mechanism (nothing holds the block in x) stops with a
/// message that names the cause and a node of the free motion, where L L^T met a round-off
/// pivot of either sign (a positive one passed before and let the block drift). Setup: BLOCK
/// on 8 x 8 elements, without the left rollers. Reference: the rigid translation in x is a
/// null vector of K_ff, so some pivot is round-off of its column's diagonal.
#[test]
fn a_mechanism_is_named_as_such() {
    let scene = BLOCK
        .replace("[[support]]\nset = \"left\"\nfix = [\"x\"]\n", "")
        .replace("nx = 20, ny = 20", "nx = 8, ny = 8");
    assert!(!scene.contains("\"left\""));
    let model = common::model("mechanism", &scene, &[]);
    let out = common::out_dir("mechanism");
    let message = match analysis::run_to_state(&model, &out, RunOptions::default()) {
        Ok((summary, _)) => panic!("ran to {:?}", summary.status),
        Err(e) => e.to_string(),
    };
    assert!(
        message.contains("singular at the x DOF of node")
            && message.contains("of body `block`")
            && message.contains("missing supports"),
        "{message}"
    );
    // a static run's message does not reason with explicit stable steps
    assert!(!message.contains("stable steps"), "{message}");
}

/// A 1 x 1 square of 2 x 2 elements with every DOF free, law `material` (TOML keys) and
/// body keys `body` (formulation and B-bar).
fn square(material: &str, body: &str) -> impact::scene::Model {
    let text = format!(
        r#"title = "tangent check"

[[material]]
name = "m"
young = 200.0
poisson = 0.3
density = 1.0
{material}

[[body]]
name = "square"
material = "m"
{body}
mesh = {{ type = "rectangle", width = 1.0, height = 1.0, nx = 2, ny = 2 }}

[analysis]
type = "static"
steps = 1
"#
    );
    impact::scene::from_str(&text, std::path::Path::new("square.toml"), &[])
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The displacement that takes `x` (relative to the square's centre) to
/// R(angle) diag(stretch) x plus a smooth non-uniform part of size `wobble`.
fn motion(x: &[[f64; 2]], angle: f64, stretch: [f64; 2], wobble: f64) -> Vec<f64> {
    let (s, c) = angle.sin_cos();
    x.iter()
        .enumerate()
        .flat_map(|(n, p)| {
            let (a, b) = (p[0] - 0.5, p[1] - 0.5);
            let (a1, b1) = (stretch[0] * a, stretch[1] * b);
            let w = wobble * ((3 * n) as f64).sin();
            [c * a1 - s * b1 - a + w, s * a1 + c * b1 - b - 0.7 * w]
        })
        .collect()
}

/// The increment `d` over `dt` at finite strain.
fn finite(d: &[f64], dt: f64) -> impact::assembly::StepIncrement<'_> {
    impact::assembly::StepIncrement {
        d,
        dt,
        geometry: impact::element::Strain::Finite,
    }
}

/// Entry (i, j) of the assembled matrix (lower triangle, compressed columns).
fn entry(system: &impact::assembly::System, i: usize, j: usize) -> f64 {
    let (row, col) = if i >= j { (i, j) } else { (j, i) };
    let p = &system.pattern;
    (p.col_ptr[col] as usize..p.col_ptr[col + 1] as usize)
        .find(|&k| p.row_idx[k] as usize == row)
        .map_or(0.0, |k| system.values[k])
}

/// Goal: the static Newton's matrix is the derivative of its residual on the updated-
/// Lagrangian path (item 4 of the static-core issue): for each formulation (plane strain
/// with and without B-bar, plane stress, axisymmetric) and each plastic law (J2 with
/// isotropic, with kinematic hardening, Johnson-Cook with its rate and heating), at a
/// stressed, rotated state, in a plastic increment.
/// Setup: `square`; a first increment (rotation 0.5 rad, stretches 1.05 / 0.96 and a
/// non-uniform part) committed at finite strain leaves a yielded, pushed-forward, rotated
/// reference; the second (a further 0.3 rad, 1.02 / 0.99) loads plastically at every point.
/// Reference: central differences of the internal force over each DOF, h = 1e-7 (of the
/// unit size). Tolerance: 1e-6 of the largest entry, the issue's bound (truncation h^2
/// |f'''| ~ 1e-12 of E; round-off eps |f| / h ~ 1e-9 of it; no point may change between
/// elastic and plastic within h, which the plastic-everywhere increment ensures).
/// Measured: 3e-11 to 3e-10 on every row. Mutation: with the axisymmetric B-bar correction's
/// hoop term added to the vv block as well as the uu block (as it was until this test found
/// it), the axisymmetric B-bar rows miss by 7.8e-5 (J2), 7.7e-5 (kinematic), 9.7e-5
/// (Johnson-Cook); the other rows are unchanged.
#[test]
fn the_static_tangent_is_the_derivative_of_the_residual() {
    use impact::assembly::{self, State, System};
    use impact::element::Strain;
    use impact::scene::spec::Tangent;
    let laws = [
        ("J2", "yield_stress = 1.0\nhardening_modulus = 20.0"),
        (
            "J2 kinematic",
            "yield_stress = 1.0\nhardening_modulus = 10.0\nkinematic_modulus = 15.0",
        ),
        (
            "Johnson-Cook",
            "johnson_cook = { a = 1.0, b = 2.0, n = 0.5, c = 0.05, reference_rate = 0.01, \
             m = 1.0, room_temperature = 0.0, melting_temperature = 100.0, specific_heat = 0.5 }",
        ),
    ];
    let bodies = [
        ("plane strain, B-bar", "formulation = \"plane_strain\""),
        (
            "plane strain",
            "formulation = \"plane_strain\"\nbbar = false",
        ),
        (
            "plane stress",
            "formulation = \"plane_stress\"\nthickness = 0.1",
        ),
        ("axisymmetric, B-bar", "formulation = \"axisymmetric\""),
        (
            "axisymmetric",
            "formulation = \"axisymmetric\"\nbbar = false",
        ),
    ];
    let dt = 0.1;
    for (law, material) in laws {
        for (form, body) in bodies {
            let mut model = square(material, body);
            // axisymmetric: off the axis, so no point sits at r = 0
            if form.starts_with("axisymmetric") {
                for b in &mut model.bodies {
                    b.mesh.nodes.iter_mut().for_each(|p| p[0] += 1.0);
                }
            }
            let mut state = State::initial(&model);
            let first = motion(&state.coordinates, 0.5, [1.05, 0.96], 0.01);
            let evaluation = assembly::evaluate(
                &model,
                &state,
                finite(&first, dt),
                None,
                Tangent::Consistent,
            )
            .unwrap_or_else(|e| panic!("{law}, {form}: {e}"));
            assembly::commit(&model, &mut state, &first, evaluation, Strain::Finite);
            let yielded = state.bodies[0]
                .points
                .iter()
                .all(|p| p.eq_plastic_strain > 0.0);
            assert!(
                yielded,
                "{law}, {form}: the first increment yields every point"
            );
            let second = motion(&state.coordinates, 0.3, [1.02, 0.99], 0.003);
            let mut system = System::new(&model, &[]);
            let at = assembly::evaluate(
                &model,
                &state,
                finite(&second, dt),
                Some(&mut system),
                Tangent::Consistent,
            )
            .unwrap_or_else(|e| panic!("{law}, {form}: {e}"));
            let loading = at.trial[0]
                .iter()
                .zip(&state.bodies[0].points)
                .all(|(t, c)| t.eq_plastic_strain > c.eq_plastic_strain);
            assert!(
                loading,
                "{law}, {form}: the second increment loads every point plastically"
            );
            let scale = system.values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let h = 1e-7;
            let force = |d: &[f64]| {
                assembly::evaluate(&model, &state, finite(d, dt), None, Tangent::Consistent)
                    .unwrap()
                    .force
            };
            let mut worst = 0.0_f64;
            for j in 0..model.dofs() {
                let (mut plus, mut minus) = (second.clone(), second.clone());
                plus[j] += h;
                minus[j] -= h;
                let (fp, fm) = (force(&plus), force(&minus));
                for i in 0..model.dofs() {
                    let derivative = (fp[i] - fm[i]) / (2.0 * h);
                    worst = worst.max((entry(&system, i, j) - derivative).abs() / scale);
                }
            }
            eprintln!(
                "{law}, {form}: largest difference {worst:.2e} of the largest entry {scale:.3e}"
            );
            assert!(worst < 1e-6, "{law}, {form}: {worst:e}");
        }
    }
}

/// A thick ring (mean radius R = 0.1 m, wall t = 0.01 m; plane strain, E 200 GPa, nu 0.3, J2
/// perfectly plastic, sigma_y 250 MPa) crushed across a diameter: the quarter from 0 to 90
/// degrees, symmetric on both cut faces, its top face pushed down 0.01 m (0.1 R) by a
/// prescribed displacement in 40 increments, every analysis key at its default.
const RING: &str = r#"
title = "a thick ring crushed across a diameter (the quarter, by symmetry)"

[[material]]
name = "steel"
young = 200e9
poisson = 0.3
density = 7850
yield_stress = 250e6

[[body]]
name = "ring"
material = "steel"
formulation = "plane_strain"
mesh = { type = "ring", inner_radius = 0.095, outer_radius = 0.105, n_radial = 4, n_circ = 80, angle = 90.0 }

[[support]]
set = "start"
fix = ["y"]

[[support]]
set = "end"
fix = ["x"]

[[load]]
type = "displacement"
set = "end"
y = -0.01

[analysis]
type = "static"
steps = 40

[output]
frame_every = 0

[[output.probe]]
quantity = "reaction_y"
set = "end"
"#;

/// Goal: a perfectly plastic structure without contact crushed under displacement control
/// past its collapse completes with the defaults (before the tangent predictor and the
/// indefinite tangents, such a run stopped in its first plastic increment).
/// Setup: `RING`, 40 increments to a deflection of 0.1 R.
/// Reference: the four-hinge collapse load of a ring under diametral compression, P = 4 M_p
/// / R with M_p = (2 / sqrt 3) sigma_y t^2 / 4 per unit depth (plane strain); the quarter
/// carries P / 2 on its top face. Its own error: a thin ring's rigid-plastic value, the axial
/// force at the side hinges (N / N_p = t / 2R: 0.25 % off M_p) and the curvature of a wall
/// of t / R = 0.1 left out. Measured: the peak 1.035 P at a deflection of 0.043 R, falling to
/// 0.991 P at 0.1 R; the peak moves to 1.029 and 1.014 P at 8 x 80 and 8 x 160 elements (the
/// 2x2 element's bending stiffness on a wall of four: the column study of validation 5.1), so
/// the band is 5 %. No step cut (asserted), 4.2 Newton iterations an increment with the
/// extrapolated start (theory 5a; 7.95 from zero starts); at most 8 asserted, the issue's
/// figure for static runs. The same on 8 x 80 (4.4 an increment, 8.55 from zero starts, peak
/// 1.029 P): before the static Newton's line search (newton/line_search.rs) that ring cut its
/// increment 4 times from zero starts (10.7 iterations an increment); from the extrapolated
/// start it needs no line search (4.45 an increment, no cut), whose removal the punch's
/// no-cut assertion catches (`shields_punch_reaches_its_limit_pressure`).
#[test]
fn a_thick_ring_is_crushed_past_its_hinge_load_with_the_defaults() {
    for (name, overrides) in [
        ("ring_crush", &[][..]),
        ("ring_crush_8x80", &["body.ring.mesh.n_radial=8"][..]),
    ] {
        crush_ring(name, overrides);
    }
}

/// The ring of `RING` with `overrides`, run into `name` and checked against the hinge load.
fn crush_ring(name: &str, overrides: &[&str]) {
    let model = common::model(name, RING, overrides);
    let dir = common::out_dir(name);
    let summary = analysis::run(&model, &dir, RunOptions::default()).unwrap();
    assert_eq!(summary.status, Status::Ok, "{name}");
    assert_eq!(summary.step_cuts, 0, "{name}");
    let iterations = summary.newton_iterations as f64 / summary.steps as f64;
    assert!(
        iterations <= 8.0,
        "{name}: {iterations} iterations an increment"
    );
    let (sigma_y, t, radius) = (250e6, 0.01, 0.1);
    let plastic_moment = 2.0 / 3f64.sqrt() * sigma_y * t * t / 4.0;
    let hinge = 4.0 * plastic_moment / radius;
    let force: Vec<f64> = common::column(&dir, "reaction_y[end]")
        .iter()
        .map(|r| -2.0 * r / hinge)
        .collect();
    let peak = force.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!(
        (peak - 1.0).abs() < 0.05,
        "{name}: peak {peak} of the hinge load"
    );
    // past the collapse: the last increments stay on the plateau
    let last = *force.last().unwrap();
    assert!(
        (last - 1.0).abs() < 0.05,
        "{name}: end {last} of the hinge load"
    );
}

/// The mean pressure under Shield's punch over a run in `dir`, in units of k = Y / 2: the
/// bottom's reaction over pi a^2 (a = 1 mm, Y = 250 MPa).
fn punch_pressure(dir: &std::path::Path) -> Vec<f64> {
    let (a, k) = (1e-3, 125e6);
    common::column(dir, "reaction_y[bottom]")
        .iter()
        .map(|r| r / (std::f64::consts::PI * a * a) / k)
        .collect()
}

/// Goal: the static core reaches the limit load of contact plasticity with the defaults
/// (before it, a flat punch stopped at 0.72 of its limit with a non-positive pivot).
/// Setup: models/shield_punch.toml, a rigid frictionless flat punch of radius a (its edge
/// rounded by 0.01 a) pressed 0.04 a in 80 increments into an axisymmetric elastic-perfectly
/// plastic cylinder of radius and height 10 a, on the three meshes of models/meshes/punch_mesh.py (24 x 20,
/// 48 x 40, 96 x 80: 50, 25 and 12.5 um at the edge), at small displacements
/// (`geometry = "linear"`, the problem Shield solved); and the scene as shipped, every key at
/// its default. Reference: Shield (1955), the limit mean pressure 5.69 k of a smooth flat
/// circular punch; in his Haar-von Karman state von Mises' k is Y / 2 (docs/validation.md
/// 2.9). Measured peaks 5.591, 5.784, 5.733 k (-1.7, +1.7, +0.8 %: the mesh error
/// oscillates as the edge nodes slide off the punch one by one, a drop of about h / a each);
/// the issue's band, 3 %, asserted on each. No step cut (asserted); 3.9, 4.0 and 4.7
/// iterations an increment, each increment started from the last one's increment scaled
/// (`analysis.newton.extrapolate`, theory 5a); at most 8 asserted, the issue's figure, which
/// levels 1 and 2 miss from zero starts at 40 increments (8.53 and 9.72, `extrapolate =
/// false`). With the defaults (finite strain) the pressure follows the small-displacement one
/// to 0.2 % up to 0.01 a of travel (1 % asserted) and then keeps rising as the punch sinks;
/// so does the finest level (0.1 %), whose elements at the edge are the smallest (12.5 um)
/// where the material flows round the edge: it too takes no step cut and at most 8 iterations
/// at the median (asserted). At 40 increments it cut its step 3 times (the first correction
/// from the extrapolated start inverted an edge element near the end of the travel), so that
/// check can fail: `--set analysis.steps=40` makes it. A dynamic
/// analysis refuses `extrapolate` (its steps start from the integrator's prediction).
#[test]
fn shields_punch_reaches_its_limit_pressure() {
    let finest = "body.block.mesh.file=\"meshes/punch2.msh\"";
    let (runs, finest_finite): (Vec<_>, _) = std::thread::scope(|s| {
        let finite =
            s.spawn(|| common::run_scene("shield_punch_finest", "shield_punch", &[finest]));
        let handles: Vec<_> = (0..3)
            .map(|level| {
                s.spawn(move || {
                    let file = format!("body.block.mesh.file=\"meshes/punch{level}.msh\"");
                    let name = format!("shield_punch_linear_{level}");
                    common::run_scene(&name, "shield_punch", &["analysis.geometry=linear", &file])
                })
            })
            .collect();
        let runs = handles.into_iter().map(|h| h.join().unwrap()).collect();
        (runs, finite.join().unwrap())
    });
    for (level, run) in runs.iter().enumerate() {
        assert_eq!(run.summary.status, Status::Ok, "level {level}");
        assert_eq!(run.summary.step_cuts, 0, "level {level}");
        let iterations = run.summary.newton_iterations as f64 / run.summary.steps as f64;
        assert!(
            iterations <= 8.0,
            "level {level}: {iterations} an increment"
        );
        // the issue's measure: the median increment (5 or fewer measured; 8 or 9 from zero)
        let median = run.summary.newton_iterations_median.unwrap();
        assert!(median <= 8.0, "level {level}: median {median}");
        let peak = punch_pressure(&run.dir)
            .into_iter()
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(
            (peak / 5.69 - 1.0).abs() < 0.03,
            "level {level}: peak {peak} k"
        );
    }
    common::check_refuses(&[(
        "models/strip_wall.toml",
        "analysis.newton.extrapolate=true",
        "analysis.newton.extrapolate: does not apply to a dynamic analysis",
    )]);
    let shipped = common::run_scene("shield_punch_defaults", "shield_punch", &[]);
    for (run, small) in [(&shipped, &runs[1]), (&finest_finite, &runs[2])] {
        assert_eq!(run.summary.status, Status::Ok);
        assert_eq!(run.summary.step_cuts, 0);
        let median = run.summary.newton_iterations_median.unwrap();
        assert!(median <= 8.0, "median {median}");
        let finite = punch_pressure(&run.dir);
        let small = punch_pressure(&small.dir);
        // increments 10 and 20 of 80: 0.005 a and 0.01 a of travel
        for i in [10, 20] {
            assert!(
                (finite[i] / small[i] - 1.0).abs() < 0.01,
                "{} against {}",
                finite[i],
                small[i]
            );
        }
    }
}
