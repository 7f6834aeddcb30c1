//! VTK files in and out: meshes read from legacy .vtk and XML .vtu files (`mesh.type =
//! "vtk"`), the same model as from the generator and from Gmsh, the errors of bad files; the
//! frames' points (the current configuration, or the reference one on request).

mod common;

use impact::mesh::{Cells, Mesh, MeshError};
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

/// Asserts that a frame's points are its `reference_coordinates` plus its `displacement`
/// within `tolerance`; returns the largest displacement.
fn points_are_reference_plus_displacement(frame: &FrameData, tolerance: f64, what: &str) -> f64 {
    let reference = rows(frame, Section::PointData, "reference_coordinates");
    let u = rows(frame, Section::PointData, "displacement");
    let points = rows(frame, Section::Points, "Points");
    let mut largest: f64 = 0.0;
    for ((x, reference), u) in points.iter().zip(&reference).zip(&u) {
        for c in 0..2 {
            assert!(
                (x[c] - (reference[c] + u[c])).abs() <= tolerance,
                "{what}: point {x:?}, reference {reference:?} + displacement {u:?}"
            );
        }
        largest = largest.max(u[0].hypot(u[1]));
    }
    largest
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
            assert_initial_grid(&rows(frame, Section::PointData, "reference_coordinates"));
            largest = largest.max(points_are_reference_plus_displacement(
                frame,
                1e-12 * 4.0,
                case,
            ));
        }
        assert!(largest > 1.0, "{case}: the tip moves by {largest}");
    }
}

