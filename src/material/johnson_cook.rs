//! The Johnson-Cook flow stress (Johnson and Cook 1983) with adiabatic heating: the
//! rate- and temperature-dependent isotropic hardening that the J2 return of `j2` solves for
//! (`Hardening::JohnsonCook`).
//!
//! Legend (A is the J2 model's `yield_stress`)
//! ```text
//! sigma_y   (A + B eps_p^n) (1 + C ln max(rate / rate_0, 1)) (1 - T*^m)
//! eps_p     eps_p,n + dep: the committed equivalent plastic strain plus the increment's
//! rate      dep / dt: the equivalent plastic strain rate of the increment (dt = infinity:
//!           no rate, the factor is 1)
//! T*        (T_n - T_room) / (T_melt - T_room), clamped to [0, 1]; T_n the committed
//!           temperature (the heating of the increment enters the next one)
//! dT        chi w_p / (rho c_p),  w_p = sigma : d eps_p the plastic work per unit volume of
//!           the increment, chi the Taylor-Quinney coefficient, c_p the specific heat
//! H         d sigma_y / d dep = [B n eps_p^(n-1) R + (A + B eps_p^n) C / dep] Theta, the
//!           second term only where the rate exceeds rate_0 (R, Theta the rate and thermal
//!           factors)
//! ```
//! Edge cases: below the reference rate the rate factor is 1 (no strength loss at low rates,
//! and the factor stays >= 1 as dep -> 0); below room temperature T* = 0 and at or above the
//! melting temperature T* = 1, so sigma_y = 0 there and the return takes the deviatoric
//! stress to zero (the point carries pressure only). At eps_p = 0 with n < 1 the slope B n
//! eps_p^(n-1) is infinite: the law is not regularized; the return's Newton is bracketed and
//! bisects when the slope is not finite, and the tangent's slope is taken at eps_p,n+1 > 0.

/// The Johnson-Cook parameters besides A (the J2 model's `yield_stress`).
#[derive(Debug, Clone, PartialEq)]
pub struct JohnsonCook {
    /// Hardening modulus B >= 0 (stress).
    pub b: f64,
    /// Hardening exponent n > 0.
    pub n: f64,
    /// Strain-rate coefficient C >= 0.
    pub c: f64,
    /// Reference strain rate rate_0 > 0 (1 / time).
    pub reference_rate: f64,
    /// Thermal softening exponent m > 0.
    pub m: f64,
    pub room_temperature: f64,
    /// T_melt > T_room.
    pub melting_temperature: f64,
    /// c_p > 0 (energy / (mass temperature)).
    pub specific_heat: f64,
    /// chi in [0, 1]: the fraction of the plastic work that heats the point.
    pub taylor_quinney: f64,
    /// The temperature of every point at t = 0.
    pub initial_temperature: f64,
}

impl JohnsonCook {
    /// T* clamped to [0, 1].
    pub fn homologous_temperature(&self, temperature: f64) -> f64 {
        ((temperature - self.room_temperature) / (self.melting_temperature - self.room_temperature))
            .clamp(0.0, 1.0)
    }

    /// The flow stress of an increment and its slope d sigma_y / d dep, for the initial
    /// yield stress `a`: from the committed `eq_plastic_strain` and `temperature` with the
    /// equivalent plastic strain increment `dep` over the step `dt`.
    pub fn flow_stress(
        &self,
        a: f64,
        eq_plastic_strain: f64,
        temperature: f64,
        dep: f64,
        dt: f64,
    ) -> (f64, f64) {
        let thermal = self.thermal_factor(temperature);
        self.flow_stress_at(a, eq_plastic_strain, thermal, dep, dt)
    }

    /// The thermal softening factor 1 - T*^m of `temperature`.
    #[inline]
    pub fn thermal_factor(&self, temperature: f64) -> f64 {
        // at or below room temperature (every point the plastic work has not heated) T* = 0
        // and the factor is 1: no powf (0^m = 0 for m > 0, so the same bits)
        let homologous = self.homologous_temperature(temperature);
        if homologous == 0.0 {
            return 1.0;
        }
        1.0 - homologous.powf(self.m)
    }

    /// The flow stress of a zero increment, without its slope (the elastic check of every
    /// point): (A + B eps_p^n) thermal.
    #[inline]
    pub fn start_flow_stress(&self, a: f64, eq_plastic_strain: f64, thermal: f64) -> f64 {
        // the rate factor of a zero increment is 1 (as flow_stress takes it)
        // a point that never flowed: eps_p^n = 0 without the powf (n > 0: the same bits)
        let power = if eq_plastic_strain == 0.0 {
            0.0
        } else {
            eq_plastic_strain.powf(self.n)
        };
        (a + self.b * power) * 1.0 * thermal
    }

