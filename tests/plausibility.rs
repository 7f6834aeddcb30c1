//! No silent wrong answers: contact set-ups that would let bodies pass through each other are
//! refused at t = 0 by `check` and `run` alike (exit 2, the pair and the key named); a run
//! that ends with an implausible answer says so in summary.json `warnings` and on stderr,
//! and `--strict` turns a warning into exit 3. Each case ran "ok" and silent before.

mod common;

use common::{impact, out_dir};
use std::path::Path;

fn text(o: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// `check` and `run` of `scene` with `sets` both exit 2 with a message containing every
/// one of `words`.
fn refused(scene: &str, sets: &[&str], words: &[&str]) {
    let dir = out_dir(&format!("refused_{}", words[0].replace(' ', "_")));
    let mut args: Vec<String> = Vec::new();
    for s in sets {
        args.push("--set".into());
        args.push((*s).into());
    }
    let dir = dir.to_str().unwrap().to_string();
    for command in [
        vec!["check", scene],
        vec!["run", scene, "--quiet", "--out", &dir],
    ] {
        let mut all: Vec<&str> = command.clone();
        all.extend(args.iter().map(String::as_str));
        let o = impact(&all);
        let said = text(&o);
        assert_eq!(o.status.code(), Some(2), "{command:?}: {said}");
        for w in words {
            assert!(said.contains(w), "{command:?}: `{w}` not in {said}");
        }
    }
    assert!(
        !Path::new(&dir).join("summary.json").exists(),
        "a refused scene writes nothing"
    );
}

/// Goal: master and slave swapped on the two bars with the node-to-node normal left as it
/// was. Before: the bars passed through each other, peak force 0, min_gap +5e-4. Reference:
/// the normal must point from the master body to the slave body.
#[test]
fn a_node_to_node_normal_into_the_master_body_is_refused() {
    let swap = [
        "contact.bars.slave.body=bar2",
        "contact.bars.slave.set=start",
        "contact.bars.master.body=bar1",
        "contact.bars.master.set=end",
    ];
    refused(
        "models/two_bars.toml",
        &swap,
        &[
            "contact `bars`",
            "normal",
            "contact.bars.setup_check = false",
        ],
    );
    // the key that accepts it: the run goes through as before (and the bars pass)
    let dir = out_dir("swapped_accepted");
    let mut args = vec!["run", "models/two_bars.toml", "--quiet", "--out"];
    let d = dir.to_str().unwrap().to_string();
    args.push(&d);
    let sets: Vec<String> = swap
        .iter()
        .chain(&["contact.bars.setup_check=false"])
        .flat_map(|s| ["--set".to_string(), s.to_string()])
        .collect();
    args.extend(sets.iter().map(String::as_str));
    let o = impact(&args);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
}

/// Goal: an obstacle whose points run the other way (its solid on the bar's side). Before:
/// the bar fell through the wall, `check` valid, the run ok. The same wall 1 mm higher,
/// into the bar's tip (its slaves start penetrated): before, exit 3 with "non-positive
/// Jacobian" and nothing about the contact. Reference: the obstacle's solid lies on the left
/// of its points in order; y < 0 is the wall's solid, the bar above it.
#[test]
fn an_obstacle_the_wrong_way_round_and_slaves_starting_inside_are_refused() {
    refused(
        "models/round_bar_wall.toml",
        &["obstacle.wall.points=[[-0.03, 0.0], [0.03, 0.0]]"],
        &["contact `tip`", "solid side of obstacle `wall`", "reverse"],
    );
    refused(
        "models/round_bar_wall.toml",
        &["obstacle.wall.points=[[0.03, 0.001], [-0.03, 0.001]]"],
        &["contact `tip`", "start inside", "gap -0.001"],
    );
}

/// Goal: a slave set on the far side of its body (the bar's top instead of its tip) faces
/// away from the wall. Reference: the outward normal of the top edge is +y, the wall's
/// normal at its nearest point +y too.
#[test]
fn a_slave_surface_facing_away_from_its_master_is_refused() {
    refused(
        "models/round_bar_wall.toml",
        &["contact.tip.slave.set=top"],
        &["contact `tip`", "faces away"],
    );
}

/// Goal: roles swapped on the round bar striking the block (the block's top as the slave,
/// the bar's tip as the master). Before: the bar's nodes sank into the block by millimetres
/// (one-pass contact never looks at master nodes), min_gap -2.5e-12, status ok, silent.
/// Reference: the block top's node spacing is 5 mm (12 elements over 60 mm); a tip node
/// inside the block by more than 1 mm (a fifth of an element) is a body sinking, far beyond
/// the 5 % of the spacing the warning allows. The roles as the scene has them stay below it
/// (the geometric error of one-pass contact at the round tip: 0.1 mm, 3.8 % of the bar's
/// 2.5 mm spacing). `--strict` exits 3 on the warning with its output complete.
#[test]
fn a_master_sinking_into_the_slave_body_is_reported() {
    let swap = [
        "contact.tip.slave.body=block",
        "contact.tip.slave.set=top",
        "contact.tip.master.body=bar",
        "contact.tip.master.set=tip",
    ];
    let dir = out_dir("round_bar_swapped");
    let d = dir.to_str().unwrap().to_string();
    let mut args = vec![
        "run",
        "models/round_bar.toml",
        "--quiet",
        "--strict",
        "--out",
        &d,
    ];
    let sets: Vec<String> = swap
        .iter()
        .flat_map(|s| ["--set".to_string(), s.to_string()])
        .collect();
    args.extend(sets.iter().map(String::as_str));
    let o = impact(&args);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(
        text(&o).contains("warning: contact: a node went"),
        "{}",
        text(&o)
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "ok");
    let depth = summary["contact"]["max_penetration"].as_f64().unwrap();
    assert!(depth > 1e-3, "{depth}");
    assert!(summary["warnings"].as_array().unwrap().len() == 1);
    let penetration = common::column(&dir, "penetration");
    assert!(penetration.iter().copied().fold(0.0, f64::max) == depth);

    let dir = out_dir("round_bar_as_given");
    let d = dir.to_str().unwrap().to_string();
    let o = impact(&[
        "run",
        "models/round_bar.toml",
        "--quiet",
        "--strict",
        "--out",
        &d,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let depth = summary["contact"]["max_penetration"].as_f64().unwrap();
    assert!(depth < 0.05 * 2.5e-3, "{depth}");
    assert!(summary["warnings"].as_array().unwrap().is_empty());
}

/// A plane-strain J2 steel block (SI) dropped on a rigid wall at 20 m/s, Newmark average.
const BLOCK: &str = r#"
[[material]]
name = "steel"
young = 200.0e9
poisson = 0.3
density = 7850.0
yield_stress = 250.0e6
hardening_modulus = 1.0e9

[[body]]
name = "block"
material = "steel"
formulation = "plane_strain"
velocity = [0.0, -20.0]
mesh = { type = "rectangle", width = 0.05, height = 0.025, nx = 8, ny = 4 }

[[obstacle]]
name = "wall"
points = [[0.1, 0.0], [-0.05, 0.0]]

[[contact]]
name = "wall"
slave = { set = "bottom" }
obstacle = "wall"

[analysis]
type = "dynamic"
integrator = "average"
dt = 2.0e-7
end_time = 2.0e-5
"#;

/// Goal: an implicit step far too long for the impact, and one longer than the run.
/// Before: exit 0, ok, the step cuts only in summary.json. Reference: the block's elements
/// are 6.25 mm square and c = sqrt((lambda + 2 mu) / rho) = 5.8 km/s, so a wave crosses one
/// in 1.1 microseconds (the element bound puts the stable step at 0.89); the block is in
/// contact for some 9 microseconds. dt = 30 microseconds is longer than the 20-microsecond
/// run; dt = 10 microseconds is 11 stable steps and resolves the contact with one step.
/// dt = 0.2 microseconds (the scene's) warns of nothing.
#[test]
fn steps_too_long_for_the_run_or_the_impact_warn() {
    let scene = out_dir("block_scene").join("block.toml");
    std::fs::write(&scene, BLOCK).unwrap();
    for (dt, word) in [("3e-5", "longer than end_time"), ("1e-5", "contact lasted")] {
        let dir = out_dir(&format!("block_dt_{dt}"));
        let d = dir.to_str().unwrap().to_string();
        let set = format!("analysis.dt={dt}");
        let o = impact(&[
            "run",
            scene.to_str().unwrap(),
            "--quiet",
            "--out",
            &d,
            "--set",
            &set,
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
        assert!(text(&o).contains(word), "dt {dt}: {}", text(&o));
        let o = impact(&[
            "run",
            scene.to_str().unwrap(),
            "--quiet",
            "--strict",
            "--out",
            &d,
            "--set",
            &set,
        ]);
        assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    }
    let dir = out_dir("block_dt_fine");
    let d = dir.to_str().unwrap().to_string();
    let o = impact(&[
        "run",
        scene.to_str().unwrap(),
        "--quiet",
        "--strict",
        "--out",
        &d,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
}

const ROUND_BAR_SWAP: [&str; 5] = [
    "contact.tip.slave.body=block",
    "contact.tip.slave.set=top",
    "contact.tip.master.body=bar",
    "contact.tip.master.set=tip",
    "contact.tip.setup_check=false",
];

/// Goal: with two-pass contact the round bar's answer does not depend on which surface is
/// the slave. Setup: models/round_bar.toml with `two_pass = true`, roles as shipped and
/// swapped. Reference: the two runs describe the same problem, so they must agree within
/// what the discretization allows: the passes see the curved tip through different node
/// sets (the bar's 2.5 mm spacing, the block's 5 mm), so the contact impulse (the force
/// integrated over the impact, both passes) differs by up to 5 % (measured 4.0 %), the
/// tip displacement and the plastic work, integrals of the whole impact, by 1 % (measured
/// 0.4 % and 0.45 %). (The peak force, a maximum over a force that alternates from step to
/// step by 40 % under Newmark's average rule with either pass, is not compared: 22.9 and
/// 25.9.) Neither body sinks: the deepest node stays within 5 % of the smallest slave
/// spacing (3.9 mm along the bar's round tip), the warning's bound (measured 0.13 mm
/// swapped, against 2.7 mm with one pass), and no contact warning is raised (the second
/// pass costs Newton: 4 and 2 step cuts, warned).
#[test]
fn two_pass_round_bar_gives_the_same_answer_with_either_role_order() {
    let mut swapped_sets = ROUND_BAR_SWAP.to_vec();
    swapped_sets.push("contact.tip.two_pass=true");
    let a = common::run_scene("round_bar_2p", "round_bar", &["contact.tip.two_pass=true"]);
    let b = common::run_scene("round_bar_2p_swapped", "round_bar", &swapped_sets);
    let impulse = |dir: &Path| {
        let t = common::column(dir, "time");
        let forward = common::column(dir, "contact_force[tip]");
        let reverse = common::column(dir, "contact_force[tip:reverse]");
        let f: Vec<f64> = forward.iter().zip(&reverse).map(|(f, r)| f + r).collect();
        (1..t.len())
            .map(|i| 0.5 * (f[i] + f[i - 1]) * (t[i] - t[i - 1]))
            .sum::<f64>()
    };
    let tip = |dir: &Path| {
        common::column(dir, "u_y[bar.tip_node]")
            .into_iter()
            .fold(0.0, f64::min)
    };
    let plastic = |dir: &Path| *common::column(dir, "plastic_work").last().unwrap();
    approx::assert_relative_eq!(impulse(&a.dir), impulse(&b.dir), max_relative = 0.05);
    approx::assert_relative_eq!(tip(&a.dir), tip(&b.dir), max_relative = 0.01);
    approx::assert_relative_eq!(plastic(&a.dir), plastic(&b.dir), max_relative = 0.01);
    for s in [&a.summary, &b.summary] {
        let depth = s.contact.max_penetration.unwrap();
        assert!(depth < 0.05 * 3.9e-3, "{depth}");
        assert!(
            !s.warnings.iter().any(|w| w.starts_with("contact")),
            "{:?}",
            s.warnings
        );
    }
}

/// Goal: two-pass contact between deformable rings. Setup: models/three_rings.toml, one
/// pass as shipped, and two-pass on both pairs with the roles as shipped and swapped.
/// Reference: with two passes each pair of rings is constrained both ways whatever the
/// roles, so the two role orders solve the same constraints (1e-9 relative: round-off of a
/// different row order) and no node of either ring ends a step inside the other beyond TOL
/// (1e-9 of the model size, about 1e-8); with one pass the master rings' nodes sink into
/// the slave rings by millimetres (measured 2.7e-3), which is what the second pass removes.
#[test]
fn two_pass_rings_do_not_depend_on_the_roles_and_do_not_sink() {
    let both = ["contact.ab.two_pass=true", "contact.bc.two_pass=true"];
    let swap = [
        "contact.ab.slave.body=a",
        "contact.ab.master.body=b",
        "contact.bc.slave.body=b",
        "contact.bc.master.body=c",
        "contact.ab.setup_check=false",
        "contact.bc.setup_check=false",
    ];
    let one = common::run_scene("rings_one_pass", "three_rings", &[]).summary;
    assert!(one.contact.max_penetration.unwrap() > 1e-3);
    let a = common::run_scene("rings_2p", "three_rings", &both).summary;
    let swapped: Vec<&str> = swap.iter().chain(&both).copied().collect();
    let b = common::run_scene("rings_2p_swapped", "three_rings", &swapped).summary;
    approx::assert_relative_eq!(
        a.contact.peak_force,
        b.contact.peak_force,
        max_relative = 1e-9
    );
    approx::assert_relative_eq!(a.energy.final_, b.energy.final_, max_relative = 1e-9);
    for s in [&a, &b] {
        assert!(s.contact.max_penetration.unwrap() < 1e-8);
    }
}

/// Goal: two-pass needs a surface on both sides: against an obstacle it is refused, exit 2
/// naming the key.
#[test]
fn two_pass_against_an_obstacle_is_refused() {
    refused(
        "models/bar_wall.toml",
        &["contact.wall.two_pass=true"],
        &["two_pass", "contact[0]"],
    );
}
