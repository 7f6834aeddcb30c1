//! The step length of the implicit steppers and what they share of the time line: cuts
//! after a failed Newton, growth back to the nominal step, the local error watch of
//! `dt = "auto"` and the probed point values it watches, steps snapped onto multiples of the
//! nominal step.

use super::newton::Counters;
use crate::assembly::State;
use crate::material::PointState;
use crate::output::readable;
use crate::scene::Model;
use crate::scene::spec::{AdaptiveStep, Quantity};
use serde::{Deserialize, Serialize};

/// Rounds a time that is a whole number of nominal steps up to round-off onto that multiple,
/// so history rows fall on k dt exactly.
pub(super) fn snap(t: f64, dt: f64) -> f64 {
    let k = (t / dt).round();
    if (t - k * dt).abs() <= 1e-9 * dt {
        k * dt
    } else {
        t
    }
}

/// The local error of the steps (theory 8.2a): with c the method's error constant,
/// ```text
/// e   = c dt^2 (a_{n+1} - a_n)                       (Zienkiewicz & Xie 1991)
/// eta = max_i |e_i| / (dt V),   V = the run's top nodal speed so far
/// ```
/// the error of the step's displacement relative to the distance the fastest node covers in
/// it. Carried through checkpoints.
#[derive(Debug, Clone, Copy, Default, serde::Serialize, serde::Deserialize)]
pub struct ErrorWatch {
    pub speed: f64,
    /// The last accepted step's estimate, and the largest of the run.
    pub last: f64,
    pub largest: f64,
}

/// The step length of a driver: halved when a step fails (at most `max_cuts` times in a
/// row), grown back towards the nominal length after each success (`accept`), or by half
/// after two in a row (`accept_patiently`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StepControl {
    pub(super) nominal: f64,
    pub(super) length: f64,
    cuts_in_a_row: usize,
    max_cuts: usize,
    /// Successes at the current length since it last changed (`accept_patiently`).
    #[serde(default)]
    successes: usize,
}

impl StepControl {
    pub(super) fn new(nominal: f64, max_cuts: usize) -> StepControl {
        StepControl {
            nominal,
            length: nominal,
            cuts_in_a_row: 0,
            max_cuts,
            successes: 0,
        }
    }

    /// A step ending at its target succeeded (`grow`: it was not ended early by an event).
    pub(super) fn accept(&mut self, grow: bool) {
        self.cuts_in_a_row = 0;
        if grow {
            self.length = (2.0 * self.length).min(self.nominal);
        }
    }

    /// A step ending at its target succeeded (`grow`: it was not ended early by an event);
    /// the length grows by half, up to the nominal, after two such steps in a row. Abaqus'
    /// automatic incrementation: a cut length is kept while it serves, where doubling back
    /// after one success met the length that had just failed, at nearly every increment of
    /// a structure crushed past its hinge load.
    pub(super) fn accept_patiently(&mut self, grow: bool) {
        self.cuts_in_a_row = 0;
        if !grow {
            return;
        }
        self.successes += 1;
        if self.successes >= 2 && self.length < self.nominal {
            self.length = (1.5 * self.length).min(self.nominal);
            self.successes = 0;
        }
    }

    /// An adaptive run's next step: `length` (the nominal too, so the floor of the cuts
    /// follows it).
    pub(super) fn propose(&mut self, length: f64) {
        self.nominal = length;
        self.length = length;
    }

    /// A step whose error estimate was too large: take it again with `length`.
    pub(super) fn retry(&mut self, length: f64) {
        self.length = length;
    }

    /// A step of length `attempted` failed: halve it, or say why the run must stop.
    ///
    /// Besides `max_cuts` cuts in a row, the length may not fall below the nominal step over
    /// 2^max_cuts and a tenth (the shortest event split of such a step): cuts and successes
    /// that alternate would otherwise shrink it without end (to 1e-17 and then 0, which
    /// Wilson-theta met on a crushed contact tip).
    pub(super) fn reject(&mut self, attempted: f64, counters: &mut Counters) -> Result<(), String> {
        if self.cuts_in_a_row >= self.max_cuts {
            return Err(format!(
                "did not converge after {} cuts (dt = {})",
                self.cuts_in_a_row,
                readable(attempted)
            ));
        }
        let floor = self.shortest();
        if 0.5 * attempted < floor {
            return Err(format!(
                "did not converge: repeated cuts brought the step to {}, and halving it would go below dt / 2^{} / 10 = {}",
                readable(attempted),
                self.max_cuts,
                readable(floor)
            ));
        }
        self.length = 0.5 * attempted;
        self.successes = 0;
        self.cuts_in_a_row += 1;
        counters.cuts += 1;
        Ok(())
    }

    /// The shortest step the control takes: the nominal over 2^max_cuts and a tenth.
    pub(super) fn shortest(&self) -> f64 {
        self.nominal * 0.5f64.powi(self.max_cuts as i32) * 0.1
    }

