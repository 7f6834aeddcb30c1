//! The sweep's charts, PNG and SVG each:
//!
//! ```text
//! error_vs_cpu    primary error against each case's CPU time, one series per integrator
//!                 (and other varied values that are not dt or a mesh), and the Pareto
//!                 front over all of them: the speed-vs-accuracy chart
//! error_vs_cpu_converged  the same against the converged reference (the finest case or
//!                 Richardson's extrapolation), beside a declared closed-form reference
//! error_vs_dt     the errors against dt, with the least-squares slope of log e against
//!                 log dt of each series printed in its fit line's legend entry
//! error_vs_h      the same against the shortest element edge h
//! stability_map   dt / dt_crit (columns) against the series (rows): unstable (status
//!                 unstable or diverged), drift (energy gained: balance error > 5 % and the
//!                 final energy above the initial), damped (bounded, more than 5 % of the
//!                 energy lost: numerical dissipation), stable, refused
//! measure_NAME    each --measure against h or dt, a series per method, with the
//!                 extrapolated value and the GCI bar (qoi.rs)
//! error_vs_cpu_NAME  its error against the converged value, against CPU time, and the
//!                 Pareto front
//! ```
//! primary error: force_l2, else |peak_force_error| (measure::Row::primary_error).

use super::measure::{Row, series_indices};
use super::plan::Plan;
use super::qoi::{MeasureScore, Units, with_unit};
use crate::analysis::RunError;
use crate::output::plot::{self, Cell, CellKind, Chart, Map, Series, SeriesStyle};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Energy drift (relative) above which a bounded run is drawn as `drift`.
pub const DRIFT_LIMIT: f64 = 0.05;

/// Least-squares slope of log y against log x (None with fewer than two distinct x).
pub fn fitted_slope(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = logs.len() as f64;
    let mean_x = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_y = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = logs.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
    if logs.len() < 2 || sxx <= 1e-24 {
        return None;
    }
    let sxy: f64 = logs.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
    let slope = sxy / sxx;
    Some((slope, mean_y - slope * mean_x))
}

fn grouped<'a>(plan: &Plan, rows: &'a [Row]) -> Vec<(String, Vec<&'a Row>)> {
    series_indices(plan, rows)
        .into_iter()
        .map(|(label, members)| (label, members.into_iter().map(|k| &rows[k]).collect()))
        .collect()
}

/// The series of the charts: each label with its rows.
type Groups<'a> = [(String, Vec<&'a Row>)];

/// Writes the charts that the rows support; returns their paths. `units`: the scene's (for
/// the axes), `notes`: lines shown on the force-error charts.
pub fn write_all(
    (plan, rows): (&Plan, &[Row]),
    title: &str,
    units: Option<&Units>,
    notes: &[String],
    out: &Path,
) -> Result<Vec<PathBuf>, RunError> {
    let mut written = Vec::new();
    let groups = grouped(plan, rows);
    let look = Look {
        title,
        units,
        notes,
    };
    let primary_name = if rows.iter().any(|r| r.measures.force_l2.is_some()) {
        "contact force L2 error (relative)"
    } else {
        "|peak force error| (relative)"
    };
    written.extend(error_vs_cpu(
        &groups,
        &look,
        primary_name,
        out,
        Accuracy::Primary,
    )?);
    if rows.iter().any(|r| r.converged_error().is_some()) {
        let name = if rows.iter().any(|r| r.measures.converged_force_l2.is_some()) {
            "contact force L2 error against the converged reference"
        } else {
            "|peak force error| against the converged reference"
        };
        written.extend(error_vs_cpu(
            &groups,
            &look,
            name,
            out,
            Accuracy::Converged,
        )?);
    }
    written.extend(convergence(rows, &groups, &look, primary_name, out)?);
    written.extend(stability_map(rows, &groups, title, out)?);
    Ok(written)
}

/// What every chart of a sweep shares: its title, the scene's units, the notes to show.
struct Look<'a> {
    title: &'a str,
    units: Option<&'a Units>,
    notes: &'a [String],
}

impl Look<'_> {
    /// An axis label with the unit `unit` picks from the scene's units.
    fn axis(&self, label: &str, unit: fn(&Units) -> &'static str) -> String {
        with_unit(label, self.units.map_or("", unit))
    }
}

/// Whether a case finished with status `ok` (the charts of errors plot only those).
fn finished(r: &&&Row) -> bool {
    r.status == "ok"
}

