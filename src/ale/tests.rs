//! The remap against closed forms: linear fields exactly, conservation to round-off, the
//! order on a smooth field, no new extrema on a step; the smoother's rules.

use super::geometry::moments;
use super::topology::tests::grid;
use super::*;
use approx::assert_relative_eq;

/// A small deterministic generator (the tests need repeatable scatter, not quality).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64) / ((1u64 << 53) as f64) - 0.5
    }
}

/// An n x n grid on [1, 2] x [0, 1] (off the axis, so axisymmetry weighs it), its interior
/// nodes scattered by `scatter` h, and a second position of the interior nodes moved by up
/// to `motion` h from the first.
fn meshes(
    n: usize,
    scatter: f64,
    motion: f64,
    seed: u64,
) -> (Topology, Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let (cells, unit) = grid(n, n);
    let t = Topology::new(&cells, unit.len());
    let h = 1.0 / n as f64;
    let mut rng = Lcg(seed);
    let mut old: Vec<[f64; 2]> = unit.iter().map(|p| [1.0 + p[0] * h, p[1] * h]).collect();
    for (k, p) in old.iter_mut().enumerate() {
        if !t.on_boundary[k] {
            *p = [
                p[0] + scatter * h * rng.next(),
                p[1] + scatter * h * rng.next(),
            ];
        }
    }
    let new = old
        .iter()
        .enumerate()
        .map(|(k, p)| {
            if t.on_boundary[k] {
                *p
            } else {
                [
                    p[0] + 2.0 * motion * h * rng.next(),
                    p[1] + 2.0 * motion * h * rng.next(),
                ]
            }
        })
        .collect();
    (t, old, new)
}

/// A linear field's means are its values at the weighted centroids; remapped they must be the
/// values at the new centroids (the reconstruction and the swept integrals are exact on it).
#[test]
fn a_linear_field_is_remapped_exactly() {
    for axisymmetric in [false, true] {
        let (t, old, new) = meshes(8, 0.3, 0.2, 7);
        let sweep = Sweep::new(&t, &old, &new, axisymmetric);
        let field = |c: [f64; 2]| 2.0 + 3.0 * c[0] - c[1];
        let mut values: Vec<f64> = sweep.old.iter().map(|m| field(m.centroid())).collect();
        sweep.remap_intensive(&t, &mut values, 1);
        for (v, m) in values.iter().zip(&sweep.new) {
            assert_relative_eq!(*v, field(m.centroid()), epsilon = 1e-12);
        }
    }
}

/// Mass and the volume integral of an intensive field are conserved to round-off, whatever
/// the field (each flux leaves one element and enters another).
#[test]
fn mass_and_integrals_are_conserved_to_round_off() {
    let (t, old, new) = meshes(10, 0.3, 0.25, 11);
    let sweep = Sweep::new(&t, &old, &new, true);
    let mut rng = Lcg(3);
    let mut mass: Vec<f64> = sweep
        .old
        .iter()
        .map(|m| m.volume * (7800.0 + 500.0 * rng.next()))
        .collect();
    let before: f64 = mass.iter().sum();
    sweep.remap_mass(&t, &mut mass);
    assert_relative_eq!(mass.iter().sum::<f64>(), before, max_relative = 1e-14);
    let mut values: Vec<f64> = (0..mass.len()).map(|_| rng.next()).collect();
    let integral: f64 = values
        .iter()
        .zip(&sweep.old)
        .map(|(v, m)| v * m.volume)
        .sum();
    sweep.remap_intensive(&t, &mut values, 1);
    let volume = sweep.volume_in(&t);
    let after: f64 = values.iter().zip(&volume).map(|(v, m)| v * m).sum();
    assert_relative_eq!(
        after,
        integral,
        epsilon = 1e-14 * volume.iter().sum::<f64>()
    );
}

