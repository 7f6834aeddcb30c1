//! The active set across steps and the event logic inside a step.
//!
//! In a step: solve with the current active set; release entries in tension (tau < 0) and
//! solve again; if inactive slaves penetrate beyond TOL, either shorten the step to the first
//! contact event (Erklig 2.1.4: the fraction alpha = g_0 / (g_0 - g_1), once per step) or
//! activate them and solve again (Hughes II-7). After the step, entries whose force fell
//! below `release_fraction` of the last step's are released; dynamics then applies the
//! impact and release conditions (`conditions`).

use super::conditions;
use super::geometry::{ContactPair, Friction, Master};
use super::search::{self, SlaveGap, slave_gaps};
use super::{ContactSummary, Interfaces, Section};

/// The shortest fraction of a step an event split may leave: an event closer to the step
/// start than this closes in the full step (Hughes II-7) instead.
const MIN_SPLIT: f64 = 0.1;

/// The contact status carried from step to step.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct ContactState {
    /// Per pair, per slave (in the pair's order): active?
    pub active: Vec<Vec<bool>>,
    /// Per pair, per slave: the last converged force.
    pub force: Vec<Vec<f64>>,
    /// Per pair, per slave: the last converged tangential (friction) force along t.
    pub tangential: Vec<Vec<f64>>,
    /// Per pair, per slave: the signed Coulomb coefficient of a sliding entry, 0 sticking.
    pub sliding: Vec<Vec<f64>>,
    pub first_contact_time: Option<f64>,
    pub last_release_time: Option<f64>,
    pub peak_force: f64,
    pub peak_extent: f64,
    /// The most negative gap of any slave after any step (penetration), or None.
    pub min_gap: Option<f64>,
    /// The deepest penetration of either surface into the other body after any step: a
    /// slave's negative gap, or a deformable master's node inside the slave body (>= 0).
    pub max_penetration: f64,
    /// The same after the last step alone.
    pub penetration: f64,
    /// Per pair: closed at some step (empty in a checkpoint written before it was kept).
    #[serde(default)]
    pub ever_closed: Vec<bool>,
    /// The explicit correction's master block after the last step: the master nodes of
    /// mortar pairs held out of the slave body by a row of their own, and their normal
    /// forces (`contact::explicit`). Empty on every other path.
    #[serde(default)]
    pub master_block: Vec<MasterEntry>,
    /// The explicit correction's vectors over all DOFs, kept zero between steps, so that a
    /// step neither allocates nor clears them whole (`contact::explicit`; not in a
    /// checkpoint: zero vectors of the right length either way).
    #[serde(skip)]
    pub(super) scratch: Scratch,
}

/// Vectors over all DOFs, zero between uses (`ContactState::scratch`).
#[derive(Debug, Clone, Default)]
pub(super) struct Scratch {
    pub delta: Vec<f64>,
    pub force: Vec<f64>,
}

/// A master node of a mortar pair held out of the slave body by its own row (the explicit
/// correction's master block), with its reported normal force.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MasterEntry {
    pub pair: usize,
    pub node: usize,
    pub force: f64,
}

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
/// tangential conditions (in theirs).
pub trait ConstrainedSolution {
    fn increment(&self) -> &[f64];
    fn normal_forces(&self) -> &[f64];
    fn tangential_forces(&self) -> &[f64];
}

/// The active set did not settle within the passes a step allows.
#[derive(Debug, Clone, Copy)]
pub struct Unsettled;

impl std::fmt::Display for Unsettled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the contact active set did not settle in 100 passes")
    }
}

