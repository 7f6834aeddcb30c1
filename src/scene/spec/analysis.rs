//! The analysis block of the scene schema: the analysis type, the integrator, the time or load
//! steps, buckling and Newton's controls.

use super::yes;
use crate::element::Strain;
use serde::Deserialize;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AnalysisKind {
    /// Load stepping in pseudo time.
    Static,
    /// Direct time integration.
    Dynamic,
}

/// The time integrator of a dynamic analysis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorKind {
    /// Newmark average acceleration (beta 1/4, gamma 1/2): no numerical damping.
    Average,
    /// Newmark linear acceleration (beta 1/6, gamma 1/2): conditionally stable.
    Linear,
    /// Hu's modified Newmark (beta 1.0, gamma 1.5), the choice of Greco & Coda (2003).
    Hu,
    /// Newmark with the scene's `beta` and `gamma`.
    Newmark,
    /// Wilson-theta (`theta`, default 1.4).
    Wilson,
    /// Houbolt, started by Newmark average steps.
    Houbolt,
    /// Hilber-Hughes-Taylor (`alpha` in [-1/3, 0], default -0.05).
    Hht,
    /// Chung-Hulbert generalized-alpha (`rho_infinity` in [0, 1], default 0.8).
    GeneralizedAlpha,
    /// Explicit central difference with lumped mass.
    CentralDifference,
}

impl IntegratorKind {
    /// The scene's name of the integrator (`average`, `central_difference`, ...).
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Average => "average",
            IntegratorKind::Linear => "linear",
            IntegratorKind::Hu => "hu",
            IntegratorKind::Newmark => "newmark",
            IntegratorKind::Wilson => "wilson",
            IntegratorKind::Houbolt => "houbolt",
            IntegratorKind::Hht => "hht",
            IntegratorKind::GeneralizedAlpha => "generalized_alpha",
            IntegratorKind::CentralDifference => "central_difference",
        }
    }
}

/// Consistent (sum rho N^T N over the initial configuration) or lumped (row sums) mass, or
/// for rods the blend 3/2 consistent - 1/2 lumped, with which the trapezoidal rule carries a
/// wave without dispersion at Courant number 1 (docs/theory.md "Contact in implicit dynamics").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MassKind {
    #[default]
    Consistent,
    Lumped,
    DispersionFree,
}

/// How an implicit dynamic run treats contact in time (docs/theory.md "Contact in implicit
/// dynamics").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactDynamics {
    /// Hughes et al. (1975): gap constraint, impact conditions II-8 at closure, release
    /// conditions II-11/II-12 with the fraction rule.
    #[default]
    Hughes,
    /// A closed pair keeps its relative normal velocity at zero at the end of the step
    /// (velocity-level persistency); no velocity jumps, release in tension.
    Persistency,
    /// The nodes of the contact surfaces carry no mass (their share goes to the other nodes
    /// of their elements); gap constraint, no velocity jumps, release in tension.
    MassRedistribution,
}

