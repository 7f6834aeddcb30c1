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
//! dt        the time step of the increment (the rate of rate-dependent laws)
//! T         temperature (Johnson-Cook: T_n+1 = T_n + chi w_p / (rho c_p), see johnson_cook)
//! ```
//! `&self` is never mutated: a failed iteration cannot corrupt the history; the caller
//! commits a step by keeping the returned state.

pub mod j2;
pub mod johnson_cook;

use crate::element::{Formulation, Moduli, Voigt};
use j2::Radial;
pub use j2::{FlowStart, Hardening, J2};
pub use johnson_cook::JohnsonCook;

/// How many stress components the body carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StressCondition {
    /// Plane strain and axisymmetric: all four components.
    General,
    /// sigma_zz = 0; the material decides the out-of-plane strain.
    PlaneStress,
}

impl StressCondition {
    /// The stress condition of a continuum formulation.
    #[inline]
    pub fn of(formulation: Formulation) -> StressCondition {
        if formulation == Formulation::PlaneStress {
            StressCondition::PlaneStress
        } else {
            StressCondition::General
        }
    }
}

/// What a material update needs besides the committed state and the strain increment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UpdateContext {
    pub condition: StressCondition,
    /// The time step of the increment (statics: the pseudo-time step), for the strain rate
    /// of rate-dependent laws; infinity when there is no step (the rate is then zero).
    pub dt: f64,
}

/// Committed state of one material point.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct PointState {
    /// Cauchy stress [xx yy zz xy] (for rods only xx is used: the axial stress).
    pub stress: Voigt,
    /// Equivalent plastic strain.
    pub eq_plastic_strain: f64,
    /// Back stress (kinematic hardening), same frame and components as `stress`.
    pub back_stress: Voigt,
    /// Temperature: Johnson-Cook materials heat adiabatically from their initial
    /// temperature; the other materials carry none and keep 0.
    #[serde(default)]
    pub temperature: f64,
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
    /// Plastic work per unit reference volume of the increment, S_{n+1} : d eps_p.
    pub plastic_work: f64,
}

/// Isotropic linear elasticity (in the rate form S = sigma_n + D dE of the updated-Lagrangian
/// increment).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elastic {
    pub young: f64,
    pub poisson: f64,
    /// (lambda, mu) of young and poisson, computed once by `new`: the explicit kernels read
    /// them at every point of every step.
    lame: (f64, f64),
}

impl Elastic {
    pub fn new(young: f64, poisson: f64) -> Elastic {
        let (e, nu) = (young, poisson);
        Elastic {
            young,
            poisson,
            lame: (
                e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
                e / (2.0 * (1.0 + nu)),
            ),
        }
    }

    /// The Lame constants (lambda, mu) of the 3D law.
    #[inline]
    pub fn lame(&self) -> (f64, f64) {
        self.lame
    }

    /// The Lame constants of the in-plane law of `condition`: those of the 3D law, or in
    /// plane stress lambda condensed by sigma_zz = 0, 2 lambda mu / (lambda + 2 mu) (mu is
    /// unchanged). The moduli, the P-wave modulus and the element frequency bounds all take
    /// lambda from here.
    #[inline]
    pub fn lame_in(&self, condition: StressCondition) -> (f64, f64) {
        let (lambda, mu) = self.lame();
        match condition {
            StressCondition::General => (lambda, mu),
            StressCondition::PlaneStress => (2.0 * lambda * mu / (lambda + 2.0 * mu), mu),
        }
    }

    /// Elastic moduli; in plane stress the condensed in-plane moduli with the zz row and
    /// column zero.
    #[inline]
    pub fn moduli(&self, state: StressCondition) -> Moduli {
        let (lambda, mu) = self.lame_in(state);
        let mut d = Moduli::zeros();
        let normal = if state == StressCondition::General {
            3
        } else {
            2
        };
        for a in 0..normal {
            for b in 0..normal {
                d[(a, b)] = lambda;
            }
            d[(a, a)] += 2.0 * mu;
        }
        d[(3, 3)] = mu;
        d
    }

    /// The P-wave (constrained) modulus M = rho c^2 of the dilatational wave under
    /// `condition`: lambda + 2 mu with the lambda of `lame_in` (plane stress: E / (1 - nu^2)).
    /// A rod's is E.
    #[inline]
    pub fn p_wave_modulus(&self, condition: StressCondition) -> f64 {
        let (lambda, mu) = self.lame_in(condition);
        lambda + 2.0 * mu
    }
}

