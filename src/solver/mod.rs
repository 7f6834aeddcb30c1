//! Sparse symmetric solves with faer: the symbolic Cholesky analysis once per topology, a
//! numeric factorization only when K* changes, back-substitutions as often as needed, and the
//! entries of K*^-1 among the contact equations from paths of the elimination tree
//! (docs/theory.md 8.6). An indefinite K* (a tangent past a limit point) is factored by
//! L D L^T and kept as L |D|^(1/2) with the signs of D, so the same tree solves serve it
//! (docs/theory.md 5a).
//!
//! The matrix is stored as its lower triangle in compressed sparse columns (`Pattern`); the
//! assembly writes into `values` through precomputed positions.

pub mod lanczos;
mod tree;

use tree::{InverseEntries, Path, TreeFactor, UNKNOWN, path_dot};

use faer::Side;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltError as LltFactorError;
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::solve_upper_triangular_in_place;
use faer::reborrow::ReborrowMut;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Accum, Par};
use rayon::prelude::*;
use std::sync::Arc;

/// The integer type of the pattern's and the symbolic factor's indices: u32 halves the
/// largest index arrays of a 1e6-DOF model (the pattern's row indices alone are 38 MB less).
/// A pattern holds fewer than 2^31 entries (checked where it is built).
pub type Ix = u32;

/// Lower-triangular CSC pattern of the free-DOF matrix.
#[derive(Debug, Clone)]
pub struct Pattern {
    pub size: usize,
    pub col_ptr: Vec<Ix>,
    pub row_idx: Vec<Ix>,
}

impl Pattern {
    /// Builds the pattern from the (free) DOF lists of the elements; `None` marks a constrained
    /// DOF. Every diagonal entry is present.
    pub fn from_elements<'a>(
        size: usize,
        elements: impl Iterator<Item = &'a [Option<usize>]>,
    ) -> Pattern {
        let mut columns: Vec<Vec<Ix>> = (0..size).map(|j| vec![j as Ix]).collect();
        for dofs in elements {
            for a in dofs.iter().flatten() {
                for b in dofs.iter().flatten() {
                    if a >= b {
                        columns[*b].push(*a as Ix);
                    }
                }
            }
        }
        for col in &mut columns {
            col.sort_unstable();
            col.dedup();
        }
        // allocated to size: grown by doubling, the largest array of the pattern held up to
        // twice its entries (58 MB too many at 1e6 DOFs)
        let nonzeros: usize = columns.iter().map(Vec::len).sum();
        assert!(
            nonzeros < 1 << 31,
            "the pattern's indices are u32: fewer than 2^31 entries"
        );
        let mut col_ptr = Vec::with_capacity(size + 1);
        let mut row_idx = Vec::with_capacity(nonzeros);
        col_ptr.push(0);
        for col in columns {
            row_idx.extend_from_slice(&col);
            col_ptr.push(row_idx.len() as Ix);
        }
        Pattern {
            size,
            col_ptr,
            row_idx,
        }
    }

    pub fn nonzeros(&self) -> usize {
        self.row_idx.len()
    }

    /// Position of entry (row, col), row >= col, in the values array.
    pub fn position(&self, row: usize, col: usize) -> Option<usize> {
        let range = self.col_ptr[col] as usize..self.col_ptr[col + 1] as usize;
        self.row_idx[range.clone()]
            .binary_search(&(row as Ix))
            .ok()
            .map(|k| range.start + k)
    }

    /// Scatter positions of one element's matrix (row-major, n x n): `usize::MAX` where the
    /// entry is skipped (constrained DOF or the upper triangle).
    pub fn scatter(&self, dofs: &[Option<usize>]) -> Vec<usize> {
        let mut positions = Vec::with_capacity(dofs.len() * dofs.len());
        for a in dofs {
            for b in dofs {
                let pos = match (a, b) {
                    (Some(i), Some(j)) if i >= j => {
                        self.position(*i, *j).expect("pattern holds the element")
                    }
                    _ => usize::MAX,
                };
                positions.push(pos);
            }
        }
        positions
    }

    /// y = K x for the symmetric matrix whose lower triangle is `values`.
    pub fn symmetric_product(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for j in 0..self.size {
            for k in self.col_ptr[j] as usize..self.col_ptr[j + 1] as usize {
                let i = self.row_idx[k] as usize;
                y[i] += values[k] * x[j];
                if i != j {
                    y[j] += values[k] * x[i];
                }
            }
        }
    }
}

#[derive(Debug, Clone, thiserror::Error)]
pub enum SolverError {
    /// Cholesky met a non-positive pivot: K* is not positive definite (buckling, a
    /// mechanism, or missing supports).
    #[error(
        "the stiffness matrix is not positive definite (pivot at free DOF {index}): a mechanism, missing supports or a buckled state"
    )]
    NotPositiveDefinite { index: usize },
    /// L D L^T met a pivot at round-off of its column's diagonal: K* is singular (a
    /// mechanism, or missing supports).
    #[error(
        "the stiffness matrix is singular (pivot at free DOF {index}): a mechanism or missing supports"
    )]
    Singular { index: usize },
    #[error("sparse factorization failed: {0}")]
    Factorization(String),
}

