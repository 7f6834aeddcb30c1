//! The contact active set decided inside Newton's iteration: a primal-dual active set
//! strategy, the semi-smooth Newton method of the contact conditions (Hueber & Wohlmuth
//! 2005; Popp, Gee & Wall 2009), with Coulomb's stick and slide in the same iteration
//! (Gitterle, Popp, Gee & Wall 2010; theory 8.3b).
//!
//! Legend (an entry: a slave of a pair; tau its normal multiplier, compressive > 0; g its gap
//! at the iterate, > 0 open; T its tangential row t . (d_s - sum w_m d_m); s its slip beyond
//! sticking: T d in statics, T v* / c_v in dynamics (v* = c_v D + v_hat, the relative
//! tangential velocity at the solve point in units of a slip, `slip_beyond_stick`); f its
//! tangential force, acting as f t on the slave; mu the pair's Coulomb coefficient)
//! ```text
//! closed -> open     tau < 0 after a solve                   (tau - c g > 0 fails, g = 0)
//! open   -> closed   g < -TOL at the iterate                 (tau = 0: tau - c g > 0)
//! stick  -> slide    |f| > mu tau after a solve              slide with f = mu sign(f) tau
//! slide  -> stick    the sliding force pushes along the slip, sign(f) s > 0
//! ```
//! These are the complementarity functions' active-set updates with the solved rows at their
//! constraint (g = 0 on closed entries, s = 0 on sticking ones), where the weight c between
//! force and gap drops out. Each iteration solves with the rows of the statuses it starts
//! with; the step has converged when the residual passes and no status changed.
//!
//! The rows of a closed entry: its gap row C (the force tau C^T) and the exact derivative
//! dg/dx for the constraint; a sliding entry's force row is C + mu sign(f) T (its friction
//! force mu tau T^T rides on tau, so Newton's step is the consistent one, not a known force
//! of the last iterate), a sticking entry adds the row T for s = 0 with its own multiplier f.
//! The force rows' own derivatives, tau dC/dx + f dT/dx, enter the tangent (`exact_solve`).

use super::constrained::{Exact, Rows};
use super::{Constraints, StepFailure};
use crate::assembly::System;
use crate::contact::search::{SlaveGap, penetrates, slave_gaps};
use crate::contact::{Friction, Gap, Settled, Tangential};

/// After this many iterations that changed a status, the statuses stay as they are.
const FREEZE: usize = 12;

/// The contact status of an entry inside the iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Status {
    Open,
    /// Closed without friction.
    Frictionless,
    Stick,
    /// Closed and sliding: the signed Coulomb coefficient of its force.
    Slide(f64),
}

impl Status {
    fn closed(self) -> bool {
        self != Status::Open
    }
}

/// An entry the iteration looks at: every entry it started with, and those that closed.
#[derive(Debug, Clone)]
struct Candidate {
    pair: usize,
    /// The slave's index in its pair, and its global node.
    index: usize,
    node: usize,
    status: Status,
    normal: f64,
    tangential: f64,
}

/// The active set of a Newton step: its candidates, their statuses and multipliers.
pub(super) struct ActiveSet {
    candidates: Vec<Candidate>,
    /// Slaves not among the candidates may close (`Inside::Closures`).
    closures: bool,
    /// Iterations that changed a status.
    changes: usize,
    /// The statuses before the last update, per candidate: an update that returns to them
    /// is a two-iterate cycle (an entry that opens in tension and closes again penetrating,
    /// a grazing contact), which is settled by keeping the closed state of each entry that
    /// flips and changing nothing more.
    before: Vec<Status>,
    frozen: bool,
    /// The rows of the last `rows` call: per row, its candidate and whether it is the
    /// tangential (sticking) row.
    layout: Vec<(usize, bool)>,
}

