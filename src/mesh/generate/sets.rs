//! Naming a generated mesh's boundary: edge sets by a rule on each boundary edge, chained head
//! to tail, and one-node sets at given points.

use std::collections::BTreeMap;

use super::blocks::min_edge;
use crate::mesh::plane::{Point, norm, sub};
use crate::mesh::{Cells, Mesh, chain_order};

/// Distance below which a node counts as lying on a line: far below any element size.
pub(super) fn feature_tol(mesh: &Mesh) -> f64 {
    let Cells::Quad4(quads) = &mesh.cells else {
        return 0.0;
    };
    1e-6 * min_edge(&mesh.nodes, quads)
}

/// Both ends on the line coordinate[axis] = value.
pub(super) fn on_line(p: Point, q: Point, axis: usize, value: f64, tol: f64) -> bool {
    (p[axis] - value).abs() <= tol && (q[axis] - value).abs() <= tol
}

/// Puts every boundary edge a -> b into the edge set `name_of(x_a, x_b)`.
pub(super) fn name_boundary(mesh: &mut Mesh, name_of: impl Fn(Point, Point) -> &'static str) {
    let mut sets: BTreeMap<&str, Vec<[usize; 2]>> = BTreeMap::new();
    for e in mesh.boundary_edges() {
        sets.entry(name_of(mesh.nodes[e[0]], mesh.nodes[e[1]]))
            .or_default()
            .push(e);
    }
    for (name, edges) in sets {
        mesh.add_edge_set(name, chain_order(edges));
    }
    if !mesh.edge_sets.contains_key("boundary") {
        mesh.add_edge_set("boundary", chain_order(mesh.boundary_edges()));
    }
}

/// The node nearest to `p`.
pub(super) fn node_at(mesh: &Mesh, p: Point) -> usize {
    let distance = |n: &usize| norm(sub(mesh.nodes[*n], p));
    (0..mesh.nodes.len())
        .min_by(|a, b| distance(a).total_cmp(&distance(b)))
        .expect("a generated mesh has nodes")
}
