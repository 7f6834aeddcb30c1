//! The validated model: bodies with meshes and materials placed in one global node numbering,
//! supports as constrained DOFs, loads resolved to global nodes, curves resolved.
//!
//! Global numbering: body b's node i is global node `node_offset[b] + i`; DOF `2 n + c`
//! (c = 0 for x / r, 1 for y / z).
//!
//! These are the types; `validate::build` makes them from a [`Scene`](super::Scene), one
//! concept per file: materials.rs, bodies.rs, analysis.rs, loads.rs, contacts.rs, probes.rs,
//! reference.rs, with the look-ups they share in context.rs.

use super::spec::{
    AdaptiveStep, BucklingSpec, ContactDynamics, IntegratorKind, MassKind, NewtonSpec, OutputSpec,
    Quadrature, Quantity, ReferenceKind, StableStepKind, Statistic, TimeStep,
};
use crate::contact::{BodySurface, ContactPair, Interfaces, Master, Obstacle, Section};
use crate::element::bulk_viscosity::BulkViscosity;
use crate::element::mass_scaling::MassScaling;
use crate::element::{Formulation, Strain, Voigt};
use crate::material::{Material, PointState, StressCondition, von_mises};
use crate::mesh::Mesh;
use crate::output::readable;
use rayon::prelude::*;
use std::path::PathBuf;

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BodyKind {
    Continuum {
        formulation: Formulation,
        bbar: bool,
        thickness: f64,
    },
    Rod {
        area: f64,
    },
}

/// What a continuum body is besides its mesh: its formulation, B-bar and thickness (plane
/// stress).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Continuum {
    pub formulation: Formulation,
    pub bbar: bool,
    pub thickness: f64,
}

impl BodyKind {
    /// The continuum's formulation, B-bar and thickness; None for a rod.
    pub fn continuum(self) -> Option<Continuum> {
        match self {
            BodyKind::Continuum {
                formulation,
                bbar,
                thickness,
            } => Some(Continuum {
                formulation,
                bbar,
                thickness,
            }),
            BodyKind::Rod { .. } => None,
        }
    }

    /// The formulation of a continuum; None for a rod.
    pub fn formulation(self) -> Option<Formulation> {
        self.continuum().map(|c| c.formulation)
    }

    pub fn is_rod(self) -> bool {
        matches!(self, BodyKind::Rod { .. })
    }

    /// The kind in words: `plane strain, B-bar`, `plane stress, thickness 0.01`, ...
    pub fn in_words(self) -> String {
        match self {
            BodyKind::Rod { area } => format!("rod, area {}", readable(area)),
            BodyKind::Continuum {
                formulation,
                bbar,
                thickness,
            } => {
                let name = match formulation {
                    Formulation::PlaneStrain => "plane strain (per unit depth)".to_string(),
                    Formulation::PlaneStress => {
                        format!("plane stress, thickness {}", readable(thickness))
                    }
                    Formulation::Axisymmetric => "axisymmetric (full ring)".to_string(),
                };
                if bbar { format!("{name}, B-bar") } else { name }
            }
        }
    }

    /// What a body's mass is of, in words: per unit depth (plane strain), through the
    /// thickness (plane stress), the full ring (axisymmetric), the rod's.
    pub fn mass_in_words(self) -> &'static str {
        match self.formulation() {
            None => "the rod's",
            Some(Formulation::PlaneStrain) => "per unit depth",
            Some(Formulation::PlaneStress) => "through the thickness",
            Some(Formulation::Axisymmetric) => "of the full ring",
        }
    }

    /// The modulus of the dilatational wave ([`Body::p_wave_modulus`]) in words.
    pub fn modulus_name(self) -> &'static str {
        match self.formulation() {
            None => "E (rod)",
            Some(Formulation::PlaneStrain) => "lambda + 2 mu (plane strain)",
            Some(Formulation::Axisymmetric) => "lambda + 2 mu (axisymmetric)",
            Some(Formulation::PlaneStress) => "E / (1 - nu^2) (plane stress)",
        }
    }
}

