//! The validated model: bodies with meshes and materials placed in one global node numbering,
//! supports as constrained DOFs, loads resolved to global nodes, curves resolved.
//!
//! Global numbering: body b's node i is global node `node_offset[b] + i`; DOF `2 n + c`
//! (c = 0 for x / r, 1 for y / z).

use super::InputError;
use super::spec::{
    AnalysisKind, AnalysisSpec, BodySpec, BucklingSpec, Component, ContactSpec, DynamicSpec,
    FormulationSpec, IntegratorKind, LoadSpec, MassKind, MaterialSpec, NewtonSpec, NodeSetSpec,
    OutputSpec, ProbeSpec, Quadrature, Quantity, ReferenceKind, ReferenceSpec, Scene, StaticSpec,
    Statistic,
};
use crate::contact::{ContactPair, Friction, Master, Obstacle, PairOptions};
use crate::element::{Formulation, Strain, Voigt, quad4, rod2};
use crate::material::{Elastic, Hardening, J2, Material};
use crate::mesh::{Cells, Mesh};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

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
}

impl Body {
    pub fn global(&self, node: usize) -> usize {
        self.node_offset + node
    }

    pub fn elements(&self) -> usize {
        self.mesh.cells.len()
    }

    /// Material points per element: 4 for Quad4, 1 for rods.
    pub fn points_per_element(&self) -> usize {
        match self.kind {
            BodyKind::Continuum { .. } => 4,
            BodyKind::Rod { .. } => 1,
        }
    }
}

/// A piecewise-linear curve, constant beyond its ends.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    pub points: Vec<[f64; 2]>,
}

impl Curve {
    pub fn value(&self, t: f64) -> f64 {
        let p = &self.points;
        if t <= p[0][0] {
            return p[0][1];
        }
        for w in p.windows(2) {
            if t <= w[1][0] {
                let s = (t - w[0][0]) / (w[1][0] - w[0][0]);
                return w[0][1] + s * (w[1][1] - w[0][1]);
            }
        }
        p[p.len() - 1][1]
    }
}

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
}

#[derive(Debug, Clone)]
pub enum Analysis {
    Static(StaticSpec),
    Dynamic(DynamicSpec),
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
    pub fn dofs(&self) -> usize {
        2 * self.node_count
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
}

struct Context<'a> {
    file: &'a Path,
}

impl Context<'_> {
    fn err(&self, message: impl Into<String>) -> InputError {
        InputError::new(self.file, message)
    }
}

pub fn build(scene: Scene, file: &Path, base_dir: &Path) -> Result<Model, InputError> {
    let cx = Context { file };
    let materials = materials(&cx, &scene)?;
    let mut bodies = Vec::new();
    let mut node_count = 0;
    for (b, spec) in scene.body.iter().enumerate() {
        if scene.body[..b].iter().any(|o| o.name == spec.name) {
            return Err(cx.err(format!("body[{b}]: the name `{}` is used twice", spec.name)));
        }
        let body = body(&cx, spec, &materials, base_dir, node_count)?;
        node_count += body.mesh.nodes.len();
        bodies.push(body);
    }
    if bodies.is_empty() {
        return Err(cx.err("the scene has no [[body]]"));
    }
    for (k, spec) in scene.node_set.iter().enumerate() {
        add_node_set(&cx, &mut bodies, k, spec)?;
    }
    let analysis = analysis(&cx, &scene.analysis)?;
    let curves = curves(&cx, &scene)?;
    let default_curve = match &analysis {
        // statics ramps the loads up over the run; dynamics applies them at once (a step)
        Analysis::Static(s) => Curve {
            points: vec![[0.0, 0.0], [s.end_time, 1.0]],
        },
        Analysis::Dynamic(_) => Curve {
            points: vec![[0.0, 1.0]],
        },
    };
    let mut fixed_dofs = Vec::new();
    for (k, s) in scene.support.iter().enumerate() {
        let key = format!("support[{k}]");
        let (b, nodes) = node_set(&cx, &bodies, s.body.as_deref(), &s.set, &key)?;
        if s.fix.is_empty() {
            return Err(cx.err(format!("{key}.fix: list at least one of \"x\", \"y\"")));
        }
        for n in nodes {
            for c in &s.fix {
                fixed_dofs.push(2 * bodies[b].global(n) + (*c == Component::Y) as usize);
            }
        }
    }
    fixed_dofs.sort_unstable();
    fixed_dofs.dedup();
    let loads = scene
        .load
        .iter()
        .enumerate()
        .map(|(k, l)| load(&cx, &bodies, &curves, &default_curve, k, l))
        .collect::<Result<Vec<_>, _>>()?;
    let probes = probes(&cx, &bodies, &scene.output.probe)?;
    let times = &scene.output.frame_times;
    if times.iter().any(|t| !(t.is_finite() && *t >= 0.0)) || times.windows(2).any(|w| w[1] <= w[0])
    {
        return Err(cx.err(format!(
            "output.frame_times: must be finite, >= 0 and increasing, got {times:?}"
        )));
    }
    let obstacles = obstacles(&cx, &scene)?;
    let contacts = scene
        .contact
        .iter()
        .enumerate()
        .map(|(k, c)| contact(&cx, &bodies, &obstacles, k, c))
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(k) =
        (0..contacts.len()).find(|k| contacts[..*k].iter().any(|c| c.name == contacts[*k].name))
    {
        return Err(cx.err(format!(
            "contact[{k}].name: `{}` is used twice",
            contacts[k].name
        )));
    }
    if let Analysis::Dynamic(d) = &analysis
        && d.quadrature == Quadrature::Reduced
        && let Some(body) = bodies.iter().find(|b| {
            !matches!(
                b.kind,
                BodyKind::Continuum {
                    formulation: Formulation::PlaneStrain | Formulation::PlaneStress,
                    ..
                }
            )
        })
    {
        return Err(cx.err(format!(
            "analysis.quadrature: `reduced` covers plane-strain and plane-stress Quad4 bodies; body `{}` is {}: use quadrature = \"full\"",
            body.name,
            match body.kind {
                BodyKind::Rod { .. } => "a rod",
                _ => "axisymmetric",
            }
        )));
    }
    if let Analysis::Dynamic(d) = &analysis
        && d.integrator == crate::scene::spec::IntegratorKind::CentralDifference
        && let Some(c) = contacts
            .iter()
            .find(|c| c.options.friction != Friction::None)
    {
        return Err(cx.err(format!(
            "contact `{}`: friction is implemented for the implicit integrators and statics; the explicit central difference contact is frictionless",
            c.name
        )));
    }
    let mut initial_velocity = vec![0.0; 2 * node_count];
    for body in &bodies {
        for n in 0..body.mesh.nodes.len() {
            initial_velocity[2 * body.global(n)] = body.velocity[0];
            initial_velocity[2 * body.global(n) + 1] = body.velocity[1];
        }
    }
    for (k, v) in scene.initial_velocity.iter().enumerate() {
        let key = format!("initial_velocity[{k}]");
        finite(&cx, &format!("{key}.velocity"), &v.velocity)?;
        let (b, nodes) = node_set(&cx, &bodies, v.body.as_deref(), &v.set, &key)?;
        for n in nodes {
            initial_velocity[2 * bodies[b].global(n)] = v.velocity[0];
            initial_velocity[2 * bodies[b].global(n) + 1] = v.velocity[1];
        }
    }
    for (b, spec) in scene.body.iter().enumerate() {
        if let Some(v) = spec.velocity {
            finite(&cx, &format!("body `{}`.velocity", bodies[b].name), &v)?;
        }
    }
    let reference = match &scene.reference {
        Some(spec) => Some(reference(&cx, &bodies, &contacts, spec)?),
        None => None,
    };
    let name = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    Ok(Model {
        name,
        file: file.to_path_buf(),
        title: scene.title,
        bodies,
        node_count,
        fixed_dofs,
        loads,
        analysis,
        output: scene.output,
        probes,
        initial_velocity,
        reference,
        contacts,
        checkpoint_every: scene.analysis.checkpoint_every,
        source: SceneSource::default(),
    })
}

