//! `rectangle` and `line`: a graded grid of quads on a rectangle, a graded row of rods.

use serde::Deserialize;

use super::blocks::{along, glue, tensor};
use super::params::{MAX_ELEMENTS, at_least, finite_point, grading, one, param, positive};
use super::sets::{feature_tol, name_boundary, node_at, on_line};
use super::spacing::{from_end, graded, spaced};
use crate::mesh::{Cells, Mesh, MeshError};

/// `type = "rectangle"`: an nx x ny grid of quads on [x0, x0 + width] x [y0, y0 + height].
///
/// Edge sets `bottom`, `right`, `top`, `left`; one-node sets `bottom_left`, `bottom_right`,
/// `top_left`, `top_right`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rectangle {
    /// Lower-left corner [x0, y0] (length). Default [0, 0].
    #[serde(default)]
    pub origin: [f64; 2],
    /// Extent along x (length), > 0.
    pub width: f64,
    /// Extent along y (length), > 0.
    pub height: f64,
    /// Elements along x, >= 1.
    pub nx: usize,
    /// Elements along y, >= 1.
    pub ny: usize,
    /// Element width farthest from / nearest to the x end named by `grade_toward`, in
    /// [1e-6, 1e6]. Default 1 (uniform).
    #[serde(default = "one")]
    pub grading_x: f64,
    /// Element height farthest from / nearest to the y end named by `grade_toward`, in
    /// [1e-6, 1e6]. Default 1 (uniform).
    #[serde(default = "one")]
    pub grading_y: f64,
    /// Where the gradings put the first (small) elements: "left" or "right" (x), "bottom" or
    /// "top" (y), or a corner "bottom_left", "bottom_right", "top_left", "top_right" (both).
    /// A direction not named keeps its default end. Default: left and bottom.
    #[serde(default)]
    pub grade_toward: Option<String>,
}

impl Rectangle {
    pub fn build(&self) -> Result<Mesh, MeshError> {
        let [x0, y0] = finite_point("origin", self.origin)?;
        let width = positive("width", self.width)?;
        let height = positive("height", self.height)?;
        let nx = at_least("nx", self.nx, 1)?;
        let ny = at_least("ny", self.ny, 1)?;
        if nx * ny > MAX_ELEMENTS {
            let reason = format!("nx x ny = {} exceeds {MAX_ELEMENTS} elements", nx * ny);
            return Err(param("ny", reason));
        }
        let grading_x = grading("grading_x", self.grading_x)?;
        let grading_y = grading("grading_y", self.grading_y)?;
        let (x_at_right, y_at_top) = self.graded_ends()?;

        let xs = spaced(x0, width, &from_end(graded(nx, grading_x), x_at_right));
        let ys = spaced(y0, height, &from_end(graded(ny, grading_y), y_at_top));
        let mut mesh = glue(&[tensor(&xs, &ys)]);

        let (x1, y1) = (x0 + width, y0 + height);
        let tol = feature_tol(&mesh);
        name_boundary(&mut mesh, |p, q| {
            if on_line(p, q, 1, y0, tol) {
                "bottom"
            } else if on_line(p, q, 1, y1, tol) {
                "top"
            } else if on_line(p, q, 0, x0, tol) {
                "left"
            } else {
                "right"
            }
        });
        let corners = [
            ("bottom_left", [x0, y0]),
            ("bottom_right", [x1, y0]),
            ("top_left", [x0, y1]),
            ("top_right", [x1, y1]),
        ];
        for (name, p) in corners {
            let node = node_at(&mesh, p);
            mesh.add_node_set(name, vec![node]);
        }
        Ok(mesh)
    }

    /// (small x elements at the right, small y elements at the top).
    fn graded_ends(&self) -> Result<(bool, bool), MeshError> {
        let Some(side) = &self.grade_toward else {
            return Ok((false, false));
        };
        match side.as_str() {
            "left" | "bottom" | "bottom_left" => Ok((false, false)),
            "right" | "bottom_right" => Ok((true, false)),
            "top" | "top_left" => Ok((false, true)),
            "top_right" => Ok((true, true)),
            other => Err(param(
                "grade_toward",
                format!(
                    "expected left, right, bottom, top, bottom_left, bottom_right, top_left or \
                     top_right, got \"{other}\""
                ),
            )),
        }
    }
}

/// `type = "line"`: n two-node rods from `start` to `end`.
///
/// One-node sets `start` and `end`; element set `all`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Line {
    /// First node (length).
    pub start: [f64; 2],
    /// Last node (length), != start.
    pub end: [f64; 2],
    /// Elements, >= 1.
    pub n: usize,
    /// Last / first element length (small ones at `start` when > 1), in [1e-6, 1e6]. Default 1.
    #[serde(default = "one")]
    pub grading: f64,
}

