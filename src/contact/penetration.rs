//! How deep any body has gone into an obstacle or into another body, whichever nodes the
//! pairs name as slaves: every boundary node of every body (every node of a rod) is tested
//! against every obstacle of the pairs and every other body's outline. The pairs' own gaps
//! see only their slaves; a slave set that misses the surface which meets the master (a
//! sphere's `axis` instead of its `arc`) lets the other nodes through unseen, and this
//! measure reports them. Beside it, the first slave that went past the open end of its
//! obstacle (an obstacle shorter than the surface that meets it: a Taylor rod's foot growing
//! beyond a short wall), which the run reports when it happens.
//!
//! Legend
//! ```text
//! depth    of a node inside an obstacle's solid or another body: its distance to the
//!          nearest segment of that obstacle or outline (0 outside)
//! open     polyline: the boundary of a half-space, solid on its left; a node whose nearest
//!          point is an open end lies beyond the polyline, not in it
//! closed   polyline: solid inside a counter-clockwise loop, outside a clockwise one (a cavity)
//! ```

use super::Interfaces;
use super::geometry::{Master, Obstacle, inside_by_crossings, project};
use crate::mesh::plane::{dot, outward, sub};

/// What a node went into.
#[derive(Debug, Clone, PartialEq)]
pub enum Intruded {
    /// The obstacle of that name.
    Obstacle(String),
    /// The body of that index.
    Body(usize),
}

/// The deepest node inside an obstacle or another body.
#[derive(Debug, Clone, PartialEq)]
pub struct Deepest {
    pub depth: f64,
    /// The global node and its body.
    pub node: usize,
    pub body: usize,
    pub into: Intruded,
}

/// summary.json `contact.deepest`: where the deepest penetration of a body's node into an
/// obstacle or another body was, in words.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DeepestNode {
    pub depth: f64,
    /// The end of the step after which it was that deep.
    pub time: f64,
    pub body: String,
    /// The node's number in its body, from 0.
    pub node: usize,
    /// What it went into: "obstacle `NAME`" or "body `NAME`".
    pub into: String,
    /// Whether a contact pair names the node as a slave (a hold pair's slaves, the master
    /// nodes it holds, are not).
    pub slave: bool,
    /// Whether the node is a master node that a mortar pair holds where it enters the slave
    /// body (`hold_master_nodes` on the implicit paths, docs/theory.md 8.3a-4).
    #[serde(default)]
    pub held: bool,
}

/// The deepest penetration of any body's node into an obstacle of `interfaces`' pairs or
/// into another body at the positions `x`, 0 when none is inside.
pub fn deepest_depth(interfaces: &Interfaces, x: &impl Fn(usize) -> [f64; 2]) -> f64 {
    deepest(interfaces, x).map_or(0.0, |d| d.depth)
}

/// The deepest node inside an obstacle of `interfaces`' pairs or inside another body at the
/// positions `x` (None when none is inside).
pub fn deepest(interfaces: &Interfaces, x: &impl Fn(usize) -> [f64; 2]) -> Option<Deepest> {
    let mut obstacles: Vec<&Obstacle> = Vec::new();
    for pair in &interfaces.pairs {
        if let Master::Obstacle(o) = &pair.master
            && !obstacles.iter().any(|known| known.name == o.name)
        {
            obstacles.push(o);
        }
    }
    let mut best: Option<Deepest> = None;
    let mut consider = |candidate: Option<(f64, usize)>, body: usize, into: Intruded| {
        if let Some((depth, node)) = candidate
            && best.as_ref().is_none_or(|b| depth > b.depth)
        {
            best = Some(Deepest {
                depth,
                node,
                body,
                into,
            });
        }
    };
    for body in 0..interfaces.bodies.len() {
        let nodes = || interfaces.bodies[body].boundary_nodes().iter().copied();
        for obstacle in &obstacles {
            let found = deepest_in_obstacle(nodes(), x, obstacle);
            consider(found, body, Intruded::Obstacle(obstacle.name.clone()));
        }
        for (other, surface) in interfaces.bodies.iter().enumerate() {
            if other != body && !surface.boundary.is_empty() {
                let found = deepest_in_outline(nodes(), x, &surface.boundary);
                consider(found, body, Intruded::Body(other));
            }
        }
    }
    best
}

/// A slave past the open end of its pair's obstacle (`past_an_end`).
#[derive(Debug, Clone, PartialEq)]
pub struct PastEnd {
    /// The pair (its index).
    pub pair: usize,
    /// The global node.
    pub node: usize,
    /// The end of the obstacle it went past.
    pub end: [f64; 2],
}

