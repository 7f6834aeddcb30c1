//! The pool's other threads kept awake between the parallel loops of an explicit run.
//!
//! ```text
//! driver   the pool thread that steps the run; between its parallel loops it works alone
//!          (the contact phase, the step rule, history rows): some 50-100 us a step on a
//!          few thousand elements
//! helper   a task on each other thread of the pool that takes the pool's pending work
//!          (`rayon::yield_now`) until the run ends, or until it has found none for IDLE
//! ```
//!
//! A rayon worker that finds no work yields 32 times and then sleeps on a futex, and the next
//! parallel loop wakes it with a system call on the driver's side and a context switch on its
//! own. A step of the 2400-element aluminium rod has four such loops and serial gaps longer
//! than those 32 yields, so each loop began with a wake-up: on two threads a sampling profile
//! put 17 % of the run in the scheduler, and the second thread ran half as many samples as the
//! driver (docs/performance.md, "Threads kept awake"). The helpers take the loops' pieces as
//! a worker would, so which thread runs which chunk changes and the results do not: every
//! loop of the step is deterministic in its chunks (STYLE, performance habits).
//!
//! A helper that finds no work for IDLE leaves (a frame written, a long serial phase), and
//! the driver starts the helpers again at its next step. A helper landing on a thread that is
//! itself stepping another run (two runs sharing a pool) leaves at once.

use rayon::{BroadcastContext, Yield};
use std::cell::Cell;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// How long a helper looks for work in vain before it leaves: longer than the serial gaps of
/// a step (tens of microseconds), short beside a frame's writing.
const IDLE: Duration = Duration::from_millis(2);

thread_local! {
    /// Whether this thread steps a run: it never serves as another run's helper.
    static DRIVING: Cell<bool> = const { Cell::new(false) };
}

/// What the driver and its helpers share.
#[derive(Debug)]
struct Shared {
    /// The pool index of the driver's thread (its own copy of the broadcast returns).
    driver: usize,
    /// Set when the run ends: every helper leaves.
    stop: AtomicBool,
    /// Helpers started and not yet gone.
    present: AtomicUsize,
}

/// The helpers of one explicit run (dropping it sends them away).
#[derive(Debug)]
pub struct Awake {
    shared: Arc<Shared>,
    helpers: usize,
    /// Whether this thread was stepping a run before this one (a run started inside a
    /// parallel loop's wait): it still is after.
    was_driving: bool,
}

impl Awake {
    /// Helpers for a run stepped on this thread; None off a pool or on a pool of one thread,
    /// where there is nobody to keep awake.
    pub fn new() -> Option<Awake> {
        let driver = rayon::current_thread_index()?;
        let helpers = rayon::current_num_threads()
            .checked_sub(1)
            .filter(|h| *h > 0)?;
        let was_driving = DRIVING.replace(true);
        Some(Awake {
            shared: Arc::new(Shared {
                driver,
                stop: AtomicBool::new(false),
                present: AtomicUsize::new(0),
            }),
            helpers,
            was_driving,
        })
    }

    /// Called before each step: starts the helpers again when all have left.
    pub fn keep(&self) {
        if self.shared.present.load(Ordering::Acquire) > 0 {
            return;
        }
        self.shared.present.store(self.helpers, Ordering::Release);
        let shared = Arc::clone(&self.shared);
        rayon::spawn_broadcast(move |context| help(context, &shared));
    }
}

impl Drop for Awake {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Release);
        DRIVING.set(self.was_driving);
    }
}

/// A helper: the pool's pending work until the run stops or none came for IDLE.
fn help(context: BroadcastContext, shared: &Shared) {
    if context.index() == shared.driver {
        return;
    }
    // the clock is read every 16th idle round only (a round is about a microsecond)
    let (mut idle_rounds, mut idle_since) = (0u32, Instant::now());
    while !DRIVING.get() && !shared.stop.load(Ordering::Acquire) {
        match rayon::yield_now() {
            Some(Yield::Executed) => idle_rounds = 0,
            Some(Yield::Idle) => {
                if idle_rounds == 0 {
                    idle_since = Instant::now();
                } else if idle_rounds % 16 == 0 && idle_since.elapsed() > IDLE {
                    break;
                }
                idle_rounds += 1;
                std::thread::yield_now();
            }
            None => break,
        }
    }
    shared.present.fetch_sub(1, Ordering::AcqRel);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Waits until `count` helpers are present or two seconds pass (a loaded machine may
    /// start a task late); whether they were.
    fn settles(awake: &Awake, count: usize) -> bool {
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(2) {
            if awake.shared.present.load(Ordering::Acquire) == count {
                return true;
            }
            std::thread::sleep(Duration::from_micros(200));
        }
        false
    }

    /// Goal: the helpers come when asked, leave after IDLE without work, come again at the
    /// next step, and leave when the run ends (none outlives it); nobody is kept awake on a
    /// pool of one thread or off the pool. Setup: a pool of two threads, the driver on one
    /// of them. Reference: the count of helpers present.
    #[test]
    fn helpers_come_and_leave() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        pool.install(|| {
            let awake = Awake::new().expect("a pool of two threads");
            assert!(DRIVING.get());
            awake.keep();
            assert_eq!(awake.shared.present.load(Ordering::Acquire), 1);
            // no work for longer than IDLE: it leaves, and the next step calls it again
            assert!(settles(&awake, 0), "the helper stayed without work");
            awake.keep();
            assert_eq!(awake.shared.present.load(Ordering::Acquire), 1);
            let shared = Arc::clone(&awake.shared);
            drop(awake);
            assert!(!DRIVING.get());
            // the pool kept busy with other work, so that only the run's end sends the
            // helper away (idle, it would leave anyway)
            let start = Instant::now();
            while shared.present.load(Ordering::Acquire) > 0 {
                assert!(
                    start.elapsed() < Duration::from_secs(2),
                    "a helper outlived the run"
                );
                rayon::spawn(|| std::thread::sleep(Duration::from_micros(100)));
                std::thread::sleep(Duration::from_micros(50));
            }
        });
        let single = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        assert!(single.install(Awake::new).is_none());
        assert!(Awake::new().is_none(), "off the pool");
    }
}
