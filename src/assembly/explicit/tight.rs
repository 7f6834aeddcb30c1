//! The tight stable step: each element's closed-form frequency bound (what the kernels give
//! every step, cheap and never below the truth) times the ratio of the element's exact highest
//! frequency squared to that bound, the ratio taken again whenever the element's bound has
//! moved by more than `DRIFT` since (docs/theory.md 8.7).
//!
//! ```text
//! omega_e^2 (step n)  =  rho_e  bound_e(n),      rho_e = lambda_max(M_e^-1 K_e) / bound_e
//!                                                 at the last step where |bound_e / at_e - 1|
//!                                                 exceeded DRIFT (at_e: the bound then)
//! K_e                 the kernel's own stiffness on the element's current configuration,
//!                     from a stress-free state (elastic; hourglass, hoop and B-bar as the
//!                     kernel has them), by central differences of its nodal forces
//! M_e                 the element's lumped masses as the bound takes them (mass scaling's
//!                     factor included)
//! ```
//!
//! The elastic tangent is the stiffest the material can be (plastic flow only softens it), and
//! Irons' element eigenvalue inequality puts the mesh's highest frequency below the largest
//! element's: 2 / sqrt(max_e omega_e^2) is a stable step of the whole mesh, to the drift of
//! the ratio between two evaluations (the bound tracks the element's size every step; the ratio
//! only its shape, within DRIFT of it).

use super::global::Global;
pub use super::global::{ElementStiffness, max_frequency_squared};
use crate::scene::spec::StableStepKind;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How far an element's bound may move (relative) before its ratio is taken again.
pub const DRIFT: f64 = 0.02;

/// Per element, the ratio of its exact frequency squared to its bound and the bound it was
/// taken at (0: not yet taken); with the global step, the estimate of the mesh's.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Tightness {
    ratio: Vec<f64>,
    at: Vec<f64>,
    global: Option<Global>,
}

impl Tightness {
    /// The ratios of `elements` elements under the estimate `kind` (None: `Bound`, the
    /// bounds stand), none taken yet.
    pub fn of(kind: StableStepKind, elements: usize) -> Option<Tightness> {
        match kind {
            StableStepKind::Bound => None,
            StableStepKind::Tight => Some(Tightness::new(elements, false)),
            StableStepKind::Global => Some(Tightness::new(elements, true)),
        }
    }

    /// `elements` elements, no ratio taken yet; `global`: the mesh's highest frequency
    /// estimated over them (`global.rs`).
    pub fn new(elements: usize, global: bool) -> Tightness {
        Tightness {
            ratio: vec![1.0; elements],
            at: vec![0.0; elements],
            global: global.then(|| Global::new(elements)),
        }
    }

    /// Whether element `e`'s ratio is due again at its bound `bound`.
    fn stale(&self, e: usize, bound: f64) -> bool {
        let at = self.at[e];
        !(at > 0.0 && (bound / at - 1.0).abs() <= DRIFT)
    }

    /// The ratio of element `e` for its bound `bound` and exact value `exact` (None: the
    /// exact value could not be formed; the bound then stands). Never above 1 (round-off of
    /// the differences aside, the bound is an upper bound).
    fn ratio_of(bound: f64, exact: Option<&ElementStiffness>) -> f64 {
        match exact.map(ElementStiffness::frequency_squared) {
            Some(exact) if bound > 0.0 && exact.is_finite() && exact > 0.0 => {
                (exact / bound).min(1.0)
            }
            _ => 1.0,
        }
    }

    /// The tight frequency squared of every element from this step's `bounds`, the largest
    /// and its element (the lowest index among equals), the stale ratios taken again with
    /// `exact(e)` (in parallel; the result does not depend on the thread count). `damping`:
    /// each bound's undamped value over it (the bulk viscosity's, 1 without): the ratios
    /// are taken against the undamped bounds and scale the damped ones. With the global
    /// step, the mesh's estimate from the elements `nodes` in its place.
    pub fn apply(
        &mut self,
        bounds: &[f64],
        damping: &[f64],
        nodes: &[[u32; 4]],
        exact: impl Fn(usize) -> Option<ElementStiffness> + Sync,
    ) -> (f64, usize) {
        let undamped = undamped(bounds, damping);
        self.refresh(0..bounds.len(), |e| undamped[e], exact);
        let largest = self.largest(bounds, |e| self.ratio[e]);
        let Some(global) = self.global.as_mut() else {
            return largest;
        };
        let (ratio, at) = (&self.ratio, &self.at);
        let peak = undamped
            .iter()
            .enumerate()
            .map(|(e, bound)| ratio[e] * bound)
            .fold(0.0, f64::max);
        let share = global.ratio(nodes, |e| undamped[e] / at[e], peak, DRIFT);
        (share * largest.0, largest.1)
    }

