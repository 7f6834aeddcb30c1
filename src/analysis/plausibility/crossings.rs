//! A body that passed through itself: at the end of a run two of its boundary edges cross.
//! No contact pair sees that unless the body is its own slave and master (docs/theory.md
//! 8.3e): a tube crushed flat whose inner face goes through itself ends `ok` otherwise.
//!
//! Legend
//! ```text
//! cross    two boundary edges that share no node, each one's ends on either side of the
//!          other's line by more than DEPTH of the shorter edge (faces pressed together by
//!          a contact touch within round-off: no crossing)
//! ```

use crate::output::readable;
use crate::scene::{Body, Model};

/// The share of the shorter edge by which two edges must cross to count.
const DEPTH: f64 = 1e-3;

/// One warning per Quad4 body whose boundary crosses itself at the positions `x` and did not
/// in the initial mesh: how many edge pairs cross, where the first is, and the pair that
/// would hold it (or that the body's own pair did not).
pub(super) fn self_crossing_warnings(model: &Model, x: &[[f64; 2]]) -> Vec<String> {
    let mut out = Vec::new();
    for (b, body) in model.bodies.iter().enumerate() {
        let crossed = run_crossings(body, x);
        if crossed.is_empty() {
            continue;
        }
        let ([p, q], [r, s]) = crossed[0];
        let local = |n: usize| n - body.node_offset;
        let own = model
            .contacts
            .iter()
            .find(|pair| pair.own.is_some() && pair.slave_body == b && pair.balances.is_none());
        let advice = match own {
            Some(pair) => format!(
                "the pair `{}` holds the body against itself, but not here: a face deeper \
                 than half an edge into the other, or outside its sets",
                pair.name
            ),
            None => format!(
                "no pair holds the body against itself; under central_difference give a \
                 pair with the body as both slave and master (slave = {{ body = \"{0}\" }}, \
                 master = {{ body = \"{0}\" }})",
                body.name
            ),
        };
        out.push(format!(
            "body `{}` passed through itself: {} pair(s) of its boundary edges cross at the \
             end, the first the edges {}-{} and {}-{} near ({}, {}); {advice}",
            body.name,
            crossed.len(),
            local(p),
            local(q),
            local(r),
            local(s),
            readable(x[p][0]),
            readable(x[p][1])
        ));
    }
    out
}

/// Whether `body`'s boundary crosses itself at the positions `x` and did not in its mesh:
/// the body passed through itself in the run.
pub(super) fn passed_through_itself(body: &Body, x: &[[f64; 2]]) -> bool {
    !run_crossings(body, x).is_empty()
}

/// The pairs of `body`'s boundary edges (global nodes) that cross at the positions `x`, none
/// when its mesh crosses itself from the start (not the run's doing).
fn run_crossings(body: &Body, x: &[[f64; 2]]) -> Vec<([usize; 2], [usize; 2])> {
    let edges: Vec<[usize; 2]> = body
        .boundary
        .iter()
        .map(|e| e.map(|n| body.global(n)))
        .collect();
    let crossed = crossings(&edges, &|n| x[n]);
    let initial = |n: usize| body.mesh.nodes[n - body.node_offset];
    if crossed.is_empty() || !crossings(&edges, &initial).is_empty() {
        return Vec::new();
    }
    crossed
}

/// The pairs of `edges` that cross at positions `x` (see the module legend).
fn crossings(edges: &[[usize; 2]], x: &dyn Fn(usize) -> [f64; 2]) -> Vec<([usize; 2], [usize; 2])> {
    // the signed distance of p from the line through a and b
    let side = |a: [f64; 2], b: [f64; 2], p: [f64; 2]| {
        ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]))
            / (b[0] - a[0]).hypot(b[1] - a[1])
    };
    let length = |[a, b]: [usize; 2]| (x(b)[0] - x(a)[0]).hypot(x(b)[1] - x(a)[1]);
    let mut out = Vec::new();
    for (i, &[a, b]) in edges.iter().enumerate() {
        let (pa, pb) = (x(a), x(b));
        for &[c, d] in &edges[i + 1..] {
            if [c, d].iter().any(|n| *n == a || *n == b) {
                continue;
            }
            let (pc, pd) = (x(c), x(d));
            let apart = |lo: f64, hi: f64, u: f64, v: f64| u.max(v) < lo || u.min(v) > hi;
            if apart(pa[0].min(pb[0]), pa[0].max(pb[0]), pc[0], pd[0])
                || apart(pa[1].min(pb[1]), pa[1].max(pb[1]), pc[1], pd[1])
            {
                continue;
            }
            let depth = DEPTH * length([a, b]).min(length([c, d]));
            let across = |s: f64, t: f64| s * t < 0.0 && s.abs().min(t.abs()) > depth;
            if across(side(pa, pb, pc), side(pa, pb, pd))
                && across(side(pc, pd, pa), side(pc, pd, pb))
            {
                out.push(([a, b], [c, d]));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference: a square loop 0..3 does not cross itself; with node 2 pulled across the
    /// edge 0-1 (to (0.5, -1)) the edges 1-2 and 3-0 do not meet, but 2-3 crosses 0-1.
    #[test]
    fn a_loop_pulled_through_itself_crosses() {
        let edges = [[0, 1], [1, 2], [2, 3], [3, 0]];
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert!(crossings(&edges, &|n| square[n]).is_empty());
        let pulled = |n: usize| if n == 2 { [0.5, -1.0] } else { square[n] };
        assert_eq!(crossings(&edges, &pulled), vec![([0, 1], [2, 3])]);
    }
}
