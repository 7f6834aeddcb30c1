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
use super::model::{Analysis, Body, BodyKind, Load, Model, Probe, SceneSource};
use super::obstacles::obstacles;
use super::probes::{check_force_window, check_history_cadence, frame_times, probes};
use super::reference::reference;
use super::spec::{
    ActiveSetSolve, IntegratorKind, MassKind, OutputSpec, Quadrature, Quantity, Scene,
};
use crate::contact::{ContactPair, Friction, Master, Obstacle};
use std::path::Path;

/// The model of a scene; `file` names it in messages, `base_dir` anchors relative mesh files.
pub fn build(scene: Scene, file: &Path, base_dir: &Path) -> Result<Model, InputError> {
    let cx = Context { file };
    let materials = materials(&cx, &scene)?;
    let (mut bodies, node_count) = bodies(&cx, &scene, &materials, base_dir)?;
    for (k, spec) in scene.node_set.iter().enumerate() {
        add_node_set(&cx, &mut bodies, k, spec)?;
    }
    let analysis = analysis(&cx, &scene.analysis, first_rod(&bodies).is_some())?;
    let curves = curves(&cx, &scene)?;
    let default_curve = default_curve(&analysis);
    let fixed_dofs = fixed_dofs(&cx, &scene, &bodies)?;
    let loads = loads(&cx, &scene, &bodies, &curves, &default_curve)?;
    let dynamic = matches!(analysis, Analysis::Dynamic(_));
    let probes = probes(&cx, &bodies, &scene.output.probe, dynamic)?;
    let frame_times = frame_times(&cx, &scene.output, analysis.end_time())?;
    check_force_window(&cx, scene.output.contact_force_window)?;
    check_history_cadence(&cx, &scene.output)?;
    let obstacles = obstacles(&cx, &scene, (&curves, analysis.end_time()))?;
    let contacts = contacts(&cx, &scene, &bodies, &obstacles)?;
    check_contact_setup(&cx, &scene, &bodies, &contacts)?;
    check_reaction_probes(&cx, &probes, &fixed_dofs, &loads)?;
    check_quad4_features(&cx, &analysis, &bodies)?;
    check_dispersion_free(&cx, &analysis, &bodies)?;
    check_explicit_friction(&cx, &analysis, &contacts)?;
    check_moving_obstacles(&cx, &analysis, &contacts)?;
    check_projectiles(&cx, &analysis, &obstacles)?;
    check_arc_length(&cx, &analysis, &loads, &contacts)?;
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
        output: OutputSpec {
            frame_times,
            ..scene.output
        },
        probes,
        initial_velocity,
        reference,
        contacts,
        obstacles,
        checkpoint_every: scene.analysis.checkpoint_every,
        source: SceneSource::default(),
    })
}

/// A reaction probe sums the support reactions of its set: the set needs a constrained DOF
/// in the probe's direction (a support or a prescribed displacement). (Its statistic, the
/// sum, is checked with the probe: `scene::probes`.)
fn check_reaction_probes(
    cx: &Context,
    probes: &[Probe],
    fixed_dofs: &[usize],
    loads: &[Load],
) -> Result<(), InputError> {
    let constrained = Model::constrained_dofs_of(fixed_dofs, loads);
    for (k, probe) in probes.iter().enumerate() {
        let component = match probe.quantity {
            Quantity::ReactionX => 0,
            Quantity::ReactionY => 1,
            _ => continue,
        };
        let dof = |n: &usize| 2 * n + component;
        if !probe
            .members
            .iter()
            .any(|n| constrained.binary_search(&dof(n)).is_ok())
        {
            return Err(cx.err(format!(
                "output.probe[{k}]: {} needs a node set with {} supported or prescribed;                  no node of `{}` has (the reaction would be 0)",
                probe.quantity.name(),
                ["x", "y"][component],
                probe.column
            )));
        }
    }
    Ok(())
}

/// The first rod body of `bodies` (None: all are Quad4 continua).
fn first_rod(bodies: &[Body]) -> Option<&Body> {
    bodies
        .iter()
        .find(|b| !matches!(b.kind, BodyKind::Continuum { .. }))
}

