//! Obstacles that move: a rigid wall or punch driven by a prescribed translation
//! (`[[obstacle]] motion`), on the static path, under central difference and under the
//! implicit integrators.

mod common;

use impact::analysis::Status;
use impact::output::vtu::{Section, read_frame};

/// The bar of models/bar_wall.toml (L = 10, E = 100, rho = 0.01, A = 1: c = 100) at rest,
/// struck at x = 10 by the wall moving at V = 0.1 towards it (0.04 over the 0.4 of the run,
/// the default curve's constant speed), under central difference.
const BAR_STRUCK: &str = r#"
[[material]]
name = "bar"
young = 100.0
poisson = 0.0
density = 0.01

[[body]]
name = "bar"
material = "bar"
formulation = "rod"
area = 1.0
mesh = { type = "line", start = [0.0, 0.0], end = [10.0, 0.0], n = 14 }

[[support]]
set = "all"
fix = ["y"]

[[obstacle]]
name = "wall"
points = [[10.0, 1.0], [10.0, -1.0]]
motion = { displacement = [-0.04, 0.0] }

[[contact]]
name = "wall"
slave = { set = "end" }
obstacle = "wall"

[analysis]
type = "dynamic"
integrator = "central_difference"
geometry = "linear"
end_time = 0.4
"#;

/// Goal: a wall that moves strikes a body as a body striking a wall at rest does, and the
/// work it does enters the energy balance as external work, not as contact work.
/// Setup: `BAR_STRUCK`. Reference: the wall's frame is the bar striking a wall at rest at V
/// (Hughes et al. 1975, I-3): the contact force rho c A V = 0.1 on 0 < t < 2 L / c = 0.2,
/// then the bar leaves at 2 V; the wall does F V (2 L / c) = 0.002 of work, which ends as the
/// bar's kinetic energy. Measured: a plateau within 0.5 % of 0.1 (the lumped mesh rings by a
/// few tenths of a per cent; 1 % asserted over 0.02 < t < 0.18), the wall's work 0.001965
/// (-1.8 %: the contact ends a step early, dt = 0.0063 of the 0.2 it lasts, 3.2 %; 3.5 %
/// asserted); the balance of the last row closed to 0.25 % of it (the kinetic energy at a
/// full step of central difference is not its conserved energy: the ringing; 0.5 %
/// asserted), and the run's own balance drift 2.2e-4 (1e-3 asserted); the end node's kinetic
/// energy at first touch, m V^2 / 2 = 1.8e-5, is contact work. Without the obstacle's work
/// booked as external the balance is short by all of it; without the placing nothing
/// touches.
#[test]
fn a_moving_wall_strikes_a_bar_at_rest() {
    let model = common::model("bar_struck", BAR_STRUCK, &[]);
    let (summary, _) = common::run("bar_struck", &model);
    assert_eq!(summary.status, Status::Ok);
    let dir = common::out_dir_of("bar_struck");
    let plateau = common::window(&dir, "contact_force[wall]", 0.02, 0.18);
    let mean = common::mean(&plateau);
    assert!((mean / 0.1 - 1.0).abs() < 0.01, "plateau {mean}");
    // the bar pushes the wall along +x with the pair's whole force
    let on_wall = common::column(&dir, "obstacle_force_x[wall]");
    for (f, g) in common::column(&dir, "contact_force[wall]")
        .iter()
        .zip(&on_wall)
    {
        assert!(
            (f - g).abs() <= 1e-12 * f.abs().max(1e-3),
            "{f} against {g}"
        );
    }
    let last = |name: &str| *common::column(&dir, name).last().unwrap();
    assert!((last("obstacle_u_x[wall]") + 0.04).abs() < 1e-15);
    let supplied = last("external_work");
    assert!(
        (supplied / 0.002 - 1.0).abs() < 0.035,
        "wall's work {supplied}"
    );
    let held = last("kinetic_energy") + last("internal_energy") + last("contact_work");
    assert!(
        (held - supplied).abs() < 5e-3 * supplied,
        "{held} held of {supplied}"
    );
    assert!(
        summary.energy.max_relative_drift < 1e-3,
        "{:?}",
        summary.energy
    );
    assert!(last("contact_work").abs() < 0.01 * supplied);
}

