//! Explicit central difference with the lumped mass: no matrix, no factorization.
//!
//! Legend (velocity-Verlet form, identical displacements to the classical central difference)
//! ```text
//! v_{n+1/2} = v_n + dt/2 a_n
//! u_{n+1}   = u_n + dt v_{n+1/2}                 (prescribed DOFs: their curve value)
//! a_{n+1}   = (f_ext(t_{n+1}) - f_int(u_{n+1}) - a_R m v_{n+1/2}) / m
//! v_{n+1}   = v_{n+1/2} + dt/2 a_{n+1}
//! dt_crit   = 2 / omega_max,  omega_max^2 <= max_e lambda_max(M_e^-1 K_e)
//! ```
//! A dt above dt_crit is refused unless `allow_unstable`; then the run goes on and stops with
//! status `unstable` once the energy exceeds 100 times its reference (the initial kinetic
//! energy, the external work, or the internal energy at the first step, whichever is largest).

use super::checkpoint::{Carry, Checkpoint, ExplicitCarry};
use super::dynamics::check_mass;
use super::newton::Counters;
use super::record::{Energies, Motion, Recorder};
use super::{Outcome, RunError, RunOptions, Status, Summary, loads};
use crate::assembly::reduced::{Reduced, StepWork};
use crate::assembly::{self, Mass, State, System};
use crate::contact::ContactState;
use crate::scene::spec::Quadrature;
use crate::scene::spec::{DynamicSpec, MassKind};
use crate::scene::{InputError, Model};
use rayon::prelude::*;
use std::path::Path;
use std::time::Instant;

/// A central-difference stability limit and the element that sets it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StableStep {
    /// dt_crit = 2 / omega_max.
    pub dt: f64,
    pub body: usize,
    pub element: usize,
}

/// The central-difference stability limit of the model in its initial state, with the
/// element that sets it.
pub fn critical_time_step(model: &Model) -> Result<StableStep, InputError> {
    let state = State::initial(model);
    let bound = assembly::max_frequency_squared(model, &state, model.analysis.geometry())
        .map_err(|err| InputError::new(&model.file, err.to_string()))?;
    Ok(StableStep {
        dt: 2.0 / bound.omega_squared.sqrt(),
        body: bound.body,
        element: bound.element,
    })
}

