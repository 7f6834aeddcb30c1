//! `[[obstacle]]` and `[[contact]]`: the rigid obstacles and the contact pairs, each pair a
//! slave node set against a master (another body's edges or nodes, or an obstacle) with its
//! options and friction.

use super::InputError;
use super::context::{
    Context, body_index, edge_lengths, edge_set, edge_sets_on_both, node_set, positive,
};
use super::model::{Body, BodyKind};
use super::roles::with_roles;
use super::spec::{
    AnalysisKind, ContactDiscretization, ContactSpec, IntegratorKind, Roles, Scene, SurfaceSpec,
};
use crate::contact::{
    ContactPair, Covered, Discretization, Friction, Holds, Master, MortarSurface, Obstacle,
    OwnSurface, PairOptions, setup,
};
use crate::element::Formulation;
use crate::mesh::Cells;

/// The scene's contact pairs in order, their names unique.
pub(super) fn contacts(
    cx: &Context,
    scene: &Scene,
    bodies: &[Body],
    obstacles: &[Obstacle],
) -> Result<Vec<ContactPair>, InputError> {
    // each pair with the roles it runs with (the code's where the scene names none)
    let specs = (scene.contact.iter().enumerate())
        .map(|entry| with_roles(cx, bodies, entry, scene))
        .collect::<Result<Vec<_>, _>>()?;
    let contacts = (specs.iter().enumerate())
        .map(|(k, (spec, why))| {
            let mut pair = contact(cx, bodies, obstacles, (k, spec), scene)?;
            pair.chosen_roles = why.clone();
            Ok(pair)
        })
        .collect::<Result<Vec<_>, _>>()?;
    refuse_repeated_pairs(cx, &contacts)?;
    let mut contacts = contacts;
    for (k, (spec, _)) in specs.iter().enumerate() {
        let spec: &ContactSpec = spec;
        if spec.two_pass {
            let reverse = reverse_pair(cx, bodies, k, spec, &contacts[k])?;
            contacts.push(reverse);
        }
        if symmetric(cx, bodies, (k, spec), scene)? {
            let mut reverse = reverse_pair(cx, bodies, k, spec, &contacts[k])?;
            reverse.covered = None;
            reverse.balances = Some(k);
            // a body against itself: the same surfaces, the segments on the other side
            if let Some(own) = &contacts[k].own {
                reverse.slaves = contacts[k].slaves.clone();
                reverse.master = contacts[k].master.clone();
                reverse.own = Some(own.reversed());
            }
            contacts.push(reverse);
        }
        let held = contacts[k]
            .mortar()
            .is_some_and(|(surface, _)| surface.hold_master_nodes);
        if held && implicit_dynamics(scene) {
            let hold = hold_pair(cx, bodies, k, spec, &contacts[k])?;
            contacts.push(hold);
        }
    }
    if let Some(k) =
        (0..contacts.len()).find(|k| contacts[..*k].iter().any(|c| c.name == contacts[*k].name))
    {
        return Err(cx.err(format!(
            "contact[{k}].name: `{}` is used twice",
            contacts[k].name
        )));
    }
    Ok(contacts)
}

/// Refuses a pair that repeats another: the same slave nodes against the same master (an
/// obstacle by name, or the same master nodes), or the other's surfaces with the roles
/// swapped. Each node would then be held twice in one step, its corrections added: the
/// Taylor rod with its face against the wall in two pairs died at 1.43 us on a runaway
/// penetration that named neither pair.
fn refuse_repeated_pairs(cx: &Context, pairs: &[ContactPair]) -> Result<(), InputError> {
    /// The sorted nodes of a surface, or the obstacle's name.
    #[derive(PartialEq)]
    enum Side<'a> {
        Nodes(Vec<usize>),
        Obstacle(&'a str),
    }
    fn sorted<'a>(mut nodes: Vec<usize>) -> Side<'a> {
        nodes.sort_unstable();
        nodes.dedup();
        Side::Nodes(nodes)
    }
    /// A pair's slave side and master side.
    fn sides(pair: &ContactPair) -> (Side<'_>, Side<'_>) {
        let master = match &pair.master {
            Master::Segments { edges, .. } => sorted(edges.as_flattened().to_vec()),
            Master::Nodes { nodes, .. } => sorted(nodes.clone()),
            Master::Obstacle(o) => Side::Obstacle(&o.name),
        };
        (sorted(pair.slaves.clone()), master)
    }
    for (j, later) in pairs.iter().enumerate() {
        let (slave, master) = sides(later);
        for earlier in &pairs[..j] {
            let (s, m) = sides(earlier);
            if (slave == s && master == m) || (slave == m && master == s) {
                return Err(cx.err(format!(
                    "contact `{}` repeats contact `{}`: the same surfaces meet in both (the \
                     same slave nodes against the same master, or the roles swapped), so every \
                     node would be held twice in a step; remove one of the two pairs",
                    later.name, earlier.name
                )));
            }
        }
    }
    Ok(())
}