/// Reads the numbers of a `[reference]` from the model: the pair's slave body (and master
/// body for `bars`), their material, section, length and initial velocities.
fn reference(
    cx: &Context,
    bodies: &[Body],
    contacts: &[ContactPair],
    spec: &ReferenceSpec,
) -> Result<Reference, InputError> {
    let pair = match &spec.contact {
        Some(name) => contacts
            .iter()
            .find(|c| &c.name == name)
            .ok_or_else(|| cx.err(format!("reference.contact: no contact pair named `{name}`")))?,
        None if contacts.len() == 1 => &contacts[0],
        None => {
            return Err(cx.err(format!(
                "reference.contact: the scene has {} contact pairs; name the one the reference speaks of",
                contacts.len()
            )));
        }
    };
    let kind_name = match spec.kind {
        ReferenceKind::Bars => "bars",
        ReferenceKind::RodWall => "rod_wall",
        ReferenceKind::HertzImpact => "hertz_impact",
    };
    let wrong = |what: &str| {
        cx.err(format!(
            "reference.kind = \"{kind_name}\" needs {what} (contact pair `{}`)",
            pair.name
        ))
    };
    let rod = |b: usize| -> Option<(f64, f64, f64, f64)> {
        let body = &bodies[b];
        let BodyKind::Rod { area } = body.kind else {
            return None;
        };
        let Cells::Rod2(cells) = &body.mesh.cells else {
            return None;
        };
        let length: f64 = cells
            .iter()
            .map(|[i, j]| {
                let (a, b) = (body.mesh.nodes[*i], body.mesh.nodes[*j]);
                (b[0] - a[0]).hypot(b[1] - a[1])
            })
            .sum();
        Some((
            body.material.density,
            body.material.elastic.young,
            area,
            length,
        ))
    };
    let speed = |v: [f64; 2]| v[0].hypot(v[1]);
    let slave = &bodies[pair.slave_body];
    match spec.kind {
        ReferenceKind::Bars => {
            let master = match &pair.master {
                Master::Segments { body, .. } | Master::Nodes { body, .. } => *body,
                Master::Obstacle(_) => return Err(wrong("a rod as master, not an obstacle")),
            };
            let (Some(a), Some(b)) = (rod(pair.slave_body), rod(master)) else {
                return Err(wrong("two rods"));
            };
            let same = |x: f64, y: f64| (x - y).abs() <= 1e-9 * x.abs().max(y.abs());
            if !(same(a.0, b.0) && same(a.1, b.1) && same(a.2, b.2) && same(a.3, b.3)) {
                return Err(wrong(
                    "two equal rods (same density, Young's modulus, area and length)",
                ));
            }
            let v = bodies[master].velocity;
            let relative = [slave.velocity[0] - v[0], slave.velocity[1] - v[1]];
            let (force, duration) =
                crate::reference::equal_bars_impact(a.0, a.1, a.2, a.3, speed(relative));
            Ok(Reference::ForcePulse {
                kind: spec.kind,
                pair: pair.name.clone(),
                force,
                duration,
            })
        }
        ReferenceKind::RodWall => {
            if !matches!(pair.master, Master::Obstacle(_)) {
                return Err(wrong("a rigid obstacle as master"));
            }
            let (density, young, area, length) =
                rod(pair.slave_body).ok_or_else(|| wrong("a rod as slave body"))?;
            let (force, duration) = crate::reference::rod_wall_impact(
                density,
                young,
                area,
                length,
                speed(slave.velocity),
            );
            Ok(Reference::ForcePulse {
                kind: spec.kind,
                pair: pair.name.clone(),
                force,
                duration,
            })
        }
        ReferenceKind::HertzImpact => {
            if !matches!(pair.master, Master::Obstacle(_)) {
                return Err(wrong("a rigid obstacle as master"));
            }
            if !matches!(
                slave.kind,
                BodyKind::Continuum {
                    formulation: Formulation::Axisymmetric,
                    ..
                }
            ) {
                return Err(wrong("an axisymmetric sphere (half disc) as slave body"));
            }
            // the half disc spans the sphere's diameter along the axis
            let (low, high) = slave
                .mesh
                .nodes
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                    (l.min(p[1]), h.max(p[1]))
                });
            let (radius, duration, peak_force) = crate::reference::hertz_sphere_impact(
                0.5 * (high - low),
                slave.material.density,
                slave.material.elastic.young,
                slave.material.elastic.poisson,
                speed(slave.velocity),
            );
            Ok(Reference::Hertz {
                pair: pair.name.clone(),
                peak_force,
                radius,
                duration,
            })
        }
    }
}

