//! Contact in the drivers: the active set across steps, the event logic inside a step, and
//! Hughes' impact and release conditions after it.
//!
//! Legend (per active entry: a slave node of a pair)
//! ```text
//! tau          compressive normal force (Lagrange multiplier)
//! Z            rho c A: the normal impedance of a node (c the dilatational wave speed,
//!              A its tributary contact area)
//! M            the node's lumped mass
//! v_n, a_n     normal components of velocity and acceleration, n out of the master
//! ```
//! In a step: solve with the current active set; release entries in tension (tau < 0) and
//! solve again; if inactive slaves penetrate beyond TOL, either shorten the step to the first
//! contact event (Erklig 2.1.4: the fraction alpha = g_0 / (g_0 - g_1), once per step) or
//! activate them and solve again (Hughes II-7). After the step, entries whose force fell
//! below `release_fraction` of the last step's are released. Dynamics then applies, for
//! entries that closed, the impact conditions (Hughes II-8)
//! ```text
//! V+ = (Z_s v_s,n-1 + Z_m v_m,n-1) / (Z_s + Z_m)       velocities of the previous step
//! a+ = (M_s a_s + M_m a_m) / (M_s + M_m),  tau+ = tau + M_s (a+ - a_s)
//! ```
//! and for entries released by the fraction rule the release conditions (II-11, II-12)
//! ```text
//! v_s,n += tau / Z_s,  v_m,n -= tau / Z_m,  a_s,n -= tau / M_s,  a_m,n += tau / M_m
//! ```
//! A rigid obstacle is a master of infinite mass and impedance at rest.

use super::newton::{Solution, StepFailure, Tangential};
use crate::contact::{ContactPair, Friction, Gap, Master};
use crate::element::Formulation;
use crate::scene::{BodyKind, Model};
use std::f64::consts::PI;

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

