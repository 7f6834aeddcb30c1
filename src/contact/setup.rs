//! Set-up checks of a contact pair on the initial configuration, and the penetration of the
//! master's nodes into the slave body during a run: the ways a pair can let two bodies pass
//! through each other while the run ends "ok" (a node-to-node normal the wrong way, an
//! obstacle whose solid is on the body's side, surfaces that face away from each other,
//! slaves that start inside their master, master nodes sinking into a slave body that a
//! one-pass search never looks at).

use super::geometry::{ContactPair, Master, inside_by_crossings, project};
use super::search::slave_gaps;
use crate::mesh::plane::{dot, sub};
use crate::output::readable;

/// What the checks need of the two bodies besides the pair's own nodes.
pub struct Bodies<'a> {
    /// Every node's position (global numbering).
    pub coords: &'a [[f64; 2]],
    /// A point inside the slave body (the mean of its element centroids) and, for a
    /// deformable master, inside the master body.
    pub slave_interior: [f64; 2],
    pub master_interior: Option<[f64; 2]>,
    /// The outward normal of the slave body's boundary at a node (the mean of its boundary
    /// edges' normals), None for rods.
    pub slave_normal: &'a dyn Fn(usize) -> Option<[f64; 2]>,
}

/// The first thing wrong with a pair's set-up, as a sentence naming the nodes and values.
pub fn setup_problem(pair: &ContactPair, bodies: &Bodies) -> Option<String> {
    direction_problem(pair, bodies)
        .or_else(|| penetration_problem(pair, bodies))
        .or_else(|| facing_problem(pair, bodies))
}

/// A node-to-node normal must point from the master body to the slave body; the slave body
/// must not lie on the solid side of an obstacle.
fn direction_problem(pair: &ContactPair, bodies: &Bodies) -> Option<String> {
    match &pair.master {
        Master::Nodes { normal, .. } => {
            let master = bodies.master_interior?;
            let side = dot(sub(bodies.slave_interior, master), *normal);
            (side <= 0.0).then(|| {
                format!(
                    "the node-to-node normal [{}, {}] points from the slave body into the \
                     master body (the gap is measured along it, so the bodies would pass \
                     through each other unseen): give the normal pointing from the master \
                     nodes towards the slaves",
                    normal[0], normal[1]
                )
            })
        }
        Master::Obstacle(o) => {
            let interior = usize::MAX;
            let x = |n: usize| {
                if n == interior {
                    bodies.slave_interior
                } else {
                    bodies.coords[n]
                }
            };
            let gap = pair.gap(interior, &x)?;
            (gap.gap < 0.0).then(|| {
                format!(
                    "the slave body lies on the solid side of obstacle `{}` (an obstacle is \
                     solid on the left of its points walked in order): reverse the order of \
                     its points",
                    o.name
                )
            })
        }
        Master::Segments { .. } => None,
    }
}

/// No slave may start inside its master beyond the pair's TOL.
fn penetration_problem(pair: &ContactPair, bodies: &Bodies) -> Option<String> {
    let x = |n: usize| bodies.coords[n];
    let tolerance = pair.options.tolerance;
    let pairs = std::slice::from_ref(pair);
    let inside: Vec<(usize, f64)> = slave_gaps(pairs, &x, &|_, _| false)
        .filter(|s| s.gap.gap < -tolerance)
        .map(|s| (s.node, s.gap.gap))
        .collect();
    let (node, gap) = inside.iter().copied().min_by(|a, b| a.1.total_cmp(&b.1))?;
    Some(format!(
        "{} slave node(s) start inside the master beyond TOL = {}, the deepest node {node} at \
         gap {}: move the bodies apart (or the obstacle)",
        inside.len(),
        readable(tolerance),
        readable(gap)
    ))
}

/// The slave nearest its master must face it: its outward normal against the master's. A
/// body's contact with itself takes only facing segments row by row (`OwnSurface::faces`).
fn facing_problem(pair: &ContactPair, bodies: &Bodies) -> Option<String> {
    if matches!(pair.master, Master::Nodes { .. }) || pair.own.is_some() {
        return None;
    }
    let x = |n: usize| bodies.coords[n];
    let pairs = std::slice::from_ref(pair);
    let nearest =
        slave_gaps(pairs, &x, &|_, _| false).min_by(|a, b| a.gap.gap.total_cmp(&b.gap.gap))?;
    let outward = (bodies.slave_normal)(nearest.node)?;
    let n = nearest.gap.normal;
    (dot(outward, n) > 0.0).then(|| {
        format!(
            "the slave surface faces away from its master: at node {}, the slave nearest the \
             master, the slave body's outward normal [{:.3}, {:.3}] points along the master's \
             [{:.3}, {:.3}] (the slave set should be the surface that meets the master)",
            nearest.node, outward[0], outward[1], n[0], n[1]
        )
    })
}

