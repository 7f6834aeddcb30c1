//! Bulk viscosity: an artificial pressure on an element's volumetric strain rate, added to the
//! stress its nodal forces see (never to the material's stress), that damps the ringing behind
//! a wave front (the linear term) and spreads a shock over a few elements (the quadratic term).
//! Von Neumann & Richtmyer (1950) in the form of Abaqus/Explicit (Analysis User's Guide,
//! "Bulk viscosity"); docs/theory.md 8.7a.
//!
//! Legend (one element, or one Gauss point of it, over a step of length dt)
//! ```text
//! d             the step's strain increment [xx yy zz xy]
//! rate          (d_xx + d_yy + d_zz) / dt, the volumetric strain rate (zz: the hoop strain in
//!               axisymmetry, 0 in plane strain; plane stress: d_xx + d_yy, the rate the
//!               in-plane forces work against)
//! rho           m_e / V, the element's current density (its lumped mass over its volume)
//! c_d           sqrt(M / rho), M the plane-wave modulus of the formulation
//! L_e           A / D_max, A the element's area in the plane, D_max its longer diagonal: for
//!               an a x b rectangle 1 / sqrt(1/a^2 + 1/b^2), the length with which the
//!               one-point frequency bound's step is L_e / c_d (so xi below is the damping
//!               of the mode that sets the step; sqrt(A) would overstate a slender element's)
//! p_1           b_1 rho c_d L_e rate                        (both signs: always damps)
//! p_2           rho (b_2 L_e)^2 |rate| min(0, rate)         (compression only)
//! q             -(p_1 + p_2), positive in compression; the forces see sigma - q I
//! xi            b_1 - b_2^2 (L_e / c_d) min(0, rate): the fraction of critical damping
//!               in the element's highest mode
//! dt_damped     dt_bound (sqrt(1 + xi^2) - xi)
//! W_visc        -V_mid 1/2 (q_n + q_{n+1}) tr d over a step: the trapezoid of the
//!               pressures the forces carried at its start and its end, as the stress work
//! ```

use super::Formulation;
use super::quad4_one_point::{Nodes, area};

/// The linear coefficient b_1 of Abaqus/Explicit (LS-DYNA's Q2 is the same 0.06).
pub const DEFAULT_LINEAR: f64 = 0.06;
/// The quadratic coefficient b_2 of Abaqus/Explicit (LS-DYNA's Q1 = 1.5 multiplies b_2^2).
pub const DEFAULT_QUADRATIC: f64 = 1.2;

/// The two coefficients of the bulk viscosity (dimensionless, >= 0).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BulkViscosity {
    pub linear: f64,
    pub quadratic: f64,
}

/// What the viscous pressure of an element depends on besides its rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementScale {
    /// Current density rho.
    pub density: f64,
    /// Current dilatational wave speed c_d.
    pub wave_speed: f64,
    /// Characteristic length L_e.
    pub length: f64,
}

impl ElementScale {
    /// The scale of the element on the nodes `x` with lumped mass `mass` and volume `volume`
    /// (thickness or 2 pi r included), whose body has the plane-wave modulus `wave_modulus`.
    #[inline(always)]
    pub fn new(x: &Nodes, mass: f64, volume: f64, wave_modulus: f64) -> ElementScale {
        let density = mass / volume;
        ElementScale {
            density,
            wave_speed: (wave_modulus / density).sqrt(),
            length: characteristic_length(x),
        }
    }
}

/// L_e = A / D_max (see the legend).
#[inline(always)]
pub fn characteristic_length(x: &Nodes) -> f64 {
    // the longer diagonal's square first, one root (hypot per diagonal was a tenth of the
    // one-point step: libm's hypot guards against overflow no element length comes near)
    let squared = |a: usize, b: usize| {
        let (dx, dy) = (x[b][0] - x[a][0], x[b][1] - x[a][1]);
        dx * dx + dy * dy
    };
    area(x) / squared(0, 2).max(squared(1, 3)).sqrt()
}

impl BulkViscosity {
    /// The viscous pressure q = -(p_1 + p_2) at volumetric strain rate `rate` (positive in
    /// compression).
    #[inline(always)]
    pub fn pressure(&self, scale: &ElementScale, rate: f64) -> f64 {
        let linear = self.linear * scale.density * scale.wave_speed * scale.length * rate;
        let reach = self.quadratic * scale.length;
        let quadratic = scale.density * reach * reach * rate.abs() * rate.min(0.0);
        -(linear + quadratic)
    }

    /// The fraction of critical damping xi of an element at rest (no strain rate yet): b_1,
    /// the same for every element (`damping_fraction` at rate 0).
    #[inline(always)]
    pub fn damping_fraction_at_rest(&self) -> f64 {
        self.linear
    }

    /// The fraction of critical damping xi in the element's highest mode at volumetric
    /// strain rate `rate` (b_1 at rest or in expansion).
    #[inline(always)]
    pub fn damping_fraction(&self, scale: &ElementScale, rate: f64) -> f64 {
        self.linear
            - self.quadratic * self.quadratic * scale.length / scale.wave_speed * rate.min(0.0)
    }
}

/// The bulk viscosity at one point over one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViscousStep {
    /// q at the end of the step.
    pub pressure: f64,
    /// The work of the viscous pressure over the step.
    pub work: f64,
    /// xi at the step's rate.
    pub damping_fraction: f64,
}

impl BulkViscosity {
    /// One step of length `dt` at a point of volume `volume` (on the mid configuration) whose
    /// strain increment has the volumetric part `volumetric` (`volumetric_increment`), the
    /// pressure at its start being `start_pressure` (see the legend).
    #[inline(always)]
    pub fn step(
        &self,
        scale: &ElementScale,
        volumetric: f64,
        dt: f64,
        volume: f64,
        start_pressure: f64,
    ) -> ViscousStep {
        let rate = volumetric / dt;
        let pressure = self.pressure(scale, rate);
        ViscousStep {
            pressure,
            work: -volume * 0.5 * (start_pressure + pressure) * volumetric,
            damping_fraction: self.damping_fraction(scale, rate),
        }
    }
}

