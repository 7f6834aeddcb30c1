//! The event logic inside an implicit step.
//!
//! In a step, with the seeds' passes (`Inside::Fixed`): solve with the current active set;
//! release entries in tension (tau < 0) and solve again; if inactive slaves penetrate beyond
//! TOL, either shorten the step to the first contact event (Erklig 2.1.4: the fraction
//! alpha = g_0 / (g_0 - g_1), once per step) or activate them and solve again (Hughes II-7);
//! Coulomb's stick and slide switch between passes too. With the active set inside Newton
//! (`step_inside`, a primal-dual active set) the solve itself settles which entries stay
//! closed and how each sticks or slides; the passes only split the step at the first contact
//! event and then let the slaves that penetrate close. After the step, entries whose force
//! fell below `release_fraction` of the last step's are released; dynamics then applies the
//! impact and release conditions (`impacts`).

use super::Interfaces;
use super::geometry::{ContactPair, Friction};
use super::search;
use super::status::ContactState;

/// The shortest fraction of a step an event split may leave: an event closer to the step
/// start than this closes in the full step (Hughes II-7) instead.
const MIN_SPLIT: f64 = 0.1;

/// What happened in a step, for the conditions and the bookkeeping.
#[derive(Debug, Clone, Default)]
pub struct Events {
    /// (pair, slave index) entries that closed in the step.
    pub closed: Vec<(usize, usize)>,
    /// Entries released by the fraction rule, with their last normal and tangential forces.
    pub released: Vec<(usize, usize, f64, f64)>,
    /// Entries released because they went into tension.
    pub separated: Vec<(usize, usize)>,
}

/// The result of a step with contact: the solver's solution `S` and the contact outcome.
pub struct ContactResult<S> {
    pub solution: S,
    /// The step length actually taken (shorter when split at an event).
    pub length: f64,
    /// Active entries and their forces after the step.
    pub active: Vec<(usize, usize)>,
    pub forces: Vec<f64>,
    /// Per active entry: the tangential force, and the signed coefficient when sliding.
    pub tangential: Vec<f64>,
    pub sliding: Vec<f64>,
    pub events: Events,
}

/// A tangential condition on active entry `entry` (an index into the active entries). The
/// slip s of a step is t . (d_s - sum w_m d_m), t = (-n_y, n_x); a tangential force f acts as
/// f t on the slave and -w_m f t on the master nodes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tangential {
    /// s = target, by a Lagrange multiplier (Coulomb stick: 0; Greco's return: (1 - R) times
    /// the frictionless slip).
    Fixed { entry: usize, target: f64 },
    /// f = coefficient x tau of the entry (Coulomb slide: +-mu), a known force in each
    /// iteration (tau of the last solve).
    Sliding { entry: usize, coefficient: f64 },
}

/// What the event logic reads of a solve with a given active set: the increment (all DOFs),
/// the normal multipliers tau of the active entries (in their order) and the forces of the
/// tangential conditions (in theirs); for a solve that decided its active set itself
/// (`Inside::Releases`, `Inside::Closures`), the set it settled on.
pub trait ConstrainedSolution {
    fn increment(&self) -> &[f64];
    fn normal_forces(&self) -> &[f64];
    fn tangential_forces(&self) -> &[f64];
    fn settled(&self) -> Option<&Settled>;
}

/// How a solve may change the active set of its pass (`Pass::inside`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Inside {
    /// The pass's entries and friction statuses are fixed; the event loop changes them
    /// between passes (the seeds' method).
    Fixed,
    /// Newton's iteration decides which of the pass's entries stay closed (a closed entry
    /// in tension opens, an open one that penetrates closes again) and whether each sticks
    /// or slides: a primal-dual active set (Hueber & Wohlmuth 2005; Gitterle, Popp, Gee &
    /// Wall 2010 for friction). No other slave closes.
    Releases,
    /// As `Releases`, and any slave of the pairs that penetrates its master closes.
    Closures,
}

