//! A rigid projectile (docs/theory.md 8.3g): an obstacle with a mass that the contact forces
//! move. Its translation u_R, and with a moment of inertia its rotation theta about its
//! centre c, are unknowns of each explicit step: the driver carries them as the DOFs of
//! nodes of their own (`analysis::steppers::explicit::projectiles`), the carrier (position
//! u_R) and the spin node (first DOF theta). The obstacle's points stay at `base`, where
//! u_R = 0 and theta = 0; a slave x_s meets them at
//! ```text
//! x_b = R(-theta) (x_s - c - u_R) + c          (the slave in the base frame)
//! ```
//! and the gap and normal found there are the world's, the normal turned by R(theta). A row
//! along d (the normal, or the tangent) holds d on x_s, -d on the carrier's DOFs (a
//! translation moves every point alike: `Gap::masters`, weight 1) and -(r x d) on theta,
//! r = x_s - c - u_R the slave's arm (`Gap::lever`): every row against the projectile shares
//! these DOFs, so the forward-increment correction solves them together.

use crate::mesh::plane::sub;

/// A rigid projectile's data (`Obstacle::projectile`).
#[derive(Debug, Clone, PartialEq)]
pub struct Projectile {
    /// Its number among the model's projectiles (`ContactState::flights`).
    pub index: usize,
    /// The mass, counted as the bodies' lumped masses are: per unit depth in plane strain,
    /// through the thickness in plane stress, the full ring in axisymmetry.
    pub mass: f64,
    /// The velocity at t = 0.
    pub velocity: [f64; 2],
    /// The rotation, when the scene gives a moment of inertia (None: it translates only).
    pub spin: Option<Spin>,
    /// The points at t = 0, from which a translation and a turn place them (`place_at`).
    pub base: Vec<[f64; 2]>,
    /// The node whose position is u_R in the explicit driver's vectors; None outside it
    /// (the points are placed instead, `Obstacle::place_at`).
    pub carrier: Option<usize>,
}

/// A projectile's rotation about its centre.
#[derive(Debug, Clone, PartialEq)]
pub struct Spin {
    /// The moment of inertia about `centre` (the mass's units times a length squared).
    pub inertia: f64,
    /// The angular velocity at t = 0 (counter-clockwise positive).
    pub angular_velocity: f64,
    /// The centre of rotation at t = 0 (the centre of mass).
    pub centre: [f64; 2],
    /// The node whose first DOF is theta in the explicit driver's vectors; None outside it.
    pub node: Option<usize>,
}

/// Where a carried projectile is at positions `x` (the driver's nodes and its carriers).
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    pub carrier: usize,
    u: [f64; 2],
    centre: [f64; 2],
    /// The spin node and theta.
    spin: Option<(usize, f64)>,
}

impl Projectile {
    /// Its frame at positions `x` when the driver carries it (None: the points are placed).
    pub fn frame(&self, x: &dyn Fn(usize) -> [f64; 2]) -> Option<Frame> {
        let carrier = self.carrier?;
        let spin = self.spin.as_ref();
        Some(Frame {
            carrier,
            u: x(carrier),
            centre: spin.map_or([0.0; 2], |s| s.centre),
            spin: spin.and_then(|s| s.node.map(|n| (n, x(n)[0]))),
        })
    }

    /// The point `b` of the base placed at translation `u` and rotation `theta`.
    pub fn placed(&self, b: [f64; 2], u: [f64; 2], theta: f64) -> [f64; 2] {
        let c = self.spin.as_ref().map_or([0.0; 2], |s| s.centre);
        let r = rotate(sub(b, c), theta);
        [c[0] + u[0] + r[0], c[1] + u[1] + r[1]]
    }
}

impl Frame {
    fn theta(&self) -> f64 {
        self.spin.map_or(0.0, |(_, theta)| theta)
    }

    /// A world point in the base frame.
    pub fn to_base(&self, x: [f64; 2]) -> [f64; 2] {
        let c = self.centre;
        let r = rotate(sub(sub(x, c), self.u), -self.theta());
        [c[0] + r[0], c[1] + r[1]]
    }

    /// A direction of the base frame in the world.
    pub fn to_world(&self, d: [f64; 2]) -> [f64; 2] {
        rotate(d, self.theta())
    }

    /// The spin node and the arm r = x - c - u_R of a slave at world point `x` (None: the
    /// projectile does not rotate).
    pub fn lever(&self, x: [f64; 2]) -> Option<(usize, [f64; 2])> {
        let (node, _) = self.spin?;
        Some((node, sub(sub(x, self.centre), self.u)))
    }
}

fn rotate(v: [f64; 2], theta: f64) -> [f64; 2] {
    if theta == 0.0 {
        return v;
    }
    let (s, c) = theta.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}
