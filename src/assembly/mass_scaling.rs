//! The mass scaling of an explicit kernel's elements (the rule: `element::mass_scaling`) and
//! how the mass it adds reaches the nodes (docs/theory.md 8.7b).
//!
//! Legend
//! ```text
//! m_a        an element's unscaled lumped mass at its node a; m_e = sum_a m_a
//! s_e        its factor; when it grows to s_e', node a gains dm = (s_e' - s_e) m_a: the
//!            added mass is spread as the lumped mass is
//! added      sum_e (s_e - 1) m_e over the run
//! m, v, a    a DOF's nodal mass, velocity and acceleration at the end of a step
//! at rest    the mass dm joins the node at rest, momentum kept (a perfectly inelastic
//!            collision): m v = (m + dm) v', and a' = m a / (m + dm) (the force is the same)
//! loss       1/2 m dm / (m + dm) v^2: the kinetic energy that collision takes (free DOFs)
//! prescribed a prescribed DOF keeps its velocity: its support brings dm up to speed with the
//!            impulse dm v and the work dm v^2 (W_ext), half of it the added mass' kinetic
//!            energy 1/2 dm v^2, half the loss
//! ```
//! Balance of the event: dKE + loss = W_ext (free: -loss + loss = 0).

use crate::element::mass_scaling::MassScaling;
use serde::{Deserialize, Serialize};

/// The mass scaling of a kernel's Quad4 elements: each element's factor, its unscaled
/// nodal masses, the mass added so far, and the nodal increments not yet taken by the run.
#[derive(Debug, Clone)]
pub struct ElementScaling {
    rule: MassScaling,
    /// s_e per kernel element (1: unscaled).
    factor: Vec<f64>,
    /// The unscaled lumped masses at the element's four nodes, and the nodes.
    nodal: Vec<[f64; 4]>,
    nodes: Vec<[u32; 4]>,
    /// sum_e (s_e - 1) m_e, accumulated as the factors grow.
    added: f64,
    /// (node, mass) the elements added since the run last took them.
    pending: Vec<(u32, f64)>,
}

/// A DOF's share of the run's nodal arrays that adding mass changes.
pub struct NodalMotion<'a> {
    /// Lumped mass per DOF and its inverse (0 on prescribed DOFs).
    pub mass: &'a mut [f64],
    pub inverse_mass: &'a mut [f64],
    pub free: &'a [bool],
    pub velocity: &'a mut [f64],
    pub acceleration: &'a mut [f64],
}

/// What adding mass at rest did to the energies (see the legend).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AddedAtRest {
    /// The change of 1/2 v.M v.
    pub kinetic_energy_change: f64,
    /// The kinetic energy taken by the inelastic joining (>= 0).
    pub loss: f64,
    /// The work of the supports that brought added mass on prescribed DOFs up to speed.
    pub support_work: f64,
}

/// What a checkpoint keeps of the mass scaling: the factors, the mass added and the nodal
/// masses as the run summed them (so a resumed run has the same bits).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScalingCarry {
    pub factor: Vec<f64>,
    pub added: f64,
    pub nodal_mass: Vec<f64>,
}

/// The mass scaling at the end of a run, per model body.
#[derive(Debug, Clone, PartialEq)]
pub struct MassScalingReport {
    pub target: f64,
    /// sum over the bodies of their added mass (as the run accumulated it).
    pub added_mass: f64,
    /// Per model body, in the model's order.
    pub bodies: Vec<BodyScaling>,
    /// (model body, element) of each scaled element.
    pub scaled: Vec<(usize, usize)>,
}

/// One body's mass and what the scaling added to it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BodyScaling {
    /// The unscaled mass (the sum of its lumped masses).
    pub mass: f64,
    pub added_mass: f64,
    pub elements_scaled: usize,
}

impl ElementScaling {
    /// Every element unscaled: `nodal` and `nodes` are the unscaled lumped masses and the
    /// global nodes of the kernel's elements.
    pub fn new(rule: MassScaling, nodal: Vec<[f64; 4]>, nodes: Vec<[u32; 4]>) -> ElementScaling {
        ElementScaling {
            rule,
            factor: vec![1.0; nodal.len()],
            nodal,
            nodes,
            added: 0.0,
            pending: Vec::new(),
        }
    }