/// Goal: the contact against a moving obstacle is the contact against one at rest seen from
/// a moving frame, in finite-strain plasticity too. Setup: models/rod_wall.toml (a
/// Johnson-Cook rod at 287 m/s onto a frictionless wall, 2x2, to 80 us), and the same rod at
/// rest with the wall moving up at 287 m/s (its displacement 287 m/s x 80 us). Reference:
/// Galilean invariance: the rod's final length and diameter and its plastic work are the
/// same in both frames; the discrete equations are too, but for the round-off of positions
/// offset by the wall's travel (measured: 1e-14 relative; 1e-9 asserted). The kinetic
/// energy differs by the frame, and the wall's work closes that balance (1 % asserted, the
/// energy check's own bound).
#[test]
fn a_rod_struck_by_a_moving_wall_deforms_as_one_striking_a_wall_at_rest() {
    let still = common::run_scene("rod_wall_still", "rod_wall", &[]);
    let moving = common::run_scene(
        "rod_wall_moving",
        "rod_wall",
        &[
            "body.rod.velocity=[0.0, 0.0]",
            "obstacle.wall.motion={ displacement = [0.0, 0.02296] }",
        ],
    );
    assert_eq!(still.summary.status, Status::Ok);
    assert_eq!(moving.summary.status, Status::Ok);
    let last = |dir: &std::path::Path, name: &str| *common::column(dir, name).last().unwrap();
    for name in ["extent_y[all]", "extent_x[all]", "plastic_work"] {
        let (a, b) = (last(&still.dir, name), last(&moving.dir, name));
        assert!((a - b).abs() < 1e-9 * a.abs(), "{name}: {a} against {b}");
    }
    let energy = &moving.summary.energy;
    assert!(energy.max_relative_drift < 0.01, "{energy:?}");
    assert!(last(&moving.dir, "external_work") > 0.0);
}

/// Goal: Shield's punch driven by the obstacle itself gives the limit of the block pushed
/// onto it (issue: "Shield's punch driven by the obstacle itself gives the same limit as the
/// block pushed onto it"). Setup: models/shield_punch.toml on its coarsest mesh (punch0,
/// 24 x 20), small displacements; once as shipped (the bottom pushed up 0.04 a), once with
/// the bottom held and the punch moved down 0.04 a. Reference: at small displacements the
/// two are the same boundary value problem (a rigid translation of the whole), so the
/// force-travel curves agree to Newton's tolerance (measured 4e-12 relative on punch1;
/// 1e-6 asserted), and Shield (1955): the limit mean pressure 5.69 k within the 3 % of the
/// mesh family's test (docs/validation.md 2.9). The force on the punch (its history
/// columns) is the bottom's reaction (equilibrium of the block, 1e-6 asserted).
#[test]
fn shields_punch_driven_by_the_obstacle_gives_the_pushed_limit() {
    let mesh = "body.block.mesh.file=\"meshes/punch0.msh\"";
    let pushed = common::run_scene(
        "punch_pushed",
        "shield_punch",
        &["analysis.geometry=linear", mesh],
    );
    let driven = common::run_scene(
        "punch_driven",
        "shield_punch",
        &[
            "analysis.geometry=linear",
            mesh,
            "load=[]",
            "support=[{ set = \"axis\", fix = [\"x\"] }, { set = \"bottom\", fix = [\"x\", \"y\"] }]",
            "obstacle.punch.motion={ displacement = [0.0, -40e-6] }",
        ],
    );
    for run in [&pushed, &driven] {
        assert_eq!(run.summary.status, Status::Ok);
        assert_eq!(run.summary.step_cuts, 0);
    }
    let reaction = |dir: &std::path::Path| common::column(dir, "reaction_y[bottom]");
    let (a, b) = (reaction(&pushed.dir), reaction(&driven.dir));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= 1e-6 * x.abs().max(1.0), "{x} against {y}");
    }
    let on_punch = common::column(&driven.dir, "obstacle_force_y[punch]");
    for (x, y) in b.iter().zip(&on_punch) {
        assert!((x - y).abs() <= 1e-6 * x.abs().max(1.0), "{x} against {y}");
    }
    let (area, k) = (std::f64::consts::PI * 1e-6, 125e6);
    let peak = b.iter().fold(f64::NEG_INFINITY, |m, r| m.max(*r)) / area / k;
    assert!((peak / 5.69 - 1.0).abs() < 0.03, "peak {peak} k");
}

