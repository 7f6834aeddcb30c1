//! Property tests of the Quad4 kernel on random valid (convex, counter-clockwise) shapes:
//! a symmetric stiffness, exactly three zero-energy modes with 2x2 Gauss, and invariance
//! under rigid motion (a finite rigid rotation plus translation strains nothing; the
//! stiffness of a moved element is the rotated stiffness).

mod common;

use impact::element::quad4::{self, Coords};
use impact::element::{Formulation, GeometricStiffness, Mat8, Moduli, Strain, Vec8};
use impact::material::{Elastic, StressCondition};
use proptest::prelude::*;

fn moduli() -> Moduli {
    Elastic::new(210.0, 0.3).moduli(StressCondition::General)
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
        &quad4::StrainOperators::new(&geom, &Vec8::zeros(), op(bbar)),
        (&[s; 4], &[moduli(); 4]),
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

    /// K_0 (and K_0 + K_sigma) is symmetric to round-off. Tolerance 1e-12 of the largest
    /// entry: each entry is a sum over four Gauss points of products of O(1) shape-function
    /// derivatives, so the two triangles differ by a few ulps (2.2e-16) times the terms summed.
    #[test]
    fn quad4_stiffness_is_symmetric(x in quad(), bbar: bool, stress in prop::array::uniform4(-5.0f64..5.0)) {
        let k = stiffness(&x, bbar, stress);
        let scale = k.abs().max();
        prop_assert!((k - k.transpose()).abs().max() <= 1e-12 * scale);
    }

    /// Exactly three zero eigenvalues (two translations, one rotation): full 2x2 Gauss
    /// has no hourglass modes, with or without B-bar. Zero means below 1e-10 of the largest
    /// eigenvalue (the symmetric eigensolver's error is ~1e-15 of it, and a rigid mode's
    /// eigenvalue is round-off); positive means above 1e-6: the shapes are convex with aspect
    /// and skew bounded by `quad()`, whose smallest deformation eigenvalue stays well above that
    /// (a missed mode would show as a fourth eigenvalue near 1e-16).
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
        let force = |geom: &quad4::QuadValues, d: &Vec8, s: impact::element::Voigt| {
            quad4::internal_force(geom, &quad4::StrainOperators::new(geom, d, op(bbar)), &[s; 4])
        };
        let f0 = force(&geom, &Vec8::zeros(), s0);
        let f_rigid = force(&geom, &d, s0);
        let f_moved = force(&geom_moved, &Vec8::zeros(), s_moved);
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

/// A quad that may be crushed: a random convex shape squashed along y by a factor down to
/// 1e-3 (the foot of a Taylor bar), placed at a distance from the axis between 1e-3 and 10
/// of its width (for axisymmetric bodies).
fn crushed_quad() -> impl Strategy<Value = (Coords, f64)> {
    (quad(), -3.0f64..0.0, -3.0f64..1.0).prop_map(|(x, squash, offset)| {
        let factor = 10f64.powf(squash);
        let min_x = x.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min);
        let width = x.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max) - min_x;
        let shift = 10f64.powf(offset) * width - min_x;
        (x.map(|[a, b]| [a + shift, b * factor]), factor)
    })
}

