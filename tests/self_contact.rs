//! A body's contact with itself: models/tube_crush.toml, a steel tube crushed flat against a
//! rigid wall until its inner face folds onto itself, held by a pair whose slave and master
//! are the tube's own boundary (docs/theory.md 8.3e; docs/validation.md 4.16).

mod common;

use impact::analysis::Status;
use impact::scene::Model;

/// How many pairs of the body's boundary edges cross each other by more than `depth` at
/// positions `x`, the edges that share a node left out: zero for a body that has not passed
/// through itself. Two segments cross when each one's ends lie on either side of the other's
/// line, each end farther than `depth` from it (faces pressed together touch within
/// round-off, which is no crossing). The test's own geometry, not the code's contact.
fn crossings(model: &Model, x: &[[f64; 2]], depth: f64) -> usize {
    let body = &model.bodies[0];
    let edges: Vec<[usize; 2]> = body
        .boundary
        .iter()
        .map(|e| e.map(|n| body.global(n)))
        .collect();
    // the signed distance of p from the line through a and b
    let side = |a: [f64; 2], b: [f64; 2], p: [f64; 2]| {
        ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]))
            / (b[0] - a[0]).hypot(b[1] - a[1])
    };
    let across = |s: f64, t: f64| s * t < 0.0 && s.abs().min(t.abs()) > depth;
    let mut count = 0;
    for (i, [a, b]) in edges.iter().enumerate() {
        for [c, d] in &edges[i + 1..] {
            if [c, d].iter().any(|n| *n == a || *n == b) {
                continue;
            }
            let (pa, pb, pc, pd) = (x[*a], x[*b], x[*c], x[*d]);
            if across(side(pa, pb, pc), side(pa, pb, pd))
                && across(side(pc, pd, pa), side(pc, pd, pb))
            {
                count += 1;
            }
        }
    }
    count
}

/// A crossing deeper than this counts (1 um, 0.2 % of the 0.5 mm element): faces pressed
/// together touch to round-off (the contact closes gaps to its TOL, 1e-9 of the model's
/// size), a wall passed through is crossed by its thickness.
const DEPTH: f64 = 1e-6;

/// The scene's text without the pair `fold` (the tube's contact with itself).
fn without_fold() -> String {
    let text = std::fs::read_to_string("models/tube_crush.toml").unwrap();
    let start = text.find("[[contact]]\nname = \"fold\"").unwrap();
    let end = text[start..].find("[analysis]").unwrap() + start;
    format!("{}{}", &text[..start], &text[end..])
}

