//! `[reference]`: a closed-form solution the run is compared with, its numbers read from the
//! model (the contact pair's bodies, their material, section, length and velocities).

use super::InputError;
use super::context::Context;
use super::model::{Body, BodyKind, Reference};
use super::spec::{ReferenceKind, ReferenceSpec};
use crate::contact::{ContactPair, Master};
use crate::element::Formulation;
use crate::mesh::Cells;

/// Reads the numbers of a `[reference]` from the model: the pair's slave body (and master
/// body for `bars`), their material, section, length and initial velocities.
pub(super) fn reference(
    cx: &Context,
    bodies: &[Body],
    contacts: &[ContactPair],
    spec: &ReferenceSpec,
) -> Result<Reference, InputError> {
    let pair = match &spec.contact {
        Some(name) => contacts
            .iter()
            .find(|c| &c.name == name)
            .ok_or_else(|| cx.err(format!("reference.contact: no contact pair named `{name}`")))?,
        None if contacts.len() == 1 => &contacts[0],
        None => {
            return Err(cx.err(format!(
                "reference.contact: the scene has {} contact pairs; name the one the reference speaks of",
                contacts.len()
            )));
        }
    };
    let kind_name = scene_name(spec.kind);
    let wrong = |what: &str| {
        cx.err(format!(
            "reference.kind = \"{kind_name}\" needs {what} (contact pair `{}`)",
            pair.name
        ))
    };
    match spec.kind {
        ReferenceKind::Bars => bars(bodies, pair, &wrong),
        ReferenceKind::RodWall => rod_wall(bodies, pair, &wrong),
        ReferenceKind::HertzImpact => hertz_impact(bodies, pair, &wrong),
    }
}

/// The scene's name of a reference kind.
fn scene_name(kind: ReferenceKind) -> &'static str {
    match kind {
        ReferenceKind::Bars => "bars",
        ReferenceKind::RodWall => "rod_wall",
        ReferenceKind::HertzImpact => "hertz_impact",
    }
}

/// The error that names what the reference needs of the pair.
type Needs<'a> = dyn Fn(&str) -> InputError + 'a;

/// A rod body's (density, Young's modulus, area, length); None for a continuum.
fn rod(body: &Body) -> Option<(f64, f64, f64, f64)> {
    let BodyKind::Rod { area } = body.kind else {
        return None;
    };
    let Cells::Rod2(cells) = &body.mesh.cells else {
        return None;
    };
    let length: f64 = cells
        .iter()
        .map(|[i, j]| {
            let (a, b) = (body.mesh.nodes[*i], body.mesh.nodes[*j]);
            (b[0] - a[0]).hypot(b[1] - a[1])
        })
        .sum();
    Some((
        body.material.density,
        body.material.elastic.young,
        area,
        length,
    ))
}

fn speed(v: [f64; 2]) -> f64 {
    v[0].hypot(v[1])
}

/// `bars`: two equal rods meeting at their relative velocity (reference::equal_bars_impact).
fn bars(bodies: &[Body], pair: &ContactPair, wrong: &Needs) -> Result<Reference, InputError> {
    let slave = &bodies[pair.slave_body];
    let master = match &pair.master {
        Master::Segments { body, .. } | Master::Nodes { body, .. } => *body,
        Master::Obstacle(_) => return Err(wrong("a rod as master, not an obstacle")),
    };
    let (Some(a), Some(b)) = (rod(slave), rod(&bodies[master])) else {
        return Err(wrong("two rods"));
    };
    let same = |x: f64, y: f64| (x - y).abs() <= 1e-9 * x.abs().max(y.abs());
    if !(same(a.0, b.0) && same(a.1, b.1) && same(a.2, b.2) && same(a.3, b.3)) {
        return Err(wrong(
            "two equal rods (same density, Young's modulus, area and length)",
        ));
    }
    let v = bodies[master].velocity;
    let relative = [slave.velocity[0] - v[0], slave.velocity[1] - v[1]];
    let (force, duration) =
        crate::reference::equal_bars_impact(a.0, a.1, a.2, a.3, speed(relative));
    Ok(Reference::ForcePulse {
        kind: ReferenceKind::Bars,
        pair: pair.name.clone(),
        force,
        duration,
    })
}

/// `rod_wall`: a rod against a rigid obstacle (reference::rod_wall_impact).
fn rod_wall(bodies: &[Body], pair: &ContactPair, wrong: &Needs) -> Result<Reference, InputError> {
    let slave = &bodies[pair.slave_body];
    if !matches!(pair.master, Master::Obstacle(_))
        || pair.moving_obstacle().is_some()
        || pair.projectile().is_some()
    {
        return Err(wrong(
            "a rigid obstacle at rest as master (the closed form reads the body's speed against it)",
        ));
    }
    let (density, young, area, length) = rod(slave).ok_or_else(|| wrong("a rod as slave body"))?;
    let (force, duration) =
        crate::reference::rod_wall_impact(density, young, area, length, speed(slave.velocity));
    Ok(Reference::ForcePulse {
        kind: ReferenceKind::RodWall,
        pair: pair.name.clone(),
        force,
        duration,
    })
}

/// `hertz_impact`: an axisymmetric sphere against a rigid obstacle
/// (reference::hertz_sphere_impact).
fn hertz_impact(
    bodies: &[Body],
    pair: &ContactPair,
    wrong: &Needs,
) -> Result<Reference, InputError> {
    let slave = &bodies[pair.slave_body];
    if !matches!(pair.master, Master::Obstacle(_))
        || pair.moving_obstacle().is_some()
        || pair.projectile().is_some()
    {
        return Err(wrong(
            "a rigid obstacle at rest as master (the closed form reads the body's speed against it)",
        ));
    }
    if !matches!(
        slave.kind,
        BodyKind::Continuum {
            formulation: Formulation::Axisymmetric,
            ..
        }
    ) {
        return Err(wrong("an axisymmetric sphere (half disc) as slave body"));
    }
    // the half disc spans the sphere's diameter along the axis
    let (low, high) = slave
        .mesh
        .nodes
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p[1]), h.max(p[1]))
        });
    let (radius, duration, peak_force) = crate::reference::hertz_sphere_impact(
        0.5 * (high - low),
        slave.material.density,
        slave.material.elastic.young,
        slave.material.elastic.poisson,
        speed(slave.velocity),
    );
    Ok(Reference::Hertz {
        pair: pair.name.clone(),
        peak_force,
        radius,
        duration,
    })
}
