//! Which steps get a history.csv row: every `every` steps and at every multiple of
//! `interval` (whichever comes first), the steps the caller forces (the first, the last, a
//! frame), and between two such rows the steps where a column reaches a value beyond both
//! of them (its extremes), so no peak falls between two rows.
//!
//! ```text
//! column  . . . ^ . . . . . v . .      ^: the window's largest value, above both rows:
//! row     R . . X . . . . . X . . R       written (X); a value between the rows' is not
//! ```
//!
//! Rule: a column's largest (smallest) value over the window between two rows is written when
//! it is above (below) both rows' values by more than `NEGLIGIBLE` times the column's largest
//! magnitude so far. Then the largest and smallest value of every column over all steps are
//! among the rows written, to that fraction of its scale (each lies in some window, where it is
//! that window's extreme, or it is a row), and the rows are a subset of the steps' rows, bit
//! for bit. The fraction leaves out round-off: on an elastic-plastic sphere (63 600 explicit
//! steps) the exact rule kept 16 400 rows beside the 10 000 of the grid, most for the
//! penetration's, the step's and the constant momentum's jitter in their last digits. A value
//! that is not finite (NaN, inf) beside finite rows is kept too, so a run going wrong stays
//! visible.

use serde::{Deserialize, Serialize};

/// An extreme between two rows that passes both by less than this fraction of its column's
/// largest magnitude is left out (round-off: the peaks kept to 1e-4 of their scale, within the
/// 0.1 % a peak force is compared to).
pub const NEGLIGIBLE: f64 = 1e-4;

/// The cadence of the rows (`output.history_every`, `output.history_interval`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cadence {
    /// A row at least every this many steps (1: every step).
    pub every: Option<usize>,
    /// A row at the first step that reaches each multiple of this time.
    pub interval: Option<f64>,
}

/// The steps since the last row written, and that row (what a checkpoint stores).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Window {
    /// The last row written; empty before the first.
    last: Vec<f64>,
    /// The rows offered since, not written, one after another (each `last.len()` long).
    rows: Vec<f64>,
    /// The time of the next multiple of the interval.
    next_time: f64,
    /// Each column's largest finite magnitude among the rows offered so far.
    scale: Vec<f64>,
}

/// Chooses the rows of history.csv from the rows of every step.
#[derive(Debug, Clone)]
pub struct Thinning {
    cadence: Cadence,
    window: Window,
}

impl Thinning {
    pub fn new(cadence: Cadence) -> Thinning {
        Thinning {
            cadence,
            window: Window::default(),
        }
    }

    /// Continues from a checkpoint's window.
    pub fn resume(cadence: Cadence, window: Window) -> Thinning {
        Thinning { cadence, window }
    }

    /// The window to store in a checkpoint.
    pub fn window(&self) -> &Window {
        &self.window
    }

    /// Offers the row of a step (`row[0]` is its time); `force` writes it. Calls `write` with
    /// the rows to write, in order: the window's extremes, then the row when it is due.
    pub fn offer<E>(
        &mut self,
        row: &[f64],
        force: bool,
        write: impl FnMut(&[f64]) -> Result<(), E>,
    ) -> Result<(), E> {
        let w = &mut self.window;
        w.scale.resize(row.len(), 0.0);
        for (s, x) in w.scale.iter_mut().zip(row).filter(|(_, x)| x.is_finite()) {
            *s = s.max(x.abs());
        }
        let steps = w.rows.len() / row.len().max(1) + 1;
        let due = force
            || w.last.is_empty()
            || self.cadence.every.is_some_and(|n| steps >= n)
            || self.cadence.interval.is_some() && row[0] >= w.next_time;
        if !due {
            w.rows.extend_from_slice(row);
            return Ok(());
        }
        self.close(row, write)
    }

