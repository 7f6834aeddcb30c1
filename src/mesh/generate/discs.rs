//! Discs and rings: `quarter_disc` and `half_disc` (O-grids, see ogrid.rs), `ring` (an
//! annulus or a sector of one) and `plate_with_hole` (two ruled blocks around a quarter hole).

use std::f64::consts::{FRAC_PI_2, PI};

use serde::Deserialize;

use super::blocks::{glue, ruled};
use super::ogrid::{HalfOGrid, QuarterOGrid};
use super::params::{MAX_DIVISIONS, at_least, finite_point, grading, one, param, positive};
use super::sets::{feature_tol, name_boundary, node_at, on_line};
use super::spacing::{graded, layer_fractions, nearest};
use crate::mesh::plane::{Point, norm, sub};
use crate::mesh::{Mesh, MeshError};

/// Size of a disc's O-grid core as a fraction of the radius.
const DISC_CORE: f64 = 0.5;

/// `type = "quarter_disc"`: the quarter x >= cx of a disc of radius R on one side of y = cy,
/// for an axisymmetric sphere (r = x) loaded on its flat face and touching a plane at the pole.
///
/// Meshing: an O-grid (a core quadrilateral at the centre, a pole-side and a rim-side outer
/// block with radial grid lines). The arc's n steps grow geometrically from the pole; the outer
/// layers (as many as the layer holds mean arc steps) grow from the arc inward so the quads at
/// the pole are about square. Quads: n n_layer + m (n - m), m = arc steps of the pole block.
///
/// Edge sets `axis` (x = cx), `flat` (y = cy), `arc`; one-node sets `pole` (the arc's end on the
/// axis) and `center`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuarterDisc {
    /// Centre of the disc (length). Default [0, 0].
    #[serde(default)]
    pub center: [f64; 2],
    /// Radius R (length), > 0.
    pub radius: f64,
    /// Elements along the arc, >= 2; it also sets the density inside.
    pub n: usize,
    /// Largest / smallest arc step (smallest at the pole), in [1e-6, 1e6]. Default 1.
    #[serde(default = "one")]
    pub grading: f64,
    /// "lower": y <= cy, pole at (cx, cy - R); "upper": y >= cy, pole at (cx, cy + R).
    /// Default "lower".
    #[serde(default = "lower")]
    pub quadrant: String,
    /// Levels of the mesh family's refinement, 0 to `MAX_REFINE` (see `refined`). Default 0.
    #[serde(default)]
    pub refine: u32,
}

/// The default quadrant of a quarter disc.
fn lower() -> String {
    "lower".to_string()
}

impl QuarterDisc {
    pub fn build(&self) -> Result<Mesh, MeshError> {
        let center = finite_point("center", self.center)?;
        let radius = positive("radius", self.radius)?;
        let n = at_least("n", self.n, 2)?;
        let (n, grading) = refined(n, grading("grading", self.grading)?, self.refine)?;
        let pole_sign = match self.quadrant.as_str() {
            "lower" => -1.0,
            "upper" => 1.0,
            other => {
                return Err(param(
                    "quadrant",
                    format!("expected \"lower\" or \"upper\", got \"{other}\""),
                ));
            }
        };

        let arc = graded(n, grading);
        let thickness = (1.0 - DISC_CORE) * radius;
        let layers = layer_fractions(
            thickness,
            FRAC_PI_2 * radius / n as f64,
            FRAC_PI_2 * radius * arc[1],
        );
        let split = nearest(&arc, 0.5, 1..=n - 1);
        let o_grid = QuarterOGrid {
            center,
            radius,
            pole_sign,
            arc,
            split,
            core: DISC_CORE,
            layers,
        };
        let mut mesh = glue(&o_grid.grids());

        let tol = feature_tol(&mesh);
        name_boundary(&mut mesh, |p, q| {
            if on_line(p, q, 0, center[0], tol) {
                "axis"
            } else if on_line(p, q, 1, center[1], tol) {
                "flat"
            } else {
                "arc"
            }
        });
        let pole = node_at(&mesh, o_grid.arc_point(0.0));
        let centre = node_at(&mesh, center);
        mesh.add_node_set("pole", vec![pole]);
        mesh.add_node_set("center", vec![centre]);
        Ok(mesh)
    }
}

