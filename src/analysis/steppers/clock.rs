//! The step of central difference: fixed, or the stable step of the current configuration
//! times a scale, re-evaluated after every step (docs/theory.md 8.7).
//!
//! Legend
//! ```text
//! omega^2_e    a bound of element e's highest frequency squared on the committed
//!              configuration (Kernel::frequency_bound, quad4_one_point::frequency_bound)
//! dt_bound     2 / sqrt(max_e omega^2_e): a stable step (Irons: the assembled model's
//!              highest frequency is at most the elements')
//! auto         h = scale dt_bound; the stop (the next listed frame time or the end time)
//!              reached in equal steps once it is at most EQUAL_STEPS steps of h away:
//!              length = remaining / ceil((1 - STRETCH) remaining / h), the last ending on
//!              the stop exactly (none clipped; `dt_min`, `dt_max` read the full steps h)
//! fixed        h = dt; stopped (status `unstable`) when dt > c dt_bound, c the ratio of the
//!              initial element-eigenvalue limit to the initial dt_bound (so the first check
//!              is the exact one, and the later ones follow the elements as they deform);
//!              the last step ends at the end time (clipped when shorter than dt)
//! ```
//! The shortest and the longest step (summary.json `dt_min`, `dt_max`) are over the steps
//! the rule set, what the mesh needed: the automatic step's h, not the equal parts it is
//! divided into before a frame; not a fixed step's clipped last one, which says where the
//! end fell.

use super::control::{snap, step_length};
use crate::analysis::summary::{Status, StepError};
use crate::assembly::StableStep;
use crate::output::readable;
use crate::scene::DynamicAnalysis;
use crate::scene::Model;
use crate::scene::spec::TimeStep;
use serde::{Deserialize, Serialize};

/// Auto: the steps before a listed frame time or the end time that are made equal (the
/// stop is reached in ceil(remaining / h) equal steps once that is at most this many): the
/// steps change by at most 1/EQUAL_STEPS where the split starts, and none is clipped short.
const EQUAL_STEPS: f64 = 16.0;

/// Auto: how much longer than h the equal steps to a stop may be (a share): the stable step
/// falls a little as elements deform inside the equal steps, and without it the last of them
/// would split in two halves (steel_block_wall: two steps of 0.5 h before a frame). At the
/// default scale 0.9 such a step is 0.909 of the bound.
const STRETCH: f64 = 0.01;

/// The step rule of a central-difference run and what it has seen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Clock {
    rule: Rule,
    /// The first step (fixed: dt; auto: scale times the initial dt_bound).
    pub dt0: f64,
    /// Fixed: the initial element-eigenvalue limit over the initial dt_bound; auto: 1.
    calibration: f64,
    /// The stable step of the committed configuration (the bound's, unscaled).
    pub limit: StableStep,
    /// The last step taken (0 before the first).
    pub last: f64,
    /// The shortest and the longest step the rule set (auto: the full step of the limit,
    /// also where equal steps to a frame divide it; a fixed step's clipped last one not
    /// counted).
    shortest: f64,
    longest: f64,
    /// The shortest and the longest step taken, clipped ones included.
    shortest_taken: f64,
    longest_taken: f64,
    /// Auto: the steps the rule's step is taken together as one (subcycling's major step,
    /// 2^K substeps of the rule's step, docs/theory.md 8.7c; 1 otherwise). `dt_min` is
    /// checked against the rule's step, the clipping to frames and the end applies to the
    /// whole.
    #[serde(default = "one")]
    multiple: u64,
}

fn one() -> u64 {
    1
}

/// A step of the clock: where it ends, its length, the rule's step (auto: the full step of
/// the stable limit, which the equal steps to a frame divide), and whether it was clipped
/// (a fixed step's last one, ended early at the end time).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    pub end: f64,
    pub length: f64,
    pub rule: f64,
    pub clipped: bool,
}

/// The shortest and the longest step of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepRange {
    pub shortest: f64,
    pub longest: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
enum Rule {
    Fixed { dt: f64, allow_unstable: bool },
    Auto { scale: f64, min: Option<f64> },
}

impl Clock {
    /// The clock of `spec`, with the initial element-eigenvalue limit `exact` and the initial
    /// bound `limit` (`stable::explicit_clock` makes it).
    pub fn new(spec: &DynamicAnalysis, exact: f64, limit: StableStep) -> Clock {
        let (rule, dt0, calibration) = match spec.step {
            TimeStep::Fixed(dt) => (
                Rule::Fixed {
                    dt,
                    allow_unstable: spec.allow_unstable,
                },
                dt,
                exact / limit.dt,
            ),
            TimeStep::Auto { scale, min, .. } => (Rule::Auto { scale, min }, scale * limit.dt, 1.0),
            TimeStep::Adaptive(_) => {
                unreachable!("the scene gives central difference a fixed or automatic step")
            }
        };
        Clock {
            rule,
            dt0,
            calibration,
            limit,
            last: 0.0,
            shortest: f64::INFINITY,
            longest: 0.0,
            shortest_taken: f64::INFINITY,
            longest_taken: 0.0,
            multiple: 1,
        }
    }

