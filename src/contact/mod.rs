//! Contact, in one place: detection on the current configuration (`geometry`, `search`,
//! the nearest-segment grid of a balanced pair's whole surfaces `grid`, the rules of a
//! body's contact with itself `own`),
//! the status carried between steps (`status`), the event logic of an implicit step
//! (`step`), Hughes' impact and release conditions (`conditions`) met at a step's events
//! (`impacts`), the explicit forward-increment multipliers (`explicit`, with the lumped
//! multiplier solve both paths share, `multipliers`), the mortar (segment-to-segment)
//! gaps (`mortar`) and their exact derivatives (`linearization`), the node and gap types
//! (`gap`), how deep any body went into another or an obstacle and which slave went past
//! an obstacle's end (`penetration`), the set-up checks of a pair (`setup`) and the
//! tractions the frames show (`traction`). It works on plain arrays (positions, masses,
//! DOF indices) and never sees the assembled system: the implicit solver receives the rows of the active entries and
//! returns their multipliers (Hughes, Taylor & Sackman 1975, section II; Greco & Coda 2003).
//!
//! Legend
//! ```text
//! slave s        a node of the slave set, position x_s
//! master         a polyline of segments [a, b] with the solid on the left of a -> b (the
//!                master body's boundary edges, or a rigid obstacle), or single nodes with a
//!                given normal (node-to-node, Hughes II-4)
//! xi             projection parameter of x_s on the nearest segment, p = (1 - xi) a + xi b
//! n              unit normal out of the master at p (right of a -> b): interpolated between
//!                the master nodes' averaged normals in one-pass rows, the segment's own
//!                (the gap's gradient) in a balanced pair's passes (theory 8.3d)
//! g              gap (x_s - p) . n: > 0 apart, < 0 penetrated (Hughes II-7: d = x^1 - x^2)
//! c(S)           winding number -1/(2 pi) sum of the angle increments seen from S over a
//!                closed boundary (Greco eq 17): 1 inside, 0 outside, alpha/(2 pi) on a
//!                corner of angle alpha, 1/2 on a smooth edge
//! C              constraint row, g(d + delta) = g + C delta: n on the slave DOFs,
//!                -(1 - xi) n on a's, -xi n on b's (Hughes II-13..II-16)
//! tau            Lagrange multiplier: the compressive normal force, +tau n on the slave
//! entry          (pair, slave index): one slave of one pair
//! ```

pub mod conditions;
pub mod energy;
pub mod explicit;
pub mod gap;
pub mod geometry;
mod grid;
pub mod impacts;
pub mod linearization;
pub mod mortar;
mod multipliers;
pub mod own;
pub mod penetration;
pub mod projectile;
pub mod search;
pub mod setup;
pub mod status;
pub mod step;
pub mod traction;

pub use geometry::{
    ContactPair, Covered, Discretization, Friction, Gap, Holds, Master, Obstacle, ObstacleMotion,
    PairOptions, Projectile, winding_number,
};
pub use impacts::{ImpactMotion, LumpedMass, apply_conditions};
pub use mortar::MortarSurface;
pub use own::OwnSurface;
pub use search::{SlaveGap, penetration_limits, runaway_penetration, slave_gaps};
pub use status::{ContactState, MasterEntry, NodalStatus};
pub use step::{
    ConstrainedSolution, ContactResult, Events, Inside, Pass, Settled, Tangential, Unsettled,
};
pub use traction::Tractions;

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// How a body's surface nodes carry area, for their impedance rho c A.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Section {
    /// A rod of the given cross-section area.
    Rod { area: f64 },
    /// A plane body of the given thickness (1 in plane strain: per unit depth).
    Plane { thickness: f64 },
    /// An axisymmetric body: a node's edges sweep 2 pi r.
    Axisymmetric,
}

/// What the impact and release conditions need to know of a body.
#[derive(Debug, Clone, PartialEq)]
pub struct BodySurface {
    pub section: Section,
    /// sqrt(M rho), M the modulus of a plane wave (lambda + 2 mu; E / (1 - nu^2) in plane
    /// stress; E for rods): the impedance per unit area.
    pub impedance_per_area: f64,
    /// The boundary edges at each node of the body (global node ids), for the tributary
    /// area; the body's first global node.
    pub boundary_at_node: Vec<Vec<[usize; 2]>>,
    /// The body's boundary edges (global ids), each once: the closed outline in which a
    /// master node's penetration into this body is sought.
    pub boundary: Vec<[usize; 2]>,
    pub node_offset: usize,
    /// The nodes that can meet another body (global ids, ascending): those with boundary
    /// edges, every node of a rod (which has none). Kept from `BodySurface::new`: the
    /// penetration check of every explicit step reads them (it scanned every node's edge list
    /// for them, 2541 nodes a step on the aluminium rod).
    boundary_nodes: Vec<usize>,
}

