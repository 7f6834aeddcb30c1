//! The numeric factor as the blocks of its elimination tree, and the entries of K^-1 among
//! the contact equations from forward solves along the tree's paths (docs/theory.md 8.6):
//! what `Solver::inverse_entries` reads.

use super::Ix;
use faer::Accum;
use faer::Par;
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::simplicial::SymbolicSimplicialCholesky;
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;

/// The numeric factor seen as the blocks of the elimination tree: supernodes, or single
/// columns of a simplicial factor (faer's choice when supernodes would not pay: small or
/// very sparse factors, e.g. the 1e4-DOF bench block). A block's parent has a larger index,
/// so a path runs in ascending order.
#[derive(Clone, Copy)]
pub(super) enum TreeFactor<'a> {
    /// The factor and the supernode of each column.
    Supernodal(SupernodalLltRef<'a, Ix, f64>, &'a [usize]),
    Simplicial(&'a SymbolicSimplicialCholesky<Ix>, &'a [f64]),
}

impl TreeFactor<'_> {
    pub(super) fn blocks(self) -> usize {
        match self {
            TreeFactor::Supernodal(factor, _) => factor.symbolic().n_supernodes(),
            TreeFactor::Simplicial(symbolic, _) => symbolic.nrows(),
        }
    }

    /// The block holding (permuted) column `column`.
    pub(super) fn block_of(self, column: usize) -> usize {
        match self {
            TreeFactor::Supernodal(_, supernode_of) => supernode_of[column],
            TreeFactor::Simplicial(..) => column,
        }
    }

    /// The columns of a block.
    pub(super) fn columns(self, block: usize) -> std::ops::Range<usize> {
        match self {
            TreeFactor::Supernodal(factor, _) => {
                let symbolic = factor.symbolic();
                symbolic.supernode_begin()[block] as usize..symbolic.supernode_end()[block] as usize
            }
            TreeFactor::Simplicial(..) => block..block + 1,
        }
    }

    /// One block of the forward solve L x = b in place: x_block = L_block^-1 x_block, then
    /// x[rows below] -= L_below x_block (rows all in the block's ancestors). Returns the
    /// parent block (None at a root). `below` is scratch.
    pub(super) fn forward_block(
        self,
        block: usize,
        x: &mut [f64],
        below: &mut Vec<f64>,
    ) -> Option<usize> {
        match self {
            TreeFactor::Simplicial(symbolic, values) => {
                let (col_ptr, row_idx) = (symbolic.col_ptr(), symbolic.row_idx());
                let (first, end) = (col_ptr[block] as usize, col_ptr[block + 1] as usize);
                let xj = x[block] / values[first];
                x[block] = xj;
                for k in first + 1..end {
                    x[row_idx[k] as usize] -= values[k] * xj;
                }
                // the parent is the first row below the diagonal
                (first + 1 < end).then(|| row_idx[first + 1] as usize)
            }
            TreeFactor::Supernodal(factor, supernode_of) => {
                let node = factor.supernode(block);
                let (l, pattern) = (node.val(), node.pattern());
                let (begin, size) = (node.start(), l.ncols());
                let (l_top, l_bottom) = l.split_at_row(size);
                let mut x_top =
                    faer::MatMut::from_column_major_slice_mut(&mut x[begin..begin + size], size, 1);
                solve_lower_triangular_in_place(l_top, x_top.rb_mut(), Par::Seq);
                below.clear();
                below.resize(pattern.len(), 0.0);
                let product = faer::MatMut::from_column_major_slice_mut(below, pattern.len(), 1);
                matmul(product, Accum::Replace, l_bottom, x_top.rb(), 1.0, Par::Seq);
                for (r, b) in pattern.iter().zip(below.iter()) {
                    x[*r as usize] -= b;
                }
                pattern.first().map(|r| supernode_of[*r as usize])
            }
        }
    }
}

/// K^-1 restricted to a growing set of equations (those contact rows name): the Schur
/// complement C K^-1 C^T needs no more. With K = P^T L L^T P,
/// ```text
/// (K^-1)_ab = y_a . y_b,   y_a = L^-1 P e_a
/// ```
/// and y_a is non-zero only on the blocks (supernodes, or columns) on the path from a's block
/// to the root of the elimination tree: a forward solve along that path (~1 900 of 1e5
/// entries on the bench block) instead of a whole back-substitution. The y's are kept per
/// factorization, so an equation named later costs its own path and its dot products.
#[derive(Default)]
pub(super) struct InverseEntries {
    /// Per equation, its local index (`UNKNOWN` until named): a look-up for every entry a
    /// contact solve reads, so an array over the equations (4 bytes a DOF) and no hashing.
    pub(super) local: Vec<u32>,
    pub(super) equations: Vec<usize>,
    /// y_{equations[k]} along its path.
    pub(super) paths: Vec<Path>,
    /// `lower[k][j]` = (K^-1)_{equations[k], equations[j]} for j <= k.
    pub(super) lower: Vec<Vec<f64>>,
}

