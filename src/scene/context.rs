//! What every validation step shares: the file that messages name, the checks of a number,
//! and the look-ups of a body and of its node and edge sets by the names a scene gives.

use super::InputError;
use super::model::{Body, BodyKind};
use super::spec::{ContactSpec, SurfaceSpec};
use std::path::Path;

/// The scene being validated: every message names its file.
pub(super) struct Context<'a> {
    pub(super) file: &'a Path,
}

impl Context<'_> {
    pub(super) fn err(&self, message: impl Into<String>) -> InputError {
        InputError::new(self.file, message)
    }
}

/// `value` if it is a positive, finite number; else an error naming `key`.
pub(super) fn positive(cx: &Context, key: &str, value: f64) -> Result<f64, InputError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(cx.err(format!("{key}: must be a positive number, got {value}")))
    }
}

/// An error naming `key` unless every value is finite.
pub(super) fn finite(cx: &Context, key: &str, values: &[f64]) -> Result<(), InputError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(cx.err(format!("{key}: values must be finite")))
    }
}

/// Index of the body a load/support/probe refers to: by name, or the only body.
pub(super) fn body_index(
    cx: &Context,
    bodies: &[Body],
    name: Option<&str>,
    key: &str,
) -> Result<usize, InputError> {
    match name {
        Some(n) => bodies.iter().position(|b| b.name == n).ok_or_else(|| {
            let known: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
            cx.err(format!(
                "{key}.body: no body named `{n}` (bodies: {known:?})"
            ))
        }),
        None if bodies.len() == 1 => Ok(0),
        None => Err(cx.err(format!(
            "{key}.body: the scene has several bodies; name one"
        ))),
    }
}

/// The body and the nodes (local numbers) of the node set `set` a scene names under `key`.
pub(super) fn node_set(
    cx: &Context,
    bodies: &[Body],
    body: Option<&str>,
    set: &str,
    key: &str,
) -> Result<(usize, Vec<usize>), InputError> {
    let b = body_index(cx, bodies, body, key)?;
    let sets = &bodies[b].mesh.node_sets;
    let nodes = sets.get(set).ok_or_else(|| {
        let known: Vec<&String> = sets.keys().collect();
        cx.err(format!(
            "{key}.set: body `{}` has no node set `{set}` (node sets: {known:?})",
            bodies[b].name
        ))
    })?;
    Ok((b, nodes.clone()))
}

/// The body and the edges (global node numbers) of the edge set `set` of a 2D body.
pub(super) fn edge_set(
    cx: &Context,
    bodies: &[Body],
    body: Option<&str>,
    set: &str,
    key: &str,
) -> Result<(usize, Vec<[usize; 2]>), InputError> {
    let b = body_index(cx, bodies, body, key)?;
    let sets = &bodies[b].mesh.edge_sets;
    let edges = sets.get(set).ok_or_else(|| {
        let known: Vec<&String> = sets.keys().collect();
        cx.err(format!(
            "{key}.set: body `{}` has no edge set `{set}` (edge sets: {known:?})",
            bodies[b].name
        ))
    })?;
    if !matches!(bodies[b].kind, BodyKind::Continuum { .. }) {
        return Err(cx.err(format!("{key}: edge loads apply to 2D bodies only")));
    }
    let global = edges
        .iter()
        .map(|e| e.map(|n| bodies[b].global(n)))
        .collect();
    Ok((b, global))
}

/// The slave's and the master's bodies of pair `spec` when both its surfaces are edge sets
/// of bodies (the same body for a body's contact with itself); None otherwise (an obstacle,
/// a node-to-node master, a node set).
pub(super) fn edge_sets_on_both(
    cx: &Context,
    bodies: &[Body],
    spec: &ContactSpec,
) -> Option<(usize, usize)> {
    let edge_set_of = |surface: &SurfaceSpec| {
        let b = body_index(cx, bodies, surface.body.as_deref(), "").ok()?;
        (surface.normal.is_none() && bodies[b].mesh.edge_sets.contains_key(&surface.set))
            .then_some(b)
    };
    Some((
        edge_set_of(&spec.slave)?,
        edge_set_of(spec.master.as_ref()?)?,
    ))
}

/// The lengths of the edges of `body`'s edge set `set` in the initial configuration (None:
/// the body has no such set).
pub(super) fn edge_lengths<'b>(
    body: &'b Body,
    set: &str,
) -> Option<impl Iterator<Item = f64> + 'b> {
    let mesh = &body.mesh;
    let edges = mesh.edge_sets.get(set)?;
    Some(edges.iter().map(|[a, b]| {
        let (p, q) = (mesh.nodes[*a], mesh.nodes[*b]);
        (q[0] - p[0]).hypot(q[1] - p[1])
    }))
}