/// Speed against accuracy: error_vs_cpu, the primary error against each case's own CPU time
/// (its wall time where a record predates it), with the Pareto front: the cases no other
/// case beats on both time and error, the cheapest way to each accuracy.
fn error_vs_cpu(
    groups: &Groups,
    look: &Look,
    primary_name: &str,
    out: &Path,
    accuracy: Accuracy,
) -> Result<Vec<PathBuf>, RunError> {
    let error = |r: &Row| match &accuracy {
        Accuracy::Primary => r.primary_error(),
        Accuracy::Converged => r.converged_error(),
        Accuracy::Quantity(k, _) => r.quantity_errors.get(*k).copied().flatten().map(f64::abs),
    };
    let mut series: Vec<Series> = groups
        .iter()
        .filter_map(|(label, members)| {
            let mut points: Vec<(f64, f64)> = members
                .iter()
                .filter(finished)
                .filter_map(|r| Some((r.cpu_seconds.or(r.wall_seconds)?, error(r)?)))
                .filter(|(x, y)| *x > 0.0 && *y > 0.0)
                .collect();
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            (!points.is_empty()).then(|| Series {
                label: label.clone(),
                points,
                style: SeriesStyle::LineAndMarkers,
            })
        })
        .collect();
    if series.is_empty() {
        return Ok(Vec::new());
    }
    let all: Vec<(f64, f64)> = series.iter().flat_map(|s| s.points.clone()).collect();
    series.push(Series {
        label: "Pareto front".into(),
        points: pareto_front(all),
        style: SeriesStyle::Line,
    });
    let chart = Chart {
        title: format!("{}: error against CPU time", look.title),
        x_label: "CPU time of the case [s]".into(),
        y_label: primary_name.into(),
        series,
        log_x: true,
        log_y: true,
        x_limits: Default::default(),
        y_limits: Default::default(),
        notes: look.notes.to_vec(),
    };
    let name = match &accuracy {
        Accuracy::Primary => "error_vs_cpu".to_string(),
        Accuracy::Converged => "error_vs_cpu_converged".to_string(),
        Accuracy::Quantity(_, stem) => format!("error_vs_cpu_{stem}"),
    };
    both(&chart, out, &name)
}

/// The charts of each `--measure`: `measure_NAME` (its value against the refinement, one
/// series per method, with each series' extrapolated value and GCI band) and
/// `error_vs_cpu_NAME` (its error against the converged value, against CPU time, with the
/// Pareto front). NAME: the measure's name with every character other than a letter, digit
/// or `_` replaced by `_`.
pub fn write_measures(
    (plan, rows): (&Plan, &[Row]),
    scores: &[MeasureScore],
    title: &str,
    units: &Units,
    out: &Path,
) -> Result<Vec<PathBuf>, RunError> {
    let groups = series_indices(plan, rows);
    let mut written = Vec::new();
    for (k, score) in scores.iter().enumerate() {
        let stem = slug(&score.measure.name);
        let notes: Vec<String> = score
            .series
            .iter()
            .filter_map(|s| {
                let verdict = s.extrapolation.as_ref()?.verdict?;
                Some(shortened(&format!("{}: {verdict}", s.series), 100))
            })
            .collect();
        let look = Look {
            title,
            units: Some(units),
            notes: &notes,
        };
        if let Some(chart) = measure_chart(k, score, rows, &groups, &look) {
            written.extend(both(&chart, out, &format!("measure_{stem}"))?);
        }
        let error_groups: Vec<(String, Vec<&Row>)> = groups
            .iter()
            .map(|(label, members)| (label.clone(), members.iter().map(|&i| &rows[i]).collect()))
            .collect();
        let common = score
            .series
            .first()
            .and_then(|s| s.reference_series.as_ref());
        let against = match (score.measure.reference, common) {
            (Some(value), _) => format!("the reference {value}"),
            (None, Some(from)) => format!("the converged value of {from}"),
            (None, None) => "the converged value".to_string(),
        };
        let name = format!(
            "|{} error| (relative, against {against})",
            score.measure.name
        );
        written.extend(error_vs_cpu(
            &error_groups,
            &look,
            &name,
            out,
            Accuracy::Quantity(k, stem),
        )?);
    }
    Ok(written)
}

