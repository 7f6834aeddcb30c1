//! A body's contact with itself (a folding lip, a tube crushed flat): the body's boundary is
//! both the slave and the master of a balanced pair. Four things set it apart from a pair
//! between two bodies.
//!
//! - Which segments a slave may meet. Its own two segments contain it (gap 0 everywhere), so
//!   they are never candidates. The two passes of the pair split the rest by the places along
//!   the boundary loops: the first pass takes, for each slave, the segments that come after
//!   it on the loops, the reverse pass those before it. Two stretches of the boundary that
//!   meet are then one pass's slave and master each way round, as two bodies' surfaces are
//!   in a balanced pair, and no pass holds a node against a segment whose own node holds it
//!   back in the same pass (such rows would repeat each other and make the multipliers
//!   indeterminate, as the joint solve of both passes did on matching meshes: theory 8.3d).
//! - Which way the segment faces. Two stretches of the boundary that fold onto each other
//!   face each other (their outward normals opposed); a slave and the segments of its own
//!   stretch beside it do not, and are no candidates either.
//! - How deep it may be. Behind a segment lies the body, and behind that its other
//!   stretches: a slave that went into one stretch is inside the body for all of them. A
//!   penetration counts only up to half the segment's length (`OwnSurface::reaches`).
//! - On which side of a segment the slave is. A segment of the same body has the body's
//!   material behind it, so a slave behind a segment is not necessarily inside the body: a
//!   node on a thin wall's outer face lies behind the wall's inner face. A slave penetrates
//!   only where a point just off its own face, along its own outward normal, lies inside the
//!   body's outline (a node on the outline itself cannot be tested: the crossing count is
//!   undecided there).
//!
//! Legend
//! ```text
//! place      (loop, position) of a boundary node along the body's boundary loops, each loop
//!            counter-clockwise around the solid, the loops in the order `chain_order` gives
//! edge place the place of the segment's first node
//! later      the first pass: segments placed after the slave; the reverse pass: before it
//! n_s        the slave's own outward normal: the sum of its two boundary segments' normals
//! probe      x_s + EPSILON l n_s / |n_s|, l the shorter of the slave's two segments
//! ```

use crate::mesh::chain_order;
use crate::mesh::plane::outward;
use std::collections::HashMap;

/// The probe's offset from the slave, as a fraction of its shorter segment: far above the
/// round-off of a crossing count at the outline, far below any penetration a step allows.
const EPSILON: f64 = 1e-6;

/// A boundary node's place on its loop (loop, position) and its neighbours there.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Place {
    place: (usize, usize),
    previous: usize,
    next: usize,
}

/// See the module header.
#[derive(Debug, Clone, PartialEq)]
pub struct OwnSurface {
    /// By global node: where it is on its loop (None off the boundary).
    places: Vec<Option<Place>>,
    /// The place of each master edge (the pair's `Master::Segments::edges`, in order).
    edge_places: Vec<(usize, usize)>,
    /// The first pass (segments after the slave) or the reverse one (before it).
    later: bool,
}

