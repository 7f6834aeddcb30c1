//! Four-node quadrilateral, 2x2 Gauss, updated Lagrangian (Erklig et al. 2010, eqs 9-34).
//!
//! Legend (one Gauss point; derivatives with respect to the reference configuration X,
//! the last converged one)
//! ```text
//! d         element displacement increment [u1 v1 u2 v2 u3 v3 u4 v4] since the reference
//! theta     slope vector [u,x  u,y  v,x  v,y] = G d                      (Erklig eq 12, 17)
//! hoop      u_r / r (axisymmetric only)
//! dE        Green-Lagrange strain increment [xx yy zz xy]
//!           = B_s d + 1/2 A(theta) theta  (+ hoop: u/r + 1/2 (u/r)^2)     (Erklig eq 9, 24)
//! B         dE/dd = B_s + B_L(theta),  B_L = A(theta) G                  (Erklig eq 21, 22)
//! S         second Piola-Kirchhoff stress relative to the reference configuration
//! K_0       sum w B^T D B                                                 (Erklig eq 33)
//! K_sigma   sum w G^T S G (+ hoop S_zz N_i N_j / r^2)                      (Erklig eq 34)
//! w         reference volume of the point: det J (x 2 pi r | x thickness | x 1)
//! ```
//! B-bar (mean dilatation, Hughes 1980) replaces the trace of dE by its volume average over
//! the element: dE_bar = dE + 1/3 (avg(tr dE) - tr dE) m, m = [1 1 1 0]. Its exact
//! linearization adds (tr S / 3)(avg(M) - M) to K_sigma, M = d^2 tr(dE) / dd^2, so the
//! tangent stays the exact derivative of the internal force (checked by finite differences).

use super::{
    Formulation, GeometricStiffness, KernelError, Mat4, Mat8, Moduli, Strain, Vec8, Voigt,
};
use multiversion::multiversion;
use nalgebra::{Matrix2, SMatrix};
use std::f64::consts::PI;

/// Node coordinates, counter-clockwise.
pub type Coords = [[f64; 2]; 4];
type BMatrix = SMatrix<f64, 4, 8>;

const GAUSS: f64 = 0.577_350_269_189_625_8; // 1 / sqrt(3)
/// Gauss points in the order of the nodes: (-,-), (+,-), (+,+), (-,+).
pub const POINTS: [[f64; 2]; 4] = [
    [-GAUSS, -GAUSS],
    [GAUSS, -GAUSS],
    [GAUSS, GAUSS],
    [-GAUSS, GAUSS],
];
const NODE_SIGNS: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// Shape functions and their reference derivatives at one Gauss point.
#[derive(Debug, Clone, Copy)]
pub struct PointValues {
    pub shape: [f64; 4],
    /// dN_i/dX, dN_i/dY
    pub dndx: [[f64; 2]; 4],
    /// Radius of the point (x coordinate); used by axisymmetric bodies.
    pub radius: f64,
    /// Reference volume of the point (see the legend).
    pub weight: f64,
}

#[derive(Debug, Clone, Copy)]
pub struct QuadValues {
    pub points: [PointValues; 4],
    pub formulation: Formulation,
}

impl QuadValues {
    pub fn volume(&self) -> f64 {
        self.points.iter().map(|p| p.weight).sum()
    }
}

const fn shape(xi: f64, eta: f64) -> ([f64; 4], [[f64; 2]; 4]) {
    let mut n = [0.0; 4];
    let mut dn = [[0.0; 2]; 4];
    let mut i = 0;
    while i < 4 {
        let [si, ti] = NODE_SIGNS[i];
        n[i] = 0.25 * (1.0 + si * xi) * (1.0 + ti * eta);
        dn[i] = [0.25 * si * (1.0 + ti * eta), 0.25 * ti * (1.0 + si * xi)];
        i += 1;
    }
    (n, dn)
}

/// The shape functions and their derivatives at the four Gauss points.
const TABLES: [([f64; 4], [[f64; 2]; 4]); 4] = [
    shape(POINTS[0][0], POINTS[0][1]),
    shape(POINTS[1][0], POINTS[1][1]),
    shape(POINTS[2][0], POINTS[2][1]),
    shape(POINTS[3][0], POINTS[3][1]),
];