    /// `flow_stress` with the thermal factor of the step's temperature given (it is the same
    /// at every iterate of a return).
    #[inline]
    pub fn flow_stress_at(
        &self,
        a: f64,
        eq_plastic_strain: f64,
        thermal: f64,
        dep: f64,
        dt: f64,
    ) -> (f64, f64) {
        let eps_p = eq_plastic_strain + dep;
        let power = eps_p.powf(self.n);
        let hardening = a + self.b * power;
        let hardening_slope = if self.b == 0.0 {
            0.0
        } else {
            // infinite at eps_p = 0 for n < 1 (see the module notes); above it eps_p^(n - 1)
            // is eps_p^n / eps_p, one powf fewer an iterate of the return
            let lower = if eps_p > 0.0 {
                power / eps_p
            } else {
                eps_p.powf(self.n - 1.0)
            };
            self.b * self.n * lower
        };
        let ratio = dep / (dt * self.reference_rate);
        let (rate_factor, rate_slope) = if self.c > 0.0 && ratio > 1.0 {
            (1.0 + self.c * ratio.ln(), self.c / dep)
        } else {
            (1.0, 0.0)
        };
        (
            hardening * rate_factor * thermal,
            (hardening_slope * rate_factor + hardening * rate_slope) * thermal,
        )
    }

    /// The temperature rise of the plastic work `plastic_work` per unit volume at `density`.
    pub fn temperature_rise(&self, plastic_work: f64, density: f64) -> f64 {
        self.taylor_quinney * plastic_work / (density * self.specific_heat)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law() -> JohnsonCook {
        JohnsonCook {
            b: 292.0,
            n: 0.31,
            c: 0.025,
            reference_rate: 1.0,
            m: 1.09,
            room_temperature: 293.0,
            melting_temperature: 1356.0,
            specific_heat: 383.0,
            taylor_quinney: 0.9,
            initial_temperature: 293.0,
        }
    }

    /// Goal: the slope H the return and its tangent use is the derivative of the flow stress
    /// in the increment, rate term included.
    /// Setup: A = 90, eps_p,n = 0.05, T_n = 500, dt = 1e-4, dep = 0.01 (rate 100 > rate_0)
    /// and dep = 1e-5 (rate 0.1 < rate_0: no rate term).
    /// Reference: central differences, h = 1e-4 dep (truncation ~ (h / dep)^2 = 1e-8,
    /// round-off eps sigma_y / h ~ 1e-7 of the slope at dep = 1e-5; 1e-6 relative bounds
    /// both).
    #[test]
    fn flow_stress_slope_matches_finite_differences() {
        let jc = law();
        let flow = |dep: f64| jc.flow_stress(90.0, 0.05, 500.0, dep, 1e-4);
        for dep in [0.01, 1e-5] {
            let (_, slope) = flow(dep);
            let h = 1e-4 * dep;
            let fd = (flow(dep + h).0 - flow(dep - h).0) / (2.0 * h);
            approx::assert_relative_eq!(slope, fd, max_relative = 1e-6);
        }
    }

    /// Goal: the edge cases of the law as documented.
    /// Setup and reference: below room temperature the thermal factor is 1; at and above the
    /// melting temperature the flow stress is 0; below the reference rate the rate factor is
    /// 1 (the rate-independent value A + B eps^n in closed form); at eps_p = 0 with n < 1
    /// the slope is infinite, and with B = 0 it is 0 (not 0 times infinity).
    #[test]
    fn edge_cases_are_clamped_as_documented() {
        let jc = law();
        let static_value = 90.0 + 292.0 * 0.1f64.powf(0.31);
        let (cold, _) = jc.flow_stress(90.0, 0.1, 100.0, 0.0, f64::INFINITY);
        assert_eq!(cold, static_value);
        for t in [1356.0, 2000.0] {
            assert_eq!(jc.flow_stress(90.0, 0.1, t, 0.01, 1.0), (0.0, 0.0));
        }
        // rate 1e-3 / 1 < 1
        let (slow, _) = jc.flow_stress(90.0, 0.1 - 1e-3, 293.0, 1e-3, 1.0);
        approx::assert_relative_eq!(slow, static_value, max_relative = 1e-15);
        let (_, slope) = jc.flow_stress(90.0, 0.0, 293.0, 0.0, 1.0);
        assert_eq!(slope, f64::INFINITY);
        let flat = JohnsonCook { b: 0.0, ..law() };
        assert_eq!(flat.flow_stress(90.0, 0.0, 293.0, 0.0, 1.0), (90.0, 0.0));
    }
}