/// The active set a solve settled on: the closed entries (pair, slave index), their normal
/// and tangential forces and sliding coefficients (the signed Coulomb coefficient, 0
/// sticking or frictionless).
#[derive(Debug, Clone, Default)]
pub struct Settled {
    pub entries: Vec<(usize, usize)>,
    pub forces: Vec<f64>,
    pub tangential: Vec<f64>,
    pub sliding: Vec<f64>,
}

/// The active set did not settle within the passes a step allows.
#[derive(Debug, Clone, Copy)]
pub struct Unsettled;

impl std::fmt::Display for Unsettled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the contact active set did not settle in 100 passes")
    }
}

/// The tangential conditions of the entries' friction status, in entry order; `carried`:
/// per entry, the slip its obstacle's own motion carries in the step (a stick holds the
/// slave on the moving obstacle: T d = carried).
fn tangential_conditions(slips: &[Slip], carried: &[f64]) -> Vec<Tangential> {
    slips
        .iter()
        .enumerate()
        .filter_map(|(entry, s)| match *s {
            Slip::Free => None,
            Slip::Stick => Some(Tangential::Fixed {
                entry,
                target: carried[entry],
            }),
            Slip::Return(target) => Some(Tangential::Fixed {
                entry,
                target: target + carried[entry],
            }),
            Slip::Slide(coefficient) => Some(Tangential::Sliding { entry, coefficient }),
        })
        .collect()
}

/// Per entry (pair, slave index), the slip t . dx that its obstacle's translation dx from
/// `time` to `time + length` carries along the slave's tangent at `start` (against the
/// pairs there, `at_start`): zero where the master does not move. The slip Coulomb's law
/// and Greco's return read is T d less this.
fn carried_slips(
    at_start: &[ContactPair],
    entries: &[(usize, usize)],
    start: &[[f64; 2]],
    (time, length): (f64, f64),
) -> Vec<f64> {
    let position = |n: usize| start[n];
    (entries.iter())
        .map(|&(p, k)| {
            let Some(m) = at_start[p].moving_obstacle() else {
                return 0.0;
            };
            let (a, b) = (m.at(time), m.at(time + length));
            let s = at_start[p].slaves[k];
            at_start[p].gap(s, &position).map_or(0.0, |g| {
                let t = g.tangent();
                t[0] * (b[0] - a[0]) + t[1] * (b[1] - a[1])
            })
        })
        .collect()
}

/// The tangential forces of a solve (in the order of `tangential_conditions`) per entry.
fn per_entry(slips: &[Slip], forces: &[f64]) -> Vec<f64> {
    let mut next = forces.iter();
    slips
        .iter()
        .map(|s| match s {
            Slip::Free => 0.0,
            _ => *next.next().expect("one force per condition"),
        })
        .collect()
}

/// The friction status of an active entry inside a step.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Slip {
    /// No tangential condition (frictionless, or Greco's return before its target is known).
    Free,
    Stick,
    Slide(f64),
    Return(f64),
}

/// The entries a contact step released in tension, each with the active set it left and the
/// step's length then. One that penetrates again when the others are as they were cycles:
/// held, it pulls; free, it penetrates (seen with friction under HHT, an entry at a corner,
/// 28 nm inside, at every step length the cuts tried). In a step's last attempt
/// (`ContactState::accept_cycles`) it stays open, its small penetration reported like any
/// other.
#[derive(Default)]
struct Pulled(Vec<Release>);

/// One release in tension: the entry, the active set it left (sorted) and the step length.
struct Release {
    entry: (usize, usize),
    left: Vec<(usize, usize)>,
    length: f64,
}

impl Pulled {
    fn sorted(entries: &[(usize, usize)]) -> Vec<(usize, usize)> {
        let mut set = entries.to_vec();
        set.sort_unstable();
        set
    }