/// A material as the analysis uses it.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    pub name: String,
    pub density: f64,
    pub elastic: Elastic,
    /// J2 plasticity; None for an elastic material.
    pub plasticity: Option<J2>,
}

impl Material {
    /// The Johnson-Cook law of the material, if it has one.
    pub fn johnson_cook(&self) -> Option<&JohnsonCook> {
        match &self.plasticity.as_ref()?.hardening {
            Hardening::JohnsonCook(law) => Some(law),
            _ => None,
        }
    }

    /// Whether the points carry a temperature (Johnson-Cook materials).
    pub fn carries_temperature(&self) -> bool {
        self.johnson_cook().is_some()
    }

    /// The temperature of the points at t = 0 (0 for materials that carry none).
    pub fn initial_temperature(&self) -> f64 {
        self.johnson_cook()
            .map_or(0.0, |law| law.initial_temperature)
    }

    /// The temperature after the plastic work `plastic_work` per unit volume at `temperature`
    /// (adiabatic heating; unchanged for materials that carry no temperature). Inside the
    /// updates only: a point heats in the step that does the work.
    fn heated(&self, temperature: f64, plastic_work: f64) -> f64 {
        match self.johnson_cook() {
            Some(law) => temperature + law.temperature_rise(plastic_work, self.density),
            None => temperature,
        }
    }

    /// The one update of a continuum point, which the implicit kernel (through `update`) and
    /// both explicit kernels call: the committed state in the frame of the increment (pushed
    /// to the reference configuration, or rotated by the step's spin), the strain increment
    /// and the time step in; the new state out, after the elastic predictor, the return to
    /// the yield surface and the adiabatic heating of the step. No tangent.
    #[inline(always)]
    pub fn step(
        &self,
        committed: &PointState,
        strain: &Voigt,
        context: UpdateContext,
    ) -> PointStep {
        match context.condition {
            StressCondition::General => {
                self.general_step(committed, strain, context.dt, |_, _, _| ())
                    .0
            }
            StressCondition::PlaneStress => {
                let r = self.update_plane_stress(committed, strain, context.dt);
                PointStep {
                    state: r.state,
                    plastic_work: r.plastic_work,
                    strain_zz: r.strain_zz,
                }
            }
        }
    }

    /// Response of a continuum point (Quad4): `step` with the algorithmic tangent.
    pub fn update(
        &self,
        committed: &PointState,
        strain: &Voigt,
        context: UpdateContext,
    ) -> Response {
        self.update_with(committed, strain, context, true)
    }

    /// `update`, or (`tangent` false) for a caller that reads no tangent (a residual): a
    /// plastic point of the general condition then skips its algorithmic moduli and carries
    /// the elastic ones in their place. Stress and state are those of `step`, bit for bit.
    /// (Plane stress solves for its out-of-plane strain with the tangent, so it keeps it.)
    pub fn update_with(
        &self,
        committed: &PointState,
        strain: &Voigt,
        context: UpdateContext,
        tangent: bool,
    ) -> Response {
        match context.condition {
            StressCondition::General => self.general(committed, strain, context.dt, tangent),
            StressCondition::PlaneStress => self.update_plane_stress(committed, strain, context.dt),
        }
    }

    /// The elastic predictor S = sigma_n + D_e dE (from the Lame constants: the same moduli,
    /// fewer products than D_e's 16), the J2 return and the heating of the general condition
    /// (plane strain, axisymmetric). A plastic point also hands its return to `returned`
    /// (the implicit kernel's tangent; the explicit kernels take nothing, so the return's
    /// record is never copied out of the update).
    #[inline(always)]
    fn general_step<T>(
        &self,
        committed: &PointState,
        strain: &Voigt,
        dt: f64,
        returned: impl FnOnce(&J2, &Radial, f64) -> T,
    ) -> (PointStep, Option<T>) {
        let (lambda, mu) = self.elastic.lame();
        let volumetric = lambda * (strain[0] + strain[1] + strain[2]);
        let trial = committed.stress
            + Voigt::new(
                volumetric + 2.0 * mu * strain[0],
                volumetric + 2.0 * mu * strain[1],
                volumetric + 2.0 * mu * strain[2],
                mu * strain[3],
            );
        let start = FlowStart {
            eq_plastic_strain: committed.eq_plastic_strain,
            temperature: committed.temperature,
            dt,
        };
        let plastic = self.plasticity.as_ref().and_then(|j2| {
            j2.radial(&trial, mu, &committed.back_stress, start)
                .map(|r| (j2, r))
        });
        let Some((j2, r)) = plastic else {
            let elastic = PointStep {
                state: PointState {
                    stress: trial,
                    ..*committed
                },
                plastic_work: 0.0,
                strain_zz: strain[2],
            };
            return (elastic, None);
        };
        let plastic_work = r.plastic_work();
        let step = PointStep {
            state: PointState {
                stress: r.stress,
                eq_plastic_strain: r.eq_plastic_strain,
                back_stress: r.back_stress,
                temperature: self.heated(committed.temperature, plastic_work),
            },
            plastic_work,
            strain_zz: strain[2],
        };
        (step, Some(returned(j2, &r, mu)))
    }

