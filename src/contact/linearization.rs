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
//!
//! The weighted gap of a mortar pair (`mortar`) is linearized the same way: its mortar
//! integrals, its overlaps and its averaged normal all move with the nodes, and the dual
//! numbers run through the same function the run's gaps come from (`mortar::weighted`).
//! Either linearization also gives dT/dx of the tangential row T (t = (-n_y, n_x) with the
//! same weights), for the stiffness of a sliding friction force mu tau T^T and a sticking
//! one's lambda T^T.

use super::geometry::{ContactPair, Gap, Master};
use super::mortar::{MortarSurface, weighted};
use nalgebra::{Const, DMatrix, DVector, SVector};
use num_dual::{DualNum, DualVec, jacobian};

/// Local nodes a linearization can span: the slave, the segment's two nodes and the far
/// nodes of the master edges at either end.
const NODES: usize = 6;
const DOFS: usize = 2 * NODES;

/// dg/dx, dC/dx and dT/dx of one slave's rows, over the local nodes' DOFs.
pub struct Linearization {
    /// Global node ids of the local nodes: the DOFs are 2 node (x) and 2 node + 1 (y).
    pub nodes: Vec<usize>,
    pub gradient: DVector<f64>,
    /// `row_jacobian[(p, q)]` = d C_p / d x_q over the local DOFs.
    pub row_jacobian: DMatrix<f64>,
    /// `tangent_jacobian[(p, q)]` = d T_p / d x_q over the local DOFs.
    pub tangent_jacobian: DMatrix<f64>,
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

/// [g, C_0 .. C_DOFS-1, T_0 .. T_DOFS-1] at the local positions `x` (slave 0, a 1, b 2), as
/// `ContactPair::gap`, `Gap::row` and `Gap::tangent_row` form them.
fn gap_and_row<T: DualNum<Primitive = f64> + Copy>(
    x: &SVector<T, DOFS>,
    local: &Local,
) -> SVector<T, { 2 * DOFS + 1 }> {
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
    let mut out = SVector::<T, { 2 * DOFS + 1 }>::from_element(T::from(0.0));
    out[0] = (xs[0] - p[0]) * normal[0] + (xs[1] - p[1]) * normal[1];
    for (node, weight) in [(0, one), (1, -(one - xi)), (2, -xi)] {
        out[1 + 2 * node] = weight * normal[0];
        out[2 + 2 * node] = weight * normal[1];
        out[1 + DOFS + 2 * node] = -(weight * normal[1]);
        out[2 + DOFS + 2 * node] = weight * normal[0];
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
    /// master: node-to-segment or mortar (None for obstacles and node-to-node masters, whose
    /// rows are already dg/dx, for the held master nodes of a hold pair, and where the gap
    /// spans more nodes than a linearization holds).
    pub fn linearization(
        &self,
        slave: usize,
        gap: &Gap,
        x: &dyn Fn(usize) -> [f64; 2],
    ) -> Option<Linearization> {
        let Master::Segments { edges, .. } = &self.master else {
            return None;
        };
        if self.is_hold() {
            // a held master node's gap: its row is the frozen-geometry derivative
            return None;
        }
        if let Some((surface, edges)) = self.mortar() {
            return mortar_linearization(surface, edges, slave, x);
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
            gradient: DVector::from_iterator(DOFS, derivative.row(0).iter().copied()),
            row_jacobian: DMatrix::from_fn(DOFS, DOFS, |p, q| derivative[(1 + p, q)]),
            tangent_jacobian: DMatrix::from_fn(DOFS, DOFS, |p, q| derivative[(1 + DOFS + p, q)]),
        })
    }
}

/// Local nodes a mortar linearization can span: the slave, its two neighbours and the
/// master nodes across its segments (a master four times finer puts about ten there).
const MORTAR_NODES: usize = 20;
const MORTAR_DOFS: usize = 2 * MORTAR_NODES;
type MortarDual = DualVec<f64, Const<MORTAR_DOFS>>;

/// The exact linearization of the weighted gap of slave node `slave` of the mortar surface
/// `surface` against the master edges `master` at positions `x`: dg/dx, dC/dx and dT/dx
/// through the mortar integrals, the overlaps, the dual basis and the averaged normal. None
/// where the slave faces no master, or where its gap spans more nodes than a linearization
/// holds (its row then stays the frozen-geometry derivative).
pub fn mortar_linearization(
    surface: &MortarSurface,
    master: &[[usize; 2]],
    slave: usize,
    x: &dyn Fn(usize) -> [f64; 2],
) -> Option<Linearization> {
    let plain = weighted(surface, master, slave, x)?;
    let mut nodes = vec![slave];
    let neighbours = surface
        .edges
        .iter()
        .filter(|e| e.contains(&slave))
        .flatten();
    for n in neighbours.chain(plain.masters.iter().map(|(m, _)| m)) {
        if !nodes.contains(n) {
            nodes.push(*n);
        }
    }
    if nodes.len() > MORTAR_NODES {
        return None;
    }
    let local = |node: usize| nodes.iter().position(|n| *n == node);
    let mut position = SVector::<f64, MORTAR_DOFS>::zeros();
    for i in 0..MORTAR_NODES {
        // unused local nodes sit at the slave's position: they enter no formula
        let p = x(*nodes.get(i).unwrap_or(&slave));
        position[2 * i] = p[0];
        position[2 * i + 1] = p[1];
    }
    // a master segment whose overlap with the slave's is degenerate (zero length) may enter
    // the dual numbers' gap and not the plain one's (their divisions round differently): with
    // a weight of round-off it is left out, as a constant; with more, the gap is not the
    // plain one's and the row stays frozen
    let strange = std::cell::Cell::new(false);
    let outputs = |y: SVector<MortarDual, MORTAR_DOFS>| {
        let at = |node: usize| match local(node) {
            Some(i) => [y[2 * i], y[2 * i + 1]],
            None => {
                let p = x(node);
                [MortarDual::from(p[0]), MortarDual::from(p[1])]
            }
        };
        let mut out = nalgebra::DVector::<MortarDual>::from_element(
            1 + 2 * MORTAR_DOFS,
            MortarDual::from(0.0),
        );
        if let Some(w) = weighted(surface, master, slave, &at) {
            out[0] = w.gap;
            let n = w.normal;
            let t = [-n[1], n[0]];
            let slave_side = std::iter::once((slave, w.share));
            let master_side = w.masters.iter().map(|(m, c)| (*m, -*c));
            for (node, c) in slave_side.chain(master_side) {
                let Some(i) = local(node) else {
                    if c.re.abs() > 1e-12 * w.share.re.abs() {
                        strange.set(true);
                    }
                    continue;
                };
                for k in 0..2 {
                    out[1 + 2 * i + k] += c * n[k];
                    out[1 + MORTAR_DOFS + 2 * i + k] += c * t[k];
                }
            }
        }
        out
    };
    let (_, derivative) = jacobian(|y: SVector<MortarDual, MORTAR_DOFS>| outputs(y), &position);
    if strange.get() {
        return None;
    }
    let dofs = 2 * nodes.len();
    Some(Linearization {
        gradient: DVector::from_fn(dofs, |q, _| derivative[(0, q)]),
        row_jacobian: DMatrix::from_fn(dofs, dofs, |p, q| derivative[(1 + p, q)]),
        tangent_jacobian: DMatrix::from_fn(dofs, dofs, |p, q| derivative[(1 + MORTAR_DOFS + p, q)]),
        nodes,
    })
}

#[cfg(test)]
mod tests {
    use super::super::geometry::tests::slave_node_0;
    use super::*;
    use crate::contact::MortarSurface;

