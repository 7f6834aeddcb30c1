//! What a stepper reports of its state besides the state itself: the energies of the step
//! and the nodal motion (velocity, acceleration, mass, internal force), and the energy
//! balance they close (docs/theory.md section 7).

/// Energies of one step (history.csv columns 2-6; `bulk_viscosity_work`, `mass_scaling_loss`,
/// `remap_loss` and `friction_work` when the scene has the bulk viscosity, the mass scaling,
/// ALE steps or a friction pair).
#[derive(Debug, Clone, Copy, Default, serde::Serialize, serde::Deserialize)]
pub struct Energies {
    pub kinetic: f64,
    pub internal: f64,
    pub plastic_work: f64,
    pub external_work: f64,
    pub contact_work: f64,
    /// The work of the bulk viscosity's pressure (central difference; 0 without it).
    pub bulk_viscosity_work: f64,
    /// Central difference: h^2 / 8 a.M a, the part of 1/2 v.M v at the full steps that the
    /// scheme's conserved energy does not hold (theory 7); 0 for the other integrators.
    pub kinetic_shadow: f64,
    /// The kinetic energy lost as the mass scaling's added mass joined the moving nodes at
    /// rest (central difference; 0 without it; docs/theory.md 8.7b).
    pub mass_scaling_loss: f64,
    /// The kinetic energy the ALE remaps took out of the nodal motion (central difference
    /// with `analysis.ale`; 0 without it; docs/theory.md 8.11).
    pub remap_loss: f64,
    /// The energy Coulomb friction dissipated (dynamic runs with a friction pair; 0
    /// otherwise), >= 0 but for the trapezoidal rule's error on the implicit paths.
    pub friction_work: f64,
}

/// Nodal kinematic fields beyond the displacement (zero in statics).
pub struct Motion<'a> {
    pub velocity: &'a [f64],
    pub acceleration: &'a [f64],
    /// Lumped mass per DOF (for the momentum probes); empty in statics.
    pub mass: &'a [f64],
    /// The internal force of the committed state, all DOFs (for the reaction probes): the
    /// one the step converged with, so the reactions balance the loads as the solution does.
    pub internal_force: &'a [f64],
}

/// Relative energy balance error |KE + W_int + W_contact + W_fric + W_visc + L_ms + L_remap - W_ext - KE_0| /
/// max(KE_0, |W_ext|, |W_elastic|, KE), W_int = W_elastic + W_plastic, W_visc the bulk
/// viscosity's work, L_ms the mass scaling's loss, L_remap the ALE remaps'. KE is in the scale for a body that starts at
/// rest under a load: the first step's kinetic energy comes before the external work that
/// books it (a step's work is its force times an increment taken before that force acted),
/// and against a scale of nothing but that lag the error read 1e300 %; where energy is created
/// from nothing the error tends to 1 (100 %), still far above the 5 % warning.
pub fn balance_error(energies: &Energies, initial_kinetic: f64) -> f64 {
    relative_gain(energies, initial_kinetic).abs()
}

/// The signed balance error: the residual of the balance over the energy in play (see
/// [`balance_error`]); positive where energy was created, negative where it was lost.
pub fn relative_gain(energies: &Energies, initial_kinetic: f64) -> f64 {
    let scale = initial_kinetic
        .max(energies.external_work.abs())
        .max(energies.internal.abs())
        .max(energies.kinetic)
        .max(f64::MIN_POSITIVE);
    balance_gain(energies, initial_kinetic) / scale
}

/// The signed residual of the balance, KE + W_int + W_contact + W_fric + W_visc + L_ms + L_remap -
/// W_ext - KE_0 (see [`balance_error`]): positive where the bodies hold more energy than they
/// were given and the sinks took (energy created), negative where some was lost.
fn balance_gain(energies: &Energies, initial_kinetic: f64) -> f64 {
    energies.kinetic - energies.kinetic_shadow
        + energies.internal
        + energies.plastic_work
        + energies.contact_work
        + energies.friction_work
        + energies.bulk_viscosity_work
        + energies.mass_scaling_loss
        + energies.remap_loss
        - energies.external_work
        - initial_kinetic
}
