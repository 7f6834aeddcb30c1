//! The contact tractions the frames show: per node of a contact surface, the normal pressure
//! and the tangential (friction) traction, the contact's nodal forces over the node's
//! tributary area.
//!
//! Legend
//! ```text
//! A_i        tributary area of node i over the edges of its contact surface (both of an
//!            edge's nodes on the surface): the integral of its shape function over them,
//!            half of each edge times the thickness, 2 pi L (2 r_i + r_j) / 6 per edge in
//!            axisymmetry (a uniform pressure's consistent nodal force over A_i is the
//!            pressure, on the axis too), a rod's cross-section (`Interfaces::tributary_area`)
//! slave i    p_i = sum over its pairs of tau / A_i,  s_i = sum of f / A_i  (tau, f the
//!            entry's normal and tangential multipliers: sum_i p_i A_i is the pairs' force
//!            of history.csv exactly)
//! master m   p_m = -F_m . n_m / A_m,  s_m = F_m . t_m / A_m  (a deformable master: F_m the
//!            pair's force on the node, n_m the mean outward normal of its master edges,
//!            t_m the mean edge direction, solid on the left)
//! ```
//! p > 0 is compression. A slave set of a single node (no edge on the surface) takes the
//! area of all its boundary edges.

use super::{ContactState, Interfaces, Master, Share};

const CONSISTENT: Share = Share::Consistent;

/// Per node (global ids): the contact pressure p (compressive > 0) and the tangential
/// traction s, zero off the contact surfaces and on open entries.
#[derive(Debug, Clone, PartialEq)]
pub struct Tractions {
    pub pressure: Vec<f64>,
    pub shear: Vec<f64>,
}

impl ContactState {
    /// The tractions at the positions `coords` (module legend).
    pub fn tractions(&self, interfaces: &Interfaces, coords: &[[f64; 2]]) -> Tractions {
        let mut out = Tractions {
            pressure: vec![0.0; coords.len()],
            shear: vec![0.0; coords.len()],
        };
        for (p, pair) in interfaces.pairs.iter().enumerate() {
            let mut surface = pair.slaves.clone();
            surface.sort_unstable();
            let on_surface = |[a, b]: [usize; 2]| {
                surface.binary_search(&a).is_ok() && surface.binary_search(&b).is_ok()
            };
            for (k, &s) in pair.slaves.iter().enumerate() {
                if !self.active[p][k] {
                    continue;
                }
                let all = |_: [usize; 2]| true;
                let mut area = interfaces.tributary_area(
                    pair.slave_body,
                    s,
                    coords,
                    (&on_surface, CONSISTENT),
                );
                if area <= 0.0 {
                    area =
                        interfaces.tributary_area(pair.slave_body, s, coords, (&all, CONSISTENT));
                }
                if area > 0.0 {
                    out.pressure[s] += self.force[p][k] / area;
                    out.shear[s] += self.tangential[p][k] / area;
                }
            }
            if let Master::Segments { body, edges, .. } = &pair.master {
                self.add_master_tractions(interfaces, coords, (p, *body, edges), &mut out);
            }
        }
        out
    }

    /// A deformable master's tractions from pair `p`'s forces on its nodes (module legend).
    fn add_master_tractions(
        &self,
        interfaces: &Interfaces,
        coords: &[[f64; 2]],
        (p, body, edges): (usize, usize, &[[usize; 2]]),
        out: &mut Tractions,
    ) {
        let only = |v: &[Vec<f64>]| -> Vec<Vec<f64>> {
            v.iter()
                .enumerate()
                .map(|(q, f)| {
                    if q == p {
                        f.clone()
                    } else {
                        vec![0.0; f.len()]
                    }
                })
                .collect()
        };
        let force = self.nodal_forces_of(
            &interfaces.pairs,
            coords,
            &only(&self.force),
            &only(&self.tangential),
        );
        let mut sorted: Vec<[usize; 2]> = edges
            .iter()
            .map(|e| [e[0].min(e[1]), e[0].max(e[1])])
            .collect();
        sorted.sort_unstable();
        let on_surface = |[a, b]: [usize; 2]| sorted.binary_search(&[a.min(b), a.max(b)]).is_ok();
        let mut nodes: Vec<usize> = edges.iter().flatten().copied().collect();
        nodes.sort_unstable();
        nodes.dedup();
        for m in nodes {
            let f = [force[2 * m], force[2 * m + 1]];
            if f == [0.0, 0.0] {
                continue;
            }
            // the mean direction of the master edges at m (solid on the left of a -> b)
            let mut t = [0.0, 0.0];
            for [a, b] in edges.iter().filter(|[a, b]| *a == m || *b == m) {
                let d = [coords[*b][0] - coords[*a][0], coords[*b][1] - coords[*a][1]];
                let length = d[0].hypot(d[1]);
                if length > 0.0 {
                    t = [t[0] + d[0] / length, t[1] + d[1] / length];
                }
            }
            let norm = t[0].hypot(t[1]);
            let area = interfaces.tributary_area(body, m, coords, (&on_surface, CONSISTENT));
            if norm == 0.0 || area <= 0.0 {
                continue;
            }
            let t = [t[0] / norm, t[1] / norm];
            let n = [t[1], -t[0]];
            out.pressure[m] -= (f[0] * n[0] + f[1] * n[1]) / area;
            out.shear[m] += (f[0] * t[0] + f[1] * t[1]) / area;
        }
    }
}