/// One `[[contact]]` pair (the k-th, `spec`): its slave nodes (global), its master and its
/// options.
fn contact(
    cx: &Context,
    bodies: &[Body],
    obstacles: &[Obstacle],
    (k, spec): (usize, &ContactSpec),
    scene: &Scene,
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
        (Some(m), None) => master_body(cx, bodies, slave_body, &key, m)?,
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
    let friction = friction(cx, &key, spec)?;
    let size = model_size(bodies);
    let tolerance = spec.tolerance.unwrap_or(1e-9 * size);
    if !(tolerance >= 0.0 && tolerance.is_finite()) {
        return Err(cx.err(format!("{key}.tolerance: must be >= 0, got {tolerance}")));
    }
    let balanced = symmetric(cx, bodies, (k, spec), scene)?;
    let own = own_surface(cx, bodies, (&key, balanced), (slave_body, &master))?;
    let search_distance = match spec.search_distance {
        Some(d) => positive(cx, &format!("{key}.search_distance"), d)?,
        // a body against itself: no penetration deeper than half a segment counts
        // (`OwnSurface::reaches`), and the search looks no farther
        None if own.is_some() => 0.25 * balanced_reach(cx, bodies, spec),
        None if balanced => balanced_reach(cx, bodies, spec),
        None => f64::INFINITY,
    };
    let mortar = mortar_surface(cx, bodies, (&key, spec), (slave_body, &master), {
        dynamic(scene) && !balanced
    })?;
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
            persistency: false,
            balanced,
        },
        covered: None,
        balances: None,
        own,
        discretization: mortar.map_or(Discretization::NodeToSegment, Discretization::Mortar),
        chosen_roles: None,
    })
}

/// The first pass of a body's contact with itself (slave and master on `slave_body`): a
/// balanced pair, which runs under central difference only (`key` names the pair). None
/// for a master on another body or an obstacle.
fn own_surface(
    cx: &Context,
    bodies: &[Body],
    (key, balanced): (&str, bool),
    (slave_body, master): (usize, &Master),
) -> Result<Option<OwnSurface>, InputError> {
    let Master::Segments { body, edges, .. } = master else {
        return Ok(None);
    };
    if *body != slave_body {
        return Ok(None);
    }
    if !balanced {
        return Err(cx.err(format!(
            "{key}.master.body: a body's contact with itself (`{}` against its own edges) is a balanced pair, which runs under central_difference, on edge sets (slave and master), with `roles` left out and without `two_pass`, `discretization = \"mortar\"` or `hold_master_nodes`",
            bodies[slave_body].name
        )));
    }
    let b = &bodies[slave_body];
    let boundary: Vec<[usize; 2]> = b.boundary.iter().map(|e| e.map(|n| b.global(n))).collect();
    OwnSurface::new(&boundary, edges, true)
        .map(Some)
        .map_err(|[p, q]| {
            cx.err(format!(
                "{key}.master.set: edge {}-{} of body `{}` is not on its boundary; a body's contact with itself takes boundary edges",
                p - b.node_offset,
                q - b.node_offset,
                b.name
            ))
        })
}

