//! The explicit driver's nodal vector loops: the predictor, the end of a step (a, v, F and the
//! step's sums), the configuration's move, in parallel over fixed chunks of `DOF_CHUNK` DOFs
//! whose partial sums add in chunk order (the bits do not depend on the thread count).

use crate::assembly::State;
use crate::element::Strain;
use rayon::prelude::*;

/// Moves the configuration of an explicit step (whose element state is already updated) by
/// du: the displacements, and at finite strain the positions (at small strain they stay the
/// initial ones).
pub(super) fn commit_kernel_step(state: &mut State, du: &[f64], geometry: Strain) {
    let (coordinates, displacement) = StateMotion::of(state, geometry).chunks();
    coordinates
        .into_par_iter()
        .zip(displacement)
        .zip(du.par_chunks(DOF_CHUNK))
        .with_min_len(CHUNKS_PER_TASK)
        .for_each(|((x, u), du)| move_by(x, u, du));
}

/// The arrays a step's du moves: the displacements, and the positions at finite strain.
pub(super) struct StateMotion<'a> {
    pub(super) coordinates: Option<&'a mut [[f64; 2]]>,
    pub(super) displacement: &'a mut [f64],
}

impl<'a> StateMotion<'a> {
    pub(super) fn of(state: &'a mut State, geometry: Strain) -> StateMotion<'a> {
        StateMotion {
            coordinates: (geometry == Strain::Finite).then_some(&mut state.coordinates[..]),
            displacement: &mut state.displacement,
        }
    }

    /// Per `DOF_CHUNK` DOFs: the positions (empty at small strain) and the displacements.
    fn chunks(self) -> (Vec<&'a mut [[f64; 2]]>, Vec<&'a mut [f64]>) {
        let displacement: Vec<&mut [f64]> = self.displacement.chunks_mut(DOF_CHUNK).collect();
        let coordinates = match self.coordinates {
            Some(x) => x.chunks_mut(DOF_CHUNK / 2).collect(),
            None => displacement
                .iter()
                .map(|_| <&mut [[f64; 2]]>::default())
                .collect(),
        };
        (coordinates, displacement)
    }
}

/// x += du and u += du over one chunk (`x` empty: the positions stay).
#[inline(always)]
pub(super) fn move_by(x: &mut [[f64; 2]], u: &mut [f64], du: &[f64]) {
    for (x, d) in x.iter_mut().zip(du.chunks_exact(2)) {
        x[0] += d[0];
        x[1] += d[1];
    }
    for (u, d) in u.iter_mut().zip(du) {
        *u += d;
    }
}

/// DOFs per chunk of the driver's vector loops: they run in parallel over fixed chunks and
/// their sums add the chunks' partial sums in chunk order, so the results are the same bits
/// for any number of threads.
pub(super) const DOF_CHUNK: usize = 1024;

/// The fewest chunks of `DOF_CHUNK` a task of the driver's vector loops takes. One: a model
/// on the pool (1000 elements or more, `analysis::parallel_from`) shares even its few chunks.
/// The loops alone hardly gain (a chunk's arrays may sit in the other core's cache), but the
/// other thread stays awake for the element loop and the end of the step runs on both cores:
/// the aluminium rod (5082 DOFs) on two threads ran 6 % faster than with tasks of 4 chunks of
/// 4096, which kept it on the stepping thread (docs/performance.md).
const CHUNKS_PER_TASK: usize = 1;

/// The predictor: v_{n+1/2} = v_n + h/2 a_n, du = h v_{n+1/2}.
pub(super) fn predict(v: &[f64], a: &[f64], h: f64, v_half: &mut [f64], du: &mut [f64]) {
    (
        v_half.par_chunks_mut(DOF_CHUNK),
        du.par_chunks_mut(DOF_CHUNK),
    )
        .into_par_iter()
        .zip((v.par_chunks(DOF_CHUNK), a.par_chunks(DOF_CHUNK)))
        .with_min_len(CHUNKS_PER_TASK)
        .for_each(|((v_half, du), (v, a))| {
            for (((vh, d), v), a) in v_half.iter_mut().zip(du).zip(v).zip(a) {
                *vh = v + 0.5 * h * a;
                *d = h * *vh;
            }
        });
}

/// sum_i term(x_i, y_i) over the DOFs `dofs` (ascending) outside which every term is zero:
/// the partial sums of the `DOF_CHUNK` chunks added in chunk order, the bits of the sum over
/// all DOFs for any number of threads.
pub(super) fn chunked_sum(
    dofs: &[usize],
    x: &[f64],
    y: &[f64],
    term: impl Fn(f64, f64) -> f64,
) -> f64 {
    let partial = |dofs: &[usize]| dofs.iter().map(|i| term(x[*i], y[*i])).sum::<f64>();
    if x.len() <= DOF_CHUNK {
        return partial(dofs);
    }
    dofs.chunk_by(|a, b| a / DOF_CHUNK == b / DOF_CHUNK)
        .map(partial)
        .collect::<Vec<f64>>()
        .into_iter()
        .sum()
}

/// a_{n+1} and v_{n+1} of one DOF at the end of a step of length h: a free DOF from its mass
/// and its forces (external, internal), `(m, (f_ext, f_int))`, and its mid-step velocity; a
/// prescribed one from its increment du and its velocity v_n. `motion` is
/// (v_{n+1/2}, v_n, du).
#[inline(always)]
pub(super) fn end_motion(
    free: bool,
    (m, (external, internal)): (f64, (f64, f64)),
    (v_half, v, du): (f64, f64, f64),
    (h, a_r): (f64, f64),
) -> (f64, f64) {
    if free {
        let a = (external - internal - a_r * m * v_half) / m;
        (a, v_half + 0.5 * h * a)
    } else {
        ((du / h - v) * 2.0 / h, du / h)
    }
}

/// The end of a step, once the internal force at u_{n+1} is known.
pub(super) struct StepEnd<'a> {
    pub(super) free: &'a [bool],
    pub(super) external: &'a [f64],
    pub(super) internal: &'a [f64],
    pub(super) m: &'a [f64],
    pub(super) v_half: &'a [f64],
    pub(super) du: &'a [f64],
    /// F of the step before (see `total_force`).
    pub(super) last_total: &'a [f64],
    pub(super) h: f64,
    pub(super) a_r: f64,
}