#[derive(Debug, Clone)]
pub struct Body {
    pub name: String,
    pub mesh: Mesh,
    pub kind: BodyKind,
    pub material: Material,
    pub node_offset: usize,
    pub initial_stress: Voigt,
    pub velocity: [f64; 2],
    /// The boundary edges of the mesh touching each node (local numbers; empty for rods):
    /// the contact impedance's tributary length, found once.
    pub boundary_at_node: Vec<Vec<[usize; 2]>>,
    /// The mesh's boundary edges as `Mesh::boundary_edges` gives them (local numbers; empty
    /// for rods), found once: the contact surfaces, the record and the warnings read them.
    pub boundary: Vec<[usize; 2]>,
}

impl Body {
    pub fn global(&self, node: usize) -> usize {
        self.node_offset + node
    }

    pub fn elements(&self) -> usize {
        self.mesh.cells.len()
    }

    /// The P-wave modulus M = rho c^2 of the body's dilatational wave: the material's under
    /// the stress condition of its formulation (lambda + 2 mu; plane stress E / (1 - nu^2)),
    /// E for a rod.
    pub fn p_wave_modulus(&self) -> f64 {
        let elastic = &self.material.elastic;
        match self.kind {
            BodyKind::Rod { .. } => elastic.young,
            BodyKind::Continuum { formulation, .. } => {
                elastic.p_wave_modulus(StressCondition::of(formulation))
            }
        }
    }

    /// Whether the body is an axisymmetric continuum (x the radius).
    pub fn is_axisymmetric(&self) -> bool {
        self.kind.formulation() == Some(Formulation::Axisymmetric)
    }

    /// Material points per element: 4 for Quad4, 1 for rods.
    pub fn points_per_element(&self) -> usize {
        match self.kind {
            BodyKind::Continuum { .. } => 4,
            BodyKind::Rod { .. } => 1,
        }
    }
}

pub use crate::curve::Curve;

#[derive(Debug, Clone)]
pub enum Load {
    /// The same force on each listed global node.
    NodalForce {
        nodes: Vec<usize>,
        force: [f64; 2],
        curve: Curve,
    },
    /// Dead traction on edges (global node pairs) of a body.
    Traction {
        body: usize,
        edges: Vec<[usize; 2]>,
        traction: [f64; 2],
        curve: Curve,
    },
    /// Pressure normal to the edges at the start of the increment.
    Pressure {
        body: usize,
        edges: Vec<[usize; 2]>,
        pressure: f64,
        curve: Curve,
    },
    /// Prescribed total displacement components.
    Displacement {
        nodes: Vec<usize>,
        x: Option<f64>,
        y: Option<f64>,
        curve: Curve,
    },
    /// Prescribed rigid rotation about `center` (initial coordinates).
    Rotation {
        nodes: Vec<usize>,
        center: [f64; 2],
        angle: f64,
        curve: Curve,
    },
    /// Prescribed affine displacement u = offset + gradient X (initial coordinates).
    Affine {
        nodes: Vec<usize>,
        gradient: [[f64; 2]; 2],
        offset: [f64; 2],
        curve: Curve,
    },
}

#[derive(Debug, Clone)]
pub struct Probe {
    pub quantity: Quantity,
    pub statistic: Statistic,
    pub body: usize,
    /// Node ids (nodal quantities, global) or element ids of the body.
    pub members: Vec<usize>,
    pub column: String,
    /// `members` as the range they are, when they are one (`consecutive_run`): an extent, and
    /// the max or min of a kernel's plastic strain or temperature, then read contiguous arrays.
    pub consecutive: Option<std::ops::Range<usize>>,
}

/// Values per part of a fold over a contiguous array (`extreme_of_run`, the extents over
/// consecutive nodes): read in order, eight thousand take about what a thousand gathered
/// through a member list take (`MEMBERS_PER_PART`).
pub const RUN_PART: usize = 8192;