impl BodySurface {
    /// A body's surface from its boundary edges at each node and once each (global ids).
    pub fn new(
        (section, impedance_per_area): (Section, f64),
        boundary_at_node: Vec<Vec<[usize; 2]>>,
        boundary: Vec<[usize; 2]>,
        node_offset: usize,
    ) -> BodySurface {
        let rod = boundary.is_empty();
        let boundary_nodes = (boundary_at_node.iter().enumerate())
            .filter(|(_, edges)| rod || !edges.is_empty())
            .map(|(n, _)| node_offset + n)
            .collect();
        BodySurface {
            section,
            impedance_per_area,
            boundary_at_node,
            boundary,
            node_offset,
            boundary_nodes,
        }
    }

    /// The nodes that can meet another body (global ids, ascending).
    pub fn boundary_nodes(&self) -> &[usize] {
        &self.boundary_nodes
    }
}

/// How a node's boundary edges share their area (`Interfaces::tributary_area`); the two
/// differ in axisymmetry only, where an edge sweeps 2 pi r.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Share {
    /// The surface of revolution of the half edge next to the node, 2 pi (L/2) (3 r + r')/4.
    HalfEdges,
    /// The integral of the node's shape function over the edge, 2 pi L (2 r + r') / 6: the
    /// share of a uniform pressure's consistent nodal force, so a node's force over it is
    /// the pressure, on the axis too (where the half edge gives 3/4 of it).
    Consistent,
}

/// Whether an obstacle of `pairs` moves.
pub fn obstacles_move(pairs: &[ContactPair]) -> bool {
    pairs.iter().any(|p| p.moving_obstacle().is_some())
}

/// Places the moving obstacles of `pairs` at time `t`.
pub fn place_obstacles(pairs: &mut [ContactPair], t: f64) {
    for pair in pairs {
        if let Master::Obstacle(o) = &mut pair.master {
            o.place(t);
        }
    }
}

/// Per DOF, the component of `quantity` of the moving obstacle of the first pair that holds
/// the DOF's node as a slave (0 elsewhere); None where no obstacle of `pairs` moves. The
/// implicit driver books with it what a moving obstacle supplies (theory 8.3f).
pub fn obstacle_by_dof(
    pairs: &[ContactPair],
    dofs: usize,
    quantity: impl Fn(&ObstacleMotion) -> [f64; 2],
) -> Option<Vec<f64>> {
    if !obstacles_move(pairs) {
        return None;
    }
    let mut out = vec![0.0; dofs];
    let mut held = vec![false; dofs / 2];
    for pair in pairs {
        let Some(motion) = pair.moving_obstacle() else {
            continue;
        };
        let value = quantity(motion);
        for &s in &pair.slaves {
            if !std::mem::replace(&mut held[s], true) {
                out[2 * s] = value[0];
                out[2 * s + 1] = value[1];
            }
        }
    }
    Some(out)
}

/// Where a projectile is (`geometry::Projectile`): its translation u_R and its velocity.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Flight {
    pub displacement: [f64; 2],
    pub velocity: [f64; 2],
    /// The rotation theta about its centre and its rate (zero for one that translates only).
    #[serde(default)]
    pub rotation: f64,
    #[serde(default)]
    pub angular_velocity: f64,
}

impl ContactState {
    /// Places the obstacles of `pairs` where the run has them at time `t`: the prescribed
    /// ones by their motion, the projectiles at their flights' translations.
    pub fn place(&self, pairs: &mut [ContactPair], t: f64) {
        for pair in pairs {
            if let Master::Obstacle(o) = &mut pair.master {
                self.place_obstacle(o, t);
            }
        }
    }