/// The most levels `refine` takes (n 2^6 arc steps).
const MAX_REFINE: u32 = 6;

/// The arc steps n and grading of a disc mesh `refine` levels down its family: each level
/// splits every arc step in two, with the ratio of consecutive steps the square root of the
/// level above's, so n becomes n 2^k, the ratio q = g^(1 / (n - 1)) becomes q^(1 / 2^k) and the
/// grading (n 2^k - 1) / (2^k (n - 1)) powers of g. The base mesh's arc nodes stay nodes
/// (two steps q^(j/2), q^((j+1)/2) sum to the base step q^(j/2) (1 + q^(1/2)), the same factor
/// for every pair) and the pole step halves at each level: the fixed rule a grid convergence
/// study needs (docs/validation.md 4.14), where changing n alone also moves the pole step and
/// the grading. The O-grid's inner layers and blocks follow the arc by the generator's rules.
fn refined(n: usize, grading: f64, refine: u32) -> Result<(usize, f64), MeshError> {
    if refine > MAX_REFINE {
        return Err(param(
            "refine",
            format!("must be at most {MAX_REFINE}, got {refine}"),
        ));
    }
    let split = 1usize << refine;
    let fine = n * split;
    if fine > MAX_DIVISIONS {
        return Err(param(
            "refine",
            format!("n 2^refine = {fine} arc steps is above the limit {MAX_DIVISIONS}"),
        ));
    }
    if refine == 0 || n < 2 {
        return Ok((fine, grading));
    }
    let power = (fine - 1) as f64 / (split * (n - 1)) as f64;
    Ok((fine, grading.powf(power)))
}

/// `type = "half_disc"`: the half x >= cx of a disc of radius R (a full sphere's axisymmetric
/// section), graded toward the lower pole (cx, cy - R) or, with `grade_toward = "upper"`,
/// toward the upper pole (cx, cy + R): a sphere striking upwards.
///
/// Meshing: an O-grid whose core is split at the centre into two quadrilaterals (so the centre
/// is a node), with three outer blocks (lower pole, rim, upper pole). The arc's n steps grow
/// geometrically from the graded pole. Each pole block takes a arc steps, a chosen so the three
/// blocks span angles as even as possible. Quads: n n_layer + a (n - 2 a). The upper-graded
/// mesh is the lower-graded one mirrored about y = cy.
///
/// Edge sets `axis` (x = cx), `arc`; one-node sets `pole` (lower pole), `top_pole`, `center`
/// (the names are geometric: `pole` is the lower pole whichever pole is graded).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HalfDisc {
    /// Centre of the disc (length). Default [0, 0].
    #[serde(default)]
    pub center: [f64; 2],
    /// Radius R (length), > 0.
    pub radius: f64,
    /// Elements along the half circle, >= 4.
    pub n: usize,
    /// Largest / smallest arc step (smallest at the pole `grade_toward` names), in
    /// [1e-6, 1e6]. Default 1.
    #[serde(default = "one")]
    pub grading: f64,
    /// The pole of the smallest arc step: `lower` (default) or `upper`.
    #[serde(default)]
    pub grade_toward: Pole,
    /// Levels of the mesh family's refinement, 0 to `MAX_REFINE` (see `refined`). Default 0.
    #[serde(default)]
    pub refine: u32,
}

/// A pole of a half disc: the lower (cx, cy - R) or the upper (cx, cy + R).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Pole {
    #[default]
    Lower,
    Upper,
}

