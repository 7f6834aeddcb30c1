//! `[output]`: the probes written to history.csv and the frame times.

use super::InputError;
use super::context::{Context, body_index, node_set};
use super::model::{Body, Probe};
use super::spec::{ProbeSpec, Quantity, Statistic};

/// `output.frame_times`: finite, >= 0 and increasing.
pub(super) fn check_frame_times(cx: &Context, times: &[f64]) -> Result<(), InputError> {
    if times.iter().any(|t| !(t.is_finite() && *t >= 0.0)) || times.windows(2).any(|w| w[1] <= w[0])
    {
        return Err(cx.err(format!(
            "output.frame_times: must be finite, >= 0 and increasing, got {times:?}"
        )));
    }
    Ok(())
}

/// `output.contact_force_window`: a time >= 0 (0: no averaging).
pub(super) fn check_force_window(cx: &Context, window: Option<f64>) -> Result<(), InputError> {
    match window {
        Some(w) if !(w.is_finite() && w >= 0.0) => Err(cx.err(format!(
            "output.contact_force_window: must be a time >= 0 (0: the raw force), got {w}"
        ))),
        _ => Ok(()),
    }
}

/// `output.history_every` (>= 1) and `output.history_interval` (a time > 0).
pub(super) fn check_history_cadence(
    cx: &Context,
    output: &super::spec::OutputSpec,
) -> Result<(), InputError> {
    if output.history_every == Some(0) {
        return Err(
            cx.err("output.history_every: must be >= 1 (1: a row every step), got 0".to_string())
        );
    }
    match output.history_interval {
        Some(h) if !(h.is_finite() && h > 0.0) => Err(cx.err(format!(
            "output.history_interval: must be a time > 0, got {h}"
        ))),
        _ => Ok(()),
    }
}

/// The frame times of `output`: `frame_times` with the multiples of `frame_interval` up to
/// `end_time` merged in (sorted; a multiple within 1e-9 relative of a listed time is that
/// time).
pub(super) fn frame_times(
    cx: &Context,
    output: &super::spec::OutputSpec,
    end_time: f64,
) -> Result<Vec<f64>, InputError> {
    check_frame_times(cx, &output.frame_times)?;
    let mut times = output.frame_times.clone();
    if let Some(interval) = output.frame_interval {
        if !(interval.is_finite() && interval > 0.0) {
            return Err(cx.err(format!(
                "output.frame_interval: must be a time > 0, got {interval}"
            )));
        }
        let count = (end_time / interval * (1.0 + 1e-9)).floor();
        if count > 1e6 {
            return Err(cx.err(format!(
                "output.frame_interval: {interval} asks for {count} frames up to the end time {end_time}; at most 1e6"
            )));
        }
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs());
        // the listed times are sorted (checked above): a multiple is compared with its two
        // neighbours among them only, so laying out n frames costs n log(listed), not n^2
        let listed = output.frame_times.as_slice();
        let near_listed = |t: f64| {
            let k = listed.partition_point(|x| *x < t);
            [k.checked_sub(1), Some(k)]
                .into_iter()
                .flatten()
                .filter_map(|i| listed.get(i))
                .any(|x| close(*x, t))
        };
        times.reserve(count as usize);
        for k in 1..=count as usize {
            let t = (k as f64 * interval).min(end_time);
            if !near_listed(t) {
                times.push(t);
            }
        }
        times.sort_by(f64::total_cmp);
    }
    Ok(times)
}

/// The `[[output.probe]]` tables: each probe's members (global nodes or elements of its body)
/// and its history.csv column.
pub(super) fn probes(
    cx: &Context,
    bodies: &[Body],
    specs: &[ProbeSpec],
    dynamic: bool,
) -> Result<Vec<Probe>, InputError> {
    let mut out = Vec::new();
    for (k, p) in specs.iter().enumerate() {
        let key = format!("output.probe[{k}]");
        let b = body_index(cx, bodies, p.body.as_deref(), &key)?;
        if p.quantity == Quantity::Temperature && !bodies[b].material.carries_temperature() {
            return Err(cx.err(format!(
                "{key}.quantity: body `{}` has material `{}`, which carries no temperature \
                 (only `johnson_cook` materials do)",
                bodies[b].name, bodies[b].material.name
            )));
        }
        if p.quantity.is_whole_set() && p.statistic != Statistic::Mean {
            let what = match p.quantity {
                Quantity::ExtentX | Quantity::ExtentY => "the extent of the set",
                _ => "the sum over the set",
            };
            return Err(cx.err(format!(
                "{key}.statistic: {} is {what}; leave statistic out",
                p.quantity.name()
            )));
        }
        if p.statistic == Statistic::MassMean && !(p.quantity.has_mass_mean() && dynamic) {
            return Err(cx.err(format!(
                "{key}.statistic: `mass_mean` weighs the nodes of a set by their mass: it takes \
                 u_x, u_y, v_x, v_y, a_x, a_y, x or y in a dynamic analysis, not `{}`{}",
                p.quantity.name(),
                if dynamic { "" } else { " in a static one" }
            )));
        }
        let members = if p.quantity.is_nodal() {
            node_set(cx, bodies, p.body.as_deref(), &p.set, &key)?
                .1
                .into_iter()
                .map(|n| bodies[b].global(n))
                .collect()
        } else {
            // an element set, or the elements around the nodes of a node set
            let mesh = &bodies[b].mesh;
            let sets = &mesh.element_sets;
            match (sets.get(&p.set), mesh.node_sets.get(&p.set)) {
                (Some(elements), _) => elements.clone(),
                (None, Some(nodes)) => (0..mesh.cells.len())
                    .filter(|e| mesh.cells.nodes_of(*e).iter().any(|n| nodes.contains(n)))
                    .collect(),
                (None, None) => {
                    let known: Vec<&String> = sets.keys().chain(mesh.node_sets.keys()).collect();
                    return Err(cx.err(format!(
                        "{key}.set: body `{}` has no element or node set `{}` (sets: {known:?})",
                        bodies[b].name, p.set
                    )));
                }
            }
        };
        let set = if bodies.len() > 1 {
            format!("{}.{}", bodies[b].name, p.set)
        } else {
            p.set.clone()
        };
        let column = match p.statistic {
            Statistic::Mean => format!("{}[{set}]", p.quantity.name()),
            Statistic::Max => format!("max_{}[{set}]", p.quantity.name()),
            Statistic::Min => format!("min_{}[{set}]", p.quantity.name()),
            Statistic::MassMean => format!("mass_mean_{}[{set}]", p.quantity.name()),
        };
        out.push(Probe {
            statistic: p.statistic,
            quantity: p.quantity,
            body: b,
            consecutive: crate::scene::model::consecutive_run(&members),
            members,
            column,
        });
    }
    Ok(out)
}
