//! Quantities of interest: what `impact sweep --measure` scores each case on, and the
//! converged value of each, extrapolated from the three finest cases of each series.
//!
//! ```text
//! --measure [NAME=]COLUMN            the column's final value (a probe: extent_y[all])
//! --measure [NAME=]STAT(COLUMN)      STAT: final, max, min, time_of_max, time_of_min,
//!                                    integral (trapezoid rule over the rows, in time)
//! ```
//!
//! The converged value follows the procedure of Celik, Ghia, Roache et al. (2008, "Procedure
//! for estimation and reporting of uncertainty due to discretization in CFD applications",
//! J. Fluids Eng. 130, 078001), Roache's grid convergence index (Roache 1994, 1998) with its
//! safety factor 1.25 for three grids, on the three finest levels h1 < h2 < h3 of the
//! refinement parameter (the shortest element edge, or dt when only dt varies):
//!
//! ```text
//! r21 = h2/h1, r32 = h3/h2, e21 = f2 - f1, e32 = f3 - f2, s = sign(e32/e21)
//! p   = ( ln|e32/e21| + q(p) ) / ln r21,   q(p) = ln( (r21^p - s) / (r32^p - s) )
//!       (fixed-point iteration; q = 0 for a constant ratio)
//! f_ext     = (r21^p f1 - f2) / (r21^p - 1)
//! GCI_fine  = 1.25 |(f1 - f2) / f1| / (r21^p - 1)      (relative, on the finest value f1)
//! ```
//!
//! Three levels are in the asymptotic range when the differences keep their sign (s > 0:
//! monotone convergence) and p lies in [`ORDER_BAND`]; otherwise no value is extrapolated, the
//! note says why, and the cases are compared with the finest case, which then has no error of
//! its own (a case is never scored against itself).

use super::measure::Row;
pub use crate::analysis::units::Units;
use crate::scene::Model;
use serde::Serialize;
use std::path::PathBuf;

/// Observed orders taken as asymptotic. The methods here are at most second order in h and
/// dt (bilinear quads, Newmark, central difference), first order where a contact event or a
/// crushed corner sets the error: an order below 0.5 is a sequence that has not settled, and
/// one above 3 is differences that shrink by a cancellation, not by the method's order.
pub const ORDER_BAND: (f64, f64) = (0.5, 3.0);

/// Roache's safety factor for a three-level study with the observed order.
pub const SAFETY_FACTOR: f64 = 1.25;

/// How a measure reduces a history column to one number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Reduction {
    Final,
    Max,
    Min,
    TimeOfMax,
    TimeOfMin,
    Integral,
}

impl Reduction {
    const ALL: [(&'static str, Reduction); 6] = [
        ("final", Reduction::Final),
        ("max", Reduction::Max),
        ("min", Reduction::Min),
        ("time_of_max", Reduction::TimeOfMax),
        ("time_of_min", Reduction::TimeOfMin),
        ("integral", Reduction::Integral),
    ];

    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, r)| *r == self)
            .map(|(n, _)| *n)
            .expect("every reduction is listed")
    }
}

/// One `--measure`: a name (the sweep.csv column), a history column and its reduction, and
/// the value it is scored against when one is given (`--reference NAME=VALUE`: a published
/// or closed-form value).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measure {
    pub name: String,
    pub column: String,
    pub reduction: Reduction,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference: Option<f64>,
}

