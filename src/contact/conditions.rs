//! Hughes' impact conditions (II-8) for the entries that close and release conditions
//! (II-11, II-12) for those released by the fraction rule, with their tangential
//! counterparts under friction.
//!
//! Legend (per entry: a slave node of a pair)
//! ```text
//! tau          compressive normal force (Lagrange multiplier)
//! Z            rho c A: the normal impedance of a node (c the dilatational wave speed,
//!              A its tributary contact area)
//! M            the node's lumped mass
//! v_n, a_n     normal components of velocity and acceleration, n out of the master
//! V+ = (Z_s v_s,n-1 + Z_m v_m,n-1) / (Z_s + Z_m)       velocities of the previous step
//! a+ = (M_s a_s + M_m a_m) / (M_s + M_m),  tau+ = tau + M_s (a+ - a_s)
//! v_s,n += tau / Z_s,  v_m,n -= tau / Z_m,  a_s,n -= tau / M_s,  a_m,n += tau / M_m
//! ```
//! A rigid obstacle is a master of infinite mass and impedance, at rest or moving with the
//! velocity its prescribed motion has at the conditions' time (its acceleration taken as
//! zero: the motion's curve is piecewise linear).

use super::Interfaces;
use super::geometry::{ContactPair, Friction, Gap, Master};

pub(super) fn normal_component(v: &[f64], node: usize, n: [f64; 2]) -> f64 {
    v[2 * node] * n[0] + v[2 * node + 1] * n[1]
}

pub(super) fn add_normal(v: &mut [f64], node: usize, n: [f64; 2], amount: f64) {
    v[2 * node] += amount * n[0];
    v[2 * node + 1] += amount * n[1];
}

/// The master side of an entry: nodes with weights, their interpolated mass, impedance, and
/// normal velocity/acceleration; a rigid obstacle has none (infinite mass, at rest).
pub(super) struct MasterSide {
    pub nodes: Vec<(usize, f64)>,
    pub mass: f64,
    pub impedance: f64,
}

/// One entry at a configuration: what its conditions read.
pub(super) struct Entry<'a> {
    pub interfaces: &'a Interfaces,
    pub pair: &'a ContactPair,
    /// The slave's global node, and its gap to the master at `coords`.
    pub slave: usize,
    pub gap: Gap,
    pub coords: &'a [[f64; 2]],
    /// The lumped mass per DOF.
    pub lumped: &'a [f64],
}

impl<'a> Entry<'a> {
    /// Entry `k` of pair `p` of `interfaces` at the positions `coords` (`lumped`: the mass
    /// per DOF), its slave's gap `gap`.
    pub fn new(
        interfaces: &'a Interfaces,
        (p, k): (usize, usize),
        gap: Gap,
        (coords, lumped): (&'a [[f64; 2]], &'a [f64]),
    ) -> Entry<'a> {
        let pair = &interfaces.pairs[p];
        Entry {
            interfaces,
            pair,
            slave: pair.slaves[k],
            gap,
            coords,
            lumped,
        }
    }

    /// [`Entry::new`] with the slave's gap found at `coords`; None when no master is within
    /// reach.
    pub fn at(
        interfaces: &'a Interfaces,
        (p, k): (usize, usize),
        (coords, lumped): (&'a [[f64; 2]], &'a [f64]),
    ) -> Option<Entry<'a>> {
        let pair = &interfaces.pairs[p];
        let gap = pair.gap(pair.slaves[k], &|n: usize| coords[n])?;
        Some(Entry::new(interfaces, (p, k), gap, (coords, lumped)))
    }

    /// The master side of the entry; None on a rigid obstacle.
    pub fn master(&self) -> Option<MasterSide> {
        let body = match &self.pair.master {
            Master::Obstacle(_) => return None,
            Master::Segments { body, .. } | Master::Nodes { body, .. } => *body,
        };
        let gap = &self.gap;
        let mass = gap
            .masters
            .iter()
            .map(|(m, w)| w * self.lumped[2 * m])
            .sum();
        let impedance = gap
            .masters
            .iter()
            .map(|(m, w)| w * self.interfaces.impedance(body, *m, self.coords))
            .sum();
        Some(MasterSide {
            nodes: gap.masters.clone(),
            mass,
            impedance,
        })
    }

    /// The component along `direction` of the velocity of the entry's obstacle (zero for a
    /// master that is a body, or an obstacle at rest).
    pub fn obstacle_velocity(&self, direction: [f64; 2]) -> f64 {
        let w = self.pair.obstacle_velocity();
        w[0] * direction[0] + w[1] * direction[1]
    }

    /// The slave's lumped mass and impedance.
    pub fn slave_mass_and_impedance(&self) -> (f64, f64) {
        let s = self.slave;
        (
            self.lumped[2 * s],
            self.interfaces
                .impedance(self.pair.slave_body, s, self.coords),
        )
    }
}

