//! Surfaces, detection and the constraint rows of a slave (Hughes et al. 1975, section II;
//! Greco & Coda 2003, section 2). The solver owns the system; this file only says where the
//! slaves are, how far from their masters, and along which direction (legend in `contact`).

use super::grid::SegmentGrid;
use super::mortar::{MortarSurface, master_node_gap, weighted_gap};
use super::own::OwnSurface;
use crate::curve::Curve;
use crate::mesh::plane::{dot, outward, sub};

pub use super::gap::Gap;
pub use super::projectile::Projectile;
use std::f64::consts::PI;

/// A rigid obstacle: a polyline, solid on its left (a closed counter-clockwise polygon is a
/// finite obstacle, a clockwise one a cavity, an open polyline a half-space boundary). Its
/// `points` are where it is now: a moving obstacle's are placed at each time a step reads
/// (`place`); the gaps read the points only.
#[derive(Debug, Clone, PartialEq)]
pub struct Obstacle {
    pub name: String,
    pub points: Vec<[f64; 2]>,
    pub closed: bool,
    /// A prescribed rigid translation; None: the obstacle stays where it was put.
    pub motion: Option<ObstacleMotion>,
    /// A rigid body of its own that the contact forces alone move (a projectile); None: the
    /// obstacle is fixed or prescribed.
    pub projectile: Option<Projectile>,
}

/// The prescribed translation of an obstacle: its points at time t are `base` +
/// `displacement` times `curve`(t) (the curve 0 at t = 0).
#[derive(Debug, Clone, PartialEq)]
pub struct ObstacleMotion {
    pub base: Vec<[f64; 2]>,
    pub displacement: [f64; 2],
    pub curve: Curve,
    /// The time `Obstacle::place` last put the points at (0 until then).
    pub placed: f64,
}

impl ObstacleMotion {
    /// The translation at time `t`.
    pub fn at(&self, t: f64) -> [f64; 2] {
        let f = self.curve.value(t);
        [f * self.displacement[0], f * self.displacement[1]]
    }

    /// The velocity at time `t` (`Curve::slope`).
    pub fn velocity(&self, t: f64) -> [f64; 2] {
        let f = self.curve.slope(t);
        [f * self.displacement[0], f * self.displacement[1]]
    }
}

impl Obstacle {
    /// Moves a moving obstacle's points to where its motion has it at time `t`.
    pub fn place(&mut self, t: f64) {
        if let Some(m) = &mut self.motion {
            m.placed = t;
            let d = m.at(t);
            for (p, b) in self.points.iter_mut().zip(&m.base) {
                *p = [b[0] + d[0], b[1] + d[1]];
            }
        }
    }

    /// Moves a projectile's points to translation `u` and rotation `theta` from its base.
    pub fn place_at(&mut self, u: [f64; 2], theta: f64) {
        if let Some(p) = &self.projectile {
            for (x, b) in self.points.iter_mut().zip(&p.base) {
                *x = p.placed(*b, u, theta);
            }
        }
    }

