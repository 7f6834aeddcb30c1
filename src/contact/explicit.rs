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
//! W_c       the step's contact work, f_step . du on the corrected increment. An entry that
//!           closes in the step is arrested within it, which at a Courant number below 1
//!           takes the closing nodes' kinetic energy out of the discrete system without
//!           work of f_step (1.1 % on models/rod_wall.toml: its face nodes hold 1/100 of the
//!           mass); at Courant number 1 the arrest is exact and loses nothing (strip_wall).
//!           Neither counting the arrest as work nor leaving it out is right at every
//!           Courant number; it is left out and shows in the energy balance.
//! T         tangential rows t . (x_s - sum w_m x_m) (`Gap::tangent_row`): T du is the
//!           relative slip of the step
//! lambda    tangential multipliers, in the units of mu; Coulomb's return (theory 8.3):
//!             stick   (T M^-1 T^T) lambda = -T du     (the slip of the step undone)
//!             slide   lambda = -mu_f mu sign(T du)    where the stick value exceeds it
//!           i.e. lambda = clamp(lambda_stick, -mu_f mu, mu_f mu), applied as M^-1 T^T lambda;
//!           mu_f the pair's Coulomb coefficient
//! C_m, nu   the master block of a mortar pair (`hold_master_nodes`, theory 8.3a-4): a master
//!           node the weighted gaps let into the slave body beyond the allowance gets a row
//!           of its own against the slave segment it faces (`mortar::master_node_gap`),
//!           looked at once the slave rows have settled and then solved with them,
//!           (C M^-1 C^T) [mu; nu] = -[g; g_m] over both; its impulse C_m^T nu joins J
//! ```

use super::Interfaces;
use super::geometry::{COVERED, Friction, Gap};
use super::mortar::MASTER_ALLOWANCE;
use super::search::{SlaveGap, penetrates, slave_gaps};
use super::status::{ContactState, MasterEntry, Scratch};

/// What an explicit contact step gives the driver.
pub struct ExplicitContact {
    /// The correction delta of the predicted increment (all DOFs).
    pub correction: Vec<f64>,
    /// The nodal forces f_step = (C^T mu + T^T lambda) / h^2 on the rows at the start
    /// positions, plus the master block's impulse C_m^T nu / h^2 as it was applied (all
    /// DOFs): what does the step's contact work on its corrected increment (the friction's
    /// share is the work it dissipates).
    pub step_force: Vec<f64>,
    /// `step_force` kept apart by pair (per pair of the interfaces, its (DOF, value) terms:
    /// its rows' and its master block's), which it is the sum of.
    pub pair_forces: Vec<Vec<(usize, f64)>>,
    /// Per pair, the work of the friction's share of its step force, T^T lambda / h^2, on
    /// the corrected increment, f_t . (du + delta / 2): minus the energy the friction
    /// dissipates in the step (0 without Coulomb friction).
    pub friction_work: Vec<f64>,
    /// Per pair, the work its moving obstacle does on the bodies in the step: the pair's
    /// force terms on the obstacle's translation over the step (0 for an obstacle at rest
    /// and between bodies), energy supplied, not taken by the contact.
    pub obstacle_work: Vec<f64>,
}