/// Whether pair `k` (`spec`) is balanced (`roles = "symmetric"`): each surface the slave of
/// the other in a pass of its own, the explicit correction the mean of the two passes
/// (docs/theory.md 8.3d). The default for a pair between two bodies' edge sets under
/// central difference, unless the pair asks for what one pass does (`two_pass`, `mortar`,
/// `hold_master_nodes`); refused on the implicit and static paths, against an obstacle or a
/// node-to-node master, and with those keys.
fn symmetric(
    cx: &Context,
    bodies: &[Body],
    (k, spec): (usize, &ContactSpec),
    scene: &Scene,
) -> Result<bool, InputError> {
    let key = format!("contact[{k}] (`{}`).roles", spec.name);
    let between_bodies = edge_sets_on_both(cx, bodies, spec).is_some();
    let one_pass = [
        (spec.two_pass, "`two_pass`"),
        (
            spec.discretization == Some(ContactDiscretization::Mortar),
            "`discretization = \"mortar\"`",
        ),
        (spec.hold_master_nodes.is_some(), "`hold_master_nodes`"),
    ];
    match spec.roles {
        None => Ok(explicit(scene) && between_bodies && one_pass.iter().all(|(on, _)| !on)),
        Some(Roles::AsWritten | Roles::Automatic) => Ok(false),
        Some(Roles::Symmetric) => {
            if !explicit(scene) {
                return Err(cx.err(format!(
                    "{key}: balanced contact runs under central_difference only; the implicit and static paths take `roles = \"as_written\"` (one pass, the slave set the slave)"
                )));
            }
            if !between_bodies {
                return Err(cx.err(format!(
                    "{key}: balanced contact needs a slave and a master edge set on two bodies (an obstacle or a node-to-node master is a master only)"
                )));
            }
            if let Some((_, name)) = one_pass.iter().find(|(on, _)| *on) {
                return Err(cx.err(format!(
                    "{key}: {name} is a one-pass choice; give `roles = \"as_written\"` with it, or leave it out"
                )));
            }
            Ok(true)
        }
    }
}

/// The slave surface of a `discretization = "mortar"` pair (`key`, `spec`): the slave set's
/// edges of `slave_body`, against a master edge set of another body.
fn mortar_surface(
    cx: &Context,
    bodies: &[Body],
    (key, spec): (&str, &ContactSpec),
    (slave_body, master): (usize, &Master),
    dynamic: bool,
) -> Result<Option<MortarSurface>, InputError> {
    let slave_edges = bodies[slave_body]
        .mesh
        .edge_sets
        .contains_key(&spec.slave.set);
    let between_bodies = matches!(master, Master::Segments { .. }) && slave_edges;
    // Greco's return is the seeds' node-to-segment friction: its target needs a frictionless
    // solve of the same step, which the active set inside Newton does not make
    let greco = spec.return_coefficient.is_some();
    let default = if dynamic && between_bodies && !spec.two_pass && !greco {
        ContactDiscretization::Mortar
    } else {
        ContactDiscretization::NodeToSegment
    };
    if spec.discretization.unwrap_or(default) != ContactDiscretization::Mortar {
        if spec.hold_master_nodes.is_some() {
            return Err(cx.err(format!(
                "{key}.hold_master_nodes: only a mortar pair holds its master nodes (this pair is node-to-segment)"
            )));
        }
        return Ok(None);
    }
    if !matches!(master, Master::Segments { .. }) {
        return Err(cx.err(format!(
            "{key}.discretization: mortar contact needs a master edge set on a body (an obstacle or a node-to-node master has no segments to weigh against); use node_to_segment"
        )));
    }
    if spec.two_pass {
        return Err(cx.err(format!(
            "{key}.two_pass: mortar contact weighs both surfaces already; give one of `two_pass` and `discretization = \"mortar\"`"
        )));
    }
    let body = &bodies[slave_body];
    let (_, edges) = edge_set(
        cx,
        bodies,
        Some(&body.name),
        &spec.slave.set,
        &format!("{key}.slave"),
    )?;
    let axisymmetric = matches!(
        body.kind,
        BodyKind::Continuum {
            formulation: Formulation::Axisymmetric,
            ..
        }
    );
    Ok(Some(MortarSurface {
        edges,
        axisymmetric,
        // the master nodes are left to the weighted gaps unless the scene asks to hold them:
        // held, a copper rod at 200 m/s on a steel plate with either body meshed finer
        // created energy and inverted an element (theory 8.3a), and with Coulomb friction
        // the one-point rod pair on non-matching meshes gained 41 % energy in one step
        hold_master_nodes: spec.hold_master_nodes.unwrap_or(false),
    }))
}

/// Whether the scene is a dynamic one (a pair between two bodies' edge sets is a mortar
/// pair there by default, on every integrator; static runs keep node-to-segment).
fn dynamic(scene: &Scene) -> bool {
    scene.analysis.kind == AnalysisKind::Dynamic
}

/// Whether the scene steps with central difference.
fn explicit(scene: &Scene) -> bool {
    scene.analysis.integrator == Some(IntegratorKind::CentralDifference)
}