    /// Whether a closed polygon runs clockwise (a cavity: its solid lies outside the loop).
    pub fn is_cavity(&self) -> bool {
        let n = self.points.len();
        let area: f64 = (0..n)
            .map(|i| {
                let (a, b) = (self.points[i], self.points[(i + 1) % n]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum();
        self.closed && area < 0.0
    }

    pub fn segments(&self) -> Vec<[[f64; 2]; 2]> {
        let n = self.points.len();
        let count = if self.closed { n } else { n - 1 };
        (0..count)
            .map(|i| [self.points[i], self.points[(i + 1) % n]])
            .collect()
    }
}

/// What the slaves of a pair meet.
#[derive(Debug, Clone, PartialEq)]
pub enum Master {
    /// Boundary edges of a deformable body (global node ids), and the body's whole boundary
    /// for the inside test.
    Segments {
        body: usize,
        edges: Vec<[usize; 2]>,
        boundary: Vec<[usize; 2]>,
    },
    /// Node-to-node: each slave meets its nearest master node along a fixed master normal.
    Nodes {
        body: usize,
        nodes: Vec<usize>,
        normal: [f64; 2],
    },
    /// A rigid obstacle.
    Obstacle(Obstacle),
}

/// How a pair behaves; every switch of the source documents is here so its effect can be shown.
#[derive(Debug, Clone, PartialEq)]
pub struct PairOptions {
    /// Hughes II-8 when a pair closes (dynamics).
    pub impact_conditions: bool,
    /// Hughes II-11, II-12 when a pair opens (dynamics).
    pub release_conditions: bool,
    /// Release when tau falls below this fraction of the last step's value (Hughes: 0.02).
    pub release_fraction: f64,
    /// TOL of Hughes II-7 (length).
    pub tolerance: f64,
    /// Slaves farther than this from the master are not candidates (length).
    pub search_distance: f64,
    /// Split a step (or load increment) at the first contact event inside it.
    pub split_at_events: bool,
    /// The tangential law of the interface.
    pub friction: Friction,
    /// Velocity-level persistency (implicit dynamics): a closed pair may keep the small gap
    /// it closed with, so an open slave that starts inside its master counts as penetrating
    /// only when it goes deeper.
    pub persistency: bool,
    /// The geometry of a balanced pair's passes (`ContactPair::node_gap`), where every node
    /// of both surfaces is a slave: (1) a slave beyond the end of its master surface and
    /// outside the master body gets its distance from that end, not its distance along the
    /// surface's extension (those beside the other body must not read its face extended);
    /// (2) the row's normal is the master segment's own, the gradient of the gap (the signed
    /// distance to the master polygon), so the contact force does no work on a slave sliding
    /// along a closed contact (docs/theory.md 8.3d). One-pass pairs keep the extension and
    /// the normal interpolated between the master nodes' normals, with which the seeds'
    /// scenes were validated.
    pub balanced: bool,
}

/// The tangential law of a contact pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Friction {
    /// No tangential force.
    None,
    /// Coulomb: stick (a tangential Lagrange multiplier) while |t| <= mu tau, else slide with
    /// |t| = mu tau against the slip.
    Coulomb { mu: f64 },
    /// Greco's geometric return (eq 36): the slide of each step is (1 - R) times the slide
    /// the step would have without friction (R = 0 frictionless, R = 1 adherence).
    Return { r: f64 },
}

/// A validated contact pair.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPair {
    pub name: String,
    pub slave_body: usize,
    /// Global node ids.
    pub slaves: Vec<usize>,
    pub master: Master,
    pub options: PairOptions,
    /// The second pass of a two-pass contact: the first pass (its pair index) and its slave
    /// nodes with their indices there, sorted by node. A slave whose nearest master point lies
    /// on one of them (weight >= COVERED) while that one is closed does not close: the first
    /// pass's row for that node would be the same row again (coincident nodes), and the two
    /// rows would make the multipliers indeterminate.
    pub covered: Option<Covered>,
    /// How the pair's rows are written: node-to-segment, mortar, or a mortar pair's hold.
    pub discretization: Discretization,
    /// The second pass of a balanced pair (`NAME:reverse`, the index of its first pass): the
    /// first pass's master surface as the slave of its slave surface. The explicit
    /// correction solves each pass on its own and applies the mean of the two corrections
    /// (`explicit`); None otherwise.
    pub balances: Option<usize>,
    /// A pass of a body's contact with itself (`own`): which of its own segments a slave
    /// may meet and on which side of them it is inside; None between two bodies.
    pub own: Option<OwnSurface>,
    /// Why the pair has its roles, where the code chose them (a one-pass pair between two
    /// bodies whose scene names none: `impact check` says it); None where the scene's roles
    /// stand.
    pub chosen_roles: Option<String>,
}

/// How a pair's gaps and rows are written (docs/theory.md 8.3, 8.3a). The passes of a
/// two-pass or balanced contact are pairs of their own, each with its discretization.
#[derive(Debug, Clone, PartialEq)]
pub enum Discretization {
    /// Each slave node against the master (a segment, a node-to-node master, an obstacle).
    NodeToSegment,
    /// Segment-to-segment: the slave surface whose segments carry the weighted gaps
    /// (`mortar`); the master is an edge set.
    Mortar(MortarSurface),
    /// The hold pair of a mortar pair on the implicit paths (`NAME:held`): its slaves are
    /// the mortar pair's master nodes and its master the mortar pair's slave surface, and a
    /// slave's gap is `mortar::master_node_gap` (docs/theory.md 8.3a-4).
    Held(Holds),
}

/// See [`Discretization::Held`].
#[derive(Debug, Clone, PartialEq)]
pub struct Holds {
    /// The held mortar pair's master edges (the nodes' own normals); the pair itself is the
    /// first pass of `ContactPair::covered`.
    pub master_edges: Vec<[usize; 2]>,
}

/// See [`ContactPair::covered`].
pub const COVERED: f64 = 0.9;

/// The first pass of a two-pass contact, as its second pass sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct Covered {
    pub pair: usize,
    /// (global node, slave index in the first pass), sorted by node.
    pub slaves: Vec<(usize, usize)>,
}

/// |a| as sqrt(a . a) (the gaps' own rounding; `plane::norm` uses hypot).
fn length(a: [f64; 2]) -> f64 {
    dot(a, a).sqrt()
}

