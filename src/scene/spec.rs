//! The scene file's schema. Each struct denies unknown fields; each enum variant wraps its own
//! struct so unknown keys are caught inside internally tagged enums too (`deny_unknown_fields`
//! on such an enum itself does not reach its variants' keys).

use crate::element::Strain;
use crate::mesh::MeshSpec;
use crate::output::vtk::Compression;
use serde::Deserialize;

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Free text shown in the summary. Default: empty.
    #[serde(default)]
    pub title: String,
    pub material: Vec<MaterialSpec>,
    pub body: Vec<BodySpec>,
    #[serde(default)]
    pub support: Vec<SupportSpec>,
    #[serde(default)]
    pub load: Vec<LoadSpec>,
    #[serde(default)]
    pub curve: Vec<CurveSpec>,
    #[serde(default)]
    pub initial_velocity: Vec<InitialVelocitySpec>,
    #[serde(default)]
    pub node_set: Vec<NodeSetSpec>,
    #[serde(default)]
    pub obstacle: Vec<ObstacleSpec>,
    #[serde(default)]
    pub contact: Vec<ContactSpec>,
    pub analysis: AnalysisSpec,
    #[serde(default)]
    pub output: OutputSpec,
    /// The analytical solution `impact sweep` measures errors against. Default: none (the
    /// sweep's finest case, with Richardson extrapolation of scalar measures).
    pub reference: Option<ReferenceSpec>,
}

/// `[reference]`: which closed-form solution the scene is an instance of; its numbers
/// (material, length, speed) are read from the model.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    pub kind: ReferenceKind,
    /// The contact pair whose force is compared. Default: the scene's only pair.
    pub contact: Option<String>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ReferenceKind {
    /// Two equal rods, the slave's body striking the master's (reference::equal_bars_impact).
    Bars,
    /// A rod striking a rigid obstacle (reference::rod_wall_impact).
    RodWall,
    /// An elastic sphere (axisymmetric half disc) striking a rigid obstacle
    /// (reference::hertz_sphere_impact).
    HertzImpact,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub name: String,
    /// Young's modulus E > 0.
    pub young: f64,
    /// Poisson's ratio, -1 < nu < 0.5.
    pub poisson: f64,
    /// Mass density >= 0. Default 0 (statics needs none).
    #[serde(default)]
    pub density: f64,
    /// Initial yield stress > 0: makes the material J2-plastic. Default: none (elastic).
    pub yield_stress: Option<f64>,
    /// Linear isotropic hardening modulus d sigma_y / d eps_p >= 0. Default 0 (perfectly plastic).
    pub hardening_modulus: Option<f64>,
    /// Piecewise-linear isotropic hardening: [eps_p, sigma_y] points after (0, yield_stress),
    /// increasing eps_p. Excludes `hardening_modulus`.
    pub hardening_table: Option<Vec<[f64; 2]>>,
    /// Linear kinematic (Prager) hardening modulus >= 0. Default 0.
    pub kinematic_modulus: Option<f64>,
    /// Johnson-Cook plasticity with adiabatic heating, instead of `yield_stress` and its
    /// hardening keys. Default: none.
    pub johnson_cook: Option<JohnsonCookSpec>,
}

/// `johnson_cook = { ... }`: sigma_y = (a + b eps_p^n) (1 + c ln max(rate /
/// reference_rate, 1)) (1 - T*^m), T* = (T - room_temperature) / (melting_temperature -
/// room_temperature) clamped to [0, 1], heated by dT = taylor_quinney sigma : d eps_p /
/// (density specific_heat).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JohnsonCookSpec {
    /// A > 0 (stress).
    pub a: f64,
    /// B >= 0 (stress).
    pub b: f64,
    /// n > 0.
    pub n: f64,
    /// C >= 0. Default 0 (rate-independent).
    #[serde(default)]
    pub c: f64,
    /// The reference equivalent plastic strain rate > 0 (1 / time). Default 1.
    #[serde(default = "default_reference_rate")]
    pub reference_rate: f64,
    /// m > 0.
    pub m: f64,
    pub room_temperature: f64,
    /// > room_temperature.
    pub melting_temperature: f64,
    /// c_p > 0 (energy / (mass temperature)).
    pub specific_heat: f64,
    /// The fraction of the plastic work that heats, in [0, 1]. Default 0.9.
    #[serde(default = "default_taylor_quinney")]
    pub taylor_quinney: f64,
    /// Below melting_temperature. Default room_temperature.
    pub initial_temperature: Option<f64>,
}

fn default_reference_rate() -> f64 {
    1.0
}