    /// The general update with the algorithmic tangent (`tangent`) or the elastic moduli.
    #[inline(always)]
    fn general(&self, committed: &PointState, strain: &Voigt, dt: f64, tangent: bool) -> Response {
        let elastic = self.elastic.moduli(StressCondition::General);
        let (step, moduli) = self.general_step(committed, strain, dt, |j2, r, mu| {
            if tangent {
                j2.tangent(r, &elastic, mu)
            } else {
                elastic
            }
        });
        Response {
            stress: step.state.stress,
            moduli: moduli.unwrap_or(elastic),
            strain_zz: step.strain_zz,
            state: step.state,
            plastic_work: step.plastic_work,
        }
    }

    /// Plane stress: the out-of-plane strain that makes the 3D update give S_zz = 0, by
    /// Newton safeguarded with bisection (S_zz grows monotonically with eps_zz, but its slope
    /// jumps where the point turns plastic), to round-off; then the tangent condensed
    /// statically: D_ps = D_ab - D_a,zz D_zz,b / D_zz,zz over a, b in {xx, yy, xy}.
    fn update_plane_stress(&self, committed: &PointState, strain: &Voigt, dt: f64) -> Response {
        let (lambda, mu) = self.elastic.lame();
        let mut trial = *strain;
        trial[2] = -(lambda * (strain[0] + strain[1]) + committed.stress[2]) / (lambda + 2.0 * mu);
        let scale = self
            .plasticity
            .as_ref()
            .map_or(0.0, |j| j.yield_stress)
            .max(committed.stress.norm());
        let tolerance = 1e-15 * scale.max(self.elastic.young * strain.norm());
        let mut response = self.general(committed, &trial, dt, true);
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for _ in 0..200 {
            let szz = response.stress[2];
            if szz.abs() <= tolerance {
                break;
            }
            if szz > 0.0 {
                hi = trial[2];
            } else {
                lo = trial[2];
            }
            let mut next = trial[2] - szz / response.moduli[(2, 2)];
            if !(next > lo && next < hi) {
                next = if lo.is_finite() && hi.is_finite() {
                    0.5 * (lo + hi)
                } else {
                    // widen towards the missing side of the bracket
                    trial[2] - szz.signum() * (strain.norm() + trial[2].abs() + f64::EPSILON)
                };
            }
            if next == trial[2] {
                break;
            }
            trial[2] = next;
            response = self.general(committed, &trial, dt, true);
        }
        let d = response.moduli;
        let mut condensed = Moduli::zeros();
        for a in [0, 1, 3] {
            for b in [0, 1, 3] {
                condensed[(a, b)] = d[(a, b)] - d[(a, 2)] * d[(2, b)] / d[(2, 2)];
            }
        }
        response.moduli = condensed;
        response.stress[2] = 0.0;
        response.state.stress[2] = 0.0;
        response.strain_zz = trial[2];
        response
    }

    /// Response of a rod to an axial strain increment over the time step `dt`.
    #[inline]
    pub fn update_uniaxial(
        &self,
        committed: &PointState,
        strain: f64,
        dt: f64,
    ) -> UniaxialResponse {
        let young = self.elastic.young;
        let trial = committed.stress[0] + young * strain;
        let plastic = self.plasticity.as_ref().and_then(|j2| {
            j2.uniaxial(
                trial,
                young,
                committed.back_stress[0],
                FlowStart {
                    eq_plastic_strain: committed.eq_plastic_strain,
                    temperature: committed.temperature,
                    dt,
                },
            )
        });
        let mut state = *committed;
        match plastic {
            None => {
                state.stress[0] = trial;
                UniaxialResponse {
                    stress: trial,
                    tangent: young,
                    state,
                    plastic_work: 0.0,
                }
            }
            Some(r) => {
                let plastic_work = r.stress * r.plastic_strain;
                state.stress[0] = r.stress;
                state.back_stress[0] = r.back_stress;
                state.eq_plastic_strain = r.eq_plastic_strain;
                state.temperature = self.heated(committed.temperature, plastic_work);
                UniaxialResponse {
                    stress: r.stress,
                    tangent: r.tangent,
                    state,
                    plastic_work,
                }
            }
        }
    }
}