pub fn run(
    model: &Model,
    spec: &DynamicSpec,
    dir: &Path,
    options: RunOptions,
    resume: Option<Checkpoint>,
) -> Result<Outcome, RunError> {
    let mut start = Instant::now();
    let setup_start = start;
    let StableStep {
        dt: dt_crit,
        body: b,
        element: e,
    } = critical_time_step(model)?;
    if spec.dt > dt_crit && !spec.allow_unstable {
        return Err(InputError::new(
            &model.file,
            format!(
                "analysis.dt = {} exceeds the central-difference stability limit {dt_crit:.6e} (set by body `{}`, element {e}); \
                 lower dt or set analysis.allow_unstable = true to watch it blow up",
                spec.dt, model.bodies[b].name
            ),
        )
        .into());
    }
    let initial = model.coordinates();
    let system = System::new(model, &loads::constrained_dofs(model));
    let mass = Mass::new(model, MassKind::Lumped)
        .map_err(|err| InputError::new(&model.file, err.to_string()))?;
    check_mass(model, &mass, &system)?;
    let free: Vec<bool> = system.equation.iter().map(Option::is_some).collect();
    let (mut recorder, resume) = match resume {
        Some(c) => {
            let Carry::Explicit(carry) = c.carry.clone() else {
                return Err(super::wrong_carry(dir, "explicit"));
            };
            (
                Recorder::resume(model, dir, c.recorder.clone())?,
                Some((c, carry)),
            )
        }
        None => (Recorder::create(model, dir)?, None),
    };
    let mut state = State::initial(model);
    let mut summary = Summary::new(
        model,
        "central_difference",
        spec.dt,
        spec.end_time,
        system.free,
    );
    // whole steps, and a shorter last one that ends exactly at end_time
    let steps = ((spec.end_time / spec.dt) * (1.0 - 1e-12)).ceil().max(1.0) as usize;
    let m = &mass.lumped;
    let a_r = spec.rayleigh[0];

    // the reduced kernel keeps its element state in its own arrays (copied into `state`
    // only when the recorder reads stresses)
    let mut reduced = (spec.quadrature == Quadrature::Reduced)
        .then(|| Reduced::new(model, &state, spec.hourglass));
    let zero = vec![0.0; model.dofs()];
    let first = match reduced.as_mut() {
        Some(kernel) => {
            let mut force = zero.clone();
            kernel
                .internal_force(&state.coordinates, &mut force)
                .map(|_| force)
        }
        None => assembly::evaluate(
            model,
            &state,
            &zero,
            spec.geometry,
            None,
            spec.newton.tangent,
        )
        .map(|e| e.force),
    }
    .map_err(|err| {
        super::fail(
            &recorder,
            summary.clone(),
            Status::Diverged,
            err.to_string(),
        )
    })?;
    let mut internal = first;
    let mut v = super::initial_velocity(model, &system, spec.dt);
    let external = loads::external_force(model, &state, &initial, 0.0);
    let mut a: Vec<f64> = (0..model.dofs())
        .map(|i| {
            if free[i] {
                (external[i] - internal[i] - a_r * m[i] * v[i]) / m[i]
            } else {
                0.0
            }
        })
        .collect();
    let kinetic = |v: &[f64]| 0.5 * v.iter().zip(m).map(|(v, m)| m * v * v).sum::<f64>();
    let mut energies = Energies {
        kinetic: kinetic(&v),
        ..Default::default()
    };
    let mut initial_kinetic = energies.kinetic;
    summary.energy.initial = initial_kinetic;
    let mut last_total = total_force(&free, &external, &internal, m, &a, &v, a_r);
    let mut energy_reference = initial_kinetic;
    let interfaces = super::interfaces(model);
    let mut contact = ContactState::new(&model.contacts);
    let penetration_limits = crate::contact::penetration_limits(&model.contacts, &initial);
    let mut first_step = 1;
    match resume {
        Some((checkpoint, carry)) => {
            state = carry.state;
            v = carry.velocity;
            a = carry.acceleration;
            energies = carry.energies;
            initial_kinetic = carry.initial_kinetic;
            last_total = carry.last_total;
            energy_reference = carry.energy_reference;
            contact = carry.contact;
            first_step = carry.step + 1;
            summary = checkpoint.summary;
            start = super::resumed_start(checkpoint.wall_seconds);
        }
        None => {
            recorder.step(
                model,
                &state,
                &Motion {
                    velocity: &v,
                    acceleration: &a,
                    mass: m,
                },
                &energies,
                true,
            )?;
        }
    }
    let save = |recorder: &Recorder,
                summary: &Summary,
                step: usize,
                state: &State,
                v: &[f64],
                a: &[f64],
                energies: &Energies,
                last_total: &[f64],
                energy_reference: f64,
                contact: &ContactState| {
        let carry = ExplicitCarry {
            state: state.clone(),
            velocity: v.to_vec(),
            acceleration: a.to_vec(),
            energies: *energies,
            initial_kinetic,
            last_total: last_total.to_vec(),
            energy_reference,
            step,
            contact: contact.clone(),
        };
        super::Bookkeeping {
            model,
            recorder,
            summary,
            counters: &Counters::default(),
            solver: None,
            start,
            buckling: None,
        }
        .save(Carry::Explicit(carry))
    };
    if first_step == 1 && model.checkpoint_every > 0 {
        save(
            &recorder,
            &summary,
            0,
            &state,
            &v,
            &a,
            &energies,
            &last_total,
            energy_reference,
            &contact,
        )?;
    }

    let progress = super::progress_bar(options.progress, steps);
    // zero on prescribed DOFs: contact corrections never move them
    let inverse_mass: Vec<f64> = (0..model.dofs())
        .map(|i| if free[i] { 1.0 / m[i] } else { 0.0 })
        .collect();
    // the step's vectors, allocated once; without force loads the external force stays zero
    let dofs = model.dofs();
    let (mut v_half, mut du) = (vec![0.0; dofs], vec![0.0; dofs]);
    let mut external = vec![0.0; dofs];
    let mut total = vec![0.0; dofs];
    let forces_applied = loads::has_external_force(model);
    crate::profile::add(crate::profile::Phase::Setup, setup_start);
    for step in first_step..=steps {
        let time = super::snap(step as f64 * spec.dt, spec.dt).min(spec.end_time);
        let h = super::step_length(time - state.time, spec.dt);
        predict(&v, &a, h, &mut v_half, &mut du);
        for (dof, value) in loads::prescribed(model, &initial, time) {
            du[dof] = value - state.displacement[dof];
        }
        if !model.contacts.is_empty() {
            crate::profile::time(crate::profile::Phase::Contact, || {
                let positions = state.positions(spec.geometry);
                let correction =
                    contact.explicit_step(&interfaces, &positions, &du, &inverse_mass, h, time);
                (
                    du.par_chunks_mut(DOF_CHUNK),
                    v_half.par_chunks_mut(DOF_CHUNK),
                )
                    .into_par_iter()
                    .zip(correction.par_chunks(DOF_CHUNK))
                    .for_each(|((du, v_half), correction)| {
                        for ((du, v), c) in du.iter_mut().zip(v_half).zip(correction) {
                            *du += c;
                            *v += c / h;
                        }
                    });
                let force = contact.nodal_forces(&model.contacts, &positions);
                energies.contact_work -= chunked_sum(&force, &du, |f, u| f * u);
            });
        }
        let evaluation = match reduced.as_mut() {
            Some(kernel) => crate::profile::time(crate::profile::Phase::Assembly, || {
                crate::profile::count_elements(kernel.elements());
                kernel.step(&state.coordinates, &du, &mut internal)
            })
            .map(|work| {
                commit_reduced(&mut state, &du, work);
                recorder.hourglass_energy = kernel.hourglass_energy;
            }),
            None => {
                assembly::evaluate(model, &state, &du, spec.geometry, None, spec.newton.tangent)
                    .map(|evaluation| {
                        internal = evaluation.force.clone();
                        assembly::commit(model, &mut state, &du, evaluation, spec.geometry);
                    })
            }
        };
        match evaluation {
            Ok(()) => {}
            Err(err) => {
                progress.abandon();
                summary.finish(&energies, &Counters::default(), None, start);
                let status = if spec.dt > dt_crit {
                    Status::Unstable
                } else {
                    Status::Diverged
                };
                return Err(super::fail(
                    &recorder,
                    summary,
                    status,
                    format!("at t = {time}: {err}"),
                ));
            }
        }
        state.time = time;
        let synced = match &reduced {
            Some(kernel) if recorder.reads_stresses(model, time, step == steps) => {
                kernel.write_points(model, &mut state);
                true
            }
            _ => false,
        };
        if forces_applied {
            external.fill(0.0);
            loads::add_external_force(model, &state, &initial, time, &mut external);
        }
        let (work, kinetic_energy) = StepEnd {
            free: &free,
            external: &external,
            internal: &internal,
            m,
            v_half: &v_half,
            du: &du,
            last_total: &last_total,
            h,
            a_r,
        }
        .apply(&mut a, &mut v, &mut total);
        energies.external_work += work;
        std::mem::swap(&mut last_total, &mut total);
        energies.kinetic = kinetic_energy;
        energies.internal = state.internal_work - state.plastic_work;
        energies.plastic_work = state.plastic_work;
        summary.steps += 1;
        summary.energy.max_relative_drift = summary
            .energy
            .max_relative_drift
            .max(super::balance_error(&energies, initial_kinetic));
        if step == 1 {
            energy_reference = energy_reference.max(energies.internal.abs());
        }
        energy_reference = energy_reference.max(energies.external_work.abs());
        let energy = energies.kinetic + energies.internal;
        let motion = Motion {
            velocity: &v,
            acceleration: &a,
            mass: m,
        };
        if !energy.is_finite() || energy > 100.0 * energy_reference {
            progress.abandon();
            if let (Some(kernel), false) = (&reduced, synced) {
                kernel.write_points(model, &mut state);
            }
            recorder.frame(model, &state, &motion, None).ok();
            summary.finish(&energies, &Counters::default(), None, start);
            let message = format!(
                "the energy grew to {energy:.3e} (reference {energy_reference:.3e}) at t = {time}: dt = {} is above the stability limit {dt_crit:.6e}",
                spec.dt
            );
            return Err(super::fail(&recorder, summary, Status::Unstable, message));
        }
        recorder.step_with_contact(
            model,
            &state,
            &motion,
            &energies,
            Some(&contact),
            step == steps,
        )?;
        let runaway = crate::profile::time(crate::profile::Phase::Contact, || {
            crate::contact::runaway_penetration(
                &model.contacts,
                &state.positions(spec.geometry),
                &penetration_limits,
            )
        });
        if let Some(message) = runaway {
            progress.abandon();
            summary.finish(&energies, &Counters::default(), None, start);
            summary.contact = contact.summary();
            let message = format!("at t = {}: {message}", state.time);
            return Err(super::fail(&recorder, summary, Status::Diverged, message));
        }
        progress.set_position(step as u64);
        let interrupted = step < steps && options.interrupted();
        if interrupted {
            if let (Some(kernel), false) = (&reduced, synced) {
                kernel.write_points(model, &mut state);
            }
            recorder.frame(model, &state, &motion, Some(&contact))?;
        }
        // the reduced kernel writes no checkpoint (its hourglass forces are not in `State`;
        // the scene refuses checkpoint_every with it)
        if reduced.is_none()
            && (interrupted || (step < steps && super::checkpoint_due(model, step)))
        {
            save(
                &recorder,
                &summary,
                step,
                &state,
                &v,
                &a,
                &energies,
                &last_total,
                energy_reference,
                &contact,
            )?;
        }
        options.halt(&summary)?;
        if interrupted {
            progress.abandon();
            summary.finish(&energies, &Counters::default(), None, start);
            summary.contact = contact.summary();
            return Err(match reduced {
                Some(_) => super::interrupted_saying(
                    &recorder,
                    summary,
                    state.time,
                    "quadrature = \"reduced\" writes no checkpoint: rerun the scene to continue",
                ),
                None => super::interrupted(&recorder, summary, state.time),
            });
        }
    }
    progress.finish_and_clear();
    if let Some(kernel) = &reduced {
        kernel.write_points(model, &mut state);
    }
    summary.finish(&energies, &Counters::default(), None, start);
    summary.contact = contact.summary();
    recorder.write_summary(&summary)?;
    let contact_force = vec![0.0; model.dofs()];
    Ok(Outcome {
        summary,
        state,
        contact_force,
    })
}