impl ActiveSet {
    /// The active set a step starts with: the pass's entries closed with their forces and
    /// friction statuses.
    pub(super) fn new(c: &Constraints, closures: bool) -> ActiveSet {
        let candidates = c
            .active
            .iter()
            .enumerate()
            .map(|(i, &(pair, node))| {
                let slide = c.tangential.iter().find_map(|t| match *t {
                    Tangential::Sliding { entry, coefficient } if entry == i => Some(coefficient),
                    _ => None,
                });
                let stick = c
                    .tangential
                    .iter()
                    .any(|t| matches!(t, Tangential::Fixed { entry, .. } if *entry == i));
                let status = match (slide, stick) {
                    (Some(coefficient), _) => Status::Slide(coefficient),
                    (None, true) => Status::Stick,
                    (None, false) => Status::Frictionless,
                };
                let normal = c.forces.get(i).copied().unwrap_or(0.0);
                Candidate {
                    pair,
                    index: index_of(c, pair, node),
                    node,
                    status,
                    normal,
                    tangential: slide.map_or(0.0, |coefficient| coefficient * normal),
                }
            })
            .collect();
        ActiveSet {
            candidates,
            closures,
            changes: 0,
            before: Vec::new(),
            frozen: false,
            layout: Vec::new(),
        }
    }

    /// The statuses at the iterate `d` from the multipliers of the last solve (module
    /// legend; `motion` as in `rows`); whether any changed.
    pub(super) fn update(
        &mut self,
        c: &Constraints,
        d: &[f64],
        motion: Option<(&[f64], f64)>,
    ) -> bool {
        let x = |n: usize| [c.start[n][0] + d[2 * n], c.start[n][1] + d[2 * n + 1]];
        let frozen = self.frozen || self.changes >= FREEZE;
        let now: Vec<Status> = self.candidates.iter().map(|e| e.status).collect();
        let mut reachable = vec![true; self.candidates.len()];
        let mut changed = false;
        for k in 0..self.candidates.len() {
            let candidate = &self.candidates[k];
            let pair = &c.pairs[candidate.pair];
            let gap = pair.gap(candidate.node, &x);
            reachable[k] = gap.is_some();
            let next = match gap {
                // no master in reach: the entry has left the surface
                None => Status::Open,
                // frozen: only a sticking force beyond the cone still slides, so the step
                // never ends with a force Coulomb's law does not allow
                Some(_) if frozen => leaves_cone(c, candidate).unwrap_or(candidate.status),
                Some(gap) => match candidate.status {
                    Status::Open => {
                        let s = SlaveGap {
                            pair: candidate.pair,
                            index: candidate.index,
                            node: candidate.node,
                            gap,
                        };
                        if penetrates(c.pairs, &s, &x, &|p, i| self.is_closed(p, i)) {
                            closed_status(c, candidate.pair)
                        } else {
                            Status::Open
                        }
                    }
                    _ if candidate.normal < 0.0 => Status::Open,
                    status => friction_status(c, candidate, status, (&gap, d), motion),
                },
            };
            if next != candidate.status {
                changed = true;
                let candidate = &mut self.candidates[k];
                if !next.closed() {
                    candidate.normal = 0.0;
                    candidate.tangential = 0.0;
                } else if !candidate.status.closed() {
                    candidate.normal = 0.0;
                }
                candidate.status = next;
            }
        }
        if self.closures && !frozen {
            let closing: Vec<SlaveGap> = slave_gaps(c.pairs, &x, &|p, i| self.is_candidate(p, i))
                .filter(|s| penetrates(c.pairs, s, &x, &|p, i| self.is_closed(p, i)))
                .collect();
            for s in closing {
                changed = true;
                self.candidates.push(Candidate {
                    pair: s.pair,
                    index: s.index,
                    node: s.node,
                    status: closed_status(c, s.pair),
                    normal: 0.0,
                    tangential: 0.0,
                });
            }
        }
        if changed {
            self.changes += 1;
            self.settle_cycle(&now, &reachable);
        }
        self.before = now;
        changed
    }