fn default_taylor_quinney() -> f64 {
    0.9
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FormulationSpec {
    PlaneStrain,
    PlaneStress,
    Axisymmetric,
    Rod,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    pub name: String,
    /// Name of a `[[material]]`.
    pub material: String,
    pub formulation: FormulationSpec,
    /// Out-of-plane thickness, plane stress only. Default 1.
    pub thickness: Option<f64>,
    /// Cross-section area, rods only (required there).
    pub area: Option<f64>,
    /// Mean-dilatation B-bar (plane strain and axisymmetric only). Default: true for J2
    /// materials (plastic flow is isochoric and would lock), false otherwise.
    pub bbar: Option<bool>,
    /// Initial Cauchy stress [xx, yy, zz, xy] in every point. Default zero.
    pub initial_stress: Option<[f64; 4]>,
    /// Initial velocity [vx, vy] of every node (dynamic analyses). Default zero.
    pub velocity: Option<[f64; 2]>,
    pub mesh: MeshSpec,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Component {
    X,
    Y,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupportSpec {
    /// The body; may be left out when the scene has one body.
    pub body: Option<String>,
    /// A node set of that body.
    pub set: String,
    /// The fixed components: ["x", "y"] fixes the nodes, ["x"] or ["y"] is a roller.
    pub fix: Vec<Component>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum LoadSpec {
    NodalForce(NodalForceSpec),
    Traction(TractionSpec),
    Pressure(PressureSpec),
    Displacement(DisplacementSpec),
    Rotation(RotationSpec),
    Affine(AffineSpec),
}

/// The same force on each node of a node set.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodalForceSpec {
    pub body: Option<String>,
    pub set: String,
    pub force: [f64; 2],
    pub curve: Option<String>,
}

/// A dead traction (force per unit reference area) on an edge set.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TractionSpec {
    pub body: Option<String>,
    pub set: String,
    pub traction: [f64; 2],
    pub curve: Option<String>,
}

/// A pressure on an edge set, normal to the edges at the start of each increment; positive
/// pushes into the body.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PressureSpec {
    pub body: Option<String>,
    pub set: String,
    pub pressure: f64,
    pub curve: Option<String>,
}

/// Prescribed displacement components of a node set (the total value, times the curve).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DisplacementSpec {
    pub body: Option<String>,
    pub set: String,
    pub x: Option<f64>,
    pub y: Option<f64>,
    pub curve: Option<String>,
}

/// A prescribed rigid rotation of a node set about `center` by `angle` radians (times the
/// curve), counter-clockwise positive.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotationSpec {
    pub body: Option<String>,
    pub set: String,
    pub center: [f64; 2],
    pub angle: f64,
    pub curve: Option<String>,
}

/// A prescribed affine displacement field u(X) = offset + gradient X (initial coordinates X,
/// times the curve) on a node set: a homogeneous deformation for patch tests and cells.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AffineSpec {
    pub body: Option<String>,
    pub set: String,
    /// [[du_x/dX, du_x/dY], [du_y/dX, du_y/dY]]
    pub gradient: [[f64; 2]; 2],
    /// Default [0, 0].
    pub offset: Option<[f64; 2]>,
    pub curve: Option<String>,
}

/// A rigid obstacle: a fixed polyline with the solid on its left (counter-clockwise closed
/// polygon: a finite obstacle; clockwise: a cavity; open: the boundary of a half-space).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSpec {
    pub name: String,
    pub points: Vec<[f64; 2]>,
    /// Default false.
    #[serde(default)]
    pub closed: bool,
}

/// A surface of a body: a node set (slaves, node-to-node masters) or an edge set (masters).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSpec {
    pub body: Option<String>,
    pub set: String,
    /// Node-to-node masters only: the master's outward unit normal.
    pub normal: Option<[f64; 2]>,
}

/// A contact pair: slave nodes against a master surface of a body or a rigid obstacle.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    pub name: String,
    pub slave: SurfaceSpec,
    /// A master surface (an edge set, or a node set with `normal`); or give `obstacle`.
    pub master: Option<SurfaceSpec>,
    /// The name of an `[[obstacle]]`.
    pub obstacle: Option<String>,
    /// The impact conditions II-8 of Hughes, Taylor & Sackman (1975) when a pair closes.
    /// Default true.
    #[serde(default = "yes")]
    pub impact_conditions: bool,
    /// The release conditions II-11, II-12 of Hughes, Taylor & Sackman (1975) when a pair
    /// opens. Default true.
    #[serde(default = "yes")]
    pub release_conditions: bool,
    /// Release when the force falls below this fraction of the last step's. Default 0.02.
    #[serde(default = "default_release_fraction")]
    pub release_fraction: f64,
    /// TOL of Hughes, Taylor & Sackman (1975) II-7 (length). Default 1e-9 of the model's size.
    pub tolerance: Option<f64>,
    /// Slaves farther than this from the master are skipped (length). Default: no limit.
    pub search_distance: Option<f64>,
    /// Split a step at the first contact event inside it (Erklig, Guzelbey & Cevik 2010,
    /// section 2.1.4). Default true.
    #[serde(default = "yes")]
    pub split_at_events: bool,
    /// Coulomb friction coefficient mu (stick/slip). Default: frictionless.
    pub friction: Option<f64>,
    /// The return coefficient R in [0, 1] of Greco & Coda (2003) (eq 36), instead of
    /// `friction`.
    pub return_coefficient: Option<f64>,
}