    /// Takes again the stale ratios among `elements`, whose (undamped) bounds are `bound(e)`,
    /// with `exact(e)` and its eigenvalue in parallel.
    fn refresh(
        &mut self,
        elements: impl Iterator<Item = usize>,
        bound: impl Fn(usize) -> f64 + Sync,
        exact: impl Fn(usize) -> Option<ElementStiffness> + Sync,
    ) {
        let stale: Vec<usize> = elements.filter(|&e| self.stale(e, bound(e))).collect();
        let fresh: Vec<(f64, Option<ElementStiffness>)> = (stale.par_iter())
            .map(|&e| {
                let stiffness = exact(e);
                (Tightness::ratio_of(bound(e), stiffness.as_ref()), stiffness)
            })
            .collect();
        for (&e, (ratio, stiffness)) in stale.iter().zip(fresh) {
            self.ratio[e] = ratio;
            self.at[e] = bound(e);
            if let Some(global) = self.global.as_mut() {
                global.keep(e, stiffness);
            }
        }
    }

    /// As `apply`, without keeping the ratios taken or the estimate made (the stable step of a
    /// configuration before a step, `impact check`).
    pub fn peek(
        &self,
        bounds: &[f64],
        damping: &[f64],
        nodes: &[[u32; 4]],
        exact: impl Fn(usize) -> Option<ElementStiffness> + Sync,
    ) -> (f64, usize) {
        self.clone().apply(bounds, damping, nodes, exact)
    }

    /// The ratio of element `e` at its bound `bound`: the one kept, or when stale a fresh one
    /// from `exact()` (not kept).
    pub fn ratio_for(
        &self,
        e: usize,
        bound: f64,
        exact: impl FnOnce() -> Option<ElementStiffness>,
    ) -> f64 {
        match self.stale(e, bound) {
            true => Tightness::ratio_of(bound, exact().as_ref()),
            false => self.ratio[e],
        }
    }

    /// As `apply` over the elements `elements` only (a subcycled substep), whose entries of
    /// `omega_squared` hold this step's bounds and are made tight (`damping` as `apply`'s: the
    /// ratios against the undamped bounds scale the damped ones); the largest of them and its
    /// element.
    pub fn apply_subset(
        &mut self,
        elements: &[u32],
        (omega_squared, damping): (&mut [f64], &[f64]),
        exact: impl Fn(usize) -> Option<ElementStiffness> + Sync,
    ) -> (f64, usize) {
        let bounds: &[f64] = omega_squared;
        self.refresh(
            elements.iter().map(|&e| e as usize),
            |e| bounds[e] * damping[e],
            exact,
        );
        let mut best = (0.0, usize::MAX);
        for &e in elements {
            let e = e as usize;
            omega_squared[e] *= self.ratio[e];
            if omega_squared[e] > best.0 || (omega_squared[e] == best.0 && e < best.1) {
                best = (omega_squared[e], e);
            }
        }
        best
    }

    fn largest(&self, bounds: &[f64], ratio: impl Fn(usize) -> f64) -> (f64, usize) {
        let mut best = (0.0, usize::MAX);
        for (e, bound) in bounds.iter().enumerate() {
            let omega_squared = ratio(e) * bound;
            if omega_squared > best.0 {
                best = (omega_squared, e);
            }
        }
        best
    }
}

/// The bounds without the bulk viscosity's damping: `bounds` times `damping` (borrowed where
/// every factor is 1).
fn undamped<'a>(bounds: &'a [f64], damping: &[f64]) -> std::borrow::Cow<'a, [f64]> {
    if damping.iter().all(|d| *d == 1.0) {
        std::borrow::Cow::Borrowed(bounds)
    } else {
        std::borrow::Cow::Owned(bounds.iter().zip(damping).map(|(b, d)| b * d).collect())
    }
}

