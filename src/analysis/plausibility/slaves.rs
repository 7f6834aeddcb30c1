//! Whether a pair's slave set is the surface that meets its master: the nodes of the slave
//! body's boundary that face the master nearest it should be slaves, since one-pass contact
//! holds only its slaves and lets every other node through (a sphere's `axis` named instead
//! of its `arc`: only the pole is held, and the arc around it sinks into the wall).
//!
//! Legend
//! ```text
//! n_b        a boundary node's outward normal: the mean of its boundary edges' (the body on
//!            the left of each edge, so the normal is to its right)
//! g, n_m     the node's gap to the master and the master's normal there (node-to-segment)
//! facing     n_b . n_m < -1/2: the node's surface turns towards the master (within 60 deg)
//! near       facing, with g within a tenth of the body's size of the least such gap
//! ```

use super::units::body_size;
use crate::contact::{ContactPair, Master};
use crate::mesh::plane::{dot, outward};
use crate::output::readable;
use crate::scene::{Body, Model};

/// A slave set that holds fewer than this share of the near facing nodes warns.
pub const SLAVE_SHARE: f64 = 0.5;

/// The near band: this share of the slave body's size beyond the least gap.
const NEAR_BAND: f64 = 0.1;

/// Fewer near facing nodes than this say nothing of the set (a corner, a point contact).
const FEW: usize = 3;

/// The pairs whose slave set holds fewer than [`SLAVE_SHARE`] of the slave body's boundary
/// nodes that face the master nearest it, each with the sets that would hold them.
pub(super) fn slave_surface_warnings(model: &Model) -> Vec<String> {
    let coords = model.coordinates();
    let mut out = Vec::new();
    for pair in &model.contacts {
        // a second pass or a hold pair has the slaves its first pass gives it
        if pair.covered.is_some() || pair.is_hold() {
            continue;
        }
        if matches!(pair.master, Master::Nodes { .. }) {
            continue;
        }
        let body = &model.bodies[pair.slave_body];
        let near = near_facing_nodes(body, pair, &coords);
        if near.len() < FEW {
            continue;
        }
        let held = near.iter().filter(|n| pair.slaves.contains(n)).count();
        if (held as f64) >= SLAVE_SHARE * near.len() as f64 {
            continue;
        }
        out.push(warning(model, body, pair, (&near, held)));
    }
    out
}

/// The boundary nodes of `body` (global ids) that face `pair`'s master nearest it.
fn near_facing_nodes(body: &Body, pair: &ContactPair, coords: &[[f64; 2]]) -> Vec<usize> {
    let edges = &body.boundary;
    let mut normal = vec![[0.0; 2]; body.mesh.nodes.len()];
    for [a, b] in edges {
        let n = outward(body.mesh.nodes[*a], body.mesh.nodes[*b]);
        for node in [a, b] {
            normal[*node] = [normal[*node][0] + n[0], normal[*node][1] + n[1]];
        }
    }
    let x = |n: usize| coords[n];
    let mut facing: Vec<(usize, f64)> = Vec::new();
    for (local, n_b) in normal.iter().enumerate() {
        let length = n_b[0].hypot(n_b[1]);
        if length == 0.0 {
            continue; // not on the boundary
        }
        let node = body.global(local);
        let Some(gap) = pair.node_gap(node, &x) else {
            continue;
        };
        if dot(*n_b, gap.normal) < -0.5 * length {
            facing.push((node, gap.gap));
        }
    }
    let least = facing.iter().map(|(_, g)| *g).fold(f64::INFINITY, f64::min);
    let band = NEAR_BAND * body_size(body);
    facing
        .into_iter()
        .filter(|(_, g)| *g <= least + band)
        .map(|(n, _)| n)
        .collect()
}

/// The warning of a pair whose slave set misses the surface: how many of the `near` nodes it
/// holds (`held`), the set it names, and the body's sets that hold them all.
fn warning(
    model: &Model,
    body: &Body,
    pair: &ContactPair,
    (near, held): (&[usize], usize),
) -> String {
    let local = |n: &usize| n - body.node_offset;
    let named = body
        .mesh
        .node_sets
        .iter()
        .find(|(_, nodes)| {
            let mut a: Vec<usize> = nodes.to_vec();
            let mut b: Vec<usize> = pair.slaves.iter().map(local).collect();
            a.sort_unstable();
            b.sort_unstable();
            a.dedup();
            b.dedup();
            a == b
        })
        .map_or("its slave set".to_string(), |(name, _)| {
            format!("the slave set `{name}`")
        });
    let mut covering: Vec<(&String, usize)> = body
        .mesh
        .node_sets
        .iter()
        .filter(|(name, nodes)| *name != "all" && near.iter().all(|n| nodes.contains(&local(n))))
        .map(|(name, nodes)| (name, nodes.len()))
        .collect();
    covering.sort_by_key(|(_, len)| *len);
    let suggestion = match covering.first() {
        Some((name, _)) => format!("`{name}` holds them all"),
        None => "add a [[node_set]] of them, or use the mesh's boundary set".to_string(),
    };
    let master = match &pair.master {
        Master::Obstacle(o) => format!("obstacle `{}`", o.name),
        Master::Segments { body, .. } | Master::Nodes { body, .. } => {
            format!("body `{}`", model.bodies[*body].name)
        }
    };
    format!(
        "contact `{}`: {named} holds {held} of the {} boundary nodes of body `{}` that face {master} \
         nearest it (within {} of the nearest): contact holds only its slaves, and the others can \
         pass through the master unseen; make the slave set the surface that meets it ({suggestion})",
        pair.name,
        near.len(),
        body.name,
        readable(NEAR_BAND * body_size(body))
    )
}
