//! BFGS updates of the factored K*^-1 between factorizations (Matthies & Strang 1979), in the
//! compact form of Byrd, Nocedal & Schnabel (1994, theorem 2.2):
//! ```text
//! H_k = H_0 + W M W^T,   W = [S, H_0 Y]                                  (n x 2k)
//! M = [ R^-T (D + Y^T H_0 Y) R^-1   -R^-T ]     R_ij = s_i . y_j (i <= j), upper
//!     [ -R^-1                        0    ]     D = diag(s_i . y_i)
//! ```
//! s_i: a correction, y_i = R(d_i) - R(d_i + s_i) (what K* makes of it, from the residuals of
//! the iterates), H_0 = K*^-1 of the current factorization. Each update makes H_k map the
//! latest y to its s, so the iteration learns the part of the tangent the factor has gone
//! stale on, for a back-substitution per pair. The contact solves need H_k only through products with the
//! few rows W has at the constrained equations, so W M W^T stays a correction beside the
//! single back-substitution of H_0 (see `constrained_solve`).

use super::norm;
use crate::solver::Solver;
use nalgebra::{DMatrix, DVector};

/// The pairs of the current factorization and the compact form's middle matrix.
pub struct Secant {
    enabled: bool,
    s: Vec<Vec<f64>>,
    h0y: Vec<Vec<f64>>,
    /// R: s_i . y_j for i <= j.
    sy: DMatrix<f64>,
    /// y_i . H_0 y_j.
    yhy: DMatrix<f64>,
    middle: DMatrix<f64>,
}

/// A pair whose curvature s . y is below this share of |s| |y| is left out: BFGS needs
/// s . y > 0 to keep H_k positive definite, and a near-zero one would dominate it.
const CURVATURE: f64 = 1e-8;

impl Secant {
    pub fn new(enabled: bool) -> Secant {
        Secant {
            enabled,
            s: Vec::new(),
            h0y: Vec::new(),
            sy: DMatrix::zeros(0, 0),
            yhy: DMatrix::zeros(0, 0),
            middle: DMatrix::zeros(0, 0),
        }
    }

    /// Whether the step takes pairs at all.
    pub fn enabled(&self) -> bool {
        self.enabled
    }

    /// No pairs: H = H_0.
    pub fn is_empty(&self) -> bool {
        self.s.is_empty()
    }

    /// Forgets the pairs (a new factorization).
    pub fn clear(&mut self) {
        *self = Secant::new(self.enabled);
    }

    /// Takes the pair of the last correction `s`, solved from the residual `start`, now that
    /// the residual after it is `now`: y = start - now, and H_0 y by a back-substitution.
    pub fn learn(&mut self, solver: &mut Solver, s: Vec<f64>, start: &[f64], now: &[f64]) {
        let y: Vec<f64> = start.iter().zip(now).map(|(a, b)| a - b).collect();
        let mut h0y = y.clone();
        solver.solve(&mut h0y);
        self.push(s, &y, h0y);
    }

    /// Adds the pair (s, y), `h0y` = H_0 y. Returns whether it was taken.
    pub fn push(&mut self, s: Vec<f64>, y: &[f64], h0y: Vec<f64>) -> bool {
        let curvature = dot(&s, y);
        if !(curvature > CURVATURE * norm(&s) * norm(y)) {
            return false;
        }
        let k = self.s.len();
        let (mut sy, mut yhy) = (
            self.sy.clone().resize(k + 1, k + 1, 0.0),
            self.yhy.clone().resize(k + 1, k + 1, 0.0),
        );
        for (i, (s_i, h0y_i)) in self.s.iter().zip(&self.h0y).enumerate() {
            sy[(i, k)] = dot(s_i, y);
            // y_i . H_0 y = (H_0 y_i) . y: H_0 is symmetric
            yhy[(i, k)] = dot(h0y_i, y);
            yhy[(k, i)] = yhy[(i, k)];
        }
        sy[(k, k)] = curvature;
        yhy[(k, k)] = dot(&h0y, y);
        self.s.push(s);
        self.h0y.push(h0y);
        self.sy = sy;
        self.yhy = yhy;
        self.middle = middle(&self.sy, &self.yhy);
        true
    }

