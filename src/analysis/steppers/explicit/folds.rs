//! What an inverted element says of its cause when a corner of another body sits on one of
//! its nodes: a sharp corner sliding through a body carries the node under it along (the
//! stagnation point of the material flowing round the corner, as at a cutting tool's edge),
//! and the element that holds the node folds once the corner has moved an element's width
//! (docs/validation.md 4.15, "the 2x2 kernel's limit").

use crate::assembly::ElementFailure;
use crate::assembly::explicit::tight::shortest_edge;
use crate::contact::Master;
use crate::element::KernelError;
use crate::scene::{Body, Model};

/// A node of the folded element lies on the other body's corner when it is closer to it
/// than this share of the element's shortest edge (the fold at 240 x 24 in validation 4.15:
/// 1e-10 m on 0.17 mm elements; a node merely near the corner is a tenth of an edge off).
const ON_CORNER_SHARE: f64 = 0.05;

/// A boundary node is a corner where the boundary turns by more than this (radians, 45
/// degrees) towards the body's inside: a convex corner, which can plough.
const CORNER_TURN: f64 = std::f64::consts::FRAC_PI_4;

/// The hint for an inverted element `failure` (its message gets it appended), from the
/// positions `x` the kernel saw (global nodes): the corner of a body in contact with the
/// element's body that carries one of its nodes, and what to do. None when the failure is
/// not an inverted element or no corner sits on its nodes.
pub(super) fn fold_hint(model: &Model, x: &[[f64; 2]], failure: &ElementFailure) -> Option<String> {
    if !matches!(failure.error, KernelError::NegativeJacobian { .. }) {
        return None;
    }
    let (index, body) = (model.bodies.iter().enumerate()).find(|(_, b)| b.name == failure.body)?;
    let nodes: [usize; 4] = body.mesh.cells.nodes_of(failure.element).try_into().ok()?;
    let nodes = nodes.map(|n| body.global(n));
    let edge = shortest_edge(&nodes.map(|n| x[n]));
    let (node, other, corner) = touching_bodies(model, index).find_map(|other| {
        let other_body = &model.bodies[other];
        corners(other_body, x).find_map(|corner| {
            (nodes.iter())
                .find(|&&n| distance(x[n], x[corner]) < ON_CORNER_SHARE * edge)
                .map(|&n| (n, other_body, corner))
        })
    })?;
    let remedy = if model.analysis.one_point() {
        "a finer mesh under the corner, or a rounded corner"
    } else {
        "the one-point kernel (analysis.quadrature = \"reduced\") runs such meshes"
    };
    Some(format!(
        "node {} of the element sits on the corner of body `{}` (its node {}), which slides \
         through body `{}`: the corner carries the node under it along and the element folds \
         (a sharp corner ploughing a finer mesh, docs/validation.md 4.15); {remedy}",
        node - body.node_offset,
        other.name,
        corner - other.node_offset,
        body.name,
    ))
}

/// The bodies that a contact pair puts against body `index` (either role).
fn touching_bodies(model: &Model, index: usize) -> impl Iterator<Item = usize> + '_ {
    let mut others: Vec<usize> = (model.contacts.iter())
        .filter_map(|pair| {
            let Master::Segments { body: master, .. } = pair.master else {
                return None;
            };
            match (pair.slave_body == index, master == index) {
                (true, false) => Some(master),
                (false, true) => Some(pair.slave_body),
                _ => None,
            }
        })
        .collect();
    others.sort_unstable();
    others.dedup();
    others.into_iter()
}

/// The convex corners of a body's boundary (global nodes) at positions `x`: the boundary is
/// counter-clockwise, so a left turn of more than [`CORNER_TURN`] at a node is a corner.
fn corners<'a>(body: &'a Body, x: &'a [[f64; 2]]) -> impl Iterator<Item = usize> + 'a {
    body.boundary.iter().filter_map(move |&[a, c]| {
        // the boundary edge leaving c: its node's other edge
        let [_, b] = *body.boundary_at_node[c].iter().find(|e| e[0] == c)?;
        let (a, c, b) = (body.global(a), body.global(c), body.global(b));
        let d1 = [x[c][0] - x[a][0], x[c][1] - x[a][1]];
        let d2 = [x[b][0] - x[c][0], x[b][1] - x[c][1]];
        let turn = (d1[0] * d2[1] - d1[1] * d2[0]).atan2(d1[0] * d2[0] + d1[1] * d2[1]);
        (turn > CORNER_TURN).then_some(c)
    })
}

fn distance(p: [f64; 2], q: [f64; 2]) -> f64 {
    (p[0] - q[0]).hypot(p[1] - q[1])
}
