//! Direct time integrators in effective-stiffness form, behind one trait.
//!
//! Legend (all vectors over every DOF; n = start of the step, dt its length)
//! ```text
//! D            the solved displacement increment from u_n (u(t_n + s dt) - u_n, s = `solve_fraction`)
//! a*(D)        = ca D + a_hat    acceleration in the inertia term of the residual
//! v*(D)        = cv D + v_hat    velocity in the damping term
//! f*           = w f_int(D) + (1 - w) f_int,n
//! R(D)         = f_ext(t_n + l dt) - M a* - C v* - f*       (l = `load_fraction`)
//! K*           = ca M + cv C + w K_T                          (dR/dD = -K*)
//! ```
//! Every method below is a choice of (ca, a_hat, cv, v_hat, w, s, l) and of the update of
//! u, v, a from the converged D; the driver never asks which method it runs.

use serde::Serialize;

/// The committed kinematics at the start of a step.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct MotionState {
    pub displacement: Vec<f64>,
    pub velocity: Vec<f64>,
    pub acceleration: Vec<f64>,
}

/// What the driver needs for one implicit step (see the legend).
#[derive(Debug, Clone)]
pub struct StepForm {
    pub solve_fraction: f64,
    pub load_fraction: f64,
    pub mass_coefficient: f64,
    pub acceleration_offset: Vec<f64>,
    pub damping_coefficient: f64,
    pub velocity_offset: Vec<f64>,
    pub internal_weight: f64,
}

impl StepForm {
    /// a*(D) and v*(D) over all DOFs.
    pub fn motion(&self, d: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let a = d
            .iter()
            .zip(&self.acceleration_offset)
            .map(|(d, h)| self.mass_coefficient * d + h)
            .collect();
        let v = d
            .iter()
            .zip(&self.velocity_offset)
            .map(|(d, h)| self.damping_coefficient * d + h)
            .collect();
        (a, v)
    }
}

/// The end-of-step kinematics from the converged D.
#[derive(Debug, Clone)]
pub struct Advance {
    /// u_{n+1} - u_n (equal to D unless the method solves at another point, as Wilson's).
    pub increment: Vec<f64>,
    pub velocity: Vec<f64>,
    pub acceleration: Vec<f64>,
}

pub trait Integrator: Send {
    /// A name for summaries and charts (with its parameters).
    fn name(&self) -> String;
    fn form(&self, dt: f64, k: &MotionState) -> StepForm;
    /// The end-of-step kinematics; the method may keep history (Houbolt).
    fn advance(&mut self, dt: f64, k: &MotionState, solved: &[f64]) -> Advance;
    /// Called when a step is abandoned (cut): history stays as before the step.
    fn reject(&mut self) {}
    /// The constant c of the local error estimate e = c dt^2 (a_{n+1} - a_n) of the
    /// displacement (Zienkiewicz & Xie 1991: c = |beta - 1/6| for the Newmark family); None
    /// where the method has no such estimate.
    fn error_constant(&self) -> Option<f64> {
        None
    }
    /// What the method carries from step to step besides u, v, a (for checkpoints).
    fn history(&self) -> MethodHistory {
        MethodHistory::default()
    }
    /// Continues from a saved [`MethodHistory`] (a resumed run).
    fn restore(&mut self, _history: MethodHistory) {}
}

/// A method's own history between steps: Houbolt's u_{n-1}, u_{n-2} and their dt; empty for
/// one-step methods.
#[derive(Debug, Clone, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct MethodHistory {
    pub past: Vec<Vec<f64>>,
    pub dt: Option<f64>,
}

fn affine(c: f64, terms: &[(f64, &[f64])], n: usize) -> (f64, Vec<f64>) {
    let mut out = vec![0.0; n];
    for (f, v) in terms {
        for (o, x) in out.iter_mut().zip(v.iter()) {
            *o += f * x;
        }
    }
    (c, out)
}