/// Goal: the frames of dynamic runs show the current configuration too, on every path that
/// moves the nodes its own way: the explicit one-point and 2x2 rate-form kernels (which keep
/// their element state as arrays and move `state.coordinates` themselves) and implicit
/// Newmark. Setup: the aluminium Taylor rod (models/taylor_aluminum.toml, 45 us; its axis
/// shortens by 9 mm of 23.5) with both explicit kernels, and the round bar on a rigid wall
/// (models/round_bar_wall.toml, Newmark average), every frame. Reference: each frame's own
/// `reference_coordinates` plus `displacement`; the coordinates are summed step by step in
/// the run, not from that sum, so they agree to the round-off of thousands of additions:
/// 1e-12 of the rod's length. The displacement must be a large part of the length.
#[test]
fn dynamic_frames_show_the_current_configuration() {
    let cases = [
        ("taylor_aluminum", "reduced", 23.47e-3),
        ("taylor_aluminum", "full", 23.47e-3),
        ("round_bar_wall", "full", 0.06),
    ];
    for (scene, quadrature, length) in cases {
        let text = std::fs::read_to_string(format!("models/{scene}.toml")).unwrap();
        let dir = common::out_dir(&format!("vtk_dynamic_{scene}_{quadrature}"));
        let set = format!("analysis.quadrature={quadrature}");
        let out = run_scene(&dir, scene, &text, &["--set", &set]);
        let frames = frames(&out, scene);
        assert!(frames.len() > 2, "{scene}");
        let mut largest: f64 = 0.0;
        for frame in &frames {
            let what = format!("{scene} {quadrature}");
            largest = largest.max(points_are_reference_plus_displacement(
                frame,
                1e-12 * length,
                &what,
            ));
        }
        assert!(
            largest > 0.05 * length,
            "{scene} {quadrature}: moves {largest}"
        );
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

// ---------------------------------------------------------------------------------------
// Meshes from VTK files. The test mesh, as tests/vtk/make_meshes.py describes it (that script
// wrote the files of tests/data/vtk/ with VTK 9.7.2 and meshio 5.3.5): [0, 4] x [0, 1] in
// 4 x 2 quads, point i + 5 j at (i, j / 2); the quads with odd i + j written clockwise (as
// [p0, p3, p2, p1], so that reordering gives the generator's node order back); lines on the
// four sides in order around the body; vertices at the corners. Cell data `side`: 0 quads,
// 1 2 3 4 bottom, right, top, left lines, 5 6 7 8 the corners bottom left, bottom right, top
// right, top left. Point data `region`: 1 at x = 0, else 0.
// ---------------------------------------------------------------------------------------

/// The test mesh's points.
fn rect_points() -> Vec<[f64; 3]> {
    (0..3)
        .flat_map(|j| (0..5).map(move |i| [i as f64, j as f64 / 2.0, 0.0]))
        .collect()
}

/// The test mesh's cells as written: (VTK type, points, `side` value).
fn rect_cells() -> Vec<(u8, Vec<usize>, i32)> {
    let p = |i: usize, j: usize| i + 5 * j;
    let mut cells = Vec::new();
    for j in 0..2 {
        for i in 0..4 {
            let q = [p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)];
            let written = if (i + j) % 2 == 1 {
                vec![q[0], q[3], q[2], q[1]]
            } else {
                q.to_vec()
            };
            cells.push((9, written, 0));
        }
    }
    let sides: [Vec<[usize; 2]>; 4] = [
        (0..4).map(|i| [p(i, 0), p(i + 1, 0)]).collect(),
        (0..2).map(|j| [p(4, j), p(4, j + 1)]).collect(),
        (0..4).map(|i| [p(4 - i, 2), p(3 - i, 2)]).collect(),
        (0..2).map(|j| [p(0, 2 - j), p(0, 1 - j)]).collect(),
    ];
    for (k, lines) in sides.iter().enumerate() {
        for l in lines {
            cells.push((3, l.to_vec(), k as i32 + 1));
        }
    }
    for (k, corner) in [p(0, 0), p(4, 0), p(4, 2), p(0, 2)].into_iter().enumerate() {
        cells.push((1, vec![corner], k as i32 + 5));
    }
    cells
}

/// The test mesh's `region` point data.
fn rect_region() -> Vec<i32> {
    (0..15).map(|k| i32::from(k % 5 == 0)).collect()
}

/// A legacy ASCII .vtk file (version 3.0: CELLS with counts) of the given points and cells,
/// with `side` as cell data and `region` as point data (SCALARS).
fn legacy_ascii(points: &[[f64; 3]], cells: &[(u8, Vec<usize>, i32)], region: &[i32]) -> String {
    let mut text =
        String::from("# vtk DataFile Version 3.0\ntest mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n");
    text += &format!("POINTS {} double\n", points.len());
    for p in points {
        text += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    let size: usize = cells.iter().map(|c| c.1.len() + 1).sum();
    text += &format!("CELLS {} {size}\n", cells.len());
    for (_, nodes, _) in cells {
        let nodes: Vec<String> = nodes.iter().map(|n| n.to_string()).collect();
        text += &format!("{} {}\n", nodes.len(), nodes.join(" "));
    }
    text += &format!("CELL_TYPES {}\n", cells.len());
    for (kind, ..) in cells {
        text += &format!("{kind}\n");
    }
    text += &format!(
        "CELL_DATA {}\nSCALARS side int 1\nLOOKUP_TABLE default\n",
        cells.len()
    );
    for (.., side) in cells {
        text += &format!("{side}\n");
    }
    text += &format!(
        "POINT_DATA {}\nSCALARS region int 1\nLOOKUP_TABLE default\n",
        points.len()
    );
    for r in region {
        text += &format!("{r}\n");
    }
    text
}

/// An XML .vtu file of the same content with ascii arrays.
fn vtu_ascii(points: &[[f64; 3]], cells: &[(u8, Vec<usize>, i32)], region: &[i32]) -> String {
    let join = |v: Vec<String>| v.join(" ");
    let mut offsets = Vec::new();
    let mut end = 0;
    for (_, nodes, _) in cells {
        end += nodes.len();
        offsets.push(end.to_string());
    }
    format!(
        r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <UnstructuredGrid>
    <Piece NumberOfPoints="{}" NumberOfCells="{}">
      <PointData>
        <DataArray type="Int32" Name="region" format="ascii">{}</DataArray>
      </PointData>
      <CellData>
        <DataArray type="Int32" Name="side" format="ascii">{}</DataArray>
      </CellData>
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">{}</DataArray>
      </Points>
      <Cells>
        <DataArray type="Int64" Name="connectivity" format="ascii">{}</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">{}</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">{}</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
"#,
        points.len(),
        cells.len(),
        join(region.iter().map(|r| r.to_string()).collect()),
        join(cells.iter().map(|c| c.2.to_string()).collect()),
        join(points.iter().flatten().map(|x| x.to_string()).collect()),
        join(
            cells
                .iter()
                .flat_map(|c| c.1.iter().map(|n| n.to_string()))
                .collect()
        ),
        join(offsets),
        join(cells.iter().map(|c| c.0.to_string()).collect()),
    )
}

/// A Gmsh MSH 4.1 ASCII file of the test mesh (node tag = point + 1): the quads in a surface
/// with the physical group "side_0", each side a curve with the group "side_K", each corner a
/// point entity with the group "side_K" (K as the `side` values), so the set names equal the
/// VTK files'.
fn gmsh_file() -> String {
    let cells = rect_cells();
    let points = rect_points();
    let mut text = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n9\n");
    for k in 5..9 {
        text += &format!("0 {k} \"side_{k}\"\n");
    }
    for k in 1..5 {
        text += &format!("1 {k} \"side_{k}\"\n");
    }
    text += "2 9 \"side_0\"\n$EndPhysicalNames\n$Entities\n4 4 1 0\n";
    let corners: Vec<&(u8, Vec<usize>, i32)> = cells.iter().filter(|c| c.0 == 1).collect();
    for (k, (_, nodes, side)) in corners.iter().enumerate() {
        let p = points[nodes[0]];
        text += &format!("{} {} {} 0 1 {side}\n", k + 1, p[0], p[1]);
    }
    for k in 1..5 {
        text += &format!("{k} 0 0 0 4 1 0 1 {k} 0\n");
    }
    text += "1 0 0 0 4 1 0 1 9 0\n$EndEntities\n$Nodes\n1 15 1 15\n2 1 0 15\n";
    for k in 1..=15 {
        text += &format!("{k}\n");
    }
    for p in &points {
        text += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    text += "$EndNodes\n$Elements\n9 24 1 24\n";
    let mut tag = 0;
    let mut block =
        |text: &mut String, dim: usize, entity: i32, kind: usize, members: Vec<&Vec<usize>>| {
            *text += &format!("{dim} {entity} {kind} {}\n", members.len());
            for nodes in members {
                tag += 1;
                let nodes: Vec<String> = nodes.iter().map(|n| (n + 1).to_string()).collect();
                *text += &format!("{tag} {}\n", nodes.join(" "));
            }
        };
    let of = |kind: u8, side: i32| -> Vec<&Vec<usize>> {
        cells
            .iter()
            .filter(|c| c.0 == kind && c.2 == side)
            .map(|c| &c.1)
            .collect()
    };
    block(&mut text, 2, 1, 3, of(9, 0));
    for k in 1..5 {
        block(&mut text, 1, k, 1, of(3, k));
    }
    for k in 5..9 {
        block(&mut text, 0, k - 4, 15, of(1, k));
    }
    text += "$EndElements\n";
    text
}

/// Writes `text` to DIR/NAME and returns the path.
fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/vtk")
        .join(name)
}

/// The files that hold the test mesh: written here (legacy ASCII, .vtu ascii, Gmsh) and by
/// VTK and meshio (tests/data/vtk/).
fn mesh_files(dir: &Path) -> Vec<PathBuf> {
    let (points, cells, region) = (rect_points(), rect_cells(), rect_region());
    let mut files = vec![
        write(
            dir,
            "rect_ascii.vtk",
            &legacy_ascii(&points, &cells, &region),
        ),
        write(dir, "rect_ascii.vtu", &vtu_ascii(&points, &cells, &region)),
    ];
    for name in [
        "rect_binary_zlib.vtu",
        "rect_binary_lz4.vtu",
        "rect_binary_lzma.vtu",
        "rect_appended_base64.vtu",
        "rect_legacy_binary.vtk",
        "rect_meshio_binary.vtk",
        "rect_meshio_zlib.vtu",
    ] {
        files.push(data(name));
    }
    files
}

/// The generator's rectangle of the same size and counts.
fn generated() -> Mesh {
    impact::mesh::generate::Rectangle {
        origin: [0.0, 0.0],
        width: 4.0,
        height: 1.0,
        nx: 4,
        ny: 2,
        grading_x: 1.0,
        grading_y: 1.0,
        grade_toward: None,
    }
    .build()
    .unwrap()
}

/// The generator's set names under the test mesh's `side` values.
const RENAMED: [(&str, &str); 8] = [
    ("bottom", "side_1"),
    ("right", "side_2"),
    ("top", "side_3"),
    ("left", "side_4"),
    ("bottom_left", "side_5"),
    ("bottom_right", "side_6"),
    ("top_right", "side_7"),
    ("top_left", "side_8"),
];

/// Checks a read mesh against the generated one: nodes and cells equal, the generator's
/// edge and node sets under their `side_K` names, `side_0` = every element, `boundary` =
/// the four sides chained counter-clockwise, and (VTK files) `region_1` = the left side's nodes.
fn assert_same_model(path: &Path, read: &Mesh, generated: &Mesh) {
    let file = path.display();
    assert_eq!(read.nodes, generated.nodes, "{file}: nodes");
    assert_eq!(read.cells, generated.cells, "{file}: cells");
    for (theirs, ours) in RENAMED {
        assert_eq!(
            read.node_sets.get(ours),
            generated.node_sets.get(theirs),
            "{file}: node set {ours} = {theirs}"
        );
        assert_eq!(
            read.edge_sets.get(ours),
            generated.edge_sets.get(theirs),
            "{file}: edge set {ours} = {theirs}"
        );
    }
    assert_eq!(
        read.element_sets["side_0"], generated.element_sets["all"],
        "{file}"
    );
    assert_eq!(
        read.element_sets["all"], generated.element_sets["all"],
        "{file}"
    );
    // the boundary: the four sides, chained head to tail around the body from (0, 0)
    let sides: Vec<[usize; 2]> = ["bottom", "right", "top", "left"]
        .iter()
        .flat_map(|s| generated.edge_sets[*s].clone())
        .collect();
    assert_eq!(read.edge_sets["boundary"], sides, "{file}: boundary");
    if path.extension().is_some_and(|e| e == "msh") {
        return;
    }
    assert_eq!(
        read.node_sets["region_1"], generated.node_sets["left"],
        "{file}"
    );
    let others: Vec<usize> = (0..15).filter(|n| n % 5 != 0).collect();
    assert_eq!(read.node_sets["region_0"], others, "{file}");
}

/// Goal: the same mesh read from a Gmsh .msh, from legacy .vtk files (ASCII, VTK's binary,
/// meshio's binary) and from .vtu files (ascii, base64 inline with zlib, LZ4 and LZMA,
/// appended base64, meshio's) is the generator's model: nodes, counter-clockwise cells in the same node
/// order, and the sets (the generator's under the files' names), plus `boundary` and the point
/// data sets. Setup: the 4 x 2 test mesh above, half of its quads clockwise; `sets =
/// ["side", "region"]`. Reference: the `rectangle` generator, which shares no code with the
/// readers, and the test mesh's description (`region`).
#[test]
fn vtk_and_gmsh_files_give_the_generated_model() {
    let dir = common::out_dir("vtk_same_model");
    let generated = generated();
    let sets = ["side".to_string(), "region".to_string()];
    for path in mesh_files(&dir) {
        let read = impact::mesh::vtk::read(&path, &sets)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_same_model(&path, &read, &generated);
    }
    let msh = write(&dir, "rect.msh", &gmsh_file());
    let read = impact::mesh::gmsh::read(&msh).unwrap();
    assert_same_model(&msh, &read, &generated);
}

/// A static plane-strain scene on the test mesh: the left side held, a finite-strain
/// traction on the right side, the right side's mean u_y probed. MESH, LEFT and RIGHT are
/// replaced by the mesh and the set names.
const SAME_SCENE: &str = r#"
[[material]]
name = "m"
young = 1000.0
poisson = 0.3

[[body]]
name = "block"
material = "m"
formulation = "plane_strain"
mesh = MESH

[[support]]
set = "LEFT"
fix = ["x", "y"]

[[load]]
type = "traction"
set = "RIGHT"
traction = [1.0, 2.0]

[analysis]
type = "static"
steps = 3

[[output.probe]]
quantity = "u_y"
set = "RIGHT"

[[output.probe]]
quantity = "von_mises"
set = "all"
"#;

/// Goal: one scene run on the mesh from the generator, a Gmsh file, a legacy .vtk and a .vtu
/// gives the same history: byte-identical history.csv from the three files, and the same
/// rows as the generator's (whose header names its own sets). Setup: SAME_SCENE (finite
/// strain, three load steps). Reference: the generator's run.
#[test]
fn same_scene_on_generated_gmsh_vtk_and_vtu_meshes_gives_the_same_history() {
    let dir = common::out_dir("vtk_same_history");
    let (points, cells, region) = (rect_points(), rect_cells(), rect_region());
    let files = [
        ("gmsh", write(&dir, "rect.msh", &gmsh_file())),
        (
            "vtk",
            write(&dir, "rect.vtk", &legacy_ascii(&points, &cells, &region)),
        ),
        ("vtk", data("rect_binary_zlib.vtu")),
    ];
    let history = |name: &str, mesh: &str, left: &str, right: &str| -> String {
        let text = SAME_SCENE
            .replace("MESH", mesh)
            .replace("LEFT", left)
            .replace("RIGHT", right);
        let model = common::model(name, &text, &[]);
        let out = dir.join(name);
        impact::analysis::run(&model, &out, Default::default()).unwrap();
        std::fs::read_to_string(out.join("history.csv")).unwrap()
    };
    let generated = history(
        "generated",
        "{ type = \"rectangle\", width = 4.0, height = 1.0, nx = 4, ny = 2 }",
        "left",
        "right",
    );
    let rows = |h: &str| h.lines().skip(1).map(str::to_string).collect::<Vec<_>>();
    let u_y: f64 = rows(&generated)[3]
        .split(',')
        .nth(6)
        .unwrap()
        .parse()
        .unwrap();
    assert!(u_y > 0.2, "the block bends: u_y = {u_y}");
    let mut from_files = Vec::new();
    for (k, (kind, path)) in files.iter().enumerate() {
        let mesh = match *kind {
            "gmsh" => format!("{{ type = \"gmsh\", file = \"{}\" }}", path.display()),
            _ => format!(
                "{{ type = \"vtk\", file = \"{}\", sets = [\"side\"] }}",
                path.display()
            ),
        };
        from_files.push(history(&format!("file_{k}"), &mesh, "side_4", "side_2"));
    }
    for h in &from_files {
        assert_eq!(h, &from_files[0]);
        assert_eq!(rows(h), rows(&generated));
    }
}

/// The test mesh as a legacy ASCII file with `edit` applied to its points and cells.
fn edited(
    dir: &Path,
    name: &str,
    edit: impl FnOnce(&mut Vec<[f64; 3]>, &mut Vec<(u8, Vec<usize>, i32)>),
) -> PathBuf {
    let (mut points, mut cells) = (rect_points(), rect_cells());
    edit(&mut points, &mut cells);
    write(dir, name, &legacy_ascii(&points, &cells, &rect_region()))
}

/// A scene on mesh file `path` with sets from `side`, checked by `impact check`: (exit
/// code, stderr).
fn check_mesh(dir: &Path, path: &Path, sets: &str) -> (i32, String) {
    let scene = SAME_SCENE
        .replace(
            "MESH",
            &format!(
                "{{ type = \"vtk\", file = \"{}\", sets = {sets} }}",
                path.display()
            ),
        )
        .replace("LEFT", "all")
        .replace("RIGHT", "boundary");
    let scene_path = write(dir, "scene.toml", &scene);
    let o = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(["check", scene_path.to_str().unwrap()])
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).to_string(),
    )
}