/// The tangential conditions of the entries' friction status, in entry order.
fn tangential_conditions(slips: &[Slip]) -> Vec<Tangential> {
    slips
        .iter()
        .enumerate()
        .filter_map(|(entry, s)| match *s {
            Slip::Free => None,
            Slip::Stick => Some(Tangential::Fixed { entry, target: 0.0 }),
            Slip::Return(target) => Some(Tangential::Fixed { entry, target }),
            Slip::Slide(coefficient) => Some(Tangential::Sliding { entry, coefficient }),
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

/// The inactive slaves that penetrate at the end of a solve (positions `end`), and the
/// fraction alpha = g_0 / (g_0 - g_1) of the step at which the first of them touched
/// (Erklig 2.1.4); 0 when one was already within TOL at the start or the pair does not split.
fn first_event(
    pairs: &[ContactPair],
    start: &[[f64; 2]],
    end: &dyn Fn(usize) -> [f64; 2],
    entries: &[(usize, usize)],
) -> (Vec<(usize, usize)>, f64) {
    let search = std::time::Instant::now();
    let at_start = |n: usize| start[n];
    let mut penetrating = Vec::new();
    let mut alpha = 1.0f64;
    for s in search::penetrating(pairs, end, &|p, k| entries.contains(&(p, k))) {
        let options = &pairs[s.pair].options;
        let g0 = pairs[s.pair].gap(s.node, &at_start).map_or(0.0, |g| g.gap);
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
/// `tangential` conditions, and `warm`: after a change of the active set at the same length
/// the last pass's increment (Newton then starts at the solution it had, not at the predictor
/// again), after a split or a change of a slip status none.
pub struct Pass<'a> {
    pub length: f64,
    pub active: &'a [(usize, usize)],
    pub forces: Vec<f64>,
    pub tangential: &'a [Tangential],
    pub warm: Option<&'a [f64]>,
}

impl ContactState {
    /// Every pair starts open: slaves touching at the start (|g| <= TOL) close in the first
    /// step they press on their master, so the impact conditions see that closure.
    pub fn new(pairs: &[ContactPair]) -> ContactState {
        let active = pairs.iter().map(|p| vec![false; p.slaves.len()]).collect();
        let force: Vec<Vec<f64>> = pairs.iter().map(|p| vec![0.0; p.slaves.len()]).collect();
        let zeros: Vec<Vec<f64>> = force.clone();
        ContactState {
            active,
            tangential: zeros.clone(),
            sliding: zeros,
            force,
            first_contact_time: None,
            last_release_time: None,
            peak_force: 0.0,
            peak_extent: 0.0,
            min_gap: None,
            max_penetration: 0.0,
            penetration: 0.0,
            ever_closed: vec![false; pairs.len()],
            master_block: Vec::new(),
            scratch: Scratch::default(),
        }
    }

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

    /// Runs one step with contact from the positions `start`: `solve` solves the step for
    /// each [`Pass`] (a length and an active set) until the active set settles.
    pub fn step<S: ConstrainedSolution, E: From<Unsettled>>(
        &self,
        pairs: &[ContactPair],
        start: &[[f64; 2]],
        length: f64,
        mut solve: impl FnMut(Pass<'_>) -> Result<S, E>,
    ) -> Result<ContactResult<S>, E> {
        let (mut entries, mut forces) = self.entries();
        let mut slips: Vec<Slip> = entries.iter().map(|e| self.slip_start(pairs, *e)).collect();
        let mut returned = false;
        let mut length = length;
        let mut split = false;
        let mut warm: Option<Vec<f64>> = None;
        for pass in 0..100 {
            let nodes: Vec<(usize, usize)> = entries
                .iter()
                .map(|(p, k)| (*p, pairs[*p].slaves[*k]))
                .collect();
            let tangential = tangential_conditions(&slips);
            let solution = solve(Pass {
                length,
                active: &nodes,
                forces: forces.clone(),
                tangential: &tangential,
                warm: warm.as_deref(),
            })?;
            let (normal, d) = (solution.normal_forces(), solution.increment());
            warm = Some(d.to_vec());
            // release entries in tension, most negative first, and solve again
            if let Some(worst) = (0..entries.len())
                .filter(|i| normal[*i] < 0.0)
                .min_by(|a, b| normal[*a].total_cmp(&normal[*b]))
            {
                entries.remove(worst);
                slips.remove(worst);
                forces = normal.to_vec();
                forces.remove(worst);
                continue;
            }
            let end = |n: usize| [start[n][0] + d[2 * n], start[n][1] + d[2 * n + 1]];
            let (penetrating, alpha) = first_event(pairs, start, &end, &entries);
            if penetrating.is_empty() {
                // friction: Greco's return targets from this (frictionless) slip, once per
                // step; Coulomb stick <-> slide switches. A cycling status is accepted after
                // half the passes.
                let slip_of = |i: usize| -> f64 {
                    let (p, k) = entries[i];
                    let s = pairs[p].slaves[k];
                    pairs[p].gap(s, &end).map_or(0.0, |g| {
                        g.tangent_row(s).iter().map(|(dof, c)| c * d[*dof]).sum()
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
                if changed && pass < 50 {
                    // a new slip status starts from the predictor: from the last increment
                    // the sliding equality |t| = mu tau lands at the Newton tolerance, not
                    // below it
                    forces = normal.to_vec();
                    warm = None;
                    continue;
                }
                let forces = normal.to_vec();
                let sliding = slips
                    .iter()
                    .map(|s| match s {
                        Slip::Slide(c) => *c,
                        _ => 0.0,
                    })
                    .collect();
                let rows = ConvergedRows {
                    entries,
                    forces,
                    tangential: forces_t,
                    sliding,
                };
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

    /// Closes, at the start of a step, the open slaves that touch their master (|g| <= TOL)
    /// and approach it: the moment of impact. With impact conditions the pair's normal
    /// velocities and accelerations are made compatible there (Hughes II-8, with the
    /// velocities of the end of the previous step, which these are). Returns the entries
    /// closed.
    pub fn close_touching(
        &mut self,
        interfaces: &Interfaces,
        coords: &[[f64; 2]],
        mass: LumpedMass,
        (velocity, acceleration): (&mut [f64], &mut [f64]),
    ) -> Vec<(usize, usize)> {
        let LumpedMass {
            mass: lumped,
            inverse: inverse_mass,
        } = mass;
        let x = |n: usize| coords[n];
        let touching: Vec<SlaveGap> = slave_gaps(&interfaces.pairs, &x, &|p, k| self.active[p][k])
            .filter(|s| {
                let pair = &interfaces.pairs[s.pair];
                s.gap.gap.abs() <= pair.options.tolerance
                    && !pair.covers(&interfaces.pairs, &s.gap, &x, &|p, k| self.active[p][k])
            })
            .collect();
        let mut closed = Vec::new();
        for SlaveGap {
            pair: p,
            index: k,
            node: s,
            gap,
        } in touching
        {
            let pair = &interfaces.pairs[p];
            let entry = conditions::Entry {
                interfaces,
                pair,
                slave: s,
                gap: &gap,
                coords,
                lumped,
            };
            if !conditions::approaching(&entry, velocity) {
                continue; // touching but not approaching
            }
            self.active[p][k] = true;
            self.force[p][k] = 0.0;
            closed.push((p, k));
            if pair.options.impact_conditions && !pair.joint_conditions() {
                // the velocities before the impact are the previous step's
                let previous = velocity.to_vec();
                let mut force = 0.0;
                conditions::impact(&entry, &previous, velocity, acceleration, &mut force);
                self.force[p][k] = force.max(0.0);
            }
        }
        // the rows of the mortar pairs and their hold pairs share nodes: their conditions are
        // met together
        let joint = |p: usize| met_together(interfaces, p);
        if closed.iter().any(|(q, _)| joint(*q)) {
            let active = &self.active;
            let entries: Vec<(usize, usize)> = (0..interfaces.pairs.len())
                .filter(|p| joint(*p))
                .flat_map(|p| {
                    (0..interfaces.pairs[p].slaves.len())
                        .filter(move |k| active[p][*k])
                        .map(move |k| (p, k))
                })
                .collect();
            let rows = joint_rows(interfaces, &entries, &x);
            let mut forces: Vec<f64> = entries.iter().map(|(p, k)| self.force[*p][*k]).collect();
            conditions::impact_together(&rows, inverse_mass, velocity, acceleration, &mut forces);
            for ((p, k), f) in entries.iter().zip(forces) {
                self.force[*p][*k] = f;
            }
        }
        closed
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

    /// Sets the status: the active entries and their forces (`(active, forces)`) after a step
    /// ending at `time` (`released`: some entry let go in it) with the nodes at `positions`.
    /// `lowest`: the lowest slave gap there when the caller has just computed every slave's
    /// gap there (Some(None): no slave has a master in reach); None computes them.
    pub(super) fn set(
        &mut self,
        interfaces: &Interfaces,
        (active, forces): (&[(usize, usize)], &[f64]),
        (time, released): (f64, bool),
        x: &impl Fn(usize) -> [f64; 2],
        lowest: Option<Option<f64>>,
    ) {
        for flags in &mut self.active {
            flags.iter_mut().for_each(|a| *a = false);
        }
        for forces in self
            .force
            .iter_mut()
            .chain(&mut self.tangential)
            .chain(&mut self.sliding)
        {
            forces.iter_mut().for_each(|f| *f = 0.0);
        }
        for (i, (p, k)) in active.iter().enumerate() {
            self.active[*p][*k] = true;
            self.force[*p][*k] = forces[i];
            if let Some(closed) = self.ever_closed.get_mut(*p) {
                *closed = true;
            }
        }
        if !active.is_empty() && self.first_contact_time.is_none() {
            self.first_contact_time = Some(time);
        }
        if released {
            self.last_release_time = Some(time);
        }
        let total: f64 =
            forces.iter().sum::<f64>() + self.master_block.iter().map(|e| e.force).sum::<f64>();
        self.peak_force = self.peak_force.max(total);
        let lowest = lowest.unwrap_or_else(|| {
            slave_gaps(&interfaces.pairs, x, &|_, _| false)
                .map(|s| s.gap.gap)
                .reduce(f64::min)
        });
        let mut penetration = 0.0f64;
        if let Some(g) = lowest {
            self.min_gap = Some(self.min_gap.map_or(g, |m| m.min(g)));
            penetration = penetration.max(-g);
        }
        for pair in &interfaces.pairs {
            let boundary = &interfaces.bodies[pair.slave_body].boundary;
            penetration = penetration.max(super::setup::master_penetration(pair, x, boundary));
            penetration = penetration.max(super::setup::slave_penetration(pair, x));
        }
        self.penetration = penetration;
        self.max_penetration = self.max_penetration.max(penetration);
        self.peak_extent = self.peak_extent.max(extent(interfaces, active, x));
    }
}

impl ContactState {
    /// The contact block of summary.json.
    /// The contact block of summary.json for the run's `pairs`.
    pub fn summary(&self, pairs: &[ContactPair]) -> ContactSummary {
        // a second pass closes nothing where its first pass holds the contact: the two
        // passes are one contact
        let closed = |p: usize| {
            let first = pairs[p].covered.as_ref().map(|c| c.pair);
            [Some(p), first]
                .into_iter()
                .flatten()
                .any(|q| self.ever_closed.get(q).copied().unwrap_or(true))
        };
        ContactSummary {
            never_closed: (0..pairs.len().min(self.ever_closed.len()))
                .filter(|p| !closed(*p))
                .map(|p| pairs[p].name.clone())
                .collect(),
            first_contact_time: self.first_contact_time,
            last_release_time: self.last_release_time,
            peak_force: self.peak_force,
            peak_contact_radius: self.peak_extent,
            min_gap: self.min_gap,
            max_penetration: self.min_gap.map(|_| self.max_penetration),
        }
    }

    /// Total normal force per pair (the slave entries' and the master block's).
    pub fn pair_forces(&self) -> Vec<f64> {
        let mut totals: Vec<f64> = self.force.iter().map(|f| f.iter().sum()).collect();
        for entry in &self.master_block {
            totals[entry.pair] += entry.force;
        }
        totals
    }

    /// Total tangential (friction) force along t per pair.
    pub fn pair_tangential_forces(&self) -> Vec<f64> {
        self.tangential.iter().map(|f| f.iter().sum()).collect()
    }

    /// Nodal contact forces (all DOFs) at positions `coords`: +tau n on slaves, -w tau n on
    /// master nodes.
    pub fn nodal_forces(&self, pairs: &[ContactPair], coords: &[[f64; 2]]) -> Vec<f64> {
        let mut f = self.nodal_forces_of(pairs, coords, &self.force, &self.tangential);
        let x = |n: usize| coords[n];
        for entry in &self.master_block {
            let pair = &pairs[entry.pair];
            let (Some(surface), Master::Segments { edges, .. }) = (&pair.mortar, &pair.master)
            else {
                continue;
            };
            let gap = super::mortar::master_node_gap(
                &surface.edges,
                edges,
                entry.node,
                super::mortar::MASTER_ALLOWANCE,
                &x,
            );
            if let Some(gap) = gap {
                for (dof, c) in gap.row(entry.node) {
                    f[dof] += entry.force * c;
                }
            }
        }
        f
    }

    /// As `nodal_forces`, with the normal forces `normal` and the tangential ones
    /// `tangential` (per pair, per slave) on the active entries.
    pub(super) fn nodal_forces_of(
        &self,
        pairs: &[ContactPair],
        coords: &[[f64; 2]],
        normal: &[Vec<f64>],
        tangential: &[Vec<f64>],
    ) -> Vec<f64> {
        let zeros = vec![0.0; 2 * coords.len()];
        self.nodal_forces_into(pairs, coords, (normal, tangential), zeros)
    }

    /// The same, added into `f` (zero over all DOFs).
    pub(super) fn nodal_forces_into(
        &self,
        pairs: &[ContactPair],
        coords: &[[f64; 2]],
        (normal, tangential): (&[Vec<f64>], &[Vec<f64>]),
        mut f: Vec<f64>,
    ) -> Vec<f64> {
        let x = |n: usize| coords[n];
        for s in slave_gaps(pairs, &x, &|p, k| !self.active[p][k]) {
            let (p, k) = (s.pair, s.index);
            for (dof, c) in s.gap.row(s.node) {
                f[dof] += normal[p][k] * c;
            }
            for (dof, c) in s.gap.tangent_row(s.node) {
                f[dof] += tangential[p][k] * c;
            }
        }
        f
    }

    /// Per node: the gap and the status of slave nodes (status 1 active, 0 open), zeros
    /// elsewhere.
    pub fn nodal_status(&self, pairs: &[ContactPair], coords: &[[f64; 2]]) -> NodalStatus {
        let mut gap = vec![0.0; coords.len()];
        let mut status = vec![0.0; coords.len()];
        let x = |n: usize| coords[n];
        for s in slave_gaps(pairs, &x, &|_, _| false) {
            gap[s.node] = s.gap.gap;
        }
        for (p, pair) in pairs.iter().enumerate() {
            for (k, s) in pair.slaves.iter().enumerate() {
                status[*s] = if self.active[p][k] { 1.0 } else { 0.0 };
            }
        }
        NodalStatus { gap, status }
    }
}

/// Per node: the gap and the contact status of slave nodes (1 active, 0 open), zeros elsewhere.
pub struct NodalStatus {
    pub gap: Vec<f64>,
    pub status: Vec<f64>,
}

/// Largest extent of the closed entries: the largest radius for axisymmetric slaves, else
/// the largest distance between two closed slaves of a pair.
fn extent(
    interfaces: &Interfaces,
    active: &[(usize, usize)],
    x: &dyn Fn(usize) -> [f64; 2],
) -> f64 {
    let mut best: f64 = 0.0;
    for (p, pair) in interfaces.pairs.iter().enumerate() {
        let nodes: Vec<[f64; 2]> = active
            .iter()
            .filter(|(q, _)| *q == p)
            .map(|(_, k)| x(pair.slaves[*k]))
            .collect();
        let axisymmetric = interfaces.bodies[pair.slave_body].section == Section::Axisymmetric;
        for (i, a) in nodes.iter().enumerate() {
            if axisymmetric {
                best = best.max(a[0]);
                continue;
            }
            for b in &nodes[i + 1..] {
                best = best.max(((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt());
            }
        }
    }
    best
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

/// The nodal motion the impact and release conditions correct: the velocity at the start of
/// the step, and the step's velocity and acceleration (all DOFs), corrected in place.
pub struct ImpactMotion<'a> {
    pub previous_velocity: &'a [f64],
    pub velocity: &'a mut [f64],
    pub acceleration: &'a mut [f64],
}

/// The lumped mass of every DOF and its inverse (0 on prescribed DOFs).
#[derive(Clone, Copy)]
pub struct LumpedMass<'a> {
    pub mass: &'a [f64],
    pub inverse: &'a [f64],
}

/// Hughes II-8 for the entries that closed and II-11, II-12 for those released by the
/// fraction rule: corrects `velocity` and `acceleration` (all DOFs) in place, and the forces
/// of closed entries. `previous_velocity` is the velocity at the start of the step.
pub fn apply_conditions<S>(
    interfaces: &Interfaces,
    step: &mut ContactResult<S>,
    coords: &[[f64; 2]],
    mass: LumpedMass,
    mut motion: ImpactMotion,
) {
    impact_mortar_pairs(interfaces, step, coords, mass.inverse, &mut motion);
    impact_slaves(interfaces, step, coords, mass.mass, &mut motion);
    release_slaves(interfaces, step, coords, mass, &mut motion);
}

/// II-8 on the mortar pairs and their hold pairs where an entry closed: all their active
/// rows at once (they share nodes), their forces corrected.
fn impact_mortar_pairs<S>(
    interfaces: &Interfaces,
    step: &mut ContactResult<S>,
    coords: &[[f64; 2]],
    inverse_mass: &[f64],
    motion: &mut ImpactMotion,
) {
    let (velocity, acceleration) = (&mut *motion.velocity, &mut *motion.acceleration);
    let x = |n: usize| coords[n];
    let joint = |p: usize| met_together(interfaces, p);
    if !step.events.closed.iter().any(|(q, _)| joint(*q)) {
        return;
    }
    let entries: Vec<usize> = (0..step.active.len())
        .filter(|i| joint(step.active[*i].0))
        .collect();
    let pairs: Vec<(usize, usize)> = entries.iter().map(|i| step.active[*i]).collect();
    let rows = joint_rows(interfaces, &pairs, &x);
    let mut forces: Vec<f64> = entries.iter().map(|i| step.forces[*i]).collect();
    conditions::impact_together(&rows, inverse_mass, velocity, acceleration, &mut forces);
    for (i, f) in entries.iter().zip(forces) {
        step.forces[*i] = f;
    }
}

/// Whether pair `p` takes impact conditions, met together with the other such pairs' rows
/// (`ContactPair::joint_conditions`).
fn met_together(interfaces: &Interfaces, p: usize) -> bool {
    let pair = &interfaces.pairs[p];
    pair.options.impact_conditions && pair.joint_conditions()
}

/// The constraint rows of `entries` (pair, slave index) at positions `x` (an entry whose gap
/// is gone: an empty row).
fn joint_rows(
    interfaces: &Interfaces,
    entries: &[(usize, usize)],
    x: &dyn Fn(usize) -> [f64; 2],
) -> Vec<Vec<(usize, f64)>> {
    entries
        .iter()
        .map(|(p, k)| {
            let pair = &interfaces.pairs[*p];
            let s = pair.slaves[*k];
            pair.gap(s, x).map_or_else(Vec::new, |g| g.row(s))
        })
        .collect()
}

/// II-8 on each closed entry of the other pairs, its force kept compressive and its
/// friction force following it.
fn impact_slaves<S>(
    interfaces: &Interfaces,
    step: &mut ContactResult<S>,
    coords: &[[f64; 2]],
    lumped: &[f64],
    motion: &mut ImpactMotion,
) {
    let previous_velocity = motion.previous_velocity;
    let (velocity, acceleration) = (&mut *motion.velocity, &mut *motion.acceleration);
    let x = |n: usize| coords[n];
    for &(p, k) in &step.events.closed {
        let pair = &interfaces.pairs[p];
        if !pair.options.impact_conditions || pair.joint_conditions() {
            continue;
        }
        let s = pair.slaves[k];
        let Some(gap) = pair.gap(s, &x) else { continue };
        let i = step
            .active
            .iter()
            .position(|e| *e == (p, k))
            .expect("closed entries are active");
        let entry = conditions::Entry {
            interfaces,
            pair,
            slave: s,
            gap: &gap,
            coords,
            lumped,
        };
        conditions::impact(
            &entry,
            previous_velocity,
            velocity,
            acceleration,
            &mut step.forces[i],
        );
        // a compressive multiplier: II-8's correction may not turn it into a pull; the
        // friction force follows the corrected normal force (a sliding entry's stays mu tau,
        // a sticking one's is held within it), and the slave's tangential acceleration with it
        step.forces[i] = step.forces[i].max(0.0);
        if let Friction::Coulomb { mu } = pair.options.friction {
            let old = step.tangential[i];
            let limit = mu * step.forces[i];
            step.tangential[i] = if step.sliding[i] != 0.0 {
                step.sliding[i] * step.forces[i]
            } else {
                old.clamp(-limit, limit)
            };
            let t = gap.tangent();
            let change = step.tangential[i] - old;
            conditions::add_normal(acceleration, s, t, change / lumped[2 * s]);
            if let Some(side) = entry.master()
                && side.mass > 0.0
            {
                conditions::spread(acceleration, &side, t, -change / side.mass);
            }
        }
    }
}

/// II-11, II-12 on the entries released by the fraction rule (along the released row on a
/// mortar pair).
fn release_slaves<S>(
    interfaces: &Interfaces,
    step: &ContactResult<S>,
    coords: &[[f64; 2]],
    mass: LumpedMass,
    motion: &mut ImpactMotion,
) {
    let LumpedMass {
        mass: lumped,
        inverse: inverse_mass,
    } = mass;
    let (velocity, acceleration) = (&mut *motion.velocity, &mut *motion.acceleration);
    let x = |n: usize| coords[n];
    for &(p, k, tau, friction) in &step.events.released {
        let pair = &interfaces.pairs[p];
        if !pair.options.release_conditions {
            continue;
        }
        let s = pair.slaves[k];
        let Some(gap) = pair.gap(s, &x) else { continue };
        let n = gap.normal;
        let entry = conditions::Entry {
            interfaces,
            pair,
            slave: s,
            gap: &gap,
            coords,
            lumped,
        };
        let (ms, zs) = entry.slave_mass_and_impedance();
        // the impedance is positive for any node with a contact area (an axis node included)
        debug_assert!(zs > 0.0, "slave {s}: impedance {zs}");
        if pair.joint_conditions() {
            let zm = entry.master().map_or(0.0, |side| side.impedance);
            let compliance = 1.0 / zs + if zm > 0.0 { 1.0 / zm } else { 0.0 };
            let rows = conditions::Released {
                normal: gap.row(s),
                tangential: gap.tangent_row(s),
            };
            let forces = (tau, friction, compliance);
            conditions::release_along(&rows, inverse_mass, (velocity, acceleration), forces);
            continue;
        }
        conditions::add_normal(velocity, s, n, tau / zs);
        conditions::add_normal(acceleration, s, n, -tau / ms);
        // the friction force goes with the normal one (its acceleration, as in II-12)
        let t = gap.tangent();
        conditions::add_normal(acceleration, s, t, -friction / ms);
        if let Some(side) = entry.master() {
            conditions::spread(velocity, &side, n, -tau / side.impedance);
            conditions::spread(acceleration, &side, n, tau / side.mass);
            conditions::spread(acceleration, &side, t, friction / side.mass);
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