fn yes() -> bool {
    true
}

fn default_release_fraction() -> f64 {
    0.02
}

/// A node set defined in the scene (for probes, supports, loads): the node nearest a point,
/// or all nodes inside a box. Added to the body's sets under `name`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodeSetSpec {
    pub name: String,
    pub body: Option<String>,
    /// The single node nearest this point.
    pub nearest: Option<[f64; 2]>,
    /// All nodes with xmin <= x <= xmax and ymin <= y <= ymax: [xmin, ymin, xmax, ymax].
    #[serde(rename = "box")]
    pub bounds: Option<[f64; 4]>,
}

/// An initial velocity for the nodes of a set (after the bodies' own `velocity`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialVelocitySpec {
    pub body: Option<String>,
    pub set: String,
    pub velocity: [f64; 2],
}

/// A piecewise-linear load curve, constant beyond its ends.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurveSpec {
    pub name: String,
    /// [time, factor] pairs with increasing times.
    pub points: Vec<[f64; 2]>,
}

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

/// Consistent (sum rho N^T N over the initial configuration) or lumped (row sums) mass.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MassKind {
    #[default]
    Consistent,
    Lumped,
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
    /// `dt = "auto"`: the run stops (status `diverged`) when the step would fall below this
    /// (a time). Default: no limit.
    pub dt_min: Option<f64>,
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
    /// `consistent` (default for implicit) or `lumped` (always for central difference).
    pub mass: Option<MassKind>,
    /// Rayleigh damping C = a M + b K (K: the tangent at the start of the step). Default [0, 0].
    pub rayleigh: Option<[f64; 2]>,
    /// Central difference: run even if dt exceeds the critical step, and report the blow-up
    /// as status `unstable`. Default false (refused).
    #[serde(default)]
    pub allow_unstable: bool,
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

/// The time step of a dynamic analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeStep {
    /// The same step throughout (the last one shorter to end at `end_time`).
    Fixed(f64),
    /// `scale` times the critical step of the current configuration, every step; the run
    /// stops when it would fall below `min`.
    Auto { scale: f64, min: Option<f64> },
}

impl DynamicSpec {
    /// The fixed step (every implicit analysis has one; scene validation refuses `auto`
    /// for them).
    pub fn fixed_dt(&self) -> Option<f64> {
        match self.step {
            TimeStep::Fixed(dt) => Some(dt),
            TimeStep::Auto { .. } => None,
        }
    }

    /// The step of an implicit analysis.
    pub fn dt(&self) -> f64 {
        self.fixed_dt()
            .expect("implicit analyses have a fixed step (checked by the scene)")
    }
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

/// The validated dynamic analysis.
#[derive(Debug, Clone)]
pub struct DynamicSpec {
    pub step: TimeStep,
    pub end_time: f64,
    pub integrator: IntegratorKind,
    pub beta: f64,
    pub gamma: f64,
    pub theta: f64,
    pub alpha: f64,
    pub rho_infinity: f64,
    pub mass: MassKind,
    pub rayleigh: [f64; 2],
    pub allow_unstable: bool,
    pub geometry: Strain,
    pub newton: NewtonSpec,
    pub buckling: Option<BucklingSpec>,
    /// Central difference's Quad4 kernel (always `full` for the implicit integrators).
    pub quadrature: Quadrature,
    /// The hourglass coefficient kappa of the reduced kernel (0.1 unless given).
    pub hourglass: f64,
}

/// The validated static analysis.
#[derive(Debug, Clone)]
pub struct StaticSpec {
    pub steps: usize,
    pub end_time: f64,
    pub geometry: Strain,
    pub newton: NewtonSpec,
    pub buckling: Option<BucklingSpec>,
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
    /// Modified Newton refactors when ||R_k|| > contraction ||R_k-1||. Default 0.8.
    #[serde(default = "default_contraction")]
    pub contraction: f64,
    /// Halvings of an increment that does not converge before the run stops `diverged`. Default 6.
    #[serde(default = "default_cuts")]
    pub max_cuts: usize,
    /// Modified Newton: factor at the start of every N-th increment. Default 1.
    #[serde(default = "default_refactor_every")]
    pub refactor_every: usize,
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
            refactor_every: default_refactor_every(),
        }
    }
}