/// Sparse Cholesky with the symbolic analysis reused and counters for the summary.
///
/// faer's LL^T (L D L^T where asked and needed, `factor_indefinite`): the symbolic analysis
/// (AMD ordering, supernodes) once per pattern, the numeric factor in `values` once per K*.
pub struct Solver {
    /// The matrix's pattern, shared with the system that assembles it.
    pattern: Arc<Pattern>,
    /// None for an empty system (every DOF prescribed): factor and solve do nothing.
    symbolic: Option<Symbolic>,
    /// The values of L of the last successful factorization (empty: none).
    values: Vec<f64>,
    /// Where the last factorization was L D L^T (`factor_indefinite`): the signs of D, per
    /// column of the factor (`signed_root`).
    signs: Option<Vec<f64>>,
    /// The negative pivots of the last factorization (0 where L L^T succeeded).
    pub negative_pivots: usize,
    pub factorizations: usize,
    pub solves: usize,
    /// Entries of K^-1 among the equations the contact rows have named, for the current
    /// factorization.
    inverse: InverseEntries,
    /// A pivot at most this share of its column's diagonal is singular (`SINGULAR`, but
    /// within `factor_indefinite_down_to`).
    singular: f64,
    /// The last `factor_indefinite` found negative pivots: the next takes L D L^T at once
    /// (`factor_indefinite`).
    ldlt_first: bool,
}

/// The symbolic factorization and what the partial forward solves need of it.
struct Symbolic {
    cholesky: SymbolicCholesky<Ix>,
    /// The supernode of each (permuted) column (supernodal factors).
    supernode_of: Vec<usize>,
}

/// New equations of `know_inverse` from which their paths and dot products are formed in
/// parallel: a contact step names a handful, and handing a few paths of microseconds to the
/// thread pool costs more than it saves (the penetration of the plastic impact bench names
/// hundreds at once).
const PARALLEL_PATHS_FROM: usize = 32;

/// faer factors supernodally where the factorization's flops per entry of L exceed 40 times
/// this (its default: 1). The quadrilateral meshes here have small supernodes that still pay
/// below that: at 0.3, sphere_wall (2156 DOFs) factors in 1.0 ms against 2.6 ms and runs in
/// 0.87x the wall time, column_buckling 0.90x, three_rings unchanged (medians of five
/// interleaved runs); at 0 (always supernodal) three_rings' solves took 1.8x as long.
const SUPERNODAL_FROM: SupernodalThreshold = SupernodalThreshold(0.3);

impl Solver {
    pub fn new(pattern: &Arc<Pattern>) -> Result<Solver, SolverError> {
        let matrix = SymbolicSparseColMatRef::new_checked(
            pattern.size,
            pattern.size,
            &pattern.col_ptr,
            None,
            &pattern.row_idx,
        );
        let symbolic = if pattern.size == 0 {
            None
        } else {
            let cholesky = factorize_symbolic_cholesky(
                matrix,
                Side::Lower,
                SymmetricOrdering::Amd,
                CholeskySymbolicParams {
                    supernodal_flop_ratio_threshold: SUPERNODAL_FROM,
                    ..Default::default()
                },
            )
            .map_err(|e| SolverError::Factorization(format!("{e:?}")))?;
            let mut supernode_of = Vec::new();
            if let SymbolicCholeskyRaw::Supernodal(supernodal) = cholesky.raw() {
                supernode_of = vec![0; pattern.size];
                for s in 0..supernodal.n_supernodes() {
                    let (begin, end) = (
                        supernodal.supernode_begin()[s] as usize,
                        supernodal.supernode_end()[s] as usize,
                    );
                    supernode_of[begin..end].fill(s);
                }
            }
            Some(Symbolic {
                cholesky,
                supernode_of,
            })
        };
        Ok(Solver {
            pattern: Arc::clone(pattern),
            symbolic,
            values: Vec::new(),
            signs: None,
            negative_pivots: 0,
            factorizations: 0,
            solves: 0,
            inverse: InverseEntries::default(),
            singular: SINGULAR,
            ldlt_first: false,
        })
    }