/// Whether the scene steps with an implicit integrator (where a mortar pair's master nodes
/// are held by a hold pair; under central difference the explicit correction holds them,
/// and statics does not: on a block dragged across another with friction the hold of the
/// base's nodes the slider's corner passes over stopped Newton's iteration at t = 1.29).
fn implicit_dynamics(scene: &Scene) -> bool {
    scene.analysis.kind == AnalysisKind::Dynamic && !explicit(scene)
}

/// The hold pair of mortar pair `k` on the implicit paths (docs/theory.md 8.3a-4), named
/// `NAME:held`: the mortar pair's master nodes as slaves of its slave surface, each with the
/// gap of `mortar::master_node_gap`, so that a master node cannot sink into the slave body
/// where the weighted gaps let it. A master node whose nearest slave point is a slave node in
/// contact is left to the mortar pair (two-pass's `covered` rule: the two rows would be one).
/// Frictionless, with the mortar pair's other options.
fn hold_pair(
    cx: &Context,
    bodies: &[Body],
    k: usize,
    spec: &ContactSpec,
    pair: &ContactPair,
) -> Result<ContactPair, InputError> {
    let mut hold = reverse_pair(cx, bodies, k, spec, pair)?;
    let Master::Segments { edges, .. } = &pair.master else {
        unreachable!("a mortar pair's master is an edge set");
    };
    hold.name = format!("{}:held", pair.name);
    // frictionless: the mortar pair's rows carry the friction; a second tangential row at
    // the same nodes would count it twice
    hold.options.friction = Friction::None;
    hold.discretization = Discretization::Held(Holds {
        master_edges: edges.clone(),
    });
    Ok(hold)
}

/// The second pair of a two-pass contact: the master surface's nodes as slaves of the slave
/// surface's edges, with the same options, named `NAME:reverse`.
fn reverse_pair(
    cx: &Context,
    bodies: &[Body],
    k: usize,
    spec: &ContactSpec,
    pair: &ContactPair,
) -> Result<ContactPair, InputError> {
    let key = format!("contact[{k}] (`{}`).two_pass", spec.name);
    let Master::Segments { body, edges, .. } = &pair.master else {
        return Err(cx.err(format!(
            "{key}: needs a master edge set on a body (node-to-segment); a node-to-node master or an obstacle has no surface to be slave to"
        )));
    };
    let slave_body = &bodies[pair.slave_body];
    let (_, slave_edges) = edge_set(
        cx,
        bodies,
        Some(&slave_body.name),
        &spec.slave.set,
        &format!("contact[{k}] (`{}`).slave", spec.name),
    )?;
    let mut slaves: Vec<usize> = edges.iter().flatten().copied().collect();
    slaves.sort_unstable();
    slaves.dedup();
    let boundary = slave_body
        .boundary
        .iter()
        .map(|e| e.map(|n| slave_body.global(n)))
        .collect();
    Ok(ContactPair {
        name: format!("{}:reverse", pair.name),
        slave_body: *body,
        slaves,
        master: Master::Segments {
            body: pair.slave_body,
            edges: slave_edges,
            boundary,
        },
        options: pair.options.clone(),
        discretization: Discretization::NodeToSegment,
        balances: None,
        own: None,
        chosen_roles: None,
        covered: Some(Covered {
            pair: k,
            slaves: {
                let mut first: Vec<(usize, usize)> = pair
                    .slaves
                    .iter()
                    .enumerate()
                    .map(|(i, n)| (*n, i))
                    .collect();
                first.sort_unstable();
                first
            },
        }),
    })
}

