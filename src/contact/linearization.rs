//! The exact derivatives of a node-to-segment gap, for Newton's iteration.
//!
//! The gap of a slave against a deformable master (`ContactPair::gap`) is
//! ```text
//! g = (x_s - p) . n,   p = (1 - xi) x_a + xi x_b,   xi = (x_s - x_a) . (x_b - x_a) / l^2,
//! n = m / |m|,         m = (1 - xi) N_a + xi N_b,   N_a = sum over the master edges at a of
//!                                                          their outward unit normals
//! ```
//! and its constraint row is C = [n, -(1 - xi) n, -xi n] on (s, a, b). C is not dg/dx: it
//! leaves out how n and xi move with the nodes, and the contact force tau C^T turns with the
//! master. Newton's iteration with C alone converges linearly (by about 1e-2 an iteration
//! on round_bar, where the rows against a rigid wall converge quadratically). Here both
//! derivatives are formed exactly, by forward-mode dual numbers through the same formulas:
//! the gradient dg/dx for the linearized constraint and dC/dx for the force's stiffness
//! tau dC/dx (see `analysis::steppers::newton::exact_solve`).

use super::geometry::{ContactPair, Gap, Master};
use nalgebra::{Const, SVector};
use num_dual::{DualNum, DualVec, jacobian};

/// Local nodes a linearization can span: the slave, the segment's two nodes and the far
/// nodes of the master edges at either end.
const NODES: usize = 6;
const DOFS: usize = 2 * NODES;

/// dg/dx and dC/dx of one slave's normal row, over the local nodes' DOFs.
pub struct Linearization {
    /// Global node ids of the local nodes: the DOFs are 2 node (x) and 2 node + 1 (y).
    pub nodes: Vec<usize>,
    pub gradient: SVector<f64, DOFS>,
    /// `row_jacobian[(p, q)]` = d C_p / d x_q over the local DOFs.
    pub row_jacobian: nalgebra::SMatrix<f64, DOFS, DOFS>,
}

impl Linearization {
    /// (global DOF, local DOF index) of every local DOF.
    pub fn dofs(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.nodes
            .iter()
            .enumerate()
            .flat_map(|(i, n)| [(2 * n, 2 * i), (2 * n + 1, 2 * i + 1)])
    }
}

/// The segment's geometry in local node indices: edges at a and at b, and xi where the
/// projection is clamped to an end (held fixed there, as the gap holds it).
struct Local {
    edges_a: Vec<[usize; 2]>,
    edges_b: Vec<[usize; 2]>,
    clamped_xi: Option<f64>,
}

type D = DualVec<f64, Const<DOFS>>;

fn outward<T: DualNum<Primitive = f64> + Copy>(p: [T; 2], q: [T; 2]) -> [T; 2] {
    let d = [q[0] - p[0], q[1] - p[1]];
    let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
    [d[1] / l, -d[0] / l]
}