    /// The pattern as faer reads it.
    fn matrix(&self) -> SymbolicSparseColMatRef<'_, Ix> {
        let p = &*self.pattern;
        // SAFETY: the same arrays passed `new_checked` in `Solver::new`, and a Pattern is
        // not changed after it is built (it is shared, immutable, behind the Arc)
        unsafe {
            SymbolicSparseColMatRef::new_unchecked(p.size, p.size, &p.col_ptr, None, &p.row_idx)
        }
    }

    /// Numeric factorization of the matrix with the given lower-triangle values, which must
    /// be positive definite (L L^T).
    pub fn factor(&mut self, values: &[f64]) -> Result<(), SolverError> {
        let start = std::time::Instant::now();
        let result = self.factor_values(values);
        crate::profile::add(crate::profile::Phase::Factorization, start);
        result
    }

    /// Numeric factorization of a symmetric matrix that may be indefinite: L L^T, and where
    /// it meets a non-positive pivot, L D L^T (`factor_ldlt`); singular where a pivot is at
    /// round-off of its column's diagonal (`singular_where`). A Newton iteration past a limit or bifurcation
    /// point, or with a perfectly plastic zone held by the supports, has such a tangent; the
    /// codes users know factor it and report the negative eigenvalues (Abaqus' "negative
    /// eigenvalues" warning).
    ///
    /// Where the last factorization found negative pivots, L D L^T is taken at once: the
    /// tangents of one Newton solve keep their inertia, and an L L^T that stops at its
    /// first non-positive pivot is work thrown away (on the finest
    /// finite-strain Shield punch, 252 factorizations, the factorization time fell by a
    /// fifth; docs/performance.md). A matrix found definite again brings back L L^T first.
    /// L D L^T without pivoting is as accurate as L L^T on a definite matrix.
    pub fn factor_indefinite(&mut self, values: &[f64]) -> Result<(), SolverError> {
        let result = if std::mem::take(&mut self.ldlt_first) {
            self.begin_factorization();
            self.timed_ldlt(values)
        } else {
            match self.factor(values) {
                Err(SolverError::NotPositiveDefinite { .. }) => self.timed_ldlt(values),
                Ok(()) => self.singular_where(values, |l| l * l),
                other => other,
            }
        };
        self.ldlt_first = result.is_ok() && self.negative_pivots > 0;
        result
    }

    /// `factor_ldlt`, its time booked as factorization.
    fn timed_ldlt(&mut self, values: &[f64]) -> Result<(), SolverError> {
        let start = std::time::Instant::now();
        let result = self.factor_ldlt(values);
        crate::profile::add(crate::profile::Phase::Factorization, start);
        result
    }

    /// Forgets the inertia of the last factorization, so that the next `factor_indefinite`
    /// tries L L^T first as a fresh solver does: at the start of a Newton solve (a resumed
    /// run then factors as the run straight through), and after an arc-length checkpoint.
    pub fn forget_inertia(&mut self) {
        self.ldlt_first = false;
    }

    /// As [`Solver::factor_indefinite`], with pivots down to `threshold` of their column's
    /// diagonal taken as they are: arc length at a limit point, where the tangent is
    /// singular and the system bordered by the arc is not (Crisfield 1981: the bordered
    /// solve stays accurate near it).
    pub fn factor_indefinite_down_to(
        &mut self,
        values: &[f64],
        threshold: f64,
    ) -> Result<(), SolverError> {
        self.singular = threshold;
        let result = self.factor_indefinite(values);
        self.singular = SINGULAR;
        result
    }

    /// Singular where a pivot of the factor in `values` (`pivot` of its column's first
    /// entry: L_jj^2 of L L^T, |D_j| of `signed_root`'s) is at most `SINGULAR` of its
    /// column's diagonal in `matrix`: a mechanism whose round-off pivot came out positive
    /// passes L L^T, and would move without bound.
    fn singular_where(
        &mut self,
        matrix: &[f64],
        pivot: impl Fn(f64) -> f64,
    ) -> Result<(), SolverError> {
        let Some(symbolic) = &self.symbolic else {
            return Ok(());
        };
        let cholesky = &symbolic.cholesky;
        let forward = cholesky.perm().map(|p| p.arrays().0);
        let original = |j: usize| forward.map_or(j, |f| f[j] as usize);
        let mut j = 0;
        let mut first = None;
        for_each_column(cholesky, &mut self.values, |entries| {
            let i = original(j);
            let diagonal = self.pattern.position(i, i).map_or(0.0, |k| matrix[k].abs());
            if first.is_none() && pivot(entries[0]) <= self.singular * diagonal {
                first = Some(i);
            }
            j += 1;
        });
        match first {
            Some(index) => {
                self.values.clear();
                Err(SolverError::Singular { index })
            }
            None => Ok(()),
        }
    }

    /// L D L^T of `values`, stored as L |D|^(1/2) with the signs of D beside it
    /// (`signed_root`); singular where a pivot is round-off (`singular_where`).
    fn factor_ldlt(&mut self, values: &[f64]) -> Result<(), SolverError> {
        let mut factor = std::mem::take(&mut self.values);
        let Some(symbolic) = &self.symbolic else {
            return Ok(());
        };
        let cholesky = &symbolic.cholesky;
        sized(&mut factor, cholesky.len_val())?;
        let par = faer::get_global_parallelism();
        let scratch = cholesky.factorize_numeric_ldlt_scratch::<f64>(par, Default::default());
        let mut buffer = workspace(scratch)?;
        let a = SparseColMatRef::new(self.matrix(), values);
        cholesky
            .factorize_numeric_ldlt::<f64>(
                &mut factor,
                a,
                Side::Lower,
                LdltRegularization::default(),
                par,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map_err(|e| {
                // (faer's index may be one past the last column)
                let faer::linalg::cholesky::ldlt::factor::LdltError::ZeroPivot { index } = e;
                let index = index.min(cholesky.nrows() - 1);
                let index = cholesky
                    .perm()
                    .map_or(index, |p| p.arrays().0[index] as usize);
                SolverError::Singular { index }
            })?;
        let signs = signed_root(cholesky, &mut factor);
        self.values = factor;
        // L~'s diagonal is |D|^(1/2)
        self.singular_where(values, |root| root * root)?;
        self.negative_pivots = signs.iter().filter(|s| **s < 0.0).count();
        self.signs = Some(signs);
        Ok(())
    }

    /// A new factorization begins: the last one's inverse entries, signs and negative
    /// pivots go, and it is counted.
    fn begin_factorization(&mut self) {
        self.inverse.clear();
        self.signs = None;
        self.negative_pivots = 0;
        self.factorizations += 1;
    }

    fn factor_values(&mut self, values: &[f64]) -> Result<(), SolverError> {
        // the last factor's buffer is reused (one factor in memory at a time); it is left
        // empty, i.e. not factored, until the new factorization succeeds
        let mut factor = std::mem::take(&mut self.values);
        self.begin_factorization();
        let Some(symbolic) = &self.symbolic else {
            return Ok(());
        };
        let cholesky = &symbolic.cholesky;
        sized(&mut factor, cholesky.len_val())?;
        let par = faer::get_global_parallelism();
        let scratch = cholesky.factorize_numeric_llt_scratch::<f64>(par, Default::default());
        let mut buffer = workspace(scratch)?;
        let a = SparseColMatRef::new(self.matrix(), values);
        cholesky
            .factorize_numeric_llt::<f64>(
                &mut factor,
                a,
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map_err(|LltFactorError::NonPositivePivot { index }| {
                // faer's index is the permuted column's: the equation is its image
                let index = index.min(cholesky.nrows() - 1);
                let index = cholesky
                    .perm()
                    .map_or(index, |p| p.arrays().0[index] as usize);
                SolverError::NotPositiveDefinite { index }
            })?;
        self.values = factor;
        Ok(())
    }

    /// Whether a factorization is at hand (an empty system counts as factored once factored).
    pub fn is_factored(&self) -> bool {
        !self.values.is_empty() || (self.symbolic.is_none() && self.factorizations > 0)
    }

    /// Makes the entries of K^-1 among `equations` (and those named before) available to
    /// `inverse_local` / `inverse_entry`: a forward solve along its elimination-tree path per
    /// equation not seen since the last factorization, and its dot products with the others.
    pub fn know_inverse(&mut self, equations: &[usize]) {
        let mut new: Vec<usize> = equations
            .iter()
            .copied()
            .filter(|eq| self.inverse.local(*eq).is_none())
            .collect();
        new.sort_unstable();
        new.dedup();
        if new.is_empty() {
            return;
        }
        let Some(factor) = self.tree() else {
            return;
        };
        let start = std::time::Instant::now();
        let inverse_perm = self.permutation().map(|p| p.arrays().1);
        let signs = self.signs.as_deref();
        let path = |(work, below, grown): &mut (Vec<f64>, Vec<f64>, Path), eq: usize| {
            let row = inverse_perm.map_or(eq, |inv| inv[eq] as usize);
            let mut path = forward_path(factor, row, work, below, grown);
            if let Some(signs) = signs {
                path.sign(factor, signs);
            }
            path
        };
        let scratch = || (vec![0.0; self.pattern.size], Vec::new(), Path::default());
        let paths: Vec<Path> = if new.len() >= PARALLEL_PATHS_FROM {
            new.par_iter()
                .map_init(scratch, |s, &eq| path(s, eq))
                .collect()
        } else {
            let mut s = scratch();
            new.iter().map(|&eq| path(&mut s, eq)).collect()
        };
        if self.inverse.local.len() < self.pattern.size {
            self.inverse.local.resize(self.pattern.size, UNKNOWN);
        }
        for (eq, path) in new.into_iter().zip(paths) {
            let k = self.inverse.equations.len();
            self.inverse.local[eq] = k as u32;
            self.inverse.equations.push(eq);
            self.inverse.paths.push(path);
        }
        // the rows of the new equations: dot products with every equation known
        let first = self.inverse.lower.len();
        let paths = &self.inverse.paths;
        let row = |k: usize| (0..=k).map(|j| path_dot(&paths[k], &paths[j])).collect();
        let rows: Vec<Vec<f64>> = if paths.len() - first >= PARALLEL_PATHS_FROM {
            (first..paths.len()).into_par_iter().map(row).collect()
        } else {
            (first..paths.len()).map(row).collect()
        };
        self.inverse.lower.extend(rows);
        crate::profile::add(crate::profile::Phase::Solve, start);
    }

    /// The local index of an equation made known by `know_inverse`.
    pub fn inverse_local(&self, equation: usize) -> usize {
        self.inverse
            .local(equation)
            .expect("an equation named to know_inverse")
    }

    /// (K^-1)_{ab} for local indices a, b from `inverse_local`.
    pub fn inverse_entry(&self, a: usize, b: usize) -> f64 {
        if a <= b {
            self.inverse.lower[b][a]
        } else {
            self.inverse.lower[a][b]
        }
    }

    /// Solves in place with the current factorization: a back-substitution, `forward` then
    /// `backward`.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        let w = self.forward(rhs);
        let x = self.backward(w);
        rhs.copy_from_slice(&x);
    }

    /// The fill-reducing permutation P (None: the identity, or an empty system).
    fn permutation(&self) -> Option<faer::perm::PermRef<'_, Ix>> {
        self.symbolic.as_ref().and_then(|s| s.cholesky.perm())
    }

    /// The tree view of the current factor (None: an empty system).
    fn tree(&self) -> Option<TreeFactor<'_>> {
        let symbolic = self.symbolic.as_ref()?;
        assert!(!self.values.is_empty(), "solve after a successful factor");
        Some(match symbolic.cholesky.raw() {
            SymbolicCholeskyRaw::Supernodal(supernodal) => TreeFactor::Supernodal(
                SupernodalLltRef::new(supernodal, &self.values),
                &symbolic.supernode_of,
            ),
            SymbolicCholeskyRaw::Simplicial(simplicial) => {
                TreeFactor::Simplicial(simplicial, &self.values)
            }
        })
    }

    /// The first half of a back-substitution: w = L^-1 P r. With `solution_entry`,
    /// `add_unit` and `backward` it solves with constraints in one back-substitution:
    /// ```text
    /// (K^-1 r)_a = y_a . w                  (y_a = L^-1 P e_a, from know_inverse)
    /// K^-1 (r + sum_a v_a e_a) = P^T L^-T (w + sum_a v_a y_a)
    /// ```
    /// (with S between: y_a . S w and P^T L~^-T S (...) for an indefinite matrix's factor,
    /// `signed_root`).
    pub fn forward(&self, rhs: &[f64]) -> Forward {
        let start = std::time::Instant::now();
        let mut x = match self.permutation() {
            Some(perm) => perm.arrays().0.iter().map(|&i| rhs[i as usize]).collect(),
            None => rhs.to_vec(),
        };
        if let Some(factor) = self.tree() {
            let mut below = Vec::new();
            for block in 0..factor.blocks() {
                factor.forward_block(block, &mut x, &mut below);
            }
        }
        crate::profile::add(crate::profile::Phase::Solve, start);
        Forward(x)
    }

    /// (K^-1 r)_eq for the w of r and an equation made known by `know_inverse`.
    pub fn solution_entry(&self, w: &Forward, equation: usize) -> f64 {
        let path = &self.inverse.paths[self.inverse_local(equation)];
        let factor = self.tree().expect("equations known: a factor at hand");
        (0..path.blocks.len())
            .map(|k| {
                let w = &w.0[factor.columns(path.blocks[k])];
                let y = path.signed_segment(k);
                y.iter().zip(w).map(|(a, b)| a * b).sum::<f64>()
            })
            .sum()
    }

    /// w += value y_eq: the backward solve then adds value K^-1 e_eq.
    pub fn add_unit(&self, w: &mut Forward, equation: usize, value: f64) {
        let path = &self.inverse.paths[self.inverse_local(equation)];
        let factor = self.tree().expect("equations known: a factor at hand");
        for (block, y) in path.segments() {
            for (x, y) in w.0[factor.columns(block)].iter_mut().zip(y) {
                *x += value * y;
            }
        }
    }

    /// The second half of the back-substitution: P^T L^-T w (P^T L~^-T S w of an indefinite
    /// matrix's factor, `signed_root`).
    pub fn backward(&mut self, w: Forward) -> Vec<f64> {
        self.solves += 1;
        let start = std::time::Instant::now();
        let mut x = w.0;
        if let Some(signs) = &self.signs {
            x.iter_mut().zip(signs).for_each(|(v, s)| *v *= s);
        }
        match self.tree() {
            Some(TreeFactor::Simplicial(symbolic, values)) => {
                let (col_ptr, row_idx) = (symbolic.col_ptr(), symbolic.row_idx());
                for j in (0..x.len()).rev() {
                    let mut xj = x[j];
                    for k in col_ptr[j] as usize + 1..col_ptr[j + 1] as usize {
                        xj -= values[k] * x[row_idx[k] as usize];
                    }
                    x[j] = xj / values[col_ptr[j] as usize];
                }
            }
            Some(TreeFactor::Supernodal(factor, _)) => {
                let mut below = Vec::new();
                for s in (0..factor.symbolic().n_supernodes()).rev() {
                    let node = factor.supernode(s);
                    let (l, pattern) = (node.val(), node.pattern());
                    let (begin, size) = (node.start(), l.ncols());
                    let (l_top, l_bottom) = l.split_at_row(size);
                    below.clear();
                    below.extend(pattern.iter().map(|r| x[*r as usize]));
                    let product = faer::MatRef::from_column_major_slice(&below, pattern.len(), 1);
                    let mut x_top = faer::MatMut::from_column_major_slice_mut(
                        &mut x[begin..begin + size],
                        size,
                        1,
                    );
                    matmul(
                        x_top.rb_mut(),
                        Accum::Add,
                        l_bottom.transpose(),
                        product,
                        -1.0,
                        Par::Seq,
                    );
                    solve_upper_triangular_in_place(l_top.transpose(), x_top.rb_mut(), Par::Seq);
                }
            }
            None => {}
        }
        let out = match self.permutation() {
            Some(perm) => perm.arrays().1.iter().map(|&i| x[i as usize]).collect(),
            None => x,
        };
        crate::profile::add(crate::profile::Phase::Solve, start);
        out
    }
}

