//! Blocks: structured patches of quads (maps of the unit square) and the gluing of blocks
//! into one mesh by merging coincident nodes.

use rayon::prelude::*;

use crate::mesh::plane::{Point, norm, quad_area, sub};
use crate::mesh::{Cells, Mesh};

pub(super) fn lerp(a: Point, b: Point, t: f64) -> Point {
    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
}

pub(super) fn along(a: Point, b: Point, ts: &[f64]) -> Vec<Point> {
    ts.iter().map(|&t| lerp(a, b, t)).collect()
}

/// A structured patch of (ni + 1) x (nj + 1) points, i running fastest.
pub(super) struct Grid {
    ni: usize,
    nj: usize,
    points: Vec<Point>,
}

impl Grid {
    fn from_fn(ni: usize, nj: usize, mut f: impl FnMut(usize, usize) -> Point) -> Grid {
        let mut points = Vec::with_capacity((ni + 1) * (nj + 1));
        for j in 0..=nj {
            for i in 0..=ni {
                points.push(f(i, j));
            }
        }
        Grid { ni, nj, points }
    }

    /// Local point ids of quad (i, j): (i, j), (i+1, j), (i+1, j+1), (i, j+1).
    fn quads(&self) -> Vec<[usize; 4]> {
        let id = |i: usize, j: usize| i + (self.ni + 1) * j;
        let mut quads = Vec::with_capacity(self.ni * self.nj);
        for j in 0..self.nj {
            for i in 0..self.ni {
                quads.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        quads
    }

    fn area(&self) -> f64 {
        self.quads()
            .iter()
            .map(|q| quad_area(q.map(|k| self.points[k])))
            .sum()
    }

    pub(super) fn mirrored_x(&self) -> Grid {
        let points = self.points.iter().map(|p| [-p[0], p[1]]).collect();
        Grid {
            ni: self.ni,
            nj: self.nj,
            points,
        }
    }
}

/// xs x ys.
pub(super) fn tensor(xs: &[f64], ys: &[f64]) -> Grid {
    Grid::from_fn(xs.len() - 1, ys.len() - 1, |i, j| [xs[i], ys[j]])
}

/// The bilinear map of the quadrilateral [c00, c10, c11, c01] sampled at us x vs. Points on the
/// sides through c00 are exact, so they stay on a straight boundary (an axis, a flat face).
pub(super) fn bilinear(corners: [Point; 4], us: &[f64], vs: &[f64]) -> Grid {
    let [p00, p10, p11, p01] = corners;
    Grid::from_fn(us.len() - 1, vs.len() - 1, |i, j| {
        let (u, v) = (us[i], vs[j]);
        std::array::from_fn(|k| {
            p00[k]
                + u * (p10[k] - p00[k])
                + v * (p01[k] - p00[k])
                + u * v * (p11[k] - p10[k] - p01[k] + p00[k])
        })
    })
}

/// Straight grid lines from inner[i] to outer[i], sampled at ws (0 inner, 1 outer).
pub(super) fn ruled(inner: &[Point], outer: &[Point], ws: &[f64]) -> Grid {
    Grid::from_fn(inner.len() - 1, ws.len() - 1, |i, j| {
        lerp(inner[i], outer[i], ws[j])
    })
}

/// One Quad4 mesh from blocks: each block oriented counter-clockwise, coincident nodes merged.
pub(super) fn glue(grids: &[Grid]) -> Mesh {
    let mut points = Vec::new();
    let mut quads = Vec::new();
    for grid in grids {
        let offset = points.len();
        let flip = grid.area() < 0.0;
        for q in grid.quads() {
            let [a, b, c, d] = q.map(|k| k + offset);
            quads.push(if flip { [a, d, c, b] } else { [a, b, c, d] });
        }
        points.extend_from_slice(&grid.points);
    }
    let tol = 1e-6 * min_edge(&points, &quads);
    let (nodes, ids) = merge_coincident(&points, tol);
    let quads = quads.iter().map(|q| q.map(|k| ids[k])).collect();
    Mesh::new(nodes, Cells::Quad4(quads))
}

pub(super) fn min_edge(points: &[Point], quads: &[[usize; 4]]) -> f64 {
    let edges = quads
        .iter()
        .flat_map(|q| (0..4).map(move |k| [q[k], q[(k + 1) % 4]]));
    edges
        .map(|[a, b]| norm(sub(points[a], points[b])))
        .fold(f64::INFINITY, f64::min)
}

/// Distinct points (first occurrence kept) and each input point's new id; points closer than
/// `tol` are one: a point takes the node of the earliest point within `tol` of it (in the
/// generators' meshes coincident points are 1e6 times closer than any two others).
///
/// The points are sorted by their cell of side `tol` (in parallel), and each looks for its
/// earliest neighbour in the three rows of cells around its own by binary search (in
/// parallel); the ids are then numbered in order of first occurrence. The result does not
/// depend on the thread count.
pub(super) fn merge_coincident(points: &[Point], tol: f64) -> (Vec<Point>, Vec<usize>) {
    let cell = tol.max(f64::MIN_POSITIVE);
    let key = |p: Point| ((p[0] / cell).floor() as i64, (p[1] / cell).floor() as i64);
    let mut sorted: Vec<((i64, i64), usize)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| (key(*p), i))
        .collect();
    sorted.par_sort_unstable();
    // the earliest point within tol of each (itself when none is earlier)
    let earliest: Vec<usize> = points
        .par_iter()
        .enumerate()
        .map(|(i, &p)| {
            let (kx, ky) = key(p);
            let mut first = i;
            for row in [kx.saturating_sub(1), kx, kx.saturating_add(1)] {
                let (low, high) = ((row, ky.saturating_sub(1)), (row, ky.saturating_add(1)));
                let from = sorted.partition_point(|(k, _)| *k < low);
                for &(k, j) in sorted[from..].iter().take_while(|(k, _)| *k <= high) {
                    debug_assert!(k >= low);
                    if j < first && norm(sub(points[j], p)) <= tol {
                        first = j;
                    }
                }
            }
            first
        })
        .collect();
    // each point's root (earliest[i] <= i, so the roots before i are known), numbered in
    // order of first occurrence
    let mut ids = vec![0; points.len()];
    let mut nodes: Vec<Point> = Vec::new();
    for (i, &first) in earliest.iter().enumerate() {
        ids[i] = if first == i {
            nodes.push(points[i]);
            nodes.len() - 1
        } else {
            ids[first]
        };
    }
    (nodes, ids)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The merge against its definition by brute force: points on a lattice with copies
    /// moved by less than tol (and one chain of two steps below tol), in scrambled order.
    #[test]
    fn merge_coincident_matches_the_pairwise_definition() {
        let tol = 1e-3;
        let mut points = Vec::new();
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for k in 0..400 {
            let base = [(k % 20) as f64 * 0.01 - 0.1, (k / 20) as f64 * 0.01];
            points.push(base);
            // a third of them have a copy within tol / 2 in a random direction
            if k % 3 == 0 {
                let (r, phi) = (0.5 * tol * next(), 6.283 * next());
                points.push([base[0] + r * phi.cos(), base[1] + r * phi.sin()]);
            }
        }
        // a chain: a, b at 0.8 tol from a, c at 0.8 tol from b (1.6 tol from a)
        points.push([5.0, 5.0]);
        points.push([5.0 + 0.8 * tol, 5.0]);
        points.push([5.0 + 1.6 * tol, 5.0]);
        // scrambled
        for i in (1..points.len()).rev() {
            let j = (next() * (i + 1) as f64) as usize;
            points.swap(i, j.min(i));
        }
        let (nodes, ids) = merge_coincident(&points, tol);
        // by definition: i joins the earliest j within tol, transitively
        let mut reference = vec![usize::MAX; points.len()];
        let mut count = 0;
        for i in 0..points.len() {
            let first = (0..i).find(|&j| norm(sub(points[j], points[i])) <= tol);
            reference[i] = match first {
                Some(j) => reference[j],
                None => {
                    count += 1;
                    count - 1
                }
            };
        }
        assert_eq!(ids, reference);
        assert_eq!(nodes.len(), count);
        // 400 lattice points (their copies merged) and the chain as one or two nodes (b
        // takes a's or c's node, whichever comes first; a and c are apart)
        assert!(count == 401 || count == 402, "{count}");
        for (i, id) in ids.iter().enumerate() {
            assert!(norm(sub(nodes[*id], points[i])) <= 2.0 * tol);
        }
    }
}
