//! Blocks: structured patches of quads (maps of the unit square) and the gluing of blocks
//! into one mesh by merging coincident nodes.

use std::collections::HashMap;

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
/// `tol` are one.
pub(super) fn merge_coincident(points: &[Point], tol: f64) -> (Vec<Point>, Vec<usize>) {
    let cell = tol.max(f64::MIN_POSITIVE);
    let key = |p: Point| ((p[0] / cell).floor() as i64, (p[1] / cell).floor() as i64);
    let mut buckets: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    let mut nodes: Vec<Point> = Vec::new();
    let mut ids = Vec::with_capacity(points.len());
    for &p in points {
        let (kx, ky) = key(p);
        let neighbours = (-1..=1).flat_map(|dx| (-1..=1).map(move |dy| (kx + dx, ky + dy)));
        let found = neighbours
            .filter_map(|k| buckets.get(&k))
            .flatten()
            .copied()
            .find(|&n| norm(sub(nodes[n], p)) <= tol);
        let id = found.unwrap_or_else(|| {
            nodes.push(p);
            buckets.entry((kx, ky)).or_default().push(nodes.len() - 1);
            nodes.len() - 1
        });
        ids.push(id);
    }
    (nodes, ids)
}
