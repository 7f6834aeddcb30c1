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
//! ```

use super::Interfaces;
use super::active::ContactState;
use super::geometry::{Friction, Gap};
use super::search::{SlaveGap, penetrates, slave_gaps};

/// What an explicit contact step gives the driver.
pub struct ExplicitContact {
    /// The correction delta of the predicted increment (all DOFs).
    pub correction: Vec<f64>,
    /// The nodal forces f_step = (C^T mu + T^T lambda) / h^2 on the rows at the start
    /// positions (all DOFs): what does the step's contact work on its corrected increment
    /// (the friction's share is the work it dissipates).
    pub step_force: Vec<f64>,
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
        let c = step.correct();
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
        let end = step.positions(&c.delta);
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
        let step_force =
            self.nodal_forces_of(&interfaces.pairs, start, &step_forces, &step_friction);
        ExplicitContact {
            correction: c.delta,
            step_force,
        }
    }
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
}

impl Predicted<'_> {
    fn position(&self, delta: &[f64], node: usize) -> [f64; 2] {
        [
            self.start[node][0] + self.du[2 * node] + delta[2 * node],
            self.start[node][1] + self.du[2 * node + 1] + delta[2 * node + 1],
        ]
    }

    /// `position` of every node.
    fn positions(&self, delta: &[f64]) -> Vec<[f64; 2]> {
        self.start
            .iter()
            .zip(self.du.chunks_exact(2).zip(delta.chunks_exact(2)))
            .map(|(s, (du, delta))| [s[0] + du[0] + delta[0], s[1] + du[1] + delta[1]])
            .collect()
    }

    /// The passes of the correction (at most 20): penetrated entries join, the multipliers
    /// close the gaps, friction returns into its cone, entries in tension leave; until no
    /// entry joins and the gaps and sticking slips are within TOL.
    fn correct(&self) -> Correction {
        let interfaces = self.interfaces;
        let mut c = Correction {
            delta: vec![0.0; self.du.len()],
            active: Vec::new(),
            in_active: interfaces
                .pairs
                .iter()
                .map(|pair| vec![false; pair.slaves.len()])
                .collect(),
            mu_total: Vec::new(),
            friction_total: Vec::new(),
            lowest: None,
        };
        let pairs = &interfaces.pairs;
        for _ in 0..20 {
            // gaps at the corrected positions: the active entries', and the others', of
            // which the penetrated join (with the gap found)
            let delta = &c.delta;
            let x = |node: usize| self.position(delta, node);
            let mut gaps: Vec<Gap> = c
                .active
                .iter()
                .map(|(p, k)| {
                    pairs[*p]
                        .gap(pairs[*p].slaves[*k], &x)
                        .expect("found above")
                })
                .collect();
            let in_active = |p: usize, k: usize| c.in_active[p][k];
            let others: Vec<SlaveGap> = slave_gaps(pairs, &x, &in_active).collect();
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
            if !changed && self.settled(&c, &gaps, &tangent_rows) {
                c.lowest = Some(lowest);
                break;
            }
            self.pass(&mut c, &gaps, &tangent_rows);
        }
        c
    }

    /// Whether the active entries' gaps are within TOL and the sticking entries' slips too
    /// (those a multiplier can move: a held node's slip is its support's).
    fn settled(
        &self,
        c: &Correction,
        gaps: &[Gap],
        tangent_rows: &[Option<Vec<(usize, f64)>>],
    ) -> bool {
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
                        .sum();
                    slip.abs() / tolerance(*p)
                })
            })
            .fold(0.0, f64::max);
        worst <= 1.0 && slip_left <= 1.0
    }

    /// One pass: the normal multipliers that close `gaps`, the friction return, and the
    /// release of the entries left in tension (they give back their correction).
    fn pass(&self, c: &mut Correction, gaps: &[Gap], tangent_rows: &[Option<Vec<(usize, f64)>>]) {
        let (interfaces, inverse_mass) = (self.interfaces, self.inverse_mass);
        let rows: Vec<Vec<(usize, f64)>> = c
            .active
            .iter()
            .zip(gaps)
            .map(|((p, k), g)| g.row(interfaces.pairs[*p].slaves[*k]))
            .collect();
        let violations: Vec<f64> = gaps.iter().map(|g| g.gap).collect();
        let mu = super::multipliers::lumped_multipliers(&rows, &violations, inverse_mass);
        for (i, row) in rows.iter().enumerate() {
            for (dof, coefficient) in row {
                c.delta[*dof] += inverse_mass[*dof] * coefficient * mu[i];
            }
            c.mu_total[i] += mu[i];
        }
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
        let mut flags = kept.iter();
        c.active
            .retain(|_| *flags.next().expect("one flag per entry"));
        let mut flags = kept.iter();
        c.friction_total
            .retain(|_| *flags.next().expect("one flag per entry"));
        c.mu_total.retain(|mu| *mu >= 0.0);
    }
}

/// Coulomb's return of the tangential multipliers of the entries with friction (those with
/// a row in `tangent_rows`, coefficient `coefficients[i]`): the stick increment that undoes
/// the slip T (du + delta) left by the step so far, (T M^-1 T^T) d_lambda = -T (du + delta),
/// then the total lambda + d_lambda clamped to the cone |lambda| <= mu_f max(mu, 0) (slide);
/// the change of lambda is added to `delta` through M^-1 T^T. A row on prescribed DOFs only
/// (T M^-1 T^T = 0: an axis node held in x against a wall whose tangent is x) is satisfied
/// by its support and takes no multiplier; it is left out, so that it cannot make the
/// rows it shares DOFs with singular.
fn friction_correction(
    tangent_rows: &[Option<Vec<(usize, f64)>>],
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
    let slips: Vec<f64> = rows
        .iter()
        .map(|row| {
            row.iter()
                .map(|(dof, c)| c * (du[*dof] + delta[*dof]))
                .sum()
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