/// Goal: a tube crushed flat does not pass through itself, and holding it there creates no
/// energy.
/// Setup: models/tube_crush.toml (2 x 120 quads, 200 m/s, 150 us: the walls meet at about
/// 90 us and stay pressed together to the end). Reference: geometry and conservation. The
/// deformed boundary of a body that has not passed through itself crosses itself nowhere
/// (counted by the test's own segment test, not by the contact); the pair `fold` may take
/// energy (the walls' impact is inelastic) but never give it: its contact work stays >= 0
/// at every row (round-off allowed: 1e-9 of the 9860 J brought in), and the balance gains
/// less than the guard's 1 % at every step. Penetration below 5 % of the 0.5 mm element.
/// summary.json names the pair as the scene does (`fold`, not its passes).
/// Without the pair the same run ends with the inner face through itself: the check fails
/// there, and the run's warnings say that the body passed through itself, and that the node
/// which went deepest into the wall came through the body's own boundary.
#[test]
fn a_tube_crushed_flat_does_not_pass_through_itself() {
    let text = std::fs::read_to_string("models/tube_crush.toml").unwrap();
    let model = common::model("tube_crush", &text, &[]);
    let (summary, state) = common::run("tube_crush", &model);
    let dir = common::out_dir_of("tube_crush");
    let least_fold_work = common::column(&dir, "contact_work[fold]")
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    let fold_force = common::column(&dir, "contact_force[fold]");
    let crossed = crossings(&model, &state.coordinates, DEPTH);
    println!(
        "fold: {:?}, {crossed} crossings, least fold work {least_fold_work:e}, peak fold force {:e}, \
         gain {:e}, penetration {:?}",
        summary.status,
        fold_force.iter().cloned().fold(0.0, f64::max),
        summary.energy.max_relative_gain,
        summary.contact.max_penetration
    );
    assert_eq!(summary.status, Status::Ok);
    // the fold must have closed, or the test says nothing
    assert!(fold_force.iter().any(|f| *f > 0.0));
    assert_eq!(crossed, 0);
    assert!(least_fold_work >= -1e-9 * summary.energy.initial);
    assert!(summary.energy.max_relative_gain < 0.01);
    assert!(summary.contact.max_penetration.unwrap_or(0.0) < 0.05 * 0.5e-3);
    // the pair is reported under its own name, its two passes as one: it closed, and the
    // walls are pressed together at the end (its force is not zero on the last row)
    assert!(summary.contact.never_closed.is_empty());
    assert!(*fold_force.last().unwrap() > 0.0);
    assert_eq!(summary.contact.closed_at_end, vec!["fold".to_string()]);

    let bare = common::model("tube_crush_without_fold", &without_fold(), &[]);
    let (bare_summary, state) = common::run("tube_crush_without_fold", &bare);
    let crossed = crossings(&bare, &state.coordinates, DEPTH);
    println!(
        "without the pair: {crossed} crossings, {} deeper than 0.1 mm",
        crossings(&bare, &state.coordinates, 1e-4)
    );
    assert!(crossed > 0);
    // and the run says so, naming the body and the pair that would hold it
    let warned = &bare_summary.warnings;
    assert!(
        warned
            .iter()
            .any(|w| w.contains("body `tube` passed through itself")
                && w.contains(r#"master = { body = "tube" }"#)),
        "{warned:?}"
    );
    // the inner node that went through the lower wall into the obstacle is named with that
    // cause, not with the advice for a slave set that misses the surface (which it gave
    // before: no slave set holds a node that comes through its own body)
    let penetration = warned
        .iter()
        .find(|w| w.starts_with("contact: a node went"))
        .expect("a penetration warning");
    assert!(
        penetration.contains("came through the body's own boundary")
            && !penetration.contains("make the slave set"),
        "{penetration}"
    );
}

/// Goal: a body's contact with itself is refused where it cannot run, with the reason.
/// Reference: the rules of the pair (theory 8.3e): balanced passes, central difference
/// only, an edge set as the master.
#[test]
fn a_body_against_itself_is_refused_where_it_cannot_run() {
    let scene = "models/tube_crush.toml";
    common::check_refuses_with(
        scene,
        &[r#"analysis.integrator="average""#, "analysis.dt=1e-7"],
        &["fold", "contact with itself", "central_difference"],
    );
    common::check_refuses_with(
        scene,
        &[r#"contact.fold.roles="as_written""#],
        &["fold", "contact with itself"],
    );
    common::check_refuses_with(
        scene,
        &["contact.fold.master.normal=[0.0, 1.0]"],
        &["fold", "not nodes with a normal"],
    );
}

/// Goal: a body's pair with itself is a precaution, not a contact that must happen: a run in
/// which the body does not fold is not warned that the pair never closed.
/// Setup: models/tube_crush.toml to 20 us, before the walls meet (about 90 us). Reference:
/// the pair's own history column, zero at every row (it never closed); no warning names it.
#[test]
fn a_body_that_does_not_fold_is_not_warned_of_its_own_pair() {
    let run = common::run_scene(
        "tube_crush_early",
        "tube_crush",
        &["analysis.end_time=20e-6"],
    );
    let fold_force = common::column(&run.dir, "contact_force[fold]");
    assert!(fold_force.iter().all(|f| *f == 0.0));
    assert_eq!(run.summary.contact.never_closed, vec!["fold".to_string()]);
    let named: Vec<&String> = run
        .summary
        .warnings
        .iter()
        .filter(|w| w.contains("`fold`"))
        .collect();
    assert!(named.is_empty(), "{named:?}");
}
