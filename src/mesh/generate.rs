//! Structured mesh generators, chosen in a scene by `type = "..."` (see [`MeshSpec`]).
//!
//! Legend
//! ```text
//! point        [x, y] in the scene's length unit (axisymmetric: [r, z])
//! n, nx, ny    element counts along a side
//! grading g    size of the last element of a graded side / size of the first one, sizes in
//!              geometric progression: g > 1 puts the small elements at the named end, g < 1
//!              the large ones, g = 1 is uniform
//! block        a structured patch of quads (a map of the unit square); blocks are glued by
//!              merging coincident nodes
//! O-grid       a disc sector meshed as a core (the sector's corner polygon scaled toward the
//!              centre) plus outer blocks between the core and the arc whose grid lines are
//!              radial, so no quad degenerates at the centre or at a pole
//! ```
//! Every generator returns counter-clockwise Quad4 cells (det J > 0 at the Gauss points) or Rod2
//! cells, the `all` element set, and edge sets that together cover the boundary, oriented with
//! the body on the left; each edge set is also a node set of the same name.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::f64::consts::{FRAC_PI_2, PI};
use std::ops::RangeInclusive;
use std::path::Path;

use serde::Deserialize;

use super::plane::{Point, cross, norm, quad_area, sub};
use super::{Cells, Mesh, MeshError};

/// Size of a disc's O-grid core as a fraction of the radius.
const DISC_CORE: f64 = 0.5;
/// Share of the half width a round bar's core takes (the rest is the outer layer).
const ROUND_CORE: f64 = 0.6;
/// Accepted range of a grading (largest / smallest element size).
const GRADING_RANGE: RangeInclusive<f64> = 1e-6..=1e6;

/// A body's mesh as a scene describes it: `type = "rectangle"` etc. plus that generator's keys.
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum MeshSpec {
    Rectangle(Rectangle),
    QuarterDisc(QuarterDisc),
    HalfDisc(HalfDisc),
    Ring(Ring),
    PlateWithHole(PlateWithHole),
    ConicalBar(ConicalBar),
    RoundBar(RoundBar),
    Line(Line),
    Gmsh(GmshFile),
}

impl MeshSpec {
    /// Builds the mesh. `base_dir` (the scene file's folder) anchors a relative Gmsh path.
    pub fn build(&self, base_dir: &Path) -> Result<Mesh, MeshError> {
        match self {
            MeshSpec::Rectangle(s) => s.build(),
            MeshSpec::QuarterDisc(s) => s.build(),
            MeshSpec::HalfDisc(s) => s.build(),
            MeshSpec::Ring(s) => s.build(),
            MeshSpec::PlateWithHole(s) => s.build(),
            MeshSpec::ConicalBar(s) => s.build(),
            MeshSpec::RoundBar(s) => s.build(),
            MeshSpec::Line(s) => s.build(),
            MeshSpec::Gmsh(s) => s.build(base_dir),
        }
    }
}

fn one() -> f64 {
    1.0
}

fn lower() -> String {
    "lower".to_string()
}

// ---------------------------------------------------------------------------------------------
// Rectangle

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

// ---------------------------------------------------------------------------------------------
// Quarter disc

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
}