/// The largest (`max`) or the smallest of `values`, in parallel parts on several threads for
/// a long array (min and max are exact: the parts give the bits of one fold).
pub fn extreme_of_run(values: &[f64], max: bool) -> f64 {
    let extreme = |part: &[f64]| {
        if max {
            part.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        } else {
            part.iter().copied().fold(f64::INFINITY, f64::min)
        }
    };
    if values.len() > RUN_PART && rayon::current_num_threads() > 1 {
        let parts: Vec<f64> = values.par_chunks(RUN_PART).map(extreme).collect();
        extreme(&parts)
    } else {
        extreme(values)
    }
}

/// The ids first..first + n when `members` are exactly these, in this order (a whole body's
/// nodes or elements).
pub fn consecutive_run(members: &[usize]) -> Option<std::ops::Range<usize>> {
    let first = *members.first()?;
    let consecutive = members.iter().enumerate().all(|(k, m)| *m == first + k);
    consecutive.then(|| first..first + members.len())
}

/// Members per part of a probe's statistic (`Probe::combine`, `in_parts`): a thousand values take about
/// a microsecond, what handing a part to another thread costs.
const MEMBERS_PER_PART: usize = 1024;

/// `part` of each part of `MEMBERS_PER_PART` members, in order: in parallel on several
/// threads, on the calling one for a single part (the parts, and so the bits, are the same).
pub fn in_parts<'m, T: Send>(
    members: &'m [usize],
    part: impl Fn(&'m [usize]) -> T + Sync,
) -> Vec<T> {
    if members.len() > MEMBERS_PER_PART && rayon::current_num_threads() > 1 {
        members.par_chunks(MEMBERS_PER_PART).map(&part).collect()
    } else {
        members.chunks(MEMBERS_PER_PART).map(part).collect()
    }
}

/// The statistic of a part of a probe's members: the sum and count of a mean, or the
/// extreme of a max or min.
#[derive(Clone, Copy)]
struct Partial {
    sum: f64,
    count: usize,
    max: f64,
    min: f64,
}

impl Partial {
    const EMPTY: Partial = Partial {
        sum: 0.0,
        count: 0,
        max: f64::NEG_INFINITY,
        min: f64::INFINITY,
    };

    #[inline(always)]
    fn take(mut self, v: f64, statistic: Statistic) -> Partial {
        match statistic {
            Statistic::Max => self.max = self.max.max(v),
            Statistic::Min => self.min = self.min.min(v),
            _ => {
                self.sum += v;
                self.count += 1;
            }
        }
        self
    }

    fn join(self, other: Partial) -> Partial {
        Partial {
            sum: self.sum + other.sum,
            count: self.count + other.count,
            max: self.max.max(other.max),
            min: self.min.min(other.min),
        }
    }
}

/// A probe's statistic over material points, given what it reads of a point
/// ([`Probe::fold_points`]).
pub trait PointFold: Sized {
    fn fold(self, value: impl Fn(&PointState) -> f64 + Sync) -> f64;

    /// `fold` of a scalar of the points (a fold that keeps it in an array reads that).
    fn fold_scalar(self, scalar: PointScalar) -> f64 {
        self.fold(move |p: &PointState| scalar.of(p))
    }
}

/// A scalar of a material point's state that a kernel also keeps in an array of its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointScalar {
    EqPlasticStrain = 0,
    Temperature = 1,
}

impl PointScalar {
    #[inline(always)]
    pub fn of(self, p: &PointState) -> f64 {
        match self {
            PointScalar::EqPlasticStrain => p.eq_plastic_strain,
            PointScalar::Temperature => p.temperature,
        }
    }
}

