//! The one search over the slaves: where each slave of each pair lies against its master.
//! Every question contact asks of the configuration (who penetrates, who touches, how deep,
//! the gaps written to the frames) walks the slaves through [`slave_gaps`].

use super::geometry::{ContactPair, Gap, Master};
use super::grid::SegmentGrid;

/// A slave node's gap at a configuration.
#[derive(Debug, Clone)]
pub struct SlaveGap {
    /// The pair and the slave's index in it.
    pub pair: usize,
    pub index: usize,
    /// The global node.
    pub node: usize,
    pub gap: Gap,
}

/// The gaps of the slaves of `pairs` at positions `x`, pair by pair in slave order; entries
/// for which `skip(pair, index)` holds are passed over before their gap is computed, and
/// slaves with no master within the search distance are left out.
pub fn slave_gaps<'a>(
    pairs: &'a [ContactPair],
    x: &'a dyn Fn(usize) -> [f64; 2],
    skip: &'a dyn Fn(usize, usize) -> bool,
) -> impl Iterator<Item = SlaveGap> + 'a {
    pairs.iter().enumerate().flat_map(move |(p, pair)| {
        let grid = grid(pair, x);
        pair.slaves
            .iter()
            .enumerate()
            .filter(move |(k, _)| !skip(p, *k))
            .filter_map(move |(k, s)| {
                let gap = match &grid {
                    Some(grid) => pair.node_gap_on(*s, x, Some(grid)),
                    None => pair.gap(*s, x),
                };
                gap.map(|gap| SlaveGap {
                    pair: p,
                    index: k,
                    node: *s,
                    gap,
                })
            })
    })
}

/// The slaves (not skipped) that penetrate their master beyond the pair's TOL (Hughes II-7).
pub fn penetrating<'a>(
    pairs: &'a [ContactPair],
    x: &'a dyn Fn(usize) -> [f64; 2],
    skip: &'a dyn Fn(usize, usize) -> bool,
) -> impl Iterator<Item = SlaveGap> + 'a {
    slave_gaps(pairs, x, skip).filter(|s| penetrates(pairs, s, x, skip))
}

/// The grid of a balanced pass's master segments at `x` (`ContactPair::node_gap_on`), where
/// its slaves, often a body's whole boundary, are searched against many segments. None for
/// other pairs, whose slaves look at every master segment, as they were validated, and for
/// a master of a few segments, which looking at costs less than building a grid.
fn grid(pair: &ContactPair, x: &dyn Fn(usize) -> [f64; 2]) -> Option<SegmentGrid> {
    /// Fewer master segments than this are looked at one by one.
    const GRID_FROM: usize = 32;
    match &pair.master {
        Master::Segments { edges, .. } if pair.options.balanced && edges.len() >= GRID_FROM => {
            let segments: Vec<[[f64; 2]; 2]> = edges.iter().map(|[a, b]| [x(*a), x(*b)]).collect();
            SegmentGrid::new(&segments)
        }
        _ => None,
    }
}

/// Whether a slave's gap is a penetration beyond its pair's TOL that no other pass covers
/// (the test of [`penetrating`]).
pub fn penetrates(
    pairs: &[ContactPair],
    s: &SlaveGap,
    x: &dyn Fn(usize) -> [f64; 2],
    skip: &dyn Fn(usize, usize) -> bool,
) -> bool {
    s.gap.gap < -pairs[s.pair].options.tolerance && !pairs[s.pair].covers(pairs, &s.gap, x, skip)
}

/// Per pair, the penetration beyond which a run stops: half the smallest distance between
/// two of its slave nodes in the configuration `x` (infinite with one slave).
pub fn penetration_limits(pairs: &[ContactPair], x: &[[f64; 2]]) -> Vec<f64> {
    pairs
        .iter()
        .map(|pair| {
            let mut nodes: Vec<[f64; 2]> = pair.slaves.iter().map(|s| x[*s]).collect();
            nodes.sort_by(|a, b| a[0].total_cmp(&b[0]));
            let mut h = f64::INFINITY;
            for i in 0..nodes.len() {
                for j in i + 1..nodes.len() {
                    let dx = nodes[j][0] - nodes[i][0];
                    if dx >= h {
                        break;
                    }
                    let d = dx.hypot(nodes[j][1] - nodes[i][1]);
                    if d > 0.0 {
                        h = h.min(d);
                    }
                }
            }
            0.5 * h
        })
        .collect()
}

/// The deepest slave penetration beyond its pair's limit (see [`penetration_limits`]), as a
/// message naming the pair, the node, the gap and the limit: a node that deep has passed
/// its neighbours' master segments, and the contact no longer holds.
pub fn runaway_penetration(
    pairs: &[ContactPair],
    coords: &[[f64; 2]],
    limits: &[f64],
) -> Option<String> {
    let x = |n: usize| coords[n];
    let mut worst: Option<(f64, usize, usize, f64)> = None;
    for s in slave_gaps(pairs, &x, &|_, _| false) {
        let (g, p) = (s.gap.gap, s.pair);
        if (g < -limits[p] || !g.is_finite()) && worst.is_none_or(|w| g / limits[p] < w.0 / w.3) {
            worst = Some((g, p, s.node, limits[p]));
        }
    }
    worst.map(|(gap, p, node, limit)| {
        format!(
            "runaway penetration: contact `{}`, node {node}: gap = {gap:e} beyond -{limit:e} \
             (half the slave node spacing)",
            pairs[p].name
        )
    })
}