/// The largest eigenvalue of M^-1 K for a lumped (diagonal) M given per node.
fn max_frequency_squared(k: &Mat8, lumped: &[f64; 4]) -> f64 {
    let scaled = Mat8::from_fn(|i, j| k[(i, j)] / (lumped[i / 2] * lumped[j / 2]).sqrt());
    let symmetric = (scaled + scaled.transpose()) * 0.5;
    symmetric.symmetric_eigenvalues().max()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, failure_persistence: None, ..ProptestConfig::default() })]

    /// Goal: the central-difference stable step of the 2x2 Quad4 is safe on distorted and
    /// crushed elements. Setup: random convex quads squashed down to 1e-3, plane strain,
    /// plane stress and axisymmetric (from near the axis to far from it), B-bar or not,
    /// nu from 0 to 0.499. Reference: the element's exact highest frequency squared, the
    /// largest eigenvalue of M^-1 K with K the kernel's small-strain tangent (checked against
    /// finite differences elsewhere) and M its lumped (row-sum) mass. The bound must not be
    /// below it (1e-9 for round-off) and is never more than 16 times it (measured: 1.2 to 8).
    #[test]
    fn quad4_frequency_bound_exceeds_the_element_frequency(
        (x, _) in crushed_quad(),
        nu in 0.0f64..0.499,
        bbar: bool,
        form in 0usize..3,
    ) {
        let formulation = [Formulation::PlaneStrain, Formulation::PlaneStress, Formulation::Axisymmetric][form];
        let elastic = Elastic::new(1.0, nu);
        let condition = if formulation == Formulation::PlaneStress {
            StressCondition::PlaneStress
        } else {
            StressCondition::General
        };
        let geom = quad4::values(&x, formulation, &[1.0; 4]).unwrap();
        let op = quad4::Operator { strain: Strain::Small, bbar };
        let kin = quad4::StrainOperators::new(&geom, &Vec8::zeros(), op);
        let k = quad4::tangent(&geom, &kin, (&[impact::element::Voigt::zeros(); 4],
            &[elastic.moduli(condition); 4]), op, GeometricStiffness::Omitted);
        let m = quad4::mass(&geom);
        let lumped: [f64; 4] = std::array::from_fn(|i| m.row(i).sum());
        let exact = max_frequency_squared(&k, &lumped);
        let (lambda, mu) = elastic.lame_in(condition);
        let bound = quad4::frequency_bound(&geom, lambda, mu, &lumped);
        prop_assert!(bound >= exact * (1.0 - 1e-9), "bound {bound} below {exact}");
        prop_assert!(bound <= 16.0 * exact, "bound {bound} far above {exact}");
    }

    /// Goal: the stable step of the one-point Quad4 with its hourglass stiffness is safe on
    /// distorted and crushed elements. Setup: as above (plane strain), hourglass coefficient
    /// kappa from 0 to 1. Reference: the largest eigenvalue of M^-1 (K_1 + K_hg) built here
    /// from the centroid gradient b: K_1 = A B^T D B (B of the gradient, D of E and nu),
    /// K_hg = k gamma gamma^T in each direction, k = kappa (lambda + 3 mu) A b.b / 24, with
    /// the element's lumped mass. The bound is not below it (1e-9) and not far above.
    #[test]
    fn one_point_frequency_bound_exceeds_the_element_frequency(
        (x, _) in crushed_quad(),
        nu in 0.0f64..0.499,
        kappa in 0.0f64..1.0,
    ) {
        use impact::element::quad4_one_point as one_point;
        let (young, rho) = (1.0, 1.0);
        let lambda = young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = young / (2.0 * (1.0 + nu));
        let g = one_point::centroid_gradient(&x);
        let gamma = one_point::gamma(&x, &g);
        let mut b = nalgebra::SMatrix::<f64, 3, 8>::zeros();
        for a in 0..4 {
            b[(0, 2 * a)] = g.bx[a];
            b[(1, 2 * a + 1)] = g.by[a];
            b[(2, 2 * a)] = g.by[a];
            b[(2, 2 * a + 1)] = g.bx[a];
        }
        let d = nalgebra::Matrix3::new(lambda + 2.0 * mu, lambda, 0.0, lambda, lambda + 2.0 * mu, 0.0, 0.0, 0.0, mu);
        let mut k = b.transpose() * d * b * g.area;
        let bb: f64 = (0..4).map(|a| g.bx[a] * g.bx[a] + g.by[a] * g.by[a]).sum();
        let hourglass = kappa * (lambda + 3.0 * mu) / 24.0;
        let stiffness = hourglass * g.area * bb;
        for a in 0..4 {
            for c in 0..4 {
                for dir in 0..2 {
                    k[(2 * a + dir, 2 * c + dir)] += stiffness * gamma[a] * gamma[c];
                }
            }
        }
        let m = quad4::mass(&quad4::values(&x, Formulation::PlaneStrain, &[1.0; 4]).unwrap());
        let lumped: [f64; 4] = std::array::from_fn(|i| rho * m.row(i).sum());
        let exact = max_frequency_squared(&k, &lumped);
        let smallest = lumped.iter().copied().fold(f64::INFINITY, f64::min);
        let bound = one_point::frequency_bound(one_point::BoundShape { gradient: &g, gamma: &gamma, volume: g.area, hoop_radius: None }, lambda + 2.0 * mu, hourglass, smallest);
        prop_assert!(bound >= exact * (1.0 - 1e-9), "bound {bound} below {exact}");
        prop_assert!(bound <= 16.0 * exact, "bound {bound} far above {exact}");
    }

    /// Goal: the stable step of the axisymmetric one-point Quad4 is safe, on the axis too.
    /// Setup: crushed convex quads (as above) placed from the axis (two nodes at r = 0, the
    /// elements of a Taylor rod's axis) to ten widths out, nu from 0 to 0.499, kappa from 0
    /// to 1. Reference: the largest eigenvalue of M^-1 (K_1 + K_hg) built here: K_1 = V B^T D B
    /// with V = 2 pi r_c A, B the centroid gradient's rows rr, zz, rz and the hoop row
    /// N_a / r_c = 1 / (4 r_c) on the radial DOFs, D the isotropic 4x4 of lambda and mu;
    /// K_hg = k gamma gamma^T in each direction, k = kappa (lambda + 3 mu) V b.b / 24; M the
    /// element's lumped (row-sum) axisymmetric mass, as the kernel takes it. The bound is not
    /// below it (1e-9 for round-off) and not more than 16 times it.
    #[test]
    fn axisymmetric_one_point_frequency_bound_exceeds_the_element_frequency(
        (x, _) in crushed_quad(),
        on_axis: bool,
        nu in 0.0f64..0.499,
        kappa in 0.0f64..1.0,
    ) {
        use impact::element::quad4_one_point as one_point;
        let x = if on_axis {
            // the two nodes nearest the axis onto it (a convex quad stays convex: its
            // smallest-x edge moves left as a whole)
            let min_x = x.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min);
            let mut order: Vec<usize> = (0..4).collect();
            order.sort_by(|a, b| x[*a][0].total_cmp(&x[*b][0]));
            let mut moved = x.map(|[a, b]| [a - min_x, b]);
            moved[order[0]][0] = 0.0;
            moved[order[1]][0] = 0.0;
            moved
        } else {
            x
        };
        prop_assume!(one_point::centroid_gradient(&x).area > 0.0);
        prop_assume!(quad4::values(&x, Formulation::Axisymmetric, &[1.0; 4]).is_ok());
        let lambda = nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = 1.0 / (2.0 * (1.0 + nu));
        let g = one_point::centroid_gradient(&x);
        let gamma = one_point::gamma(&x, &g);
        let r = one_point::centroid_radius(&x);
        let volume = 2.0 * std::f64::consts::PI * r * g.area;
        let mut b = nalgebra::SMatrix::<f64, 4, 8>::zeros();
        for a in 0..4 {
            b[(0, 2 * a)] = g.bx[a];
            b[(1, 2 * a + 1)] = g.by[a];
            b[(2, 2 * a)] = 0.25 / r;
            b[(3, 2 * a)] = g.by[a];
            b[(3, 2 * a + 1)] = g.bx[a];
        }
        let mut d = nalgebra::Matrix4::<f64>::zeros();
        for i in 0..3 {
            for j in 0..3 {
                d[(i, j)] = if i == j { lambda + 2.0 * mu } else { lambda };
            }
        }
        d[(3, 3)] = mu;
        let mut k = b.transpose() * d * b * volume;
        let bb: f64 = (0..4).map(|a| g.bx[a] * g.bx[a] + g.by[a] * g.by[a]).sum();
        let hourglass = kappa * (lambda + 3.0 * mu) / 24.0;
        let stiffness = hourglass * volume * bb;
        for a in 0..4 {
            for c in 0..4 {
                for dir in 0..2 {
                    k[(2 * a + dir, 2 * c + dir)] += stiffness * gamma[a] * gamma[c];
                }
            }
        }
        let m = quad4::mass(&quad4::values(&x, Formulation::Axisymmetric, &[1.0; 4]).unwrap());
        let lumped: [f64; 4] = std::array::from_fn(|i| m.row(i).sum());
        let exact = max_frequency_squared(&k, &lumped);
        let smallest = lumped.iter().copied().fold(f64::INFINITY, f64::min);
        let bound = one_point::frequency_bound(one_point::BoundShape { gradient: &g, gamma: &gamma, volume, hoop_radius: Some(r) }, lambda + 2.0 * mu, hourglass, smallest);
        prop_assert!(bound >= exact * (1.0 - 1e-9), "bound {bound} below {exact}");
        prop_assert!(bound <= 16.0 * exact, "bound {bound} far above {exact}");
    }
}