impl Probe {
    /// The probe's statistic (mean, max, min) of the values `values(part)` yields for the
    /// members `part`. The members are taken in parts of `MEMBERS_PER_PART`, folded apart
    /// (in parallel on several threads: a probe over a whole body is a serial pass per step
    /// otherwise) and combined in order, so the bits do not depend on the thread count.
    #[inline]
    pub fn combine<'m, I: Iterator<Item = f64>>(
        &'m self,
        values: impl Fn(&'m [usize]) -> I + Sync,
    ) -> f64 {
        let statistic = self.statistic;
        let part = |members: &'m [usize]| {
            values(members).fold(Partial::EMPTY, |p, v| p.take(v, statistic))
        };
        let total = in_parts(&self.members, part)
            .into_iter()
            .fold(Partial::EMPTY, Partial::join);
        match statistic {
            Statistic::Mean => total.sum / total.count.max(1) as f64,
            Statistic::Max => total.max,
            Statistic::Min => total.min,
            // the nodes' masses are the caller's (`analysis::run::record`): a scene gives
            // `mass_mean` only to nodal quantities, which never come here
            Statistic::MassMean => f64::NAN,
        }
    }

    /// `fold` of what the probe reads of a material point (one closure per quantity, so the
    /// fold is compiled for each); None for a nodal quantity.
    #[inline]
    pub fn fold_points<F: PointFold>(&self, fold: F) -> Option<f64> {
        Some(match self.quantity {
            Quantity::StressXX => fold.fold(|p: &PointState| p.stress[0]),
            Quantity::StressYY => fold.fold(|p: &PointState| p.stress[1]),
            Quantity::StressZZ => fold.fold(|p: &PointState| p.stress[2]),
            Quantity::StressXY => fold.fold(|p: &PointState| p.stress[3]),
            Quantity::VonMises => fold.fold(|p: &PointState| von_mises(&p.stress)),
            Quantity::EqPlasticStrain => fold.fold_scalar(PointScalar::EqPlasticStrain),
            Quantity::Temperature => fold.fold_scalar(PointScalar::Temperature),
            _ => return None,
        })
    }

    /// The statistic of `f` over the material points of the probe's elements, `points` the
    /// points of its body (`points_per_element` each).
    #[inline]
    pub fn of_points(
        &self,
        points: &[PointState],
        points_per_element: usize,
        f: impl Fn(&PointState) -> f64 + Sync,
    ) -> f64 {
        let ppe = points_per_element;
        self.combine(|members| {
            members
                .iter()
                .flat_map(move |e| &points[e * ppe..(e + 1) * ppe])
                .map(&f)
        })
    }
}

#[derive(Debug, Clone)]
pub enum Analysis {
    Static(StaticAnalysis),
    Dynamic(DynamicAnalysis),
}

/// The validated dynamic analysis.
#[derive(Debug, Clone)]
pub struct DynamicAnalysis {
    pub step: TimeStep,
    pub end_time: f64,
    pub integrator: IntegratorKind,
    pub beta: f64,
    pub gamma: f64,
    pub theta: f64,
    pub alpha: f64,
    pub rho_infinity: f64,
    pub mass: MassKind,
    pub contact_dynamics: ContactDynamics,
    pub rayleigh: [f64; 2],
    pub allow_unstable: bool,
    /// The share of the energy in play the balance may gain at any step before the run ends
    /// (`analysis.energy_gain_limit`; None: not guarded, the integrator's default).
    pub energy_gain_limit: Option<f64>,
    pub geometry: Strain,
    pub newton: NewtonSpec,
    pub buckling: Option<BucklingSpec>,
    /// Central difference's Quad4 kernel (always `full` for the implicit integrators).
    pub quadrature: Quadrature,
    /// The hourglass coefficient kappa of the reduced kernel (0.1 unless given).
    pub hourglass: f64,
    /// Central difference: the bulk viscosity of the explicit Quad4 kernels (None: off).
    pub bulk_viscosity: Option<BulkViscosity>,
    /// Central difference: the mass scaling of the explicit Quad4 kernels (None: off).
    pub mass_scaling: Option<MassScaling>,
    /// Central difference: the subcycling of the explicit Quad4 kernels (None: off).
    pub subcycling: Option<Subcycling>,
    /// Central difference: the arbitrary Lagrangian-Eulerian steps (None: Lagrangian).
    pub ale: Option<Ale>,
}

