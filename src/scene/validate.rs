//! A deserialized [`Scene`] validated into a [`Model`], step by step in a fixed order (so the
//! first error a scene has is the one reported): materials, bodies and node sets, the
//! analysis, supports and loads, output, contact pairs, the checks that join the analysis to
//! the bodies and pairs, initial velocities, and the reference.

use super::InputError;
use super::analysis::analysis;
use super::bodies::{add_node_set, bodies, initial_velocity};
use super::contacts::{check_contact_setup, contacts};
use super::context::Context;
use super::loads::{curves, default_curve, fixed_dofs, loads};
use super::materials::materials;
use super::model::{Analysis, Body, BodyKind, Model, SceneSource};
use super::probes::{check_frame_times, probes};
use super::reference::reference;
use super::spec::{IntegratorKind, Quadrature, Scene};
use crate::contact::{ContactPair, Friction};
use std::path::Path;

/// The model of a scene; `file` names it in messages, `base_dir` anchors relative mesh files.
pub fn build(scene: Scene, file: &Path, base_dir: &Path) -> Result<Model, InputError> {
    let cx = Context { file };
    let materials = materials(&cx, &scene)?;
    let (mut bodies, node_count) = bodies(&cx, &scene, &materials, base_dir)?;
    for (k, spec) in scene.node_set.iter().enumerate() {
        add_node_set(&cx, &mut bodies, k, spec)?;
    }
    let analysis = analysis(&cx, &scene.analysis)?;
    let curves = curves(&cx, &scene)?;
    let default_curve = default_curve(&analysis);
    let fixed_dofs = fixed_dofs(&cx, &scene, &bodies)?;
    let loads = loads(&cx, &scene, &bodies, &curves, &default_curve)?;
    let probes = probes(&cx, &bodies, &scene.output.probe)?;
    check_frame_times(&cx, &scene.output.frame_times)?;
    let contacts = contacts(&cx, &scene, &bodies)?;
    check_contact_setup(&cx, &scene, &bodies, &contacts)?;
    check_reduced_quadrature(&cx, &analysis, &bodies)?;
    check_explicit_friction(&cx, &analysis, &contacts)?;
    let initial_velocity = initial_velocity(&cx, &scene, &bodies, node_count)?;
    let reference = match &scene.reference {
        Some(spec) => Some(reference(&cx, &bodies, &contacts, spec)?),
        None => None,
    };
    let name = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    Ok(Model {
        name,
        file: file.to_path_buf(),
        title: scene.title,
        bodies,
        node_count,
        fixed_dofs,
        loads,
        analysis,
        output: scene.output,
        probes,
        initial_velocity,
        reference,
        contacts,
        checkpoint_every: scene.analysis.checkpoint_every,
        source: SceneSource::default(),
    })
}

/// One-point quadrature in a dynamic run covers Quad4 bodies only (no rods).
fn check_reduced_quadrature(
    cx: &Context,
    analysis: &Analysis,
    bodies: &[Body],
) -> Result<(), InputError> {
    if let Analysis::Dynamic(d) = analysis
        && d.quadrature == Quadrature::Reduced
        && let Some(body) = bodies
            .iter()
            .find(|b| !matches!(b.kind, BodyKind::Continuum { .. }))
    {
        return Err(cx.err(format!(
            "analysis.quadrature: `reduced` covers Quad4 bodies (plane strain, plane stress, axisymmetric); body `{}` is a rod: use quadrature = \"full\"",
            body.name
        )));
    }
    Ok(())
}

/// The explicit central difference contact is frictionless: no pair may have friction.
fn check_explicit_friction(
    cx: &Context,
    analysis: &Analysis,
    contacts: &[ContactPair],
) -> Result<(), InputError> {
    if let Analysis::Dynamic(d) = analysis
        && d.integrator == IntegratorKind::CentralDifference
        && let Some(c) = contacts
            .iter()
            .find(|c| c.options.friction != Friction::None)
    {
        return Err(cx.err(format!(
            "contact `{}`: friction is implemented for the implicit integrators and statics; the explicit central difference contact is frictionless",
            c.name
        )));
    }
    Ok(())
}