impl ContactState {
    /// Explicit contact by forward-increment Lagrange multipliers (Carpenter, Taylor & Katona
    /// 1991) in the velocity-Verlet form of central difference: the predicted increment `du`
    /// (positions `start + du`) of a step of length `h` is corrected by delta = M^-1 C^T mu
    /// with (C M^-1 C^T) mu = -g over the penetrated entries, mu >= 0 (entries in tension
    /// leave, penetrations join, the rows are rebuilt at the corrected positions until the
    /// gaps close to TOL). On a pair with Coulomb friction each pass then returns the
    /// tangential multipliers into the cone |lambda| <= mu_f mu (`friction_correction`);
    /// the passes go on until a sticking entry's slip is within TOL too. The status takes the
    /// reported forces mu / (h span) and lambda / (h span) (module legend; `previous` is the
    /// length of the step before, 0 before the first).
    pub fn explicit_step(
        &mut self,
        step: &Predicted,
        h: f64,
        previous: f64,
        time: f64,
    ) -> ExplicitContact {
        let Predicted {
            interfaces, start, ..
        } = *step;
        let c = step.balanced_correction(zeros(&mut self.scratch.delta, step.du.len()));
        let coulomb = |p: usize| coulomb(interfaces, p);
        // entries closed at the start of the step (their multiplier is the step's force)
        let persistent: Vec<bool> = c
            .active
            .iter()
            .map(|(p, k)| self.active[*p][*k] && previous > 0.0)
            .collect();
        let spans: Vec<f64> = persistent
            .iter()
            .map(|closed| if *closed { 0.5 * (previous + h) } else { h })
            .collect();
        let forces: Vec<f64> = c
            .mu_total
            .iter()
            .zip(&spans)
            .map(|(mu, span)| mu / (h * span))
            .collect();
        let mut step_forces: Vec<Vec<f64>> =
            self.force.iter().map(|f| vec![0.0; f.len()]).collect();
        let mut step_friction = step_forces.clone();
        for (i, (p, k)) in c.active.iter().enumerate() {
            step_forces[*p][*k] = c.mu_total[i] / (h * h);
            step_friction[*p][*k] = c.friction_total[i] / (h * h);
        }
        let released = self
            .active
            .iter()
            .zip(&c.in_active)
            .any(|(was, is)| was.iter().zip(is).any(|(was, is)| *was && !*is));
        // the corrected end positions, read at the nodes the contact looks at
        let end = |node: usize| step.position(&c.delta, node);
        self.master_block = c
            .masters
            .iter()
            .zip(&c.nu_total)
            .map(|(&(pair, node), nu)| {
                let closed = previous > 0.0
                    && self
                        .master_block
                        .iter()
                        .any(|e| (e.pair, e.node) == (pair, node));
                let span = if closed { 0.5 * (previous + h) } else { h };
                MasterEntry {
                    pair,
                    node,
                    force: nu / (h * span),
                }
            })
            .collect();
        let rows = (&c.active[..], &forces[..]);
        self.set(interfaces, rows, (time, released), &end, c.lowest);
        for (i, (p, k)) in c.active.iter().enumerate() {
            self.tangential[*p][*k] = c.friction_total[i] / (h * spans[i]);
            // a sliding entry: on the cone, with the signed coefficient of its force
            let limit = coulomb(*p).unwrap_or(0.0) * c.mu_total[i];
            if limit > 0.0 && c.friction_total[i].abs() >= limit * (1.0 - 1e-12) {
                self.sliding[*p][*k] = coulomb(*p).unwrap_or(0.0) * c.friction_total[i].signum();
            }
        }
        let mut step_force = zeros(&mut self.scratch.force, step.du.len());
        let rows = (&step_forces[..], &step_friction[..]);
        let mut pair_forces = self.pair_force_terms(&interfaces.pairs, start, rows);
        for (pair, dof, impulse) in &c.master_impulse {
            pair_forces[*pair].push((*dof, impulse / (h * h)));
        }
        for (dof, force) in pair_forces.iter().flatten() {
            step_force[*dof] += force;
        }
        // the friction's share of the driver's balance f . (du + delta / 2) - delta . F_n / 2
        // (f = M delta / h^2 at a free DOF, so its share of delta . F_n is f_t h^2 a_n): with
        // du = h v_n + h^2 a_n / 2, the work of f_t on h v_n + delta / 2, v_n the velocity at
        // t_n. On du + delta / 2 alone it read the slip on the predicted velocity, which
        // carries a_n h / 2 more: a first-order excess the normal rows' work gave back
        let increment = |dof: usize| {
            let held = if step.inverse_mass[dof] > 0.0 {
                0.5 * h * h * step.acceleration[dof]
            } else {
                0.0
            };
            step.du[dof] + 0.5 * c.delta[dof] - held
        };
        let carried = |p: usize, row: &[(usize, f64)]| step.carried(p, row);
        let friction_work = self.tangential_work(
            &interfaces.pairs,
            start,
            &step_friction,
            (&increment, &carried),
        );
        let obstacle_work = obstacle_work(&pair_forces, step.obstacle_steps);
        ExplicitContact {
            correction: c.delta,
            step_force,
            pair_forces,
            friction_work,
            obstacle_work,
        }
    }
}