impl Measure {
    /// Parses `[NAME=]COLUMN` or `[NAME=]STAT(COLUMN)`.
    pub fn parse(text: &str) -> Result<Measure, String> {
        let text = text.trim();
        let (name, body) = match text.split_once('=') {
            Some((name, body)) if !name.contains(['(', '[']) => {
                (Some(name.trim().to_string()), body.trim())
            }
            _ => (None, text),
        };
        let (reduction, column) = match body.split_once('(') {
            Some((stat, rest)) => {
                let column = rest.strip_suffix(')').ok_or_else(|| {
                    format!("`{body}`: a measure is STAT(COLUMN) with a closing parenthesis")
                })?;
                let reduction = Reduction::ALL
                    .iter()
                    .find(|(n, _)| *n == stat.trim())
                    .map(|(_, r)| *r)
                    .ok_or_else(|| {
                        let names: Vec<&str> = Reduction::ALL.iter().map(|(n, _)| *n).collect();
                        format!(
                            "`{}`: unknown statistic; one of {}",
                            stat.trim(),
                            names.join(", ")
                        )
                    })?;
                (reduction, column.trim().to_string())
            }
            None => (Reduction::Final, body.to_string()),
        };
        if column.is_empty() {
            return Err(format!("`{text}`: name a history.csv column"));
        }
        let name = name.unwrap_or_else(|| match reduction {
            Reduction::Final => column.clone(),
            other => format!("{}({column})", other.name()),
        });
        if name.is_empty() || name.contains([',', '"']) || name.chars().any(char::is_whitespace) {
            return Err(format!(
                "`{name}`: a measure's name is a sweep.csv column: no comma, quote or space"
            ));
        }
        Ok(Measure {
            name,
            column,
            reduction,
            reference: None,
        })
    }

    /// Gives the measures the values of `--reference NAME=VALUE`; an unknown name or a value
    /// that is no finite number is an error naming it.
    pub fn with_references(measures: &mut [Measure], given: &[String]) -> Result<(), String> {
        for text in given {
            let (name, value) = text
                .split_once('=')
                .ok_or_else(|| format!("--reference {text}: write NAME=VALUE"))?;
            let value: f64 = value
                .trim()
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| format!("--reference {text}: `{}` is not a number", value.trim()))?;
            let names: Vec<String> = measures.iter().map(|m| m.name.clone()).collect();
            let measure = measures
                .iter_mut()
                .find(|m| m.name == name.trim())
                .ok_or_else(|| {
                    format!(
                        "--reference {text}: no --measure is named `{}` (measures: {})",
                        name.trim(),
                        names.join(", ")
                    )
                })?;
            measure.reference = Some(value);
        }
        Ok(())
    }

    /// The measure of a history: `time` and the column's `values`, row by row. None when
    /// the history has no row.
    pub fn evaluate(&self, time: &[f64], values: &[f64]) -> Option<f64> {
        let arg = |better: fn(f64, f64) -> bool| {
            let mut best: Option<(f64, f64)> = None;
            for (t, v) in time.iter().zip(values) {
                if best.is_none_or(|(_, b)| better(*v, b)) {
                    best = Some((*t, *v));
                }
            }
            best
        };
        match self.reduction {
            Reduction::Final => values.last().copied(),
            Reduction::Max => arg(|v, b| v > b).map(|(_, v)| v),
            Reduction::Min => arg(|v, b| v < b).map(|(_, v)| v),
            Reduction::TimeOfMax => arg(|v, b| v > b).map(|(t, _)| t),
            Reduction::TimeOfMin => arg(|v, b| v < b).map(|(t, _)| t),
            Reduction::Integral => (!values.is_empty()).then(|| {
                time.windows(2)
                    .zip(values.windows(2))
                    .map(|(t, v)| 0.5 * (t[1] - t[0]) * (v[0] + v[1]))
                    .sum()
            }),
        }
    }

    /// The unit of the measure given the column's unit: time for `time_of_*`, the column's
    /// unit times seconds for `integral`.
    pub fn unit(&self, column_unit: &str) -> String {
        match self.reduction {
            Reduction::TimeOfMax | Reduction::TimeOfMin => "s".into(),
            Reduction::Integral if column_unit.is_empty() => "s".into(),
            Reduction::Integral => format!("{column_unit} s"),
            _ => column_unit.to_string(),
        }
    }
}

