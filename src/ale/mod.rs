//! Arbitrary Lagrangian-Eulerian steps on a fixed-topology Quad4 mesh, on plain arrays: move
//! the nodes by a smoother (`smooth`), then carry the element quantities, the mass and the
//! nodal momentum from the old elements to the new ones through the regions the interior
//! edges sweep (`remap`; docs/theory.md 8.11). The explicit driver calls them every few steps
//! (`analysis.ale`); nothing here knows the scene or the material.
//!
//! Legend of the momentum remap (element e with old corner masses m_a^e, new ones n_a^e, node a
//! with velocity v_a; u_e = Q_e / m_e the element's mean velocity)
//! ```text
//! Q_e   = sum_a m_a^e v_a                         the element's momentum before
//! dQ_e  = sum_k F_k(rho) u_d(x_k)                 what the swept regions bring (remap.rs)
//! R_e   = Q_e + dQ_e - sum_a n_a^e v_a            what the new corners do not yet hold
//! p_a   = sum_e n_a^e v_a + sum_e n_a^e / n_e R_e,   v_a' = p_a / sum_e n_a^e
//! ```
//! With no motion of the mesh R_e = 0 and every velocity stays as it was; a uniform velocity
//! stays uniform; sum_a p_a = sum_e (Q_e + dQ_e) = sum_e Q_e, since each flux leaves one
//! element and enters another: the momentum is conserved to round-off.

pub mod geometry;
pub mod remap;
pub mod smooth;
pub mod topology;

pub use remap::Sweep;
pub use smooth::{Freedom, Rules, Smoother, smooth};
pub use topology::Topology;

/// The nodal velocities after a remap (see the legend): `velocity` (2 per node) in place;
/// `old` and `new` the corner masses of each element before and after (the new ones summing
/// to the remapped element masses), `mass_flux` the mass through each interior edge
/// (`Sweep::remap_mass`).
pub fn remap_velocity(
    topology: &Topology,
    sweep: &Sweep,
    (old, new): (&[[f64; 4]], &[[f64; 4]]),
    mass_flux: &[f64],
    velocity: &mut [f64],
) {
    let cells = &topology.cells;
    let mut mean = vec![0.0; 2 * cells.len()];
    let mut momentum = vec![0.0; 2 * cells.len()];
    for (e, cell) in cells.iter().enumerate() {
        let m: f64 = old[e].iter().sum();
        for j in 0..2 {
            let q: f64 = (0..4).map(|a| old[e][a] * velocity[2 * cell[a] + j]).sum();
            momentum[2 * e + j] = q;
            mean[2 * e + j] = q / m;
        }
    }
    let gained = sweep.momentum_change(topology, &mean, mass_flux);
    let mut p = vec![0.0; velocity.len()];
    let mut nodal = vec![0.0; topology.nodes];
    for (e, cell) in cells.iter().enumerate() {
        let total: f64 = new[e].iter().sum();
        for j in 0..2 {
            let held: f64 = (0..4).map(|a| new[e][a] * velocity[2 * cell[a] + j]).sum();
            let rest = momentum[2 * e + j] + gained[2 * e + j] - held;
            for a in 0..4 {
                p[2 * cell[a] + j] +=
                    new[e][a] * velocity[2 * cell[a] + j] + new[e][a] / total * rest;
            }
        }
        for a in 0..4 {
            nodal[cell[a]] += new[e][a];
        }
    }
    for (n, m) in nodal.iter().enumerate() {
        if *m > 0.0 {
            velocity[2 * n] = p[2 * n] / m;
            velocity[2 * n + 1] = p[2 * n + 1] / m;
        }
    }
}

#[cfg(test)]
mod tests;