/// Whether a touching slave approaches its master: the normal velocity relative to the
/// master's interpolated one is negative.
pub(super) fn approaching(entry: &Entry, velocity: &[f64]) -> bool {
    let n = entry.gap.normal;
    let master = entry.master();
    let vm = master
        .as_ref()
        .map_or(entry.obstacle_velocity(n), |m| interpolated(velocity, m, n));
    normal_component(velocity, entry.slave, n) - vm < 0.0
}

/// Spreads a change of the interpolated normal component over the master nodes so that the
/// interpolation sum w_i x_i changes by exactly `change`.
pub(super) fn spread(v: &mut [f64], side: &MasterSide, n: [f64; 2], change: f64) {
    let w2: f64 = side.nodes.iter().map(|(_, w)| w * w).sum();
    if w2 > 0.0 {
        for (m, w) in &side.nodes {
            add_normal(v, *m, n, change * w / w2);
        }
    }
}

pub(super) fn interpolated(v: &[f64], side: &MasterSide, n: [f64; 2]) -> f64 {
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
    entry: &Entry,
    master: Option<&MasterSide>,
    previous_velocity: &[f64],
    velocity: &mut [f64],
    normal_change: f64,
) {
    let (pair, s, lumped) = (entry.pair, entry.slave, entry.lumped);
    let t = entry.gap.tangent();
    let obstacle = entry.obstacle_velocity(t);
    let vm = master.map_or(obstacle, |m| interpolated(velocity, m, t));
    let relative = normal_component(velocity, s, t) - vm;
    let change = match pair.options.friction {
        Friction::None => return,
        Friction::Coulomb { mu } if normal_change > 0.0 => {
            -relative.signum() * relative.abs().min(mu * normal_change)
        }
        Friction::Coulomb { mu } => {
            // towards the tangential velocity before the step, and no further
            let before = normal_component(previous_velocity, s, t)
                - master.map_or(obstacle, |m| interpolated(previous_velocity, m, t));
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
pub(super) fn impact(
    entry: &Entry,
    previous_velocity: &[f64],
    velocity: &mut [f64],
    acceleration: &mut [f64],
    force: &mut f64,
) {
    let (s, n) = (entry.slave, entry.gap.normal);
    let (ms, zs) = entry.slave_mass_and_impedance();
    let (vs_prev, as_now) = (
        normal_component(previous_velocity, s, n),
        normal_component(acceleration, s, n),
    );
    let master = entry.master();
    let (v_plus, a_plus) = match &master {
        None => (entry.obstacle_velocity(n), 0.0),
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
        entry,
        master.as_ref(),
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

/// Hughes II-8 for the active rows `rows` of a mortar pair together, `forces` their
/// multipliers: the velocities and accelerations are made compatible on every row at once,
/// C v = 0 and C a = 0, by the multipliers of the lumped mass,
/// ```text
/// (C M^-1 C^T) mu = -C v,   v += M^-1 C^T mu
/// ```
/// (and the same for a, whose mu is added to the forces). A row shares master nodes with its
/// neighbours, so one slave's condition at a time would undo the last one's; together they
/// take no momentum from the pair (each row's weights sum to zero), and the kinetic energy
/// they take is that of the relative normal motion. A row whose force would turn to a pull
/// only loses its present force and is left out of the accelerations' condition.
pub(super) fn impact_together(
    rows: &[Vec<(usize, f64)>],
    inverse_mass: &[f64],
    velocity: &mut [f64],
    acceleration: &mut [f64],
    forces: &mut [f64],
) -> Vec<f64> {
    let along =
        |row: &[(usize, f64)], v: &[f64]| -> f64 { row.iter().map(|(d, c)| c * v[*d]).sum() };
    let push = |v: &mut [f64], row: &[(usize, f64)], mu: f64| {
        for (d, c) in row {
            v[*d] += inverse_mass[*d] * c * mu;
        }
    };
    let rates: Vec<f64> = rows.iter().map(|r| along(r, velocity)).collect();
    let impulses = super::multipliers::lumped_multipliers(rows, &rates, inverse_mass);
    for (row, m) in rows.iter().zip(&impulses) {
        push(velocity, row, *m);
    }
    let mut kept: Vec<usize> = (0..rows.len()).collect();
    loop {
        let subset: Vec<Vec<(usize, f64)>> = kept.iter().map(|i| rows[*i].clone()).collect();
        let rates: Vec<f64> = subset.iter().map(|r| along(r, acceleration)).collect();
        let mu = super::multipliers::lumped_multipliers(&subset, &rates, inverse_mass);
        let worst = (0..kept.len())
            .filter(|a| forces[kept[*a]] + mu[*a] < 0.0)
            .min_by(|a, b| (forces[kept[*a]] + mu[*a]).total_cmp(&(forces[kept[*b]] + mu[*b])));
        if let Some(a) = worst {
            let i = kept.remove(a);
            push(acceleration, &rows[i], -forces[i]);
            forces[i] = 0.0;
            continue;
        }
        for (a, i) in kept.iter().enumerate() {
            push(acceleration, &rows[*i], mu[a]);
            forces[*i] += mu[a];
        }
        break;
    }
    impulses
}

/// The tangential part of (8.3a-1) under Coulomb friction: the relative tangential
/// velocities of the rows `tangential` stopped together by impulses on the lumped mass,
/// (T M^-1 T^T) mu_t = -T v, each within the cone of its row's normal impulse,
/// |mu_t| <= `limits` (mu times the normal impulse of the closure), then v <- v + M^-1 T^T mu_t.
/// A sticking entry starts its contact with the relative tangential velocity it is held at
/// (the stick rows hold it at zero), and a sliding one loses what the cone allows. Rows
/// that move no free DOF are left to their supports.
pub(super) fn stick_together(
    tangential: &[Vec<(usize, f64)>],
    limits: &[f64],
    inverse_mass: &[f64],
    velocity: &mut [f64],
) {
    let rates: Vec<f64> = tangential
        .iter()
        .map(|r| r.iter().map(|(d, c)| c * velocity[*d]).sum())
        .collect();
    let impulses = super::multipliers::lumped_multipliers(tangential, &rates, inverse_mass);
    for ((row, mu), limit) in tangential.iter().zip(&impulses).zip(limits) {
        let mu = mu.clamp(-limit.max(0.0), limit.max(0.0));
        for (d, c) in row {
            velocity[*d] += inverse_mass[*d] * c * mu;
        }
    }
}

/// The rows of a released mortar entry: the normal row C and the tangential row T.
pub(super) struct Released {
    pub normal: Vec<(usize, f64)>,
    pub tangential: Vec<(usize, f64)>,
}

/// Hughes II-11, II-12 for an entry of a mortar pair released by the fraction rule: the
/// forces it carried (`tau` along C, `friction` along T) leave the accelerations, and the
/// relative normal velocity jumps by II-11's `tau (1 / Z_s + 1 / Z_m)` (`compliance` the
/// bracket) through an impulse along the row,
/// ```text
/// a <- a - M^-1 (C^T tau + T^T friction),   v <- v + M^-1 C^T mu,   (C M^-1 C^T) mu = tau compliance
/// ```
/// Both are equal and opposite on the two surfaces (the row's weights sum to zero), where
/// II-11's jumps of the slave and of the master point, spread over master nodes that other
/// rows share, are not.
pub(super) fn release_along(
    rows: &Released,
    inverse_mass: &[f64],
    (velocity, acceleration): (&mut [f64], &mut [f64]),
    (tau, friction, compliance): (f64, f64, f64),
) {
    let stiffness: f64 = rows
        .normal
        .iter()
        .map(|(d, c)| c * c * inverse_mass[*d])
        .sum();
    let mu = if stiffness > 0.0 {
        tau * compliance / stiffness
    } else {
        0.0
    };
    for (d, c) in &rows.normal {
        velocity[*d] += inverse_mass[*d] * c * mu;
        acceleration[*d] -= inverse_mass[*d] * c * tau;
    }
    for (d, c) in &rows.tangential {
        acceleration[*d] -= inverse_mass[*d] * c * friction;
    }
}