/// The generalized-alpha family (Chung & Hulbert 1993): Newmark (alpha_m = alpha_f = 0),
/// Hilber-Hughes-Taylor (alpha_m = 0, alpha_f = -alpha_HHT) and Chung-Hulbert.
///
/// ```text
/// (1 - am) M a_{n+1} + am M a_n + (1 - af)(C v_{n+1} + f_int,n+1) + af (C v_n + f_int,n)
///     = f_ext(t_{n+1-af})
/// u_{n+1} = u_n + dt v_n + dt^2 ((1/2 - beta) a_n + beta a_{n+1})
/// v_{n+1} = v_n + dt ((1 - gamma) a_n + gamma a_{n+1})
/// ```
/// Newmark presets: `average` (1/4, 1/2), `linear` (1/6, 1/2), and Hu's (1.0, 1.5) of the
/// Greco & Coda 2003 (eqs 18-33), which is unconditionally stable and strongly dissipative.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneralizedAlpha {
    pub label: &'static str,
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub beta: f64,
    pub gamma: f64,
}

impl GeneralizedAlpha {
    pub fn newmark(label: &'static str, beta: f64, gamma: f64) -> Self {
        GeneralizedAlpha {
            label,
            alpha_m: 0.0,
            alpha_f: 0.0,
            beta,
            gamma,
        }
    }

    /// HHT with alpha in [-1/3, 0].
    pub fn hht(alpha: f64) -> Self {
        GeneralizedAlpha {
            label: "hht",
            alpha_m: 0.0,
            alpha_f: -alpha,
            beta: (1.0 - alpha).powi(2) / 4.0,
            gamma: 0.5 - alpha,
        }
    }

    /// Chung-Hulbert with spectral radius rho_inf in [0, 1] at infinite frequency.
    pub fn chung_hulbert(rho_inf: f64) -> Self {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 - alpha_m + alpha_f;
        GeneralizedAlpha {
            label: "generalized_alpha",
            alpha_m,
            alpha_f,
            beta: 0.25 * (gamma + 0.5).powi(2),
            gamma,
        }
    }

    fn newmark_acceleration(&self, dt: f64, k: &MotionState) -> (f64, Vec<f64>) {
        // a_{n+1} = D / (beta dt^2) - v_n / (beta dt) - (1/(2 beta) - 1) a_n
        let b = self.beta;
        affine(
            1.0 / (b * dt * dt),
            &[
                (-1.0 / (b * dt), &k.velocity),
                (-(0.5 / b - 1.0), &k.acceleration),
            ],
            k.velocity.len(),
        )
    }
}

impl Integrator for GeneralizedAlpha {
    fn error_constant(&self) -> Option<f64> {
        let c = (self.beta - 1.0 / 6.0).abs();
        (c > 1e-3).then_some(c)
    }

    fn name(&self) -> String {
        match self.label {
            "hht" => format!("hht(alpha={})", -self.alpha_f),
            "generalized_alpha" => format!(
                "generalized_alpha(am={:.4},af={:.4})",
                self.alpha_m, self.alpha_f
            ),
            l => format!("{l}(beta={},gamma={})", self.beta, self.gamma),
        }
    }

    fn form(&self, dt: f64, k: &MotionState) -> StepForm {
        let n = k.velocity.len();
        let (ca, a_hat) = self.newmark_acceleration(dt, k);
        let (b, g) = (self.beta, self.gamma);
        // v_{n+1} = gamma/(beta dt) D + (1 - gamma/beta) v_n + dt (1 - gamma/(2 beta)) a_n
        let (cv, v_hat) = affine(
            g / (b * dt),
            &[
                (1.0 - g / b, &k.velocity),
                (dt * (1.0 - g / (2.0 * b)), &k.acceleration),
            ],
            n,
        );
        let (am, af) = (self.alpha_m, self.alpha_f);
        let acceleration_offset = a_hat
            .iter()
            .zip(&k.acceleration)
            .map(|(h, a)| (1.0 - am) * h + am * a)
            .collect();
        let velocity_offset = v_hat
            .iter()
            .zip(&k.velocity)
            .map(|(h, v)| (1.0 - af) * h + af * v)
            .collect();
        StepForm {
            solve_fraction: 1.0,
            load_fraction: 1.0 - af,
            mass_coefficient: (1.0 - am) * ca,
            acceleration_offset,
            damping_coefficient: (1.0 - af) * cv,
            velocity_offset,
            internal_weight: 1.0 - af,
        }
    }

