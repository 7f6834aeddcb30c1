//! Element kernels: pure functions on small fixed-size nalgebra types.
//!
//! A kernel sees one element's reference coordinates (the last converged configuration,
//! updated Lagrangian), its displacement increment and its per-point stresses; it never sees
//! global indices, never calls the material and never allocates.
//!
//! Voigt order of strains and stresses everywhere: `[xx, yy, zz, xy]`, shear strain as the
//! engineering value `2 E_xy` (so `stress . strain` is the work density). For axisymmetric
//! bodies x = r, y = z and zz is the hoop (theta theta) component.

pub mod bulk_viscosity;
pub mod mass_scaling;
pub mod quad4;
pub mod quad4_one_point;
pub mod rod2;

use nalgebra::{Matrix4, SMatrix, SVector, Vector4};

/// Strain or stress in Voigt order `[xx, yy, zz, xy]`.
pub type Voigt = Vector4<f64>;
/// Material tangent in Voigt order.
pub type Moduli = Matrix4<f64>;
pub type Vec8 = SVector<f64, 8>;
pub type Mat8 = SMatrix<f64, 8, 8>;
pub type Vec4 = SVector<f64, 4>;
pub type Mat4 = SMatrix<f64, 4, 4>;

/// The 2D idealization of a Quad4 body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Formulation {
    /// eps_zz = 0; forces per unit depth.
    PlaneStrain,
    /// sigma_zz = 0; the thickness follows the out-of-plane stretch.
    PlaneStress,
    /// x = r >= 0, y = z; forces are totals over the full ring (2 pi r).
    Axisymmetric,
}

/// Small or finite strain: the scene's `analysis.geometry = "linear" | "nonlinear"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize, serde::Serialize)]
pub enum Strain {
    /// Linear geometry: B = B_s, no geometric stiffness, the reference configuration is
    /// never updated.
    #[serde(rename = "linear")]
    Small,
    /// Updated Lagrangian: B = B_s + B_L(theta), K_T = K_0 + K_sigma, reference = the last
    /// converged configuration.
    #[default]
    #[serde(rename = "nonlinear")]
    Finite,
}

/// Whether a tangent includes the geometric (initial-stress) stiffness K_sigma.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GeometricStiffness {
    Included,
    Omitted,
}

/// A failure inside an element kernel: the caller knows the element id and adds it.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum KernelError {
    /// det J <= 0 at a Gauss point: the element is inverted or degenerate.
    #[error("non-positive Jacobian det J = {det:.3e} at Gauss point {point}")]
    NegativeJacobian { point: usize, det: f64 },
    /// An axisymmetric Gauss point at r <= 0.
    #[error("Gauss point {point} at radius r = {radius:.3e} <= 0 in an axisymmetric body")]
    NonPositiveRadius { point: usize, radius: f64 },
    /// A rod of zero length.
    #[error("rod of zero length")]
    ZeroLength,
    /// A return whose plastic work (the trapezoidal rule, per unit volume) is negative: the
    /// step reversed the stress across the whole elastic range.
    #[error(
        "the return at Gauss point {point} would dissipate a negative plastic work ({work:.3e} per \
         unit volume): the step reversed the stress across the whole elastic range (a step far \
         too long for the plastic flow, or inconsistent units)"
    )]
    NegativePlasticWork { point: usize, work: f64 },
}

/// An element's highest frequency squared: the largest eigenvalue of M^-1 K for its n x n
/// stiffness `k(i, j)` (symmetrized, (K + K^T) / 2) and its lumped nodal masses `lumped` (each
/// for both directions of its node: n = 2 lumped.len(), at most 8, a quad or a rod), from the
/// symmetric M^-1/2 K M^-1/2. The one routine of the exact element frequency: the eigenvalue
/// stable step (dt_crit) and the explicit kernels' tight and global steps.
pub fn highest_frequency_squared(k: impl Fn(usize, usize) -> f64, lumped: &[f64]) -> f64 {
    let n = 2 * lumped.len();
    // on the stack: the tight and global steps call this for every element they re-take
    let mut scale = [0.0; 8];
    for (i, s) in scale.iter_mut().enumerate().take(n) {
        *s = 1.0 / lumped[i / 2].sqrt();
    }
    let entry = |i: usize, j: usize| 0.5 * (k(i, j) + k(j, i)) * scale[i] * scale[j];
    if n == 8 {
        // a quad's on the stack (a dynamic matrix's heap and loops made the set-up of a
        // 5e5-element mesh twice as long)
        SMatrix::<f64, 8, 8>::from_fn(entry)
            .symmetric_eigenvalues()
            .max()
    } else {
        nalgebra::DMatrix::from_fn(n, n, entry)
            .symmetric_eigenvalues()
            .max()
    }
}
