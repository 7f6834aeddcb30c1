//! Where a run's time goes: wall-clock seconds per phase, summed over the run, for
//! summary.json's `timing` block and `impact bench`.
//!
//! Phases are timed where they are called (one clock read per call), so the cost is nil next
//! to the work they time; the constitutive update is timed per element and only when fine
//! timing is switched on (`set_fine(true)`, as `impact bench` does), since a clock read per
//! element would show in the explicit path. Counters are process-wide atomics: one run per
//! process is what they describe (`reset` at the start of a run).

use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// A timed phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Element loops and the scatter into the force vector and stiffness (includes the
    /// constitutive update).
    Assembly,
    /// The constitutive update inside the element loops (fine timing only): CPU seconds
    /// summed over the threads, so on several threads it can exceed the assembly's wall time.
    Constitutive,
    /// Numeric factorizations.
    Factorization,
    /// Back-substitutions with the factor (including the unit columns of the contact Schur
    /// complement).
    Solve,
    /// Contact: the penetration search, the constraint rows, forming and solving the Schur
    /// complement, the explicit multipliers (the impact and release conditions and the
    /// active-set bookkeeping are not timed: they are per slave node, not per DOF).
    Contact,
    /// history.csv rows, VTK frames, checkpoints.
    Output,
    /// From the start of the analysis to its first step: model arrays, the symbolic
    /// analysis, the mass, the stability limit, the first frame.
    Setup,
}

const PHASES: usize = 7;

static NANOS: [AtomicU64; PHASES] = [const { AtomicU64::new(0) }; PHASES];
static ELEMENT_UPDATES: AtomicU64 = AtomicU64::new(0);
static FINE: AtomicBool = AtomicBool::new(false);

/// Clears the counters (the start of a run).
pub fn reset() {
    for n in &NANOS {
        n.store(0, Ordering::Relaxed);
    }
    ELEMENT_UPDATES.store(0, Ordering::Relaxed);
}

/// Switches the per-element timing of the constitutive update on or off.
pub fn set_fine(on: bool) {
    FINE.store(on, Ordering::Relaxed);
}

pub fn fine() -> bool {
    FINE.load(Ordering::Relaxed)
}

/// The constitutive phase is timed on every `SAMPLE`-th element and scaled up: two clock
/// reads around each element's material updates cost conical_bar 8.6 % of its wall time,
/// which the bench's wall column then carried; one element in eight costs ~1 %.
const SAMPLE: usize = 8;

/// Whether element `element` is one the fine profile times (see `add_constitutive`).
pub fn fine_sample(element: usize) -> bool {
    element.is_multiple_of(SAMPLE) && fine()
}

/// Adds the time since `start` of a sampled element (`fine_sample`), scaled by the sample's
/// rate, to the constitutive phase from inside a parallel element loop: summed per thread
/// and handed to the shared counter a millisecond at a time, so the threads do not contend
/// for it once per element (each thread keeps under 1 ms unreported).
pub fn add_constitutive(start: Instant) {
    thread_local! {
        static PENDING: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
    }
    let nanos = start.elapsed().as_nanos() as u64 * SAMPLE as u64;
    PENDING.with(|pending| {
        let total = pending.get() + nanos;
        if total >= 1_000_000 {
            NANOS[Phase::Constitutive as usize].fetch_add(total, Ordering::Relaxed);
            pending.set(0);
        } else {
            pending.set(total);
        }
    });
}

/// Adds the time since `start` to `phase`.
pub fn add(phase: Phase, start: Instant) {
    NANOS[phase as usize].fetch_add(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
}

/// Adds the time from its creation to its drop to a phase (for functions with early returns).
pub struct Timer(Phase, Instant);

impl Timer {
    pub fn new(phase: Phase) -> Timer {
        Timer(phase, Instant::now())
    }
}

impl Drop for Timer {
    fn drop(&mut self) {
        add(self.0, self.1);
    }
}

/// Runs `f`, adding its time to `phase`.
pub fn time<T>(phase: Phase, f: impl FnOnce() -> T) -> T {
    let start = Instant::now();
    let out = f();
    add(phase, start);
    out
}

/// Counts element evaluations (one element's force, with or without its stiffness).
pub fn count_elements(n: usize) {
    ELEMENT_UPDATES.fetch_add(n as u64, Ordering::Relaxed);
}

/// The `timing` block of summary.json: seconds per phase, and the element updates.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct Timing {
    pub assembly: f64,
    /// Zero unless fine timing was on; CPU seconds summed over threads.
    pub constitutive: f64,
    pub factorization: f64,
    pub solve: f64,
    pub contact: f64,
    pub output: f64,
    /// Before the first step (included in the run's wall_seconds). It overlaps the phases
    /// above: the first frame (output), the initial acceleration's evaluation (assembly,
    /// counted in element_updates) and, with loads, its factorization and solve.
    #[serde(default)]
    pub setup: f64,
    pub element_updates: u64,
    /// Peak resident memory of the process (bytes, Linux VmHWM), null where unknown.
    pub peak_memory_bytes: Option<u64>,
    /// The threads of the pool the run stepped on (`analysis::run_threads`).
    #[serde(default)]
    pub threads: usize,
    /// The build of the loops compiled twice (`registers`) that this processor runs:
    /// "avx2+fma" or "baseline".
    #[serde(default)]
    pub registers: String,
}

/// Which of the two builds of the multiversioned loops this processor runs (the explicit
/// element steps, the stable step's estimates, the implicit element tangent;
/// docs/performance.md, "Wider registers where the processor has them"): "avx2+fma" where
/// it has both features, the test `multiversion` makes for its target "x86_64+avx2+fma",
/// else "baseline". The two give the same bits; the name tells timings apart.
pub fn registers() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        return "avx2+fma";
    }
    "baseline"
}

/// The counters now.
pub fn snapshot() -> Timing {
    let s = |p: Phase| NANOS[p as usize].load(Ordering::Relaxed) as f64 * 1e-9;
    Timing {
        assembly: s(Phase::Assembly),
        constitutive: s(Phase::Constitutive),
        factorization: s(Phase::Factorization),
        solve: s(Phase::Solve),
        contact: s(Phase::Contact),
        output: s(Phase::Output),
        setup: s(Phase::Setup),
        element_updates: ELEMENT_UPDATES.load(Ordering::Relaxed),
        peak_memory_bytes: peak_memory(),
        // called inside the run: its pool
        threads: rayon::current_num_threads(),
        registers: registers().to_string(),
    }
}

/// VmHWM of /proc/self/status.
fn peak_memory() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