/// `analysis.ale` validated: smooth and remap every `every` steps by `rules`
/// (docs/theory.md 8.11).
#[derive(Debug, Clone, Copy)]
pub struct Ale {
    pub every: usize,
    pub rules: crate::ale::Rules,
}

/// Multi-time-step central difference (docs/theory.md 8.7c): each element steps with its
/// own stable step rounded down to 2^k times the shortest, k <= `levels`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Subcycling {
    pub levels: u32,
}

/// The validated static analysis.
#[derive(Debug, Clone)]
pub struct StaticAnalysis {
    pub steps: usize,
    pub end_time: f64,
    pub geometry: Strain,
    pub newton: NewtonSpec,
    pub buckling: Option<BucklingSpec>,
    /// Arc-length continuation instead of load stepping (None: load stepping).
    pub arc_length: Option<ArcLength>,
}

/// The validated `analysis.arc_length`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcLength {
    pub max_increments: usize,
    /// The Newton iterations an increment aims at: the next arc is the last one times
    /// sqrt(iterations / taken), within [1/2, 2].
    pub iterations: usize,
}

impl DynamicAnalysis {
    /// The estimate of the highest frequency central difference's automatic step scales
    /// (the one answer to `analysis.stable_step`; docs/theory.md 8.7): the elements' bounds
    /// (`Bound`, and every step that is not automatic), their exact frequencies
    /// (`Tight`), or the mesh's highest frequency estimated over those (`Global`). With the
    /// bulk viscosity the ratios are taken against the undamped bounds and scale the damped
    /// ones. With the mass scaling the elements are scaled by their bounds as without it
    /// (more mass than the tight step needs); with the subcycling the levels come from the
    /// tight frequencies (damped as the single step's).
    pub fn stable_estimate(&self) -> StableStepKind {
        match self.step {
            TimeStep::Auto { stable, .. } => stable,
            _ => StableStepKind::Bound,
        }
    }

    /// The fixed step (every implicit analysis has one; scene validation refuses `auto`
    /// for them).
    pub fn fixed_dt(&self) -> Option<f64> {
        match self.step {
            TimeStep::Fixed(dt) => Some(dt),
            TimeStep::Auto { .. } | TimeStep::Adaptive(_) => None,
        }
    }

    /// Whether the integrator has a one-step local error estimate (the Newmark family with
    /// beta != 1/6: theory 8.2a): implicit `dt = "auto"` and history.csv `error_estimate`.
    pub fn has_error_estimate(&self) -> bool {
        match self.integrator {
            IntegratorKind::Average
            | IntegratorKind::Hu
            | IntegratorKind::Hht
            | IntegratorKind::GeneralizedAlpha => true,
            IntegratorKind::Newmark => (self.beta - 1.0 / 6.0).abs() > 1e-3,
            IntegratorKind::Linear
            | IntegratorKind::Wilson
            | IntegratorKind::Houbolt
            | IntegratorKind::CentralDifference => false,
        }
    }

    /// The error-controlled step of an adaptive implicit analysis.
    pub fn adaptive(&self) -> Option<AdaptiveStep> {
        match self.step {
            TimeStep::Adaptive(adaptive) => Some(adaptive),
            _ => None,
        }
    }
}

impl Analysis {
    pub fn geometry(&self) -> Strain {
        match self {
            Analysis::Static(s) => s.geometry,
            Analysis::Dynamic(s) => s.geometry,
        }
    }

    pub fn end_time(&self) -> f64 {
        match self {
            Analysis::Static(s) => s.end_time,
            Analysis::Dynamic(s) => s.end_time,
        }
    }

    /// The `[analysis.buckling]` table, if the scene has one.
    pub fn buckling(&self) -> Option<&BucklingSpec> {
        match self {
            Analysis::Static(s) => s.buckling.as_ref(),
            Analysis::Dynamic(s) => s.buckling.as_ref(),
        }
    }