/// [g, C_0 .. C_DOFS-1] at the local positions `x` (slave 0, a 1, b 2), as `ContactPair::gap`
/// and `Gap::row` form them.
fn gap_and_row<T: DualNum<Primitive = f64> + Copy>(
    x: &SVector<T, DOFS>,
    local: &Local,
) -> SVector<T, { DOFS + 1 }> {
    let at = |i: usize| [x[2 * i], x[2 * i + 1]];
    let (xs, xa, xb) = (at(0), at(1), at(2));
    let ab = [xb[0] - xa[0], xb[1] - xa[1]];
    let xi = match local.clamped_xi {
        Some(xi) => T::from(xi),
        None => {
            ((xs[0] - xa[0]) * ab[0] + (xs[1] - xa[1]) * ab[1]) / (ab[0] * ab[0] + ab[1] * ab[1])
        }
    };
    let nodal = |edges: &[[usize; 2]]| {
        edges.iter().fold([T::from(0.0); 2], |sum, [p, q]| {
            let n = outward(at(*p), at(*q));
            [sum[0] + n[0], sum[1] + n[1]]
        })
    };
    let (na, nb) = (nodal(&local.edges_a), nodal(&local.edges_b));
    let one = T::from(1.0);
    let raw = [
        (one - xi) * na[0] + xi * nb[0],
        (one - xi) * na[1] + xi * nb[1],
    ];
    let l = (raw[0] * raw[0] + raw[1] * raw[1]).sqrt();
    let normal = if l.re() > 0.0 {
        [raw[0] / l, raw[1] / l]
    } else {
        outward(xa, xb)
    };
    let p = [
        (one - xi) * xa[0] + xi * xb[0],
        (one - xi) * xa[1] + xi * xb[1],
    ];
    let mut out = SVector::<T, { DOFS + 1 }>::from_element(T::from(0.0));
    out[0] = (xs[0] - p[0]) * normal[0] + (xs[1] - p[1]) * normal[1];
    for (node, weight) in [(0, one), (1, -(one - xi)), (2, -xi)] {
        out[1 + 2 * node] = weight * normal[0];
        out[2 + 2 * node] = weight * normal[1];
    }
    out
}

/// The master edges at node `end`, in local node indices (new nodes appended to `nodes`).
fn local_edges(edges: &[[usize; 2]], end: usize, nodes: &mut Vec<usize>) -> Vec<[usize; 2]> {
    let mut index = |node: usize| match nodes.iter().position(|n| *n == node) {
        Some(i) => i,
        None => {
            nodes.push(node);
            nodes.len() - 1
        }
    };
    edges
        .iter()
        .filter(|e| e.contains(&end))
        .map(|[p, q]| [index(*p), index(*q)])
        .collect()
}

/// The linearization of row `slave` of pair `pair` among `pairs` as Newton's rows take it:
/// [`ContactPair::linearization`], except for either pass of a two-pass contact, whose rows
/// keep the constraint row for dg/dx: with the exact terms the two passes' near-coincident
/// rows make the active set cycle (round_bar two-pass: 14 step cuts and 2.3 % more plastic
/// work than the swapped roles, against 4 cuts and 0.6 % with the row).
pub fn row_linearization(
    pairs: &[ContactPair],
    pair: usize,
    slave: usize,
    gap: &Gap,
    x: &dyn Fn(usize) -> [f64; 2],
) -> Option<Linearization> {
    if in_two_pass(pairs, pair) {
        return None;
    }
    pairs[pair].linearization(slave, gap, x)
}

/// Whether pair `pair` is either pass of a two-pass contact.
fn in_two_pass(pairs: &[ContactPair], pair: usize) -> bool {
    pairs[pair].covered.is_some()
        || pairs
            .iter()
            .any(|p| p.covered.as_ref().is_some_and(|c| c.pair == pair))
}

