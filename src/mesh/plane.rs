//! Points of the plane and the few operations on them that meshes and contact share.

/// A point or vector [x, y] (axisymmetric: [r, z]).
pub type Point = [f64; 2];

pub fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1]]
}

pub fn dot(a: Point, b: Point) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// The z component of a x b.
pub fn cross(a: Point, b: Point) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// |a| by `hypot` (no overflow for coordinates near the range of f64).
pub fn norm(a: Point) -> f64 {
    a[0].hypot(a[1])
}

/// Signed area of a quadrilateral (> 0 when counter-clockwise).
pub fn quad_area(q: [Point; 4]) -> f64 {
    0.5 * (0..4).map(|k| cross(q[k], q[(k + 1) % 4])).sum::<f64>()
}

/// The outward unit normal of the segment a -> b with the solid on its left (its right-hand
/// normal), its length taken as sqrt(d . d).
pub fn outward(a: Point, b: Point) -> Point {
    let d = sub(b, a);
    let l = dot(d, d).sqrt();
    [d[1] / l, -d[0] / l]
}
