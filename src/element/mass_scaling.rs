//! Selective mass scaling of central difference: an element whose stable step is below a
//! target gets the density that makes its step the target; the others keep theirs
//! (docs/theory.md 8.7b; LS-DYNA's DT2MS < 0, Abaqus' variable mass scaling "below minimum").
//!
//! Legend (one element)
//! ```text
//! omega^2    the bound of the element's highest frequency squared that its kernel computes
//!            with its current lumped masses s m_a (docs/theory.md 8.7); every such bound is
//!            a stiffness over a mass, so omega^2 = omega_0^2 / s, omega_0 the unscaled one
//! dt_e       2 / omega, the element's stable step
//! s          the element's mass factor (1: unscaled): its lumped masses are s m_a
//! target     analysis.mass_scaling.target, a stable step (a time)
//! s'         max(s, (target / dt_e,0)^2) = max(s, s omega^2 target^2 / 4): the element's
//!            step becomes the target when it is below it; a factor never falls (the mass
//!            added stays), so an element that recovers keeps the step its mass gives it
//! ```

use serde::{Deserialize, Serialize};

/// The mass scaling's rule: the target stable step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MassScaling {
    /// The stable step (a time, > 0) below which an element's mass is raised.
    pub target: f64,
}

/// An element whose factor grew: its new factor and the frequency bound squared it has with
/// it (4 / target^2: its step is the target).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rescaled {
    pub factor: f64,
    pub omega_squared: f64,
}

impl MassScaling {
    /// The factor s' of an element whose factor is `factor` and whose frequency bound
    /// squared with it is `omega_squared` (see the legend); None when its step is at least
    /// the target (or its bound not a number: the run's own checks stop it).
    #[inline(always)]
    pub fn rescale(&self, factor: f64, omega_squared: f64) -> Option<Rescaled> {
        let needed = factor * omega_squared * 0.25 * self.target * self.target;
        (needed > factor).then(|| Rescaled {
            factor: needed,
            omega_squared: 4.0 / (self.target * self.target),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An element at half the target needs four times its mass (omega^2 ~ 1 / m), and its
    /// step is then the target; one at or above the target keeps its factor; an element
    /// already scaled grows from its factor, not from 1.
    #[test]
    fn rescale_raises_the_step_to_the_target() {
        let rule = MassScaling { target: 2.0 };
        // step 2 / omega = 1: half the target
        let r = rule.rescale(1.0, 4.0).unwrap();
        assert_eq!(r.factor, 4.0);
        assert!((2.0 / r.omega_squared.sqrt() - 2.0).abs() < 1e-15);
        // step 2 / omega = 2: the target itself, and above it
        assert_eq!(rule.rescale(1.0, 1.0), None);
        assert_eq!(rule.rescale(1.0, 0.25), None);
        // factor 4, its step fell to 1 again (the element crushed to half its size): the
        // unscaled step is 0.5, so it needs 16
        assert_eq!(rule.rescale(4.0, 4.0).unwrap().factor, 16.0);
        assert_eq!(rule.rescale(1.0, f64::NAN), None);
    }
}