impl ContactPair {
    /// The exact linearization of slave `slave`'s row at positions `x`, for a deformable
    /// master (None for obstacles and node-to-node masters, whose rows are already dg/dx, and
    /// where the master edges at the segment span more nodes than a linearization holds; and for mortar
    /// gaps).
    pub fn linearization(
        &self,
        slave: usize,
        gap: &Gap,
        x: &dyn Fn(usize) -> [f64; 2],
    ) -> Option<Linearization> {
        let Master::Segments { edges, .. } = &self.master else {
            return None;
        };
        if self.joint_conditions() {
            // a weighted gap, or a held master node's: its row is the frozen-geometry
            // derivative
            return None;
        }
        let [(a, _), (b, xi)] = gap.masters[..] else {
            return None;
        };
        let mut nodes = vec![slave, a, b];
        let edges_a = local_edges(edges, a, &mut nodes);
        let edges_b = local_edges(edges, b, &mut nodes);
        if nodes.len() > NODES || nodes[1..].contains(&slave) {
            return None;
        }
        let local = Local {
            edges_a,
            edges_b,
            clamped_xi: (xi <= 0.0 || xi >= 1.0).then_some(xi),
        };
        let mut position = SVector::<f64, DOFS>::zeros();
        for (i, node) in nodes.iter().enumerate() {
            let p = x(*node);
            position[2 * i] = p[0];
            position[2 * i + 1] = p[1];
        }
        // unused local nodes sit at the slave's position: they enter no formula
        for i in nodes.len()..NODES {
            position[2 * i] = position[0];
            position[2 * i + 1] = position[1];
        }
        let (_, derivative) = jacobian(|x: SVector<D, DOFS>| gap_and_row(&x, &local), &position);
        Some(Linearization {
            nodes,
            gradient: derivative.row(0).transpose(),
            row_jacobian: derivative.fixed_rows::<DOFS>(1).into_owned(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::geometry::tests::slave_node_0;
    use super::*;

    /// A slave over a dented master (five nodes, no two edges collinear, so the interpolated
    /// normal differs from the segment's): the dual-number gradient of the gap and Jacobian
    /// of the row against central differences of `ContactPair::gap` and `Gap::row`
    /// themselves. Step 1e-6: truncation ~1e-12 and round-off ~1e-10 on entries of order
    /// 1 to 10, so 1e-7 separates a right derivative from any missing term (the terms the
    /// row leaves out are of order 0.1 here).
    #[test]
    fn derivatives_match_central_differences_of_the_gap() {
        let coords: Vec<[f64; 2]> = vec![
            [1.6, 0.081],
            [0.0, 0.0],
            [1.0, 0.1],
            [2.0, 0.05],
            [3.0, 0.2],
            [4.0, 0.0],
            [4.0, -1.0],
            [0.0, -1.0],
        ];
        // edges run right to left: the solid (below) on their left
        let edges = vec![[2, 1], [3, 2], [4, 3], [5, 4]];
        let mut boundary = edges.clone();
        boundary.extend([[1, 7], [7, 6], [6, 5]]);
        let pair = slave_node_0(Master::Segments {
            body: 1,
            edges,
            boundary,
        });
        let at = |c: &[[f64; 2]]| {
            let c = c.to_vec();
            move |n: usize| c[n]
        };
        let gap = pair.gap(0, &at(&coords)).unwrap();
        let l = pair.linearization(0, &gap, &at(&coords)).unwrap();
        let rows_of = |c: &[[f64; 2]]| {
            let g = pair.gap(0, &at(c)).unwrap();
            assert_eq!(g.masters.len(), 2);
            (g.gap, g.row(0))
        };
        let h = 1e-6;
        let mut largest_missing: f64 = 0.0;
        for (dof, local) in l.dofs() {
            let shifted = |s: f64| {
                let mut c = coords.clone();
                c[dof / 2][dof % 2] += s;
                rows_of(&c)
            };
            let ((gp, rp), (gm, rm)) = (shifted(h), shifted(-h));
            approx::assert_abs_diff_eq!(l.gradient[local], (gp - gm) / (2.0 * h), epsilon = 1e-7);
            let row_entry: f64 = gap
                .row(0)
                .iter()
                .filter(|(d, _)| *d == dof)
                .map(|(_, c)| c)
                .sum();
            largest_missing = largest_missing.max((l.gradient[local] - row_entry).abs());
            for ((row_dof, cp), (_, cm)) in rp.iter().zip(&rm) {
                let p_local = l.dofs().find(|(d, _)| d == row_dof).unwrap().1;
                approx::assert_abs_diff_eq!(
                    l.row_jacobian[(p_local, local)],
                    (cp - cm) / (2.0 * h),
                    epsilon = 1e-7
                );
            }
        }
        // the check can tell: the row alone misses a term of this size
        assert!(largest_missing > 1e-3, "{largest_missing}");
    }
}
