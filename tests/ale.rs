//! ALE steps on the explicit path (docs/theory.md 8.11, docs/validation.md 11): the Taylor rods
//! against the published results and the Lagrangian runs, the copper rod past the Lagrangian
//! mesh's limit on both kernels, the energy balance with the remap's term, and the scene's
//! refusals. The remap itself (exact on linear fields, conservative, second order, no new
//! extrema) is tested on plain arrays in src/ale/tests.rs.

mod common;

use common::{check_refuses, column, run_scene};
use impact::analysis::Status;

/// The ratio of the longest step to the shortest of a run (the rule's steps, not those
/// shortened to land on an end or a frame).
fn step_fall(summary: &impact::analysis::Summary) -> f64 {
    summary.dt_max.unwrap() / summary.dt_min.unwrap()
}

/// The Johnson-Cook rod's L_f and D_f of the run in `dir` in the bands of the test below.
fn assert_in_the_published_band(dir: &std::path::Path) {
    let last = |c: &str| *column(dir, c).last().unwrap();
    let length = (32.4e-3 + last("u_y[top_axis]")) * 1e3;
    let diameter = 2.0 * (3.2e-3 + last("u_x[face_edge]")) * 1e3;
    assert!((26.475..=26.605).contains(&length), "L_f {length}");
    let widen = 0.0065 * 11.16;
    assert!(
        (11.135 - widen..=11.175 + widen).contains(&diameter),
        "D_f {diameter}"
    );
}

/// Goal: ALE steps keep the Johnson-Cook rod on the published results and stop its step from
/// falling. Setup: models/taylor_jc.toml (2x2 B-bar, 5 x 50) with `analysis.ale = {}`.
/// Reference: DynELA 26.52 mm and Abaqus/Explicit 26.56 mm for L_f, widened by their spread
/// (the two codes' spread band, [26.475, 26.605] mm); D_f in its band [11.135, 11.175] mm
/// widened by the Lagrangian runs' own change under one halving of the mesh, +0.65 %
/// (docs/validation.md 10.2: the face's diameter on 5 x 50 is not converged, and the remap
/// moves it toward the finer meshes' value; measured 26.521 mm, 11.190 mm). The energy
/// balance with the remap's term below 6e-5 (measured 1.8e-5; with the remap's kinetic
/// energy loss left out of the balance, 1.6e-4: the bound tells the two apart, far inside
/// the 1 %); the step falls at most 2 times over the run (measured 1.35; the
/// Lagrangian run's falls 3.1 times on this rod, 31 times on the aluminium rod's foot, so
/// the bound fails with ALE off, which the published band alone would not: the Lagrangian
/// L_f and D_f lie in it too). All of it at the bound's step without the bulk viscosity,
/// where those figures were measured: the remap's error grows with the motion between two
/// remaps, so with the defaults (the global step, 1.4 times longer, and the viscosity) the
/// balance is 1.1e-4 (1.0e-4 at the tight step) and no longer tells the remap's term apart;
/// the default run is asserted in the bands, its step fall and its balance within 1e-3.
#[test]
fn taylor_jc_with_ale_lands_on_the_published_results() {
    let defaults = run_scene(
        "ale_taylor_jc_defaults",
        "taylor_jc",
        &["analysis.ale={}", "output.frame_every=0"],
    );
    assert_eq!(defaults.summary.status, Status::Ok);
    assert_in_the_published_band(&defaults.dir);
    assert!(defaults.summary.energy.max_relative_drift < 1e-3);
    // the viscosity's damping grows in the foot's fast compression (measured 2.01; the
    // Lagrangian run's 4.07 at the same defaults)
    assert!(step_fall(&defaults.summary) <= 2.5);
    let run = run_scene(
        "ale_taylor_jc",
        "taylor_jc",
        &[
            "analysis.ale={}",
            "output.frame_every=0",
            "analysis.stable_step=bound",
            "analysis.bulk_viscosity=off",
        ],
    );
    assert_eq!(run.summary.status, Status::Ok);
    assert_in_the_published_band(&run.dir);
    let drift = run.summary.energy.max_relative_drift;
    assert!(drift < 6e-5, "energy balance {drift}");
    assert!(
        step_fall(&run.summary) <= 2.0,
        "step fell {}",
        step_fall(&run.summary)
    );
    let ale = run.summary.ale.as_ref().expect("summary.json has `ale`");
    assert!(ale.remaps > 0 && ale.largest_courant < 1.0, "{ale:?}");
}

