//! Selective mass scaling of central difference (`analysis.mass_scaling`, docs/theory.md 8.7b):
//! the step and the wave speed of a scaled strip against d'Alembert, the added mass of a
//! graded strip against its closed-form sum, momentum and the energy balance as mass joins
//! the moving nodes, the warnings at their edges, and the scenes it refuses.

mod common;

use common::{column, impact};
use impact::analysis::{self, RunOptions, Summary};

/// Steel-like numbers in consistent units: E = 200, nu = 0.3, rho = 1.
const YOUNG: f64 = 200.0;
const POISSON: f64 = 0.3;
const DENSITY: f64 = 1.0;
/// The one-point kernel's default hourglass coefficient kappa.
const KAPPA: f64 = 0.1;

/// The stable step 2 / omega_e of an a x b plane-strain rectangle of the one-point kernel,
/// written out from its frequency bound (docs/theory.md 8.7: Flanagan & Belytschko's
/// (lambda + 2 mu) V b.b plus the hourglass stiffness' k_hg V b.b |gamma|^2, over the
/// smallest lumped nodal mass): for a rectangle b.b = 1/a^2 + 1/b^2, gamma_a = h_a -
/// (h.x) b_a = h_a = (1, -1, 1, -1) (|gamma|^2 = 4) and the smallest nodal mass is
/// rho a b t / 4, so omega_e^2 = 4 (1/a^2 + 1/b^2) (lambda + 2 mu + 4 k_hg) / rho,
/// k_hg = kappa (lambda + 3 mu) / 24.
fn one_point_step(a: f64, b: f64) -> f64 {
    let lambda = YOUNG * POISSON / ((1.0 + POISSON) * (1.0 - 2.0 * POISSON));
    let mu = YOUNG / (2.0 * (1.0 + POISSON));
    let hourglass = KAPPA * (lambda + 3.0 * mu) / 24.0;
    let omega_squared =
        4.0 * (1.0 / (a * a) + 1.0 / (b * b)) * (lambda + 2.0 * mu + 4.0 * hourglass) / DENSITY;
    2.0 / omega_squared.sqrt()
}

/// The plane-strain (constrained) wave speed sqrt((lambda + 2 mu) / rho).
fn wave_speed() -> f64 {
    let modulus = YOUNG * (1.0 - POISSON) / ((1.0 + POISSON) * (1.0 - 2.0 * POISSON));
    (modulus / DENSITY).sqrt()
}

const MATERIAL: &str = r#"
[[material]]
name = "m"
young = 200.0
poisson = 0.3
density = 1.0
"#;

/// A plane-strain strip `width` x `height` of nx x 1 one-point elements (graded along x by
/// `grading`), every node held in y; `rest` adds its loads, sets and analysis.
fn strip(width: f64, height: f64, nx: usize, grading: f64, rest: &str) -> String {
    format!(
        r#"{MATERIAL}
[[body]]
name = "strip"
material = "m"
formulation = "plane_strain"
mesh = {{ type = "rectangle", width = {width}, height = {height}, nx = {nx}, ny = 1, grading_x = {grading} }}

[[support]]
set = "all"
fix = ["y"]
{rest}
"#
    )
}

/// The strip of `strip` 1 x 0.01 in 100 square elements, its left end pulled at V = 1e-5
/// (a tension wave of strain V / c ~ 6e-7: linear to that order), probed at x = 0.5, to
/// `end_time`.
fn pulled_strip(end_time: f64) -> String {
    strip(
        1.0,
        0.01,
        100,
        1.0,
        &format!(
            r#"
[[curve]]
name = "ramp"
points = [[0.0, 0.0], [1.0, 1.0]]

[[load]]
type = "displacement"
set = "left"
x = -1.0e-5
curve = "ramp"

[[node_set]]
name = "middle"
nearest = [0.5, 0.0]

[analysis]
type = "dynamic"
integrator = "central_difference"
quadrature = "reduced"
end_time = {end_time}

[output]
frame_every = 0

[[output.probe]]
quantity = "v_x"
set = "middle"
"#
        ),
    )
}

