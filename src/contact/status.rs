//! The contact status carried from step to step: the active entries and their forces, the
//! run's contact figures (first contact, last release, peak force, penetration), and what
//! the frames and the history read of it (nodal forces, gaps, pair totals).

use super::geometry::ContactPair;
use super::search::slave_gaps;
use super::{ContactSummary, Interfaces, Section};

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
    /// Per pair: the energy its normal rows took from the bodies so far (history.csv
    /// `contact_work[pair]`, the pair's share of `contact_work`; dynamic runs; empty in a
    /// checkpoint written before it was kept).
    #[serde(default)]
    pub work: Vec<f64>,
    /// Per pair: the energy its friction dissipated so far (`friction_work[pair]`).
    #[serde(default)]
    pub friction_work: Vec<f64>,
    /// Per projectile (`Projectile::index`), where it is and how fast it moves (empty
    /// without projectiles; the explicit driver keeps it).
    #[serde(default)]
    pub flights: Vec<super::Flight>,
    /// The explicit correction's vectors over all DOFs, kept zero between steps, so that a
    /// step neither allocates nor clears them whole (`contact::explicit`; not in a
    /// checkpoint: zero vectors of the right length either way).
    #[serde(skip)]
    pub(super) scratch: Scratch,
    /// The last resort of an implicit step whose active set did not settle at any length
    /// the cuts tried: an entry that cycles between tension and penetration stays open
    /// (`ContactState::step`); set by the driver for that step's last attempt only.
    #[serde(skip)]
    pub accept_cycles: bool,
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
            work: vec![0.0; pairs.len()],
            friction_work: vec![0.0; pairs.len()],
            flights: Vec::new(),
            scratch: Scratch::default(),
            accept_cycles: false,
        }
    }

    /// Closes the open slaves of `pairs` that rest on their master at positions `x` (|g| <=
    /// `band` TOL: 1 for those that touch), with no force yet; how many. A static body held
    /// by its contact alone (a load pressing it onto its support) is otherwise a free body in
    /// its first solve, whose rigid motion nothing holds (docs/theory.md 5c).
    pub fn close_resting(
        &mut self,
        pairs: &[ContactPair],
        x: &dyn Fn(usize) -> [f64; 2],
        band: f64,
    ) -> usize {
        let active = &self.active;
        let open = |p: usize, k: usize| active[p][k];
        let touching: Vec<(usize, usize)> = slave_gaps(pairs, x, &open)
            .filter(|s| {
                let pair = &pairs[s.pair];
                s.gap.gap.abs() <= band * pair.options.tolerance
                    && !pair.covers(pairs, &s.gap, x, &open)
            })
            .map(|s| (s.pair, s.index))
            .collect();
        for &(p, k) in &touching {
            self.active[p][k] = true;
            self.force[p][k] = 0.0;
        }
        touching.len()
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
        penetration = penetration.max(super::penetration::deepest_depth(interfaces, x));
        self.penetration = penetration;
        self.max_penetration = self.max_penetration.max(penetration);
        self.peak_extent = self.peak_extent.max(extent(interfaces, active, x));
    }
}

impl ContactState {
    /// The contact block of summary.json for the run's `pairs`.
    pub fn summary(&self, pairs: &[ContactPair]) -> ContactSummary {
        // a second pass closes nothing where its first pass holds the contact: the two
        // passes are one contact; a balanced pair (its reverse pass folded into it, as
        // everywhere it is reported) closed where either of its passes did
        let ever = |q: usize| self.ever_closed.get(q).copied().unwrap_or(true);
        let closed = |p: usize| {
            let first = pairs[p].covered.as_ref().map(|c| c.pair);
            let reverse = pairs.iter().position(|q| q.balances == Some(p));
            [Some(p), first, reverse].into_iter().flatten().any(ever)
        };
        ContactSummary {
            never_closed: (0..pairs.len().min(self.ever_closed.len()))
                .filter(|p| pairs[*p].balances.is_none() && !closed(*p))
                .map(|p| pairs[p].name.clone())
                .collect(),
            first_contact_time: self.first_contact_time,
            last_release_time: self.last_release_time,
            peak_force: self.peak_force,
            peak_contact_radius: self.peak_extent,
            min_gap: self.min_gap,
            max_penetration: self.min_gap.map(|_| self.max_penetration),
            pairs: self.pair_energies(pairs),
            ..ContactSummary::default()
        }
    }