/// Goal: past the Lagrangian mesh's limit (the 2x2 kernel stops at 23.6 us on a non-positive
/// Jacobian without ALE), the copper rod at 400 m/s completes on both kernels with ALE steps.
/// Setup: models/taylor_copper_ale.toml (5 x 50) on the 2x2 and the one-point kernel; the
/// one-point kernel also on 10 x 100. Reference: the energy balance with the remap's term
/// below 1e-3 at the bound's step without the bulk viscosity (measured 1.1e-4, 9.3e-5; with
/// the remap's kinetic energy loss left out of the balance 6.0e-3 and 5.4e-3, which the
/// issue's 1 % let pass; with the defaults, the longer global step and the viscosity, 1.2e-3
/// on one-point: the remap's error grows with the motion between two remaps, and the 10 x
/// 100 run, at the defaults, is held to the 1 %); the hourglass energy of the one-point
/// kernel below the 2 % of the work on 10 x 100 (measured 0.3 %; 2.7 % on 5 x 50,
/// where five elements span a foot four times the rod's radius); the two kernels' L_f within
/// 1 % of each other, the 5 x 50 level's spread in the mesh study of docs/validation.md 11
/// (measured 10.228 and 10.154 mm).
#[test]
fn a_copper_rod_at_400_m_s_completes_on_both_kernels_with_ale() {
    let mut lengths = Vec::new();
    for (name, sets) in [
        (
            "ale_copper_full",
            vec![
                "output.frame_every=0",
                "analysis.stable_step=bound",
                "analysis.bulk_viscosity=off",
            ],
        ),
        (
            "ale_copper_reduced",
            vec![
                "output.frame_every=0",
                "analysis.quadrature=\"reduced\"",
                "analysis.stable_step=bound",
                "analysis.bulk_viscosity=off",
            ],
        ),
    ] {
        let run = run_scene(name, "taylor_copper_ale", &sets);
        assert_eq!(
            run.summary.status,
            Status::Ok,
            "{name}: {:?}",
            run.summary.message
        );
        let drift = run.summary.energy.max_relative_drift;
        assert!(drift < 1e-3, "{name}: energy balance {drift}");
        lengths.push(*column(&run.dir, "extent_y[all]").last().unwrap());
    }
    assert!(
        (lengths[0] / lengths[1] - 1.0).abs() < 0.01,
        "L_f {lengths:?}"
    );
    let fine = run_scene(
        "ale_copper_reduced_10",
        "taylor_copper_ale",
        &[
            "output.frame_every=0",
            "analysis.quadrature=\"reduced\"",
            "body.rod.mesh.nx=10",
            "body.rod.mesh.ny=100",
        ],
    );
    assert_eq!(fine.summary.status, Status::Ok);
    assert!(fine.summary.energy.max_relative_drift < 1e-2);
    let last = |c: &str| *column(&fine.dir, c).last().unwrap();
    let work = last("internal_energy") + last("plastic_work");
    assert!(
        last("hourglass_energy") < 0.02 * work,
        "hourglass {}",
        last("hourglass_energy")
    );
}

/// Goal: `analysis.ale` is refused where it does not apply, naming the key. Setup: the
/// copper rod's scene with an implicit integrator, small strain, the subcycling, the mass
/// scaling, and out-of-range keys; a rod body. Reference: exit code 2 (input) and
/// the key in the message.
#[test]
fn ale_is_refused_where_it_does_not_apply() {
    let scene = "models/taylor_copper_ale.toml";
    common::check_refuses_with(
        scene,
        &["analysis.integrator=\"average\"", "analysis.dt=1e-7"],
        &["analysis.ale", "implicit"],
    );
    check_refuses(&[
        (scene, "analysis.geometry=\"linear\"", "analysis.ale"),
        (scene, "analysis.subcycling={}", "analysis.subcycling"),
        (
            scene,
            "analysis.mass_scaling={target=1e-9}",
            "analysis.mass_scaling",
        ),
        (scene, "analysis.ale.every=0", "analysis.ale.every"),
        // the message says what the number is, as the user guide defines it
        (
            scene,
            "analysis.ale.max_move=0.9",
            "analysis.ale.max_move: the share of an element's area",
        ),
        (
            scene,
            "analysis.ale.slide_angle=60",
            "analysis.ale.slide_angle",
        ),
        (scene, "analysis.ale.smoother=\"spring\"", "smoother"),
        (scene, "analysis.ale.often=3", "often"),
        ("models/two_bars.toml", "analysis.ale={}", "analysis.ale"),
    ]);
}