/// One elastic element (E = 1, rho = 1) of `formulation`, run explicit with `quadrature`
/// (`reduced` with hourglass coefficient `kappa`, or `full`), its nodes moved to `x`; the
/// bulk viscosity off (the limits asserted with it are the undamped element's).
fn one_element_model(
    x: &Coords,
    formulation: &str,
    quadrature: &str,
    nu: f64,
    kappa: f64,
) -> impact::scene::Model {
    let text = format!(
        r#"
[[material]]
name = "m"
young = 1.0
poisson = {nu}
density = 1.0

[[body]]
name = "element"
material = "m"
formulation = "{formulation}"
mesh = {{ type = "rectangle", origin = [1.0, 0.0], width = 1.0, height = 1.0, nx = 1, ny = 1 }}

[analysis]
type = "dynamic"
integrator = "central_difference"
quadrature = "{quadrature}"
{hourglass}
end_time = 1.0
bulk_viscosity = "off"
"#,
        hourglass = if quadrature == "reduced" {
            format!("hourglass = {kappa}")
        } else {
            String::new()
        }
    );
    let mut model =
        impact::scene::from_str(&text, std::path::Path::new("element.toml"), &[]).unwrap();
    let body = &mut model.bodies[0];
    let cell: Vec<usize> = body.mesh.cells.nodes_of(0).to_vec();
    for (a, n) in cell.iter().enumerate() {
        body.mesh.nodes[*n] = x[a];
    }
    model
}