    /// Goal: the mortar linearization is the derivative of the weighted gap the run uses:
    /// dg/dx, dC/dx and dT/dx against central differences of `weighted_gap`, its `Gap::row`
    /// and `Gap::tangent_row`. Setup: an axisymmetric slave surface of three nodes (2 pi r
    /// weights, the dual basis per segment) over a curved master twice as fine, tilted, so
    /// that overlaps, weights and the averaged normal all move with the nodes; the middle
    /// slave node, whose support spans both segments. Reference: the difference quotients,
    /// step 1e-7 on coordinates of order 1 (truncation ~1e-14, round-off ~1e-9 on entries
    /// of order 1), so 1e-6 separates a right derivative from a missing term (the frozen
    /// row misses terms of order 1e-2 in dg/dx, asserted above 1e-3).
    #[test]
    fn mortar_derivatives_match_central_differences_of_the_weighted_gap() {
        // the slave body lies above its surface: its edges run left to right (solid on their
        // left, above)
        let coords: Vec<[f64; 2]> = vec![
            [0.3, 0.02],
            [1.3, 0.05],
            [2.2, 0.11],
            // master surface below, edges right to left (solid below), twice as fine
            [2.6, 0.07],
            [2.05, 0.06],
            [1.55, 0.035],
            [1.05, 0.02],
            [0.55, 0.0],
            [0.05, -0.03],
        ];
        let surface = MortarSurface {
            edges: vec![[0, 1], [1, 2]],
            axisymmetric: true,
            hold_master_nodes: false,
        };
        let master = vec![[3, 4], [4, 5], [5, 6], [6, 7], [7, 8]];
        let at = |c: &[[f64; 2]]| {
            let c = c.to_vec();
            move |n: usize| c[n]
        };
        let slave = 1;
        let plain = |c: &[[f64; 2]]| {
            let g = super::super::mortar::weighted_gap(&surface, &master, slave, &at(c)).unwrap();
            (g.gap, g.row(slave), g.tangent_row(slave))
        };
        let l = mortar_linearization(&surface, &master, slave, &at(&coords)).unwrap();
        let (_, row, _) = plain(&coords);
        let entry = |r: &[(usize, f64)], dof: usize| -> f64 {
            r.iter().filter(|(d, _)| *d == dof).map(|(_, c)| c).sum()
        };
        let h = 1e-7;
        let mut largest_missing: f64 = 0.0;
        for (dof, local) in l.dofs() {
            let shifted = |s: f64| {
                let mut c = coords.clone();
                c[dof / 2][dof % 2] += s;
                plain(&c)
            };
            let ((gp, rp, tp), (gm, rm, tm)) = (shifted(h), shifted(-h));
            approx::assert_abs_diff_eq!(l.gradient[local], (gp - gm) / (2.0 * h), epsilon = 1e-6);
            largest_missing = largest_missing.max((l.gradient[local] - entry(&row, dof)).abs());
            for (p_dof, p_local) in l.dofs() {
                let fd = (entry(&rp, p_dof) - entry(&rm, p_dof)) / (2.0 * h);
                approx::assert_abs_diff_eq!(l.row_jacobian[(p_local, local)], fd, epsilon = 1e-6);
                let fd = (entry(&tp, p_dof) - entry(&tm, p_dof)) / (2.0 * h);
                approx::assert_abs_diff_eq!(
                    l.tangent_jacobian[(p_local, local)],
                    fd,
                    epsilon = 1e-6
                );
            }
        }
        // the check can tell: the frozen row misses a term of this size in dg/dx
        assert!(largest_missing > 1e-3, "{largest_missing}");
    }