impl HalfDisc {
    pub fn build(&self) -> Result<Mesh, MeshError> {
        let mesh = self.build_lower()?;
        Ok(match self.grade_toward {
            Pole::Lower => mesh,
            Pole::Upper => mirrored(mesh, self.center[1]),
        })
    }

    /// The mesh graded toward the lower pole.
    fn build_lower(&self) -> Result<Mesh, MeshError> {
        let center = finite_point("center", self.center)?;
        let radius = positive("radius", self.radius)?;
        let n = at_least("n", self.n, 4)?;
        let (n, grading) = refined(n, grading("grading", self.grading)?, self.refine)?;

        let arc = graded(n, grading);
        let thickness = (1.0 - DISC_CORE) * radius;
        let layers = layer_fractions(thickness, PI * radius / n as f64, PI * radius * arc[1]);
        // The core is the polygon pole - split - split - top pole: the largest one has the most
        // even block spans.
        let core_area = |a: &usize| {
            let (low, high) = (PI * arc[*a], PI * arc[n - *a]);
            low.sin() + (high - low).sin() + (PI - high).sin()
        };
        let low = (1..=(n - 2) / 2)
            .max_by(|a, b| core_area(a).total_cmp(&core_area(b)))
            .expect("n >= 4 leaves a >= 1");
        let equator = nearest(&arc, 0.5, low + 1..=n - low - 1);
        let o_grid = HalfOGrid {
            center,
            radius,
            arc,
            low,
            equator,
            core: DISC_CORE,
            layers,
        };
        let mut mesh = glue(&o_grid.grids());

        let tol = feature_tol(&mesh);
        name_boundary(&mut mesh, |p, q| {
            if on_line(p, q, 0, center[0], tol) {
                "axis"
            } else {
                "arc"
            }
        });
        let pole = node_at(&mesh, o_grid.arc_point(0.0));
        let top_pole = node_at(&mesh, o_grid.arc_point(1.0));
        let centre = node_at(&mesh, center);
        mesh.add_node_set("pole", vec![pole]);
        mesh.add_node_set("top_pole", vec![top_pole]);
        mesh.add_node_set("center", vec![centre]);
        Ok(mesh)
    }
}

/// `mesh` mirrored about the line y = `y`: cells and edges reversed so that cells stay
/// counter-clockwise and edges keep the body on their left; the node sets `pole` and
/// `top_pole` swap nodes (each keeps naming the lower and the upper pole).
fn mirrored(mut mesh: Mesh, y: f64) -> Mesh {
    for node in &mut mesh.nodes {
        node[1] = 2.0 * y - node[1];
    }
    if let crate::mesh::Cells::Quad4(cells) = &mut mesh.cells {
        for cell in cells.iter_mut() {
            cell.reverse();
        }
    }
    for edges in mesh.edge_sets.values_mut() {
        for edge in edges.iter_mut() {
            edge.reverse();
        }
        edges.reverse();
    }
    if let (Some(lower), Some(upper)) = (
        mesh.node_sets.remove("pole"),
        mesh.node_sets.remove("top_pole"),
    ) {
        mesh.node_sets.insert("pole".into(), upper);
        mesh.node_sets.insert("top_pole".into(), lower);
    }
    mesh
}

/// `type = "ring"`: an annulus, n_radial x n_circ quads: the full ring (closed without a seam)
/// or, with `angle` < 360, the sector from 0 to `angle` degrees counter-clockwise from +x.
///
/// Edge sets `outer` (counter-clockwise) and `inner` (clockwise): the body is on the left of
/// both. A sector adds `start` (the radial edge at 0 degrees) and `end` (at `angle`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ring {
    /// Centre (length). Default [0, 0].
    #[serde(default)]
    pub center: [f64; 2],
    /// Inner radius (length), > 0.
    pub inner_radius: f64,
    /// Outer radius (length), > inner_radius.
    pub outer_radius: f64,
    /// Elements through the wall, >= 1.
    pub n_radial: usize,
    /// Elements around, >= 3 (>= 1 for a sector).
    pub n_circ: usize,
    /// Opening angle in degrees, in (0, 360]. Default 360 (the full ring).
    #[serde(default = "full_turn")]
    pub angle: f64,
    /// Ratio of the outermost to the innermost radial element size. Default 1.
    #[serde(default = "one")]
    pub grading: f64,
}