/// Commits a step of the reduced kernel (whose element state is already updated): the
/// configuration moves by du, the work accumulates.
fn commit_reduced(state: &mut State, du: &[f64], work: StepWork) {
    state
        .coordinates
        .par_chunks_mut(DOF_CHUNK / 2)
        .zip(du.par_chunks(DOF_CHUNK))
        .for_each(|(x, du)| {
            for (x, d) in x.iter_mut().zip(du.chunks_exact(2)) {
                x[0] += d[0];
                x[1] += d[1];
            }
        });
    state
        .displacement
        .par_chunks_mut(DOF_CHUNK)
        .zip(du.par_chunks(DOF_CHUNK))
        .for_each(|(u, du)| {
            for (u, d) in u.iter_mut().zip(du) {
                *u += d;
            }
        });
    state.internal_work += work.internal;
    state.plastic_work += work.plastic;
}

/// DOFs per chunk of the driver's vector loops: they run in parallel over fixed chunks and
/// their sums add the chunks' partial sums in chunk order, so the results are the same bits
/// for any number of threads.
const DOF_CHUNK: usize = 4096;

/// The predictor: v_{n+1/2} = v_n + h/2 a_n, du = h v_{n+1/2}.
fn predict(v: &[f64], a: &[f64], h: f64, v_half: &mut [f64], du: &mut [f64]) {
    (
        v_half.par_chunks_mut(DOF_CHUNK),
        du.par_chunks_mut(DOF_CHUNK),
    )
        .into_par_iter()
        .zip((v.par_chunks(DOF_CHUNK), a.par_chunks(DOF_CHUNK)))
        .for_each(|((v_half, du), (v, a))| {
            for (((vh, d), v), a) in v_half.iter_mut().zip(du).zip(v).zip(a) {
                *vh = v + 0.5 * h * a;
                *d = h * *vh;
            }
        });
}

