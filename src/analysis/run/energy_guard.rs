//! The energy guards of a dynamic run (docs/theory.md 7): the energy the contact gave the
//! bodies, the balance's gain, plastic work beyond the energy supplied or below zero; each
//! ends the run with exit 3 at the step it is found.

use super::Run;
use crate::analysis::steppers::Stepper;
use crate::analysis::steppers::energies::{Energies, relative_gain};
use crate::output::readable;
use crate::scene::model::{Analysis, DynamicAnalysis};

/// The total plastic work below zero beyond round-off (of the energies in play), as a
/// failure's message: no material dissipates negative work; a return that books it (a
/// kinematically hardening point reversed beyond what it stored) is a numerical failure,
/// not a row of history.
pub(super) fn negative_plastic_work(e: &Energies, initial_kinetic: f64) -> Option<String> {
    let scale = initial_kinetic
        .max(e.external_work.abs())
        .max(e.internal.abs())
        .max(f64::MIN_POSITIVE);
    (e.plastic_work < -1e-12 * scale).then(|| {
        format!(
            "the plastic work fell to {} (below zero): the returns of the step gave back more than \
             the run had dissipated (a step far too long for the plastic flow, or inconsistent units)",
            readable(e.plastic_work)
        )
    })
}

/// The share of the energy in play that the contact of an explicit run may give the bodies,
/// at any step, before the run stops. Contact takes energy (an arrest, an impact, friction)
/// and gives back at most the discretization's error of sliding (docs/validation.md 4.12:
/// up to 1.2 % of 225 J at a run's end, on a rod sliding over a plate four times as fine,
/// one pass of mortar; no run of the suite reaches this bound at any step); beyond it the
/// contact is creating energy, and the answer is not the physics'.
const CREATED_SHARE: f64 = 0.01;

/// What makes an explicit run's contact give energy (the guard's message).
const EXPLICIT_CAUSES: &str = "a step too long for the contact (a shorter dt), master nodes held \
     on meshes of unlike size (hold_master_nodes = false), or surfaces that do not face each \
     other";

/// What makes an implicit run's contact give energy (the guard's message; docs/validation.md
/// 4.15): one pass between bodies whose master is the finer mesh or has corners that enter
/// the slave body, a mortar pair's closures at short steps under friction, surfaces that do
/// not face each other.
const IMPLICIT_CAUSES: &str = "one pass where the master's corners or finer nodes enter the \
     slave body (roles = \"automatic\" and whole boundaries, or central difference, which \
     balances a pair between bodies), a mortar pair's closures at a short step under friction \
     (discretization = \"node_to_segment\" with HHT's alpha), or surfaces that do not face each \
     other";

