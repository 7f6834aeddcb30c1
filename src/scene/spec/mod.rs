//! The scene file's schema. Each struct denies unknown fields; each enum variant wraps its own
//! struct so unknown keys are caught inside internally tagged enums too (`deny_unknown_fields`
//! on such an enum itself does not reach its variants' keys).

use crate::mesh::MeshSpec;
use serde::Deserialize;

mod analysis;
mod output;

pub use analysis::*;
pub use output::*;

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

/// A rigid obstacle: a polyline with the solid on its left (counter-clockwise closed
/// polygon: a finite obstacle; clockwise: a cavity; open: the boundary of a half-space).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSpec {
    pub name: String,
    pub points: Vec<[f64; 2]>,
    /// Default false.
    #[serde(default)]
    pub closed: bool,
    /// Each corner rounded by an arc of this radius (a length) tangent to its two segments
    /// (`mesh::plane::round_corners`); default none: sharp corners.
    pub corner_radius: Option<f64>,
    /// A prescribed rigid translation; default none: the obstacle does not move.
    pub motion: Option<ObstacleMotionSpec>,
    /// A rigid projectile: the obstacle has a mass and an initial velocity and translates
    /// under the contact forces (central difference); default none.
    pub projectile: Option<ProjectileSpec>,
}

/// A rigid projectile's mass (as the bodies' lumped masses count it: per unit depth in plane
/// strain, through the thickness in plane stress, the full ring in axisymmetry) and its
/// initial velocity.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProjectileSpec {
    pub mass: f64,
    #[serde(default)]
    pub velocity: [f64; 2],
    /// The moment of inertia about `centre`; default none: the projectile translates only.
    pub inertia: Option<f64>,
    /// The angular velocity at t = 0 (rad per time, counter-clockwise); default 0.
    pub angular_velocity: Option<f64>,
    /// The centre of mass; default the centroid of a closed polygon.
    pub centre: Option<[f64; 2]>,
}

/// An obstacle's prescribed translation: `displacement` times the curve (default: a ramp
/// from 0 at t = 0 to 1 at the end time, a constant speed).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleMotionSpec {
    pub displacement: [f64; 2],
    pub curve: Option<String>,
}

/// A surface of a body: a node set (slaves, node-to-node masters) or an edge set (masters).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSpec {
    pub body: Option<String>,
    /// Default `boundary`: the body's whole exterior, the edge set (and node set) every quad
    /// mesh has, as Abaqus' general contact takes a body's exterior without being told.
    #[serde(default = "whole_boundary")]
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
    /// Slaves farther than this from the master are skipped (length). Default: no limit;
    /// for a balanced pair twice the longest face element of its two surfaces.
    pub search_distance: Option<f64>,
    /// Split a step at the first contact event inside it (Erklig, Guzelbey & Cevik 2010,
    /// section 2.1.4). Default true.
    #[serde(default = "yes")]
    pub split_at_events: bool,
    /// Refuse the pair when its set-up looks wrong at t = 0: slaves that start inside the
    /// master, a node-to-node normal pointing into the master body, a slave body on the
    /// solid side of an obstacle, a slave surface facing away from its master. Default true.
    #[serde(default = "yes")]
    pub setup_check: bool,
    /// Two-pass (symmetric) node-to-segment contact: the master surface's nodes are also
    /// slaves of the slave surface (a second pair `NAME:reverse`), so neither body can sink
    /// into the other whatever the roles. Needs edge sets on both sides. Default false.
    #[serde(default)]
    pub two_pass: bool,
    /// Coulomb friction coefficient mu (stick/slip). Default: frictionless.
    pub friction: Option<f64>,
    /// The return coefficient R in [0, 1] of Greco & Coda (2003) (eq 36), instead of
    /// `friction`.
    pub return_coefficient: Option<f64>,
    /// `node_to_segment` (each slave node against the master) or `mortar` (segment-to-segment:
    /// the gap weighted over the slave surface; a slave and a master edge set on two
    /// deformable bodies). Default: `mortar` for such a pair in a dynamic analysis with one
    /// pass (the implicit integrators, or `roles = "as_written"` or `"automatic"`), and
    /// `node_to_segment` otherwise (a balanced pair's two passes, statics, obstacles,
    /// node-to-node, `two_pass`).
    pub discretization: Option<ContactDiscretization>,
    /// Mortar pairs in dynamics: a master node that the weighted gaps let into the slave body
    /// is held out by a row of its own (where the surfaces fold at the rim of a contact zone):
    /// under central difference in the explicit correction, beyond 0.25 % of the slave
    /// segment it faces; with the implicit integrators by a hold pair `NAME:held` (its own
    /// history column), where the master's edges are not much finer than the slave's
    /// (`mortar::FINER`). Statics holds the weighted gaps alone. Default false.
    pub hold_master_nodes: Option<bool>,
    /// Which surface is the slave of a pair between two bodies' edge sets: `symmetric` (a
    /// balanced pair: each surface the slave of the other in a pass of its own, node to
    /// segment, the explicit correction the mean of the two; the default under central
    /// difference, refused elsewhere), `automatic` (one pass, the slave chosen by the code:
    /// the default on the implicit and static paths) or `as_written` (one pass: the slave
    /// set the slave).
    pub roles: Option<Roles>,
}

/// Whether a pair between two bodies checks both surfaces or the slave's alone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Roles {
    /// Both surfaces are slaves of the other (two node-to-segment passes, each solved on its
    /// own, their corrections averaged).
    Symmetric,
    /// The slave set is the slave, the master set the master (one pass).
    AsWritten,
    /// One pass, the slave chosen by the code: the shorter surface, else the finer, else the
    /// body listed later (`scene::roles`); the default on the implicit and static paths.
    Automatic,
}

/// How a contact pair's constraints are discretized.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactDiscretization {
    /// Each slave node against the nearest master point (Hughes et al. 1975, II-13..16).
    NodeToSegment,
    /// Segment-to-segment: a weighted gap per slave node over its slave segments (Puso &
    /// Laursen 2004; Yang, Laursen & Meng 2005).
    Mortar,
}

fn whole_boundary() -> String {
    "boundary".to_string()
}

pub(super) fn yes() -> bool {
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
