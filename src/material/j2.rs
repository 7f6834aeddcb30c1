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
//! sigma_y    sigma_y0 + H_iso eps_p, a piecewise-linear table eps_p -> sigma_y, or the
//!            Johnson-Cook law of the increment (`johnson_cook`: sigma_y0 is its A, and
//!            sigma_y depends on the increment's rate dep / dt and the committed temperature)
//! H_iso      d sigma_y / d dep, dep = sqrt(2/3) dl the equivalent plastic strain increment
//! ```
//! One radial return, [`J2::radial`], serves every continuum path (plane strain and
//! axisymmetric 2x2 points, the 3D update inside plane stress, the one-point explicit
//! kernel) and every hardening law: dl from g(dl) = ||eta_tr|| - (2 mu + 2/3 H_kin) dl -
//! sqrt(2/3) sigma_y(sqrt(2/3) dl) = 0, in closed form for linear hardening and by Newton for
//! a table or Johnson-Cook (bracketed: g(0) > 0 for a plastic trial state and g(a / b) <= 0,
//! so a Newton iterate outside the bracket, or one from an infinite slope, is replaced by
//! bisection); the implicit paths add its consistent tangent ([`J2::tangent`]), the same
//! formula for every law with H_iso the total derivative of sigma_y in dep (the rate term's
//! included). Plane stress finds the
//! out-of-plane strain by Newton so that sigma_zz = 0 (see `Material::update`), which keeps
//! the model identical to the 3D one (kinematic hardening included) and its tangent exact by
//! static condensation. Rods: the one-dimensional form of the same multiplier equation.

use super::johnson_cook::JohnsonCook;
use crate::element::{Moduli, Voigt};

/// The isotropic hardening law.
#[derive(Debug, Clone, PartialEq)]
pub enum Hardening {
    /// sigma_y = yield_stress + modulus eps_p.
    Linear { modulus: f64 },
    /// Piecewise-linear sigma_y(eps_p) through (0, yield_stress) and the given points,
    /// constant slope of the last segment beyond them.
    Table { points: Vec<[f64; 2]> },
    /// sigma_y = (yield_stress + B eps_p^n) (1 + C ln max(rate / rate_0, 1)) (1 - T*^m).
    JohnsonCook(JohnsonCook),
}

/// What the flow stress of an increment depends on besides its plastic strain increment:
/// the committed equivalent plastic strain and temperature, and the step length (the rate
/// is dep / dt; dt = infinity means no rate).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowStart {
    pub eq_plastic_strain: f64,
    pub temperature: f64,
    pub dt: f64,
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
    /// The isotropic hardening slope d sigma_y / d dep at the solution.
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

fn squared_norm(x: &Voigt) -> f64 {
    x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + 2.0 * x[3] * x[3]
}

fn deviator(s: &Voigt) -> Voigt {
    let p = (s[0] + s[1] + s[2]) * (1.0 / 3.0);
    Voigt::new(s[0] - p, s[1] - p, s[2] - p, s[3])
}

/// The piecewise-linear sigma_y(eps_p) through (0, yield_stress) and `points`, and its slope
/// (beyond the last point the last segment's).
fn table_flow_stress(yield_stress: f64, points: &[[f64; 2]], eps_p: f64) -> (f64, f64) {
    let mut prev = [0.0, yield_stress];
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
        [0.0, yield_stress]
    };
    let slope = (prev[1] - before[1]) / (prev[0] - before[0]);
    (prev[1] + slope * (eps_p - prev[0]), slope)
}

impl J2 {
    /// The flow stress of an increment from `start` with the equivalent plastic strain
    /// increment `dep`, and its slope d sigma_y / d dep.
    #[inline]
    pub fn flow_stress(&self, start: &FlowStart, dep: f64) -> (f64, f64) {
        let eps_p = start.eq_plastic_strain + dep;
        match &self.hardening {
            Hardening::Linear { modulus } => (self.yield_stress + modulus * eps_p, *modulus),
            Hardening::Table { points } => table_flow_stress(self.yield_stress, points, eps_p),
            Hardening::JohnsonCook(law) => law.flow_stress(
                self.yield_stress,
                start.eq_plastic_strain,
                start.temperature,
                dep,
                start.dt,
            ),
        }
    }