    pub fn rule(&self) -> &MassScaling {
        &self.rule
    }

    /// The factor of kernel element `e`.
    #[inline(always)]
    pub fn factor(&self, e: usize) -> f64 {
        self.factor[e]
    }

    /// The mass added so far, all elements.
    pub fn added(&self) -> f64 {
        self.added
    }

    /// Scales the elements below the target at the start of a run: `frequency` gives
    /// element e's unscaled frequency bound squared (None: not computable, left unscaled;
    /// the run's first stable step reports the element).
    pub fn scale_at_start(&mut self, frequency: impl Fn(usize) -> Option<f64>) {
        let rule = self.rule;
        for e in 0..self.factor.len() {
            if let Some(omega_squared) = frequency(e)
                && let Some(r) = rule.rescale(self.factor[e], omega_squared)
            {
                self.grow(e, r.factor);
            }
        }
    }

    /// Element `e`'s factor grows to `factor` (> its factor): the mass it adds waits for
    /// the run at its nodes.
    pub fn grow(&mut self, e: usize, factor: f64) {
        let increase = factor - self.factor[e];
        for (node, m) in self.nodes[e].iter().zip(&self.nodal[e]) {
            self.pending.push((*node, increase * m));
        }
        self.added += increase * self.nodal[e].iter().sum::<f64>();
        self.factor[e] = factor;
    }

    /// Adds the pending nodal masses to `mass` (per DOF) before the motion starts: the
    /// scene's initial velocities then move the scaled masses.
    pub fn add_pending(&mut self, mass: &mut [f64]) {
        for (node, dm) in self.pending.drain(..) {
            let dof = 2 * node as usize;
            mass[dof] += dm;
            mass[dof + 1] += dm;
        }
    }

    /// Adds the pending nodal masses at rest to a moving model (see the legend), in the
    /// order the elements grew (a node that several elements feed takes them one after the
    /// other: the momentum is kept by each, so by all).
    pub fn add_pending_at_rest(&mut self, motion: NodalMotion) -> AddedAtRest {
        let mut out = AddedAtRest::default();
        for (node, dm) in self.pending.drain(..) {
            let dof = 2 * node as usize;
            for i in [dof, dof + 1] {
                let (m, v) = (motion.mass[i], motion.velocity[i]);
                let joined = m + dm;
                if motion.free[i] {
                    let ratio = m / joined;
                    let loss = 0.5 * dm * ratio * v * v;
                    motion.velocity[i] = ratio * v;
                    motion.acceleration[i] *= ratio;
                    motion.inverse_mass[i] = 1.0 / joined;
                    out.loss += loss;
                    out.kinetic_energy_change -= loss;
                } else {
                    let kinetic = 0.5 * dm * v * v;
                    out.kinetic_energy_change += kinetic;
                    out.loss += kinetic;
                    out.support_work += 2.0 * kinetic;
                }
                motion.mass[i] = joined;
            }
        }
        out
    }

    /// What a checkpoint stores, with the run's nodal masses `nodal_mass`.
    pub fn carry(&self, nodal_mass: &[f64]) -> ScalingCarry {
        ScalingCarry {
            factor: self.factor.clone(),
            added: self.added,
            nodal_mass: nodal_mass.to_vec(),
        }
    }

    /// Takes back the factors and the added mass of a checkpoint, and its nodal masses into
    /// `mass` with their inverses on the `free` DOFs (nothing pending: the checkpoint's
    /// nodal masses have it all).
    pub fn restore(
        &mut self,
        carry: &ScalingCarry,
        mass: &mut [f64],
        inverse_mass: &mut [f64],
        free: &[bool],
    ) {
        self.factor.copy_from_slice(&carry.factor);
        self.added = carry.added;
        self.pending.clear();
        mass.copy_from_slice(&carry.nodal_mass);
        for ((inverse, m), free) in inverse_mass.iter_mut().zip(mass.iter()).zip(free) {
            if *free {
                *inverse = 1.0 / m;
            }
        }
    }