impl OwnSurface {
    /// The own surface of a body whose whole boundary is `boundary` (global node ids,
    /// counter-clockwise around the solid) for the master edges `edges` (a subset of it),
    /// the first pass when `later`. An error names the first master edge that is not on
    /// the boundary.
    pub fn new(
        boundary: &[[usize; 2]],
        edges: &[[usize; 2]],
        later: bool,
    ) -> Result<Self, [usize; 2]> {
        let mut places = Vec::new();
        let mut set = |node: usize, (place, previous, next)| {
            if places.len() <= node {
                places.resize(node + 1, None);
            }
            places[node] = Some(Place {
                place,
                previous,
                next,
            });
        };
        let mut edge_at: HashMap<[usize; 2], (usize, usize)> = HashMap::new();
        let ordered = chain_order(boundary.to_vec());
        let (mut loop_index, mut position, mut start) = (0, 0, 0);
        for (k, edge) in ordered.iter().enumerate() {
            if k > start && edge[0] != ordered[k - 1][1] {
                (loop_index, position, start) = (loop_index + 1, 0, k);
            }
            edge_at.insert(*edge, (loop_index, position));
            position += 1;
            // the loop closes where the next edge does not follow on from this one
            let closes = ordered.get(k + 1).is_none_or(|next| next[0] != edge[1]);
            if closes {
                let first = ordered[start];
                for (i, e) in ordered[start..=k].iter().enumerate() {
                    let previous = if i == 0 {
                        ordered[k][0]
                    } else {
                        ordered[start + i - 1][0]
                    };
                    set(e[0], ((loop_index, i), previous, e[1]));
                }
                if edge[1] != first[0] {
                    // an open chain (not a whole boundary): its last node ends it
                    set(edge[1], ((loop_index, k + 1 - start), edge[0], edge[1]));
                }
            }
        }
        let edge_places = edges
            .iter()
            .map(|e| edge_at.get(e).copied().ok_or(*e))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(OwnSurface {
            places,
            edge_places,
            later,
        })
    }

    /// The same surface for the other pass.
    pub fn reversed(&self) -> Self {
        OwnSurface {
            later: !self.later,
            ..self.clone()
        }
    }

    /// Whether the slave `slave` of this pass may meet the master edge `k` (`edge`): not one
    /// of its own segments, and placed after it (first pass) or before it (reverse pass).
    pub fn admits(&self, slave: usize, k: usize, edge: [usize; 2]) -> bool {
        if edge.contains(&slave) {
            return false;
        }
        let Some(Place { place, .. }) = self.place(slave) else {
            return false;
        };
        if self.later {
            self.edge_places[k] > place
        } else {
            self.edge_places[k] < place
        }
    }

    /// A node's place along its loop.
    fn place(&self, node: usize) -> Option<Place> {
        self.places.get(node).copied().flatten()
    }

    /// The slave's own outward normal at `xs` (positions `x`): the sum of its two boundary
    /// segments' unit normals (not unit; zero for a node not on the boundary).
    pub fn normal(&self, slave: usize, xs: [f64; 2], x: &dyn Fn(usize) -> [f64; 2]) -> [f64; 2] {
        let Some(Place { previous, next, .. }) = self.place(slave) else {
            return [0.0; 2];
        };
        let (before, after) = (outward(x(previous), xs), outward(xs, x(next)));
        [before[0] + after[0], before[1] + after[1]]
    }

    /// Whether a segment of outward normal `segment` faces a slave of own normal `own`
    /// (`OwnSurface::normal`): the two normals opposed. A stretch of the boundary folding
    /// onto another faces it; a slave and the segments of its own stretch beside it do not
    /// (a slave that went into another stretch of the body lies behind its neighbours'
    /// segments too, and would otherwise be pushed back through them).
    pub fn faces(own: [f64; 2], segment: [f64; 2]) -> bool {
        own[0] * segment[0] + own[1] * segment[1] < 0.0
    }

    /// Whether a penetration `gap` (< 0) of a segment `[a, b]` of the slave's own body can
    /// be one: not deeper than half the segment's length. The body's other stretches lie
    /// behind each segment too (a thin wall's other face, 1 mm behind the inner face of a
    /// tube whose walls have met), and a slave that went into one stretch is inside the
    /// body for all of them; only the segment it went through is that near (a step moves a
    /// node by a fraction of an element). Explicit codes bound a penetration the same way
    /// (a node deeper than a fraction of its segment's element is let go).
    pub fn reaches(gap: f64, [a, b]: [[f64; 2]; 2]) -> bool {
        -gap <= 0.5 * (b[0] - a[0]).hypot(b[1] - a[1])
    }