impl StepEnd<'_> {
    /// a_{n+1} and v_{n+1} (prescribed DOFs: from their increment), F_{n+1} into `total`;
    /// returns the external work of the step by the trapezoidal rule,
    /// du . (F_{n+1} + F_n) / 2, the kinetic energy 1/2 v.M v and its shadow h^2 / 8 a.M a
    /// (free DOFs).
    /// `motion`: the state that du moves, in the same pass (None: moved before).
    pub(super) fn apply(
        &self,
        (a, v, total): (&mut [f64], &mut [f64], &mut [f64]),
        motion: Option<StateMotion>,
    ) -> (f64, f64, f64) {
        let (h, a_r) = (self.h, self.a_r);
        let chunks = a.len().div_ceil(DOF_CHUNK);
        let (mut coordinates, mut displacement) = match motion {
            Some(motion) => motion.chunks(),
            None => (0..chunks).map(|_| Default::default()).unzip(),
        };
        // DOFs past the state's (a projectile's carrier, `explicit::projectiles`) move no
        // state: their chunks' state slices are empty
        coordinates.resize_with(chunks, Default::default);
        displacement.resize_with(chunks, Default::default);
        let sums: Vec<(f64, f64, f64)> = (
            a.par_chunks_mut(DOF_CHUNK),
            v.par_chunks_mut(DOF_CHUNK),
            total.par_chunks_mut(DOF_CHUNK),
            coordinates.into_par_iter().zip(displacement),
        )
            .into_par_iter()
            .enumerate()
            .with_min_len(CHUNKS_PER_TASK)
            .map(|(k, (a, v, total, (x, u)))| {
                let dofs = k * DOF_CHUNK..k * DOF_CHUNK + a.len();
                // the chunk's slices, so that the loop indexes without bounds checks
                let (free, m) = (&self.free[dofs.clone()], &self.m[dofs.clone()]);
                let (external, internal) =
                    (&self.external[dofs.clone()], &self.internal[dofs.clone()]);
                let (v_half, du) = (&self.v_half[dofs.clone()], &self.du[dofs.clone()]);
                let last_total = &self.last_total[dofs];
                move_by(x, u, du);
                let (mut work, mut kinetic, mut shadow) = (0.0, 0.0, 0.0);
                for (j, ((a, v), total)) in a.iter_mut().zip(v).zip(total).enumerate() {
                    let forces = (external[j], internal[j]);
                    let motion = (v_half[j], *v, du[j]);
                    (*a, *v) = end_motion(free[j], (m[j], forces), motion, (h, a_r));
                    if free[j] {
                        shadow += m[j] * *a * *a;
                    }
                    let dof = Dof {
                        free: free[j],
                        external: external[j],
                        internal: internal[j],
                        m: m[j],
                        a: *a,
                        v: *v,
                    };
                    *total = total_at(dof, a_r);
                    work += du[j] * (*total + last_total[j]);
                    kinetic += m[j] * *v * *v;
                }
                (work, kinetic, shadow)
            })
            .collect();
        let (work, kinetic, shadow) = sums
            .into_iter()
            .fold((0.0, 0.0, 0.0), |(w, k, s), (dw, dk, ds)| {
                (w + dw, k + dk, s + ds)
            });
        (0.5 * work, 0.5 * kinetic, 0.125 * h * h * shadow)
    }
}

/// What F reads at one DOF: whether it is free, its external and internal force, lumped
/// mass, acceleration and velocity.
#[derive(Clone, Copy)]
pub(super) struct Dof {
    pub(super) free: bool,
    pub(super) external: f64,
    pub(super) internal: f64,
    pub(super) m: f64,
    pub(super) a: f64,
    pub(super) v: f64,
}

/// The same over all DOFs.
pub(super) struct DofArrays<'a> {
    pub(super) free: &'a [bool],
    pub(super) external: &'a [f64],
    pub(super) internal: &'a [f64],
    pub(super) m: &'a [f64],
    pub(super) a: &'a [f64],
    pub(super) v: &'a [f64],
}

/// F: f_ext on the free DOFs, the reaction m a + a_R m v + f_int on the prescribed ones.
pub(super) fn total_force(dofs: &DofArrays, a_r: f64) -> Vec<f64> {
    (0..dofs.free.len())
        .map(|i| {
            let dof = Dof {
                free: dofs.free[i],
                external: dofs.external[i],
                internal: dofs.internal[i],
                m: dofs.m[i],
                a: dofs.a[i],
                v: dofs.v[i],
            };
            total_at(dof, a_r)
        })
        .collect()
}

/// F at one DOF (see `total_force`).
#[inline]
pub(super) fn total_at(dof: Dof, a_r: f64) -> f64 {
    if dof.free {
        dof.external
    } else {
        dof.m * dof.a + a_r * dof.m * dof.v + dof.internal
    }
}