/// Shape-function derivatives, radii and point volumes on the reference configuration `x`.
/// `thickness` is per Gauss point and used only in plane stress.
#[inline(always)]
pub fn values(
    x: &Coords,
    formulation: Formulation,
    thickness: &[f64; 4],
) -> Result<QuadValues, KernelError> {
    let mut points = [PointValues {
        shape: [0.0; 4],
        dndx: [[0.0; 2]; 4],
        radius: 0.0,
        weight: 0.0,
    }; 4];
    for (q, (n, dn)) in TABLES.iter().enumerate() {
        // J_ab = dX_a / dxi_b
        let jac = |a: usize, b: usize| {
            x[0][a] * dn[0][b] + x[1][a] * dn[1][b] + x[2][a] * dn[2][b] + x[3][a] * dn[3][b]
        };
        let (j00, j01, j10, j11) = (jac(0, 0), jac(0, 1), jac(1, 0), jac(1, 1));
        let det = j00 * j11 - j10 * j01;
        if !(det > 0.0) {
            return Err(KernelError::NegativeJacobian { point: q, det });
        }
        // J^-1 = [[j11 -j01] [-j10 j00]] / det (one division, four products)
        let inv_det = 1.0 / det;
        let inv = [
            [j11 * inv_det, -j01 * inv_det],
            [-j10 * inv_det, j00 * inv_det],
        ];
        let p = &mut points[q];
        for i in 0..4 {
            // dN/dX_a = dN/dxi_b (J^-1)_ba
            p.dndx[i] = [
                dn[i][0] * inv[0][0] + dn[i][1] * inv[1][0],
                dn[i][0] * inv[0][1] + dn[i][1] * inv[1][1],
            ];
        }
        let radius = n[0] * x[0][0] + n[1] * x[1][0] + n[2] * x[2][0] + n[3] * x[3][0];
        p.weight = match formulation {
            Formulation::PlaneStrain => det,
            Formulation::PlaneStress => det * thickness[q],
            Formulation::Axisymmetric => {
                if !(radius > 0.0) {
                    return Err(KernelError::NonPositiveRadius { point: q, radius });
                }
                det * 2.0 * PI * radius
            }
        };
        p.shape = *n;
        p.radius = radius;
    }
    Ok(QuadValues {
        points,
        formulation,
    })
}

/// The strains and strain operators of one point for a given increment d.
struct PointStrain {
    /// [u,x u,y v,x v,y]
    theta: [f64; 4],
    /// u_r / r (zero unless axisymmetric)
    hoop: f64,
    strain: Voigt,
    b: BMatrix,
}

impl PointStrain {
    const ZERO: PointStrain = PointStrain {
        theta: [0.0; 4],
        hoop: 0.0,
        strain: Voigt::new(0.0, 0.0, 0.0, 0.0),
        b: BMatrix::from_array_storage(nalgebra::ArrayStorage([[0.0; 4]; 8])),
    };
}

/// One point's displacement gradient, hoop strain and Green-Lagrange strain increment.
#[derive(Debug, Clone, Copy)]
struct PointGradient {
    /// [u,x u,y v,x v,y]
    theta: [f64; 4],
    /// u_r / r (zero unless axisymmetric)
    hoop: f64,
    strain: Voigt,
}

#[inline(always)]
fn point_gradient(
    p: &PointValues,
    d: &Vec8,
    formulation: Formulation,
    geometry: Strain,
) -> PointGradient {
    let mut theta = [0.0; 4];
    for i in 0..4 {
        let [nx, ny] = p.dndx[i];
        theta[0] += nx * d[2 * i];
        theta[1] += ny * d[2 * i];
        theta[2] += nx * d[2 * i + 1];
        theta[3] += ny * d[2 * i + 1];
    }
    let hoop = if formulation == Formulation::Axisymmetric {
        (0..4).map(|i| p.shape[i] * d[2 * i]).sum::<f64>() / p.radius
    } else {
        0.0
    };
    // Nonlinear parts switched off by a zero factor in linear kinematics.
    let nl = if geometry == Strain::Finite { 1.0 } else { 0.0 };
    let [ux, uy, vx, vy] = theta;
    let strain = Voigt::new(
        ux + 0.5 * nl * (ux * ux + vx * vx),
        vy + 0.5 * nl * (uy * uy + vy * vy),
        hoop + 0.5 * nl * hoop * hoop,
        uy + vx + nl * (ux * uy + vx * vy),
    );
    PointGradient {
        theta,
        hoop,
        strain,
    }
}