    /// The point whose place tells whether the slave at `xs` has gone into its own body:
    /// just off its face along its own outward normal (positions `x`). The caller counts the
    /// crossings of the body's outline around it (`ContactPair::segment_gap`); None for a
    /// node off the boundary.
    pub fn probe(
        &self,
        slave: usize,
        xs: [f64; 2],
        x: &dyn Fn(usize) -> [f64; 2],
    ) -> Option<[f64; 2]> {
        let Place { previous, next, .. } = self.place(slave)?;
        let (p, q) = (x(previous), x(next));
        let n = self.normal(slave, xs, x);
        let length = |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]).hypot(b[1] - a[1]);
        let scale = EPSILON * length(p, xs).min(length(xs, q)) / n[0].hypot(n[1]).max(1e-300);
        Some([xs[0] + scale * n[0], xs[1] + scale * n[1]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::geometry::inside_by_crossings;

    /// Whether the probe of `slave` at `x` lies inside the outline `boundary` there.
    fn inside(
        own: &OwnSurface,
        slave: usize,
        x: &dyn Fn(usize) -> [f64; 2],
        boundary: &[[usize; 2]],
    ) -> bool {
        let probe = own.probe(slave, x(slave), x).unwrap();
        inside_by_crossings(probe, boundary.iter().map(|[a, b]| [x(*a), x(*b)]))
    }

    /// The edges of one loop of `n` nodes, 0 -> 1 -> ... -> n - 1 -> 0.
    fn loop_of(n: usize) -> Vec<[usize; 2]> {
        (0..n).map(|i| [i, (i + 1) % n]).collect()
    }

    /// Reference: the places along one loop of 8. Node 2 meets edges 4..7 in the first pass
    /// and edge 0 in the reverse one; never its own edges 1 and 2.
    #[test]
    fn the_passes_split_the_segments_by_place() {
        let boundary = loop_of(8);
        let first = OwnSurface::new(&boundary, &boundary, true).unwrap();
        let second = first.reversed();
        let admitted = |s: &OwnSurface, slave| {
            (0..8)
                .filter(|k| s.admits(slave, *k, boundary[*k]))
                .collect::<Vec<_>>()
        };
        assert_eq!(admitted(&first, 2), vec![3, 4, 5, 6, 7]);
        assert_eq!(admitted(&second, 2), vec![0]);
        // node 0's own edges are 0 and 7 (the loop closes through it)
        assert_eq!(admitted(&first, 0), vec![1, 2, 3, 4, 5, 6]);
        assert!(admitted(&second, 0).is_empty());
        // each segment not touching a node is in exactly one of the two passes
        for slave in 0..8 {
            for (k, edge) in boundary.iter().enumerate() {
                let own = edge.contains(&slave);
                let count = [&first, &second]
                    .iter()
                    .filter(|s| s.admits(slave, k, *edge))
                    .count();
                assert_eq!(count, usize::from(!own), "slave {slave}, edge {k}");
            }
        }
    }

    /// Reference: a C-shaped outline (counter-clockwise, nodes 0..7) around a slot open to
    /// the right between y = 1 and y = 2: 0 (0,0), 1 (3,0), 2 (3,1), 3 (1,1), 4 (1,2),
    /// 5 (3,2), 6 (3,3), 7 (0,3). Every node on the outline is not inside (its probe goes
    /// outward); node 5, the upper arm's tip, pushed down to (2.5, 0.5) in the lower arm is.
    #[test]
    fn a_node_on_its_own_outline_is_not_inside() {
        let boundary = loop_of(8);
        let own = OwnSurface::new(&boundary, &boundary, true).unwrap();
        let c = [
            [0.0, 0.0],
            [3.0, 0.0],
            [3.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [3.0, 2.0],
            [3.0, 3.0],
            [0.0, 3.0],
        ];
        let x = |n: usize| c[n];
        for n in 0..8 {
            assert!(!inside(&own, n, &x, &boundary), "node {n}");
        }
        let folded = |n: usize| if n == 5 { [2.5, 0.5] } else { c[n] };
        assert!(inside(&own, 5, &folded, &boundary));
    }
}
