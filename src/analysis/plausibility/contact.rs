//! What a finished run says of its contact pairs: a pair that never closed (and how its
//! slaves moved at the start), a penetration beyond the discretization's own, a slave that
//! went past the end of its obstacle.

use super::model_size;
use crate::analysis::steppers::energies::Energies;
use crate::analysis::{Status, Summary};
use crate::contact::penetration::{DeepestNode, PastEndNode};
use crate::contact::{ContactPair, ContactState, Master, penetration_limits};
use crate::output::readable;
use crate::scene::model::Analysis;
use crate::scene::{Body, Model};

/// A penetration deeper than this share of the slave node spacing warns: one-pass
/// node-to-segment contact lets master nodes into the slave body by a geometric error of
/// the discretization (a few per cent of an element at a curved tip: 3.8 % on round_bar),
/// and a body sinking into the other (the roles swapped: more than an element) is far
/// beyond it. Never below the pair's TOL.
pub const PENETRATION_SHARE: f64 = 0.05;

/// The warnings of the pairs that never closed, in a run where something moved (initial
/// kinetic energy or external work), with advice that follows how the run ended; not of a
/// body's pair with itself.
pub(super) fn never_closed_warnings(
    model: &Model,
    summary: &Summary,
    energies: &Energies,
) -> Vec<String> {
    let moved = summary.energy.initial > 0.0 || energies.external_work.abs() > 0.0;
    if !moved {
        return Vec::new();
    }
    summary
        .contact
        .never_closed
        .iter()
        .filter_map(|name| model.contacts.iter().find(|p| &p.name == name))
        // a body's pair with itself holds it where it folds; a body that did not fold needs
        // none (one that went through itself is warned of by `crossings`)
        .filter(|pair| pair.own.is_none())
        .map(|pair| never_closed_warning(model, pair, summary))
        .collect()
}

/// A penetration deeper than [`PENETRATION_SHARE`] of the slave node spacing (a lone
/// slave's element) and than the pairs' TOL, with where it was and its likely cause: a node
/// no pair holds (a slave set that misses the surface meeting the master, or, where the
/// end positions `end` show its body crossing itself, a node that came through the body's
/// own boundary), or a slave or master node of one-pass contact.
pub(super) fn penetration_warning(
    model: &Model,
    summary: &Summary,
    end: Option<&[[f64; 2]]>,
) -> Option<String> {
    let depth = summary.contact.max_penetration?;
    let coords = model.coordinates();
    let limits = penetration_limits(&model.contacts, &coords);
    // a pair with one slave (a rod's end) has no spacing: the length of its elements
    let spacing = model
        .contacts
        .iter()
        .zip(&limits)
        .map(|(pair, limit)| match pair.slaves.as_slice() {
            [single] => shortest_edge_at(model, &coords, *single),
            _ => 2.0 * limit,
        })
        .fold(f64::INFINITY, f64::min);
    let tolerance = model
        .contacts
        .iter()
        .map(|c| c.options.tolerance)
        .fold(0.0, f64::max);
    let share = if spacing.is_finite() {
        PENETRATION_SHARE * spacing
    } else {
        0.0
    };
    let bound = tolerance.max(share);
    if depth <= bound {
        return None;
    }
    // what checks both surfaces: a balanced pair under central difference; elsewhere one
    // pass is all there is
    let remedy = if model.is_explicit() {
        "a balanced pair, `roles = \"symmetric\"`, checks both surfaces: the default under \
         central difference; or refine both surfaces"
    } else {
        "the implicit and static paths take one pass (docs/theory.md 8.3d): refine the \
         surface that was entered where the other body's corners or finer nodes meet it, \
         or run central difference, whose balanced pair checks both surfaces"
    };
    let cause = match &summary.contact.deepest {
        Some(d) if !d.slave => unheld_node_cause(model, d, end),
        Some(d) => format!(
            "node {} of body `{}` (a slave) went {} into {} at t = {}: a slave node one-pass \
             contact did not hold, or a master node sinking into the slave body, which one-pass \
             contact does not see ({remedy})",
            d.node,
            d.body,
            readable(d.depth),
            d.into,
            readable(d.time)
        ),
        None => format!(
            "a master node sinking into the slave body is not seen by one-pass contact: \
             {remedy}"
        ),
    };
    Some(format!(
        "contact: a node went {} deep into the other body, beyond {} (the larger of TOL and {} % \
         of the slave node spacing, or of a lone slave's element); history.csv `penetration` \
         shows when; {cause}",
        readable(depth),
        readable(bound),
        100.0 * PENETRATION_SHARE
    ))
}

