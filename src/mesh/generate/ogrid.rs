//! O-grids of disc sectors: a core (the sector's corner polygon scaled toward the centre) and
//! outer blocks with radial grid lines between the core and the arc.

use std::f64::consts::{FRAC_PI_2, PI};

use super::blocks::{Grid, along, bilinear, lerp, ruled};
use super::spacing::reversed;
use crate::mesh::plane::{Point, cross, sub};

/// Where the rays from `center` through `points` cut the chord from the first to the last
/// point, as fractions of the chord (exactly 0 and 1 at its ends).
fn ray_fractions(center: Point, points: &[Point]) -> Vec<f64> {
    let last = points.len() - 1;
    let (p, q) = (sub(points[0], center), sub(points[last], center));
    let interior = |x: Point| {
        let d = sub(x, center);
        cross(p, d) / cross(sub(p, q), d)
    };
    (0..=last)
        .map(|k| {
            if k == 0 {
                0.0
            } else if k == last {
                1.0
            } else {
                interior(points[k])
            }
        })
        .collect()
}

/// O-grid of a quarter disc: the core [centre, B, D, A] is the polygon centre-rim-split-pole
/// scaled by `core`; the pole block spans pole..split and the rim block split..rim of the arc.
pub(super) struct QuarterOGrid {
    pub(super) center: Point,
    pub(super) radius: f64,
    /// +1: pole at (cx, cy + R); -1: pole at (cx, cy - R).
    pub(super) pole_sign: f64,
    /// Arc node fractions from the pole (0) to the rim on y = cy (1).
    pub(super) arc: Vec<f64>,
    /// Arc index where the pole and rim blocks meet.
    pub(super) split: usize,
    /// Core size / radius.
    pub(super) core: f64,
    /// Outer layer fractions from the core (0) to the arc (1).
    pub(super) layers: Vec<f64>,
}

impl QuarterOGrid {
    /// Point of the arc at `fraction` (0 pole, 1 rim), exact at both ends.
    pub(super) fn arc_point(&self, fraction: f64) -> Point {
        let (sin, cos) = if fraction == 0.0 {
            (0.0, 1.0)
        } else if fraction == 1.0 {
            (1.0, 0.0)
        } else {
            (FRAC_PI_2 * fraction).sin_cos()
        };
        [
            self.center[0] + self.radius * sin,
            self.center[1] + self.pole_sign * self.radius * cos,
        ]
    }

    fn arc_points(&self, fractions: &[f64]) -> Vec<Point> {
        fractions.iter().map(|&f| self.arc_point(f)).collect()
    }

    pub(super) fn grids(&self) -> Vec<Grid> {
        let pole_arc = self.arc_points(&self.arc[..=self.split]);
        let rim_arc = self.arc_points(&self.arc[self.split..]);
        let scaled = |p: Point| lerp(self.center, p, self.core);
        let (a, d, b) = (
            scaled(pole_arc[0]),
            scaled(rim_arc[0]),
            scaled(*rim_arc.last().unwrap()),
        );
        let us = ray_fractions(self.center, &pole_arc);
        let ts = ray_fractions(self.center, &rim_arc);
        vec![
            bilinear([self.center, b, d, a], &us, &reversed(&ts)),
            ruled(&along(a, d, &us), &pole_arc, &self.layers),
            ruled(&along(d, b, &ts), &rim_arc, &self.layers),
        ]
    }

    /// x of the nodes on the flat face, from the centre to the rim.
    pub(super) fn flat_xs(&self) -> Vec<f64> {
        let pole_arc = self.arc_points(&self.arc[..=self.split]);
        let b = self.center[0] + self.core * self.radius;
        let rim = self.center[0] + self.radius;
        let core_xs = ray_fractions(self.center, &pole_arc)
            .into_iter()
            .map(|u| self.center[0] + u * (b - self.center[0]));
        let layer_xs = self.layers[1..].iter().map(|w| b + w * (rim - b));
        core_xs.chain(layer_xs).collect()
    }
}

/// O-grid of a half disc x >= cx: the core (the polygon lower pole - low split - high split -
/// top pole scaled by `core`) is cut at the centre into a lower and an upper quadrilateral;
/// outer blocks span the arc from the lower pole to `low`, `low` to `n - low`, and on to the top.
pub(super) struct HalfOGrid {
    pub(super) center: Point,
    pub(super) radius: f64,
    /// Arc node fractions from the lower pole (0) to the top pole (1).
    pub(super) arc: Vec<f64>,
    /// Arc steps of each pole block.
    pub(super) low: usize,
    /// Arc index (strictly between the splits) of the point the core is cut to from the centre.
    pub(super) equator: usize,
    /// Core size / radius.
    pub(super) core: f64,
    /// Outer layer fractions from the core (0) to the arc (1).
    pub(super) layers: Vec<f64>,
}

impl HalfOGrid {
    /// Point of the arc at `fraction` (0 lower pole, 1 top pole), exact at both ends.
    pub(super) fn arc_point(&self, fraction: f64) -> Point {
        let (sin, cos) = if fraction == 0.0 {
            (0.0, 1.0)
        } else if fraction == 1.0 {
            (0.0, -1.0)
        } else {
            (PI * fraction).sin_cos()
        };
        [
            self.center[0] + self.radius * sin,
            self.center[1] - self.radius * cos,
        ]
    }

    fn arc_points(&self, fractions: &[f64]) -> Vec<Point> {
        fractions.iter().map(|&f| self.arc_point(f)).collect()
    }

    pub(super) fn grids(&self) -> Vec<Grid> {
        let n = self.arc.len() - 1;
        let (a, b, e) = (self.low, n - self.low, self.equator);
        let low_arc = self.arc_points(&self.arc[..=a]);
        let rim_arc = self.arc_points(&self.arc[a..=b]);
        let top_arc = self.arc_points(&self.arc[b..]);
        let scaled = |p: Point| lerp(self.center, p, self.core);
        let (low_pole, low_split) = (scaled(low_arc[0]), scaled(rim_arc[0]));
        let (top_split, top_pole) = (scaled(rim_arc[b - a]), scaled(top_arc[a]));

        let us = ray_fractions(self.center, &low_arc);
        let ts = ray_fractions(self.center, &rim_arc);
        let t_mid = ts[e - a];
        let mid = lerp(low_split, top_split, t_mid);
        let v_low: Vec<f64> = ts[..=e - a].iter().map(|t| t / t_mid).collect();
        let v_top: Vec<f64> = ts[e - a..]
            .iter()
            .map(|t| (t - t_mid) / (1.0 - t_mid))
            .collect();
        let top_inner: Vec<Point> = along(top_pole, top_split, &us).into_iter().rev().collect();
        vec![
            bilinear([low_pole, low_split, mid, self.center], &us, &v_low),
            bilinear([self.center, mid, top_split, top_pole], &us, &v_top),
            ruled(&along(low_pole, low_split, &us), &low_arc, &self.layers),
            ruled(&along(low_split, top_split, &ts), &rim_arc, &self.layers),
            ruled(&top_inner, &top_arc, &self.layers),
        ]
    }
}
