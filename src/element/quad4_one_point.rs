//! One-point Quad4 with Flanagan-Belytschko (1981) hourglass control: the kinematics of a
//! step, the stress rotation, the hourglass forces and the nodal forces of one element
//! (docs/theory.md, "Reduced explicit Quad4"). Pure functions of one element's nodes; the
//! material update between `increment` and `hourglass` is the caller's.
//!
//! Legend (one element; x_a node positions, u_a the increment of the step, a = 1..4)
//! ```text
//! b_a        dN_a/dx at the centroid = the element mean, FB eq 13:
//!            b_x = [y2-y4, y3-y1, y4-y2, y1-y3] / 2A,  b_y = [x4-x2, x1-x3, x2-x4, x3-x1] / 2A
//! A          area, A = 1/2 ((x3-x1)(y4-y2) - (x4-x2)(y3-y1))
//! G          sum_a u_a (x) b_a(x_mid): the increment gradient on x_mid = x_n + u / 2
//! d, w       sym G (strain increment [xx yy zz xy], engineering shear), w = (G_xy - G_yx) / 2
//! R          Hughes-Winget rotation (I - W/2)^-1 (I + W/2), W = w [[0 1] [-1 0]]
//! h          [1 -1 1 -1], the hourglass base vector
//! gamma_a    h_a - (h . x) b_xa - (h . y) b_ya           (FB eq 25: orthogonal to linear fields)
//! q_i        sum_a gamma_a u_ia, the hourglass-mode increment (i = x, y)
//! Q_i        Q_{n+1} = R Q_n + k q,  k = kappa (lambda + 3 mu) t A (b . b) / 24
//!            (kappa = 1: a square element gets the hourglass stiffness of the 2x2 Gauss one)
//! f_a        t A sigma b_a + Q gamma_a, on the end configuration x_{n+1}
//! W_hg       1/2 (R Q_n + Q_{n+1}) . q
//! ```
//! Axisymmetric (x = r, y = z, zz the hoop component): the same element with its volume
//! weight 2 pi r_c in place of t (r_c the centroid radius, the mean of the node radii), the
//! hoop strain increment d_tt = (sum_a u_r,a / 4) / r_c at the centroid, and the hoop
//! stress's share of the radial forces, f_a,r += 2 pi A sigma_tt / 4 (N_a = 1/4 at the
//! centroid): one-point integration of int (B^T sigma) 2 pi r dA, volume-weighted like the
//! mass, so momentum is kept exactly.

use super::KernelError;

/// The four nodes of an element, counter-clockwise.
pub type Nodes = [[f64; 2]; 4];

/// How an element's area becomes a volume.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Section {
    /// Plane strain or plane stress: the thickness (1 per unit depth in plane strain).
    Plane { thickness: f64 },
    /// 2 pi r_c, r_c the centroid radius.
    Axisymmetric,
}

/// The centroid radius of an element (the mean of its node radii: N_a = 1/4 there).
#[inline(always)]
pub fn centroid_radius(x: &Nodes) -> f64 {
    0.25 * (x[0][0] + x[1][0] + x[2][0] + x[3][0])
}

impl Section {
    /// The volume per unit area on the configuration x: t, or 2 pi r_c.
    #[inline(always)]
    pub fn weight(&self, x: &Nodes) -> f64 {
        match *self {
            Section::Plane { thickness } => thickness,
            Section::Axisymmetric => 2.0 * std::f64::consts::PI * centroid_radius(x),
        }
    }
}

const HOURGLASS: [f64; 4] = [1.0, -1.0, 1.0, -1.0];

/// The centroid gradient of an element: its area and b_x, b_y (see the legend).
#[derive(Debug, Clone, Copy)]
pub struct Gradient {
    pub area: f64,
    pub bx: [f64; 4],
    pub by: [f64; 4],
}

/// Area, b_x, b_y (see the legend).
#[inline(always)]
pub fn centroid_gradient(x: &Nodes) -> Gradient {
    let area = area(x);
    let s = 0.5 / area;
    let bx = [
        s * (x[1][1] - x[3][1]),
        s * (x[2][1] - x[0][1]),
        s * (x[3][1] - x[1][1]),
        s * (x[0][1] - x[2][1]),
    ];
    let by = [
        s * (x[3][0] - x[1][0]),
        s * (x[0][0] - x[2][0]),
        s * (x[1][0] - x[3][0]),
        s * (x[2][0] - x[0][0]),
    ];
    Gradient { area, bx, by }
}

/// The area of the quadrilateral x (half the cross product of its diagonals; negative when
/// inverted).
#[inline(always)]
pub fn area(x: &Nodes) -> f64 {
    0.5 * ((x[2][0] - x[0][0]) * (x[3][1] - x[1][1]) - (x[3][0] - x[1][0]) * (x[2][1] - x[0][1]))
}