/// The default opening of a ring: the full turn, in degrees.
fn full_turn() -> f64 {
    360.0
}

impl Ring {
    pub fn build(&self) -> Result<Mesh, MeshError> {
        let center = finite_point("center", self.center)?;
        let inner_radius = positive("inner_radius", self.inner_radius)?;
        let outer_radius = positive("outer_radius", self.outer_radius)?;
        if outer_radius <= inner_radius {
            let reason = format!("must exceed inner_radius = {inner_radius}, got {outer_radius}");
            return Err(param("outer_radius", reason));
        }
        let n_radial = at_least("n_radial", self.n_radial, 1)?;
        if !(self.angle > 0.0 && self.angle <= 360.0) {
            return Err(param(
                "angle",
                format!("must lie in (0, 360] degrees, got {}", self.angle),
            ));
        }
        let sector = self.angle < 360.0;
        let n_circ = at_least("n_circ", self.n_circ, if sector { 1 } else { 3 })?;
        let ratio = grading("grading", self.grading)?;
        let opening = self.angle.to_radians();

        let circle = |radius: f64| -> Vec<Point> {
            (0..=n_circ)
                .map(|k| {
                    let k = if sector { k } else { k % n_circ };
                    let (sin, cos) = (opening * k as f64 / n_circ as f64).sin_cos();
                    [center[0] + radius * cos, center[1] + radius * sin]
                })
                .collect()
        };
        let grid = ruled(
            &circle(inner_radius),
            &circle(outer_radius),
            &graded(n_radial, ratio),
        );
        let mut mesh = glue(&[grid]);

        let mid_radius = 0.5 * (inner_radius + outer_radius);
        let radius = |p: Point| norm(sub(p, center));
        let tol = 1e-9 * outer_radius;
        let radial_on = |p: Point, q: Point, phi: f64| {
            let (sin, cos) = phi.sin_cos();
            // on the ray from the centre at angle phi (not the opposite ray)
            let on = |x: Point| {
                let (dx, dy) = (x[0] - center[0], x[1] - center[1]);
                (dx * sin - dy * cos).abs() < tol && dx * cos + dy * sin > 0.0
            };
            on(p) && on(q)
        };
        name_boundary(&mut mesh, |p, q| {
            if sector && radial_on(p, q, 0.0) {
                "start"
            } else if sector && radial_on(p, q, opening) {
                "end"
            } else if radius(p).max(radius(q)) < mid_radius {
                "inner"
            } else {
                "outer"
            }
        });
        Ok(mesh)
    }
}

/// `type = "plate_with_hole"`: the quarter [0, width] x [0, height] of a plate with a central
/// hole of radius `radius` at the origin (symmetry on x = 0 and y = 0). Two ruled blocks
/// split on the ray to the corner (width, height); `n` elements along each block's arc and
/// outer edge, `n_radial` from the hole outwards, graded by `grading` (outermost / innermost).
///
/// Edge sets `hole`, `bottom` (y = 0), `right` (x = width), `top` (y = height), `left` (x = 0).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlateWithHole {
    /// Half width of the plate (length), > radius.
    pub width: f64,
    /// Half height of the plate (length), > radius.
    pub height: f64,
    /// Hole radius (length), > 0.
    pub radius: f64,
    /// Elements along each half of the arc, >= 1.
    pub n: usize,
    /// Elements from the hole to the outer edges, >= 1.
    pub n_radial: usize,
    /// Ratio of the outermost to the innermost radial element size. Default 1.
    #[serde(default = "one")]
    pub grading: f64,
}

