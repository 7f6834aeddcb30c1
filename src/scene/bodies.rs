//! `[[body]]`: each body's mesh, material and kind (continuum or rod) checked and placed in
//! the global node numbering, the `[[node_set]]` tables added to the meshes, and the initial
//! velocity of every DOF.

use super::InputError;
use super::context::{Context, body_index, finite, node_set, positive};
use super::model::{Body, BodyKind};
use super::spec::{BodySpec, FormulationSpec, NodeSetSpec, Scene};
use crate::element::{Formulation, Voigt, quad4, rod2};
use crate::material::Material;
use crate::mesh::{Cells, Mesh};
use crate::output::readable;
use std::collections::BTreeMap;
use std::path::Path;

/// The scene's bodies in order, body b's nodes numbered after those of bodies 0..b, and the
/// total node count.
pub(super) fn bodies(
    cx: &Context,
    scene: &Scene,
    materials: &BTreeMap<String, Material>,
    base_dir: &Path,
) -> Result<(Vec<Body>, usize), InputError> {
    let mut bodies = Vec::new();
    let mut node_count = 0;
    for (b, spec) in scene.body.iter().enumerate() {
        if scene.body[..b].iter().any(|o| o.name == spec.name) {
            return Err(cx.err(format!("body[{b}]: the name `{}` is used twice", spec.name)));
        }
        let body = body(cx, spec, materials, base_dir, node_count)?;
        node_count += body.mesh.nodes.len();
        bodies.push(body);
    }
    if bodies.is_empty() {
        return Err(cx.err("the scene has no [[body]]"));
    }
    Ok((bodies, node_count))
}

/// One body: its material, its mesh (with the node set `all`), its kind and the boundary
/// edges at each node; global node numbers start at `node_offset`.
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
        let why = match spec.formulation {
            FormulationSpec::PlaneStrain => {
                "a plane_strain body is per unit depth (its forces, masses and energies are per unit of thickness: multiply by the depth for totals)"
            }
            FormulationSpec::Axisymmetric => {
                "an axisymmetric body is the full ring (its forces are totals over 2 pi r)"
            }
            _ => "a rod has a cross-section `area` instead",
        };
        return Err(cx.err(format!(
            "{key}.thickness: only plane_stress bodies have a thickness; {why}"
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
    let boundary = mesh.boundary_edges();
    let mut boundary_at_node = vec![Vec::new(); mesh.nodes.len()];
    for edge in &boundary {
        for node in edge {
            boundary_at_node[*node].push(*edge);
        }
    }
    Ok(Body {
        name: spec.name.clone(),
        boundary_at_node,
        boundary,
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

/// A `[[node_set]]`: the node nearest a point or the nodes in a box, added to its body's mesh.
pub(super) fn add_node_set(
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
            if let Some(n) = best {
                let (d, h) = (distance(&mesh.nodes[n]).sqrt(), longest_edge(mesh));
                if d > h {
                    return Err(cx.err(format!(
                        "{key}.nearest: [{}, {}] lies {} from the nearest node of body `{}` \
                         (node {n} at [{}, {}]), farther than its longest element edge ({}): a \
                         point off the body (a sign or unit slip?); give a point on it",
                        readable(p[0]),
                        readable(p[1]),
                        readable(d),
                        bodies[b].name,
                        readable(mesh.nodes[n][0]),
                        readable(mesh.nodes[n][1]),
                        readable(h)
                    )));
                }
            }
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

/// The longest element edge of a mesh.
fn longest_edge(mesh: &Mesh) -> f64 {
    (0..mesh.cells.len())
        .flat_map(|e| mesh.edge_lengths(e))
        .fold(0.0, f64::max)
}

/// Initial velocity per DOF: each body's `velocity`, then the `[[initial_velocity]]` sets in
/// order (a later set overrides an earlier value).
pub(super) fn initial_velocity(
    cx: &Context,
    scene: &Scene,
    bodies: &[Body],
    node_count: usize,
) -> Result<Vec<f64>, InputError> {
    let mut initial_velocity = vec![0.0; 2 * node_count];
    for body in bodies {
        for n in 0..body.mesh.nodes.len() {
            initial_velocity[2 * body.global(n)] = body.velocity[0];
            initial_velocity[2 * body.global(n) + 1] = body.velocity[1];
        }
    }
    for (k, v) in scene.initial_velocity.iter().enumerate() {
        let key = format!("initial_velocity[{k}]");
        finite(cx, &format!("{key}.velocity"), &v.velocity)?;
        let (b, nodes) = node_set(cx, bodies, v.body.as_deref(), &v.set, &key)?;
        for n in nodes {
            initial_velocity[2 * bodies[b].global(n)] = v.velocity[0];
            initial_velocity[2 * bodies[b].global(n) + 1] = v.velocity[1];
        }
    }
    for (b, spec) in scene.body.iter().enumerate() {
        if let Some(v) = spec.velocity {
            finite(cx, &format!("body `{}`.velocity", bodies[b].name), &v)?;
        }
    }
    Ok(initial_velocity)
}