/// F = I + [[u,x u,y] [v,x v,y]] and the hoop stretch 1 + u/r.
fn stretches(theta: &[f64; 4], hoop: f64) -> (Matrix2<f64>, f64) {
    let [ux, uy, vx, vy] = *theta;
    (Matrix2::new(1.0 + ux, uy, vx, 1.0 + vy), 1.0 + hoop)
}

/// A point's displacement gradient, strain and B operator, written into `out`, whose
/// operator entries that stay zero (the hoop row off the axisymmetric case, the v columns of
/// the hoop row) must be zero already. Compiled twice, as `tangent` is.
#[multiversion(targets("x86_64+avx2+fma"))]
fn point_strain_into(
    p: &PointValues,
    d: &Vec8,
    formulation: Formulation,
    geometry: Strain,
    out: &mut PointStrain,
) {
    let PointGradient {
        theta,
        hoop,
        strain,
    } = point_gradient(p, d, formulation, geometry);
    let axisymmetric = formulation == Formulation::Axisymmetric;
    let nl = if geometry == Strain::Finite { 1.0 } else { 0.0 };
    let [ux, uy, vx, vy] = theta;
    out.theta = theta;
    out.hoop = hoop;
    out.strain = strain;
    let b = &mut out.b;
    for i in 0..4 {
        let [nx, ny] = p.dndx[i];
        let (cu, cv) = (2 * i, 2 * i + 1);
        b[(0, cu)] = nx * (1.0 + nl * ux);
        b[(0, cv)] = nx * nl * vx;
        b[(1, cu)] = ny * nl * uy;
        b[(1, cv)] = ny * (1.0 + nl * vy);
        if axisymmetric {
            b[(2, cu)] = p.shape[i] / p.radius * (1.0 + nl * hoop);
        }
        b[(3, cu)] = ny * (1.0 + nl * ux) + nx * nl * uy;
        b[(3, cv)] = nx * (1.0 + nl * vy) + ny * nl * vx;
    }
}

/// The four points' gradients and strains without their operators B: what a residual
/// needs where B-bar leaves the operator alone. Its internal force is B^T S with B's
/// entries written out, node by node: with a = S_xx N,x + S_xy N,y and
/// b = S_xy N,x + S_yy N,y,
/// ```text
/// f_u = w [(1 + u,x) a + u,y b + S_zz (N / r)(1 + u/r)],   f_v = w [v,x a + (1 + v,y) b]
/// ```
/// (the nonlinear factors zero in linear kinematics, the hoop term only axisymmetric): a
/// few products a node instead of the 4 x 8 operator formed and multiplied.
pub struct Gradients {
    points: [PointGradient; 4],
    geometry: Strain,
}

impl Gradients {
    #[inline]
    pub fn new(geom: &QuadValues, d: &Vec8, geometry: Strain) -> Gradients {
        let point = |q: usize| point_gradient(&geom.points[q], d, geom.formulation, geometry);
        Gradients {
            points: [point(0), point(1), point(2), point(3)],
            geometry,
        }
    }

    pub fn strains(&self) -> [Voigt; 4] {
        std::array::from_fn(|q| self.points[q].strain)
    }

    pub fn deformation(&self) -> [(Matrix2<f64>, f64); 4] {
        std::array::from_fn(|q| stretches(&self.points[q].theta, self.points[q].hoop))
    }

