//! Distributions: fractions 0 = t_0 < t_1 < ... < t_n = 1 along a side.

use std::ops::RangeInclusive;

/// n steps, each q times the previous one.
pub(super) fn geometric(n: usize, q: f64) -> Vec<f64> {
    let mut ts = Vec::with_capacity(n + 1);
    let (mut sum, mut step) = (0.0, 1.0);
    ts.push(0.0);
    for _ in 0..n {
        sum += step;
        ts.push(sum);
        step *= q;
    }
    ts.iter().map(|t| t / sum).collect()
}

/// n steps with last / first = grading.
pub(super) fn graded(n: usize, grading: f64) -> Vec<f64> {
    let q = if n > 1 {
        grading.powf(1.0 / (n - 1) as f64)
    } else {
        1.0
    };
    geometric(n, q)
}

pub(super) fn uniform(n: usize) -> Vec<f64> {
    (0..=n).map(|k| k as f64 / n as f64).collect()
}

/// The same steps measured from the other end.
pub(super) fn reversed(ts: &[f64]) -> Vec<f64> {
    ts.iter().rev().map(|t| 1.0 - t).collect()
}

/// `ts` as is, or from the far end.
pub(super) fn from_end(ts: Vec<f64>, far_end: bool) -> Vec<f64> {
    if far_end { reversed(&ts) } else { ts }
}

/// Coordinates start + length t.
pub(super) fn spaced(start: f64, length: f64, ts: &[f64]) -> Vec<f64> {
    ts.iter().map(|t| start + length * t).collect()
}

/// The index in `range` whose fraction is nearest to `target`.
pub(super) fn nearest(ts: &[f64], target: f64, range: RangeInclusive<usize>) -> usize {
    range
        .min_by(|&a, &b| (ts[a] - target).abs().total_cmp(&(ts[b] - target).abs()))
        .expect("validated counts give a non-empty range")
}

/// Fractions 0 (core) .. 1 (arc) of an O-grid's outer layers: as many layers as the thickness
/// holds mean arc steps, growing away from the arc (at most 2x per layer) so that the layer at
/// the arc is about as thick as the arc step next to it.
pub(super) fn layer_fractions(thickness: f64, mean_step: f64, step_at_arc: f64) -> Vec<f64> {
    let layers = ((thickness / mean_step).round() as usize).max(1);
    if layers == 1 {
        return vec![0.0, 1.0];
    }
    let target = step_at_arc / thickness;
    let first_step = |ln_q: f64| 1.0 / (0..layers).map(|k| (k as f64 * ln_q).exp()).sum::<f64>();
    let (mut lo, mut hi) = (-2f64.ln(), 2f64.ln());
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if first_step(mid) > target {
            lo = mid
        } else {
            hi = mid
        }
    }
    reversed(&geometric(layers, (0.5 * (lo + hi)).exp()))
}
