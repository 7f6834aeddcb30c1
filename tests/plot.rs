//! Charts (`impact::output::plot` and `impact plot`): files that exist, carry their text, have
//! the promised size, and errors instead of panics for bad input.

mod common;

use common::impact;

use impact::output::plot::{self, Chart, Series, SeriesStyle};
use std::f64::consts::PI;
use std::path::Path;

/// sin and cos over one period, 101 points each: a line and a line with markers.
fn sin_cos_chart() -> Chart {
    let points = |f: fn(f64) -> f64| -> Vec<(f64, f64)> {
        (0..=100)
            .map(|i| 2.0 * PI * i as f64 / 100.0)
            .map(|t| (t, f(t)))
            .collect()
    };
    Chart {
        title: "Analytic check: sin and cos".to_string(),
        x_label: "t [rad]".to_string(),
        y_label: "value".to_string(),
        series: vec![
            Series {
                label: "sin(t)".to_string(),
                points: points(f64::sin),
                style: SeriesStyle::Line,
            },
            Series {
                label: "cos(t)".to_string(),
                points: points(f64::cos),
                style: SeriesStyle::LineAndMarkers,
            },
        ],
        log_x: false,
        log_y: false,
        x_limits: Default::default(),
        y_limits: Default::default(),
        notes: Vec::new(),
    }
}

/// The contents of the SVG's `<text>` elements, trimmed.
fn svg_texts(svg: &str) -> Vec<&str> {
    svg.split("<text")
        .skip(1)
        .filter_map(|element| {
            let (_, rest) = element.split_once('>')?;
            let (content, _) = rest.split_once("</text>")?;
            Some(content.trim())
        })
        .collect()
}

/// (width, height) from a PNG's signature and IHDR chunk, checked by hand.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&bytes[12..16], b"IHDR", "first chunk");
    let word = |at: usize| u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap());
    (word(16), word(20))
}

