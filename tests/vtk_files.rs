//! VTK files in and out: the frames' points (the current configuration, or the reference one
//! on request).

mod common;

use impact::output::vtu::{FrameData, Section, read_frame};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A 4 x 1 cantilever of 8 x 2 quads (node spacing 0.5) bent by a tip traction far enough
/// that the tip moves by a third of the length: the old frames (points at the initial
/// coordinates) are far from the deformed ones.
const CANTILEVER: &str = r#"
[[material]]
name = "soft"
young = 1000.0
poisson = 0.3

[[body]]
name = "beam"
material = "soft"
formulation = "plane_stress"
mesh = { type = "rectangle", width = 4.0, height = 1.0, nx = 8, ny = 2 }

[[support]]
set = "left"
fix = ["x", "y"]

[[load]]
type = "traction"
set = "right"
traction = [0.0, 5.0]

[analysis]
type = "static"
steps = 8

[analysis.newton]
strategy = "full"
"#;

/// Runs `impact run SCENE --out DIR` with extra arguments; panics unless it exits 0.
fn run_scene(dir: &Path, name: &str, text: &str, extra: &[&str]) -> PathBuf {
    let scene = dir.join(format!("{name}.toml"));
    std::fs::write(&scene, text).unwrap();
    let out = dir.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(["run", scene.to_str().unwrap(), "--quiet", "--out"])
        .arg(&out)
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

/// The frames a run's .pvd lists, read back.
fn frames(out: &Path, name: &str) -> Vec<FrameData> {
    impact::output::vtk::read_pvd(&out.join(format!("{name}.pvd")))
        .unwrap()
        .iter()
        .map(|(_, path)| read_frame(path).unwrap())
        .collect()
}

/// (x, y) rows of a 3-component array; z must be 0.
fn rows(frame: &FrameData, section: Section, name: &str) -> Vec<[f64; 2]> {
    let (components, values) = frame
        .floats(section, name)
        .unwrap_or_else(|| panic!("no array {name}"));
    assert_eq!(components, 3, "{name}");
    values
        .chunks_exact(3)
        .map(|c| {
            assert_eq!(c[2], 0.0, "{name}: z");
            [c[0], c[1]]
        })
        .collect()
}

/// The 27 nodes of the 8 x 2 grid with spacing 0.5 on [0, 4] x [0, 1], each once: the
/// initial coordinates, known without the mesh generator.
fn assert_initial_grid(points: &[[f64; 2]]) {
    let mut lattice: Vec<(i64, i64)> = points
        .iter()
        .map(|p| {
            let (i, j) = ((p[0] / 0.5).round(), (p[1] / 0.5).round());
            assert_eq!([i * 0.5, j * 0.5], *p, "not a node of the initial grid");
            (i as i64, j as i64)
        })
        .collect();
    lattice.sort_unstable();
    let expected: Vec<(i64, i64)> = (0..=8).flat_map(|i| (0..=2).map(move |j| (i, j))).collect();
    assert_eq!(lattice, expected);
}

/// Goal: a frame's points are the current configuration, the initial coordinates plus the
/// displacement, to round-off; `reference_coordinates` holds the initial coordinates.
/// Setup: the finite-strain cantilever above (tip displacement about 1.3, a third of the
/// length), every frame; and the same scene in small strain (`geometry = "linear"`).
/// Reference: the initial grid (known in closed form: spacing 0.5) plus the frame's own
/// `displacement` array; in finite strain the points come from the updated configuration,
/// accumulated increment by increment, not from that sum. The displacement must be large
/// (so frames drawn at the initial coordinates would fail).
#[test]
fn frame_points_are_reference_coordinates_plus_displacement() {
    for (case, geometry) in [("finite", "nonlinear"), ("small", "linear")] {
        let dir = common::out_dir(&format!("vtk_points_{case}"));
        let set = format!("analysis.geometry={geometry}");
        let out = run_scene(&dir, "beam", CANTILEVER, &["--set", &set]);
        let frames = frames(&out, "beam");
        assert_eq!(frames.len(), 9, "{case}");
        let mut largest: f64 = 0.0;
        for frame in &frames {
            let reference = rows(frame, Section::PointData, "reference_coordinates");
            assert_initial_grid(&reference);
            let u = rows(frame, Section::PointData, "displacement");
            let points = rows(frame, Section::Points, "Points");
            for ((x, reference), u) in points.iter().zip(&reference).zip(&u) {
                for c in 0..2 {
                    let expected = reference[c] + u[c];
                    assert!(
                        (x[c] - expected).abs() <= 1e-12 * 4.0,
                        "{case}: point {x:?}, reference {reference:?} + displacement {u:?}"
                    );
                }
                largest = largest.max(u[1].abs());
            }
        }
        assert!(largest > 1.0, "{case}: the tip moves by {largest}");
    }
}

/// Goal: `output.points = "reference"` writes the initial coordinates as points, with the
/// same `displacement` as the default frames. Setup: the finite-strain cantilever, last frame.
/// Reference: the initial grid (closed form) and the default run's displacement.
#[test]
fn reference_points_on_request_are_the_initial_grid() {
    let dir = common::out_dir("vtk_points_reference");
    let out = run_scene(
        &dir,
        "beam",
        CANTILEVER,
        &["--set", "output.points=reference"],
    );
    let frames_reference = frames(&out, "beam");
    let current = frames(
        &run_scene(
            &common::out_dir("vtk_points_current"),
            "beam",
            CANTILEVER,
            &[],
        ),
        "beam",
    );
    let (last, last_current) = (frames_reference.last().unwrap(), current.last().unwrap());
    let points = rows(last, Section::Points, "Points");
    assert_initial_grid(&points);
    assert_eq!(
        points,
        rows(last, Section::PointData, "reference_coordinates")
    );
    let u = rows(last, Section::PointData, "displacement");
    assert_eq!(u, rows(last_current, Section::PointData, "displacement"));
    assert!(u.iter().any(|u| u[1] > 1.0));
    assert_eq!(last.vectors.as_deref(), Some("displacement"));
}
