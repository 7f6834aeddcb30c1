//! The buckling check (Erklig, Guzelbey & Cevik 2010, section 2.1.3; docs/theory.md section
//! 8.4): the inertia of the tangent without mass, and the linearized eigen-buckling problem at
//! a converged state.
//!
//! Legend
//! ```text
//! K_T        tangent stiffness at the committed state (d = 0): K_0 + K_sigma, free DOFs
//! K_0        material part, sum w B^T D B                      (Erklig et al. 2010, eq 33)
//! K_sigma    geometric part from the current stresses, sum w G^T S G               (eq 34)
//! inertia    number of negative pivots of K_T = L D L^T (= negative eigenvalues, Sylvester)
//! lambda     load factor of (K_0 + lambda K_sigma) phi = 0: the current stresses times
//!            lambda make the tangent singular; lambda_cr = the smallest positive one
//! mu         1 / lambda, eigenvalue of A = K_0^-1 (-K_sigma), self-adjoint in <x, y> = x^T K_0 y
//! ```
//! The matrices are always assembled with nonlinear kinematics at d = 0 (a small-strain run
//! still has stresses, and K_sigma is what they do to the stiffness of the current shape).
//! K_sigma is the difference of the assembled `elastic_geometric` and `elastic` tangents, so
//! it holds exactly the geometric terms; K_0 = K_T - K_sigma carries the material tangent.
//!
//! Eigen-solver: Lanczos with full (twice repeated) K_0-orthogonalization on the factored
//! sparse K_0 (shift-invert at zero: the buckling modes are the largest mu, which Lanczos
//! finds first), the Ritz values of the tridiagonal matrix accepted when their residual
//! estimate beta_m |s_m,i| is below 1e-10 mu_i.

use crate::assembly::{self, ElementFailure, State, StepIncrement, System};
use crate::element::Strain;
use crate::scene::Model;
use crate::scene::spec::Tangent;
use crate::solver::lanczos::{start_vector, tridiagonal_eigen};
use crate::solver::{Ix, Pattern, Solver, SolverError};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Par, Side};

#[derive(Debug, thiserror::Error)]
pub enum BucklingError {
    #[error("{0}")]
    Element(#[from] ElementFailure),
    #[error("{0}")]
    Solver(#[from] SolverError),
    /// K_0 itself is not positive definite: supports missing, or the material has softened.
    #[error(
        "the material stiffness K_0 is not positive definite (missing supports?): the linearized buckling problem needs it factored"
    )]
    MaterialStiffness,
    /// No positive lambda: the stresses stiffen every mode (tension) or the mesh is empty.
    #[error("no buckling mode: the current stresses do not destabilize the model")]
    NoMode,
}

/// Counts the negative pivots of a symmetric matrix with the pattern of a [`System`] by a
/// sparse simplicial L D L^T (AMD ordering, no pivoting, no regularization). The symbolic
/// analysis is done once.
pub struct InertiaCounter {
    matrix: SymbolicSparseColMat<Ix>,
    symbolic: Option<SymbolicCholesky<Ix>>,
    factor: Vec<f64>,
}

impl InertiaCounter {
    pub fn new(pattern: &Pattern) -> Result<InertiaCounter, SolverError> {
        let matrix = SymbolicSparseColMat::new_checked(
            pattern.size,
            pattern.size,
            pattern.col_ptr.clone(),
            None,
            pattern.row_idx.clone(),
        );
        let symbolic = if pattern.size == 0 {
            None
        } else {
            Some(
                factorize_symbolic_cholesky(
                    matrix.as_ref(),
                    Side::Lower,
                    SymmetricOrdering::Amd,
                    CholeskySymbolicParams {
                        // the simplicial factor keeps D as the first entry of each column
                        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
                        ..Default::default()
                    },
                )
                .map_err(|e| SolverError::Factorization(format!("{e:?}")))?,
            )
        };
        let len = symbolic.as_ref().map_or(0, |s| s.len_val());
        Ok(InertiaCounter {
            matrix,
            symbolic,
            factor: vec![0.0; len],
        })
    }

