//! The global stable step (`analysis.stable_step = "global"`): an estimate of the mesh's
//! highest frequency, below the largest element's (a step longer than the tight element
//! step), from the element stiffnesses the tight step takes (docs/theory.md 8.7, "The global
//! step").
//!
//! ```text
//! A        = D^-1/2 K D^-1/2,   K = sum_e s_e K_e,   D the nodal lumped masses (both directions)
//! s_e      = bound_e / at_e     the element's bound now over its bound when K_e was taken
//!                               (the tight step's own drift rule, 8.7)
//! theta    the largest Ritz value of at most ITERATIONS Lanczos steps (twice as many the
//!          first time; full reorthogonalization; stopped once r <= TOLERANCE theta) from
//!          the last estimate's Ritz vector plus a tenth of a fixed pseudo-random vector
//!          (`solver::lanczos::start_vector`)
//! r        = beta_m |s_m|       its residual: an eigenvalue of A lies within r of theta
//! lambda   = min(theta + r, max_e omega_e^2)    omega_e^2 the tight element frequencies
//! ```
//!
//! Irons' element eigenvalue inequality puts the mesh's highest eigenvalue at or below the
//! largest element's, and a Ritz value is at or below it too: the estimate lies between the
//! two, the element step its safety net. Between two estimates the step follows the tight
//! element maximum at the ratio last found (`lambda / max_e omega_e^2`); an estimate is taken
//! again every `EVERY` steps and whenever that maximum has moved by more than the tight
//! step's `DRIFT`. The product, the dot products and the vector updates run in parallel,
//! every sum in a fixed order (`Product`, `dot`): the estimate does not depend on the thread
//! count.

use crate::solver::lanczos::{start_vector, tridiagonal_eigen};
use multiversion::multiversion;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Lanczos steps of an estimate (the first from the pseudo-random vector alone takes twice).
const ITERATIONS: usize = 30;

/// Steps between two estimates when the element maximum stays within the drift.
pub const EVERY: usize = 100;

/// An element's stiffness from a stress-free state and its lumped nodal masses (each for
/// both directions of its node), as the tight step forms them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ElementStiffness {
    pub k: [[f64; 8]; 8],
    pub lumped: [f64; 4],
}

impl ElementStiffness {
    /// The element's highest frequency squared, the largest eigenvalue of M^-1 K.
    pub fn frequency_squared(&self) -> f64 {
        max_frequency_squared(&self.k, &self.lumped)
    }
}

/// The largest eigenvalue of M^-1 K for an 8 x 8 element stiffness `k` (symmetrized) and the
/// lumped nodal masses `lumped` (each for both directions of its node).
pub fn max_frequency_squared(k: &[[f64; 8]; 8], lumped: &[f64; 4]) -> f64 {
    crate::element::highest_frequency_squared(|i, j| k[i][j], lumped)
}

/// The global estimate's state: the element stiffnesses and what the last estimate found.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Global {
    /// Each element's stiffness and lumped masses as the tight step last took them.
    stiffness: Vec<Option<ElementStiffness>>,
    /// The last estimate over the element maximum then (0: none yet).
    ratio: f64,
    /// The element maximum at the last estimate.
    at: f64,
    /// Steps since the last estimate.
    since: usize,
    /// The last estimate's Ritz vector (the next one starts from it).
    vector: Vec<f64>,
}

impl Global {
    /// The state of a mesh of `elements` elements, no stiffness taken yet.
    pub fn new(elements: usize) -> Global {
        Global {
            stiffness: vec![None; elements],
            ..Global::default()
        }
    }

    /// Keeps element `e`'s stiffness (None: it could not be formed; no estimate is then
    /// taken until it is).
    pub fn keep(&mut self, e: usize, stiffness: Option<ElementStiffness>) {
        self.stiffness[e] = stiffness;
    }

    /// The ratio of the mesh's highest frequency squared to the tight element maximum `max`
    /// for this step (at most 1), from the elements' `nodes` and their stiffness scales
    /// `scale(e)`: the last estimate's, or a new one when one is due (`drift`: how far the
    /// maximum may move before one is, the tight step's own `DRIFT`).
    pub fn ratio(
        &mut self,
        nodes: &[[u32; 4]],
        scale: impl Fn(usize) -> f64,
        max: f64,
        drift: f64,
    ) -> f64 {
        let due = self.ratio == 0.0 || self.since >= EVERY || (max / self.at - 1.0).abs() > drift;
        if due {
            self.ratio = match self.estimate(nodes, scale) {
                Some(lambda) if max > 0.0 => (lambda / max).min(1.0),
                _ => 1.0,
            };
            self.at = max;
            self.since = 0;
        }
        self.since += 1;
        self.ratio
    }