fn positive(cx: &Context, key: &str, value: f64) -> Result<f64, InputError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(cx.err(format!("{key}: must be a positive number, got {value}")))
    }
}

fn materials(cx: &Context, scene: &Scene) -> Result<BTreeMap<String, Material>, InputError> {
    let mut out = BTreeMap::new();
    for (k, m) in scene.material.iter().enumerate() {
        let key = format!("material[{k}] (`{}`)", m.name);
        positive(cx, &format!("{key}.young"), m.young)?;
        if !(m.poisson > -1.0 && m.poisson < 0.5) {
            return Err(cx.err(format!(
                "{key}.poisson: must lie in (-1, 0.5), got {}",
                m.poisson
            )));
        }
        if !(m.density >= 0.0 && m.density.is_finite()) {
            return Err(cx.err(format!("{key}.density: must be >= 0, got {}", m.density)));
        }
        let material = Material {
            name: m.name.clone(),
            density: m.density,
            elastic: Elastic {
                young: m.young,
                poisson: m.poisson,
            },
            plasticity: plasticity(cx, &key, m)?,
        };
        if out.insert(m.name.clone(), material).is_some() {
            return Err(cx.err(format!("{key}.name: `{}` is used twice", m.name)));
        }
    }
    Ok(out)
}

fn plasticity(cx: &Context, key: &str, m: &MaterialSpec) -> Result<Option<J2>, InputError> {
    let Some(yield_stress) = m.yield_stress else {
        for (present, name) in [
            (m.hardening_modulus.is_some(), "hardening_modulus"),
            (m.hardening_table.is_some(), "hardening_table"),
            (m.kinematic_modulus.is_some(), "kinematic_modulus"),
        ] {
            if present {
                return Err(cx.err(format!(
                    "{key}.{name}: needs `yield_stress` (an elastic material does not harden)"
                )));
            }
        }
        return Ok(None);
    };
    positive(cx, &format!("{key}.yield_stress"), yield_stress)?;
    let non_negative = |name: &str, v: Option<f64>| -> Result<f64, InputError> {
        let v = v.unwrap_or(0.0);
        if v >= 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(cx.err(format!("{key}.{name}: must be >= 0, got {v}")))
        }
    };
    let hardening = match (&m.hardening_table, m.hardening_modulus) {
        (Some(_), Some(_)) => {
            return Err(cx.err(format!(
                "{key}: give `hardening_modulus` or `hardening_table`, not both"
            )));
        }
        (Some(points), None) => {
            let mut previous = [0.0, yield_stress];
            for (i, p) in points.iter().enumerate() {
                if !(p[0] > previous[0] && p[1].is_finite() && p[0].is_finite()) {
                    return Err(cx.err(format!(
                        "{key}.hardening_table[{i}]: eps_p must increase from 0 (got {} after {})",
                        p[0], previous[0]
                    )));
                }
                if p[1] <= 0.0 {
                    return Err(cx.err(format!(
                        "{key}.hardening_table[{i}]: sigma_y must stay positive"
                    )));
                }
                previous = *p;
            }
            if points.is_empty() {
                return Err(cx.err(format!(
                    "{key}.hardening_table: give at least one [eps_p, sigma_y] point"
                )));
            }
            Hardening::Table {
                points: points.clone(),
            }
        }
        (None, h) => Hardening::Linear {
            modulus: non_negative("hardening_modulus", h)?,
        },
    };
    Ok(Some(J2 {
        yield_stress,
        hardening,
        kinematic_modulus: non_negative("kinematic_modulus", m.kinematic_modulus)?,
    }))
}

