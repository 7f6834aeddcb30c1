//! Supports, loads and their curves: `[[support]]` as fixed DOFs, `[[load]]` resolved to
//! global nodes or edges, `[[curve]]` as piecewise-linear factors of time.

use super::InputError;
use super::context::{Context, edge_set, finite, node_set};
use super::model::{Analysis, Body, Curve, Load};
use super::spec::{Component, LoadSpec, Scene};
use std::collections::BTreeMap;

/// The curve of a load that names none: statics ramps the loads up over the run; dynamics
/// applies them at once (a step).
pub(super) fn default_curve(analysis: &Analysis) -> Curve {
    match analysis {
        Analysis::Static(s) => Curve {
            points: vec![[0.0, 0.0], [s.end_time, 1.0]],
        },
        Analysis::Dynamic(_) => Curve {
            points: vec![[0.0, 1.0]],
        },
    }
}

/// The DOFs the `[[support]]` tables fix (sorted, unique).
pub(super) fn fixed_dofs(
    cx: &Context,
    scene: &Scene,
    bodies: &[Body],
) -> Result<Vec<usize>, InputError> {
    let mut fixed_dofs = Vec::new();
    for (k, s) in scene.support.iter().enumerate() {
        let key = format!("support[{k}]");
        let (b, nodes) = node_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
        if s.fix.is_empty() {
            return Err(cx.err(format!("{key}.fix: list at least one of \"x\", \"y\"")));
        }
        for n in nodes {
            for c in &s.fix {
                fixed_dofs.push(2 * bodies[b].global(n) + (*c == Component::Y) as usize);
            }
        }
    }
    fixed_dofs.sort_unstable();
    fixed_dofs.dedup();
    Ok(fixed_dofs)
}

/// The `[[load]]` tables in order.
pub(super) fn loads(
    cx: &Context,
    scene: &Scene,
    bodies: &[Body],
    curves: &BTreeMap<String, Curve>,
    default: &Curve,
) -> Result<Vec<Load>, InputError> {
    scene
        .load
        .iter()
        .enumerate()
        .map(|entry| load(cx, bodies, (curves, default), entry))
        .collect()
}

/// The `[[curve]]` tables by name: at least one point, finite, times strictly increasing.
pub(super) fn curves(cx: &Context, scene: &Scene) -> Result<BTreeMap<String, Curve>, InputError> {
    let mut out = BTreeMap::new();
    for (k, c) in scene.curve.iter().enumerate() {
        let key = format!("curve[{k}] (`{}`)", c.name);
        if c.points.is_empty() {
            return Err(cx.err(format!(
                "{key}.points: give at least one [time, factor] pair"
            )));
        }
        if c.points.iter().flatten().any(|v| !v.is_finite()) {
            return Err(cx.err(format!("{key}.points: values must be finite")));
        }
        if c.points.windows(2).any(|w| w[1][0] <= w[0][0]) {
            return Err(cx.err(format!("{key}.points: times must increase strictly")));
        }
        if out
            .insert(
                c.name.clone(),
                Curve {
                    points: c.points.clone(),
                },
            )
            .is_some()
        {
            return Err(cx.err(format!("{key}.name: `{}` is used twice", c.name)));
        }
    }
    Ok(out)
}

/// The curve a load names, or the default one.
pub(super) fn curve(
    cx: &Context,
    curves: &BTreeMap<String, Curve>,
    default: &Curve,
    name: &Option<String>,
    key: &str,
) -> Result<Curve, InputError> {
    match name {
        None => Ok(default.clone()),
        Some(n) => curves.get(n).cloned().ok_or_else(|| {
            let known: Vec<&String> = curves.keys().collect();
            cx.err(format!(
                "{key}.curve: no curve named `{n}` (curves: {known:?})"
            ))
        }),
    }
}

/// One `[[load]]` (the k-th, `spec`), resolved to global nodes (or a body's edges) and its
/// curve among the named `curves` (`default` when it names none).
fn load(
    cx: &Context,
    bodies: &[Body],
    (curves, default): (&BTreeMap<String, Curve>, &Curve),
    (k, spec): (usize, &LoadSpec),
) -> Result<Load, InputError> {
    let key = format!("load[{k}]");
    let globals =
        |b: usize, nodes: Vec<usize>| nodes.into_iter().map(|n| bodies[b].global(n)).collect();
    Ok(match spec {
        LoadSpec::NodalForce(s) => {
            finite(cx, &format!("{key}.force"), &s.force)?;
            let (b, nodes) = node_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
            Load::NodalForce {
                nodes: globals(b, nodes),
                force: s.force,
                curve: curve(cx, curves, default, &s.curve, &key)?,
            }
        }
        LoadSpec::Traction(s) => {
            finite(cx, &format!("{key}.traction"), &s.traction)?;
            let (body, edges) = edge_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
            Load::Traction {
                body,
                edges,
                traction: s.traction,
                curve: curve(cx, curves, default, &s.curve, &key)?,
            }
        }
        LoadSpec::Pressure(s) => {
            finite(cx, &format!("{key}.pressure"), &[s.pressure])?;
            let (body, edges) = edge_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
            Load::Pressure {
                body,
                edges,
                pressure: s.pressure,
                curve: curve(cx, curves, default, &s.curve, &key)?,
            }
        }
        LoadSpec::Displacement(s) => {
            if s.x.is_none() && s.y.is_none() {
                return Err(cx.err(format!("{key}: give `x`, `y` or both")));
            }
            finite(cx, &key, &[s.x.unwrap_or(0.0), s.y.unwrap_or(0.0)])?;
            let (b, nodes) = node_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
            Load::Displacement {
                nodes: globals(b, nodes),
                x: s.x,
                y: s.y,
                curve: curve(cx, curves, default, &s.curve, &key)?,
            }
        }
        LoadSpec::Rotation(s) => {
            finite(cx, &key, &[s.center[0], s.center[1], s.angle])?;
            let (b, nodes) = node_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
            Load::Rotation {
                nodes: globals(b, nodes),
                center: s.center,
                angle: s.angle,
                curve: curve(cx, curves, default, &s.curve, &key)?,
            }
        }
        LoadSpec::Affine(s) => {
            let offset = s.offset.unwrap_or([0.0; 2]);
            finite(
                cx,
                &key,
                &[
                    s.gradient[0][0],
                    s.gradient[0][1],
                    s.gradient[1][0],
                    s.gradient[1][1],
                ],
            )?;
            finite(cx, &key, &offset)?;
            let (b, nodes) = node_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
            Load::Affine {
                nodes: globals(b, nodes),
                gradient: s.gradient,
                offset,
                curve: curve(cx, curves, default, &s.curve, &key)?,
            }
        }
    })
}