/// What the three finest levels of a series say about a measure's converged value.
#[derive(Debug, Clone, Serialize)]
pub struct Extrapolation {
    /// The refinement parameter of the three levels, finest first.
    pub levels: [f64; 3],
    /// The measure on them.
    pub values: [f64; 3],
    /// The observed order (None when the differences vanish).
    pub order: Option<f64>,
    /// Set in the asymptotic range: the extrapolated value and GCI_fine (relative, on the
    /// finest value).
    pub value: Option<f64>,
    pub gci: Option<f64>,
    /// Oscillatory convergence (the differences change sign): the uncertainty of the finest
    /// value, half the range of the three levels' values relative to the finest (Stern,
    /// Wilson, Coleman & Paterson 2001, J. Fluids Eng. 123: U = (S_U - S_L) / 2), where no
    /// order and no GCI can be formed. None otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uncertainty: Option<f64>,
    /// Why there is no extrapolated value (or a caution beside one).
    pub note: Option<String>,
    /// The same in a few words, for the charts.
    #[serde(skip)]
    pub verdict: Option<&'static str>,
}

/// Celik et al. (2008) on three levels `h` (finest first, increasing) with values `f`.
pub fn extrapolate(h: [f64; 3], f: [f64; 3]) -> Extrapolation {
    let mut out = Extrapolation {
        levels: h,
        values: f,
        order: None,
        value: None,
        gci: None,
        uncertainty: None,
        note: None,
        verdict: None,
    };
    let (r21, r32) = (h[1] / h[0], h[2] / h[1]);
    if !(r21 > 1.0 && r32 > 1.0) {
        out.note = Some("the three finest levels are not distinct".into());
        out.verdict = Some("three distinct levels needed");
        return out;
    }
    let (e21, e32) = (f[1] - f[0], f[2] - f[1]);
    let scale = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if e21.abs() <= 1e-14 * scale || e32.abs() <= 1e-14 * scale {
        out.note = Some(format!(
            "the values of the three finest levels differ by round-off only ({:e}, {:e}): no order to observe",
            f[0], f[1]
        ));
        out.verdict = Some("no change under refinement: no order");
        return out;
    }
    let s = (e32 / e21).signum();
    let log_ratio = (e32 / e21).abs().ln();
    let mut p = log_ratio / r21.ln();
    for _ in 0..200 {
        let q = ((r21.powf(p) - s) / (r32.powf(p) - s)).ln();
        let next = (log_ratio + q) / r21.ln();
        if !next.is_finite() {
            break;
        }
        let done = (next - p).abs() <= 1e-12 * p.abs().max(1.0);
        p = next;
        if done {
            break;
        }
    }
    out.order = p.is_finite().then_some(p);
    let (low, high) = ORDER_BAND;
    if s < 0.0 {
        let range = f.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v))
            - f.iter().fold(f64::INFINITY, |m, v| m.min(*v));
        out.uncertainty = (f[0] != 0.0).then(|| 0.5 * range / f[0].abs());
        let u = out.uncertainty.map_or(String::new(), |u| {
            format!(
                "; U = {:.3} % (half the range of the three, Stern et al. 2001)",
                100.0 * u
            )
        });
        out.note = Some(format!(
            "the differences change sign (f2 - f1 = {e21:.3e}, f3 - f2 = {e32:.3e}): oscillating, not in the asymptotic range{u}"
        ));
        out.verdict = Some("oscillating: not in the asymptotic range, no extrapolation");
    } else if !(p.is_finite() && (low..=high).contains(&p)) {
        out.note = Some(format!(
            "observed order {p:.2} outside [{low}, {high}]: not in the asymptotic range"
        ));
        out.verdict = Some("order outside the plausible band: no extrapolation");
    } else {
        let rp = r21.powf(p);
        out.value = Some((rp * f[0] - f[1]) / (rp - 1.0));
        // the GCI is relative to the finest value: none when that is 0
        out.gci = (f[0] != 0.0).then(|| SAFETY_FACTOR * (e21 / f[0]).abs() / (rp - 1.0));
        if r21 < 1.3 || r32 < 1.3 {
            out.note = Some(format!(
                "refinement ratios {r21:.2} and {r32:.2}: below the 1.3 Celik et al. ask for, the order is sensitive to noise"
            ));
            out.verdict = Some("refinement ratio below 1.3: order sensitive to noise");
        }
    }
    out
}