fn body(
    cx: &Context,
    spec: &BodySpec,
    materials: &BTreeMap<String, Material>,
    base_dir: &Path,
    node_offset: usize,
) -> Result<Body, InputError> {
    let key = format!("body `{}`", spec.name);
    let material = materials.get(&spec.material).cloned().ok_or_else(|| {
        let known: Vec<&String> = materials.keys().collect();
        cx.err(format!(
            "{key}.material: no material named `{}` (known: {known:?})",
            spec.material
        ))
    })?;
    let mut mesh = spec
        .mesh
        .build(base_dir)
        .map_err(|e| cx.err(format!("{key}.mesh: {e}")))?;
    if !mesh.node_sets.contains_key("all") {
        mesh.add_node_set("all", (0..mesh.nodes.len()).collect());
    }
    let is_rod = spec.formulation == FormulationSpec::Rod;
    if spec.thickness.is_some() && spec.formulation != FormulationSpec::PlaneStress {
        return Err(cx.err(format!(
            "{key}.thickness: only plane_stress bodies have a thickness"
        )));
    }
    if spec.area.is_some() && !is_rod {
        return Err(cx.err(format!("{key}.area: only rod bodies have an area")));
    }
    let plastic = material.plasticity.is_some()
        && matches!(
            spec.formulation,
            FormulationSpec::PlaneStrain | FormulationSpec::Axisymmetric
        );
    let bbar = spec.bbar.unwrap_or(plastic);
    if bbar
        && matches!(
            spec.formulation,
            FormulationSpec::PlaneStress | FormulationSpec::Rod
        )
    {
        return Err(cx.err(format!(
            "{key}.bbar: B-bar applies to plane_strain and axisymmetric bodies only"
        )));
    }
    let kind = match spec.formulation {
        FormulationSpec::Rod => {
            let area = spec.area.ok_or_else(|| {
                cx.err(format!(
                    "{key}.area: a rod body needs its cross-section area"
                ))
            })?;
            BodyKind::Rod {
                area: positive(cx, &format!("{key}.area"), area)?,
            }
        }
        f => {
            let formulation = match f {
                FormulationSpec::PlaneStrain => Formulation::PlaneStrain,
                FormulationSpec::PlaneStress => Formulation::PlaneStress,
                _ => Formulation::Axisymmetric,
            };
            let thickness = positive(
                cx,
                &format!("{key}.thickness"),
                spec.thickness.unwrap_or(1.0),
            )?;
            BodyKind::Continuum {
                formulation,
                bbar,
                thickness,
            }
        }
    };
    check_cells(cx, &key, &mesh, &kind)?;
    let initial_stress = Voigt::from(spec.initial_stress.unwrap_or([0.0; 4]));
    let mut boundary_at_node = vec![Vec::new(); mesh.nodes.len()];
    for edge in mesh.boundary_edges() {
        for node in edge {
            boundary_at_node[node].push(edge);
        }
    }
    Ok(Body {
        name: spec.name.clone(),
        boundary_at_node,
        mesh,
        kind,
        material,
        node_offset,
        initial_stress,
        velocity: spec.velocity.unwrap_or([0.0; 2]),
    })
}

/// Every element of the initial mesh must be valid: det J > 0 at the Gauss points, r > 0 in
/// axisymmetry, rods of non-zero length, and cells of the kind the formulation needs.
fn check_cells(cx: &Context, key: &str, mesh: &Mesh, kind: &BodyKind) -> Result<(), InputError> {
    if mesh.nodes.iter().flatten().any(|c| !c.is_finite()) {
        return Err(cx.err(format!("{key}.mesh: a node coordinate is not finite")));
    }
    match (&mesh.cells, kind) {
        (Cells::Quad4(quads), BodyKind::Continuum { formulation, .. }) => {
            for (e, q) in quads.iter().enumerate() {
                let x = q.map(|n| mesh.nodes[n]);
                quad4::values(&x, *formulation, &[1.0; 4]).map_err(|err| {
                    cx.err(format!(
                        "{key}: element {e} (nodes {q:?}) is invalid: {err}"
                    ))
                })?;
            }
        }
        (Cells::Rod2(rods), BodyKind::Rod { .. }) => {
            for (e, r) in rods.iter().enumerate() {
                rod2::length(&r.map(|n| mesh.nodes[n])).map_err(|err| {
                    cx.err(format!(
                        "{key}: element {e} (nodes {r:?}) is invalid: {err}"
                    ))
                })?;
            }
        }
        (Cells::Rod2(_), _) => {
            return Err(cx.err(format!(
                "{key}: the mesh has rods but the formulation is 2D"
            )));
        }
        (Cells::Quad4(_), _) => {
            return Err(cx.err(format!(
                "{key}: the mesh has quads but the formulation is rod"
            )));
        }
    }
    Ok(())
}

fn analysis(cx: &Context, spec: &AnalysisSpec) -> Result<Analysis, InputError> {
    let given = |present: bool, key: &str, kind: &str| {
        if present {
            Err(cx.err(format!(
                "analysis.{key}: does not apply to a {kind} analysis"
            )))
        } else {
            Ok(())
        }
    };
    newton(cx, &spec.newton)?;
    match spec.kind {
        AnalysisKind::Static => {
            given(spec.dt.is_some(), "dt", "static")?;
            given(spec.integrator.is_some(), "integrator", "static")?;
            for (present, key) in [
                (spec.beta.is_some(), "beta"),
                (spec.gamma.is_some(), "gamma"),
                (spec.theta.is_some(), "theta"),
                (spec.alpha.is_some(), "alpha"),
                (spec.rho_infinity.is_some(), "rho_infinity"),
                (spec.mass.is_some(), "mass"),
                (spec.rayleigh.is_some(), "rayleigh"),
                (spec.allow_unstable, "allow_unstable"),
                (spec.quadrature.is_some(), "quadrature"),
                (spec.hourglass.is_some(), "hourglass"),
            ] {
                given(present, key, "static")?;
            }
            let steps = spec.steps.ok_or_else(|| {
                cx.err("analysis.steps: a static analysis needs its number of load steps")
            })?;
            if steps == 0 {
                return Err(cx.err("analysis.steps: must be at least 1"));
            }
            let end_time = positive(cx, "analysis.end_time", spec.end_time.unwrap_or(1.0))?;
            Ok(Analysis::Static(StaticSpec {
                steps,
                end_time,
                geometry: spec.geometry,
                newton: spec.newton.clone(),
                buckling: buckling(cx, spec)?,
            }))
        }
        AnalysisKind::Dynamic => dynamic(cx, spec).map(Analysis::Dynamic),
    }
}