    /// After an update that changed a status: if the statuses are back where they were
    /// before the last update (`before`; `now` the ones this update started from), each
    /// entry that flips takes the closed one of its two states where it still faces its
    /// master (`reachable`), the sticking one of stick and slide, and the statuses stay from
    /// here on, but for a sticking force that leaves the cone (`leaves_cone`).
    fn settle_cycle(&mut self, now: &[Status], reachable: &[bool]) {
        let back = self.before.len() == self.candidates.len()
            && self
                .candidates
                .iter()
                .zip(&self.before)
                .all(|(e, b)| e.status == *b);
        if !back {
            return;
        }
        for ((candidate, last), reachable) in self.candidates.iter_mut().zip(now).zip(reachable) {
            if candidate.status == *last || !*reachable {
                continue;
            }
            // closed before open; between stick and slide, stick: a sliding force that pushes
            // along the slip would do work on the bodies, a sticking one does none
            let keep_last = !candidate.status.closed()
                || (*last == Status::Stick && matches!(candidate.status, Status::Slide(_)));
            if keep_last {
                candidate.status = *last;
            }
        }
        self.frozen = true;
    }

    fn is_candidate(&self, pair: usize, index: usize) -> bool {
        self.candidates
            .iter()
            .any(|e| e.pair == pair && e.index == index)
    }

    fn is_closed(&self, pair: usize, index: usize) -> bool {
        self.candidates
            .iter()
            .any(|e| e.pair == pair && e.index == index && e.status.closed())
    }

    /// The rows of the closed entries at the iterate `d` (module legend), and the
    /// multipliers they start from: the normal rows, then the sticking entries' tangential
    /// rows. In dynamics (`motion`: v* = c_v D + v_hat at the solve point, as (v_hat, c_v))
    /// a sticking entry's relative tangential velocity is held at zero, T v* = 0, so its
    /// slip over the step is -T v_hat / c_v (the trapezoidal rule's h/2 of the start's
    /// relative tangential velocity); a slip of zero would hold the displacement and leave
    /// that velocity to alternate in sign from step to step, with a multiplier growing as
    /// 1/dt (a copper rod on a steel plate with mu = 0.1 created 252 J and diverged at
    /// dt = 2.5e-8). In statics the slip is held at zero.
    pub(super) fn rows(
        &mut self,
        c: &Constraints,
        d: &[f64],
        system: &System,
        motion: Option<(&[f64], f64)>,
    ) -> Result<(Rows, Vec<f64>), StepFailure> {
        let x = |n: usize| [c.start[n][0] + d[2 * n], c.start[n][1] + d[2 * n + 1]];
        let mut rows = Rows::empty();
        let mut forces = Vec::new();
        let mut sticking = Vec::new();
        self.layout.clear();
        for (k, candidate) in self.candidates.iter().enumerate() {
            if !candidate.status.closed() {
                continue;
            }
            let pair = &c.pairs[candidate.pair];
            let gap = pair
                .gap(candidate.node, &x)
                .ok_or_else(|| StepFailure(c.lost(candidate.pair, candidate.node)))?;
            let linearization = pair.linearization(candidate.node, &gap, &x);
            let slide = match candidate.status {
                Status::Slide(coefficient) => coefficient,
                _ => 0.0,
            };
            let mut force_row = gap.row(candidate.node);
            if slide != 0.0 {
                let tangent = gap.tangent_row(candidate.node);
                force_row
                    .iter_mut()
                    .zip(&tangent)
                    .for_each(|((_, f), (_, t))| *f += slide * t);
            }
            let violation = gap.gap - c.target((candidate.pair, candidate.node));
            rows.worst_gap = rows.worst_gap.max(violation.abs() / pair.options.tolerance);
            let exact = match &linearization {
                Some(l) => Some(Exact::combined(l, slide, system)),
                // a sliding force row is not the constraint's: its gradient is the gap row
                None if slide != 0.0 => Some(Exact::plain(&free(gap.row(candidate.node), system))),
                None => None,
            };
            rows.rows.push(free(force_row, system));
            rows.gaps.push(violation);
            rows.exact.push(exact);
            forces.push(candidate.normal);
            self.layout.push((k, false));
            if candidate.status == Status::Stick {
                sticking.push((k, gap, linearization));
            }
        }
        rows.normal = rows.rows.len();
        for (k, gap, linearization) in sticking {
            let candidate = &self.candidates[k];
            let row = gap.tangent_row(candidate.node);
            let slip = slip_beyond_stick(&row, d, motion);
            // the support holds the slip where the row's free part is (nearly) the normal
            // row's: an axis node held in x, whose tangent is x but for the tilt of the mean
            // normal, would get a second row on its y DOFs, the normal row again
            let whole = row.iter().map(|(_, t)| t * t).sum::<f64>();
            let on_free = free(row, system);
            if held_by_support(&on_free, whole, &free(gap.row(candidate.node), system)) {
                continue;
            }
            rows.exact.push(Some(match &linearization {
                Some(l) => Exact::tangential(l, &on_free, system),
                None => Exact::plain(&on_free),
            }));
            rows.rows.push(on_free);
            rows.gaps.push(slip);
            forces.push(candidate.tangential);
            self.layout.push((k, true));
        }
        if rows.exact.iter().all(Option::is_none) {
            rows.exact.clear();
        }
        Ok((rows, forces))
    }

