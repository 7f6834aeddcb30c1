//! The output block of the scene schema: frames and probes.

use crate::output::vtk::Compression;
use serde::Deserialize;

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Write a VTK frame every N steps (and always the first and last). 0 writes none.
    /// Default 1, or 0 where `frame_interval` is given (`frame_every()`).
    #[serde(default)]
    pub frame_every: Option<usize>,
    /// Times at which a frame is written besides (dynamic steps end exactly there).
    /// Validation adds the multiples of `frame_interval` to it.
    #[serde(default)]
    pub frame_times: Vec<f64>,
    /// A frame every this much simulated time (seconds in SI scenes), besides: the times
    /// k * frame_interval up to the end time join `frame_times`.
    #[serde(default)]
    pub frame_interval: Option<f64>,
    /// `none` (default), `lz4` or `zlib` for the .vtu arrays.
    #[serde(default)]
    pub compression: Compression,
    /// Where the frames' points are: `current` (default) or `reference`.
    #[serde(default)]
    pub points: FramePoints,
    #[serde(default)]
    pub probe: Vec<ProbeSpec>,
    /// The window (a time > 0) over which history.csv's `contact_force_avg[PAIR]` averages
    /// each pair's force, and from which summary.json's `contact.peak_force` is taken; 0:
    /// none (`peak_force` is the raw multipliers' peak). Default: 10 first steps for central
    /// difference, none for the other integrators.
    #[serde(default)]
    pub contact_force_window: Option<f64>,
    /// A history.csv row at least every N steps (1: every step).
    #[serde(default)]
    pub history_every: Option<usize>,
    /// A history.csv row at every multiple of this time. Without either key: every step, and
    /// for central difference a row at every `end_time / DEFAULT_HISTORY_ROWS`.
    #[serde(default)]
    pub history_interval: Option<f64>,
}

/// The history rows of a central-difference run that names no cadence: at most this many on
/// the time grid (and the extremes between them, `output::thinning`), so an explicit run of
/// 1e5 steps or more writes a few megabytes, not one row a step. (The implicit and static
/// paths, whose steps each cost a solve, write every step.)
pub const DEFAULT_HISTORY_ROWS: f64 = 1e4;

/// The configuration a frame's points show; the `displacement` and `reference_coordinates`
/// arrays are written either way.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FramePoints {
    /// The deformed configuration: the mesh moves as the series plays.
    #[default]
    Current,
    /// The initial coordinates, for Warp By Vector on `displacement` with a scale factor.
    Reference,
}

impl OutputSpec {
    /// Frames every N steps: as given, else 1, or 0 where `frame_interval` is given (a frame
    /// every interval of time replaces the frames per step; it once came on top of them,
    /// 1 783 frames and 150 MB where the interval asked for 7).
    pub fn frame_every(&self) -> usize {
        self.frame_every
            .unwrap_or(if self.frame_interval.is_some() { 0 } else { 1 })
    }

    /// Which steps get a history row: the keys; without them a row every step, or for
    /// central difference (`explicit_end_time`: its end time) at every `end_time /
    /// DEFAULT_HISTORY_ROWS`.
    pub fn history_cadence(
        &self,
        explicit_end_time: Option<f64>,
    ) -> crate::output::thinning::Cadence {
        use crate::output::thinning::Cadence;
        if self.history_every.is_some() || self.history_interval.is_some() {
            return Cadence {
                every: self.history_every,
                interval: self.history_interval,
            };
        }
        match explicit_end_time.filter(|t| *t > 0.0) {
            Some(end_time) => Cadence {
                every: None,
                interval: Some(end_time / DEFAULT_HISTORY_ROWS),
            },
            None => Cadence {
                every: Some(1),
                interval: None,
            },
        }
    }

    /// The first frame time after `time` (strictly), or None. The validated `frame_times`
    /// are sorted, so a binary search finds it: a run of many frames does not scan the list
    /// at every step.
    pub fn next_frame_after(&self, time: f64) -> Option<f64> {
        let k = self.frame_times.partition_point(|t| *t <= time);
        self.frame_times.get(k).copied()
    }

    /// Whether a listed frame time satisfies `hit` among those in [low, high] (sorted: found
    /// by a binary search, then a walk over the few in the range).
    pub fn any_frame_in(&self, low: f64, high: f64, hit: impl Fn(f64) -> bool) -> bool {
        let k = self.frame_times.partition_point(|t| *t < low);
        self.frame_times[k..]
            .iter()
            .take_while(|t| **t <= high)
            .any(|t| hit(*t))
    }
}