impl QuarterDisc {
    pub fn build(&self) -> Result<Mesh, MeshError> {
        let center = finite_point("center", self.center)?;
        let radius = positive("radius", self.radius)?;
        let n = at_least("n", self.n, 2)?;
        let grading = grading("grading", self.grading)?;
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

// ---------------------------------------------------------------------------------------------
// Half disc

/// `type = "half_disc"`: the half x >= cx of a disc of radius R (a full sphere's axisymmetric
/// section), graded toward the lower pole (cx, cy - R).
///
/// Meshing: an O-grid whose core is split at the centre into two quadrilaterals (so the centre
/// is a node), with three outer blocks (lower pole, rim, upper pole). The arc's n steps grow
/// geometrically from the lower pole. Each pole block takes a arc steps, a chosen so the three
/// blocks span angles as even as possible. Quads: n n_layer + a (n - 2 a).
///
/// Edge sets `axis` (x = cx), `arc`; one-node sets `pole` (lower pole), `top_pole`, `center`.
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
    /// Largest / smallest arc step (smallest at the lower pole), in [1e-6, 1e6]. Default 1.
    #[serde(default = "one")]
    pub grading: f64,
}

impl HalfDisc {
    pub fn build(&self) -> Result<Mesh, MeshError> {
        let center = finite_point("center", self.center)?;
        let radius = positive("radius", self.radius)?;
        let n = at_least("n", self.n, 4)?;
        let grading = grading("grading", self.grading)?;

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

// ---------------------------------------------------------------------------------------------
// Ring

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

// ---------------------------------------------------------------------------------------------
// Bars

/// `type = "conical_bar"`: a plane bar along the y axis whose lower end tapers to a sharp point:
/// tip at (0, 0), top face at y = length, x in [-width/2, width/2] (or [0, width/2] if `half`).
///
/// Meshing: the body (y >= tip_length) is an (nx/2 per half) x ny_body grid. Each half of the
/// tip triangle is split into three convex blocks meeting at an interior point: a core below
/// the body's axis end, a pole block whose corner is the tip (so the tip is a node) and a rim
/// block along the slant face. n_layer = max(1, round(min(nx/2, ny_tip) / 3)) element layers
/// run along the slant face. Quads per half: nx/2 ny_body + m1 m2 + (m1 + m2) n_layer with
/// m2 = nx/2 - n_layer, m1 = ny_tip - n_layer. The full bar is the half mirrored about x = 0.
/// For example half = true, nx = 8, ny_body = 26, ny_tip = 3 gives 115 quads; the full bar with
/// nx = 4, ny_body = 25, ny_tip = 4 gives 114.
///
/// Edge sets `tip` (the slant faces), `top`, `sides` (x = +-width/2; half: x = width/2) and, if
/// `half`, `axis` (x = 0). One-node set `tip_node` (the tip, the first contact point).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConicalBar {
    /// Full width (length), > 0.
    pub width: f64,
    /// Total length, tip to top face (length), > tip_length.
    pub length: f64,
    /// Height of the tapered end (length), > 0.
    pub tip_length: f64,
    /// Elements across the full width, even and >= 4 (the half bar keeps nx/2 of them).
    pub nx: usize,
    /// Elements along the straight body, >= 1.
    pub ny_body: usize,
    /// Elements along the axis over the tapered end, >= 2.
    pub ny_tip: usize,
    /// Mesh only x >= 0 (symmetry about x = 0). Default false.
    #[serde(default)]
    pub half: bool,
}

impl ConicalBar {
    pub fn build(&self) -> Result<Mesh, MeshError> {
        let width = positive("width", self.width)?;
        let tip_length = positive("tip_length", self.tip_length)?;
        let length = positive("length", self.length)?;
        if length <= tip_length {
            return Err(param(
                "length",
                format!("must exceed tip_length = {tip_length}, got {length}"),
            ));
        }
        let nx_half = even_width_count(self.nx)?;
        let ny_body = at_least("ny_body", self.ny_body, 1)?;
        let ny_tip = at_least("ny_tip", self.ny_tip, 2)?;

        let half_width = 0.5 * width;
        let mut grids = conical_tip(half_width, tip_length, nx_half, ny_tip);
        grids.push(tensor(
            &spaced(0.0, half_width, &uniform(nx_half)),
            &spaced(tip_length, length - tip_length, &uniform(ny_body)),
        ));
        Ok(bar_mesh(grids, self.half, half_width, length))
    }
}

/// `type = "round_bar"`: a plane bar along the y axis whose lower end is a half disc of radius
/// width/2: lowest point (0, 0), top face at y = length, x in [-width/2, width/2] (or
/// [0, width/2] if `half`).
///
/// Meshing: the body (y >= width/2) is an (nx/2 per half) x ny_body grid; each quarter of the
/// round end is an O-grid with m = round(0.6 nx/2) (kept in 1..nx/2-1) core elements across and
/// n_layer = nx/2 - m layers along the arc, so the interface columns are about uniform and the
/// arc has 2 m elements per quarter. Quads per half: nx/2 ny_body + m^2 + 2 m n_layer. The full
/// bar is the half mirrored about x = 0. For example nx = 10, ny_body = 14 gives 182 quads (full
/// bar); half = true, nx = 12, ny_body = 25 also gives 182.
///
/// Edge sets `tip` (the round end), `top`, `sides` (x = +-width/2; half: x = width/2) and, if
/// `half`, `axis` (x = 0). One-node set `tip_node` (the lowest point, the first contact point).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoundBar {
    /// Full width = diameter of the round end (length), > 0.
    pub width: f64,
    /// Total length, lowest point to top face (length), > width/2.
    pub length: f64,
    /// Elements across the full width, even and >= 4 (the half bar keeps nx/2 of them).
    pub nx: usize,
    /// Elements along the straight body, >= 1.
    pub ny_body: usize,
    /// Mesh only x >= 0 (symmetry about x = 0). Default false.
    #[serde(default)]
    pub half: bool,
}

impl RoundBar {
    pub fn build(&self) -> Result<Mesh, MeshError> {
        let width = positive("width", self.width)?;
        let length = positive("length", self.length)?;
        let radius = 0.5 * width;
        if length <= radius {
            return Err(param(
                "length",
                format!("must exceed width/2 = {radius}, got {length}"),
            ));
        }
        let nx_half = even_width_count(self.nx)?;
        let ny_body = at_least("ny_body", self.ny_body, 1)?;

        let core = ((ROUND_CORE * nx_half as f64).round() as usize).clamp(1, nx_half - 1);
        let o_grid = QuarterOGrid {
            center: [0.0, radius],
            radius,
            pole_sign: -1.0,
            arc: uniform(2 * core),
            split: core,
            core: core as f64 / nx_half as f64,
            layers: uniform(nx_half - core),
        };
        let mut grids = o_grid.grids();
        grids.push(tensor(
            &o_grid.flat_xs(),
            &spaced(radius, length - radius, &uniform(ny_body)),
        ));
        Ok(bar_mesh(grids, self.half, radius, length))
    }
}

fn even_width_count(nx: usize) -> Result<usize, MeshError> {
    at_least("nx", nx, 4)?;
    if !nx.is_multiple_of(2) {
        let reason = format!(
            "must be even and >= 4 (the axis is a grid line so the tip is a node), got {nx}"
        );
        return Err(param("nx", reason));
    }
    Ok(nx / 2)
}

/// The three blocks of the half tip triangle (0, 0), (0, tl), (w, tl); see [`ConicalBar`].
fn conical_tip(half_width: f64, tip_length: f64, nx_half: usize, ny_tip: usize) -> Vec<Grid> {
    let layers = ((nx_half.min(ny_tip) as f64 / 3.0).round() as usize).max(1);
    let (m2, m1) = (nx_half - layers, ny_tip - layers);
    let top_axis = [0.0, tip_length];
    let rim = [half_width, tip_length];
    let tip = [0.0, 0.0];
    let b = [half_width * m2 as f64 / nx_half as f64, tip_length];
    let a = [0.0, tip_length * layers as f64 / ny_tip as f64];
    let s = lerp(tip, rim, m2 as f64 / (m1 + m2) as f64);
    let d = [(a[0] + b[0] + s[0]) / 3.0, (a[1] + b[1] + s[1]) / 3.0];
    vec![
        bilinear([top_axis, b, d, a], &uniform(m2), &uniform(m1)),
        bilinear([a, d, s, tip], &uniform(m2), &uniform(layers)),
        bilinear([b, rim, s, d], &uniform(layers), &uniform(m1)),
    ]
}

/// Glues a half bar's blocks (mirrored unless `half`) and names its boundary.
fn bar_mesh(half_grids: Vec<Grid>, half: bool, half_width: f64, length: f64) -> Mesh {
    let mut grids = half_grids;
    if !half {
        let mirrored: Vec<Grid> = grids.iter().map(Grid::mirrored_x).collect();
        grids.extend(mirrored);
    }
    let mut mesh = glue(&grids);
    let tol = feature_tol(&mesh);
    name_boundary(&mut mesh, |p, q| {
        if on_line(p, q, 1, length, tol) {
            "top"
        } else if on_line(p, q, 0, 0.0, tol) {
            "axis"
        } else if on_line(p, q, 0, half_width, tol) || on_line(p, q, 0, -half_width, tol) {
            "sides"
        } else {
            "tip"
        }
    });
    let tip = node_at(&mesh, [0.0, 0.0]);
    mesh.add_node_set("tip_node", vec![tip]);
    mesh
}

// ---------------------------------------------------------------------------------------------
// Line and Gmsh

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

/// `type = "gmsh"`: a Gmsh MSH 4.1 file (what is read: [`super::gmsh::read`]).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GmshFile {
    /// Path of the .msh file; a relative path is relative to the scene file's folder.
    pub file: String,
}