/// The analysis block. One flat table (so every message points at its key's line); keys
/// that do not apply to the chosen `type` are refused during validation.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnalysisSpec {
    #[serde(rename = "type")]
    pub kind: AnalysisKind,
    /// Static: the number of equal load increments up to `end_time` (required).
    pub steps: Option<usize>,
    /// Dynamic: the time step, a number or `"auto"` (central difference only: the stable
    /// step of the current configuration times `time_step_scale`, every step). Required for
    /// the implicit integrators; `"auto"` by default for central difference.
    pub dt: Option<StepSpec>,
    /// `dt = "auto"`: the fraction of the critical step taken, in (0, 1]. Default 0.9.
    pub time_step_scale: Option<f64>,
    /// `dt = "auto"`, central difference: the critical step the scale applies to: `bound`
    /// (the kernels' closed-form frequency bounds; the default with the mass scaling),
    /// `tight` (each element's exact highest frequency, `assembly::explicit::tight`: up to
    /// twice the step; the default with the subcycling) or `global` (the default: the mesh's
    /// highest frequency estimated over the tight elements, `assembly::explicit::global`).
    pub stable_step: Option<StableStepKind>,
    /// `dt = "auto"`, central difference: the run stops (status `diverged`) when the step
    /// would fall below this (a time); default no limit. Implicit: the shortest step the
    /// error control takes (a step there is accepted whatever its estimate); default none,
    /// or the first step when the scene has contact pairs.
    pub dt_min: Option<f64>,
    /// Implicit `dt = "auto"`: the longest step (a time). Default: no limit (end_time).
    pub dt_max: Option<f64>,
    /// Implicit `dt = "auto"`: the local error each step may make, relative to the distance
    /// travelled in the step at the run's top speed (docs/theory.md 8.2a). Default
    /// [`DEFAULT_ERROR_TOLERANCE`].
    pub error_tolerance: Option<f64>,
    /// Static: default 1 (pseudo time). Dynamic: required.
    pub end_time: Option<f64>,
    /// `nonlinear` (default, updated Lagrangian) or `linear` (small strain).
    #[serde(default)]
    pub geometry: Strain,
    #[serde(default)]
    pub newton: NewtonSpec,
    /// Dynamic: the integrator (default `average`).
    pub integrator: Option<IntegratorKind>,
    /// Newmark's beta (integrator `newmark`).
    pub beta: Option<f64>,
    /// Newmark's gamma (integrator `newmark`).
    pub gamma: Option<f64>,
    /// Wilson's theta (default 1.4).
    pub theta: Option<f64>,
    /// HHT's alpha (default -0.05).
    pub alpha: Option<f64>,
    /// Generalized-alpha's spectral radius at infinite frequency (default 0.8).
    pub rho_infinity: Option<f64>,
    /// `consistent` (default for implicit), `lumped` (always for central difference) or
    /// `dispersion_free` (rods, implicit).
    pub mass: Option<MassKind>,
    /// Implicit dynamics: `hughes` (default), `persistency` or `mass_redistribution`.
    pub contact_dynamics: Option<ContactDynamics>,
    /// Rayleigh damping C = a M + b K (K: the tangent at the start of the step). Default [0, 0].
    pub rayleigh: Option<[f64; 2]>,
    /// Central difference: run even if dt exceeds the critical step, and report the blow-up
    /// as status `unstable`. Default false (refused).
    #[serde(default)]
    pub allow_unstable: bool,
    /// The share of the energy in play the balance may gain at any step before the run ends
    /// with exit 3 (energy created). Default 0.01.
    pub energy_gain_limit: Option<f64>,
    /// The buckling check (Erklig, Guzelbey & Cevik 2010, section 2.1.3). Default: none.
    pub buckling: Option<BucklingSpec>,
    /// Write DIR/checkpoint.bin (the whole run state) at the start and every N converged
    /// steps, so `impact resume DIR` can continue the run. Default 0: no checkpoints.
    #[serde(default)]
    pub checkpoint_every: usize,
    /// Central difference: the Quad4 kernel. `full` (default): 2x2 Gauss, exact push-forward;
    /// `reduced`: one point with Flanagan-Belytschko hourglass control, the structure-of-arrays
    /// fast path (plane strain, plane stress, axisymmetric; see docs/theory.md "Reduced
    /// explicit Quad4").
    pub quadrature: Option<Quadrature>,
    /// `quadrature = "reduced"`: the hourglass stiffness coefficient kappa in [0, 1]: kappa = 1
    /// gives a square element the hourglass stiffness of the fully integrated one. Default 0.1.
    pub hourglass: Option<f64>,
    /// Central difference on Quad4 bodies at finite strain: the bulk viscosity, an artificial
    /// pressure on the volumetric strain rate (docs/theory.md 8.7a). Default: on, with
    /// Abaqus/Explicit's coefficients, where it applies (central difference, finite strain,
    /// no rod body); `"off"` turns it off.
    pub bulk_viscosity: Option<BulkViscositySetting>,
    /// Central difference on Quad4 bodies at finite strain with dt = "auto": selective mass
    /// scaling, the elements whose stable step falls below `target` made heavier until it is
    /// the target (docs/theory.md 8.7b). Default: none (off).
    pub mass_scaling: Option<MassScalingSpec>,
    /// Central difference on Quad4 bodies at finite strain with dt = "auto": multi-time-step
    /// integration, each element stepped with its own stable step rounded down to a power of
    /// two of the shortest (docs/theory.md 8.7c). Default: none (one step for every element).
    pub subcycling: Option<SubcyclingSpec>,
    /// Central difference on Quad4 bodies at finite strain: arbitrary Lagrangian-Eulerian
    /// steps, the mesh smoothed and the state remapped every few steps (docs/theory.md 8.11).
    /// Default: none (Lagrangian).
    pub ale: Option<AleSpec>,
    /// Static: arc-length continuation (Riks 1979, Crisfield 1981), the load factor an
    /// unknown beside the displacements, so a run follows its equilibrium path past a limit
    /// point (docs/theory.md 5b). Default: none (load stepping in pseudo time).
    pub arc_length: Option<ArcLengthSpec>,
}