    /// f = sum_q w_q B_q^T S_q, as [`internal_force`] forms it with the operators.
    pub fn internal_force(&self, geom: &QuadValues, stress: &[Voigt; 4]) -> Vec8 {
        let nl = if self.geometry == Strain::Finite {
            1.0
        } else {
            0.0
        };
        let axisymmetric = geom.formulation == Formulation::Axisymmetric;
        let mut f = Vec8::zeros();
        for (q, (p, g)) in geom.points.iter().zip(&self.points).enumerate() {
            let s = &stress[q];
            let [ux, uy, vx, vy] = g.theta;
            let hoop = if axisymmetric {
                s[2] * (1.0 + nl * g.hoop) / p.radius
            } else {
                0.0
            };
            for i in 0..4 {
                let [nx, ny] = p.dndx[i];
                let a = s[0] * nx + s[3] * ny;
                let b = s[3] * nx + s[1] * ny;
                f[2 * i] += p.weight * ((1.0 + nl * ux) * a + nl * uy * b + hoop * p.shape[i]);
                f[2 * i + 1] += p.weight * (nl * vx * a + (1.0 + nl * vy) * b);
            }
        }
        f
    }
}

/// How a Quad4 body forms its strains: small or finite strain, and the volumetric part
/// standard or averaged over the element (B-bar, mean dilatation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Operator {
    pub strain: Strain,
    pub bbar: bool,
}

/// The four points' strains and strain operators of an increment, B-bar applied when the
/// operator asks: computed once per element evaluation and shared by the strains, the
/// internal force and the tangent.
pub struct StrainOperators {
    points: [PointStrain; 4],
}

impl StrainOperators {
    #[inline]
    pub fn new(geom: &QuadValues, d: &Vec8, op: Operator) -> StrainOperators {
        let mut kin = StrainOperators {
            points: [PointStrain::ZERO; 4],
        };
        // filled in place: a map over the points copied the 1.3 kB array several times
        for (k, p) in kin.points.iter_mut().zip(&geom.points) {
            point_strain_into(p, d, geom.formulation, op.strain, k);
        }
        if op.bbar {
            kin.average_volumetric(geom);
        }
        kin
    }

    /// B-bar: the volumetric part of each point's strain and operator replaced by its
    /// volume mean.
    fn average_volumetric(&mut self, geom: &QuadValues) {
        let k = &mut self.points;
        let volume = geom.volume();
        let mut mean_trace = 0.0;
        let mut mean_b = SMatrix::<f64, 1, 8>::zeros();
        for (p, kp) in geom.points.iter().zip(k.iter()) {
            mean_trace += p.weight * trace(&kp.strain) / volume;
            mean_b += (kp.b.row(0) + kp.b.row(1) + kp.b.row(2)) * (p.weight / volume);
        }
        for kp in k.iter_mut() {
            let dev_trace = (mean_trace - trace(&kp.strain)) / 3.0;
            let dev_b = (mean_b - (kp.b.row(0) + kp.b.row(1) + kp.b.row(2))) / 3.0;
            for r in 0..3 {
                kp.strain[r] += dev_trace;
                let row = kp.b.row(r) + dev_b;
                kp.b.set_row(r, &row);
            }
        }
    }

    /// Green-Lagrange strain increments at the four Gauss points (zz = 0 in plane stress:
    /// the material decides it).
    pub fn strains(&self) -> [Voigt; 4] {
        std::array::from_fn(|q| self.points[q].strain)
    }

    /// As [`deformation`], from the displacement gradients already formed (B-bar changes
    /// the strains and operators, not these).
    pub fn deformation(&self) -> [(Matrix2<f64>, f64); 4] {
        std::array::from_fn(|q| stretches(&self.points[q].theta, self.points[q].hoop))
    }
}

fn trace(v: &Voigt) -> f64 {
    v[0] + v[1] + v[2]
}

/// Green-Lagrange strain increments at the four Gauss points (zz = 0 in plane stress: the
/// material decides it).
pub fn strains(geom: &QuadValues, d: &Vec8, op: Operator) -> [Voigt; 4] {
    StrainOperators::new(geom, d, op).strains()
}

/// In-plane deformation gradient F = I + [[u,x u,y] [v,x v,y]] and the hoop stretch 1 + u/r
/// (1 unless axisymmetric) at the four Gauss points.
pub fn deformation(geom: &QuadValues, d: &Vec8) -> [(Matrix2<f64>, f64); 4] {
    let op = Operator {
        strain: Strain::Finite,
        bbar: false,
    };
    StrainOperators::new(geom, d, op).deformation()
}