    /// Solves g(dl) = a - b dl - sqrt(2/3) sigma_y(sqrt(2/3) dl) = 0 for dl >= 0 (a
    /// plastic trial state: g(0) > 0): in closed form for linear hardening (g is linear in
    /// dl), else by Newton to round-off, kept inside the bracket (lo, hi] that starts as
    /// (0, a / b] (g(a / b) = -sqrt(2/3) sigma_y <= 0) by bisection when an iterate leaves it
    /// or the slope is not finite. Returns dl and the hardening slope at the solution.
    /// Johnson-Cook goes first by [`J2::johnson_cook_multiplier`] from the start's flow
    /// stress `start_stress`, and comes here only where that fails; then it needs the
    /// bracket: from dl = 0 below the reference rate Newton does not see the rate term and
    /// overshoots, and on the convex g of the logarithm it can fall back to 0.
    #[inline]
    fn plastic_multiplier(&self, a: f64, b: f64, flow: &Flow, start_stress: f64) -> (f64, f64) {
        let start = &flow.start;
        match self.hardening {
            Hardening::Linear { modulus } => {
                let yield_stress = self.yield_stress + modulus * start.eq_plastic_strain;
                let dl = (a - SQRT_2_3 * yield_stress) / (b + 2.0 / 3.0 * modulus);
                return (dl.max(0.0), modulus);
            }
            Hardening::JohnsonCook(_) => {
                if let Some(found) = Self::johnson_cook_multiplier(a, b, flow, start_stress) {
                    return found;
                }
            }
            Hardening::Table { .. } => {}
        }
        let (mut lo, mut hi) = (0.0, a / b);
        let mut dl = 0.0;
        let mut slope = 0.0;
        for _ in 0..200 {
            let (sy, h) = flow.stress(SQRT_2_3 * dl);
            slope = h;
            let g = a - b * dl - SQRT_2_3 * sy;
            if g > 0.0 {
                lo = dl;
            } else {
                hi = dl;
            }
            let dg = -b - 2.0 / 3.0 * h;
            let step = g / dg;
            let newton = (dl - step).max(0.0);
            // |g| = |step| (b + 2/3 h): for slopes small against b the step's own test
            // |step| <= 1e-15 (1 + dl); where the flow stress is steep (the rate term of a
            // tiny increment) the step must be smaller, so that sigma_y, not only dl, has
            // converged
            if g.abs() <= 1e-15 * (1.0 + newton.abs()) * b {
                dl = newton;
                break;
            }
            // a Newton iterate at or below lo would go back where g > 0 is known (a cycle)
            dl = if h.is_finite() && newton > lo && newton <= hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
        }
        (dl, slope)
    }

    /// g(dl) = 0 for Johnson-Cook by Newton in s = ln dl, from the perfectly plastic return
    /// dl_0 = (a - sqrt(2/3) sigma_y(0)) / b. The flow stress rises with the increment
    /// (hardening, rate; the thermal factor is the step's), so g(dl_0) <= 0: dl_0 lies above
    /// the root. In s, sigma_y is convex: A + B (eps_p + e^s)^n is (its second derivative is
    /// B n (eps_p + e^s)^(n - 2) e^s (eps_p + n e^s) > 0), the rate factor 1 + C (s - ln(r_0
    /// dt)) is linear above its kink and 1 below it (a kink that only steepens it), and a
    /// product of positive, rising, convex factors is convex. So g(s) = a - b e^s -
    /// sqrt(2/3) sigma_y is concave, and Newton from a point where g <= 0 falls to the root
    /// without passing it (a tangent of a concave function lies above it). In dl itself the
    /// rate term's logarithm made Newton overshoot below zero and the safeguard bisect: 8.7
    /// iterates a return on the Johnson-Cook Taylor rod (each a powf and a logarithm). None
    /// where an iterate is not finite or 50 do not reach the tolerance (the bracketed
    /// Newton of `plastic_multiplier` then takes over).
    fn johnson_cook_multiplier(
        a: f64,
        b: f64,
        flow: &Flow,
        start_stress: f64,
    ) -> Option<(f64, f64)> {
        let mut dl = (a - SQRT_2_3 * start_stress) / b;
        if !(dl > 0.0 && dl.is_finite()) {
            return None;
        }
        for _ in 0..50 {
            let (sy, h) = flow.stress(SQRT_2_3 * dl);
            let g = a - b * dl - SQRT_2_3 * sy;
            // the tolerance of plastic_multiplier
            if g.abs() <= 1e-15 * (1.0 + dl) * b {
                return Some((dl, h));
            }
            // dg/ds = dl dg/d dl
            let ds = g / (dl * (b + 2.0 / 3.0 * h));
            if !ds.is_finite() {
                return None;
            }
            dl *= ds.exp();
        }
        None
    }

