//! Checks of a generator's parameters: each error names the scene key.

use std::ops::RangeInclusive;

use crate::mesh::MeshError;
use crate::mesh::plane::Point;

/// Accepted range of a grading (largest / smallest element size).
const GRADING_RANGE: RangeInclusive<f64> = 1e-6..=1e6;

/// The default grading: 1, uniform.
pub(super) fn one() -> f64 {
    1.0
}

/// The error of the parameter `key`.
pub(super) fn param(key: &str, reason: impl Into<String>) -> MeshError {
    MeshError::Parameter {
        key: key.to_string(),
        reason: reason.into(),
    }
}

/// `value` if it is finite and > 0.
pub(super) fn positive(key: &str, value: f64) -> Result<f64, MeshError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(param(
            key,
            format!("must be a finite number > 0, got {value}"),
        ))
    }
}

/// `value` if it is a grading in [1e-6, 1e6].
pub(super) fn grading(key: &str, value: f64) -> Result<f64, MeshError> {
    if GRADING_RANGE.contains(&value) {
        Ok(value)
    } else {
        Err(param(
            key,
            format!("must be in [1e-6, 1e6] (1 = uniform), got {value}"),
        ))
    }
}

/// The most divisions along one direction of a generated mesh (a count beyond it is a typo
/// that would allocate without end, not a mesh).
pub const MAX_DIVISIONS: usize = 20_000;

/// The most elements a `rectangle` may generate (4000 x 2500; a million load in about a second).
pub const MAX_ELEMENTS: usize = 10_000_000;

/// A count `value` in [min, MAX_DIVISIONS].
pub(super) fn at_least(key: &str, value: usize, min: usize) -> Result<usize, MeshError> {
    if value > MAX_DIVISIONS {
        Err(param(
            key,
            format!("must be at most {MAX_DIVISIONS}, got {value}"),
        ))
    } else if value >= min {
        Ok(value)
    } else {
        Err(param(key, format!("must be >= {min}, got {value}")))
    }
}

/// `p` if both coordinates are finite.
pub(super) fn finite_point(key: &str, p: Point) -> Result<Point, MeshError> {
    if p.iter().all(|c| c.is_finite()) {
        Ok(p)
    } else {
        Err(param(key, format!("must be finite, got {p:?}")))
    }
}
