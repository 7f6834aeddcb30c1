//! A piecewise-linear factor of time, constant beyond its ends: the `[[curve]]` of a load,
//! a prescribed displacement or an obstacle's motion.

/// A piecewise-linear curve through `points` ([time, value], times increasing), constant
/// beyond its ends.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    pub points: Vec<[f64; 2]>,
}

impl Curve {
    pub fn value(&self, t: f64) -> f64 {
        let p = &self.points;
        if t <= p[0][0] {
            return p[0][1];
        }
        for w in p.windows(2) {
            if t <= w[1][0] {
                let s = (t - w[0][0]) / (w[1][0] - w[0][0]);
                return w[0][1] + s * (w[1][1] - w[0][1]);
            }
        }
        p[p.len() - 1][1]
    }

    /// The slope of the segment at `t` (the one ending at `t` at a breakpoint, the first at
    /// the first point), 0 before and beyond the ends: the rate of what the curve scales.
    pub fn slope(&self, t: f64) -> f64 {
        (self.points.windows(2))
            .find(|w| t <= w[1][0])
            .filter(|w| t >= w[0][0])
            .map_or(0.0, |w| (w[1][1] - w[0][1]) / (w[1][0] - w[0][0]))
    }
}