/// A master on another body: its edge set (node-to-segment), or a node set with the
/// `normal` of its surface (node-to-node).
fn master_body(
    cx: &Context,
    bodies: &[Body],
    slave_body: usize,
    key: &str,
    m: &SurfaceSpec,
) -> Result<Master, InputError> {
    let mkey = format!("{key}.master");
    let b = body_index(cx, bodies, m.body.as_deref(), &mkey)?;
    if b == slave_body && m.normal.is_some() {
        return Err(cx.err(format!(
            "{mkey}.normal: a body's contact with itself takes an edge set as its master, not nodes with a normal"
        )));
    }
    Ok(match (bodies[b].mesh.edge_sets.get(&m.set), m.normal) {
        (Some(_), None) => {
            let (b, edges) = edge_set(cx, bodies, m.body.as_deref(), &m.set, &mkey)?;
            let boundary = bodies[b]
                .boundary
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
    })
}

/// The pair's friction: none, Coulomb's `friction` or the `return_coefficient` of Greco &
/// Coda (2003), never both.
fn friction(cx: &Context, key: &str, spec: &ContactSpec) -> Result<Friction, InputError> {
    Ok(match (spec.friction, spec.return_coefficient) {
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
    })
}

/// The search distance of a balanced pair (`spec`) not given one: twice the longest edge of
/// its two surfaces. A node farther than that from the other body cannot reach it within a
/// step (a step moves a node far less than an element), and each surface is a whole one (up
/// to a body's boundary), so looking at the far side of both bodies every step would cost
/// more than the contact itself.
fn balanced_reach(cx: &Context, bodies: &[Body], spec: &ContactSpec) -> f64 {
    let longest = |surface: &SurfaceSpec| -> f64 {
        let Ok(b) = body_index(cx, bodies, surface.body.as_deref(), "") else {
            return f64::INFINITY;
        };
        edge_lengths(&bodies[b], &surface.set)
            .map_or(f64::INFINITY, |lengths| lengths.fold(0.0, f64::max))
    };
    let master = spec.master.as_ref().map_or(f64::INFINITY, longest);
    2.0 * longest(&spec.slave).max(master)
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

/// The set-up checks of every pair whose `setup_check` is on (contact::setup), on the initial
/// configuration: the first problem is an error naming the pair and the key that accepts it.
pub(super) fn check_contact_setup(
    cx: &Context,
    scene: &Scene,
    bodies: &[Body],
    contacts: &[ContactPair],
) -> Result<(), InputError> {
    let coords: Vec<[f64; 2]> = bodies
        .iter()
        .flat_map(|b| b.mesh.nodes.iter().copied())
        .collect();
    for pair in contacts {
        let name = pair.name.strip_suffix(":reverse").unwrap_or(&pair.name);
        let Some(spec) = scene.contact.iter().find(|s| s.name == name) else {
            continue;
        };
        if !spec.setup_check {
            continue;
        }
        let slave = &bodies[pair.slave_body];
        let master_interior = match &pair.master {
            Master::Segments { body, .. } | Master::Nodes { body, .. } => {
                Some(interior(&bodies[*body]))
            }
            Master::Obstacle(_) => None,
        };
        let slave_normal = |node: usize| outward_normal(slave, node - slave.node_offset);
        let placement = setup::Bodies {
            coords: &coords,
            slave_interior: interior(slave),
            master_interior,
            slave_normal: &slave_normal,
        };
        if let Some(problem) = setup::setup_problem(pair, &placement) {
            return Err(cx.err(format!(
                "contact `{}`: {problem}. (contact.{}.setup_check = false runs it as it is)",
                pair.name, pair.name
            )));
        }
    }
    Ok(())
}

/// A point inside a body: the mean of its element centroids (of its nodes for rods).
fn interior(body: &Body) -> [f64; 2] {
    let nodes = &body.mesh.nodes;
    let mean = |points: &mut dyn Iterator<Item = [f64; 2]>| {
        let (mut sum, mut count) = ([0.0; 2], 0.0);
        for p in points {
            sum = [sum[0] + p[0], sum[1] + p[1]];
            count += 1.0;
        }
        [sum[0] / count, sum[1] / count]
    };
    match &body.mesh.cells {
        Cells::Quad4(quads) => {
            mean(&mut quads.iter().map(|q| mean(&mut q.iter().map(|n| nodes[*n]))))
        }
        _ => mean(&mut nodes.iter().copied()),
    }
}

/// The outward normal of a body's boundary at local node `node`: the normalized sum of its
/// boundary edges' outward normals (edges run counter-clockwise around the body). None for
/// rods and interior nodes.
fn outward_normal(body: &Body, node: usize) -> Option<[f64; 2]> {
    let nodes = &body.mesh.nodes;
    let mut sum = [0.0; 2];
    for [a, b] in body.boundary_at_node.get(node)? {
        let d = [nodes[*b][0] - nodes[*a][0], nodes[*b][1] - nodes[*a][1]];
        let l = d[0].hypot(d[1]);
        if l > 0.0 {
            sum = [sum[0] + d[1] / l, sum[1] - d[0] / l];
        }
    }
    let l = sum[0].hypot(sum[1]);
    (l > 0.0).then(|| [sum[0] / l, sum[1] / l])
}