/// The stiffness of an element's nodal forces `force(u)` (u: a nodal increment from the
/// stress-free state; forces linear in it) by central differences with step `h` (a small
/// fraction of the element's shortest edge: the forces are linear to O(h^2 / L^2)). None when
/// a force could not be formed. (Inlined, so that it takes the target features of its
/// caller: `skeleton::stiffness_at`.)
#[inline(always)]
pub fn stiffness_by_differences(
    h: f64,
    force: impl Fn(&[[f64; 2]; 4]) -> Option<[f64; 8]>,
) -> Option<[[f64; 8]; 8]> {
    let mut k = [[0.0; 8]; 8];
    for j in 0..8 {
        let mut u = [[0.0; 2]; 4];
        u[j / 2][j % 2] = h;
        let plus = force(&u)?;
        u[j / 2][j % 2] = -h;
        let minus = force(&u)?;
        for i in 0..8 {
            k[i][j] = (plus[i] - minus[i]) / (2.0 * h);
        }
    }
    Some(k)
}

/// The nodes of an element at the end of a step: `x` at its start moved by `du`.
pub fn end_nodes(nodes: [u32; 4], x: &[[f64; 2]], du: &[f64]) -> [[f64; 2]; 4] {
    nodes.map(|n| {
        let n = n as usize;
        [x[n][0] + du[2 * n], x[n][1] + du[2 * n + 1]]
    })
}

/// The shortest edge of a quad.
pub fn shortest_edge(x: &[[f64; 2]; 4]) -> f64 {
    (0..4)
        .map(|a| {
            let (p, q) = (x[a], x[(a + 1) % 4]);
            (q[0] - p[0]).hypot(q[1] - p[1])
        })
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: a ratio is taken once, kept while the bound stays within DRIFT, taken again past
    /// it; the largest tight value and its element. Reference: by hand.
    #[test]
    fn ratios_are_kept_within_the_drift_and_taken_again_past_it() {
        let mut t = Tightness::new(2, false);
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let exact = |e: usize| {
            calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            Some(of_frequency([2.0, 3.0][e]))
        };
        let nodes = [[0, 1, 2, 3], [1, 4, 5, 2]];
        // ratios 0.5 and 0.75: tight values 2 and 3
        assert_eq!(t.apply(&[4.0, 4.0], &[1.0; 2], &nodes, exact), (3.0, 1));
        assert_eq!(calls.load(std::sync::atomic::Ordering::Relaxed), 2);
        // element 0's bound moves 1 %: kept (0.5 * 4.04); element 1 by 5 %: taken again
        // (exact 3 over 4.2)
        assert_eq!(t.apply(&[4.04, 4.2], &[1.0; 2], &nodes, exact), (3.0, 1));
        assert_eq!(calls.load(std::sync::atomic::Ordering::Relaxed), 3);
        assert_eq!(t.ratio[0], 0.5);
        // a bound below the exact value (round-off) is not trusted beyond 1
        let mut t = Tightness::new(1, false);
        let one = [[0, 1, 2, 3]];
        assert_eq!(
            t.apply(&[1.0], &[1.0], &one, |_| Some(of_frequency(1.0 + 1e-12))),
            (1.0, 0)
        );
        assert_eq!(t.apply(&[1.0], &[1.0], &one, |_| None).0, 1.0);
    }

    /// An element whose highest frequency squared is `omega_squared` (unit masses).
    fn of_frequency(omega_squared: f64) -> ElementStiffness {
        let mut k = [[0.0; 8]; 8];
        k[0][0] = omega_squared;
        ElementStiffness {
            k,
            lumped: [1.0; 4],
        }
    }

    /// Goal: the eigenvalue of M^-1 K of a known system. Reference: two unit masses joined
    /// by a spring k along x (nodes 0 and 1): omega^2 = 2 k / m; the other DOFs free.
    #[test]
    fn spring_between_two_masses() {
        let mut k = [[0.0; 8]; 8];
        let s = 3.0;
        k[0][0] = s;
        k[2][2] = s;
        k[0][2] = -s;
        k[2][0] = -s;
        let w = max_frequency_squared(&k, &[1.0, 1.0, 5.0, 5.0]);
        assert!((w - 6.0).abs() < 1e-12, "{w}");
        let w = max_frequency_squared(&k, &[2.0, 1.0, 5.0, 5.0]);
        // 1/m_0 + 1/m_1 = 1.5 times s
        assert!((w - 4.5).abs() < 1e-12, "{w}");
    }
}