    /// The number of negative pivots of the matrix whose lower triangle is `values`. A zero
    /// pivot (exactly singular) is an error.
    pub fn negative_pivots(&mut self, values: &[f64]) -> Result<usize, SolverError> {
        let Some(symbolic) = &self.symbolic else {
            return Ok(0);
        };
        let a = SparseColMatRef::new(self.matrix.as_ref(), values);
        let par = Par::Seq;
        let mut buffer =
            MemBuffer::new(symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()));
        symbolic
            .factorize_numeric_ldlt(
                &mut self.factor,
                a,
                Side::Lower,
                LdltRegularization::default(),
                par,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map_err(|e| SolverError::Factorization(format!("L D L^T: {e:?}")))?;
        let SymbolicCholeskyRaw::Simplicial(simplicial) = symbolic.raw() else {
            unreachable!("the analysis forces the simplicial factor")
        };
        let col_ptr = simplicial.col_ptr();
        let count = (0..symbolic.nrows())
            .filter(|&j| self.factor[col_ptr[j] as usize] < 0.0)
            .count();
        Ok(count)
    }

    /// The eigenvector of the matrix last counted (`negative_pivots`) whose eigenvalue lies
    /// nearest zero, by `iterations` steps of inverse iteration on its L D L^T factor (each
    /// step divides the other eigenvectors' shares by their eigenvalue's ratio to the
    /// nearest one), normalized to unit length; None for an empty matrix. Where the count
    /// has just changed, that eigenvalue is the one that crossed zero, and its vector is the
    /// critical mode.
    pub fn nearly_null(&self, iterations: usize) -> Option<Vec<f64>> {
        let symbolic = self.symbolic.as_ref()?;
        let n = symbolic.nrows();
        let factor = faer::sparse::linalg::cholesky::LdltRef::new(symbolic, &self.factor);
        let mut buffer = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        let mut x = start_vector(n);
        for _ in 0..iterations {
            let rhs = faer::MatMut::from_column_major_slice_mut(&mut x, n, 1);
            factor.solve_in_place_with_conj(
                faer::Conj::No,
                rhs,
                Par::Seq,
                MemStack::new(&mut buffer),
            );
            let norm = dot(&x, &x).sqrt();
            if !(norm > 0.0 && norm.is_finite()) {
                return None;
            }
            x.iter_mut().for_each(|v| *v /= norm);
        }
        Some(x)
    }
}

/// K_T of the committed state (d = 0) into `system.values`.
pub fn assemble_tangent(
    model: &Model,
    state: &State,
    system: &mut System,
) -> Result<(), ElementFailure> {
    let zero = vec![0.0; model.dofs()];
    assembly::evaluate(
        model,
        state,
        StepIncrement {
            d: &zero,
            dt: f64::INFINITY,
            geometry: Strain::Finite,
        },
        Some(system),
        Tangent::Consistent,
    )?;
    Ok(())
}

/// (K_0, K_sigma) of the committed state, lower-triangle values on `system.pattern`.
pub fn stiffness_parts(
    model: &Model,
    state: &State,
    system: &mut System,
) -> Result<(Vec<f64>, Vec<f64>), ElementFailure> {
    let zero = vec![0.0; model.dofs()];
    let mut assemble = |tangent| {
        assembly::evaluate(
            model,
            state,
            StepIncrement {
                d: &zero,
                dt: f64::INFINITY,
                geometry: Strain::Finite,
            },
            Some(&mut *system),
            tangent,
        )
        .map(|_| system.values.clone())
    };
    let full = assemble(Tangent::Consistent)?;
    let elastic = assemble(Tangent::Elastic)?;
    let geometric = assemble(Tangent::ElasticGeometric)?;
    let k_sigma: Vec<f64> = geometric.iter().zip(&elastic).map(|(g, e)| g - e).collect();
    let k_0 = full.iter().zip(&k_sigma).map(|(t, s)| t - s).collect();
    Ok((k_0, k_sigma))
}