/// `analysis.arc_length = { max_increments = 200, iterations = 5 }`: at most
/// `max_increments` increments (default 10 x `steps`) before the run ends where the path has
/// got to; each arc grows or shrinks so that an increment takes about `iterations` Newton
/// iterations (default 5). `arc_length = {}` turns it on with the defaults; `steps` sets the
/// first increment (1 / steps of the load).
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArcLengthSpec {
    pub max_increments: Option<usize>,
    pub iterations: Option<usize>,
}

/// `analysis.ale = { every = 10, smoother = "equipotential", max_move = 0.25, slide_angle = 30 }`:
/// smooth and remap every `every` steps (default 10, Abaqus/Explicit's); the smoother
/// (`equipotential`, default, `volume` or `laplace`); a node's move sweeps at most `max_move`
/// of each of its elements' areas per smoothing (default 0.25); a boundary node slides along
/// the boundary where it turns by at most `slide_angle` degrees (default 30). `ale = {}`
/// turns it on with the defaults.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AleSpec {
    pub every: Option<usize>,
    pub smoother: Option<AleSmoother>,
    pub max_move: Option<f64>,
    pub slide_angle: Option<f64>,
}

/// `analysis.ale.smoother`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AleSmoother {
    /// The area-weighted mean of the centroids of a node's elements (Abaqus' volume smoothing).
    Volume,
    /// The mean of the nodes joined to a node by an edge.
    Laplace,
    /// Winslow's equipotential smoothing (structured nodes; volume elsewhere).
    Equipotential,
}

/// `analysis.subcycling = { levels = 5 }`: the elements' steps are 2^k times the shortest,
/// k = 0 ..= levels (default [`DEFAULT_SUBCYCLING_LEVELS`]); `subcycling = {}` turns it on
/// with the default.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SubcyclingSpec {
    pub levels: Option<u32>,
}

/// The default number of subcycling levels above the finest: steps up to 32 times the
/// shortest.
pub const DEFAULT_SUBCYCLING_LEVELS: u32 = 5;

/// `analysis.mass_scaling = { target = 2e-9 }`: the stable step (a time, > 0) below which an
/// element's density is raised, re-evaluated every step.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassScalingSpec {
    pub target: f64,
}

/// `analysis.bulk_viscosity = { linear = 0.06, quadratic = 1.2 }`: the coefficients b_1 and
/// b_2 of Abaqus/Explicit's bulk viscosity, each >= 0 and defaulting to those values (so
/// `bulk_viscosity = {}` turns it on with the defaults).
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BulkViscositySpec {
    pub linear: Option<f64>,
    pub quadratic: Option<f64>,
}

/// `analysis.bulk_viscosity` as written: its coefficients (a table) or the word `off`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BulkViscositySetting {
    Off,
    On(BulkViscositySpec),
}

