//! Closed-form and independently computed reference solutions, shared by the tests, the
//! validation report and `impact sweep`.

/// Lame's thick-walled cylinder under internal pressure `p` (radii (a, b): inner, outer) of
/// an elastic material (E, nu), in plane strain (eps_zz = 0): the radial displacement at
/// radius r, u_r = (1 + nu) p a^2 / (E (b^2 - a^2)) ((1 - 2 nu) r + b^2 / r).
pub fn lame_radial_displacement(
    p: f64,
    (a, b): (f64, f64),
    (young, poisson): (f64, f64),
    r: f64,
) -> f64 {
    (1.0 + poisson) * p * a * a / (young * (b * b - a * a))
        * ((1.0 - 2.0 * poisson) * r + b * b / r)
}

/// Euler's critical load of an elastic column, P_E = pi^2 E I / (K L)^2 (effective-length
/// factor K = 1 pinned-pinned, 2 cantilever). A plane-stress strip of depth h and thickness t
/// has I = t h^3 / 12.
pub fn euler_load(young: f64, inertia: f64, length: f64, k: f64) -> f64 {
    std::f64::consts::PI.powi(2) * young * inertia / (k * length).powi(2)
}

/// Euler's load reduced by the shear flexibility (Engesser; Timoshenko and Gere, Theory of
/// Elastic Stability, section 2.16): P = P_E / (1 + P_E / (kappa G A)), kappa = 5/6 for a
/// rectangle.
pub fn shear_corrected_load(euler: f64, shear_modulus: f64, area: f64, kappa: f64) -> f64 {
    euler / (1.0 + euler / (kappa * shear_modulus * area))
}