    /// Takes the multipliers of a solve with the last `rows`: normal forces, the sticking
    /// entries' tangential forces, and the sliding ones' mu tau.
    pub(super) fn take(&mut self, multipliers: &[f64]) {
        for (&(k, tangential), value) in self.layout.iter().zip(multipliers) {
            let candidate = &mut self.candidates[k];
            if tangential {
                candidate.tangential = *value;
            } else {
                candidate.normal = *value;
                if let Status::Slide(coefficient) = candidate.status {
                    candidate.tangential = coefficient * value;
                }
            }
        }
    }

    /// The set the iteration settled on.
    pub(super) fn settled(&self) -> Settled {
        let mut settled = Settled::default();
        for candidate in self.candidates.iter().filter(|e| e.status.closed()) {
            settled.entries.push((candidate.pair, candidate.index));
            settled.forces.push(candidate.normal);
            settled.tangential.push(candidate.tangential);
            settled.sliding.push(match candidate.status {
                Status::Slide(coefficient) => coefficient,
                _ => 0.0,
            });
        }
        settled
    }
}

/// The status an entry closes with: sticking under Coulomb friction, else frictionless.
fn closed_status(c: &Constraints, pair: usize) -> Status {
    match c.pairs[pair].options.friction {
        Friction::Coulomb { mu } if mu > 0.0 => Status::Stick,
        _ => Status::Frictionless,
    }
}

/// The slip of a step beyond what sticking allows: T d in statics; in dynamics
/// (`motion` = (v_hat, c_v), v* = c_v D + v_hat) T d + T v_hat / c_v = T v* / c_v, the
/// relative tangential velocity at the solve point in units of a slip (`ActiveSet::rows`).
fn slip_beyond_stick(row: &[(usize, f64)], d: &[f64], motion: Option<(&[f64], f64)>) -> f64 {
    let along = |v: &[f64]| -> f64 { row.iter().map(|(dof, t)| t * v[*dof]).sum() };
    along(d) + motion.map_or(0.0, |(offset, coefficient)| along(offset) / coefficient)
}

/// A closed entry's next friction status (module legend): stick -> slide when its force
/// leaves the cone, slide -> stick when the sliding force would push along the slip (in
/// dynamics, along the relative tangential velocity at the solve point).
fn friction_status(
    c: &Constraints,
    candidate: &Candidate,
    status: Status,
    (gap, d): (&Gap, &[f64]),
    motion: Option<(&[f64], f64)>,
) -> Status {
    let pair = &c.pairs[candidate.pair];
    match status {
        Status::Stick => leaves_cone(c, candidate).unwrap_or(status),
        Status::Slide(coefficient) => {
            let slip = slip_beyond_stick(&gap.tangent_row(candidate.node), d, motion);
            if coefficient * slip > 1e-3 * pair.options.tolerance.max(f64::MIN_POSITIVE) {
                Status::Stick
            } else {
                status
            }
        }
        _ => status,
    }
}

/// The sliding status of a sticking entry whose tangential force has left Coulomb's cone,
/// |f| > mu tau; None for any other entry.
fn leaves_cone(c: &Constraints, candidate: &Candidate) -> Option<Status> {
    let Friction::Coulomb { mu } = c.pairs[candidate.pair].options.friction else {
        return None;
    };
    (candidate.status == Status::Stick
        && candidate.tangential.abs() > mu * candidate.normal * (1.0 + 1e-9))
        .then(|| Status::Slide(mu * candidate.tangential.signum()))
}

