//! Mesh smoothing: where each node of a fixed-topology Quad4 mesh moves in one ALE step.
//!
//! Legend (node n, its elements e with plane area A_e and centroid c_e, its joined nodes j)
//! ```text
//! volume    x* = sum A_e c_e / sum A_e         (Abaqus/Explicit's volume smoothing)
//! laplace   x* = mean of x_j
//! inside    d  = x* - x_n
//! boundary  d  = s t, s = (|x_q - x_n| - |x_n - x_p|) / 2 (even spacing along the
//!           boundary), t the unit chord of the boundary neighbours p, q:
//!           parallel to the chord, the triangle (p, n, q) keeps its area, so the body's
//!           area stays (to second order in the moves of p and q); |s| at most half the
//!           edge toward which it moves; only where the boundary turns by less than
//!           `slide_angle` at the node (a corner stays)
//! held      d  = 0 (the caller's: loads, probes, deformable contact); a support's
//!           components of d are zero
//! limit     the area n's two edges sweep in each of its elements, sum 1/2 |d x (x_j - x_n)|,
//!           at most `max_move` of that element's area (the remap's Courant number: a node
//!           slides far along a crushed layer, little across it); a move that would fold an
//!           element's corner (its Jacobian there not positive) is halved, at most 8 times,
//!           then dropped
//! ```
//! One Jacobi sweep per call (every target from the positions before the call), so the
//! result does not depend on the node order.

use super::geometry::moments;
use super::topology::Topology;

/// The smoother's target for an interior node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Smoother {
    /// The area-weighted mean of the centroids of the node's elements.
    Volume,
    /// The mean of the nodes joined to the node by an edge.
    Laplace,
    /// Winslow's equipotential smoothing (Winslow 1967): the node where the mesh lines are
    /// harmonic in the physical plane, the discrete form on the node's four elements; the
    /// volume target where a node has other than four.
    Equipotential,
}

impl Smoother {
    /// The scene's name of the smoother.
    pub fn name(self) -> &'static str {
        match self {
            Smoother::Volume => "volume",
            Smoother::Laplace => "laplace",
            Smoother::Equipotential => "equipotential",
        }
    }
}

/// How far and where the nodes may move.
#[derive(Debug, Clone, Copy)]
pub struct Rules {
    pub smoother: Smoother,
    /// The largest area a node's move sweeps in one of its elements, as a fraction of that
    /// element's area.
    pub max_move: f64,
    /// The largest turn of the boundary (radians) at which a boundary node still slides.
    pub slide_angle: f64,
}

/// Per node, what may move: `held` nodes stay; a `fixed` component stays.
pub struct Freedom<'a> {
    pub held: &'a [bool],
    pub fixed: &'a [[bool; 2]],
}

/// The smoothed positions of the nodes `x` (local numbering of `topology`).
pub fn smooth(
    topology: &Topology,
    x: &[[f64; 2]],
    freedom: &Freedom,
    rules: &Rules,
) -> Vec<[f64; 2]> {
    let mut moves: Vec<[f64; 2]> = (0..topology.nodes)
        .map(|n| node_move(topology, x, freedom, rules, n))
        .collect();
    for _ in 0..8 {
        let inverted = inverted_cells(topology, x, &moves);
        if inverted.is_empty() {
            return apply(x, &moves);
        }
        for e in inverted {
            for n in topology.cells[e] {
                moves[n] = [0.5 * moves[n][0], 0.5 * moves[n][1]];
            }
        }
    }
    for e in inverted_cells(topology, x, &moves) {
        for n in topology.cells[e] {
            moves[n] = [0.0, 0.0];
        }
    }
    apply(x, &moves)
}

fn apply(x: &[[f64; 2]], moves: &[[f64; 2]]) -> Vec<[f64; 2]> {
    x.iter()
        .zip(moves)
        .map(|(p, d)| [p[0] + d[0], p[1] + d[1]])
        .collect()
}