/// Goal: friction against a moving obstacle acts on the slip relative to it. Setup:
/// models/steel_block_wall.toml (a J2 steel block at 50 m/s onto a rigid wall, plane strain,
/// central difference) with Coulomb friction mu = 0.3, struck obliquely: the block at
/// (50, 20) m/s onto the wall at rest, and the block at (50, 0) m/s onto the wall sliding at
/// -20 m/s along itself. Reference: Galilean invariance: the block's x momentum, its plastic
/// work and the friction's dissipation are the same in both frames (measured: 2e-13 apart;
/// 1e-9 asserted); without friction the x momentum differs by 35 % and the plastic work by
/// 1.3 % (10 % and 0.5 % asserted), and the friction dissipates 10 % of the plastic work, so
/// it acts. Mutation: with the slave's own slip read as its slip on the moving wall, the x
/// momentum ends at -8.11 against -11.66 kg m/s.
#[test]
fn friction_on_a_wall_that_slides_is_friction_in_the_walls_frame() {
    let oblique = common::run_scene(
        "block_oblique",
        "steel_block_wall",
        &[
            "body.block.velocity=[50.0, 20.0]",
            "contact.wall.friction=0.3",
        ],
    );
    let sliding_wall = common::run_scene(
        "block_sliding_wall",
        "steel_block_wall",
        &[
            "contact.wall.friction=0.3",
            "obstacle.wall.motion={ displacement = [0.0, -6e-4] }",
        ],
    );
    let frictionless = common::run_scene(
        "block_oblique_frictionless",
        "steel_block_wall",
        &["body.block.velocity=[50.0, 20.0]"],
    );
    let last = |dir: &std::path::Path, name: &str| *common::column(dir, name).last().unwrap();
    for name in ["p_x[all]", "plastic_work", "friction_work"] {
        let (a, b) = (last(&oblique.dir, name), last(&sliding_wall.dir, name));
        assert!((a - b).abs() < 1e-9 * a.abs(), "{name}: {a} against {b}");
    }
    for (name, apart) in [("p_x[all]", 0.1), ("plastic_work", 0.005)] {
        let (a, b) = (last(&oblique.dir, name), last(&frictionless.dir, name));
        assert!(
            (a - b).abs() > apart * a.abs(),
            "{name}: {a} and {b} without friction"
        );
    }
    assert!(last(&oblique.dir, "friction_work") > 0.05 * last(&oblique.dir, "plastic_work"));
}

/// Goal: in statics a moving obstacle with friction drags the body as a body pushed under an
/// obstacle at rest is dragged. Setup: models/rough_platen.toml (a J2 steel block, plane
/// strain, on a held bottom, pressed 50 um and sheared 20 um by a rough platen, mu = 0.3, in
/// 10 increments with the defaults: finite strain, the contact passes), against the same block with the platen at rest and the bottom moved by
/// (-20, +50) um. Reference: the two are one problem seen from frames a translation apart
/// (updated Lagrangian statics is invariant under it): the bottom's reactions agree
/// (measured 1e-8 relative, Newton's tolerance; 1e-6 asserted), and the force on the platen
/// is the bottom's reaction (the block's equilibrium, 1e-6). Without friction the shear reaction is 0
/// (the platen's sideways motion drags nothing), with it 92.6 kN per metre, 1.2 % of the
/// normal force (asserted above 0.5 %), so the relative slip is what the stick holds.
#[test]
fn a_rough_platen_that_moves_drags_the_block_as_the_pushed_block_is_dragged() {
    let driven = common::run_scene("platen_driven", "rough_platen", &[]);
    let pushed = common::run_scene(
        "platen_pushed",
        "rough_platen",
        &[
            "obstacle.platen.motion={ displacement = [0.0, 0.0] }",
            "support=[]",
            "load=[{ type = \"displacement\", set = \"bottom\", x = -2e-5, y = 5e-5 }]",
        ],
    );
    for run in [&driven, &pushed] {
        assert_eq!(run.summary.status, Status::Ok);
    }
    let (a, b) = (&driven.dir, &pushed.dir);
    let last = |dir: &std::path::Path, name: &str| *common::column(dir, name).last().unwrap();
    for name in ["reaction_x[bottom]", "reaction_y[bottom]", "plastic_work"] {
        let (x, y) = (last(a, name), last(b, name));
        assert!((x - y).abs() < 1e-6 * x.abs(), "{name}: {x} against {y}");
    }
    for (reaction, force) in [
        ("reaction_x[bottom]", "obstacle_force_x[platen]"),
        ("reaction_y[bottom]", "obstacle_force_y[platen]"),
    ] {
        let (r, f) = (last(a, reaction), last(a, force));
        assert!(
            (r - f).abs() < 1e-6 * last(a, "reaction_y[bottom]"),
            "{r} against {f}"
        );
    }
    let shear = last(a, "reaction_x[bottom]").abs();
    assert!(
        shear > 5e-3 * last(a, "reaction_y[bottom]"),
        "shear reaction {shear}"
    );
}