    /// The bulk viscosity of a central-difference analysis (None: off, or not dynamic).
    pub fn bulk_viscosity(&self) -> Option<&crate::element::bulk_viscosity::BulkViscosity> {
        match self {
            Analysis::Static(_) => None,
            Analysis::Dynamic(s) => s.bulk_viscosity.as_ref(),
        }
    }

    /// The ALE steps of a central-difference analysis (None: Lagrangian, or not dynamic).
    pub fn ale(&self) -> Option<&Ale> {
        match self {
            Analysis::Static(_) => None,
            Analysis::Dynamic(s) => s.ale.as_ref(),
        }
    }

    /// The mass scaling of a central-difference analysis (None: off, or not dynamic).
    pub fn mass_scaling(&self) -> Option<&crate::element::mass_scaling::MassScaling> {
        match self {
            Analysis::Static(_) => None,
            Analysis::Dynamic(s) => s.mass_scaling.as_ref(),
        }
    }

    /// Whether central difference's Quad4 kernel is the one-point one (`quadrature =
    /// "reduced"`).
    pub fn one_point(&self) -> bool {
        matches!(self, Analysis::Dynamic(d) if d.quadrature == crate::scene::spec::Quadrature::Reduced)
    }
}

#[derive(Debug, Clone)]
pub struct Model {
    /// Scene file stem: names the output folder and the .pvd.
    pub name: String,
    pub file: PathBuf,
    pub title: String,
    pub bodies: Vec<Body>,
    pub node_count: usize,
    /// DOFs fixed by supports (sorted, unique).
    pub fixed_dofs: Vec<usize>,
    pub loads: Vec<Load>,
    pub analysis: Analysis,
    pub output: OutputSpec,
    pub probes: Vec<Probe>,
    /// Initial velocity per DOF (bodies' `velocity`, then `[[initial_velocity]]` sets).
    pub initial_velocity: Vec<f64>,
    pub contacts: Vec<ContactPair>,
    /// Every `[[obstacle]]` of the scene, whether a pair uses it or not (the pairs hold their
    /// own copies): an obstacle no pair names stops nothing.
    pub obstacles: Vec<Obstacle>,
    /// The `[reference]` solution with its numbers (None without the table).
    pub reference: Option<Reference>,
    /// `analysis.checkpoint_every`: a checkpoint every N converged steps (0: none).
    pub checkpoint_every: usize,
    /// The scene's text and `--set` overrides, embedded in checkpoints so `impact resume`
    /// needs nothing else (empty for a model not read from text).
    pub source: SceneSource,
}

/// Where a model came from: the scene text as read and the overrides applied to it.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SceneSource {
    pub text: String,
    pub overrides: Vec<String>,
}

/// A validated `[reference]`: a closed-form solution with its numbers read from the model.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// A constant contact force `force` for 0 < t < `duration`, zero after (rod impacts,
    /// reference::rod_wall_impact and reference::equal_bars_impact).
    ForcePulse {
        kind: ReferenceKind,
        pair: String,
        force: f64,
        duration: f64,
    },
    /// Hertz impact (reference::hertz_sphere_impact): peak force, largest contact radius and
    /// contact duration.
    Hertz {
        pair: String,
        peak_force: f64,
        radius: f64,
        duration: f64,
    },
}

impl Reference {
    /// The contact pair the reference speaks of.
    pub fn pair(&self) -> &str {
        match self {
            Reference::ForcePulse { pair, .. } | Reference::Hertz { pair, .. } => pair,
        }
    }
}

impl Model {
    /// Whether the analysis is explicit dynamics (central difference).
    pub fn is_explicit(&self) -> bool {
        matches!(&self.analysis, Analysis::Dynamic(d)
            if d.integrator == IntegratorKind::CentralDifference)
    }

