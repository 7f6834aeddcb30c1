//! The command line against its contract: exit codes (0 ok, 2 bad input, 3 numerical),
//! messages that name the file and the key or element, output that loads and stays intact.

mod common;

use common::impact;

use std::path::{Path, PathBuf};

const BEAM: &str = r#"
[[material]]
name = "steel"
young = 1000.0
poisson = 0.3
density = 1.0

[[body]]
name = "beam"
material = "steel"
formulation = "plane_strain"
mesh = { type = "rectangle", width = 4.0, height = 1.0, nx = 8, ny = 2 }

[[support]]
set = "left"
fix = ["x", "y"]

[[load]]
type = "traction"
set = "right"
traction = [0.0, 1.0]

[analysis]
type = "static"
steps = 4

[[output.probe]]
quantity = "u_y"
set = "right"
"#;


fn write_scene(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Runs `impact run` on a scene text and returns (exit code, stderr).
fn run_text(name: &str, text: &str, extra: &[&str]) -> (i32, String) {
    let dir = common::out_dir(&format!("cli_{name}"));
    let scene = write_scene(&dir, name, text);
    let out = dir.join("out");
    let mut args = vec![
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ];
    args.extend_from_slice(extra);
    let o = impact(&args);
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn assert_input_error(name: &str, text: &str, extra: &[&str], needles: &[&str]) {
    let (code, stderr) = run_text(name, text, extra);
    assert_eq!(code, 2, "{name}: expected exit 2, stderr: {stderr}");
    assert!(
        stderr.contains(&format!("{name}.toml")),
        "{name}: the message must name the file: {stderr}"
    );
    for n in needles {
        assert!(
            stderr.contains(n),
            "{name}: the message must mention `{n}`: {stderr}"
        );
    }
    assert!(!stderr.contains("panicked"), "{name}: {stderr}");
}

#[test]
fn unknown_key_is_refused_with_its_name() {
    assert_input_error(
        "unknown_key",
        &BEAM.replace("poisson = 0.3", "poisson = 0.3\npoison = 0.3"),
        &[],
        &["poison"],
    );
    // inside an internally tagged enum (serde #2123): the mesh generator's keys
    assert_input_error(
        "unknown_mesh_key",
        &BEAM.replace("nx = 8", "nx = 8, nz = 3"),
        &[],
        &["nz"],
    );
    assert_input_error(
        "unknown_load_key",
        &BEAM.replace("traction = [0.0, 1.0]", "traction = [0.0, 1.0]\nscale = 2"),
        &[],
        &["scale"],
    );
}

#[test]
fn wrong_type_is_refused() {
    assert_input_error(
        "wrong_type",
        &BEAM.replace("steps = 4", "steps = \"four\""),
        &[],
        &["steps"],
    );
}

#[test]
fn negative_modulus_and_density_are_refused() {
    assert_input_error(
        "negative_modulus",
        BEAM,
        &["--set", "material.steel.young=-5"],
        &["young", "-5"],
    );
    assert_input_error(
        "negative_density",
        BEAM,
        &["--set", "material.steel.density=-1"],
        &["density"],
    );
    assert_input_error(
        "bad_poisson",
        BEAM,
        &["--set", "material.steel.poisson=0.5"],
        &["poisson"],
    );
}

#[test]
fn missing_mesh_file_is_refused() {
    let text = BEAM.replace(
        r#"mesh = { type = "rectangle", width = 4.0, height = 1.0, nx = 8, ny = 2 }"#,
        r#"mesh = { type = "gmsh", file = "no_such_mesh.msh" }"#,
    );
    assert_input_error("missing_mesh", &text, &[], &["no_such_mesh.msh"]);
    let (code, stderr) = (impact(&["run", "no_such_scene.toml"]).status.code(), "");
    assert_eq!(code, Some(2), "{stderr}");
}

/// The second quad of tests/data/inverted.msh is concave (positive area, det J < 0 at a Gauss
/// point): refused before the run, naming element 1 (0-based).
#[test]
fn inverted_element_is_refused_with_its_id() {
    let data = std::fs::canonicalize("tests/data/inverted.msh").unwrap();
    let text = BEAM
        .replace(
            r#"mesh = { type = "rectangle", width = 4.0, height = 1.0, nx = 8, ny = 2 }"#,
            &format!(
                "mesh = {{ type = \"gmsh\", file = \"{}\" }}",
                data.display()
            ),
        )
        .replace("set = \"left\"", "set = \"all\"")
        .replace(
            "[[load]]\ntype = \"traction\"\nset = \"right\"\ntraction = [0.0, 1.0]\n",
            "",
        )
        .replace(
            "[[output.probe]]\nquantity = \"u_y\"\nset = \"right\"\n",
            "",
        );
    assert_input_error("inverted", &text, &[], &["element 1", "Jacobian"]);
}

#[test]
fn unknown_set_is_refused_with_the_known_ones() {
    assert_input_error(
        "unknown_set",
        &BEAM.replace("set = \"left\"", "set = \"west\""),
        &[],
        &["west", "left"],
    );
    assert_input_error(
        "unknown_set_override",
        BEAM,
        &["--set", "body.girder.formulation=plane_stress"],
        &["girder"],
    );
}

/// A run that cannot converge (one iteration allowed, no cuts) stops with exit 3, status
/// `diverged` in summary.json, and the frames and history written so far intact.
#[test]
fn divergence_exits_3_and_keeps_output() {
    let (code, stderr) = run_text(
        "diverges",
        BEAM,
        &[
            "--set",
            "analysis.newton.max_iterations=1",
            "--set",
            "analysis.newton.max_cuts=0",
            "--set",
            "load.0.traction=[0,300]",
        ],
    );
    assert_eq!(code, 3, "{stderr}");
    let out = common::out_dir("cli_diverges_probe")
        .parent()
        .unwrap()
        .join("cli_diverges")
        .join("out");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "diverged");
    assert!(
        summary["message"]
            .as_str()
            .unwrap()
            .contains("did not converge")
    );
    let frames = impact::output::vtk::read_pvd(&out.join("diverges.pvd")).unwrap();
    assert_eq!(frames.len(), 1, "the initial frame is listed");
    for (_, path) in frames {
        impact::output::vtu::read_frame(&path).expect("a listed frame loads");
    }
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert_eq!(history.lines().count(), 2, "header and the initial row");
}

/// `impact run` writes a .pvd whose every listed frame loads (`read_frame`), with
/// unique increasing times, the displacement vectors and the stress tensor; `impact check`
/// prints the model size.
#[test]
fn run_writes_a_loadable_series_and_check_reports_size() {
    let dir = common::out_dir("cli_series");
    let scene = write_scene(&dir, "beam", BEAM);
    let out = dir.join("out");
    let o = impact(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let frames = impact::output::vtk::read_pvd(&out.join("beam.pvd")).unwrap();
    assert_eq!(frames.len(), 5);
    assert!(frames.windows(2).all(|w| w[1].0 > w[0].0));
    for (_, path) in &frames {
        use impact::output::vtu::Section::{CellData, PointData};
        let frame = impact::output::vtu::read_frame(path).expect("frame loads");
        assert_eq!((frame.points, frame.cells), (27, 16));
        assert_eq!(frame.vectors.as_deref(), Some("displacement"));
        for (section, name, components) in [
            (PointData, "displacement", 3),
            (PointData, "contact_force", 3),
            (CellData, "stress", 6),
            (CellData, "von_mises", 1),
        ] {
            let found = frame.floats(section, name).map(|(c, v)| (c, v.len()));
            let entries = if section == PointData { 27 } else { 16 };
            assert_eq!(
                found,
                Some((components, components * entries)),
                "{name} in {}",
                path.display()
            );
        }
    }
    let check = impact(&["check", scene.to_str().unwrap()]);
    assert!(check.status.success());
    let stdout = String::from_utf8_lossy(&check.stdout);
    assert!(
        stdout.contains("27 nodes") && stdout.contains("16 elements") && stdout.contains("54 DOFs"),
        "{stdout}"
    );
}

/// A small pinned column (L / h = 25, 50 x 2 elements) for the buckling subcommand and keys.
const COLUMN: &str = r#"
[[material]]
name = "steel"
young = 1.2e6
poisson = 0.3

[[body]]
name = "column"
material = "steel"
formulation = "plane_stress"
mesh = { type = "rectangle", width = 10.0, height = 0.4, nx = 50, ny = 2 }

[[node_set]]
name = "mid_left"
nearest = [0.0, 0.2]

[[node_set]]
name = "mid_right"
nearest = [10.0, 0.2]

[[support]]
set = "mid_left"
fix = ["x", "y"]

[[support]]
set = "mid_right"
fix = ["y"]

[[load]]
type = "traction"
set = "left"
traction = [2.5, 0.0]

[[load]]
type = "traction"
set = "right"
traction = [-2.5, 0.0]

[analysis]
type = "static"
steps = 1

[analysis.buckling]
modes = 2
"#;

/// Bad `[analysis.buckling]` input exits 2 with a message naming the key, never a panic:
/// a misspelled key, an enum value, a zero imperfection, and loads that buckle nothing
/// (tension: no positive load factor).
#[test]
fn bad_buckling_input_is_refused_with_its_key() {
    assert_input_error(
        "buckling_key",
        &COLUMN.replace("modes = 2", "modes = 2\nmode = 1"),
        &[],
        &["mode"],
    );
    assert_input_error(
        "buckling_on_critical",
        &COLUMN.replace("modes = 2", "modes = 2\non_critical = \"halt\""),
        &[],
        &["halt"],
    );
    assert_input_error(
        "buckling_amplitude",
        &COLUMN.replace("modes = 2", "modes = 2\nimperfection = { amplitude = 0.0 }"),
        &[],
        &["analysis.buckling.imperfection.amplitude"],
    );
    assert_input_error(
        "buckling_tension",
        &COLUMN
            .replace("[2.5, 0.0]", "[-2.5, 0.0]")
            .replace("[-2.5, 0.0]\n\n[analysis]", "[2.5, 0.0]\n\n[analysis]"),
        &[],
        &["analysis.buckling", "no buckling mode"],
    );
}

/// `impact buckle` prints the load factors and writes the modes as a loadable series;
/// `impact run` with the check writes the history column and the summary block.
#[test]
fn buckle_prints_load_factors_and_writes_modes() {
    let dir = common::out_dir("cli_buckle");
    let scene = write_scene(&dir, "column", COLUMN);
    let out = dir.join("out");
    let o = impact(&[
        "buckle",
        scene.to_str().unwrap(),
        "--modes",
        "3",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{stdout} {}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("mode 3: lambda = "), "{stdout}");
    let frames = impact::output::vtk::read_pvd(&out.join("column_buckling.pvd")).unwrap();
    assert_eq!(frames.len(), 3);
    let run_out = dir.join("run");
    let o = impact(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        run_out.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(
        common::column(&run_out, "tangent_negative_pivots"),
        vec![0.0, 0.0]
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run_out.join("summary.json")).unwrap())
            .unwrap();
    let factors = summary["buckling"]["load_factors"].as_array().unwrap();
    assert_eq!(factors.len(), 2);
    assert!(
        summary["buckling"]["critical_load_factor"]
            .as_f64()
            .unwrap()
            > 1.0
    );
}
