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

/// The largest turn of one segment of a rounded corner (`round_corners`): 5 degrees, 18
/// segments on a right angle, whose chords lie within r (1 - cos 2.5 deg) = 1e-3 r of the
/// arc.
pub const ARC_STEP: f64 = std::f64::consts::PI / 36.0;

/// The polyline `points` (a closed loop when `closed`) with each corner replaced by an arc
/// of radius `radius` tangent to its two segments, in steps of at most [`ARC_STEP`]; an
/// open polyline keeps its two ends. Err(k): the arc of vertex k does not fit, its tangent
/// length r tan(turn / 2) beyond half of one of its segments (two arcs would overlap on it).
pub fn round_corners(points: &[Point], closed: bool, radius: f64) -> Result<Vec<Point>, usize> {
    let n = points.len();
    let corners: Vec<usize> = if closed {
        (0..n).collect()
    } else {
        (1..n.saturating_sub(1)).collect()
    };
    let unit = |a: Point| {
        let l = norm(a);
        [a[0] / l, a[1] / l]
    };
    let mut out = Vec::with_capacity(n);
    if !closed {
        out.push(points[0]);
    }
    for k in corners {
        let (before, vertex, after) = (points[(k + n - 1) % n], points[k], points[(k + 1) % n]);
        let (u1, u2) = (unit(sub(vertex, before)), unit(sub(after, vertex)));
        let turn = cross(u1, u2).atan2(dot(u1, u2));
        if turn.abs() < 1e-12 {
            out.push(vertex);
            continue;
        }
        let tangent = radius * (0.5 * turn.abs()).tan();
        if tangent > 0.5 * norm(sub(vertex, before)) || tangent > 0.5 * norm(sub(after, vertex)) {
            return Err(k);
        }
        // the centre lies on the inside of the turn, r from the first tangent point
        let start = [vertex[0] - tangent * u1[0], vertex[1] - tangent * u1[1]];
        let side = turn.signum();
        let centre = [
            start[0] - side * radius * u1[1],
            start[1] + side * radius * u1[0],
        ];
        let steps = (turn.abs() / ARC_STEP).ceil() as usize;
        let arm = sub(start, centre);
        for j in 0..=steps {
            let (s, c) = (turn * j as f64 / steps as f64).sin_cos();
            out.push([
                centre[0] + c * arm[0] - s * arm[1],
                centre[1] + s * arm[0] + c * arm[1],
            ]);
        }
    }
    if !closed {
        out.push(points[n - 1]);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: a rounded right angle is a quarter circle tangent to both segments. Setup: the
    /// corner (0, 0) between (-1, 0) and (0, 1) (a left turn), radius 0.5. Reference (by
    /// hand): tangent length 0.5 tan 45 deg = 0.5, tangent points (-0.5, 0) and (0, 0.5),
    /// centre (-0.5, 0.5); 90 / 5 = 18 segments, every point 0.5 from the centre; the ends
    /// kept. The same corner turning right ((0, -1) after it) mirrors the arc.
    #[test]
    fn a_right_angle_becomes_a_quarter_circle() {
        let rounded = round_corners(&[[-1.0, 0.0], [0.0, 0.0], [0.0, 1.0]], false, 0.5).unwrap();
        assert_eq!(rounded.len(), 2 + 19);
        assert_eq!(rounded[0], [-1.0, 0.0]);
        assert_eq!(rounded[20], [0.0, 1.0]);
        let close = |a: Point, b: Point| norm(sub(a, b)) < 1e-14;
        assert!(close(rounded[1], [-0.5, 0.0]) && close(rounded[19], [0.0, 0.5]));
        for p in &rounded[1..20] {
            assert!((norm(sub(*p, [-0.5, 0.5])) - 0.5).abs() < 1e-14, "{p:?}");
        }
        let right = round_corners(&[[-1.0, 0.0], [0.0, 0.0], [0.0, -1.0]], false, 0.5).unwrap();
        assert!(close(right[19], [0.0, -0.5]));
        for p in &right[1..20] {
            assert!((norm(sub(*p, [-0.5, -0.5])) - 0.5).abs() < 1e-14, "{p:?}");
        }
    }

    /// Goal: an arc that does not fit is refused with its vertex, and a closed square keeps
    /// its area but for the four corners. Reference (by hand): radius 0.6 on a corner whose
    /// segments are 1 long needs a tangent of 0.6 > 0.5; the unit square with r = 0.1 loses
    /// (4 - pi) r^2 = 0.0085841 of its area to the fillets (chords: within 1e-3 r of the
    /// arcs, so within 1e-4 of that).
    #[test]
    fn arcs_that_do_not_fit_are_refused_and_a_square_loses_its_corners() {
        assert_eq!(
            round_corners(&[[-1.0, 0.0], [0.0, 0.0], [0.0, 1.0]], false, 0.6),
            Err(1)
        );
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let rounded = round_corners(&square, true, 0.1).unwrap();
        let area: f64 = (0..rounded.len())
            .map(|i| cross(rounded[i], rounded[(i + 1) % rounded.len()]))
            .sum::<f64>()
            * 0.5;
        let lost = (4.0 - std::f64::consts::PI) * 0.01;
        assert!((1.0 - area - lost).abs() < 1e-4, "{area}");
    }
}
