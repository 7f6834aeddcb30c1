//! Contact, in one place: detection on the current configuration (`geometry`, `search`),
//! the active set and the event logic of a step (`active`), Hughes' impact and release
//! conditions (`conditions`) and the explicit forward-increment multipliers (`explicit`).
//! It works on plain arrays (positions, masses, DOF indices) and never sees the model or
//! the assembled system: the implicit solver receives the rows of the active entries and
//! returns their multipliers (Hughes, Taylor & Sackman 1975, section II; Greco & Coda 2003).
//!
//! Legend
//! ```text
//! slave s        a node of the slave set, position x_s
//! master         a polyline of segments [a, b] with the solid on the left of a -> b (the
//!                master body's boundary edges, or a rigid obstacle), or single nodes with a
//!                given normal (node-to-node, Hughes II-4)
//! xi             projection parameter of x_s on the nearest segment, p = (1 - xi) a + xi b
//! n              unit normal out of the master at p (right of a -> b)
//! g              gap (x_s - p) . n: > 0 apart, < 0 penetrated (Hughes II-7: d = x^1 - x^2)
//! c(S)           winding number -1/(2 pi) sum of the angle increments seen from S over a
//!                closed boundary (Greco eq 17): 1 inside, 0 outside, alpha/(2 pi) on a
//!                corner of angle alpha, 1/2 on a smooth edge
//! C              constraint row, g(d + delta) = g + C delta: n on the slave DOFs,
//!                -(1 - xi) n on a's, -xi n on b's (Hughes II-13..II-16)
//! tau            Lagrange multiplier: the compressive normal force, +tau n on the slave
//! entry          (pair, slave index): one slave of one pair
//! ```

pub mod active;
pub mod conditions;
pub mod explicit;
pub mod geometry;
pub mod search;

pub use active::{
    ConstrainedSolution, ContactResult, ContactState, Events, NodalStatus, Tangential, Unsettled,
    apply_conditions,
};
pub use geometry::{ContactPair, Friction, Gap, Master, Obstacle, PairOptions, winding_number};
pub use search::{SlaveGap, penetration_limits, runaway_penetration, slave_gaps};

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
    pub node_offset: usize,
}

/// The contact problem of a model: its pairs and, per body, its surface data.
#[derive(Debug, Clone, PartialEq)]
pub struct Interfaces {
    pub pairs: Vec<ContactPair>,
    pub bodies: Vec<BodySurface>,
}

impl Interfaces {
    /// The impedance rho c A of global node `node` of body `body` (A: its tributary contact
    /// area at the positions `coords`).
    pub fn impedance(&self, body: usize, node: usize, coords: &[[f64; 2]]) -> f64 {
        let b = &self.bodies[body];
        let half_edges = || -> f64 {
            b.boundary_at_node[node - b.node_offset]
                .iter()
                .map(|[p, q]| {
                    let (a, c) = (coords[*p], coords[*q]);
                    0.5 * ((a[0] - c[0]).powi(2) + (a[1] - c[1]).powi(2)).sqrt()
                })
                .sum()
        };
        let area = match b.section {
            Section::Rod { area } => area,
            Section::Plane { thickness } => half_edges() * thickness,
            Section::Axisymmetric => half_edges() * 2.0 * PI * coords[node][0].max(0.0),
        };
        b.impedance_per_area * area
    }
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
}