    /// The consistent tangent of a radial return from the elastic moduli:
    /// D_e - 2 mu [c1 n n^T + c2 (I_dev - n n^T)], c1 = 2 mu / (2 mu + 2/3 (H_iso + H_kin)),
    /// c2 = 2 mu dl / ||eta_tr||.
    pub fn tangent(&self, r: &Radial, elastic: &Moduli, mu: f64) -> Moduli {
        let (n, dl, eta_norm) = (r.direction, r.multiplier, r.eta_norm);
        let c1 = 2.0 * mu / (2.0 * mu + 2.0 / 3.0 * (r.slope + self.kinematic_modulus));
        let c2 = 2.0 * mu * dl / eta_norm;
        // D_e - 2 mu [(c1 - c2) n n^T + c2 I_dev], entry by entry (symmetric)
        let (a, b) = (2.0 * mu * (c1 - c2), 2.0 * mu * c2);
        let mut d = *elastic;
        for j in 0..4 {
            for i in 0..4 {
                let i_dev = match (i, j) {
                    (3, 3) => 0.5,
                    (3, _) | (_, 3) => 0.0,
                    _ if i == j => 2.0 / 3.0,
                    _ => -1.0 / 3.0,
                };
                d[(i, j)] -= a * n[i] * n[j] + b * i_dev;
            }
        }
        d
    }

    /// The radial return of a trial stress (plane strain, axisymmetric, the 3D update inside
    /// plane stress, and the one-point explicit kernel: the one return of every continuum
    /// path): dl from ||eta_tr|| - (2 mu + 2/3 H_kin) dl = sqrt(2/3) sigma_y(sqrt(2/3) dl)
    /// and the returned state; None when the trial state is elastic (at the flow stress of a
    /// zero increment).
    /// (Inlined, the elastic check with it; the return itself is `plastic_return`, out of
    /// line: most points of an explicit step are elastic.)
    #[inline(always)]
    pub fn radial(&self, trial: &Voigt, mu: f64, back: &Voigt, start: FlowStart) -> Option<Radial> {
        // dev of the difference: the pushed-forward back stress need not stay traceless
        let eta = deviator(&(trial - back));
        let eta_squared = squared_norm(&eta);
        // below a floor of the flow stress that takes no powf: elastic, as the exact check
        // below would find (the floor is at most the flow stress, bit for bit)
        if let Some(floor) = self.cheap_flow_floor(&start)
            && 1.5 * eta_squared <= floor * floor
        {
            return None;
        }
        let flow = Flow::new(self, start);
        let sy = flow.at_start();
        // f = sqrt(3/2) ||eta|| - sigma_y <= 0 without the root (most points are elastic)
        if sy >= 0.0 && 1.5 * eta_squared <= sy * sy {
            return None;
        }
        Some(self.plastic_return((trial, back), (&eta, eta_squared), mu, &flow, sy))
    }