/// The result of a step with contact.
pub struct ContactStep {
    pub solution: Solution,
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

/// Per pair, the penetration beyond which a run stops: half the smallest distance between
/// two of its slave nodes in the initial configuration (infinite with one slave).
pub fn penetration_limits(model: &Model) -> Vec<f64> {
    let x = model.coordinates();
    model
        .contacts
        .iter()
        .map(|pair| {
            let mut nodes: Vec<[f64; 2]> = pair.slaves.iter().map(|s| x[*s]).collect();
            nodes.sort_by(|a, b| a[0].total_cmp(&b[0]));
            let mut h = f64::INFINITY;
            for i in 0..nodes.len() {
                for j in i + 1..nodes.len() {
                    let dx = nodes[j][0] - nodes[i][0];
                    if dx >= h {
                        break;
                    }
                    let d = dx.hypot(nodes[j][1] - nodes[i][1]);
                    if d > 0.0 {
                        h = h.min(d);
                    }
                }
            }
            0.5 * h
        })
        .collect()
}

impl ContactState {
    /// Every pair starts open: slaves touching at the start (|g| <= TOL) close in the first
    /// step they press on their master, so the impact conditions see that closure.
    pub fn new(model: &Model) -> ContactState {
        let active = model
            .contacts
            .iter()
            .map(|p| vec![false; p.slaves.len()])
            .collect();
        let force: Vec<Vec<f64>> = model
            .contacts
            .iter()
            .map(|p| vec![0.0; p.slaves.len()])
            .collect();
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

    /// The friction status an entry starts a step with.
    fn slip_start(&self, model: &Model, (p, k): (usize, usize)) -> Slip {
        match model.contacts[p].options.friction {
            Friction::None | Friction::Return { .. } => Slip::Free,
            Friction::Coulomb { .. } if self.active[p][k] && self.sliding[p][k] != 0.0 => {
                Slip::Slide(self.sliding[p][k])
            }
            Friction::Coulomb { .. } => Slip::Stick,
        }
    }

    /// Runs one step with contact. `solve(length, active (pair, slave node), forces,
    /// tangential conditions)` solves the step for a given active set.
    pub fn step(
        &self,
        model: &Model,
        reference: &[[f64; 2]],
        length: f64,
        mut solve: impl FnMut(
            f64,
            &[(usize, usize)],
            Vec<f64>,
            &[Tangential],
        ) -> Result<Solution, StepFailure>,
    ) -> Result<ContactStep, StepFailure> {
        let pairs = &model.contacts;
        let (mut entries, mut forces) = self.entries();
        let mut slips: Vec<Slip> = entries.iter().map(|e| self.slip_start(model, *e)).collect();
        let mut returned = false;
        let mut length = length;
        let mut split = false;
        for pass in 0..100 {
            let nodes: Vec<(usize, usize)> = entries
                .iter()
                .map(|(p, k)| (*p, pairs[*p].slaves[*k]))
                .collect();
            let tangential = tangential_conditions(&slips);
            let solution = solve(length, &nodes, forces.clone(), &tangential)?;
            // release entries in tension, most negative first, and solve again
            if let Some(worst) = (0..entries.len())
                .filter(|i| solution.forces[*i] < 0.0)
                .min_by(|a, b| solution.forces[*a].total_cmp(&solution.forces[*b]))
            {
                entries.remove(worst);
                slips.remove(worst);
                forces = solution.forces.clone();
                forces.remove(worst);
                continue;
            }
            let end = |n: usize| {
                [
                    reference[n][0] + solution.d[2 * n],
                    reference[n][1] + solution.d[2 * n + 1],
                ]
            };
            let start = |n: usize| reference[n];
            let search = std::time::Instant::now();
            let mut penetrating = Vec::new();
            let mut alpha = 1.0f64;
            for (p, pair) in pairs.iter().enumerate() {
                for (k, s) in pair.slaves.iter().enumerate() {
                    if entries.contains(&(p, k)) {
                        continue;
                    }
                    let Some(g1) = pair.gap(*s, &end) else {
                        continue;
                    };
                    if g1.gap >= -pair.options.tolerance {
                        continue;
                    }
                    penetrating.push((p, k));
                    let g0 = pair.gap(*s, &start).map_or(0.0, |g| g.gap);
                    if pair.options.split_at_events && g0 > pair.options.tolerance {
                        alpha = alpha.min(g0 / (g0 - g1.gap));
                    } else {
                        alpha = 0.0;
                    }
                }
            }
            crate::profile::add(crate::profile::Phase::Contact, search);
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
                            .map(|(dof, c)| c * solution.d[*dof])
                            .sum()
                    })
                };
                let forces_t = per_entry(&slips, &solution.tangential);
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
                for i in 0..entries.len() {
                    let Friction::Coulomb { mu } = pairs[entries[i].0].options.friction else {
                        continue;
                    };
                    let tau = solution.forces[i];
                    let tol = pairs[entries[i].0].options.tolerance;
                    match slips[i] {
                        Slip::Stick if forces_t[i].abs() > mu * tau * (1.0 + 1e-9) => {
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
                if changed && pass < 50 {
                    forces = solution.forces.clone();
                    continue;
                }
                let forces = solution.forces.clone();
                let sliding = slips
                    .iter()
                    .map(|s| match s {
                        Slip::Slide(c) => *c,
                        _ => 0.0,
                    })
                    .collect();
                return Ok(self.finish(model, solution, length, entries, forces, forces_t, sliding));
            }
            if !split && alpha > MIN_SPLIT && alpha < 1.0 {
                // Erklig 2.1.4: end the step where the first slave touches
                length *= alpha;
                split = true;
                returned = false;
                forces = solution.forces.clone();
                continue;
            }
            forces = solution.forces.clone();
            for e in penetrating {
                entries.push(e);
                slips.push(match pairs[e.0].options.friction {
                    Friction::Coulomb { .. } => Slip::Stick,
                    _ => Slip::Free,
                });
                forces.push(0.0);
            }
        }
        Err(StepFailure(
            "the contact active set did not settle in 100 passes".into(),
        ))
    }