/// A point after one increment: the one update's output (no tangent).
#[derive(Debug, Clone, Copy)]
pub struct PointStep {
    /// The new state, its stress in the frame of the increment.
    pub state: PointState,
    /// Plastic work per unit volume of the increment, S_{n+1} : d eps_p.
    pub plastic_work: f64,
    /// The out-of-plane strain increment: the material's in plane stress, else the input's.
    pub strain_zz: f64,
}

/// The response of a rod point.
#[derive(Debug, Clone, Copy)]
pub struct UniaxialResponse {
    /// Axial second Piola-Kirchhoff stress relative to the reference configuration.
    pub stress: f64,
    /// dS/dE.
    pub tangent: f64,
    pub state: PointState,
    /// Plastic work per unit reference volume of the increment.
    pub plastic_work: f64,
}

/// The plastic work of an increment by the trapezoidal rule, 1/2 (S_n + S_{n+1}) : d eps_p,
/// from the return's S_{n+1} : d eps_p (`plastic_work`) and the start stress: with
/// d eps_p = dl n and n the direction of the returned relative stress dev(S_{n+1} - alpha),
/// S_n : d eps_p = (s_n : n) / (s_{n+1} : n) times it. The energy bookkeeping uses this
/// value: the element work is summed by the same rule, 1/2 (S_n + S_{n+1}) : d eps, so
/// work - dissipation = 1/2 (S_n + S_{n+1}) : C^-1 (S_{n+1} - S_n), the exact change of
/// the stored elastic energy, and the stored energy cannot drift below zero (with
/// S_{n+1} : d eps_p the difference 1/2 (S_{n+1} - S_n) : d eps_p >= 0 is lost every plastic
/// step). It is never negative: |s_n : n| <= sigma_y,n <= s_{n+1} : n under hardening.
/// The heating of Johnson-Cook keeps the return's own S_{n+1} : d eps_p.
#[inline]
pub fn trapezoid_dissipation(
    start: &Voigt,
    end: &Voigt,
    end_back: &Voigt,
    plastic_work: f64,
) -> f64 {
    if plastic_work == 0.0 {
        return 0.0;
    }
    let relative = end - end_back;
    let p = (relative[0] + relative[1] + relative[2]) / 3.0;
    let n = Voigt::new(
        relative[0] - p,
        relative[1] - p,
        relative[2] - p,
        relative[3],
    );
    let dot = |a: &Voigt| a[0] * n[0] + a[1] * n[1] + a[2] * n[2] + 2.0 * a[3] * n[3];
    let along_end = dot(end);
    if along_end <= 0.0 {
        return plastic_work;
    }
    0.5 * (1.0 + dot(start) / along_end) * plastic_work
}

/// [`trapezoid_dissipation`], refused (`Err` with its value) where it is negative beyond
/// round-off at a point without back stress and a yield stress that did not fall. The factor
/// 1 + s_n : n / s_{n+1} : n < 0 needs the start stress reversed beyond the whole elastic
/// range of the end, and |s_n : n| <= |s_n| (Cauchy-Schwarz): under hardening, |s_n| <=
/// |s_{n+1}| on the yield surfaces, it cannot be negative, and a run would book negative
/// plastic work, which no material dissipates. Where the yield stress falls between the
/// two (Johnson-Cook's rate and thermal terms, |s_n| > |s_{n+1}|) a reversal, the highest
/// mode of a struck face ringing near the stable step, makes it negative by at most
/// (|s_n| / |s_{n+1}| - 1) / 2 of the increment: the trapezoid's path through the elastic
/// range, not a material giving energy back; it is booked as it is, which keeps work minus
/// dissipation the exact change of the stored energy (docs/theory.md 8.7). With kinematic
/// hardening a reversed flow gives back stored back-stress energy, and an increment may be
/// negative; its total is the run's to check. For the explicit kernels, whose every step is
/// final; Newton's iterates may pass through such states, and the implicit run checks its
/// committed total instead.
/// (Inlined always, the rare negative case out of line: whether the compiler inlined it at
/// the explicit kernels' call moved with unrelated changes, 1 % of a Johnson-Cook rod's
/// instructions.)
#[inline(always)]
pub fn dissipation(
    start: &Voigt,
    end: &Voigt,
    end_back: &Voigt,
    plastic_work: f64,
) -> Result<f64, f64> {
    let d = trapezoid_dissipation(start, end, end_back, plastic_work);
    // (the cheap test first: every elastic point of an explicit step passes here)
    if !(d < 0.0 && d < -1e-9 * plastic_work.abs()) {
        return Ok(d);
    }
    negative_dissipation(start, end, end_back, d)
}

