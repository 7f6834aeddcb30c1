//! What the two Lanczos iterations share (the buckling analysis' in the K_0 inner product,
//! `buckling::lanczos`; the global stable step's in the Euclidean one,
//! `assembly::explicit::global`): a deterministic start vector and the eigen-decomposition
//! of the tridiagonal matrix they build.

use nalgebra::{DMatrix, Dyn, SymmetricEigen};

/// A deterministic start vector with every component in [-0.5, 0.5) (a linear congruential
/// sequence: the same on every run and thread count).
pub fn start_vector(n: usize) -> Vec<f64> {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    (0..n)
        .map(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect()
}

/// The eigenvalues and eigenvectors of T = tridiag(beta, alpha, beta), m = `alpha.len()`,
/// from the first m - 1 entries of `beta` (a further one, the next step's coefficient, is
/// not part of T).
pub fn tridiagonal_eigen(alpha: &[f64], beta: &[f64]) -> SymmetricEigen<f64, Dyn> {
    let m = alpha.len();
    DMatrix::from_fn(m, m, |i, j| match i.abs_diff(j) {
        0 => alpha[i],
        1 => beta[i.min(j)],
        _ => 0.0,
    })
    .symmetric_eigen()
}