/// FB's gamma vector (see the legend).
#[inline(always)]
pub fn gamma(x: &Nodes, g: &Gradient) -> [f64; 4] {
    let hx: f64 = (0..4).map(|a| HOURGLASS[a] * x[a][0]).sum();
    let hy: f64 = (0..4).map(|a| HOURGLASS[a] * x[a][1]).sum();
    std::array::from_fn(|a| HOURGLASS[a] - hx * g.bx[a] - hy * g.by[a])
}

/// Rotates the in-plane part of a symmetric tensor [xx yy zz xy] by R = [[c s] [-s c]].
#[inline(always)]
pub fn rotate(t: &[f64; 4], c: f64, s: f64) -> [f64; 4] {
    let (a, b, x) = (t[0], t[1], t[3]);
    [
        c * c * a + 2.0 * c * s * x + s * s * b,
        s * s * a - 2.0 * c * s * x + c * c * b,
        t[2],
        c * s * (b - a) + (c * c - s * s) * x,
    ]
}

/// The kinematics of one step of an element: the mid-step gradient, the strain increment
/// and the Hughes-Winget rotation (cos, sin), and the end configuration.
#[derive(Debug, Clone, Copy)]
pub struct Increment {
    pub mid: Nodes,
    pub end: Nodes,
    pub gradient: Gradient,
    /// [xx yy zz xy], zz = 0 (the material decides it in plane stress).
    pub strain: [f64; 4],
    pub cos: f64,
    pub sin: f64,
}

/// The step of an element from positions `x` by the increment `u` (see the legend); the
/// hoop strain of an axisymmetric one.
#[inline(always)]
pub fn increment(x: &Nodes, u: &Nodes, section: Section) -> Result<Increment, KernelError> {
    let mid: Nodes = std::array::from_fn(|a| [x[a][0] + 0.5 * u[a][0], x[a][1] + 0.5 * u[a][1]]);
    let end: Nodes = std::array::from_fn(|a| [x[a][0] + u[a][0], x[a][1] + u[a][1]]);
    let gradient = centroid_gradient(&mid);
    let (area, bx, by) = (gradient.area, &gradient.bx, &gradient.by);
    if !(area > 0.0) {
        return Err(KernelError::NegativeJacobian {
            point: 0,
            det: area,
        });
    }
    let (mut gxx, mut gxy, mut gyx, mut gyy) = (0.0, 0.0, 0.0, 0.0);
    for a in 0..4 {
        gxx += u[a][0] * bx[a];
        gxy += u[a][0] * by[a];
        gyx += u[a][1] * bx[a];
        gyy += u[a][1] * by[a];
    }
    let w = 0.5 * (gxy - gyx);
    let scale = 1.0 / (1.0 + 0.25 * w * w);
    let (cos, sin) = ((1.0 - 0.25 * w * w) * scale, w * scale);
    let hoop = match section {
        Section::Axisymmetric => {
            0.25 * (u[0][0] + u[1][0] + u[2][0] + u[3][0]) / centroid_radius(&mid)
        }
        Section::Plane { .. } => 0.0,
    };
    Ok(Increment {
        mid,
        end,
        gradient,
        strain: [gxx, gyy, hoop, gxy + gyx],
        cos,
        sin,
    })
}

/// The hourglass forces after a step and their work.
#[derive(Debug, Clone, Copy)]
pub struct Hourglass {
    pub forces: [f64; 2],
    pub work: f64,
}

/// Q_{n+1} = R Q_n + k q in the stiffness form on the mid-step configuration, with
/// `modulus` = kappa (lambda + 3 mu) / 24 and `weight` the section's volume per area there
/// (t, or 2 pi r_c; see the legend).
#[inline(always)]
pub fn hourglass(
    step: &Increment,
    u: &Nodes,
    committed: &[f64; 2],
    modulus: f64,
    weight: f64,
) -> Hourglass {
    let g = gamma(&step.mid, &step.gradient);
    let (bx, by) = (&step.gradient.bx, &step.gradient.by);
    let bb: f64 = (0..4).map(|a| bx[a] * bx[a] + by[a] * by[a]).sum();
    let k = modulus * weight * step.gradient.area * bb;
    let q = [
        (0..4).map(|a| g[a] * u[a][0]).sum::<f64>(),
        (0..4).map(|a| g[a] * u[a][1]).sum::<f64>(),
    ];
    let (c, s) = (step.cos, step.sin);
    let rotated = [
        c * committed[0] + s * committed[1],
        -s * committed[0] + c * committed[1],
    ];
    let forces = [rotated[0] + k * q[0], rotated[1] + k * q[1]];
    let work = 0.5 * ((rotated[0] + forces[0]) * q[0] + (rotated[1] + forces[1]) * q[1]);
    Hourglass { forces, work }
}