/// Greco eq 17: c(S) = -1/(2 pi) sum over the segments [A, B] of the angle increment
/// phi_B - phi_A seen from S (wrapped into (-pi, pi]); segments run with the solid on their
/// left, so a point inside a counter-clockwise boundary gets 1. A point on a segment gets
/// 1/2 and a point on a corner alpha / (2 pi).
pub fn winding_number(s: [f64; 2], segments: &[[[f64; 2]; 2]]) -> f64 {
    let mut total = 0.0;
    for [a, b] in segments {
        let (ra, rb) = (sub(*a, s), sub(*b, s));
        if length(ra) == 0.0 || length(rb) == 0.0 {
            continue; // S on a node: the two adjacent segments give the corner angle
        }
        let mut delta = rb[1].atan2(rb[0]) - ra[1].atan2(ra[0]);
        if delta > PI {
            delta -= 2.0 * PI;
        } else if delta <= -PI {
            delta += 2.0 * PI;
        }
        // S on the segment itself sees it under +-pi: it contributes nothing, the rest of the
        // boundary sums to the half turn
        if (delta.abs() - PI).abs() < 1e-12 {
            continue;
        }
        total += delta;
    }
    // counter-clockwise boundaries sum to +2 pi around interior points
    total / (2.0 * PI)
}