/// The features of the explicit Quad4 kernels (one-point quadrature, the bulk viscosity,
/// the mass scaling, the subcycling, ALE) are refused in a dynamic run with a rod body,
/// the first of them named with the rod.
fn check_quad4_features(
    cx: &Context,
    analysis: &Analysis,
    bodies: &[Body],
) -> Result<(), InputError> {
    let (Analysis::Dynamic(d), Some(rod)) = (analysis, first_rod(bodies)) else {
        return Ok(());
    };
    let kernels = "acts in the explicit Quad4 kernels (plane strain, plane stress, axisymmetric)";
    let refused = [
        (
            d.quadrature == Quadrature::Reduced,
            "quadrature",
            "`reduced` covers Quad4 bodies (plane strain, plane stress, axisymmetric)",
            "use quadrature = \"full\"",
        ),
        (
            d.bulk_viscosity.is_some(),
            "bulk_viscosity",
            kernels,
            "remove bulk_viscosity",
        ),
        (
            d.mass_scaling.is_some(),
            "mass_scaling",
            kernels,
            "remove mass_scaling",
        ),
        (
            d.subcycling.is_some(),
            "subcycling",
            kernels,
            "remove subcycling",
        ),
        (d.ale.is_some(), "ale", kernels, "remove ale"),
    ];
    match refused.iter().find(|(on, ..)| *on) {
        Some((_, key, what, remedy)) => Err(cx.err(format!(
            "analysis.{key}: {what}; body `{}` is a rod: {remedy}",
            rod.name
        ))),
        None => Ok(()),
    }
}

/// `mass = "dispersion_free"` is the rod blend: refused for a continuum body (the
/// quadrilateral blend is indefinite, docs/theory.md 8.9).
fn check_dispersion_free(
    cx: &Context,
    analysis: &Analysis,
    bodies: &[Body],
) -> Result<(), InputError> {
    if let Analysis::Dynamic(d) = analysis
        && d.mass == MassKind::DispersionFree
        && let Some(body) = bodies
            .iter()
            .find(|b| !matches!(b.kind, BodyKind::Rod { .. }))
    {
        return Err(cx.err(format!(
            "analysis.mass: `dispersion_free` is the blend for rods; body `{}` is a continuum (use `consistent` or `lumped`)",
            body.name
        )));
    }
    Ok(())
}

/// The explicit central difference contact has Coulomb friction; Greco's return coefficient
/// (the slip of a step a fraction of the frictionless one, solved again with its target) is
/// implemented for the implicit integrators and statics only.
fn check_explicit_friction(
    cx: &Context,
    analysis: &Analysis,
    contacts: &[ContactPair],
) -> Result<(), InputError> {
    if let Analysis::Dynamic(d) = analysis
        && d.integrator == IntegratorKind::CentralDifference
        && let Some(c) = contacts
            .iter()
            .find(|c| matches!(c.options.friction, Friction::Return { .. }))
    {
        return Err(cx.err(format!(
            "contact `{}`: return_coefficient is implemented for the implicit integrators and statics; with central_difference use Coulomb's `friction`",
            c.name
        )));
    }
    Ok(())
}

/// A moving obstacle is placed where its motion has it at each step of statics, of the
/// implicit integrators (whose impact conditions give a slave its velocity) and of central
/// difference without subcycling or ALE (a subcycled substep and an ALE slide read its
/// start position). Friction against it reads the slip relative to it, in central
/// difference and in the contact passes of statics and the implicit integrators, not in
/// the active set inside Newton.
fn check_moving_obstacles(
    cx: &Context,
    analysis: &Analysis,
    contacts: &[ContactPair],
) -> Result<(), InputError> {
    let Some(pair) = contacts.iter().find(|c| c.moving_obstacle().is_some()) else {
        return Ok(());
    };
    let Master::Obstacle(obstacle) = &pair.master else {
        return Ok(());
    };
    let key = format!(
        "obstacle `{}`.motion (contact `{}`)",
        obstacle.name, pair.name
    );
    let path = match analysis {
        Analysis::Static(_) => None,
        Analysis::Dynamic(d) if d.subcycling.is_some() => Some("analysis.subcycling"),
        Analysis::Dynamic(d) if d.ale.is_some() => Some("analysis.ale"),
        Analysis::Dynamic(_) => None,
    };
    if let Some(path) = path {
        return Err(cx.err(format!(
            "{key}: a moving obstacle runs under statics and every integrator (central \
             difference without subcycling or ALE), not under {path}"
        )));
    }
    // the stick and slide of the active set inside Newton (theory 8.3b) read the slave's
    // own slip; the passes read the slip relative to the obstacle
    let newton = match analysis {
        Analysis::Static(s) => Some(&s.newton),
        Analysis::Dynamic(d) if d.integrator != IntegratorKind::CentralDifference => {
            Some(&d.newton)
        }
        Analysis::Dynamic(_) => None,
    };
    let inside = newton.is_some_and(|newton| match newton.active_set {
        Some(ActiveSetSolve::Newton) => true,
        Some(ActiveSetSolve::Passes) => false,
        None => contacts.iter().any(|pair| pair.mortar().is_some()),
    });
    if inside
        && let Some(c) = contacts.iter().find(|c| {
            c.moving_obstacle().is_some() && !matches!(c.options.friction, Friction::None)
        })
    {
        return Err(cx.err(format!(
            "contact `{}`: friction against a moving obstacle with the active set decided \
             inside Newton's iteration (analysis.newton.active_set `newton`, or a mortar pair \
             in the scene), whose stick and slide read the slave's own slip, not its slip \
             along the obstacle; set analysis.newton.active_set to `passes`",
            c.name
        )));
    }
    Ok(())
}

