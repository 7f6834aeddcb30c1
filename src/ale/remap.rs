//! The conservative remap of element quantities from the old to the new positions of the
//! nodes of a fixed-topology Quad4 mesh: fluxes through the regions the interior edges sweep
//! (Margolin & Shashkov 2003; Benson 1992 section 4), each the integral of the donor
//! element's limited linear reconstruction (MUSCL, van Leer 1979) over the swept region.
//!
//! Legend (edge k between elements L and R, a -> b counter-clockwise in L)
//! ```text
//! S_k        the quadrilateral (a_old, a_new, b_new, b_old): its signed measure dV_k > 0
//!            when L grows into R; its moments M_k (geometry.rs, radius-weighted in
//!            axisymmetry)
//! d          the donor: R when dV_k > 0, else L
//! phi_d(x)   Phi_d + alpha_d g_d . (x - c_d): Phi_d the element mean, c_d its weighted
//!            centroid, g_d the least-squares gradient over the elements sharing a node with
//!            d, alpha_d in [0, 1] Barth & Jespersen's limiter: phi_d at the midpoints of d's
//!            interior edges stays within the means of d's neighbourhood
//! F_k        int_{S_k} phi_d = Phi_d dV_k + alpha_d g_d . (M_k - c_d dV_k)
//! intensive  Phi_L' = (Phi_L V_L + sum_k F_k) / (V_L + sum_k dV_k)   (+ for L, - for R)
//! mass       m_L'   = m_L + sum_k F_k(rho),  rho = m / V
//! momentum   dQ_L   = sum_k F_k(rho) u_d(x_k),  u = Q / m the element mean velocity, x_k the
//!            midpoint of S_k
//! ```
//! Exact on linear fields (the reconstruction is, and the flux integrates it exactly);
//! mass, and the momentum changes, sum to zero over the mesh to round-off (each flux leaves
//! one element and enters the other); first order where the limiter acts.

use super::geometry::{Moments, moments};
use super::topology::{Edge, Topology};

/// The geometry of one remap: the old and new element moments and the swept regions.
#[derive(Debug, Clone)]
pub struct Sweep {
    pub old: Vec<Moments>,
    pub new: Vec<Moments>,
    /// Per interior edge of the topology, the signed moments of its swept region (positive
    /// volume: its left element grows).
    pub swept: Vec<Moments>,
    /// Per interior edge, the midpoint of its swept region's four corners.
    pub midpoint: Vec<[f64; 2]>,
}

impl Sweep {
    pub fn new(
        topology: &Topology,
        old: &[[f64; 2]],
        new: &[[f64; 2]],
        axisymmetric: bool,
    ) -> Sweep {
        let cell_moments = |x: &[[f64; 2]]| -> Vec<Moments> {
            (0..topology.cells.len())
                .map(|e| moments(&topology.corners(x, e), axisymmetric))
                .collect()
        };
        let (mut swept, mut midpoint) = (Vec::new(), Vec::new());
        for edge in &topology.edges {
            let region = [old[edge.a], new[edge.a], new[edge.b], old[edge.b]];
            swept.push(moments(&region, axisymmetric));
            midpoint.push([0, 1].map(|i| 0.25 * region.iter().map(|p| p[i]).sum::<f64>()));
        }
        Sweep {
            old: cell_moments(old),
            new: cell_moments(new),
            swept,
            midpoint,
        }
    }

    /// The largest share of an element's old volume that its edges sweep out of it (the
    /// remap's Courant number: below 1 the donor's volume is never used up).
    pub fn courant(&self, topology: &Topology) -> f64 {
        let mut out = vec![0.0; self.old.len()];
        for (edge, s) in topology.edges.iter().zip(&self.swept) {
            out[donor(edge, s)] += s.volume.abs();
        }
        out.iter()
            .zip(&self.old)
            .map(|(o, m)| o / m.volume.abs())
            .fold(0.0, f64::max)
    }

    /// The fluxes of `count` fields (element-major `values`, means over the old elements)
    /// through each interior edge (edge-major, `count` each; positive into the left element).
    pub fn fluxes(&self, topology: &Topology, values: &[f64], count: usize) -> Vec<f64> {
        let slopes = limited_gradients(topology, self, values, count);
        let mut fluxes = vec![0.0; topology.edges.len() * count];
        for (k, (edge, s)) in topology.edges.iter().zip(&self.swept).enumerate() {
            let d = donor(edge, s);
            let c = self.old[d].centroid();
            let arm = [s.first[0] - c[0] * s.volume, s.first[1] - c[1] * s.volume];
            for j in 0..count {
                let g = &slopes[(d * count + j) * 2..(d * count + j) * 2 + 2];
                fluxes[k * count + j] =
                    values[d * count + j] * s.volume + g[0] * arm[0] + g[1] * arm[1];
            }
        }
        fluxes
    }

    /// The net inflow of each element of edge quantities `per_edge` (`count` per edge).
    pub fn net(&self, topology: &Topology, per_edge: &[f64], count: usize) -> Vec<f64> {
        let mut net = vec![0.0; self.old.len() * count];
        for (k, edge) in topology.edges.iter().enumerate() {
            for j in 0..count {
                net[edge.left * count + j] += per_edge[k * count + j];
                net[edge.right * count + j] -= per_edge[k * count + j];
            }
        }
        net
    }

