//! The impact and release conditions of a step's events (Hughes II-8, II-11, II-12; theory
//! 8.3, 8.3a): the closure of touching slaves at the start of a step, and the conditions of
//! the entries that closed or were released in it (`conditions` holds the formulas).

use super::Interfaces;
use super::conditions;
use super::geometry::{ContactPair, Friction};
use super::search::{SlaveGap, slave_gaps};
use super::status::ContactState;
use super::step::ContactResult;

impl ContactState {
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
            gap,
            ..
        } in touching
        {
            let pair = &interfaces.pairs[p];
            let entry = conditions::Entry::new(interfaces, (p, k), gap, (coords, lumped));
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
            let impulses = conditions::impact_together(
                &rows,
                inverse_mass,
                velocity,
                acceleration,
                &mut forces,
            );
            stick_joint(
                interfaces,
                (&entries, &impulses),
                &x,
                inverse_mass,
                velocity,
            );
            for ((p, k), f) in entries.iter().zip(forces) {
                let followed = Followed {
                    force: f,
                    sliding: self.sliding[*p][*k],
                    tangential: &mut self.tangential[*p][*k],
                };
                follow_along_row(
                    &interfaces.pairs[*p],
                    *k,
                    followed,
                    &x,
                    (inverse_mass, acceleration),
                );
                self.force[*p][*k] = f;
            }
        }
        closed
    }
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
    let impulses =
        conditions::impact_together(&rows, inverse_mass, velocity, acceleration, &mut forces);
    stick_joint(interfaces, (&pairs, &impulses), &x, inverse_mass, velocity);
    for (i, f) in entries.iter().zip(forces) {
        let (p, k) = step.active[*i];
        let followed = Followed {
            force: f,
            sliding: step.sliding[*i],
            tangential: &mut step.tangential[*i],
        };
        follow_along_row(
            &interfaces.pairs[p],
            k,
            followed,
            &x,
            (inverse_mass, acceleration),
        );
        step.forces[*i] = f;
    }
}

/// An entry's friction force after II-8 corrected its normal force to `force`: a sliding
/// entry's (signed coefficient `sliding`) stays mu tau, a sticking one's is held within the
/// cone. Without it the step's friction force stays that of the uncorrected normal force,
/// and the accelerations the next step starts from carry a friction beyond Coulomb's cone
/// (the block on the plate under Newmark: a pair's totals up to T = 23 mu N, and a slide
/// that slowed more the shorter the step).
struct Followed<'a> {
    force: f64,
    sliding: f64,
    tangential: &'a mut f64,
}

impl Followed<'_> {
    /// Sets the followed friction force under Coulomb's `mu`; returns its change.
    fn follow(self, mu: f64) -> f64 {
        let old = *self.tangential;
        let limit = mu * self.force;
        *self.tangential = if self.sliding != 0.0 {
            self.sliding * self.force
        } else {
            old.clamp(-limit, limit)
        };
        *self.tangential - old
    }
}

/// [`Followed`] on slave `k` of a mortar pair, its change acting on the accelerations
/// along the tangential row T (a <- a + M^-1 T^T change), the friction force's own row.
fn follow_along_row(
    pair: &ContactPair,
    k: usize,
    followed: Followed,
    x: &dyn Fn(usize) -> [f64; 2],
    (inverse_mass, acceleration): (&[f64], &mut [f64]),
) {
    let Friction::Coulomb { mu } = pair.options.friction else {
        return;
    };
    let change = followed.follow(mu);
    if change == 0.0 {
        return;
    }
    let s = pair.slaves[k];
    if let Some(gap) = pair.gap(s, x) {
        for (d, c) in gap.tangent_row(s) {
            acceleration[d] += inverse_mass[d] * c * change;
        }
    }
}

/// The tangential part of the joint impact conditions (`conditions::stick_together`) on the
/// entries `pairs` of pairs with Coulomb friction, whose normal impulses were `impulses`.
fn stick_joint(
    interfaces: &Interfaces,
    (entries, impulses): (&[(usize, usize)], &[f64]),
    x: &dyn Fn(usize) -> [f64; 2],
    inverse_mass: &[f64],
    velocity: &mut [f64],
) {
    let mut rows = Vec::new();
    let mut limits = Vec::new();
    for ((p, k), impulse) in entries.iter().zip(impulses) {
        let pair = &interfaces.pairs[*p];
        let Friction::Coulomb { mu } = pair.options.friction else {
            continue;
        };
        let s = pair.slaves[*k];
        if let Some(gap) = pair.gap(s, x) {
            rows.push(gap.tangent_row(s));
            limits.push(mu * impulse);
        }
    }
    if !rows.is_empty() {
        conditions::stick_together(&rows, &limits, inverse_mass, velocity);
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
    for &(p, k) in &step.events.closed {
        let pair = &interfaces.pairs[p];
        if !pair.options.impact_conditions || pair.joint_conditions() {
            continue;
        }
        let Some(entry) = conditions::Entry::at(interfaces, (p, k), (coords, lumped)) else {
            continue;
        };
        let (s, gap) = (entry.slave, &entry.gap);
        let i = step
            .active
            .iter()
            .position(|e| *e == (p, k))
            .expect("closed entries are active");
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
            let followed = Followed {
                force: step.forces[i],
                sliding: step.sliding[i],
                tangential: &mut step.tangential[i],
            };
            let change = followed.follow(mu);
            let t = gap.tangent();
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
    for &(p, k, tau, friction) in &step.events.released {
        let pair = &interfaces.pairs[p];
        if !pair.options.release_conditions {
            continue;
        }
        let Some(entry) = conditions::Entry::at(interfaces, (p, k), (coords, lumped)) else {
            continue;
        };
        let (s, gap) = (entry.slave, &entry.gap);
        let n = gap.normal;
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