/// Internal force f = sum_q w_q B_q^T S_q (Erklig eq 25).
pub fn internal_force(geom: &QuadValues, kin: &StrainOperators, stress: &[Voigt; 4]) -> Vec8 {
    let k = &kin.points;
    let mut f = Vec8::zeros();
    for q in 0..4 {
        f += k[q].b.transpose() * stress[q] * geom.points[q].weight;
    }
    f
}

/// Tangent K_T = K_0 + K_sigma (Erklig eqs 32-34), the exact derivative of `internal_force`
/// for the points' stresses and material moduli dS/dE (`points`); K_sigma only when
/// `geometric` includes it. Compiled twice by `multiversion`, for baseline x86-64 and for
/// AVX2 and FMA, chosen at run time: the same operations in the same order, the same bits
/// (docs/performance.md, "Wider registers where the processor has them").
#[multiversion(targets("x86_64+avx2+fma"))]
pub fn tangent(
    geom: &QuadValues,
    kin: &StrainOperators,
    (stress, moduli): (&[Voigt; 4], &[Moduli; 4]),
    op: Operator,
    geometric: GeometricStiffness,
) -> Mat8 {
    let k = &kin.points;
    // K_T is symmetric (the moduli are): the upper triangle is summed, then mirrored
    let mut kt = Mat8::zeros();
    for q in 0..4 {
        let b = &k[q].b;
        let dbw = (moduli[q] * b) * geom.points[q].weight;
        for j in 0..8 {
            for i in 0..=j {
                let column = b.column(i);
                let other = dbw.column(j);
                kt[(i, j)] += column[0] * other[0]
                    + column[1] * other[1]
                    + column[2] * other[2]
                    + column[3] * other[3];
            }
        }
    }
    if op.strain == Strain::Finite && geometric == GeometricStiffness::Included {
        add_geometric(geom, stress, op.bbar, &mut kt);
    }
    for j in 0..8 {
        for i in 0..j {
            kt[(j, i)] = kt[(i, j)];
        }
    }
    kt
}

/// K_sigma (and B-bar's correction), upper triangle only. (Inlined into `tangent`, whose
/// target features it then takes.)
#[inline(always)]
fn add_geometric(geom: &QuadValues, stress: &[Voigt; 4], bbar: bool, kt: &mut Mat8) {
    let axisymmetric = geom.formulation == Formulation::Axisymmetric;
    // the B-bar correction's point matrices M: the vv block's (the in-plane gradients), and
    // the uu block's, which adds the hoop strain's N_i N_j / r^2 in axisymmetry
    let mut ms = [[[0.0; 4]; 4]; 4];
    let mut hoops = [[[0.0; 4]; 4]; 4];
    for q in 0..4 {
        let p = &geom.points[q];
        let s = &stress[q];
        for j in 0..4 {
            let [xj, yj] = p.dndx[j];
            let (sx, sy) = (s[0] * xj + s[3] * yj, s[3] * xj + s[1] * yj);
            for i in 0..=j {
                let [xi, yi] = p.dndx[i];
                let g = xi * sx + yi * sy;
                let mut guu = g;
                if axisymmetric {
                    let nn = p.shape[i] * p.shape[j] / (p.radius * p.radius);
                    guu += s[2] * nn;
                    hoops[q][i][j] = nn;
                }
                kt[(2 * i, 2 * j)] += p.weight * guu;
                kt[(2 * i + 1, 2 * j + 1)] += p.weight * g;
                ms[q][i][j] = xi * xj + yi * yj;
            }
        }
    }
    if bbar {
        // (tr S / 3) (avg(M) - M) at each point, for the uu and the vv block
        let volume = geom.volume();
        let correction = |m: &dyn Fn(usize) -> f64| -> f64 {
            let mean: f64 = (0..4).map(|q| m(q) * geom.points[q].weight / volume).sum();
            (0..4)
                .map(|q| (mean - m(q)) * geom.points[q].weight * trace(&stress[q]) / 3.0)
                .sum()
        };
        for j in 0..4 {
            for i in 0..=j {
                let vv = correction(&|q| ms[q][i][j]);
                let uu = vv + correction(&|q| hoops[q][i][j]);
                kt[(2 * i, 2 * j)] += uu;
                kt[(2 * i + 1, 2 * j + 1)] += vv;
            }
        }
    }
}