/// The implicit integrators of `implicit_integrators_meet_a_moving_wall_as_one_at_rest`:
/// each with the `--set`s that select it, and whether it conserves energy (Newmark's
/// average acceleration; Wilson, Houbolt and HHT damp numerically).
const IMPLICIT: [(&str, &[&str], bool); 5] = [
    ("average", &["analysis.integrator=average"], true),
    (
        "average_persistency",
        &[
            "analysis.integrator=average",
            "analysis.contact_dynamics=\"persistency\"",
        ],
        true,
    ),
    ("wilson", &["analysis.integrator=wilson"], false),
    ("houbolt", &["analysis.integrator=houbolt"], false),
    ("hht", &["analysis.integrator=hht"], false),
];

/// Goal: on every implicit integrator a wall that moves strikes a body as the body striking
/// a wall at rest does (the impact conditions give the struck node the wall's velocity, the
/// gap reads the wall where it is at the solve's time, a persistent contact holds the
/// relative velocity), and the wall's work enters the balance as external work. Setup:
/// `BAR_STRUCK` on each integrator (consistent mass, dt = 0.005, the seeds' step for the
/// bar), against the same bar at V = 0.1 onto the wall at rest. Reference: Galilean
/// invariance: the contact force and the energy the contact takes are the same in both
/// frames (the equations differ by a rigid translation V t, exact for the linear bar, so
/// they agree to Newton's tolerance, 1e-8 of the force: measured 1e-12 to 1e-10 apart; 1e-9
/// asserted, and 1e-9 of the contact work); the wall's
/// work F V 2 L / c = 0.002 (Hughes et al. 1975, I-3; measured 0.00194-0.00197 on the
/// integrators, the contact ending within a step of 2 L / c, dt / 0.2 = 2.5 %; 3.5 %
/// asserted); the balance KE + U + contact work = external work on the last row, to round-off
/// on Newmark's average acceleration (1e-9 of the wall's work asserted; measured 1e-15), and
/// on the damping integrators short of it by their damping alone (Wilson 1.3 % here; at most
/// the balance warning's 5 %, and no gain, asserted). Mutations: the obstacle's velocity left out of the
/// impact conditions, its work out of the external work, its travel out of a persistent
/// target, or Wilson's solve meeting it at the step's end: each fails here.
#[test]
fn implicit_integrators_meet_a_moving_wall_as_one_at_rest() {
    let at_rest = BAR_STRUCK.replace("motion = { displacement = [-0.04, 0.0] }\n", "");
    let implicit = ["analysis.mass=consistent", "analysis.dt=0.005"];
    for (name, sets, conserving) in IMPLICIT {
        let sets: Vec<&str> = implicit.iter().chain(sets.iter()).copied().collect();
        let moving = format!("bar_struck_{name}");
        let still = format!("bar_at_wall_{name}");
        common::run(&moving, &common::model(&moving, BAR_STRUCK, &sets));
        let mut rest_sets = sets.clone();
        rest_sets.push("body.bar.velocity=[0.1, 0.0]");
        common::run(&still, &common::model(&still, &at_rest, &rest_sets));
        let (a, b) = (common::out_dir_of(&still), common::out_dir_of(&moving));
        let force = |dir: &std::path::Path| common::column(dir, "contact_force[wall]");
        let (fa, fb) = (force(&a), force(&b));
        assert_eq!(fa.len(), fb.len(), "{name}");
        for (x, y) in fa.iter().zip(&fb) {
            assert!((x - y).abs() < 1e-9, "{name}: {x} against {y}");
        }
        let last =
            |dir: &std::path::Path, column: &str| *common::column(dir, column).last().unwrap();
        let (wa, wb) = (last(&a, "contact_work"), last(&b, "contact_work"));
        assert!(
            (wa - wb).abs() < 1e-9 * wa.abs(),
            "{name}: {wa} against {wb}"
        );
        let supplied = last(&b, "external_work");
        assert!(
            (supplied / 0.002 - 1.0).abs() < 0.035,
            "{name}: the wall's work {supplied}"
        );
        let held = last(&b, "kinetic_energy") + last(&b, "internal_energy") + wb;
        let lost = supplied - held;
        if conserving {
            assert!(
                lost.abs() < 1e-9 * supplied,
                "{name}: {held} held of {supplied}"
            );
        } else {
            // the integrator's own damping, never a gain
            assert!(
                lost > -1e-9 * supplied && lost < 0.05 * supplied,
                "{name}: {held} held of {supplied}"
            );
        }
    }
}