/// Goal: a bad mesh file is refused with exit 2 and a message naming the file and what is
/// wrong (the cell or point by its index in the file), never a panic. Setup: the test mesh
/// with one defect each, through `impact check`. Reference: the defect written into the file.
#[test]
fn bad_vtk_meshes_are_refused_naming_the_file_and_the_defect() {
    let dir = common::out_dir("vtk_bad_meshes");
    let triangle = edited(&dir, "triangle.vtk", |_, cells| {
        cells[3] = (5, vec![3, 4, 9], 0);
    });
    let repeated = edited(&dir, "repeated.vtk", |_, cells| {
        cells[2].1 = vec![2, 3, 3, 7];
    });
    let flat = edited(&dir, "flat.vtk", |points, _| {
        // cell 0 (points 0 1 6 5) on the line y = 0
        points[5] = [0.5, 0.0, 0.0];
        points[6] = [1.0, 0.0, 0.0];
    });
    let lifted = edited(&dir, "lifted.vtk", |points, _| {
        points[7][2] = 0.25;
    });
    let outside = edited(&dir, "outside.vtk", |_, cells| {
        cells[4].1[2] = 99;
    });
    let inside = edited(&dir, "inside.vtk", |_, cells| {
        cells[8] = (3, vec![6, 7], 1);
    });
    let cases: Vec<(PathBuf, &str, Vec<&str>)> = vec![
        (
            triangle,
            "[\"side\"]",
            vec!["cell 3", "Triangle", "VTK type 5"],
        ),
        (
            repeated,
            "[\"side\"]",
            vec!["cell 2", "degenerate", "point 3 twice"],
        ),
        (
            flat,
            "[\"side\"]",
            vec!["cell 0", "degenerate", "zero area"],
        ),
        (lifted, "[\"side\"]", vec!["point 7", "z = 0.25"]),
        (
            outside,
            "[\"side\"]",
            vec!["cell 4", "point 99", "15 points"],
        ),
        (
            inside,
            "[\"side\"]",
            vec!["cell 8", "side_1", "inside the body"],
        ),
        (
            data("rect_appended_raw.vtu"),
            "[]",
            vec![
                "appended raw",
                "Save Data",
                "meshio convert rect_appended_raw.vtu",
            ],
        ),
        (dir.join("no_such_mesh.vtk"), "[]", vec!["cannot read"]),
        (
            data("rect_binary_zlib.vtu"),
            "[\"nope\"]",
            vec!["`sets`", "\"nope\"", "side", "region"],
        ),
        (
            write(&dir, "garbage.vtk", "not a mesh\n"),
            "[]",
            vec!["not a VTK file"],
        ),
        (
            write(
                &dir,
                "polydata.vtk",
                "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\nPOLYGONS 1 4\n3 0 1 2\n",
            ),
            "[]",
            vec!["poly data", "unstructured grid"],
        ),
        (
            write(
                &dir,
                "floats.vtk",
                &legacy_ascii(&rect_points(), &rect_cells(), &rect_region())
                    .replace("SCALARS side int", "SCALARS side float"),
            ),
            "[\"side\"]",
            vec!["\"side\"", "F32", "integer"],
        ),
    ];
    for (path, sets, words) in cases {
        let (code, stderr) = check_mesh(&dir, &path, sets);
        assert_eq!(code, 2, "{}: {stderr}", path.display());
        let file = path.file_name().unwrap().to_string_lossy().to_string();
        assert!(stderr.contains(&file), "{stderr}");
        assert!(stderr.contains("mesh"), "{stderr}");
        for word in words {
            assert!(
                stderr.contains(word),
                "{}: `{word}` not in {stderr}",
                path.display()
            );
        }
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}

/// Goal: the scene keys of this feature are checked like every other: a misspelled mesh key
/// and an unknown `output.points` are refused (exit 2) naming what is expected. Setup: the
/// test mesh's scene through `impact check`, and `--set output.points=deformed`. Reference:
/// the keys' documented spellings.
#[test]
fn misspelled_vtk_and_points_keys_are_refused() {
    let dir = common::out_dir("vtk_keys");
    let path = data("rect_binary_zlib.vtu");
    let (code, stderr) = check_mesh(&dir, &path, "[\"side\"], set = [\"side\"]");
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("`set`") && stderr.contains("sets"),
        "{stderr}"
    );
    let (code, stderr) = check_mesh(&dir, &path, "[]");
    assert_eq!(code, 0, "{stderr}");
    let o = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(["check", dir.join("scene.toml").to_str().unwrap()])
        .args(["--set", "output.points=deformed"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("deformed") && stderr.contains("`current` or `reference`"),
        "{stderr}"
    );
}

/// Goal: quads given only clockwise are read, reordered counter-clockwise with their first
/// node kept. Setup: every quad of the test mesh written clockwise. Reference: the generator's
/// cells.
#[test]
fn clockwise_quads_are_reordered() {
    let dir = common::out_dir("vtk_clockwise");
    let path = edited(&dir, "clockwise.vtk", |_, cells| {
        for (kind, nodes, _) in cells.iter_mut() {
            if *kind == 9 && nodes[1] == nodes[0] + 1 {
                *nodes = vec![nodes[0], nodes[3], nodes[2], nodes[1]];
            }
        }
    });
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("4 0 5 6 1\n") && text.contains("4 1 6 7 2\n"),
        "all clockwise"
    );
    let read = impact::mesh::vtk::read(&path, &[]).unwrap();
    assert_eq!(read.cells, generated().cells);
    let (code, stderr) = check_mesh(&dir, &path, "[]");
    assert_eq!(code, 0, "{stderr}");
}