/// Runs a scene text with `--set` overrides to its end (status ok), without the bulk
/// viscosity and at the bound's step: the closed forms below are of the undamped elements'
/// bounds (the viscosity shortens every step by its damping at rest, sqrt(1 + b_1^2) - b_1
/// = 0.94, theory 8.7a; the global step, the default without the mass scaling, is longer).
fn run(name: &str, text: &str, overrides: &[&str]) -> (std::path::PathBuf, Summary) {
    let overrides: Vec<&str> = overrides
        .iter()
        .copied()
        .chain(["analysis.bulk_viscosity=off", "analysis.stable_step=bound"])
        .collect();
    let model = common::model(name, text, &overrides);
    let dir = common::out_dir(name);
    let summary = analysis::run(&model, &dir, RunOptions::default())
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    (dir, summary)
}

/// The time at which history.csv column `name` first crosses `level` (linear between rows).
fn crossing(dir: &std::path::Path, name: &str, level: f64) -> f64 {
    let (time, value) = (column(dir, "time"), column(dir, name));
    for k in 1..time.len() {
        let (a, b) = (value[k - 1] - level, value[k] - level);
        if a * b <= 0.0 && a != b {
            return time[k - 1] + (time[k] - time[k - 1]) * a / (a - b);
        }
    }
    panic!("{name} never crosses {level}");
}

/// Goal: with every element below the target the run steps at the target (times the
/// clock's 0.9) and every wave is slower by exactly sqrt(s), s = (target / dt_e)^2 the mass
/// factor. Setup: `pulled_strip`, square elements of side h = 0.01, unscaled and with
/// target = 3 dt_e (s = 9). Reference: dt_e of `one_point_step`; d'Alembert: the tension
/// front reaches x = 0.5 at t = 0.5 / c unscaled and 0.5 sqrt(s) / c scaled, c the
/// plane-strain wave speed; the added mass (s - 1) rho W H. Tolerances: the steps and the
/// mass at the start are sums and products of a few numbers (1e-12); the elements that the
/// front's oscillating precursor compresses take a little more (2e-12 measured; 1e-9).
/// Linearized, the scaled run is the unscaled one with its clock stretched by sqrt(s)
/// (m s / (sqrt(s) dt)^2 = m / dt^2 at every step, the pulled end's velocity the same at
/// corresponding steps), so the half-level crossings of v_x at the probe differ by
/// sqrt(s) up to the finite-strain terms, of the order of the strain V sqrt(s) / c = 2e-6
/// (measured 3e-7; 1e-5). The crossing itself lags d'Alembert's time by the discrete
/// front's offset (measured 0.6 element transits): within one transit h sqrt(s) / c.
#[test]
fn uniform_strip_steps_at_the_target_and_its_wave_slows_by_sqrt_of_the_factor() {
    let (h, c) = (0.01, wave_speed());
    let dt_e = one_point_step(h, h);
    let target = 3.0 * dt_e;
    let factor: f64 = 9.0;
    let (plain_dir, plain) = run("ms_strip_plain", &pulled_strip(0.8 / c), &[]);
    let set = format!("analysis.mass_scaling={{target={target:e}}}");
    let (scaled_dir, scaled) = run(
        "ms_strip_scaled",
        &pulled_strip(0.8 * factor.sqrt() / c),
        &[&set],
    );
    let relative = |a: f64, b: f64| (a / b - 1.0).abs();
    let plain_step = plain.dt_max.unwrap();
    assert!(
        relative(plain_step, 0.9 * dt_e) < 1e-12,
        "{plain_step} vs 0.9 x {dt_e}"
    );
    for step in [scaled.dt_min.unwrap(), scaled.dt_max.unwrap()] {
        assert!(
            relative(step, 0.9 * target) < 1e-12,
            "{step} vs 0.9 x {target}"
        );
    }
    let report = scaled.mass_scaling.as_ref().expect("summary.mass_scaling");
    assert_eq!(report.elements_scaled, 100);
    let expected = (factor - 1.0) * DENSITY * 1.0 * h;
    let added = column(&scaled_dir, "added_mass");
    assert!(
        relative(added[0], expected) < 1e-12,
        "{} vs {expected}",
        added[0]
    );
    // the oscillating precursor of the discrete front compresses a few elements ahead of it
    // by a fraction of the wave's strain, and they take that much more mass
    assert!(
        relative(report.added_mass, expected) < 1e-9,
        "{}",
        report.added_mass
    );
    assert!(relative(report.added_mass_percent, 800.0) < 1e-9);
    let level = -0.5e-5;
    let (t_plain, t_scaled) = (
        crossing(&plain_dir, "v_x[middle]", level),
        crossing(&scaled_dir, "v_x[middle]", level),
    );
    assert!(
        relative(t_scaled / t_plain, factor.sqrt()) < 1e-5,
        "crossings {t_plain}, {t_scaled}: ratio {}",
        t_scaled / t_plain
    );
    let dalembert = 0.5 * factor.sqrt() / c;
    assert!(
        (t_scaled - dalembert).abs() < h * factor.sqrt() / c,
        "crossing {t_scaled} vs d'Alembert {dalembert}"
    );
}