/// sum_i term(x_i, y_i), deterministic for any number of threads (see `DOF_CHUNK`).
fn chunked_sum(x: &[f64], y: &[f64], term: impl Fn(f64, f64) -> f64 + Sync) -> f64 {
    x.par_chunks(DOF_CHUNK)
        .zip(y.par_chunks(DOF_CHUNK))
        .map(|(x, y)| x.iter().zip(y).map(|(x, y)| term(*x, *y)).sum::<f64>())
        .collect::<Vec<f64>>()
        .into_iter()
        .sum()
}

/// The end of a step, once the internal force at u_{n+1} is known.
struct StepEnd<'a> {
    free: &'a [bool],
    external: &'a [f64],
    internal: &'a [f64],
    m: &'a [f64],
    v_half: &'a [f64],
    du: &'a [f64],
    /// F of the step before (see `total_force`).
    last_total: &'a [f64],
    h: f64,
    a_r: f64,
}

impl StepEnd<'_> {
    /// a_{n+1} and v_{n+1} (prescribed DOFs: from their increment), F_{n+1} into `total`;
    /// returns the external work of the step by the trapezoidal rule,
    /// du . (F_{n+1} + F_n) / 2, and the kinetic energy 1/2 v.M v.
    fn apply(&self, a: &mut [f64], v: &mut [f64], total: &mut [f64]) -> (f64, f64) {
        let (h, a_r) = (self.h, self.a_r);
        let sums: Vec<(f64, f64)> = (
            a.par_chunks_mut(DOF_CHUNK),
            v.par_chunks_mut(DOF_CHUNK),
            total.par_chunks_mut(DOF_CHUNK),
        )
            .into_par_iter()
            .enumerate()
            .map(|(k, (a, v, total))| {
                let (mut work, mut kinetic) = (0.0, 0.0);
                for (j, ((a, v), total)) in a.iter_mut().zip(v).zip(total).enumerate() {
                    let i = k * DOF_CHUNK + j;
                    let m = self.m[i];
                    if self.free[i] {
                        *a = (self.external[i] - self.internal[i] - a_r * m * self.v_half[i]) / m;
                        *v = self.v_half[i] + 0.5 * h * *a;
                    } else {
                        *a = (self.du[i] / h - *v) * 2.0 / h;
                        *v = self.du[i] / h;
                    }
                    let (external, internal) = (self.external[i], self.internal[i]);
                    *total = total_at(self.free[i], external, internal, m, *a, *v, a_r);
                    work += self.du[i] * (*total + self.last_total[i]);
                    kinetic += m * *v * *v;
                }
                (work, kinetic)
            })
            .collect();
        let (work, kinetic) = sums
            .into_iter()
            .fold((0.0, 0.0), |(w, k), (dw, dk)| (w + dw, k + dk));
        (0.5 * work, 0.5 * kinetic)
    }
}