/// Goal: a file of lines only is a rod mesh: Rod2 cells, a cell data value -> element set and
/// node set, a vertex -> node set, no `boundary`. Setup: three lines along x, the middle
/// point unused by any vertex. Reference: the file written here.
#[test]
fn lines_without_quads_are_rods() {
    let dir = common::out_dir("vtk_rods");
    let points = vec![
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [3.0, 0.0, 0.0],
    ];
    let cells = vec![
        (3, vec![0, 2], 1),
        (3, vec![2, 1], 1),
        (3, vec![1, 3], 2),
        (1, vec![0], 7),
    ];
    let path = write(
        &dir,
        "rods.vtk",
        &legacy_ascii(&points, &cells, &[0, 0, 0, 0]),
    );
    let mesh = impact::mesh::vtk::read(&path, &["side".to_string()]).unwrap();
    assert_eq!(mesh.cells, Cells::Rod2(vec![[0, 2], [2, 1], [1, 3]]));
    assert_eq!(mesh.element_sets["side_1"], vec![0, 1]);
    assert_eq!(mesh.node_sets["side_1"], vec![0, 1, 2]);
    assert_eq!(mesh.element_sets["side_2"], vec![2]);
    assert_eq!(mesh.node_sets["side_7"], vec![0]);
    assert!(mesh.edge_sets.is_empty());
}