/// The element widths of the graded strip `text` (its body's x coordinates in order).
fn widths(text: &str) -> Vec<f64> {
    let model = common::model("ms_widths", text, &[]);
    let mut xs: Vec<f64> = model.coordinates().iter().map(|p| p[0]).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    xs.windows(2).map(|w| w[1] - w[0]).collect()
}

/// A graded strip 1 x 0.05 of 20 elements, the last four times as wide as the first, at
/// rest: nothing deforms, so only the scaling at the start adds mass. `rest` adds to it.
fn graded_strip(rest: &str) -> String {
    strip(
        1.0,
        0.05,
        20,
        4.0,
        &format!(
            r#"
{rest}
[analysis]
type = "dynamic"
integrator = "central_difference"
quadrature = "reduced"
end_time = 0.002

[output]
frame_every = 0
"#
        ),
    )
}

/// The mass the scaling to `target` adds to elements of widths `widths` and height
/// `height`: sum over those below the target of (s_e - 1) rho a_e b, s_e = (target /
/// dt_e)^2 (docs/theory.md 8.7b).
fn added_mass(widths: &[f64], height: f64, target: f64) -> f64 {
    widths
        .iter()
        .map(|a| (a, one_point_step(*a, height)))
        .filter(|(_, dt)| *dt < target)
        .map(|(a, dt)| ((target / dt).powi(2) - 1.0) * DENSITY * a * height)
        .sum()
}

/// Goal: only the elements whose step is below the target are scaled, each to the target.
/// Setup: `graded_strip` (element widths 0.018 to 0.071, height 0.05), target the geometric
/// mean of the 6th and the 7th element's step. Reference: the six narrowest elements
/// scaled, the added mass sum_e (s_e - 1) m_e with s_e = (target / dt_e)^2 and dt_e of
/// `one_point_step` on the mesh's element widths; the body's mass rho W H. Tolerance: sums
/// of 20 products (1e-12).
#[test]
fn graded_strip_adds_the_closed_form_mass_to_the_elements_below_the_target() {
    let text = graded_strip("");
    let widths = widths(&text);
    assert_eq!(widths.len(), 20);
    let steps: Vec<f64> = widths.iter().map(|a| one_point_step(*a, 0.05)).collect();
    assert!(steps.windows(2).all(|w| w[0] < w[1]), "widths grow along x");
    let target = (steps[5] * steps[6]).sqrt();
    let expected = added_mass(&widths, 0.05, target);
    let set = format!("analysis.mass_scaling={{target={target:e}}}");
    let (dir, summary) = run("ms_graded", &text, &[&set]);
    let report = summary.mass_scaling.expect("summary.mass_scaling");
    let relative = |a: f64, b: f64| (a / b - 1.0).abs();
    assert_eq!(report.elements_scaled, 6);
    assert!(
        relative(report.added_mass, expected) < 1e-12,
        "{} vs {expected}",
        report.added_mass
    );
    let body = &report.bodies[0];
    assert!(relative(body.mass, DENSITY * 0.05) < 1e-12, "{}", body.mass);
    assert!(relative(body.added_mass, expected) < 1e-12);
    assert!(
        relative(
            report.added_mass_percent,
            100.0 * expected / (DENSITY * 0.05)
        ) < 1e-12
    );
    // the history's column has it from the first row on, and nothing more (at rest)
    let added = column(&dir, "added_mass");
    assert!(
        added.iter().all(|m| relative(*m, expected) < 1e-12),
        "{added:?}"
    );
    // the run's step: the target (below the 7th element's), times 0.9
    assert!(relative(summary.dt_max.unwrap(), 0.9 * target) < 1e-12);
    // `impact check` reports the scaling the run starts with
    let model = common::model("ms_graded", &text, &[&set, "analysis.bulk_viscosity=off"]);
    let lines = impact::analysis::check::report(&model).unwrap();
    assert!(
        lines.iter().any(|l| l.contains("6 element(s) below it")),
        "{lines:?}"
    );
}