/// A projectile's translation is an unknown of the explicit step (its carrier's DOFs in the
/// forward-increment correction): central difference without subcycling or ALE, whose
/// substeps and slides do not carry it; statics has no mass to move it, and the implicit
/// integrators' contact rows do not hold it.
fn check_projectiles(
    cx: &Context,
    analysis: &Analysis,
    obstacles: &[Obstacle],
) -> Result<(), InputError> {
    let Some(obstacle) = obstacles.iter().find(|o| o.projectile.is_some()) else {
        return Ok(());
    };
    let path = match analysis {
        Analysis::Static(_) => Some("statics (nothing but the contact would hold it)"),
        Analysis::Dynamic(d) if d.integrator != IntegratorKind::CentralDifference => {
            Some("an implicit integrator")
        }
        Analysis::Dynamic(d) if d.subcycling.is_some() => Some("analysis.subcycling"),
        Analysis::Dynamic(d) if d.ale.is_some() => Some("analysis.ale"),
        Analysis::Dynamic(_) => None,
    };
    match path {
        Some(path) => Err(cx.err(format!(
            "obstacle `{}`.projectile: a projectile runs under central_difference (without \
             subcycling or ALE), not under {path}",
            obstacle.name
        ))),
        None => Ok(()),
    }
}

/// The contact pairs arc length takes: against still obstacles (a moving one is a
/// prescribed motion), with the active set decided by passes (not a mortar pair's Newton).
fn check_arc_length_contacts(
    cx: &Context,
    newton: &super::spec::NewtonSpec,
    contacts: &[ContactPair],
) -> Result<(), InputError> {
    for c in contacts {
        let why = if matches!(c.options.friction, Friction::Return { .. }) {
            "return_coefficient's target is the slip of the same increment solved without \
             friction, whose load factor an arc does not keep; use Coulomb's `friction`"
        } else if c.moving_obstacle().is_some() {
            "its obstacle moves, a prescribed motion, which arc length does not scale"
        } else if c.mortar().is_some() || matches!(newton.active_set, Some(ActiveSetSolve::Newton))
        {
            "arc length decides the active set by passes; set the pair's discretization to \
             `node_to_segment` and analysis.newton.active_set to `passes`"
        } else {
            continue;
        };
        return Err(cx.err(format!("analysis.arc_length: contact `{}`: {why}", c.name)));
    }
    Ok(())
}

/// Arc-length continuation scales the loads by one factor: the loads are forces that grow
/// in proportion (a curve through zero, linear in the pseudo time) and nothing is
/// prescribed but the supports. Its contact pairs are still, with Coulomb's friction or
/// none (theory 5b): their active set changes between the passes of an increment, not
/// inside Newton.
fn check_arc_length(
    cx: &Context,
    analysis: &Analysis,
    loads: &[Load],
    contacts: &[ContactPair],
) -> Result<(), InputError> {
    let Analysis::Static(s) = analysis else {
        return Ok(());
    };
    if s.arc_length.is_none() {
        return Ok(());
    }
    check_arc_length_contacts(cx, &s.newton, contacts)?;
    let end = s.end_time;
    for (k, load) in loads.iter().enumerate() {
        let curve = match load {
            Load::NodalForce { curve, .. }
            | Load::Traction { curve, .. }
            | Load::Pressure { curve, .. } => curve,
            _ => {
                return Err(cx.err(format!(
                    "load[{k}]: a prescribed motion under analysis.arc_length, which scales \
                     forces only; a displacement-driven run passes its limit without it"
                )));
            }
        };
        let full = curve.value(end);
        let proportional = full != 0.0
            && (0..=4).all(|i| {
                let t = end * i as f64 / 4.0;
                (curve.value(t) - full * t / end).abs() <= 1e-12 * full.abs()
            });
        if !proportional {
            return Err(cx.err(format!(
                "load[{k}]: its curve is not a ramp from zero to end_time; \
                 analysis.arc_length scales the loads by one factor"
            )));
        }
    }
    if loads.is_empty() {
        return Err(cx.err("analysis.arc_length: the scene has no load to scale"));
    }
    Ok(())
}