/// Goal: the implicit contact against a moving wall is the contact against one at rest seen
/// from a moving frame in finite-strain plasticity, and with friction on a wall that slides
/// along itself. Setup: models/steel_block_wall.toml (a J2 steel block, 20 x 10, plane
/// strain) on Newmark's average acceleration at dt = 1e-7: (1) the block at 50 m/s onto the
/// wall at rest, against the block at rest struck by the wall at 50 m/s, to 30 us; (2) with
/// Coulomb friction mu = 0.3, the block at (50, 20) m/s onto the wall at rest against the block
/// at (50, 0) m/s onto the wall sliding at -20 m/s along itself, to 5 us (the run at rest
/// creates energy beyond the guard's 1 % at 6.4 us, in both frames alike). Reference:
/// Galilean invariance: the plastic work, the contact's and the friction's work agree, and
/// the momentum differs by M V (M = 1.57 kg per metre); the discrete equations differ by the
/// frame's translation, so they agree to Newton's tolerance (1e-8 of the forces; measured
/// 3e-11 and 3e-9 relative on (1), 1e-14 on (2); 1e-7 asserted). Without friction (2)'s block
/// does 3 % less plastic work, so the friction acts. Mutation: the friction's work read on
/// the slave's own slip, not its slip along the wall: (2)'s friction work fails.
#[test]
fn a_block_struck_by_a_moving_wall_on_newmark_is_the_block_striking_it() {
    let newmark = ["analysis.integrator=average", "analysis.dt=1e-7"];
    let run = |name: &str, extra: &[&str]| {
        let sets: Vec<&str> = newmark.iter().chain(extra).copied().collect();
        let run = common::run_scene(name, "steel_block_wall", &sets);
        assert_eq!(run.summary.status, Status::Ok, "{name}");
        run.dir
    };
    let striking = run("block_strikes_newmark", &[]);
    let struck = run(
        "block_struck_newmark",
        &[
            "body.block.velocity=[0.0, 0.0]",
            "obstacle.wall.motion={ displacement = [-1.5e-3, 0.0] }",
        ],
    );
    let last = |dir: &std::path::Path, name: &str| *common::column(dir, name).last().unwrap();
    let close = |a: f64, b: f64, what: &str| {
        assert!((a - b).abs() < 1e-7 * a.abs(), "{what}: {a} against {b}");
    };
    for name in ["plastic_work", "contact_work"] {
        close(last(&striking, name), last(&struck, name), name);
    }
    // the struck block's frame moves at -50 m/s: its momentum is M V less
    let momentum = 1.57 * 50.0;
    let (p_striking, p_struck) = (last(&striking, "p_x[all]"), last(&struck, "p_x[all]"));
    let apart = p_striking - (p_struck + momentum);
    assert!(
        apart.abs() < 1e-7 * momentum,
        "p_x: {p_striking} against {p_struck} + M V"
    );
    let short = ["analysis.end_time=5e-6", "contact.wall.friction=0.3"];
    let oblique: Vec<&str> = short
        .iter()
        .copied()
        .chain(["body.block.velocity=[50.0, 20.0]"])
        .collect();
    let sliding: Vec<&str> = short
        .iter()
        .copied()
        .chain(["obstacle.wall.motion={ displacement = [0.0, -1e-4] }"])
        .collect();
    let oblique = run("block_oblique_newmark", &oblique);
    let sliding = run("block_sliding_wall_newmark", &sliding);
    for name in ["p_x[all]", "plastic_work", "friction_work", "contact_work"] {
        close(last(&oblique, name), last(&sliding, name), name);
    }
    let frictionless = run(
        "block_oblique_frictionless_newmark",
        &["analysis.end_time=5e-6", "body.block.velocity=[50.0, 20.0]"],
    );
    let (with, without) = (
        last(&oblique, "plastic_work"),
        last(&frictionless, "plastic_work"),
    );
    assert!((with - without).abs() > 0.02 * with, "{with} and {without}");
}