/// The warnings of a run that mention `what`.
fn warnings_with(summary: &Summary, what: &str) -> usize {
    summary.warnings.iter().filter(|w| w.contains(what)).count()
}

/// Goal: the added-mass warning fires when a body's added mass passes 1 % of its mass, and
/// not before. Setup: `graded_strip` at the target T_1 at which the closed-form added mass
/// (`added_mass`) is 1 % of the body's (bisection), run at T_1 (1 -+ 1e-3). Reference: the
/// closed form of the test above; a 1e-3 change of the target changes the added mass by
/// more than 2e-3 of itself, far beyond the 1e-12 at which the run matches the closed form.
#[test]
fn added_mass_warning_fires_at_one_percent_of_the_body() {
    let text = graded_strip("");
    let widths = widths(&text);
    let body = DENSITY * 0.05;
    let (mut low, mut high) = (
        one_point_step(widths[0], 0.05),
        one_point_step(widths[19], 0.05),
    );
    for _ in 0..200 {
        let mid = 0.5 * (low + high);
        if added_mass(&widths, 0.05, mid) < 0.01 * body {
            low = mid;
        } else {
            high = mid;
        }
    }
    let threshold = 0.5 * (low + high);
    for (factor, warned) in [(1.0 - 1e-3, 0), (1.0 + 1e-3, 1)] {
        let target = threshold * factor;
        let set = format!("analysis.mass_scaling={{target={target:e}}}");
        let (_, summary) = run("ms_one_percent", &text, &[&set]);
        let percent = summary.mass_scaling.as_ref().unwrap().added_mass_percent;
        assert_eq!(
            warnings_with(&summary, "above 1 %"),
            warned,
            "target {target}: {percent} %: {:?}",
            summary.warnings
        );
    }
}

/// Goal: the contact warning fires when a scaled element has a node on a contact surface,
/// and not when the scaled elements stay off it. Setup: `graded_strip` with a contact pair
/// whose slaves are its right end (the widest element's outer nodes) against a wall beyond
/// it, at 1 -+ 1e-3 times the widest element's step (`one_point_step`). Reference: below it
/// the 19 narrower elements are scaled, none with a node at x = 1; above it all 20.
#[test]
fn contact_warning_fires_when_a_scaled_element_touches_a_contact_surface() {
    let text = graded_strip(
        r#"
[[obstacle]]
name = "wall"
points = [[1.5, 1.0], [1.5, -1.0]]

[[contact]]
name = "end"
slave = { set = "right" }
obstacle = "wall"
"#,
    );
    let widest = one_point_step(*widths(&text).last().unwrap(), 0.05);
    for (factor, scaled, warned) in [(1.0 - 1e-3, 19, 0), (1.0 + 1e-3, 20, 1)] {
        let target = widest * factor;
        let set = format!("analysis.mass_scaling={{target={target:e}}}");
        let (_, summary) = run("ms_contact_edge", &text, &[&set]);
        assert_eq!(
            summary.mass_scaling.as_ref().unwrap().elements_scaled,
            scaled
        );
        assert_eq!(
            warnings_with(&summary, "contact pair `end`"),
            warned,
            "{:?}",
            summary.warnings
        );
    }
}

/// A free plane-strain block 1 x 1 of 4 x 4 one-point J2 elements (yield 0.3, hardening 2),
/// no support: given an isochoric flow plus a drift it flows plastically, its elements
/// narrowing in x.
const FREE_BLOCK: &str = r#"
[[material]]
name = "m"
young = 200.0
poisson = 0.3
density = 1.0
yield_stress = 0.3
hardening_modulus = 2.0

[[body]]
name = "block"
material = "m"
formulation = "plane_strain"
mesh = { type = "rectangle", width = 1.0, height = 1.0, nx = 4, ny = 4 }

[analysis]
type = "dynamic"
integrator = "central_difference"
quadrature = "reduced"
end_time = 0.3