    /// The fraction release rule and the event lists of a converged step.
    fn finish(
        &self,
        model: &Model,
        solution: Solution,
        length: f64,
        mut entries: Vec<(usize, usize)>,
        mut forces: Vec<f64>,
        mut tangential: Vec<f64>,
        mut sliding: Vec<f64>,
    ) -> ContactStep {
        let mut events = Events::default();
        let mut i = 0;
        while i < entries.len() {
            let (p, k) = entries[i];
            let previous = self.force[p][k];
            let was_active = self.active[p][k];
            let fraction = model.contacts[p].options.release_fraction;
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
        ContactStep {
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
        model: &Model,
        coords: &[[f64; 2]],
        lumped: &[f64],
        velocity: &mut [f64],
        acceleration: &mut [f64],
    ) -> Vec<(usize, usize)> {
        let x = |n: usize| coords[n];
        let mut closed = Vec::new();
        for (p, pair) in model.contacts.iter().enumerate() {
            for (k, s) in pair.slaves.iter().enumerate() {
                if self.active[p][k] {
                    continue;
                }
                let Some(gap) = pair.gap(*s, &x) else {
                    continue;
                };
                if gap.gap.abs() > pair.options.tolerance {
                    continue;
                }
                let n = gap.normal;
                let master = master_side(model, pair, &gap, lumped, coords);
                let vm = master
                    .as_ref()
                    .map_or(0.0, |m| interpolated(velocity, m, n));
                if normal_component(velocity, *s, n) - vm >= 0.0 {
                    continue; // touching but not approaching
                }
                self.active[p][k] = true;
                self.force[p][k] = 0.0;
                closed.push((p, k));
                if pair.options.impact_conditions {
                    // the velocities before the impact are the previous step's
                    let previous = velocity.to_vec();
                    let mut force = 0.0;
                    impact(
                        model,
                        pair,
                        *s,
                        &gap,
                        coords,
                        lumped,
                        &previous,
                        velocity,
                        acceleration,
                        &mut force,
                    );
                    self.force[p][k] = force.max(0.0);
                }
            }
        }
        closed
    }

    /// Takes a step's outcome as the new status; `time` is the end of the step.
    pub fn commit(&mut self, model: &Model, step: &ContactStep, time: f64, coords: &[[f64; 2]]) {
        let released = !step.events.released.is_empty() || !step.events.separated.is_empty();
        self.set(model, &step.active, &step.forces, released, time, coords);
        for (i, (p, k)) in step.active.iter().enumerate() {
            self.tangential[*p][*k] = step.tangential[i];
            self.sliding[*p][*k] = step.sliding[i];
        }
    }

    /// Sets the status: the active entries and their forces after a step ending at `time`.
    fn set(
        &mut self,
        model: &Model,
        active: &[(usize, usize)],
        forces: &[f64],
        released: bool,
        time: f64,
        coords: &[[f64; 2]],
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
        }
        if !active.is_empty() && self.first_contact_time.is_none() {
            self.first_contact_time = Some(time);
        }
        if released {
            self.last_release_time = Some(time);
        }
        let total: f64 = forces.iter().sum();
        self.peak_force = self.peak_force.max(total);
        let x = |n: usize| coords[n];
        for pair in &model.contacts {
            for s in &pair.slaves {
                if let Some(g) = pair.gap(*s, &x) {
                    self.min_gap = Some(self.min_gap.map_or(g.gap, |m| m.min(g.gap)));
                }
            }
        }
        self.peak_extent = self.peak_extent.max(extent(model, active, coords));
    }

    /// Explicit contact by forward-increment Lagrange multipliers (Carpenter, Taylor & Katona
    /// 1991) in the velocity-Verlet form of central difference: the predicted increment `du`
    /// (positions `start + du`) is corrected by delta = M^-1 C^T mu with (C M^-1 C^T) mu = -g
    /// over the penetrated entries, mu >= 0 (entries in tension leave, penetrations join, the
    /// rows are rebuilt at the corrected positions until the gaps close to TOL). The correction
    /// enters the half-step velocity as delta / h, a full step's impulse M delta / h, so the
    /// contact force of the step is mu / h^2. Returns the correction delta (all DOFs).
    pub fn explicit_step(
        &mut self,
        model: &Model,
        start: &[[f64; 2]],
        du: &[f64],
        inverse_mass: &[f64],
        h: f64,
        time: f64,
    ) -> Vec<f64> {
        let n = du.len();
        let mut delta = vec![0.0; n];
        let mut active: Vec<(usize, usize)> = Vec::new();
        // whether (p, k) is in `active`: keeps the bookkeeping linear in the slaves
        let mut in_active: Vec<Vec<bool>> = model
            .contacts
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
            let mut changed = false;
            for (p, pair) in model.contacts.iter().enumerate() {
                for (k, s) in pair.slaves.iter().enumerate() {
                    if in_active[p][k] {
                        continue;
                    }
                    if pair
                        .gap(*s, &x)
                        .is_some_and(|g| g.gap < -pair.options.tolerance)
                    {
                        active.push((p, k));
                        in_active[p][k] = true;
                        mu_total.push(0.0);
                        changed = true;
                    }
                }
            }
            let gaps: Vec<Gap> = active
                .iter()
                .map(|(p, k)| {
                    model.contacts[*p]
                        .gap(model.contacts[*p].slaves[*k], &x)
                        .expect("found above")
                })
                .collect();
            let worst = active
                .iter()
                .zip(&gaps)
                .map(|((p, _), g)| {
                    g.gap.abs() / model.contacts[*p].options.tolerance.max(f64::MIN_POSITIVE)
                })
                .fold(0.0, f64::max);
            if !changed && worst <= 1.0 {
                break;
            }
            let rows: Vec<Vec<(usize, f64)>> = active
                .iter()
                .zip(&gaps)
                .map(|((p, k), g)| g.row(model.contacts[*p].slaves[*k]))
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
        let forces: Vec<f64> = mu_total.iter().map(|mu| mu / (h * h)).collect();
        let released = self
            .active
            .iter()
            .zip(&in_active)
            .any(|(was, is)| was.iter().zip(is).any(|(was, is)| *was && !*is));
        let end: Vec<[f64; 2]> = (0..start.len())
            .map(|node| position(&delta, node))
            .collect();
        self.set(model, &active, &forces, released, time, &end);
        delta
    }

    /// The contact block of summary.json.
    pub fn summary(&self) -> super::ContactSummary {
        super::ContactSummary {
            first_contact_time: self.first_contact_time,
            last_release_time: self.last_release_time,
            peak_force: self.peak_force,
            peak_contact_radius: self.peak_extent,
            min_gap: self.min_gap,
        }
    }

    /// The deepest slave penetration beyond the pair's limit after a converged step, as a
    /// message naming the pair, the node, the gap and the limit (half the smallest spacing
    /// of the pair's slave nodes: a node that deep has passed its neighbours' master
    /// segments, the contact no longer holds).
    pub fn runaway_penetration(
        &self,
        model: &Model,
        coords: &[[f64; 2]],
        limits: &[f64],
    ) -> Option<String> {
        let x = |n: usize| coords[n];
        let mut worst: Option<(f64, usize, usize, f64)> = None;
        for (p, pair) in model.contacts.iter().enumerate() {
            for s in &pair.slaves {
                if let Some(g) = pair.gap(*s, &x)
                    && (g.gap < -limits[p] || !g.gap.is_finite())
                    && worst.is_none_or(|w| g.gap / limits[p] < w.0 / w.3)
                {
                    worst = Some((g.gap, p, *s, limits[p]));
                }
            }
        }
        worst.map(|(gap, p, node, limit)| {
            format!(
                "runaway penetration: contact `{}`, node {node}: gap = {gap:e} beyond -{limit:e} \
                 (half the slave node spacing)",
                model.contacts[p].name
            )
        })
    }

    /// Total normal force per pair.
    pub fn pair_forces(&self) -> Vec<f64> {
        self.force.iter().map(|f| f.iter().sum()).collect()
    }

    /// Total tangential (friction) force along t per pair.
    pub fn pair_tangential_forces(&self) -> Vec<f64> {
        self.tangential.iter().map(|f| f.iter().sum()).collect()
    }

    /// Nodal contact forces (all DOFs) at positions `coords`: +tau n on slaves, -w tau n on
    /// master nodes.
    pub fn nodal_forces(&self, model: &Model, coords: &[[f64; 2]]) -> Vec<f64> {
        let mut f = vec![0.0; 2 * coords.len()];
        let x = |n: usize| coords[n];
        for (p, pair) in model.contacts.iter().enumerate() {
            for (k, s) in pair.slaves.iter().enumerate() {
                if !self.active[p][k] {
                    continue;
                }
                let Some(gap) = pair.gap(*s, &x) else {
                    continue;
                };
                for (dof, c) in gap.row(*s) {
                    f[dof] += self.force[p][k] * c;
                }
                for (dof, c) in gap.tangent_row(*s) {
                    f[dof] += self.tangential[p][k] * c;
                }
            }
        }
        f
    }

    /// Per node: (gap, status) of slave nodes (status 1 active, 0 open), NaN-free zeros
    /// elsewhere.
    pub fn nodal_status(&self, model: &Model, coords: &[[f64; 2]]) -> (Vec<f64>, Vec<f64>) {
        let mut gap = vec![0.0; coords.len()];
        let mut status = vec![0.0; coords.len()];
        let x = |n: usize| coords[n];
        for (p, pair) in model.contacts.iter().enumerate() {
            for (k, s) in pair.slaves.iter().enumerate() {
                if let Some(g) = pair.gap(*s, &x) {
                    gap[*s] = g.gap;
                }
                status[*s] = if self.active[p][k] { 1.0 } else { 0.0 };
            }
        }
        (gap, status)
    }
}

/// Largest extent of the closed entries: the largest radius for axisymmetric slaves, else
/// the largest distance between two closed slaves of a pair.
fn extent(model: &Model, active: &[(usize, usize)], coords: &[[f64; 2]]) -> f64 {
    let mut best: f64 = 0.0;
    for (p, pair) in model.contacts.iter().enumerate() {
        let nodes: Vec<[f64; 2]> = active
            .iter()
            .filter(|(q, _)| *q == p)
            .map(|(_, k)| coords[pair.slaves[*k]])
            .collect();
        let axisymmetric = matches!(
            model.bodies[pair.slave_body].kind,
            BodyKind::Continuum {
                formulation: Formulation::Axisymmetric,
                ..
            }
        );
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

/// The impedance rho c A of node `node` of body `body` (A: its tributary contact area).
fn impedance(model: &Model, body: usize, node: usize, coords: &[[f64; 2]]) -> f64 {
    let b = &model.bodies[body];
    let m = &b.material;
    let e = &m.elastic;
    let (lambda, mu) = e.lame();
    let (modulus, area) = match b.kind {
        BodyKind::Rod { area } => (e.young, area),
        BodyKind::Continuum {
            formulation,
            thickness,
            ..
        } => {
            let local = node - b.node_offset;
            let half_edges: f64 = b.boundary_at_node[local]
                .iter()
                .map(|[p, q]| {
                    let (a, c) = (coords[b.global(*p)], coords[b.global(*q)]);
                    0.5 * ((a[0] - c[0]).powi(2) + (a[1] - c[1]).powi(2)).sqrt()
                })
                .sum();
            match formulation {
                Formulation::PlaneStrain => (lambda + 2.0 * mu, half_edges),
                Formulation::PlaneStress => (
                    e.young / (1.0 - e.poisson * e.poisson),
                    half_edges * thickness,
                ),
                Formulation::Axisymmetric => (
                    lambda + 2.0 * mu,
                    half_edges * 2.0 * PI * coords[node][0].max(0.0),
                ),
            }
        }
    };
    (modulus * m.density).sqrt() * area
}

fn normal_component(v: &[f64], node: usize, n: [f64; 2]) -> f64 {
    v[2 * node] * n[0] + v[2 * node + 1] * n[1]
}

fn add_normal(v: &mut [f64], node: usize, n: [f64; 2], amount: f64) {
    v[2 * node] += amount * n[0];
    v[2 * node + 1] += amount * n[1];
}

/// The master side of an entry: nodes with weights, their interpolated mass, impedance, and
/// normal velocity/acceleration; a rigid obstacle has none (infinite mass, at rest).
struct MasterSide {
    nodes: Vec<(usize, f64)>,
    mass: f64,
    impedance: f64,
}

fn master_side(
    model: &Model,
    pair: &ContactPair,
    gap: &Gap,
    lumped: &[f64],
    coords: &[[f64; 2]],
) -> Option<MasterSide> {
    let body = match &pair.master {
        Master::Obstacle(_) => return None,
        Master::Segments { body, .. } | Master::Nodes { body, .. } => *body,
    };
    let mass = gap.masters.iter().map(|(m, w)| w * lumped[2 * m]).sum();
    let impedance = gap
        .masters
        .iter()
        .map(|(m, w)| w * impedance(model, body, *m, coords))
        .sum();
    Some(MasterSide {
        nodes: gap.masters.clone(),
        mass,
        impedance,
    })
}

/// Spreads a change of the interpolated normal component over the master nodes so that the
/// interpolation sum w_i x_i changes by exactly `change`.
fn spread(v: &mut [f64], side: &MasterSide, n: [f64; 2], change: f64) {
    let w2: f64 = side.nodes.iter().map(|(_, w)| w * w).sum();
    if w2 > 0.0 {
        for (m, w) in &side.nodes {
            add_normal(v, *m, n, change * w / w2);
        }
    }
}

fn interpolated(v: &[f64], side: &MasterSide, n: [f64; 2]) -> f64 {
    side.nodes
        .iter()
        .map(|(m, w)| w * normal_component(v, *m, n))
        .sum()
}

/// The tangential counterpart of II-8 with friction: a change dv_n of the normal velocity
/// (positive: a push out of the master) comes with a change of the relative tangential
/// velocity v_t by -sign(v_t) mu dv_n, at most down to v_t = 0 (Coulomb: the impulse of the
/// condition obeys the friction law; a pull, which takes back part of the step's normal
/// impulse, gives back the friction that came with it), or by -R v_t (Greco's return: R = 0
/// keeps the tangential motion, R = 1 stops it). The give-back turns v_t towards its value
/// before the step and stops there. Momentum is shared by the lumped masses.
fn tangential_impact(
    pair: &ContactPair,
    s: usize,
    gap: &Gap,
    master: Option<&MasterSide>,
    lumped: &[f64],
    previous_velocity: &[f64],
    velocity: &mut [f64],
    normal_change: f64,
) {
    let t = gap.tangent();
    let vm = master.map_or(0.0, |m| interpolated(velocity, m, t));
    let relative = normal_component(velocity, s, t) - vm;
    let change = match pair.options.friction {
        Friction::None => return,
        Friction::Coulomb { mu } if normal_change > 0.0 => {
            -relative.signum() * relative.abs().min(mu * normal_change)
        }
        Friction::Coulomb { mu } => {
            // towards the tangential velocity before the step, and no further
            let before = normal_component(previous_velocity, s, t)
                - master.map_or(0.0, |m| interpolated(previous_velocity, m, t));
            let limit = -mu * normal_change;
            (before - relative).clamp(-limit, limit)
        }
        Friction::Return { r } => -r * relative,
    };
    let ms = lumped[2 * s];
    let share = master.map_or(1.0, |side| side.mass / (ms + side.mass));
    add_normal(velocity, s, t, share * change);
    if let Some(side) = master {
        spread(velocity, side, t, -(1.0 - share) * change);
    }
}

/// Hughes II-8 for one slave: the common normal velocity from the impedances and the
/// previous velocities, the common acceleration from the masses, and the force that keeps
/// the equations of motion.
#[allow(clippy::too_many_arguments)]
fn impact(
    model: &Model,
    pair: &ContactPair,
    s: usize,
    gap: &Gap,
    coords: &[[f64; 2]],
    lumped: &[f64],
    previous_velocity: &[f64],
    velocity: &mut [f64],
    acceleration: &mut [f64],
    force: &mut f64,
) {
    let n = gap.normal;
    let (ms, zs) = (lumped[2 * s], impedance(model, pair.slave_body, s, coords));
    let (vs_prev, as_now) = (
        normal_component(previous_velocity, s, n),
        normal_component(acceleration, s, n),
    );
    let master = master_side(model, pair, gap, lumped, coords);
    let (v_plus, a_plus) = match &master {
        None => (0.0, 0.0),
        Some(side) => {
            let vm_prev = interpolated(previous_velocity, side, n);
            let am_now = interpolated(acceleration, side, n);
            (
                (zs * vs_prev + side.impedance * vm_prev) / (zs + side.impedance),
                (ms * as_now + side.mass * am_now) / (ms + side.mass),
            )
        }
    };
    // II-8's force; were it a pull, the pair's accelerations only lose the present force
    // (the multiplier stays compressive and the equations of motion hold with it)
    let tau_plus = *force + ms * (a_plus - as_now);
    let (a_plus, master_acceleration) = if tau_plus >= 0.0 {
        (a_plus, None)
    } else {
        let released = *force;
        (
            as_now - released / ms,
            master.as_ref().map(|side| {
                interpolated(acceleration, side, n) + released / side.mass.max(f64::MIN_POSITIVE)
            }),
        )
    };
    *force = tau_plus.max(0.0);
    let normal_change = v_plus - normal_component(velocity, s, n);
    tangential_impact(
        pair,
        s,
        gap,
        master.as_ref(),
        lumped,
        previous_velocity,
        velocity,
        normal_change,
    );
    add_normal(velocity, s, n, v_plus - normal_component(velocity, s, n));
    add_normal(acceleration, s, n, a_plus - as_now);
    if let Some(side) = &master {
        let vm = interpolated(velocity, side, n);
        let am = interpolated(acceleration, side, n);
        spread(velocity, side, n, v_plus - vm);
        spread(
            acceleration,
            side,
            n,
            master_acceleration.unwrap_or(a_plus) - am,
        );
    }
}

/// Hughes II-8 for the entries that closed and II-11, II-12 for those released by the
/// fraction rule: corrects `velocity` and `acceleration` (all DOFs) in place, and the forces
/// of closed entries. `previous_velocity` is the velocity at the start of the step.
#[allow(clippy::too_many_arguments)]
pub fn apply_conditions(
    model: &Model,
    step: &mut ContactStep,
    coords: &[[f64; 2]],
    lumped: &[f64],
    previous_velocity: &[f64],
    velocity: &mut [f64],
    acceleration: &mut [f64],
) {
    let x = |n: usize| coords[n];
    for &(p, k) in &step.events.closed {
        let pair = &model.contacts[p];
        if !pair.options.impact_conditions {
            continue;
        }
        let s = pair.slaves[k];
        let Some(gap) = pair.gap(s, &x) else { continue };
        let i = step
            .active
            .iter()
            .position(|e| *e == (p, k))
            .expect("closed entries are active");
        impact(
            model,
            pair,
            s,
            &gap,
            coords,
            lumped,
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
            add_normal(acceleration, s, t, change / lumped[2 * s]);
            if let Some(side) = master_side(model, pair, &gap, lumped, coords)
                && side.mass > 0.0
            {
                spread(acceleration, &side, t, -change / side.mass);
            }
        }
    }
    for &(p, k, tau, friction) in &step.events.released {
        let pair = &model.contacts[p];
        if !pair.options.release_conditions {
            continue;
        }
        let s = pair.slaves[k];
        let Some(gap) = pair.gap(s, &x) else { continue };
        let n = gap.normal;
        let (ms, zs) = (lumped[2 * s], impedance(model, pair.slave_body, s, coords));
        add_normal(velocity, s, n, tau / zs);
        add_normal(acceleration, s, n, -tau / ms);
        // the friction force goes with the normal one (its acceleration, as in II-12)
        let t = gap.tangent();
        add_normal(acceleration, s, t, -friction / ms);
        if let Some(side) = master_side(model, pair, &gap, lumped, coords) {
            spread(velocity, &side, n, -tau / side.impedance);
            spread(acceleration, &side, n, tau / side.mass);
            spread(acceleration, &side, t, friction / side.mass);
        }
    }
}