impl ContactState {
    /// Takes back the vectors of a step's correction once they are read: the entries at the
    /// contact surfaces' nodes (the only ones a step writes: its rows and master block) and
    /// at `nonzero` (the DOFs where either is not zero) are zeroed, and the vectors kept for
    /// the next step.
    pub fn recycle(&mut self, step: ExplicitContact, interfaces: &Interfaces, nonzero: &[usize]) {
        let (mut delta, mut force) = (step.correction, step.step_force);
        for &d in nonzero {
            delta[d] = 0.0;
            force[d] = 0.0;
        }
        for pair in &interfaces.pairs {
            for n in pair.surface_nodes() {
                delta[2 * n..2 * n + 2].fill(0.0);
                force[2 * n..2 * n + 2].fill(0.0);
            }
        }
        self.scratch = Scratch { delta, force };
    }
}

/// Per pair, the work of its force terms `pair_forces` (on the slaves) on its obstacle's
/// translation in the step, `steps` (per pair; empty where no obstacle moves): a rigid
/// translation moves every point of the obstacle by the same increment dx, so the pair's
/// forces do sum_d f_d dx_(d mod 2) on it.
fn obstacle_work(pair_forces: &[Vec<(usize, f64)>], steps: &[[f64; 2]]) -> Vec<f64> {
    (pair_forces.iter().enumerate())
        .map(|(p, terms)| match steps.get(p) {
            None => 0.0,
            Some(dx) => terms.iter().map(|(d, f)| f * dx[d % 2]).sum(),
        })
        .collect()
}

/// `buffer` (zero, or empty) as a zero vector of length `len`.
fn zeros(buffer: &mut Vec<f64>, len: usize) -> Vec<f64> {
    let mut v = std::mem::take(buffer);
    if v.len() != len {
        v.clear();
        v.resize(len, 0.0);
    }
    v
}

/// Pair `p`'s Coulomb coefficient, when it has friction.
fn coulomb(interfaces: &Interfaces, p: usize) -> Option<f64> {
    match interfaces.pairs[p].options.friction {
        Friction::Coulomb { mu } if mu > 0.0 => Some(mu),
        _ => None,
    }
}

/// The predicted step that the contact corrects: positions `start + du`, the contact
/// pairs and the inverse lumped mass of every DOF.
#[derive(Clone, Copy)]
pub struct Predicted<'a> {
    pub interfaces: &'a Interfaces,
    pub start: &'a [[f64; 2]],
    pub du: &'a [f64],
    pub inverse_mass: &'a [f64],
    /// a_n = M^-1 F_n: the acceleration of the other forces at the step's start, which `du`
    /// carries (du = h v_n + h^2 a_n / 2; the friction's dissipation is read on v_n).
    pub acceleration: &'a [f64],
    /// Per pair, the translation of its obstacle in the step (`moving_obstacle_steps`);
    /// empty where no obstacle moves.
    pub obstacle_steps: &'a [[f64; 2]],
}

/// The correction of a step: delta, the active entries and their accumulated normal (mu)
/// and tangential (lambda) multipliers.
struct Correction {
    delta: Vec<f64>,
    active: Vec<(usize, usize)>,
    /// Whether (p, k) is in `active`: keeps the bookkeeping linear in the slaves.
    in_active: Vec<Vec<bool>>,
    mu_total: Vec<f64>,
    friction_total: Vec<f64>,
    /// When the passes settled: the lowest slave gap at the corrected positions (every
    /// slave's gap was computed there by the last pass; None inside: no master in reach).
    lowest: Option<Option<f64>>,
    /// The master block of the mortar pairs: (pair, master node) entries held out of the
    /// slave body, their accumulated multipliers, and the impulse C^T nu they applied as
    /// (pair, DOF, value) terms.
    masters: Vec<(usize, usize)>,
    nu_total: Vec<f64>,
    master_impulse: Vec<(usize, usize, f64)>,
}