/// Sizes `factor` to `len` entries, keeping its allocation where it is large enough (one
/// factor in memory at a time). A factor of that length already (the last one's) is kept as
/// it is: faer's numeric factorizations write every entry of L (the supernodal ones zero
/// them first themselves, the simplicial ones write each entry of the pattern), so zeroing
/// it here was a second pass over the whole factor at every factorization.
fn sized(factor: &mut Vec<f64>, len: usize) -> Result<(), SolverError> {
    if factor.len() == len {
        return Ok(());
    }
    factor.clear();
    factor
        .try_reserve_exact(len)
        .map_err(|_| SolverError::Factorization("out of memory for the factor".into()))?;
    factor.resize(len, 0.0);
    Ok(())
}

/// The workspace a numeric factorization asks for.
fn workspace(scratch: faer::dyn_stack::StackReq) -> Result<MemBuffer, SolverError> {
    MemBuffer::try_new(scratch)
        .map_err(|_| SolverError::Factorization("out of memory for the workspace".into()))
}

/// A pivot of L D L^T at most this share of its column's diagonal is round-off: the matrix
/// is singular there. A mechanism's pivot is ~1e-16 of the diagonal times the growth of the
/// elimination (1e-13 on the meshes here); a stiff structure's smallest legitimate ratio is
/// far above it (nearly incompressible elements without B-bar: 1 - 2 nu ~ 2e-4).
const SINGULAR: f64 = 1e-11;