/// Goal: one chart written as SVG and as PNG; the SVG holds the title and both legend labels as
/// text, the PNG is 800 x 500 by its header and decodes to that many RGB pixels with text and
/// lines drawn (not a blank canvas). No temporary file is left behind.
#[test]
fn sin_cos_chart_writes_svg_and_png_with_text() {
    let dir = common::out_dir("plot_sin_cos");
    let chart = sin_cos_chart();
    let svg_path = dir.join("sin_cos.svg");
    let png_path = dir.join("sin_cos.png");
    plot::write(&chart, &svg_path).unwrap();
    plot::write(&chart, &png_path).unwrap();

    let svg = std::fs::read_to_string(&svg_path).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..80.min(svg.len())]);
    assert!(svg.contains(r#"width="800" height="500""#));
    let texts = svg_texts(&svg);
    for text in [
        "Analytic check: sin and cos",
        "sin(t)",
        "cos(t)",
        "t [rad]",
        "value",
    ] {
        assert!(
            texts.contains(&text),
            "no text `{text}` in the SVG: {texts:?}"
        );
    }

    let bytes = std::fs::read(&png_path).unwrap();
    assert_eq!(png_size(&bytes), (800, 500));
    let mut reader = png::Decoder::new(std::io::Cursor::new(&bytes))
        .read_info()
        .unwrap();
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let frame = reader.next_frame(&mut pixels).unwrap();
    assert_eq!((frame.width, frame.height), (800, 500));
    assert_eq!(frame.color_type, png::ColorType::Rgb);
    let rgb = &pixels[..frame.buffer_size()];
    let dark = rgb.chunks(3).filter(|p| p.iter().all(|&c| c < 80)).count();
    let blue = rgb.chunks(3).filter(|p| p == &[31, 119, 180]).count();
    assert!(dark > 1000, "{dark} dark pixels: no text or axes drawn");
    assert!(blue > 500, "{blue} pixels of the first series' colour");

    for path in [&svg_path, &png_path] {
        let mut tmp = path.as_os_str().to_owned();
        tmp.push(".tmp");
        assert!(!Path::new(&tmp).exists());
    }
}

/// Goal: bad charts are errors naming the problem, not panics, and write nothing: an unknown
/// extension, a NaN, no series, an empty series, a zero on a logarithmic axis.
#[test]
fn bad_charts_are_errors() {
    let dir = common::out_dir("plot_errors");
    let chart = sin_cos_chart();
    let jpg = dir.join("chart.jpg");
    let err = plot::write(&chart, &jpg).unwrap_err().to_string();
    assert!(
        err.contains(".png or .svg") && err.contains("chart.jpg"),
        "{err}"
    );
    assert!(!jpg.exists());

    let svg = dir.join("chart.svg");
    let mut nan = sin_cos_chart();
    nan.series[1].points[7].1 = f64::NAN;
    let err = plot::write(&nan, &svg).unwrap_err().to_string();
    assert!(
        err.contains("cos(t)") && err.contains("point 7") && err.contains("NaN"),
        "{err}"
    );

    let mut none = sin_cos_chart();
    none.series.clear();
    let err = plot::write(&none, &svg).unwrap_err().to_string();
    assert!(err.contains("no series"), "{err}");

    let mut empty = sin_cos_chart();
    empty.series[0].points.clear();
    let err = plot::write(&empty, &svg).unwrap_err().to_string();
    assert!(err.contains("`sin(t)` has no points"), "{err}");

    let mut log = sin_cos_chart();
    log.log_x = true;
    let err = plot::write(&log, &svg).unwrap_err().to_string();
    assert!(err.contains("logarithmic"), "{err}");
    assert!(!svg.exists());
}

/// Goal: logarithmic axes on both sides draw (a convergence plot: error ~ h^2 with markers).
#[test]
fn log_log_convergence_chart_writes() {
    let dir = common::out_dir("plot_log_log");
    let h = [0.5, 0.25, 0.125, 0.0625];
    let chart = Chart {
        title: "Convergence".to_string(),
        x_label: "h".to_string(),
        y_label: "error".to_string(),
        series: vec![Series {
            label: "error".to_string(),
            points: h.iter().map(|&h| (h, 0.3 * h * h)).collect(),
            style: SeriesStyle::Markers,
        }],
        log_x: true,
        log_y: true,
        x_limits: Default::default(),
        y_limits: Default::default(),
        notes: Vec::new(),
    };
    for name in ["convergence.svg", "convergence.png"] {
        plot::write(&chart, &dir.join(name)).unwrap();
    }
    let svg = std::fs::read_to_string(dir.join("convergence.svg")).unwrap();
    assert!(svg_texts(&svg).contains(&"Convergence") && svg.contains("<circle"));
}

/// Goal: history_columns reads columns by name in the order asked; a missing column is an
/// error naming it and the columns there are.
#[test]
fn history_columns_reads_by_name() {
    let dir = common::out_dir("plot_history_columns");
    let path = write_history(&dir);
    let columns = plot::history_columns(&path, &["u_y[tip]", "time"]).unwrap();
    assert_eq!(columns[1], [0.0, 0.1, 0.2, 0.3]);
    assert_eq!(columns[0], [0.0, -1e-3, -4e-3, -9e-3]);
    let err = plot::history_columns(&path, &["time", "u_z"])
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("`u_z`") && err.contains("kinetic_energy"),
        "{err}"
    );
}

fn write_history(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("history.csv");
    std::fs::write(
        &path,
        "time,kinetic_energy,u_y[tip]\n0,0,0\n0.1,0.5,-1e-3\n0.2,2,-4e-3\n0.3,4.5,-9e-3\n",
    )
    .unwrap();
    path
}