/// Goal: bad input never panics: every prefix of the mesh files (cut every 23 bytes) reads
/// as a mesh or as an error. Reference: no panic (the test harness fails on one).
#[test]
fn cut_mesh_files_are_errors_not_panics() {
    let dir = common::out_dir("vtk_cut");
    let sets = ["side".to_string(), "region".to_string()];
    let mut errors = 0;
    for path in mesh_files(&dir) {
        let bytes = std::fs::read(&path).unwrap();
        let cut = dir.join(format!(
            "cut.{}",
            path.extension().unwrap().to_string_lossy()
        ));
        for end in (0..bytes.len()).step_by(23) {
            std::fs::write(&cut, &bytes[..end]).unwrap();
            match impact::mesh::vtk::read(&cut, &sets) {
                Err(MeshError::Content { path, .. }) => {
                    assert!(path.ends_with(&*cut.file_name().unwrap().to_string_lossy()));
                    errors += 1;
                }
                Err(other) => panic!("{other}"),
                Ok(_) => {}
            }
        }
    }
    assert!(errors > 100, "{errors}");
}

/// Goal: the scene of models/ on a VTK mesh (a quarter cylinder from a zlib-compressed .vtu,
/// its supports, pressure and probe on sets from the cell data array `face`) gives Lame's
/// bore displacement, as the generator's ring of the same points does. Setup:
/// models/lame_cylinder_vtk.toml as shipped, and the same scene on `type = "ring"` (4 x 16)
/// with a node set at the bore point. Reference: Lame's u_r(a) (reference module), within
/// 1.5 % (measured -1.07 %: Q4 and the polygonal bore at 4 x 16), and the generated ring's
/// value to 1e-12 (same mesh, other node numbers).
#[test]
fn lame_cylinder_from_a_vtu_matches_lame_and_the_generated_ring() {
    let scene = Path::new("models/lame_cylinder_vtk.toml");
    let model = impact::scene::load(scene, &[]).unwrap();
    let dir = common::out_dir("vtk_lame");
    impact::analysis::run(&model, &dir, Default::default()).unwrap();
    let from_vtu = *common::column(&dir, "u_x[face_5]").last().unwrap();

    let text = std::fs::read_to_string(scene)
        .unwrap()
        .replace(
            r#"{ type = "vtk", file = "meshes/quarter_cylinder.vtu", sets = ["face"] }"#,
            r#"{ type = "ring", inner_radius = 1.0, outer_radius = 2.0, n_radial = 4, n_circ = 16, angle = 90.0 }"#,
        )
        .replace("face_1", "inner")
        .replace("face_3", "start")
        .replace("face_4", "end")
        .replace("face_5", "bore")
        + "\n[[node_set]]\nname = \"bore\"\nnearest = [1.0, 0.0]\n";
    let ring = common::model("lame_ring", &text, &[]);
    assert_eq!(
        ring.bodies[0].mesh.nodes.len(),
        model.bodies[0].mesh.nodes.len()
    );
    let ring_dir = common::out_dir("vtk_lame_ring");
    impact::analysis::run(&ring, &ring_dir, Default::default()).unwrap();
    let generated = *common::column(&ring_dir, "u_x[bore]").last().unwrap();

    let exact = impact::reference::lame_radial_displacement(1.0, (1.0, 2.0), (1000.0, 0.3), 1.0);
    let error = (from_vtu - exact) / exact;
    eprintln!("Lame from the .vtu: u_x(a) = {from_vtu:e}, exact {exact:e}, error {error:.4}");
    assert!(error.abs() < 0.015, "{error}");
    assert!(
        (from_vtu - generated).abs() <= 1e-12 * exact,
        "{from_vtu} vs {generated}"
    );
}