impl Line {
    pub fn build(&self) -> Result<Mesh, MeshError> {
        let start = finite_point("start", self.start)?;
        let end = finite_point("end", self.end)?;
        if start == end {
            return Err(param("end", "must differ from start"));
        }
        let n = at_least("n", self.n, 1)?;
        let grading = grading("grading", self.grading)?;
        let nodes = along(start, end, &graded(n, grading));
        let rods = (0..n).map(|k| [k, k + 1]).collect();
        let mut mesh = Mesh::new(nodes, Cells::Rod2(rods));
        mesh.add_node_set("start", vec![0]);
        mesh.add_node_set("end", vec![n]);
        Ok(mesh)
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::*;
    use super::*;
    use crate::mesh::plane::{Point, norm, sub};

    /// Rectangle: counts, exact area, side set sizes, corners, valid quads.
    #[test]
    fn rectangle_counts_area_sets_and_corners() {
        for (nx, ny) in [(1, 1), (3, 2), (7, 5)] {
            let mesh = rectangle(nx, ny).build().unwrap();
            assert_valid(&mesh);
            assert_eq!(mesh.cells.len(), nx * ny);
            assert_eq!(mesh.nodes.len(), (nx + 1) * (ny + 1));
            assert!((total_area(&mesh) - 6.0).abs() < 1e-12);
            assert_eq!(edge_count(&mesh, "bottom"), nx);
            assert_eq!(edge_count(&mesh, "top"), nx);
            assert_eq!(edge_count(&mesh, "left"), ny);
            assert_eq!(edge_count(&mesh, "right"), ny);
            assert!(close(node(&mesh, "bottom_left"), [1.0, -2.0]));
            assert!(close(node(&mesh, "top_right"), [4.0, 0.0]));
            assert!(close(node(&mesh, "bottom_right"), [4.0, -2.0]));
            assert!(close(node(&mesh, "top_left"), [1.0, 0.0]));
        }
    }

    /// Bottom edges run +x and left edges run -y (body on the left).
    #[test]
    fn rectangle_edges_are_counter_clockwise() {
        let mesh = rectangle(3, 2).build().unwrap();
        let dir = |set: &str| -> Vec<Point> {
            mesh.edge_sets[set]
                .iter()
                .map(|e| sub(mesh.nodes[e[1]], mesh.nodes[e[0]]))
                .collect()
        };
        assert!(dir("bottom").iter().all(|d| d[0] > 0.0));
        assert!(dir("right").iter().all(|d| d[1] > 0.0));
        assert!(dir("top").iter().all(|d| d[0] < 0.0));
        assert!(dir("left").iter().all(|d| d[1] < 0.0));
    }

    /// Grading: the element next to the named edge is 1/grading of the farthest one.
    #[test]
    fn rectangle_grading_puts_small_elements_at_the_named_edge() {
        let widths = |mesh: &Mesh, set: &str, axis: usize| -> Vec<f64> {
            let mut xs: Vec<f64> = mesh.node_sets[set]
                .iter()
                .map(|&n| mesh.nodes[n][axis])
                .collect();
            xs.sort_by(f64::total_cmp);
            xs.windows(2).map(|w| w[1] - w[0]).collect()
        };
        let mut spec = rectangle(5, 4);
        spec.grading_x = 8.0;
        spec.grading_y = 3.0;
        let mesh = spec.build().unwrap();
        assert_valid(&mesh);
        let dx = widths(&mesh, "bottom", 0);
        assert!((dx[4] / dx[0] - 8.0).abs() < 1e-9);
        let dy = widths(&mesh, "left", 1);
        assert!((dy[3] / dy[0] - 3.0).abs() < 1e-9);

        spec.grade_toward = Some("top_right".into());
        let mesh = spec.build().unwrap();
        assert_valid(&mesh);
        let dx = widths(&mesh, "bottom", 0);
        assert!((dx[0] / dx[4] - 8.0).abs() < 1e-9);
        let dy = widths(&mesh, "left", 1);
        assert!((dy[0] / dy[3] - 3.0).abs() < 1e-9);
        assert!((total_area(&mesh) - 6.0).abs() < 1e-12);
    }

    /// Line: rods in order, graded lengths, end node sets.
    #[test]
    fn line_makes_graded_rods() {
        let mesh = Line {
            start: [0.0, 0.0],
            end: [3.0, 4.0],
            n: 4,
            grading: 2.0,
        }
        .build()
        .unwrap();
        let Cells::Rod2(rods) = &mesh.cells else {
            panic!("rods expected")
        };
        assert_eq!(rods, &vec![[0, 1], [1, 2], [2, 3], [3, 4]]);
        let lengths: Vec<f64> = rods
            .iter()
            .map(|r| norm(sub(mesh.nodes[r[1]], mesh.nodes[r[0]])))
            .collect();
        assert!((lengths.iter().sum::<f64>() - 5.0).abs() < 1e-12);
        assert!((lengths[3] / lengths[0] - 2.0).abs() < 1e-12);
        assert_eq!(mesh.node_sets["start"], vec![0]);
        assert_eq!(mesh.node_sets["end"], vec![4]);
        assert_eq!(mesh.element_sets["all"], vec![0, 1, 2, 3]);
    }
}