    pub(super) fn after_cut(&self) -> bool {
        self.cuts_in_a_row > 0
    }
}

/// A step of nominal length up to round-off is given exactly the nominal length, so methods
/// that keep history (Houbolt) or a factorization of K*(dt) see one dt.
pub(super) fn step_length(h: f64, dt: f64) -> f64 {
    if (h - dt).abs() <= 1e-9 * dt { dt } else { h }
}

/// A point value of the scene's probes (eq_plastic_strain, temperature) that an adaptive
/// step watches (theory 8.2a): with q its value above `base` at the start and the end of a
/// step, its share of the estimate is
/// ```text
/// eta_q = (|q_{n+1} - q_n| / Q)^2,   Q = max(|q_n|, |q_{n+1}|, floor)
/// ```
/// so the step that meets the tolerance changes q by at most sqrt(tol) of its size (the
/// return map's error over a step grows with the square of the step's increment).
/// eq_plastic_strain: base 0, floor the yield strain sigma_y / E; temperature: base the
/// initial temperature, floor the heating of a yield strain's plastic work,
/// chi sigma_y (sigma_y / E) / (rho c_p).
#[derive(Debug, Clone, Copy)]
pub(super) struct WatchedPoint {
    probe: usize,
    base: f64,
    floor: f64,
}

impl WatchedPoint {
    /// The point probes of `model` an adaptive step watches.
    pub(super) fn of(model: &Model) -> Vec<WatchedPoint> {
        model
            .probes
            .iter()
            .enumerate()
            .filter_map(|(k, probe)| {
                let material = &model.bodies[probe.body].material;
                let yield_stress = material.plasticity.as_ref()?.yield_stress;
                let yield_strain = yield_stress / material.elastic.young;
                match probe.quantity {
                    Quantity::EqPlasticStrain => Some(WatchedPoint {
                        probe: k,
                        base: 0.0,
                        floor: yield_strain,
                    }),
                    Quantity::Temperature => material.johnson_cook().map(|law| WatchedPoint {
                        probe: k,
                        base: law.initial_temperature,
                        floor: law.taylor_quinney * yield_stress * yield_strain
                            / (material.density * law.specific_heat),
                    }),
                    _ => None,
                }
            })
            .collect()
    }

    /// eta_q of a step from the committed `state` to the trial points `trial` (per body).
    pub(super) fn estimate(&self, model: &Model, state: &State, trial: &[Vec<PointState>]) -> f64 {
        let probe = &model.probes[self.probe];
        let ppe = model.bodies[probe.body].points_per_element();
        let value = |points: &[PointState]| {
            let f: &(dyn Fn(&PointState) -> f64 + Sync) = match probe.quantity {
                Quantity::Temperature => &|p| p.temperature,
                _ => &|p| p.eq_plastic_strain,
            };
            probe.of_points(points, ppe, f) - self.base
        };
        let q0 = value(&state.bodies[probe.body].points);
        let q1 = value(&trial[probe.body]);
        let size = q0.abs().max(q1.abs()).max(self.floor);
        ((q1 - q0) / size).powi(2)
    }
}

/// The error control of an adaptive implicit run (`dt = "auto"`, docs/theory.md 8.2a).
#[derive(Debug, Clone, Copy)]
pub(super) struct ErrorControl {
    /// The error tolerance and the shortest and longest step (None: a fixed step).
    pub(super) adaptive: Option<AdaptiveStep>,
    /// The method's local error constant (None: no estimate, Wilson and Houbolt).
    pub(super) constant: Option<f64>,
}

impl ErrorControl {
    /// dt_min of an adaptive run (0 without one).
    pub(super) fn floor(&self) -> f64 {
        self.adaptive.and_then(|a| a.min).unwrap_or(0.0)
    }

    pub(super) fn tolerance(&self) -> f64 {
        self.adaptive.map_or(f64::INFINITY, |a| a.tolerance)
    }

    /// The local error estimate eta = c h |jump| / V of a step of length `h`: `jump` the
    /// change of the acceleration over it (`weighted_jump`, scaled to the step), `speed` V
    /// the run's top speed; 0 for a method without an estimate or a body at rest.
    pub(super) fn estimate(&self, h: f64, jump: f64, speed: f64) -> f64 {
        match self.constant {
            Some(c) if speed > 0.0 => c * h * jump / speed,
            _ => 0.0,
        }
    }

    /// Whether an adaptive run takes the step of length `h` (nominal `nominal`, its estimate
    /// `estimate`) again, shorter: its estimate is above the tolerance, it was not ended
    /// early by a contact event (an event is a discontinuity the estimate does not describe),
    /// and it is longer than dt_min and than `shortest`, the shortest step the control takes
    /// (the step's nominal over 2^max_cuts and a tenth). At an impact the acceleration jumps
    /// by the velocity change over the step, so the estimate does not shrink with the step:
    /// the floor ends the rejections there.
    pub(super) fn refuses(&self, (h, nominal, estimate): (f64, f64, f64), shortest: f64) -> bool {
        let Some(adaptive) = self.adaptive else {
            return false;
        };
        let floor = adaptive.min.unwrap_or(0.0).max(shortest);
        estimate > adaptive.tolerance && h >= nominal * (1.0 - 1e-9) && h > floor * (1.0 + 1e-9)
    }