    /// Each reported pair's energies (a balanced pair's two passes as one).
    pub fn pair_energies(&self, pairs: &[ContactPair]) -> Vec<super::PairEnergies> {
        let folded = |values: &[f64]| {
            let mut values = values.to_vec();
            values.resize(pairs.len(), 0.0);
            super::fold_passes(pairs, &values)
        };
        let (work, friction) = (folded(&self.work), folded(&self.friction_work));
        let reported = pairs.iter().filter(|p| p.balances.is_none());
        (reported.zip(work).zip(friction))
            .map(
                |((pair, contact_work), friction_work)| super::PairEnergies {
                    name: pair.name.clone(),
                    contact_work,
                    friction_work,
                },
            )
            .collect()
    }

    /// Total normal force per pair (the slave entries' and the master block's).
    pub fn pair_forces(&self) -> Vec<f64> {
        let mut totals: Vec<f64> = self.force.iter().map(|f| f.iter().sum()).collect();
        for entry in &self.master_block {
            totals[entry.pair] += entry.force;
        }
        totals
    }

    /// The friction forces alone (all DOFs) at positions `coords`: +f t on the slaves, -w f t
    /// on their master nodes (None: no pair has Coulomb friction).
    pub fn friction_forces(&self, pairs: &[ContactPair], coords: &[[f64; 2]]) -> Option<Vec<f64>> {
        if !(pairs.iter()).any(|p| matches!(p.options.friction, super::Friction::Coulomb { .. })) {
            return None;
        }
        let none: Vec<Vec<f64>> = self.force.iter().map(|f| vec![0.0; f.len()]).collect();
        Some(self.nodal_forces_of(pairs, coords, &none, &self.tangential))
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
            let gap = pair.master_node_gap(entry.node, super::mortar::MASTER_ALLOWANCE, &x);
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
        let mut f = vec![0.0; 2 * coords.len()];
        let terms = self.pair_force_terms(pairs, coords, (normal, tangential));
        for (dof, value) in terms.iter().flatten() {
            f[*dof] += value;
        }
        f
    }

    /// Per pair, the terms (DOF, value) of the nodal forces of the rows `normal` and
    /// `tangential` (per pair, per slave) of the active entries at positions `coords`, in
    /// slave order (their sum in pair order is `nodal_forces_of`).
    pub(super) fn pair_force_terms(
        &self,
        pairs: &[ContactPair],
        coords: &[[f64; 2]],
        (normal, tangential): (&[Vec<f64>], &[Vec<f64>]),
    ) -> Vec<Vec<(usize, f64)>> {
        let x = |n: usize| coords[n];
        let mut terms = vec![Vec::new(); pairs.len()];
        for s in slave_gaps(pairs, &x, &|p, k| !self.active[p][k]) {
            let (p, k) = (s.pair, s.index);
            let normal = s
                .gap
                .row(s.node)
                .into_iter()
                .map(|(d, c)| (d, normal[p][k] * c));
            terms[p].extend(normal);
            if tangential[p][k] != 0.0 {
                let tangent = s.gap.tangent_row(s.node).into_iter();
                terms[p].extend(tangent.map(|(d, c)| (d, tangential[p][k] * c)));
            }
        }
        terms
    }

    /// The force the bodies exert on pair `p`'s master through its closed rows at the
    /// positions `coords`: minus the sum of the rows' forces on the slaves (the master of an
    /// obstacle: its reaction).
    pub fn master_force(&self, pairs: &[ContactPair], p: usize, coords: &[[f64; 2]]) -> [f64; 2] {
        let rows = (&self.force[..], &self.tangential[..]);
        let terms = self.pair_force_terms(pairs, coords, rows);
        let mut force = [0.0; 2];
        for (dof, value) in &terms[p] {
            force[dof % 2] -= value;
        }
        force
    }

    /// Per pair, the work `tangential`'s forces do on the increment `increment(dof)` relative
    /// to the master, the rows at positions `coords`: lambda (T du - carried) over the pair's
    /// active entries, `carried(pair, row)` the slip a moving obstacle's own motion carries
    /// along the row (0 otherwise): what the forces of `pair_force_terms`' tangential rows
    /// dissipate.
    pub(super) fn tangential_work(
        &self,
        pairs: &[ContactPair],
        coords: &[[f64; 2]],
        tangential: &[Vec<f64>],
        (increment, carried): (
            &dyn Fn(usize) -> f64,
            &dyn Fn(usize, &[(usize, f64)]) -> f64,
        ),
    ) -> Vec<f64> {
        let x = |n: usize| coords[n];
        let mut work = vec![0.0; pairs.len()];
        let skip = |p: usize, k: usize| !self.active[p][k] || tangential[p][k] == 0.0;
        for s in slave_gaps(pairs, &x, &skip) {
            let row = s.gap.tangent_row(s.node);
            let slip: f64 =
                row.iter().map(|(d, c)| c * increment(*d)).sum::<f64>() - carried(s.pair, &row);
            work[s.pair] += tangential[s.pair][s.index] * slip;
        }
        work
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