/// A slave that went past the open end of its obstacle (summary.json `contact.past_end`),
/// in words: the obstacle is shorter than the surface that meets it. The warning of a run
/// and a clause of a failure's message.
pub fn past_end_text(p: &PastEndNode) -> String {
    format!(
        "node {} of body `{}` (a slave of contact `{}`) went past the end ({}, {}) of obstacle \
         `{}` at t = {}, to ({}, {}): the obstacle is shorter than the surface that meets it, \
         and past its end a slave meets only its last segment's line extended and its corner; \
         extend the obstacle's points beyond where the body can reach",
        p.node,
        p.body,
        p.pair,
        readable(p.end[0]),
        readable(p.end[1]),
        p.obstacle,
        readable(p.time),
        readable(p.position[0]),
        readable(p.position[1])
    )
}

/// Why a node that no pair names as a slave went into an obstacle or a body: the pairs of
/// its body name slave sets that miss it; the sets of its body that hold it. Where its body
/// crosses itself at the end positions `end`, the node came through the body's own
/// boundary (a tube crushed flat: its inner face through the wall beneath it), which no
/// slave set mends: a pair of the body with itself does.
fn unheld_node_cause(model: &Model, d: &DeepestNode, end: Option<&[[f64; 2]]>) -> String {
    let Some((b, body)) = model
        .bodies
        .iter()
        .enumerate()
        .find(|(_, b)| b.name == d.body)
    else {
        return String::new();
    };
    if end.is_some_and(|x| super::crossings::passed_through_itself(body, x)) {
        return through_own_body_cause(d);
    }
    let global = body.global(d.node);
    let master_of = (model.contacts.iter()).find(|p| {
        matches!(&p.master, Master::Segments { body: m, edges, .. }
            if *m == b && edges.as_flattened().contains(&global))
    });
    if let Some(pair) = master_of {
        return master_node_cause(model, d, pair);
    }
    let named: Vec<String> = model
        .contacts
        .iter()
        .filter(|p| p.slave_body == b && p.covered.is_none() && !p.is_hold())
        .map(|p| match set_named_by(body, &p.slaves) {
            Some(set) => format!("`{set}` of pair `{}`", p.name),
            None => format!("the slaves of pair `{}`", p.name),
        })
        .collect();
    let mut holding: Vec<(&String, usize)> = body
        .mesh
        .node_sets
        .iter()
        .filter(|(name, nodes)| *name != "all" && nodes.contains(&d.node))
        .map(|(name, nodes)| (name, nodes.len()))
        .collect();
    holding.sort_by_key(|(_, len)| *len);
    let sets: Vec<String> = holding.iter().map(|(n, _)| format!("`{n}`")).collect();
    format!(
        "node {} of body `{}` went {} into {} at t = {}, and no contact pair names it as a \
         slave: nothing held it. The slave set ({}) misses the surface that meets the master; \
         make the slave set the body's surface there (the body's sets holding the node: {})",
        d.node,
        d.body,
        readable(d.depth),
        d.into,
        readable(d.time),
        if named.is_empty() {
            "none of this body".to_string()
        } else {
            named.join(", ")
        },
        if sets.is_empty() {
            "no set".to_string()
        } else {
            sets.join(", ")
        }
    )
}

/// The cause of `unheld_node_cause` for a master node of one-pass `pair`: one pass holds the
/// slave's nodes only, and what mends it depends on the path and on who chose the roles; a
/// master node its hold (`d.held`) let in even so.
fn master_node_cause(model: &Model, d: &DeepestNode, pair: &ContactPair) -> String {
    const BALANCED: &str = "leave `roles` out: under central difference the pair is then \
        balanced, each surface the slave of the other (docs/theory.md 8.3d)";
    const CHOSEN: &str = "leave `roles` out: the code then makes the shorter surface the slave, \
        whose ends the other's corners cannot enter (docs/theory.md 8.3d), or refine the slave \
        surface where this node meets it";
    const ALREADY: &str = "the code chose these roles (`impact check` says why): refine the \
        slave surface where this node meets it, or run central difference, whose balanced \
        pair checks both surfaces";
    const HELD: &str = "its row holds it where it enters the slave body \
        (`hold_master_nodes`, docs/theory.md 8.3a-4), and a row on a node does not keep a sharp \
        corner out of a finer surface that wraps it (a corner ploughing the slave, docs/\
        validation.md 4.15): round or refine the master surface at the corner, or run central \
        difference, whose balanced pair checks both surfaces";
    let went = format!(
        "node {} of body `{}` went {} into {} at t = {}: it is a master node of contact `{}`",
        d.node,
        d.body,
        readable(d.depth),
        d.into,
        readable(d.time),
        pair.name
    );
    if d.held {
        return format!("{went}; {HELD}");
    }
    let remedy = match (model.is_explicit(), pair.chosen_roles.is_some()) {
        (true, _) => BALANCED,
        (false, false) => CHOSEN,
        (false, true) => ALREADY,
    };
    format!(
        "{went}, and one pass holds the slave's nodes only, so a master node that enters the \
         slave body is not seen; {remedy}"
    )
}