/// Midspan deflection w / L of the pinned-pinned elastica (inextensible, dead axial load)
/// at P / P_E = `load_ratio` >= 1 (Timoshenko and Gere, Theory of Elastic Stability,
/// section 2.7). Each half of the column is a cantilever of length L / 2 with
/// sqrt(P / EI) L / 2 = K(k), k = sin(alpha / 2) (alpha the end slope), whose tip deflects
/// 2 k / sqrt(P / EI); so
/// ```text
/// P / P_E = (2 K(k) / pi)^2,    w / L = k / K(k) = (2 k / pi) / sqrt(P / P_E)
/// ```
/// with K the complete elliptic integral of the first kind (by the arithmetic-geometric
/// mean) and k by bisection. Zero below P_E.
pub fn elastica_midspan_deflection(load_ratio: f64) -> f64 {
    if load_ratio <= 1.0 {
        return 0.0;
    }
    let elliptic_k = |k: f64| {
        let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
        for _ in 0..60 {
            (a, b) = (0.5 * (a + b), (a * b).sqrt());
        }
        std::f64::consts::PI / (2.0 * a)
    };
    let ratio = |k: f64| (2.0 * elliptic_k(k) / std::f64::consts::PI).powi(2);
    let (mut lo, mut hi) = (0.0, 1.0 - 1e-15);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if ratio(mid) < load_ratio {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let k = 0.5 * (lo + hi);
    k / elliptic_k(k)
}

/// Tip of an inextensible elastic cantilever (the elastica) of length 1, clamped at s = 0
/// along x, under a dead tip load perpendicular to the initial axis with k = P L^2 / (E I).
///
/// theta'' = -k cos(theta), theta(0) = 0, theta'(1) = 0, solved by shooting on theta'(0)
/// with RK4 (4000 steps) and bisection; x' = cos(theta), y' = sin(theta).
pub fn elastica_tip(k: f64) -> ElasticaTip {
    let end_curvature = |kappa0: f64| integrate_elastica(k, kappa0).3;
    // theta'(0) = k x_tip lies in (0, k]
    let (mut lo, mut hi) = (0.0, k);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if end_curvature(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let (x, y, theta, _) = integrate_elastica(k, 0.5 * (lo + hi));
    ElasticaTip {
        shortening: 1.0 - x,
        deflection: y,
        rotation: theta,
    }
}

/// The tip of the cantilever elastica of length 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticaTip {
    /// u / L along the initial axis.
    pub shortening: f64,
    /// w / L across it.
    pub deflection: f64,
    /// The tip rotation (radians).
    pub rotation: f64,
}

/// Integrates the elastica from s = 0 to 1; returns (x, y, theta, theta') at s = 1.
fn integrate_elastica(k: f64, kappa0: f64) -> (f64, f64, f64, f64) {
    let n = 4000;
    let h = 1.0 / n as f64;
    // state: x, y, theta, theta'
    let rhs = |s: [f64; 4]| [s[2].cos(), s[2].sin(), s[3], -k * s[2].cos()];
    let mut s = [0.0, 0.0, 0.0, kappa0];
    for _ in 0..n {
        let add = |a: [f64; 4], b: [f64; 4], f: f64| {
            std::array::from_fn::<f64, 4, _>(|i| a[i] + f * b[i])
        };
        let k1 = rhs(s);
        let k2 = rhs(add(s, k1, h / 2.0));
        let k3 = rhs(add(s, k2, h / 2.0));
        let k4 = rhs(add(s, k3, h));
        s = std::array::from_fn(|i| s[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    (s[0], s[1], s[2], s[3])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mattiasson (1981), Table 1: u/L and w/L of the tip-loaded elastica, 5 digits given.
    #[test]
    fn elastica_matches_mattiasson_table() {
        for (k, u, w) in [(1.0, 0.05643, 0.30172), (2.0, 0.16064, 0.49346)] {
            let tip = elastica_tip(k);
            let (du, dw) = (tip.shortening, tip.deflection);
            approx::assert_abs_diff_eq!(du, u, epsilon = 1e-5);
            approx::assert_abs_diff_eq!(dw, w, epsilon = 1e-5);
        }
    }

    /// The pinned-pinned elastica against its ODE integrated here on its own: a column of
    /// length 1 and EI = 1 under P = r pi^2, theta'' = -P sin(theta) from the pinned end
    /// (theta = alpha, theta' = 0) to midspan, alpha found by bisection so that theta(1/2) = 0
    /// (the symmetric first mode); w = int_0^1/2 sin(theta) ds. RK4 with 20 000 steps:
    /// truncation far below the 1e-9 asserted. Also the values of the closed form at
    /// 1.05 and 1.015 P_E (0.1900, 0.1083, four digits by hand from k / K(k)).
    #[test]
    fn pinned_elastica_matches_its_ode() {
        let midspan = |r: f64, alpha: f64| {
            let p = r * std::f64::consts::PI.powi(2);
            let n = 20_000;
            let h = 0.5 / n as f64;
            let rhs = |s: [f64; 3]| [s[1], -p * s[0].sin(), s[0].sin()];
            let mut s = [alpha, 0.0, 0.0];
            for _ in 0..n {
                let add = |a: [f64; 3], b: [f64; 3], f: f64| {
                    std::array::from_fn::<f64, 3, _>(|i| a[i] + f * b[i])
                };
                let k1 = rhs(s);
                let k2 = rhs(add(s, k1, h / 2.0));
                let k3 = rhs(add(s, k2, h / 2.0));
                let k4 = rhs(add(s, k3, h));
                s = std::array::from_fn(|i| {
                    s[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
                });
            }
            (s[0], s[2])
        };
        for r in [1.015, 1.05, 1.2, 2.0] {
            // above P_E the half-wave of a small alpha is shorter than the column (theta(1/2)
            // < 0); it lengthens with alpha (the pendulum's period) and reaches the column's
            // at the buckled end slope
            let (mut lo, mut hi) = (1e-6, 3.0);
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if midspan(r, mid).0 < 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let w = midspan(r, 0.5 * (lo + hi)).1;
            approx::assert_abs_diff_eq!(elastica_midspan_deflection(r), w, epsilon = 1e-9);
        }
        approx::assert_abs_diff_eq!(elastica_midspan_deflection(1.05), 0.1900, epsilon = 5e-5);
        approx::assert_abs_diff_eq!(elastica_midspan_deflection(1.015), 0.1083, epsilon = 5e-5);
        assert_eq!(elastica_midspan_deflection(0.9), 0.0);
    }

    /// Small loads: the linear beam's w = k/3, and u = 1/2 int w'^2 ds = k^2 / 15.
    #[test]
    fn elastica_reduces_to_linear_beam() {
        let tip = elastica_tip(1e-4);
        let (u, w) = (tip.shortening, tip.deflection);
        approx::assert_relative_eq!(w, 1e-4 / 3.0, max_relative = 1e-6);
        approx::assert_relative_eq!(u, 1e-8 / 15.0, max_relative = 1e-3);
    }
}

/// A direct integrator's textbook recurrence for the undamped oscillator u'' + omega^2 u = 0,
/// written independently of `integrator` (state and formulas as in Bathe, Finite Element
/// Procedures, section 9.4, and Chung & Hulbert 1993).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Recurrence {
    /// Newmark (beta, gamma); state [u, h v, h^2 a].
    Newmark { beta: f64, gamma: f64 },
    /// Generalized-alpha (alpha_m, alpha_f, beta, gamma); HHT is alpha_m = 0, alpha_f = -alpha.
    GeneralizedAlpha {
        alpha_m: f64,
        alpha_f: f64,
        beta: f64,
        gamma: f64,
    },
    /// Wilson-theta; state [u, h v, h^2 a].
    Wilson { theta: f64 },
    /// Houbolt; state [u_{n+1}, u_n, u_{n-1}].
    Houbolt,
}

/// The amplification matrix A(Omega), Omega = omega h: X_{n+1} = A X_n.
pub fn amplification(method: Recurrence, omega_h: f64) -> nalgebra::Matrix3<f64> {
    use nalgebra::Matrix3;
    let w2 = omega_h * omega_h;
    match method {
        Recurrence::Newmark { beta, gamma } => amplification(
            Recurrence::GeneralizedAlpha {
                alpha_m: 0.0,
                alpha_f: 0.0,
                beta,
                gamma,
            },
            omega_h,
        ),
        Recurrence::GeneralizedAlpha {
            alpha_m,
            alpha_f,
            beta,
            gamma,
        } => {
            // unknowns scaled: U = u, V = h v, A = h^2 a
            // (1-am) A1 + am A0 + w2 ((1-af) U1 + af U0) = 0
            // U1 = U0 + V0 + (1/2 - beta) A0 + beta A1
            // V1 = V0 + (1 - gamma) A0 + gamma A1
            let l = Matrix3::new(
                w2 * (1.0 - alpha_f),
                0.0,
                1.0 - alpha_m,
                1.0,
                0.0,
                -beta,
                0.0,
                1.0,
                -gamma,
            );
            let r = Matrix3::new(
                -w2 * alpha_f,
                0.0,
                -alpha_m,
                1.0,
                1.0,
                0.5 - beta,
                0.0,
                1.0,
                1.0 - gamma,
            );
            l.try_inverse().expect("regular") * r
        }
        Recurrence::Wilson { theta } => {
            // equilibrium at t + theta h with linear acceleration (Bathe table 9.3):
            // A_t = A0 + theta (A1 - A0) ... solved for A1 from
            // A_t + w2 U_t = 0, U_t = U0 + theta V0 + theta^2/6 (A_t + 2 A0)
            // then U1 = U0 + V0 + (A1 + 2 A0)/6, V1 = V0 + (A0 + A1)/2
            let t = theta;
            // A_t (1 + w2 t^2/6) = -w2 (U0 + t V0 + t^2/3 A0)
            let c = 1.0 / (1.0 + w2 * t * t / 6.0);
            let at = [-w2 * c, -w2 * t * c, -w2 * t * t / 3.0 * c];
            // A1 = A0 + (A_t - A0)/theta
            let a1 = [at[0] / t, at[1] / t, at[2] / t + 1.0 - 1.0 / t];
            let u1 = [1.0 + a1[0] / 6.0, 1.0 + a1[1] / 6.0, (a1[2] + 2.0) / 6.0];
            let v1 = [a1[0] / 2.0, 1.0 + a1[1] / 2.0, (1.0 + a1[2]) / 2.0];
            Matrix3::new(
                u1[0], u1[1], u1[2], v1[0], v1[1], v1[2], a1[0], a1[1], a1[2],
            )
        }
        Recurrence::Houbolt => {
            // (2 u_{n+1} - 5 u_n + 4 u_{n-1} - u_{n-2}) + w2 u_{n+1} = 0
            let c = 1.0 / (2.0 + w2);
            Matrix3::new(5.0 * c, -4.0 * c, c, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0)
        }
    }
}

/// Spectral radius rho and phase Omega_bar of the principal (complex) root of A(omega h);
/// the numerical period is 2 pi h / Omega_bar.
pub fn principal_root(method: Recurrence, omega_h: f64) -> (f64, f64) {
    let eig = amplification(method, omega_h).complex_eigenvalues();
    let root = eig
        .iter()
        .filter(|z| z.im > 0.0)
        .max_by(|a, b| a.norm().total_cmp(&b.norm()))
        .copied();
    let root = root.unwrap_or_else(|| {
        *eig.iter()
            .max_by(|a, b| a.norm().total_cmp(&b.norm()))
            .expect("3 roots")
    });
    (root.norm(), root.arg().abs())
}

/// Spectral radius (largest root modulus) of A(omega h): > 1 means the method is unstable there.
pub fn spectral_radius(method: Recurrence, omega_h: f64) -> f64 {
    amplification(method, omega_h)
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

/// Uniaxial stress of a bar with linear isotropic (H_iso) and kinematic (H_kin) hardening
/// along a strain path, each step monotone: the closed-form piecewise-linear response
/// (elastic slope E until |sigma - alpha| = sigma_y0 + H_iso eps_p, then slope
/// E (H_iso + H_kin) / (E + H_iso + H_kin)). Returns the stress after each point of `strains`
/// (starting from zero strain and stress).
pub fn uniaxial_bar_stress(
    young: f64,
    yield_stress: f64,
    h_iso: f64,
    h_kin: f64,
    strains: &[f64],
) -> Vec<f64> {
    let (mut eps, mut sigma, mut alpha, mut eps_p) = (0.0, 0.0, 0.0, 0.0);
    let h = h_iso + h_kin;
    let tangent = young * h / (young + h);
    strains
        .iter()
        .map(|&target| {
            let d = target - eps;
            eps = target;
            if d == 0.0 {
                return sigma;
            }
            let s = d.signum();
            // stress room before the yield surface alpha + s sigma_y(eps_p), as strain
            let room = s * (alpha + s * (yield_stress + h_iso * eps_p) - sigma);
            let elastic = (room / young).max(0.0);
            if elastic >= d.abs() {
                sigma += young * d;
            } else {
                let plastic = d.abs() - elastic;
                sigma += s * (young * elastic + tangent * plastic);
                let dep = plastic * young / (young + h); // d eps - d sigma / E
                eps_p += dep;
                alpha += s * h_kin * dep;
            }
            sigma
        })
        .collect()
}

/// Uniaxial strain (plane strain, the lateral strains held at zero) of a J2 material with
/// linear isotropic hardening H under a monotone axial (logarithmic) strain `strain`:
/// the mean stress K eps (plastic flow is isochoric), the Mises stress q = 2 mu |eps| while
/// elastic, then q = 2 mu |eps| - 3 mu eps_p = sigma_y + H eps_p, so
/// eps_p = (2 mu |eps| - sigma_y) / (3 mu + H). Returns (sigma_axial, sigma_lateral, eps_p)
/// with sigma_axial = K eps + sign(eps) 2/3 q, sigma_lateral = K eps - sign(eps) q / 3
/// (the lateral stresses xx and zz are equal).
pub fn uniaxial_strain_j2(
    young: f64,
    poisson: f64,
    yield_stress: f64,
    hardening: f64,
    strain: f64,
) -> (f64, f64, f64) {
    let mu = young / (2.0 * (1.0 + poisson));
    let bulk = young / (3.0 * (1.0 - 2.0 * poisson));
    let eps_p = ((2.0 * mu * strain.abs() - yield_stress) / (3.0 * mu + hardening)).max(0.0);
    let q = 2.0 * mu * strain.abs() - 3.0 * mu * eps_p;
    let s = strain.signum();
    (
        bulk * strain + s * 2.0 / 3.0 * q,
        bulk * strain - s * q / 3.0,
        eps_p,
    )
}

/// Hill's elastic-perfectly plastic thick cylinder (Mises, plane strain, incompressible),
/// inner radius a, outer b, yield stress sigma_y, shear modulus G, plastic front at radius c:
/// internal pressure p(c) = (2/sqrt 3) sigma_y (ln(c/a) + (1 - c^2/b^2)/2) and bore
/// displacement u(a) = sigma_y c^2 / (2 sqrt 3 G a). Returns (p, u_a).
pub fn hill_cylinder(a: f64, b: f64, yield_stress: f64, shear_modulus: f64, c: f64) -> (f64, f64) {
    let k = yield_stress / 3f64.sqrt();
    (
        k * (2.0 * (c / a).ln() + 1.0 - c * c / (b * b)),
        k * c * c / (2.0 * shear_modulus * a),
    )
}

/// Hill's limit pressure (2/sqrt 3) sigma_y ln(b/a).
pub fn hill_limit_pressure(a: f64, b: f64, yield_stress: f64) -> f64 {
    2.0 / 3f64.sqrt() * yield_stress * (b / a).ln()
}

/// The bore displacement of Hill's cylinder at pressure p (elastic below first yield,
/// p < limit): the front c solved from p(c) by bisection.
pub fn hill_bore_displacement(
    a: f64,
    b: f64,
    yield_stress: f64,
    shear_modulus: f64,
    p: f64,
) -> f64 {
    let (p_first, _) = hill_cylinder(a, b, yield_stress, shear_modulus, a);
    if p <= p_first {
        // incompressible Lame: u(a) = p a b^2 / (2 G (b^2 - a^2))
        return p * a * b * b / (2.0 * shear_modulus * (b * b - a * a));
    }
    let (mut lo, mut hi) = (a, b);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if hill_cylinder(a, b, yield_stress, shear_modulus, mid).0 < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hill_cylinder(a, b, yield_stress, shear_modulus, 0.5 * (lo + hi)).1
}

/// Hertz impact of an elastic sphere (radius R, density rho, E, nu) on a rigid plane at
/// speed V (Johnson, Contact Mechanics, section 11.4): the maximum approach
/// delta = (15 m V^2 / (16 E* sqrt R))^(2/5) with m = 4/3 pi R^3 rho, E* = E / (1 - nu^2);
/// returns (maximum contact radius sqrt(R delta), contact duration 2.9432 delta / V,
/// peak force 4/3 E* sqrt(R) delta^(3/2)).
pub fn hertz_sphere_impact(
    radius: f64,
    density: f64,
    young: f64,
    poisson: f64,
    speed: f64,
) -> (f64, f64, f64) {
    let mass = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3) * density;
    let e_star = young / (1.0 - poisson * poisson);
    let delta = (15.0 * mass * speed * speed / (16.0 * e_star * radius.sqrt())).powf(0.4);
    (
        (radius * delta).sqrt(),
        2.9432 * delta / speed,
        4.0 / 3.0 * e_star * radius.sqrt() * delta.powf(1.5),
    )
}

/// A rod (density rho, Young's modulus E, section A, length L) striking a rigid wall at speed V
/// (Hughes, Taylor & Sackman 1975, section I-3; d'Alembert): the contact force is
/// rho c A V (c = sqrt(E / rho)) for 0 < t < 2 L / c, then the rod leaves at -V.
/// Returns (force, duration 2 L / c).
pub fn rod_wall_impact(density: f64, young: f64, area: f64, length: f64, speed: f64) -> (f64, f64) {
    let c = (young / density).sqrt();
    (density * c * area * speed, 2.0 * length / c)
}

/// Two equal rods (rho, E, A, L) meeting at relative speed V (same source): the contact
/// force is rho c A V / 2 for 0 < t < 2 L / c, then they release, the striker at rest and
/// the struck rod at V. Returns (force, duration 2 L / c).
pub fn equal_bars_impact(
    density: f64,
    young: f64,
    area: f64,
    length: f64,
    speed: f64,
) -> (f64, f64) {
    let (force, duration) = rod_wall_impact(density, young, area, length, speed);
    (0.5 * force, duration)
}

/// Static Hertz contact of a sphere (radius R) pressed by a force P on a rigid plane:
/// contact radius a = (3 P R / (4 E*))^(1/3) and peak pressure p0 = 3 P / (2 pi a^2).
pub fn hertz_static(radius: f64, young: f64, poisson: f64, force: f64) -> (f64, f64) {
    let e_star = young / (1.0 - poisson * poisson);
    let a = (3.0 * force * radius / (4.0 * e_star)).cbrt();
    (a, 3.0 * force / (2.0 * std::f64::consts::PI * a * a))
}

/// Hertz line contact of two parallel cylinders (radii R1, R2, plane strain moduli from E
/// and nu of each) pressed together by a force P per unit length (Johnson 1985, section 4.3):
/// 1/R* = 1/R1 + 1/R2, 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2, half-width
/// b = sqrt(4 P R* / (pi E*)) and peak pressure p0 = 2 P / (pi b), the pressure
/// p0 sqrt(1 - x^2 / b^2) across the strip. Returns (b, p0).
pub fn hertz_cylinders(
    radii: [f64; 2],
    young: [f64; 2],
    poisson: [f64; 2],
    force: f64,
) -> (f64, f64) {
    let radius = 1.0 / (1.0 / radii[0] + 1.0 / radii[1]);
    let modulus = 1.0
        / ((1.0 - poisson[0] * poisson[0]) / young[0] + (1.0 - poisson[1] * poisson[1]) / young[1]);
    let b = (4.0 * force * radius / (std::f64::consts::PI * modulus)).sqrt();
    (b, 2.0 * force / (std::f64::consts::PI * b))
}

#[cfg(test)]
mod hertz_tests {
    /// Hughes et al. 1975, Table I-1 (their Hertz column): a = 0.59, t = 0.256, p = 60.2 at
    /// V = 0.8 and a = 1.00, t = 0.197, p = 294 at V = 3.0 (R = 5, rho = 0.01, E = 1000,
    /// nu = 0.3), to their printed digits.
    #[test]
    fn hertz_impact_matches_hughes_table_i_1() {
        let (a, t, p) = super::hertz_sphere_impact(5.0, 0.01, 1000.0, 0.3, 0.8);
        approx::assert_abs_diff_eq!(a, 0.59, epsilon = 0.005);
        approx::assert_abs_diff_eq!(t, 0.256, epsilon = 0.0005);
        approx::assert_abs_diff_eq!(p, 60.2, epsilon = 0.05);
        let (a, t, p) = super::hertz_sphere_impact(5.0, 0.01, 1000.0, 0.3, 3.0);
        approx::assert_abs_diff_eq!(a, 1.00, epsilon = 0.005);
        approx::assert_abs_diff_eq!(t, 0.197, epsilon = 0.0005);
        approx::assert_abs_diff_eq!(p, 294.0, epsilon = 0.5);
    }
}
