//! Set-up mistakes a new user makes, each as a scene: tests/data/sphere_wall_si.toml (an
//! elastic-plastic steel sphere, R = 5 mm, striking a rigid wall at 5 m/s, SI units) with one
//! key spoiled. Each is refused or warned with its likely cause in the message, and
//! `--strict` exits 3 (docs/user-guide.md 3.2a). The scene as it stands warns of nothing, and
//! neither do the shipped scenes under `impact check` (tests/scenes.rs asserts their runs).

mod common;

use impact::analysis::Summary;
use impact::analysis::plausibility;
use impact::analysis::steppers::energies::Energies;
use std::path::Path;

const SPHERE: &str = "tests/data/sphere_wall_si.toml";

/// `impact ARGS` on the sphere scene with `--set` edits; returns the exit code and stderr.
fn impact_on_sphere(command: &str, out: Option<&Path>, edits: &[&str]) -> (i32, String) {
    let mut args: Vec<String> = vec![command.into(), SPHERE.into(), "--strict".into()];
    if let Some(out) = out {
        args.extend(["--out".into(), out.display().to_string(), "--quiet".into()]);
    }
    for edit in edits {
        args.extend(["--set".into(), edit.to_string()]);
    }
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    let output = common::impact(&refs);
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// Asserts that `stderr` holds a warning line with every one of `words`.
fn warned(stderr: &str, words: &[&str]) {
    let found = stderr
        .lines()
        .filter(|l| l.starts_with("warning: "))
        .any(|l| words.iter().all(|w| l.contains(w)));
    assert!(found, "no warning with {words:?} in:\n{stderr}");
}

/// summary.json of a run folder.
fn summary_json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// Goal: no shipped scene and not the sphere as it stands gives a set-up warning: the new
/// checks (slave sets, units) are no false alarms on scenes meant to be right. Setup: every
/// models/*.toml and tests/data/sphere_wall_si.toml. Reference: none expected (tests/scenes.rs
/// holds their runs' warnings to three_rings' energy balance alone).
#[test]
fn shipped_scenes_and_the_sphere_give_no_setup_warning() {
    let mut paths: Vec<_> = std::fs::read_dir("models")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.push(SPHERE.into());
    for path in paths {
        let model = impact::scene::load(&path, &[]).unwrap();
        let warnings = impact::analysis::plausibility::setup_warnings(&model);
        assert!(warnings.is_empty(), "{}: {warnings:?}", path.display());
    }
}

/// Goal: the sphere as it stands runs silent, and the mass-weighted probe is the centre of
/// mass's velocity. Setup: the scene, central difference to 40 us (the contact ends at about
/// 24 us). Reference: momentum conservation's definition of the centre of mass, v_cm =
/// p_y / m with p_y = sum m v (the `p_y` probe) and m the body's mass of summary.json
/// `bodies`; to 1e-12 (two sums of the same products in one order or another: round-off).
/// The plain nodal mean `v_y[all]` is a different number on this graded mesh (its small
/// elements at the pole count as much as the large ones): at least 1 % off.
#[test]
fn the_sphere_runs_silent_and_its_mass_mean_velocity_is_p_over_m() {
    let dir = common::out_dir("sphere_right");
    let (code, stderr) = impact_on_sphere("run", Some(&dir), &[]);
    assert_eq!(code, 0, "{stderr}");
    let json = summary_json(&dir);
    assert_eq!(json["warnings"].as_array().unwrap().len(), 0);
    let mass = json["bodies"][0]["mass"].as_f64().unwrap();
    let last = |column: &str| *common::column(&dir, column).last().unwrap();
    let (v_cm, p_y) = (last("mass_mean_v_y[all]"), last("p_y[all]"));
    assert!(v_cm > 0.0, "the sphere rebounds: {v_cm}");
    assert!(
        (v_cm - p_y / mass).abs() <= 1e-12 * v_cm.abs(),
        "v_cm {v_cm} against p_y / m {}",
        p_y / mass
    );
    let plain = last("v_y[all]");
    assert!((plain / v_cm - 1.0).abs() > 0.01, "{plain} vs {v_cm}");
    println!(
        "v_cm = {v_cm:.10}, p_y / m = {:.10}, plain mean {plain:.6}",
        p_y / mass
    );
}

/// Goal: a run that ends during the impact says so. Setup: end_time = 10 us, while the sphere
/// is still pressed into the wall (the contact lasts about 24 us). Reference: the user
/// guide's rule: a pair closed at the end while its slave body still approaches the master
/// at more than 10 % of its approach speed at the start; `--strict` exits 3.
#[test]
fn an_end_time_inside_the_impact_is_warned() {
    let dir = common::out_dir("sphere_short");
    let (code, stderr) = impact_on_sphere("run", Some(&dir), &["analysis.end_time=10e-6"]);
    assert_eq!(code, 3, "{stderr}");
    warned(
        &stderr,
        &[
            "contact `wall` is still closed",
            "lengthen analysis.end_time",
        ],
    );
}

/// Goal: a slave set that misses the surface meeting the wall is caught before the run,
/// and the run reports the true penetration, its node and its cause. Setup: slave =
/// `axis` (the sphere's axis nodes: of its surface facing the wall only the pole) instead
/// of `arc`; the run writes its last frame. Reference: `check --strict` exits 3 naming
/// `arc`; the run's last `penetration` within 5 % of the largest depth of the last frame's
/// nodes behind the wall y = 0 (reference_coordinates + displacement: the frame's own
/// arrays, not the contact code); the warning names a node no pair holds.
#[test]
fn a_slave_set_that_misses_the_surface_is_caught_and_measured() {
    let edit = "contact.wall.slave.set=axis";
    let (code, stderr) = impact_on_sphere("check", None, &[edit]);
    assert_eq!(code, 3, "{stderr}");
    warned(
        &stderr,
        &["the slave set `axis` holds 1 of", "`arc` holds them all"],
    );
    let dir = common::out_dir("sphere_axis");
    let (code, stderr) = impact_on_sphere("run", Some(&dir), &[edit, "output.frame_every=100000"]);
    assert_eq!(code, 3, "{stderr}");
    warned(&stderr, &["no contact pair names it as a slave", "`arc`"]);
    let frames = impact::output::vtk::read_pvd(&dir.join("sphere_wall_si.pvd")).unwrap();
    let (_, last) = frames.last().unwrap();
    let frame = impact::output::vtu::read_frame(last).unwrap();
    use impact::output::vtu::Section::PointData;
    let (_, reference) = frame.floats(PointData, "reference_coordinates").unwrap();
    let (_, displacement) = frame.floats(PointData, "displacement").unwrap();
    let deepest = (0..frame.points)
        .map(|n| -(reference[3 * n + 1] + displacement[3 * n + 1]))
        .fold(0.0, f64::max);
    let reported = *common::column(&dir, "penetration").last().unwrap();
    assert!(
        deepest > 1e-5,
        "the sphere went through the wall: {deepest}"
    );
    assert!(
        (reported / deepest - 1.0).abs() < 0.05,
        "reported {reported}, the frame's deepest node {deepest}"
    );
    println!("penetration: reported {reported:.6e} m, last frame {deepest:.6e} m");
}

/// Goal: a mesh too coarse for the contact is warned, with the count. Setup: half_disc with
/// n = 6 and no grading (six elements on the half circle). Reference: the rule of the user
/// guide: a plastic contact that closed at most three slave nodes at once (fewer than three
/// segments); `--strict` exits 3.
#[test]
fn a_mesh_too_coarse_for_the_contact_is_warned() {
    let dir = common::out_dir("sphere_coarse");
    let edits = ["body.sphere.mesh.n=6", "body.sphere.mesh.grading=1"];
    let (code, stderr) = impact_on_sphere("run", Some(&dir), &edits);
    assert_eq!(code, 3, "{stderr}");
    warned(
        &stderr,
        &[
            "closed at most 1 slave node(s) at once",
            "resolved by 0 segment(s)",
        ],
    );
}

/// Goal: a density in g/cm^3 beside SI moduli is caught before the run, and a run that
/// then gains kinetic energy says so. Setup: density = 7.85; the run with Newmark average
/// at dt = 2e-7 s on a coarser arc (n = 12), the step a user takes from the wave speed he
/// expects. Reference: waves faster than in any solid (25 km/s) with moduli in Pa;
/// kinetic energy at the end above the initial one by more than 1 %, which no rebound
/// gives; `--strict` exits 3 both times.
#[test]
fn a_density_in_grams_per_cubic_centimetre_is_caught() {
    let (code, stderr) = impact_on_sphere("check", None, &["material.steel.density=7.85"]);
    assert_eq!(code, 3, "{stderr}");
    warned(&stderr, &["faster than in any solid", "kg/m^3"]);
    let dir = common::out_dir("sphere_density");
    let edits = [
        "material.steel.density=7.85",
        "analysis.integrator=average",
        "analysis.dt=2e-7",
        "analysis.mass=lumped",
        "body.sphere.mesh.n=12",
    ];
    let (code, stderr) = impact_on_sphere("run", Some(&dir), &edits);
    assert_eq!(code, 3, "{stderr}");
    warned(&stderr, &["more than they were given", "kg/m^3"]);
}

/// Goal: a yield stress in MPa beside a modulus in Pa is caught before the run; the run
/// that diverges says the state points to mixed units, and books no negative plastic work.
/// Setup: yield_stress = 300, Newmark average at dt = 1e-7 s, n = 12. Reference: a yield
/// strain of 1.4e-9, below the 1e-5 of any solid; the divergence is a numerical failure
/// (exit 3: the step that would make the plastic work negative is refused, not recorded)
/// whose message names the units; summary.json `plastic_dissipation` >= 0.
#[test]
fn a_yield_stress_in_mpa_is_caught_and_its_divergence_names_the_units() {
    let (code, stderr) = impact_on_sphere("check", None, &["material.steel.yield_stress=300.0"]);
    assert_eq!(code, 3, "{stderr}");
    warned(&stderr, &["a yield stress in MPa beside young in Pa"]);
    let dir = common::out_dir("sphere_mpa");
    let edits = [
        "material.steel.yield_stress=300.0",
        "analysis.integrator=average",
        "analysis.dt=1e-7",
        "body.sphere.mesh.n=12",
    ];
    let (code, stderr) = impact_on_sphere("run", Some(&dir), &edits);
    assert_eq!(code, 3, "{stderr}");
    let error = stderr.lines().find(|l| l.starts_with("error: ")).unwrap();
    assert!(error.contains("mixed units"), "{error}");
    let json = summary_json(&dir);
    assert_eq!(json["status"], "diverged");
    assert!(json["energy"]["plastic_dissipation"].as_f64().unwrap() >= 0.0);
}

/// Goal: a velocity in mm/s beside lengths in m is caught before the run, and the run that
/// fails says its state points to mixed units. Setup: velocity = [0, -5000]. Reference: a
/// start at 0.83 of the wave speed, beyond the quarter of it solid impacts stay under;
/// the failure (an element inverted at the contact) names a node beyond a quarter of the
/// wave speed.
#[test]
fn a_velocity_in_mm_per_second_is_caught() {
    let edit = "body.sphere.velocity=[0,-5000.0]";
    let (code, stderr) = impact_on_sphere("check", None, &[edit]);
    assert_eq!(code, 3, "{stderr}");
    warned(&stderr, &["a velocity in mm/s beside lengths in m"]);
    let dir = common::out_dir("sphere_mm_per_s");
    let (code, stderr) = impact_on_sphere("run", Some(&dir), &[edit]);
    assert_eq!(code, 3, "{stderr}");
    let error = stderr.lines().find(|l| l.starts_with("error: ")).unwrap();
    assert!(
        error.contains("mixed units") && error.contains("of its wave speed"),
        "{error}"
    );
}

/// Goal: the advice of a pair that never closed follows what happened: after a run that
/// failed in its first step it does not ask for a longer end time. Setup: the sphere 1 mm
/// above the wall, its pole node alone thrown at 2000 m/s into the sphere (an initial
/// velocity on the set `pole`): an element at the pole inverts within the first 0.4 us,
/// long before the sphere (5 m/s) could cross the 1 mm to the wall (200 us). Reference:
/// status diverged; the never-closed warning says the run stopped before its end time and
/// does not say to lengthen it.
#[test]
fn the_never_closed_advice_follows_a_failed_run() {
    let text = std::fs::read_to_string(SPHERE).unwrap().replace(
        "[[support]]",
        "[[initial_velocity]]\nset = \"pole\"\nvelocity = [0.0, 2000.0]\n\n[[support]]",
    );
    let scene = common::out_dir("sphere_crash_scene").join("crash.toml");
    std::fs::write(&scene, text).unwrap();
    let dir = common::out_dir("sphere_crash");
    let out = common::impact(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
        "--quiet",
        "--set",
        "body.sphere.mesh.center=[0.0,6.0e-3]",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    let json = summary_json(&dir);
    assert_eq!(json["status"], "diverged");
    let warnings: Vec<&str> = json["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap())
        .collect();
    let never = warnings
        .iter()
        .find(|w| w.contains("never closed"))
        .unwrap_or_else(|| panic!("{warnings:?}"));
    assert!(never.contains("stopped before its end time"), "{never}");
    assert!(!never.contains("lengthen analysis.end_time"), "{never}");
}

/// Goal: the new scene keys refuse bad values naming the key (exit 2). Setup: a negative
/// `output.contact_force_window`; `statistic = "mass_mean"` on a stress probe. Reference:
/// the user guide (2.13): a window is a time >= 0; `mass_mean` takes nodal kinematic
/// quantities only.
#[test]
fn bad_window_and_mass_mean_probes_are_refused() {
    let (code, stderr) = impact_on_sphere("check", None, &["output.contact_force_window=-1e-6"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("output.contact_force_window"), "{stderr}");
    let (code, stderr) = impact_on_sphere(
        "check",
        None,
        &[
            "output.probe.0.quantity=s_yy",
            "output.probe.1.quantity=s_yy",
        ],
    );
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("output.probe[1].statistic") && stderr.contains("mass_mean"),
        "{stderr}"
    );
}

// The new thresholds at their edges: `plausibility::warnings` and `final_warnings` on the
// sphere with a summary, energies and an end state set by hand so that one quantity sits
// 0.1 % either side of the edge the user guide documents (far above the round-off of the
// comparisons; an edge misplaced by more than 0.1 % fails one side).

/// The sphere's model and a summary of an `ok` run with nothing to warn of.
fn sphere_summary() -> (impact::scene::Model, Summary) {
    let model = impact::scene::load(Path::new(SPHERE), &[]).unwrap();
    let summary = Summary::new(&model, "central_difference", 1e-8, 40e-6, 100);
    (model, summary)
}

/// Goal: the kinetic-energy warning fires above 1.01 times the energy given. Setup: initial
/// kinetic energy 1, no external work, final kinetic energy 1.01 (1 -+ 1e-3). Reference:
/// the user guide's edge, 1.01.
#[test]
fn kinetic_energy_gain_warns_above_one_per_cent() {
    let (model, mut summary) = sphere_summary();
    summary.energy.initial = 1.0;
    let at = |kinetic: f64| {
        let energies = Energies {
            kinetic,
            ..Energies::default()
        };
        plausibility::warnings(&model, &summary, &energies, (None, None))
    };
    assert!(at(1.01 * (1.0 - 1e-3)).is_empty());
    let above = at(1.01 * (1.0 + 1e-3));
    assert_eq!(above.len(), 1, "{above:?}");
    assert!(
        above[0].contains("more than they were given"),
        "{}",
        above[0]
    );
}

/// Goal: the coarse-contact warning fires at three closed slaves at most, on a plastic body.
/// Setup: the sphere's pair closed at most 4, then 3 slave nodes at once. Reference: the
/// user guide: fewer than three segments, i.e. three nodes or fewer.
#[test]
fn coarse_contact_warns_at_three_closed_nodes() {
    let (model, mut summary) = sphere_summary();
    let energies = Energies::default();
    summary.contact.closed_at_widest = vec![4];
    assert!(plausibility::warnings(&model, &summary, &energies, (None, None)).is_empty());
    summary.contact.closed_at_widest = vec![3];
    let warned = plausibility::warnings(&model, &summary, &energies, (None, None));
    assert_eq!(warned.len(), 1, "{warned:?}");
    assert!(
        warned[0].contains("resolved by 2 segment(s)"),
        "{}",
        warned[0]
    );
}

/// Goal: a balanced pair's coarse contact is judged once, under the pair's name, on the
/// nodes both passes closed. Setup: models/block_on_plate.toml (a balanced pair `impact`
/// between two plastic bodies, its reverse pass `impact:reverse`), the widest closed counts
/// set by hand per pass. Reference: the user guide's rule (three closed nodes or fewer
/// warn), applied to the contact, whose nodes are the two passes' together: 2 + 2 = 4 does
/// not warn (each pass alone would), 1 + 1 = 2 warns once, naming `impact`.
#[test]
fn a_balanced_pair_is_judged_on_both_passes_under_its_name() {
    let model = impact::scene::load(Path::new("models/block_on_plate.toml"), &[]).unwrap();
    assert_eq!(model.contacts[1].balances, Some(0));
    let mut summary = Summary::new(&model, "central_difference", 1e-8, 150e-6, 100);
    let energies = Energies::default();
    summary.contact.closed_at_widest = vec![2, 2];
    let warned = plausibility::warnings(&model, &summary, &energies, (None, None));
    assert!(warned.is_empty(), "{warned:?}");
    summary.contact.closed_at_widest = vec![1, 1];
    let warned = plausibility::warnings(&model, &summary, &energies, (None, None));
    assert_eq!(warned.len(), 1, "{warned:?}");
    assert!(
        warned[0].contains("contact `impact` closed at most 2"),
        "{}",
        warned[0]
    );
}

/// Goal: the still-closed warning fires when the slave body approaches the wall at more
/// than a tenth of its approach speed at the start. Setup: the sphere (5 m/s towards the
/// wall at the start), the pair closed at the end, every node moving towards the wall at
/// 0.5 m/s (1 -+ 1e-3). Reference: the user guide's edge, 10 % of the start's approach.
#[test]
fn still_closed_warns_above_a_tenth_of_the_approach() {
    let (model, _) = sphere_summary();
    let mass = impact::assembly::Mass::new(&model, impact::scene::spec::MassKind::Lumped)
        .unwrap()
        .lumped;
    let positions = model.coordinates();
    let closed = vec!["wall".to_string()];
    let energies = Energies::default();
    let at = |speed: f64| {
        let velocity: Vec<f64> = (0..model.dofs())
            .map(|i| if i % 2 == 1 { -speed } else { 0.0 })
            .collect();
        let end = plausibility::EndOfRun {
            positions: &positions,
            energies: &energies,
            hourglass_energy: None,
            mass_scaling: None,
            velocity: &velocity,
            mass: &mass,
            closed_at_end: &closed,
            finished: true,
            contact: None,
        };
        plausibility::final_warnings(&model, &end)
    };
    assert!(at(0.5 * (1.0 - 1e-3)).is_empty());
    let above = at(0.5 * (1.0 + 1e-3));
    assert_eq!(above.len(), 1, "{above:?}");
    assert!(above[0].contains("is still closed"), "{}", above[0]);
}

/// Goal: a hardening modulus at or above Young's modulus and a Johnson-Cook specific heat in
/// kJ / (kg K) are caught before the run (exit 3 with `--strict`), each naming its key.
/// Setup: the sphere with hardening_modulus = 3e11 (E = 2.1e11); models/taylor_jc.toml with
/// specific_heat = 0.46 instead of 460. Reference: metals harden at E / 1000 to E / 10; the
/// 42CrMo4 rod heats by chi A / (rho c_p) = 0.9 x 806e6 / (7850 x 460) = 201 K per unit of
/// plastic strain, 0.13 of its 1520 K from room to melting (silent: the shipped scenes give
/// no warning, above), and 2.0e5 K with the specific heat in kJ, 132 times that span, beyond
/// the 3 times the check allows.
#[test]
fn a_hardening_above_young_and_a_specific_heat_in_kilojoules_are_caught() {
    let (code, stderr) =
        impact_on_sphere("check", None, &["material.steel.hardening_modulus=3.0e11"]);
    assert_eq!(code, 3, "{stderr}");
    warned(&stderr, &["hardening_modulus", "at or above its young"]);
    let out = common::impact(&[
        "check",
        "models/taylor_jc.toml",
        "--strict",
        "--set",
        "material.42CrMo4.johnson_cook.specific_heat=0.46",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    warned(
        &stderr,
        &["material `42CrMo4` would heat by", "kJ / (kg K)"],
    );
}

/// Writes the sphere scene with `from` replaced by `to` into the test folder `name`, and
/// returns its path.
fn sphere_edited(name: &str, from: &str, to: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(SPHERE).unwrap();
    assert!(text.contains(from), "{from}");
    let dir = common::out_dir(name);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("scene.toml");
    std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
    path
}

/// Goal: the same slave surface against the same wall in two pairs is refused, naming both
/// (before: `check` passed and the run died on a runaway penetration naming neither).
/// Setup: the sphere with its pair `wall` repeated as `wall2`. Reference: the nodes of one
/// surface would be held twice in a step; exit 2 with both names (the sphere as it stands
/// passes `check`: above).
#[test]
fn a_contact_pair_given_twice_is_refused() {
    let pair = "[[contact]]\nname = \"wall\"\nslave = { set = \"arc\" }\nobstacle = \"wall\"\n";
    let twice = format!(
        "{pair}\n{}",
        pair.replace("\"wall\"\nslave", "\"wall2\"\nslave")
    );
    let path = sphere_edited("sphere_pair_twice", pair, &twice);
    let out = common::impact(&["check", path.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("contact `wall2` repeats contact `wall`"),
        "{stderr}"
    );
}

/// Goal: a support that holds nodes in a component in which their body starts moving, an
/// axisymmetric body given a radial velocity as a whole, and elements of aspect ratio 30 are
/// each warned before the run (exit 3 with `--strict`). Setup: the sphere with its axis
/// support fixing y too (its nodes start at -5 m/s in y); the sphere at velocity [-5, 0];
/// models/taylor_jc.toml at nx = 1, ny = 200 (rod 3.2 x 32.4 mm: elements 3.2 x 0.162 mm,
/// aspect 19.8).
/// Reference: a fixed DOF keeps no velocity; x is the radius in axisymmetry; the mesh
/// guidance of explicit codes (aspect ratio below 10). The sphere and the shipped scenes as
/// they stand give none of them (above).
#[test]
fn a_cancelled_velocity_a_radial_velocity_and_long_elements_are_warned() {
    let path = sphere_edited(
        "sphere_axis_held_in_y",
        "fix = [\"x\"]",
        "fix = [\"x\", \"y\"]",
    );
    let out = common::impact(&["check", path.to_str().unwrap(), "--strict"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    warned(
        &stderr,
        &[
            "body `sphere`",
            "held in y by a [[support]] start moving in y",
        ],
    );
    let (code, stderr) = impact_on_sphere("check", None, &["body.sphere.velocity=[-5.0, 0.0]"]);
    assert_eq!(code, 3, "{stderr}");
    warned(
        &stderr,
        &[
            "axisymmetric body `sphere`",
            "imploding",
            "components swapped",
        ],
    );
    let out = common::impact(&[
        "check",
        "models/taylor_jc.toml",
        "--strict",
        "--set",
        "body.rod.mesh.nx=1",
        "--set",
        "body.rod.mesh.ny=200",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    warned(
        &stderr,
        &["body `rod` has 200 element(s) longer than 10 times their width"],
    );
}

/// Goal: a Taylor rod written as plane stress, its thickness left at the default 1 (m), is
/// warned before the run. Setup: models/taylor_jc.toml with `formulation = "plane_stress"`
/// (the rod 3.2 x 32.4 mm). Reference: plane stress is for plates thin against their
/// in-plane size; 1 m is 31 times the rod's length (the run: plastic work 8069 J
/// against 96 J). The shipped plane-stress scenes (thickness 0.1 to 1, sizes 5 to 20) give
/// none (`shipped_scenes_and_the_sphere_give_no_setup_warning`).
#[test]
fn a_plane_stress_body_thicker_than_it_is_long_is_warned() {
    let out = common::impact(&[
        "check",
        "models/taylor_jc.toml",
        "--strict",
        "--set",
        "body.rod.formulation=\"plane_stress\"",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    warned(
        &stderr,
        &[
            "body `rod` is plane stress with a thickness of 1",
            "give `thickness`",
        ],
    );
}

/// Goal: a `[[node_set]]` point off its body (a sign slip) is refused naming the distance,
/// not snapped to a node far away. Setup: models/taylor_jc.toml with the node set
/// `face_centre` at [0, -25.4e-3] instead of on the rod's face (y = 0). Reference: the
/// point lies 25.4 mm from the rod's nearest node, 160 times the rod's longest element
/// edge (0.65 mm: 3.2 / 5 mm wide); exit 2 with the key.
#[test]
fn a_node_set_point_off_its_body_is_refused() {
    common::check_refuses_with(
        "models/taylor_jc.toml",
        &["node_set.face_centre.nearest=[0.0, -25.4e-3]"],
        &[
            "(`face_centre`).nearest",
            "from the nearest node of body `rod`",
            "sign or unit slip",
        ],
    );
}

/// Goal: a wall shorter than the foot a Taylor rod grows is named when the foot leaves it,
/// and the run's failure blames that, not the units. Setup: models/taylor_aluminum.toml
/// (the foot 3.81 mm in radius) with the wall ending at r = 4.0 mm instead of 20 mm,
/// `--strict`. Reference: the geometry alone: the foot's outer corner (node 5 of the
/// bottom row, the outermost slave) is the first to cross r = 4.0 mm, so summary.json
/// `contact.past_end` names that node past (0.004, 0) at r > 4.0 mm. The run then fails
/// (the contact gives energy at the corner) with exit 3; its message names the end of the
/// obstacle and says nothing of units (every body started at 0.08 of its wave speed). With
/// the wall as shipped, no node passes (tests/scenes.rs: the shipped run warns of nothing).
#[test]
fn a_wall_shorter_than_the_foot_is_named_when_the_foot_leaves_it() {
    let dir = common::out_dir("taylor_short_wall");
    let output = common::impact(&[
        "run",
        "models/taylor_aluminum.toml",
        "--strict",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
        "--set",
        "obstacle.wall.points=[[0.004, 0.0], [-0.01, 0.0]]",
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(3), "{stderr}");
    warned(
        &stderr,
        &["went past the end (0.004, 0) of obstacle `wall`"],
    );
    let json = summary_json(&dir);
    let past = &json["contact"]["past_end"];
    assert_eq!(past["node"], 5, "{past}");
    assert_eq!(past["body"], "rod");
    assert!(past["position"][0].as_f64().unwrap() > 0.004, "{past}");
    if json["status"] == "diverged" {
        let message = json["message"].as_str().unwrap();
        assert!(message.contains("past the end"), "{message}");
        assert!(!message.contains("mixed units"), "{message}");
    }
}

/// Goal: a node that the run made fast is not blamed on the units when every body started
/// slow, and a body that started fast still is. Setup: tests/data/sphere_wall_si.toml (the
/// steel sphere at 5 m/s; its dilatational wave speed sqrt(M / rho) = 6.0 km/s, M = E (1 -
/// nu) / ((1 + nu) (1 - 2 nu)) = 283 GPa); at the failure one node moves at 3000 m/s.
/// Reference: 3000 m/s is 0.50 of the wave speed, beyond the quarter solid impacts stay
/// under, while the start (5 m/s, 0.0008 of it) is far below: the hint says the run made the
/// speed, not mixed units. The same state with the sphere started at 5000 m/s (0.83 of it)
/// points to mixed units.
#[test]
fn a_node_the_run_made_fast_is_not_blamed_on_the_units() {
    let model = impact::scene::load(Path::new(SPHERE), &[]).unwrap();
    let mut velocity = vec![0.0; 2 * model.coordinates().len()];
    velocity[1] = 3000.0;
    let hint = plausibility::failure_hint(&model, &velocity).expect("a fast node is named");
    assert!(hint.contains("not mixed units"), "{hint}");
    assert!(!hint.contains("points to mixed units"), "{hint}");
    let edit = ["body.sphere.velocity=[0,-5000.0]".to_string()];
    let fast = impact::scene::load(Path::new(SPHERE), &edit).unwrap();
    let hint = plausibility::failure_hint(&fast, &velocity).expect("the start is named");
    assert!(hint.contains("points to mixed units"), "{hint}");
}

/// Goal: a Johnson-Cook room temperature in degrees Celsius beside a melting temperature in
/// K is caught before the run (exit 3 with `--strict`). Setup: models/taylor_jc.toml (room
/// 20 C, melting 1540 C, both Celsius: silent, as every shipped scene above) with the
/// melting temperature of Ti-6Al-4V in K, 1878, as the user wrote it; and with
/// 1878 - 273 = 1605 (both Celsius again). Reference: 1878 K is titanium's melting point
/// (1870-1941 K, ASM Handbook) and no metal's in degrees Celsius (steels end at 1538 C,
/// titanium starts at 1597 C), while the room temperature 20 reads as Celsius; 1605 is
/// titanium's in Celsius and is silent.
#[test]
fn a_room_temperature_in_celsius_beside_a_melting_point_in_kelvin_is_caught() {
    let check = |melting: &str| {
        let set = format!("material.42CrMo4.johnson_cook.melting_temperature={melting}");
        let out = common::impact(&["check", "models/taylor_jc.toml", "--strict", "--set", &set]);
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        (out.status.code(), stderr)
    };
    let (code, stderr) = check("1878.0");
    assert_eq!(code, Some(3), "{stderr}");
    warned(
        &stderr,
        &[
            "room_temperature = 20 reads as degrees Celsius",
            "melting 1604.85",
        ],
    );
    let (code, stderr) = check("1605.0");
    assert_eq!(code, Some(0), "{stderr}");
}