/// The mean of `f` over element e of positions x by 3 x 3 Gauss on the bilinear map (plane).
fn exact_mean(t: &Topology, x: &[[f64; 2]], e: usize, f: impl Fn([f64; 2]) -> f64) -> f64 {
    let p = t.corners(x, e);
    let (g, w) = (
        [-(0.6f64).sqrt(), 0.0, (0.6f64).sqrt()],
        [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0],
    );
    let (mut sum, mut volume) = (0.0, 0.0);
    for (i, xi) in g.iter().enumerate() {
        for (j, eta) in g.iter().enumerate() {
            let n = [
                (1.0 - xi) * (1.0 - eta),
                (1.0 + xi) * (1.0 - eta),
                (1.0 + xi) * (1.0 + eta),
                (1.0 - xi) * (1.0 + eta),
            ]
            .map(|v| v / 4.0);
            let dxi = [-(1.0 - eta), 1.0 - eta, 1.0 + eta, -(1.0 + eta)].map(|v| v / 4.0);
            let deta = [-(1.0 - xi), -(1.0 + xi), 1.0 + xi, 1.0 - xi].map(|v| v / 4.0);
            let at = |d: [f64; 4], k: usize| (0..4).map(|a| d[a] * p[a][k]).sum::<f64>();
            let jac = at(dxi, 0) * at(deta, 1) - at(dxi, 1) * at(deta, 0);
            let point = [at(n, 0), at(n, 1)];
            sum += w[i] * w[j] * jac * f(point);
            volume += w[i] * w[j] * jac;
        }
    }
    sum / volume
}

/// A smooth field remapped n / 4 times while the mesh moves by a smooth field of fixed size
/// (each remap moves it by about 0.3 h): the mean error falls as h^2 (second order; the donor
/// cell alone, the limiter everywhere at zero, gives h).
#[test]
fn a_smooth_field_converges_at_second_order() {
    let f = |p: [f64; 2]| (3.0 * p[0]).sin() * (2.0 * p[1]).cos();
    let error = |n: usize| {
        let (cells, unit) = grid(n, n);
        let t = Topology::new(&cells, unit.len());
        let h = 1.0 / n as f64;
        let start: Vec<[f64; 2]> = unit.iter().map(|p| [1.0 + p[0] * h, p[1] * h]).collect();
        let pi = std::f64::consts::PI;
        let remaps = n / 4;
        let at = |k: usize| -> Vec<[f64; 2]> {
            start
                .iter()
                .map(|p| {
                    let s = 0.075
                        * (k as f64 / remaps as f64)
                        * (pi * (p[0] - 1.0)).sin()
                        * (pi * p[1]).sin();
                    [p[0] + s, p[1] + 0.5 * s]
                })
                .collect()
        };
        let mut values: Vec<f64> = (0..cells.len())
            .map(|e| exact_mean(&t, &start, e, f))
            .collect();
        for k in 0..remaps {
            Sweep::new(&t, &at(k), &at(k + 1), false).remap_intensive(&t, &mut values, 1);
        }
        let end = at(remaps);
        let sweep = Sweep::new(&t, &end, &end, false);
        let total: f64 = sweep.new.iter().map(|m| m.volume).sum();
        (0..cells.len())
            .map(|e| (values[e] - exact_mean(&t, &end, e, f)).abs() * sweep.new[e].volume)
            .sum::<f64>()
            / total
    };
    let (coarse, fine) = (error(32), error(64));
    let order = (coarse / fine).log2();
    // the limiter clips at the field's extrema, which costs a little of the order there
    assert!(order > 1.8, "order {order} ({coarse:e} -> {fine:e})");
}

/// A step field stays within its bounds: no new extrema.
#[test]
fn a_step_gets_no_new_extrema() {
    for seed in 1..6 {
        let (t, old, new) = meshes(12, 0.3, 0.25, seed);
        let sweep = Sweep::new(&t, &old, &new, seed % 2 == 0);
        let mut values: Vec<f64> = sweep
            .old
            .iter()
            .map(|m| {
                if m.centroid()[0] + 0.3 * m.centroid()[1] < 1.6 {
                    1.0
                } else {
                    0.0
                }
            })
            .collect();
        sweep.remap_intensive(&t, &mut values, 1);
        for v in &values {
            assert!((-1e-12..=1.0 + 1e-12).contains(v), "new extremum {v}");
        }
    }
}

/// The corner masses of each element on positions x, density `rho` (a lumped mass share
/// proportional to the corner's quarter, enough for the momentum identities).
fn corners(t: &Topology, x: &[[f64; 2]], mass: &[f64]) -> Vec<[f64; 4]> {
    (0..t.cells.len())
        .map(|e| {
            let p = t.corners(x, e);
            let c = moments(&p, false).centroid();
            let w: Vec<f64> = p.iter().map(|q| 1.0 + 0.1 * (q[0] - c[0])).collect();
            let s: f64 = w.iter().sum();
            [0, 1, 2, 3].map(|a| mass[e] * w[a] / s)
        })
        .collect()
}