    /// theta + r of the Lanczos estimate (module docs); None when an element's stiffness is
    /// missing or the masses are not positive.
    fn estimate(&mut self, nodes: &[[u32; 4]], scale: impl Fn(usize) -> f64) -> Option<f64> {
        let count = nodes.iter().flatten().map(|&n| n as usize + 1).max()?;
        let mut mass = vec![0.0; count];
        for (e, element) in nodes.iter().enumerate() {
            let stiffness = self.stiffness[e].as_ref()?;
            for (a, &n) in element.iter().enumerate() {
                mass[n as usize] += stiffness.lumped[a];
            }
        }
        // nodes of no element (an obstacle's, a rod's) take no part
        let weight: Vec<f64> = mass
            .iter()
            .flat_map(|&m| {
                let w = if m > 0.0 { 1.0 / m.sqrt() } else { 0.0 };
                [w, w]
            })
            .collect();
        let scales: Vec<f64> = (0..nodes.len()).map(&scale).collect();
        let product = Product {
            nodes,
            stiffness: &self.stiffness,
            scales: &scales,
            weight: &weight,
            entries: NodeEntries::new(nodes, count),
        };
        let mut contributions = vec![0.0; 8 * nodes.len()];
        let apply = |q: &[f64], out: &mut [f64]| product.apply(q, out, &mut contributions);
        let mut start = start_vector(2 * count);
        let iterations = if self.vector.len() == start.len() {
            let norm = dot(&start, &start).sqrt();
            for (v, previous) in start.iter_mut().zip(&self.vector) {
                *v = 0.1 * *v / norm + previous;
            }
            ITERATIONS
        } else {
            2 * ITERATIONS
        };
        let (theta, residual, vector) = lanczos(apply, start, iterations)?;
        self.vector = vector;
        Some(theta + residual)
    }
}

/// Vector entries a block of the estimate's dot products sums (the blocks fix the order of
/// the additions, and so the bits).
const TASK: usize = 2048;

/// Elements, nodes or vector entries a task of the loops whose entries do not depend on how
/// they are split (the product, the updates) takes at least: short enough that a mesh of a
/// few thousand elements shares them between two threads (with 2048 such a mesh's estimate
/// ran on the stepping thread alone).
const SPLIT: usize = 256;

/// A global node's entries in the element contributions of `Product`, in element order: the
/// offsets 8 e + 2 a of its elements e (a: its place in e), node n's at
/// `offsets[start[n]..start[n + 1]]`.
struct NodeEntries {
    start: Vec<usize>,
    offsets: Vec<usize>,
}

impl NodeEntries {
    fn new(nodes: &[[u32; 4]], count: usize) -> NodeEntries {
        let mut start = vec![0; count + 1];
        for &n in nodes.iter().flatten() {
            start[n as usize + 1] += 1;
        }
        for n in 0..count {
            start[n + 1] += start[n];
        }
        let mut next = start.clone();
        let mut offsets = vec![0; start[count]];
        for (e, element) in nodes.iter().enumerate() {
            for (a, &n) in element.iter().enumerate() {
                offsets[next[n as usize]] = 8 * e + 2 * a;
                next[n as usize] += 1;
            }
        }
        NodeEntries { start, offsets }
    }
}

/// The product A q of the estimate (module docs), in parallel: each element's contribution
/// s_e W K_e W q on its own, then each DOF the sum of its elements' in element order, which is
/// the order, and so the bits, of a loop adding the elements into A q one after another.
struct Product<'a> {
    nodes: &'a [[u32; 4]],
    stiffness: &'a [Option<ElementStiffness>],
    /// s_e.
    scales: &'a [f64],
    /// D^-1/2 per DOF.
    weight: &'a [f64],
    entries: NodeEntries,
}