impl<'de> Deserialize<'de> for BulkViscositySetting {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<BulkViscositySetting, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = BulkViscositySetting;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                write!(
                    f,
                    "a table of coefficients ({{ linear = 0.06, quadratic = 1.2 }}) or \"off\""
                )
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<BulkViscositySetting, E> {
                match v {
                    "off" => Ok(BulkViscositySetting::Off),
                    _ => Err(E::custom(format!(
                        "expected a table of coefficients or \"off\", got \"{v}\""
                    ))),
                }
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                map: A,
            ) -> Result<BulkViscositySetting, A::Error> {
                BulkViscositySpec::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    .map(BulkViscositySetting::On)
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// `analysis.dt` as written: a step length or the word `auto`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepSpec {
    Fixed(f64),
    Auto,
}

impl<'de> Deserialize<'de> for StepSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<StepSpec, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = StepSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                write!(f, "a time step (a number) or \"auto\"")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<StepSpec, E> {
                Ok(StepSpec::Fixed(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<StepSpec, E> {
                Ok(StepSpec::Fixed(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<StepSpec, E> {
                Ok(StepSpec::Fixed(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<StepSpec, E> {
                match v {
                    "auto" => Ok(StepSpec::Auto),
                    _ => Err(E::custom(format!(
                        "expected a time step (a number) or \"auto\", got \"{v}\""
                    ))),
                }
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// The default of `analysis.error_tolerance`, set by measurement (docs/validation.md 10.3a):
/// the unit oscillator keeps 1.1 % of its amplitude after 1.6 periods, and taylor_jc lands
/// within 0.04 % (L_f) and 0.15 % (D_f) of its dt-converged answer.
pub const DEFAULT_ERROR_TOLERANCE: f64 = 1e-3;

/// The time step of a dynamic analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeStep {
    /// The same step throughout (the last one shorter to end at `end_time`).
    Fixed(f64),
    /// `scale` times the critical step of the current configuration, every step; the run
    /// stops when it would fall below `min`; `stable`: the critical step it scales (the
    /// elements' bounds, their exact frequencies, or the mesh's estimate over them).
    Auto {
        scale: f64,
        min: Option<f64>,
        stable: StableStepKind,
    },
    /// Implicit: each step as long as the local error estimate allows; the first from the
    /// wave speed and the smallest element.
    Adaptive(AdaptiveStep),
}

/// `analysis.stable_step`: the critical step central difference's `dt = "auto"` scales.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StableStepKind {
    Tight,
    Bound,
    Global,
}

/// The implicit error-controlled step (`dt = "auto"`): the tolerance of the local error
/// estimate and the shortest and longest step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveStep {
    pub tolerance: f64,
    pub min: Option<f64>,
    pub max: Option<f64>,
}

/// Quadrature of the explicit Quad4 kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Quadrature {
    /// 2x2 Gauss (B-bar by option), the same kernel as the implicit integrators.
    #[default]
    Full,
    /// One point at the centroid plus hourglass control (central difference only).
    Reduced,
}

/// `[analysis.buckling]`: the inertia of the tangent after every converged state, the
/// linearized buckling modes of the end loads, what to do when the tangent loses positive
/// definiteness, and an initial imperfection.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BucklingSpec {
    /// Count the negative pivots of K_T (no mass) after every converged state: history.csv
    /// column `tangent_negative_pivots`. Default true.
    #[serde(default = "yes")]
    pub check: bool,
    /// The number of linearized buckling modes of the end loads computed before the run
    /// (summary.json `buckling.load_factors`, frames NAME_buckling.pvd). Default 0.
    #[serde(default)]
    pub modes: usize,
    /// `continue` (default) or `stop` (the run ends, status ok, when the negative-pivot
    /// count first changes).
    #[serde(default)]
    pub on_critical: OnCritical,
    /// A buckling mode added to the initial coordinates. Default: none.
    pub imperfection: Option<ImperfectionSpec>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OnCritical {
    #[default]
    Continue,
    Stop,
}

/// The initial imperfection: `amplitude` times linearized buckling mode `mode` (of the end
/// loads), the mode scaled so its largest nodal displacement is 1: `amplitude` is the
/// largest nodal offset (a length).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImperfectionSpec {
    /// Mode number, >= 1. Default 1.
    #[serde(default = "one")]
    pub mode: usize,
    /// The largest nodal offset (length), finite and non-zero.
    pub amplitude: f64,
}

fn one() -> usize {
    1
}

/// How often K_T is factored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Strategy {
    /// Factor at the start of each increment; refactor only when the residual stops
    /// contracting (the modified Newton-Raphson of Erklig, Guzelbey & Cevik 2010, section
    /// 2.1.2).
    #[default]
    Modified,
    /// Factor the current tangent at every iteration.
    Full,
    /// Factor once for the whole run (and again only when dt changes or the iteration stops
    /// contracting).
    Initial,
}

/// What the iteration does with its residuals between factorizations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Updates {
    /// None: every correction is K*^-1 R with the factored K*.
    #[default]
    None,
    /// Quasi-Newton: BFGS updates of K*^-1 (Matthies & Strang 1979).
    Bfgs,
}

/// Which matrix the factorized tangent holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Tangent {
    /// The algorithmic (consistent) material tangent plus K_sigma: the exact derivative.
    #[default]
    Consistent,
    /// D_e only (Erklig, Guzelbey & Cevik 2010, section 2.1.2 (c)(ii): "D_r is taken as the
    /// elastic stress-strain matrix").
    Elastic,
    /// D_e plus the geometric stiffness K_sigma.
    ElasticGeometric,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NewtonSpec {
    /// Default `modified`.
    #[serde(default)]
    pub strategy: Strategy,
    /// Default `consistent`.
    #[serde(default)]
    pub tangent: Tangent,
    /// Iterations per increment before it is cut. Default 30.
    #[serde(default = "default_iterations")]
    pub max_iterations: usize,
    /// Tolerance on ||d delta|| / ||delta|| (Erklig, Guzelbey & Cevik 2010, section 2.1.2
    /// (viii)). Default 1e-8.
    #[serde(default = "default_tolerance")]
    pub tol_displacement: f64,
    /// Tolerance on ||R|| / ||F|| (Erklig, Guzelbey & Cevik 2010, section 2.1.2 (viii)).
    /// Default 1e-8.
    #[serde(default = "default_tolerance")]
    pub tol_force: f64,
    /// Modified Newton refactors when ||R_k|| > contraction ||R_k-1||. Default 0.1.
    #[serde(default = "default_contraction")]
    pub contraction: f64,
    /// Halvings of an increment that does not converge before the run stops `diverged`. Default 6.
    #[serde(default = "default_cuts")]
    pub max_cuts: usize,
    /// Between factorizations, the factored matrix alone (`none`, default: the modified Newton
    /// of Erklig, Guzelbey & Cevik 2010) or with BFGS updates from the residuals of the
    /// iterates (`bfgs`, for a factor kept long: `initial`, the elastic tangent). `full` has
    /// nothing to update.
    #[serde(default)]
    pub updates: Updates,
    /// Modified Newton: also factor at the start of every N-th increment (Erklig's
    /// algorithm: 1). Default: none, only when the iteration stalls, after a cut and when
    /// K*'s coefficients change.
    #[serde(default)]
    pub refactor_every: Option<usize>,
    /// Where the contact active set and the stick/slide statuses are decided: `newton`,
    /// inside the iteration (a primal-dual active set, theory 8.3b), or `passes`, between
    /// Newton solves (the seeds' method). Default: `newton` where the model has a mortar
    /// pair (contact between two bodies), `passes` otherwise.
    #[serde(default)]
    pub active_set: Option<ActiveSetSolve>,
    /// Statics: each increment starts from the last one's displacement increment, scaled to
    /// its length (linear extrapolation, Abaqus/Standard's default), instead of from zero
    /// with the tangent predictor; an increment that does not converge from there is tried
    /// again from zero before it is cut (docs/theory.md 5a). Default true, false with
    /// `strategy = "initial"` (the seeds' algorithm starts each increment from the
    /// converged state).
    #[serde(default)]
    pub extrapolate: Option<bool>,
}

/// See [`NewtonSpec::active_set`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ActiveSetSolve {
    /// Inside Newton's iteration.
    Newton,
    /// Between Newton solves, each with a fixed active set.
    Passes,
}

impl Default for NewtonSpec {
    fn default() -> Self {
        NewtonSpec {
            strategy: Strategy::default(),
            tangent: Tangent::default(),
            max_iterations: default_iterations(),
            tol_displacement: default_tolerance(),
            tol_force: default_tolerance(),
            contraction: default_contraction(),
            max_cuts: default_cuts(),
            updates: Updates::default(),
            refactor_every: None,
            active_set: None,
            extrapolate: None,
        }
    }
}

impl NewtonSpec {
    /// Whether a static increment starts from the last one's, scaled (`extrapolate`).
    pub fn extrapolates(&self) -> bool {
        self.extrapolate
            .unwrap_or(self.strategy != Strategy::Initial)
    }
}

fn default_iterations() -> usize {
    30
}
fn default_tolerance() -> f64 {
    1e-8
}
fn default_contraction() -> f64 {
    0.1
}
fn default_cuts() -> usize {
    6
}