/// measure_NAME: the values of measure `k` against h or dt, a series per method, with the
/// extrapolated value (a line over the levels' span) and the GCI band (a bar at the finest
/// level, f1 (1 +- GCI)) of each series that has them.
fn measure_chart(
    k: usize,
    score: &MeasureScore,
    rows: &[Row],
    groups: &[(String, Vec<usize>)],
    look: &Look,
) -> Option<Chart> {
    let refinement = score.series.iter().find_map(|s| s.refinement)?;
    let x_of = |r: &Row| if refinement == "h" { Some(r.h) } else { r.dt };
    let mut series = Vec::new();
    for ((label, members), scored) in groups.iter().zip(&score.series) {
        let mut points: Vec<(f64, f64)> = members
            .iter()
            .map(|&i| &rows[i])
            .filter(|r| r.status == "ok")
            .filter_map(|r| Some((x_of(r)?, r.quantities[k]?)))
            .filter(|(x, y)| *x > 0.0 && y.is_finite())
            .collect();
        if points.is_empty() {
            continue;
        }
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (low, high) = (points[0].0, points[points.len() - 1].0);
        series.push(Series {
            label: label.clone(),
            points,
            style: SeriesStyle::LineAndMarkers,
        });
        let Some(e) = &scored.extrapolation else {
            continue;
        };
        if let (Some(value), Some(gci)) = (e.value, e.gci) {
            series.push(Series {
                label: format!(
                    "{label}: extrapolated {value:.5e}, order {:.2}",
                    e.order.unwrap_or(f64::NAN)
                ),
                points: vec![(low, value), (high, value)],
                style: SeriesStyle::Line,
            });
            let f1 = e.values[0];
            let (a, b) = (f1 - gci * f1.abs(), f1 + gci * f1.abs());
            series.push(Series {
                label: format!("{label}: GCI band of the finest, +-{:.2} %", 100.0 * gci),
                points: vec![(low, a), (low, b)],
                style: SeriesStyle::LineAndMarkers,
            });
        }
    }
    if series.is_empty() {
        return None;
    }
    let (x_label, unit) = if refinement == "h" {
        (
            "shortest element edge h",
            look.units.map_or("", |u| u.length),
        )
    } else {
        ("time step dt", look.units.map_or("", |u| u.time))
    };
    Some(Chart {
        title: format!("{}: {}", look.title, score.measure.name),
        x_label: with_unit(x_label, unit),
        y_label: with_unit(&score.measure.name, &score.unit),
        series,
        log_x: true,
        log_y: false,
        x_limits: Default::default(),
        y_limits: Default::default(),
        notes: look.notes.to_vec(),
    })
}

/// `text` cut to `width` characters, with an ellipsis when cut.
fn shortened(text: &str, width: usize) -> String {
    if text.chars().count() <= width {
        text.to_string()
    } else {
        let cut: String = text.chars().take(width - 1).collect();
        format!("{cut}…")
    }
}

/// A file-name stem of a measure's name.
fn slug(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    s.trim_matches('_').to_string()
}

/// Which error a speed chart plots: against the scene's reference (or the finest case
/// without one), or against the converged reference beside a declared one.
#[derive(Clone)]
enum Accuracy {
    Primary,
    Converged,
    /// The error of `--measure` k; the chart's file name ends with the measure's slug.
    Quantity(usize, String),
}

/// The (time, error) points no other point beats on both, by increasing time: each has a
/// lower error than every cheaper one.
pub fn pareto_front(mut points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    points.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for p in points {
        if front.last().is_none_or(|last| p.1 < last.1) {
            front.push(p);
        }
    }
    front
}

/// Convergence: error_vs_dt and error_vs_h, each series with its fitted slope.
fn convergence(
    rows: &[Row],
    groups: &Groups,
    look: &Look,
    primary_name: &str,
    out: &Path,
) -> Result<Vec<PathBuf>, RunError> {
    let mut written = Vec::new();
    type Measure = fn(&Row) -> Option<f64>;
    let mut measures: Vec<(&str, Measure)> = vec![("", |r: &Row| r.primary_error())];
    if rows.iter().any(|r| r.measures.force_l2_smooth.is_some()) {
        measures.push((" away from jumps", |r: &Row| r.measures.force_l2_smooth));
    }
    type Abscissa = fn(&Row) -> Option<f64>;
    let axes: [(&str, String, Abscissa); 2] = [
        ("dt", look.axis("time step dt", |u| u.time), |r: &Row| r.dt),
        (
            "h",
            look.axis("shortest element edge h", |u| u.length),
            |r: &Row| Some(r.h),
        ),
    ];
    for (name, x_label, x_of) in axes {
        let mut series = Vec::new();
        for (label, members) in groups {
            for (suffix, measure) in &measures {
                let mut points: Vec<(f64, f64)> = members
                    .iter()
                    .filter(finished)
                    .filter_map(|r| Some((x_of(r)?, measure(r)?)))
                    .filter(|(x, y)| *x > 0.0 && *y > 0.0)
                    .collect();
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
                let Some((slope, intercept)) = fitted_slope(&points) else {
                    continue;
                };
                let (low, high) = (points[0].0, points[points.len() - 1].0);
                let fit = |x: f64| (intercept + slope * x.ln()).exp();
                series.push(Series {
                    label: format!("{label}{suffix}"),
                    points,
                    style: SeriesStyle::Markers,
                });
                series.push(Series {
                    label: format!("fit: slope {slope:.2}"),
                    points: vec![(low, fit(low)), (high, fit(high))],
                    style: SeriesStyle::Line,
                });
            }
        }
        if !series.is_empty() {
            let chart = Chart {
                title: format!("{}: error against {name}", look.title),
                x_label,
                y_label: primary_name.into(),
                series,
                log_x: true,
                log_y: true,
                x_limits: Default::default(),
                y_limits: Default::default(),
                notes: look.notes.to_vec(),
            };
            written.extend(both(&chart, out, &format!("error_vs_{name}"))?);
        }
    }
    Ok(written)
}