/// Per pair of `interfaces`, the translation of its obstacle from `t0` to `t1` (zero for a
/// pair whose master does not move); empty where no obstacle moves.
pub fn moving_obstacle_steps(interfaces: &Interfaces, (t0, t1): (f64, f64)) -> Vec<[f64; 2]> {
    if !super::obstacles_move(&interfaces.pairs) {
        return Vec::new();
    }
    (interfaces.pairs.iter())
        .map(|pair| match pair.moving_obstacle() {
            None => [0.0; 2],
            Some(m) => {
                let (a, b) = (m.at(t0), m.at(t1));
                [b[0] - a[0], b[1] - a[1]]
            }
        })
        .collect()
}

impl Predicted<'_> {
    /// The slip along the tangential row `row` of pair `p` that its obstacle's own motion
    /// carries in the step, t . dx (a moving obstacle's rows are on the slave alone): the
    /// slip of a slave relative to the obstacle is T (du + delta) less this.
    fn carried(&self, p: usize, row: &[(usize, f64)]) -> f64 {
        self.obstacle_steps
            .get(p)
            .map_or(0.0, |dx| row.iter().map(|(d, c)| c * dx[d % 2]).sum())
    }

    fn position(&self, delta: &[f64], node: usize) -> [f64; 2] {
        [
            self.start[node][0] + self.du[2 * node] + delta[2 * node],
            self.start[node][1] + self.du[2 * node + 1] + delta[2 * node + 1],
        ]
    }

    /// The correction of the step. Without a balanced pair, `correct` over every pair.
    /// With one (a pair and its reverse pass, `ContactPair::balances`), the mean of two
    /// corrections of the same prediction: the first over every pair but the reverse
    /// passes, the second over every pair but their first passes (balanced master-slave
    /// contact: each surface the slave once). Each is a projection of the predicted motion
    /// in the mass metric onto its pass's constraints, which takes approach away and adds no
    /// kinetic energy; their mean cannot add any either (docs/theory.md 8.3d). Neither pass
    /// solves the other's rows, so the two never meet in one system, where a node held by
    /// both would make it singular.
    fn balanced_correction(&self, delta: Vec<f64>) -> Correction {
        let pairs = &self.interfaces.pairs;
        if pairs.iter().all(|p| p.balances.is_none()) {
            return self.correct(delta, &|_| true);
        }
        let first_pass = |p: usize| pairs.iter().any(|q| q.balances == Some(p));
        let first = self.correct(delta.clone(), &|p| pairs[p].balances.is_none());
        let second = self.correct(delta, &|p| !first_pass(p));
        first.mean(second)
    }

    /// The passes of the correction (at most 20) over the pairs that `include`: penetrated
    /// entries join, the multipliers close the gaps, friction returns into its cone, entries
    /// in tension leave; until no entry joins and the gaps and sticking slips are within TOL.
    fn correct(&self, delta: Vec<f64>, include: &dyn Fn(usize) -> bool) -> Correction {
        let interfaces = self.interfaces;
        let mut c = Correction {
            delta,
            active: Vec::new(),
            in_active: interfaces
                .pairs
                .iter()
                .map(|pair| vec![false; pair.slaves.len()])
                .collect(),
            mu_total: Vec::new(),
            friction_total: Vec::new(),
            lowest: None,
            masters: Vec::new(),
            nu_total: Vec::new(),
            master_impulse: Vec::new(),
        };
        let pairs = &interfaces.pairs;
        let mut candidates = master_candidates(interfaces);
        candidates.retain(|(p, _)| include(*p));
        let left_out: Vec<bool> = (0..pairs.len()).map(|p| !include(p)).collect();
        for _ in 0..20 {
            // gaps at the corrected positions: the active entries', and the others', of
            // which the penetrated join (with the gap found)
            let mut gaps = self.active_gaps(&mut c);
            let delta = &c.delta;
            let x = |node: usize| self.position(delta, node);
            let in_active = |p: usize, k: usize| c.in_active[p][k];
            let skipped = |p: usize, k: usize| left_out[p] || c.in_active[p][k];
            let others: Vec<SlaveGap> = slave_gaps(pairs, &x, &skipped).collect();
            let lowest = others
                .iter()
                .map(|s| s.gap.gap)
                .chain(gaps.iter().map(|g| g.gap))
                .reduce(f64::min);
            let joining: Vec<SlaveGap> = others
                .into_iter()
                .filter(|s| penetrates(pairs, s, &x, &in_active))
                .collect();
            let changed = !joining.is_empty();
            for s in joining {
                c.active.push((s.pair, s.index));
                c.in_active[s.pair][s.index] = true;
                c.mu_total.push(0.0);
                c.friction_total.push(0.0);
                gaps.push(s.gap);
            }
            let tangent_rows: Vec<Option<Vec<(usize, f64)>>> = c
                .active
                .iter()
                .zip(&gaps)
                .map(|((p, k), g)| {
                    coulomb(interfaces, *p).map(|_| g.tangent_row(interfaces.pairs[*p].slaves[*k]))
                })
                .collect();
            let carried: Vec<f64> = (c.active.iter().zip(&tangent_rows))
                .map(|((p, _), row)| row.as_deref().map_or(0.0, |row| self.carried(*p, row)))
                .collect();
            let tangent_rows = (&tangent_rows[..], &carried[..]);
            // the master nodes are looked at once the slaves have settled: before, the
            // pass is about to move them anyway
            let slaves_settled = !changed && self.settled(&c, &gaps, tangent_rows);
            let looked_at = if slaves_settled { &candidates[..] } else { &[] };
            let (master_gaps, masters_joined) = self.look_at_masters(&mut c, looked_at, &gaps);
            if slaves_settled && !masters_joined && self.masters_settled(&c, &master_gaps) {
                c.lowest = Some(lowest);
                break;
            }
            self.pass(&mut c, (&gaps, &master_gaps), tangent_rows);
        }
        c
    }

    /// The gaps of the active entries at the corrected positions. An entry whose slave no
    /// longer faces a master segment there (the master block moved it past a master's end)
    /// leaves; its correction so far stays applied (there is no row to give it back along).
    fn active_gaps(&self, c: &mut Correction) -> Vec<Gap> {
        let pairs = &self.interfaces.pairs;
        let delta = &c.delta;
        let x = |node: usize| self.position(delta, node);
        let gap = |(p, k): &(usize, usize)| pairs[*p].gap(pairs[*p].slaves[*k], &x);
        if let Some(gaps) = c.active.iter().map(gap).collect::<Option<Vec<Gap>>>() {
            return gaps;
        }
        let gaps: Vec<Option<Gap>> = c.active.iter().map(gap).collect();
        for ((p, k), gap) in c.active.iter().zip(&gaps) {
            if gap.is_none() {
                c.in_active[*p][*k] = false;
            }
        }
        let kept: Vec<bool> = gaps.iter().map(Option::is_some).collect();
        keep(&mut c.active, &kept);
        keep(&mut c.mu_total, &kept);
        keep(&mut c.friction_total, &kept);
        gaps.into_iter().flatten().collect()
    }

    /// The master block at the corrected positions: the gaps of its entries (None: the
    /// node faces no slave segment any more), and whether master nodes of the mortar pairs
    /// (`candidates`, (pair, node)) found inside the slave body by more than TOL joined it.
    /// A master node that an active slave row ties to itself (weight >= COVERED of the
    /// slave's, `gaps` the active slaves' gaps: facing nodes of matching meshes) stays out:
    /// its row would be that slave's row again.
    fn look_at_masters(
        &self,
        c: &mut Correction,
        candidates: &[(usize, usize)],
        gaps: &[Gap],
    ) -> (Vec<Option<Gap>>, bool) {
        if candidates.is_empty() && c.masters.is_empty() {
            return (Vec::new(), false);
        }
        let x = |node: usize| self.position(&c.delta, node);
        let held_gap =
            |p: usize, m: usize| self.interfaces.pairs[p].master_node_gap(m, MASTER_ALLOWANCE, &x);
        let mut master_gaps: Vec<Option<Gap>> =
            c.masters.iter().map(|(p, m)| held_gap(*p, *m)).collect();
        let tied = |p: usize, m: usize| {
            c.active.iter().zip(gaps).any(|((q, _), g)| {
                *q == p
                    && g.masters
                        .iter()
                        .any(|(n, w)| *n == m && *w >= COVERED * g.weight)
            })
        };
        let mut joined = false;
        for &(p, m) in candidates {
            if c.masters.contains(&(p, m)) || tied(p, m) {
                continue;
            }
            let Some(gap) = held_gap(p, m) else {
                continue;
            };
            if gap.gap < -self.interfaces.pairs[p].options.tolerance {
                c.masters.push((p, m));
                c.nu_total.push(0.0);
                master_gaps.push(Some(gap));
                joined = true;
            }
        }
        (master_gaps, joined)
    }

    /// Whether the master block's gaps are within TOL.
    fn masters_settled(&self, c: &Correction, master_gaps: &[Option<Gap>]) -> bool {
        c.masters.iter().zip(master_gaps).all(|((p, _), g)| {
            let tolerance = self.interfaces.pairs[*p].options.tolerance;
            g.as_ref()
                .is_some_and(|g| g.gap.abs() <= tolerance.max(f64::MIN_POSITIVE))
        })
    }

    /// Whether the active entries' gaps are within TOL and the sticking entries' slips too
    /// (those a multiplier can move: a held node's slip is its support's), each slip its
    /// row's T (du + delta) less what its obstacle carries (`tangent_rows`: the rows and
    /// those slips).
    fn settled(&self, c: &Correction, gaps: &[Gap], tangent_rows: TangentRows) -> bool {
        let (tangent_rows, carried) = tangent_rows;
        let tolerance = |p: usize| {
            self.interfaces.pairs[p]
                .options
                .tolerance
                .max(f64::MIN_POSITIVE)
        };
        let worst = c
            .active
            .iter()
            .zip(gaps)
            .map(|((p, _), g)| g.gap.abs() / tolerance(*p))
            .fold(0.0, f64::max);
        let slip_left = c
            .active
            .iter()
            .enumerate()
            .filter_map(|(i, (p, _))| {
                let limit = coulomb(self.interfaces, *p)? * c.mu_total[i].max(0.0);
                let row = tangent_rows[i].as_ref()?;
                (c.friction_total[i].abs() < limit && moves(row, self.inverse_mass)).then(|| {
                    let slip: f64 = row
                        .iter()
                        .map(|(dof, coefficient)| coefficient * (self.du[*dof] + c.delta[*dof]))
                        .sum::<f64>()
                        - carried[i];
                    slip.abs() / tolerance(*p)
                })
            })
            .fold(0.0, f64::max);
        worst <= 1.0 && slip_left <= 1.0
    }

    /// One pass: the normal multipliers that close `gaps` (the slaves', then the master
    /// block's, solved together), the friction return, and the release of the entries left
    /// in tension (they give back their correction).
    fn pass(
        &self,
        c: &mut Correction,
        (gaps, master_gaps): (&[Gap], &[Option<Gap>]),
        tangent_rows: TangentRows,
    ) {
        let (interfaces, inverse_mass) = (self.interfaces, self.inverse_mass);
        let master_gaps = self.drop_lost_masters(c, master_gaps);
        let mut rows: Vec<Vec<(usize, f64)>> = c
            .active
            .iter()
            .zip(gaps)
            .map(|((p, k), g)| g.row(interfaces.pairs[*p].slaves[*k]))
            .collect();
        rows.extend(
            c.masters
                .iter()
                .zip(&master_gaps)
                .map(|((_, m), g)| g.row(*m)),
        );
        let violations: Vec<f64> = gaps.iter().chain(&master_gaps).map(|g| g.gap).collect();
        let mu = super::multipliers::lumped_multipliers(&rows, &violations, inverse_mass);
        let (master_rows, master_mu) = (rows.split_off(gaps.len()), &mu[gaps.len()..]);
        for (i, row) in rows.iter().enumerate() {
            for (dof, coefficient) in row {
                c.delta[*dof] += inverse_mass[*dof] * coefficient * mu[i];
            }
            c.mu_total[i] += mu[i];
        }
        self.apply_masters(c, &master_rows, master_mu);
        // before the release below: an entry pulled off gets the cone of a zero normal
        // multiplier, so its friction is gone with it
        let coefficients: Vec<f64> = c
            .active
            .iter()
            .map(|(p, _)| coulomb(interfaces, *p).unwrap_or(0.0))
            .collect();
        let cones = (&coefficients[..], &c.mu_total[..]);
        let increment = (self.du, &mut c.delta[..]);
        friction_correction(
            tangent_rows,
            cones,
            &mut c.friction_total,
            increment,
            inverse_mass,
        );
        // entries pulled (total multiplier negative) leave and give back their correction
        for (i, row) in rows.iter().enumerate() {
            if c.mu_total[i] < 0.0 {
                for (dof, coefficient) in row {
                    c.delta[*dof] -= inverse_mass[*dof] * coefficient * c.mu_total[i];
                }
                let (p, k) = c.active[i];
                c.in_active[p][k] = false;
            }
        }
        let kept: Vec<bool> = c.mu_total.iter().map(|mu| *mu >= 0.0).collect();
        keep(&mut c.active, &kept);
        keep(&mut c.friction_total, &kept);
        keep(&mut c.mu_total, &kept);
    }

    /// The master block's entries that face no slave segment any more leave it (their
    /// impulse so far stays applied: there is no row to give it back along); the gaps of the
    /// others.
    fn drop_lost_masters(&self, c: &mut Correction, master_gaps: &[Option<Gap>]) -> Vec<Gap> {
        let kept: Vec<bool> = master_gaps.iter().map(Option::is_some).collect();
        keep(&mut c.nu_total, &kept);
        keep(&mut c.masters, &kept);
        master_gaps.iter().flatten().cloned().collect()
    }

    /// The master block's share of a pass: the multipliers `nu` on its `rows` applied (the
    /// impulse kept for the step force), then the entries pulled leave and give back their
    /// correction.
    fn apply_masters(&self, c: &mut Correction, rows: &[Vec<(usize, f64)>], nu: &[f64]) {
        let inverse_mass = self.inverse_mass;
        let apply = |c: &mut Correction, i: usize, value: f64| {
            let pair = c.masters[i].0;
            for (dof, coefficient) in &rows[i] {
                c.delta[*dof] += inverse_mass[*dof] * coefficient * value;
                c.master_impulse.push((pair, *dof, coefficient * value));
            }
        };
        for (i, nu) in nu.iter().enumerate() {
            apply(c, i, *nu);
            c.nu_total[i] += nu;
        }
        for i in 0..rows.len() {
            if c.nu_total[i] < 0.0 {
                apply(c, i, -c.nu_total[i]);
            }
        }
        let kept: Vec<bool> = c.nu_total.iter().map(|nu| *nu >= 0.0).collect();
        keep(&mut c.masters, &kept);
        keep(&mut c.nu_total, &kept);
    }
}

