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

/// A steel rod (SI units) for `impact check`: 10 rods of h = 0.01 m, central difference.
const STEEL_ROD: &str = r#"
[[material]]
name = "steel"
young = 200e9
poisson = 0.3
density = 7850.0
yield_stress = 250e6

[[body]]
name = "rod"
material = "steel"
formulation = "rod"
area = 1e-4
velocity = [1.0, 0.0]
mesh = { type = "line", start = [0.0, 0.0], end = [0.1, 0.0], n = 10 }

[[support]]
set = "all"
fix = ["y"]

[analysis]
type = "dynamic"
integrator = "central_difference"
dt = 1.9e-6
end_time = 1e-5
"#;

/// The number printed right after `label` in `text` (up to a space, `;`, `,` or `)`).
fn number_after(text: &str, label: &str) -> f64 {
    let start = text
        .find(label)
        .unwrap_or_else(|| panic!("no `{label}` in:\n{text}"))
        + label.len();
    let rest = &text[start..];
    let end = rest
        .find(|c: char| c.is_whitespace() || matches!(c, ';' | ',' | ')'))
        .unwrap_or(rest.len());
    rest[..end]
        .parse()
        .unwrap_or_else(|e| panic!("`{}` after `{label}`: {e}", &rest[..end]))
}

/// Goal: `impact check` says what it knows about a scene: the wave speed of the
/// formulation, the yield strain, dt against the central-difference limit; and it refuses
/// the fixed dt a run refuses, with the same exit code 2.
/// Setup: the steel rod above (E = 200 GPa, rho = 7850 kg/m^3, sigma_y = 250 MPa, h = 0.01 m).
/// Reference: c = sqrt(E / rho); eps_y = sigma_y / E; the lumped two-node rod's only
/// nonzero eigenvalue omega^2 = 4 c^2 / h^2 gives dt_crit = h / c exactly (Irons' element
/// bound is attained by a uniform free rod). Tolerance 1e-5 relative: the report prints six
/// significant digits (rounding error at most 5e-6).
#[test]
fn check_reports_wave_speed_yield_strain_and_step_ratio() {
    let dir = common::out_dir("cli_check_rod");
    let scene = write_scene(&dir, "steel_rod", STEEL_ROD);
    let o = impact(&["check", scene.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let (young, density, yield_stress, h) = (200e9f64, 7850.0, 250e6, 0.01);
    let c = (young / density).sqrt();
    let close = |found: f64, exact: f64| (found / exact - 1.0).abs() < 1e-5;
    let speed = number_after(&stdout, "c = sqrt(M / rho) = ");
    assert!(close(speed, c), "c = {speed}, exact {c}\n{stdout}");
    let strain = number_after(&stdout, "sigma_y / E = ");
    assert!(close(strain, yield_stress / young), "{strain}\n{stdout}");
    let dt_crit = number_after(&stdout, "dt_crit = ");
    assert!(
        close(dt_crit, h / c),
        "dt_crit = {dt_crit}, exact {}\n{stdout}",
        h / c
    );
    let ratio = number_after(&stdout, "dt / dt_crit = ");
    assert!(close(ratio, 1.9e-6 / (h / c)), "{ratio}\n{stdout}");
    assert!(stdout.contains("integrator central_difference"), "{stdout}");
    assert!(!stdout.contains("Rod {"), "a Rust debug struct: {stdout}");
    // Newmark linear acceleration (beta 1/6, gamma 1/2) with the lumped mass: Omega_crit =
    // 1 / sqrt(gamma/2 - beta) = 2 sqrt 3, so its limit is sqrt 3 times central difference's
    let linear = impact(&[
        "check",
        scene.to_str().unwrap(),
        "--set",
        "analysis.integrator=\"linear\"",
        "--set",
        "analysis.mass=\"lumped\"",
    ]);
    let linear_out = String::from_utf8_lossy(&linear.stdout);
    assert!(linear.status.success(), "{linear_out}");
    let linear_crit = number_after(
        &linear_out,
        "integrator linear: dt = 1.9e-6, stability limit dt_crit = ",
    );
    assert!(close(linear_crit, 3f64.sqrt() * h / c), "{linear_out}");
    // just above the limit: check and run refuse it alike, naming the key
    let above = format!("analysis.dt={:e}", 1.05 * h / c);
    let check = impact(&["check", scene.to_str().unwrap(), "--set", &above]);
    let check_err = String::from_utf8_lossy(&check.stderr);
    assert_eq!(check.status.code(), Some(2), "{check_err}");
    let (code, run_err) = run_text("steel_rod", STEEL_ROD, &["--set", &above]);
    assert_eq!(code, 2, "{run_err}");
    for stderr in [&*check_err, &*run_err] {
        assert!(
            stderr.contains("analysis.dt = ") && stderr.contains("steel_rod.toml"),
            "{stderr}"
        );
        let limit = number_after(stderr, "stability limit ");
        assert!(close(limit, h / c), "{stderr}");
    }
}

/// Goal: the plane-strain wave speed is the dilatational one, and the body's kind reads in
/// words. Reference: c = sqrt((lambda + 2 mu) / rho) with lambda = E nu / ((1 + nu)(1 - 2 nu)),
/// mu = E / (2 (1 + nu)). Tolerance 1e-5 relative (six printed digits).
#[test]
fn check_prints_the_plane_strain_dilatational_wave_speed() {
    let dir = common::out_dir("cli_check_beam");
    let scene = write_scene(&dir, "beam", BEAM);
    let o = impact(&["check", scene.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{stdout}");
    let (young, nu, density) = (1000.0f64, 0.3, 1.0);
    let lambda = young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = young / (2.0 * (1.0 + nu));
    let c = ((lambda + 2.0 * mu) / density).sqrt();
    let speed = number_after(&stdout, "c = sqrt(M / rho) = ");
    assert!(
        (speed / c - 1.0).abs() < 1e-5,
        "c = {speed}, exact {c}\n{stdout}"
    );
    assert!(stdout.contains("lambda + 2 mu (plane strain)"), "{stdout}");
    assert!(stdout.contains("plane strain (per unit depth)"), "{stdout}");
    assert!(
        !stdout.contains("Continuum {"),
        "a Rust debug struct: {stdout}"
    );
}

/// Goal: messages read as a person writes: integrator names as the scene spells them, the
/// plane-strain thickness refusal says forces are per unit depth, and an output folder that
/// cannot be made is bad input (exit 2) naming the folder, with "cannot" said once.
#[test]
fn messages_name_things_as_the_scene_does() {
    assert_input_error(
        "auto_implicit",
        &BEAM.replace(
            "type = \"static\"\nsteps = 4",
            "type = \"dynamic\"\nintegrator = \"houbolt\"\ndt = \"auto\"\nend_time = 1.0",
        ),
        &[],
        &["integrator houbolt"],
    );
    assert_input_error(
        "strain_thickness",
        &BEAM.replace(
            "formulation = \"plane_strain\"",
            "formulation = \"plane_strain\"\nthickness = 0.1",
        ),
        &[],
        &["thickness", "per unit depth"],
    );
    let dir = common::out_dir("cli_bad_out");
    let scene = write_scene(&dir, "beam", BEAM);
    let blocker = dir.join("a_file");
    std::fs::write(&blocker, "in the way").unwrap();
    let out = blocker.join("out");
    let o = impact(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains(out.to_str().unwrap()), "{stderr}");
    assert!(
        stderr.contains("output folder") && !stderr.contains("cannot cannot"),
        "{stderr}"
    );
}

/// Goal: the closing line of a run counts in words ("1 factorization", "4 steps") and gives
/// the end time. Setup: the static beam in small strain with `strategy = "initial"` (one
/// factorization for the run). Reference: the summary.json of the same run.
#[test]
fn closing_line_counts_in_words() {
    let dir = common::out_dir("cli_closing");
    let scene = write_scene(&dir, "beam", BEAM);
    let out = dir.join("out");
    let o = impact(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--set",
        "analysis.geometry=\"linear\"",
        "--set",
        "analysis.newton.strategy=\"initial\"",
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{stdout}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let factorizations = summary["factorizations"].as_u64().unwrap();
    let expected = if factorizations == 1 {
        "1 factorization,".to_string()
    } else {
        format!("{factorizations} factorizations,")
    };
    assert!(stdout.contains(&expected), "{expected} in {stdout}");
    assert!(stdout.contains("4 steps"), "{stdout}");
    assert_eq!(factorizations, 1, "{stdout}");
    assert!(stdout.contains("t = 1,"), "{stdout}");
}

/// Goal: without a terminal (a batch log) a run prints plain progress lines with the
/// simulated time, the steps and an ETA, and a sweep prints a line per finished case.
/// Setup: the static beam (4 increments to t = 1) with `--progress-every 0` (a line at every
/// step); a sweep of it over analysis.steps = 2, 4. Reference: the scene's end time and
/// increment count, the sweep's two cases.
#[test]
fn batch_logs_get_progress_lines() {
    let dir = common::out_dir("cli_progress");
    let scene = write_scene(&dir, "beam", BEAM);
    let out = dir.join("out");
    let o = impact(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--progress-every",
        "0",
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains("beam: t = 0.25 / 1 (25 %), 1 step"),
        "{stderr}"
    );
    assert!(
        stderr.contains("beam: t = 1 / 1 (100 %), 4 steps"),
        "{stderr}"
    );
    assert!(stderr.contains("ETA"), "{stderr}");
    let o = impact(&[
        "sweep",
        scene.to_str().unwrap(),
        "--vary",
        "analysis.steps=2,4",
        "--jobs",
        "1",
        "--out",
        dir.join("sweep").to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    for line in [
        "case 1 of 2 (analysis.steps=2): ok",
        "case 2 of 2 (analysis.steps=4): ok",
    ] {
        assert!(stderr.contains(line), "`{line}` in:\n{stderr}");
    }
}

/// Goal: an error in a scene edited by `--set` names the edit and no line number (the edited
/// text is not the user's file, so its line numbers would point nowhere).
#[test]
fn set_errors_name_the_edit_not_a_line() {
    let (code, stderr) = run_text(
        "set_type",
        BEAM,
        &["--set", "material.steel.young=\"stiff\""],
    );
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("--set material.steel.young=\"stiff\""),
        "{stderr}"
    );
    assert!(!stderr.contains("line "), "{stderr}");
}

/// Runs `impact ARGS` with stdout and stderr pipes whose reading ends are closed before the
/// child writes anything (a run piped into `head -1` that has already exited), and returns
/// its exit code.
fn with_closed_output(args: &[&str]) -> Option<i32> {
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    // the child holds only the writing ends now: every write it makes fails with EPIPE
    drop(child.stdout.take());
    drop(child.stderr.take());
    child.wait().expect("the child ends").code()
}

/// Goal: a reader that stops reading (`impact run scene.toml 2>&1 | head -1`) never costs a
/// run its output or its exit code. Before: `println!` panicked on the closed pipe after the
/// last step (exit 101) and summary.json was never written. Setup: the static beam with a
/// progress line at every step and the closing line; the two bars with a step longer than
/// the run (a warning on stderr) under --strict; check, sweep and plot of the same, all with
/// both pipes closed. Reference: the exit codes of the contract (0, and 3 for --strict with
/// a warning) and a summary.json that parses with status "ok".
#[test]
fn closed_stdout_and_stderr_cost_no_output() {
    let dir = common::out_dir("cli_closed_pipe");
    let scene = write_scene(&dir, "beam", BEAM);
    let scene = scene.to_str().unwrap();
    let out = dir.join("out");
    let code = with_closed_output(&[
        "run",
        scene,
        "--out",
        out.to_str().unwrap(),
        "--progress-every",
        "0",
    ]);
    assert_eq!(code, Some(0));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "ok");
    assert_eq!(summary["steps"], 4);

    let bars = dir.join("bars");
    let code = with_closed_output(&[
        "run",
        "models/two_bars.toml",
        "--out",
        bars.to_str().unwrap(),
        "--set",
        "analysis.dt=0.5",
        "--strict",
    ]);
    assert_eq!(code, Some(3), "--strict with a warning exits 3");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(bars.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "ok");
    assert!(!summary["warnings"].as_array().unwrap().is_empty());

    assert_eq!(with_closed_output(&["check", scene]), Some(0));
    let sweep = dir.join("sweep");
    let code = with_closed_output(&[
        "sweep",
        scene,
        "--vary",
        "analysis.steps=2,4",
        "--jobs",
        "1",
        "--out",
        sweep.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0));
    assert!(sweep.join("sweep.csv").is_file());
    let chart = dir.join("u.svg");
    let history = out.join("history.csv");
    let code = with_closed_output(&[
        "plot",
        history.to_str().unwrap(),
        "--y",
        "u_y[right]",
        "--out",
        chart.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0));
    assert!(chart.is_file());
    // a refused scene keeps its exit code 2 with stderr closed
    assert_eq!(
        with_closed_output(&["check", "no_such_scene.toml"]),
        Some(2)
    );
}

/// A probe that is one number of its set (an extent, a momentum) refuses `max` and `min`
/// with the probe and the reason named (`p_x` took them silently and summed before).
#[test]
fn whole_set_probes_refuse_a_statistic() {
    for (quantity, why) in [
        ("extent_x", "extent of the set"),
        ("p_x", "sum over the set"),
    ] {
        let text = format!(
            "{BEAM}\n[[output.probe]]\nquantity = \"{quantity}\"\nset = \"all\"\nstatistic = \"max\"\n"
        );
        assert_input_error(
            &format!("whole_set_{quantity}"),
            &text,
            &[],
            &["output.probe[1].statistic", quantity, why],
        );
    }
}

/// The keys of the implicit error-controlled step are refused where they do not apply, and
/// `dt = "auto"` for a method without an error estimate says why.
#[test]
fn adaptive_step_keys_are_refused_where_they_do_not_apply() {
    let dynamic = BEAM.replace(
        "type = \"static\"\nsteps = 4",
        "type = \"dynamic\"\nend_time = 1.0",
    );
    let cases: [(&str, &[&str], &[&str]); 6] = [
        (
            "tolerance_fixed_dt",
            &["analysis.dt=0.1", "analysis.error_tolerance=1e-3"],
            &["analysis.error_tolerance", "dt = \"auto\""],
        ),
        (
            "auto_wilson",
            &["analysis.dt=\"auto\"", "analysis.integrator=\"wilson\""],
            &["wilson", "no error estimate"],
        ),
        (
            "auto_linear",
            &["analysis.dt=\"auto\"", "analysis.integrator=\"linear\""],
            &["beta = 1/6"],
        ),
        (
            "dt_max_explicit",
            &[
                "analysis.integrator=\"central_difference\"",
                "analysis.dt_max=1e-3",
            ],
            &["analysis.dt_max"],
        ),
        (
            "dt_min_above_max",
            &[
                "analysis.dt=\"auto\"",
                "analysis.dt_min=0.1",
                "analysis.dt_max=0.01",
            ],
            &["analysis.dt_min", "dt_max"],
        ),
        (
            "tolerance_range",
            &["analysis.dt=\"auto\"", "analysis.error_tolerance=2.0"],
            &["analysis.error_tolerance", "(0, 1)"],
        ),
    ];
    for (name, sets, needles) in cases {
        let extra: Vec<String> = sets
            .iter()
            .flat_map(|s| ["--set".into(), s.to_string()])
            .collect();
        let extra: Vec<&str> = extra.iter().map(String::as_str).collect();
        assert_input_error(name, &dynamic, &extra, needles);
    }
}

/// Goal: `impact run --verbose` logs every Newton iteration on stderr (the residual, its
/// share of the force scale against the tolerance, the displacement criterion), and nothing
/// without it. Setup: models/hill_cylinder.toml (static, 20 load increments, no cut).
/// Reference: Newton's structure: a step that converges after k solves evaluates its
/// residual k + 1 times, so the log has summary.json `newton_iterations` + `steps` lines;
/// the last line of each step is the converged one, its eps_force below the tolerance
/// (1e-8).
#[test]
fn verbose_logs_each_newton_iteration() {
    let dir = common::out_dir("verbose_hill");
    let d = dir.to_str().unwrap();
    let output = impact(&[
        "run",
        "models/hill_cylinder.toml",
        "--quiet",
        "--verbose",
        "--out",
        d,
    ]);
    assert_eq!(output.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&output.stderr);
    let lines: Vec<&str> = stderr
        .lines()
        .filter(|l| l.contains("newton: step from"))
        .collect();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["step_cuts"], 0);
    let (iterations, steps) = (
        summary["newton_iterations"].as_u64().unwrap(),
        summary["steps"].as_u64().unwrap(),
    );
    assert_eq!(lines.len() as u64, iterations + steps, "{stderr}");
    let eps = |line: &str| -> f64 {
        let value = line
            .split("eps_force = ")
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap();
        value.parse().unwrap()
    };
    for (k, line) in lines.iter().enumerate() {
        let last_of_step = lines
            .get(k + 1)
            .is_none_or(|next| next.contains("iteration 0:"));
        if last_of_step {
            assert!(eps(line) < 1e-8, "{line}");
        }
    }
    let quiet = impact(&["run", "models/hill_cylinder.toml", "--quiet", "--out", d]);
    assert!(!String::from_utf8_lossy(&quiet.stderr).contains("newton:"));
}

/// Goal: `--verbose` says why an increment was cut, at each cut. Setup:
/// models/column_buckling.toml with modified Newton (the scene names full Newton; modified
/// cuts its increments near the critical load). Reference: the cut count summary.json
/// reports (`step_cuts`, at least one): one "is cut:" line per cut, each naming the
/// increment's end time and a reason (an inverted element names its body and element).
#[test]
fn verbose_says_why_each_cut_was_made() {
    let dir = common::out_dir("verbose_cuts");
    let d = dir.to_str().unwrap();
    let output = impact(&[
        "run",
        "models/column_buckling.toml",
        "--quiet",
        "--verbose",
        "--set",
        "analysis.newton.strategy=modified",
        "--set",
        "output.frame_every=0",
        "--out",
        d,
    ]);
    assert_eq!(output.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&output.stderr);
    let cuts: Vec<&str> = stderr.lines().filter(|l| l.contains("is cut:")).collect();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let counted = summary["step_cuts"].as_u64().unwrap();
    assert!(counted > 0, "the run must cut to test this");
    assert_eq!(cuts.len() as u64, counted, "{stderr}");
    for line in cuts {
        let reason = line.split("is cut:").nth(1).unwrap().trim();
        assert!(
            line.contains("increment to t = ") && !reason.is_empty(),
            "{line}"
        );
        if reason.contains("Jacobian") {
            assert!(reason.contains("body `column`, element"), "{line}");
        }
    }
}

/// A plane-strain steel block of 40 x 25 = 1000 elements struck downwards, central
/// difference for a few steps: the smallest explicit model that runs on the pool.
const THOUSAND_ELEMENTS: &str = r#"
[[material]]
name = "steel"
young = 200e9
poisson = 0.3
density = 7800.0

[[body]]
name = "block"
material = "steel"
formulation = "plane_strain"
velocity = [0.0, -10.0]
mesh = { type = "rectangle", width = 0.04, height = 0.025, nx = 40, ny = 25 }

[[support]]
set = "bottom"
fix = ["y"]

[analysis]
type = "dynamic"
integrator = "central_difference"
end_time = 2e-7

[output]
frame_every = 0
"#;

/// `impact` with `RAYON_NUM_THREADS` set to `threads`.
fn impact_on(threads: &str, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_impact"))
        .env("RAYON_NUM_THREADS", threads)
        .args(args)
        .output()
        .expect("the binary runs")
}

/// Goal: summary.json says how many threads a run stepped on, and `impact check` says it
/// beforehand: the count the user set for a model on the pool, one below its size; both
/// name the build of the twice-compiled loops the processor runs.
/// Setup: a 16-element beam and a 1000-element explicit block, `RAYON_NUM_THREADS=3`.
/// Reference: the user's 3, and 1 for the static beam, below the 4000 elements from which
/// a static run uses the pool (the user guide's rule, not the code's count); the build
/// from this processor's features as the standard library detects them.
#[test]
fn the_thread_count_is_reported() {
    let dir = common::out_dir("cli_threads");
    for (name, text, expected) in [("beam", BEAM, 1), ("block", THOUSAND_ELEMENTS, 3)] {
        let scene = write_scene(&dir, name, text);
        let out = dir.join(name);
        let o = impact_on(
            "3",
            &[
                "run",
                scene.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
        );
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let text = std::fs::read_to_string(out.join("summary.json")).unwrap();
        let summary: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(
            summary["timing"]["threads"], expected,
            "{name}: summary.json"
        );
        let check = impact_on("3", &["check", scene.to_str().unwrap()]);
        let said = String::from_utf8_lossy(&check.stdout);
        assert!(
            said.contains(&format!("threads: {expected} of 3")),
            "{name}: check says\n{said}"
        );
        let registers = registers_here();
        assert_eq!(
            summary["timing"]["registers"], registers,
            "{name}: summary.json"
        );
        assert!(
            said.contains(&format!("registers: {registers}")),
            "{name}: check says\n{said}"
        );
    }
}

/// The build of the loops compiled twice that this processor should run: AVX2 and FMA
/// where it has both (the target the loops are compiled for), else the baseline.
fn registers_here() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        return "avx2+fma";
    }
    "baseline"
}