/// F: f_ext on the free DOFs, the reaction m a + a_R m v + f_int on the prescribed ones.
fn total_force(
    free: &[bool],
    external: &[f64],
    internal: &[f64],
    m: &[f64],
    a: &[f64],
    v: &[f64],
    a_r: f64,
) -> Vec<f64> {
    (0..free.len())
        .map(|i| total_at(free[i], external[i], internal[i], m[i], a[i], v[i], a_r))
        .collect()
}

/// F at one DOF (see `total_force`).
fn total_at(free: bool, external: f64, internal: f64, m: f64, a: f64, v: f64, a_r: f64) -> f64 {
    if free {
        external
    } else {
        m * a + a_r * m * v + internal
    }
}

/// The scene of `kernel_benchmark`: a unit-cell n x n plane-strain J2 block, reduced kernel.
fn benchmark_scene(n: usize) -> String {
    format!(
        r#"
[[material]]
name = "steel"
young = 200.0
poisson = 0.3
density = 1.0
yield_stress = 0.3
hardening_modulus = 2.0

[[body]]
name = "block"
material = "steel"
formulation = "plane_strain"
mesh = {{ type = "rectangle", width = {n}.0, height = {n}.0, nx = {n}, ny = {n} }}

[analysis]
type = "dynamic"
integrator = "central_difference"
quadrature = "reduced"
dt = 0.02
end_time = 1.0

[output]
frame_every = 0
"#
    )
}