impl Correction {
    /// The mean of two corrections of the same prediction (the two passes of a balanced
    /// pair): the mean delta; per entry (pair, slave) and per master-block entry the mean of
    /// the two passes' multipliers (half of one where only one pass has it).
    fn mean(self, other: Correction) -> Correction {
        let delta = (self.delta.iter().zip(&other.delta))
            .map(|(a, b)| 0.5 * (a + b))
            .collect();
        let mut in_active = self.in_active.clone();
        let mut active: Vec<(usize, usize)> = Vec::new();
        let (mut mu_total, mut friction_total) = (Vec::new(), Vec::new());
        for c in [&self, &other] {
            for (i, &(p, k)) in c.active.iter().enumerate() {
                let at = match active.iter().position(|e| *e == (p, k)) {
                    Some(at) => at,
                    None => {
                        active.push((p, k));
                        mu_total.push(0.0);
                        friction_total.push(0.0);
                        active.len() - 1
                    }
                };
                mu_total[at] += 0.5 * c.mu_total[i];
                friction_total[at] += 0.5 * c.friction_total[i];
                in_active[p][k] = true;
            }
        }
        let mut masters: Vec<(usize, usize)> = Vec::new();
        let mut nu_total = Vec::new();
        for c in [&self, &other] {
            for (i, entry) in c.masters.iter().enumerate() {
                match masters.iter().position(|e| e == entry) {
                    Some(at) => nu_total[at] += 0.5 * c.nu_total[i],
                    None => {
                        masters.push(*entry);
                        nu_total.push(0.5 * c.nu_total[i]);
                    }
                }
            }
        }
        let master_impulse = (self.master_impulse.iter().chain(&other.master_impulse))
            .map(|(pair, dof, value)| (*pair, *dof, 0.5 * value))
            .collect();
        let lowest = match (self.lowest, other.lowest) {
            (Some(a), Some(b)) => Some(match (a, b) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            }),
            _ => None,
        };
        Correction {
            delta,
            active,
            in_active,
            mu_total,
            friction_total,
            lowest,
            masters,
            nu_total,
            master_impulse,
        }
    }
}