impl Product<'_> {
    /// `out` = A q, the element contributions written into `contributions` (8 a element).
    fn apply(&self, q: &[f64], out: &mut [f64], contributions: &mut [f64]) {
        contributions
            .par_chunks_mut(8 * SPLIT)
            .enumerate()
            .for_each(|(b, c)| contributions_from(self, b * SPLIT, q, c));
        let (start, offsets) = (&self.entries.start, &self.entries.offsets);
        out.par_chunks_mut(2)
            .enumerate()
            .with_min_len(SPLIT)
            .for_each(|(n, d)| {
                let (mut x, mut y) = (0.0, 0.0);
                for &o in &offsets[start[n]..start[n + 1]] {
                    x += contributions[o];
                    y += contributions[o + 1];
                }
                d.copy_from_slice(&[x, y]);
            });
    }
}

/// The element contributions s_e W K_e W q of the elements from `first` on, 8 each, into
/// `contributions` (one task's block of `Product::apply`). Compiled twice (module
/// `explicit`, "Wider registers").
#[multiversion(targets("x86_64+avx2+fma"))]
fn contributions_from(product: &Product, first: usize, q: &[f64], contributions: &mut [f64]) {
    let weight = product.weight;
    for (i, c) in contributions.chunks_exact_mut(8).enumerate() {
        let e = first + i;
        let Some(k) = product.stiffness[e].as_ref() else {
            c.fill(0.0);
            continue;
        };
        let element = product.nodes[e];
        let s = product.scales[e];
        let dofs: [usize; 8] = std::array::from_fn(|i| 2 * element[i / 2] as usize + i % 2);
        let v: [f64; 8] = std::array::from_fn(|i| q[dofs[i]] * weight[dofs[i]]);
        for i in 0..8 {
            let row: f64 = (0..8).map(|j| k.k[i][j] * v[j]).sum();
            c[i] = s * row * weight[dofs[i]];
        }
    }
}

/// The largest Ritz value of at most `iterations` Lanczos steps on the symmetric operator
/// `apply` from `start` (full reorthogonalization), its residual norm and its unit Ritz
/// vector; the steps stop early once the residual is below `TOLERANCE` of the value. The
/// reorthogonalization is classical Gram-Schmidt twice; its dot products and vector updates
/// run in parallel over blocks of `TASK` entries in a fixed order (`dot`, `dots`,
/// `subtract`), so the bits do not depend on the thread count.
pub fn lanczos(
    mut apply: impl FnMut(&[f64], &mut [f64]),
    start: Vec<f64>,
    iterations: usize,
) -> Option<(f64, f64, Vec<f64>)> {
    let n = start.len();
    let norm = dot(&start, &start).sqrt();
    if !(norm > 0.0 && norm.is_finite()) {
        return None;
    }
    let mut basis: Vec<Vec<f64>> = vec![start.iter().map(|v| v / norm).collect()];
    let (mut alpha, mut beta) = (Vec::new(), Vec::new());
    let mut w = vec![0.0; n];
    let last = iterations.min(n).max(1) - 1;
    let ritz = loop {
        let j = alpha.len();
        apply(&basis[j], &mut w);
        alpha.push(dot(&w, &basis[j]));
        // classical Gram-Schmidt twice ("twice is enough": Giraud, Langou & Rozloznik 2005):
        // all of a pass's coefficients in one sweep over the basis
        for _ in 0..2 {
            let c = dots(&w, &basis);
            subtract(&mut w, &c, &basis);
        }
        let b = dot(&w, &w).sqrt();
        beta.push(b);
        let exhausted = !(b > 1e-12 * alpha[0].abs().max(alpha[j].abs()));
        if j == last || exhausted || j % CHECK_EVERY == CHECK_EVERY - 1 {
            let (theta, residual, s) = largest_ritz(&alpha, &beta)?;
            if j == last || exhausted || residual <= TOLERANCE * theta.abs() {
                break (theta, residual, s);
            }
        }
        basis.push(w.par_iter().with_min_len(SPLIT).map(|v| v / b).collect());
    };
    let (theta, residual, s) = ritz;
    let mut vector = vec![0.0; n];
    let minus: Vec<f64> = s.iter().map(|c| -c).collect();
    subtract(&mut vector, &minus, &basis);
    Some((theta, residual, vector))
}

/// Lanczos steps between two looks at the Ritz value.
const CHECK_EVERY: usize = 5;

/// The residual, relative to the Ritz value, at which the Lanczos steps stop.
const TOLERANCE: f64 = 1e-4;