    /// Places obstacle `o` where the run has it at time `t` (see `place`).
    pub fn place_obstacle(&self, o: &mut Obstacle, t: f64) {
        o.place(t);
        let flight = (o.projectile.as_ref()).and_then(|p| self.flights.get(p.index));
        if let Some(&Flight {
            displacement,
            rotation,
            ..
        }) = flight
        {
            o.place_at(displacement, rotation);
        }
    }

    /// `pairs` with their obstacles where the run has them at time `t` (`place`): the pairs
    /// themselves where none moves.
    pub fn placed<'p>(
        &self,
        pairs: &'p [ContactPair],
        t: f64,
    ) -> std::borrow::Cow<'p, [ContactPair]> {
        if !obstacles_move(pairs) && pairs.iter().all(|p| p.projectile().is_none()) {
            return std::borrow::Cow::Borrowed(pairs);
        }
        let mut moved = pairs.to_vec();
        self.place(&mut moved, t);
        std::borrow::Cow::Owned(moved)
    }

    /// The translation and velocity of obstacle `o` at time `t`: prescribed by its motion, a
    /// projectile's where the run has it (its start before a step has tracked it), zero for
    /// one at rest.
    pub fn obstacle_motion(&self, o: &Obstacle, t: f64) -> ([f64; 2], [f64; 2]) {
        match (&o.motion, &o.projectile) {
            (Some(m), _) => (m.at(t), m.velocity(t)),
            (None, Some(p)) => self
                .flights
                .get(p.index)
                .map_or(([0.0; 2], p.velocity), |f| (f.displacement, f.velocity)),
            (None, None) => ([0.0; 2], [0.0; 2]),
        }
    }
}

/// The contact problem of a model: its pairs and, per body, its surface data.
#[derive(Debug, Clone, PartialEq)]
pub struct Interfaces {
    pub pairs: Vec<ContactPair>,
    pub bodies: Vec<BodySurface>,
}

impl Interfaces {
    /// Places the moving obstacles of the pairs at time `t` (`Obstacle::place`).
    pub fn place_obstacles(&mut self, t: f64) {
        place_obstacles(&mut self.pairs, t);
    }

    /// The impedance rho c A of global node `node` of body `body` (A: its tributary contact
    /// area at the positions `coords`: the half of each boundary edge next to the node, times
    /// the thickness in plane bodies; in axisymmetry the surface of revolution of those
    /// halves, 2 pi (L/2) (3 r_node + r_other) / 4 per edge, so that a node on the axis
    /// carries the disc pi (r_other / 2)^2 and not zero).
    pub fn impedance(&self, body: usize, node: usize, coords: &[[f64; 2]]) -> f64 {
        let all = |_: [usize; 2]| true;
        self.bodies[body].impedance_per_area
            * self.tributary_area(body, node, coords, (&all, Share::HalfEdges))
    }

    /// The tributary area of global node `node` of body `body` at the positions `coords`
    /// over its boundary edges that `counts`, shared as `share` says (a rod: its
    /// cross-section).
    pub fn tributary_area(
        &self,
        body: usize,
        node: usize,
        coords: &[[f64; 2]],
        (counts, share): (&dyn Fn([usize; 2]) -> bool, Share),
    ) -> f64 {
        let b = &self.bodies[body];
        let edges = b.boundary_at_node[node - b.node_offset]
            .iter()
            .filter(|e| counts(**e));
        let length =
            |a: [f64; 2], c: [f64; 2]| ((a[0] - c[0]).powi(2) + (a[1] - c[1]).powi(2)).sqrt();
        match b.section {
            Section::Rod { area } => area,
            Section::Plane { thickness } => {
                let half_edges: f64 = edges
                    .map(|[p, q]| 0.5 * length(coords[*p], coords[*q]))
                    .sum();
                half_edges * thickness
            }
            Section::Axisymmetric => edges
                .map(|[p, q]| {
                    let other = if *p == node { *q } else { *p };
                    let (r, r_other) = (coords[node][0].max(0.0), coords[other][0].max(0.0));
                    let length = length(coords[*p], coords[*q]);
                    match share {
                        Share::HalfEdges => 2.0 * PI * 0.5 * length * (3.0 * r + r_other) / 4.0,
                        Share::Consistent => 2.0 * PI * length * (2.0 * r + r_other) / 6.0,
                    }
                })
                .sum(),
        }
    }
}