[output]
frame_every = 0

[[output.probe]]
quantity = "p_x"
set = "all"

[[output.probe]]
quantity = "p_y"
set = "all"
"#;

/// Goal: mass added during the run joins the nodes at rest: the momentum stays what it was
/// (a rule that kept the nodes' velocities would raise it by the added mass times the drift)
/// and the energy balance closes with the loss of that joining. Setup: FREE_BLOCK with the
/// initial velocity v = (V - r (x - 1/2), r (y - 1/2)), V = 0.5, r = 2, to t = 0.3 (33
/// steps), target 0.97 of the
/// square elements' step (`one_point_step`): nothing is scaled at the start; as the
/// elements narrow their steps fall below it. Reference: the momentum of the drift, rho A V
/// = 0.5 in x and 0 in y (the isochoric part has none about the block's centre), at every
/// row; the balance's own terms. Tolerances: the momentum is a sum of 25 products,
/// conserved step by step to round-off (1e-13 of 0.5; measured 3e-16); the drift is the
/// central-difference balance of a plastic flow (measured 2e-4; 5e-3), while the loss the
/// scaling took (measured 0.05, 10 % of the initial kinetic energy, with 22 % of the mass
/// added) is asserted above twice the drift: left out, the balance would be off by it.
#[test]
fn mass_added_during_the_run_keeps_momentum_and_closes_the_balance() {
    let (drift, rate) = (0.5, 2.0);
    let target = 0.97 * one_point_step(0.25, 0.25);
    let set = format!("analysis.mass_scaling={{target={target:e}}}");
    // without the bulk viscosity, as `run` (the target is 0.97 of the undamped step)
    let mut model = common::model(
        "ms_free_block",
        FREE_BLOCK,
        &[&set, "analysis.bulk_viscosity=off"],
    );
    model.initial_velocity = model
        .coordinates()
        .iter()
        .flat_map(|p| [drift - rate * (p[0] - 0.5), rate * (p[1] - 0.5)])
        .collect();
    let dir = common::out_dir("ms_free_block");
    let summary = analysis::run(&model, &dir, RunOptions::default()).unwrap();
    let added = column(&dir, "added_mass");
    assert_eq!(added[0], 0.0, "scaled at the start");
    let final_added = *added.last().unwrap();
    assert!(
        final_added > 1e-3,
        "added mass {final_added}: nothing scaled"
    );
    for (k, (px, py)) in column(&dir, "p_x[all]")
        .iter()
        .zip(column(&dir, "p_y[all]"))
        .enumerate()
    {
        assert!(
            (px - DENSITY * drift).abs() < 1e-13 * drift,
            "row {k}: p_x {px}"
        );
        assert!(py.abs() < 1e-13 * drift, "row {k}: p_y {py}");
    }
    let loss = summary
        .energy
        .mass_scaling_loss
        .expect("energy.mass_scaling_loss");
    let drift_measure = summary.energy.max_relative_drift;
    assert!(drift_measure < 5e-3, "drift {drift_measure}");
    assert!(
        loss > 2.0 * drift_measure * summary.energy.initial,
        "loss {loss}, drift {drift_measure}"
    );
}

/// The energy balance of each history.csv row of `dir`, |KE + W_int + W_p + W_c + W_visc +
/// L - KE_0 - W_ext| / max(KE_0, |W_ext|, |W_int|) (docs/theory.md 7), with the mass
/// scaling's loss L counted or left out (W_visc: the bulk viscosity's work, of a run with it).
fn balance_rows(dir: &std::path::Path, with_loss: bool) -> Vec<f64> {
    let kinetic = column(dir, "kinetic_energy");
    let internal = column(dir, "internal_energy");
    let plastic = column(dir, "plastic_work");
    let external = column(dir, "external_work");
    let contact = column(dir, "contact_work");
    let viscous = column(dir, "bulk_viscosity_work");
    let loss = column(dir, "mass_scaling_loss");
    (0..kinetic.len())
        .map(|k| {
            let scale = kinetic[0].max(external[k].abs()).max(internal[k].abs());
            let counted = if with_loss { loss[k] } else { 0.0 };
            (kinetic[k] + internal[k] + plastic[k] + contact[k] + viscous[k] + counted
                - kinetic[0]
                - external[k])
                .abs()
                / scale
        })
        .collect()
}