    /// A floor of the flow stress of a zero increment from `start` that takes no powf, for
    /// Johnson-Cook with m >= 1 (its two powf, eps_p^n and T*^m, were a fifth of the Johnson-
    /// Cook rod pair's run): (A + B eps_p^n)(1 - T*^m) >= A (1 - T*), as B >= 0 and T*^m <= T*
    /// on [0, 1], less 1e-12 on the factor (absolute) and on the product (relative), which
    /// covers the rounding of the exact value (a few units in the last place). None for the
    /// other laws (their flow stress is cheap), for m < 1, and where the floor is not
    /// positive.
    #[inline(always)]
    fn cheap_flow_floor(&self, start: &FlowStart) -> Option<f64> {
        let Hardening::JohnsonCook(law) = &self.hardening else {
            return None;
        };
        if law.m < 1.0 || !(self.yield_stress > 0.0) {
            return None;
        }
        let factor = 1.0 - law.homologous_temperature(start.temperature) - 1e-12;
        (factor > 0.0).then(|| self.yield_stress * factor * (1.0 - 1e-12))
    }

    /// The return of `radial` past its elastic check: the trial stress and back stress
    /// `(trial, back)`, eta and ||eta||^2, the flow stress `sy` of a zero increment.
    #[inline(never)]
    fn plastic_return(
        &self,
        (trial, back): (&Voigt, &Voigt),
        (eta, eta_squared): (&Voigt, f64),
        mu: f64,
        flow: &Flow,
        sy: f64,
    ) -> Radial {
        let start = flow.start;
        let eta_norm = eta_squared.sqrt();
        let h_kin = self.kinematic_modulus;
        let (dl, h_iso) = self.plastic_multiplier(eta_norm, 2.0 * mu + 2.0 / 3.0 * h_kin, flow, sy);
        let n = eta / eta_norm;
        Radial {
            stress: trial - n * (2.0 * mu * dl),
            back_stress: back + n * (2.0 / 3.0 * h_kin * dl),
            eq_plastic_strain: start.eq_plastic_strain + SQRT_2_3 * dl,
            direction: n,
            multiplier: dl,
            eta_norm,
            slope: h_iso,
        }
    }

    /// One-dimensional return for rods, None when the trial stress is elastic.
    pub fn uniaxial(
        &self,
        trial: f64,
        young: f64,
        back: f64,
        start: FlowStart,
    ) -> Option<UniaxialReturn> {
        let xi = trial - back;
        let flow = Flow::new(self, start);
        let sy = flow.at_start();
        if xi.abs() - sy <= 0.0 {
            return None;
        }
        let sign = xi.signum();
        // |xi| - (E + H_kin) de_p = sigma_y(eps_p + de_p); reuse the scalar solver with
        // dl = sqrt(3/2) de_p: a = sqrt(2/3)|xi|, b = 2/3 (E + H_kin)
        let h_kin = self.kinematic_modulus;
        let (dl, h_iso) =
            self.plastic_multiplier(SQRT_2_3 * xi.abs(), 2.0 / 3.0 * (young + h_kin), &flow, sy);
        let dep = SQRT_2_3 * dl;
        let h = h_iso + h_kin;
        Some(UniaxialReturn {
            stress: trial - sign * young * dep,
            back_stress: back + sign * h_kin * dep,
            eq_plastic_strain: start.eq_plastic_strain + dep,
            // E H / (E + H) -> E as H -> infinity (Johnson-Cook's slope at eps_p = 0, n < 1)
            tangent: if h.is_finite() {
                young * h / (young + h)
            } else {
                young
            },
            plastic_strain: sign * dep,
        })
    }
}

/// The flow stress of one return: what does not change with the increment (Johnson-Cook's
/// thermal factor of the step's temperature) computed once for the elastic check and every
/// iterate. The same values as `J2::flow_stress`, bit for bit.
struct Flow<'a> {
    j2: &'a J2,
    start: FlowStart,
    /// Johnson-Cook's 1 - T*^m (1 for the other laws, unused).
    thermal: f64,
}