/// An upper bound of the element's highest frequency squared: for every displacement u,
/// u . K u <= omega^2 u . M u, with K = sum_q w_q B_q^T D B_q (standard or B-bar, small
/// strain operators on the current configuration), D isotropic with Lame constants
/// (`lambda`, `mu`) (plane stress: the condensed lambda 2 lambda mu / (lambda + 2 mu)) and M
/// the lumped mass `lumped` at the four nodes. At each point, with mass-weighted sums
/// X = sum_a N_a,x^2 / m_a, Y = sum_a N_a,y^2 / m_a, H = sum_a (N_a / r)^2 / m_a and
/// XH = sum_a (N_a,x + N_a / r)^2 / m_a (H = 0 and XH = X off the axisymmetric case),
/// ```text
/// omega^2 <= sum_q w_q [lambda (XH + Y) + mu (X + Y) + 2 mu max(X + H, Y)]
/// ```
/// by Cauchy-Schwarz on each strain component of the energy lambda tr^2 + 2 mu e:e (and
/// by Jensen's inequality B-bar's averaged volumetric strain stores no more energy than the
/// points' own). docs/theory.md 8.7 gives the derivation.
pub fn frequency_bound(values: &QuadValues, lambda: f64, mu: f64, lumped: &[f64; 4]) -> f64 {
    let axisymmetric = values.formulation == Formulation::Axisymmetric;
    let mut bound = 0.0;
    for p in &values.points {
        let (mut x, mut y, mut h, mut xh) = (0.0, 0.0, 0.0, 0.0);
        for a in 0..4 {
            let [nx, ny] = p.dndx[a];
            let inv = 1.0 / lumped[a];
            x += nx * nx * inv;
            y += ny * ny * inv;
            if axisymmetric {
                let nh = p.shape[a] / p.radius;
                h += nh * nh * inv;
                xh += (nx + nh) * (nx + nh) * inv;
            }
        }
        if !axisymmetric {
            xh = x;
        }
        bound += p.weight * (lambda * (xh + y) + mu * (x + y) + 2.0 * mu * (x + h).max(y));
    }
    bound
}

/// Consistent mass per unit density, the same for both directions: M_ij = sum w N_i N_j.
pub fn mass(geom: &QuadValues) -> Mat4 {
    let mut m = Mat4::zeros();
    for p in &geom.points {
        for i in 0..4 {
            for j in 0..4 {
                m[(i, j)] += p.weight * p.shape[i] * p.shape[j];
            }
        }
    }
    m
}
/// The Green-Lagrange strain (E_XX, E_YY, E_XY, tensor shear) at the centre (xi = eta = 0) of
/// a quad with nodes at `reference` (initial) and `current`, counter-clockwise: H = grad_X u
/// there, E = (H + H^T + H^T H) / 2 (the frames' cell strain; the out-of-plane part is the
/// formulation's).
pub fn centre_green_strain(reference: &[[f64; 2]; 4], current: &[[f64; 2]; 4]) -> [f64; 3] {
    // dN/dxi and dN/deta at the centre, nodes counter-clockwise
    let dxi = [-0.25, 0.25, 0.25, -0.25];
    let deta = [-0.25, -0.25, 0.25, 0.25];
    let mut jacobian = [[0.0; 2]; 2]; // dX_i / d(xi, eta)_j
    let mut du = [[0.0; 2]; 2]; // du_i / d(xi, eta)_j
    for (a, (x0, x)) in reference.iter().zip(current).enumerate() {
        for i in 0..2 {
            let displacement = x[i] - x0[i];
            jacobian[i][0] += x0[i] * dxi[a];
            jacobian[i][1] += x0[i] * deta[a];
            du[i][0] += displacement * dxi[a];
            du[i][1] += displacement * deta[a];
        }
    }
    let det = jacobian[0][0] * jacobian[1][1] - jacobian[0][1] * jacobian[1][0];
    // d(xi, eta) / dX = J^-1
    let inverse = [
        [jacobian[1][1] / det, -jacobian[0][1] / det],
        [-jacobian[1][0] / det, jacobian[0][0] / det],
    ];
    let h: [[f64; 2]; 2] = std::array::from_fn(|i| {
        std::array::from_fn(|j| du[i][0] * inverse[0][j] + du[i][1] * inverse[1][j])
    });
    let green =
        |i: usize, j: usize| 0.5 * (h[i][j] + h[j][i] + h[0][i] * h[0][j] + h[1][i] * h[1][j]);
    [green(0, 0), green(1, 1), green(0, 1)]
}