/// The largest eigenvalue of the tridiagonal matrix of diagonal `alpha` and off-diagonal
/// `beta` (its last entry the next step's coefficient), the residual `beta_m |s_m|` and the
/// eigenvector `s`.
fn largest_ritz(alpha: &[f64], beta: &[f64]) -> Option<(f64, f64, Vec<f64>)> {
    let m = alpha.len();
    let eigen = tridiagonal_eigen(alpha, beta);
    let (top, theta) = eigen
        .eigenvalues
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    let s: Vec<f64> = eigen.eigenvectors.column(top).iter().copied().collect();
    let residual = beta[m - 1] * s[m - 1].abs();
    theta.is_finite().then_some((theta, residual, s))
}

/// a . b: each block of `TASK` entries summed on its own task ([`block_dot`]), the blocks'
/// sums then in block order, so the bits do not depend on the thread count.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let blocks: Vec<f64> = (a.par_chunks(TASK).zip(b.par_chunks(TASK)))
        .map(|(a, b)| block_dot(a, b))
        .collect();
    blocks.iter().sum()
}

/// a . b over one block (b at least as long as a) in four interleaved sums, which do not wait
/// on each other's additions as one running sum does. Compiled twice (module `explicit`,
/// "Wider registers").
#[multiversion(targets("x86_64+avx2+fma"))]
fn block_dot(a: &[f64], b: &[f64]) -> f64 {
    let mut sums = [0.0; 4];
    let (a4, b4) = (a.chunks_exact(4), b[..a.len()].chunks_exact(4));
    let (a_rest, b_rest) = (a4.remainder(), b4.remainder());
    for (a, b) in a4.zip(b4) {
        for k in 0..4 {
            sums[k] += a[k] * b[k];
        }
    }
    let rest: f64 = a_rest.iter().zip(b_rest).map(|(a, b)| a * b).sum();
    (sums[0] + sums[1]) + (sums[2] + sums[3]) + rest
}

/// q . w for every q of `basis`, in one sweep: the blocks as in [`dot`].
fn dots(w: &[f64], basis: &[Vec<f64>]) -> Vec<f64> {
    let blocks: Vec<Vec<f64>> = w
        .par_chunks(TASK)
        .enumerate()
        .map(|(k, w)| {
            let at = k * TASK;
            basis.iter().map(|q| block_dot(w, &q[at..])).collect()
        })
        .collect();
    let mut sums = vec![0.0; basis.len()];
    for block in &blocks {
        sums.iter_mut().zip(block).for_each(|(s, b)| *s += b);
    }
    sums
}

/// w -= sum_q c_q q, each entry taking the q in basis order.
fn subtract(w: &mut [f64], c: &[f64], basis: &[Vec<f64>]) {
    (w.par_chunks_mut(SPLIT).enumerate()).for_each(|(k, w)| subtract_block(w, k * SPLIT, c, basis));
}