    /// A slave over a dented master (five nodes, no two edges collinear, so the interpolated
    /// normal differs from the segment's): the dual-number gradient of the gap and Jacobians
    /// of the normal and tangential rows against central differences of `ContactPair::gap`,
    /// `Gap::row` and `Gap::tangent_row` themselves. Step 1e-6: truncation ~1e-12 and round-off ~1e-10 on entries of order
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
            (g.gap, g.row(0), g.tangent_row(0))
        };
        let h = 1e-6;
        let mut largest_missing: f64 = 0.0;
        for (dof, local) in l.dofs() {
            let shifted = |s: f64| {
                let mut c = coords.clone();
                c[dof / 2][dof % 2] += s;
                rows_of(&c)
            };
            let ((gp, rp, tp), (gm, rm, tm)) = (shifted(h), shifted(-h));
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
            for ((row_dof, cp), (_, cm)) in tp.iter().zip(&tm) {
                let p_local = l.dofs().find(|(d, _)| d == row_dof).unwrap().1;
                approx::assert_abs_diff_eq!(
                    l.tangent_jacobian[(p_local, local)],
                    (cp - cm) / (2.0 * h),
                    epsilon = 1e-7
                );
            }
        }
        // the check can tell: the row alone misses a term of this size
        assert!(largest_missing > 1e-3, "{largest_missing}");
    }
}