/// Consistent nodal forces [fa_x fa_y fb_x fb_y] of a constant traction `t` (force per unit
/// reference length; per unit area in plane stress with `thickness`, per unit area of the
/// surface of revolution in axisymmetry) on the straight edge a -> b.
pub fn edge_force(
    a: [f64; 2],
    b: [f64; 2],
    t: [f64; 2],
    formulation: Formulation,
    thickness: f64,
) -> [f64; 4] {
    let length = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
    let (wa, wb) = match formulation {
        Formulation::PlaneStrain => (0.5 * length, 0.5 * length),
        Formulation::PlaneStress => (0.5 * length * thickness, 0.5 * length * thickness),
        // integral of N_a 2 pi r ds with r linear along the edge
        Formulation::Axisymmetric => (
            2.0 * PI * length * (2.0 * a[0] + b[0]) / 6.0,
            2.0 * PI * length * (a[0] + 2.0 * b[0]) / 6.0,
        ),
    };
    [wa * t[0], wa * t[1], wb * t[0], wb * t[1]]
}

/// Outward unit normal of the edge a -> b of a body that lies on its left.
pub fn outward_normal(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let length = (dx * dx + dy * dy).sqrt();
    [dy / length, -dx / length]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::Moduli;

    fn distorted() -> Coords {
        [[1.0, 0.1], [2.2, -0.1], [2.0, 1.3], [0.9, 0.8]]
    }

    fn moduli() -> Moduli {
        let (lambda, mu) = (1.2, 0.8);
        let mut d = Moduli::zeros();
        for a in 0..3 {
            for b in 0..3 {
                d[(a, b)] = lambda;
            }
            d[(a, a)] += 2.0 * mu;
        }
        d[(3, 3)] = mu;
        d
    }

    fn stress_of(strain: &Voigt, s0: &Voigt) -> Voigt {
        s0 + moduli() * strain
    }

    /// Both forms of the internal force, from the operators (B^T S) and from the gradients
    /// alone (`Gradients`), are the derivative of the potential sum_q w_q (s0 . E_q +
    /// 1/2 E_q . D E_q) whose stress is S = s0 + D E (central differences, h = 1e-6:
    /// truncation O(h^2), round-off eps |P| / h ~ 1e-10; the band of the tangent's test),
    /// and agree with each other to round-off.
    #[test]
    fn internal_force_is_the_derivative_of_the_potential() {
        let d = Vec8::from_fn(|i, _| 0.05 * ((i as f64) * 1.3).cos());
        let s0 = Voigt::new(0.3, -0.2, 0.1, 0.15);
        for form in [
            Formulation::PlaneStrain,
            Formulation::PlaneStress,
            Formulation::Axisymmetric,
        ] {
            for strain in [Strain::Finite, Strain::Small] {
                let op = Operator {
                    strain,
                    bbar: false,
                };
                let geom = values(&distorted(), form, &[0.7; 4]).unwrap();
                let potential = |d: &Vec8| -> f64 {
                    let e = strains(&geom, d, op);
                    (0..4)
                        .map(|q| {
                            geom.points[q].weight
                                * (s0.dot(&e[q]) + 0.5 * e[q].dot(&(moduli() * e[q])))
                        })
                        .sum()
                };
                let stress = strains(&geom, &d, op).map(|e| stress_of(&e, &s0));
                let with_operators =
                    internal_force(&geom, &StrainOperators::new(&geom, &d, op), &stress);
                let from_gradients =
                    Gradients::new(&geom, &d, strain).internal_force(&geom, &stress);
                let h = 1e-6;
                for j in 0..8 {
                    let (mut dp, mut dm) = (d, d);
                    dp[j] += h;
                    dm[j] -= h;
                    let derivative = (potential(&dp) - potential(&dm)) / (2.0 * h);
                    for f in [with_operators[j], from_gradients[j]] {
                        approx::assert_abs_diff_eq!(
                            f,
                            derivative,
                            epsilon = 1e-7 * (1.0 + derivative.abs())
                        );
                    }
                    approx::assert_abs_diff_eq!(
                        with_operators[j],
                        from_gradients[j],
                        epsilon = 1e-13 * (1.0 + derivative.abs())
                    );
                }
            }
        }
    }

    /// The tangent is the derivative of the internal force (central differences, h = 1e-6:
    /// truncation O(h^2) ~ 1e-12, round-off eps |f| / h ~ 1e-9 for forces ~ 10; 1e-7 of
    /// 1 + |entry| keeps a margin of 100 over both).
    #[test]
    fn tangent_matches_finite_differences_of_internal_force() {
        let d = Vec8::from_fn(|i, _| 0.05 * ((i as f64) * 1.7).sin());
        // a different initial stress at each point: B-bar makes the trace of D E uniform
        // over the element, so only a non-uniform tr S exercises its correction's
        // point-to-point part (where the axisymmetric hoop term once went to both blocks)
        let s0: [Voigt; 4] = std::array::from_fn(|q| {
            Voigt::new(0.3, -0.2, 0.1, 0.15) + (q as f64) * Voigt::new(0.1, 0.05, -0.2, 0.03)
        });
        let stresses =
            |e: [Voigt; 4]| -> [Voigt; 4] { std::array::from_fn(|q| stress_of(&e[q], &s0[q])) };
        for form in [
            Formulation::PlaneStrain,
            Formulation::PlaneStress,
            Formulation::Axisymmetric,
        ] {
            for bbar in [false, true] {
                let op = Operator {
                    strain: Strain::Finite,
                    bbar,
                };
                let geom = values(&distorted(), form, &[0.7; 4]).unwrap();
                let force = |d: &Vec8| {
                    let e = strains(&geom, d, op);
                    let kin = StrainOperators::new(&geom, d, op);
                    internal_force(&geom, &kin, &stresses(e))
                };
                let e = strains(&geom, &d, op);
                let kt = tangent(
                    &geom,
                    &StrainOperators::new(&geom, &d, op),
                    (&stresses(e), &[moduli(); 4]),
                    op,
                    GeometricStiffness::Included,
                );
                let h = 1e-6;
                for j in 0..8 {
                    let mut dp = d;
                    let mut dm = d;
                    dp[j] += h;
                    dm[j] -= h;
                    let col = (force(&dp) - force(&dm)) / (2.0 * h);
                    for i in 0..8 {
                        approx::assert_abs_diff_eq!(
                            kt[(i, j)],
                            col[i],
                            epsilon = 1e-7 * (1.0 + col[i].abs())
                        );
                    }
                }
                // (symmetric by construction now: the lower triangle is the mirrored upper
                // one, checked above against the derivative like the rest)
            }
        }
    }

    /// A rigid translation gives no strain, no force; volume of the reference element is its area.
    #[test]
    fn rigid_translation_is_strain_free() {
        let geom = values(&distorted(), Formulation::PlaneStrain, &[1.0; 4]).unwrap();
        let d = Vec8::from_fn(|i, _| if i % 2 == 0 { 0.3 } else { -0.7 });
        let op = Operator {
            strain: Strain::Finite,
            bbar: true,
        };
        for e in strains(&geom, &d, op) {
            assert!(e.norm() < 1e-14);
        }
        // shoelace area of the quad
        let x = distorted();
        let area: f64 = (0..4)
            .map(|i| x[i][0] * x[(i + 1) % 4][1] - x[(i + 1) % 4][0] * x[i][1])
            .sum::<f64>()
            / 2.0;
        approx::assert_relative_eq!(geom.volume(), area, max_relative = 1e-14);
    }

    #[test]
    fn inverted_element_is_an_error() {
        let mut x = distorted();
        x.swap(1, 3);
        assert!(matches!(
            values(&x, Formulation::PlaneStrain, &[1.0; 4]),
            Err(KernelError::NegativeJacobian { .. })
        ));
    }
}