/// Two blocks, not touching, the first struck towards the second: frames at fixed times.
const TWO_BLOCKS: &str = r#"
[[material]]
name = "soft"
young = 1000.0
poisson = 0.3
density = 1.0

[[body]]
name = "small"
material = "soft"
formulation = "plane_strain"
velocity = [0.1, 0.0]
mesh = { type = "rectangle", width = 2.0, height = 1.0, nx = 2, ny = 1 }

[[body]]
name = "large"
material = "soft"
formulation = "plane_strain"
mesh = { type = "rectangle", width = 3.0, height = 2.0, nx = 3, ny = 2, origin = [5.0, 0.0] }

[analysis]
type = "dynamic"
integrator = "average"
dt = 0.03
end_time = 1.0

[output]
frame_every = 0
frame_interval = 0.25
"#;

/// Goal: frames carry a `body` cell array (the body's index in the scene) so ParaView can
/// tell bodies apart (and a point array of the averaged stress), and `output.frame_interval` writes frames at fixed simulated times,
/// with implicit steps ending exactly there.
/// Setup: two plane-strain blocks of 2 x 1 and 3 x 2 quads; average acceleration with
/// dt = 0.03 (0.25 is no multiple of it), frame_interval = 0.25, frame_every = 0.
/// Reference: the cells in scene order (2 of body 0, then 6 of body 1); the frame times
/// 0 (the first frame), 0.25, 0.5, 0.75, 1. Tolerance 1e-12: the times are k * 0.25
/// computed once, written at full precision.
#[test]
fn frames_carry_body_ids_and_fall_on_the_frame_interval() {
    let dir = common::out_dir("vtk_frame_interval");
    let out = run_scene(&dir, "two_blocks", TWO_BLOCKS, &[]);
    let listed = impact::output::vtk::read_pvd(&out.join("two_blocks.pvd")).unwrap();
    let times: Vec<f64> = listed.iter().map(|(t, _)| *t).collect();
    let expected = [0.0, 0.25, 0.5, 0.75, 1.0];
    assert_eq!(times.len(), expected.len(), "{times:?}");
    for (t, e) in times.iter().zip(expected) {
        assert!((t - e).abs() < 1e-12, "{times:?}");
    }
    for frame in frames(&out, "two_blocks") {
        let ids = frame.ids(Section::CellData, "body").expect("a body array");
        assert_eq!(ids, [0, 0, 1, 1, 1, 1, 1, 1]);
        let (components, values) = frame
            .floats(Section::PointData, "nodal_stress")
            .expect("a nodal stress array");
        assert_eq!((components, values.len()), (6, 6 * frame.points));
    }
    // central difference with a fixed dt that does not divide the interval: the frame of
    // each listed time is the first step at or past it
    let dt = 0.007;
    let explicit = TWO_BLOCKS
        .replace(
            "integrator = \"average\"",
            "integrator = \"central_difference\"",
        )
        .replace("dt = 0.03", &format!("dt = {dt}"));
    std::fs::create_dir_all(dir.join("explicit")).unwrap();
    let out = run_scene(&dir.join("explicit"), "two_blocks", &explicit, &[]);
    let listed = impact::output::vtk::read_pvd(&out.join("two_blocks.pvd")).unwrap();
    let times: Vec<f64> = listed.iter().map(|(t, _)| *t).collect();
    assert_eq!(times.len(), expected.len(), "{times:?}");
    for (t, e) in times.iter().zip(expected) {
        assert!(*t >= e - 1e-12 && *t < e + dt, "{times:?}");
    }
}

