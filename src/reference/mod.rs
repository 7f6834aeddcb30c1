//! Closed-form and independently computed reference solutions, shared by the tests, the
//! validation report and `impact sweep`.

/// Lame's thick-walled cylinder under internal pressure `p` (inner radius a, outer b), in
/// plane strain (eps_zz = 0): the radial displacement at radius r,
/// u_r = (1 + nu) p a^2 / (E (b^2 - a^2)) ((1 - 2 nu) r + b^2 / r).
pub fn lame_radial_displacement(p: f64, a: f64, b: f64, young: f64, poisson: f64, r: f64) -> f64 {
    (1.0 + poisson) * p * a * a / (young * (b * b - a * a))
        * ((1.0 - 2.0 * poisson) * r + b * b / r)
}

/// Tip of an inextensible elastic cantilever (the elastica) of length 1, clamped at s = 0
/// along x, under a dead tip load perpendicular to the initial axis with k = P L^2 / (E I).
/// Returns (shortening u / L, deflection w / L, tip rotation).
///
/// theta'' = -k cos(theta), theta(0) = 0, theta'(1) = 0, solved by shooting on theta'(0)
/// with RK4 (4000 steps) and bisection; x' = cos(theta), y' = sin(theta).
pub fn elastica_tip(k: f64) -> (f64, f64, f64) {
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
    (1.0 - x, y, theta)
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
            let (du, dw, _) = elastica_tip(k);
            approx::assert_abs_diff_eq!(du, u, epsilon = 1e-5);
            approx::assert_abs_diff_eq!(dw, w, epsilon = 1e-5);
        }
    }

    /// Small loads: the linear beam's w = k/3, and u = 1/2 int w'^2 ds = k^2 / 15.
    #[test]
    fn elastica_reduces_to_linear_beam() {
        let (u, w, _) = elastica_tip(1e-4);
        approx::assert_relative_eq!(w, 1e-4 / 3.0, max_relative = 1e-6);
        approx::assert_relative_eq!(u, 1e-8 / 15.0, max_relative = 1e-3);
    }
}
