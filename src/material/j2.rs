//! Von Mises (J2) plasticity by the initial-stress approach (Erklig 2.1.2 (b), (c)(v)-(vi)):
//! the elastic predictor D_e dE, then the return to the yield surface gives the corrected
//! stress from which the residual is formed.
//!
//! Legend (all in the reference frame of the increment; Voigt [xx yy zz xy], engineering
//! shear strain, tensor stress components)
//! ```text
//! S_tr       sigma_n + D_e dE                          elastic predictor
//! eta        dev(S_tr - alpha)                         relative stress, alpha the back stress
//! ||x||      sqrt(x_xx^2 + x_yy^2 + x_zz^2 + 2 x_xy^2)
//! f          sqrt(3/2) ||eta|| - sigma_y(eps_p)        yield function
//! n          eta / ||eta||,  d eps_p = dl n,  eps_p += sqrt(2/3) dl
//! alpha     += 2/3 H_kin dl n                           linear kinematic hardening
//! sigma_y    sigma_y0 + H_iso eps_p, or a piecewise-linear table eps_p -> sigma_y
//! ```
//! General (plane strain, axisymmetric): radial return, dl from
//! ||eta_tr|| - (2 mu + 2/3 H_kin) dl = sqrt(2/3) sigma_y(eps_p,n + sqrt(2/3) dl).
//! Plane stress: the same three-dimensional return with the out-of-plane strain found by
//! Newton so that sigma_zz = 0 (see `Material::update`), which keeps the model identical to
//! the 3D one (kinematic hardening included) and its tangent exact by static condensation.
//! Rods: the one-dimensional return.

use crate::element::{Moduli, Voigt};

/// The isotropic hardening law.
#[derive(Debug, Clone, PartialEq)]
pub enum Hardening {
    /// sigma_y = yield_stress + modulus eps_p.
    Linear { modulus: f64 },
    /// Piecewise-linear sigma_y(eps_p) through (0, yield_stress) and the given points,
    /// constant slope of the last segment beyond them.
    Table { points: Vec<[f64; 2]> },
}

#[derive(Debug, Clone, PartialEq)]
pub struct J2 {
    pub yield_stress: f64,
    pub hardening: Hardening,
    /// Linear kinematic (Prager) hardening modulus H_kin.
    pub kinematic_modulus: f64,
}

/// Result of a return.
#[derive(Debug, Clone, Copy)]
pub struct Return {
    pub stress: Voigt,
    pub back_stress: Voigt,
    pub eq_plastic_strain: f64,
    pub moduli: Moduli,
    /// Plastic strain increment (tensor components; zz included) for the plastic work.
    pub plastic_strain: Voigt,
}

/// The state after a radial return, with what the tangent needs.
struct Radial {
    stress: Voigt,
    back_stress: Voigt,
    eq_plastic_strain: f64,
    /// n = eta / ||eta||
    direction: Voigt,
    /// dl
    multiplier: f64,
    eta_norm: f64,
    /// The isotropic hardening slope at the solution.
    slope: f64,
}

const SQRT_2_3: f64 = 0.816_496_580_927_726;

fn norm(x: &Voigt) -> f64 {
    (x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + 2.0 * x[3] * x[3]).sqrt()
}

fn deviator(s: &Voigt) -> Voigt {
    let p = (s[0] + s[1] + s[2]) / 3.0;
    Voigt::new(s[0] - p, s[1] - p, s[2] - p, s[3])
}

impl J2 {
    /// Yield stress and its slope at eps_p.
    pub fn yield_stress_at(&self, eps_p: f64) -> (f64, f64) {
        match &self.hardening {
            Hardening::Linear { modulus } => (self.yield_stress + modulus * eps_p, *modulus),
            Hardening::Table { points } => {
                let mut prev = [0.0, self.yield_stress];
                for p in points {
                    if eps_p <= p[0] {
                        let slope = (p[1] - prev[1]) / (p[0] - prev[0]);
                        return (prev[1] + slope * (eps_p - prev[0]), slope);
                    }
                    prev = *p;
                }
                let n = points.len();
                let before = if n >= 2 {
                    points[n - 2]
                } else {
                    [0.0, self.yield_stress]
                };
                let slope = (prev[1] - before[1]) / (prev[0] - before[0]);
                (prev[1] + slope * (eps_p - prev[0]), slope)
            }
        }
    }

    /// Solves g(dl) = a - b dl - sqrt(2/3) sigma_y(eps_p + sqrt(2/3) dl) = 0 for dl >= 0
    /// (Newton; exact in one step for linear hardening). Returns dl and the hardening slope
    /// at the solution.
    fn plastic_multiplier(&self, a: f64, b: f64, eps_p: f64) -> (f64, f64) {
        let mut dl = 0.0;
        let mut slope = 0.0;
        for _ in 0..50 {
            let (sy, h) = self.yield_stress_at(eps_p + SQRT_2_3 * dl);
            slope = h;
            let g = a - b * dl - SQRT_2_3 * sy;
            let dg = -b - 2.0 / 3.0 * h;
            let step = g / dg;
            dl = (dl - step).max(0.0);
            if step.abs() <= 1e-15 * (1.0 + dl.abs()) {
                break;
            }
        }
        (dl, slope)
    }