fn default_iterations() -> usize {
    30
}
fn default_tolerance() -> f64 {
    1e-8
}
fn default_contraction() -> f64 {
    0.8
}
fn default_cuts() -> usize {
    6
}
fn default_refactor_every() -> usize {
    1
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Write a VTK frame every N steps (and always the first and last). 0 writes none. Default 1.
    #[serde(default = "default_frame_every")]
    pub frame_every: usize,
    /// Times at which a frame is written besides (dynamic steps end exactly there).
    #[serde(default)]
    pub frame_times: Vec<f64>,
    /// `none` (default), `lz4` or `zlib` for the .vtu arrays.
    #[serde(default)]
    pub compression: Compression,
    /// Where the frames' points are: `current` (default) or `reference`.
    #[serde(default)]
    pub points: FramePoints,
    #[serde(default)]
    pub probe: Vec<ProbeSpec>,
}

/// The configuration a frame's points show; the `displacement` and `reference_coordinates`
/// arrays are written either way.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FramePoints {
    /// The deformed configuration: the mesh moves as the series plays.
    #[default]
    Current,
    /// The initial coordinates, for Warp By Vector on `displacement` with a scale factor.
    Reference,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            frame_every: default_frame_every(),
            frame_times: Vec::new(),
            compression: Compression::default(),
            points: FramePoints::default(),
            probe: Vec::new(),
        }
    }
}

fn default_frame_every() -> usize {
    1
}

/// A probed quantity; the name in the scene and in history.csv is the serde name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum Quantity {
    #[serde(rename = "u_x")]
    DisplacementX,
    #[serde(rename = "u_y")]
    DisplacementY,
    #[serde(rename = "v_x")]
    VelocityX,
    #[serde(rename = "v_y")]
    VelocityY,
    #[serde(rename = "a_x")]
    AccelerationX,
    #[serde(rename = "a_y")]
    AccelerationY,
    /// Linear momentum sum m v of the set (lumped mass), not a mean.
    #[serde(rename = "p_x")]
    MomentumX,
    #[serde(rename = "p_y")]
    MomentumY,
    #[serde(rename = "s_xx")]
    StressXX,
    #[serde(rename = "s_yy")]
    StressYY,
    #[serde(rename = "s_xy")]
    StressXY,
    #[serde(rename = "s_zz")]
    StressZZ,
    #[serde(rename = "von_mises")]
    VonMises,
    #[serde(rename = "eq_plastic_strain")]
    EqPlasticStrain,
    /// Johnson-Cook materials only.
    #[serde(rename = "temperature")]
    Temperature,
}

impl Quantity {
    /// The name used in scenes and history.csv.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::DisplacementX => "u_x",
            Quantity::DisplacementY => "u_y",
            Quantity::VelocityX => "v_x",
            Quantity::VelocityY => "v_y",
            Quantity::AccelerationX => "a_x",
            Quantity::AccelerationY => "a_y",
            Quantity::MomentumX => "p_x",
            Quantity::MomentumY => "p_y",
            Quantity::StressXX => "s_xx",
            Quantity::StressYY => "s_yy",
            Quantity::StressXY => "s_xy",
            Quantity::StressZZ => "s_zz",
            Quantity::VonMises => "von_mises",
            Quantity::EqPlasticStrain => "eq_plastic_strain",
            Quantity::Temperature => "temperature",
        }
    }

    /// Nodal quantities are averaged over node sets, the others over element sets.
    pub fn is_nodal(self) -> bool {
        matches!(
            self,
            Quantity::DisplacementX
                | Quantity::DisplacementY
                | Quantity::VelocityX
                | Quantity::VelocityY
                | Quantity::AccelerationX
                | Quantity::AccelerationY
                | Quantity::MomentumX
                | Quantity::MomentumY
        )
    }
}

/// A history column: the mean of a nodal quantity over a node set, or of a stress quantity
/// over an element set. Written as `QUANTITY[SET]` (`QUANTITY[BODY.SET]` with several bodies).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    pub quantity: Quantity,
    pub body: Option<String>,
    pub set: String,
    /// How the set's values combine: `mean` (default; momentum: the sum), `max` or `min`
    /// (over nodes, or over the elements' integration points).
    #[serde(default)]
    pub statistic: Statistic,
}

/// How a probe combines the values of its set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Statistic {
    #[default]
    Mean,
    Max,
    Min,
}