    /// Writes what the window holds: its extremes, and its last row as the closing row (at
    /// the end of a run, also one that failed). Nothing when every row offered is written.
    pub fn finish<E>(&mut self, write: impl FnMut(&[f64]) -> Result<(), E>) -> Result<(), E> {
        let width = self.window.last.len();
        if self.window.rows.is_empty() || width == 0 {
            return Ok(());
        }
        let split = self.window.rows.len() - width;
        let row = self.window.rows.split_off(split);
        self.close(&row, write)
    }

    /// Writes the window's extremes and `row`, which starts the next window.
    fn close<E>(
        &mut self,
        row: &[f64],
        mut write: impl FnMut(&[f64]) -> Result<(), E>,
    ) -> Result<(), E> {
        let w = &mut self.window;
        if !w.last.is_empty() {
            for k in extremes(&w.last, &w.rows, row, &w.scale) {
                write(&w.rows[k * row.len()..(k + 1) * row.len()])?;
            }
        }
        write(row)?;
        w.rows.clear();
        w.last.clear();
        w.last.extend_from_slice(row);
        if let Some(h) = self.cadence.interval {
            // the first multiple of h after this row's time (a row a hair before a multiple,
            // by round-off in the sum of the steps, counts as on it)
            w.next_time = ((row[0] / h * (1.0 + 1e-9)).floor() + 1.0) * h;
        }
        Ok(())
    }
}