/// The deepest penetration of a deformable master's nodes into the slave body at the node
/// positions `x` (global numbering), whose boundary edges are `slave_boundary` (global
/// ids): for each master node inside that
/// boundary (an odd number of crossings of a ray), its distance to the nearest boundary edge.
/// Zero when none is inside. Only master nodes within the slave boundary's bounding box are tested.
/// Zero for a body's contact with itself: its master nodes lie on the slave body's outline
/// (at distance zero from it, and undecided by the crossing count), and its passes' own
/// gaps measure how deep a stretch went into another.
pub fn master_penetration(
    pair: &ContactPair,
    x: &impl Fn(usize) -> [f64; 2],
    slave_boundary: &[[usize; 2]],
) -> f64 {
    let Master::Segments { edges, .. } = &pair.master else {
        return 0.0;
    };
    if pair.own.is_some() {
        return 0.0;
    }
    let mut nodes: Vec<usize> = edges.iter().flatten().copied().collect();
    nodes.sort_unstable();
    nodes.dedup();
    deepest_inside(&nodes, x, slave_boundary)
}

/// The deepest pointwise penetration of a mortar pair's slave nodes into the master body at
/// the node positions `x`: each slave node's distance inside the nearest master segment it
/// projects onto (`mortar::nearest_projection`), which the weighted gaps hold only on
/// average over the slave segments. Zero for other pairs, whose slave gaps are pointwise
/// already.
pub fn slave_penetration(pair: &ContactPair, x: &impl Fn(usize) -> [f64; 2]) -> f64 {
    let Some((_, edges)) = pair.mortar() else {
        return 0.0;
    };
    pair.slaves
        .iter()
        .filter_map(|s| super::mortar::nearest_projection(edges, *s, x))
        .fold(0.0, |deepest, (distance, _, _)| deepest.max(-distance))
}

/// The deepest of `nodes` inside the body of boundary edges `boundary` (global ids, at
/// positions `x`): for each node inside (an odd number of crossings of a ray), its distance
/// to the nearest boundary edge; zero when none is inside. Only nodes within the boundary's
/// bounding box are tested.
fn deepest_inside(nodes: &[usize], x: &impl Fn(usize) -> [f64; 2], boundary: &[[usize; 2]]) -> f64 {
    let slave_boundary = boundary;
    if slave_boundary.is_empty() {
        return 0.0;
    }
    let segments: Vec<[[f64; 2]; 2]> = slave_boundary.iter().map(|[a, b]| [x(*a), x(*b)]).collect();
    // the bounding box by plain comparisons, the edges' start and end points in separate
    // lanes (independent chains of minima; they differ from `f64::min` only in the sign of
    // a zero bound, which the tests below ignore)
    let (mut low, mut high) = ([f64::INFINITY; 4], [f64::NEG_INFINITY; 4]);
    for [a, b] in &segments {
        let lanes = [a[0], a[1], b[0], b[1]];
        for j in 0..4 {
            low[j] = if lanes[j] < low[j] { lanes[j] } else { low[j] };
            high[j] = if lanes[j] > high[j] {
                lanes[j]
            } else {
                high[j]
            };
        }
    }
    let lo: [f64; 2] = std::array::from_fn(|c| {
        if low[c + 2] < low[c] {
            low[c + 2]
        } else {
            low[c]
        }
    });
    let hi: [f64; 2] = std::array::from_fn(|c| {
        if high[c + 2] > high[c] {
            high[c + 2]
        } else {
            high[c]
        }
    });
    let scale = (0..2)
        .map(|c| lo[c].abs().max(hi[c].abs()))
        .fold(0.0, f64::max);
    let mut deepest = 0.0f64;
    for &m in nodes {
        let p = x(m);
        let boxed = (0..2).all(|c| p[c] > lo[c] && p[c] < hi[c]);
        if !boxed || !inside_by_crossings(p, segments.iter().copied()) {
            continue;
        }
        deepest = deepest.max(distance_to_nearest(p, &segments, scale));
    }
    deepest
}

/// The distance from `p` to the nearest of `segments` (coordinates up to `scale` in
/// magnitude): the least `project` distance. A segment whose bounding box lies farther from
/// `p` than the nearest distance so far cannot be nearer and is not projected; the margin
/// of the skip covers the rounding of the projection (a few ulps of `scale`, far below
/// 1e-12 of it), so the least distance is the one the projection of every segment gives.
fn distance_to_nearest(p: [f64; 2], segments: &[[[f64; 2]; 2]], scale: f64) -> f64 {
    let margin = 1e-12 * scale;
    let mut nearest = f64::INFINITY;
    for [a, b] in segments {
        let outside = |lo: f64, hi: f64, v: f64| (lo - v).max(v - hi).max(0.0);
        let bx = outside(a[0].min(b[0]), a[0].max(b[0]), p[0]);
        let by = outside(a[1].min(b[1]), a[1].max(b[1]), p[1]);
        let reach = nearest * (1.0 + 1e-9) + margin;
        if bx * bx + by * by > reach * reach {
            continue;
        }
        nearest = nearest.min(project(p, *a, *b).1);
    }
    nearest
}
