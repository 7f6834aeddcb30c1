//! A line search for the static Newton (theory 5a): a correction that leaves the
//! equilibrium residual above the largest of the last few iterates' is taken back by half,
//! at most `HALVINGS` times, before the next solve.
//!
//! Where a perfectly plastic zone forms under a stress concentration (a punch's edge), the
//! residual is not smooth: integration points cross the yield surface within a correction,
//! and the consistent tangent of one side predicts the other badly; Newton then overshoots
//! and the residual grows from iteration to iteration (Shield's punch on the finest mesh of
//! its family cut its increment 11 times so, docs/validation.md 2.9). Backtracking on the
//! residual's norm is the safeguard of a Newton method (Dennis & Schnabel 1983, 6.3). It is
//! non-monotone (Grippo, Lampariello & Lucidi 1986): the reference is the largest norm of the
//! last `WINDOW` iterates, not the last one, because near a bifurcation a right correction
//! may raise the residual tenfold on its way to converging (the column of validation 5.3 cut
//! its increment 6 times under the monotone test, none under this one). Dynamics keeps the
//! plain correction: K* = K + M / (beta h^2) is dominated by its mass there, and a dynamic
//! step too long for Newton is cut by the error control.

use super::active_set::ActiveSet;
use crate::assembly::System;

/// The most halvings of one correction.
const HALVINGS: usize = 3;

/// The iterates whose largest residual norm a correction must not exceed.
const WINDOW: usize = 3;

/// The last correction and where it stands.
struct Taken {
    /// The share of the correction on the free DOFs the iterate still holds.
    delta: Vec<f64>,
    /// The multipliers before it.
    before: Vec<f64>,
    halvings: usize,
}

/// The line search's memory of one step's iteration.
pub(super) struct LineSearch {
    enabled: bool,
    /// The residual norms of the iterates the watched corrections were solved at.
    norms: Vec<f64>,
    taken: Option<Taken>,
}

impl LineSearch {
    pub(super) fn new(enabled: bool) -> LineSearch {
        LineSearch {
            enabled,
            norms: Vec::new(),
            taken: None,
        }
    }

    /// Whether the correction of iteration `iteration` is watched: not the first, which is
    /// solved at the step's start (or its predictor), whose residual is not the iterate's.
    pub(super) fn watches(&self, iteration: usize) -> bool {
        self.enabled && iteration > 0
    }

    /// Records the correction `delta` just added to the iterate, solved at an iterate of
    /// residual norm `norm`, the multipliers having been `before` it (None: not watched).
    pub(super) fn took(&mut self, delta: &[f64], norm: f64, before: Option<Vec<f64>>) {
        self.taken = before.map(|before| {
            self.norms.push(norm);
            Taken {
                delta: delta.to_vec(),
                before,
                halvings: 0,
            }
        });
    }

    /// Where the iterate's residual norm `now` exceeds the largest of the last `WINDOW`
    /// iterates' and the contact rows did not change (`settled`): takes back half of the
    /// correction in `d` and moves the multipliers `forces` (and the active set's) half way
    /// back; whether it did.
    pub(super) fn search(
        &mut self,
        now: f64,
        settled: bool,
        (d, forces, active_set): (&mut [f64], &mut Vec<f64>, &mut Option<ActiveSet>),
        system: &System,
    ) -> bool {
        let Some(taken) = &mut self.taken else {
            return false;
        };
        let recent = &self.norms[self.norms.len().saturating_sub(WINDOW)..];
        let reference = recent.iter().copied().fold(0.0, f64::max);
        if !settled || now <= reference || taken.halvings == HALVINGS {
            self.taken = None;
            return false;
        }
        taken.delta.iter_mut().for_each(|v| *v *= 0.5);
        let back: Vec<f64> = taken.delta.iter().map(|v| -v).collect();
        system.scatter_add(&back, d);
        for (f, s) in forces.iter_mut().zip(&taken.before) {
            *f = s + 0.5 * (*f - s);
        }
        if let Some(set) = active_set {
            set.take(forces);
        }
        taken.halvings += 1;
        crate::output::console::iteration(format_args!(
            "  newton: the residual rose to {now:.3e} above {reference:.3e}: half of the correction taken back"
        ));
        true
    }
}