    fn advance(&mut self, dt: f64, k: &MotionState, solved: &[f64]) -> Advance {
        let (ca, a_hat) = self.newmark_acceleration(dt, k);
        let acceleration: Vec<f64> = solved.iter().zip(&a_hat).map(|(d, h)| ca * d + h).collect();
        let g = self.gamma;
        let velocity = k
            .velocity
            .iter()
            .zip(k.acceleration.iter().zip(&acceleration))
            .map(|(v, (a0, a1))| v + dt * ((1.0 - g) * a0 + g * a1))
            .collect();
        Advance {
            increment: solved.to_vec(),
            velocity,
            acceleration,
        }
    }
}

/// Wilson's theta method (Wilson, Farhoomand & Bathe 1973): linear acceleration over
/// [t_n, t_n + theta dt], equilibrium at t_n + theta dt, then interpolated back to t_{n+1}.
/// Unconditionally stable for theta >= 1.37 (1.4 is the usual choice).
/// ```text
/// a_theta = 6/(theta dt)^2 D - 6/(theta dt) v_n - 2 a_n,   D = u(t_n + theta dt) - u_n
/// v_theta = 3/(theta dt) D - 2 v_n - theta dt/2 a_n
/// a_{n+1} = a_n + (a_theta - a_n)/theta
/// v_{n+1} = v_n + dt/2 (a_n + a_{n+1}),  u_{n+1} = u_n + dt v_n + dt^2/6 (a_{n+1} + 2 a_n)
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wilson {
    pub theta: f64,
}

impl Integrator for Wilson {
    fn name(&self) -> String {
        format!("wilson(theta={})", self.theta)
    }

    fn form(&self, dt: f64, k: &MotionState) -> StepForm {
        let n = k.velocity.len();
        let h = self.theta * dt;
        let (ca, acceleration_offset) = affine(
            6.0 / (h * h),
            &[(-6.0 / h, &k.velocity), (-2.0, &k.acceleration)],
            n,
        );
        let (cv, velocity_offset) = affine(
            3.0 / h,
            &[(-2.0, &k.velocity), (-h / 2.0, &k.acceleration)],
            n,
        );
        StepForm {
            solve_fraction: self.theta,
            load_fraction: self.theta,
            mass_coefficient: ca,
            acceleration_offset,
            damping_coefficient: cv,
            velocity_offset,
            internal_weight: 1.0,
        }
    }

    fn advance(&mut self, dt: f64, k: &MotionState, solved: &[f64]) -> Advance {
        let h = self.theta * dt;
        let mut increment = Vec::with_capacity(solved.len());
        let mut velocity = Vec::with_capacity(solved.len());
        let mut acceleration = Vec::with_capacity(solved.len());
        for (i, d) in solved.iter().enumerate() {
            let (v0, a0) = (k.velocity[i], k.acceleration[i]);
            let a_theta = 6.0 / (h * h) * d - 6.0 / h * v0 - 2.0 * a0;
            let a1 = a0 + (a_theta - a0) / self.theta;
            acceleration.push(a1);
            velocity.push(v0 + dt / 2.0 * (a0 + a1));
            increment.push(dt * v0 + dt * dt / 6.0 * (a1 + 2.0 * a0));
        }
        Advance {
            increment,
            velocity,
            acceleration,
        }
    }
}

/// Houbolt's method (Houbolt 1950): backward differences through u_{n-2}, u_{n-1}, u_n,
/// u_{n+1}; the first two steps are average-acceleration Newmark steps.
/// ```text
/// a_{n+1} = (2 u_{n+1} - 5 u_n + 4 u_{n-1} - u_{n-2}) / dt^2
/// v_{n+1} = (11 u_{n+1} - 18 u_n + 9 u_{n-1} - 2 u_{n-2}) / (6 dt)
/// ```
/// The history assumes a constant dt; a changed dt restarts it with Newmark steps.
#[derive(Debug, Clone, Default)]
pub struct Houbolt {
    /// u_{n-1}, u_{n-2} (most recent first), with the dt they were taken at.
    past: Vec<Vec<f64>>,
    dt: Option<f64>,
}