/// [`dissipation`]'s negative increment `d`: kept where a back stress or a falling yield
/// stress explains it, refused otherwise.
#[cold]
#[inline(never)]
fn negative_dissipation(start: &Voigt, end: &Voigt, end_back: &Voigt, d: f64) -> Result<f64, f64> {
    let kinematic = end_back.iter().any(|b| *b != 0.0);
    // |s_n| > |s_{n+1}|: von Mises' stress is sqrt(3/2) |dev s|
    let fell = von_mises(start) > von_mises(end);
    if kinematic || fell { Ok(d) } else { Err(d) }
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

    /// Plane-stress moduli give the textbook E / (1 - nu^2) in-plane stiffness and the
    /// out-of-plane strain -nu / (1 - nu) of the in-plane normal strain; the three-dimensional
    /// update at the returned strain_zz gives S_zz = 0 (to 1e-12 of the stress: the iteration
    /// stops at 1e-15 of the scale).
    #[test]
    fn plane_stress_keeps_szz_zero() {
        let m = Material {
            name: "m".into(),
            density: 1.0,
            elastic: Elastic::new(200.0, 0.3),
            plasticity: None,
        };
        let r = m.update(
            &PointState::default(),
            &Voigt::new(1e-3, 0.0, 0.0, 0.0),
            UpdateContext {
                condition: StressCondition::PlaneStress,
                dt: 1.0,
            },
        );
        approx::assert_relative_eq!(
            r.stress[0],
            200.0 / (1.0 - 0.09) * 1e-3,
            max_relative = 1e-14
        );
        approx::assert_relative_eq!(r.strain_zz, -0.3 / 0.7 * 1e-3, max_relative = 1e-14);
        let replay = m.update(
            &PointState::default(),
            &Voigt::new(1e-3, 0.0, r.strain_zz, 0.0),
            UpdateContext {
                condition: StressCondition::General,
                dt: 1.0,
            },
        );
        assert!(replay.stress[2].abs() <= 1e-12 * replay.stress.norm());
    }

    /// A return whose start stress lies reversed beyond the end's elastic range is booked by
    /// the trapezoid where the yield stress fell (it was refused before, which stopped the
    /// struck faces of Johnson-Cook rods at the longer steps). By hand, deviatoric stresses
    /// along n = (1, -1, 0, 0): s_n = -a n, s_{n+1} = b n, the trapezoid 1/2 (1 - a / b) W.
    /// With a = 1.02, b = 1 (the start's von Mises above the end's) it is -0.01 W, returned;
    /// with a = 1, b = 1.02 (the yield stress grew) 1/2 (1 - 1/1.02) W > 0. (A negative
    /// trapezoid with the start not above the end is what Cauchy-Schwarz forbids: the refusal
    /// is left to round-off.)
    #[test]
    fn a_reversal_under_a_falling_yield_stress_is_booked_by_the_trapezoid() {
        let along = |k: f64| Voigt::new(k, -k, 0.0, 0.0);
        let none = Voigt::zeros();
        let d = dissipation(&along(-1.02), &along(1.0), &none, 1.0).unwrap();
        assert!((d - (-0.01)).abs() < 1e-12, "{d}");
        let d = dissipation(&along(-1.0), &along(1.02), &none, 1.0).unwrap();
        assert!((d - 0.5 * (1.0 - 1.0 / 1.02)).abs() < 1e-12, "{d}");
    }
}

#[cfg(test)]
mod plasticity_tests {
    use super::*;

    fn steel(hardening: Hardening, kinematic: f64) -> Material {
        Material {
            name: "steel".into(),
            density: 1.0,
            elastic: Elastic::new(200.0, 0.3),
            plasticity: Some(J2 {
                yield_stress: 0.5,
                hardening,
                kinematic_modulus: kinematic,
            }),
        }
    }

    fn committed() -> PointState {
        PointState {
            stress: Voigt::new(0.2, -0.1, 0.05, 0.15),
            eq_plastic_strain: 0.01,
            back_stress: Voigt::new(0.02, -0.01, -0.01, 0.01),
            temperature: 0.0,
        }
    }

