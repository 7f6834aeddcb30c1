//! Meshes: nodes, cells and named node / edge / element sets.
//!
//! Legend
//! ```text
//! nodes          node coordinates [x, y] (axisymmetric: [r, z]; rods: any 2D line)
//! cells          Quad4 (counter-clockwise node order, det J > 0) or Rod2 connectivity
//! node_sets      name -> sorted, unique node ids
//! edge_sets      name -> boundary edges [a, b], oriented so the body lies on the left
//!                of a -> b (counter-clockwise around the body)
//! element_sets   name -> element ids
//! ```
//! Every generator and the file readers (Gmsh, VTK) fill `element_sets["all"]`, and every
//! edge set also appears as a node set of the same name (the union of its edge nodes). The
//! readers share the turning of a file's tagged cells into sets (tagged.rs) and give quad
//! meshes the edge set `boundary`.

pub mod generate;
pub mod gmsh;
pub mod plane;
mod tagged;
pub mod vtk;

use rayon::prelude::*;
use std::collections::{BTreeMap, BTreeSet};

pub use generate::MeshSpec;

/// Cell connectivity of a body: one element kind per body.
#[derive(Debug, Clone, PartialEq)]
pub enum Cells {
    /// Four-node quadrilaterals, nodes counter-clockwise.
    Quad4(Vec<[usize; 4]>),
    /// Two-node rods (bars).
    Rod2(Vec<[usize; 2]>),
}

impl Cells {
    pub fn len(&self) -> usize {
        match self {
            Cells::Quad4(c) => c.len(),
            Cells::Rod2(c) => c.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Nodes of each element (4 or 2), whether or not there is an element.
    pub fn nodes_per_cell(&self) -> usize {
        match self {
            Cells::Quad4(_) => 4,
            Cells::Rod2(_) => 2,
        }
    }

    /// Node ids of element `e`.
    pub fn nodes_of(&self, e: usize) -> &[usize] {
        match self {
            Cells::Quad4(c) => &c[e],
            Cells::Rod2(c) => &c[e],
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    pub nodes: Vec<[f64; 2]>,
    pub cells: Cells,
    pub node_sets: BTreeMap<String, Vec<usize>>,
    pub edge_sets: BTreeMap<String, Vec<[usize; 2]>>,
    pub element_sets: BTreeMap<String, Vec<usize>>,
}

/// Errors from building or reading a mesh. `Display` names the file and line where there is one.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("mesh parameter `{key}`: {reason}")]
    Parameter { key: String, reason: String },
    #[error("cannot read mesh file {path}: {reason}")]
    Io { path: String, reason: String },
    #[error("mesh file {path}, line {line}: {reason}")]
    Parse {
        path: String,
        line: usize,
        reason: String,
    },
    #[error("mesh file {path}: {reason}")]
    Content { path: String, reason: String },
}

impl Mesh {
    /// The side lengths of element `e`: a quad's four sides in node order, a rod's length.
    pub fn edge_lengths(&self, e: usize) -> impl Iterator<Item = f64> + '_ {
        let corners = self.cells.nodes_of(e);
        let sides = match self.cells {
            Cells::Quad4(_) => 4,
            Cells::Rod2(_) => 1,
        };
        (0..sides).map(move |a| {
            let (p, q) = (
                self.nodes[corners[a]],
                self.nodes[corners[(a + 1) % corners.len()]],
            );
            (q[0] - p[0]).hypot(q[1] - p[1])
        })
    }

    /// A mesh with the given nodes and cells and only the `all` element set.
    pub fn new(nodes: Vec<[f64; 2]>, cells: Cells) -> Mesh {
        let all = (0..cells.len()).collect();
        let mut element_sets = BTreeMap::new();
        element_sets.insert("all".to_string(), all);
        Mesh {
            nodes,
            cells,
            node_sets: BTreeMap::new(),
            edge_sets: BTreeMap::new(),
            element_sets,
        }
    }

    /// Adds an edge set and the node set of the same name (its nodes, sorted and unique).
    pub fn add_edge_set(&mut self, name: &str, edges: Vec<[usize; 2]>) {
        let mut nodes: Vec<usize> = edges.iter().flat_map(|e| e.iter().copied()).collect();
        nodes.sort_unstable();
        nodes.dedup();
        self.node_sets.insert(name.to_string(), nodes);
        self.edge_sets.insert(name.to_string(), edges);
    }

    /// Adds a node set (sorted and deduplicated).
    pub fn add_node_set(&mut self, name: &str, mut nodes: Vec<usize>) {
        nodes.sort_unstable();
        nodes.dedup();
        self.node_sets.insert(name.to_string(), nodes);
    }

    /// Boundary edges of a Quad4 mesh (edges used by one element), oriented counter-clockwise
    /// around the body. Empty for rods.
    pub fn boundary_edges(&self) -> Vec<[usize; 2]> {
        let Cells::Quad4(quads) = &self.cells else {
            return Vec::new();
        };
        // every element edge under its sorted node pair; an edge of one element is the
        // boundary's (in the order of the pairs, as a map over them gave it)
        let mut edges: Vec<((usize, usize), [usize; 2])> = quads
            .iter()
            .flat_map(|q| {
                (0..4).map(move |k| {
                    let edge = [q[k], q[(k + 1) % 4]];
                    ((edge[0].min(edge[1]), edge[0].max(edge[1])), edge)
                })
            })
            .collect();
        edges.par_sort_unstable_by_key(|(key, _)| *key);
        edges
            .chunk_by(|a, b| a.0 == b.0)
            .filter(|run| run.len() == 1)
            .map(|run| run[0].1)
            .collect()
    }
}

/// Edges head to tail: open chains first (by first node), then closed loops.
pub fn chain_order(edges: Vec<[usize; 2]>) -> Vec<[usize; 2]> {
    let mut leaving: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (k, e) in edges.iter().enumerate() {
        leaving.entry(e[0]).or_default().push(k);
    }
    let ends: BTreeSet<usize> = edges.iter().map(|e| e[1]).collect();
    let mut heads: Vec<usize> = edges
        .iter()
        .map(|e| e[0])
        .filter(|n| !ends.contains(n))
        .collect();
    heads.sort_unstable();
    heads.extend(edges.iter().map(|e| e[0]));

    let mut used = vec![false; edges.len()];
    let mut ordered = Vec::with_capacity(edges.len());
    for head in heads {
        let mut node = head;
        while let Some(&k) = leaving
            .get(&node)
            .and_then(|ks| ks.iter().find(|&&k| !used[k]))
        {
            used[k] = true;
            ordered.push(edges[k]);
            node = edges[k][1];
        }
    }
    ordered
}
