//! Property tests of the Quad4 kernel on random valid (convex, counter-clockwise) shapes:
//! a symmetric stiffness, exactly three zero-energy modes with 2x2 Gauss, and invariance
//! under rigid motion (a finite rigid rotation plus translation strains nothing; the
//! stiffness of a moved element is the rotated stiffness).

use impact::element::quad4::{self, Coords};
use impact::element::{Formulation, GeometricStiffness, Mat8, Moduli, Strain, Vec8};
use impact::material::{Elastic, StressCondition};
use proptest::prelude::*;

fn moduli() -> Moduli {
    Elastic {
        young: 210.0,
        poisson: 0.3,
    }
    .moduli(StressCondition::General)
}

/// A convex counter-clockwise quad: the unit square's corners moved by up to 0.3, scaled,
/// rotated and translated; None when the perturbation made it non-convex.
fn shape(offsets: [f64; 8], scale: f64, angle: f64, shift: [f64; 2]) -> Option<Coords> {
    let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let (s, c) = angle.sin_cos();
    let x: Coords = std::array::from_fn(|i| {
        let p = [
            square[i][0] + offsets[2 * i],
            square[i][1] + offsets[2 * i + 1],
        ];
        [
            shift[0] + scale * (c * p[0] - s * p[1]),
            shift[1] + scale * (s * p[0] + c * p[1]),
        ]
    });
    let convex = (0..4).all(|i| {
        let (a, b, c) = (x[i], x[(i + 1) % 4], x[(i + 2) % 4]);
        (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]) > 1e-3 * scale * scale
    });
    convex.then_some(x)
}

fn op(bbar: bool) -> quad4::Operator {
    quad4::Operator {
        strain: Strain::Finite,
        bbar,
    }
}

fn stiffness(x: &Coords, bbar: bool, stress: [f64; 4]) -> Mat8 {
    let geom = quad4::values(x, Formulation::PlaneStrain, &[1.0; 4]).expect("valid shape");
    let s = impact::element::Voigt::new(stress[0], stress[1], stress[2], stress[3]);
    quad4::tangent(
        &geom,
        &Vec8::zeros(),
        &[s; 4],
        &[moduli(); 4],
        op(bbar),
        GeometricStiffness::Included,
    )
}

