//! What the generators' tests share: the checks every generated quad mesh must pass, areas
//! and arc angles, and small specs of each shape.

use std::collections::BTreeSet;
use std::f64::consts::PI;

use super::blocks::{merge_coincident, min_edge};
use super::{ConicalBar, QuarterDisc, Rectangle, RoundBar};
use crate::mesh::plane::{Point, norm, quad_area, sub};
use crate::mesh::{Cells, Mesh};

const GAUSS: f64 = 0.577_350_269_189_625_8;

/// det J at the 2x2 Gauss points of a Quad4.
pub(super) fn det_j(x: [Point; 4]) -> [f64; 4] {
    let points = [
        (-GAUSS, -GAUSS),
        (GAUSS, -GAUSS),
        (GAUSS, GAUSS),
        (-GAUSS, GAUSS),
    ];
    points.map(|(xi, eta)| {
        let d_xi = [-(1.0 - eta), 1.0 - eta, 1.0 + eta, -(1.0 + eta)].map(|v| 0.25 * v);
        let d_eta = [-(1.0 - xi), -(1.0 + xi), 1.0 + xi, 1.0 - xi].map(|v| 0.25 * v);
        let j = |d: [f64; 4], c: usize| (0..4).map(|k| d[k] * x[k][c]).sum::<f64>();
        j(d_xi, 0) * j(d_eta, 1) - j(d_eta, 0) * j(d_xi, 1)
    })
}

pub(super) fn quads(mesh: &Mesh) -> &[[usize; 4]] {
    match &mesh.cells {
        Cells::Quad4(q) => q,
        Cells::Rod2(_) => panic!("expected quads"),
    }
}

pub(super) fn total_area(mesh: &Mesh) -> f64 {
    quads(mesh)
        .iter()
        .map(|q| quad_area(q.map(|n| mesh.nodes[n])))
        .sum()
}

pub(super) fn edge_count(mesh: &Mesh, name: &str) -> usize {
    mesh.edge_sets[name].len()
}

/// The checks every generated quad mesh must pass: det J > 0 at every Gauss point, `all`,
/// no duplicate or unused nodes, every edge set on the boundary with the boundary's
/// orientation and chained head to tail, its node set matching, and the edge sets exactly
/// covering the boundary.
pub(super) fn assert_valid(mesh: &Mesh) {
    let quads = quads(mesh);
    for (e, q) in quads.iter().enumerate() {
        let dets = det_j(q.map(|n| mesh.nodes[n]));
        assert!(dets.iter().all(|&d| d > 0.0), "element {e}: det J {dets:?}");
    }
    assert_eq!(
        mesh.element_sets["all"],
        (0..quads.len()).collect::<Vec<_>>()
    );
    let used: BTreeSet<usize> = quads.iter().flatten().copied().collect();
    assert_eq!(used.len(), mesh.nodes.len(), "unused nodes");
    let (distinct, _) = merge_coincident(&mesh.nodes, 1e-9 * min_edge(&mesh.nodes, quads));
    assert_eq!(distinct.len(), mesh.nodes.len(), "duplicate nodes");

    let boundary: BTreeSet<[usize; 2]> = mesh.boundary_edges().into_iter().collect();
    let mut covered = BTreeSet::new();
    // `boundary` is the whole of it; the named sets partition it
    let whole: BTreeSet<[usize; 2]> = mesh.edge_sets["boundary"].iter().copied().collect();
    assert_eq!(whole, boundary, "the set boundary");
    for (name, edges) in &mesh.edge_sets {
        for e in edges {
            assert!(
                boundary.contains(e),
                "set {name}: edge {e:?} is not a ccw boundary edge"
            );
            assert!(
                name == "boundary" || covered.insert(*e),
                "edge {e:?} in two sets"
            );
        }
        let chained = edges.windows(2).filter(|w| w[0][1] == w[1][0]).count();
        let chains = edges.len() - chained;
        assert!(chains <= 2, "set {name} is in {chains} pieces");
        let nodes: BTreeSet<usize> = edges.iter().flatten().copied().collect();
        assert_eq!(
            mesh.node_sets[name],
            nodes.into_iter().collect::<Vec<_>>(),
            "node set {name}"
        );
    }
    assert_eq!(covered, boundary, "edge sets do not cover the boundary");
}

pub(super) fn node(mesh: &Mesh, set: &str) -> Point {
    let ids = &mesh.node_sets[set];
    assert_eq!(ids.len(), 1, "set {set}");
    mesh.nodes[ids[0]]
}

pub(super) fn close(a: Point, b: Point) -> bool {
    norm(sub(a, b)) < 1e-12 * (1.0 + norm(b))
}

/// Exact area of a disc sector minus the segments cut off by the chords of the arc steps.
pub(super) fn chord_area(radius: f64, angles: impl Iterator<Item = f64>) -> f64 {
    angles.map(|d| 0.5 * radius * radius * d.sin()).sum()
}

pub(super) fn arc_angles(mesh: &Mesh, set: &str, center: Point) -> Vec<f64> {
    let angle = |p: Point| (p[1] - center[1]).atan2(p[0] - center[0]);
    mesh.edge_sets[set]
        .iter()
        .map(|e| {
            let d = angle(mesh.nodes[e[1]]) - angle(mesh.nodes[e[0]]);
            d.abs().min(2.0 * PI - d.abs())
        })
        .collect()
}

pub(super) fn rectangle(nx: usize, ny: usize) -> Rectangle {
    Rectangle {
        origin: [1.0, -2.0],
        width: 3.0,
        height: 2.0,
        nx,
        ny,
        grading_x: 1.0,
        grading_y: 1.0,
        grade_toward: None,
    }
}

pub(super) fn quarter(n: usize, grading: f64, quadrant: &str) -> QuarterDisc {
    QuarterDisc {
        center: [0.5, 2.0],
        radius: 8.0,
        n,
        grading,
        quadrant: quadrant.into(),
        refine: 0,
    }
}

pub(super) fn cone(nx: usize, ny_body: usize, ny_tip: usize, half: bool) -> ConicalBar {
    ConicalBar {
        width: 0.02,
        length: 0.1,
        tip_length: 0.015,
        nx,
        ny_body,
        ny_tip,
        half,
    }
}

pub(super) fn round(nx: usize, ny_body: usize, half: bool) -> RoundBar {
    RoundBar {
        width: 0.02,
        length: 0.06,
        nx,
        ny_body,
        half,
    }
}