/// The elements that `moves` leave folded at a 2x2 Gauss point (the kernels integrate
/// there), or with a corner whose Jacobian is not positive and lower than before the moves
/// (a corner the Lagrangian steps folded may stay as it was, not fold further).
fn inverted_cells(topology: &Topology, x: &[[f64; 2]], moves: &[[f64; 2]]) -> Vec<usize> {
    (0..topology.cells.len())
        .filter(|e| {
            let cell = topology.cells[*e];
            if cell.iter().all(|n| moves[*n] == [0.0, 0.0]) {
                return false;
            }
            let before = corner_jacobians(&cell.map(|n| x[n]));
            let after =
                corner_jacobians(&cell.map(|n| [x[n][0] + moves[n][0], x[n][1] + moves[n][1]]));
            let worst = |c: &[f64; 4]| c.iter().copied().fold(f64::INFINITY, f64::min);
            gauss_folded(&after) || (worst(&after) <= 0.0 && worst(&after) < worst(&before))
        })
        .collect()
}

/// A quadrilateral's Jacobian at its corners (twice the area of the triangle at each): the
/// bilinear map's det J is affine in (xi, eta), so these four give it everywhere.
pub fn corner_jacobians(p: &[[f64; 2]; 4]) -> [f64; 4] {
    std::array::from_fn(|k| {
        let (a, b, c) = (p[(k + 3) % 4], p[k], p[(k + 1) % 4]);
        (c[0] - b[0]) * (a[1] - b[1]) - (c[1] - b[1]) * (a[0] - b[0])
    })
}

/// Whether det J is not positive at one of the 2x2 Gauss points (+-1/sqrt 3): there the
/// corner values mix with the bilinear weights (1 + g)^2, 1 - g^2, (1 - g)^2 over 4.
fn gauss_folded(corners: &[f64; 4]) -> bool {
    let g = 1.0 / 3.0f64.sqrt();
    let (near, side, far) = ((1.0 + g) * (1.0 + g), 1.0 - g * g, (1.0 - g) * (1.0 - g));
    (0..4).any(|k| {
        near * corners[k]
            + side * (corners[(k + 1) % 4] + corners[(k + 3) % 4])
            + far * corners[(k + 2) % 4]
            <= 0.0
    })
}

/// The move of node `n` (see the legend).
fn node_move(
    topology: &Topology,
    x: &[[f64; 2]],
    freedom: &Freedom,
    rules: &Rules,
    n: usize,
) -> [f64; 2] {
    if freedom.held[n] || topology.cells_at[n].is_empty() {
        return [0.0, 0.0];
    }
    let target = match rules.smoother {
        Smoother::Volume => volume_target(topology, x, n),
        Smoother::Equipotential => {
            equipotential(topology, x, n).unwrap_or_else(|| volume_target(topology, x, n))
        }
        Smoother::Laplace => {
            let joined = &topology.joined[n];
            let count = joined.len() as f64;
            [0, 1].map(|i| joined.iter().map(|j| x[*j][i]).sum::<f64>() / count)
        }
    };
    let here = x[n];
    let mut d = [target[0] - here[0], target[1] - here[1]];
    if topology.on_boundary[n] {
        let Some([p, q]) = topology.boundary[n] else {
            return [0.0, 0.0]; // a pinch stays
        };
        let (back, ahead) = (
            [x[p][0] - here[0], x[p][1] - here[1]],
            [x[q][0] - here[0], x[q][1] - here[1]],
        );
        // the turn of the boundary at n: the angle between the edge into n and the edge out
        let (into, out) = ([-back[0], -back[1]], ahead);
        let turn = (into[0] * out[1] - into[1] * out[0]).atan2(into[0] * out[0] + into[1] * out[1]);
        if turn.abs() > rules.slide_angle {
            return [0.0, 0.0];
        }
        // parallel to the chord: the triangle (p, n, q) keeps its area, so the two boundary
        // edges sweep as much into the body as out of it
        // the target spaces the node evenly between its boundary neighbours (the interior
        // smoother's target of a boundary node lies inside the body)
        let chord = [x[q][0] - x[p][0], x[q][1] - x[p][1]];
        let length = norm(chord);
        let s = 0.5 * (norm(ahead) - norm(back));
        let reach = if s >= 0.0 { norm(ahead) } else { norm(back) };
        let along = s.clamp(-0.5 * reach, 0.5 * reach);
        d = [chord[0] / length * along, chord[1] / length * along];
    }
    for i in 0..2 {
        if freedom.fixed[n][i] {
            d[i] = 0.0;
        }
    }
    let scale = sweep_limit(topology, x, n, d, rules.max_move);
    [d[0] * scale, d[1] * scale]
}