impl GmshFile {
    pub fn build(&self, base_dir: &Path) -> Result<Mesh, MeshError> {
        super::gmsh::read(&base_dir.join(&self.file))
    }
}

// ---------------------------------------------------------------------------------------------
// Validation

fn param(key: &str, reason: impl Into<String>) -> MeshError {
    MeshError::Parameter {
        key: key.to_string(),
        reason: reason.into(),
    }
}

fn positive(key: &str, value: f64) -> Result<f64, MeshError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(param(
            key,
            format!("must be a finite number > 0, got {value}"),
        ))
    }
}

fn grading(key: &str, value: f64) -> Result<f64, MeshError> {
    if GRADING_RANGE.contains(&value) {
        Ok(value)
    } else {
        Err(param(
            key,
            format!("must be in [1e-6, 1e6] (1 = uniform), got {value}"),
        ))
    }
}

/// The most divisions along one direction of a generated mesh (a count beyond it is a typo
/// that would allocate without end, not a mesh).
pub const MAX_DIVISIONS: usize = 20_000;
/// The most elements a `rectangle` may generate (4000 x 2500; a million load in about a second).
pub const MAX_ELEMENTS: usize = 10_000_000;

fn at_least(key: &str, value: usize, min: usize) -> Result<usize, MeshError> {
    if value > MAX_DIVISIONS {
        Err(param(
            key,
            format!("must be at most {MAX_DIVISIONS}, got {value}"),
        ))
    } else if value >= min {
        Ok(value)
    } else {
        Err(param(key, format!("must be >= {min}, got {value}")))
    }
}

fn finite_point(key: &str, p: Point) -> Result<Point, MeshError> {
    if p.iter().all(|c| c.is_finite()) {
        Ok(p)
    } else {
        Err(param(key, format!("must be finite, got {p:?}")))
    }
}

// ---------------------------------------------------------------------------------------------
// Distributions: fractions 0 = t_0 < t_1 < ... < t_n = 1 along a side

/// n steps, each q times the previous one.
fn geometric(n: usize, q: f64) -> Vec<f64> {
    let mut ts = Vec::with_capacity(n + 1);
    let (mut sum, mut step) = (0.0, 1.0);
    ts.push(0.0);
    for _ in 0..n {
        sum += step;
        ts.push(sum);
        step *= q;
    }
    ts.iter().map(|t| t / sum).collect()
}

/// n steps with last / first = grading.
fn graded(n: usize, grading: f64) -> Vec<f64> {
    let q = if n > 1 {
        grading.powf(1.0 / (n - 1) as f64)
    } else {
        1.0
    };
    geometric(n, q)
}

fn uniform(n: usize) -> Vec<f64> {
    (0..=n).map(|k| k as f64 / n as f64).collect()
}

/// The same steps measured from the other end.
fn reversed(ts: &[f64]) -> Vec<f64> {
    ts.iter().rev().map(|t| 1.0 - t).collect()
}

/// `ts` as is, or from the far end.
fn from_end(ts: Vec<f64>, far_end: bool) -> Vec<f64> {
    if far_end { reversed(&ts) } else { ts }
}

/// Coordinates start + length t.
fn spaced(start: f64, length: f64, ts: &[f64]) -> Vec<f64> {
    ts.iter().map(|t| start + length * t).collect()
}

/// The index in `range` whose fraction is nearest to `target`.
fn nearest(ts: &[f64], target: f64, range: RangeInclusive<usize>) -> usize {
    range
        .min_by(|&a, &b| (ts[a] - target).abs().total_cmp(&(ts[b] - target).abs()))
        .expect("validated counts give a non-empty range")
}

/// Fractions 0 (core) .. 1 (arc) of an O-grid's outer layers: as many layers as the thickness
/// holds mean arc steps, growing away from the arc (at most 2x per layer) so that the layer at
/// the arc is about as thick as the arc step next to it.
fn layer_fractions(thickness: f64, mean_step: f64, step_at_arc: f64) -> Vec<f64> {
    let layers = ((thickness / mean_step).round() as usize).max(1);
    if layers == 1 {
        return vec![0.0, 1.0];
    }
    let target = step_at_arc / thickness;
    let first_step = |ln_q: f64| 1.0 / (0..layers).map(|k| (k as f64 * ln_q).exp()).sum::<f64>();
    let (mut lo, mut hi) = (-2f64.ln(), 2f64.ln());
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if first_step(mid) > target {
            lo = mid
        } else {
            hi = mid
        }
    }
    reversed(&geometric(layers, (0.5 * (lo + hi)).exp()))
}

// ---------------------------------------------------------------------------------------------
// Geometry

