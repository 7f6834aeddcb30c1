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

/// The final length and impact-face radius of a run of the scene with a mesh of `nx` x
/// `6 nx` quads and `quadrature`: the extent of the rod's current shape (top minus lowest
/// point, the largest radius). The rod leaves the contact wall before the end (at 34-36 us,
/// its face 0.2 to 1.2 mm above the wall at 45 us), so the top's height is not its length.
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
    let (summary, state) =
        impact::analysis::run_to_state(&model, &dir, Default::default()).unwrap();
    let current: Vec<[f64; 2]> = model
        .coordinates()
        .iter()
        .enumerate()
        .map(|(n, p)| {
            [
                p[0] + state.displacement[2 * n],
                p[1] + state.displacement[2 * n + 1],
            ]
        })
        .collect();
    let (low, high) = current
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p[1]), h.max(p[1]))
        });
    let length = high - low;
    let radius = current.iter().map(|p| p[0]).fold(0.0, f64::max);
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
/// docs/validation.md: too slow for the suite). References and the reasoning of each band:
/// - convergence: the final length changes by less than 1 % between the two meshes (the
///   criterion of the mesh study; measured 0.10 %);
/// - VMC8's finite-element results, 14.07 to 14.22 mm: bilinear models of the same shot
///   that differ from each other by 0.15 mm (1.1 %), their choice of element, contact and
///   step. Ours is one more such model, so it may lie that far beyond either end: the band
///   is [14.07 - 0.15, 14.22 + 0.15] mm. Measured 14.262 (5 x 30), 14.248 (10 x 60),
///   14.224 mm (2x2), the length being the extent of the final shape (the rod has left the
///   wall). The experiment (13.19 mm) is no band for a model without rate hardening
///   (VMC8's own results are 6.7 % to 7.8 % long); the band's lower end lies above it, so
///   "longer than the experiment" is not asserted separately;
/// - the two kernels on the same mesh are two discretizations of the same model: their final
///   lengths agree within VMC8's spread, 0.15 / 14.07 = 1.07 % (measured 0.27 %);
/// - the impact-face radius: neither docs/validation.md nor src/reference has a published
///   radius for this shot (Wilkins & Guinan and VMC8 are quoted for the length only), so it
///   is checked for convergence, not against a reference: the two kernels' radii differ by
///   their discretization errors on 5 x 30, which must lie within the first-order estimate
///   of the one-point kernel's error there, twice its change under one halving, 2 |R(10 x
///   60) - R(5 x 30)| (first order, the conservative choice for a radius set by the foot's
///   edge; measured: kernels 0.280 mm apart, the estimate 0.460 mm).
#[test]
fn taylor_aluminum_converges_and_lands_with_the_bilinear_models() {
    let (coarse, coarse_r, _) = taylor(5, "reduced");
    let (fine, fine_r, _) = taylor(10, "reduced");
    let (full, full_r, _) = taylor(5, "full");
    assert!((fine / coarse - 1.0).abs() < 0.01, "{coarse} -> {fine}");
    let spread = MANUAL[1] - MANUAL[0];
    assert!(
        (full / coarse - 1.0).abs() < spread / MANUAL[0],
        "{full} vs {coarse}"
    );
    let (low, high) = (MANUAL[0] - spread, MANUAL[1] + spread);
    for length in [coarse, fine, full] {
        assert!(
            length > low && length < high,
            "{length} not in [{low}, {high}]"
        );
    }
    let estimate = 2.0 * (fine_r - coarse_r).abs();
    assert!(
        (full_r - coarse_r).abs() < estimate,
        "kernels {full_r} vs {coarse_r}, error estimate {estimate}"
    );
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
            "{quadrature}: changes {:.2} %, {:.2} %; finest {:+.1} % from the experiment",
            100.0 * (lengths[1] / lengths[0] - 1.0),
            100.0 * (lengths[2] / lengths[1] - 1.0),
            100.0 * (lengths[2] / EXPERIMENT - 1.0)
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

/// The names of [L_f, D_f, T, eps_p] in messages.
const NAMES: [&str; 4] = ["L_f", "D_f", "T", "eps_p"];

/// The band the published values give a third code on the authors' mesh, per quantity: the
/// interval between DynELA and Abaqus widened on each side by their difference (two codes
/// of the same model on the same mesh differ by that much, so a third may lie that far
/// beyond either) and by half a unit of the last printed digit (0.005 for each quantity);
/// for the shape, L_f and D_f, at least 0.5 % of Abaqus either side (the accuracy a Taylor
/// run is held to against Abaqus; the two codes' spread in D_f, 0.01 mm, is below what the
/// bulk viscosity alone moves it, 0.04 mm, and Abaqus ran with it, DynELA we cannot say).
/// L_f [26.427, 26.693] mm, D_f [11.104, 11.216] mm, T [573.7, 599.6] C, eps_p [1.745,
/// 1.845].
fn reference_band(k: usize) -> (f64, f64) {
    let (low, high) = (DYNELA[k].min(ABAQUS[k]), DYNELA[k].max(ABAQUS[k]));
    let widen = (high - low) + 0.005;
    let (low, high) = (low - widen, high + widen);
    match k {
        0 | 1 => (low.min(0.995 * ABAQUS[k]), high.max(1.005 * ABAQUS[k])),
        _ => (low, high),
    }
}

/// Asserts `finals[k]` inside the reference band of each k of `which`, widened by
/// `error[k]` either side.
fn assert_in_bands(run: &str, finals: &[f64; 4], which: &[usize], error: &[f64; 4]) {
    for &k in which {
        let (low, high) = reference_band(k);
        let (low, high) = (low - error[k], high + error[k]);
        assert!(
            finals[k] >= low && finals[k] <= high,
            "{run}: {} = {} outside [{low}, {high}]",
            NAMES[k],
            finals[k]
        );
    }
}

/// Goal: the explicit Johnson-Cook Taylor impact lands on the published results.
/// Setup: models/taylor_jc.toml as it ships (5 x 50, 2x2 B-bar like DynELA's ElQua4NAx,
/// the defaults: the global stable step, the bulk viscosity), then the one-point kernel
/// (kappa 0.1) on the same mesh and on the mesh twice as fine (10 x 100).
/// Reference: DynELA and Abaqus/Explicit on the 5 x 50 mesh, in the bands of
/// `reference_band` (the references' own spread, not the measured values; L_f and D_f at
/// least 0.5 % of Abaqus). The 2x2 run on their mesh must lie in them (measured 26.553 mm,
/// 11.192 mm, 598.5 C, 1.839: -0.03 %, +0.28 %, +1.3 %, +1.6 % from Abaqus; without the
/// viscosity and at the bound's step 26.530 mm, 11.148 mm, 589.8 C, 1.807). D_f, T and eps_p are asserted on the published
/// mesh only: under one halving they move by more than their bands (docs/validation.md 10.2:
/// +0.65 %, +3.0 %, +3.7 %; the last two are values of an element that shrinks into the
/// corner of axis and wall, not converged quantities); L_f moves by 0.06 %, inside its band.
/// The one-point kernel's L_f lies in the same band (its change under halving, 0.13 %, is
/// inside it; measured 26.560 mm). Its foot is under-resolved with one point per element
/// five elements across: D_f, T and eps_p are not in the bands on this mesh (measured
/// 10.593 mm, 516.2 C, 1.541). Its known error there is its discretization error, estimated
/// to first order (strains and what follows from them converge as h) by twice its change
/// under one halving, 2 |x(10 x 100) - x(5 x 50)|: the 5 x 50 values must lie in the bands
/// widened by that estimate (measured estimates 0.82 mm, 133 C, 0.48), and the 10 x 100
/// values nearer the references than the 5 x 50 ones (measured 11.003 mm, 582.5 C, 1.780).
#[test]
fn taylor_jc_explicit_matches_abaqus() {
    let (full, summary) = taylor_jc("taylor_jc_full", &[]);
    assert_eq!(summary.status, impact::analysis::Status::Ok);
    assert_in_bands("2x2 5 x 50", &full, &[0, 1, 2, 3], &[0.0; 4]);
    println!("2x2 against Abaqus: {:?}", deviations(&full, &ABAQUS));
    let (reduced, _) = taylor_jc("taylor_jc_reduced", &["analysis.quadrature=reduced"]);
    assert_in_bands("one-point 5 x 50", &reduced, &[0], &[0.0; 4]);
    let (finer, _) = taylor_jc(
        "taylor_jc_reduced_10",
        &[
            "analysis.quadrature=reduced",
            "body.rod.mesh.nx=10",
            "body.rod.mesh.ny=100",
        ],
    );
    let estimate: [f64; 4] = std::array::from_fn(|k| 2.0 * (finer[k] - reduced[k]).abs());
    println!("one-point first-order error estimates: {estimate:?}");
    assert_in_bands("one-point 5 x 50", &reduced, &[1, 2, 3], &estimate);
    for k in 1..4 {
        let middle = 0.5 * (DYNELA[k] + ABAQUS[k]);
        assert!(
            (finer[k] - middle).abs() < (reduced[k] - middle).abs(),
            "{}: {} -> {}",
            NAMES[k],
            reduced[k],
            finer[k]
        );
    }
}

/// Goal: the tight stable step (`analysis.stable_step = "tight"`: each element's exact
/// highest frequency instead of its bound) lands the Johnson-Cook rod on the published results
/// as the bound's step does. Setup: models/taylor_jc.toml (2x2 B-bar, 5 x 50) with the tight
/// step, without the bulk viscosity (the default run, with it, is the test above).
/// Reference: DynELA and Abaqus/Explicit in the bands of `reference_band`, every
/// quantity (measured 26.526 mm, 11.148 mm: -0.13 %, -0.11 % from Abaqus, in 4 233 steps
/// against the bound's 5 449).
#[test]
fn taylor_jc_tight_step_matches_abaqus() {
    let (tight, summary) = taylor_jc(
        "taylor_jc_tight",
        &["analysis.stable_step=tight", "analysis.bulk_viscosity=off"],
    );
    assert_eq!(summary.status, impact::analysis::Status::Ok);
    assert_in_bands("2x2 5 x 50 tight", &tight, &[0, 1, 2, 3], &[0.0; 4]);
}

/// Goal: the global stable step (`analysis.stable_step = "global"`: the mesh's highest
/// frequency estimated over the tight elements) lands the Johnson-Cook rod on the published
/// results as the bound's and the tight step do, on both kernels, with the energy balanced.
/// Setup: models/taylor_jc.toml (5 x 50) with the global step, 2x2 B-bar and one-point,
/// without the bulk viscosity (the default run, with it, is `taylor_jc_explicit_matches_abaqus`).
/// Reference: DynELA and Abaqus/Explicit in the bands of `reference_band` (measured 26.525 mm,
/// 11.146 mm in 3 442 steps on 2x2 against the bound's 5 449 and the tight step's 4 233);
/// the energy balance (theory 7) within 1e-3 of the energy in play (measured 5.8e-5 2x2,
/// 2.5e-4 one-point, against 1.1e-4 and 8e-5 with the tight step).
#[test]
fn taylor_jc_global_step_matches_abaqus() {
    let (global, summary) = taylor_jc(
        "taylor_jc_global",
        &["analysis.stable_step=global", "analysis.bulk_viscosity=off"],
    );
    assert_eq!(summary.status, impact::analysis::Status::Ok);
    assert_in_bands("2x2 5 x 50 global", &global, &[0, 1, 2, 3], &[0.0; 4]);
    assert!(
        summary.energy.max_relative_drift < 1e-3,
        "{}",
        summary.energy.max_relative_drift
    );
    let (reduced, summary) = taylor_jc(
        "taylor_jc_global_reduced",
        &[
            "analysis.stable_step=global",
            "analysis.quadrature=reduced",
            "analysis.bulk_viscosity=off",
        ],
    );
    assert_eq!(summary.status, impact::analysis::Status::Ok);
    // L_f only: D_f of the one-point kernel is under-resolved on this mesh (the test above)
    assert_in_bands("one-point 5 x 50 global", &reduced, &[0], &[0.0; 4]);
    assert!(
        summary.energy.max_relative_drift < 1e-3,
        "{}",
        summary.energy.max_relative_drift
    );
}

/// Goal: implicit Newmark (average acceleration, modified Newton, B-bar 2x2) survives the
/// crushed foot and lands where the explicit run does.
/// Setup: models/taylor_jc.toml with `integrator = "average"`, dt = 1e-7 s (800 steps; about
/// 2.5 times the explicit stable step at the start, 10 times the smallest one at the end).
/// Reference: the explicit run of the same mesh within 1 % on L_f and D_f (the accuracy
/// docs/validation.md 10.3 asks of an implicit step against the explicit one; measured
/// -0.23 %, +0.36 %); with the explicit run inside the reference bands (the test above),
/// this bounds L_f and D_f against the references too, and they are not asserted again.
/// T and eps_p of the axis element in the reference bands of the explicit test, on the same
/// mesh (measured 594.2 C, 1.821). No step is cut at this dt.
#[test]
fn taylor_jc_implicit_average_lands_with_the_explicit_run() {
    let (implicit, summary) = taylor_jc(
        "taylor_jc_average",
        &["analysis.integrator=average", "analysis.dt=1e-7"],
    );
    assert_eq!(summary.status, impact::analysis::Status::Ok);
    assert_eq!(summary.step_cuts, 0);
    assert_in_bands("implicit 5 x 50", &implicit, &[2, 3], &[0.0; 4]);
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

/// Goal: the Taylor rod runs on a wall with Coulomb friction on both paths, with the axis
/// node held in x against the wall whose tangent is x (its stick row is the support's: the
/// implicit run used to stop at its first step, and central difference refused friction),
/// and friction narrows the foot. Setup: the Johnson-Cook rod on a contact wall (above),
/// 5 x 50, 2x2 B-bar, mu = 0 (no friction), 0.1 and 0.3; central difference with the
/// automatic step, and Newmark average at dt = 1e-7 s. Reference: Coulomb's law and the
/// two integrators against each other, no stored numbers. Wall friction holds the face
/// back against its radial flow, so the impact-face diameter D_f falls strictly as mu rises
/// on each path (measured explicit 11.249, 10.281, 8.303 mm; implicit 11.315, 10.329,
/// 8.227 mm); the two paths enforce contact differently (forward-increment multipliers on
/// the lumped mass, the Schur complement on K*) and must agree on D_f within the 1 % of the
/// implicit-against-explicit tests above, widened to 1.5 % for the sliding face (measured
/// 0.59, 0.47 and 0.92 %); the summed friction force never exceeds mu times the summed
/// normal force; every run completes with its energy balance within 0.2 % (theory 7: the
/// friction's dissipation and the arrest of the face nodes are in the contact work;
/// measured 0.002 to 0.003 % explicit, 0.057 to 0.072 % implicit).
#[test]
fn taylor_jc_wall_friction_narrows_the_foot_on_both_paths() {
    let mut diameters = Vec::new();
    for (path, overrides) in [
        ("explicit", vec![]),
        (
            "average",
            vec!["analysis.integrator=average", "analysis.dt=1e-7"],
        ),
    ] {
        let mut path_diameters = Vec::new();
        for mu in [0.0, 0.1, 0.3] {
            let name = format!("taylor_jc_friction_{path}_{mu}");
            let friction = format!("contact.wall.friction={mu}");
            let mut all = overrides.clone();
            if mu > 0.0 {
                all.push(&friction);
            }
            let (finals, summary) = taylor_jc_on_contact_wall(&name, &all);
            println!(
                "{name}: L_f {:.3} mm, D_f {:.3} mm, drift {:.3} %, {} steps, {} cuts, {:.2} s",
                finals[0],
                finals[1],
                100.0 * summary.energy.max_relative_drift,
                summary.steps,
                summary.step_cuts,
                summary.wall_seconds
            );
            assert_eq!(
                summary.status,
                impact::analysis::Status::Ok,
                "{name}: {:?}",
                summary.message
            );
            // the balance loses the kinetic energy of the face nodes the contact arrests at
            // first touch (1 / 100 of the mass: 1.1 % on the explicit path, theory 8.3); friction
            // work is counted in contact_work, so friction must not add to the loss
            assert!(
                summary.energy.max_relative_drift < 0.002,
                "{name}: {}",
                summary.energy.max_relative_drift
            );
            if mu > 0.0 {
                let dir = common::out_dir_of(&name);
                let normal = column(&dir, "contact_force[wall]");
                let tangential = column(&dir, "tangential_force[wall]");
                for (f, n) in tangential.iter().zip(&normal) {
                    assert!(
                        f.abs() <= mu * n * (1.0 + 1e-9) + 1e-9,
                        "{name}: {f} > mu {n}"
                    );
                }
            }
            path_diameters.push(finals[1]);
        }
        assert!(
            path_diameters.windows(2).all(|w| w[1] < w[0]),
            "{path}: D_f {path_diameters:?}"
        );
        diameters.push(path_diameters);
    }
    for (explicit, implicit) in diameters[0].iter().zip(&diameters[1]) {
        assert!(
            (implicit / explicit - 1.0).abs() < 0.015,
            "D_f {implicit} implicit against {explicit} explicit"
        );
    }
}