/// `subtract` on the entries of `w` from `at` on (one task's block). Compiled twice (module
/// `explicit`, "Wider registers").
#[multiversion(targets("x86_64+avx2+fma"))]
fn subtract_block(w: &mut [f64], at: usize, c: &[f64], basis: &[Vec<f64>]) {
    for (c, q) in c.iter().zip(basis) {
        w.iter_mut().zip(&q[at..]).for_each(|(w, q)| *w -= c * q);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// A grid of `nx` x `ny` elements with random positive semi-definite stiffnesses
    /// (B^T B, B 4 x 8: three zero-energy modes and more, as a one-point element has) and
    /// random lumped masses in [0.5, 1.5]; the nodes, the stiffnesses and the node count.
    fn random_mesh(
        nx: usize,
        ny: usize,
        seed: u64,
    ) -> (Vec<[u32; 4]>, Vec<ElementStiffness>, usize) {
        let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let node = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
        let mut nodes = Vec::new();
        let mut stiffness = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                nodes.push([
                    node(i, j),
                    node(i + 1, j),
                    node(i + 1, j + 1),
                    node(i, j + 1),
                ]);
                let b: Vec<[f64; 8]> = (0..4)
                    .map(|_| std::array::from_fn(|_| 2.0 * next() - 1.0))
                    .collect();
                let k = std::array::from_fn(|r| {
                    std::array::from_fn(|c| b.iter().map(|row| row[r] * row[c]).sum())
                });
                let lumped = std::array::from_fn(|_| 0.5 + next());
                stiffness.push(ElementStiffness { k, lumped });
            }
        }
        (nodes, stiffness, (nx + 1) * (ny + 1))
    }

    /// The assembled stiffness and the diagonal lumped mass of a mesh.
    fn assemble(
        nodes: &[[u32; 4]],
        stiffness: &[ElementStiffness],
        count: usize,
    ) -> (DMatrix<f64>, Vec<f64>) {
        let mut k = DMatrix::zeros(2 * count, 2 * count);
        let mut m = vec![0.0; 2 * count];
        for (element, s) in nodes.iter().zip(stiffness) {
            let dofs: [usize; 8] = std::array::from_fn(|i| 2 * element[i / 2] as usize + i % 2);
            for i in 0..8 {
                m[dofs[i]] += s.lumped[i / 2];
                for j in 0..8 {
                    k[(dofs[i], dofs[j])] += s.k[i][j];
                }
            }
        }
        (k, m)
    }

    fn estimate_of(nodes: &[[u32; 4]], stiffness: &[ElementStiffness]) -> (f64, f64) {
        let mut global = Global::new(nodes.len());
        for (e, s) in stiffness.iter().enumerate() {
            global.keep(e, Some(s.clone()));
        }
        let element_max = stiffness
            .iter()
            .map(ElementStiffness::frequency_squared)
            .fold(0.0, f64::max);
        let share = global.ratio(nodes, |_| 1.0, element_max, 0.02);
        (share * element_max, element_max)
    }

    /// Goal: the estimate is the mesh's highest eigenvalue, below the largest element's.
    /// Setup: random 6 x 5 meshes (random element stiffnesses and masses). Reference: the
    /// largest eigenvalue of the assembled D^-1/2 K D^-1/2 by a dense symmetric eigensolver,
    /// to 1e-3 (the Lanczos steps stop at a residual of 1e-4 of the value; the first estimate
    /// starts from a pseudo-random vector); Irons' inequality, the largest element
    /// eigenvalue at or above it.
    #[test]
    fn the_estimate_is_the_assembled_mesh_highest_eigenvalue() {
        for seed in 1..=8 {
            let (nodes, stiffness, count) = random_mesh(6, 5, seed);
            let (k, m) = assemble(&nodes, &stiffness, count);
            let a = DMatrix::from_fn(k.nrows(), k.ncols(), |i, j| {
                k[(i, j)] / (m[i] * m[j]).sqrt()
            });
            let exact = a.symmetric_eigenvalues().max();
            let (estimate, element_max) = estimate_of(&nodes, &stiffness);
            assert!(
                (estimate / exact - 1.0).abs() < 1e-3,
                "seed {seed}: {estimate} against {exact}"
            );
            assert!(exact <= element_max * (1.0 + 1e-12), "seed {seed}: Irons");
            assert!(
                estimate < 0.95 * element_max,
                "seed {seed}: {estimate} against the elements' {element_max}"
            );
        }
    }

    /// Goal: the estimate is the limit of central difference on the mesh, not a lucky margin.
    /// Setup: random 6 x 5 meshes, u'' = -M^-1 K u from a random displacement at rest, stepped
    /// by central difference at 0.95 and at 1.05 times 2 / sqrt(estimate), 3000 steps.
    /// Reference: central difference on a linear system is stable iff omega_max dt <= 2: at
    /// 0.95 the displacement stays within 100 times its start (it is bounded), at 1.05 it
    /// grows past 1e6 times.
    #[test]
    fn central_difference_is_stable_below_the_estimate_and_unstable_above() {
        for seed in 1..=4 {
            let (nodes, stiffness, count) = random_mesh(6, 5, seed);
            let (k, m) = assemble(&nodes, &stiffness, count);
            let (estimate, _) = estimate_of(&nodes, &stiffness);
            let start = nalgebra::DVector::from_vec(start_vector(2 * count));
            let largest = |factor: f64| {
                let dt = factor * 2.0 / estimate.sqrt();
                let (mut previous, mut u) = (start.clone(), start.clone());
                let mut largest: f64 = 0.0;
                for _ in 0..3000 {
                    let force = &k * &u;
                    let next = nalgebra::DVector::from_fn(u.len(), |i, _| {
                        2.0 * u[i] - previous[i] - dt * dt * force[i] / m[i]
                    });
                    (previous, u) = (u, next);
                    largest = largest.max(u.amax() / start.amax());
                }
                largest
            };
            let below = largest(0.95);
            let above = largest(1.05);
            assert!(below < 100.0, "seed {seed}: {below} at 0.95");
            assert!(above > 1e6, "seed {seed}: {above} at 1.05");
        }
    }
}