/// One buckling mode: the load factor and the mode shape over all DOFs (constrained DOFs
/// zero), scaled so its largest nodal displacement is 1.
#[derive(Debug, Clone)]
pub struct Mode {
    pub lambda: f64,
    pub shape: Vec<f64>,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The lowest `count` positive load factors of (K_0 + lambda K_sigma) phi = 0 at the
/// committed state, ascending. Fewer are returned when fewer converge; none (an error) when
/// no mu = 1 / lambda exceeds 1e-8 of the largest |mu| (tension everywhere).
pub fn eigen_buckling(
    model: &Model,
    state: &State,
    system: &mut System,
    count: usize,
) -> Result<Vec<Mode>, BucklingError> {
    let (k_0, k_sigma) = stiffness_parts(model, state, system)?;
    let pattern = &system.pattern;
    let n = pattern.size;
    if n == 0 || count == 0 {
        return Err(BucklingError::NoMode);
    }
    let mut solver = Solver::new(pattern)?;
    solver.factor(&k_0).map_err(|e| match e {
        SolverError::NotPositiveDefinite { .. } => BucklingError::MaterialStiffness,
        other => BucklingError::Solver(other),
    })?;
    let mut operator = Operator {
        pattern,
        k_0: &k_0,
        k_sigma: &k_sigma,
        solver,
        product: vec![0.0; n],
    };
    let converged = lanczos(&mut operator, count);
    if converged.is_empty() {
        return Err(BucklingError::NoMode);
    }
    Ok(converged
        .into_iter()
        .map(|(mu, free)| {
            let mut shape = vec![0.0; model.dofs()];
            system.scatter_add(&free, &mut shape);
            normalize(&mut shape);
            Mode {
                lambda: 1.0 / mu,
                shape,
            }
        })
        .collect())
}

/// A = K_0^-1 (-K_sigma) on the free DOFs, K_0 factored, and K_0 for the inner product.
struct Operator<'a> {
    pattern: &'a Pattern,
    k_0: &'a [f64],
    k_sigma: &'a [f64],
    solver: Solver,
    product: Vec<f64>,
}

impl Operator<'_> {
    /// y = K_0^-1 (-K_sigma x)
    fn apply(&mut self, x: &[f64]) -> Vec<f64> {
        self.pattern
            .symmetric_product(self.k_sigma, x, &mut self.product);
        let mut y: Vec<f64> = self.product.iter().map(|v| -v).collect();
        self.solver.solve(&mut y);
        y
    }

    /// y = K_0 x
    fn k0_times(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.pattern.size];
        self.pattern.symmetric_product(self.k_0, x, &mut y);
        y
    }
}

/// Lanczos on A in the K_0 inner product, the basis fully K_0-orthogonalized: the converged
/// Ritz pairs (mu, shape on the free DOFs) of the `count` largest positive mu, checked every
/// 5 steps once the basis has 2 count + 10 vectors (at most 400 steps).
fn lanczos(operator: &mut Operator, count: usize) -> Vec<(f64, Vec<f64>)> {
    let n = operator.pattern.size;
    // start in the range of A, where the modes live (K_0^-1 of a random vector is smooth)
    let mut q = operator.apply(&start_vector(n));
    let mut kq = operator.k0_times(&q);
    let norm = dot(&q, &kq).sqrt();
    q.iter_mut().for_each(|v| *v /= norm);
    kq.iter_mut().for_each(|v| *v /= norm);
    let max_steps = n.min(400);
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let mut k_basis: Vec<Vec<f64>> = Vec::new();
    let mut alpha: Vec<f64> = Vec::new();
    let mut beta: Vec<f64> = Vec::new();
    for step in 0..max_steps {
        let mut w = operator.apply(&q);
        alpha.push(dot(&w, &kq));
        basis.push(q);
        k_basis.push(kq);
        // full K_0-orthogonalization, twice (Lanczos loses orthogonality as Ritz values converge)
        for _ in 0..2 {
            for (v, kv) in basis.iter().zip(&k_basis) {
                let c = dot(&w, kv);
                w.iter_mut().zip(v).for_each(|(wi, vi)| *wi -= c * vi);
            }
        }
        let kw = operator.k0_times(&w);
        let b = dot(&w, &kw).max(0.0).sqrt();
        let m = alpha.len();
        let check = m >= (2 * count + 10).min(max_steps) && (m.is_multiple_of(5) || b == 0.0)
            || step + 1 == max_steps;
        if check {
            let done = b == 0.0 || step + 1 == max_steps || m == n;
            if let Some(converged) = ritz_pairs((&alpha, &beta, b), &basis, count, done) {
                return converged;
            }
        }
        if b == 0.0 {
            break;
        }
        beta.push(b);
        q = w.iter().map(|v| v / b).collect();
        kq = kw.iter().map(|v| v / b).collect();
    }
    Vec::new()
}

