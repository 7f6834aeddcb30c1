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
//! One radial return, [`J2::radial`], serves every continuum path (plane strain and
//! axisymmetric 2x2 points, the 3D update inside plane stress, the one-point explicit
//! kernel): dl from ||eta_tr|| - (2 mu + 2/3 H_kin) dl = sqrt(2/3) sigma_y(eps_p,n +
//! sqrt(2/3) dl), in closed form for linear hardening and by Newton for a table; the
//! implicit paths add its consistent tangent ([`J2::tangent`]). Plane stress finds the
//! out-of-plane strain by Newton so that sigma_zz = 0 (see `Material::update`), which keeps
//! the model identical to the 3D one (kinematic hardening included) and its tangent exact by
//! static condensation. Rods: the one-dimensional form of the same multiplier equation.

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

/// The state after a radial return, with what the consistent tangent needs.
#[derive(Debug, Clone, Copy)]
pub struct Radial {
    pub stress: Voigt,
    pub back_stress: Voigt,
    pub eq_plastic_strain: f64,
    /// n = eta / ||eta||
    pub direction: Voigt,
    /// dl: the plastic strain increment is dl n (tensor components, zz included).
    pub multiplier: f64,
    pub eta_norm: f64,
    /// The isotropic hardening slope at the solution.
    pub slope: f64,
}

impl Radial {
    /// Plastic work per unit volume of the increment, S_{n+1} : d eps_p.
    pub fn plastic_work(&self) -> f64 {
        let (s, e) = (&self.stress, self.direction * self.multiplier);
        s[0] * e[0] + s[1] * e[1] + s[2] * e[2] + 2.0 * s[3] * e[3]
    }
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

    /// Solves g(dl) = a - b dl - sqrt(2/3) sigma_y(eps_p + sqrt(2/3) dl) = 0 for dl >= 0:
    /// in closed form for linear hardening (g is linear in dl), else by Newton to round-off.
    /// Returns dl and the hardening slope at the solution.
    fn plastic_multiplier(&self, a: f64, b: f64, eps_p: f64) -> (f64, f64) {
        if let Hardening::Linear { modulus } = self.hardening {
            let yield_stress = self.yield_stress + modulus * eps_p;
            let dl = (a - SQRT_2_3 * yield_stress) / (b + 2.0 / 3.0 * modulus);
            return (dl.max(0.0), modulus);
        }
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

    /// The consistent tangent of a radial return from the elastic moduli:
    /// D_e - 2 mu [c1 n n^T + c2 (I_dev - n n^T)], c1 = 2 mu / (2 mu + 2/3 (H_iso + H_kin)),
    /// c2 = 2 mu dl / ||eta_tr||.
    pub fn tangent(&self, r: &Radial, elastic: &Moduli, mu: f64) -> Moduli {
        let (n, dl, eta_norm) = (r.direction, r.multiplier, r.eta_norm);
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
        elastic - (nn * c1 + (i_dev - nn) * c2) * (2.0 * mu)
    }

    /// The radial return of a trial stress (plane strain, axisymmetric, the 3D update inside
    /// plane stress, and the one-point explicit kernel: the one return of every continuum
    /// path): dl from ||eta_tr|| - (2 mu + 2/3 H_kin) dl = sqrt(2/3) sigma_y(eps_p,n +
    /// sqrt(2/3) dl) and the returned state; None when the trial state is elastic.
    pub fn radial(&self, trial: &Voigt, mu: f64, back: &Voigt, eps_p: f64) -> Option<Radial> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form multiplier of linear hardening equals Newton's on the same law given as
    /// a table (one point on the line: the table's slope continues beyond it), isotropic plus
    /// kinematic hardening; an elastic trial returns None. Newton stops at 1e-15 relative.
    #[test]
    fn linear_multiplier_matches_newton_on_the_same_law() {
        let linear = J2 {
            yield_stress: 0.5,
            hardening: Hardening::Linear { modulus: 10.0 },
            kinematic_modulus: 5.0,
        };
        let table = J2 {
            hardening: Hardening::Table {
                points: vec![[1.0, 10.5]],
            },
            ..linear.clone()
        };
        let mu = 200.0 / 2.6;
        let trial = Voigt::new(1.4, -0.3, 0.2, 0.6);
        let back = Voigt::new(0.02, -0.01, -0.01, 0.01);
        let a = linear.radial(&trial, mu, &back, 0.01).unwrap();
        let b = table.radial(&trial, mu, &back, 0.01).unwrap();
        assert!((a.stress - b.stress).norm() < 1e-13);
        assert!((a.back_stress - b.back_stress).norm() < 1e-13);
        assert!((a.eq_plastic_strain - b.eq_plastic_strain).abs() < 1e-15);
        assert!((a.plastic_work() - b.plastic_work()).abs() < 1e-13);
        assert!(
            linear
                .radial(&Voigt::new(0.1, 0.0, 0.0, 0.0), mu, &Voigt::zeros(), 0.0)
                .is_none()
        );
    }
}