fn dynamic(cx: &Context, spec: &AnalysisSpec) -> Result<DynamicSpec, InputError> {
    if spec.steps.is_some() {
        return Err(cx.err("analysis.steps: a dynamic analysis takes `dt` and `end_time`"));
    }
    let dt = positive(
        cx,
        "analysis.dt",
        spec.dt
            .ok_or_else(|| cx.err("analysis.dt: a dynamic analysis needs its time step"))?,
    )?;
    let end_time = positive(
        cx,
        "analysis.end_time",
        spec.end_time
            .ok_or_else(|| cx.err("analysis.end_time: a dynamic analysis needs its end time"))?,
    )?;
    let integrator = spec.integrator.unwrap_or(IntegratorKind::Average);
    let only_for = |present: bool, key: &str, kinds: &[IntegratorKind]| {
        if present && !kinds.contains(&integrator) {
            Err(cx.err(format!(
                "analysis.{key}: does not apply to integrator {integrator:?}"
            )))
        } else {
            Ok(())
        }
    };
    use IntegratorKind as I;
    only_for(spec.beta.is_some(), "beta", &[I::Newmark])?;
    only_for(spec.gamma.is_some(), "gamma", &[I::Newmark])?;
    only_for(spec.theta.is_some(), "theta", &[I::Wilson])?;
    only_for(spec.alpha.is_some(), "alpha", &[I::Hht])?;
    only_for(
        spec.rho_infinity.is_some(),
        "rho_infinity",
        &[I::GeneralizedAlpha],
    )?;
    only_for(
        spec.allow_unstable,
        "allow_unstable",
        &[I::CentralDifference],
    )?;
    let (beta, gamma) = match integrator {
        I::Average => (0.25, 0.5),
        I::Linear => (1.0 / 6.0, 0.5),
        I::Hu => (1.0, 1.5),
        I::Newmark => (
            spec.beta
                .ok_or_else(|| cx.err("analysis.beta: integrator newmark needs beta"))?,
            spec.gamma
                .ok_or_else(|| cx.err("analysis.gamma: integrator newmark needs gamma"))?,
        ),
        _ => (0.25, 0.5),
    };
    if integrator == I::Newmark && !(beta > 0.0 && gamma >= 0.0) {
        return Err(cx.err(format!(
            "analysis.beta, gamma: need beta > 0 and gamma >= 0, got {beta}, {gamma}"
        )));
    }
    let theta = spec.theta.unwrap_or(1.4);
    if !(theta >= 1.0) {
        return Err(cx.err(format!(
            "analysis.theta: Wilson's theta must be >= 1, got {theta}"
        )));
    }
    let alpha = spec.alpha.unwrap_or(-0.05);
    if !(-1.0 / 3.0..=0.0).contains(&alpha) {
        return Err(cx.err(format!(
            "analysis.alpha: HHT's alpha must lie in [-1/3, 0], got {alpha}"
        )));
    }
    let rho_infinity = spec.rho_infinity.unwrap_or(0.8);
    if !(0.0..=1.0).contains(&rho_infinity) {
        return Err(cx.err(format!(
            "analysis.rho_infinity: must lie in [0, 1], got {rho_infinity}"
        )));
    }
    let mass = match (integrator, spec.mass) {
        (I::CentralDifference, Some(MassKind::Consistent)) => {
            return Err(cx.err("analysis.mass: central difference uses the lumped mass"));
        }
        (I::CentralDifference, _) => MassKind::Lumped,
        (_, m) => m.unwrap_or_default(),
    };
    let rayleigh = spec.rayleigh.unwrap_or([0.0, 0.0]);
    if integrator == I::CentralDifference && rayleigh[1] != 0.0 {
        return Err(cx.err(
            "analysis.rayleigh: central difference takes mass-proportional damping only (b = 0)",
        ));
    }
    if rayleigh.iter().any(|c| !(*c >= 0.0 && c.is_finite())) {
        return Err(cx.err(format!(
            "analysis.rayleigh: coefficients must be >= 0, got {rayleigh:?}"
        )));
    }
    let quadrature = spec.quadrature.unwrap_or_default();
    if quadrature == Quadrature::Reduced {
        if integrator != I::CentralDifference {
            return Err(cx.err(format!(
                "analysis.quadrature: `reduced` (one-point Quad4 with hourglass control) is the explicit fast path; \
                 integrator {integrator:?} needs the tangent of the full 2x2 kernel: use quadrature = \"full\" or integrator = \"central_difference\""
            )));
        }
        if spec.geometry == Strain::Small {
            return Err(cx.err(
                "analysis.quadrature: `reduced` runs the updated-Lagrangian (finite-strain) kernel only; use geometry = \"nonlinear\" or quadrature = \"full\"",
            ));
        }
        if spec.checkpoint_every > 0 {
            return Err(cx.err(
                "analysis.checkpoint_every: checkpoints are not implemented for quadrature = \"reduced\" (its hourglass forces are not in the checkpoint); use quadrature = \"full\" or no checkpoints",
            ));
        }
    }
    let hourglass = match (quadrature, spec.hourglass) {
        (Quadrature::Full, Some(_)) => {
            return Err(cx.err(
                "analysis.hourglass: applies to quadrature = \"reduced\" only (the full 2x2 kernel has no hourglass modes)",
            ));
        }
        (_, Some(k)) if !(0.0..=1.0).contains(&k) => {
            return Err(cx.err(format!(
                "analysis.hourglass: the hourglass coefficient must lie in [0, 1], got {k}"
            )));
        }
        (_, k) => k.unwrap_or(0.1),
    };
    Ok(DynamicSpec {
        quadrature,
        hourglass,
        dt,
        end_time,
        integrator,
        beta,
        gamma,
        theta,
        alpha,
        rho_infinity,
        mass,
        rayleigh,
        allow_unstable: spec.allow_unstable,
        geometry: spec.geometry,
        newton: spec.newton.clone(),
        buckling: buckling(cx, spec)?,
    })
}

fn buckling(cx: &Context, spec: &AnalysisSpec) -> Result<Option<BucklingSpec>, InputError> {
    let Some(b) = &spec.buckling else {
        return Ok(None);
    };
    if spec.integrator == Some(IntegratorKind::CentralDifference) {
        return Err(cx.err(
            "analysis.buckling: the explicit method assembles no tangent; use an implicit integrator",
        ));
    }
    if let Some(imperfection) = &b.imperfection {
        if imperfection.mode == 0 {
            return Err(cx.err("analysis.buckling.imperfection.mode: modes count from 1"));
        }
        if !(imperfection.amplitude.is_finite() && imperfection.amplitude != 0.0) {
            return Err(cx.err(format!(
                "analysis.buckling.imperfection.amplitude: a finite, non-zero length, got {}",
                imperfection.amplitude
            )));
        }
    }
    Ok(Some(b.clone()))
}