/// Keeps the entries of `items` whose flag in `kept` (one per entry, in order) is set.
fn keep<T>(items: &mut Vec<T>, kept: &[bool]) {
    let mut flags = kept.iter();
    items.retain(|_| *flags.next().expect("one flag per entry"));
}

/// The master nodes of the mortar pairs on deformable masters, as (pair, node).
fn master_candidates(interfaces: &Interfaces) -> Vec<(usize, usize)> {
    let mut candidates = Vec::new();
    for (p, pair) in interfaces.pairs.iter().enumerate() {
        let Some((surface, edges)) = pair.mortar() else {
            continue;
        };
        if surface.hold_master_nodes {
            let start = candidates.len();
            candidates.extend(edges.iter().flatten().map(|m| (p, *m)));
            candidates[start..].sort_unstable();
            candidates.dedup();
        }
    }
    candidates
}

/// The tangential rows of the active entries (those with friction) and, per entry, the slip
/// its obstacle's own motion carries in the step (0 where the master does not move).
type TangentRows<'r> = (&'r [Option<Vec<(usize, f64)>>], &'r [f64]);

/// Coulomb's return of the tangential multipliers of the entries with friction (those with
/// a row in `tangent_rows`, coefficient `coefficients[i]`): the stick increment that undoes
/// the slip s = T (du + delta) - carried left by the step so far (relative to a moving
/// obstacle), (T M^-1 T^T) d_lambda = -s,
/// then the total lambda + d_lambda clamped to the cone |lambda| <= mu_f max(mu, 0) (slide);
/// the change of lambda is added to `delta` through M^-1 T^T. A row on prescribed DOFs only
/// (T M^-1 T^T = 0: an axis node held in x against a wall whose tangent is x) is satisfied
/// by its support and takes no multiplier; it is left out, so that it cannot make the
/// rows it shares DOFs with singular.
fn friction_correction(
    (tangent_rows, carried): TangentRows,
    (coefficients, mu_total): (&[f64], &[f64]),
    friction_total: &mut [f64],
    (du, delta): (&[f64], &mut [f64]),
    inverse_mass: &[f64],
) {
    let entries: Vec<usize> = (0..tangent_rows.len())
        .filter(|i| {
            tangent_rows[*i]
                .as_deref()
                .is_some_and(|row| moves(row, inverse_mass))
        })
        .collect();
    if entries.is_empty() {
        return;
    }
    let rows: Vec<Vec<(usize, f64)>> = entries
        .iter()
        .map(|i| tangent_rows[*i].clone().expect("filtered above"))
        .collect();
    let slips: Vec<f64> = (rows.iter().zip(&entries))
        .map(|(row, &i)| {
            row.iter()
                .map(|(dof, c)| c * (du[*dof] + delta[*dof]))
                .sum::<f64>()
                - carried[i]
        })
        .collect();
    let stick = super::multipliers::lumped_multipliers(&rows, &slips, inverse_mass);
    for (a, &i) in entries.iter().enumerate() {
        let limit = coefficients[i] * mu_total[i].max(0.0);
        let total = (friction_total[i] + stick[a]).clamp(-limit, limit);
        let change = total - friction_total[i];
        for (dof, c) in &rows[a] {
            delta[*dof] += inverse_mass[*dof] * c * change;
        }
        friction_total[i] = total;
    }
}

/// Whether a multiplier on `row` moves anything: a coefficient on a free DOF (prescribed
/// DOFs have a zero inverse mass).
fn moves(row: &[(usize, f64)], inverse_mass: &[f64]) -> bool {
    row.iter()
        .any(|(dof, c)| *c != 0.0 && inverse_mass[*dof] > 0.0)
}