    /// W^T v.
    pub fn project(&self, v: &[f64]) -> DVector<f64> {
        DVector::from_iterator(
            2 * self.s.len(),
            self.s.iter().chain(&self.h0y).map(|w| dot(w, v)),
        )
    }

    /// W^T v for a sparse v given as (equation, value).
    pub fn project_sparse<'a>(
        &self,
        v: impl IntoIterator<Item = &'a (usize, f64)> + Clone,
    ) -> DVector<f64> {
        DVector::from_iterator(
            2 * self.s.len(),
            self.s
                .iter()
                .chain(&self.h0y)
                .map(|w| v.clone().into_iter().map(|(eq, c)| c * w[*eq]).sum()),
        )
    }

    /// The row of W at one equation.
    pub fn row(&self, equation: usize) -> DVector<f64> {
        DVector::from_iterator(
            2 * self.s.len(),
            self.s.iter().chain(&self.h0y).map(|w| w[equation]),
        )
    }

    /// M b for a projection b: a^T M b, an entry of the correction, is then a dot product,
    /// and M b is formed once for all the a it meets.
    pub fn weigh(&self, b: &DVector<f64>) -> DVector<f64> {
        &self.middle * b
    }

    /// target += W M p for a projection p = W^T v: adds (H_k - H_0) v.
    pub fn add_correction(&self, p: &DVector<f64>, target: &mut [f64]) {
        let c = &self.middle * p;
        for (w, c) in self.s.iter().chain(&self.h0y).zip(c.iter()) {
            target.iter_mut().zip(w).for_each(|(t, w)| *t += c * w);
        }
    }
}