impl<S: Stepper> Run<'_, S> {
    /// (1) of `energy_created`: the energy the guarded pairs gave the bodies (their normal
    /// rows' and friction's work together, theory 7) beyond a share of the energy in play
    /// `scale`: the whole interface on central difference (CREATED_SHARE); on the implicit
    /// paths the pairs `Model::guards_pair` names, under `analysis.energy_gain_limit` (1 %
    /// by default, so that a scene that accepts a gain accepts this one too). `givers` names
    /// the pairs that gave energy.
    fn contact_gave(
        &self,
        analysis: &DynamicAnalysis,
        scale: f64,
        givers: &dyn Fn() -> String,
    ) -> Option<String> {
        if !self.model.guards_contact_work() {
            return None;
        }
        let explicit = self.model.is_explicit();
        let given = if explicit {
            let e = self.stepper.energies();
            -(e.contact_work + e.friction_work)
        } else {
            let energies = self.stepper.contact().pair_energies(&self.model.contacts);
            let reported = self.model.contacts.iter().filter(|p| p.balances.is_none());
            (reported.zip(&energies))
                .filter(|(pair, _)| self.model.guards_pair(pair))
                .map(|(_, e)| -(e.contact_work + e.friction_work))
                .sum()
        };
        let (share, key, causes) = match (explicit, analysis.energy_gain_limit) {
            (true, _) => (CREATED_SHARE, "", EXPLICIT_CAUSES),
            (false, limit) => (
                limit.unwrap_or(CREATED_SHARE),
                ", analysis.energy_gain_limit",
                IMPLICIT_CAUSES,
            ),
        };
        (given > share * scale).then(|| {
            format!(
                "the contact gave the bodies {} of energy, {:.1} % of the {} in play (more than \
                 {} %{key}): contact {} created energy, so the answer is not the physics'; \
                 likely causes: {causes}",
                readable(given),
                100.0 * given / scale,
                readable(scale),
                100.0 * share,
                givers(),
            )
        })
    }

    /// Why a dynamic run fails at this step: energy created.
    /// (1) The guarded pairs' work, friction's included (energy taken up by the interfaces,
    /// theory 7), is below a share of the energy in play (`contact_gave`): the pairs named.
    /// Elsewhere the implicit contact work is the trapezoidal work of the multipliers, which
    /// gives energy back for a while and takes it again (two bars without impact conditions:
    /// -5 % at t = 0.01), and Wilson's interpolated step is not what it books (a plastic
    /// block on a floor: -67 %).
    /// (2) On every dynamic path, the balance has gained more than
    /// `analysis.energy_gain_limit` of the energy in play: the bodies hold more than they
    /// were given and the sinks took, whoever made it.
    /// (3) On every dynamic path, the plastic work exceeds the energy supplied by more than
    /// that share (an implicit pair whose work went negative closes the balance while it
    /// makes the energy).
    /// None otherwise, and in statics (whose balance measures the trapezoidal rule's error
    /// along a load path, not energy made).
    pub(super) fn energy_created(&self) -> Option<String> {
        let Analysis::Dynamic(analysis) = &self.model.analysis else {
            return None;
        };
        let e = self.stepper.energies();
        let initial = self.stepper.initial_kinetic();
        let scale = initial
            .max(e.external_work.abs())
            .max(e.internal.abs())
            .max(f64::MIN_POSITIVE);
        // the interface as a whole: the normal rows' and the friction's work together (their
        // split follows the rows at the step's start, and a block held on a floor by friction
        // moves energy between the two columns while the sum takes it)
        let given = -(e.contact_work + e.friction_work);
        let pairs = || {
            let names: Vec<String> = (self.model.contacts.iter())
                .filter(|p| p.balances.is_none())
                .map(|p| format!("`{}`", p.name))
                .collect();
            names.join(", ")
        };
        // the pairs that gave energy (all of them when none did), with what each gave where
        // there are several
        let givers = || {
            let energies = self.stepper.contact().pair_energies(&self.model.contacts);
            let gave: Vec<(String, f64)> = (energies.iter())
                .map(|p| (p.name.clone(), -(p.contact_work + p.friction_work)))
                .filter(|(_, given)| *given > 0.0)
                .collect();
            match gave.len() {
                0 => pairs(),
                1 => format!("`{}`", gave[0].0),
                _ => (gave.iter())
                    .map(|(name, given)| format!("`{name}` ({})", readable(*given)))
                    .collect::<Vec<String>>()
                    .join(", "),
            }
        };
        if let Some(message) = self.contact_gave(analysis, scale, &givers) {
            return Some(message);
        }
        let gain = relative_gain(e, initial);
        let limit = analysis.energy_gain_limit?;
        // (3) plastic work is dissipated for good: beyond the energy supplied it was made,
        // even where the balance closes because the contact's work went negative by as much
        let supplied = initial + e.external_work.max(0.0);
        if gain <= limit && e.plastic_work > supplied + limit * scale {
            return Some(format!(
                "the plastic work {} exceeds the energy supplied {} (initial energy and \
                 external work) by {:.1} % of the energy in play (more than {} %, \
                 analysis.energy_gain_limit): energy was created; the contact {} gave {}, so \
                 the answer is not the physics'",
                readable(e.plastic_work),
                readable(supplied),
                100.0 * (e.plastic_work - supplied) / scale,
                100.0 * limit,
                givers(),
                readable(given),
            ));
        }
        (gain > limit).then(|| {
            let cause = match (given > 0.0, self.model.contacts.is_empty()) {
                (true, _) => format!(
                    "the contact {} gave {} of it: a step too long for the contact, or \
                     surfaces that do not face each other",
                    givers(),
                    readable(given)
                ),
                (false, false) => format!(
                    "the contact {} took energy, so the bodies made it: a step too long for \
                     the motion or the contact (a shorter dt), or a penetration pushed out",
                    pairs()
                ),
                (false, true) => "a step too long for the motion (a shorter dt)".to_string(),
            };
            format!(
                "the energy balance gained {:.2} % of the energy in play (more than {} %, \
                 analysis.energy_gain_limit): the bodies hold more than they were given and \
                 the sinks took, so the answer is not the physics'; {cause}",
                100.0 * gain,
                100.0 * limit,
            )
        })
    }
}
