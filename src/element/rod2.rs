//! Two-node rod (bar) in the plane, updated Lagrangian with constant area.
//!
//! Legend
//! ```text
//! X1, X2   reference (last converged) node positions,   L = |X2 - X1|
//! x = X + d current positions,                            l = |x2 - x1|,  dx = x2 - x1
//! dE       Green-Lagrange strain increment (l^2 - L^2) / (2 L^2)
//! B        dE/dd = [-dx, dx] / L^2
//! S        second Piola-Kirchhoff stress relative to the reference;  N = S A l / L
//! K_T      A L (B^T E_t B + S / L^2 [[I, -I], [-I, I]])
//! ```
//! Linear kinematics keeps B = [-e, e] / L with e the reference direction and no K_sigma.

use super::{GeometricStiffness, KernelError, Mat4, Strain, Vec4};
/// The Green-Lagrange strain along a rod with ends at `reference` (initial) and `current`:
/// (l^2 / L^2 - 1) / 2 (the frames' cell strain).
pub fn green_strain(reference: &[[f64; 2]; 2], current: &[[f64; 2]; 2]) -> f64 {
    let length2 = |p: [f64; 2], q: [f64; 2]| (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
    0.5 * (length2(current[0], current[1]) / length2(reference[0], reference[1]) - 1.0)
}

/// Reference length and unit direction of the rod X1 -> X2.
pub fn length(x: &[[f64; 2]; 2]) -> Result<f64, KernelError> {
    let l = ((x[1][0] - x[0][0]).powi(2) + (x[1][1] - x[0][1]).powi(2)).sqrt();
    if l > 0.0 {
        Ok(l)
    } else {
        Err(KernelError::ZeroLength)
    }
}

fn b_vector(x: &[[f64; 2]; 2], d: &Vec4, length: f64, geometry: Strain) -> Vec4 {
    let mut dx = [x[1][0] - x[0][0], x[1][1] - x[0][1]];
    if geometry == Strain::Finite {
        dx[0] += d[2] - d[0];
        dx[1] += d[3] - d[1];
    }
    let l2 = length * length;
    Vec4::new(-dx[0], -dx[1], dx[0], dx[1]) / l2
}

/// Axial Green-Lagrange strain increment, (dX . du + 1/2 du . du) / L^2 (the linear part
/// alone in linear kinematics). From L^2, not L: the material update that waits on the strain
/// does not wait on a square root too.
pub fn strain(x: &[[f64; 2]; 2], d: &Vec4, geometry: Strain) -> Result<f64, KernelError> {
    let dx = [x[1][0] - x[0][0], x[1][1] - x[0][1]];
    let l2 = dx[0] * dx[0] + dx[1] * dx[1];
    if !(l2 > 0.0) {
        return Err(KernelError::ZeroLength);
    }
    let du = [d[2] - d[0], d[3] - d[1]];
    let linear = (dx[0] * du[0] + dx[1] * du[1]) / l2;
    Ok(match geometry {
        Strain::Small => linear,
        Strain::Finite => linear + 0.5 * (du[0] * du[0] + du[1] * du[1]) / l2,
    })
}

/// Stretch l / L of the increment (pushes S forward to the Cauchy stress S l / L).
pub fn stretch(x: &[[f64; 2]; 2], d: &Vec4) -> Result<f64, KernelError> {
    let l = length(x)?;
    let dx = [
        x[1][0] - x[0][0] + d[2] - d[0],
        x[1][1] - x[0][1] + d[3] - d[1],
    ];
    Ok((dx[0] * dx[0] + dx[1] * dx[1]).sqrt() / l)
}

/// Internal force A L B^T S.
pub fn internal_force(
    x: &[[f64; 2]; 2],
    d: &Vec4,
    stress: f64,
    area: f64,
    geometry: Strain,
) -> Result<Vec4, KernelError> {
    let l = length(x)?;
    Ok(b_vector(x, d, l, geometry) * (area * l * stress))
}

/// The axial state a rod's tangent reads: the second Piola-Kirchhoff stress S and the
/// modulus dS/dE.
#[derive(Debug, Clone, Copy)]
pub struct Axial {
    pub stress: f64,
    pub modulus: f64,
}

/// Tangent: the exact derivative of `internal_force` for dS/dE = `axial.modulus`; the
/// geometric term (finite strain) only when `geometric` includes it.
pub fn tangent(
    x: &[[f64; 2]; 2],
    d: &Vec4,
    axial: Axial,
    area: f64,
    (geometry, geometric): (Strain, GeometricStiffness),
) -> Result<Mat4, KernelError> {
    let Axial { stress, modulus } = axial;
    let l = length(x)?;
    let b = b_vector(x, d, l, geometry);
    let mut k = b * b.transpose() * (area * l * modulus);
    if geometry == Strain::Finite && geometric == GeometricStiffness::Included {
        let g = area * stress / l;
        for a in 0..2 {
            k[(a, a)] += g;
            k[(a + 2, a + 2)] += g;
            k[(a, a + 2)] -= g;
            k[(a + 2, a)] -= g;
        }
    }
    Ok(k)
}

/// Lumped (diagonal) and consistent mass per unit density and area: L/2 per node, and
/// L/6 [[2, 1], [1, 2]] per direction.
pub fn mass(x: &[[f64; 2]; 2]) -> Result<[[f64; 2]; 2], KernelError> {
    let l = length(x)?;
    Ok([[l / 3.0, l / 6.0], [l / 6.0, l / 3.0]])
}

/// The rod's highest frequency squared with its lumped mass, exact: 2 k / m with the axial
/// stiffness k = E A / L on the current length and the mass m = rho A L_0 / 2 at each node.
pub fn frequency_squared(
    x: &[[f64; 2]; 2],
    young: f64,
    area: f64,
    node_mass: f64,
) -> Result<f64, KernelError> {
    let l = length(x)?;
    Ok(2.0 * young * area / (l * node_mass))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tangent_matches_finite_differences() {
        let x = [[0.2, 0.1], [1.3, 0.6]];
        let d = Vec4::new(0.01, -0.03, 0.08, 0.05);
        let (s0, modulus, area) = (0.4, 3.0, 0.7);
        let force = |d: &Vec4| {
            let e = strain(&x, d, Strain::Finite).unwrap();
            internal_force(&x, d, s0 + modulus * e, area, Strain::Finite).unwrap()
        };
        let e = strain(&x, &d, Strain::Finite).unwrap();
        let axial = Axial {
            stress: s0 + modulus * e,
            modulus,
        };
        let terms = (Strain::Finite, GeometricStiffness::Included);
        let k = tangent(&x, &d, axial, area, terms).unwrap();
        // central differences: truncation O(h^2) ~ 1e-12 and round-off eps |f| / h ~ 1e-10
        // against entries ~ EA / L ~ 2; 1e-8 bounds both with a margin of 100
        let h = 1e-6;
        for j in 0..4 {
            let (mut dp, mut dm) = (d, d);
            dp[j] += h;
            dm[j] -= h;
            let col = (force(&dp) - force(&dm)) / (2.0 * h);
            for i in 0..4 {
                approx::assert_abs_diff_eq!(k[(i, j)], col[i], epsilon = 1e-8);
            }
        }
    }

    /// Green-Lagrange strain equals (l^2 - L^2) / (2 L^2) exactly.
    #[test]
    fn strain_is_green_lagrange() {
        let x = [[0.0, 0.0], [2.0, 0.0]];
        let d = Vec4::new(0.0, 0.0, 0.5, 1.0);
        let l2: f64 = 2.5f64.powi(2) + 1.0;
        approx::assert_relative_eq!(
            strain(&x, &d, Strain::Finite).unwrap(),
            (l2 - 4.0) / 8.0,
            max_relative = 1e-14
        );
    }
}