/// The index of slave `node` in pair `pair`.
fn index_of(c: &Constraints, pair: usize, node: usize) -> usize {
    c.pairs[pair]
        .slaves
        .iter()
        .position(|s| *s == node)
        .expect("an active entry is a slave of its pair")
}

/// Whether a sticking entry's tangential row `tangential` (on the free DOFs; `whole` the
/// squared norm of the row on all DOFs) is left to the supports: what is left of it after
/// its component along the entry's normal row `normal` is removed is less than a tenth of
/// the row, free or whole (none at all: prescribed DOFs only). Its multiplier would then
/// have to enforce the slip through the normal's own DOFs, nearly the normal row again, or
/// through the small weight of a neighbouring master node (an axis slave in axisymmetry,
/// held in x with the master's axis node: its row is the next master node's x with the
/// weight of the first half segment), and would grow without bound (1e6 N beside a normal
/// force of 1e2 N on a copper rod on a steel plate with mu = 0.3, which pinned the plate's
/// axis element and gave it 40 times its plastic strain).
fn held_by_support(tangential: &[(usize, f64)], whole: f64, normal: &[(usize, f64)]) -> bool {
    let dot = |a: &[(usize, f64)], b: &[(usize, f64)]| -> f64 {
        a.iter()
            .map(|(eq, v)| {
                v * b
                    .iter()
                    .filter(|(e, _)| e == eq)
                    .map(|(_, w)| w)
                    .sum::<f64>()
            })
            .sum()
    };
    let (tt, nn, tn) = (
        dot(tangential, tangential),
        dot(normal, normal),
        dot(tangential, normal),
    );
    let left = if nn > 0.0 { tt - tn * tn / nn } else { tt };
    !(left > 0.01 * whole.max(tt))
}