/// summary.json `contact.past_end`: the first slave that went past the open end of its
/// obstacle, in words.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PastEndNode {
    /// The end of the step after which it was found there.
    pub time: f64,
    pub pair: String,
    pub obstacle: String,
    pub body: String,
    /// The node's number in its body, from 0.
    pub node: usize,
    /// Where the node was, and the end of the obstacle.
    pub position: [f64; 2],
    pub end: [f64; 2],
}

/// The first slave of `interfaces`' pairs (in pair order, then slave order) at the positions
/// `x` that lies past an open end of its pair's obstacle: its nearest point on the polyline
/// is that end, it lies beyond the end along the end segment, and it is below the end
/// segment's line extended or less than 45 degrees above it (where a longer obstacle would
/// meet it). None while every slave is over its obstacle. Closed obstacles have no ends.
pub fn past_an_end(interfaces: &Interfaces, x: &impl Fn(usize) -> [f64; 2]) -> Option<PastEnd> {
    for (index, pair) in interfaces.pairs.iter().enumerate() {
        let Master::Obstacle(obstacle) = &pair.master else {
            continue;
        };
        if obstacle.closed || obstacle.points.len() < 2 {
            continue;
        }
        let segments = obstacle.segments();
        let last = segments.len() - 1;
        for &node in &pair.slaves {
            let p = x(node);
            let Some((k, xi, _)) = nearest_segment(p, &segments) else {
                continue;
            };
            let [a, b] = segments[k];
            // the end, and the direction beyond it along its segment
            let (end, onward) = match (k, xi) {
                (0, xi) if xi <= 0.0 => (a, sub(a, b)),
                (k, xi) if k == last && xi >= 1.0 => (b, sub(b, a)),
                _ => continue,
            };
            let length = dot(onward, onward).sqrt();
            if length == 0.0 {
                continue;
            }
            let beyond = dot(sub(p, end), onward) / length;
            let above = dot(sub(p, end), outward(a, b));
            if beyond > 0.0 && above <= beyond {
                return Some(PastEnd {
                    pair: index,
                    node,
                    end,
                });
            }
        }
    }
    None
}

/// The segment of `segments` nearest to `p`: (index, projection parameter, distance).
fn nearest_segment(p: [f64; 2], segments: &[[[f64; 2]; 2]]) -> Option<(usize, f64, f64)> {
    (segments.iter().enumerate())
        .map(|(k, [a, b])| {
            let (xi, d) = project(p, *a, *b);
            (k, xi, d)
        })
        .min_by(|a, b| a.2.total_cmp(&b.2))
}

/// The deepest of `nodes` inside the solid of `obstacle` (depth, node).
fn deepest_in_obstacle(
    nodes: impl Iterator<Item = usize>,
    x: &impl Fn(usize) -> [f64; 2],
    obstacle: &Obstacle,
) -> Option<(f64, usize)> {
    let segments = obstacle.segments();
    let cavity = obstacle.is_cavity();
    let last = segments.len() - 1;
    let mut best: Option<(f64, usize)> = None;
    for node in nodes {
        let p = x(node);
        let (k, xi, distance) = nearest_segment(p, &segments)?;
        let inside = if obstacle.closed {
            inside_by_crossings(p, segments.iter().copied()) != cavity
        } else {
            let beyond_end = (k == 0 && xi <= 0.0) || (k == last && xi >= 1.0);
            let [a, b] = segments[k];
            !beyond_end && dot(sub(p, a), outward(a, b)) < 0.0
        };
        if inside && distance > 0.0 && best.is_none_or(|(d, _)| distance > d) {
            best = Some((distance, node));
        }
    }
    best
}