/// The factor sqrt(1 + xi^2) - xi by which a fraction xi of critical damping shortens the
/// stable step of central difference, 2 / omega, in a mode of frequency omega (Abaqus Theory
/// Manual, "Explicit dynamic analysis": the stability limit with damping). 1 at xi = 0.
#[inline(always)]
pub fn damped_step_factor(damping_fraction: f64) -> f64 {
    let xi = damping_fraction;
    (1.0 + xi * xi).sqrt() - xi
}

/// The square of `damped_step_factor`: an element's undamped frequency bound squared over
/// its damped one (`damped_frequency_squared`).
#[inline(always)]
pub fn damping_factor(damping_fraction: f64) -> f64 {
    let factor = damped_step_factor(damping_fraction);
    factor * factor
}

/// The element frequency bound squared whose undamped step 2 / omega is the damped step
/// of an element with bound `omega_squared` and damping fraction `damping_fraction`: the
/// stable-step rule then takes the damping into account unchanged.
#[inline(always)]
pub fn damped_frequency_squared(omega_squared: f64, damping_fraction: f64) -> f64 {
    omega_squared / damping_factor(damping_fraction)
}

/// The volumetric part of a strain increment (see the legend): the trace over the components
/// the formulation's forces carry.
#[inline(always)]
pub fn volumetric_increment(strain: &[f64; 4], formulation: Formulation) -> f64 {
    match formulation {
        Formulation::PlaneStress => strain[0] + strain[1],
        Formulation::PlaneStrain | Formulation::Axisymmetric => strain[0] + strain[1] + strain[2],
    }
}

/// The stress the nodal forces see: `stress` minus the viscous pressure `q` on its normal
/// components (plane stress: in plane; sigma_zz stays 0).
#[inline(always)]
pub fn loaded_stress(stress: &[f64; 4], q: f64, formulation: Formulation) -> [f64; 4] {
    let zz = match formulation {
        Formulation::PlaneStress => stress[2],
        Formulation::PlaneStrain | Formulation::Axisymmetric => stress[2] - q,
    };
    [stress[0] - q, stress[1] - q, zz, stress[3]]
}

#[cfg(test)]
mod tests {
    use super::*;

    const DEFAULTS: BulkViscosity = BulkViscosity {
        linear: DEFAULT_LINEAR,
        quadratic: DEFAULT_QUADRATIC,
    };

    /// A rectangle a x b has L_e = a b / sqrt(a^2 + b^2); a slender one its short side nearly.
    #[test]
    fn characteristic_length_of_rectangles() {
        let rectangle = |a: f64, b: f64| -> Nodes { [[0.0, 0.0], [a, 0.0], [a, b], [0.0, b]] };
        assert!((characteristic_length(&rectangle(3.0, 4.0)) - 12.0 / 5.0).abs() < 1e-14);
        assert!((characteristic_length(&rectangle(1.0, 1.0)) - 0.5f64.sqrt()).abs() < 1e-15);
        let slender = characteristic_length(&rectangle(0.1, 2.0));
        assert!((slender - 0.2 / 4.01f64.sqrt()).abs() < 1e-15, "{slender}");
    }

    /// In compression both terms resist (q > 0); in expansion the linear term alone acts, with
    /// the opposite sign; the values are the formulas of the legend worked by hand.
    #[test]
    fn pressure_resists_the_rate() {
        // rho = 2, c_d = 3, L_e = 0.5
        let scale = ElementScale {
            density: 2.0,
            wave_speed: 3.0,
            length: 0.5,
        };
        // rate -4: p_1 = 0.06 * 2 * 3 * 0.5 * -4 = -0.72; p_2 = 2 * 0.36 * 4 * -4 = -11.52
        assert!((DEFAULTS.pressure(&scale, -4.0) - 12.24).abs() < 1e-12);
        // rate +4: p_1 = 0.72, p_2 = 0
        assert!((DEFAULTS.pressure(&scale, 4.0) + 0.72).abs() < 1e-12);
        // xi at rate -4: 0.06 + 1.44 * 0.5 / 3 * 4 = 1.02
        assert!((DEFAULTS.damping_fraction(&scale, -4.0) - 1.02).abs() < 1e-12);
        assert_eq!(DEFAULTS.damping_fraction(&scale, 4.0), DEFAULT_LINEAR);
        assert_eq!(
            DEFAULTS.damping_fraction(&scale, 0.0),
            DEFAULTS.damping_fraction_at_rest()
        );
    }

    /// The damped step factor solves the stability condition of the lagged-velocity central
    /// difference: with u_{n+1} - 2 u_n + u_{n-1} = -W^2 u_n - 2 xi W (u_n - u_{n-1}),
    /// W = omega dt, the root z = -1 of z^2 - (2 - W^2 - 2 xi W) z + 1 - 2 xi W sits at
    /// 4 - W^2 - 4 xi W = 0, so W = 2 (sqrt(1 + xi^2) - xi).
    #[test]
    fn damped_step_factor_is_the_stability_limit() {
        for xi in [0.0, 0.06, 0.5, 2.0] {
            let w = 2.0 * damped_step_factor(xi);
            assert!((4.0 - w * w - 4.0 * xi * w).abs() < 1e-12, "xi {xi}");
        }
        assert_eq!(damped_step_factor(0.0), 1.0);
        assert_eq!(damped_frequency_squared(4.0, 0.0), 4.0);
    }
}