/// The cause of `unheld_node_cause` for a node whose body crossed itself: it came through
/// the body's own boundary, and the body's pair with itself would hold it.
fn through_own_body_cause(d: &DeepestNode) -> String {
    let pair = format!(
        r#"slave = {{ body = "{0}" }}, master = {{ body = "{0}" }}"#,
        d.body
    );
    format!(
        "node {} of body `{}` went {} into {} at t = {}, and no contact pair names it as a \
         slave; the body's boundary crosses itself at the end (its own warning says where): \
         the node most likely came through the body's own boundary, which a slave set does \
         not mend; under central_difference a pair with the body as both slave and master \
         holds it ({pair})",
        d.node,
        d.body,
        readable(d.depth),
        d.into,
        readable(d.time)
    )
}

/// The node set of `body` that holds exactly the global nodes `slaves`, if one does.
fn set_named_by<'a>(body: &'a Body, slaves: &[usize]) -> Option<&'a str> {
    let mut wanted: Vec<usize> = slaves.iter().map(|n| n - body.node_offset).collect();
    wanted.sort_unstable();
    wanted.dedup();
    body.mesh.node_sets.iter().find_map(|(name, nodes)| {
        let mut nodes = nodes.clone();
        nodes.sort_unstable();
        nodes.dedup();
        (nodes == wanted).then_some(name.as_str())
    })
}

/// A contact closed on at most this many slave nodes at once (this many minus one segments
/// of the slave surface) warns when a body of the pair is plastic: fewer than about three
/// segments across a contact patch draw its pressure with one or two values, and the
/// plastic zone under it (a sphere of six elements on its half circle struck a wall at 27
/// times its yield velocity and dissipated nothing). Elastic contacts answer with the
/// force and the rebound, which coarse meshes still get (the shipped elastic rings close
/// two or three nodes).
pub const COARSE_CONTACT_NODES: usize = 3;

/// The pairs whose contact was resolved by too few slave nodes at its widest (see
/// [`COARSE_CONTACT_NODES`]): the pair's own slaves and those of its second pass, hold pair
/// or balanced reverse pass (nodes of the other surface held on it), counted together, and
/// judged under the pair's name.
pub(super) fn coarse_contact_warnings(model: &Model, summary: &Summary) -> Vec<String> {
    if summary.status != Status::Ok {
        // a run that stopped early had no contact to resolve yet
        return Vec::new();
    }
    let plastic = |b: usize| model.bodies[b].material.plasticity.is_some();
    let mut out = Vec::new();
    let widest = &summary.contact.closed_at_widest;
    for (p, pair) in model.contacts.iter().enumerate() {
        // the slaves of the pair's second pass, hold pair and reverse pass close on the
        // same contact
        let passes = model
            .contacts
            .iter()
            .enumerate()
            .filter(|(_, q)| {
                q.covered.as_ref().is_some_and(|c| c.pair == p) || q.balances == Some(p)
            })
            .map(|(q, _)| widest.get(q).copied().unwrap_or(0));
        let closed = &(widest.get(p).copied().unwrap_or(0) + passes.sum::<usize>());
        let master_plastic = match &pair.master {
            Master::Segments { body, .. } | Master::Nodes { body, .. } => plastic(*body),
            Master::Obstacle(_) => false,
        };
        // a hold pair, a second pass or a reverse pass takes its slaves from its first pass,
        // which is judged
        let derived = pair.is_hold() || pair.covered.is_some() || pair.balances.is_some();
        let surface = pair.slaves.len() > COARSE_CONTACT_NODES
            && !model.bodies[pair.slave_body].kind.is_rod()
            && !derived;
        if !surface
            || *closed == 0
            || *closed > COARSE_CONTACT_NODES
            || !(plastic(pair.slave_body) || master_plastic)
        {
            continue;
        }
        let unheld = summary
            .contact
            .deepest
            .as_ref()
            .is_some_and(|d| !d.slave && d.body == model.bodies[pair.slave_body].name);
        if unheld {
            // the penetration warning names the cause: a slave set that misses the surface
            continue;
        }
        let yielded = if summary.energy.plastic_dissipation > 0.0 {
            format!(
                "the plastic work {} rests on a contact pressure drawn by {closed} nodal value(s)",
                readable(summary.energy.plastic_dissipation)
            )
        } else {
            "no point yielded: the mesh cannot hold the contact's stress peak".to_string()
        };
        out.push(format!(
            "contact `{}` closed at most {closed} slave node(s) at once: it was resolved by {} \
             segment(s) of the slave surface at its widest, fewer than about {}, too coarse a \
             mesh where the bodies meet; {yielded}; refine the slave surface (and the master's) \
             there (more elements along it, or a grading towards the contact)",
            pair.name,
            closed - 1,
            COARSE_CONTACT_NODES
        ));
    }
    out
}