impl PlateWithHole {
    pub fn build(&self) -> Result<Mesh, MeshError> {
        let radius = positive("radius", self.radius)?;
        let width = positive("width", self.width)?;
        let height = positive("height", self.height)?;
        if width <= radius || height <= radius {
            return Err(param(
                "width",
                format!("width and height must exceed the radius {radius}"),
            ));
        }
        let n = at_least("n", self.n, 1)?;
        let ws = graded(
            at_least("n_radial", self.n_radial, 1)?,
            grading("grading", self.grading)?,
        );
        let corner = height.atan2(width);
        let arc = |from: f64, to: f64| -> Vec<Point> {
            (0..=n)
                .map(|k| {
                    let (sin, cos) = (from + (to - from) * k as f64 / n as f64).sin_cos();
                    [radius * cos, radius * sin]
                })
                .collect()
        };
        let right: Vec<Point> = (0..=n)
            .map(|k| [width, height * k as f64 / n as f64])
            .collect();
        let top: Vec<Point> = (0..=n)
            .map(|k| [width * (1.0 - k as f64 / n as f64), height])
            .collect();
        let blocks = [
            ruled(&arc(0.0, corner), &right, &ws),
            ruled(&arc(corner, FRAC_PI_2), &top, &ws),
        ];
        let mut mesh = glue(&blocks);
        let tol = 1e-9 * width.max(height);
        name_boundary(&mut mesh, |p, q| {
            let both = |f: &dyn Fn(Point) -> bool| f(p) && f(q);
            if both(&|x| x[1].abs() < tol) {
                "bottom"
            } else if both(&|x| x[0].abs() < tol) {
                "left"
            } else if both(&|x| (x[0] - width).abs() < tol) {
                "right"
            } else if both(&|x| (x[1] - height).abs() < tol) {
                "top"
            } else {
                "hole"
            }
        });
        Ok(mesh)
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::*;
    use super::*;
    use crate::mesh::plane::cross;

    /// Quarter disc: valid quads for a range of n and gradings, area = sector minus chord
    /// segments, pole and centre nodes, set sizes.
    #[test]
    fn quarter_disc_is_valid_and_has_the_chord_area() {
        for quadrant in ["lower", "upper"] {
            for n in [2, 3, 4, 5, 8, 13, 24] {
                for grading in [1.0, 0.3, 4.0, 30.0] {
                    let spec = quarter(n, grading, quadrant);
                    let mesh = spec.build().unwrap();
                    assert_valid(&mesh);
                    assert_eq!(edge_count(&mesh, "arc"), n);
                    let exact = chord_area(8.0, arc_angles(&mesh, "arc", spec.center).into_iter());
                    assert!(
                        (total_area(&mesh) - exact).abs() < 1e-9,
                        "n {n} g {grading}"
                    );
                    let sign = if quadrant == "lower" { -1.0 } else { 1.0 };
                    assert!(close(node(&mesh, "pole"), [0.5, 2.0 + sign * 8.0]));
                    assert!(close(node(&mesh, "center"), [0.5, 2.0]));
                    let axis = &mesh.node_sets["axis"];
                    assert!(
                        axis.iter().all(|&k| mesh.nodes[k][0] == 0.5),
                        "axis nodes exactly on x = cx"
                    );
                    assert!(
                        mesh.node_sets["flat"]
                            .iter()
                            .all(|&k| mesh.nodes[k][1] == 2.0)
                    );
                    assert!(
                        mesh.nodes
                            .iter()
                            .all(|p| sign * (p[1] - 2.0) >= 0.0 && p[0] >= 0.5)
                    );
                }
            }
        }
    }

    /// The smallest arc step is at the pole, and pole-step / largest step = 1 / grading.
    #[test]
    fn quarter_disc_grading_refines_the_pole() {
        let mesh = quarter(16, 10.0, "lower").build().unwrap();
        let pole = mesh.node_sets["pole"][0];
        let steps = arc_angles(&mesh, "arc", [0.5, 2.0]);
        let smallest = steps.iter().copied().fold(f64::INFINITY, f64::min);
        let largest = steps.iter().copied().fold(0.0, f64::max);
        assert!((largest / smallest - 10.0).abs() < 1e-6);
        let at_pole = mesh.edge_sets["arc"]
            .iter()
            .position(|e| e.contains(&pole))
            .unwrap();
        assert!((steps[at_pole] - smallest).abs() < 1e-12);
        // counter-clockwise around the lower quadrant: the arc runs from the pole to the rim
        assert_eq!(mesh.edge_sets["arc"][0][0], pole);
    }

    /// Half disc: valid quads, chord area, poles and centre on the axis, graded at the lower pole.
    #[test]
    fn half_disc_is_valid_and_has_the_chord_area() {
        for n in [4, 5, 6, 9, 16, 32] {
            for grading in [1.0, 0.5, 5.0, 20.0] {
                let spec = HalfDisc {
                    center: [0.0, 5.0],
                    radius: 5.0,
                    n,
                    grading,
                    grade_toward: Pole::Lower,
                    refine: 0,
                };
                let mesh = spec.build().unwrap();
                assert_valid(&mesh);
                assert_eq!(edge_count(&mesh, "arc"), n);
                let steps = arc_angles(&mesh, "arc", spec.center);
                assert!((steps.iter().sum::<f64>() - PI).abs() < 1e-12);
                assert!((total_area(&mesh) - chord_area(5.0, steps.into_iter())).abs() < 1e-9);
                assert!(close(node(&mesh, "pole"), [0.0, 0.0]));
                assert!(close(node(&mesh, "top_pole"), [0.0, 10.0]));
                assert!(close(node(&mesh, "center"), [0.0, 5.0]));
                assert!(
                    mesh.node_sets["axis"]
                        .iter()
                        .all(|&k| mesh.nodes[k][0] == 0.0)
                );
            }
        }
        let mesh = HalfDisc {
            center: [0.0, 0.0],
            radius: 1.0,
            n: 12,
            grading: 6.0,
            grade_toward: Pole::Lower,
            refine: 0,
        }
        .build()
        .unwrap();
        let steps = arc_angles(&mesh, "arc", [0.0, 0.0]);
        let first = mesh.edge_sets["arc"]
            .iter()
            .position(|e| e[0] == mesh.node_sets["pole"][0])
            .unwrap();
        assert!(steps.iter().all(|&s| s >= steps[first] - 1e-12));
    }

    /// Goal: `grade_toward = "upper"` grades the half disc toward its upper pole: the mesh
    /// graded toward the lower pole mirrored about y = cy. Setup: n = 12, grading 6 about
    /// cy = 2. Reference (geometry): every node of the upper-graded mesh is the mirror image
    /// of one of the lower-graded mesh's (same count), the quads stay counter-clockwise
    /// (positive area) with the same total area, the arc runs counter-clockwise from the lower
    /// pole to the upper one, `pole` and `top_pole` keep their places, and the smallest arc
    /// step touches the upper pole, 1/6 of the largest.
    #[test]
    fn half_disc_graded_toward_the_upper_pole_is_the_mirror_image() {
        let spec = |grade_toward| HalfDisc {
            center: [1.0, 2.0],
            radius: 3.0,
            n: 12,
            grading: 6.0,
            grade_toward,
            refine: 0,
        };
        let lower = spec(Pole::Lower).build().unwrap();
        let upper = spec(Pole::Upper).build().unwrap();
        assert_valid(&upper);
        assert_eq!(upper.nodes.len(), lower.nodes.len());
        for p in &upper.nodes {
            let image = [p[0], 4.0 - p[1]];
            assert!(lower.nodes.iter().any(|q| close(*q, image)), "{p:?}");
        }
        assert!((total_area(&upper) - total_area(&lower)).abs() < 1e-12);
        assert!(close(node(&upper, "pole"), [1.0, -1.0]));
        assert!(close(node(&upper, "top_pole"), [1.0, 5.0]));
        let arc = &upper.edge_sets["arc"];
        assert_eq!(arc[0][0], upper.node_sets["pole"][0]);
        assert_eq!(arc[arc.len() - 1][1], upper.node_sets["top_pole"][0]);
        assert!(arc.windows(2).all(|w| w[0][1] == w[1][0]));
        let steps = arc_angles(&upper, "arc", [1.0, 2.0]);
        let top = upper.node_sets["top_pole"][0];
        let at_top = arc.iter().position(|e| e.contains(&top)).unwrap();
        let largest = steps.iter().copied().fold(0.0, f64::max);
        assert!(steps.iter().all(|&s| s >= steps[at_top] - 1e-12));
        assert!((largest / steps[at_top] - 6.0).abs() < 1e-9);
    }

    /// Goal: `refine` is a mesh family by a fixed rule. Setup: half discs n = 10, grading 20
    /// (and a quarter disc n = 8, grading 5) at refine 0 to 3. Reference (geometry of the
    /// rule): at level k the arc has n 2^k steps; every arc node of level k - 1 is an arc node
    /// of level k; the pole step is half the level above's (the base's over 2^k); the ratio of
    /// consecutive arc steps is the 2^k-th root of the base's; the quads stay valid with the
    /// area of the same polygon refined. Too many levels are refused naming `refine`.
    #[test]
    fn refine_splits_every_arc_step_in_two_per_level() {
        let half = |refine| HalfDisc {
            center: [0.0, 5.0],
            radius: 5.0,
            n: 10,
            grading: 20.0,
            grade_toward: Pole::Lower,
            refine,
        };
        let arc_nodes = |mesh: &Mesh| -> Vec<Point> {
            let arc = &mesh.edge_sets["arc"];
            let mut points: Vec<Point> = arc.iter().map(|e| mesh.nodes[e[0]]).collect();
            points.push(mesh.nodes[arc[arc.len() - 1][1]]);
            points
        };
        let base_ratio = 20f64.powf(1.0 / 9.0);
        let mut above: Option<Mesh> = None;
        for k in 0..4u32 {
            let mesh = half(k).build().unwrap();
            assert_valid(&mesh);
            let steps = arc_angles(&mesh, "arc", [0.0, 5.0]);
            assert_eq!(steps.len(), 10 << k);
            let ratio = base_ratio.powf(1.0 / f64::from(1u32 << k));
            for w in steps[..steps.len() / 2].windows(2) {
                assert!((w[1] / w[0] - ratio).abs() < 1e-9, "level {k}");
            }
            if let Some(coarse) = &above {
                let fine = arc_nodes(&mesh);
                for p in arc_nodes(coarse) {
                    assert!(fine.iter().any(|q| close(*q, p)), "level {k}: {p:?}");
                }
                let coarse_steps = arc_angles(coarse, "arc", [0.0, 5.0]);
                let pole_ratio = steps[0] / coarse_steps[0];
                // two fine steps make the coarse one: s + s q^(1/2) = S, so s / S = 1 / (1 + q^(1/2))
                assert!((pole_ratio - 1.0 / (1.0 + ratio)).abs() < 1e-9, "level {k}");
                assert!((pole_ratio - 0.5).abs() < 0.08, "level {k}: {pole_ratio}");
            }
            above = Some(mesh);
        }
        let mut quarter_spec = quarter(8, 5.0, "lower");
        quarter_spec.refine = 2;
        let mesh = quarter_spec.build().unwrap();
        assert_valid(&mesh);
        assert_eq!(mesh.edge_sets["arc"].len(), 32);
        let steps = arc_angles(&mesh, "arc", [0.5, 2.0]);
        let ratio = 5f64.powf(1.0 / 7.0 / 4.0);
        assert!((steps[1] / steps[0] - ratio).abs() < 1e-9);
        let err = half(7).build().unwrap_err().to_string();
        assert!(err.contains("refine"), "{err}");
    }

    /// Ring: counts, polygon area n_circ/2 sin(2 pi/n_circ) (R^2 - r^2), outer ccw, inner cw.
    #[test]
    fn ring_has_the_polygon_area_and_oriented_sets() {
        for (n_radial, n_circ) in [(1, 3), (2, 8), (4, 37)] {
            let spec = Ring {
                center: [1.0, 1.0],
                inner_radius: 2.0,
                outer_radius: 3.0,
                n_radial,
                n_circ,
                angle: 360.0,
                grading: 1.0,
            };
            let mesh = spec.build().unwrap();
            assert_valid(&mesh);
            assert_eq!(mesh.cells.len(), n_radial * n_circ);
            assert_eq!(mesh.nodes.len(), (n_radial + 1) * n_circ);
            let nc = n_circ as f64;
            let exact = nc / 2.0 * (2.0 * PI / nc).sin() * (9.0 - 4.0);
            assert!((total_area(&mesh) - exact).abs() < 1e-12);
            assert_eq!(edge_count(&mesh, "inner"), n_circ);
            assert_eq!(edge_count(&mesh, "outer"), n_circ);
            let loop_area = |set: &str| -> f64 {
                mesh.edge_sets[set]
                    .iter()
                    .map(|e| 0.5 * cross(mesh.nodes[e[0]], mesh.nodes[e[1]]))
                    .sum()
            };
            assert!(loop_area("outer") > 0.0);
            assert!(loop_area("inner") < 0.0);
        }
    }

    /// Quarter ring: sector sets `start` (on +x) and `end` (on +y), graded radially; the area
    /// of the polygonal sector n/2 sin(theta/n) (R^2 - r^2).
    #[test]
    fn ring_sector_has_radial_sets_and_area() {
        for angle in [90.0, 180.0] {
            let spec = Ring {
                center: [0.0, 0.0],
                inner_radius: 1.0,
                outer_radius: 2.0,
                n_radial: 4,
                n_circ: 16,
                angle,
                grading: 2.0,
            };
            let mesh = spec.build().unwrap();
            assert_valid(&mesh);
            assert_eq!(mesh.nodes.len(), 5 * 17);
            let theta = f64::to_radians(angle) / 16.0;
            let exact = 16.0 / 2.0 * theta.sin() * (4.0 - 1.0);
            assert!((total_area(&mesh) - exact).abs() < 1e-12);
            assert_eq!(edge_count(&mesh, "start"), 4);
            assert_eq!(edge_count(&mesh, "end"), 4);
            assert!(
                mesh.node_sets["start"]
                    .iter()
                    .all(|n| mesh.nodes[*n][1].abs() < 1e-12)
            );
            assert!(
                mesh.node_sets["start"]
                    .iter()
                    .all(|n| mesh.nodes[*n][0] > 0.0)
            );
        }
    }

    /// Plate with a hole: valid quads, all five sets, area W H - pi a^2 / 4 up to the
    /// polygonal hole (chord error < 1e-3 with 16 segments).
    #[test]
    fn plate_with_hole_has_its_sets_and_area() {
        let mesh = PlateWithHole {
            width: 5.0,
            height: 4.0,
            radius: 1.0,
            n: 8,
            n_radial: 6,
            grading: 3.0,
        }
        .build()
        .unwrap();
        assert_valid(&mesh);
        assert_eq!(mesh.cells.len(), 2 * 8 * 6);
        for set in ["hole", "bottom", "right", "top", "left"] {
            assert!(edge_count(&mesh, set) > 0, "{set}");
        }
        assert_eq!(edge_count(&mesh, "hole"), 16);
        let exact = 20.0 - PI / 4.0;
        assert!((total_area(&mesh) - exact).abs() < 1e-3 * exact);
    }
}