/// The factor (at most 1) that keeps the area node `n`'s two edges sweep in each of its
/// elements, sum 1/2 |d x (x_j - x_n)|, within `max_move` of that element's area: the remap's
/// Courant number. A move along a thin element's long edges sweeps little, so a node may
/// slide far along a crushed layer and only a little across it.
fn sweep_limit(topology: &Topology, x: &[[f64; 2]], n: usize, d: [f64; 2], max_move: f64) -> f64 {
    let mut scale: f64 = 1.0;
    for e in &topology.cells_at[n] {
        let cell = topology.cells[*e];
        let k = cell
            .iter()
            .position(|m| *m == n)
            .expect("the node is a corner of its cells");
        let here = x[n];
        let swept: f64 = [cell[(k + 1) % 4], cell[(k + 3) % 4]]
            .iter()
            .map(|j| 0.5 * (d[0] * (x[*j][1] - here[1]) - d[1] * (x[*j][0] - here[0])).abs())
            .sum();
        let area = moments(&topology.corners(x, *e), false).volume;
        if swept > max_move * area {
            scale = scale.min(max_move * area / swept);
        }
    }
    scale.max(0.0)
}

/// The area-weighted mean of the centroids of node `n`'s elements.
fn volume_target(topology: &Topology, x: &[[f64; 2]], n: usize) -> [f64; 2] {
    let (mut sum, mut weighted) = (0.0, [0.0, 0.0]);
    for e in &topology.cells_at[n] {
        let m = moments(&topology.corners(x, *e), false);
        sum += m.volume;
        weighted = [weighted[0] + m.first[0], weighted[1] + m.first[1]];
    }
    [weighted[0] / sum, weighted[1] / sum]
}

/// Winslow's target of an interior node with four elements: its edge neighbours E, N, W, S
/// and diagonal ones NE, NW, SW, SE in turn around it,
/// x = (a (x_E + x_W) + g (x_N + x_S) - b / 2 (x_NE - x_NW + x_SW - x_SE)) / (2 (a + g)),
/// x_xi = (x_E - x_W) / 2, x_eta = (x_N - x_S) / 2, a = |x_eta|^2, b = x_xi . x_eta,
/// g = |x_xi|^2. None where the node has other than four elements.
fn equipotential(topology: &Topology, x: &[[f64; 2]], n: usize) -> Option<[f64; 2]> {
    let cells = &topology.cells_at[n];
    if cells.len() != 4 {
        return None;
    }
    // per element (after, diagonal, before) counter-clockwise around n
    let corners: Vec<[usize; 3]> = cells
        .iter()
        .map(|e| {
            let c = topology.cells[*e];
            let k = c
                .iter()
                .position(|m| *m == n)
                .expect("n is a corner of its cells");
            [c[(k + 1) % 4], c[(k + 2) % 4], c[(k + 3) % 4]]
        })
        .collect();
    let mut order = vec![0];
    for _ in 0..3 {
        let last = corners[*order.last().expect("one at least")];
        order.push(corners.iter().position(|c| c[0] == last[2])?);
    }
    let [e, ne, nn] = corners[order[0]];
    let [_, nw, w] = corners[order[1]];
    let [_, sw, s] = corners[order[2]];
    let [_, se, _] = corners[order[3]];
    let p = |i: usize, k: usize| x[i][k];
    let xi = [0.5 * (p(e, 0) - p(w, 0)), 0.5 * (p(e, 1) - p(w, 1))];
    let eta = [0.5 * (p(nn, 0) - p(s, 0)), 0.5 * (p(nn, 1) - p(s, 1))];
    let a = eta[0] * eta[0] + eta[1] * eta[1];
    let g = xi[0] * xi[0] + xi[1] * xi[1];
    let b = xi[0] * eta[0] + xi[1] * eta[1];
    Some([0, 1].map(|k| {
        (a * (p(e, k) + p(w, k)) + g * (p(nn, k) + p(s, k))
            - 0.5 * b * (p(ne, k) - p(nw, k) + p(sw, k) - p(se, k)))
            / (2.0 * (a + g))
    }))
}

fn norm(v: [f64; 2]) -> f64 {
    v[0].hypot(v[1])
}
