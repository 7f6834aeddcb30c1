//! The contact's energies pair by pair: each pair's share of the contact work a dynamic step
//! books and of the energy its friction dissipates (history.csv `contact_work[PAIR]` and
//! `friction_work[PAIR]`, summary.json `contact.pairs`), as LS-DYNA's RCFORC or Abaqus'
//! energy output per interaction give them (docs/theory.md 7, "Per pair").
//!
//! Legend (one step)
//! ```text
//! f_p        pair p's nodal forces: its rows' (and master block's) terms (DOF, value)
//! W          the step's contact work as the driver books it, a sum of terms per DOF w_d
//! W_p        pair p's share: explicit, f_p . (du + delta / 2) exactly, and of the held term
//!            delta_d (M a_n)_d its share |f_p,d| / sum_q |f_q,d| of the forces at d; implicit,
//!            of each w_d its share (|f_p,d| at the start + at the end) / (the same over
//!            all pairs)
//! owner(d)   the first pair (scene order) whose surfaces hold d's node: takes a term at a
//!            DOF where no pair has a force (a correction whose rows moved in its passes, an
//!            impact condition met before the step)
//! ```
//! The pairs' shares add up to the step's W but for round-off, so the columns add up to
//! `contact_work` and `friction_work`.

use super::Interfaces;
use super::explicit::ExplicitContact;
use super::geometry::ContactPair;
use super::status::ContactState;
use std::collections::HashMap;

/// Per pair of the interfaces: its (DOF, value) force terms.
pub type PairForces = Vec<Vec<(usize, f64)>>;

/// An implicit step's contact, DOF by DOF, as the driver booked it (`book_implicit_step`).
pub struct ImplicitStepWork<'a> {
    /// The step's displacement increment.
    pub increment: &'a [f64],
    /// The slip the friction forces work on: the increment, less a moving obstacle's
    /// travel at its slaves.
    pub slip: &'a [f64],
    /// The contact forces the integrator applied at the step's end, and at its start.
    pub applied: (&'a [f64], &'a [f64]),
    /// Per DOF, the kinetic energy the step's impact and release conditions removed (None:
    /// no condition was met).
    pub conditions: Option<Vec<f64>>,
    /// The pairs' force terms, and their friction force terms alone, at the step's start.
    pub start: (PairForces, PairForces),
}

impl ContactState {
    /// Books an explicit step's contact work pair by pair (`work`, `friction_work`): of the
    /// driver's W = sum_d f_d (du_d + delta_d / 2) - held(d) / 2, held(d) = delta_d (M a_n)_d
    /// (`touched`: the DOFs where f or delta is not zero; `du` the predicted increment),
    /// pair p takes f_p . (du + delta / 2) and |f_p,d| / sum_q |f_q,d| of held(d) (module
    /// legend), less the work its moving obstacle does (supplied, not taken).
    pub fn book_explicit_work(
        &mut self,
        step: &ExplicitContact,
        (interfaces, touched): (&Interfaces, &[usize]),
        du: &[f64],
        held: &dyn Fn(usize) -> f64,
    ) {
        let delta = &step.correction;
        self.ensure_pair_energies(interfaces.pairs.len());
        // the held term's weights, |f_p,d| summed over the pairs' terms (the signed share
        // f_p,d / f_d is unbounded where two pairs' forces at a node nearly cancel, as a
        // balanced pair's passes do along the face)
        let mut weight: HashMap<usize, f64> = HashMap::new();
        for (d, value) in step.pair_forces.iter().flatten() {
            *weight.entry(*d).or_default() += value.abs();
        }
        for (p, terms) in step.pair_forces.iter().enumerate() {
            let work: f64 = (terms.iter())
                .map(|&(d, value)| {
                    let share = match weight[&d] {
                        0.0 => 0.0,
                        total => value.abs() / total,
                    };
                    value * (du[d] + 0.5 * delta[d]) - 0.5 * share * held(d)
                })
                .sum();
            self.work[p] -= work - step.friction_work[p] - step.obstacle_work[p];
            self.friction_work[p] -= step.friction_work[p];
        }
        let unweighted = |d: usize| weight.get(&d).is_none_or(|w| *w == 0.0);
        let unshared = touched
            .iter()
            .filter(|d| unweighted(**d) && delta[**d] != 0.0);
        for &d in unshared {
            if let Some(p) = owner(&interfaces.pairs, d) {
                self.work[p] += 0.5 * held(d);
            }
        }
    }