    /// `entry` was released, leaving `entries` active, at step length `length`.
    fn record(&mut self, entry: (usize, usize), entries: &[(usize, usize)], length: f64) {
        let left = Self::sorted(entries);
        self.0.push(Release {
            entry,
            left,
            length,
        });
    }

    /// Whether `entry`, penetrating with `entries` active at `length`, closes such a cycle.
    fn cycles(&self, entry: (usize, usize), entries: &[(usize, usize)], length: f64) -> bool {
        let now = Self::sorted(entries);
        (self.0.iter()).any(|r| r.entry == entry && r.left == now && r.length == length)
    }
}

/// The passes of a contact step before it is given up as unsettled; in its second half a
/// cycling friction status is accepted as it stands, and with `ContactState::accept_cycles`
/// an entry that cycles between tension and penetration stays open.
const PASSES: usize = 100;

/// The inactive slaves that penetrate at the end of a solve (positions `end`, against the
/// pairs `at_end`), and the fraction alpha = g_0 / (g_0 - g_1) of the step at which the first
/// of them touched (Erklig 2.1.4; g_0 at `start` against the pairs `at_start`, which differ
/// where an obstacle moves); 0 when one was already within TOL at the start or the pair does
/// not split.
fn first_event(
    (at_start, at_end): (&[ContactPair], &[ContactPair]),
    start: &[[f64; 2]],
    end: &dyn Fn(usize) -> [f64; 2],
    entries: &[(usize, usize)],
) -> (Vec<(usize, usize)>, f64) {
    let search = std::time::Instant::now();
    let start_position = |n: usize| start[n];
    let mut penetrating = Vec::new();
    let mut alpha = 1.0f64;
    for s in search::penetrating(at_end, end, &|p, k| entries.contains(&(p, k))) {
        let options = &at_end[s.pair].options;
        let g0 = (at_start[s.pair].gap(s.node, &start_position)).map_or(0.0, |g| g.gap);
        if options.persistency && g0 < 0.0 && s.gap.gap >= g0 - options.tolerance {
            continue; // the gap a persistent pair closed with, not deeper
        }
        penetrating.push((s.pair, s.index));
        if options.split_at_events && g0 > options.tolerance {
            alpha = alpha.min(g0 / (g0 - s.gap.gap));
        } else {
            alpha = 0.0;
        }
    }
    crate::profile::add(crate::profile::Phase::Contact, search);
    (penetrating, alpha)
}
/// One pass of a contact step, what the solver is asked to solve: the step's `length`, the
/// `active` entries as (pair, slave node), their `forces` (the multipliers' start), the
/// `tangential` conditions, `warm`: after a change of the active set at the same length
/// the last pass's increment (Newton then starts at the solution it had, not at the predictor
/// again), after a split or a change of a slip status none; and how the solve may change the
/// active set (`inside`; with `Releases` and `Closures` the entries and conditions are where
/// the iteration starts).
pub struct Pass<'a> {
    /// The pairs at the end of the pass's length (a moving obstacle placed there).
    pub pairs: &'a [ContactPair],
    pub length: f64,
    pub active: &'a [(usize, usize)],
    pub forces: Vec<f64>,
    pub tangential: &'a [Tangential],
    pub warm: Option<&'a [f64]>,
    pub inside: Inside,
}

impl ContactState {
    fn entries(&self) -> (Vec<(usize, usize)>, Vec<f64>) {
        let mut entries = Vec::new();
        let mut forces = Vec::new();
        for (p, flags) in self.active.iter().enumerate() {
            for (k, a) in flags.iter().enumerate() {
                if *a {
                    entries.push((p, k));
                    forces.push(self.force[p][k]);
                }
            }
        }
        (entries, forces)
    }

    /// The friction status an entry starts a step with (Coulomb with mu = 0 is frictionless:
    /// no tangential condition, rather than rows that would only ever slide with 0).
    fn slip_start(&self, pairs: &[ContactPair], (p, k): (usize, usize)) -> Slip {
        match pairs[p].options.friction {
            Friction::None | Friction::Return { .. } => Slip::Free,
            Friction::Coulomb { mu: 0.0 } => Slip::Free,
            Friction::Coulomb { .. } if self.active[p][k] && self.sliding[p][k] != 0.0 => {
                Slip::Slide(self.sliding[p][k])
            }
            Friction::Coulomb { .. } => Slip::Stick,
        }
    }