/// The deepest of `nodes` inside the closed outline `boundary` (global ids) of another body
/// (depth, node); only nodes within the outline's bounding box are tested.
fn deepest_in_outline(
    nodes: impl Iterator<Item = usize>,
    x: &impl Fn(usize) -> [f64; 2],
    boundary: &[[usize; 2]],
) -> Option<(f64, usize)> {
    let segments: Vec<[[f64; 2]; 2]> = boundary.iter().map(|[a, b]| [x(*a), x(*b)]).collect();
    let (mut low, mut high) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in segments.iter().flatten() {
        for c in 0..2 {
            low[c] = low[c].min(p[c]);
            high[c] = high[c].max(p[c]);
        }
    }
    let mut best: Option<(f64, usize)> = None;
    for node in nodes {
        let p = x(node);
        let boxed = (0..2).all(|c| p[c] > low[c] && p[c] < high[c]);
        if !boxed || !inside_by_crossings(p, segments.iter().copied()) {
            continue;
        }
        let distance = segments
            .iter()
            .map(|[a, b]| project(p, *a, *b).1)
            .fold(f64::INFINITY, f64::min);
        if distance > 0.0 && best.is_none_or(|(d, _)| distance > d) {
            best = Some((distance, node));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{BodySurface, Section};

    /// A unit square body's outline (nodes 0..4, counter-clockwise), as global node ids from
    /// `offset`.
    fn square(offset: usize) -> BodySurface {
        let n = |k: usize| offset + k;
        let boundary = vec![[n(0), n(1)], [n(1), n(2)], [n(2), n(3)], [n(3), n(0)]];
        let at_node = (0..4)
            .map(|k| vec![boundary[(k + 3) % 4], boundary[k]])
            .collect();
        BodySurface::new(
            (Section::Plane { thickness: 1.0 }, 1.0),
            at_node,
            boundary,
            offset,
        )
    }

    /// The unit square (nodes 0..4) and the wall y = 0 from x = 2 to x = -2 (solid below),
    /// node 0 its pair's slave.
    fn square_on_a_wall() -> Interfaces {
        let wall = Obstacle {
            name: "wall".into(),
            points: vec![[2.0, 0.0], [-2.0, 0.0]],
            closed: false,
            motion: None,
            projectile: None,
        };
        let pair = crate::contact::geometry::tests::slave_node_0(Master::Obstacle(wall));
        Interfaces {
            pairs: vec![pair],
            bodies: vec![square(0)],
        }
    }

    /// Goal: a body through a wall is measured from every boundary node, not only the
    /// slaves. Setup: a unit square [0, 1] x [-0.3, 0.7] against the wall y = 0 (solid below:
    /// points run from x = 2 to x = -2), no slaves at all. Reference: its two lower corners
    /// are 0.3 deep (by hand); above the wall, nothing.
    #[test]
    fn a_body_through_a_wall_is_never_zero() {
        let points = [[0.0, -0.3], [1.0, -0.3], [1.0, 0.7], [0.0, 0.7]];
        let interfaces = square_on_a_wall();
        let deepest = deepest(&interfaces, &|n| points[n]).unwrap();
        assert!((deepest.depth - 0.3).abs() < 1e-15, "{deepest:?}");
        assert_eq!(deepest.into, Intruded::Obstacle("wall".into()));
        let lifted = |n: usize| [points[n][0], points[n][1] + 0.31];
        assert_eq!(deepest_depth(&interfaces, &lifted), 0.0);
        // beyond the wall's open end the half-space is not the wall's
        let aside = |n: usize| [points[n][0] + 2.5, points[n][1]];
        assert_eq!(deepest_depth(&interfaces, &aside), 0.0);
    }

    /// Goal: a body inside another is measured. Setup: two unit squares, the second moved
    /// by (0.6, 0.2) into the first (no pair between them), so it spans [0.6, 1.6] x
    /// [0.2, 1.2]. Reference (by hand): its corner (0.6, 0.2) lies 0.2 above the first's
    /// bottom edge (0.4 from its right edge), and the first's corner (1, 1) 0.2 below the
    /// second's top: depth 0.2.
    #[test]
    fn a_body_inside_another_is_measured() {
        let unit = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let x = |n: usize| {
            let p = unit[n % 4];
            if n < 4 { p } else { [p[0] + 0.6, p[1] + 0.2] }
        };
        let interfaces = Interfaces {
            pairs: Vec::new(),
            bodies: vec![square(0), square(4)],
        };
        let deepest = deepest(&interfaces, &x).unwrap();
        assert!((deepest.depth - 0.2).abs() < 1e-15, "{deepest:?}");
    }

    /// Goal: a slave past the open end of its wall is found, and only there. Setup: the wall
    /// y = 0 from x = 2 to x = -2 (solid below), one slave node (node 0). Reference (by
    /// hand): over the wall (x = 1.9, on it or above) nothing; at x = 2.1 on the line, or
    /// 0.05 below it, past the end (2, 0); at x = -2.1, 0.05 above the line (less than 45
    /// degrees from it), past the end (-2, 0); at x = 2.1 and 0.2 above (more than 45
    /// degrees), nothing: a node beside the end, not one that slid off it.
    #[test]
    fn a_slave_past_the_end_of_its_wall_is_found() {
        let interfaces = square_on_a_wall();
        let at = |p: [f64; 2]| past_an_end(&interfaces, &|_| p).map(|e| e.end);
        assert_eq!(at([1.9, 0.0]), None);
        assert_eq!(at([1.9, 0.3]), None);
        assert_eq!(at([2.1, 0.0]), Some([2.0, 0.0]));
        assert_eq!(at([2.1, -0.05]), Some([2.0, 0.0]));
        assert_eq!(at([-2.1, 0.05]), Some([-2.0, 0.0]));
        assert_eq!(at([2.1, 0.2]), None);
    }
}