impl<'a> Flow<'a> {
    #[inline]
    fn new(j2: &'a J2, start: FlowStart) -> Flow<'a> {
        let thermal = match &j2.hardening {
            Hardening::JohnsonCook(law) => law.thermal_factor(start.temperature),
            _ => 1.0,
        };
        Flow { j2, start, thermal }
    }

    /// The flow stress of a zero increment (no slope: the elastic check).
    #[inline]
    fn at_start(&self) -> f64 {
        match &self.j2.hardening {
            Hardening::JohnsonCook(law) => law.start_flow_stress(
                self.j2.yield_stress,
                self.start.eq_plastic_strain,
                self.thermal,
            ),
            _ => self.j2.flow_stress(&self.start, 0.0).0,
        }
    }

    /// The flow stress of the increment `dep` and its slope.
    #[inline]
    fn stress(&self, dep: f64) -> (f64, f64) {
        match &self.j2.hardening {
            Hardening::JohnsonCook(law) => law.flow_stress_at(
                self.j2.yield_stress,
                self.start.eq_plastic_strain,
                self.thermal,
                dep,
                self.start.dt,
            ),
            _ => self.j2.flow_stress(&self.start, dep),
        }
    }
}

/// The result of a one-dimensional (rod) return.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UniaxialReturn {
    pub stress: f64,
    pub back_stress: f64,
    pub eq_plastic_strain: f64,
    /// The algorithmic tangent E H / (E + H), H = H_iso + H_kin (E for an infinite H).
    pub tangent: f64,
    /// The plastic strain increment (signed).
    pub plastic_strain: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::JohnsonCook;