/// Per-pair values (forces) folded onto the pairs the history reports: the reverse pass of a
/// balanced pair (`ContactPair::balances`) adds its value to its first pass's and has no
/// column of its own, so `contact_force[NAME]` is the pair's whole force.
pub fn fold_passes(pairs: &[ContactPair], values: &[f64]) -> Vec<f64> {
    let mut folded = values.to_vec();
    for (p, pair) in pairs.iter().enumerate() {
        if let Some(first) = pair.balances {
            folded[first] += values[p];
        }
    }
    pairs
        .iter()
        .zip(folded)
        .filter(|(pair, _)| pair.balances.is_none())
        .map(|(_, value)| value)
        .collect()
}

/// The contact block of summary.json.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct ContactSummary {
    pub first_contact_time: Option<f64>,
    pub last_release_time: Option<f64>,
    pub peak_force: f64,
    pub peak_contact_radius: f64,
    /// The most negative slave gap after any step (penetration if < 0), null without contact.
    pub min_gap: Option<f64>,
    /// The deepest penetration of either surface into the other body after any step (a
    /// slave into its master, or a deformable master's node into the slave body), >= 0;
    /// null without contact.
    #[serde(default)]
    pub max_penetration: Option<f64>,
    /// The pairs (by name) that never closed in the run; empty when every pair closed.
    #[serde(default)]
    pub never_closed: Vec<String>,
    /// The largest total of the raw normal forces (the multipliers of each step); with a
    /// `force_window`, `peak_force` is the largest of the forces averaged over it.
    #[serde(default)]
    pub peak_force_raw: f64,
    #[serde(default)]
    pub force_window: Option<f64>,
    /// Per pair, in scene order: the most slave nodes closed at once.
    #[serde(default)]
    pub closed_at_widest: Vec<usize>,
    /// The pairs (by name) closed at the end of the run.
    #[serde(default)]
    pub closed_at_end: Vec<String>,
    /// Where the deepest penetration of a body into an obstacle or another body was.
    #[serde(default)]
    pub deepest: Option<penetration::DeepestNode>,
    /// The end of the step whose raw normal force (the pairs' total) was the largest.
    #[serde(default)]
    pub peak_force_time: Option<f64>,
    /// The first slave that went past the open end of its obstacle.
    #[serde(default)]
    pub past_end: Option<penetration::PastEndNode>,
    /// Per pair, in scene order, the energy its contact took and its friction dissipated
    /// over the run (dynamic runs; empty in statics, which books no contact energy).
    #[serde(default)]
    pub pairs: Vec<PairEnergies>,
}

/// One pair's energies in summary.json `contact.pairs` (history.csv `contact_work[NAME]`,
/// `friction_work[NAME]`; `energy`'s `contact_work` and `friction_work` are their sums).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PairEnergies {
    pub name: String,
    /// The energy its normal rows took from the bodies (>= 0 where nothing is created).
    pub contact_work: f64,
    /// The energy its friction dissipated (>= 0; 0 without friction).
    pub friction_work: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: the tributary contact area of an axisymmetric surface node is the surface of
    /// revolution of its half-edges. Setup: three nodes of a flat face z = 0 at r = 0, 1, 3
    /// (edges [0, 1] and [1, 2]), impedance per area 1. Reference (by hand): the axis node
    /// carries the disc r < 1/2, pi / 4; the middle node the annulus 1/2 < r < 2, pi (4 - 1/4);
    /// the end node the annulus 2 < r < 3, pi (9 - 4). The three add up to the face, 9 pi.
    /// Tolerance 1e-14 relative: a few operations on O(1) numbers.
    #[test]
    fn axisymmetric_areas_are_the_rings_of_the_half_edges() {
        let coords = [[0.0, 0.0], [1.0, 0.0], [3.0, 0.0]];
        let interfaces = Interfaces {
            pairs: Vec::new(),
            bodies: vec![BodySurface::new(
                (Section::Axisymmetric, 1.0),
                vec![vec![[0, 1]], vec![[0, 1], [1, 2]], vec![[1, 2]]],
                vec![[0, 1], [1, 2]],
                0,
            )],
        };
        let exact = [PI / 4.0, PI * (4.0 - 0.25), PI * (9.0 - 4.0)];
        for (node, area) in exact.iter().enumerate() {
            let z = interfaces.impedance(0, node, &coords);
            assert!(
                (z / area - 1.0).abs() < 1e-14,
                "node {node}: {z} against {area}"
            );
        }
    }
}
