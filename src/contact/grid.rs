//! A master surface's segments binned on a uniform grid, for the nearest-segment search of
//! many slaves: each slave visits the cells ring by ring around its own and stops once a
//! ring lies farther than the nearest segment found, instead of looking at every segment.
//! A balanced pair between two bodies' whole boundaries has some hundreds of slaves against
//! some hundreds of segments, searched several times a step (docs/theory.md 8.3d).

/// Segments binned by their bounding boxes on a uniform grid of square cells.
pub struct SegmentGrid {
    origin: [f64; 2],
    cell: f64,
    size: [usize; 2],
    /// The segments overlapping cell `c` are `items[starts[c]..starts[c + 1]]`.
    starts: Vec<usize>,
    items: Vec<usize>,
}

/// The most cells along a side: a surface of long and short segments mixed stays a grid of
/// bounded size.
const MAX_CELLS: usize = 512;

impl SegmentGrid {
    /// The grid of `segments` (cells about the mean segment length); None without segments.
    pub fn new(segments: &[[[f64; 2]; 2]]) -> Option<Self> {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let mut total = 0.0;
        for [a, b] in segments {
            for axis in 0..2 {
                lo[axis] = lo[axis].min(a[axis].min(b[axis]));
                hi[axis] = hi[axis].max(a[axis].max(b[axis]));
            }
            total += (b[0] - a[0]).hypot(b[1] - a[1]);
        }
        if segments.is_empty() || !(lo[0].is_finite() && hi[0].is_finite()) {
            return None;
        }
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        let mean = total / segments.len() as f64;
        let cell = mean.max(extent / MAX_CELLS as f64).max(f64::MIN_POSITIVE);
        let count = |axis: usize| ((hi[axis] - lo[axis]) / cell) as usize + 1;
        let size = [count(0).min(MAX_CELLS + 1), count(1).min(MAX_CELLS + 1)];
        let index = |v: f64, axis: usize| (((v - lo[axis]) / cell) as usize).min(size[axis] - 1);
        let span = |[a, b]: &[[f64; 2]; 2], axis: usize| {
            index(a[axis].min(b[axis]), axis)..=index(a[axis].max(b[axis]), axis)
        };
        let mut counts = vec![0usize; size[0] * size[1] + 1];
        for s in segments {
            for j in span(s, 1) {
                for i in span(s, 0) {
                    counts[j * size[0] + i + 1] += 1;
                }
            }
        }
        for c in 1..counts.len() {
            counts[c] += counts[c - 1];
        }
        let starts = counts.clone();
        let mut items = vec![0; counts[counts.len() - 1]];
        for (k, s) in segments.iter().enumerate() {
            for j in span(s, 1) {
                for i in span(s, 0) {
                    let c = j * size[0] + i;
                    items[counts[c]] = k;
                    counts[c] += 1;
                }
            }
        }
        Some(Self {
            origin: lo,
            cell,
            size,
            starts,
            items,
        })
    }

    /// Offers `visit` every segment that may lie nearer to `x` than `reach()` (the nearest
    /// distance found so far) and than `limit`, ring by ring of cells around `x`'s cell (the
    /// cell of the grid nearest to `x` when `x` lies outside it); a segment overlapping
    /// several cells may be offered more than once.
    pub fn visit(
        &self,
        x: [f64; 2],
        mut visit: impl FnMut(usize),
        reach: impl Fn() -> f64,
        limit: f64,
    ) {
        let at = |axis: usize| {
            let v = ((x[axis] - self.origin[axis]) / self.cell).floor();
            v.clamp(0.0, (self.size[axis] - 1) as f64) as usize
        };
        let (ci, cj) = (at(0), at(1));
        let rings = self.size[0].max(self.size[1]);
        for r in 0..rings {
            // every point of a ring-r cell lies at least (r - 1) cells from x (from its
            // nearest point on the grid, when x lies outside the grid)
            if r >= 2 && (r - 1) as f64 * self.cell > reach().min(limit) * (1.0 + 1e-9) {
                return;
            }
            let (i0, i1) = (ci.saturating_sub(r), (ci + r).min(self.size[0] - 1));
            let (j0, j1) = (cj.saturating_sub(r), (cj + r).min(self.size[1] - 1));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let on_ring = i.abs_diff(ci) == r || j.abs_diff(cj) == r;
                    if !on_ring {
                        continue;
                    }
                    let c = j * self.size[0] + i;
                    for &k in &self.items[self.starts[c]..self.starts[c + 1]] {
                        visit(k);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::SegmentGrid;

    /// Goal: the ring search finds the nearest segment that looking at every segment finds.
    /// Setup: a closed polygon of 200 segments on a wavy circle of radius 1 (a deformed
    /// surface, segments of unlike lengths) and 400 query points inside, on and outside it
    /// out to 3 radii. Reference: the nearest distance over all segments (brute force, exact
    /// projections). Tolerance 1e-15: the same projections, compared bit for bit.
    #[test]
    fn the_ring_search_finds_the_nearest_segment() {
        let n = 200;
        let point = |k: usize| {
            let t = std::f64::consts::TAU * (k as f64 + 0.3 * (k as f64 * 0.7).sin()) / n as f64;
            let r = 1.0 + 0.1 * (5.0 * t).sin();
            [r * t.cos(), r * t.sin()]
        };
        let segments: Vec<[[f64; 2]; 2]> = (0..n).map(|k| [point(k), point((k + 1) % n)]).collect();
        let distance =
            |x: [f64; 2], [a, b]: [[f64; 2]; 2]| super::super::geometry::project(x, a, b).1;
        let grid = SegmentGrid::new(&segments).expect("segments");
        for q in 0..400 {
            let t = q as f64 * 0.618_033_988_7 * std::f64::consts::TAU;
            let r = 3.0 * (q as f64 / 400.0);
            let x = [r * t.cos(), r * t.sin()];
            let exact = segments
                .iter()
                .map(|s| distance(x, *s))
                .fold(f64::INFINITY, f64::min);
            let best = std::cell::Cell::new(f64::INFINITY);
            grid.visit(
                x,
                |k| best.set(best.get().min(distance(x, segments[k]))),
                || best.get(),
                f64::INFINITY,
            );
            assert!(
                (best.get() - exact).abs() <= 1e-15,
                "at {x:?}: {} against {exact}",
                best.get()
            );
        }
    }
}