fn lerp(a: Point, b: Point, t: f64) -> Point {
    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
}

fn along(a: Point, b: Point, ts: &[f64]) -> Vec<Point> {
    ts.iter().map(|&t| lerp(a, b, t)).collect()
}

/// Where the rays from `center` through `points` cut the chord from the first to the last
/// point, as fractions of the chord (exactly 0 and 1 at its ends).
fn ray_fractions(center: Point, points: &[Point]) -> Vec<f64> {
    let last = points.len() - 1;
    let (p, q) = (sub(points[0], center), sub(points[last], center));
    let interior = |x: Point| {
        let d = sub(x, center);
        cross(p, d) / cross(sub(p, q), d)
    };
    (0..=last)
        .map(|k| {
            if k == 0 {
                0.0
            } else if k == last {
                1.0
            } else {
                interior(points[k])
            }
        })
        .collect()
}

/// O-grid of a quarter disc: the core [centre, B, D, A] is the polygon centre-rim-split-pole
/// scaled by `core`; the pole block spans pole..split and the rim block split..rim of the arc.
struct QuarterOGrid {
    center: Point,
    radius: f64,
    /// +1: pole at (cx, cy + R); -1: pole at (cx, cy - R).
    pole_sign: f64,
    /// Arc node fractions from the pole (0) to the rim on y = cy (1).
    arc: Vec<f64>,
    /// Arc index where the pole and rim blocks meet.
    split: usize,
    /// Core size / radius.
    core: f64,
    /// Outer layer fractions from the core (0) to the arc (1).
    layers: Vec<f64>,
}

impl QuarterOGrid {
    /// Point of the arc at `fraction` (0 pole, 1 rim), exact at both ends.
    fn arc_point(&self, fraction: f64) -> Point {
        let (sin, cos) = if fraction == 0.0 {
            (0.0, 1.0)
        } else if fraction == 1.0 {
            (1.0, 0.0)
        } else {
            (FRAC_PI_2 * fraction).sin_cos()
        };
        [
            self.center[0] + self.radius * sin,
            self.center[1] + self.pole_sign * self.radius * cos,
        ]
    }

    fn arc_points(&self, fractions: &[f64]) -> Vec<Point> {
        fractions.iter().map(|&f| self.arc_point(f)).collect()
    }

    fn grids(&self) -> Vec<Grid> {
        let pole_arc = self.arc_points(&self.arc[..=self.split]);
        let rim_arc = self.arc_points(&self.arc[self.split..]);
        let scaled = |p: Point| lerp(self.center, p, self.core);
        let (a, d, b) = (
            scaled(pole_arc[0]),
            scaled(rim_arc[0]),
            scaled(*rim_arc.last().unwrap()),
        );
        let us = ray_fractions(self.center, &pole_arc);
        let ts = ray_fractions(self.center, &rim_arc);
        vec![
            bilinear([self.center, b, d, a], &us, &reversed(&ts)),
            ruled(&along(a, d, &us), &pole_arc, &self.layers),
            ruled(&along(d, b, &ts), &rim_arc, &self.layers),
        ]
    }

    /// x of the nodes on the flat face, from the centre to the rim.
    fn flat_xs(&self) -> Vec<f64> {
        let pole_arc = self.arc_points(&self.arc[..=self.split]);
        let b = self.center[0] + self.core * self.radius;
        let rim = self.center[0] + self.radius;
        let core_xs = ray_fractions(self.center, &pole_arc)
            .into_iter()
            .map(|u| self.center[0] + u * (b - self.center[0]));
        let layer_xs = self.layers[1..].iter().map(|w| b + w * (rim - b));
        core_xs.chain(layer_xs).collect()
    }
}

/// O-grid of a half disc x >= cx: the core (the polygon lower pole - low split - high split -
/// top pole scaled by `core`) is cut at the centre into a lower and an upper quadrilateral;
/// outer blocks span the arc from the lower pole to `low`, `low` to `n - low`, and on to the top.
struct HalfOGrid {
    center: Point,
    radius: f64,
    /// Arc node fractions from the lower pole (0) to the top pole (1).
    arc: Vec<f64>,
    /// Arc steps of each pole block.
    low: usize,
    /// Arc index (strictly between the splits) of the point the core is cut to from the centre.
    equator: usize,
    /// Core size / radius.
    core: f64,
    /// Outer layer fractions from the core (0) to the arc (1).
    layers: Vec<f64>,
}

impl HalfOGrid {
    /// Point of the arc at `fraction` (0 lower pole, 1 top pole), exact at both ends.
    fn arc_point(&self, fraction: f64) -> Point {
        let (sin, cos) = if fraction == 0.0 {
            (0.0, 1.0)
        } else if fraction == 1.0 {
            (0.0, -1.0)
        } else {
            (PI * fraction).sin_cos()
        };
        [
            self.center[0] + self.radius * sin,
            self.center[1] - self.radius * cos,
        ]
    }

    fn arc_points(&self, fractions: &[f64]) -> Vec<Point> {
        fractions.iter().map(|&f| self.arc_point(f)).collect()
    }

    fn grids(&self) -> Vec<Grid> {
        let n = self.arc.len() - 1;
        let (a, b, e) = (self.low, n - self.low, self.equator);
        let low_arc = self.arc_points(&self.arc[..=a]);
        let rim_arc = self.arc_points(&self.arc[a..=b]);
        let top_arc = self.arc_points(&self.arc[b..]);
        let scaled = |p: Point| lerp(self.center, p, self.core);
        let (low_pole, low_split) = (scaled(low_arc[0]), scaled(rim_arc[0]));
        let (top_split, top_pole) = (scaled(rim_arc[b - a]), scaled(top_arc[a]));

        let us = ray_fractions(self.center, &low_arc);
        let ts = ray_fractions(self.center, &rim_arc);
        let t_mid = ts[e - a];
        let mid = lerp(low_split, top_split, t_mid);
        let v_low: Vec<f64> = ts[..=e - a].iter().map(|t| t / t_mid).collect();
        let v_top: Vec<f64> = ts[e - a..]
            .iter()
            .map(|t| (t - t_mid) / (1.0 - t_mid))
            .collect();
        let top_inner: Vec<Point> = along(top_pole, top_split, &us).into_iter().rev().collect();
        vec![
            bilinear([low_pole, low_split, mid, self.center], &us, &v_low),
            bilinear([self.center, mid, top_split, top_pole], &us, &v_top),
            ruled(&along(low_pole, low_split, &us), &low_arc, &self.layers),
            ruled(&along(low_split, top_split, &ts), &rim_arc, &self.layers),
            ruled(&top_inner, &top_arc, &self.layers),
        ]
    }
}

