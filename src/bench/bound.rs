//! The memory bound of the one-point explicit step: the bytes one element update must move at
//! least (each array the step reads or writes touched once) and the rate at which this machine
//! copies that many bytes on one thread, a stream-like copy: their quotient is the element
//! updates a second that memory alone would allow, the figure `impact bench` sets each
//! one-point row against (docs/performance.md, "How close to the machine").
//!
//! ```text
//! per element   state columns read and written: stress 4, back stress 4, eps_p, temperature,
//!               thickness, viscous pressure, hourglass 2 = 14 f64, 2 x 112 B      224 B
//!               nodes [u32; 4] and body u32 read                                    20 B
//!               masses (smallest, total) read                                        16 B
//!               element forces 8 f64, bound and damping written                     80 B
//!               the gather: element forces read, 4 u32 entries                      80 B
//!                                                                           sum    420 B
//! per node      x and du read by the element loop (each node once)                  32 B
//!  (2 DOFs)     predict: v, a read; v_half, du written                              64 B
//!               the gather's nodal force written, its start (u64) read               24 B
//!               the step's end: free (u8), external, internal, mass, v_half, du,
//!               last total read; a, v, total written; x and u read and written    210 B
//!                                                                           sum    330 B
//! ```
//!
//! A copy of B bytes moves 2 B (read and written), so the copy rate is 2 B / t; the bound is
//! that rate over the bytes of one update, (420 E + 330 N) / E for E elements on N nodes.

use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Bytes one element update moves, per element (see the tally).
pub const ELEMENT_BYTES: f64 = 420.0;

/// Bytes one step moves per node (see the tally).
pub const NODE_BYTES: f64 = 330.0;

/// The memory bound of a one-point step of `elements` elements on `nodes` nodes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Bound {
    /// Bytes one element update moves (the nodes' share included).
    pub bytes_per_update: f64,
    /// Bytes a second a stream-like copy of the same bytes moves on one thread.
    pub copy_bytes_per_second: f64,
    /// The element updates a second that rate allows.
    pub updates_per_second: f64,
}

/// Bytes one element update moves on a mesh of `elements` elements and `nodes` nodes.
pub fn bytes_per_update(elements: usize, nodes: usize) -> f64 {
    ELEMENT_BYTES + NODE_BYTES * nodes as f64 / elements.max(1) as f64
}

/// The bound for `elements` elements on `nodes` nodes, the copy timed on this thread over a
/// buffer of one step's bytes (the best of `repeats` copies, after one that faults the pages
/// in).
pub fn measure(elements: usize, nodes: usize, repeats: usize) -> Bound {
    let bytes_per_update = bytes_per_update(elements, nodes);
    // half the step's bytes read, half written: a copy of half of them
    let words = ((bytes_per_update * elements as f64 / 16.0) as usize).max(1 << 16);
    let source: Vec<f64> = (0..words).map(|i| i as f64).collect();
    let mut target = vec![0.0; words];
    let mut best = f64::INFINITY;
    for _ in 0..=repeats {
        let start = Instant::now();
        target.copy_from_slice(&source);
        std::hint::black_box(&mut target);
        best = best.min(start.elapsed().as_secs_f64());
    }
    let copy_bytes_per_second = 2.0 * 8.0 * words as f64 / best.max(1e-12);
    Bound {
        bytes_per_update,
        copy_bytes_per_second,
        updates_per_second: copy_bytes_per_second / bytes_per_update,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The constants are the tally's sums, line by line (bytes).
    #[test]
    fn the_constants_are_the_tally() {
        let element = 2.0 * 14.0 * 8.0
            + (4.0 * 4.0 + 4.0)
            + 2.0 * 8.0
            + (8.0 + 2.0) * 8.0
            + (8.0 * 8.0 + 4.0 * 4.0);
        assert_eq!(element, ELEMENT_BYTES);
        let per_dof_end = (1.0 + 6.0 * 8.0) + 3.0 * 8.0 + 2.0 * 2.0 * 8.0;
        let node = 2.0 * 2.0 * 8.0 + 2.0 * 4.0 * 8.0 + (2.0 * 8.0 + 8.0) + 2.0 * per_dof_end;
        assert_eq!(node, NODE_BYTES);
    }

    /// A square mesh of n x n elements has (n + 1)^2 nodes: the nodes' share tends to
    /// NODE_BYTES per element.
    #[test]
    fn bytes_per_update_counts_the_nodes_share() {
        let n = 448;
        let bytes = bytes_per_update(n * n, (n + 1) * (n + 1));
        assert!((bytes - (ELEMENT_BYTES + NODE_BYTES)).abs() < NODE_BYTES * 3.0 / n as f64);
    }
}
