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
