//! The warnings of the bodies' start, before a step is taken: a support that cancels the
//! initial velocity it holds, an axisymmetric body moving radially as a whole, elements too
//! elongated to carry a plastic impact, and a plane-stress body thicker than it is long.

use super::some_nodes;
use crate::output::readable;
use crate::scene::{Body, Model};

/// A body whose median element has its longest edge more than this many times its
/// shortest warns: explicit practice keeps impact meshes near square (LS-DYNA's and Abaqus'
/// guidance: aspect ratios below about 5, 10 at most away from the action). A Taylor rod
/// of 1 x 200 elements (aspect 30) gave a foot diameter 1.7 % off and twice the plastic
/// strain of square elements. The median, not the worst: a graded mesh (the Hertz sphere's
/// half disc, whose thin elements near the pole reach 51) elongates some elements on
/// purpose; a mesh whose typical element is long has nx and ny against the body's shape.
pub const ASPECT_RATIO: f64 = 10.0;

/// The warnings of the bodies' start (see the module legend).
pub(super) fn initial_warnings(model: &Model) -> Vec<String> {
    let mut out = Vec::new();
    for body in &model.bodies {
        out.extend(cancelled_velocity(model, body));
        out.extend(radial_velocity(body));
        out.extend(elongated_elements(body));
        out.extend(thick_plane_stress(body));
    }
    out
}

/// A plane-stress body whose thickness exceeds its larger in-plane extent: plane stress
/// (sigma_zz = 0 through the thickness) holds for plates thin against their in-plane size;
/// one thicker than it is long is not a plate. It is how the default thickness of 1 shows
/// when the lengths are small (a Taylor rod of 25 mm written as plane stress carried 1 m of
/// depth: plastic work 8069 J against 96 J).
fn thick_plane_stress(body: &Body) -> Option<String> {
    let continuum = body.kind.continuum()?;
    if continuum.formulation != crate::element::Formulation::PlaneStress {
        return None;
    }
    let extent = |c: usize| {
        let (low, high) = (body.mesh.nodes.iter())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                (l.min(p[c]), h.max(p[c]))
            });
        high - low
    };
    let size = extent(0).max(extent(1));
    (continuum.thickness > size).then(|| {
        format!(
            "body `{}` is plane stress with a thickness of {} (the default is 1), more than its \
             in-plane size {}: plane stress is for plates thin against their size, and every \
             force, mass and energy scales with the thickness; give `thickness`, or use \
             plane_strain (per unit depth) or axisymmetric for a solid body",
            body.name,
            readable(continuum.thickness),
            readable(size)
        )
    })
}

/// The nodes of `body` a support holds in a component in which they start moving, where
/// they lie on the body's trailing side in that component (behind its centre, as the body
/// moves). Held nodes on the leading side are the held-face idealization of a rigid wall (a
/// Taylor rod's face held in y, the rest at the impact speed: Wilkins & Guinan's set-up),
/// which loses their share of the kinetic energy on purpose; held on the trailing side,
/// they hold back the body they belong to (a `fix = ["y"]` left on the moving rod's top:
/// L_f 25.34 mm against 24.06).
fn cancelled_velocity(model: &Model, body: &Body) -> Vec<String> {
    let mut out = Vec::new();
    let count = body.mesh.nodes.len() as f64;
    for (c, axis) in ["x", "y"].iter().enumerate() {
        let centre = body.mesh.nodes.iter().map(|p| p[c]).sum::<f64>() / count;
        let nodes: Vec<usize> = (0..body.mesh.nodes.len())
            .filter(|n| {
                let (g, x) = (body.global(*n), body.mesh.nodes[*n][c]);
                let v = model.initial_velocity[2 * g + c];
                model.fixed_dofs.binary_search(&(2 * g + c)).is_ok()
                    && v != 0.0
                    && (x - centre) * v <= 0.0
            })
            .map(|n| body.global(n))
            .collect();
        let Some(first) = nodes.first() else {
            continue;
        };
        out.push(format!(
            "body `{}`: {} node(s) on its trailing side held in {axis} by a [[support]] start \
             moving in {axis} (at {} at node {first}; global nodes {}): the support holds them \
             at rest from the first step, holding the body back; a support meant for another \
             body, or on the wrong end (a held face belongs where the body strikes)?",
            body.name,
            nodes.len(),
            readable(model.initial_velocity[2 * first + c]),
            some_nodes(&nodes)
        ));
    }
    out
}

/// An axisymmetric body given a radial velocity as a whole (`velocity = [v_r, v_z]`).
fn radial_velocity(body: &Body) -> Option<String> {
    let [radial, axial] = body.velocity;
    (body.is_axisymmetric() && radial != 0.0).then(|| {
        format!(
            "axisymmetric body `{}` starts with velocity = [{}, {}]: x is the radius, so the \
             whole body moves radially, {} (a uniform radial velocity is no rigid motion of a \
             ring); the components swapped ([{}, {}] for an axial motion)?",
            body.name,
            readable(radial),
            readable(axial),
            if radial < 0.0 {
                "imploding onto the axis"
            } else {
                "expanding"
            },
            readable(axial),
            readable(radial)
        )
    })
}

/// How elongated `body`'s elements are, when its median element is beyond [`ASPECT_RATIO`].
fn elongated_elements(body: &Body) -> Option<String> {
    if body.kind.is_rod() {
        return None;
    }
    let ratio = |e: usize| {
        let (short, long) = (body.mesh.edge_lengths(e))
            .fold((f64::INFINITY, 0.0_f64), |(s, l), d| (s.min(d), l.max(d)));
        long / short
    };
    let mut ratios: Vec<f64> = (0..body.elements()).map(ratio).collect();
    if ratios.is_empty() {
        return None;
    }
    let count = ratios.iter().filter(|r| **r > ASPECT_RATIO).count();
    let middle = ratios.len() / 2;
    let median = *ratios.select_nth_unstable_by(middle, f64::total_cmp).1;
    (median > ASPECT_RATIO).then(|| {
        format!(
            "body `{}` has {count} element(s) longer than {} times their width (the median \
             element: {}): such elements bend and crush unlike the material (a Taylor rod of \
             1 x 200 elements: foot diameter 1.7 % off, twice the plastic strain); choose nx \
             and ny near the body's width and height ratio",
            body.name,
            readable(ASPECT_RATIO),
            readable(median)
        )
    })
}