/// `label [unit]`, or the label alone without a unit.
pub fn with_unit(label: &str, unit: &str) -> String {
    if unit.is_empty() {
        label.to_string()
    } else {
        format!("{label} [{unit}]")
    }
}

/// Refuses a measure whose column the scene's history.csv will not have (before any case
/// runs), naming the columns it will have.
pub fn check(measures: &[Measure], model: &Model) -> Result<(), String> {
    let columns = crate::analysis::run::columns::column_names(model);
    for m in measures {
        if !columns.contains(&m.column) {
            return Err(format!(
                "--measure {}: history.csv has no column `{}`; its columns are: {} (add a [[output.probe]] for a quantity of the shape, e.g. extent_y over `all`)",
                m.name,
                m.column,
                columns.join(", ")
            ));
        }
    }
    let mut names: Vec<&str> = measures.iter().map(|m| m.name.as_str()).collect();
    names.sort_unstable();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        return Err(format!("--measure: two measures are named `{}`", w[0]));
    }
    Ok(())
}

/// What one measure gave on one series of the sweep.
#[derive(Debug, Clone, Serialize)]
pub struct SeriesScore {
    pub series: String,
    /// `h` (the shortest element edge) or `dt`; None when neither varies in the series.
    pub refinement: Option<&'static str>,
    /// The converged value the cases are compared with: the extrapolated one, else the
    /// finest case's.
    pub reference: Option<f64>,
    /// `given` (`--reference`), `extrapolated` or `finest case`.
    pub reference_kind: Option<&'static str>,
    /// The finest case's folder when it is the reference (it has no error then).
    pub finest: Option<String>,
    /// The series whose extrapolation or finest case is the reference of every series of
    /// the sweep (`common_reference`), None with a given one or a single series.
    pub reference_series: Option<String>,
    pub extrapolation: Option<Extrapolation>,
}

/// One measure over the whole sweep (measures.json).
#[derive(Debug, Clone, Serialize)]
pub struct MeasureScore {
    #[serde(flatten)]
    pub measure: Measure,
    pub unit: String,
    pub series: Vec<SeriesScore>,
}

impl MeasureScore {
    /// The lines the sweep prints and the charts show: why a series has no extrapolated
    /// value, or a caution beside one.
    pub fn notes(&self) -> Vec<String> {
        self.series
            .iter()
            .filter_map(|s| {
                let note = s.extrapolation.as_ref()?.note.as_ref()?;
                Some(format!("{} ({}): {note}", self.measure.name, s.series))
            })
            .collect()
    }
}

/// `; errors against X's extrapolated value V` where the series is scored against another
/// series' reference (`common_reference`), else nothing.
fn against_another(s: &SeriesScore) -> String {
    match (&s.reference_series, s.reference, s.reference_kind) {
        (Some(from), Some(value), Some(kind)) if *from != s.series => {
            format!("; errors against the {kind} of {from}, {value:.6e}")
        }
        _ => String::new(),
    }
}

/// One line per series of a measure: the finest three values, the order, the extrapolated
/// value and its GCI (or the reference the cases are compared with, and why).
pub fn summary_lines(score: &MeasureScore) -> Vec<String> {
    let unit = if score.unit.is_empty() {
        String::new()
    } else {
        format!(" {}", score.unit)
    };
    score
        .series
        .iter()
        .map(|s| {
            let head = format!("{} ({})", score.measure.name, s.series);
            match (&s.extrapolation, s.reference, s.reference_kind) {
                (Some(e), _, _) if e.value.is_some() => format!(
                    "{head}: {:.6e}, {:.6e}, {:.6e}{unit} at {} = {:.3e}, {:.3e}, {:.3e}: order {:.2}, extrapolated {:.6e}{unit}, GCI {}",
                    e.values[0],
                    e.values[1],
                    e.values[2],
                    s.refinement.unwrap_or("h"),
                    e.levels[0],
                    e.levels[1],
                    e.levels[2],
                    e.order.unwrap_or(f64::NAN),
                    e.value.unwrap_or(f64::NAN),
                    e.gci.map_or("none (the finest value is 0)".to_string(), |g| format!(
                        "{:.3} %",
                        100.0 * g
                    ))
                ) + &against_another(s),
                (_, Some(reference), Some(kind)) => match &s.reference_series {
                    Some(from) if *from != s.series => format!(
                        "{head}: compared with the {kind} of {from}, {reference:.6e}{unit}"
                    ),
                    _ => format!("{head}: compared with the {kind}, {reference:.6e}{unit}"),
                },
                _ => format!("{head}: no refinement in this series (neither h nor dt varies)"),
            }
        })
        .collect()
}