/// stability_map: one column per dt / dt_crit, one row per series.
fn stability_map(
    rows: &[Row],
    groups: &Groups,
    title: &str,
    out: &Path,
) -> Result<Vec<PathBuf>, RunError> {
    let mut written = Vec::new();
    let mut columns: BTreeMap<i64, String> = BTreeMap::new();
    let key = |ratio: f64| (ratio * 1e3).round() as i64;
    for row in rows {
        if let Some(ratio) = row.dt_over_dt_crit() {
            columns.entry(key(ratio)).or_insert_with(|| {
                format!("{ratio:.3}")
                    .trim_end_matches('0')
                    .trim_end_matches('.')
                    .to_string()
            });
        }
    }
    if columns.is_empty() || rows.iter().all(|r| r.status == "missing") {
        return Ok(written);
    }
    let column_keys: Vec<i64> = columns.keys().copied().collect();
    let mut cells = Vec::new();
    for (_, members) in groups {
        let mut line = vec![None; column_keys.len()];
        for row in members {
            let Some(ratio) = row.dt_over_dt_crit() else {
                continue;
            };
            let j = column_keys
                .binary_search(&key(ratio))
                .expect("listed above");
            line[j] = Some(cell(row));
        }
        cells.push(line);
    }
    let map = Map {
        title: format!(
            "{title}: stability (energy drift limit {:.0} %)",
            100.0 * DRIFT_LIMIT
        ),
        x_label: "dt / dt_crit (central difference, lumped mass)".into(),
        columns: columns.into_values().collect(),
        rows: groups.iter().map(|(l, _)| l.clone()).collect(),
        cells,
    };
    for extension in ["png", "svg"] {
        let path = out.join(format!("stability_map.{extension}"));
        plot::write_map(&map, &path)?;
        written.push(path);
    }
    Ok(written)
}

/// A stability map cell of a case.
pub fn cell(row: &Row) -> Cell {
    let drift = row.measures.energy_drift.unwrap_or(0.0);
    let change = row.measures.energy_change.unwrap_or(0.0);
    match row.status.as_str() {
        "ok" if drift > DRIFT_LIMIT && change > 0.0 => Cell {
            text: format!("drift +{:.0}%", 100.0 * change),
            kind: CellKind::Drift,
        },
        "ok" if change < -DRIFT_LIMIT => Cell {
            text: format!("damped {:.0}%", 100.0 * change),
            kind: CellKind::Damped,
        },
        "ok" => Cell {
            text: "stable".into(),
            kind: CellKind::Stable,
        },
        "unstable" | "diverged" => Cell {
            text: row.status.clone(),
            kind: CellKind::Unstable,
        },
        other => Cell {
            text: other.to_string(),
            kind: CellKind::Other,
        },
    }
}

fn both(chart: &Chart, out: &Path, stem: &str) -> Result<Vec<PathBuf>, RunError> {
    let mut paths = Vec::new();
    for extension in ["png", "svg"] {
        let path = out.join(format!("{stem}.{extension}"));
        plot::write(chart, &path)?;
        paths.push(path);
    }
    Ok(paths)
}

#[cfg(test)]
mod tests {
    /// Goal: the Pareto front keeps exactly the points no other beats on both time and error.
    /// Reference, by hand: of (1, 0.5), (2, 0.6), (2, 0.1), (3, 0.3), (4, 0.05), (5, 0.05),
    /// (0.5, 0.9), the front is (0.5, 0.9), (1, 0.5), (2, 0.1), (4, 0.05): (2, 0.6) and
    /// (3, 0.3) are beaten by (2, 0.1), and (5, 0.05) by (4, 0.05) at a lower time.
    #[test]
    fn pareto_front_keeps_the_cheapest_point_of_each_accuracy() {
        let points = vec![
            (1.0, 0.5),
            (2.0, 0.6),
            (2.0, 0.1),
            (3.0, 0.3),
            (4.0, 0.05),
            (5.0, 0.05),
            (0.5, 0.9),
        ];
        assert_eq!(
            super::pareto_front(points),
            vec![(0.5, 0.9), (1.0, 0.5), (2.0, 0.1), (4.0, 0.05)]
        );
    }
}