    /// The report per model body (`bodies` of them); `locate` gives the model body and
    /// element of a kernel element.
    pub fn report(
        &self,
        bodies: usize,
        locate: impl Fn(usize) -> (usize, usize),
    ) -> MassScalingReport {
        let mut per_body = vec![BodyScaling::default(); bodies];
        let mut scaled = Vec::new();
        for (e, (factor, nodal)) in self.factor.iter().zip(&self.nodal).enumerate() {
            let (b, element) = locate(e);
            let mass: f64 = nodal.iter().sum();
            let body = &mut per_body[b];
            body.mass += mass;
            if *factor > 1.0 {
                body.added_mass += (factor - 1.0) * mass;
                body.elements_scaled += 1;
                scaled.push((b, element));
            }
        }
        MassScalingReport {
            target: self.rule.target,
            added_mass: self.added,
            bodies: per_body,
            scaled,
        }
    }
}

impl MassScalingReport {
    /// The unscaled mass of the model (its bodies').
    pub fn model_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.mass).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: adding mass at rest keeps each DOF's momentum, takes the kinetic energy of a
    /// perfectly inelastic collision on a free DOF, and on a prescribed DOF keeps the
    /// velocity with the support's work dm v^2. Setup: one element of nodal masses 1, 2, 3,
    /// 4 at nodes 0..3, grown from 1 to 3 (each node gains 2 m_a); node 1 prescribed.
    /// Reference (by hand): node 0 (nodal mass 5 with its other elements' share, v = (2, -1))
    /// gains 2: joined 7, v' = 5/7 v, loss 1/2 * 2 * 5/7 * |v|^2 = 25/7; node 1 (mass 2,
    /// v = (0, 3) prescribed) gains 4: support work 4 * 9 = 36 on y, kinetic +18, loss 18.
    #[test]
    fn mass_added_at_rest_keeps_momentum() {
        let rule = MassScaling { target: 1.0 };
        let mut scaling = ElementScaling::new(rule, vec![[1.0, 2.0, 3.0, 4.0]], vec![[0, 1, 2, 3]]);
        scaling.grow(0, 3.0);
        assert_eq!(scaling.added(), 20.0);
        let mut mass = vec![5.0, 5.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0];
        let mut inverse: Vec<f64> = mass.iter().map(|m| 1.0 / m).collect();
        inverse[2] = 0.0;
        inverse[3] = 0.0;
        let free = [true, true, false, false, true, true, true, true];
        let mut velocity = vec![2.0, -1.0, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0];
        let mut acceleration = vec![7.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let momentum: Vec<f64> = mass.iter().zip(&velocity).map(|(m, v)| m * v).collect();
        let kinetic =
            |m: &[f64], v: &[f64]| 0.5 * m.iter().zip(v).map(|(m, v)| m * v * v).sum::<f64>();
        let before = kinetic(&mass, &velocity);
        let out = scaling.add_pending_at_rest(NodalMotion {
            mass: &mut mass,
            inverse_mass: &mut inverse,
            free: &free,
            velocity: &mut velocity,
            acceleration: &mut acceleration,
        });
        // round-off of a few products of small integers and sevenths
        let close = |a: f64, b: f64| (a - b).abs() < 1e-13 * b.abs().max(1.0);
        assert_eq!(mass, vec![7.0, 7.0, 6.0, 6.0, 9.0, 9.0, 12.0, 12.0]);
        for i in [0, 1, 4, 5, 6, 7] {
            assert!(close(mass[i] * velocity[i], momentum[i]), "dof {i}");
            assert!(close(inverse[i], 1.0 / mass[i]));
        }
        assert_eq!((inverse[2], inverse[3]), (0.0, 0.0));
        assert_eq!(velocity[3], 3.0);
        assert!(close(acceleration[0], 5.0));
        assert!(close(out.loss, 25.0 / 7.0 + 18.0), "loss {}", out.loss);
        assert!(close(out.support_work, 36.0));
        assert!(close(
            kinetic(&mass, &velocity) - before,
            out.kinetic_energy_change
        ));
        assert!(close(
            out.kinetic_energy_change + out.loss,
            out.support_work
        ));
        // nothing left pending
        let again = scaling.add_pending_at_rest(NodalMotion {
            mass: &mut mass,
            inverse_mass: &mut inverse,
            free: &free,
            velocity: &mut velocity,
            acceleration: &mut acceleration,
        });
        assert_eq!(again, AddedAtRest::default());
    }
}
