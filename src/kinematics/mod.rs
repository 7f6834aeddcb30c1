//! Objectivity of the stress update over an increment.
//!
//! Legend
//! ```text
//! F     deformation gradient of the increment, in-plane 2x2 plus F_zz (hoop stretch 1 + u/r
//!       in axisymmetry, sqrt(1 + 2 dE_zz) in plane stress, 1 in plane strain)
//! J     det F = det(F_2x2) F_zz
//! S     second Piola-Kirchhoff stress relative to the start of the increment
//! sigma Cauchy stress at the end: sigma = F S F^T / J
//! ```
//! The committed Cauchy stress is the second Piola-Kirchhoff stress of the next increment's
//! reference configuration, so the material only ever sees stresses in the reference frame
//! of the increment. The push-forward is the exact integral of the Truesdell rate over the
//! increment: a rigid rotation R (dE = 0, S = sigma_n) gives sigma = R sigma_n R^T, so the
//! invariants are kept to round-off whatever the rotation's size.

use crate::element::Voigt;
use nalgebra::{Matrix2, Matrix3};

fn tensor(s: &Voigt) -> Matrix3<f64> {
    Matrix3::new(s[0], s[3], 0.0, s[3], s[1], 0.0, 0.0, 0.0, s[2])
}

/// Cauchy stress F S F^T / J of the increment with in-plane F and out-of-plane stretch f_zz.
pub fn push_forward(s: &Voigt, f: &Matrix2<f64>, f_zz: f64) -> Voigt {
    let f3 = Matrix3::new(
        f[(0, 0)],
        f[(0, 1)],
        0.0,
        f[(1, 0)],
        f[(1, 1)],
        0.0,
        0.0,
        0.0,
        f_zz,
    );
    let j = f.determinant() * f_zz;
    let sigma = f3 * tensor(s) * f3.transpose() / j;
    Voigt::new(sigma[(0, 0)], sigma[(1, 1)], sigma[(2, 2)], sigma[(0, 1)])
}

/// The out-of-plane stretch of a plane-stress point from its Green-Lagrange zz increment.
pub fn plane_stress_stretch(strain_zz: f64) -> f64 {
    (1.0 + 2.0 * strain_zz).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::von_mises;

    /// A rigid rotation by 90 degrees turns [sxx, syy, 0, sxy] into [syy, sxx, 0, -sxy].
    #[test]
    fn rigid_rotation_turns_the_stress() {
        let s = Voigt::new(3.0, -1.0, 0.5, 2.0);
        let r = Matrix2::new(0.0, -1.0, 1.0, 0.0);
        let sigma = push_forward(&s, &r, 1.0);
        approx::assert_abs_diff_eq!(sigma, Voigt::new(-1.0, 3.0, 0.5, -2.0), epsilon = 1e-15);
        approx::assert_relative_eq!(von_mises(&sigma), von_mises(&s), max_relative = 1e-15);
    }
}