/// A fresh explicit kernel of `model`'s quadrature on its initial (stress-free) state.
fn explicit_kernel(
    model: &impact::scene::Model,
    quadrature: &str,
    kappa: f64,
) -> Box<dyn impact::assembly::explicit::ExplicitKernel> {
    kernel_of(model, quadrature, kappa, false)
}

/// The kernel of `explicit_kernel`, its stable step tight or from the bounds.
fn kernel_of(
    model: &impact::scene::Model,
    quadrature: &str,
    kappa: f64,
    tight: bool,
) -> Box<dyn impact::assembly::explicit::ExplicitKernel> {
    use impact::assembly::explicit::{Full, Reduced};
    use impact::scene::spec::StableStepKind;
    let state = impact::assembly::State::initial(model);
    let masses = impact::assembly::ElementMasses::new(model).unwrap();
    let kind = if tight {
        StableStepKind::Tight
    } else {
        StableStepKind::Bound
    };
    if quadrature == "reduced" {
        Box::new(Reduced::new(model, &state, kappa, &masses).with_stable_step(kind))
    } else {
        Box::new(Full::new(model, &state, &masses).with_stable_step(kind))
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, failure_persistence: None, ..ProptestConfig::default() })]

    /// Goal: the stable step that the explicit run takes is safe for the kernel that runs:
    /// each explicit kernel's frequency bound is not below the highest frequency of that
    /// kernel's own force, on distorted and crushed elements of every formulation.
    /// Setup: one elastic element (random convex shape squashed along y down to 1e-3,
    /// placed 1e-3 to 10 widths from the axis), plane strain, plane stress or axisymmetric,
    /// the one-point kernel (kappa 0 to 1) or the 2x2 rate-form kernel, nu 0 to 0.499.
    /// Reference: the largest eigenvalue of M^-1 K with K the kernel's linearized force,
    /// by central differences of its one-step force from the stress-free state (a fresh
    /// kernel for each of the 16 perturbed steps, size 1e-7 of the shortest edge: the
    /// force is linear to O(h^2 / L^2) = 1e-14 and round-off is relative), M the lumped
    /// mass the run uses. The bound must not be below it (1e-6: the differences' error)
    /// and, to stay useful, not above 16 times it.
    #[test]
    fn explicit_kernel_frequency_bound_exceeds_the_kernel_frequency(
        (x, _) in crushed_quad(),
        nu in 0.0f64..0.499,
        kappa in 0.0f64..1.0,
        form in 0usize..3,
        reduced: bool,
    ) {
        let formulation = ["plane_strain", "plane_stress", "axisymmetric"][form];
        let quadrature = if reduced { "reduced" } else { "full" };
        let model = one_element_model(&x, formulation, quadrature, nu, kappa);
        let positions = model.coordinates();
        let edge = (0..4)
            .map(|a| {
                let (p, q) = (x[a], x[(a + 1) % 4]);
                (q[0] - p[0]).hypot(q[1] - p[1])
            })
            .fold(f64::INFINITY, f64::min);
        let h = 1e-7 * edge;
        let cell: Vec<usize> = model.bodies[0].mesh.cells.nodes_of(0).to_vec();
        let dofs = model.dofs();
        let force_at = |dof: usize, sign: f64| -> Vec<f64> {
            let mut kernel = explicit_kernel(&model, quadrature, kappa);
            let mut du = vec![0.0; dofs];
            du[dof] = sign * h;
            let mut force = vec![0.0; dofs];
            kernel.step(&positions, &du, 1.0, &mut force).unwrap();
            force
        };
        let mut k = Mat8::zeros();
        for (a, node) in cell.iter().enumerate() {
            for i in 0..2 {
                let (plus, minus) = (force_at(2 * node + i, 1.0), force_at(2 * node + i, -1.0));
                for (c, other) in cell.iter().enumerate() {
                    for j in 0..2 {
                        k[(2 * c + j, 2 * a + i)] =
                            (plus[2 * other + j] - minus[2 * other + j]) / (2.0 * h);
                    }
                }
            }
        }
        let lumped_all = impact::assembly::Mass::new(&model, impact::scene::spec::MassKind::Lumped)
            .unwrap()
            .lumped;
        let lumped: [f64; 4] = std::array::from_fn(|a| lumped_all[2 * cell[a]]);
        let exact = max_frequency_squared(&k, &lumped);
        let step = explicit_kernel(&model, quadrature, kappa)
            .stable_step(&positions)
            .unwrap()
            .dt;
        // the bound's omega^2 = (2 / dt)^2 (a round-off of 1e-16 against the 1e-6 below)
        let bound = (2.0 / step).powi(2);
        prop_assert!(bound >= exact * (1.0 - 1e-6), "{formulation} {quadrature}: bound {bound} below {exact}");
        prop_assert!(bound <= 16.0 * exact, "{formulation} {quadrature}: bound {bound} far above {exact}");
        // `analysis.stable_step = "tight"`: the kernel's step is that highest frequency's
        // (1e-5: both from differences of the forces, each 1e-7 of the shortest edge)
        let tight = tight_kernel(&model, quadrature, kappa).stable_step(&positions).unwrap().dt;
        let tight = (2.0 / tight).powi(2);
        prop_assert!((tight / exact - 1.0).abs() < 1e-5, "{formulation} {quadrature}: tight {tight} against {exact}");
        // with the bulk viscosity (Abaqus' defaults b_1 = 0.06, b_2 = 1.2) the tight step at
        // rest is that limit shortened by the damping b_1 as Abaqus' Theory Manual gives it,
        // 2 / omega (sqrt(1 + xi^2) - xi)
        let viscosity = impact::element::bulk_viscosity::BulkViscosity { linear: 0.06, quadratic: 1.2 };
        let damped = viscous_tight_kernel(&model, quadrature, kappa, viscosity)
            .stable_step(&positions)
            .unwrap()
            .dt;
        let expected = 2.0 / exact.sqrt() * ((1.0f64 + 0.06 * 0.06).sqrt() - 0.06);
        prop_assert!((damped / expected - 1.0).abs() < 1e-5, "{formulation} {quadrature}: damped tight {damped} against {expected}");
    }
}