    fn at(condition: StressCondition) -> UpdateContext {
        UpdateContext { condition, dt: 1.0 }
    }

    /// The algorithmic tangent is the derivative of the return map (central differences,
    /// h = 1e-8 against strain increments ~ 1e-2: truncation ~ 1e-12 relative; round-off
    /// eps |S| / h ~ 1e-8 and the plane-stress iteration's stop, 1e-15 of the stress scale
    /// over h, ~ 1e-7 absolute, against moduli of norm ~ 400: 1e-9 of the norm bounds both),
    /// for linear and tabulated isotropic plus kinematic hardening, in plane strain and plane
    /// stress.
    #[test]
    fn tangent_matches_finite_differences_of_the_return() {
        let laws = [
            (Hardening::Linear { modulus: 10.0 }, 5.0),
            (
                Hardening::Table {
                    points: vec![[0.005, 0.55], [0.02, 0.6], [0.1, 0.62]],
                },
                0.0,
            ),
            (Hardening::Linear { modulus: 0.0 }, 0.0),
        ];
        for (law, kinematic) in laws {
            let m = steel(law, kinematic);
            for state in [StressCondition::General, StressCondition::PlaneStress] {
                let mut c = committed();
                if state == StressCondition::PlaneStress {
                    c.stress[2] = 0.0;
                    c.back_stress[2] = 0.0;
                }
                let strain = Voigt::new(0.004, -0.001, 0.0005, 0.003);
                let r = m.update(&c, &strain, at(state));
                assert!(r.plastic_work > 0.0, "the step must be plastic");
                let h = 1e-8;
                let columns: &[usize] = if state == StressCondition::General {
                    &[0, 1, 2, 3]
                } else {
                    &[0, 1, 3]
                };
                for &j in columns {
                    let (mut p, mut q) = (strain, strain);
                    p[j] += h;
                    q[j] -= h;
                    let fd = (m.update(&c, &p, at(state)).stress
                        - m.update(&c, &q, at(state)).stress)
                        / (2.0 * h);
                    for i in 0..4 {
                        assert!(
                            (r.moduli[(i, j)] - fd[i]).abs() <= 1e-9 * r.moduli.norm(),
                            "{state:?} kin {kinematic} ({i},{j}): {} vs {}",
                            r.moduli[(i, j)],
                            fd[i]
                        );
                    }
                }
            }
        }
    }

    /// The residual's update (`update_with`, no tangent) returns the stress and state of
    /// `update` bit for bit, plastic and elastic, in both conditions: the Newton iteration
    /// mixes the two within a step.
    #[test]
    fn the_update_without_tangent_keeps_the_state() {
        let m = steel(Hardening::Linear { modulus: 10.0 }, 5.0);
        for state in [StressCondition::General, StressCondition::PlaneStress] {
            for strain in [
                Voigt::new(0.004, -0.001, 0.0005, 0.003),
                Voigt::new(1e-5, 0.0, 0.0, 0.0),
            ] {
                let full = m.update(&committed(), &strain, at(state));
                let residual = m.update_with(&committed(), &strain, at(state), false);
                assert_eq!(full.stress, residual.stress);
                assert_eq!(full.state, residual.state);
                assert_eq!(full.plastic_work, residual.plastic_work);
                assert_eq!(full.strain_zz, residual.strain_zz);
            }
        }
        let r = m.update(
            &committed(),
            &Voigt::new(0.004, -0.001, 0.0005, 0.003),
            at(StressCondition::General),
        );
        assert!(r.plastic_work > 0.0, "the first strain must be plastic");
    }

