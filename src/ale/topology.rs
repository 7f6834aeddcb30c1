//! The fixed topology of a Quad4 mesh as the smoother and the remap read it: the interior edges
//! with the elements on either side, each element's neighbourhood (the elements sharing a node
//! with it), the elements at each node and the boundary's chain of nodes. Built once per run:
//! an arbitrary Lagrangian-Eulerian step moves the nodes, never the connectivity.

use std::collections::HashMap;

/// An edge between two elements: from node `a` to node `b` counter-clockwise in `left`
/// (so clockwise in `right`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    pub left: usize,
    pub right: usize,
    pub a: usize,
    pub b: usize,
}

/// The connectivity of one Quad4 mesh (local node numbers, counter-clockwise cells).
#[derive(Debug, Clone)]
pub struct Topology {
    pub cells: Vec<[usize; 4]>,
    pub nodes: usize,
    /// The edges with an element on either side.
    pub edges: Vec<Edge>,
    /// Per element, its interior edges (indices into `edges`).
    pub edges_of: Vec<Vec<usize>>,
    /// Per element, the other elements that share a node with it (ascending).
    pub neighbourhood: Vec<Vec<usize>>,
    /// Per node, the elements at it (ascending).
    pub cells_at: Vec<Vec<usize>>,
    /// Per node, the nodes joined to it by an element edge (ascending).
    pub joined: Vec<Vec<usize>>,
    /// Per boundary node with exactly two boundary edges, its boundary neighbours (the one
    /// before it and the one after it, the body on the left); None inside and at a pinch.
    pub boundary: Vec<Option<[usize; 2]>>,
    /// Whether a node lies on the boundary (including pinches).
    pub on_boundary: Vec<bool>,
}

impl Topology {
    pub fn new(cells: &[[usize; 4]], nodes: usize) -> Topology {
        let mut owner: HashMap<(usize, usize), (usize, usize, usize)> = HashMap::new();
        let mut edges = Vec::new();
        for (e, cell) in cells.iter().enumerate() {
            for k in 0..4 {
                let (a, b) = (cell[k], cell[(k + 1) % 4]);
                let key = (a.min(b), a.max(b));
                match owner.remove(&key) {
                    Some((left, la, lb)) => edges.push(Edge {
                        left,
                        right: e,
                        a: la,
                        b: lb,
                    }),
                    None => {
                        owner.insert(key, (e, a, b));
                    }
                }
            }
        }
        edges.sort_by_key(|edge| (edge.left, edge.right));
        let mut edges_of = vec![Vec::new(); cells.len()];
        for (i, edge) in edges.iter().enumerate() {
            edges_of[edge.left].push(i);
            edges_of[edge.right].push(i);
        }
        let mut cells_at = vec![Vec::new(); nodes];
        let mut joined = vec![Vec::new(); nodes];
        for (e, cell) in cells.iter().enumerate() {
            for k in 0..4 {
                cells_at[cell[k]].push(e);
                joined[cell[k]].push(cell[(k + 1) % 4]);
                joined[cell[k]].push(cell[(k + 3) % 4]);
            }
        }
        for list in joined.iter_mut().chain(cells_at.iter_mut()) {
            list.sort_unstable();
            list.dedup();
        }
        let neighbourhood = cells
            .iter()
            .enumerate()
            .map(|(e, cell)| {
                let mut near: Vec<usize> = cell
                    .iter()
                    .flat_map(|n| cells_at[*n].iter().copied())
                    .filter(|f| *f != e)
                    .collect();
                near.sort_unstable();
                near.dedup();
                near
            })
            .collect();
        // what is left in `owner` are the boundary edges, a -> b with the body on the left
        let mut after: Vec<Vec<usize>> = vec![Vec::new(); nodes];
        let mut before: Vec<Vec<usize>> = vec![Vec::new(); nodes];
        for (_, a, b) in owner.values() {
            after[*a].push(*b);
            before[*b].push(*a);
        }
        let on_boundary: Vec<bool> = (0..nodes).map(|n| !after[n].is_empty()).collect();
        let boundary = (0..nodes)
            .map(|n| match (before[n].as_slice(), after[n].as_slice()) {
                ([p], [q]) => Some([*p, *q]),
                _ => None,
            })
            .collect();
        Topology {
            cells: cells.to_vec(),
            nodes,
            edges,
            edges_of,
            neighbourhood,
            cells_at,
            joined,
            boundary,
            on_boundary,
        }
    }

    /// The positions of element `e`'s nodes in `x`.
    pub fn corners(&self, x: &[[f64; 2]], e: usize) -> [[f64; 2]; 4] {
        self.cells[e].map(|n| x[n])
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A structured nx x ny grid of unit cells (nodes row by row, cells counter-clockwise).
    pub(crate) fn grid(nx: usize, ny: usize) -> (Vec<[usize; 4]>, Vec<[f64; 2]>) {
        let node = |i: usize, j: usize| j * (nx + 1) + i;
        let cells = (0..ny)
            .flat_map(|j| {
                (0..nx).map(move |i| {
                    [
                        node(i, j),
                        node(i + 1, j),
                        node(i + 1, j + 1),
                        node(i, j + 1),
                    ]
                })
            })
            .collect();
        let x = (0..=ny)
            .flat_map(|j| (0..=nx).map(move |i| [i as f64, j as f64]))
            .collect();
        (cells, x)
    }

    /// A 3 x 2 grid: 7 interior edges (2 per row of 3, 3 between the rows), 10 boundary nodes
    /// each with its two boundary neighbours, the two middle nodes inside.
    #[test]
    fn a_grid_has_its_interior_edges_and_boundary_chain() {
        let (cells, x) = grid(3, 2);
        let t = Topology::new(&cells, x.len());
        assert_eq!(t.edges.len(), 7);
        for edge in &t.edges {
            let left = &t.cells[edge.left];
            let k = left.iter().position(|n| *n == edge.a).unwrap();
            assert_eq!(
                left[(k + 1) % 4],
                edge.b,
                "a -> b runs counter-clockwise in left"
            );
        }
        let inside: Vec<usize> = (0..x.len()).filter(|n| !t.on_boundary[*n]).collect();
        assert_eq!(inside, vec![5, 6]);
        // node 1 on the bottom edge: before it node 0, after it node 2 (body on the left)
        assert_eq!(t.boundary[1], Some([0, 2]));
        assert_eq!(t.neighbourhood[0], vec![1, 3, 4]);
        assert_eq!(t.cells_at[5], vec![0, 1, 3, 4]);
    }
}
