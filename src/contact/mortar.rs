//! Segment-to-segment (dual mortar) contact in 2D: the gap of a slave node is the mean of
//! the gap over its part of the slave surface, weighted by its dual shape function and
//! measured against whatever master segments lie across it (Puso & Laursen 2004; Yang,
//! Laursen & Meng 2005 for 2D large sliding; the dual basis of Wohlmuth 2000 and Popp, Gee &
//! Wall 2009; docs/theory.md "Mortar contact").
//!
//! Legend
//! ```text
//! s_a, s_b     a slave segment (solid on its left), eta in [0, 1] along it, length L
//! N_j(eta)     the slave node j's linear shape function on its segments
//! Phi_j(eta)   its dual shape function: int Phi_j N_k dA = delta_jk int N_j dA per segment
//! p, q         a master segment across it, xi in [0, 1] along it, N^_p = 1 - xi, N^_q = xi
//! dA           ds (plane), 2 pi r ds (axisymmetric, r at the slave point)
//! D_j          int N_j dA over j's whole support (= int Phi_j N_j dA)
//! M_jm         int Phi_j N^_m dA over the overlaps
//! s_j          int Phi_j dA over the overlaps / D_j: the share of j's support a master
//!              covers (1 inside a contact zone; it falls to 0 as a master end slides off)
//! n_j          the mean of the slave's and the master's unit normals at j, pointing from
//!              the master towards the slave (on a plane of symmetry: the plane's normal)
//! g~_j         (s_j x_j - sum_m M_jm / D_j x_m) . n_j
//! ```
//! The row of g~_j is s_j n_j on the slave node and -M_jm / D_j n_j on the master nodes
//! (normal and overlaps frozen): the master weights sum to s_j, so the force tau C^T is equal
//! and opposite on the two surfaces. With the dual basis the slave side is the node alone:
//! a neighbour that opens does not pass its gap on to the node (the standard basis leaves a
//! checkerboard of alternating gaps there), on matching meshes the constraints tie facing
//! nodes, and a master node between two slave nodes enters the gaps of both, where
//! node-to-segment contact would not see it.
//!
//! The overlap of a slave segment and a master segment is found by projecting the master's
//! end points onto the slave segment's line; a slave point at eta meets the master point of
//! the same projection (the overlap maps linearly), so the integrands are cubic in eta and
//! two Gauss points integrate them exactly.

use super::gap::Gap;
use crate::mesh::plane::{dot, outward, sub};
use num_dual::DualNum;
use std::f64::consts::PI;

/// The slave surface of a mortar pair.
#[derive(Debug, Clone, PartialEq)]
pub struct MortarSurface {
    /// The slave body's boundary edges of the slave set (global ids, solid on the left).
    pub edges: Vec<[usize; 2]>,
    /// Surface integrals over the surface of revolution (weight 2 pi r).
    pub axisymmetric: bool,
    /// The explicit correction holds the master nodes too (`master_node_gap`).
    pub hold_master_nodes: bool,
}

/// A master segment lies across a slave segment when their outward normals are opposed
/// within 60 degrees (-n_m . n_s above this). A segment turned further is beside the slave
/// rather than across it: the plate's surface that rises beside a block's flank would
/// otherwise pair with the flank while it still faces up, and the flank's rows, flipping in
/// and out over Newton's iterates, stopped the whole-boundary block on Newmark in its first
/// microseconds (docs/theory.md 8.3a).
const FACING: f64 = 0.5;

/// A slave node is a corner when its two segments' outward normals turn by more than 30
/// degrees (their cosine below this).
const CORNER: f64 = 0.866;

/// The two-point Gauss rule on [0, 1]: positions and weights.
const GAUSS: [(f64, f64); 2] = [
    (0.211_324_865_405_187_1, 0.5),
    (0.788_675_134_594_812_9, 0.5),
];

/// The weighted gap g~ of slave node `slave` of `surface` against the master segments
/// `master` at positions `x`, or None when no master segment faces its segments.
pub fn weighted_gap(
    surface: &MortarSurface,
    master: &[[usize; 2]],
    slave: usize,
    x: &dyn Fn(usize) -> [f64; 2],
) -> Option<Gap> {
    weighted(surface, master, slave, x).map(|w| Gap {
        gap: w.gap,
        normal: w.normal,
        masters: w.masters,
        weight: w.share,
        lever: None,
    })
}