/// The measures' values of every case (`Row::quantities`), and their errors
/// (`Row::quantity_errors`) against each series' converged value: (value - reference) /
/// |reference|, the difference itself where the reference is 0; none for the case that is
/// the reference. `series`: each series' label and its rows' indices.
pub fn score(
    measures: &[Measure],
    units: &Units,
    model: &Model,
    (rows, folders): (&mut [Row], &[Option<PathBuf>]),
    series: &[(String, Vec<usize>)],
) -> Vec<MeasureScore> {
    let columns: Vec<&str> = measures.iter().map(|m| m.column.as_str()).collect();
    for (row, folder) in rows.iter_mut().zip(folders) {
        let histories = folder.as_ref().and_then(|f| {
            let mut names = vec!["time"];
            names.extend(&columns);
            crate::output::plot::history_columns(&f.join("history.csv"), &names).ok()
        });
        row.quantities = measures
            .iter()
            .enumerate()
            .map(|(k, m)| {
                let h = histories.as_ref()?;
                m.evaluate(&h[0], &h[k + 1])
            })
            .collect();
        row.quantity_errors = vec![None; measures.len()];
    }
    measures
        .iter()
        .enumerate()
        .map(|(k, measure)| {
            let mut scores: Vec<SeriesScore> = series
                .iter()
                .map(|(label, members)| score_series(k, measure, label, rows, members))
                .collect();
            if measure.reference.is_none() {
                common_reference(k, &mut scores, rows, series);
            }
            MeasureScore {
                measure: measure.clone(),
                unit: measure.unit(&units.of_column(model, &measure.column)),
                series: scores,
            }
        })
        .collect()
}

/// One reference for measure `k` across the series, each scored against its own by
/// `score_series`: the extrapolation of the series with the smallest GCI (the most certain
/// converged value), else the finest case of all when the series refine the same parameter.
/// Every series' errors are then against it, so two methods' fronts are measured against the
/// same answer, and a series without an extrapolation keeps its finest case on the charts.
/// One series, or series that refine different parameters without an extrapolation, keep
/// their own.
fn common_reference(
    k: usize,
    scores: &mut [SeriesScore],
    rows: &mut [Row],
    series: &[(String, Vec<usize>)],
) {
    if scores.len() < 2 {
        return;
    }
    let certainty = |s: &SeriesScore| {
        let e = s.extrapolation.as_ref()?;
        Some((e.gci.unwrap_or(f64::INFINITY), e.value?))
    };
    let best = (scores.iter().enumerate())
        .filter_map(|(i, s)| Some((i, certainty(s)?)))
        .min_by(|a, b| a.1.0.total_cmp(&b.1.0));
    let (from, reference, kind, skip) = match best {
        Some((i, (_, value))) => (i, value, "extrapolated", None),
        None => {
            let refinement = scores[0].refinement;
            if refinement.is_none() || scores.iter().any(|s| s.refinement != refinement) {
                return;
            }
            let level = |i: usize| {
                let r = &rows[i];
                if refinement == Some("h") {
                    Some(r.h)
                } else {
                    r.dt
                }
            };
            // each series' finest case is its reference (`score_series`): the finest of them
            let finest = (scores.iter().enumerate())
                .filter_map(|(s, score)| {
                    let folder = score.finest.as_ref()?;
                    let i = rows.iter().position(|r| &r.folder == folder)?;
                    Some((s, i, level(i)?))
                })
                .min_by(|a, b| a.2.total_cmp(&b.2));
            let Some((s, i, _)) = finest else {
                return;
            };
            let value = rows[i].quantities[k].expect("a reference case has the value");
            (s, value, "finest case", Some(i))
        }
    };
    let label = scores[from].series.clone();
    let folder = skip.map(|i| rows[i].folder.clone());
    for (score, (_, members)) in scores.iter_mut().zip(series) {
        score.reference = Some(reference);
        score.reference_kind = Some(kind);
        score.reference_series = Some(label.clone());
        score.finest = folder.clone();
        let usable: Vec<usize> = (members.iter().copied())
            .filter(|&i| rows[i].status == "ok" && rows[i].quantities[k].is_some())
            .collect();
        for &i in &usable {
            rows[i].quantity_errors[k] = None;
        }
        score_against(k, reference, rows, &usable, skip);
    }
}