    /// Radial return for plane strain and axisymmetric points.
    pub fn general(
        &self,
        trial: &Voigt,
        elastic: &Moduli,
        mu: f64,
        back: &Voigt,
        eps_p: f64,
    ) -> Option<Return> {
        let r = self.radial(trial, mu, back, eps_p)?;
        let (n, dl, eta_norm) = (r.direction, r.multiplier, r.eta_norm);
        // consistent tangent D_e - 2 mu [c1 n n^T + c2 (I_dev - n n^T)]
        let c1 = 2.0 * mu / (2.0 * mu + 2.0 / 3.0 * (r.slope + self.kinematic_modulus));
        let c2 = 2.0 * mu * dl / eta_norm;
        let nn = n * n.transpose();
        let mut i_dev = Moduli::zeros();
        for a in 0..3 {
            for b in 0..3 {
                i_dev[(a, b)] = if a == b { 2.0 / 3.0 } else { -1.0 / 3.0 };
            }
        }
        i_dev[(3, 3)] = 0.5;
        let moduli = elastic - (nn * c1 + (i_dev - nn) * c2) * (2.0 * mu);
        Some(Return {
            stress: r.stress,
            back_stress: r.back_stress,
            eq_plastic_strain: r.eq_plastic_strain,
            moduli,
            plastic_strain: n * dl,
        })
    }

    /// The radial return without the tangent (the explicit kernels, which need none):
    /// (stress, back stress, eps_p, plastic work density S : d eps_p), or None when elastic.
    pub fn return_stress(
        &self,
        trial: &Voigt,
        mu: f64,
        back: &Voigt,
        eps_p: f64,
    ) -> Option<(Voigt, Voigt, f64, f64)> {
        let r = self.radial(trial, mu, back, eps_p)?;
        let e = r.direction * r.multiplier;
        let s = &r.stress;
        let work = s[0] * e[0] + s[1] * e[1] + s[2] * e[2] + 2.0 * s[3] * e[3];
        Some((r.stress, r.back_stress, r.eq_plastic_strain, work))
    }

    /// dl from ||eta_tr|| - (2 mu + 2/3 H_kin) dl = sqrt(2/3) sigma_y(eps_p,n + sqrt(2/3) dl)
    /// and the returned state; None when the trial state is elastic.
    fn radial(&self, trial: &Voigt, mu: f64, back: &Voigt, eps_p: f64) -> Option<Radial> {
        // dev of the difference: the pushed-forward back stress need not stay traceless
        let eta = deviator(&(trial - back));
        let eta_norm = norm(&eta);
        let (sy, _) = self.yield_stress_at(eps_p);
        if (1.5f64).sqrt() * eta_norm - sy <= 0.0 {
            return None;
        }
        let h_kin = self.kinematic_modulus;
        let (dl, h_iso) = self.plastic_multiplier(eta_norm, 2.0 * mu + 2.0 / 3.0 * h_kin, eps_p);
        let n = eta / eta_norm;
        Some(Radial {
            stress: trial - n * (2.0 * mu * dl),
            back_stress: back + n * (2.0 / 3.0 * h_kin * dl),
            eq_plastic_strain: eps_p + SQRT_2_3 * dl,
            direction: n,
            multiplier: dl,
            eta_norm,
            slope: h_iso,
        })
    }

    /// One-dimensional return for rods, None when the trial stress is elastic.
    pub fn uniaxial(
        &self,
        trial: f64,
        young: f64,
        back: f64,
        eps_p: f64,
    ) -> Option<UniaxialReturn> {
        let xi = trial - back;
        let (sy, _) = self.yield_stress_at(eps_p);
        if xi.abs() - sy <= 0.0 {
            return None;
        }
        let sign = xi.signum();
        // |xi| - (E + H_kin) de_p = sigma_y(eps_p + de_p); reuse the scalar solver with
        // dl = sqrt(3/2) de_p: a = sqrt(2/3)|xi|, b = 2/3 (E + H_kin)
        let h_kin = self.kinematic_modulus;
        let (dl, h_iso) =
            self.plastic_multiplier(SQRT_2_3 * xi.abs(), 2.0 / 3.0 * (young + h_kin), eps_p);
        let dep = SQRT_2_3 * dl;
        let h = h_iso + h_kin;
        Some(UniaxialReturn {
            stress: trial - sign * young * dep,
            back_stress: back + sign * h_kin * dep,
            eq_plastic_strain: eps_p + dep,
            tangent: young * h / (young + h),
            plastic_strain: sign * dep,
        })
    }
}

/// The result of a one-dimensional (rod) return.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UniaxialReturn {
    pub stress: f64,
    pub back_stress: f64,
    pub eq_plastic_strain: f64,
    /// The algorithmic tangent E H / (E + H), H = H_iso + H_kin.
    pub tangent: f64,
    /// The plastic strain increment (signed).
    pub plastic_strain: f64,
}