    /// The step an adaptive run proposes after an accepted step of length `h` with its
    /// `estimate`, on the ladder through `first`, within dt_min and dt_max (None: a fixed
    /// step, or a step `clipped` by an event that met the tolerance: the control's length
    /// stands).
    pub(super) fn next_step(
        &self,
        first: f64,
        h: f64,
        estimate: f64,
        clipped: bool,
    ) -> Option<f64> {
        let a = self.adaptive?;
        if clipped && estimate <= a.tolerance {
            return None;
        }
        let next = on_ladder(first, h * step_factor(a.tolerance, estimate));
        let next = next.min(a.max.unwrap_or(f64::INFINITY));
        Some(next.max(a.min.unwrap_or(0.0)))
    }
}

/// The mass-weighted root mean square of `end - start` over the DOFs read, `(read, mass)`:
/// the change of the acceleration the estimate reads, so that the few light nodes of a mesh
/// graded to a contact point, ringing at the mesh's highest frequencies, do not set the step
/// of the whole body (0 where nothing is read).
pub(super) fn weighted_jump(end: &[f64], start: &[f64], (read, mass): (&[bool], &[f64])) -> f64 {
    let (mut sum, mut total) = (0.0, 0.0);
    let dofs = end.iter().zip(start).zip(read).zip(mass);
    for (((a1, a0), _), m) in dofs.filter(|((_, r), _)| **r) {
        sum += m * (a1 - a0).powi(2);
        total += m;
    }
    if total > 0.0 {
        (sum / total).sqrt()
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: where the nominal length fails at every increment (a structure past its hinge
    /// load), the static control keeps the cut length instead of returning to the failing
    /// one after each success. Setup: any length above 0.6 of the nominal fails; 200
    /// successful increments. Reference: doubling back after each success fails once per
    /// success (200); growing by half after two successes tries the nominal once per five
    /// successes (0.5 -> 0.75 -> nominal), so at most a third of that.
    #[test]
    fn a_cut_length_is_kept_while_it_serves() {
        let count = |patient: bool| {
            let mut control = StepControl::new(1.0, 6);
            let mut counters = Counters::default();
            let mut successes = 0;
            while successes < 200 {
                if control.length > 0.6 {
                    control.reject(control.length, &mut counters).unwrap();
                } else if patient {
                    control.accept_patiently(true);
                    successes += 1;
                } else {
                    control.accept(true);
                    successes += 1;
                }
            }
            counters.cuts
        };
        assert_eq!(count(false), 200);
        let kept = count(true);
        assert!(kept > 0 && kept <= 200 / 3, "{kept} cuts");
    }

    /// Goal: cuts that alternate with successes cannot shrink the step without end (the
    /// cuts-in-a-row limit never trips then). Reference: the floor dt / 2^max_cuts / 10.
    #[test]
    fn alternating_cuts_stop_at_the_floor() {
        let mut control = StepControl::new(1e-3, 6);
        let mut counters = Counters::default();
        let floor = 1e-3 / 64.0 / 10.0;
        let mut error = None;
        // two cuts, one success (which doubles back once): the length halves per round
        for _ in 0..100 {
            let mut round = || -> Result<(), String> {
                control.reject(control.length, &mut counters)?;
                control.reject(control.length, &mut counters)?;
                control.accept(true);
                Ok(())
            };
            if let Err(e) = round() {
                error = Some(e);
                break;
            }
            assert!(control.length >= floor, "length {}", control.length);
        }
        let error = error.expect("the floor stops the run");
        assert!(error.contains("below dt / 2^6 / 10"), "{error}");
    }
}

/// The growth of an adaptive step: at most doubled, at least a fifth; the estimate grows as
/// dt^2 (eta ~ c dt |da/dt| / V and the jump of a over the step ~ dt), so the step that meets
/// the tolerance is dt (tol / eta)^(1/2), taken with a safety factor 0.9.
pub(super) fn step_factor(tolerance: f64, estimate: f64) -> f64 {
    if estimate <= 0.0 {
        return 2.0;
    }
    (0.9 * (tolerance / estimate).sqrt()).clamp(0.2, 2.0)
}

/// The ratio of the ladder an adaptive step moves on: a proposed step is rounded down to
/// first x LADDER^k, so steady stretches repeat one length and K*(dt) stays factored
/// (a factorization per new length would cost more than the steps it saves).
const LADDER: f64 = std::f64::consts::SQRT_2;

/// `proposal` rounded down to the ladder through `first`.
pub(super) fn on_ladder(first: f64, proposal: f64) -> f64 {
    let k = ((proposal / first).ln() / LADDER.ln() + 1e-9).floor();
    first * LADDER.powf(k)
}