/// Element-updates per second of the reduced explicit kernel (the issue #9 target), for
/// `impact bench`: a sqrt(elements)^2 plane-strain J2 block (unit elements, E = 200,
/// nu = 0.3, rho = 1, sigma_y = 0.3) sheared isochorically (v = r (-x, y) about the centre,
/// r such that it yields after ~10 steps, so most of the run is plastic) for `steps`
/// central-difference steps at dt = 0.5 h / c_p, in a rayon pool of `threads` threads.
/// Times the whole step (nodal updates, element kernel, gather); setup excluded.
/// Returns 0 when `elements`, `steps` or `threads` is 0 or the pool cannot be built.
pub fn kernel_benchmark(elements: usize, steps: usize, threads: usize) -> f64 {
    kernel_benchmark_run(elements, steps, threads).map_or(0.0, |r| r.0)
}

/// `kernel_benchmark` with the fraction of elements that turned plastic: (element-updates/s,
/// plastic fraction).
pub fn kernel_benchmark_run(elements: usize, steps: usize, threads: usize) -> Option<(f64, f64)> {
    let n = (elements as f64).sqrt().round() as usize;
    if n == 0 || steps == 0 || threads == 0 {
        return None;
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .ok()?;
    let model =
        crate::scene::from_str(&benchmark_scene(n), Path::new("kernel_benchmark.toml"), &[])
            .expect("the benchmark scene is valid");
    let mass = Mass::new(&model, MassKind::Lumped).ok()?;
    let m = &mass.lumped;
    let young: f64 = 200.0;
    let c = (model.bodies[0].material.elastic.p_wave_modulus()).sqrt();
    let h = 0.5 / c;
    let rate = 0.3 / young / (10.0 * h);
    let centre = 0.5 * n as f64;
    pool.install(|| {
        let mut state = State::initial(&model);
        let mut kernel = Reduced::new(&model, &state, 0.1);
        let dofs = model.dofs();
        let mut v: Vec<f64> = state
            .coordinates
            .iter()
            .flat_map(|x| [-rate * (x[0] - centre), rate * (x[1] - centre)])
            .collect();
        let mut a = vec![0.0; dofs];
        let mut du = vec![0.0; dofs];
        let mut force = vec![0.0; dofs];
        use rayon::prelude::*;
        let start = Instant::now();
        for _ in 0..steps {
            v.par_iter_mut()
                .zip(a.par_iter())
                .zip(du.par_iter_mut())
                .for_each(|((v, a), du)| {
                    *v += 0.5 * h * a;
                    *du = h * *v;
                });
            if kernel.step(&state.coordinates, &du, &mut force).is_err() {
                return None;
            }
            state
                .coordinates
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, x)| {
                    x[0] += du[2 * i];
                    x[1] += du[2 * i + 1];
                });
            v.par_iter_mut()
                .zip(a.par_iter_mut())
                .zip(force.par_iter().zip(m.par_iter()))
                .for_each(|((v, a), (f, m))| {
                    *a = -f / m;
                    *v += 0.5 * h * *a;
                });
        }
        let seconds = start.elapsed().as_secs_f64();
        let plastic = kernel
            .eq_plastic_strain
            .iter()
            .filter(|e| **e > 0.0)
            .count();
        Some((
            (kernel.elements() * steps) as f64 / seconds,
            plastic as f64 / kernel.elements() as f64,
        ))
    })
}