/// Turns faer's L D L^T (unit L, D on its diagonal) in `factor` into L |D|^(1/2), a lower
/// triangle with a positive diagonal like L L^T's, so that the tree solves serve both:
/// ```text
/// K = L D L^T = L~ S L~^T,   L~ = L |D|^(1/2),   S = sign(D)
/// K^-1 = P^T L~^-T S L~^-1 P,    (K^-1)_ab = y_a . S y_b
/// ```
/// Returns the signs, per (permuted) column.
fn signed_root(cholesky: &SymbolicCholesky<Ix>, factor: &mut [f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(cholesky.nrows());
    for_each_column(cholesky, factor, |entries| {
        let d = entries[0];
        let root = d.abs().sqrt();
        entries[0] = root;
        entries[1..].iter_mut().for_each(|v| *v *= root);
        out.push(if d < 0.0 { -1.0 } else { 1.0 });
    });
    out
}

/// Calls `f` with each (permuted) column of the factor's lower triangle in order, its
/// diagonal entry first, then the entries below it.
fn for_each_column(
    cholesky: &SymbolicCholesky<Ix>,
    factor: &mut [f64],
    mut f: impl FnMut(&mut [f64]),
) {
    match cholesky.raw() {
        SymbolicCholeskyRaw::Simplicial(simplicial) => {
            let col_ptr = simplicial.col_ptr();
            for j in 0..simplicial.nrows() {
                f(&mut factor[col_ptr[j] as usize..col_ptr[j + 1] as usize]);
            }
        }
        SymbolicCholeskyRaw::Supernodal(supernodal) => {
            let ptr = supernodal.col_ptr_for_val();
            for s in 0..supernodal.n_supernodes() {
                let size =
                    (supernodal.supernode_end()[s] - supernodal.supernode_begin()[s]) as usize;
                let block = &mut factor[ptr[s] as usize..ptr[s + 1] as usize];
                let rows = block.len() / size;
                // column-major: column c's diagonal entry is at row c
                for c in 0..size {
                    f(&mut block[c * rows + c..(c + 1) * rows]);
                }
            }
        }
    }
}

/// w = L^-1 P r of `Solver::forward`, in the factor's (permuted) order.
pub struct Forward(Vec<f64>);

/// y = L^-1 e_row along the elimination-tree path from `row`'s block (supernode, or column
/// of a simplicial factor) to the root, as (block, its segment of y) in path order: the
/// forward solve's block steps on that path only (e_row is zero before it). `work` is zero
/// on entry and on return; `below` and `path` are scratch: the path is grown there (its
/// length is not known before the walk) and returned as a copy of its exact size.
fn forward_path(
    factor: TreeFactor<'_>,
    row: usize,
    work: &mut [f64],
    below: &mut Vec<f64>,
    path: &mut Path,
) -> Path {
    path.blocks.clear();
    path.ends.clear();
    path.values.clear();
    work[row] = 1.0;
    let mut block = Some(factor.block_of(row));
    while let Some(b) = block {
        block = factor.forward_block(b, work, below);
        let segment = &mut work[factor.columns(b)];
        path.blocks.push(b);
        path.values.extend_from_slice(segment);
        path.ends.push(path.values.len());
        segment.fill(0.0);
    }
    Path {
        blocks: path.blocks.clone(),
        ends: path.ends.clone(),
        values: path.values.clone(),
        signed: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1D chain of springs: K = tridiag(-1, 2, -1), K x = b solved exactly.
    #[test]
    fn spring_chain_solves_exactly() {
        let n = 50;
        let elements: Vec<Vec<Option<usize>>> = (0..=n)
            .map(|e: usize| vec![e.checked_sub(1), if e < n { Some(e) } else { None }])
            .collect();
        let pattern = Pattern::from_elements(n, elements.iter().map(|e| e.as_slice()));
        let mut values = vec![0.0; pattern.nonzeros()];
        for dofs in &elements {
            let k = [1.0, -1.0, -1.0, 1.0];
            for (p, v) in pattern.scatter(dofs).iter().zip(k) {
                if *p != usize::MAX {
                    values[*p] += v;
                }
            }
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).sin()).collect();
        let mut b = vec![0.0; n];
        pattern.symmetric_product(&values, &x, &mut b);
        let mut solver = Solver::new(&Arc::new(pattern.clone())).unwrap();
        solver.factor(&values).unwrap();
        solver.solve(&mut b);
        for (xi, bi) in x.iter().zip(&b) {
            approx::assert_abs_diff_eq!(xi, bi, epsilon = 1e-12);
        }
    }

    /// The largest error of `know_inverse`'s entries among `named` (in two groups, as
    /// contact rows grow) against whole solves K^-1 e_a, and the largest entry.
    fn inverse_errors(solver: &mut Solver, size: usize, named: &[usize]) -> (f64, f64) {
        let (first, second) = named.split_at(named.len() / 2);
        solver.know_inverse(first);
        solver.know_inverse(second);
        solver.know_inverse(&first[..1]);
        let (mut largest, mut worst): (f64, f64) = (0.0, 0.0);
        for &a in named {
            let mut column = vec![0.0; size];
            column[a] = 1.0;
            solver.solve(&mut column);
            for &b in named {
                let entry = solver.inverse_entry(solver.inverse_local(a), solver.inverse_local(b));
                largest = largest.max(column[b].abs());
                worst = worst.max((entry - column[b]).abs());
            }
        }
        (worst, largest)
    }

    fn is_supernodal(solver: &Solver) -> bool {
        let symbolic = solver.symbolic.as_ref().unwrap();
        matches!(symbolic.cholesky.raw(), SymbolicCholeskyRaw::Supernodal(_))
    }

    /// A 2-DOF-per-node nx x ny node grid with the Quad4 pattern, SPD by diagonal dominance
    /// with varying off-diagonals.
    fn grid(nx: usize, ny: usize) -> (Pattern, Vec<f64>) {
        let node = |i: usize, j: usize| j * nx + i;
        let elements: Vec<Vec<Option<usize>>> = (0..ny - 1)
            .flat_map(|j| (0..nx - 1).map(move |i| (i, j)))
            .map(|(i, j)| {
                [
                    node(i, j),
                    node(i + 1, j),
                    node(i + 1, j + 1),
                    node(i, j + 1),
                ]
                .iter()
                .flat_map(|n| [Some(2 * n), Some(2 * n + 1)])
                .collect()
            })
            .collect();
        let size = 2 * nx * ny;
        let pattern = Pattern::from_elements(size, elements.iter().map(|e| e.as_slice()));
        let mut values = vec![0.0; pattern.nonzeros()];
        for j in 0..size {
            for k in pattern.col_ptr[j] as usize..pattern.col_ptr[j + 1] as usize {
                let i = pattern.row_idx[k] as usize;
                values[k] = if i == j {
                    20.0 + (j % 7) as f64
                } else {
                    -0.5 - 0.4 * ((i * 31 + j * 17) % 5) as f64 / 5.0
                };
            }
        }
        (pattern, values)
    }

    /// Goal: an indefinite matrix (a tangent past a limit point) is factored by L D L^T and
    /// solved, its inverse entries along the tree paths carry the signs of D, its negative
    /// pivots count its negative eigenvalues (Sylvester's law of inertia), and a singular
    /// one is refused. Setup: the grids of `inverse_entries_from_tree_paths_match_whole_solves`
    /// (supernodal and simplicial factors) with their diagonal shifted down by 21.5, between
    /// the grid's diagonal entries (20 to 26), so that K has negative and positive
    /// eigenvalues; a 2-spring chain with a free end's mode (singular). References: the
    /// residual K x - r from the pattern (`symmetric_product`); whole solves K^-1 e_a; the
    /// eigenvalues of the dense matrix (nalgebra's symmetric eigen-decomposition).
    /// Tolerances: the residual 1e-9 of |r| (L D L^T without pivoting has no bound on the
    /// growth of its pivots: 2e-11 on the larger grid, against 1e-15 for L L^T); the
    /// inverse entries 1e-10 of the largest (the shift brings an eigenvalue near 0: K^-1's
    /// entries are large and their forward errors grow with the condition number).
    #[test]
    fn indefinite_matrices_are_factored_with_their_inertia() {
        let mut kinds = Vec::new();
        for (nx, ny) in [(9, 7), (201, 101)] {
            let (pattern, mut values) = grid(nx, ny);
            let size = pattern.size;
            for j in 0..size {
                values[pattern.position(j, j).unwrap()] -= 21.5;
            }
            let mut solver = Solver::new(&Arc::new(pattern.clone())).unwrap();
            assert!(solver.factor(&values).is_err(), "L L^T refuses it");
            solver.factor_indefinite(&values).unwrap();
            kinds.push(is_supernodal(&solver));
            let x: Vec<f64> = (0..size).map(|i| (i as f64 * 0.7).cos()).collect();
            let mut r = vec![0.0; size];
            pattern.symmetric_product(&values, &x, &mut r);
            let mut solved = r.clone();
            solver.solve(&mut solved);
            let mut back = vec![0.0; size];
            pattern.symmetric_product(&values, &solved, &mut back);
            let (residual, scale) = back
                .iter()
                .zip(&r)
                .fold((0.0f64, 0.0f64), |(m, s), (a, b)| {
                    (m.max((a - b).abs()), s.max(b.abs()))
                });
            assert!(
                residual < 1e-9 * scale,
                "{nx} x {ny}: residual {residual} of {scale}"
            );
            let named: Vec<usize> = (0..12).map(|k| (k * 37 + 5) % size).collect();
            let (worst, largest) = inverse_errors(&mut solver, size, &named);
            assert!(
                worst <= 1e-10 * largest,
                "{nx} x {ny}: {worst} against {largest}"
            );
            if size <= 200 {
                let mut dense = nalgebra::DMatrix::<f64>::zeros(size, size);
                for j in 0..size {
                    for k in pattern.col_ptr[j] as usize..pattern.col_ptr[j + 1] as usize {
                        let i = pattern.row_idx[k] as usize;
                        dense[(i, j)] = values[k];
                        dense[(j, i)] = values[k];
                    }
                }
                let eigen = dense.symmetric_eigenvalues();
                let negative = eigen.iter().filter(|l| **l < 0.0).count();
                assert!(negative > 0 && negative < size, "{negative}");
                assert_eq!(solver.negative_pivots, negative);
            }
        }
        assert!(kinds.contains(&true) && kinds.contains(&false), "{kinds:?}");
        // two springs in a chain, the far end free and nothing holding the first node's
        // neighbour: K = [[1, -1], [-1, 1]] has the rigid mode (1, 1)
        let elements = [vec![Some(0), Some(1)]];
        let pattern = Pattern::from_elements(2, elements.iter().map(|e| e.as_slice()));
        let mut values = vec![0.0; pattern.nonzeros()];
        for (p, v) in pattern
            .scatter(&elements[0])
            .iter()
            .zip([1.0, -1.0, -1.0, 1.0])
        {
            if *p != usize::MAX {
                values[*p] += v;
            }
        }
        let mut solver = Solver::new(&Arc::new(pattern)).unwrap();
        assert!(matches!(
            solver.factor_indefinite(&values),
            Err(SolverError::Singular { .. })
        ));
    }

    /// Goal: the entries of K^-1 from the partial forward solves along the elimination tree
    /// (`know_inverse`) are those of whole back-substitutions K^-1 e_a, for supernodal and
    /// for simplicial factors (faer picks by the flop count).
    /// Setup: Quad4-pattern grids of 31 x 13 and 201 x 101 nodes (2 DOFs each) and a diagonal
    /// matrix; 40 equations (6 for the diagonal) named in two groups, one again.
    /// Reference: solve(e_a) read at every named b. Tolerance: 1e-12 relative to the
    /// largest entry (two orders of summation).
    #[test]
    fn inverse_entries_from_tree_paths_match_whole_solves() {
        let mut kinds = Vec::new();
        for (nx, ny) in [(31, 13), (201, 101)] {
            let (pattern, values) = grid(nx, ny);
            let size = pattern.size;
            let mut solver = Solver::new(&Arc::new(pattern.clone())).unwrap();
            solver.factor(&values).unwrap();
            kinds.push(is_supernodal(&solver));
            let named: Vec<usize> = (0..20)
                .map(|k| (k * 37) % size)
                .chain((0..20).map(|k| (k * 53 + 11) % size))
                .collect();
            let (worst, largest) = inverse_errors(&mut solver, size, &named);
            assert!(largest > 0.01, "{largest}");
            assert!(
                worst <= 1e-12 * largest,
                "{nx} x {ny}: {worst} against {largest}"
            );
        }
        let n = 12;
        let singles: Vec<[Option<usize>; 1]> = (0..n).map(|i| [Some(i)]).collect();
        let diagonal = Pattern::from_elements(n, singles.iter().map(|e| e.as_slice()));
        let values: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        let mut solver = Solver::new(&Arc::new(diagonal.clone())).unwrap();
        solver.factor(&values).unwrap();
        kinds.push(is_supernodal(&solver));
        let (worst, largest) = inverse_errors(&mut solver, n, &[0, 3, 7, 11, 5, 2]);
        assert_eq!(largest, 1.0);
        assert!(worst <= 1e-15, "{worst}");
        assert!(kinds.contains(&true) && kinds.contains(&false), "{kinds:?}");
    }

    /// Goal: a back-substitution (`forward` then `backward`) solves K x = r, and the
    /// constrained solve in one back-substitution (`solution_entry`, `add_unit` between the
    /// halves) gives (K^-1 r)_a and K^-1 (r + v e_a) (the identities of `Solver::forward`).
    /// Setup: the two grids and a diagonal matrix of the test above (supernodal and
    /// simplicial factors), r with all entries distinct, 5 named equations.
    /// Reference: the residual K x - r computed from the pattern (`symmetric_product`), and
    /// the solves so checked. Tolerance: 1e-12 relative to the largest entry (the residual:
    /// 1e-12 of |r|, K being well conditioned by diagonal dominance).
    #[test]
    fn forward_and_backward_halves_solve_with_constraints_in_one_back_substitution() {
        let singles: Vec<[Option<usize>; 1]> = (0..12).map(|i| [Some(i)]).collect();
        let diagonal = Pattern::from_elements(12, singles.iter().map(|e| e.as_slice()));
        let cases = [
            grid(31, 13),
            grid(201, 101),
            (diagonal, (0..12).map(|i| 1.0 + i as f64).collect()),
        ];
        for (pattern, values) in cases {
            let n = pattern.size;
            let mut solver = Solver::new(&Arc::new(pattern.clone())).unwrap();
            solver.factor(&values).unwrap();
            let r: Vec<f64> = (0..n)
                .map(|i| ((i * 7919) % 101) as f64 / 101.0 - 0.3)
                .collect();
            let named: Vec<usize> = (0..5).map(|k| (k * 97 + 5) % n).collect();
            solver.know_inverse(&named);
            let mut whole = r.clone();
            solver.solve(&mut whole);
            let mut product = vec![0.0; n];
            pattern.symmetric_product(&values, &whole, &mut product);
            let residual = product
                .iter()
                .zip(&r)
                .fold(0.0f64, |m, (p, r)| m.max((p - r).abs()));
            assert!(residual <= 1e-12, "{n} DOFs: |K x - r| = {residual}");
            let scale = whole.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let close =
                |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-12 * scale);
            let w = solver.forward(&r);
            for &a in &named {
                assert!((solver.solution_entry(&w, a) - whole[a]).abs() <= 1e-12 * scale);
            }
            assert!(close(&solver.backward(w), &whole));
            let (a, v) = (named[2], 0.75);
            let mut shifted = r.clone();
            shifted[a] += v;
            solver.solve(&mut shifted);
            let mut w = solver.forward(&r);
            solver.add_unit(&mut w, a, v);
            assert!(close(&solver.backward(w), &shifted));
        }
    }
}
