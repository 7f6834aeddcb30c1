//! Explicit contact: forward-increment Lagrange multipliers on the lumped mass (Carpenter,
//! Taylor & Katona 1991), in the velocity-Verlet form of central difference.
//!
//! Legend (a step of length h from t_n, the step before it h_prev)
//! ```text
//! mu        multipliers of (C M^-1 C^T) mu = -g; the correction delta = M^-1 C^T mu
//! J         the step's impulse, M delta / h = C^T mu / h (delta / h enters v_{n+1/2})
//! f_step    J / h = C^T mu / h^2: the force that does the step's contact work on du
//! span      the time an entry's multiplier stands for:
//!             (h_prev + h) / 2  an entry closed at t_n: v_{n+1/2} = v_{n-1/2}
//!                               + (h_prev + h) / 2 a_n, so the force holding it at t_n
//!                               carries that impulse (the averaged step of central
//!                               difference with varying steps)
//!             h                 an entry that closes in the step: its multiplier arrests the
//!                               approach within the step
//! f         mu / (h span): the reported force (history, frames, peak_force); f span = J
//!           per entry, so the impulses sum exactly, and a step clipped to a frame time
//!           (h << h_prev) reports the force of its neighbours, not J / h
//! ```

use super::Interfaces;
use super::active::ContactState;
use super::geometry::Gap;
use super::search::penetrating;

/// What an explicit contact step gives the driver.
pub struct ExplicitContact {
    /// The correction delta of the predicted increment (all DOFs).
    pub correction: Vec<f64>,
    /// The nodal forces f_step = C^T mu / h^2 on the rows at the start positions (all DOFs):
    /// what does the step's contact work on its corrected increment.
    pub step_force: Vec<f64>,
    /// The kinetic energy the entries that closed in this step lose to it: their relative
    /// normal velocity is stopped within the step (a perfectly inelastic impact of the
    /// contact nodes' lumped mass), (1/2) sum over them of (mu / h^2) C . delta. The work
    /// f_step . du of the corrected increment does not see it.
    pub impact_loss: f64,
}

impl ContactState {
    /// Explicit contact by forward-increment Lagrange multipliers (Carpenter, Taylor & Katona
    /// 1991) in the velocity-Verlet form of central difference: the predicted increment `du`
    /// (positions `start + du`) of a step of length `h` is corrected by delta = M^-1 C^T mu
    /// with (C M^-1 C^T) mu = -g over the penetrated entries, mu >= 0 (entries in tension
    /// leave, penetrations join, the rows are rebuilt at the corrected positions until the
    /// gaps close to TOL). The status takes the reported forces mu / (h span) (module legend;
    /// `previous` is the length of the step before, 0 before the first).
    #[allow(clippy::too_many_arguments)]
    pub fn explicit_step(
        &mut self,
        interfaces: &Interfaces,
        start: &[[f64; 2]],
        du: &[f64],
        inverse_mass: &[f64],
        h: f64,
        previous: f64,
        time: f64,
    ) -> ExplicitContact {
        let n = du.len();
        let mut delta = vec![0.0; n];
        let mut active: Vec<(usize, usize)> = Vec::new();
        // whether (p, k) is in `active`: keeps the bookkeeping linear in the slaves
        let mut in_active: Vec<Vec<bool>> = interfaces
            .pairs
            .iter()
            .map(|pair| vec![false; pair.slaves.len()])
            .collect();
        let mut mu_total: Vec<f64> = Vec::new();
        let position = |delta: &[f64], node: usize| {
            [
                start[node][0] + du[2 * node] + delta[2 * node],
                start[node][1] + du[2 * node + 1] + delta[2 * node + 1],
            ]
        };
        for _ in 0..20 {
            // gaps at the corrected positions; penetrated entries join
            let x = |node: usize| position(&delta, node);
            let joining: Vec<(usize, usize)> =
                penetrating(&interfaces.pairs, &x, &|p, k| in_active[p][k])
                    .map(|s| (s.pair, s.index))
                    .collect();
            let changed = !joining.is_empty();
            for (p, k) in joining {
                active.push((p, k));
                in_active[p][k] = true;
                mu_total.push(0.0);
            }
            let gaps: Vec<Gap> = active
                .iter()
                .map(|(p, k)| {
                    interfaces.pairs[*p]
                        .gap(interfaces.pairs[*p].slaves[*k], &x)
                        .expect("found above")
                })
                .collect();
            let worst = active
                .iter()
                .zip(&gaps)
                .map(|((p, _), g)| {
                    g.gap.abs()
                        / interfaces.pairs[*p]
                            .options
                            .tolerance
                            .max(f64::MIN_POSITIVE)
                })
                .fold(0.0, f64::max);
            if !changed && worst <= 1.0 {
                break;
            }
            let rows: Vec<Vec<(usize, f64)>> = active
                .iter()
                .zip(&gaps)
                .map(|((p, k), g)| g.row(interfaces.pairs[*p].slaves[*k]))
                .collect();
            let mu = lumped_multipliers(&rows, &gaps, inverse_mass);
            for (i, row) in rows.iter().enumerate() {
                for (dof, c) in row {
                    delta[*dof] += inverse_mass[*dof] * c * mu[i];
                }
                mu_total[i] += mu[i];
            }
            // entries pulled (total multiplier negative) leave and give back their correction
            for (i, row) in rows.iter().enumerate() {
                if mu_total[i] < 0.0 {
                    for (dof, c) in row {
                        delta[*dof] -= inverse_mass[*dof] * c * mu_total[i];
                    }
                    let (p, k) = active[i];
                    in_active[p][k] = false;
                }
            }
            let mut kept = mu_total.iter().map(|mu| *mu >= 0.0);
            active.retain(|_| kept.next().expect("one flag per entry"));
            mu_total.retain(|mu| *mu >= 0.0);
        }
        let forces: Vec<f64> = active
            .iter()
            .zip(&mu_total)
            .map(|((p, k), mu)| {
                let span = if self.active[*p][*k] && previous > 0.0 {
                    0.5 * (previous + h)
                } else {
                    h
                };
                mu / (h * span)
            })
            .collect();
        let end_position = |node: usize| position(&delta, node);
        let impact_loss: f64 = active
            .iter()
            .zip(&mu_total)
            .filter(|((p, k), _)| !self.active[*p][*k])
            .filter_map(|((p, k), mu)| {
                let pair = &interfaces.pairs[*p];
                let slave = pair.slaves[*k];
                let gap = pair.gap(slave, &end_position)?;
                let moved: f64 = gap.row(slave).iter().map(|(dof, c)| c * delta[*dof]).sum();
                Some(0.5 * mu / (h * h) * moved)
            })
            .sum();
        let mut step_forces: Vec<Vec<f64>> =
            self.force.iter().map(|f| vec![0.0; f.len()]).collect();
        for ((p, k), mu) in active.iter().zip(&mu_total) {
            step_forces[*p][*k] = mu / (h * h);
        }
        let released = self
            .active
            .iter()
            .zip(&in_active)
            .any(|(was, is)| was.iter().zip(is).any(|(was, is)| *was && !*is));
        let end: Vec<[f64; 2]> = (0..start.len())
            .map(|node| position(&delta, node))
            .collect();
        self.set(interfaces, &active, &forces, released, time, &end);
        let step_force = self.nodal_forces_of(&interfaces.pairs, start, &step_forces);
        ExplicitContact {
            correction: delta,
            step_force,
            impact_loss,
        }
    }
}