/// The extent of a frame's points: (min x, max x, min y, max y).
fn bounds(frame: &FrameData) -> [f64; 4] {
    rows(frame, Section::Points, "Points").iter().fold(
        [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ],
        |b, p| {
            [
                b[0].min(p[0]),
                b[1].max(p[0]),
                b[2].min(p[1]),
                b[3].max(p[1]),
            ]
        },
    )
}

/// Goal: the shape probes (`extent_x`, `extent_y`, `x`/`y` with `max`/`min`) give the extent
/// of the current configuration, the last history row and summary.json's `probes` agree, so
/// a Taylor rod's L_f and D_f need no arithmetic.
/// Setup: the aluminium Taylor rod (axisymmetric, models/taylor_aluminum.toml, its probes
/// `extent_y[all]` and `extent_x[all]`, one-point kernel, 45 us) and the finite-strain
/// cantilever above (plane stress) with the four kinds of probe over `all`.
/// Reference: the last frame's points (the coordinates the run moved step by step; the probes
/// sum initial coordinates and displacements): the same to the round-off of thousands of
/// additions, 1e-12 of the body's size. Axisymmetric: the body of revolution's extent across
/// the axis, 2 max r.
#[test]
fn shape_probes_are_the_extent_of_the_last_frame() {
    let dir = common::out_dir("shape_probes_taylor");
    let text = std::fs::read_to_string("models/taylor_aluminum.toml").unwrap();
    let out = run_scene(
        &dir,
        "taylor",
        &text,
        &[
            "--set",
            "analysis.quadrature=reduced",
            "--set",
            "output.frame_every=100000",
        ],
    );
    let last = frames(&out, "taylor").pop().unwrap();
    let b = bounds(&last);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let probe = |name: &str| summary["probes"][name].as_f64().unwrap();
    let size = 23.47e-3;
    assert!((probe("extent_y[all]") - (b[3] - b[2])).abs() <= 1e-12 * size);
    assert!((probe("extent_x[all]") - 2.0 * b[1]).abs() <= 1e-12 * size);
    // history.csv prints 17 significant digits: the last one may differ by rounding
    for name in ["extent_y[all]", "extent_x[all]"] {
        let last_row = *common::column(&out, name).last().unwrap();
        approx::assert_relative_eq!(last_row, probe(name), max_relative = 1e-15);
    }

    let dir = common::out_dir("shape_probes_beam");
    let probes = r#"
[[output.probe]]
quantity = "extent_x"
set = "all"

[[output.probe]]
quantity = "extent_y"
set = "all"

[[output.probe]]
quantity = "y"
set = "all"
statistic = "max"

[[output.probe]]
quantity = "x"
set = "all"
statistic = "min"
"#;
    let out = run_scene(&dir, "beam", &format!("{CANTILEVER}{probes}"), &[]);
    let last = frames(&out, "beam").pop().unwrap();
    let b = bounds(&last);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let probe = |name: &str| summary["probes"][name].as_f64().unwrap();
    let size = 4.0;
    for (name, expected) in [
        ("extent_x[all]", b[1] - b[0]),
        ("extent_y[all]", b[3] - b[2]),
        ("max_y[all]", b[3]),
        ("min_x[all]", b[0]),
    ] {
        assert!(
            (probe(name) - expected).abs() <= 1e-12 * size,
            "{name}: {} against {expected}",
            probe(name)
        );
    }
    // the tip rises by a third of the length: the extents are not the initial ones
    assert!(probe("max_y[all]") > 1.5);
}