/// A pair closed at the end of a run whose slave body still approaches the master faster
/// than this share of its approach speed at the start: the impact the scene set up has not
/// ended (its rebound, a restitution read off the last row, are not the impact's).
pub const STILL_APPROACHING: f64 = 0.1;

/// The pairs closed at the end (`closed`) of a dynamic run while the slave body's centre of
/// mass still approaches the master's along the contact normal faster than
/// [`STILL_APPROACHING`] of its approach at the start; `end_velocity` and `mass` per DOF,
/// `positions` the final configuration.
pub(super) fn still_closed_warnings(
    model: &Model,
    closed: &[String],
    (positions, end_velocity, mass): (&[[f64; 2]], &[f64], &[f64]),
    contact: Option<&ContactState>,
) -> Vec<String> {
    let Analysis::Dynamic(d) = &model.analysis else {
        return Vec::new();
    };
    if mass.is_empty() {
        return Vec::new();
    }
    let coords = model.coordinates();
    let mut out = Vec::new();
    for pair in model.contacts.iter().filter(|p| closed.contains(&p.name)) {
        if pair.covered.is_some() || pair.is_hold() {
            continue;
        }
        // a projectile's flight at the start, and where the run has it at the end
        let at_start = ContactState::new(&[]);
        let at_start = (&at_start, 0.0);
        let start = approach(
            model,
            pair,
            (&coords, &model.initial_velocity, mass),
            at_start,
        );
        let at_end = (contact.unwrap_or(at_start.0), d.end_time);
        let end = approach(model, pair, (positions, end_velocity, mass), at_end);
        if let (Some(start), Some(end)) = (start, end)
            && start > 0.0
            && end > STILL_APPROACHING * start
        {
            out.push(format!(
                "contact `{}` is still closed at analysis.end_time = {}, and its slave body still \
                 moves towards the master at {} ({:.0} % of its approach speed {} at the start): \
                 the impact has not ended, so a rebound or a restitution read off the last row \
                 is not the impact's; lengthen analysis.end_time",
                pair.name,
                readable(d.end_time),
                readable(end),
                100.0 * end / start,
                readable(start)
            ));
        }
    }
    out
}

/// The speed at which the slave body's centre of mass approaches the master's (an
/// obstacle: its motion's velocity) along the master's normal at the slave nearest it, at
/// positions `x` with velocities `v` and masses `mass` per DOF at time `t` (None when no
/// slave has a master in reach).
fn approach(
    model: &Model,
    pair: &ContactPair,
    (x, v, mass): (&[[f64; 2]], &[f64], &[f64]),
    (contact, t): (&ContactState, f64),
) -> Option<f64> {
    let placed = contact.placed(std::slice::from_ref(pair), t);
    let pair = &placed[0];
    let nearest = pair
        .slaves
        .iter()
        .filter_map(|s| pair.node_gap(*s, &|n| x[n]))
        .min_by(|a, b| a.gap.total_cmp(&b.gap))?;
    let centre = |b: usize| -> [f64; 2] {
        let body = &model.bodies[b];
        let (mut p, mut m) = ([0.0; 2], 0.0);
        for n in (0..body.mesh.nodes.len()).map(|n| body.global(n)) {
            for c in 0..2 {
                p[c] += mass[2 * n + c] * v[2 * n + c];
            }
            m += mass[2 * n];
        }
        [p[0] / m, p[1] / m]
    };
    let slave = centre(pair.slave_body);
    let master = match &pair.master {
        Master::Segments { body, .. } | Master::Nodes { body, .. } => centre(*body),
        Master::Obstacle(o) => contact.obstacle_motion(o, t).1,
    };
    let n = nearest.normal;
    // the master's normal points out of it, towards the slave: approaching is -(v_s - v_m).n
    Some(-((slave[0] - master[0]) * n[0] + (slave[1] - master[1]) * n[1]))
}