fn newton(cx: &Context, n: &NewtonSpec) -> Result<(), InputError> {
    if n.refactor_every == 0 {
        return Err(cx.err("analysis.newton.refactor_every: must be at least 1"));
    }
    if n.max_iterations == 0 {
        return Err(cx.err("analysis.newton.max_iterations: must be at least 1"));
    }
    positive(cx, "analysis.newton.tol_displacement", n.tol_displacement)?;
    positive(cx, "analysis.newton.tol_force", n.tol_force)?;
    if !(n.contraction > 0.0 && n.contraction <= 1.0) {
        return Err(cx.err(format!(
            "analysis.newton.contraction: must lie in (0, 1], got {}",
            n.contraction
        )));
    }
    Ok(())
}

fn curves(cx: &Context, scene: &Scene) -> Result<BTreeMap<String, Curve>, InputError> {
    let mut out = BTreeMap::new();
    for (k, c) in scene.curve.iter().enumerate() {
        let key = format!("curve[{k}] (`{}`)", c.name);
        if c.points.is_empty() {
            return Err(cx.err(format!(
                "{key}.points: give at least one [time, factor] pair"
            )));
        }
        if c.points.iter().flatten().any(|v| !v.is_finite()) {
            return Err(cx.err(format!("{key}.points: values must be finite")));
        }
        if c.points.windows(2).any(|w| w[1][0] <= w[0][0]) {
            return Err(cx.err(format!("{key}.points: times must increase strictly")));
        }
        if out
            .insert(
                c.name.clone(),
                Curve {
                    points: c.points.clone(),
                },
            )
            .is_some()
        {
            return Err(cx.err(format!("{key}.name: `{}` is used twice", c.name)));
        }
    }
    Ok(out)
}

/// Index of the body a load/support/probe refers to: by name, or the only body.
fn body_index(
    cx: &Context,
    bodies: &[Body],
    name: Option<&str>,
    key: &str,
) -> Result<usize, InputError> {
    match name {
        Some(n) => bodies.iter().position(|b| b.name == n).ok_or_else(|| {
            let known: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
            cx.err(format!(
                "{key}.body: no body named `{n}` (bodies: {known:?})"
            ))
        }),
        None if bodies.len() == 1 => Ok(0),
        None => Err(cx.err(format!(
            "{key}.body: the scene has several bodies; name one"
        ))),
    }
}

fn node_set(
    cx: &Context,
    bodies: &[Body],
    body: Option<&str>,
    set: &str,
    key: &str,
) -> Result<(usize, Vec<usize>), InputError> {
    let b = body_index(cx, bodies, body, key)?;
    let sets = &bodies[b].mesh.node_sets;
    let nodes = sets.get(set).ok_or_else(|| {
        let known: Vec<&String> = sets.keys().collect();
        cx.err(format!(
            "{key}.set: body `{}` has no node set `{set}` (node sets: {known:?})",
            bodies[b].name
        ))
    })?;
    Ok((b, nodes.clone()))
}

fn edge_set(
    cx: &Context,
    bodies: &[Body],
    body: Option<&str>,
    set: &str,
    key: &str,
) -> Result<(usize, Vec<[usize; 2]>), InputError> {
    let b = body_index(cx, bodies, body, key)?;
    let sets = &bodies[b].mesh.edge_sets;
    let edges = sets.get(set).ok_or_else(|| {
        let known: Vec<&String> = sets.keys().collect();
        cx.err(format!(
            "{key}.set: body `{}` has no edge set `{set}` (edge sets: {known:?})",
            bodies[b].name
        ))
    })?;
    if !matches!(bodies[b].kind, BodyKind::Continuum { .. }) {
        return Err(cx.err(format!("{key}: edge loads apply to 2D bodies only")));
    }
    let global = edges
        .iter()
        .map(|e| e.map(|n| bodies[b].global(n)))
        .collect();
    Ok((b, global))
}

fn curve(
    cx: &Context,
    curves: &BTreeMap<String, Curve>,
    default: &Curve,
    name: &Option<String>,
    key: &str,
) -> Result<Curve, InputError> {
    match name {
        None => Ok(default.clone()),
        Some(n) => curves.get(n).cloned().ok_or_else(|| {
            let known: Vec<&String> = curves.keys().collect();
            cx.err(format!(
                "{key}.curve: no curve named `{n}` (curves: {known:?})"
            ))
        }),
    }
}

fn obstacles(cx: &Context, scene: &Scene) -> Result<Vec<Obstacle>, InputError> {
    let mut out: Vec<Obstacle> = Vec::new();
    for (k, o) in scene.obstacle.iter().enumerate() {
        let key = format!("obstacle[{k}] (`{}`)", o.name);
        if out.iter().any(|p| p.name == o.name) {
            return Err(cx.err(format!("{key}.name: used twice")));
        }
        if o.points.len() < 2 || (o.closed && o.points.len() < 3) {
            return Err(cx.err(format!(
                "{key}.points: an obstacle needs at least 2 points (3 when closed)"
            )));
        }
        finite(
            cx,
            &format!("{key}.points"),
            &o.points.iter().flatten().copied().collect::<Vec<_>>(),
        )?;
        if o.points.windows(2).any(|w| w[0] == w[1]) {
            return Err(cx.err(format!("{key}.points: two consecutive points coincide")));
        }
        out.push(Obstacle {
            name: o.name.clone(),
            points: o.points.clone(),
            closed: o.closed,
        });
    }
    Ok(out)
}

