//! The explicit fast path (issue #9): one-point Quad4 with Flanagan-Belytschko hourglass
//! control (`analysis.quadrature = "reduced"`), against closed-form references and the full
//! kernel.

mod common;

use common::column;

/// Goal: the micro-benchmark of the reduced kernel (run by hand, no timing assertion):
/// `cargo test --release -j 1 --test explicit_fast -- --ignored --nocapture`.
/// Setup: impact::analysis::explicit::kernel_benchmark_run on a 316 x 316 plane-strain J2
/// block, 200 steps, 1 and 2 threads.
#[test]
#[ignore]
fn kernel_benchmark_element_updates_per_second() {
    for threads in [1, 2] {
        let (rate, plastic) =
            impact::analysis::explicit::kernel_benchmark_run(316 * 316, 200, threads).unwrap();
        println!(
            "threads {threads}: {:.3e} element-updates/s ({:.1} % of the elements plastic)",
            rate,
            100.0 * plastic
        );
    }
}
