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
//!
//! Files: the generators by shape family in rectangle.rs (`rectangle`, `line`), discs.rs
//! (`quarter_disc`, `half_disc`, `ring`, `plate_with_hole`) and bars.rs (`conical_bar`,
//! `round_bar`); the O-grids of the discs and the round bar's end in ogrid.rs; what they share
//! in blocks.rs (structured patches, glued by merging coincident nodes), spacing.rs (node
//! fractions along a side), sets.rs (naming the boundary) and params.rs (checking a scene's
//! numbers).

mod bars;
mod blocks;
mod discs;
mod ogrid;
mod params;
mod rectangle;
mod sets;
mod spacing;

pub use bars::{ConicalBar, RoundBar};
pub use discs::{HalfDisc, PlateWithHole, QuarterDisc, Ring};
pub use params::{MAX_DIVISIONS, MAX_ELEMENTS};
pub use rectangle::{Line, Rectangle};

use std::path::Path;

use serde::Deserialize;

use super::{Mesh, MeshError};

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
    Vtk(VtkFile),
}

impl MeshSpec {
    /// Builds the mesh. `base_dir` (the scene file's folder) anchors a relative file path.
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
            MeshSpec::Vtk(s) => s.build(base_dir),
        }
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

/// `type = "vtk"`: a legacy .vtk or XML .vtu file (what is read: [`super::vtk::read`]).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VtkFile {
    /// Path of the .vtk or .vtu file; a relative path is relative to the scene file's folder.
    pub file: String,
    /// Integer point or cell data arrays whose values name sets (`NAME_value`). Default: none.
    #[serde(default)]
    pub sets: Vec<String>,
}

impl VtkFile {
    pub fn build(&self, base_dir: &Path) -> Result<Mesh, MeshError> {
        super::vtk::read(&base_dir.join(&self.file), &self.sets)
    }
}

#[cfg(test)]
mod testing;

#[cfg(test)]
mod tests {
    use super::testing::*;
    use super::*;

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
                    grading: 1.0,
                    grade_toward: Default::default(),
                    refine: 0,
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
        let Ok(MeshSpec::Vtk(vtk)) = spec("type = 'vtk'\nfile = 'a.vtu'") else {
            panic!("a vtk spec expected")
        };
        assert!(vtk.sets.is_empty());
        let misspelled = spec("type = 'vtk'\nfile = 'a.vtu'\nset = ['region']");
        assert!(misspelled.unwrap_err().to_string().contains("sets"));
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