    /// After a plastic step the stress lies on the yield surface, sqrt(3/2) |dev S - alpha| =
    /// sigma_y(eps_p), to round-off. In plane stress, the three-dimensional update replayed at
    /// the returned strain_zz gives S_zz = 0 (1e-12 of the stress) and the same in-plane
    /// stress and state: the plane-stress result is the 3D model's, not a zero written over it.
    #[test]
    fn plastic_state_lies_on_the_yield_surface() {
        let m = steel(Hardening::Linear { modulus: 10.0 }, 5.0);
        for state in [StressCondition::General, StressCondition::PlaneStress] {
            let mut c = committed();
            if state == StressCondition::PlaneStress {
                c.stress[2] = 0.0;
            }
            let strain = Voigt::new(0.004, -0.001, 0.0005, 0.003);
            let r = m.update(&c, &strain, at(state));
            let s = r.state.stress;
            let p = (s[0] + s[1] + s[2]) / 3.0;
            let a = r.state.back_stress;
            let eta = Voigt::new(
                s[0] - p - a[0],
                s[1] - p - a[1],
                s[2] - p - a[2],
                s[3] - a[3],
            );
            let mises = (1.5
                * (eta[0].powi(2) + eta[1].powi(2) + eta[2].powi(2) + 2.0 * eta[3].powi(2)))
            .sqrt();
            let sy = 0.5 + 10.0 * r.state.eq_plastic_strain;
            approx::assert_relative_eq!(mises, sy, max_relative = 1e-12);
            if state == StressCondition::PlaneStress {
                let mut strain_3d = strain;
                strain_3d[2] = r.strain_zz;
                let replay = m.update(&c, &strain_3d, at(StressCondition::General));
                let scale = replay.stress.norm();
                assert!(
                    replay.stress[2].abs() <= 1e-12 * scale,
                    "{}",
                    replay.stress[2]
                );
                for i in [0, 1, 3] {
                    approx::assert_abs_diff_eq!(s[i], replay.stress[i], epsilon = 1e-12 * scale);
                }
                assert_eq!(r.state.eq_plastic_strain, replay.state.eq_plastic_strain);
            }
        }
    }

    fn johnson_cook_steel() -> Material {
        let law = JohnsonCook {
            b: 0.3,
            n: 0.3,
            c: 0.02,
            reference_rate: 1.0,
            m: 1.0,
            room_temperature: 0.0,
            melting_temperature: 1.0,
            specific_heat: 1.0,
            taylor_quinney: 0.9,
            initial_temperature: 0.0,
        };
        Material {
            plasticity: Some(J2 {
                yield_stress: 0.5,
                hardening: Hardening::JohnsonCook(law),
                kinematic_modulus: 0.0,
            }),
            ..steel(Hardening::Linear { modulus: 0.0 }, 0.0)
        }
    }

    /// Goal: the Johnson-Cook tangent (the radial return's formula with the flow stress's
    /// total slope in dep, rate term included) is the derivative of the return map, in plane
    /// strain and plane stress, from a hardened warm point and from the first yield (eps_p =
    /// 0 with n = 0.3 < 1: the multiplier's Newton starts at an infinite slope and bisects).
    /// Setup: E = 200, A = 0.5, B = 0.3, n = 0.3, C = 0.02, rate_0 = 1, m = 1, T* = 0.3 or 0;
    /// strain increments ~ 1e-2 over dt = 1e-3 (rates ~ 10 > rate_0: the rate term is on).
    /// Reference: central differences of the stress, h = 1e-8; tolerance 1e-8 of the
    /// tangent's norm (the multiplier's Newton stops at 1e-15 relative: ~1e-7 absolute over
    /// h against moduli of norm ~ 400, as for the other laws, with a margin for the rate
    /// term's curvature).
    #[test]
    fn johnson_cook_tangent_matches_finite_differences_of_the_return() {
        let m = johnson_cook_steel();
        let mut worst: f64 = 0.0;
        let warm = PointState {
            back_stress: Voigt::zeros(),
            temperature: 0.3,
            ..committed()
        };
        let virgin = PointState::default();
        for (c, strain) in [
            (warm, Voigt::new(0.004, -0.001, 0.0005, 0.003)),
            (virgin, Voigt::new(0.008, -0.002, 0.0, 0.006)),
        ] {
            for condition in [StressCondition::General, StressCondition::PlaneStress] {
                let mut c = c;
                if condition == StressCondition::PlaneStress {
                    c.stress[2] = 0.0;
                }
                let context = UpdateContext {
                    condition,
                    dt: 1e-3,
                };
                let r = m.update(&c, &strain, context);
                let dep = r.state.eq_plastic_strain - c.eq_plastic_strain;
                assert!(
                    dep / 1e-3 > 1.0,
                    "the rate term must be on: rate {}",
                    dep / 1e-3
                );
                let h = 1e-8;
                let columns: &[usize] = if condition == StressCondition::General {
                    &[0, 1, 2, 3]
                } else {
                    &[0, 1, 3]
                };
                for &j in columns {
                    let (mut p, mut q) = (strain, strain);
                    p[j] += h;
                    q[j] -= h;
                    let fd = (m.update(&c, &p, context).stress - m.update(&c, &q, context).stress)
                        / (2.0 * h);
                    for i in 0..4 {
                        worst = worst.max((r.moduli[(i, j)] - fd[i]).abs() / r.moduli.norm());
                        assert!(
                            (r.moduli[(i, j)] - fd[i]).abs() <= 1e-8 * r.moduli.norm(),
                            "{condition:?} eps_p {} ({i},{j}): {} vs {}",
                            c.eq_plastic_strain,
                            r.moduli[(i, j)],
                            fd[i]
                        );
                    }
                }
            }
        }
        println!("largest |D - D_fd| / |D|: {worst:.1e}");
    }