fn contact(
    cx: &Context,
    bodies: &[Body],
    obstacles: &[Obstacle],
    k: usize,
    spec: &ContactSpec,
) -> Result<ContactPair, InputError> {
    let key = format!("contact[{k}] (`{}`)", spec.name);
    let (slave_body, slaves) = node_set(
        cx,
        bodies,
        spec.slave.body.as_deref(),
        &spec.slave.set,
        &format!("{key}.slave"),
    )?;
    if spec.slave.normal.is_some() {
        return Err(cx.err(format!(
            "{key}.slave.normal: only a node-to-node master takes a normal"
        )));
    }
    let slaves: Vec<usize> = slaves
        .into_iter()
        .map(|n| bodies[slave_body].global(n))
        .collect();
    let master = match (&spec.master, &spec.obstacle) {
        (Some(m), None) => {
            let mkey = format!("{key}.master");
            let b = body_index(cx, bodies, m.body.as_deref(), &mkey)?;
            if b == slave_body {
                return Err(cx.err(format!("{mkey}.body: self-contact is not supported; master and slave must be different bodies")));
            }
            match (bodies[b].mesh.edge_sets.get(&m.set), m.normal) {
                (Some(_), None) => {
                    let (b, edges) = edge_set(cx, bodies, m.body.as_deref(), &m.set, &mkey)?;
                    let boundary = bodies[b]
                        .mesh
                        .boundary_edges()
                        .iter()
                        .map(|e| e.map(|n| bodies[b].global(n)))
                        .collect();
                    Master::Segments {
                        body: b,
                        edges,
                        boundary,
                    }
                }
                (_, Some(normal)) => {
                    let l = (normal[0] * normal[0] + normal[1] * normal[1]).sqrt();
                    if !(l > 0.0 && l.is_finite()) {
                        return Err(cx.err(format!("{mkey}.normal: must be a non-zero vector")));
                    }
                    let (b, nodes) = node_set(cx, bodies, m.body.as_deref(), &m.set, &mkey)?;
                    let nodes = nodes.into_iter().map(|n| bodies[b].global(n)).collect();
                    Master::Nodes {
                        body: b,
                        nodes,
                        normal: [normal[0] / l, normal[1] / l],
                    }
                }
                (None, None) => {
                    return Err(cx.err(format!(
                        "{mkey}: `{}` is not an edge set of body `{}`; a node-set master (node-to-node) needs `normal`",
                        m.set, bodies[b].name
                    )));
                }
            }
        }
        (None, Some(name)) => {
            let o = obstacles.iter().find(|o| &o.name == name).ok_or_else(|| {
                let known: Vec<&str> = obstacles.iter().map(|o| o.name.as_str()).collect();
                cx.err(format!(
                    "{key}.obstacle: no obstacle named `{name}` (obstacles: {known:?})"
                ))
            })?;
            Master::Obstacle(o.clone())
        }
        _ => return Err(cx.err(format!("{key}: give exactly one of `master` or `obstacle`"))),
    };
    if !(spec.release_fraction >= 0.0 && spec.release_fraction < 1.0) {
        return Err(cx.err(format!(
            "{key}.release_fraction: must lie in [0, 1), got {}",
            spec.release_fraction
        )));
    }
    let friction = match (spec.friction, spec.return_coefficient) {
        (None, None) => Friction::None,
        (Some(mu), None) if mu >= 0.0 && mu.is_finite() => Friction::Coulomb { mu },
        (Some(mu), None) => {
            return Err(cx.err(format!(
                "{key}.friction: the Coulomb coefficient must be finite and >= 0, got {mu}"
            )));
        }
        (None, Some(r)) if (0.0..=1.0).contains(&r) => Friction::Return { r },
        (None, Some(r)) => {
            return Err(cx.err(format!(
                "{key}.return_coefficient: must lie in [0, 1] (0 frictionless, 1 adherence), got {r}"
            )));
        }
        (Some(_), Some(_)) => {
            return Err(cx.err(format!(
                "{key}: give `friction` (Coulomb) or `return_coefficient` (Greco), not both"
            )));
        }
    };
    let size = model_size(bodies);
    let tolerance = spec.tolerance.unwrap_or(1e-9 * size);
    if !(tolerance >= 0.0 && tolerance.is_finite()) {
        return Err(cx.err(format!("{key}.tolerance: must be >= 0, got {tolerance}")));
    }
    let search_distance = match spec.search_distance {
        Some(d) => positive(cx, &format!("{key}.search_distance"), d)?,
        None => f64::INFINITY,
    };
    Ok(ContactPair {
        name: spec.name.clone(),
        slave_body,
        slaves,
        master,
        options: PairOptions {
            impact_conditions: spec.impact_conditions,
            release_conditions: spec.release_conditions,
            release_fraction: spec.release_fraction,
            tolerance,
            search_distance,
            split_at_events: spec.split_at_events,
            friction,
        },
    })
}

