//! Where each element matrix goes in the assembled lower triangle: positions computed once
//! per topology (`System::new`), the element loop adds through them.

use crate::solver::Pattern;

/// Scatter positions of one body's element matrices, element-major: one u32 for each entry
/// of an element's lower triangle, pairs of local DOFs (a, b), b <= a, in the order (0, 0),
/// (1, 0), (1, 1), (2, 0), ... The element matrices are symmetric, so the upper triangle is
/// not looked at: 36 positions a Quad4 where the full n x n took 64, 0.07 kB a DOF less at
/// 1e6 DOFs. A position with `TRANSPOSED` set takes entry (b, a) of the element matrix, the
/// one the global lower triangle holds when b's equation number is the larger, so the sum
/// is bit for bit the one a full n x n scatter gives.
pub(super) struct Scatter {
    /// Element DOFs.
    n: usize,
    positions: Vec<u32>,
}

/// A scatter position that is not assembled (a constrained DOF).
pub(super) const NONE: u32 = u32::MAX;
/// The flag of a position that takes the element matrix's transposed entry.
pub(super) const TRANSPOSED: u32 = 1 << 31;

impl Scatter {
    pub(super) fn new(pattern: &Pattern, elements: &[Vec<Option<usize>>]) -> Scatter {
        let n = elements.first().map_or(0, Vec::len);
        let per_element = n * (n + 1) / 2;
        let mut positions = Vec::with_capacity(elements.len() * per_element);
        for eqs in elements {
            for a in 0..n {
                for b in 0..=a {
                    positions.push(match (eqs[a], eqs[b]) {
                        (Some(i), Some(j)) => {
                            let (row, col, flag) = if i >= j {
                                (i, j, 0)
                            } else {
                                (j, i, TRANSPOSED)
                            };
                            let p = pattern
                                .position(row, col)
                                .expect("pattern holds the element");
                            p as u32 | flag
                        }
                        _ => NONE,
                    });
                }
            }
        }
        Scatter { n, positions }
    }

    /// Adds element e's n x n row-major matrix `m` into `values`.
    pub(super) fn add(&self, e: usize, m: &[f64], values: &mut [f64]) {
        self.for_each(e, |p, a, b| values[p] += m[a * self.n + b]);
    }

    /// Calls `f(position, a, b)` for each assembled lower-triangle entry of element e, with
    /// (a, b) the element matrix entry that goes there.
    pub(super) fn for_each(&self, e: usize, mut f: impl FnMut(usize, usize, usize)) {
        let n = self.n;
        // an element's lower triangle: n (n + 1) / 2 entries
        let per_element = n * (n + 1) / 2;
        let positions = &self.positions[e * per_element..(e + 1) * per_element];
        let mut k = 0;
        for a in 0..n {
            for b in 0..=a {
                let p = positions[k];
                k += 1;
                if p == NONE {
                    continue;
                }
                if p & TRANSPOSED == 0 {
                    f(p as usize, a, b);
                } else {
                    f((p & !TRANSPOSED) as usize, b, a);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lower-triangle scatter adds, at every global entry (i, j), i >= j, the element
    /// entries (a, b) with equations (i, j): what a dense assembly of the full element
    /// matrices gives there. The element matrices are deliberately not symmetric, so a
    /// transposed entry taken where the plain one belongs (or the reverse) shows.
    #[test]
    fn lower_triangle_scatter_matches_a_dense_assembly() {
        // three 4-DOF elements, equations in both orders, one constrained DOF (None)
        let elements: Vec<Vec<Option<usize>>> = vec![
            vec![Some(4), Some(1), Some(0), Some(3)],
            vec![Some(2), Some(4), None, Some(5)],
            vec![Some(5), Some(0), Some(1), Some(2)],
        ];
        let size = 6;
        let pattern = Pattern::from_elements(size, elements.iter().map(|v| v.as_slice()));
        let scatter = Scatter::new(&pattern, &elements);
        let n = 4;
        let matrix = |e: usize| -> Vec<f64> {
            (0..n * n)
                .map(|k| 1.0 + (e * 16 + k) as f64 * 0.37 + (k % 3) as f64 * 1e-3)
                .collect()
        };
        let mut values = vec![0.0; pattern.nonzeros()];
        let mut dense = vec![vec![0.0; size]; size];
        for (e, eqs) in elements.iter().enumerate() {
            let m = matrix(e);
            scatter.add(e, &m, &mut values);
            for a in 0..n {
                for b in 0..n {
                    if let (Some(i), Some(j)) = (eqs[a], eqs[b]) {
                        dense[i][j] += m[a * n + b];
                    }
                }
            }
        }
        for j in 0..size {
            for i in j..size {
                let got = pattern.position(i, j).map_or(0.0, |p| values[p]);
                // exact: each entry receives one element entry per element, in element order
                // in both sums
                assert_eq!(got, dense[i][j], "entry ({i}, {j})");
            }
        }
    }
}