/// The middle matrix M of the compact form from R and Y^T H_0 Y.
fn middle(r: &DMatrix<f64>, yhy: &DMatrix<f64>) -> DMatrix<f64> {
    let k = r.nrows();
    let mut r_inv = DMatrix::<f64>::identity(k, k);
    // R has a positive diagonal (every pair's curvature): the triangular solve exists
    let solved = r.solve_upper_triangular_mut(&mut r_inv);
    debug_assert!(solved);
    let mut inner = yhy.clone();
    for i in 0..k {
        inner[(i, i)] += r[(i, i)];
    }
    let top_left = r_inv.transpose() * inner * &r_inv;
    let mut m = DMatrix::zeros(2 * k, 2 * k);
    m.view_mut((0, 0), (k, k)).copy_from(&top_left);
    m.view_mut((0, k), (k, k)).copy_from(&(-r_inv.transpose()));
    m.view_mut((k, 0), (k, k)).copy_from(&(-r_inv));
    m
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// H_0 = diag(h0), the pairs from a fixed SPD matrix K (y = K s).
    fn pairs(h0: &[f64], k: &DMatrix<f64>, steps: &[Vec<f64>]) -> Secant {
        let mut secant = Secant::new(true);
        for s in steps {
            let y: Vec<f64> = (k * DVector::from_column_slice(s))
                .iter()
                .copied()
                .collect();
            let h0y = y.iter().zip(h0).map(|(y, h)| y * h).collect();
            assert!(secant.push(s.clone(), &y, h0y));
        }
        secant
    }

    fn apply(secant: &Secant, h0: &[f64], v: &[f64]) -> Vec<f64> {
        let mut x: Vec<f64> = v.iter().zip(h0).map(|(v, h)| v * h).collect();
        secant.add_correction(&secant.project(v), &mut x);
        x
    }

    fn spd() -> DMatrix<f64> {
        DMatrix::from_row_slice(
            4,
            4,
            &[
                4.0, 1.0, 0.0, 0.5, 1.0, 3.0, 0.2, 0.0, 0.0, 0.2, 2.0, 0.3, 0.5, 0.0, 0.3, 5.0,
            ],
        )
    }

    /// The compact form against the recursive BFGS update of the inverse,
    /// H+ = (I - rho s y^T) H (I - rho y s^T) + rho s s^T (rho = 1 / s.y), pair by pair.
    #[test]
    fn compact_form_is_the_recursive_bfgs_update() {
        let k = spd();
        let h0 = [0.3, 0.25, 0.6, 0.15];
        let steps = vec![
            vec![1.0, 0.0, 0.5, -0.2],
            vec![0.1, 1.0, -0.3, 0.4],
            vec![-0.2, 0.3, 1.0, 0.1],
        ];
        let secant = pairs(&h0, &k, &steps);
        let mut h = DMatrix::from_diagonal(&DVector::from_column_slice(&h0));
        for s in &steps {
            let s = DVector::from_column_slice(s);
            let y = &k * &s;
            let rho = 1.0 / s.dot(&y);
            let v = DMatrix::identity(4, 4) - rho * &y * s.transpose();
            h = v.transpose() * h * v + rho * &s * s.transpose();
        }
        for j in 0..4 {
            let mut e = vec![0.0; 4];
            e[j] = 1.0;
            let column = apply(&secant, &h0, &e);
            for i in 0..4 {
                // a few products of O(1) entries: round-off
                approx::assert_abs_diff_eq!(column[i], h[(i, j)], epsilon = 1e-13);
            }
        }
    }

    /// Each update meets its own secant equation H_k y_k = s_k (the BFGS condition; older
    /// pairs keep theirs only along conjugate steps).
    #[test]
    fn the_latest_pair_meets_the_secant_equation() {
        let k = spd();
        let h0 = [1.0, 0.5, 2.0, 0.25];
        let mut steps: Vec<Vec<f64>> = Vec::new();
        for i in 0..4 {
            steps.push(
                (0..4)
                    .map(|j| if i == j { 1.0 } else { 0.1 * (j + 1) as f64 })
                    .collect(),
            );
            let secant = pairs(&h0, &k, &steps);
            let s = DVector::from_column_slice(&steps[i]);
            let y: Vec<f64> = (&k * &s).iter().copied().collect();
            let hy = apply(&secant, &h0, &y);
            for j in 0..4 {
                approx::assert_abs_diff_eq!(hy[j], s[j], epsilon = 1e-12);
            }
        }
    }

    /// One element of all 8 DOFs: a dense 8 x 8 pattern, its K, the solver factored on it.
    fn factored() -> (crate::solver::Solver, DMatrix<f64>) {
        use crate::solver::{Pattern, Solver};
        let dofs: Vec<Option<usize>> = (0..8).map(Some).collect();
        let pattern = std::sync::Arc::new(Pattern::from_elements(8, [dofs.as_slice()].into_iter()));
        let k = DMatrix::from_fn(8, 8, |i, j| {
            if i == j {
                6.0 + i as f64
            } else {
                -0.3 - 0.1 * ((i + j) % 3) as f64
            }
        });
        let mut values = vec![0.0; pattern.nonzeros()];
        for j in 0..8 {
            for p in pattern.col_ptr[j] as usize..pattern.col_ptr[j + 1] as usize {
                values[p] = k[(pattern.row_idx[p] as usize, j)];
            }
        }
        let mut solver = Solver::new(&pattern).unwrap();
        solver.factor(&values).unwrap();
        (solver, k)
    }

    /// Goal: the contact solves with BFGS pairs solve the constrained Newton step with H_k for
    /// K*^-1. Setup: an 8-DOF SPD K factored as H_0, two pairs from another matrix (K plus a
    /// diagonal), two constraint rows; the Schur path (rows = dg/dx) and the exact path (one
    /// row with its own gradient and a row Jacobian). Reference: the dense step from H_k built
    /// by the recursive update of H_0 = K^-1 (nalgebra inverse):
    /// (I - H A) delta - H C^T tau = H R, G delta = -g. Tolerance: round-off of O(1) entries.
    #[test]
    fn contact_solves_use_the_updated_inverse() {
        use super::super::constrained::{Exact, Rows, constrained_solve};
        let (mut solver, k) = factored();
        let stiffer =
            &k + DMatrix::from_diagonal(&DVector::from_fn(8, |i, _| 1.0 + 0.5 * i as f64));
        let h0 = k.clone().try_inverse().unwrap();
        let mut secant = Secant::new(true);
        let mut h = h0.clone();
        for s in [
            DVector::from_fn(8, |i, _| (i as f64 * 0.7).sin()),
            DVector::from_fn(8, |i, _| (i as f64 * 1.3).cos()),
        ] {
            let y = &stiffer * &s;
            let mut h0y: Vec<f64> = y.iter().copied().collect();
            solver.solve(&mut h0y);
            assert!(secant.push(s.iter().copied().collect(), y.as_slice(), h0y));
            let rho = 1.0 / s.dot(&y);
            let v = DMatrix::identity(8, 8) - rho * &y * s.transpose();
            h = v.transpose() * h * v + rho * &s * s.transpose();
        }
        let residual: Vec<f64> = (0..8).map(|i| 0.2 * i as f64 - 0.5).collect();
        let c_rows = vec![
            vec![(1, 1.0), (4, -0.6)],
            vec![(2, 0.8), (6, 0.5), (7, -1.0)],
        ];
        let gaps = vec![0.03, -0.02];
        let forces = [0.4, 0.0];
        for exact in [false, true] {
            let mut c = DMatrix::zeros(2, 8);
            for (i, row) in c_rows.iter().enumerate() {
                for (eq, v) in row {
                    c[(i, *eq)] = *v;
                }
            }
            let (mut g, mut a) = (c.clone(), DMatrix::zeros(8, 8));
            let exact_rows = if exact {
                let gradient = vec![(1, 0.9), (3, 0.2), (4, -0.6)];
                let row_jacobian = vec![(1, 3, 0.5), (3, 1, 0.5), (4, 4, -0.2)];
                g.row_mut(0).fill(0.0);
                for (eq, v) in &gradient {
                    g[(0, *eq)] = *v;
                }
                for (p, q, v) in &row_jacobian {
                    a[(*p, *q)] += forces[0] * v;
                }
                vec![
                    Some(Exact {
                        gradient,
                        row_jacobian,
                        equations: vec![1, 3, 4],
                    }),
                    None,
                ]
            } else {
                vec![None, None]
            };
            let rows = Rows {
                rows: c_rows.clone(),
                gaps: gaps.clone(),
                normal: 2,
                sliding: Vec::new(),
                fixed: Vec::new(),
                exact: exact_rows,
                worst_gap: 0.0,
            };
            let (delta, tau) =
                constrained_solve(&mut solver, &rows, residual.clone(), &forces, &secant).unwrap();
            let mut system = DMatrix::<f64>::zeros(10, 10);
            system
                .view_mut((0, 0), (8, 8))
                .copy_from(&(DMatrix::identity(8, 8) - &h * &a));
            system
                .view_mut((0, 8), (8, 2))
                .copy_from(&(-(&h * c.transpose())));
            system.view_mut((8, 0), (2, 8)).copy_from(&g);
            let r = DVector::from_column_slice(&residual);
            let hr = &h * r;
            let rhs = DVector::from_fn(10, |i, _| if i < 8 { hr[i] } else { -gaps[i - 8] });
            let reference = system.lu().solve(&rhs).unwrap();
            for i in 0..8 {
                approx::assert_abs_diff_eq!(delta[i], reference[i], epsilon = 1e-12);
            }
            for i in 0..2 {
                approx::assert_abs_diff_eq!(tau[i], reference[8 + i], epsilon = 1e-12);
            }
        }
    }

    #[test]
    fn a_pair_without_positive_curvature_is_left_out() {
        let mut secant = Secant::new(true);
        assert!(!secant.push(vec![1.0, 0.0], &[-1.0, 0.5], vec![-1.0, 0.5]));
        assert!(secant.is_empty());
    }
}