/// Measure `k` on one series: its levels, the extrapolation of the three finest, the errors.
fn score_series(
    k: usize,
    measure: &Measure,
    label: &str,
    rows: &mut [Row],
    members: &[usize],
) -> SeriesScore {
    let mut score = SeriesScore {
        series: label.to_string(),
        refinement: None,
        reference: None,
        reference_kind: None,
        finest: None,
        reference_series: None,
        extrapolation: None,
    };
    let usable: Vec<usize> = members
        .iter()
        .copied()
        .filter(|&i| rows[i].status == "ok" && rows[i].quantities[k].is_some())
        .collect();
    let distinct = |of: fn(&Row) -> Option<f64>| {
        let mut v: Vec<f64> = usable.iter().filter_map(|&i| of(&rows[i])).collect();
        v.sort_by(f64::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * b.abs());
        v.len()
    };
    let of_h: fn(&Row) -> Option<f64> = |r| Some(r.h);
    let of_dt: fn(&Row) -> Option<f64> = |r| r.dt;
    let given = measure.reference;
    let (name, of) = if distinct(of_h) >= 2 {
        ("h", of_h)
    } else if distinct(of_dt) >= 2 {
        ("dt", of_dt)
    } else {
        if let Some(reference) = given {
            score_against(k, reference, rows, &usable, None);
            score.reference = Some(reference);
            score.reference_kind = Some("given");
        }
        return score;
    };
    score.refinement = Some(name);
    // one case per level, finest first
    let mut levels: Vec<(f64, usize)> = usable
        .iter()
        .filter_map(|&i| Some((of(&rows[i])?, i)))
        .collect();
    levels.sort_by(|a, b| a.0.total_cmp(&b.0));
    levels.dedup_by(|a, b| (a.0 - b.0).abs() <= 1e-9 * b.0.abs());
    let value = |i: usize| rows[i].quantities[k].expect("usable rows have the value");
    if levels.len() >= 3 {
        let h = [levels[0].0, levels[1].0, levels[2].0];
        let f = [value(levels[0].1), value(levels[1].1), value(levels[2].1)];
        score.extrapolation = Some(extrapolate(h, f));
    }
    let extrapolated = score.extrapolation.as_ref().and_then(|e| e.value);
    let finest = levels[0].1;
    let (reference, kind, skip) = match (given, extrapolated) {
        (Some(v), _) => (v, "given", None),
        (None, Some(v)) => (v, "extrapolated", None),
        (None, None) => {
            score.finest = Some(rows[finest].folder.clone());
            (value(finest), "finest case", Some(finest))
        }
    };
    score.reference = Some(reference);
    score.reference_kind = Some(kind);
    score_against(k, reference, rows, &usable, skip);
    score
}