/// The indices (in order) of the rows of `window` (flat, rows as long as `before`) that hold a
/// column's extreme beyond both `before` and `after` (by more than `NEGLIGIBLE` of the
/// column's `scale`), or a value that is not finite where both are.
fn extremes(before: &[f64], window: &[f64], after: &[f64], scale: &[f64]) -> Vec<usize> {
    let width = before.len();
    let count = window.len() / width.max(1);
    let mut keep = vec![false; count];
    for c in 1..width {
        let value = |k: usize| window[k * width + c];
        let (mut high, mut low) = (None::<usize>, None::<usize>);
        for k in 0..count {
            let x = value(k);
            if !x.is_finite() {
                keep[k] |= before[c].is_finite() && after[c].is_finite();
                continue;
            }
            if high.is_none_or(|h| x > value(h)) {
                high = Some(k);
            }
            if low.is_none_or(|l| x < value(l)) {
                low = Some(k);
            }
        }
        // a comparison with a NaN row is false: its neighbour's extreme is then kept
        let margin = NEGLIGIBLE * scale[c];
        if let Some(h) = high.filter(|&h| !(value(h) <= before[c].max(after[c]) + margin)) {
            keep[h] = true;
        }
        if let Some(l) = low.filter(|&l| !(value(l) >= before[c].min(after[c]) - margin)) {
            keep[l] = true;
        }
    }
    (0..count).filter(|&k| keep[k]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows `thinning` writes of `rows` (the last forced, as a run's last step is).
    fn thin(cadence: Cadence, rows: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let mut thinning = Thinning::new(cadence);
        let mut out = Vec::new();
        for (i, row) in rows.iter().enumerate() {
            thinning
                .offer(row, i + 1 == rows.len(), |r| {
                    out.push(r.to_vec());
                    Ok::<(), ()>(())
                })
                .unwrap();
        }
        out
    }

    /// A pseudo-random sequence (a linear congruential generator): no dependency for a test.
    fn noise(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    /// Goal: the rows written are steps' rows, in time order, and every column's largest and
    /// smallest value over all steps is among them to `NEGLIGIBLE` of its scale (the rule of
    /// the module), with far fewer rows. Setup: 5000 steps of uneven length, a smooth column, a noisy one, a pulse one step
    /// wide, a monotone one; a row every 0.01 of 1 (100 windows).
    #[test]
    fn thinned_rows_keep_every_extreme() {
        let mut seed = 7;
        let mut t = 0.0;
        let rows: Vec<Vec<f64>> = (0..5000)
            .map(|i| {
                t += 2e-4 * (1.0 + noise(&mut seed));
                let pulse = if i == 2345 { 9.0 } else { 0.0 };
                vec![t, (7.0 * t).sin(), noise(&mut seed), pulse, t * t]
            })
            .collect();
        let cadence = Cadence {
            every: None,
            interval: Some(0.01),
        };
        let out = thin(cadence, &rows);
        assert!(out.iter().all(|r| rows.contains(r)));
        assert!(out.windows(2).all(|w| w[1][0] > w[0][0]));
        assert_eq!(out.last(), rows.last());
        for c in 1..5 {
            let max = |v: &[Vec<f64>]| v.iter().map(|r| r[c]).fold(f64::MIN, f64::max);
            let min = |v: &[Vec<f64>]| v.iter().map(|r| r[c]).fold(f64::MAX, f64::min);
            let scale = max(&rows).abs().max(min(&rows).abs());
            assert!(max(&rows) - max(&out) <= NEGLIGIBLE * scale, "column {c}");
            assert!(min(&out) - min(&rows) <= NEGLIGIBLE * scale, "column {c}");
        }
        // the pulse (9 above rows of 0) is a row
        assert!(out.iter().any(|r| r[3] == 9.0));
        // ~100 rows on the grid, at most 2 more per window for the noisy column, 1 for the
        // pulse and 1 at each of the sine's 2 turns inside [0, 1] (a turn passes its rows by
        // ~ (7 * 0.005)^2 / 2 = 6e-4 of its scale: kept or not); the monotone column has its
        // extremes on the rows: at most 1 + 100 + 200 + 1 + 2
        assert!(out.len() <= 304, "{}", out.len());
        // the grid: a row at the first step at or past each multiple of 0.01
        for k in 1..100 {
            let tk = k as f64 * 0.01;
            let first = rows.iter().find(|r| r[0] >= tk).unwrap();
            assert!(out.contains(first), "multiple {k}");
        }
    }

    /// Goal: `every` writes every n-th step; with both keys, whichever comes first; every = 1
    /// writes every row. Reference: by hand, on a steady column (no extremes).
    #[test]
    fn every_n_steps_and_both_keys() {
        let rows: Vec<Vec<f64>> = (0..10).map(|i| vec![i as f64, 1.0]).collect();
        let times = |out: Vec<Vec<f64>>| out.iter().map(|r| r[0]).collect::<Vec<_>>();
        let every = |n| Cadence {
            every: Some(n),
            interval: None,
        };
        assert_eq!(
            times(thin(every(1), &rows)),
            (0..10).map(f64::from).collect::<Vec<_>>()
        );
        assert_eq!(times(thin(every(4), &rows)), [0.0, 4.0, 8.0, 9.0]);
        let both = Cadence {
            every: Some(4),
            interval: Some(3.0),
        };
        // 0, 3 (multiple), 6 (multiple), 9 (multiple, last)
        assert_eq!(times(thin(both, &rows)), [0.0, 3.0, 6.0, 9.0]);
    }

    /// Goal: `finish` writes the window's last row (and its extremes) after a run that ended
    /// between rows, and nothing when the last row is written; a NaN between finite rows is
    /// kept.
    #[test]
    fn finish_and_non_finite_values() {
        let mut thinning = Thinning::new(Cadence {
            every: Some(100),
            interval: None,
        });
        let mut out = Vec::new();
        let mut push = |r: &[f64]| {
            out.push(r.to_vec());
            Ok::<(), ()>(())
        };
        for row in [[0.0, 1.0], [1.0, f64::NAN], [2.0, 1.0], [3.0, 1.0]] {
            thinning.offer(&row, false, &mut push).unwrap();
        }
        thinning.finish(&mut push).unwrap();
        thinning.finish(&mut push).unwrap();
        let times: Vec<f64> = out.iter().map(|r| r[0]).collect();
        assert_eq!(times, [0.0, 1.0, 3.0]);
    }
}
