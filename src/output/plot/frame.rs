//! A frame's point arrays as the columns of a chart (`impact plot FRAME.vtu`): one row per
//! point, the columns `x` and `y` (the point's coordinates) and every point array of the frame
//! (a scalar by its name; a vector's components as NAME_x and NAME_y; a tensor's as NAME_XX,
//! NAME_YY, NAME_ZZ, NAME_XY, NAME_YZ, NAME_XZ), the rows sorted by the chart's x column and,
//! with `keep`, only those where that column is not zero (the touching nodes of a contact
//! surface: `contact_status`).

use crate::output::OutputError;
use crate::output::vtu::{Section, Values, read_frame};
use std::path::Path;

/// The columns `names` of the frame at `path` (the first is the chart's x: the rows are
/// sorted by it), over the points where the column `keep` is not zero (all without it).
///
/// A missing column is an [`OutputError::Invalid`] that names it and lists the columns there
/// are.
pub fn frame_columns(
    path: &Path,
    names: &[&str],
    keep: Option<&str>,
) -> Result<Vec<Vec<f64>>, OutputError> {
    let frame = read_frame(path)?;
    // the points' coordinates, x and y of three components
    let mut available: Vec<(String, Vec<f64>)> = match frame.floats(Section::Points, "Points") {
        Some((_, v)) => ["x", "y"]
            .into_iter()
            .enumerate()
            .map(|(k, name)| (name.into(), v.iter().skip(k).step_by(3).copied().collect()))
            .collect(),
        None => Vec::new(),
    };
    let mut add = |name: &str, components: usize, values: &[f64]| {
        let suffixes: &[&str] = match components {
            1 => &[""],
            3 => &["_x", "_y"],
            6 => &["_XX", "_YY", "_ZZ", "_XY", "_YZ", "_XZ"],
            _ => &[],
        };
        for (k, suffix) in suffixes.iter().enumerate() {
            let column = values.iter().skip(k).step_by(components).copied().collect();
            available.push((format!("{name}{suffix}"), column));
        }
    };
    for array in &frame.arrays {
        match (&array.values, array.section) {
            (Values::Float64(v), Section::PointData) => add(&array.name, array.components, v),
            (Values::Int64(v), Section::PointData) => {
                let v: Vec<f64> = v.iter().map(|i| *i as f64).collect();
                add(&array.name, 1, &v);
            }
            _ => {}
        }
    }
    let column = |name: &str| -> Result<&Vec<f64>, OutputError> {
        available
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v)
            .ok_or_else(|| {
                let names: Vec<&str> = available.iter().map(|(n, _)| n.as_str()).collect();
                OutputError::invalid(
                    path,
                    format!(
                        "no point column `{name}` in the frame; the columns are: {}",
                        names.join(", ")
                    ),
                )
            })
    };
    let chosen: Vec<&Vec<f64>> = names.iter().map(|n| column(n)).collect::<Result<_, _>>()?;
    let kept = keep.map(column).transpose()?;
    let mut rows: Vec<usize> = (0..frame.points)
        .filter(|i| kept.is_none_or(|k| k[*i] != 0.0))
        .collect();
    if let Some(x) = chosen.first() {
        rows.sort_by(|a, b| x[*a].total_cmp(&x[*b]));
    }
    Ok(chosen
        .iter()
        .map(|c| rows.iter().map(|i| c[*i]).collect())
        .collect())
}