/// The diagonal of the bounding box of all nodes.
fn model_size(bodies: &[Body]) -> f64 {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in bodies.iter().flat_map(|b| b.mesh.nodes.iter()) {
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt()
}

fn add_node_set(
    cx: &Context,
    bodies: &mut [Body],
    k: usize,
    spec: &NodeSetSpec,
) -> Result<(), InputError> {
    let key = format!("node_set[{k}] (`{}`)", spec.name);
    let b = body_index(cx, bodies, spec.body.as_deref(), &key)?;
    let mesh = &mut bodies[b].mesh;
    if mesh.node_sets.contains_key(&spec.name) {
        return Err(cx.err(format!(
            "{key}.name: body `{}` already has a node set `{}`",
            bodies[b].name, spec.name
        )));
    }
    let nodes: Vec<usize> = match (spec.nearest, spec.bounds) {
        (Some(p), None) => {
            finite(cx, &format!("{key}.nearest"), &p)?;
            let distance = |n: &[f64; 2]| (n[0] - p[0]).powi(2) + (n[1] - p[1]).powi(2);
            let best = (0..mesh.nodes.len())
                .min_by(|a, b| distance(&mesh.nodes[*a]).total_cmp(&distance(&mesh.nodes[*b])));
            best.into_iter().collect()
        }
        (None, Some([x0, y0, x1, y1])) => {
            finite(cx, &format!("{key}.box"), &[x0, y0, x1, y1])?;
            (0..mesh.nodes.len())
                .filter(|n| {
                    let [x, y] = mesh.nodes[*n];
                    x >= x0 && x <= x1 && y >= y0 && y <= y1
                })
                .collect()
        }
        _ => return Err(cx.err(format!("{key}: give exactly one of `nearest` or `box`"))),
    };
    if nodes.is_empty() {
        return Err(cx.err(format!(
            "{key}.box: no node of body `{}` lies in the box",
            bodies[b].name
        )));
    }
    bodies[b].mesh.add_node_set(&spec.name, nodes);
    Ok(())
}

fn finite(cx: &Context, key: &str, values: &[f64]) -> Result<(), InputError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(cx.err(format!("{key}: values must be finite")))
    }
}

fn load(
    cx: &Context,
    bodies: &[Body],
    curves: &BTreeMap<String, Curve>,
    default: &Curve,
    k: usize,
    spec: &LoadSpec,
) -> Result<Load, InputError> {
    let key = format!("load[{k}]");
    let globals =
        |b: usize, nodes: Vec<usize>| nodes.into_iter().map(|n| bodies[b].global(n)).collect();
    Ok(match spec {
        LoadSpec::NodalForce(s) => {
            finite(cx, &format!("{key}.force"), &s.force)?;
            let (b, nodes) = node_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
            Load::NodalForce {
                nodes: globals(b, nodes),
                force: s.force,
                curve: curve(cx, curves, default, &s.curve, &key)?,
            }
        }
        LoadSpec::Traction(s) => {
            finite(cx, &format!("{key}.traction"), &s.traction)?;
            let (body, edges) = edge_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
            Load::Traction {
                body,
                edges,
                traction: s.traction,
                curve: curve(cx, curves, default, &s.curve, &key)?,
            }
        }
        LoadSpec::Pressure(s) => {
            finite(cx, &format!("{key}.pressure"), &[s.pressure])?;
            let (body, edges) = edge_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
            Load::Pressure {
                body,
                edges,
                pressure: s.pressure,
                curve: curve(cx, curves, default, &s.curve, &key)?,
            }
        }
        LoadSpec::Displacement(s) => {
            if s.x.is_none() && s.y.is_none() {
                return Err(cx.err(format!("{key}: give `x`, `y` or both")));
            }
            finite(cx, &key, &[s.x.unwrap_or(0.0), s.y.unwrap_or(0.0)])?;
            let (b, nodes) = node_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
            Load::Displacement {
                nodes: globals(b, nodes),
                x: s.x,
                y: s.y,
                curve: curve(cx, curves, default, &s.curve, &key)?,
            }
        }
        LoadSpec::Rotation(s) => {
            finite(cx, &key, &[s.center[0], s.center[1], s.angle])?;
            let (b, nodes) = node_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
            Load::Rotation {
                nodes: globals(b, nodes),
                center: s.center,
                angle: s.angle,
                curve: curve(cx, curves, default, &s.curve, &key)?,
            }
        }
        LoadSpec::Affine(s) => {
            let offset = s.offset.unwrap_or([0.0; 2]);
            finite(
                cx,
                &key,
                &[
                    s.gradient[0][0],
                    s.gradient[0][1],
                    s.gradient[1][0],
                    s.gradient[1][1],
                ],
            )?;
            finite(cx, &key, &offset)?;
            let (b, nodes) = node_set(cx, bodies, s.body.as_deref(), &s.set, &key)?;
            Load::Affine {
                nodes: globals(b, nodes),
                gradient: s.gradient,
                offset,
                curve: curve(cx, curves, default, &s.curve, &key)?,
            }
        }
    })
}

fn probes(cx: &Context, bodies: &[Body], specs: &[ProbeSpec]) -> Result<Vec<Probe>, InputError> {
    let mut out = Vec::new();
    for (k, p) in specs.iter().enumerate() {
        let key = format!("output.probe[{k}]");
        let b = body_index(cx, bodies, p.body.as_deref(), &key)?;
        let members = if p.quantity.is_nodal() {
            node_set(cx, bodies, p.body.as_deref(), &p.set, &key)?
                .1
                .into_iter()
                .map(|n| bodies[b].global(n))
                .collect()
        } else {
            // an element set, or the elements around the nodes of a node set
            let mesh = &bodies[b].mesh;
            let sets = &mesh.element_sets;
            match (sets.get(&p.set), mesh.node_sets.get(&p.set)) {
                (Some(elements), _) => elements.clone(),
                (None, Some(nodes)) => (0..mesh.cells.len())
                    .filter(|e| mesh.cells.nodes_of(*e).iter().any(|n| nodes.contains(n)))
                    .collect(),
                (None, None) => {
                    let known: Vec<&String> = sets.keys().chain(mesh.node_sets.keys()).collect();
                    return Err(cx.err(format!(
                        "{key}.set: body `{}` has no element or node set `{}` (sets: {known:?})",
                        bodies[b].name, p.set
                    )));
                }
            }
        };
        let set = if bodies.len() > 1 {
            format!("{}.{}", bodies[b].name, p.set)
        } else {
            p.set.clone()
        };
        let column = match p.statistic {
            Statistic::Mean => format!("{}[{set}]", p.quantity.name()),
            Statistic::Max => format!("max_{}[{set}]", p.quantity.name()),
            Statistic::Min => format!("min_{}[{set}]", p.quantity.name()),
        };
        out.push(Probe {
            statistic: p.statistic,
            quantity: p.quantity,
            body: b,
            members,
            column,
        });
    }
    Ok(out)
}