/// Goal: on the Johnson-Cook Taylor rod (2x2 kernel), whose foot elements crush during the
/// impact, the mass added as they do keeps the energy balance closed. Setup:
/// models/taylor_jc.toml (5 x 50, the bulk viscosity on by default) with target 4e-8 s (its
/// unscaled stable step falls from 4.4e-8 to 1.4e-8 s; 11 % of the rod's mass is added),
/// frames off. Reference: the balance itself, recomputed from history.csv's columns, the
/// viscous work among them. Tolerance: the scaled run's worst row within 1e-3 (measured
/// 2.2e-4), and the same rows without the loss column off by more than twice that somewhere
/// (the loss, 1.76 J of 333 J, puts them at 5.3e-3: the check can fail; without the viscous
/// work, 2.7 J, 8.0e-3).
#[test]
fn crushing_taylor_rod_keeps_the_energy_balance_with_mass_added() {
    let run = common::run_scene(
        "ms_taylor_jc",
        "taylor_jc",
        &[
            "output.frame_every=0",
            "analysis.mass_scaling={target=4e-8}",
        ],
    );
    let report = run.summary.mass_scaling.as_ref().unwrap();
    let added = column(&run.dir, "added_mass");
    assert_eq!(added[0], 0.0, "scaled at the start");
    assert!(report.elements_scaled > 0 && report.added_mass > 0.0);
    let worst = |rows: Vec<f64>| rows.into_iter().fold(0.0, f64::max);
    let (with, without) = (
        worst(balance_rows(&run.dir, true)),
        worst(balance_rows(&run.dir, false)),
    );
    assert!(with < 1e-3, "balance with the loss {with}");
    assert!(without > 2e-3, "balance without the loss {without}");
    // summary.json's drift also subtracts central difference's kinetic shadow (theory 7),
    // which history.csv does not hold: it is below the rows' (measured 1.9e-5 against 2.9e-4)
    let drift = run.summary.energy.max_relative_drift;
    assert!(drift <= with, "summary drift {drift} vs the rows' {with}");
}

/// Goal: bad mass scaling input is refused as bad input (exit code 2) with a message that
/// names the key. Setup: shipped scenes with `--set`. Reference: the scene rules of
/// docs/user-guide.md (central difference with dt = "auto" at finite strain on Quad4 bodies
/// only; target a time > 0; no unknown keys).
#[test]
fn bad_mass_scaling_is_refused_naming_the_key() {
    let cases = [
        (
            "models/taylor_jc.toml",
            "analysis.mass_scaling={target=0}",
            "analysis.mass_scaling.target: a stable step (a time) > 0, got 0",
        ),
        (
            "models/taylor_jc.toml",
            "analysis.mass_scaling={target=-1e-9}",
            "analysis.mass_scaling.target",
        ),
        (
            "models/taylor_jc.toml",
            "analysis.mass_scaling={target=nan}",
            "analysis.mass_scaling.target",
        ),
        (
            "models/taylor_jc.toml",
            "analysis.mass_scaling={target=inf}",
            "analysis.mass_scaling.target",
        ),
        (
            "models/taylor_jc.toml",
            "analysis.mass_scaling={target=1e-9,every=10}",
            "unknown field `every`",
        ),
        (
            "models/taylor_jc.toml",
            "analysis.mass_scaling={}",
            "missing field `target`",
        ),
        (
            "models/strip_wall.toml",
            "analysis.mass_scaling={target=0.01}",
            "with the fixed analysis.dt = 0.007",
        ),
        (
            "models/sphere_wall.toml",
            "analysis.mass_scaling={target=0.01}",
            "integrator average is implicit",
        ),
        (
            "models/hill_cylinder.toml",
            "analysis.mass_scaling={target=0.01}",
            "analysis.mass_scaling: does not apply to a static analysis",
        ),
    ];
    common::check_refuses(&cases);
}