/// A pair that never closed in a run where something moved, with the way its slaves moved
/// relative to the master at the start: the gap rate dg/dt of the slave nearest the master
/// under the initial velocities (a small advance of every node along its velocity, master
/// nodes included, so the rate is the relative one).
fn never_closed_warning(model: &Model, pair: &ContactPair, summary: &Summary) -> String {
    let coords = model.coordinates();
    let velocity = |n: usize| {
        [
            model.initial_velocity[2 * n],
            model.initial_velocity[2 * n + 1],
        ]
    };
    let speed = (0..model.node_count)
        .map(|n| velocity(n)[0].hypot(velocity(n)[1]))
        .fold(0.0, f64::max);
    let at = |x: &dyn Fn(usize) -> [f64; 2]| {
        pair.slaves
            .iter()
            .filter_map(|s| pair.gap(*s, x).map(|g| (*s, g.gap)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    };
    let start = at(&|n: usize| coords[n]);
    let name = &pair.name;
    if summary.status != Status::Ok {
        return format!(
            "contact `{name}` never closed, but the run stopped before its end time (status {}, \
             after {} step(s): {}): what failed, not the end time, kept the slaves off the \
             master; mend that first",
            summary.status.name(),
            summary.steps,
            summary
                .message
                .as_deref()
                .unwrap_or("see summary.json `message`")
        );
    }
    let Some((slave, gap)) = start else {
        return format!(
            "contact `{name}` never closed: no slave node came within its search distance of \
             the master at the start; check the pair's slave and master sets (or obstacle) and \
             where the bodies are"
        );
    };
    // an advance of a millionth of the gap (or of the model's size) along the velocities
    let size = model_size(&coords);
    let h = if speed > 0.0 {
        1e-6 * gap.abs().max(1e-3 * size) / speed
    } else {
        0.0
    };
    let rate = if h > 0.0 {
        pair.gap(slave, &|n: usize| {
            let v = velocity(n);
            [coords[n][0] + h * v[0], coords[n][1] + h * v[1]]
        })
        .map(|g| (g.gap - gap) / h)
        .unwrap_or(0.0)
    } else {
        0.0
    };
    if rate > 0.0 {
        format!(
            "contact `{name}` never closed: at the start its slaves move away from the master \
             (gap {} opening at {}): check the sign of the body's velocity (or which side of \
             the master the slaves are on)",
            readable(gap),
            readable(rate)
        )
    } else if rate < 0.0 && gap / -rate > summary.end_time {
        format!(
            "contact `{name}` never closed: its slaves approach the master at the start (gap {} \
             closing at {}) and would meet it at about t = {}, after analysis.end_time = {}; \
             lengthen analysis.end_time beyond it",
            readable(gap),
            readable(-rate),
            readable(gap / -rate),
            readable(summary.end_time)
        )
    } else if rate < 0.0 {
        format!(
            "contact `{name}` never closed although its slaves approach the master at the start \
             (gap {} closing at {}: they would meet at about t = {}, before analysis.end_time = \
             {}): they passed beside it, or something turned them away; check the pair's sets \
             and the master's extent",
            readable(gap),
            readable(-rate),
            readable(gap / -rate),
            readable(summary.end_time)
        )
    } else {
        format!(
            "contact `{name}` never closed (gap {} at the start, no initial motion towards or \
             away from the master): the loads never brought the slaves onto it; check the \
             loads, analysis.end_time and the pair's sets",
            readable(gap)
        )
    }
}

/// The shortest element edge that ends at global node `node`.
fn shortest_edge_at(model: &Model, coords: &[[f64; 2]], node: usize) -> f64 {
    let mut shortest = f64::INFINITY;
    for body in &model.bodies {
        for e in 0..body.elements() {
            let nodes: Vec<usize> = body
                .mesh
                .cells
                .nodes_of(e)
                .iter()
                .map(|n| body.global(*n))
                .collect();
            for (i, a) in nodes.iter().enumerate() {
                let b = nodes[(i + 1) % nodes.len()];
                if (*a == node || b == node) && *a != b {
                    let (p, q) = (coords[*a], coords[b]);
                    shortest = shortest.min((q[0] - p[0]).hypot(q[1] - p[1]));
                }
            }
        }
    }
    shortest
}