    /// The volume the swept regions bring into each element: the old volume plus this is the
    /// volume the remapped means refer to (the new geometric volume, less what boundary
    /// nodes sliding along a curved boundary cut off).
    pub fn volume_in(&self, topology: &Topology) -> Vec<f64> {
        let volumes: Vec<f64> = self.swept.iter().map(|s| s.volume).collect();
        let net = self.net(topology, &volumes, 1);
        self.old
            .iter()
            .zip(net)
            .map(|(m, dv)| m.volume + dv)
            .collect()
    }

    /// Remaps `count` intensive fields (volume means, element-major) in place.
    pub fn remap_intensive(&self, topology: &Topology, values: &mut [f64], count: usize) {
        let net = self.net(topology, &self.fluxes(topology, values, count), count);
        let volume = self.volume_in(topology);
        for (e, m) in self.old.iter().enumerate() {
            for j in 0..count {
                let i = e * count + j;
                values[i] = (values[i] * m.volume + net[i]) / volume[e];
            }
        }
    }

    /// Remaps the element masses in place (the density m / V moved by the fluxes); returns
    /// the mass through each interior edge (positive into its left element).
    pub fn remap_mass(&self, topology: &Topology, mass: &mut [f64]) -> Vec<f64> {
        let density: Vec<f64> = mass
            .iter()
            .zip(&self.old)
            .map(|(m, v)| m / v.volume)
            .collect();
        let flux = self.fluxes(topology, &density, 1);
        for (m, dm) in mass.iter_mut().zip(self.net(topology, &flux, 1)) {
            *m += dm;
        }
        flux
    }

    /// The momentum each element gains: the mass through each edge times the donor's limited
    /// mean velocity (`velocity`: 2 per element) at the swept region's midpoint.
    pub fn momentum_change(
        &self,
        topology: &Topology,
        velocity: &[f64],
        mass_flux: &[f64],
    ) -> Vec<f64> {
        let slopes = limited_gradients(topology, self, velocity, 2);
        let mut carried = vec![0.0; topology.edges.len() * 2];
        for (k, (edge, s)) in topology.edges.iter().zip(&self.swept).enumerate() {
            let d = donor(edge, s);
            let c = self.old[d].centroid();
            let arm = [self.midpoint[k][0] - c[0], self.midpoint[k][1] - c[1]];
            for j in 0..2 {
                let g = &slopes[(d * 2 + j) * 2..(d * 2 + j) * 2 + 2];
                let u = velocity[d * 2 + j] + g[0] * arm[0] + g[1] * arm[1];
                carried[k * 2 + j] = mass_flux[k] * u;
            }
        }
        self.net(topology, &carried, 2)
    }
}

/// The element whose material an edge's swept region takes: the right one when the left
/// grows (positive swept volume), else the left.
fn donor(edge: &Edge, swept: &Moments) -> usize {
    if swept.volume > 0.0 {
        edge.right
    } else {
        edge.left
    }
}

/// Each element's limited gradient of each field (element-major, field-major, 2 each): least
/// squares over the element's neighbourhood, times Barth & Jespersen's alpha.
fn limited_gradients(topology: &Topology, sweep: &Sweep, values: &[f64], count: usize) -> Vec<f64> {
    let cells = topology.cells.len();
    let centroid: Vec<[f64; 2]> = sweep.old.iter().map(Moments::centroid).collect();
    let mut slopes = vec![0.0; cells * count * 2];
    for e in 0..cells {
        let near = &topology.neighbourhood[e];
        let c = centroid[e];
        let (mut axx, mut axy, mut ayy) = (0.0, 0.0, 0.0);
        for f in near {
            let d = [centroid[*f][0] - c[0], centroid[*f][1] - c[1]];
            axx += d[0] * d[0];
            axy += d[0] * d[1];
            ayy += d[1] * d[1];
        }
        let det = axx * ayy - axy * axy;
        if near.len() < 2 || det <= 1e-12 * (axx + ayy) * (axx + ayy) {
            continue; // no gradient: first order here
        }
        for j in 0..count {
            let own = values[e * count + j];
            let (mut bx, mut by) = (0.0, 0.0);
            let (mut low, mut high) = (own, own);
            for f in near {
                let d = [centroid[*f][0] - c[0], centroid[*f][1] - c[1]];
                let dv = values[f * count + j] - own;
                bx += d[0] * dv;
                by += d[1] * dv;
                low = low.min(values[f * count + j]);
                high = high.max(values[f * count + j]);
            }
            let g = [(ayy * bx - axy * by) / det, (axx * by - axy * bx) / det];
            let mut alpha: f64 = 1.0;
            for k in &topology.edges_of[e] {
                let x = sweep.midpoint[*k];
                let delta = g[0] * (x[0] - c[0]) + g[1] * (x[1] - c[1]);
                if delta > 0.0 {
                    alpha = alpha.min((high - own) / delta);
                } else if delta < 0.0 {
                    alpha = alpha.min((low - own) / delta);
                }
            }
            let i = (e * count + j) * 2;
            slopes[i] = alpha.max(0.0) * g[0];
            slopes[i + 1] = alpha.max(0.0) * g[1];
        }
    }
    slopes
}