/// Goal: a moving obstacle writes where it is at each frame, so ParaView shows it move.
/// Setup: `BAR_STRUCK` with 5 frames. Reference: the motion: the wall's points at a frame's
/// time t are its start points moved by -0.1 t in x.
#[test]
fn a_moving_obstacle_is_drawn_where_it_is_at_each_frame() {
    let model = common::model(
        "bar_struck_frames",
        BAR_STRUCK,
        &["output.frame_times=[0.1, 0.2, 0.3, 0.4]"],
    );
    common::run("bar_struck_frames", &model);
    let dir = common::out_dir_of("bar_struck_frames");
    let listed =
        impact::output::vtk::read_pvd(&dir.join("bar_struck_frames_obstacles.pvd")).unwrap();
    assert!(listed.len() >= 4, "{listed:?}");
    for (t, path) in &listed {
        let frame = read_frame(path).unwrap();
        let (_, points) = frame.floats(Section::Points, "Points").unwrap();
        let expected = 10.0 - 0.1 * t;
        let x: Vec<f64> = points.chunks_exact(3).map(|p| p[0]).collect();
        assert!(
            x.iter().all(|x| (x - expected).abs() < 1e-12),
            "t = {t}: {x:?}"
        );
    }
}

/// Goal: a moving obstacle where it is not implemented is refused with the reason (exit 2).
/// Reference: the paths that read an obstacle at rest (validate::check_moving_obstacles).
#[test]
fn moving_obstacles_are_refused_where_they_would_be_read_at_rest() {
    let motion = "obstacle.wall.motion={ displacement = [-0.04, 0.0] }";
    common::check_refuses_with(
        "models/rod_wall.toml",
        &[
            "obstacle.wall.motion={ displacement = [0.0, 0.02296] }",
            "analysis.subcycling={}",
        ],
        &["moving obstacle", "subcycling"],
    );
    // the closed form of bar_wall's [reference] reads the bar's speed against a wall at rest
    common::check_refuses_with(
        "models/bar_wall.toml",
        &[
            motion,
            "analysis.integrator=central_difference",
            "analysis.mass=lumped",
            "analysis.dt=0.004",
        ],
        &["reference.kind", "at rest"],
    );
    common::check_refuses_with(
        "models/shield_punch.toml",
        &[
            "obstacle.punch.motion={ displacement = [0.0, -40e-6] }",
            "contact.punch.friction=0.2",
            "analysis.newton.active_set=\"newton\"",
        ],
        &["friction against a moving obstacle", "active_set"],
    );
    // the same on an implicit integrator
    common::check_refuses_with(
        "models/steel_block_wall.toml",
        &[
            "analysis.integrator=average",
            "analysis.dt=1e-7",
            "obstacle.wall.motion={ displacement = [0.0, -6e-4] }",
            "contact.wall.friction=0.3",
            "analysis.newton.active_set=\"newton\"",
        ],
        &["friction against a moving obstacle", "active_set"],
    );
    common::check_refuses_with(
        "models/bar_wall.toml",
        &[
            "obstacle.wall.motion={ displacement = [-0.04, 0.0], curve = \"c\" }",
            "curve=[{ name = \"c\", points = [[0.0, 1.0], [1.0, 1.0]] }]",
        ],
        &["motion.curve", "at t = 0"],
    );
}