/// Goal: the mass scaling is refused where the explicit Quad4 kernels do not run: rods and
/// small-strain geometry (the general element loop), each named. Setup: the rod bar of
/// models/bar_wall.toml turned to central difference, at small and at finite strain.
#[test]
fn mass_scaling_is_refused_off_the_explicit_quad4_kernels() {
    let explicit = [
        "analysis.integrator=central_difference",
        "analysis.mass=lumped",
        "analysis.dt=auto",
        "analysis.mass_scaling={target=1e-3}",
    ];
    let finite = [&explicit[..], &["analysis.geometry=nonlinear"]].concat();
    let bar = "models/bar_wall.toml";
    let key = "analysis.mass_scaling";
    common::check_refuses_with(bar, &explicit, &[key, "geometry = \"nonlinear\""]);
    common::check_refuses_with(bar, &finite, &[key, "body `bar` is a rod"]);
}

/// One rod of the Taylor study: its scene, the overrides that set the issue's mesh and the
/// one-point kernel, and the two targets (s; the unscaled run's stable step falls to 7e-10
/// s on the aluminium rod and to 3.5e-9 s on the steel one as their feet crush).
struct StudyRod {
    label: &'static str,
    scene: &'static str,
    overrides: &'static [&'static str],
    targets: [f64; 2],
}

/// What the study keeps of a run: the shortest wall time of its repetitions, and the rest
/// (the same every time).
#[derive(Debug, Clone, serde::Serialize)]
struct StudyRow {
    rod: &'static str,
    target: Option<f64>,
    steps: u64,
    wall_seconds: f64,
    /// The shape probes extent_y[all], extent_x[all] (m).
    length: f64,
    diameter: f64,
    added_mass_percent: f64,
    warnings: usize,
}