/// As `tight_kernel`, with the bulk viscosity `viscosity`.
fn viscous_tight_kernel(
    model: &impact::scene::Model,
    quadrature: &str,
    kappa: f64,
    viscosity: impact::element::bulk_viscosity::BulkViscosity,
) -> Box<dyn impact::assembly::explicit::ExplicitKernel> {
    use impact::assembly::explicit::{Full, Reduced};
    let state = impact::assembly::State::initial(model);
    let masses = impact::assembly::ElementMasses::new(model).unwrap();
    if quadrature == "reduced" {
        Box::new(
            Reduced::new(model, &state, kappa, &masses)
                .with_stable_step(impact::scene::spec::StableStepKind::Tight)
                .with_bulk_viscosity(Some(viscosity)),
        )
    } else {
        Box::new(
            Full::new(model, &state, &masses)
                .with_stable_step(impact::scene::spec::StableStepKind::Tight)
                .with_bulk_viscosity(Some(viscosity)),
        )
    }
}

/// As `explicit_kernel`, its stable step the elements' exact frequencies (`stable_step =
/// "tight"`).
fn tight_kernel(
    model: &impact::scene::Model,
    quadrature: &str,
    kappa: f64,
) -> Box<dyn impact::assembly::explicit::ExplicitKernel> {
    kernel_of(model, quadrature, kappa, true)
}

