//! The Newton iterations of each step of an implicit or static run, tallied for
//! summary.json.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The Newton iterations of each converged step, its cut attempts' and contact passes'
/// included, as a tally (how many steps took n): summary.json's median and largest.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct StepIterations {
    steps: BTreeMap<usize, usize>,
}

impl StepIterations {
    /// A converged step that took `iterations` (none: an explicit step, not tallied).
    pub fn record(&mut self, iterations: usize) {
        if iterations > 0 {
            *self.steps.entry(iterations).or_default() += 1;
        }
    }

    /// The median over the tallied steps (the mean of the middle two of an even count).
    pub fn median(&self) -> Option<f64> {
        let count: usize = self.steps.values().sum();
        let nth = |k: usize| {
            let mut seen = 0;
            self.steps.iter().find_map(|(n, c)| {
                seen += c;
                (seen > k).then_some(*n as f64)
            })
        };
        match count {
            0 => None,
            _ => Some(0.5 * (nth((count - 1) / 2)? + nth(count / 2)?)),
        }
    }

    /// The most a tallied step took.
    pub fn max(&self) -> Option<usize> {
        self.steps.keys().next_back().copied()
    }
}

#[cfg(test)]
mod tests {
    use super::StepIterations;

    /// Goal: the median and the largest of a tally of steps' iterations. Reference: the
    /// sorted counts 2, 3, 3, 5, 9 (median 3; an explicit step's 0 not tallied), with a
    /// sixth of 7 (median (3 + 5) / 2 = 4).
    #[test]
    fn step_iterations_give_the_median_and_the_largest() {
        let mut tally = StepIterations::default();
        assert_eq!(tally.median(), None);
        for n in [5, 3, 9, 0, 2, 3] {
            tally.record(n);
        }
        assert_eq!(tally.median(), Some(3.0));
        assert_eq!(tally.max(), Some(9));
        tally.record(7);
        assert_eq!(tally.median(), Some(4.0));
    }
}