/// The Ritz pairs of the tridiagonal T = tridiag(beta, alpha, beta) whose next off-diagonal
/// would be `b` (the three given as `(alpha, beta, b)`): once the `count` largest positive mu
/// have residual estimates b |s_m,i| below 1e-10 mu (or `done`), those below 1e-6 mu with
/// their shapes; None to go on.
fn ritz_pairs(
    (alpha, beta, b): (&[f64], &[f64], f64),
    basis: &[Vec<f64>],
    count: usize,
    done: bool,
) -> Option<Vec<(f64, Vec<f64>)>> {
    let m = alpha.len();
    let n = basis[0].len();
    let eigen = tridiagonal_eigen(alpha, beta);
    // mu below 1e-8 of the spectrum's largest |mu| is round-off of a zero (a mode
    // the stresses leave alone), not a buckling load
    let largest = eigen.eigenvalues.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut order: Vec<usize> = (0..m)
        .filter(|&i| eigen.eigenvalues[i] > 1e-8 * largest)
        .collect();
    order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
    let wanted: Vec<usize> = order.into_iter().take(count).collect();
    let residual = |i: usize| b * eigen.eigenvectors[(m - 1, i)].abs() / eigen.eigenvalues[i];
    if !(wanted.len() == count && wanted.iter().all(|&i| residual(i) < 1e-10) || done) {
        return None;
    }
    Some(
        wanted
            .iter()
            .filter(|&&i| residual(i) < 1e-6)
            .map(|&i| {
                let mut shape = vec![0.0; n];
                for (k, v) in basis.iter().enumerate() {
                    let s = eigen.eigenvectors[(k, i)];
                    shape.iter_mut().zip(v).for_each(|(x, vk)| *x += s * vk);
                }
                (eigen.eigenvalues[i], shape)
            })
            .collect(),
    )
}

/// Scales a nodal vector so that its largest nodal displacement is 1, with the sign that
/// makes its largest component positive.
fn normalize(shape: &mut [f64]) {
    let largest = shape
        .chunks_exact(2)
        .map(|c| c[0].hypot(c[1]))
        .fold(0.0, f64::max);
    let signed = shape
        .iter()
        .copied()
        .fold(0.0f64, |m, v| if v.abs() > m.abs() { v } else { m });
    if largest > 0.0 {
        let scale = signed.signum() / largest;
        shape.iter_mut().for_each(|v| *v *= scale);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: the negative-pivot count equals the number of negative eigenvalues.
    /// Setup: tridiag(-1, 2 - s, -1) of size 30, whose eigenvalues 2 - s - 2 cos(k pi / 31)
    /// are known; s chosen between them. Reference: the closed-form count.
    #[test]
    fn negative_pivots_count_negative_eigenvalues() {
        let n = 30;
        let elements: Vec<Vec<Option<usize>>> = (0..=n)
            .map(|e: usize| vec![e.checked_sub(1), if e < n { Some(e) } else { None }])
            .collect();
        let pattern = Pattern::from_elements(n, elements.iter().map(|e| e.as_slice()));
        let mut counter = InertiaCounter::new(&pattern).unwrap();
        for shift in [0.0, 0.05, 0.5, 1.3, 2.7, 3.5] {
            let mut values = vec![0.0; pattern.nonzeros()];
            for dofs in &elements {
                for (p, v) in pattern.scatter(dofs).iter().zip([1.0, -1.0, -1.0, 1.0]) {
                    if *p != usize::MAX {
                        values[*p] += v;
                    }
                }
            }
            for j in 0..n {
                values[pattern.position(j, j).unwrap()] -= shift;
            }
            let expected = (1..=n)
                .filter(|k| {
                    2.0 - 2.0 * (*k as f64 * std::f64::consts::PI / (n + 1) as f64).cos() < shift
                })
                .count();
            assert_eq!(
                counter.negative_pivots(&values).unwrap(),
                expected,
                "s = {shift}"
            );
        }
    }
}