/// The Taylor study of docs/validation.md 10.6 (not run by default: about five minutes):
/// models/taylor_aluminum.toml at 20 x 120 and models/taylor_jc.toml at 20 x 200, one-point
/// kernel, frames off, without mass scaling and at two targets each; three repetitions,
/// interleaved, the shortest wall time (summary.json `wall_seconds`) kept. Writes the table
/// (DIR/mass_scaling_taylor.json) and the chart of the added mass and the changes of L_f
/// and D_f against the wall time saved (DIR/mass_scaling_taylor.svg, .png), DIR from
/// IMPACT_STUDY_OUT or output/mass_scaling_study.
/// `cargo test --release --test mass_scaling -- --ignored mass_scaling_taylor_study --nocapture`
/// Asserted: the steps fall with the target, and L_f and D_f stay within 0.5 % of the
/// unscaled run's.
#[test]
#[ignore]
fn mass_scaling_taylor_study() {
    use impact::output::plot::{self, Chart, Limits, Series, SeriesStyle};
    let rods = [
        StudyRod {
            label: "aluminium, 20 x 120",
            scene: "models/taylor_aluminum.toml",
            overrides: &["body.rod.mesh.nx=20", "body.rod.mesh.ny=120"],
            targets: [2e-9, 4e-9],
        },
        StudyRod {
            label: "42CrMo4 Johnson-Cook, 20 x 200",
            scene: "models/taylor_jc.toml",
            overrides: &[
                "body.rod.mesh.nx=20",
                "body.rod.mesh.ny=200",
                "analysis.quadrature=reduced",
            ],
            targets: [5e-9, 8e-9],
        },
    ];
    let out = std::env::var("IMPACT_STUDY_OUT")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|_| std::path::PathBuf::from("output/mass_scaling_study"));
    std::fs::create_dir_all(&out).unwrap();
    let cases: Vec<(&StudyRod, Option<f64>)> = rods
        .iter()
        .flat_map(|rod| [None, Some(rod.targets[0]), Some(rod.targets[1])].map(|t| (rod, t)))
        .collect();
    let mut rows: Vec<Option<StudyRow>> = vec![None; cases.len()];
    for repetition in 0..3 {
        for (k, (rod, target)) in cases.iter().enumerate() {
            let dir = out.join(format!("case_{k}"));
            let mut args = vec![
                "run".to_string(),
                rod.scene.to_string(),
                "--quiet".into(),
                "--out".into(),
                dir.display().to_string(),
                "--set".into(),
                "output.frame_every=0".into(),
            ];
            for set in rod.overrides {
                args.extend(["--set".into(), set.to_string()]);
            }
            if let Some(target) = target {
                args.extend([
                    "--set".into(),
                    format!("analysis.mass_scaling.target={target:e}"),
                ]);
            }
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let output = impact(&args);
            assert_eq!(output.status.code(), Some(0), "{args:?}");
            let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
            let s: serde_json::Value = serde_json::from_str(&text).unwrap();
            let row = StudyRow {
                rod: rod.label,
                target: *target,
                steps: s["steps"].as_u64().unwrap(),
                wall_seconds: s["wall_seconds"].as_f64().unwrap(),
                length: s["probes"]["extent_y[all]"].as_f64().unwrap(),
                diameter: s["probes"]["extent_x[all]"].as_f64().unwrap(),
                added_mass_percent: s["mass_scaling"]["added_mass_percent"]
                    .as_f64()
                    .unwrap_or(0.0),
                warnings: s["warnings"].as_array().unwrap().len(),
            };
            println!("repetition {repetition}: {row:?}");
            rows[k] = Some(match rows[k].take() {
                Some(kept) if kept.wall_seconds <= row.wall_seconds => kept,
                _ => row,
            });
        }
    }
    let rows: Vec<StudyRow> = rows.into_iter().map(Option::unwrap).collect();
    let json = serde_json::to_string_pretty(&rows).unwrap();
    std::fs::write(out.join("mass_scaling_taylor.json"), json).unwrap();
    println!(
        "| rod | target (s) | steps | wall (s) | saved | L_f (mm) | change | D_f (mm) | change | added mass |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut panels: [Vec<Series>; 3] = Default::default();
    for chunk in rows.chunks(3) {
        let plain = &chunk[0];
        let mut points: [Vec<(f64, f64)>; 3] = Default::default();
        for row in chunk {
            let saved = 100.0 * (1.0 - row.wall_seconds / plain.wall_seconds);
            let length = 100.0 * (row.length / plain.length - 1.0);
            let diameter = 100.0 * (row.diameter / plain.diameter - 1.0);
            println!(
                "| {} | {} | {} | {:.2} | {:.0} % | {:.3} | {:+.2} % | {:.3} | {:+.2} % | {:.2} % |",
                row.rod,
                row.target.map_or("off".to_string(), |t| format!("{t:e}")),
                row.steps,
                row.wall_seconds,
                saved,
                1e3 * row.length,
                length,
                1e3 * row.diameter,
                diameter,
                row.added_mass_percent
            );
            for (p, y) in points
                .iter_mut()
                .zip([row.added_mass_percent, length, diameter])
            {
                p.push((saved, y));
            }
        }
        for (panel, p) in panels.iter_mut().zip(points) {
            panel.push(Series {
                label: chunk[0].rod.to_string(),
                points: p,
                style: SeriesStyle::LineAndMarkers,
            });
        }
        // the unscaled run took longest: scaling saved time
        assert!(chunk[1].steps < plain.steps && chunk[2].steps < chunk[1].steps);
        // and cost little: the mass goes to the crushed foot, which the wall has nearly
        // stopped, so L_f and D_f stay within 0.5 % of the unscaled run's (measured at most
        // 0.13 %, docs/validation.md 10.6; the 2x2 and one-point kernels differ by more)
        for row in &chunk[1..] {
            let change = |a: f64, b: f64| (a / b - 1.0).abs();
            assert!(
                change(row.length, plain.length) < 5e-3
                    && change(row.diameter, plain.diameter) < 5e-3,
                "{row:?} against {plain:?}"
            );
        }
    }
    let y_labels = [
        "added mass (% of the rod's)",
        "change of L_f (%)",
        "change of D_f (%)",
    ];
    let titles = [
        "Taylor rods, one-point: added mass (unscaled, then two targets)",
        "final length L_f against the unscaled run",
        "impact-face diameter D_f against the unscaled run",
    ];
    let charts: Vec<Chart> = panels
        .into_iter()
        .zip(y_labels.iter().zip(titles))
        .map(|(series, (y_label, title))| Chart {
            title: title.to_string(),
            x_label: "wall time saved (% of the unscaled run's)".into(),
            y_label: y_label.to_string(),
            series,
            log_x: false,
            log_y: false,
            x_limits: Limits::default(),
            y_limits: Limits::default(),
            notes: Vec::new(),
        })
        .collect();
    for ext in ["svg", "png"] {
        plot::write_panels(&charts, &out.join(format!("mass_scaling_taylor.{ext}"))).unwrap();
    }
}