    /// Goal: the rod's tangent is the derivative of its one-dimensional return, for linear
    /// hardening with kinematic hardening and for Johnson-Cook (rate term on, and from eps_p
    /// = 0 with n < 1, where the slope is infinite at the start and the tangent uses the
    /// slope at the solution).
    /// Setup: axial strain increments 4e-3 and -8e-3 over dt = 1e-3 from a warm hardened
    /// point and from a virgin one.
    /// Reference: central differences, h = 1e-9: round-off eps |S| / h ~ 2e-7 with stresses
    /// ~ 1, truncation far below; 1e-6 absolute (the tangents are 3 to 17; measured
    /// discrepancies up to 1.3e-7).
    #[test]
    fn rod_tangent_matches_finite_differences_of_the_return() {
        let laws = [
            steel(Hardening::Linear { modulus: 10.0 }, 5.0),
            johnson_cook_steel(),
        ];
        for m in laws {
            for c in [
                PointState {
                    stress: Voigt::new(0.4, 0.0, 0.0, 0.0),
                    eq_plastic_strain: 0.02,
                    temperature: 0.3,
                    ..Default::default()
                },
                PointState::default(),
            ] {
                for strain in [4e-3, -8e-3] {
                    let r = m.update_uniaxial(&c, strain, 1e-3);
                    assert!(r.plastic_work > 0.0, "the step must be plastic");
                    let h = 1e-9;
                    let fd = (m.update_uniaxial(&c, strain + h, 1e-3).stress
                        - m.update_uniaxial(&c, strain - h, 1e-3).stress)
                        / (2.0 * h);
                    approx::assert_abs_diff_eq!(r.tangent, fd, epsilon = 1e-6);
                }
            }
        }
    }

    /// Goal: a plastic Johnson-Cook step heats the point by chi w_p / (rho c_p) with the
    /// step's plastic work, and an elastic step or a J2 material leaves the temperature as it
    /// was.
    /// Setup: the warm point of the tangent test, a plastic and an elastic increment; the
    /// same increments on the linear-hardening material.
    /// Reference: w_p = S : d eps_p from the returned stress and the plastic strain
    /// increment recomputed here, dep sqrt(3/2) n with n = dev S / |dev S| (the return is
    /// radial and isotropic, so n is the returned stress's own direction).
    #[test]
    fn johnson_cook_heats_by_the_plastic_work() {
        let m = johnson_cook_steel();
        let c = PointState {
            back_stress: Voigt::zeros(),
            temperature: 0.3,
            ..committed()
        };
        let context = UpdateContext {
            condition: StressCondition::General,
            dt: 1e-3,
        };
        let r = m.update(&c, &Voigt::new(0.004, -0.001, 0.0005, 0.003), context);
        let s = r.state.stress;
        let p = (s[0] + s[1] + s[2]) / 3.0;
        let dev = Voigt::new(s[0] - p, s[1] - p, s[2] - p, s[3]);
        let norm = (dev[0].powi(2) + dev[1].powi(2) + dev[2].powi(2) + 2.0 * dev[3].powi(2)).sqrt();
        let dep = r.state.eq_plastic_strain - c.eq_plastic_strain;
        // S : (sqrt(3/2) dep n) = sqrt(3/2) dep |dev S|
        let work = 1.5f64.sqrt() * dep * norm;
        approx::assert_relative_eq!(r.plastic_work, work, max_relative = 1e-12);
        approx::assert_relative_eq!(
            r.state.temperature,
            0.3 + 0.9 * work / (1.0 * 1.0),
            max_relative = 1e-12
        );
        let elastic = m.update(&c, &Voigt::new(-1e-4, 0.0, 0.0, 0.0), context);
        assert_eq!(elastic.plastic_work, 0.0);
        assert_eq!(elastic.state.temperature, 0.3);
        let j2 = steel(Hardening::Linear { modulus: 10.0 }, 0.0);
        let plain = j2.update(&c, &Voigt::new(0.004, -0.001, 0.0005, 0.003), context);
        assert!(plain.plastic_work > 0.0);
        assert_eq!(plain.state.temperature, 0.3);
    }
}