fn quad() -> impl Strategy<Value = Coords> {
    (
        prop::array::uniform8(-0.3f64..0.3),
        0.01f64..100.0,
        0.0f64..std::f64::consts::TAU,
        prop::array::uniform2(-50.0f64..50.0),
    )
        .prop_filter_map("convex", |(o, scale, angle, shift)| {
            shape(o, scale, angle, shift)
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, failure_persistence: None, ..ProptestConfig::default() })]

    /// K_0 (and K_0 + K_sigma) is symmetric to round-off.
    #[test]
    fn quad4_stiffness_is_symmetric(x in quad(), bbar: bool, stress in prop::array::uniform4(-5.0f64..5.0)) {
        let k = stiffness(&x, bbar, stress);
        let scale = k.abs().max();
        prop_assert!((k - k.transpose()).abs().max() <= 1e-12 * scale);
    }

    /// Exactly three zero eigenvalues (two translations, one rotation): full 2x2 Gauss
    /// has no hourglass modes, with or without B-bar.
    #[test]
    fn quad4_has_exactly_three_zero_energy_modes(x in quad(), bbar: bool) {
        let k = stiffness(&x, bbar, [0.0; 4]);
        let eigen = k.symmetric_eigen();
        let max = eigen.eigenvalues.abs().max();
        let zero = eigen.eigenvalues.iter().filter(|l| l.abs() <= 1e-10 * max).count();
        let positive = eigen.eigenvalues.iter().filter(|l| **l > 1e-6 * max).count();
        prop_assert_eq!(zero, 3, "eigenvalues {:?}", eigen.eigenvalues);
        prop_assert_eq!(positive, 5, "eigenvalues {:?}", eigen.eigenvalues);
    }

    /// A finite rigid rotation plus translation of the nodes strains nothing (Green-Lagrange
    /// increment zero to round-off); a prestressed element's internal force turns with it:
    /// f(x, rigid increment, S_0) = T f(x, 0, S_0) and f(moved, 0, R S_0 R^T) = T f(x, 0, S_0)
    /// (T: the rotation at each node); the stiffness of the moved element is T K T^T.
    /// Tolerances: coordinates up to ~1e2 against elements down to 1e-2 lose about four
    /// digits in the shape-function gradients (1e-12 relative); 1e-9 keeps a margin.
    #[test]
    fn quad4_is_invariant_under_rigid_motion(
        x in quad(),
        angle in -3.0f64..3.0,
        shift in prop::array::uniform2(-10.0f64..10.0),
        bbar: bool,
        stress in prop::array::uniform4(-5.0f64..5.0),
    ) {
        let geom = quad4::values(&x, Formulation::PlaneStrain, &[1.0; 4]).unwrap();
        let (s, c) = angle.sin_cos();
        let mut d = Vec8::zeros();
        let mut moved = x;
        for i in 0..4 {
            let [px, py] = x[i];
            let r = [c * px - s * py + shift[0], s * px + c * py + shift[1]];
            d[2 * i] = r[0] - px;
            d[2 * i + 1] = r[1] - py;
            moved[i] = r;
        }
        let size = x.iter().flatten().fold(1.0f64, |m, v| m.max(v.abs()));
        for strain in quad4::strains(&geom, &d, op(bbar)) {
            prop_assert!(strain.abs().max() <= 1e-11 * size * size, "strain {:?}", strain);
        }
        let s0 = impact::element::Voigt::new(stress[0], stress[1], stress[2], stress[3]);
        let r = stress_rotated(stress, angle);
        let s_moved = impact::element::Voigt::new(r[0], r[1], r[2], r[3]);
        let geom_moved = quad4::values(&moved, Formulation::PlaneStrain, &[1.0; 4]).unwrap();
        let f0 = quad4::internal_force(&geom, &Vec8::zeros(), &[s0; 4], op(bbar));
        let f_rigid = quad4::internal_force(&geom, &d, &[s0; 4], op(bbar));
        let f_moved =
            quad4::internal_force(&geom_moved, &Vec8::zeros(), &[s_moved; 4], op(bbar));
        let k = stiffness(&x, bbar, stress);
        let k_moved = stiffness(&moved, bbar, stress_rotated(stress, angle));
        let mut t = Mat8::zeros();
        for i in 0..4 {
            t[(2 * i, 2 * i)] = c;
            t[(2 * i, 2 * i + 1)] = -s;
            t[(2 * i + 1, 2 * i)] = s;
            t[(2 * i + 1, 2 * i + 1)] = c;
        }
        let expected = t * k * t.transpose();
        prop_assert!((k_moved - expected).abs().max() <= 1e-9 * k.abs().max());
        let f_turned = t * f0;
        let scale = f0.abs().max().max(f64::MIN_POSITIVE);
        prop_assert!((f_rigid - f_turned).abs().max() <= 1e-9 * scale, "{:?} vs {:?}", f_rigid, f_turned);
        prop_assert!((f_moved - f_turned).abs().max() <= 1e-9 * scale, "{:?} vs {:?}", f_moved, f_turned);
    }
}

/// The stress [xx yy zz xy] seen in axes rotated by `angle`: R S R^T.
fn stress_rotated(s: [f64; 4], angle: f64) -> [f64; 4] {
    let (sn, c) = angle.sin_cos();
    let [xx, yy, zz, xy] = s;
    [
        c * c * xx - 2.0 * sn * c * xy + sn * sn * yy,
        sn * sn * xx + 2.0 * sn * c * xy + c * c * yy,
        zz,
        sn * c * (xx - yy) + (c * c - sn * sn) * xy,
    ]
}