// ---------------------------------------------------------------------------------------------
// Blocks

/// A structured patch of (ni + 1) x (nj + 1) points, i running fastest.
struct Grid {
    ni: usize,
    nj: usize,
    points: Vec<Point>,
}

impl Grid {
    fn from_fn(ni: usize, nj: usize, mut f: impl FnMut(usize, usize) -> Point) -> Grid {
        let mut points = Vec::with_capacity((ni + 1) * (nj + 1));
        for j in 0..=nj {
            for i in 0..=ni {
                points.push(f(i, j));
            }
        }
        Grid { ni, nj, points }
    }

    /// Local point ids of quad (i, j): (i, j), (i+1, j), (i+1, j+1), (i, j+1).
    fn quads(&self) -> Vec<[usize; 4]> {
        let id = |i: usize, j: usize| i + (self.ni + 1) * j;
        let mut quads = Vec::with_capacity(self.ni * self.nj);
        for j in 0..self.nj {
            for i in 0..self.ni {
                quads.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        quads
    }

    fn area(&self) -> f64 {
        self.quads()
            .iter()
            .map(|q| quad_area(q.map(|k| self.points[k])))
            .sum()
    }

    fn mirrored_x(&self) -> Grid {
        let points = self.points.iter().map(|p| [-p[0], p[1]]).collect();
        Grid {
            ni: self.ni,
            nj: self.nj,
            points,
        }
    }
}

/// xs x ys.
fn tensor(xs: &[f64], ys: &[f64]) -> Grid {
    Grid::from_fn(xs.len() - 1, ys.len() - 1, |i, j| [xs[i], ys[j]])
}

/// The bilinear map of the quadrilateral [c00, c10, c11, c01] sampled at us x vs. Points on the
/// sides through c00 are exact, so they stay on a straight boundary (an axis, a flat face).
fn bilinear(corners: [Point; 4], us: &[f64], vs: &[f64]) -> Grid {
    let [p00, p10, p11, p01] = corners;
    Grid::from_fn(us.len() - 1, vs.len() - 1, |i, j| {
        let (u, v) = (us[i], vs[j]);
        std::array::from_fn(|k| {
            p00[k]
                + u * (p10[k] - p00[k])
                + v * (p01[k] - p00[k])
                + u * v * (p11[k] - p10[k] - p01[k] + p00[k])
        })
    })
}

/// Straight grid lines from inner[i] to outer[i], sampled at ws (0 inner, 1 outer).
fn ruled(inner: &[Point], outer: &[Point], ws: &[f64]) -> Grid {
    Grid::from_fn(inner.len() - 1, ws.len() - 1, |i, j| {
        lerp(inner[i], outer[i], ws[j])
    })
}

/// One Quad4 mesh from blocks: each block oriented counter-clockwise, coincident nodes merged.
fn glue(grids: &[Grid]) -> Mesh {
    let mut points = Vec::new();
    let mut quads = Vec::new();
    for grid in grids {
        let offset = points.len();
        let flip = grid.area() < 0.0;
        for q in grid.quads() {
            let [a, b, c, d] = q.map(|k| k + offset);
            quads.push(if flip { [a, d, c, b] } else { [a, b, c, d] });
        }
        points.extend_from_slice(&grid.points);
    }
    let tol = 1e-6 * min_edge(&points, &quads);
    let (nodes, ids) = merge_coincident(&points, tol);
    let quads = quads.iter().map(|q| q.map(|k| ids[k])).collect();
    Mesh::new(nodes, Cells::Quad4(quads))
}

fn min_edge(points: &[Point], quads: &[[usize; 4]]) -> f64 {
    let edges = quads
        .iter()
        .flat_map(|q| (0..4).map(move |k| [q[k], q[(k + 1) % 4]]));
    edges
        .map(|[a, b]| norm(sub(points[a], points[b])))
        .fold(f64::INFINITY, f64::min)
}

/// Distinct points (first occurrence kept) and each input point's new id; points closer than
/// `tol` are one.
fn merge_coincident(points: &[Point], tol: f64) -> (Vec<Point>, Vec<usize>) {
    let cell = tol.max(f64::MIN_POSITIVE);
    let key = |p: Point| ((p[0] / cell).floor() as i64, (p[1] / cell).floor() as i64);
    let mut buckets: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    let mut nodes: Vec<Point> = Vec::new();
    let mut ids = Vec::with_capacity(points.len());
    for &p in points {
        let (kx, ky) = key(p);
        let neighbours = (-1..=1).flat_map(|dx| (-1..=1).map(move |dy| (kx + dx, ky + dy)));
        let found = neighbours
            .filter_map(|k| buckets.get(&k))
            .flatten()
            .copied()
            .find(|&n| norm(sub(nodes[n], p)) <= tol);
        let id = found.unwrap_or_else(|| {
            nodes.push(p);
            buckets.entry((kx, ky)).or_default().push(nodes.len() - 1);
            nodes.len() - 1
        });
        ids.push(id);
    }
    (nodes, ids)
}

// ---------------------------------------------------------------------------------------------
// Sets

/// Distance below which a node counts as lying on a line: far below any element size.
fn feature_tol(mesh: &Mesh) -> f64 {
    let Cells::Quad4(quads) = &mesh.cells else {
        return 0.0;
    };
    1e-6 * min_edge(&mesh.nodes, quads)
}

/// Both ends on the line coordinate[axis] = value.
fn on_line(p: Point, q: Point, axis: usize, value: f64, tol: f64) -> bool {
    (p[axis] - value).abs() <= tol && (q[axis] - value).abs() <= tol
}

/// Puts every boundary edge a -> b into the edge set `name_of(x_a, x_b)`.
fn name_boundary(mesh: &mut Mesh, name_of: impl Fn(Point, Point) -> &'static str) {
    let mut sets: BTreeMap<&str, Vec<[usize; 2]>> = BTreeMap::new();
    for e in mesh.boundary_edges() {
        sets.entry(name_of(mesh.nodes[e[0]], mesh.nodes[e[1]]))
            .or_default()
            .push(e);
    }
    for (name, edges) in sets {
        mesh.add_edge_set(name, chain_order(edges));
    }
}

/// Edges head to tail: open chains first (by first node), then closed loops.
fn chain_order(edges: Vec<[usize; 2]>) -> Vec<[usize; 2]> {
    let mut leaving: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (k, e) in edges.iter().enumerate() {
        leaving.entry(e[0]).or_default().push(k);
    }
    let ends: BTreeSet<usize> = edges.iter().map(|e| e[1]).collect();
    let mut heads: Vec<usize> = edges
        .iter()
        .map(|e| e[0])
        .filter(|n| !ends.contains(n))
        .collect();
    heads.sort_unstable();
    heads.extend(edges.iter().map(|e| e[0]));

    let mut used = vec![false; edges.len()];
    let mut ordered = Vec::with_capacity(edges.len());
    for head in heads {
        let mut node = head;
        while let Some(&k) = leaving
            .get(&node)
            .and_then(|ks| ks.iter().find(|&&k| !used[k]))
        {
            used[k] = true;
            ordered.push(edges[k]);
            node = edges[k][1];
        }
    }
    ordered
}

/// The node nearest to `p`.
fn node_at(mesh: &Mesh, p: Point) -> usize {
    let distance = |n: &usize| norm(sub(mesh.nodes[*n], p));
    (0..mesh.nodes.len())
        .min_by(|a, b| distance(a).total_cmp(&distance(b)))
        .expect("a generated mesh has nodes")
}

#[cfg(test)]
mod tests {
    use super::*;

    const GAUSS: f64 = 0.577_350_269_189_625_8;

    /// det J at the 2x2 Gauss points of a Quad4.
    fn det_j(x: [Point; 4]) -> [f64; 4] {
        let points = [
            (-GAUSS, -GAUSS),
            (GAUSS, -GAUSS),
            (GAUSS, GAUSS),
            (-GAUSS, GAUSS),
        ];
        points.map(|(xi, eta)| {
            let d_xi = [-(1.0 - eta), 1.0 - eta, 1.0 + eta, -(1.0 + eta)].map(|v| 0.25 * v);
            let d_eta = [-(1.0 - xi), -(1.0 + xi), 1.0 + xi, 1.0 - xi].map(|v| 0.25 * v);
            let j = |d: [f64; 4], c: usize| (0..4).map(|k| d[k] * x[k][c]).sum::<f64>();
            j(d_xi, 0) * j(d_eta, 1) - j(d_eta, 0) * j(d_xi, 1)
        })
    }

    fn quads(mesh: &Mesh) -> &[[usize; 4]] {
        match &mesh.cells {
            Cells::Quad4(q) => q,
            Cells::Rod2(_) => panic!("expected quads"),
        }
    }

    fn total_area(mesh: &Mesh) -> f64 {
        quads(mesh)
            .iter()
            .map(|q| quad_area(q.map(|n| mesh.nodes[n])))
            .sum()
    }

    fn edge_count(mesh: &Mesh, name: &str) -> usize {
        mesh.edge_sets[name].len()
    }

    /// The checks every generated quad mesh must pass: det J > 0 at every Gauss point, `all`,
    /// no duplicate or unused nodes, every edge set on the boundary with the boundary's
    /// orientation and chained head to tail, its node set matching, and the edge sets exactly
    /// covering the boundary.
    fn assert_valid(mesh: &Mesh) {
        let quads = quads(mesh);
        for (e, q) in quads.iter().enumerate() {
            let dets = det_j(q.map(|n| mesh.nodes[n]));
            assert!(dets.iter().all(|&d| d > 0.0), "element {e}: det J {dets:?}");
        }
        assert_eq!(
            mesh.element_sets["all"],
            (0..quads.len()).collect::<Vec<_>>()
        );
        let used: BTreeSet<usize> = quads.iter().flatten().copied().collect();
        assert_eq!(used.len(), mesh.nodes.len(), "unused nodes");
        let (distinct, _) = merge_coincident(&mesh.nodes, 1e-9 * min_edge(&mesh.nodes, quads));
        assert_eq!(distinct.len(), mesh.nodes.len(), "duplicate nodes");

        let boundary: BTreeSet<[usize; 2]> = mesh.boundary_edges().into_iter().collect();
        let mut covered = BTreeSet::new();
        for (name, edges) in &mesh.edge_sets {
            for e in edges {
                assert!(
                    boundary.contains(e),
                    "set {name}: edge {e:?} is not a ccw boundary edge"
                );
                assert!(covered.insert(*e), "edge {e:?} in two sets");
            }
            let chained = edges.windows(2).filter(|w| w[0][1] == w[1][0]).count();
            let chains = edges.len() - chained;
            assert!(chains <= 2, "set {name} is in {chains} pieces");
            let nodes: BTreeSet<usize> = edges.iter().flatten().copied().collect();
            assert_eq!(
                mesh.node_sets[name],
                nodes.into_iter().collect::<Vec<_>>(),
                "node set {name}"
            );
        }
        assert_eq!(covered, boundary, "edge sets do not cover the boundary");
    }

    fn node(mesh: &Mesh, set: &str) -> Point {
        let ids = &mesh.node_sets[set];
        assert_eq!(ids.len(), 1, "set {set}");
        mesh.nodes[ids[0]]
    }

    fn close(a: Point, b: Point) -> bool {
        norm(sub(a, b)) < 1e-12 * (1.0 + norm(b))
    }

    /// Exact area of a disc sector minus the segments cut off by the chords of the arc steps.
    fn chord_area(radius: f64, angles: impl Iterator<Item = f64>) -> f64 {
        angles.map(|d| 0.5 * radius * radius * d.sin()).sum()
    }

    fn arc_angles(mesh: &Mesh, set: &str, center: Point) -> Vec<f64> {
        let angle = |p: Point| (p[1] - center[1]).atan2(p[0] - center[0]);
        mesh.edge_sets[set]
            .iter()
            .map(|e| {
                let d = angle(mesh.nodes[e[1]]) - angle(mesh.nodes[e[0]]);
                d.abs().min(2.0 * PI - d.abs())
            })
            .collect()
    }

    fn rectangle(nx: usize, ny: usize) -> Rectangle {
        Rectangle {
            origin: [1.0, -2.0],
            width: 3.0,
            height: 2.0,
            nx,
            ny,
            grading_x: 1.0,
            grading_y: 1.0,
            grade_toward: None,
        }
    }

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

    fn quarter(n: usize, grading: f64, quadrant: &str) -> QuarterDisc {
        QuarterDisc {
            center: [0.5, 2.0],
            radius: 8.0,
            n,
            grading,
            quadrant: quadrant.into(),
        }
    }

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

    fn cone(nx: usize, ny_body: usize, ny_tip: usize, half: bool) -> ConicalBar {
        ConicalBar {
            width: 0.02,
            length: 0.1,
            tip_length: 0.015,
            nx,
            ny_body,
            ny_tip,
            half,
        }
    }

    fn cone_count(nx: usize, ny_body: usize, ny_tip: usize, half: bool) -> usize {
        let nh = nx / 2;
        let layers = ((nh.min(ny_tip) as f64 / 3.0).round() as usize).max(1);
        let (m2, m1) = (nh - layers, ny_tip - layers);
        let per_half = nh * ny_body + m1 * m2 + (m1 + m2) * layers;
        if half { per_half } else { 2 * per_half }
    }

    /// Conical bar: valid quads for blunt to slender tips, exact area, counts, tip node, sets.
    #[test]
    fn conical_bar_is_valid_with_a_node_at_the_tip() {
        for tip_length in [0.002, 0.015, 0.09] {
            for (nx, ny_body, ny_tip) in [
                (4, 1, 2),
                (4, 25, 4),
                (6, 10, 3),
                (8, 26, 3),
                (10, 12, 9),
                (16, 3, 2),
            ] {
                for half in [false, true] {
                    let spec = ConicalBar {
                        tip_length,
                        ..cone(nx, ny_body, ny_tip, half)
                    };
                    let mesh = spec.build().unwrap();
                    assert_valid(&mesh);
                    assert_eq!(mesh.cells.len(), cone_count(nx, ny_body, ny_tip, half));
                    let full_area = 0.02 * (0.1 - tip_length) + 0.5 * 0.02 * tip_length;
                    let area = if half { 0.5 * full_area } else { full_area };
                    assert!((total_area(&mesh) - area).abs() < 1e-15);
                    assert!(close(node(&mesh, "tip_node"), [0.0, 0.0]));
                    assert_eq!(edge_count(&mesh, "top"), if half { nx / 2 } else { nx });
                    assert_eq!(
                        edge_count(&mesh, "sides"),
                        if half { ny_body } else { 2 * ny_body }
                    );
                    assert_eq!(mesh.edge_sets.contains_key("axis"), half);
                    if half {
                        assert_eq!(edge_count(&mesh, "axis"), ny_body + ny_tip);
                        assert!(
                            mesh.node_sets["axis"]
                                .iter()
                                .all(|&k| mesh.nodes[k][0] == 0.0)
                        );
                    }
                }
            }
        }
        assert_eq!(cone(8, 26, 3, true).build().unwrap().cells.len(), 115);
        assert_eq!(cone(4, 25, 4, false).build().unwrap().cells.len(), 114);
    }

    fn round(nx: usize, ny_body: usize, half: bool) -> RoundBar {
        RoundBar {
            width: 0.02,
            length: 0.06,
            nx,
            ny_body,
            half,
        }
    }

    /// Round bar: valid quads, counts, area = rectangle + half disc minus chord segments.
    #[test]
    fn round_bar_is_valid_with_a_node_at_the_lowest_point() {
        for nx in [4, 6, 8, 10, 12, 20] {
            for half in [false, true] {
                let mesh = round(nx, 7, half).build().unwrap();
                assert_valid(&mesh);
                let nh = nx / 2;
                let core = ((0.6 * nh as f64).round() as usize).clamp(1, nh - 1);
                let per_half = nh * 7 + core * core + 2 * core * (nh - core);
                assert_eq!(mesh.cells.len(), if half { per_half } else { 2 * per_half });
                assert_eq!(
                    edge_count(&mesh, "tip"),
                    if half { 2 * core } else { 4 * core }
                );
                let steps = arc_angles(&mesh, "tip", [0.0, 0.01]);
                let rect = 0.02 * 0.05 * if half { 0.5 } else { 1.0 };
                assert!(
                    (total_area(&mesh) - rect - chord_area(0.01, steps.into_iter())).abs() < 1e-15
                );
                assert!(close(node(&mesh, "tip_node"), [0.0, 0.0]));
                assert_eq!(edge_count(&mesh, "sides"), if half { 7 } else { 14 });
            }
        }
        assert_eq!(round(10, 14, false).build().unwrap().cells.len(), 182);
        assert_eq!(round(12, 25, true).build().unwrap().cells.len(), 182);
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

    fn key_of(result: Result<Mesh, MeshError>) -> String {
        match result {
            Err(MeshError::Parameter { key, .. }) => key,
            other => panic!("expected a parameter error, got {other:?}"),
        }
    }

    /// Invalid parameters are errors that name the key, never panics or clamping.
    #[test]
    fn invalid_parameters_name_their_key() {
        assert_eq!(
            key_of(
                Rectangle {
                    width: -1.0,
                    ..rectangle(2, 2)
                }
                .build()
            ),
            "width"
        );
        assert_eq!(
            key_of(
                Rectangle {
                    height: f64::NAN,
                    ..rectangle(2, 2)
                }
                .build()
            ),
            "height"
        );
        assert_eq!(key_of(rectangle(0, 2).build()), "nx");
        assert_eq!(
            key_of(
                Rectangle {
                    grading_y: 0.0,
                    ..rectangle(2, 2)
                }
                .build()
            ),
            "grading_y"
        );
        assert_eq!(
            key_of(
                Rectangle {
                    grade_toward: Some("up".into()),
                    ..rectangle(2, 2)
                }
                .build()
            ),
            "grade_toward"
        );
        assert_eq!(key_of(quarter(1, 1.0, "lower").build()), "n");
        assert_eq!(key_of(quarter(4, 1.0, "left").build()), "quadrant");
        assert_eq!(key_of(quarter(4, -2.0, "lower").build()), "grading");
        assert_eq!(
            key_of(
                HalfDisc {
                    center: [0.0, 0.0],
                    radius: 1.0,
                    n: 3,
                    grading: 1.0
                }
                .build()
            ),
            "n"
        );
        let ring = Ring {
            center: [0.0, 0.0],
            inner_radius: 2.0,
            outer_radius: 2.0,
            n_radial: 1,
            n_circ: 8,
            angle: 360.0,
            grading: 1.0,
        };
        assert_eq!(key_of(ring.build()), "outer_radius");
        assert_eq!(
            key_of(
                Ring {
                    n_circ: 2,
                    outer_radius: 3.0,
                    ..ring
                }
                .build()
            ),
            "n_circ"
        );
        assert_eq!(key_of(cone(5, 4, 3, false).build()), "nx");
        assert_eq!(key_of(cone(2, 4, 3, true).build()), "nx");
        assert_eq!(key_of(cone(4, 4, 1, false).build()), "ny_tip");
        assert_eq!(
            key_of(
                ConicalBar {
                    length: 0.01,
                    ..cone(4, 4, 3, false)
                }
                .build()
            ),
            "length"
        );
        assert_eq!(
            key_of(
                RoundBar {
                    length: 0.01,
                    ..round(4, 4, false)
                }
                .build()
            ),
            "length"
        );
        assert_eq!(key_of(round(4, 0, false).build()), "ny_body");
        assert_eq!(
            key_of(
                Line {
                    start: [1.0, 1.0],
                    end: [1.0, 1.0],
                    n: 2,
                    grading: 1.0
                }
                .build()
            ),
            "end"
        );
    }

    fn spec(text: &str) -> Result<MeshSpec, toml::de::Error> {
        toml::from_str(text)
    }

    /// Scene text: every type parses with its defaults; a misspelled key is rejected.
    #[test]
    fn specs_parse_from_toml_and_reject_unknown_keys() {
        let base = Path::new(".");
        let texts = [
            "type = 'rectangle'\nwidth = 2\nheight = 1\nnx = 2\nny = 1",
            "type = 'quarter_disc'\nradius = 8\nn = 8",
            "type = 'half_disc'\nradius = 5\nn = 8\ngrading = 3",
            "type = 'ring'\ninner_radius = 1\nouter_radius = 1.5\nn_radial = 2\nn_circ = 24",
            "type = 'conical_bar'\nwidth = 0.02\nlength = 0.1\ntip_length = 0.01\nnx = 4\nny_body = 10\nny_tip = 3",
            "type = 'round_bar'\nwidth = 0.02\nlength = 0.1\nnx = 6\nny_body = 10\nhalf = true",
            "type = 'line'\nstart = [0, 0]\nend = [10, 0]\nn = 10",
        ];
        for text in texts {
            let mesh = spec(text).unwrap().build(base).unwrap();
            assert!(!mesh.cells.is_empty(), "{text}");
        }
        let MeshSpec::QuarterDisc(q) = spec("type = 'quarter_disc'\nradius = 8\nn = 8").unwrap()
        else {
            panic!("quarter disc expected")
        };
        assert_eq!(
            (q.center, q.grading, q.quadrant.as_str()),
            ([0.0, 0.0], 1.0, "lower")
        );

        let misspelled =
            spec("type = 'rectangle'\nwidth = 2\nheight = 1\nnx = 2\nny = 1\ngradng_x = 2");
        assert!(misspelled.unwrap_err().to_string().contains("gradng_x"));
        assert!(spec("type = 'quarter_disc'\nradius = 8\nn = 8\nquadrnt = 'upper'").is_err());
        assert!(spec("type = 'gmsh'\nfile = 'a.msh'\nscale = 2").is_err());
        assert!(spec("type = 'hexagon'\nradius = 1").is_err());
    }

    /// A relative Gmsh path is resolved against the scene's folder.
    #[test]
    fn gmsh_spec_resolves_relative_paths() {
        let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
        let mesh = spec("type = 'gmsh'\nfile = 'two_quads.msh'")
            .unwrap()
            .build(&data)
            .unwrap();
        assert_eq!(mesh.cells.len(), 2);
        let missing = spec("type = 'gmsh'\nfile = 'none.msh'")
            .unwrap()
            .build(&data);
        assert!(matches!(missing, Err(MeshError::Io { .. })));
    }
}