/// Whether `s` lies inside the closed boundary `segments` (any orientation, holes
/// included): an odd number of the boundary's crossings of the ray from `s` along +x. For a
/// point off the boundary this is `winding_number(s) > 0.5` without its two arc tangents a
/// segment, which made the inside test the costliest part of a contact search.
pub(super) fn inside_by_crossings(
    s: [f64; 2],
    segments: impl Iterator<Item = [[f64; 2]; 2]>,
) -> bool {
    let mut inside = false;
    for [a, b] in segments {
        if (a[1] > s[1]) != (b[1] > s[1]) {
            let crossing = a[0] + (s[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if s[0] < crossing {
                inside = !inside;
            }
        }
    }
    inside
}

/// Nearest point of segment [a, b] to x: (xi, distance).
pub(super) fn project(x: [f64; 2], a: [f64; 2], b: [f64; 2]) -> (f64, f64) {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let xi = if l2 > 0.0 {
        (dot(sub(x, a), ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let p = [a[0] + xi * ab[0], a[1] + xi * ab[1]];
    (xi, length(sub(x, p)))
}

/// The gap of a point to a polyline of (possibly degenerate) segments with the solid on the
/// left; `inside` decides the sign where the nearest point is a corner.
fn gap_to_segments(
    x: [f64; 2],
    count: usize,
    segment: impl Fn(usize) -> [[f64; 2]; 2],
    inside: impl Fn() -> bool,
) -> Option<(usize, f64, f64, [f64; 2])> {
    let mut nearest = Nearest { x, best: None };
    for k in 0..count {
        nearest.offer(k, segment(k));
    }
    signed_gap(x, nearest.best?, segment, inside)
}

/// The nearest of the segments offered to `x`: (segment, xi, distance, xi interior). Within
/// round-off of a tie the interior projection wins, then the lower index: the segments may
/// be offered in any order (`SegmentGrid::visit`) and give what offering them in index
/// order gives.
struct Nearest {
    x: [f64; 2],
    best: Option<(usize, f64, f64, bool)>,
}

impl Nearest {
    fn offer(&mut self, k: usize, [a, b]: [[f64; 2]; 2]) {
        let x = self.x;
        if let Some((_, _, db, _)) = self.best {
            // a segment whose bounding box lies farther than the best distance (and its tie
            // band) cannot win: skip its projection
            let outside = |lo: f64, hi: f64, v: f64| (lo - v).max(v - hi).max(0.0);
            let bx = outside(a[0].min(b[0]), a[0].max(b[0]), x[0]);
            let by = outside(a[1].min(b[1]), a[1].max(b[1]), x[1]);
            let reach = db * (1.0 + 1e-9);
            if bx * bx + by * by > reach * reach {
                return;
            }
        }
        let (xi, d) = project(x, a, b);
        let interior = xi > 0.0 && xi < 1.0;
        let better = match self.best {
            None => true,
            Some((bk, _, db, best_interior)) => {
                let tie = (d - db).abs() <= 1e-12 * db.max(1e-300);
                d < db - 1e-12 * db.max(1e-300)
                    || (tie && interior && !best_interior)
                    || (tie && interior == best_interior && k < bk)
            }
        };
        if better {
            self.best = Some((k, xi, d, interior));
        }
    }

    fn reach(&self) -> f64 {
        self.best.map_or(f64::INFINITY, |(_, _, d, _)| d)
    }
}

/// The signed gap and normal of `x` at its nearest segment `best` (`Nearest`).
fn signed_gap(
    x: [f64; 2],
    best: (usize, f64, f64, bool),
    segment: impl Fn(usize) -> [[f64; 2]; 2],
    inside: impl Fn() -> bool,
) -> Option<(usize, f64, f64, [f64; 2])> {
    let (k, xi, d, _) = best;
    let [a, b] = segment(k);
    let n = outward(a, b);
    let p = [a[0] + xi * (b[0] - a[0]), a[1] + xi * (b[1] - a[1])];
    let along_normal = dot(sub(x, p), n);
    // a point on the vertex itself (within round-off of the segment's length): the
    // direction to the vertex is noise, the segment's normal is not
    let on_vertex = d <= 1e-9 * length(sub(b, a));
    let (gap, normal) = if xi > 0.0 && xi < 1.0 || on_vertex {
        (along_normal, n)
    } else if inside() {
        // penetrated near a vertex: the segment's own normal. The direction to the vertex
        // would turn with every small tangential offset (at a vertex between collinear
        // segments it flips from side to side) and Newton could not settle.
        (along_normal, n)
    } else {
        // outside a convex corner: the normal points from the corner to the slave
        let dir = sub(x, p);
        (d, [dir[0] / d, dir[1] / d])
    };
    Some((k, xi, gap, normal))
}

/// The projection parameter within which a balanced pass's slave is on a master vertex
/// (`ContactPair::node_gap_on`): round-off of the projection of a node lying on it.
const VERTEX: f64 = 1e-9;

impl ContactPair {
    /// The motion of the pair's obstacle, when it has one that moves.
    pub fn moving_obstacle(&self) -> Option<&ObstacleMotion> {
        match &self.master {
            Master::Obstacle(o) => o.motion.as_ref(),
            _ => None,
        }
    }

    /// The velocity of the pair's obstacle where it was last placed (`Obstacle::place`):
    /// zero for a master that is a body or an obstacle at rest (the implicit integrators'
    /// impact conditions give a slave the master's velocity, theory 8.3f).
    pub fn obstacle_velocity(&self) -> [f64; 2] {
        self.moving_obstacle()
            .map_or([0.0; 2], |m| m.velocity(m.placed))
    }

    /// The pair's projectile, when its master is one.
    pub fn projectile(&self) -> Option<&Projectile> {
        match &self.master {
            Master::Obstacle(o) => o.projectile.as_ref(),
            _ => None,
        }
    }

    /// The nodes of its surfaces: its slaves, then its deformable master's nodes (none on an
    /// obstacle).
    pub fn surface_nodes(&self) -> impl Iterator<Item = usize> + '_ {
        let masters: &[usize] = match &self.master {
            Master::Segments { edges, .. } => edges.as_flattened(),
            Master::Nodes { nodes, .. } => nodes,
            Master::Obstacle(_) => &[],
        };
        self.slaves.iter().chain(masters).copied()
    }

    /// Whether the pair's impact and release conditions act along its rows, all of them
    /// together (a mortar pair and its hold pair: rows that share master nodes), rather than
    /// node by node (Hughes II-8, II-11).
    pub fn joint_conditions(&self) -> bool {
        !matches!(self.discretization, Discretization::NodeToSegment)
    }

    /// A mortar pair's slave surface and master edges; None for the other discretizations.
    pub fn mortar(&self) -> Option<(&MortarSurface, &[[usize; 2]])> {
        match (&self.discretization, &self.master) {
            (Discretization::Mortar(surface), Master::Segments { edges, .. }) => {
                Some((surface, edges))
            }
            _ => None,
        }
    }

    /// Whether the pair holds the master nodes of a mortar pair (`NAME:held`).
    pub fn is_hold(&self) -> bool {
        matches!(self.discretization, Discretization::Held(_))
    }

    /// The gap of a mortar contact's master node `node` against the slave surface at `x`
    /// (`mortar::master_node_gap`, a node `allowance` past the surface's ends still
    /// facing it): on a mortar pair, of a node of its master edges; on its hold pair, of one
    /// of its slaves. None for node-to-segment pairs, or when no slave segment faces the node.
    pub fn master_node_gap(
        &self,
        node: usize,
        allowance: f64,
        x: &dyn Fn(usize) -> [f64; 2],
    ) -> Option<Gap> {
        let Master::Segments { edges, .. } = &self.master else {
            return None;
        };
        match &self.discretization {
            Discretization::Mortar(surface) => {
                master_node_gap(&surface.edges, edges, node, allowance, x)
            }
            Discretization::Held(holds) => {
                master_node_gap(edges, &holds.master_edges, node, allowance, x)
            }
            Discretization::NodeToSegment => None,
        }
    }

    /// Whether a slave at `gap` is left to the first pass of a two-pass contact (see
    /// [`ContactPair::covered`]): its nearest master point lies on a first-pass slave that
    /// is closed (`closed(pair, index)`) or touches or penetrates its own master at `x`. Such
    /// a slave may not close; once closed it stays until released.
    pub fn covers(
        &self,
        pairs: &[ContactPair],
        gap: &Gap,
        x: &dyn Fn(usize) -> [f64; 2],
        closed: &dyn Fn(usize, usize) -> bool,
    ) -> bool {
        let Some(first) = &self.covered else {
            return false;
        };
        let pair = &pairs[first.pair];
        gap.masters.iter().any(|(m, w)| {
            *w >= COVERED
                && first
                    .slaves
                    .binary_search_by_key(m, |(node, _)| *node)
                    .is_ok_and(|i| {
                        closed(first.pair, first.slaves[i].1)
                            || pair
                                .gap(*m, x)
                                .is_some_and(|g| g.gap <= pair.options.tolerance)
                    })
        })
    }

    /// The gap of slave node `slave` at positions `x` (global node -> position), or None
    /// when there is no master within the search distance.
    pub fn gap(&self, slave: usize, x: &dyn Fn(usize) -> [f64; 2]) -> Option<Gap> {
        let within = |g: &Gap| g.gap <= self.options.search_distance;
        if self.is_hold() {
            return self.master_node_gap(slave, 0.0, x).filter(within);
        }
        match self.mortar() {
            Some((surface, edges)) => weighted_gap(surface, edges, slave, x).filter(within),
            None => self.node_gap(slave, x),
        }
    }

    /// The gap of slave node `slave` itself (node-to-segment) at positions `x`, or None when
    /// there is no master within the search distance: the pointwise gap, also of a mortar
    /// pair's nodes (their penetration).
    pub fn node_gap(&self, slave: usize, x: &dyn Fn(usize) -> [f64; 2]) -> Option<Gap> {
        self.node_gap_on(slave, x, None)
    }

    /// [`ContactPair::node_gap`], the nearest master segment found on `grid` (the master's
    /// segments at `x`) when given.
    pub fn node_gap_on(
        &self,
        slave: usize,
        x: &dyn Fn(usize) -> [f64; 2],
        grid: Option<&SegmentGrid>,
    ) -> Option<Gap> {
        let xs = x(slave);
        let result = match &self.master {
            Master::Nodes { nodes, normal, .. } => {
                let m = *nodes
                    .iter()
                    .min_by(|a, b| length(sub(x(**a), xs)).total_cmp(&length(sub(x(**b), xs))))?;
                Gap {
                    gap: dot(sub(xs, x(m)), *normal),
                    normal: *normal,
                    masters: vec![(m, 1.0)],
                    weight: 1.0,
                    lever: None,
                }
            }
            Master::Segments {
                edges, boundary, ..
            } => self.segment_gap((slave, xs), (&edges[..], &boundary[..]), x, grid)?,
            Master::Obstacle(o) => {
                // a projectile carried by nodes: the slave in its base frame, where its
                // points are (module `projectile`)
                let frame = o.projectile.as_ref().and_then(|p| p.frame(x));
                let world = xs;
                let xs = frame.map_or(xs, |f| f.to_base(xs));
                let segments = o.segments();
                let inside = || {
                    if o.closed {
                        // a cavity's loop winds -1 around its void: the solid is where the
                        // winding number plus the boundary at infinity (1) exceeds 1/2
                        let infinity = if o.is_cavity() { 1.0 } else { 0.0 };
                        winding_number(xs, &segments) + infinity > 0.5
                    } else {
                        // a half-space boundary: the side of the nearest segment
                        let (k, _, _) = segments
                            .iter()
                            .enumerate()
                            .map(|(k, [a, b])| (k, project(xs, *a, *b)))
                            .map(|(k, (xi, d))| (k, xi, d))
                            .min_by(|a, b| a.2.total_cmp(&b.2))
                            .expect("segments");
                        let [a, b] = segments[k];
                        dot(sub(xs, a), outward(a, b)) < 0.0
                    }
                };
                let (_, _, gap, normal) =
                    gap_to_segments(xs, segments.len(), |k| segments[k], inside)?;
                Gap {
                    gap,
                    normal: frame.map_or(normal, |f| f.to_world(normal)),
                    masters: frame.map(|f| vec![(f.carrier, 1.0)]).unwrap_or_default(),
                    weight: 1.0,
                    lever: frame.and_then(|f| f.lever(world)),
                }
            }
        };
        (result.gap <= self.options.search_distance).then_some(result)
    }

    /// The gap of slave `slave` at `xs` to a master surface of `edges` on a body of
    /// `boundary` edges (node-to-segment, Hughes II-13..16), the nearest segment found on
    /// `grid` when given. A pass of a body's contact with itself looks only at the segments
    /// its `OwnSurface` admits, and a slave behind one of them that is not inside the body
    /// has no gap there (`own`).
    fn segment_gap(
        &self,
        (slave, xs): (usize, [f64; 2]),
        (edges, boundary): (&[[usize; 2]], &[[usize; 2]]),
        x: &dyn Fn(usize) -> [f64; 2],
        grid: Option<&SegmentGrid>,
    ) -> Option<Gap> {
        let own = self.own.as_ref();
        let segment = |k: usize| [x(edges[k][0]), x(edges[k][1])];
        // segment k at `x` when the slave may meet it (`OwnSurface`: placed for this pass and
        // facing the slave's own normal `n`)
        let facing = own.map(|own| (own, own.normal(slave, xs, x)));
        let admitted = |k: usize| match facing {
            Some((own, n)) => own
                .admits(slave, k, edges[k])
                .then(|| segment(k))
                .filter(|[a, b]| OwnSurface::faces(n, outward(*a, *b))),
            None => Some(segment(k)),
        };
        let mut nearest = Nearest { x: xs, best: None };
        match grid {
            Some(grid) => {
                let nearest = std::cell::RefCell::new(&mut nearest);
                let offer = |k: usize| {
                    if let Some(s) = admitted(k) {
                        nearest.borrow_mut().offer(k, s);
                    }
                };
                let limit = self.options.search_distance;
                grid.visit(xs, offer, || nearest.borrow().reach(), limit);
            }
            None => (0..edges.len()).for_each(|k| {
                if let Some(s) = admitted(k) {
                    nearest.offer(k, s);
                }
            }),
        }
        let best = nearest.best?;
        // a slave behind a segment of its own body penetrates it only if it went into the
        // body, and not deeper than the segment's own depth (`OwnSurface::reaches`): beyond
        // that depth which side it is on does not matter, and the crossing count is spared
        // (counted once: the sign of a corner gap and the test below may both ask)
        let counted = std::cell::OnceCell::new();
        let inside = || {
            *counted.get_or_init(|| match own {
                Some(own) => {
                    OwnSurface::reaches(-best.2, segment(best.0))
                        && own.probe(slave, xs, x).is_some_and(|probe| {
                            let outline = boundary.iter().map(|[a, b]| [x(*a), x(*b)]);
                            inside_by_crossings(probe, outline)
                        })
                }
                None => inside_by_crossings(xs, boundary.iter().map(|[a, b]| [x(*a), x(*b)])),
            })
        };
        let gap = self.gap_at(xs, best, (edges, segment), x, &inside)?;
        let behind_own = own.is_some()
            && gap.gap < 0.0
            && !(OwnSurface::reaches(gap.gap, segment(best.0)) && inside());
        (!behind_own).then_some(gap)
    }

    /// The gap of a slave at `xs` whose nearest master segment is `best` (`Nearest`).
    fn gap_at(
        &self,
        xs: [f64; 2],
        best: (usize, f64, f64, bool),
        (edges, segment): (&[[usize; 2]], impl Fn(usize) -> [[f64; 2]; 2]),
        x: &dyn Fn(usize) -> [f64; 2],
        inside: &dyn Fn() -> bool,
    ) -> Option<Gap> {
        let (k, xi, corner_gap, corner_normal) = signed_gap(xs, best, segment, inside)?;
        let [a, b] = edges[k];
        let ab = sub(x(b), x(a));
        let turned =
            (corner_normal[0] * ab[0] + corner_normal[1] * ab[1]).abs() > 1e-9 * length(ab);
        let beyond = (xi <= 0.0 || xi >= 1.0) && corner_gap > 0.0 && turned;
        if beyond && self.options.balanced {
            // beyond the master's end and outside its body (the direction from the end
            // turned off the segment's normal): the distance from the end (the nodal normal
            // there would read the surface's extension)
            let end = if xi <= 0.0 { a } else { b };
            return Some(Gap {
                gap: corner_gap,
                normal: corner_normal,
                masters: vec![(end, 1.0)],
                weight: 1.0,
                lever: None,
            });
        }
        let normal = self.row_normal(edges, (a, b, xi), x);
        let p = [
            (1.0 - xi) * x(a)[0] + xi * x(b)[0],
            (1.0 - xi) * x(a)[1] + xi * x(b)[1],
        ];
        Some(Gap {
            gap: dot(sub(xs, p), normal),
            normal,
            masters: vec![(a, 1.0 - xi), (b, xi)],
            weight: 1.0,
            lever: None,
        })
    }

    /// The normal of a node-to-segment row at `xi` on the master segment `a -> b` of `edges`.
    /// One pass: interpolated between the master nodes' averaged normals; it turns
    /// continuously across a vertex, where a dented deformable surface would otherwise flip
    /// the slave's row between its two segments. A balanced pass: the segment's own normal,
    /// the gradient of the gap (the interpolated one is not: its force would work on a
    /// sliding slave); on a vertex itself (within round-off of the projection: a slave of
    /// matching meshes sits on one), where the gap has no gradient, the vertex's normal, the
    /// same from either segment (mirror images stay mirrored).
    fn row_normal(
        &self,
        edges: &[[usize; 2]],
        (a, b, xi): (usize, usize, f64),
        x: &dyn Fn(usize) -> [f64; 2],
    ) -> [f64; 2] {
        let nodal = |node: usize| -> [f64; 2] {
            let mut sum = [0.0; 2];
            for [p, q] in edges.iter().filter(|e| e.contains(&node)) {
                let n = outward(x(*p), x(*q));
                sum = [sum[0] + n[0], sum[1] + n[1]];
            }
            sum
        };
        let unit = |n: [f64; 2]| {
            let l = length(n);
            (l > 0.0).then(|| [n[0] / l, n[1] / l])
        };
        let normal = if self.options.balanced {
            let vertex = if xi <= VERTEX {
                Some(a)
            } else {
                (xi >= 1.0 - VERTEX).then_some(b)
            };
            vertex.and_then(|v| unit(nodal(v)))
        } else {
            let (na, nb) = (nodal(a), nodal(b));
            unit([
                (1.0 - xi) * na[0] + xi * nb[0],
                (1.0 - xi) * na[1] + xi * nb[1],
            ])
        };
        normal.unwrap_or_else(|| outward(x(a), x(b)))
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    fn square() -> Vec<[[f64; 2]; 2]> {
        let p = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        (0..4).map(|i| [p[i], p[(i + 1) % 4]]).collect()
    }

    /// Greco eq 17 on a convex square: 1 inside, 0 outside, 1/2 on an edge, 1/4 at a corner
    /// (alpha = pi/2).
    #[test]
    fn winding_number_of_convex_polygon() {
        let s = square();
        approx::assert_abs_diff_eq!(winding_number([0.3, 0.6], &s), 1.0, epsilon = 1e-12);
        approx::assert_abs_diff_eq!(winding_number([1.3, 0.6], &s), 0.0, epsilon = 1e-12);
        approx::assert_abs_diff_eq!(winding_number([0.5, 0.0], &s), 0.5, epsilon = 1e-12);
        approx::assert_abs_diff_eq!(winding_number([1.0, 1.0], &s), 0.25, epsilon = 1e-12);
    }

    /// A concave L-shape: points in the notch are outside; the reflex corner (alpha = 3 pi/2)
    /// gives 3/4. A clockwise square (a cavity) gives -1 inside: its solid is outside.
    #[test]
    fn winding_number_of_concave_polygon_and_cavity() {
        let p = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        let l: Vec<[[f64; 2]; 2]> = (0..6).map(|i| [p[i], p[(i + 1) % 6]]).collect();
        approx::assert_abs_diff_eq!(winding_number([1.5, 1.5], &l), 0.0, epsilon = 1e-12);
        approx::assert_abs_diff_eq!(winding_number([0.5, 1.5], &l), 1.0, epsilon = 1e-12);
        approx::assert_abs_diff_eq!(winding_number([1.0, 1.0], &l), 0.75, epsilon = 1e-12);
        let cavity: Vec<[[f64; 2]; 2]> = square().iter().rev().map(|[a, b]| [*b, *a]).collect();
        approx::assert_abs_diff_eq!(winding_number([0.5, 0.5], &cavity), -1.0, epsilon = 1e-12);
        approx::assert_abs_diff_eq!(winding_number([3.0, 0.5], &cavity), 0.0, epsilon = 1e-12);
    }

    /// A rigid cavity (clockwise square): a slave pushed out through a corner is inside the
    /// solid and gets a negative gap; one in the void near the corner a positive gap.
    #[test]
    fn cavity_corner_signs() {
        let cavity = Obstacle {
            name: "box".into(),
            points: vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]],
            closed: true,
            motion: None,
            projectile: None,
        };
        assert!(cavity.is_cavity());
        let pair = slave_node_0(Master::Obstacle(cavity));
        let outside = pair.gap(0, &|_| [1.1, 1.2]).unwrap();
        assert!(outside.gap < 0.0, "{outside:?}");
        let inside = pair.gap(0, &|_| [0.9, 0.95]).unwrap();
        approx::assert_abs_diff_eq!(inside.gap, 0.05, epsilon = 1e-12);
    }

    /// A slave pressed in just below a vertex between two collinear master segments keeps
    /// the surface normal and the gap -depth whichever side of the vertex it drifts to
    /// (the direction to the vertex would swing through 180 degrees).
    #[test]
    fn penetration_below_a_flat_vertex_keeps_the_surface_normal() {
        let coords = [
            [0.0, 0.0],
            [1.0, 0.0],
            [0.0, 0.0],
            [-1.0, 0.0],
            [-1.0, -1.0],
            [1.0, -1.0],
        ];
        let pair = slave_node_0(Master::Segments {
            body: 1,
            edges: vec![[1, 2], [2, 3]],
            boundary: vec![[1, 2], [2, 3], [3, 4], [4, 5], [5, 1]],
        });
        for dx in [-1e-9, 0.0, 1e-9] {
            let x = |n: usize| if n == 0 { [dx, -1e-6] } else { coords[n] };
            let g = pair.gap(0, &x).unwrap();
            approx::assert_abs_diff_eq!(g.gap, -1e-6, epsilon = 1e-15);
            approx::assert_abs_diff_eq!(g.normal[1], 1.0, epsilon = 1e-12);
        }
    }

    /// On a dented deformable master (a V at a vertex) the interpolated normal is continuous
    /// across the vertex: slaves just left and right of it (at 0.001 above, projecting at
    /// xi = 1e-4 from the vertex) get the averaged vertex normal to within 1e-4, where the
    /// segments' own normals differ by 0.2 in their x component.
    #[test]
    fn smoothed_normal_is_continuous_across_a_dented_vertex() {
        let coords = [
            [0.0, 0.0],
            [1.0, 0.1],
            [0.0, 0.0],
            [-1.0, 0.1],
            [-1.0, -1.0],
            [1.0, -1.0],
        ];
        let pair = slave_node_0(Master::Segments {
            body: 1,
            edges: vec![[1, 2], [2, 3]],
            boundary: vec![[1, 2], [2, 3], [3, 4], [4, 5], [5, 1]],
        });
        let normal_at = |dx: f64| {
            pair.gap(0, &|n: usize| if n == 0 { [dx, 0.001] } else { coords[n] })
                .unwrap()
                .normal
        };
        let (left, right) = (normal_at(-1e-7), normal_at(1e-7));
        approx::assert_abs_diff_eq!(left[0], right[0], epsilon = 1e-4);
        approx::assert_abs_diff_eq!(left[1], 1.0, epsilon = 1e-6);
        approx::assert_abs_diff_eq!(right[1], 1.0, epsilon = 1e-6);
    }

    /// A pair whose only slave is node 0.
    pub(in crate::contact) fn slave_node_0(master: Master) -> ContactPair {
        ContactPair {
            name: "p".into(),
            slave_body: 0,
            slaves: vec![0],
            master,
            options: options(),
            covered: None,
            balances: None,
            own: None,
            discretization: Discretization::NodeToSegment,
            chosen_roles: None,
        }
    }

    fn options() -> PairOptions {
        PairOptions {
            impact_conditions: true,
            release_conditions: true,
            release_fraction: 0.02,
            tolerance: 1e-10,
            search_distance: f64::INFINITY,
            split_at_events: true,
            friction: Friction::None,
            persistency: false,
            balanced: false,
        }
    }

    /// Gap and weights to a wall (open polyline, solid below y = 0): signed distance, the
    /// normal +y, no master nodes; the row is the normal on the slave DOFs.
    #[test]
    fn gap_to_a_rigid_wall_and_its_row() {
        let wall = Obstacle {
            name: "w".into(),
            points: vec![[2.0, 0.0], [-2.0, 0.0]],
            closed: false,
            motion: None,
            projectile: None,
        };
        let pair = slave_node_0(Master::Obstacle(wall));
        for (y, expected) in [(0.3, 0.3), (-0.2, -0.2)] {
            let g = pair.gap(0, &|_| [0.5, y]).unwrap();
            approx::assert_abs_diff_eq!(g.gap, expected, epsilon = 1e-15);
            approx::assert_abs_diff_eq!(g.normal[1], 1.0, epsilon = 1e-15);
            assert_eq!(g.row(0), vec![(0, 0.0), (1, 1.0)]);
        }
    }

    /// Node-to-segment weights (Hughes II-13..16): the projection parameter splits the
    /// constraint between the two master nodes; with the slave over a master node the row
    /// reduces to node-to-node (II-4).
    #[test]
    fn segment_weights_reduce_to_node_to_node() {
        let coords = [
            [0.25, 0.1],
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, -1.0],
            [0.0, -1.0],
        ];
        let pair = slave_node_0(Master::Segments {
            body: 1,
            edges: vec![[2, 1]],
            boundary: vec![[1, 4], [4, 3], [3, 2], [2, 1]],
        });
        let g = pair.gap(0, &|n| coords[n]).unwrap();
        approx::assert_abs_diff_eq!(g.gap, 0.1, epsilon = 1e-15);
        assert_eq!(g.masters, vec![(2, 0.25), (1, 0.75)]);
        let over_node = [
            [1.0, -0.05],
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, -1.0],
            [0.0, -1.0],
        ];
        let g = pair.gap(0, &|n| over_node[n]).unwrap();
        approx::assert_abs_diff_eq!(g.gap, -0.05, epsilon = 1e-15);
        assert_eq!(g.masters, vec![(2, 1.0), (1, 0.0)]);
    }
}