/// The errors of measure `k` of the rows `usable` against `reference`, but for `skip` (the
/// reference's own case): (value - reference) / |reference|, the difference where it is 0.
fn score_against(
    k: usize,
    reference: f64,
    rows: &mut [Row],
    usable: &[usize],
    skip: Option<usize>,
) {
    for &i in usable {
        if Some(i) == skip {
            continue;
        }
        let v = rows[i].quantities[k].expect("usable rows have the value");
        rows[i].quantity_errors[k] = Some(if reference != 0.0 {
            (v - reference) / reference.abs()
        } else {
            v - reference
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: the parser's forms. Reference: the grammar in the module comment.
    #[test]
    fn measures_parse_with_and_without_a_name_and_a_statistic() {
        let m = Measure::parse("extent_y[all]").unwrap();
        assert_eq!(
            (m.name.as_str(), m.column.as_str(), m.reduction),
            ("extent_y[all]", "extent_y[all]", Reduction::Final)
        );
        let m = Measure::parse("L_f = extent_y[rod.all]").unwrap();
        assert_eq!(
            (m.name.as_str(), m.column.as_str()),
            ("L_f", "extent_y[rod.all]")
        );
        let m = Measure::parse("time_of_max(contact_force[wall])").unwrap();
        assert_eq!(m.name, "time_of_max(contact_force[wall])");
        assert_eq!(m.reduction, Reduction::TimeOfMax);
        assert!(Measure::parse("mean(x[all])").is_err());
        assert!(Measure::parse("max(x[all]").is_err());
        assert!(Measure::parse("a b=x[all]").is_err());
    }

    /// Goal: each reduction of a sampled history. Reference, by hand: v = (0, 2, 1, 3, -1)
    /// at t = (0, 1, 2, 3, 4): final -1, max 3 at t 3, min -1 at t 4, trapezoid integral
    /// 1 + 1.5 + 2 + 1 = 5.5.
    #[test]
    fn reductions_of_a_history() {
        let time = [0.0, 1.0, 2.0, 3.0, 4.0];
        let values = [0.0, 2.0, 1.0, 3.0, -1.0];
        let of = |text: &str| {
            Measure::parse(text)
                .unwrap()
                .evaluate(&time, &values)
                .unwrap()
        };
        assert_eq!(of("c"), -1.0);
        assert_eq!(of("max(c)"), 3.0);
        assert_eq!(of("time_of_max(c)"), 3.0);
        assert_eq!(of("min(c)"), -1.0);
        assert_eq!(of("time_of_min(c)"), 4.0);
        assert_eq!(of("integral(c)"), 5.5);
    }

    /// Goal: the extrapolation recovers f(h) = 1 + h^2 exactly, with a constant and with a
    /// varying refinement ratio (the fixed-point iteration for q(p)), and its GCI band holds
    /// the exact value. Reference: the closed form f(0) = 1, order 2.
    #[test]
    fn extrapolation_recovers_a_quadratic_with_any_ratios() {
        let f = |h: f64| 1.0 + 0.3 * h * h;
        for h in [[0.25, 0.5, 1.0], [0.5, 2.0 / 3.0, 1.0]] {
            let e = extrapolate(h, h.map(f));
            approx::assert_abs_diff_eq!(e.order.unwrap(), 2.0, epsilon = 1e-9);
            approx::assert_abs_diff_eq!(e.value.unwrap(), 1.0, epsilon = 1e-12);
            assert!((f(h[0]) - 1.0).abs() <= e.gci.unwrap() * f(h[0]));
        }
    }

    /// Goal: sequences outside the asymptotic range give no value, and say why: oscillating
    /// differences, an order far above the band, identical values.
    #[test]
    fn no_value_outside_the_asymptotic_range() {
        let h = [0.25, 0.5, 1.0];
        let oscillating = extrapolate(h, [1.0, 1.1, 0.9]);
        assert!(oscillating.value.is_none());
        // half the range 0.9..1.1 over the finest value 1.0
        approx::assert_abs_diff_eq!(oscillating.uncertainty.unwrap(), 0.1, epsilon = 1e-12);
        assert!(oscillating.note.unwrap().contains("oscillating"));
        let steep = extrapolate(h, [1.0, 1.0 + 1e-4, 1.0 + 1e-4 + 1.0]);
        assert!(steep.value.is_none() && steep.uncertainty.is_none());
        assert!(steep.note.unwrap().contains("outside"));
        let flat = extrapolate(h, [2.0, 2.0, 2.0]);
        assert!(flat.value.is_none() && flat.order.is_none());
    }
}
