//! The `[[obstacle]]` tables: rigid polylines, at rest, driven by a prescribed translation
//! (`motion`), or thrown with a mass of their own (`projectile`).

use super::InputError;
use super::context::{Context, finite, positive};
use super::model::Curve;
use super::spec::{FormulationSpec, ObstacleMotionSpec, ProjectileSpec, Scene};
use crate::contact::projectile::Spin;
use crate::contact::{Obstacle, ObstacleMotion, Projectile};
use crate::mesh::plane::round_corners;
use crate::output::readable;
use std::collections::BTreeMap;

/// The `[[obstacle]]` polylines: unique names, at least 2 points (3 when closed), finite,
/// no two consecutive points equal; with `corner_radius` each corner rounded by an arc; a
/// `motion` resolved against the named `curves` (its default a ramp over `end_time`).
pub(super) fn obstacles(
    cx: &Context,
    scene: &Scene,
    (curves, end_time): (&BTreeMap<String, Curve>, f64),
) -> Result<Vec<Obstacle>, InputError> {
    let mut out: Vec<Obstacle> = Vec::new();
    for (k, o) in scene.obstacle.iter().enumerate() {
        let key = format!("obstacle[{k}] (`{}`)", o.name);
        if out.iter().any(|p| p.name == o.name) {
            return Err(cx.err(format!("{key}.name: used twice")));
        }
        if o.points.len() < 2 || (o.closed && o.points.len() < 3) {
            return Err(cx.err(format!(
                "{key}.points: an obstacle needs at least 2 points (3 when closed)"
            )));
        }
        finite(
            cx,
            &format!("{key}.points"),
            &o.points.iter().flatten().copied().collect::<Vec<_>>(),
        )?;
        if o.points.windows(2).any(|w| w[0] == w[1]) {
            return Err(cx.err(format!("{key}.points: two consecutive points coincide")));
        }
        let points = match o.corner_radius {
            None => o.points.clone(),
            Some(r) => {
                let radius = positive(cx, &format!("{key}.corner_radius"), r)?;
                round_corners(&o.points, o.closed, radius).map_err(|k| {
                    cx.err(format!(
                        "{key}.corner_radius: an arc of radius {} does not fit at point {k} \
                         ({}, {}): its tangent length r tan(turn / 2) is more than half a \
                         segment beside it; a smaller corner_radius",
                        readable(radius),
                        readable(o.points[k][0]),
                        readable(o.points[k][1])
                    ))
                })?
            }
        };
        let motion = match &o.motion {
            None => None,
            Some(m) => Some(motion(cx, m, &points, (curves, end_time), &key)?),
        };
        let index = out.iter().filter(|o| o.projectile.is_some()).count();
        let projectile = match &o.projectile {
            None => None,
            Some(p) => Some(projectile(cx, scene, p, (&points, o.closed, index), &key)?),
        };
        if motion.is_some() && projectile.is_some() {
            return Err(cx.err(format!(
                "{key}: both `motion` and `projectile`: an obstacle is either driven (motion) \
                 or moved by the contact forces (projectile); remove one"
            )));
        }
        out.push(Obstacle {
            name: o.name.clone(),
            points,
            closed: o.closed,
            motion,
            projectile,
        });
    }
    Ok(out)
}

/// An obstacle's `motion` from its `points`: a finite displacement, its curve named among
/// `curves` (default: 0 at t = 0, 1 at `end_time`), 0 at t = 0 (the obstacle starts where
/// its points are).
fn motion(
    cx: &Context,
    spec: &ObstacleMotionSpec,
    points: &[[f64; 2]],
    (curves, end_time): (&BTreeMap<String, Curve>, f64),
    key: &str,
) -> Result<ObstacleMotion, InputError> {
    let key = format!("{key}.motion");
    finite(cx, &format!("{key}.displacement"), &spec.displacement)?;
    let ramp = Curve {
        points: vec![[0.0, 0.0], [end_time, 1.0]],
    };
    let curve = super::loads::curve(cx, curves, &ramp, &spec.curve, &key)?;
    if curve.value(0.0) != 0.0 {
        return Err(cx.err(format!(
            "{key}.curve: the curve is {} at t = 0, so the obstacle would jump there from its \
             points; a motion starts at 0 (write the start position in `points`)",
            readable(curve.value(0.0))
        )));
    }
    Ok(ObstacleMotion {
        base: points.to_vec(),
        displacement: spec.displacement,
        curve,
        placed: 0.0,
    })
}

/// An obstacle's `projectile` from its `points`, the `index`-th of the scene: a positive
/// mass, a finite velocity, along the axis in axisymmetry (a ring cannot translate radially
/// as a rigid body).
fn projectile(
    cx: &Context,
    scene: &Scene,
    spec: &ProjectileSpec,
    (points, closed, index): (&[[f64; 2]], bool, usize),
    key: &str,
) -> Result<Projectile, InputError> {
    let key = format!("{key}.projectile");
    let mass = positive(cx, &format!("{key}.mass"), spec.mass)?;
    finite(cx, &format!("{key}.velocity"), &spec.velocity)?;
    let axisymmetric = (scene.body.iter()).any(|b| b.formulation == FormulationSpec::Axisymmetric);
    if axisymmetric && spec.velocity[0] != 0.0 {
        return Err(cx.err(format!(
            "{key}.velocity: {} across the axis in an axisymmetric scene; a projectile there \
             is a body of revolution and moves along the axis only (velocity = [0, vy])",
            readable(spec.velocity[0])
        )));
    }
    Ok(Projectile {
        index,
        mass,
        velocity: spec.velocity,
        spin: spin(cx, spec, (points, closed), axisymmetric, &key)?,
        base: points.to_vec(),
        carrier: None,
    })
}

/// A projectile's rotation: with an `inertia` (positive), about `centre` (default: the
/// centroid of a closed polygon; an open polyline needs one), at `angular_velocity` (default
/// 0); none without an inertia, where the other two are refused, and in axisymmetry.
fn spin(
    cx: &Context,
    spec: &ProjectileSpec,
    (points, closed): (&[[f64; 2]], bool),
    axisymmetric: bool,
    key: &str,
) -> Result<Option<Spin>, InputError> {
    let Some(inertia) = spec.inertia else {
        if spec.angular_velocity.is_some() || spec.centre.is_some() {
            return Err(cx.err(format!(
                "{key}: `angular_velocity` or `centre` without `inertia`: a projectile \
                 rotates only with a moment of inertia (give `inertia`, or remove them)"
            )));
        }
        return Ok(None);
    };
    let inertia = positive(cx, &format!("{key}.inertia"), inertia)?;
    if axisymmetric {
        return Err(cx.err(format!(
            "{key}.inertia: a projectile in an axisymmetric scene is a body of revolution and \
             does not rotate in the plane; remove `inertia`"
        )));
    }
    let angular_velocity = spec.angular_velocity.unwrap_or(0.0);
    finite(cx, &format!("{key}.angular_velocity"), &[angular_velocity])?;
    let centre = match (spec.centre, closed) {
        (Some(c), _) => {
            finite(cx, &format!("{key}.centre"), &c)?;
            c
        }
        (None, true) => crate::ale::geometry::moments(points, false).centroid(),
        (None, false) => {
            return Err(cx.err(format!(
                "{key}.centre: a rotating projectile on an open polyline needs its centre of \
                 mass (`centre = [x, y]`); a closed polygon's defaults to its centroid"
            )));
        }
    };
    Ok(Some(Spin {
        inertia,
        angular_velocity,
        centre,
        node: None,
    }))
}
