//! Bars with a tip: `conical_bar` (a tapered end meshed as three convex blocks per half) and
//! `round_bar` (a half-disc end meshed as two quarter O-grids), each a half mirrored about x = 0
//! unless `half`.

use serde::Deserialize;

use super::blocks::{Grid, bilinear, glue, lerp, tensor};
use super::ogrid::QuarterOGrid;
use super::params::{at_least, param, positive};
use super::sets::{feature_tol, name_boundary, node_at, on_line};
use super::spacing::{spaced, uniform};
use crate::mesh::{Mesh, MeshError};

/// Share of the half width a round bar's core takes (the rest is the outer layer).
const ROUND_CORE: f64 = 0.6;

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

#[cfg(test)]
mod tests {
    use super::super::testing::*;
    use super::*;

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
}