/// What the frequency bound reads of an element's shape.
#[derive(Debug, Clone, Copy)]
pub struct BoundShape<'a> {
    /// The centroid gradient.
    pub gradient: &'a Gradient,
    pub gamma: &'a [f64; 4],
    /// The element's volume (thickness or 2 pi r included).
    pub volume: f64,
    /// The centroid radius of an axisymmetric element.
    pub hoop_radius: Option<f64>,
}

/// An element's nodal forces on a configuration, with the gradient and gamma they used.
#[derive(Debug, Clone, Copy)]
pub struct Forces {
    /// [f1x f1y ... f4x f4y]
    pub force: [f64; 8],
    pub gradient: Gradient,
    pub gamma: [f64; 4],
}

/// Internal force [f1x f1y ... f4x f4y] of an element on the configuration x from its
/// Cauchy stress, section and hourglass forces.
#[inline(always)]
pub fn force(
    x: &Nodes,
    stress: &[f64; 4],
    section: Section,
    hourglass: &[f64; 2],
) -> Result<Forces, KernelError> {
    let grad = centroid_gradient(x);
    let (area, bx, by) = (grad.area, &grad.bx, &grad.by);
    if !(area > 0.0) {
        return Err(KernelError::NegativeJacobian {
            point: 0,
            det: area,
        });
    }
    let g = gamma(x, &grad);
    let v = area * section.weight(x);
    let (s, q) = (stress, hourglass);
    let mut f = [0.0; 8];
    for a in 0..4 {
        f[2 * a] = v * (s[0] * bx[a] + s[3] * by[a]) + q[0] * g[a];
        f[2 * a + 1] = v * (s[3] * bx[a] + s[1] * by[a]) + q[1] * g[a];
    }
    if section == Section::Axisymmetric {
        let hoop = 2.0 * std::f64::consts::PI * area * 0.25 * s[2];
        for a in 0..4 {
            f[2 * a] += hoop;
        }
    }
    Ok(Forces {
        force: f,
        gradient: grad,
        gamma: g,
    })
}

/// An upper bound of the element's highest frequency squared with the hourglass stiffness:
/// the one-point stiffness (Flanagan & Belytschko 1981: lambda_max <= (lambda + 2 mu) V b.b
/// for the centroid gradient, the hoop term V / (4 r^2) added in axisymmetry) plus the
/// hourglass stiffness's own k |gamma|^2 (Weyl: the largest eigenvalue of a sum of positive
/// semi-definite matrices is at most the sum of theirs: the hourglass stiffness k gamma
/// gamma^T has the one eigenvalue k |gamma|^2 per direction), over the smallest lumped nodal
/// mass. `modulus` is lambda + 2 mu (plane stress: E / (1 - nu^2)), `volume` the element's
/// (`shape`), `hourglass_modulus` kappa (lambda + 3 mu) / 24 (k = it V b.b).
#[inline(always)]
pub fn frequency_bound(
    shape: BoundShape,
    modulus: f64,
    hourglass_modulus: f64,
    smallest_mass: f64,
) -> f64 {
    let BoundShape {
        gradient,
        gamma,
        volume,
        hoop_radius,
    } = shape;
    let (bx, by) = (&gradient.bx, &gradient.by);
    let bb: f64 = (0..4).map(|a| bx[a] * bx[a] + by[a] * by[a]).sum();
    let hoop = hoop_radius.map_or(0.0, |r| 0.25 / (r * r));
    let gg: f64 = gamma.iter().map(|g| g * g).sum();
    (modulus * volume * (bb + hoop) + hourglass_modulus * volume * bb * gg) / smallest_mass
}

#[cfg(test)]
mod tests {
    use super::*;

    /// b_a is the gradient of N_a at the centroid: sum_a b_a = 0, sum_a x_a b_a = I; gamma is
    /// orthogonal to the linear fields (FB eq 25) on a distorted element.
    #[test]
    fn centroid_gradient_and_gamma_identities() {
        let x: Nodes = [[0.1, -0.2], [2.3, 0.1], [1.9, 1.7], [-0.3, 1.2]];
        let grad = centroid_gradient(&x);
        let g = gamma(&x, &grad);
        for (i, b) in [grad.bx, grad.by].iter().enumerate() {
            assert!(b.iter().sum::<f64>().abs() < 1e-14);
            for j in 0..2 {
                let v: f64 = (0..4).map(|a| x[a][j] * b[a]).sum();
                assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
        assert!(g.iter().sum::<f64>().abs() < 1e-14);
        for j in 0..2 {
            assert!((0..4).map(|a| x[a][j] * g[a]).sum::<f64>().abs() < 1e-14);
        }
    }
}