    /// Whether the contact's own work (normal rows and friction together) is guarded at
    /// every step (`Run::energy_created`): on central difference, and on the implicit
    /// integrators whose balance is guarded by default (not the linear acceleration method,
    /// Wilson-theta or Houbolt, whose full-step energy is not their invariant) with the
    /// seeds' contact treatment (`contact_dynamics = "hughes"`) and a pair that `guards_pair`
    /// names (the mortar pairs and their holds, the only ones read there). The balance alone
    /// misses energy that the contact makes where the bodies take it up as plastic work or an
    /// integrator's damping takes as much.
    pub fn guards_contact_work(&self) -> bool {
        let Analysis::Dynamic(d) = &self.analysis else {
            return false;
        };
        match d.integrator {
            IntegratorKind::CentralDifference => true,
            IntegratorKind::Linear | IntegratorKind::Wilson | IntegratorKind::Houbolt => false,
            _ => {
                d.contact_dynamics == ContactDynamics::Hughes
                    && self.contacts.iter().any(|p| self.guards_pair(p))
            }
        }
    }

    /// Whether pair `pair`'s own work counts in the guard of `guards_contact_work`: every
    /// pair on central difference; on the implicit paths a mortar pair or a mortar pair's
    /// hold with its impact conditions. A node-to-segment pair's trapezoidal work swings
    /// there beyond the guard's 1 % and comes back: the elastic bar on the wall at ten times
    /// the critical step, the seeds' two-pass round bar (-1.1 % at t = 0.024 while the
    /// balance gains 0.38 %), two bars without impact conditions (-5 %); those pairs keep
    /// the balance guard.
    pub fn guards_pair(&self, pair: &ContactPair) -> bool {
        use crate::contact::Discretization;
        self.is_explicit()
            || (pair.options.impact_conditions
                && matches!(
                    pair.discretization,
                    Discretization::Mortar(_) | Discretization::Held(_)
                ))
    }

    /// Which steps get a history row (`output.history_every`, `output.history_interval`, or
    /// the default: every step; central difference's grid of its end time).
    pub fn history_cadence(&self) -> crate::output::thinning::Cadence {
        self.output
            .history_cadence(self.is_explicit().then(|| self.analysis.end_time()))
    }

    /// Constrained DOFs: supports and prescribed-displacement loads (sorted, unique).
    pub fn constrained_dofs(&self) -> Vec<usize> {
        Model::constrained_dofs_of(&self.fixed_dofs, &self.loads)
    }

    /// The constrained DOFs of supports `fixed_dofs` and `loads` (for validation, before
    /// the model exists).
    pub(super) fn constrained_dofs_of(fixed_dofs: &[usize], loads: &[Load]) -> Vec<usize> {
        let mut dofs = fixed_dofs.to_vec();
        for load in loads {
            match load {
                Load::Displacement { nodes, x, y, .. } => {
                    for n in nodes {
                        if x.is_some() {
                            dofs.push(2 * n);
                        }
                        if y.is_some() {
                            dofs.push(2 * n + 1);
                        }
                    }
                }
                Load::Rotation { nodes, .. } | Load::Affine { nodes, .. } => {
                    dofs.extend(nodes.iter().flat_map(|n| [2 * n, 2 * n + 1]))
                }
                _ => {}
            }
        }
        dofs.sort_unstable();
        dofs.dedup();
        dofs
    }

    /// The nodes of every contact surface (slaves, and the nodes of deformable masters),
    /// flagged by global node.
    pub fn contact_surface_nodes(&self) -> Vec<bool> {
        let mut flags = vec![false; self.dofs() / 2];
        for pair in &self.contacts {
            pair.slaves.iter().for_each(|s| flags[*s] = true);
            match &pair.master {
                Master::Segments { edges, .. } => {
                    edges.iter().flatten().for_each(|n| flags[*n] = true)
                }
                Master::Nodes { nodes, .. } => nodes.iter().for_each(|n| flags[*n] = true),
                Master::Obstacle(_) => {}
            }
        }
        flags
    }

    pub fn dofs(&self) -> usize {
        2 * self.node_count
    }

