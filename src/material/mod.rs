//! Constitutive models: committed state + strain increment -> response with a new state.
//!
//! Legend
//! ```text
//! sigma_n   committed Cauchy stress, pushed to the reference configuration of the increment
//!           (the last converged one, where it equals the second Piola-Kirchhoff stress)
//! dE        Green-Lagrange strain increment relative to that configuration [xx yy zz xy]
//! S         sigma_n + dS: second Piola-Kirchhoff stress relative to that configuration
//! D         dS/ddE, the material tangent (the elastic moduli for the elastic model)
//! young E, poisson nu, lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu))
//! ```
//! `&self` is never mutated: a failed iteration cannot corrupt the history; the caller
//! commits a step by keeping the returned state.

use crate::element::{Moduli, Voigt};

/// How many stress components the body carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StressState {
    /// Plane strain and axisymmetric: all four components.
    General,
    /// sigma_zz = 0; the material decides the out-of-plane strain.
    PlaneStress,
}

/// Committed state of one material point.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct PointState {
    /// Cauchy stress [xx yy zz xy] (for rods only xx is used: the axial stress).
    pub stress: Voigt,
    /// Equivalent plastic strain.
    pub eq_plastic_strain: f64,
}

/// The result of a material update.
#[derive(Debug, Clone, Copy)]
pub struct Response {
    /// Second Piola-Kirchhoff stress relative to the reference configuration.
    pub stress: Voigt,
    /// dS/ddE.
    pub moduli: Moduli,
    /// The out-of-plane Green-Lagrange strain increment (plane stress), else the input's zz.
    pub strain_zz: f64,
    /// The new state, stress still in the reference configuration (the kinematics pushes it).
    pub state: PointState,
}

/// Isotropic linear elasticity (in the rate form S = sigma_n + D dE of the updated-Lagrangian
/// increment).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elastic {
    pub young: f64,
    pub poisson: f64,
}

impl Elastic {
    pub fn lame(&self) -> (f64, f64) {
        let (e, nu) = (self.young, self.poisson);
        (
            e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            e / (2.0 * (1.0 + nu)),
        )
    }

    /// Elastic moduli; in plane stress the condensed in-plane moduli with the zz row and
    /// column zero.
    pub fn moduli(&self, state: StressState) -> Moduli {
        let (lambda, mu) = self.lame();
        let lambda = match state {
            StressState::General => lambda,
            StressState::PlaneStress => 2.0 * lambda * mu / (lambda + 2.0 * mu),
        };
        let mut d = Moduli::zeros();
        let normal = if state == StressState::General { 3 } else { 2 };
        for a in 0..normal {
            for b in 0..normal {
                d[(a, b)] = lambda;
            }
            d[(a, a)] += 2.0 * mu;
        }
        d[(3, 3)] = mu;
        d
    }

    /// Dilatational wave speed squared times density (the P-wave modulus); for rods E.
    pub fn p_wave_modulus(&self) -> f64 {
        let (lambda, mu) = self.lame();
        lambda + 2.0 * mu
    }
}

/// A material as the analysis uses it.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    pub name: String,
    pub density: f64,
    pub elastic: Elastic,
}

impl Material {
    /// Response of a continuum point (Quad4).
    pub fn update(&self, committed: &PointState, strain: &Voigt, state: StressState) -> Response {
        let moduli = self.elastic.moduli(state);
        let mut strain = *strain;
        if state == StressState::PlaneStress {
            let (lambda, mu) = self.elastic.lame();
            strain[2] = -lambda / (lambda + 2.0 * mu) * (strain[0] + strain[1]);
        }
        let stress = committed.stress + moduli * strain;
        Response {
            stress,
            moduli,
            strain_zz: strain[2],
            state: PointState {
                stress,
                ..*committed
            },
        }
    }

    /// Response of a rod: axial stress and modulus.
    pub fn update_uniaxial(&self, committed: &PointState, strain: f64) -> (f64, f64, PointState) {
        let stress = committed.stress[0] + self.elastic.young * strain;
        let mut state = *committed;
        state.stress[0] = stress;
        (stress, self.elastic.young, state)
    }
}

/// Von Mises equivalent stress of [xx yy zz xy].
pub fn von_mises(s: &Voigt) -> f64 {
    let p = (s[0] + s[1] + s[2]) / 3.0;
    let (a, b, c) = (s[0] - p, s[1] - p, s[2] - p);
    (1.5 * (a * a + b * b + c * c + 2.0 * s[3] * s[3])).sqrt()
}

/// Pressure -tr(sigma)/3.
pub fn pressure(s: &Voigt) -> f64 {
    -(s[0] + s[1] + s[2]) / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Plane-stress moduli with the zz strain from the material give S_zz = 0 and the textbook
    /// E / (1 - nu^2) in-plane stiffness.
    #[test]
    fn plane_stress_keeps_szz_zero() {
        let m = Material {
            name: "m".into(),
            density: 1.0,
            elastic: Elastic {
                young: 200.0,
                poisson: 0.3,
            },
        };
        let r = m.update(
            &PointState::default(),
            &Voigt::new(1e-3, 0.0, 0.0, 0.0),
            StressState::PlaneStress,
        );
        approx::assert_relative_eq!(
            r.stress[0],
            200.0 / (1.0 - 0.09) * 1e-3,
            max_relative = 1e-14
        );
        assert_eq!(r.stress[2], 0.0);
        approx::assert_relative_eq!(r.strain_zz, -0.3 / 0.7 * 1e-3, max_relative = 1e-14);
    }
}