/// A probed quantity; the name in the scene and in history.csv is the serde name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum Quantity {
    #[serde(rename = "u_x")]
    DisplacementX,
    #[serde(rename = "u_y")]
    DisplacementY,
    #[serde(rename = "v_x")]
    VelocityX,
    #[serde(rename = "v_y")]
    VelocityY,
    #[serde(rename = "a_x")]
    AccelerationX,
    #[serde(rename = "a_y")]
    AccelerationY,
    /// Linear momentum sum m v of the set (lumped mass), not a mean.
    #[serde(rename = "p_x")]
    MomentumX,
    #[serde(rename = "p_y")]
    MomentumY,
    /// Current coordinates (initial + displacement): with `max` / `min`, where the set
    /// reaches.
    #[serde(rename = "x")]
    CoordinateX,
    #[serde(rename = "y")]
    CoordinateY,
    /// The set's extent in x of the current configuration, max x - min x (an axisymmetric
    /// body's set: the body of revolution's, 2 max r, its diameter); in y, max y - min y.
    /// A length, not a mean: the statistic does not apply.
    #[serde(rename = "extent_x")]
    ExtentX,
    #[serde(rename = "extent_y")]
    ExtentY,
    /// Support reaction summed over the set's constrained DOFs: f_int - f_ext (+ m a with
    /// the lumped mass in dynamics), the force the supports exert on the body; f_int the
    /// internal force the step converged with.
    #[serde(rename = "reaction_x")]
    ReactionX,
    #[serde(rename = "reaction_y")]
    ReactionY,
    #[serde(rename = "s_xx")]
    StressXX,
    #[serde(rename = "s_yy")]
    StressYY,
    #[serde(rename = "s_xy")]
    StressXY,
    #[serde(rename = "s_zz")]
    StressZZ,
    #[serde(rename = "von_mises")]
    VonMises,
    #[serde(rename = "eq_plastic_strain")]
    EqPlasticStrain,
    /// Johnson-Cook materials only.
    #[serde(rename = "temperature")]
    Temperature,
}

impl Quantity {
    /// The name used in scenes and history.csv.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::DisplacementX => "u_x",
            Quantity::DisplacementY => "u_y",
            Quantity::VelocityX => "v_x",
            Quantity::VelocityY => "v_y",
            Quantity::AccelerationX => "a_x",
            Quantity::AccelerationY => "a_y",
            Quantity::MomentumX => "p_x",
            Quantity::MomentumY => "p_y",
            Quantity::CoordinateX => "x",
            Quantity::CoordinateY => "y",
            Quantity::ExtentX => "extent_x",
            Quantity::ExtentY => "extent_y",
            Quantity::ReactionX => "reaction_x",
            Quantity::ReactionY => "reaction_y",
            Quantity::StressXX => "s_xx",
            Quantity::StressYY => "s_yy",
            Quantity::StressXY => "s_xy",
            Quantity::StressZZ => "s_zz",
            Quantity::VonMises => "von_mises",
            Quantity::EqPlasticStrain => "eq_plastic_strain",
            Quantity::Temperature => "temperature",
        }
    }

    /// Nodal quantities are averaged over node sets, the others over element sets.
    pub fn is_nodal(self) -> bool {
        matches!(
            self,
            Quantity::DisplacementX
                | Quantity::DisplacementY
                | Quantity::VelocityX
                | Quantity::VelocityY
                | Quantity::AccelerationX
                | Quantity::AccelerationY
                | Quantity::MomentumX
                | Quantity::MomentumY
                | Quantity::CoordinateX
                | Quantity::CoordinateY
                | Quantity::ExtentX
                | Quantity::ExtentY
                | Quantity::ReactionX
                | Quantity::ReactionY
        )
    }

    /// The quantity's unit in SI scenes (the scene's own units otherwise): `m`, `m/s`, ...
    /// Per unit depth where a plane-strain body says so (section 4 of the user guide).
    pub fn unit(self) -> &'static str {
        match self {
            Quantity::DisplacementX
            | Quantity::DisplacementY
            | Quantity::CoordinateX
            | Quantity::CoordinateY
            | Quantity::ExtentX
            | Quantity::ExtentY => "m",
            Quantity::VelocityX | Quantity::VelocityY => "m/s",
            Quantity::AccelerationX | Quantity::AccelerationY => "m/s^2",
            Quantity::MomentumX | Quantity::MomentumY => "kg m/s",
            Quantity::ReactionX | Quantity::ReactionY => "N",
            Quantity::StressXX
            | Quantity::StressYY
            | Quantity::StressXY
            | Quantity::StressZZ
            | Quantity::VonMises => "Pa",
            Quantity::EqPlasticStrain => "",
            Quantity::Temperature => "K",
        }
    }

    /// Quantities that are one number of the whole set (a sum or a length), so `max` and
    /// `min` do not apply.
    pub fn is_whole_set(self) -> bool {
        matches!(
            self,
            Quantity::MomentumX
                | Quantity::MomentumY
                | Quantity::ReactionX
                | Quantity::ReactionY
                | Quantity::ExtentX
                | Quantity::ExtentY
        )
    }
}

/// A history column: the mean of a nodal quantity over a node set, or of a stress quantity
/// over an element set. Written as `QUANTITY[SET]` (`QUANTITY[BODY.SET]` with several bodies).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    pub quantity: Quantity,
    pub body: Option<String>,
    pub set: String,
    /// How the set's values combine: `mean` (default; momentum and reaction: the sum), `max` or `min`
    /// (over nodes, or over the elements' integration points), `mass_mean` (nodal quantities
    /// of a dynamic analysis: weighted by the nodes' lumped mass; of `v_x`, `v_y` the velocity
    /// of the set's centre of mass).
    #[serde(default)]
    pub statistic: Statistic,
}

/// How a probe combines the values of its set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Statistic {
    #[default]
    Mean,
    Max,
    Min,
    /// sum m q / sum m over the set's nodes, m their lumped mass.
    MassMean,
}

impl Quantity {
    /// Whether the mass-weighted mean of the quantity over a node set means something: the
    /// nodal kinematic quantities (of `x`, `y` the centre of mass).
    pub fn has_mass_mean(self) -> bool {
        matches!(
            self,
            Quantity::DisplacementX
                | Quantity::DisplacementY
                | Quantity::VelocityX
                | Quantity::VelocityY
                | Quantity::AccelerationX
                | Quantity::AccelerationY
                | Quantity::CoordinateX
                | Quantity::CoordinateY
        )
    }
}