    /// Runs one step with contact from the positions `start` at time `time`: `solve` solves
    /// the step for each [`Pass`] (a length and an active set, the pairs placed at its end)
    /// until the active set settles.
    pub fn step<S: ConstrainedSolution, E: From<Unsettled>>(
        &self,
        (pairs, time): (&[ContactPair], f64),
        start: &[[f64; 2]],
        length: f64,
        mut solve: impl FnMut(Pass<'_>) -> Result<S, E>,
    ) -> Result<ContactResult<S>, E> {
        let at_start = self.placed(pairs, time);
        let (mut entries, mut forces) = self.entries();
        let mut slips: Vec<Slip> = entries.iter().map(|e| self.slip_start(pairs, *e)).collect();
        let mut returned = false;
        let mut length = length;
        let mut split = false;
        let mut warm: Option<Vec<f64>> = None;
        let mut pulled = Pulled::default();
        for pass in 0..PASSES {
            let nodes: Vec<(usize, usize)> = entries
                .iter()
                .map(|(p, k)| (*p, pairs[*p].slaves[*k]))
                .collect();
            let carried = carried_slips(&at_start, &entries, start, (time, length));
            let tangential = tangential_conditions(&slips, &carried);
            let at_end = self.placed(pairs, time + length);
            let pairs = &at_end[..];
            let solution = solve(Pass {
                pairs,
                length,
                active: &nodes,
                forces: forces.clone(),
                tangential: &tangential,
                warm: warm.as_deref(),
                inside: Inside::Fixed,
            })?;
            let (normal, d) = (solution.normal_forces(), solution.increment());
            warm = Some(d.to_vec());
            // release entries in tension, most negative first, and solve again
            if let Some(worst) = (0..entries.len())
                .filter(|i| normal[*i] < 0.0)
                .min_by(|a, b| normal[*a].total_cmp(&normal[*b]))
            {
                let entry = entries.remove(worst);
                pulled.record(entry, &entries, length);
                slips.remove(worst);
                forces = normal.to_vec();
                forces.remove(worst);
                continue;
            }
            let end = |n: usize| [start[n][0] + d[2 * n], start[n][1] + d[2 * n + 1]];
            let (mut penetrating, alpha) = first_event((&at_start, pairs), start, &end, &entries);
            if self.accept_cycles && pass >= PASSES / 2 {
                // the last resort before the run stops (`Pulled`)
                penetrating.retain(|e| !pulled.cycles(*e, &entries, length));
            }
            if penetrating.is_empty() {
                // friction: Greco's return targets from this (frictionless) slip, once per
                // step; Coulomb stick <-> slide switches. A cycling status is accepted after
                // half the passes.
                let slip_of = |i: usize| -> f64 {
                    let (p, k) = entries[i];
                    let s = pairs[p].slaves[k];
                    pairs[p].gap(s, &end).map_or(0.0, |g| {
                        g.tangent_row(s)
                            .iter()
                            .map(|(dof, c)| c * d[*dof])
                            .sum::<f64>()
                            - carried[i]
                    })
                };
                let forces_t = per_entry(&slips, solution.tangential_forces());
                let mut changed = false;
                if !returned {
                    returned = true;
                    for i in 0..entries.len() {
                        if let Friction::Return { r } = pairs[entries[i].0].options.friction
                            && r > 0.0
                        {
                            slips[i] = Slip::Return((1.0 - r) * slip_of(i));
                            changed = true;
                        }
                    }
                }
                changed |=
                    coulomb_switches(pairs, &entries, &mut slips, (normal, &forces_t), &slip_of);
                if changed && pass < PASSES / 2 {
                    // a new slip status starts from the predictor: from the last increment
                    // the sliding equality |t| = mu tau lands at the Newton tolerance, not
                    // below it
                    forces = normal.to_vec();
                    warm = None;
                    continue;
                }
                let rows = ConvergedRows::of_passes(entries, (normal.to_vec(), forces_t), &slips);
                return Ok(self.finish(pairs, solution, length, rows));
            }
            if !split && alpha > MIN_SPLIT && alpha < 1.0 {
                // Erklig 2.1.4: end the step where the first slave touches
                length *= alpha;
                split = true;
                returned = false;
                warm = None;
                forces = normal.to_vec();
                continue;
            }
            forces = normal.to_vec();
            for e in penetrating {
                entries.push(e);
                slips.push(match pairs[e.0].options.friction {
                    Friction::Coulomb { mu } if mu > 0.0 => Slip::Stick,
                    _ => Slip::Free,
                });
                forces.push(0.0);
            }
        }
        Err(Unsettled.into())
    }

    /// Runs one step with contact from the positions `start` with the active set decided
    /// inside Newton's iteration: the first pass keeps the slaves open at the start open
    /// (`Inside::Releases`); if some penetrate at its end, the step is split at the first
    /// contact event (Erklig 2.1.4, once) or, where it cannot be, solved again with those
    /// slaves free to close (`Inside::Closures`).
    pub fn step_inside<S: ConstrainedSolution, E: From<Unsettled>>(
        &self,
        (pairs, time): (&[ContactPair], f64),
        start: &[[f64; 2]],
        length: f64,
        mut solve: impl FnMut(Pass<'_>) -> Result<S, E>,
    ) -> Result<ContactResult<S>, E> {
        let at_start = self.placed(pairs, time);
        let (entries, forces) = self.entries();
        let slips: Vec<Slip> = entries.iter().map(|e| self.slip_start(pairs, *e)).collect();
        let nodes: Vec<(usize, usize)> = entries
            .iter()
            .map(|(p, k)| (*p, pairs[*p].slaves[*k]))
            .collect();
        // the active set inside Newton is refused against a moving obstacle with friction
        let tangential = tangential_conditions(&slips, &vec![0.0; slips.len()]);
        let mut length = length;
        let mut split = false;
        let mut inside = Inside::Releases;
        let mut warm: Option<Vec<f64>> = None;
        loop {
            let at_end = self.placed(pairs, time + length);
            let pairs = &at_end[..];
            let solution = solve(Pass {
                pairs,
                length,
                active: &nodes,
                forces: forces.clone(),
                tangential: &tangential,
                warm: warm.as_deref(),
                inside,
            })?;
            let Some(settled) = solution.settled().cloned() else {
                return Err(Unsettled.into());
            };
            let d = solution.increment();
            let end = |n: usize| [start[n][0] + d[2 * n], start[n][1] + d[2 * n + 1]];
            let (penetrating, alpha) = match inside {
                Inside::Closures => (Vec::new(), 1.0),
                _ => first_event((&at_start, pairs), start, &end, &settled.entries),
            };
            if penetrating.is_empty() {
                let rows = ConvergedRows {
                    entries: settled.entries,
                    forces: settled.forces,
                    tangential: settled.tangential,
                    sliding: settled.sliding,
                };
                return Ok(self.finish(pairs, solution, length, rows));
            }
            if !split && alpha > MIN_SPLIT && alpha < 1.0 {
                // Erklig 2.1.4: end the step where the first slave touches
                length *= alpha;
                split = true;
                warm = None;
                continue;
            }
            inside = Inside::Closures;
            warm = Some(d.to_vec());
        }
    }

    /// Takes a step's outcome as the new status; `time` is the end of the step.
    pub fn commit<S>(
        &mut self,
        interfaces: &Interfaces,
        step: &ContactResult<S>,
        time: f64,
        coords: &[[f64; 2]],
    ) {
        let released = !step.events.released.is_empty() || !step.events.separated.is_empty();
        let rows = (&step.active[..], &step.forces[..]);
        self.set(interfaces, rows, (time, released), &|n| coords[n], None);
        for (i, (p, k)) in step.active.iter().enumerate() {
            self.tangential[*p][*k] = step.tangential[i];
            self.sliding[*p][*k] = step.sliding[i];
        }
    }

    /// The fraction release rule and the event lists of a converged step.
    fn finish<S>(
        &self,
        pairs: &[ContactPair],
        solution: S,
        length: f64,
        rows: ConvergedRows,
    ) -> ContactResult<S> {
        let ConvergedRows {
            mut entries,
            mut forces,
            mut tangential,
            mut sliding,
        } = rows;
        let mut events = Events::default();
        let mut i = 0;
        while i < entries.len() {
            let (p, k) = entries[i];
            let previous = self.force[p][k];
            let was_active = self.active[p][k];
            let fraction = pairs[p].options.release_fraction;
            if was_active && previous > 0.0 && forces[i] < fraction * previous {
                events.released.push((p, k, forces[i], tangential[i]));
                entries.remove(i);
                forces.remove(i);
                tangential.remove(i);
                sliding.remove(i);
                continue;
            }
            if !was_active {
                events.closed.push((p, k));
            }
            i += 1;
        }
        for (p, flags) in self.active.iter().enumerate() {
            for (k, a) in flags.iter().enumerate() {
                if *a
                    && !entries.contains(&(p, k))
                    && !events.released.iter().any(|r| (r.0, r.1) == (p, k))
                {
                    events.separated.push((p, k));
                }
            }
        }
        ContactResult {
            solution,
            length,
            active: entries,
            forces,
            tangential,
            sliding,
            events,
        }
    }
}

/// The rows of a converged contact iteration: the active entries (pair, slave) and their
/// normal and tangential forces, and each entry's sliding coefficient (0: sticking or
/// frictionless).
struct ConvergedRows {
    entries: Vec<(usize, usize)>,
    forces: Vec<f64>,
    tangential: Vec<f64>,
    sliding: Vec<f64>,
}

impl ConvergedRows {
    /// The rows the passes converged to: the entries, their normal and tangential forces,
    /// and the sliding coefficient of each entry's slip status.
    fn of_passes(
        entries: Vec<(usize, usize)>,
        (forces, tangential): (Vec<f64>, Vec<f64>),
        slips: &[Slip],
    ) -> ConvergedRows {
        let sliding = (slips.iter())
            .map(|s| match s {
                Slip::Slide(c) => *c,
                _ => 0.0,
            })
            .collect();
        ConvergedRows {
            entries,
            forces,
            tangential,
            sliding,
        }
    }
}

/// Coulomb stick <-> slide switches of a converged pass: a sticking entry whose friction
/// force exceeds mu tau slides, a sliding one whose friction force would push along its slip
/// (`slip_of`) sticks. Whether any status changed.
fn coulomb_switches(
    pairs: &[ContactPair],
    entries: &[(usize, usize)],
    slips: &mut [Slip],
    (normal, forces_t): (&[f64], &[f64]),
    slip_of: &dyn Fn(usize) -> f64,
) -> bool {
    let mut changed = false;
    for i in 0..entries.len() {
        let Friction::Coulomb { mu } = pairs[entries[i].0].options.friction else {
            continue;
        };
        let tol = pairs[entries[i].0].options.tolerance;
        match slips[i] {
            Slip::Stick if forces_t[i].abs() > mu * normal[i] * (1.0 + 1e-9) => {
                slips[i] = Slip::Slide(mu * forces_t[i].signum());
                changed = true;
            }
            // the friction force may not push along the slip
            Slip::Slide(c) if c * slip_of(i) > 1e-3 * tol.max(1e-300) => {
                slips[i] = Slip::Stick;
                changed = true;
            }
            _ => {}
        }
    }
    changed
}