/// Goal: `impact plot` exits 0 and writes the chart (with a reference run overlaid); an unknown
/// column or a missing history exits 2 with a message naming it; clap's own errors also exit 2.
#[test]
fn cli_plot_exit_codes() {
    let dir = common::out_dir("plot_cli");
    let history = write_history(&dir);
    let history = history.to_str().unwrap();
    let out = dir.join("tip.png");
    let run = impact(&[
        "plot",
        history,
        "--y",
        "u_y[tip]",
        "--y",
        "kinetic_energy",
        "--out",
        out.to_str().unwrap(),
        "--title",
        "Tip",
        "--reference",
        history,
    ]);
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(png_size(&std::fs::read(&out).unwrap()), (800, 500));

    let run = impact(&["plot", history, "--y", "kinetic_energy"]);
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let svg = std::fs::read_to_string(dir.join("plot_kinetic_energy.svg")).unwrap();
    assert!(svg_texts(&svg).contains(&"kinetic_energy"));

    let run = impact(&["plot", history, "--y", "u_z"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("`u_z`") && stderr.contains("history.csv"),
        "{stderr}"
    );

    let missing = dir.join("no_such_run").join("history.csv");
    let run = impact(&["plot", missing.to_str().unwrap(), "--y", "kinetic_energy"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("no_such_run"), "{stderr}");

    let run = impact(&["plot", history, "--y", "kinetic_energy", "--out", "a.jpg"]);
    assert_eq!(run.status.code(), Some(2));
    let run = impact(&["plot", history]);
    assert_eq!(run.status.code(), Some(2), "--y is required");
}

/// The RGB pixels of a PNG file: (width, height, rows of pixels).
fn png_pixels(path: &Path) -> (usize, usize, Vec<[u8; 3]>) {
    let bytes = std::fs::read(path).unwrap();
    let mut reader = png::Decoder::new(std::io::Cursor::new(&bytes))
        .read_info()
        .unwrap();
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let frame = reader.next_frame(&mut pixels).unwrap();
    let rgb = pixels[..frame.buffer_size()]
        .chunks(3)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    (frame.width as usize, frame.height as usize, rgb)
}

/// Goal: a PNG draws a chattering curve inside its axes (the bitmap backend's mitred joins of
/// a thick polyline drew a vertical line below the x axis at t = 0.046, the SVG did not).
/// Setup: the contact force of models/round_bar.toml (tests/data/round_bar_contact_force.csv,
/// 211 rows between 0 and 23.3; near t = 0.046 two steps of 2e-4 and 1e-4 go 6.0 -> 13.4 ->
/// 5.5), drawn as PNG.
/// Reference: the layout: a 16 px margin and a 48 px x-label area below the plot, so no pixel
/// of the series' colour may lie in the bottom 64 rows (labels and ticks are black or grey).
#[test]
fn png_curve_stays_inside_the_axes() {
    let dir = common::out_dir("plot_chatter");
    let columns = plot::history_columns(
        Path::new("tests/data/round_bar_contact_force.csv"),
        &["time", "contact_force[tip]"],
    )
    .unwrap();
    let chart = Chart {
        title: "round_bar".into(),
        x_label: "time".into(),
        y_label: "contact_force[tip]".into(),
        series: vec![Series {
            label: "contact_force[tip]".into(),
            points: columns[0]
                .iter()
                .copied()
                .zip(columns[1].iter().copied())
                .collect(),
            style: SeriesStyle::Line,
        }],
        log_x: false,
        log_y: false,
        x_limits: Default::default(),
        y_limits: Default::default(),
        notes: Vec::new(),
    };
    let path = dir.join("round_bar.png");
    plot::write(&chart, &path).unwrap();
    let (width, height, rgb) = png_pixels(&path);
    let blue = [31, 119, 180];
    let below: Vec<(usize, usize)> = rgb
        .iter()
        .enumerate()
        .filter(|(_, p)| **p == blue)
        .map(|(k, _)| (k % width, k / width))
        .filter(|(_, row)| *row >= height - 64)
        .collect();
    assert!(
        rgb.iter().filter(|p| **p == blue).count() > 1000,
        "the curve is drawn"
    );
    assert!(
        below.is_empty(),
        "{} series pixels below the axis, e.g. {:?}",
        below.len(),
        &below[..below.len().min(5)]
    );
}

/// Goal: `impact plot` offers one panel per column (a 1e-3 column beside a 4.5 one stays
/// readable) and fixed axis ends; a legend goes where it covers the fewest points.
/// Reference: the panel layout (300 px per panel), the SVG's tick labels within the asked
/// x range [0.1, 0.2], and the legend of a curve rising to the upper right placed elsewhere.
#[test]
fn cli_plot_panels_and_axis_ranges() {
    let dir = common::out_dir("plot_panels");
    let history = write_history(&dir);
    let history = history.to_str().unwrap();
    let out = dir.join("panels.png");
    let run = impact(&[
        "plot",
        history,
        "--y",
        "u_y[tip]",
        "--y",
        "kinetic_energy",
        "--panels",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(png_size(&std::fs::read(&out).unwrap()), (800, 600));
    let svg_out = dir.join("range.svg");
    let run = impact(&[
        "plot",
        history,
        "--y",
        "kinetic_energy",
        "--xmin",
        "0.1",
        "--xmax",
        "0.2",
        "--ymin",
        "-1",
        "--out",
        svg_out.to_str().unwrap(),
    ]);
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let svg = std::fs::read_to_string(&svg_out).unwrap();
    let ticks: Vec<f64> = svg_texts(&svg)
        .iter()
        .filter_map(|t| t.parse::<f64>().ok())
        .collect();
    assert!(ticks.contains(&0.1) && ticks.contains(&0.2), "{ticks:?}");
    assert!(ticks.contains(&-1.0), "{ticks:?}");
    let bad = impact(&[
        "plot",
        history,
        "--y",
        "kinetic_energy",
        "--xmin",
        "1",
        "--xmax",
        "0",
    ]);
    assert_eq!(
        bad.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&bad.stderr)
    );
}

/// Goal: `impact plot` draws any table in history.csv's form against a column named by --x, on
/// a logarithmic axis with --log-x, and refuses a logarithmic axis over a value <= 0 (exit 2,
/// the value named). Setup: a study's table (v_over_vy 1, 10, 100 and a column e).
#[test]
fn cli_plot_draws_a_study_table_on_a_log_axis() {
    let dir = common::out_dir("plot_table");
    let table = dir.join("restitution.csv");
    std::fs::write(&table, "v_over_vy,e\n1,1\n10,0.85\n100,0.57\n").unwrap();
    let table = table.to_str().unwrap();
    let out = dir.join("e.svg");
    let args = [
        "plot",
        table,
        "--x",
        "v_over_vy",
        "--y",
        "e",
        "--log-x",
        "--out",
    ];
    let run = impact(&[&args[..], &[out.to_str().unwrap()]].concat());
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let svg = std::fs::read_to_string(&out).unwrap();
    // the decades of the logarithmic axis are labelled
    for label in ["10", "100"] {
        assert!(
            svg_texts(&svg).contains(&label),
            "{label} not in {:?}",
            svg_texts(&svg)
        );
    }
    let zero = dir.join("zero.csv");
    std::fs::write(&zero, "v_over_vy,e\n0,1\n10,0.85\n").unwrap();
    let args = [
        "plot",
        zero.to_str().unwrap(),
        "--x",
        "v_over_vy",
        "--y",
        "e",
        "--log-x",
    ];
    let run = impact(&args);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("x = 0") && stderr.contains("logarithmic axis"),
        "{stderr}"
    );
}

/// Goal: `impact plot` labels its axes with the units of the run's columns (summary.json
/// `column_units` beside the history). Setup: models/taylor_aluminum.toml run as shipped,
/// then kinetic energy and plastic work on one axis, kinetic energy beside a displacement
/// probe on another. Reference: the scene's material data are SI (density 2700 kg/m^3, E
/// 70 GPa: the user guide's rule for SI), and the rod is axisymmetric (the full ring: no
/// "per depth"): energies in J, time in s, displacements in m; one unit after columns that
/// share it, each column's own where they differ.
#[test]
fn cli_plot_labels_its_axes_with_the_run_units() {
    let dir = common::out_dir("plot_units");
    let run = impact(&[
        "run",
        "models/taylor_aluminum.toml",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(0));
    let history = dir.join("history.csv");
    let plotted = |y: &[&str], name: &str| {
        let out = dir.join(name);
        let mut args = vec![
            "plot",
            history.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        for column in y {
            args.extend(["--y", column]);
        }
        let run = impact(&args);
        assert_eq!(
            run.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let svg = std::fs::read_to_string(&out).unwrap();
        svg_texts(&svg)
            .into_iter()
            .map(String::from)
            .collect::<Vec<String>>()
    };
    let texts = plotted(&["kinetic_energy", "plastic_work"], "energies.svg");
    assert!(texts.iter().any(|t| t == "time [s]"), "{texts:?}");
    assert!(
        texts
            .iter()
            .any(|t| t == "kinetic_energy, plastic_work [J]"),
        "{texts:?}"
    );
    let texts = plotted(&["kinetic_energy", "u_y[top_axis]"], "mixed.svg");
    let mixed = "kinetic_energy [J], u_y[top_axis] [m]";
    assert!(texts.iter().any(|t| t == mixed), "{texts:?}");
}