/// The multipliers mu of (C M^-1 C^T) mu = -g for the rows C of the explicit contact step
/// (lumped M). C M^-1 C^T couples two rows only through a shared DOF, so it is solved per
/// group of rows linked by shared DOFs (one row each on a rigid wall; a run of slaves on a
/// shared master segment otherwise; on a deformable master a continuous contact zone is one
/// group, so the gain is on rigid obstacles): dense LU of the groups instead of the whole
/// m x m matrix. A singular group (redundant rows, or rows on prescribed DOFs only, which no
/// multiplier can move) gets mu = 0 and is left to the penetration check; the others are
/// solved.
fn lumped_multipliers(rows: &[Vec<(usize, f64)>], gaps: &[Gap], inverse_mass: &[f64]) -> Vec<f64> {
    let m = rows.len();
    // union-find of the rows over their DOFs
    let mut parent: Vec<usize> = (0..m).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut owner: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    for (i, row) in rows.iter().enumerate() {
        for (dof, c) in row {
            if *c == 0.0 {
                continue;
            }
            if let Some(&j) = owner.get(dof) {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                parent[a] = b;
            } else {
                owner.insert(*dof, i);
            }
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for i in 0..m {
        let r = root(&mut parent, i);
        groups.entry(r).or_default().push(i);
    }
    let mut mu = vec![0.0; m];
    for members in groups.values() {
        let w = |i: usize, j: usize| -> f64 {
            rows[i]
                .iter()
                .map(|(a, ca)| {
                    rows[j]
                        .iter()
                        .filter(|(b, _)| b == a)
                        .map(|(_, cb)| ca * cb * inverse_mass[*a])
                        .sum::<f64>()
                })
                .sum()
        };
        let k = members.len();
        let matrix = nalgebra::DMatrix::from_fn(k, k, |a, b| w(members[a], members[b]));
        let rhs = nalgebra::DVector::from_fn(k, |a, _| -gaps[members[a]].gap);
        let Some(solution) = matrix.lu().solve(&rhs) else {
            continue;
        };
        for (a, &i) in members.iter().enumerate() {
            mu[i] = solution[a];
        }
    }
    mu
}