    fn start(eq_plastic_strain: f64) -> FlowStart {
        FlowStart {
            eq_plastic_strain,
            temperature: 0.0,
            dt: f64::INFINITY,
        }
    }

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
        let a = linear.radial(&trial, mu, &back, start(0.01)).unwrap();
        let b = table.radial(&trial, mu, &back, start(0.01)).unwrap();
        assert!((a.stress - b.stress).norm() < 1e-13);
        assert!((a.back_stress - b.back_stress).norm() < 1e-13);
        assert!((a.eq_plastic_strain - b.eq_plastic_strain).abs() < 1e-15);
        assert!((a.plastic_work() - b.plastic_work()).abs() < 1e-13);
        assert!(
            linear
                .radial(
                    &Voigt::new(0.1, 0.0, 0.0, 0.0),
                    mu,
                    &Voigt::zeros(),
                    start(0.0)
                )
                .is_none()
        );
    }

    /// Goal: the Johnson-Cook return satisfies the consistency condition sqrt(3/2)
    /// ||dev S|| = sigma_y(eps_p,n + dep, dep / dt, T_n) to round-off wherever Newton alone
    /// would fail: steps so short that the rate term switches on at a tiny dep (Newton from
    /// dl = 0 overshoots, then falls back towards 0), n < 1 from eps_p = 0 (infinite slope),
    /// a melted point (sigma_y = 0: the deviator must vanish), and no step (dt = infinity).
    /// Setup: mu = 76.9, A = 0.5, B = 0.3, n = 0.3, C = 0.02, rate_0 = 1, m = 1, T in [0, 1];
    /// trial von Mises stresses 1.001, 1.1 and 4 times the flow stress of a zero increment
    /// (0.1 for the melted point), eps_p,n in {0, 0.05}, T_n in {0, 0.5, 1}, dt from 1e-12
    /// to infinity.
    /// Reference: the law written here; 1e-12 of the trial stress.
    #[test]
    fn johnson_cook_return_satisfies_the_consistency_condition() {
        let j2 = johnson_cook([0.5, 0.3, 0.3, 0.02, 1.0], [0.0, 1.0]);
        let flow = |eps_p: f64, rate: f64, t: f64| -> f64 {
            (0.5 + 0.3 * eps_p.powf(0.3)) * (1.0 + 0.02 * rate.max(1.0).ln()) * (1.0 - t)
        };
        let mu = 200.0 / 2.6;
        let shape = deviator(&Voigt::new(1.4, -0.3, 0.2, 0.6));
        let shape = shape / (1.5 * squared_norm(&shape)).sqrt();
        let pressure = Voigt::new(-0.3, -0.3, -0.3, 0.0);
        for (eps_p, temperature, over) in
            itertools(&[0.0, 0.05], &[0.0, 0.5, 1.0], &[1.001, 1.1, 4.0])
        {
            let trial_mises = over * flow(eps_p, 0.0, temperature).max(0.1);
            let trial = shape * trial_mises + pressure;
            {
                for dt in [1e-12, 1e-9, 1e-6, 1e-3, 1.0, f64::INFINITY] {
                    let start = FlowStart {
                        eq_plastic_strain: eps_p,
                        temperature,
                        dt,
                    };
                    let r = j2.radial(&trial, mu, &Voigt::zeros(), start).unwrap();
                    // from the multiplier: eps_p,n+1 - eps_p,n would lose the digits of a
                    // tiny dep
                    let dep = SQRT_2_3 * r.multiplier;
                    let mises = (1.5 * squared_norm(&deviator(&r.stress))).sqrt();
                    let expected = flow(eps_p + dep, dep / dt, temperature);
                    assert!(
                        (mises - expected).abs() <= 1e-12 * trial_mises,
                        "eps_p {eps_p} T {temperature} dt {dt}: {mises} vs {expected}"
                    );
                    assert!(dep > 0.0);
                }
            }
        }
    }

    /// Newton in ln dl (`johnson_cook_multiplier`) reaches the root on its own, without the
    /// bracketed fallback, on the 42CrMo4 law of models/taylor_jc.toml at that rod's steps
    /// (1e-9 to 4e-8 s), eps_p 0 to 1.8, T from room to 40 C below melting, from trial
    /// stresses just above the flow stress to 20 times it. Reference: the law written out
    /// here, (A + B eps^n) (1 + C ln(rate)) (1 - T*^m), and the consistency condition
    /// ||eta_tr|| - 2 mu dl = sqrt(2/3) sigma_y(eps_p + sqrt(2/3) dl) to twice the
    /// iteration's own stopping test |g| <= 1e-15 (1 + dl) 2 mu (3e-4 Pa) and 1e-14 of the
    /// trial for the round-off of the law evaluated here.
    #[test]
    fn johnson_cook_log_newton_converges_without_the_fallback() {
        let j2 = johnson_cook([806.0e6, 614.0e6, 0.168, 0.0089, 1.1], [20.0, 1540.0]);
        let sigma = |eps: f64, rate: f64, t: f64| -> f64 {
            let homologous: f64 = ((t - 20.0) / 1520.0).clamp(0.0, 1.0);
            (806.0e6 + 614.0e6 * eps.powf(0.168))
                * (1.0 + 0.0089 * rate.max(1.0).ln())
                * (1.0 - homologous.powf(1.1))
        };
        let two_mu = 206.0e9 / 1.3;
        for (eps_p, temperature, over) in itertools(
            &[0.0, 1e-6, 0.02, 0.5, 1.8],
            &[20.0, 300.0, 900.0, 1500.0],
            &[1.0 + 1e-9, 1.001, 1.1, 2.0, 20.0],
        ) {
            for dt in [1e-9, 3.2e-9, 4e-8] {
                let start = FlowStart {
                    eq_plastic_strain: eps_p,
                    temperature,
                    dt,
                };
                let flow = Flow::new(&j2, start);
                let start_stress = flow.at_start();
                let a = SQRT_2_3 * over * start_stress;
                let (dl, _) = J2::johnson_cook_multiplier(a, two_mu, &flow, start_stress)
                    .unwrap_or_else(|| panic!("eps_p {eps_p} T {temperature} x{over} dt {dt}"));
                let dep = SQRT_2_3 * dl;
                let residual =
                    a - two_mu * dl - SQRT_2_3 * sigma(eps_p + dep, dep / dt, temperature);
                assert!(
                    residual.abs() <= 2e-15 * (1.0 + dl) * two_mu + 1e-14 * a,
                    "eps_p {eps_p} T {temperature} x{over} dt {dt}: residual {residual} of {a}"
                );
            }
        }
    }

    /// J2 with the Johnson-Cook law [A, B, n, C, m] (reference rate 1) between the room and
    /// melting temperatures [T_room, T_melt], starting at room temperature.
    fn johnson_cook([a, b, n, c, m]: [f64; 5], [room, melting]: [f64; 2]) -> J2 {
        let law = JohnsonCook {
            b,
            n,
            c,
            reference_rate: 1.0,
            m,
            room_temperature: room,
            melting_temperature: melting,
            specific_heat: 1.0,
            taylor_quinney: 0.9,
            initial_temperature: room,
        };
        J2 {
            yield_stress: a,
            hardening: Hardening::JohnsonCook(law),
            kinematic_modulus: 0.0,
        }
    }

    /// Goal: the Johnson-Cook floor of the elastic check (`cheap_flow_floor`) never lies
    /// above the flow stress of a zero increment, so `radial` decides as the exact check
    /// does, and it is only taken where it holds (m >= 1).
    /// Setup: the 42CrMo4 law of models/taylor_jc.toml (A 806 MPa, B 614 MPa, n 0.168,
    /// m 1.1, 20 to 1540 C) and the same with m = 1 and m = 0.5; eps_p from 0 to 3, T from
    /// room to melting. Reference: the law written out here, (A + B eps^n)(1 - T*^m), and
    /// T*^m <= T* on [0, 1] for m >= 1. A trial von Mises stress at the written-out flow
    /// stress less 1e-9 of it is elastic; 1e-9 above it, plastic (the floor lies below both
    /// where the point is hot and has hardened: a floor of A alone, without the factor
    /// (1 - T*), fails the first assertion at the hot points).
    #[test]
    fn johnson_cook_floor_lies_below_the_flow_stress() {
        let shape = deviator(&Voigt::new(1.4, -0.3, 0.2, 0.6));
        let shape = shape / (1.5 * squared_norm(&shape)).sqrt();
        for m in [1.1, 1.0, 0.5] {
            let j2 = johnson_cook([806e6, 614e6, 0.168, 0.0089, m], [20.0, 1540.0]);
            for (eps_p, temperature, _) in itertools(
                &[0.0, 1e-9, 1e-3, 0.1, 1.0, 3.0],
                &[20.0, 21.0, 400.0, 1000.0, 1539.0, 1540.0],
                &[0.0],
            ) {
                let homologous = (temperature - 20.0) / 1520.0;
                let exact = (806e6 + 614e6 * eps_p.powf(0.168)) * (1.0 - homologous.powf(m));
                let start = FlowStart {
                    eq_plastic_strain: eps_p,
                    temperature,
                    dt: f64::INFINITY,
                };
                let floor = j2.cheap_flow_floor(&start);
                assert_eq!(
                    floor.is_some(),
                    m >= 1.0 && homologous < 1.0,
                    "m {m} T {temperature}"
                );
                if let Some(floor) = floor {
                    assert!(
                        floor <= exact,
                        "m {m} eps {eps_p} T {temperature}: {floor} > {exact}"
                    );
                }
                if exact <= 0.0 {
                    continue; // melted: every deviator is plastic
                }
                for (over, plastic) in [(1.0 - 1e-9, false), (1.0 + 1e-9, true)] {
                    let trial = shape * (over * exact);
                    let r = j2.radial(&trial, 80e9, &Voigt::zeros(), start);
                    assert_eq!(
                        r.is_some(),
                        plastic,
                        "m {m} eps {eps_p} T {temperature} x{over}"
                    );
                }
            }
        }
    }

    /// Every combination of the three lists.
    fn itertools(a: &[f64], b: &[f64], c: &[f64]) -> Vec<(f64, f64, f64)> {
        a.iter()
            .flat_map(|x| {
                b.iter()
                    .flat_map(move |y| c.iter().map(move |z| (*x, *y, *z)))
            })
            .collect()
    }
}
