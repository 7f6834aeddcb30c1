//! Moments of straight-edged polygons: the measure and first moments of a region, weighted by
//! the radius in axisymmetry (Green's theorem on each edge, exact for any simple or
//! self-crossing polygon taken with its signed area).
//!
//! Legend (polygon x_0 .. x_{n-1}, c_i = x_i y_{i+1} - x_{i+1} y_i)
//! ```text
//! plane          V   = sum c_i / 2                        (area)
//!                M_x = sum (x_i + x_{i+1}) c_i / 6        M_y = sum (y_i + y_{i+1}) c_i / 6
//! axisymmetric   V   = int r dA   = M_x of the plane      (per radian)
//!                M_x = int r^2 dA = sum (x_i^2 + x_i x_{i+1} + x_{i+1}^2) c_i / 12
//!                M_y = int r y dA = sum (x_i y_{i+1} + 2 x_i y_i + 2 x_{i+1} y_{i+1}
//!                                        + x_{i+1} y_i) c_i / 24
//! ```
//! A linear field phi = a + g . x integrates exactly to a V + g . M over any such region,
//! which is what makes the remap exact on linear fields.

/// The measure (area, or int r dA in axisymmetry) and first moments of a region.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Moments {
    pub volume: f64,
    pub first: [f64; 2],
}

impl Moments {
    /// The weighted centroid M / V.
    pub fn centroid(&self) -> [f64; 2] {
        [self.first[0] / self.volume, self.first[1] / self.volume]
    }
}

/// The moments of the polygon `points` (counter-clockwise: positive volume), weighted by the
/// radius x when `axisymmetric`.
pub fn moments(points: &[[f64; 2]], axisymmetric: bool) -> Moments {
    let n = points.len();
    let mut m = Moments::default();
    for i in 0..n {
        let [x0, y0] = points[i];
        let [x1, y1] = points[(i + 1) % n];
        let c = x0 * y1 - x1 * y0;
        if axisymmetric {
            m.volume += (x0 + x1) * c / 6.0;
            m.first[0] += (x0 * x0 + x0 * x1 + x1 * x1) * c / 12.0;
            m.first[1] += (x0 * y1 + 2.0 * x0 * y0 + 2.0 * x1 * y1 + x1 * y0) * c / 24.0;
        } else {
            m.volume += 0.5 * c;
            m.first[0] += (x0 + x1) * c / 6.0;
            m.first[1] += (y0 + y1) * c / 6.0;
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The unit square [1, 2] x [0, 1]: area 1, centroid (1.5, 0.5); int r dA = 1.5,
    /// int r^2 dA = (8 - 1) / 3, int r y dA = 1.5 / 2 (closed forms).
    #[test]
    fn a_square_has_its_closed_form_moments() {
        let square = [[1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0]];
        let plane = moments(&square, false);
        assert_relative_eq!(plane.volume, 1.0, epsilon = 1e-15);
        assert_relative_eq!(plane.centroid()[0], 1.5, epsilon = 1e-15);
        assert_relative_eq!(plane.centroid()[1], 0.5, epsilon = 1e-15);
        let axi = moments(&square, true);
        assert_relative_eq!(axi.volume, 1.5, epsilon = 1e-15);
        assert_relative_eq!(axi.first[0], 7.0 / 3.0, epsilon = 1e-15);
        assert_relative_eq!(axi.first[1], 0.75, epsilon = 1e-15);
    }

    /// A triangle (0,0), (2,0), (0,2) in axisymmetry: int r dA = int_0^2 r (2 - r) dr = 4/3,
    /// int r^2 dA = int_0^2 r^2 (2 - r) dr = 4/3, int r y dA = int_0^2 r (2 - r)^2 / 2 dr = 2/3.
    #[test]
    fn a_triangle_has_its_closed_form_axisymmetric_moments() {
        let triangle = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]];
        let m = moments(&triangle, true);
        assert_relative_eq!(m.volume, 4.0 / 3.0, epsilon = 1e-14);
        assert_relative_eq!(m.first[0], 4.0 / 3.0, epsilon = 1e-14);
        assert_relative_eq!(m.first[1], 2.0 / 3.0, epsilon = 1e-14);
    }
}