/// A weighted gap in the scalar type `T`: f64, or the dual numbers of its derivatives
/// (`linearization`). The formulas are the same for both, so the derivatives are those of
/// the gap the run uses.
pub(super) struct Weighted<T> {
    pub gap: T,
    pub normal: [T; 2],
    /// The master nodes and their weights M_jm / D_j.
    pub masters: Vec<(usize, T)>,
    /// s_j, the slave node's weight.
    pub share: T,
}

/// The scalars the mortar integrals are written in: f64, and dual numbers over a fixed
/// number of DOFs.
pub(super) trait Scalar: DualNum<Primitive = f64> + Copy {}
impl<T: DualNum<Primitive = f64> + Copy> Scalar for T {}

fn sub_t<T: Scalar>(a: [T; 2], b: [T; 2]) -> [T; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn dot_t<T: Scalar>(a: [T; 2], b: [T; 2]) -> T {
    a[0] * b[0] + a[1] * b[1]
}

/// `plane::outward` in `T`.
fn outward_t<T: Scalar>(a: [T; 2], b: [T; 2]) -> [T; 2] {
    let d = sub_t(b, a);
    let l = dot_t(d, d).sqrt();
    [d[1] / l, -d[0] / l]
}

/// [`weighted_gap`] in the scalar `T` (see [`Weighted`]).
pub(super) fn weighted<T: Scalar>(
    surface: &MortarSurface,
    master: &[[usize; 2]],
    slave: usize,
    x: &dyn Fn(usize) -> [T; 2],
) -> Option<Weighted<T>> {
    let zero = T::from(0.0);
    let (own, count, slave_normal) = slave_side(surface, slave, x)?;
    let own = &own[..count];
    let mut master_normal = [zero; 2];
    let mut masters: Vec<(usize, T)> = Vec::with_capacity(4);
    // D_jj over the whole support, and int Phi_j dA over the overlaps; per own segment, its
    // D part, its int Phi_j dA and its outward normal (`corner`)
    let mut full = zero;
    let mut covered = zero;
    let mut parts = [(zero, zero, [zero; 2]); 2];
    for (k, [a, b]) in own.iter().enumerate() {
        let covered_before = covered;
        let (xa, xb) = (x(*a), x(*b));
        let ab = sub_t(xb, xa);
        let length2 = dot_t(ab, ab);
        if !(length2.re() > 0.0) {
            continue;
        }
        let length = length2.sqrt();
        let area = |eta: T| {
            if surface.axisymmetric {
                (xa[0] + eta * ab[0]) * (2.0 * PI)
            } else {
                T::from(1.0)
            }
        };
        let Some((phi, d)) = dual_shape(length, &area, usize::from(*b == slave)) else {
            continue;
        };
        full += d;
        let facing = outward_t(xa, xb);
        for [p, q] in master {
            let (xp, xq) = (x(*p), x(*q));
            // the master's end points both before the slave segment's start (eta < 0) or
            // both past its end (eta > 1): no overlap, told before a normal and the
            // divisions (the overlap test below finds none either)
            let (along_p, along_q) = (dot_t(sub_t(xp, xa), ab), dot_t(sub_t(xq, xa), ab));
            let (ap, aq, l2) = (along_p.re(), along_q.re(), length2.re());
            if (ap < 0.0 && aq < 0.0) || (ap > l2 && aq > l2) {
                continue;
            }
            let across = outward_t(xp, xq);
            if dot_t(across, facing).re() >= -FACING {
                continue;
            }
            let (eta_p, eta_q) = (along_p / length2, along_q / length2);
            let (low, high) = overlap(eta_p, eta_q);
            if !(high.re() > low.re())
                || !within_reach((xa, ab, facing), [xp, xq], [eta_p, eta_q], [low, high])
            {
                continue;
            }
            let mut overlap = zero;
            for (g, w) in GAUSS {
                let eta = low + (high - low) * g;
                let xi = (eta - eta_p) / (eta_q - eta_p);
                let da = (high - low) * w * length * area(eta);
                let dphi = da * (phi[0] * (-eta + 1.0) + phi[1] * eta);
                covered += dphi;
                overlap += da;
                add(&mut masters, *p, dphi * (-xi + 1.0));
                add(&mut masters, *q, dphi * xi);
            }
            master_normal = [
                master_normal[0] + overlap * across[0],
                master_normal[1] + overlap * across[1],
            ];
        }
        parts[k] = (d, covered - covered_before, facing);
    }
    let (slave_normal, full) = corner(&parts[..count]).unwrap_or((slave_normal, full));
    let share = covered / full;
    if !(share.re() > 0.0) {
        return None;
    }
    masters.iter_mut().for_each(|(_, w)| *w /= full);
    // the mean of the two surfaces' normals: on a plane of symmetry between two mirror
    // bodies it is the plane's normal, where either surface's own would push the other
    // body sideways as the surfaces curl
    let lm = dot_t(master_normal, master_normal).sqrt();
    let both = [
        slave_normal[0] + master_normal[0] / lm,
        slave_normal[1] + master_normal[1] / lm,
    ];
    let lb = dot_t(both, both).sqrt();
    let normal = if lb.re() > 0.0 {
        [both[0] / lb, both[1] / lb]
    } else {
        slave_normal
    };
    let xs = x(slave);
    let xm = masters.iter().fold([zero; 2], |acc, (n, w)| {
        let p = x(*n);
        [acc[0] + *w * p[0], acc[1] + *w * p[1]]
    });
    let gap = dot_t([share * xs[0] - xm[0], share * xs[1] - xm[1]], normal);
    Some(Weighted {
        gap,
        normal,
        masters,
        share,
    })
}

/// The normal and D_j of a corner node from its segments' `parts` (D part, int Phi_j dA over
/// the overlaps, outward normal), or None for a node that is not a corner (one segment, or
/// two turning by less than 30 degrees: its normal and D_j stay the whole support's). At a
/// corner each segment counts in proportion to how much of it a master covers, in full from
/// half its D part on: a face with nothing across it (a block's flank while its bottom
/// strikes) neither tilts the node's normal towards itself nor dilutes its share, so the
/// corner node is the end of the face in contact, as it is when the slave set is that face
/// alone; a face that comes into contact enters gradually.
fn corner<T: Scalar>(parts: &[(T, T, [T; 2])]) -> Option<([T; 2], T)> {
    let [(_, _, n0), (_, _, n1)] = parts else {
        return None;
    };
    if dot_t(*n0, *n1).re() >= CORNER {
        return None;
    }
    let zero = T::from(0.0);
    let mut normal = [zero; 2];
    let mut full = zero;
    for (d, covered, outward) in parts {
        let ratio = *covered / *d * 2.0;
        let w = if ratio.re() >= 1.0 {
            T::from(1.0)
        } else if ratio.re() > 0.0 {
            ratio
        } else {
            continue;
        };
        normal = [normal[0] - w * outward[0], normal[1] - w * outward[1]];
        full += w * *d;
    }
    let l = dot_t(normal, normal).sqrt();
    (l.re() > 0.0).then(|| ([normal[0] / l, normal[1] / l], full))
}

/// The overlap [low, high] of the master's projections `eta_p`, `eta_q` with [0, 1].
fn overlap<T: Scalar>(eta_p: T, eta_q: T) -> (T, T) {
    let (first, last) = if eta_p.re() <= eta_q.re() {
        (eta_p, eta_q)
    } else {
        (eta_q, eta_p)
    };
    let low = if first.re() >= 0.0 {
        first
    } else {
        T::from(0.0)
    };
    let high = if last.re() <= 1.0 { last } else { T::from(1.0) };
    (low, high)
}

/// How deep a master node may sit inside the slave body before its own row holds it, as a
/// fraction of the length of the slave segment it faces: a quarter of the 1 % of a face
/// element that a contact between two bodies is held to, so that a segment stretched twice
/// (a Taylor foot's rim) still holds it within half. The mortar's weighted gaps are the
/// discretization's constraint (stable, patch test passed); a row on every master node as
/// well over-constrains a master finer than its slave (a steel block's 0.33 mm bottom on a
/// 0.5 mm plate edge: an element of the plate inverted at 2.8 us with the allowance 0), so
/// the master rows only cap how far the weighted sense lets a master node in.
pub const MASTER_ALLOWANCE: f64 = 0.0025;

/// A master node is held only where its master edges are at least this share of the slave
/// segment it faces: on a master finer than its slave, rows on every master node ask the
/// coarse slave polygon to hold a surface it cannot follow (the master nodes between two
/// slave nodes sink in by the polygon's own chord error, which the weighted gaps allow),
/// over-constrain it and, in the explicit correction, push nodes that were already inside
/// out in one step: a copper rod (8 x 50) at 200 m/s on a steel plate twice as fine created
/// 751 J of energy in its first 11 steps and inverted a plate element; with a tie rule and
/// these rows it still created 3-8 J and left the plate a plastic strain of 0.7-1.1 at the
/// rim against 0.14 without them. A rod face of 0.64 mm on one of 0.457 mm (ratio 0.71)
/// is still held.
pub const FINER: f64 = 0.6;

/// The pointwise gap of master node `node` (its master edges among `master`) against the
/// slave surface `slave_edges` at positions `x`: its distance from the nearest slave segment
/// it projects onto (positive outside the slave body) plus `allowance` times that segment's
/// length (`MASTER_ALLOWANCE` on the explicit path, 0 on the implicit), as a `Gap` whose "masters" are that segment's two
/// nodes, so that its row is n on the master node and -(1 - xi) n, -xi n on the segment's
/// ends (equal and opposite). The normal n is the mean of the segment's outward normal and
/// the master node's own inward one, as in the slave nodes' weighted gaps (on a plane of
/// symmetry the plane's normal: either surface's own would push the bodies apart sideways
/// where the surfaces curl). None when the node projects onto no slave segment within one
/// segment length, or where its master edges are shorter than [`FINER`] times that segment.
/// The dual mortar holds the slave nodes' weighted gaps, not the master nodes: where the two
/// surfaces fold at the rim of a contact zone a master node can sit inside the slave body
/// while every weighted gap is closed (the explicit correction's master block, `explicit`).
pub fn master_node_gap(
    slave_edges: &[[usize; 2]],
    master: &[[usize; 2]],
    node: usize,
    allowance: f64,
    x: &dyn Fn(usize) -> [f64; 2],
) -> Option<Gap> {
    let (_, e, xi) = nearest_projection(slave_edges, node, x)?;
    let p = x(node);
    let [a, b] = slave_edges[e];
    let (xa, xb) = (x(a), x(b));
    let slave_normal = outward(xa, xb);
    let slave_length = dot(sub(xb, xa), sub(xb, xa)).sqrt();
    let mut own = [0.0; 2];
    for [q, r] in master.iter().filter(|edge| edge.contains(&node)) {
        let (xq, xr) = (x(*q), x(*r));
        if dot(sub(xr, xq), sub(xr, xq)).sqrt() < FINER * slave_length {
            return None;
        }
        let n = outward(xq, xr);
        own = [own[0] - n[0], own[1] - n[1]];
    }
    let lo = dot(own, own).sqrt();
    let both = if lo > 0.0 {
        [slave_normal[0] + own[0] / lo, slave_normal[1] + own[1] / lo]
    } else {
        slave_normal
    };
    let lb = dot(both, both).sqrt();
    let normal = if lb > 0.0 {
        [both[0] / lb, both[1] / lb]
    } else {
        slave_normal
    };
    let on = [xa[0] + xi * (xb[0] - xa[0]), xa[1] + xi * (xb[1] - xa[1])];
    let allowance = allowance * dot(sub(xb, xa), sub(xb, xa)).sqrt();
    Some(Gap {
        gap: dot(sub(p, on), normal) + allowance,
        normal,
        masters: vec![(a, 1.0 - xi), (b, xi)],
        weight: 1.0,
        lever: None,
    })
}

/// The nearest of `edges` (solid on their left) that node `node` projects onto at positions
/// `x`, within one edge length of it: (the node's signed distance along the edge's outward
/// normal, negative inside; the edge's index; the projection's xi along it). None when it
/// projects onto none (an edge through the node itself is skipped).
pub fn nearest_projection(
    edges: &[[usize; 2]],
    node: usize,
    x: &dyn Fn(usize) -> [f64; 2],
) -> Option<(f64, usize, f64)> {
    let p = x(node);
    let mut nearest: Option<(f64, usize, f64)> = None;
    for (e, [a, b]) in edges.iter().enumerate() {
        if *a == node || *b == node {
            continue;
        }
        let (xa, xb) = (x(*a), x(*b));
        let ab = sub(xb, xa);
        let length2 = dot(ab, ab);
        let along = dot(sub(p, xa), ab);
        if !(length2 > 0.0 && along >= 0.0 && along <= length2) {
            continue;
        }
        let xi = along / length2;
        let on = [xa[0] + xi * ab[0], xa[1] + xi * ab[1]];
        let distance = dot(sub(p, on), outward(xa, xb));
        if distance * distance >= length2
            || nearest.is_some_and(|(d, _, _)| d.abs() <= distance.abs())
        {
            continue;
        }
        nearest = Some((distance, e, xi));
    }
    nearest
}

/// The slave node's segments (at most two: a surface node has no more) and their count, and
/// the node's normal: minus the mean of its segments' outward normals. None for a node of
/// more than two segments or of degenerate ones.
fn slave_side<T: Scalar>(
    surface: &MortarSurface,
    slave: usize,
    x: &dyn Fn(usize) -> [T; 2],
) -> Option<([[usize; 2]; 2], usize, [T; 2])> {
    let mut own = [[0usize; 2]; 2];
    let mut count = 0;
    for e in surface.edges.iter().filter(|e| e.contains(&slave)) {
        if count == own.len() {
            return None;
        }
        own[count] = *e;
        count += 1;
    }
    let zero = T::from(0.0);
    let mut sum = [zero; 2];
    for [a, b] in &own[..count] {
        let n = outward_t(x(*a), x(*b));
        sum = [sum[0] + n[0], sum[1] + n[1]];
    }
    let l = dot_t(sum, sum).sqrt();
    if !(l.re() > 0.0) {
        return None;
    }
    Some((own, count, [-sum[0] / l, -sum[1] / l]))
}

/// Whether the master segment `master` (its end points' projections `etas` on the slave
/// segment from `xa` along `ab`, outward normal `facing`: `slave = (xa, ab, facing)`) lies
/// across the slave segment rather than behind it: at the overlap `[low, high]` it is not
/// deeper inside the slave body than one slave segment length. A closed master (a ring)
/// faces a slave segment from its far side too, where the "gap" is the body's thickness.
fn within_reach<T: Scalar>(
    (xa, ab, facing): ([T; 2], [T; 2], [T; 2]),
    master: [[T; 2]; 2],
    etas: [T; 2],
    overlap: [T; 2],
) -> bool {
    let length = dot_t(ab, ab).sqrt();
    overlap.iter().any(|eta| {
        let xi = (*eta - etas[0]) / (etas[1] - etas[0]);
        let on_master = [
            master[0][0] + xi * (master[1][0] - master[0][0]),
            master[0][1] + xi * (master[1][1] - master[0][1]),
        ];
        let on_slave = [xa[0] + *eta * ab[0], xa[1] + *eta * ab[1]];
        // along the slave's outward normal: positive apart, negative inside
        dot_t(sub_t(on_master, on_slave), facing).re() > -length.re()
    })
}

/// Adds weight `w` to `node` in `list`.
fn add<T: Scalar>(list: &mut Vec<(usize, T)>, node: usize, w: T) {
    match list.iter_mut().find(|(n, _)| *n == node) {
        Some(entry) => entry.1 += w,
        None => list.push((node, w)),
    }
}

/// The dual shape function of local node `local` (0: the segment's start, 1: its end) on a
/// slave segment of length `length` with the area weight `area(eta)`: the coefficients of
/// Phi = c_0 N_0 + c_1 N_1 such that int Phi N_k dA = delta_local,k int N_local dA
/// (biorthogonal: Wohlmuth 2000; Popp, Gee & Wall 2009), and D = int N_local dA. Plane
/// segments give Phi_0 = 2 N_0 - N_1.
fn dual_shape<T: Scalar>(length: T, area: &dyn Fn(T) -> T, local: usize) -> Option<([T; 2], T)> {
    let zero = T::from(0.0);
    let mut m = [[zero; 2]; 2];
    for (g, w) in GAUSS {
        let n = [1.0 - g, g];
        let da = length * w * area(T::from(g));
        for i in 0..2 {
            for k in 0..2 {
                m[i][k] += da * (n[i] * n[k]);
            }
        }
    }
    let d = m[local][0] + m[local][1];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    if !(det.re() > 0.0) {
        return None;
    }
    // row `local` of diag(d) M^-1
    let inverse_row = [
        [m[1][1] / det, -m[0][1] / det],
        [-m[1][0] / det, m[0][0] / det],
    ][local];
    Some(([d * inverse_row[0], d * inverse_row[1]], d))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Goal: a master node's own gap against the slave surface: the distance along the
    /// slave segment's outward normal, negative inside the slave body, with the segment's
    /// ends weighted by the projection (equal and opposite).
    /// Reference: plane geometry (a flat slave surface along x, solid above).
    #[test]
    fn master_node_gap_is_the_distance_to_the_slave_segment() {
        // slave edges 0 -> 1 -> 2 along +x: the solid is on their left (above), outward -y
        let surface = MortarSurface {
            edges: vec![[0, 1], [1, 2]],
            axisymmetric: false,
            hold_master_nodes: true,
        };
        // master node 3 on a master edge 4 -> 3 (solid below it: its own normal +y, the
        // slave's outward -y, so their mean is the slave's)
        let mut nodes = vec![
            [0.0, 0.0],
            [1.0, 0.0],
            [2.0, 0.0],
            [0.25, 0.01],
            [-0.75, 0.01],
        ];
        let master = [[3, 4]];
        let x = |nodes: &Vec<[f64; 2]>| {
            let nodes = nodes.clone();
            move |n: usize| nodes[n]
        };
        let inside = master_node_gap(&surface.edges, &master, 3, MASTER_ALLOWANCE, &x(&nodes))
            .expect("faces edge 0-1");
        // 0.01 inside a segment of length 1, less the allowance
        assert_relative_eq!(inside.gap, -0.01 + MASTER_ALLOWANCE, max_relative = 1e-12);
        assert_eq!(inside.masters, vec![(0, 0.75), (1, 0.25)]);
        let row = inside.row(3);
        let sum_y: f64 = row.iter().filter(|(d, _)| d % 2 == 1).map(|(_, c)| c).sum();
        assert!(sum_y.abs() < 1e-15, "equal and opposite: {row:?}");
        nodes[3] = [1.5, -0.02];
        nodes[4] = [0.5, -0.02];
        let outside = master_node_gap(&surface.edges, &master, 3, MASTER_ALLOWANCE, &x(&nodes))
            .expect("faces edge 1-2");
        assert_relative_eq!(outside.gap, 0.02 + MASTER_ALLOWANCE, max_relative = 1e-12);
        assert_eq!(outside.masters, vec![(1, 0.5), (2, 0.5)]);
        // past the surface's end, or deeper than a segment length: no gap
        nodes[3] = [2.5, 0.01];
        assert!(
            master_node_gap(&surface.edges, &master, 3, MASTER_ALLOWANCE, &x(&nodes)).is_none()
        );
        nodes[3] = [0.5, 1.5];
        assert!(
            master_node_gap(&surface.edges, &master, 3, MASTER_ALLOWANCE, &x(&nodes)).is_none()
        );
    }

    /// Goal: a corner of the slave surface whose one face strikes a flat master (a block's
    /// bottom-left corner on its whole boundary, the flank free) is the end of that face:
    /// its gap is its height above the master, along the master's normal, with the full
    /// share, whether the corner is above or inside the master. Reference: plane geometry
    /// (a flat master y = 0, solid below; the corner at (0, h) with its bottom edge along +x
    /// and its flank along +y): g = h, n = (0, 1), as the bottom edge alone gives. Without
    /// the corner rule the normal was the mean of the bottom's and the flank's, (0.38, 0.92),
    /// and the share 2/3: g = 0.62 h.
    #[test]
    fn a_corner_whose_flank_is_free_is_the_end_of_its_face() {
        // slave: flank 2 -> 0 (down the left side), bottom 0 -> 1; the solid on their left
        let surface = MortarSurface {
            edges: vec![[2, 0], [0, 1]],
            axisymmetric: false,
            hold_master_nodes: false,
        };
        // master y = 0 from x = 1 to x = -1 (solid below), its segments 6-3-4-5-7
        let master = [[6, 3], [3, 4], [4, 5], [5, 7]];
        for h in [1e-6, -1e-5, -5e-5] {
            let nodes = [
                [0.0, h],
                [0.5e-3, h],
                [0.0, 0.25e-3 + h],
                [0.5e-3, 0.0],
                [0.0, 0.0],
                [-0.5e-3, 0.0],
                [1.0e-3, 0.0],
                [-1.0e-3, 0.0],
            ];
            let g = weighted_gap(&surface, &master, 0, &|n: usize| nodes[n]).expect("a gap");
            assert_relative_eq!(g.gap, h, max_relative = 1e-12);
            assert_relative_eq!(g.normal[1], 1.0, max_relative = 1e-12);
            assert_relative_eq!(g.weight, 1.0, max_relative = 1e-12);
        }
    }
}