/// The momentum remap conserves the momentum to round-off, keeps a uniform velocity uniform
/// and leaves every velocity as it was when the mesh does not move.
#[test]
fn the_momentum_remap_conserves_and_keeps_uniform_motion() {
    let (t, old, new) = meshes(9, 0.3, 0.25, 5);
    let sweep = Sweep::new(&t, &old, &new, true);
    let mut mass: Vec<f64> = sweep.old.iter().map(|m| 7800.0 * m.volume).collect();
    let before = corners(&t, &old, &mass);
    let flux = sweep.remap_mass(&t, &mut mass);
    let after = corners(&t, &new, &mass);
    let momentum = |c: &[[f64; 4]], v: &[f64]| -> [f64; 2] {
        let mut p = [0.0; 2];
        for (e, cell) in t.cells.iter().enumerate() {
            for a in 0..4 {
                p[0] += c[e][a] * v[2 * cell[a]];
                p[1] += c[e][a] * v[2 * cell[a] + 1];
            }
        }
        p
    };
    let mut rng = Lcg(9);
    let mut v: Vec<f64> = (0..2 * t.nodes).map(|_| rng.next()).collect();
    let p0 = momentum(&before, &v);
    remap_velocity(&t, &sweep, (&before, &after), &flux, &mut v);
    let p1 = momentum(&after, &v);
    let scale: f64 = mass.iter().sum();
    assert_relative_eq!(p1[0], p0[0], epsilon = 1e-14 * scale);
    assert_relative_eq!(p1[1], p0[1], epsilon = 1e-14 * scale);
    let mut uniform: Vec<f64> = (0..t.nodes).flat_map(|_| [3.0, -2.0]).collect();
    remap_velocity(&t, &sweep, (&before, &after), &flux, &mut uniform);
    for pair in uniform.chunks(2) {
        assert_relative_eq!(pair[0], 3.0, epsilon = 1e-12);
        assert_relative_eq!(pair[1], -2.0, epsilon = 1e-12);
    }
    let still = Sweep::new(&t, &old, &old, true);
    let mut w: Vec<f64> = (0..2 * t.nodes).map(|_| rng.next()).collect();
    let copy = w.clone();
    let zero = vec![0.0; t.edges.len()];
    remap_velocity(&t, &still, (&before, &before), &zero, &mut w);
    for (a, b) in w.iter().zip(&copy) {
        assert_relative_eq!(*a, *b, epsilon = 1e-14);
    }
}

/// On a square grid with one interior node pushed off, the volume smoother moves it back
/// toward the centre of its elements; a boundary node slides along its straight edge, a corner
/// and a held node stay, a support's component stays.
#[test]
fn the_smoother_restores_a_pushed_node_and_respects_the_boundary() {
    let (cells, mut x) = grid(4, 4);
    let t = Topology::new(&cells, x.len());
    x[12] = [2.3, 2.2]; // interior node (2, 2) pushed
    x[2] = [2.3, 0.0]; // bottom node pushed along its edge
    let mut held = vec![false; x.len()];
    held[6] = true; // interior node (1, 1)
    let mut fixed = vec![[false; 2]; x.len()];
    fixed[10] = [true, false]; // left edge node (0, 2): x fixed, as on an axis
    let rules = Rules {
        smoother: Smoother::Volume,
        max_move: 1.0,
        slide_angle: 1e-3,
    };
    let y = smooth(
        &t,
        &x,
        &Freedom {
            held: &held,
            fixed: &fixed,
        },
        &rules,
    );
    assert!(
        (y[12][0] - 2.0).abs() < 0.3 && (y[12][1] - 2.0).abs() < 0.2,
        "{:?}",
        y[12]
    );
    assert_eq!(y[2][1], 0.0, "a bottom node stays on the bottom");
    assert!(y[2][0] < 2.3, "and slides back toward the middle");
    assert_eq!(y[0], x[0], "a corner stays");
    assert_eq!(y[6], x[6], "a held node stays");
    assert_eq!(y[10][0], 0.0, "a fixed component stays");
    for e in 0..cells.len() {
        assert!(moments(&t.corners(&y, e), false).volume > 0.0);
    }
}