/// A row on all DOFs restricted to the free ones (equation numbers).
fn free(row: Vec<(usize, f64)>, system: &System) -> Vec<(usize, f64)> {
    row.into_iter()
        .filter_map(|(dof, v)| system.equation[dof].map(|eq| (eq, v)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{ContactPair, Discretization, Inside, Master, Obstacle, PairOptions};

    /// Node 0 against the wall y = 0 (solid below), with Coulomb friction `mu` (0: none).
    fn pair(mu: f64) -> ContactPair {
        ContactPair {
            name: "p".into(),
            slave_body: 0,
            slaves: vec![0],
            master: Master::Obstacle(Obstacle {
                name: "wall".into(),
                points: vec![[1.0, 0.0], [-1.0, 0.0]],
                closed: false,
                motion: None,
                projectile: None,
            }),
            options: PairOptions {
                impact_conditions: false,
                release_conditions: false,
                release_fraction: 0.0,
                tolerance: 1e-6,
                search_distance: f64::INFINITY,
                split_at_events: false,
                friction: if mu > 0.0 {
                    Friction::Coulomb { mu }
                } else {
                    Friction::None
                },
                persistency: false,
                balanced: false,
            },
            chosen_roles: None,
            covered: None,
            balances: None,
            own: None,
            discretization: Discretization::NodeToSegment,
        }
    }

    /// The constraints of `pairs` with node 0 active, as a Newton step sees them.
    fn constraints<'a>(
        pairs: &'a [ContactPair],
        describe: &'a dyn Fn(usize) -> String,
    ) -> Constraints<'a> {
        Constraints {
            pairs,
            active: &[(0, 0)],
            start: &[[0.0, 0.0]],
            forces: vec![0.0],
            tangential: &[],
            targets: Vec::new(),
            inside: Inside::Releases,
            describe,
        }
    }

    fn candidate(normal: f64, tangential: f64, status: Status) -> Candidate {
        Candidate {
            pair: 0,
            index: 0,
            node: 0,
            status,
            normal,
            tangential,
        }
    }

    /// Goal: the slip beyond sticking is the tangential row applied to the increment, plus
    /// in dynamics the predictor's relative velocity over c_v. Reference (by hand): the row
    /// (0.6, 0.8) on d = (1, 2) gives 0.6 + 1.6 = 2.2; with v_hat = (3, -1) and c_v = 2,
    /// 2.2 + (1.8 - 0.8) / 2 = 2.7.
    #[test]
    fn the_slip_beyond_sticking_is_the_row_on_the_increment_and_the_predictor() {
        let row = [(0, 0.6), (1, 0.8)];
        let d = [1.0, 2.0];
        assert!((slip_beyond_stick(&row, &d, None) - 2.2).abs() < 1e-15);
        let dynamic = slip_beyond_stick(&row, &d, Some((&[3.0, -1.0], 2.0)));
        assert!((dynamic - 2.7).abs() < 1e-15, "{dynamic}");
    }

    /// Goal: a sticking entry leaves Coulomb's cone exactly when |f| > mu tau, sliding with
    /// the sign of its force; a frictionless or sliding entry never does. Reference (by
    /// hand): mu = 0.3, tau = 10: the cone's edge is 3; 2.9 and 3 stay, 3.1 and -3.1 slide
    /// with +0.3 and -0.3.
    #[test]
    fn a_sticking_entry_slides_when_its_force_leaves_the_cone() {
        let describe = |n: usize| format!("node {n}");
        let pairs = [pair(0.3)];
        let c = constraints(&pairs, &describe);
        let at = |f: f64| leaves_cone(&c, &candidate(10.0, f, Status::Stick));
        assert_eq!(at(2.9), None);
        assert_eq!(at(3.0), None);
        assert_eq!(at(3.1), Some(Status::Slide(0.3)));
        assert_eq!(at(-3.1), Some(Status::Slide(-0.3)));
        assert_eq!(
            leaves_cone(&c, &candidate(10.0, 5.0, Status::Slide(0.3))),
            None
        );
        let frictionless = [pair(0.0)];
        let c = constraints(&frictionless, &describe);
        assert_eq!(leaves_cone(&c, &candidate(10.0, 5.0, Status::Stick)), None);
        assert_eq!(closed_status(&c, 0), Status::Frictionless);
        assert_eq!(
            closed_status(&constraints(&pairs, &describe), 0),
            Status::Stick
        );
    }

    /// Goal: a sliding entry sticks again when its sliding force would push along the slip
    /// (the slip has reversed against the force's sign), and keeps sliding otherwise.
    /// Setup: node 0 on the wall y = 0 (normal (0, 1), tangent (-1, 0): a slip to -x is
    /// positive), sliding with +mu. Reference (by hand): d = (-1e-3, 0) is a slip of +1e-3,
    /// along the force's sign: stick; d = (+1e-3, 0), a slip of -1e-3: slide on; a slip of
    /// 1e-10, below 1e-3 of TOL (1e-6): slide on.
    #[test]
    fn a_sliding_entry_sticks_when_the_slip_turns_along_its_force() {
        let describe = |n: usize| format!("node {n}");
        let pairs = [pair(0.3)];
        let c = constraints(&pairs, &describe);
        let gap = Gap {
            gap: 0.0,
            normal: [0.0, 1.0],
            masters: Vec::new(),
            weight: 1.0,
            lever: None,
        };
        let sliding = Status::Slide(0.3);
        let next = |d: [f64; 2]| {
            friction_status(
                &c,
                &candidate(10.0, 3.0, sliding),
                sliding,
                (&gap, &d),
                None,
            )
        };
        assert_eq!(next([-1e-3, 0.0]), Status::Stick);
        assert_eq!(next([1e-3, 0.0]), sliding);
        assert_eq!(next([-1e-10, 0.0]), sliding);
    }

    /// Goal: a sticking row is left to the supports when what remains of it after its part
    /// along the normal row is less than a tenth of the row. Reference (by hand): t = e0
    /// against n = e1 keeps all of it (1); t = e0 + 0.05 e1 against n = e0 keeps 0.0025 of
    /// 1.0025; a row with no free DOF keeps nothing.
    #[test]
    fn a_sticking_row_along_its_normal_row_is_left_to_the_supports() {
        assert!(!held_by_support(&[(0, 1.0)], 1.0, &[(1, 1.0)]));
        assert!(held_by_support(&[(0, 1.0), (1, 0.05)], 1.0025, &[(0, 1.0)]));
        assert!(held_by_support(&[], 1.0, &[(0, 1.0)]));
    }
}