impl Houbolt {
    fn starter() -> GeneralizedAlpha {
        GeneralizedAlpha::newmark("average", 0.25, 0.5)
    }

    fn ready(&self, dt: f64) -> bool {
        self.past.len() >= 2 && self.dt == Some(dt)
    }
}

impl Integrator for Houbolt {
    fn name(&self) -> String {
        "houbolt".into()
    }

    fn form(&self, dt: f64, k: &MotionState) -> StepForm {
        if !self.ready(dt) {
            return Houbolt::starter().form(dt, k);
        }
        let n = k.displacement.len();
        let (u0, u1, u2) = (&k.displacement, &self.past[0], &self.past[1]);
        // u_{n+1} = u_n + D
        let (ca, acceleration_offset) = affine(
            2.0 / (dt * dt),
            &[
                (-3.0 / (dt * dt), u0),
                (4.0 / (dt * dt), u1),
                (-1.0 / (dt * dt), u2),
            ],
            n,
        );
        let (cv, velocity_offset) = affine(
            11.0 / (6.0 * dt),
            &[
                (-7.0 / (6.0 * dt), u0),
                (9.0 / (6.0 * dt), u1),
                (-2.0 / (6.0 * dt), u2),
            ],
            n,
        );
        StepForm {
            solve_fraction: 1.0,
            load_fraction: 1.0,
            mass_coefficient: ca,
            acceleration_offset,
            damping_coefficient: cv,
            velocity_offset,
            internal_weight: 1.0,
        }
    }

    fn advance(&mut self, dt: f64, k: &MotionState, solved: &[f64]) -> Advance {
        let advance = if self.ready(dt) {
            let (acceleration, velocity) = self.form(dt, k).motion(solved);
            Advance {
                increment: solved.to_vec(),
                velocity,
                acceleration,
            }
        } else {
            if self.dt != Some(dt) {
                self.past.clear();
            }
            Houbolt::starter().advance(dt, k, solved)
        };
        self.dt = Some(dt);
        self.past.insert(0, k.displacement.clone());
        self.past.truncate(2);
        advance
    }

    fn history(&self) -> MethodHistory {
        MethodHistory {
            past: self.past.clone(),
            dt: self.dt,
        }
    }

    fn restore(&mut self, history: MethodHistory) {
        self.past = history.past;
        self.dt = history.dt;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For a linear SDOF oscillator (m = 1, k = omega^2) each implicit method's residual form
    /// must reproduce its textbook recurrence; checked on Newmark average: the discrete energy
    /// 1/2 v^2 + 1/2 omega^2 u^2 is conserved exactly.
    #[test]
    fn newmark_average_conserves_sdof_energy() {
        let omega: f64 = 2.0;
        let dt = 0.3;
        let mut m = GeneralizedAlpha::newmark("average", 0.25, 0.5);
        let mut k = MotionState {
            displacement: vec![1.0],
            velocity: vec![0.0],
            acceleration: vec![-omega * omega],
        };
        let e0 = 0.5 * omega * omega;
        for _ in 0..100 {
            let f = m.form(dt, &k);
            // R = -(ca D + ah) - omega^2 (u + D) = 0
            let d = -(f.acceleration_offset[0] + omega * omega * k.displacement[0])
                / (f.mass_coefficient + omega * omega);
            let adv = m.advance(dt, &k, &[d]);
            k = MotionState {
                displacement: vec![k.displacement[0] + adv.increment[0]],
                velocity: adv.velocity,
                acceleration: adv.acceleration,
            };
            let e = 0.5 * k.velocity[0].powi(2) + 0.5 * omega * omega * k.displacement[0].powi(2);
            approx::assert_relative_eq!(e, e0, max_relative = 1e-12);
        }
    }
}