    /// Step number `step` from `time`, or why it cannot be taken.
    pub fn next(
        &self,
        model: &Model,
        spec: &DynamicAnalysis,
        time: f64,
        step: usize,
    ) -> Result<Step, StepError> {
        let limit = self.calibration * self.limit.dt;
        let element = || {
            format!(
                "body `{}`, element {}",
                model.bodies[self.limit.body].name, self.limit.element
            )
        };
        match self.rule {
            Rule::Fixed { dt, allow_unstable } => {
                if dt > limit && !allow_unstable {
                    return Err(StepError {
                        status: Status::Unstable,
                        message: format!(
                            "at t = {}: dt = {} exceeds the stability limit {} of the current configuration, set by {}; \
                             lower dt or use dt = \"auto\"",
                            readable(time),
                            readable(dt),
                            readable(limit),
                            element()
                        ),
                        frame: true,
                    });
                }
                let end = snap(step as f64 * dt, dt).min(spec.end_time);
                let length = step_length(end - time, dt);
                Ok(Step {
                    end,
                    length,
                    rule: dt,
                    clipped: length < dt,
                })
            }
            Rule::Auto { scale, min } => {
                let substep = scale * limit;
                let h = substep * self.multiple as f64;
                if let Some(min) = min
                    && substep < min
                {
                    return Err(StepError {
                        status: Status::Diverged,
                        message: format!(
                            "at t = {}: the stable step fell to {}, below analysis.dt_min = {}, set by {}",
                            readable(time),
                            readable(substep),
                            readable(min),
                            element()
                        ),
                        frame: true,
                    });
                }
                let next_frame = model
                    .output
                    .next_frame_after(time * (1.0 + 1e-12))
                    .unwrap_or(f64::INFINITY);
                // a frame time that is the end time but for round-off ends the run there
                let next_frame = if (next_frame - spec.end_time).abs() <= 1e-9 * h {
                    spec.end_time
                } else {
                    next_frame
                };
                let stop = spec.end_time.min(next_frame);
                let remaining = stop - time;
                // the steps left to the stop, each at most h (but for STRETCH): the last
                // EQUAL_STEPS before it are equal, so no short step lands on a frame (no
                // spike in a column, no alternation of long and short steps with frequent
                // frames)
                let left = (remaining / h * (1.0 - STRETCH)).ceil().max(1.0);
                let (end, length) = if left <= 1.0 {
                    (stop, remaining)
                } else if left <= EQUAL_STEPS {
                    (time + remaining / left, remaining / left)
                } else {
                    (time + h, h)
                };
                Ok(Step {
                    end,
                    length,
                    rule: h,
                    clipped: false,
                })
            }
        }
    }

    /// Auto: the next steps are taken `multiple` rule steps at a time (subcycling).
    pub fn take_together(&mut self, multiple: u64) {
        self.multiple = multiple;
    }

    /// `step` was taken; `limit` is the stable step of the new configuration.
    pub fn took(&mut self, step: Step, limit: StableStep) {
        let h = step.length;
        self.last = h;
        if !step.clipped {
            self.shortest = self.shortest.min(step.rule);
            self.longest = self.longest.max(step.rule);
        }
        self.shortest_taken = self.shortest_taken.min(h);
        self.longest_taken = self.longest_taken.max(h);
        self.limit = limit;
    }

    /// The shortest and the longest step the rule set; the steps taken when every step was
    /// clipped (an end time or frames closer than one stable step). None before the first.
    pub fn range(&self) -> Option<StepRange> {
        if self.longest > 0.0 {
            Some(StepRange {
                shortest: self.shortest,
                longest: self.longest,
            })
        } else if self.longest_taken > 0.0 {
            Some(StepRange {
                shortest: self.shortest_taken,
                longest: self.longest_taken,
            })
        } else {
            None
        }
    }

    /// A fixed step above the limit of the committed configuration (the run was allowed to
    /// go on: an element that fails then is the instability's doing).
    pub fn fixed_above_limit(&self) -> bool {
        matches!(self.rule, Rule::Fixed { dt, .. } if dt > self.calibration * self.limit.dt)
    }
}