/// One free element of `model` stepped by central difference at `factor` times its tight
/// stable step from random nodal velocities (seed `seed`), `steps` steps: the largest kinetic
/// energy over the first, and the status the run ended with (the driver stops a run that
/// blows up: `unstable`).
fn kinetic_growth(
    model: &mut impact::scene::Model,
    quadrature: &str,
    kappa: f64,
    (factor, steps, seed): (f64, usize, u64),
) -> (f64, impact::analysis::Status) {
    let tight = tight_kernel(model, quadrature, kappa)
        .stable_step(&model.coordinates())
        .unwrap()
        .dt;
    let mut state = seed;
    let mut random = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    // small: the element stays linear until the growth is plain
    model.initial_velocity = (0..model.dofs()).map(|_| 1e-6 * random()).collect();
    let dt = factor * tight;
    if let impact::scene::model::Analysis::Dynamic(spec) = &mut model.analysis {
        spec.step = impact::scene::spec::TimeStep::Fixed(dt);
        spec.end_time = steps as f64 * dt;
        spec.allow_unstable = true;
        // the stability is what this measures, not the balance: a guarded run at 1.05 could
        // stop on the energy it gains before the growth is plain
        spec.energy_gain_limit = None;
    }
    let dir = common::tests_root().join(format!("tight_{quadrature}_{factor}_{seed}"));
    let status = match impact::analysis::run(model, &dir, Default::default()) {
        Ok(summary) => summary.status,
        Err(impact::analysis::RunError::Numerical { summary, .. }) => summary.status,
        Err(e) => panic!("{e}"),
    };
    let text = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let mut lines = text.lines();
    let k = lines
        .next()
        .unwrap()
        .split(',')
        .position(|c| c == "kinetic_energy")
        .unwrap();
    let kinetic: Vec<f64> = lines
        .map(|l| {
            l.split(',')
                .nth(k)
                .unwrap()
                .parse::<f64>()
                .unwrap_or(f64::INFINITY)
        })
        .collect();
    (
        kinetic.iter().copied().fold(0.0, f64::max) / kinetic[0],
        status,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, failure_persistence: None, ..ProptestConfig::default() })]

    /// Goal: the tight stable step is the element's limit, not a lucky margin: a free element
    /// stepped at 0.95 of it keeps its energy over thousands of steps, at 1.05 of it blows up.
    /// Setup: one elastic element (random convex shape squashed down to 1e-3, plane strain,
    /// plane stress or axisymmetric, the 2x2 kernel or the one-point kernel with kappa 0.05 to
    /// 1), random nodal velocities (which hold some of the highest mode), a fixed step of 0.95
    /// and 1.05 times the tight step, 2000 and 400 steps. Reference: central difference on a
    /// linear system is stable for omega dt <= 2 and its highest mode grows by a factor
    /// |1 - (omega dt)^2 / 2| + (((omega dt)^2 / 2 - 1)^2 - 1)^(1/2) per step beyond (1.88 at
    /// 1.05); the run at 0.95 ends `ok` with its kinetic energy below its start plus the strain
    /// energy it can trade (1.5 times), the run at 1.05 is stopped as blown up (status
    /// `unstable`) or its energy grows past 1e6 times.
    #[test]
    fn tight_step_is_stable_below_and_unstable_above(
        (x, _) in crushed_quad(),
        nu in 0.0f64..0.45,
        kappa in 0.05f64..1.0,
        form in 0usize..3,
        reduced: bool,
        seed in 0u64..1000,
    ) {
        let formulation = ["plane_strain", "plane_stress", "axisymmetric"][form];
        let quadrature = if reduced { "reduced" } else { "full" };
        let mut model = one_element_model(&x, formulation, quadrature, nu, kappa);
        use impact::analysis::Status;
        let (below, status) = kinetic_growth(&mut model, quadrature, kappa, (0.95, 2000, seed));
        prop_assert!(status == Status::Ok && below < 1.5, "{formulation} {quadrature}: grew {below} at 0.95 ({status:?})");
        let mut model = one_element_model(&x, formulation, quadrature, nu, kappa);
        let (above, status) = kinetic_growth(&mut model, quadrature, kappa, (1.05, 400, seed));
        prop_assert!(status == Status::Unstable || above > 1e6, "{formulation} {quadrature}: grew {above} at 1.05 ({status:?})");
    }
}