    /// Global node `node` in the user's words: its number within its body, the body, and
    /// the node sets of the body that hold it ("node 12 of body `lower` (sets `top`,
    /// `right`)"); messages name nodes this way, since global numbers appear nowhere in a
    /// scene or a frame.
    pub fn describe_node(&self, node: usize) -> String {
        let Some(body) = self
            .bodies
            .iter()
            .rev()
            .find(|b| b.node_offset <= node)
            .filter(|b| node - b.node_offset < b.mesh.nodes.len())
        else {
            return format!("node {node}");
        };
        let local = node - body.node_offset;
        let sets: Vec<String> = body
            .mesh
            .node_sets
            .iter()
            .filter(|(name, nodes)| name.as_str() != "all" && nodes.binary_search(&local).is_ok())
            .map(|(name, _)| format!("`{name}`"))
            .collect();
        let within = match sets.len() {
            0 => String::new(),
            1 => format!(" (set {})", sets[0]),
            _ => format!(" (sets {})", sets.join(", ")),
        };
        format!("node {local} of body `{}`{within}", body.name)
    }

    pub fn elements(&self) -> usize {
        self.bodies.iter().map(Body::elements).sum()
    }

    /// Initial coordinates of all nodes in global numbering.
    pub fn coordinates(&self) -> Vec<[f64; 2]> {
        self.bodies
            .iter()
            .flat_map(|b| b.mesh.nodes.iter().copied())
            .collect()
    }

    /// Whether some body's material carries a temperature (Johnson-Cook).
    pub fn carries_temperature(&self) -> bool {
        self.bodies.iter().any(|b| b.material.carries_temperature())
    }

    /// The contact problem of the model as contact sees it: the pairs, and per body its
    /// section, its plane-wave impedance for the impact and release conditions and its
    /// boundary (every stepper's contact set-up).
    pub fn interfaces(&self) -> Interfaces {
        let bodies = self
            .bodies
            .iter()
            .map(|b| {
                let section = match b.kind {
                    BodyKind::Rod { area } => Section::Rod { area },
                    BodyKind::Continuum {
                        formulation,
                        thickness,
                        ..
                    } => match formulation {
                        Formulation::PlaneStrain => Section::Plane { thickness: 1.0 },
                        Formulation::PlaneStress => Section::Plane { thickness },
                        Formulation::Axisymmetric => Section::Axisymmetric,
                    },
                };
                let impedance_per_area = (b.p_wave_modulus() * b.material.density).sqrt();
                BodySurface::new(
                    (section, impedance_per_area),
                    (b.boundary_at_node.iter())
                        .map(|edges| edges.iter().map(|e| e.map(|n| b.global(n))).collect())
                        .collect(),
                    (b.boundary.iter())
                        .map(|e| e.map(|n| b.global(n)))
                        .collect(),
                    b.node_offset,
                )
            })
            .collect();
        Interfaces {
            pairs: self.contacts.clone(),
            bodies,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_is_found_only_where_the_members_are_one() {
        assert_eq!(consecutive_run(&[3, 4, 5]), Some(3..6));
        assert_eq!(consecutive_run(&[0]), Some(0..1));
        assert_eq!(consecutive_run(&[3, 5]), None);
        assert_eq!(consecutive_run(&[4, 3]), None);
        assert_eq!(consecutive_run(&[]), None);
    }

    #[test]
    fn the_extreme_of_a_long_run_in_parts_is_the_sorted_ends() {
        // more than two parts, on a pool of three threads, so the parallel branch runs; the
        // reference is the ends of the sorted values
        let n = 3 * RUN_PART + 17;
        let values: Vec<f64> = (0..n)
            .map(|k| ((k * 7919) % 10007) as f64 - 5000.5)
            .collect();
        let mut sorted = values.clone();
        sorted.sort_by(f64::total_cmp);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        let ends = pool.install(|| {
            (
                extreme_of_run(&values, false),
                extreme_of_run(&values, true),
            )
        });
        assert_eq!(ends, (sorted[0], sorted[n - 1]));
        // a short run, on the calling thread: 0, 7919, 5831, 3743, 1655 less 5000.5
        assert_eq!(extreme_of_run(&values[..5], true), 7919.0 - 5000.5);
        assert_eq!(extreme_of_run(&values[..5], false), -5000.5);
    }
}
