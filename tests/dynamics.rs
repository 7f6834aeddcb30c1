//! Dynamics verification: each integrator's period elongation and amplitude decay against
//! its amplification matrix, stability limits, energy conservation, and the rod wave.

mod common;

use common::column;

use impact::reference::{self, Recurrence};

fn run_oscillator(name: &str, integrator: &[&str], dt_over_t: f64, cycles: f64) -> Vec<f64> {
    let period = 2.0 * std::f64::consts::PI;
    let dt = dt_over_t * period;
    let mut overrides: Vec<String> = integrator.iter().map(|s| s.to_string()).collect();
    overrides.push(format!("analysis.dt={dt:e}"));
    overrides.push(format!("analysis.end_time={:e}", cycles * period));
    let refs: Vec<&str> = overrides.iter().map(String::as_str).collect();
    let model = common::model("oscillator", common::UNIT_OSCILLATOR, &refs);
    let dir = common::out_dir(name);
    impact::analysis::run(&model, &dir, Default::default())
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    column(&dir, "u_x[end]")
}

/// Least-squares fit of u_{n+1} = p u_n - q u_{n-1} on the signal after its first `skip`
/// samples (spurious roots have died out there): rho = sqrt(q), Omega_bar = acos(p / 2 rho).
fn measured_root(u: &[f64], skip: usize) -> (f64, f64) {
    let (mut a11, mut a12, mut a22, mut b1, mut b2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for n in skip.max(1)..u.len() - 1 {
        let (x1, x2, y) = (u[n], -u[n - 1], u[n + 1]);
        a11 += x1 * x1;
        a12 += x1 * x2;
        a22 += x2 * x2;
        b1 += x1 * y;
        b2 += x2 * y;
    }
    let det = a11 * a22 - a12 * a12;
    let p = (b1 * a22 - b2 * a12) / det;
    let q = (a11 * b2 - a12 * b1) / det;
    let rho = q.sqrt();
    (rho, (p / (2.0 * rho)).acos())
}

/// Period elongation (T_bar - T) / T and amplitude decay per cycle 1 - rho^(2 pi / Omega_bar).
fn elongation_and_decay(rho: f64, phase: f64, omega_h: f64) -> (f64, f64) {
    (
        omega_h / phase - 1.0,
        1.0 - rho.powf(2.0 * std::f64::consts::PI / phase),
    )
}

/// Goal: each implicit method reproduces its own numerical dispersion and dissipation.
/// Setup: the undamped unit oscillator at dt/T = 0.05, 0.1, 0.2 (as in Bathe & Wilson's
/// charts), 12 cycles (3 for Hu above dt/T = 0.05, whose decay leaves little signal).
/// Reference: the principal root of the method's amplification matrix
/// (reference::amplification, written from the textbook recurrences). The measured root
/// comes from a least-squares fit of the two-term recurrence to u_n. Tolerance: 5 % of the
/// predicted value (the required accuracy), or 1e-6 absolute where the prediction is zero.
#[test]
fn oscillator_period_elongation_and_decay_match_amplification_matrices() {
    let cases: [(&str, &[&str], Recurrence); 7] = [
        (
            "average",
            &["analysis.integrator=average"],
            Recurrence::Newmark {
                beta: 0.25,
                gamma: 0.5,
            },
        ),
        (
            "linear",
            &["analysis.integrator=linear"],
            Recurrence::Newmark {
                beta: 1.0 / 6.0,
                gamma: 0.5,
            },
        ),
        (
            "hu",
            &["analysis.integrator=hu"],
            Recurrence::Newmark {
                beta: 1.0,
                gamma: 1.5,
            },
        ),
        (
            "wilson",
            &["analysis.integrator=wilson"],
            Recurrence::Wilson { theta: 1.4 },
        ),
        (
            "houbolt",
            &["analysis.integrator=houbolt"],
            Recurrence::Houbolt,
        ),
        (
            "hht",
            &["analysis.integrator=hht", "analysis.alpha=-0.1"],
            Recurrence::GeneralizedAlpha {
                alpha_m: 0.0,
                alpha_f: 0.1,
                beta: 0.3025,
                gamma: 0.6,
            },
        ),
        (
            "generalized_alpha",
            &[
                "analysis.integrator=generalized_alpha",
                "analysis.rho_infinity=0.5",
            ],
            // rho_inf = 0.5: alpha_m = 0, alpha_f = 1/3, gamma = 5/6, beta = 4/9
            Recurrence::GeneralizedAlpha {
                alpha_m: 0.0,
                alpha_f: 1.0 / 3.0,
                beta: 4.0 / 9.0,
                gamma: 5.0 / 6.0,
            },
        ),
    ];
    for (name, overrides, recurrence) in cases {
        for dt_over_t in [0.05, 0.1, 0.2] {
            let omega_h = 2.0 * std::f64::consts::PI * dt_over_t;
            // strongly dissipative methods decay fast: fewer cycles keep the signal above round-off
            let cycles = if matches!(name, "hu") && dt_over_t > 0.05 {
                3.0
            } else {
                12.0
            };
            let u = run_oscillator(
                &format!("osc_{name}_{dt_over_t}"),
                overrides,
                dt_over_t,
                cycles,
            );
            let (rho, phase) = measured_root(&u, 10);
            let (pe, ad) = elongation_and_decay(rho, phase, omega_h);
            let (rho_ref, phase_ref) = reference::principal_root(recurrence, omega_h);
            let (pe_ref, ad_ref) = elongation_and_decay(rho_ref, phase_ref, omega_h);
            eprintln!(
                "{name} dt/T={dt_over_t}: PE {pe:.5} (ref {pe_ref:.5}), AD {ad:.5} (ref {ad_ref:.5})"
            );
            let close = |x: f64, r: f64| (x - r).abs() <= 0.05 * r.abs() + 1e-6;
            assert!(
                close(pe, pe_ref),
                "{name} dt/T={dt_over_t}: period elongation {pe:.5} vs {pe_ref:.5}"
            );
            assert!(
                close(ad, ad_ref),
                "{name} dt/T={dt_over_t}: amplitude decay {ad:.5} vs {ad_ref:.5}"
            );
        }
    }
}

/// Goal: unconditional stability where the theory promises it, and its loss where it does
/// not. dt/T = 10 for 2000 steps from u = 0, v = 1. Reference: the spectral radius of the
/// amplification matrix: Wilson 1.4, Houbolt, Newmark average and Hu <= 1; Wilson 1.2 > 1
/// at this dt. Bounded: the last 100 steps stay below the first 100 (the first step of a
/// velocity start overshoots at such a dt: u_1 = h v_0 (1 - 1/theta^2) for Wilson);
/// unbounded: they exceed them a thousandfold.
#[test]
fn wilson_and_houbolt_stable_at_large_steps_wilson_low_theta_is_not() {
    let omega_h = 20.0 * std::f64::consts::PI;
    assert!(reference::spectral_radius(Recurrence::Wilson { theta: 1.4 }, omega_h) <= 1.0);
    assert!(reference::spectral_radius(Recurrence::Houbolt, omega_h) <= 1.0);
    assert!(reference::spectral_radius(Recurrence::Wilson { theta: 1.2 }, omega_h) > 1.0);
    for (name, overrides, bounded) in [
        (
            "wilson14",
            vec!["analysis.integrator=wilson", "analysis.theta=1.4"],
            true,
        ),
        ("houbolt", vec!["analysis.integrator=houbolt"], true),
        ("average", vec!["analysis.integrator=average"], true),
        ("hu", vec!["analysis.integrator=hu"], true),
        (
            "wilson12",
            vec!["analysis.integrator=wilson", "analysis.theta=1.2"],
            false,
        ),
    ] {
        let u = run_oscillator(&format!("stab_{name}"), &overrides, 10.0, 2000.0);
        let peak = |s: &[f64]| s.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let (first, last) = (peak(&u[..100]), peak(&u[u.len() - 100..]));
        if bounded {
            assert!(
                last <= first,
                "{name}: |u| {first} in the first steps, {last} in the last"
            );
        } else {
            assert!(
                last > 1e3 * first,
                "{name}: expected growth, |u| {first} -> {last}"
            );
        }
    }
}

/// A fixed-free rod (L = 10, E = 100, rho = 0.01, c = 100), 10 elements unless overridden.
const FIXED_FREE_ROD: &str = r#"
[[material]]
name = "m"
young = 100.0
poisson = 0.0
density = 0.01

[[body]]
name = "rod"
material = "m"
formulation = "rod"
area = 1.0
mesh = { type = "line", start = [0.0, 0.0], end = [10.0, 0.0], n = 10 }

[[support]]
set = "start"
fix = ["x", "y"]

[[support]]
set = "all"
fix = ["y"]
"#;

/// The fixed-free rod set moving at 0.1, central difference.
fn chain() -> String {
    format!(
        "{FIXED_FREE_ROD}{}",
        r#"
[[initial_velocity]]
set = "all"
velocity = [0.1, 0.0]

[analysis]
type = "dynamic"
integrator = "central_difference"
geometry = "linear"
dt = 0.001
end_time = 1.0

[output]
frame_every = 0
"#
    )
}

/// The exact highest frequency of the fixed-free 10-rod chain with lumped mass, from the
/// assembled matrices (independent of the code: K tridiagonal E A / h, M diagonal rho A h
/// with the free end's half).
fn chain_omega_max() -> f64 {
    let (n, h, e, rho) = (10, 1.0, 100.0, 0.01);
    let mut k = nalgebra::DMatrix::<f64>::zeros(n, n);
    for i in 0..n {
        k[(i, i)] = if i == n - 1 { e / h } else { 2.0 * e / h };
        if i + 1 < n {
            k[(i, i + 1)] = -e / h;
            k[(i + 1, i)] = -e / h;
        }
    }
    let m: Vec<f64> = (0..n)
        .map(|i| if i == n - 1 { rho * h / 2.0 } else { rho * h })
        .collect();
    let a = nalgebra::DMatrix::from_fn(n, n, |i, j| k[(i, j)] / (m[i] * m[j]).sqrt());
    a.symmetric_eigenvalues().max().sqrt()
}

/// Goal: central difference is stable below its limit and unstable just above it.
/// Setup: fixed-free chain of 10 rods set moving at v = 0.1. Reference: dt_crit = 2 / omega_max
/// with omega_max from the assembled eigenproblem (chain_omega_max). At 0.95 dt_crit the run
/// finishes with the energy balance within 5 % (the measured kinetic + strain energy of
/// central difference oscillates about its conserved shadow energy, by O((omega dt)^2) in the
/// highest mode); at 1.05 dt_crit (allow_unstable) it stops
/// with status `unstable`, exit code 3. Without allow_unstable it is refused (exit 2).
#[test]
fn central_difference_stable_below_and_unstable_above_dt_crit() {
    let dt_crit = 2.0 / chain_omega_max();
    let model = common::model(
        "chain",
        &chain(),
        &[&format!("analysis.dt={:e}", 0.95 * dt_crit)],
    );
    let (summary, _) = common::run("chain_stable", &model);
    assert!(
        summary.energy.max_relative_drift < 0.05,
        "drift {}",
        summary.energy.max_relative_drift
    );

    let above = format!("analysis.dt={:e}", 1.05 * dt_crit);
    let model = common::model("chain", &chain(), &[&above, "analysis.allow_unstable=true"]);
    let err = impact::analysis::run(
        &model,
        &common::out_dir("chain_unstable"),
        Default::default(),
    )
    .unwrap_err();
    assert_eq!(err.exit_code(), 3, "{err}");
    match err {
        impact::analysis::RunError::Numerical { summary, .. } => {
            assert_eq!(summary.status, impact::analysis::Status::Unstable)
        }
        other => panic!("expected a numerical failure, got {other}"),
    }
    let model = common::model("chain", &chain(), &[&above]);
    let err = impact::analysis::run(
        &model,
        &common::out_dir("chain_refused"),
        Default::default(),
    )
    .unwrap_err();
    assert_eq!(err.exit_code(), 2, "{err}");
    assert!(err.to_string().contains("analysis.dt"), "{err}");
}

const BLOCK: &str = r#"
[[material]]
name = "m"
young = 1000.0
poisson = 0.3
density = 1.0

[[body]]
name = "block"
material = "m"
formulation = "plane_strain"
mesh = { type = "rectangle", width = 2.0, height = 1.0, nx = 6, ny = 3 }

[[support]]
set = "bottom"
fix = ["x", "y"]

[[initial_velocity]]
set = "top"
velocity = [0.3, -0.2]

[analysis]
type = "dynamic"
integrator = "average"
geometry = "linear"
dt = 0.002
end_time = 2.0
newton = { strategy = "initial", tol_displacement = 1e-13, tol_force = 1e-13 }

[output]
frame_every = 0
"#;

/// Goal: the trapezoidal rule conserves energy exactly on a linear system.
/// Setup: a plane-strain Quad4 block fixed at its base, its top nodes started moving;
/// Newmark average, consistent mass, linear kinematics, 1000 steps. Reference: energy
/// conservation, kinetic + internal = initial kinetic, to 1e-9 relative.
#[test]
fn newmark_average_conserves_energy_of_elastic_block() {
    let model = common::model("block_energy", BLOCK, &[]);
    let dir = common::out_dir("block_energy");
    let summary = impact::analysis::run(&model, &dir, Default::default()).unwrap();
    assert_eq!(summary.steps, 1000);
    let kinetic = column(&dir, "kinetic_energy");
    let internal = column(&dir, "internal_energy");
    let e0 = kinetic[0];
    assert!(e0 > 0.0);
    for (k, i) in kinetic.iter().zip(&internal) {
        approx::assert_relative_eq!(k + i, e0, max_relative = 1e-9);
    }
    assert_eq!(
        summary.factorizations, 1,
        "strategy `initial` factors K* once for a linear run"
    );
}

/// The fixed-free rod with 100 elements and a step force at its free end.
fn wave() -> String {
    format!(
        "{}{}",
        FIXED_FREE_ROD.replace("n = 10 }", "n = 100 }"),
        r#"
[[load]]
type = "nodal_force"
set = "end"
force = [-1.0, 0.0]

[analysis]
type = "dynamic"
integrator = "central_difference"
geometry = "linear"
dt = 0.000999
end_time = 0.05

[output]
frame_every = 0
"#
    )
}

/// Goal: a step load travels at c and doubles on reflection at a fixed end.
/// Setup: rod L = 10, E = 100, rho = 0.01 (c = 100, L/c = 0.1), 100 elements, fixed at x = 0,
/// a compressive step force F = 1 at x = L from t = 0; central difference at Courant number
/// 0.999 (nearly exact for lumped rods); the fixed-end element's stress in every history row
/// up to 3 L/c. Reference (d'Alembert): the stress at the fixed end is 0 before L/c and
/// -2 F / A after it, until 3 L/c. Tolerance: one element transit (h/c = 0.001) in time,
/// checked from two transits before and after the arrivals; 5 % of F on the doubled stress
/// and before the arrival (the front's dispersion at Courant 0.999).
#[test]
fn rod_wave_arrives_at_l_over_c_and_doubles_on_reflection() {
    let (f, c, l, transit) = (1.0, 100.0, 10.0, 0.001);
    let text = format!(
        "{}\n[[output.probe]]\nquantity = \"s_xx\"\nset = \"start\"\n",
        wave()
    );
    let model = common::model(
        "wave",
        &text,
        &[&format!("analysis.end_time={}", 3.0 * l / c)],
    );
    let dir = common::out_dir("wave");
    impact::analysis::run(&model, &dir, Default::default()).unwrap();
    let time = column(&dir, "time");
    let stress = column(&dir, "s_xx[start]");
    let (mut before, mut after) = (0, 0);
    for (t, s) in time.iter().zip(&stress) {
        if *t <= l / c - 2.0 * transit {
            assert!(s.abs() < 0.05 * f, "stress before arrival at t = {t}: {s}");
            before += 1;
        } else if *t >= l / c + 2.0 * transit && *t <= 3.0 * l / c - 2.0 * transit {
            assert!(
                (s + 2.0 * f).abs() < 0.05 * f,
                "doubled stress at t = {t}: {s}"
            );
            after += 1;
        }
    }
    assert!(
        before > 90 && after > 190,
        "rows checked: {before} before, {after} after"
    );
}

/// Goal: Rayleigh damping C = a M + b K damps the oscillator at zeta = a / (2 omega) + b omega / 2.
/// Setup: the unit oscillator (omega = 1), Newmark average at dt/T = 0.005, 5 cycles, with
/// (a, b) = (0.1, 0) and (0, 0.1): zeta = 0.05 either way. Reference: the exact damped root
/// exp((-zeta + i sqrt(1 - zeta^2)) omega dt): the measured zeta = -ln(rho) / (omega dt)
/// within 1 % (the trapezoidal rule's error is O((omega dt)^2) ~ 1e-3 here).
#[test]
fn rayleigh_damping_gives_the_exact_decay_rate() {
    let dt_over_t = 0.005;
    let omega_h = 2.0 * std::f64::consts::PI * dt_over_t;
    for rayleigh in ["[0.1,0.0]", "[0.0,0.1]"] {
        let u = run_oscillator(
            &format!("rayleigh_{rayleigh}"),
            &[
                "analysis.integrator=average",
                &format!("analysis.rayleigh={rayleigh}"),
            ],
            dt_over_t,
            5.0,
        );
        let (rho, _) = measured_root(&u, 2);
        let zeta = -rho.ln() / omega_h;
        approx::assert_relative_eq!(zeta, 0.05, max_relative = 1e-2);
    }
}

/// Goal: prescribed motions drive the integrator consistently (their velocity and
/// acceleration come from the same formulas as the free DOFs, and they start with the
/// curve's slope). Setup: the left edge of an elastic strip is moved by
/// u_x(t) = 0.05 sin(2 pi t / 0.4) (a curve sampled every 0.01), the rest free, Newmark average,
/// linear kinematics. Reference: (1) energy conservation with the work done by the moving
/// edge, kinetic + strain = W_ext, to 1e-6 relative (the trapezoidal rule conserves it on a
/// linear system); (2) the trapezoidal identity (v_n + v_n+1)/2 = (u_n+1 - u_n)/dt for the
/// prescribed edge, with u from the curve, to 1e-9 of the velocity amplitude.
#[test]
fn prescribed_motion_drives_consistently() {
    let samples: Vec<String> = (0..=80)
        .map(|k| {
            let t = k as f64 * 0.01;
            format!("[{t}, {}]", (2.0 * std::f64::consts::PI * t / 0.4).sin())
        })
        .collect();
    let text = format!(
        r#"
[[curve]]
name = "shake"
points = [{}]

[[material]]
name = "m"
young = 1000.0
poisson = 0.3
density = 1.0

[[body]]
name = "strip"
material = "m"
formulation = "plane_stress"
mesh = {{ type = "rectangle", width = 4.0, height = 0.5, nx = 16, ny = 2 }}

[[load]]
type = "displacement"
set = "left"
x = 0.05
y = 0.0
curve = "shake"

[analysis]
type = "dynamic"
integrator = "average"
geometry = "linear"
dt = 0.002
end_time = 0.8
newton = {{ strategy = "initial", tol_displacement = 1e-12, tol_force = 1e-12 }}

[output]
frame_every = 0

[[output.probe]]
quantity = "v_x"
set = "left"
"#,
        samples.join(", ")
    );
    let model = common::model("shake", &text, &[]);
    let dir = common::out_dir("shake");
    let summary = impact::analysis::run(&model, &dir, Default::default()).unwrap();
    assert!(
        summary.energy.max_relative_drift < 1e-6,
        "drift {}",
        summary.energy.max_relative_drift
    );
    let t = column(&dir, "time");
    let v = column(&dir, "v_x[left]");
    let u = |t: f64| {
        0.05 * model
            .loads
            .iter()
            .find_map(|l| match l {
                impact::scene::Load::Displacement { curve, .. } => Some(curve.value(t)),
                _ => None,
            })
            .unwrap()
    };
    let amplitude = 0.05 * 2.0 * std::f64::consts::PI / 0.4;
    for n in 0..t.len() - 1 {
        let mean = 0.5 * (v[n] + v[n + 1]);
        let rate = (u(t[n + 1]) - u(t[n])) / (t[n + 1] - t[n]);
        assert!(
            (mean - rate).abs() < 1e-9 * amplitude,
            "t = {}: {mean} vs {rate}",
            t[n]
        );
    }
    // the edge starts with the slope of the curve's first segment
    let first_slope = 0.05 * (2.0 * std::f64::consts::PI * 0.01 / 0.4).sin() / 0.01;
    approx::assert_relative_eq!(v[0], first_slope, max_relative = 1e-9);
}

/// Goal: an end time a hair past a whole number of steps (as an end_time written with a few
/// digits gives) ends the run in the last whole step, lengthened by the hair, instead of a
/// step of 1e-8 dt of its own (found with the bench block: such a step did not converge,
/// `diverged` after six cuts, with end_time = 5.1226381e-06). Setup: the bench's 20 x 10 J2 steel block in free flight at 10 m/s, Newmark average,
/// modified Newton, end_time = 3 dt + 1e-13 s (6e-8 dt) and 3 dt + 3.6e-10 s (2e-4 dt, under
/// the shortest step the control takes, dt / 2^6 / 10). Reference: a rigid motion keeps its
/// kinetic energy (1/2 m V^2 = 1962.5 J/m), and the run ends at end_time in 3 steps.
#[test]
fn a_remainder_shorter_than_the_shortest_step_joins_the_last_step() {
    let text = impact::bench::scene(&impact::bench::Case {
        name: "remainder".into(),
        method: impact::bench::Method::Implicit,
        n: 20,
        steps: 3,
        bottom: impact::bench::Bottom::Free,
        frame_every: 0,
        threads: None,
        speed: 10.0,
        strategy: "modified",
        scene: None,
    });
    let model = common::model("remainder", &text, &[]);
    let impact::scene::model::Analysis::Dynamic(spec) = &model.analysis else {
        panic!("a dynamic scene")
    };
    let dt = spec.fixed_dt().unwrap();
    for extra in [1e-13, 3.6e-10] {
        let end = 3.0 * dt + extra;
        let set = format!("analysis.end_time={end:e}");
        let model = common::model("remainder", &text, &[set.as_str()]);
        let dir = common::out_dir("remainder");
        let summary = impact::analysis::run(&model, &dir, Default::default()).unwrap();
        assert_eq!(summary.steps, 3, "extra {extra:e}");
        let time = column(&dir, "time");
        assert_eq!(*time.last().unwrap(), end);
        // rho W H V^2 / 2 = 7850 * 0.1 * 0.05 * 100 / 2; round-off of 3 steps
        approx::assert_relative_eq!(
            *column(&dir, "kinetic_energy").last().unwrap(),
            1962.5,
            max_relative = 1e-12
        );
    }
}

/// A steel rod of 10 elements at 10 m/s, Newmark average, to end_time 1e-4 with frames every
/// 3e-6: the numbers a user writes, whose multiples of dt are not those times in floating
/// point (100 x 1e-6 = 9.999999999999999e-5, 15 x 1e-6 = 1.4999999999999999e-5).
const ROUND_OFF_ROD: &str = r#"
[[material]]
name = "bar"
young = 200e9
poisson = 0.0
density = 7850.0

[[body]]
name = "bar"
material = "bar"
formulation = "rod"
area = 1e-4
velocity = [10.0, 0.0]
mesh = { type = "line", start = [0.0, 0.0], end = [0.1, 0.0], n = 10 }

[[support]]
set = "all"
fix = ["y"]

[analysis]
type = "dynamic"
integrator = "average"
dt = 1e-6
end_time = 1e-4

[output]
frame_every = 0
frame_interval = 3e-6
"#;

/// Goal: implicit steps land exactly on end_time and on the frame times. Before: the last
/// history row was at 9.999999999999999e-5 (100 x 1e-6) instead of 1e-4, and frames at
/// 1.4999999999999999e-5 instead of the listed 1.5e-5. Setup: `ROUND_OFF_ROD` with dt = 1e-6
/// and 2e-6 (both land off in floating point) and 7e-7 (a dt the frames split).
/// Reference: the scene's own numbers: the last row's time is the text `1e-4` parsed, each
/// frame's time is k x 3e-6 as the scene defines the frame times, and each of those times
/// has a history row.
#[test]
fn implicit_steps_land_exactly_on_end_time_and_frame_times() {
    let end_time: f64 = "1e-4".parse().unwrap();
    let listed: Vec<f64> = (1..=33).map(|k| k as f64 * 3e-6).collect();
    for dt in ["1e-6", "2e-6", "7e-7"] {
        let name = format!("round_off_{dt}");
        let model = common::model(&name, ROUND_OFF_ROD, &[&format!("analysis.dt={dt}")]);
        common::run(&name, &model);
        let dir = common::out_dir_of(&name);
        let times = column(&dir, "time");
        assert_eq!(*times.last().unwrap(), end_time, "dt {dt}");
        let frames = impact::output::vtk::read_pvd(&dir.join(format!("{name}.pvd"))).unwrap();
        let frame_times: Vec<f64> = frames.iter().map(|(t, _)| *t).collect();
        let mut expected = vec![0.0];
        expected.extend(&listed);
        expected.push(end_time);
        assert_eq!(frame_times, expected, "dt {dt}");
        for t in &listed {
            assert!(times.contains(t), "dt {dt}: no history row at {t:e}");
        }
        // each frame file carries its own time (ParaView shows it without the .pvd)
        for ((_, path), t) in frames.iter().zip(&expected) {
            assert_eq!(time_value(path), *t, "dt {dt}: {}", path.display());
        }
    }
}

/// Goal: `frame_interval` alone replaces the frames per step (it once came on top of them:
/// 1 783 frames where the interval asked for 7). Setup: `ROUND_OFF_ROD` without its
/// `frame_every = 0`, dt = 1e-6 (100 steps). Reference: the scene's numbers: the initial
/// frame, the 33 multiples of 3e-6 up to 1e-4, and the end.
#[test]
fn a_frame_interval_replaces_the_frames_per_step() {
    let text = ROUND_OFF_ROD.replace("frame_every = 0\n", "");
    assert!(!text.contains("frame_every"));
    let model = common::model("interval_alone", &text, &["analysis.dt=1e-6"]);
    common::run("interval_alone", &model);
    let dir = common::out_dir_of("interval_alone");
    let frames = impact::output::vtk::read_pvd(&dir.join("interval_alone.pvd")).unwrap();
    assert_eq!(frames.len(), 1 + 33 + 1);
}

/// The `TimeValue` field data of a .vtu frame, read from its XML header.
fn time_value(path: &std::path::Path) -> f64 {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes
        .windows(13)
        .position(|w| w == b"<AppendedData")
        .unwrap_or(bytes.len());
    let header = String::from_utf8_lossy(&bytes[..end]);
    let at = header
        .find("Name=\"TimeValue\"")
        .unwrap_or_else(|| panic!("{}: no TimeValue", path.display()));
    let rest = &header[at..];
    let open = rest.find('>').unwrap() + 1;
    let close = rest.find("</DataArray>").unwrap();
    rest[open..close].trim().parse().unwrap()
}

/// A fixed-free rod of `n` lumped-mass elements (E = A = L = 1, rho = 1) started in its first
/// mode: node k (x = k / n) at v_k = sin(k theta), theta = pi / (2 n). With the half mass at
/// the free end, sin(k theta) is an exact eigenvector of the lumped chain, with
/// omega^2 = 2 (E A / h) (1 - cos theta) / (rho A h): the semi-discrete solution is
/// u_k(t) = sin(k theta) sin(omega t) / omega, a standing wave.
fn rod_mode(n: usize) -> (String, f64) {
    let h = 1.0 / n as f64;
    let theta = std::f64::consts::PI / (2.0 * n as f64);
    let omega = (2.0 * (1.0 - theta.cos())).sqrt() / h;
    let mut text = String::from(
        r#"
[[material]]
name = "m"
young = 1.0
poisson = 0.0
density = 1.0

[[body]]
name = "rod"
material = "m"
formulation = "rod"
area = 1.0
"#,
    );
    text.push_str(&format!(
        "mesh = {{ type = \"line\", start = [0.0, 0.0], end = [1.0, 0.0], n = {n} }}\n"
    ));
    text.push_str(
        "\n[[support]]\nset = \"start\"\nfix = [\"x\", \"y\"]\n\n[[support]]\nset = \"all\"\nfix = [\"y\"]\n",
    );
    for k in 1..=n {
        let x = k as f64 * h;
        text.push_str(&format!(
            "\n[[node_set]]\nname = \"n{k}\"\nnearest = [{x:e}, 0.0]\n\n[[initial_velocity]]\nset = \"n{k}\"\nvelocity = [{:e}, 0.0]\n",
            (k as f64 * theta).sin()
        ));
    }
    text.push_str(
        r#"
[analysis]
type = "dynamic"
geometry = "linear"
mass = "lumped"
dt = "auto"
end_time = 20.0
newton = { strategy = "initial" }

[output]
frame_every = 0

[[output.probe]]
quantity = "u_x"
set = "end"
"#,
    );
    (text, omega)
}

/// The final error |u(T) - u_exact(T)| of an adaptive run of `text` at `tolerance`, with the
/// run's steps and rejected steps.
fn adaptive_error(name: &str, text: &str, tolerance: f64, exact: f64) -> (f64, usize, usize) {
    let tol = format!("analysis.error_tolerance={tolerance:e}");
    let model = common::model(name, text, &[tol.as_str()]);
    let dir = common::out_dir(&format!("{name}_{tolerance:e}"));
    let summary = impact::analysis::run(&model, &dir, Default::default())
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let u = *column(&dir, "u_x[end]").last().unwrap();
    ((u - exact).abs(), summary.steps, summary.rejected_steps)
}

/// Goal: with `dt = "auto"` (Newmark average) the global error falls in proportion to
/// `error_tolerance`. Reference: the estimate e = dt^2 (a_{n+1} - a_n) / 12 of Zienkiewicz
/// and Xie (1991), taken relative to dt V (theory 8.2a), grows as dt^2 in smooth motion, so
/// the step is proportional to tol^(1/2), and the trapezoidal rule's global (phase) error,
/// of order dt^2, to tol: a log-log slope of 1 against the exact solutions of the unit
/// oscillator (u = sin t, at t = 10) and of the first mode of a 10-element rod (the
/// semi-discrete standing wave, rod_mode, its tip at t = 20).
/// Asserted: the slope over tolerances 1e-2, 1e-3, 1e-4 (two decades) within 0.2 of 1
/// (measured 0.905 and 0.881); the error at the tightest tolerance below 1 % of the amplitude
/// (measured 0.12 % and 0.48 %: about 1.6 periods of the oscillator, 5 of the rod).
#[test]
fn adaptive_step_global_error_follows_the_tolerance() {
    let oscillator = common::UNIT_OSCILLATOR
        .replace("dt = 0.1", "dt = \"auto\"")
        .replace(
            "newton = { strategy = \"initial\", tol_displacement = 1e-12, tol_force = 1e-12 }",
            "newton = { strategy = \"initial\" }",
        );
    let (rod, omega) = rod_mode(10);
    // u_tip(t) = sin(n theta) sin(omega t) / omega, sin(n theta) = 1
    let studies = [
        ("adaptive_oscillator", oscillator, 10f64.sin(), 1.0),
        (
            "adaptive_rod_mode",
            rod,
            (omega * 20.0).sin() / omega,
            1.0 / omega,
        ),
    ];
    for (name, text, exact, amplitude) in studies {
        let points: Vec<(f64, f64)> = [1e-2, 1e-3, 1e-4]
            .iter()
            .map(|&tol| {
                let (error, steps, rejected) = adaptive_error(name, &text, tol, exact);
                println!(
                    "{name}: tol {tol:e}: error {error:.3e}, {steps} steps, {rejected} rejected"
                );
                (tol, error)
            })
            .collect();
        let slope = impact::sweep::charts::fitted_slope(&points).unwrap().0;
        println!("{name}: slope {slope:.3}");
        assert!((slope - 1.0).abs() <= 0.2, "{name}: slope {slope}");
        assert!(points[2].1 < 1e-2 * amplitude, "{name}: {points:?}");
    }
}
