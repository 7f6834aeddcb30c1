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
//! ```
//! primary error: force_l2, else |peak_force_error| (measure::Row::primary_error).

use super::measure::Row;
use super::plan::Plan;
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

/// Whether a key is a refinement or the method: dt, the integrator, a mesh parameter.
fn is_method_or_refinement(key: &str) -> bool {
    key == "analysis.dt" || key == "analysis.integrator" || key.contains(".mesh.")
}

/// Keys that do not name a series: those varied together with a refinement or the method
/// (`--vary "analysis.integrator,analysis.mass=..."`).
fn unlabelled_keys(plan: &Plan) -> Vec<String> {
    plan.variations
        .iter()
        .filter(|v| v.keys.iter().any(|k| is_method_or_refinement(k)))
        .flat_map(|v| v.keys.iter().cloned())
        .collect()
}

/// The series a row belongs to: its integrator and the varied values that are not dt,
/// the integrator, a mesh parameter or varied together with one of those.
pub fn series_label(row: &Row, unlabelled: &[String]) -> String {
    let mut label = row.integrator.clone();
    for (key, value) in &row.case.values {
        if unlabelled.contains(key) {
            continue;
        }
        let short = key.rsplit('.').next().unwrap_or(key);
        label.push_str(&format!(", {short}={value}"));
    }
    label
}

fn grouped<'a>(plan: &Plan, rows: &'a [Row]) -> Vec<(String, Vec<&'a Row>)> {
    let unlabelled = unlabelled_keys(plan);
    let mut groups: Vec<(String, Vec<&Row>)> = Vec::new();
    for row in rows {
        let label = series_label(row, &unlabelled);
        match groups.iter_mut().find(|(l, _)| *l == label) {
            Some((_, members)) => members.push(row),
            None => groups.push((label, vec![row])),
        }
    }
    groups
}

/// The series of the charts: each label with its rows.
type Groups<'a> = [(String, Vec<&'a Row>)];

/// Writes the charts that the rows support; returns their paths.
pub fn write_all(
    plan: &Plan,
    rows: &[Row],
    title: &str,
    out: &Path,
) -> Result<Vec<PathBuf>, RunError> {
    let mut written = Vec::new();
    let groups = grouped(plan, rows);
    let primary_name = if rows.iter().any(|r| r.measures.force_l2.is_some()) {
        "contact force L2 error (relative)"
    } else {
        "|peak force error| (relative)"
    };
    written.extend(error_vs_cpu(
        &groups,
        title,
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
            title,
            name,
            out,
            Accuracy::Converged,
        )?);
    }
    written.extend(convergence(rows, &groups, title, primary_name, out)?);
    written.extend(stability_map(rows, &groups, title, out)?);
    Ok(written)
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
    title: &str,
    primary_name: &str,
    out: &Path,
    accuracy: Accuracy,
) -> Result<Vec<PathBuf>, RunError> {
    let error = |r: &Row| match accuracy {
        Accuracy::Primary => r.primary_error(),
        Accuracy::Converged => r.converged_error(),
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
        title: format!("{title}: error against CPU time"),
        x_label: "CPU time of the case [s]".into(),
        y_label: primary_name.into(),
        series,
        log_x: true,
        log_y: true,
        x_limits: Default::default(),
        y_limits: Default::default(),
    };
    let name = match accuracy {
        Accuracy::Primary => "error_vs_cpu",
        Accuracy::Converged => "error_vs_cpu_converged",
    };
    both(&chart, out, name)
}

/// Which error a speed chart plots: against the scene's reference (or the finest case
/// without one), or against the converged reference beside a declared one.
#[derive(Clone, Copy)]
enum Accuracy {
    Primary,
    Converged,
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
    title: &str,
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
    let axes: [(&str, &str, Abscissa); 2] = [
        ("dt", "time step dt", |r: &Row| r.dt),
        ("h", "shortest element edge h", |r: &Row| Some(r.h)),
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
                title: format!("{title}: error against {name}"),
                x_label: x_label.into(),
                y_label: primary_name.into(),
                series,
                log_x: true,
                log_y: true,
                x_limits: Default::default(),
                y_limits: Default::default(),
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