    /// Books an implicit step's contact energy pair by pair: `taken[d]` is the energy the
    /// interface took at DOF d in the step as the driver booked it (minus the contact forces'
    /// trapezoidal work, plus the kinetic energy the impact and release conditions removed,
    /// friction's share included), `forces` the pairs' force terms at the step's start and
    /// end (their weights, module legend), and `friction` each pair's dissipation in the step
    /// (exact, from its own tangential forces), which its contact work leaves out.
    fn book_implicit_work(
        &mut self,
        pairs: &[ContactPair],
        (start, end): (&PairForces, &PairForces),
        taken: &[f64],
        friction: &[f64],
    ) {
        self.ensure_pair_energies(pairs.len());
        let mut weight = vec![0.0; taken.len()];
        for (d, value) in start.iter().chain(end).flatten() {
            weight[*d] += value.abs();
        }
        for (p, terms) in start.iter().zip(end).enumerate() {
            let share: f64 = (terms.0.iter().chain(terms.1))
                .filter(|(d, _)| weight[*d] > 0.0)
                .map(|(d, value)| value.abs() / weight[*d] * taken[*d])
                .sum();
            self.work[p] += share - friction[p];
            self.friction_work[p] += friction[p];
        }
        self.book_by_owner(pairs, taken, &weight);
    }

    /// Books an implicit step pair by pair (`book_implicit_work`), the status at the step's
    /// end and the nodes at `coords` (module legend).
    pub fn book_implicit_step(
        &mut self,
        pairs: &[ContactPair],
        coords: &[[f64; 2]],
        step: ImplicitStepWork,
    ) {
        if pairs.is_empty() {
            return;
        }
        let (end, end_friction) = (
            self.pair_force_vectors(pairs, coords),
            self.pair_friction_forces(pairs, coords),
        );
        let (increment, (applied, last)) = (step.increment, step.applied);
        let mut taken: Vec<f64> = (increment.iter().zip(applied.iter().zip(last)))
            .map(|(u, (a, b))| -0.5 * u * (a + b))
            .collect();
        if let Some(removed) = &step.conditions {
            taken.iter_mut().zip(removed).for_each(|(t, r)| *t += r);
        }
        let friction: Vec<f64> = (step.start.1.iter().zip(&end_friction))
            .map(|(start, end)| {
                let work: f64 = start
                    .iter()
                    .chain(end)
                    .map(|(d, f)| step.slip[*d] * f)
                    .sum();
                -0.5 * work
            })
            .collect();
        self.book_implicit_work(pairs, (&step.start.0, &end), &taken, &friction);
    }

    /// Books the energy `taken[d]` at the DOFs with no weight (all of them where `weight` is
    /// empty) to the pair that owns each (module legend): the impact conditions a step
    /// meets before it starts.
    pub fn book_by_owner(&mut self, pairs: &[ContactPair], taken: &[f64], weight: &[f64]) {
        self.ensure_pair_energies(pairs.len());
        let unweighted = |d: usize| weight.get(d).is_none_or(|w| *w == 0.0);
        for (d, value) in taken.iter().enumerate() {
            if *value != 0.0 && unweighted(d) {
                if let Some(p) = owner(pairs, d) {
                    self.work[p] += value;
                }
            }
        }
    }

    /// The pairs' force terms (normal and tangential, `pair_force_terms`) of the status at
    /// positions `coords`.
    pub fn pair_force_vectors(&self, pairs: &[ContactPair], coords: &[[f64; 2]]) -> PairForces {
        self.pair_force_terms(pairs, coords, (&self.force, &self.tangential))
    }

    /// The pairs' friction force terms alone at positions `coords`.
    pub fn pair_friction_forces(&self, pairs: &[ContactPair], coords: &[[f64; 2]]) -> PairForces {
        let none: Vec<Vec<f64>> = self.force.iter().map(|f| vec![0.0; f.len()]).collect();
        self.pair_force_terms(pairs, coords, (&none, &self.tangential))
    }

    /// The per-pair energies sized for `pairs` (a checkpoint written before they were kept
    /// has none).
    fn ensure_pair_energies(&mut self, pairs: usize) {
        self.work.resize(pairs, 0.0);
        self.friction_work.resize(pairs, 0.0);
    }
}

/// The first pair whose surfaces hold DOF `d`'s node.
fn owner(pairs: &[ContactPair], d: usize) -> Option<usize> {
    pairs
        .iter()
        .position(|pair| pair.surface_nodes().any(|n| n == d / 2))
}