/// `InverseEntries::local` of an equation not named since the last factorization.
pub(super) const UNKNOWN: u32 = u32::MAX;

impl InverseEntries {
    pub(super) fn local(&self, equation: usize) -> Option<usize> {
        match self.local.get(equation) {
            Some(&k) if k != UNKNOWN => Some(k as usize),
            _ => None,
        }
    }

    /// Forgets the entries (a new factorization); the index array is kept.
    pub(super) fn clear(&mut self) {
        for eq in self.equations.drain(..) {
            self.local[eq] = UNKNOWN;
        }
        self.paths.clear();
        self.lower.clear();
    }
}

/// y_a on the blocks of its elimination-tree path (ascending), the blocks' segments of y end
/// to end in one array (a simplicial factor's blocks are single columns: one allocation a
/// path, not one an entry).
#[derive(Default)]
pub(super) struct Path {
    pub(super) blocks: Vec<usize>,
    /// Segment k is `values[ends[k - 1]..ends[k]]` (from 0 for k = 0).
    pub(super) ends: Vec<usize>,
    pub(super) values: Vec<f64>,
    /// S y_a where the factor is of an indefinite matrix (`signed_root`), else empty.
    pub(super) signed: Vec<f64>,
}

impl Path {
    pub(super) fn segment(&self, k: usize) -> &[f64] {
        let start = if k == 0 { 0 } else { self.ends[k - 1] };
        &self.values[start..self.ends[k]]
    }

    /// S y_a's segment k (y_a's where the factor is definite).
    pub(super) fn signed_segment(&self, k: usize) -> &[f64] {
        if self.signed.is_empty() {
            return self.segment(k);
        }
        let start = if k == 0 { 0 } else { self.ends[k - 1] };
        &self.signed[start..self.ends[k]]
    }

    /// Forms S y_a from the signs of the factor's columns.
    pub(super) fn sign(&mut self, factor: TreeFactor<'_>, signs: &[f64]) {
        self.signed = self.values.clone();
        let mut at = 0;
        for &block in &self.blocks {
            for column in factor.columns(block) {
                self.signed[at] *= signs[column];
                at += 1;
            }
        }
    }

    /// (block, segment of y) along the path.
    pub(super) fn segments(&self) -> impl Iterator<Item = (usize, &[f64])> {
        (0..self.blocks.len()).map(|k| (self.blocks[k], self.segment(k)))
    }
}

/// y_a . S y_b over the blocks both paths hold, their common ancestors. Two paths to the root
/// of a tree share a suffix: from the block where they meet up to the root they are the same
/// blocks with segments of the same length, and below it they hold none in common. The
/// suffix's length is found by bisection, and the sum runs over it alone, block by block in
/// ascending order (a merge of the two paths adds the same products in the same order).
pub(super) fn path_dot(a: &Path, b: &Path) -> f64 {
    let (na, nb) = (a.blocks.len(), b.blocks.len());
    // the last l blocks agree for l <= common and differ for every longer l
    let (mut common, mut beyond) = (0, na.min(nb) + 1);
    while beyond - common > 1 {
        let l = (common + beyond) / 2;
        if a.blocks[na - l] == b.blocks[nb - l] {
            common = l;
        } else {
            beyond = l;
        }
    }
    if common == 0 {
        return 0.0;
    }
    let (ia, ib) = (na - common, nb - common);
    let from = |p: &Path, k: usize| if k == 0 { 0 } else { p.ends[k - 1] };
    let (sa, sb) = (from(a, ia), from(b, ib));
    let b_values = if b.signed.is_empty() {
        &b.values
    } else {
        &b.signed
    };
    if a.values.len() - sa == common {
        // single columns (a simplicial factor): the suffix is one contiguous run
        let mut sum = 0.0;
        for (x, y) in a.values[sa..].iter().zip(&b_values[sb..]) {
            sum += x * y;
        }
        return sum;
    }
    let mut sum = 0.0;
    for k in 0..common {
        sum += a
            .segment(ia + k)
            .iter()
            .zip(b.signed_segment(ib + k))
            .map(|(x, y)| x * y)
            .sum::<f64>();
    }
    sum
}
