//! Charts of x-y series as PNG or SVG, drawn by plotters: `impact plot` now, convergence and
//! sweep studies later.
//!
//! ```text
//! Chart   title, axis labels, linear or logarithmic axes, one or more Series
//! Series  label (shown in the legend when the chart has more than one), points (x, y),
//!         style: Line, Markers or LineAndMarkers
//! write   800 x 500 pixels; the format follows the extension (.png or .svg); the file is
//!         written whole to a temporary name and renamed, like every output file
//! ```
//!
//! Text in the PNG is rasterized from DejaVu Sans embedded in the binary (no system font, no
//! fontconfig or freetype). The SVG names the family `sans-serif` and leaves rendering to the
//! viewer; the same embedded font measures the text for the layout.

use super::{OutputError, write_atomic};
use plotters::coord::Shift;
use plotters::coord::combinators::{LogCoord, WithKeyPoints};
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

mod frame;
mod map;

pub use frame::frame_columns;
pub use map::{Cell, CellKind, Map, write_map};

/// Width and height of every chart, in pixels (PNG) or user units (SVG).
pub const SIZE: (u32, u32) = (800, 500);

// DejaVu Sans 2.37 (Debian fonts-dejavu-core), Bitstream Vera license: redistribution permitted,
// see DejaVuSans.LICENSE next to it.
const DEJAVU_SANS: &[u8] = include_bytes!("../DejaVuSans.ttf");

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesStyle {
    /// A polyline through the points in the given order.
    Line,
    /// A filled circle at each point.
    Markers,
    /// Both.
    LineAndMarkers,
}

/// One curve of a chart.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text (the legend is drawn only when the chart has more than one series).
    pub label: String,
    /// (x, y) pairs; all finite, and positive on a logarithmic axis.
    pub points: Vec<(f64, f64)>,
    pub style: SeriesStyle,
}

/// A chart to write with [`write`].
#[derive(Debug, Clone)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub log_x: bool,
    pub log_y: bool,
    /// Axis ends given by the user; the others follow the data (with a margin).
    pub x_limits: Limits,
    pub y_limits: Limits,
    /// Lines printed in the plot's upper left corner, in red: what a reader must know before
    /// trusting the curves (e.g. that a measure does not converge).
    pub notes: Vec<String>,
}

/// Ends of an axis fixed by the user (`--xmin` ...); None: from the data.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Limits {
    pub low: Option<f64>,
    pub high: Option<f64>,
}

/// Writes `chart` to `path`: PNG or SVG by the extension, 800 x 500, legend when more than one series.
///
/// An unknown extension, a chart without series, a series without points, a NaN or infinite
/// value, or a value <= 0 on a logarithmic axis is an [`OutputError::Invalid`] naming the file;
/// nothing is written then.
pub fn write(chart: &Chart, path: &Path) -> Result<(), OutputError> {
    write_panels(std::slice::from_ref(chart), path)
}

/// Writes `panels` stacked from top to bottom in one file (800 wide, 500 high for one panel,
/// 300 per panel for several), each with its own axes, like [`write`].
pub fn write_panels(panels: &[Chart], path: &Path) -> Result<(), OutputError> {
    let format = Format::of(path)?;
    if panels.is_empty() {
        return Err(OutputError::invalid(path, "the chart has no series"));
    }
    let ranges = panels
        .iter()
        .map(|chart| {
            Ok((
                axis_range(chart, path, Axis::X)?,
                axis_range(chart, path, Axis::Y)?,
            ))
        })
        .collect::<Result<Vec<_>, OutputError>>()?;
    register_embedded_font();
    let size = if panels.len() == 1 {
        SIZE
    } else {
        (SIZE.0, PANEL_HEIGHT * panels.len() as u32)
    };
    let drawing_error =
        |e: String| OutputError::invalid(path, format!("cannot draw the chart: {e}"));
    match format {
        Format::Svg => {
            let mut text = String::new();
            draw_all(
                SVGBackend::with_string(&mut text, size).into_drawing_area(),
                panels,
                &ranges,
            )
            .map_err(drawing_error)?;
            write_atomic(path, text.as_bytes())
        }
        Format::Png => {
            let (width, height) = size;
            let mut pixels = vec![0u8; 3 * width as usize * height as usize];
            draw_all(
                BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area(),
                panels,
                &ranges,
            )
            .map_err(drawing_error)?;
            let bytes = encode_png(&pixels, size)
                .map_err(|e| OutputError::invalid(path, format!("cannot encode the PNG: {e}")))?;
            write_atomic(path, &bytes)
        }
    }
}

/// The height of one of several panels, in pixels.
const PANEL_HEIGHT: u32 = 300;

type Ranges = ((f64, f64), (f64, f64));

/// Draws the panels one below the other on `root` and presents it.
fn draw_all<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    panels: &[Chart],
    ranges: &[Ranges],
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let areas = root.split_evenly((panels.len(), 1));
    for ((area, chart), (x, y)) in areas.into_iter().zip(panels).zip(ranges) {
        draw(area, chart, *x, *y)?;
    }
    root.present().map_err(e)
}

/// Reads the columns `names` of a history.csv, or of any table of numbers in its form
/// (header line of names, one row of numbers per line; a study's table such as
/// models/restitution_study.sh writes), each as a vector over the rows, in the order asked.
///
/// A missing column is an [`OutputError::Invalid`] that names it and lists the columns there are.
pub fn history_columns(path: &Path, names: &[&str]) -> Result<Vec<Vec<f64>>, OutputError> {
    let text = std::fs::read_to_string(path).map_err(|e| OutputError::io(path, "read", e))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let mut indices = Vec::with_capacity(names.len());
    for name in names {
        let index = header.iter().position(|h| h == name).ok_or_else(|| {
            OutputError::invalid(
                path,
                format!("no column `{name}`; the columns are: {}", header.join(", ")),
            )
        })?;
        indices.push(index);
    }
    let mut columns = vec![Vec::new(); names.len()];
    for (row, line) in lines.enumerate().filter(|(_, line)| !line.is_empty()) {
        let line_number = row + 2;
        let values: Vec<&str> = line.split(',').collect();
        if values.len() != header.len() {
            return Err(OutputError::Length {
                path: path.to_path_buf(),
                what: format!("line {line_number}"),
                expected: header.len(),
                found: values.len(),
            });
        }
        for (column, &index) in columns.iter_mut().zip(&indices) {
            let value = values[index].trim().parse::<f64>().map_err(|_| {
                OutputError::invalid(
                    path,
                    format!(
                        "line {line_number}, column `{}`: `{}` is not a number",
                        header[index], values[index]
                    ),
                )
            })?;
            column.push(value);
        }
    }
    Ok(columns)
}

enum Format {
    Png,
    Svg,
}

impl Format {
    fn of(path: &Path) -> Result<Format, OutputError> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("png") => Ok(Format::Png),
            Some("svg") => Ok(Format::Svg),
            _ => Err(OutputError::invalid(
                path,
                "unknown chart format: the file name must end in .png or .svg",
            )),
        }
    }
}

#[derive(Clone, Copy)]
enum Axis {
    X,
    Y,
}

/// The axis range (low, high) covering every point with a margin; checks the values on the way.
fn axis_range(chart: &Chart, path: &Path, axis: Axis) -> Result<(f64, f64), OutputError> {
    let (log, name) = match axis {
        Axis::X => (chart.log_x, "x"),
        Axis::Y => (chart.log_y, "y"),
    };
    if chart.series.is_empty() {
        return Err(OutputError::invalid(path, "the chart has no series"));
    }
    let mut low = f64::INFINITY;
    let mut high = f64::NEG_INFINITY;
    for series in &chart.series {
        if series.points.is_empty() {
            return Err(OutputError::invalid(
                path,
                format!("series `{}` has no points", series.label),
            ));
        }
        for (index, &(x, y)) in series.points.iter().enumerate() {
            let value = match axis {
                Axis::X => x,
                Axis::Y => y,
            };
            let problem = if !value.is_finite() {
                "only finite values can be plotted"
            } else if log && value <= 0.0 {
                "only positive values can be plotted on a logarithmic axis"
            } else {
                ""
            };
            if !problem.is_empty() {
                return Err(OutputError::invalid(
                    path,
                    format!(
                        "series `{}` point {index} has {name} = {value}; {problem}",
                        series.label
                    ),
                ));
            }
            low = low.min(value);
            high = high.max(value);
        }
    }
    // markers at the ends of the x range would be cut in half without a margin
    let markers = chart.series.iter().any(|s| s.style != SeriesStyle::Line);
    let margin = match axis {
        Axis::X if !markers => 0.0,
        Axis::X => 0.03,
        Axis::Y => 0.05,
    };
    let limits = match axis {
        Axis::X => chart.x_limits,
        Axis::Y => chart.y_limits,
    };
    let (auto_low, auto_high) = if log {
        let factor = if high > low {
            (high / low).powf(margin)
        } else {
            2.0
        };
        (low / factor, high * factor)
    } else if high > low {
        let pad = margin * (high - low);
        (low - pad, high + pad)
    } else {
        let pad = if low == 0.0 { 1.0 } else { 0.1 * low.abs() };
        (low - pad, high + pad)
    };
    let (low, high) = (
        limits.low.unwrap_or(auto_low),
        limits.high.unwrap_or(auto_high),
    );
    if !(low.is_finite() && high.is_finite() && low < high) || (log && low <= 0.0) {
        return Err(OutputError::invalid(
            path,
            format!(
                "the {name} axis from {low} to {high} is empty{}",
                if log {
                    " or not positive (logarithmic)"
                } else {
                    ""
                }
            ),
        ));
    }
    Ok((low, high))
}

/// Makes the embedded font the `sans-serif` family plotters measures and rasterizes text with.
fn register_embedded_font() {
    static REGISTER: Once = Once::new();
    REGISTER.call_once(|| {
        if plotters::style::register_font("sans-serif", FontStyle::Normal, DEJAVU_SANS).is_err() {
            panic!("the embedded DejaVu Sans does not parse as a font");
        }
    });
}

/// Draws the whole chart on `root` and presents it (SVG: fills the string; bitmap: the buffer).
fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    chart: &Chart,
    x: (f64, f64),
    y: (f64, f64),
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(&chart.title, (FontFamily::SansSerif, 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(80);
    // tick labels much smaller than a linear axis' span print as 0; log axes pass 0
    let span = |(low, high): (f64, f64), log: bool| if log { 0.0 } else { high - low };
    let (x_span, y_span) = (span(x, chart.log_x), span(y, chart.log_y));
    let plotted = match (chart.log_x, chart.log_y) {
        (false, false) => draw_series(
            builder.build_cartesian_2d(x.0..x.1, y.0..y.1).map_err(e)?,
            chart,
            x_span,
            y_span,
        ),
        (true, false) => draw_series(
            builder
                .build_cartesian_2d(log_axis(x), y.0..y.1)
                .map_err(e)?,
            chart,
            x_span,
            y_span,
        ),
        (false, true) => draw_series(
            builder
                .build_cartesian_2d(x.0..x.1, log_axis(y))
                .map_err(e)?,
            chart,
            x_span,
            y_span,
        ),
        (true, true) => draw_series(
            builder
                .build_cartesian_2d(log_axis(x), log_axis(y))
                .map_err(e)?,
            chart,
            x_span,
            y_span,
        ),
    };
    plotted.map_err(e)?;
    let note_style = TextStyle::from((FontFamily::SansSerif, 14)).color(&RGBColor(180, 0, 0));
    for (k, note) in chart.notes.iter().enumerate() {
        root.draw(&Text::new(
            note.as_str(),
            (104, 50 + 18 * k as i32),
            note_style.clone(),
        ))
        .map_err(e)?;
    }
    Ok(())
}

/// Colours of the series in order (the matplotlib "tab10" cycle), repeated past ten.
const COLORS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Mesh, axis labels, the series and the legend, on axes of any kind (linear or log).
///
/// `x_span`, `y_span`: widths of linear axes (tick labels much smaller than it print as 0);
/// 0 for a logarithmic axis.
fn draw_series<'a, DB, X, Y>(
    mut context: ChartContext<'a, DB, Cartesian2d<X, Y>>,
    chart: &Chart,
    x_span: f64,
    y_span: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let x_ticks = |v: &f64| tick_label(*v, x_span);
    let y_ticks = |v: &f64| tick_label(*v, y_span);
    context
        .configure_mesh()
        .x_desc(chart.x_label.as_str())
        .y_desc(chart.y_label.as_str())
        .x_label_formatter(&x_ticks)
        .y_label_formatter(&y_ticks)
        .label_style((FontFamily::SansSerif, 14))
        .axis_desc_style((FontFamily::SansSerif, 16))
        .bold_line_style(BLACK.mix(0.15))
        .light_line_style(BLACK.mix(0.05))
        .draw()?;
    let legend = chart.series.len() > 1;
    let (x_range, y_range) = (context.x_range(), context.y_range());
    let bounds = Bounds {
        x: (x_range.start, x_range.end),
        y: (y_range.start, y_range.end),
    };
    for (index, series) in chart.series.iter().enumerate() {
        let color = COLORS[index % COLORS.len()];
        let line = color.stroke_width(2);
        let dot = color.filled();
        let with_line = series.style != SeriesStyle::Markers;
        let with_markers = series.style != SeriesStyle::Line;
        if with_line {
            // segment by segment, clipped to the axes: plotters joins a thick polyline's
            // segments with miters, which on a curve that turns back sharply (a contact force
            // that chatters between steps) reach far outside the plot in the bitmap backend
            let segments = series
                .points
                .windows(2)
                .filter_map(|w| clip_segment(w[0], w[1], &bounds))
                .map(|(a, b)| PathElement::new(vec![a, b], line));
            let annotation = context.draw_series(segments)?;
            if legend && !with_markers {
                annotation
                    .label(series.label.as_str())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], line));
            }
        }
        if with_markers {
            let annotation = context.draw_series(
                series
                    .points
                    .iter()
                    .filter(|p| bounds.contains(**p))
                    .map(|&point| Circle::new(point, 3, dot)),
            )?;
            if legend {
                annotation
                    .label(series.label.as_str())
                    .legend(move |(x, y)| {
                        let stroke = if with_line { line } else { TRANSPARENT.into() };
                        EmptyElement::at((x, y))
                            + PathElement::new(vec![(0, 0), (20, 0)], stroke)
                            + Circle::new((10, 0), 3, dot)
                    });
            }
        }
    }
    if legend {
        context
            .configure_series_labels()
            .position(legend_corner(chart, &bounds))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .label_font((FontFamily::SansSerif, 14))
            .draw()?;
    }
    Ok(())
}

/// The plotted ranges of a chart's axes (in data values).
struct Bounds {
    x: (f64, f64),
    y: (f64, f64),
}

impl Bounds {
    fn contains(&self, (x, y): (f64, f64)) -> bool {
        (self.x.0..=self.x.1).contains(&x) && (self.y.0..=self.y.1).contains(&y)
    }

    /// The point as fractions of the axes (0 at the low end, 1 at the high one); logarithmic
    /// axes are measured linearly here, which is enough to choose a corner.
    fn fraction(&self, (x, y): (f64, f64)) -> (f64, f64) {
        (
            (x - self.x.0) / (self.x.1 - self.x.0),
            (y - self.y.0) / (self.y.1 - self.y.0),
        )
    }
}

/// The part of the segment a-b inside `bounds` (Liang-Barsky), or None.
fn clip_segment(a: (f64, f64), b: (f64, f64), bounds: &Bounds) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - bounds.x.0),
        (dx, bounds.x.1 - a.0),
        (-dy, a.1 - bounds.y.0),
        (dy, bounds.y.1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    (t0 <= t1).then_some((
        (a.0 + t0 * dx, a.1 + t0 * dy),
        (a.0 + t1 * dx, a.1 + t1 * dy),
    ))
}

/// The corner of the plot whose legend-sized box (a third of the width, a band of the height
/// growing with the entries) covers the fewest points of the series; upper right on a tie.
fn legend_corner(chart: &Chart, bounds: &Bounds) -> SeriesLabelPosition {
    let width = 0.4;
    let height = (0.08 * chart.series.len() as f64 + 0.05).min(0.6);
    let corners = [
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::LowerLeft, false, false),
    ];
    let covered = |right: bool, upper: bool| -> usize {
        let inside = |(fx, fy): (f64, f64)| {
            let in_x = if right {
                fx >= 1.0 - width
            } else {
                fx <= width
            };
            let in_y = if upper {
                fy >= 1.0 - height
            } else {
                fy <= height
            };
            in_x && in_y
        };
        chart
            .series
            .iter()
            .flat_map(|s| &s.points)
            .filter(|p| inside(bounds.fraction(**p)))
            .count()
    };
    corners
        .into_iter()
        .min_by_key(|(_, right, upper)| covered(*right, *upper))
        .map(|(position, _, _)| position)
        .expect("four corners")
}

/// A logarithmic axis over `low..high` with its own ticks.
///
/// plotters' log axis puts ticks at 1..9 x 10^k computed by multiplication (0.00999.. and 0.01
/// both appear, labelled twice a pixel apart) and up to a hundred light lines a decade. Here
/// the ticks are parsed from text (`2e-3` is exactly 0.002): labelled (bold) at 1..9 x 10^k
/// within a decade, 1, 2, 5 x 10^k over one to three, 10^k beyond (every n-th decade past
/// eight); light lines at 1..9 x 10^k up to six decades.
fn log_axis((low, high): (f64, f64)) -> WithKeyPoints<LogCoord<f64>> {
    let decades = (high / low).log10();
    let ticks = |mantissas: &[u32], every: i32| -> Vec<f64> {
        let first = low.log10().floor() as i32;
        let last = high.log10().ceil() as i32;
        (first..=last)
            .filter(|k| k.rem_euclid(every) == 0)
            .flat_map(|k| mantissas.iter().map(move |m| format!("{m}e{k}")))
            .filter_map(|text| text.parse::<f64>().ok())
            .filter(|v| (low..=high).contains(v))
            .collect()
    };
    const ALL: [u32; 9] = [1, 2, 3, 4, 5, 6, 7, 8, 9];
    let mut bold = if decades >= 3.0 {
        ticks(&[1], (decades / 8.0).ceil() as i32)
    } else if decades >= 1.0 {
        ticks(&[1, 2, 5], 1)
    } else {
        ticks(&ALL, 1)
    };
    if bold.len() < 2 {
        // a narrow range between two ticks: five geometric steps in two significant digits
        bold = (0..5)
            .map(|i| low * (high / low).powf(0.1 + 0.2 * f64::from(i)))
            .filter_map(|v| format!("{v:.1e}").parse::<f64>().ok())
            .collect();
        bold.dedup();
    }
    let light = if decades <= 6.0 {
        ticks(&ALL, 1)
    } else {
        ticks(&[1], 1)
    };
    (low..high)
        .log_scale()
        .with_key_points(bold)
        .with_light_points(light)
}

/// A tick value in at most four significant digits, `0` for values negligible against `span`
/// (linear axes; 0 for logarithmic ones), exponent notation outside [1e-3, 1e5).
fn tick_label(value: f64, span: f64) -> String {
    if value == 0.0 || value.abs() < 1e-9 * span {
        return "0".to_string();
    }
    let magnitude = value.abs();
    // the decimal place of a tenth of the span: neighbouring ticks must print apart
    let resolved = if span > 0.0 {
        -(0.1 * span).log10().floor() as i32
    } else {
        i32::MIN / 2
    };
    let order = magnitude.log10().floor() as i32;
    if (1e-3..1e5).contains(&magnitude) {
        let decimals = (3 - order).max(resolved).max(0) as usize;
        trim_zeros(&format!("{value:.decimals$}"))
    } else {
        let digits = 3.max(order + resolved) as usize;
        let text = format!("{value:.digits$e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        format!("{}e{exponent}", trim_zeros(mantissa))
    }
}

/// "1.2500" -> "1.25", "2.000" -> "2", "40" -> "40".
fn trim_zeros(text: &str) -> String {
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text.to_string()
    }
}

/// 8-bit RGB pixels (row-major, as plotters' bitmap backend leaves them) as a PNG file.
fn encode_png(pixels: &[u8], (width, height): (u32, u32)) -> Result<Vec<u8>, png::EncodingError> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(pixels)?;
    writer.finish()?;
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: tick labels are short and free of floating-point noise.
    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick_label(0.30000000000000004, 1.0), "0.3");
        assert_eq!(tick_label(1e-17, 1.0), "0");
        assert_eq!(tick_label(2.0, 10.0), "2");
        assert_eq!(tick_label(1234.5678, 1e4), "1235");
        assert_eq!(tick_label(-0.0125, 0.1), "-0.0125");
        assert_eq!(tick_label(1e-6, 0.0), "1e-6");
        assert_eq!(tick_label(2.5e7, 1e8), "2.5e7");
        // a narrow span about a large value: neighbouring ticks 2e-6 apart print apart
        assert_eq!(tick_label(0.026572, 2e-5), "0.026572");
        assert_eq!(tick_label(1.23456e7, 1e3), "1.23456e7");
    }

    /// Goal: log-axis ticks are exact 1-2-5 values inside the range, once each, and a range
    /// narrower than a tick step still gets labels.
    #[test]
    fn log_axis_ticks_are_exact_and_sparse() {
        let bold = |range| log_axis(range).bold_points().to_vec();
        assert_eq!(bold((8e-4, 0.09)), [1e-3, 2e-3, 5e-3, 0.01, 0.02, 0.05]);
        assert_eq!(bold((0.5, 2e4)), [1.0, 10.0, 100.0, 1e3, 1e4]);
        assert_eq!(bold((1e-20, 1.0)).len(), 7);
        assert_eq!(bold((0.25, 0.55)), [0.3, 0.4, 0.5]);
        assert_eq!(bold((0.31, 0.39)).len(), 5);
        let light = log_axis((8e-4, 0.09)).light_points().to_vec();
        assert_eq!(light.len(), 2 + 9 + 9);
        assert!(light.contains(&0.01) && !light.contains(&0.09999999999999999));
    }

    /// Goal: the axis range covers the data with a margin, and a single value gets a range too.
    #[test]
    fn axis_range_pads_and_handles_constant_data() {
        let series = |points: Vec<(f64, f64)>| Series {
            label: "s".into(),
            points,
            style: SeriesStyle::Line,
        };
        let mut chart = Chart {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            series: vec![series(vec![(0.0, -1.0), (2.0, 1.0)])],
            log_x: false,
            log_y: false,
            x_limits: Default::default(),
            y_limits: Default::default(),
            notes: Vec::new(),
        };
        let path = Path::new("a.svg");
        assert_eq!(axis_range(&chart, path, Axis::X).unwrap(), (0.0, 2.0));
        assert_eq!(axis_range(&chart, path, Axis::Y).unwrap(), (-1.1, 1.1));
        chart.series = vec![series(vec![(1.0, 3.0)])];
        assert_eq!(axis_range(&chart, path, Axis::X).unwrap(), (0.9, 1.1));
        chart.log_y = true;
        assert_eq!(axis_range(&chart, path, Axis::Y).unwrap(), (1.5, 6.0));
        chart.series = vec![series(vec![(1.0, 0.0)])];
        let err = axis_range(&chart, path, Axis::Y).unwrap_err().to_string();
        assert!(err.contains("logarithmic"), "{err}");
    }

    /// Goal: the legend goes to the corner with the fewest points, and segments are clipped
    /// to the axes. Reference: a line rising from the lower left to the upper right leaves the
    /// upper-left corner empty; a segment crossing x = 1 is cut at its midpoint.
    #[test]
    fn legend_avoids_the_curve_and_segments_are_clipped() {
        let rising = Series {
            label: "rising".into(),
            points: (0..=100).map(|i| (i as f64, i as f64)).collect(),
            style: SeriesStyle::Line,
        };
        let mut other = rising.clone();
        other.label = "other".into();
        let chart = Chart {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            series: vec![rising, other],
            log_x: false,
            log_y: false,
            x_limits: Limits::default(),
            y_limits: Limits::default(),
            notes: Vec::new(),
        };
        let bounds = Bounds {
            x: (0.0, 100.0),
            y: (0.0, 100.0),
        };
        assert!(matches!(
            legend_corner(&chart, &bounds),
            SeriesLabelPosition::UpperLeft | SeriesLabelPosition::LowerRight
        ));
        let unit = Bounds {
            x: (0.0, 1.0),
            y: (0.0, 1.0),
        };
        assert_eq!(
            clip_segment((0.5, 0.5), (1.5, 0.5), &unit),
            Some(((0.5, 0.5), (1.0, 0.5)))
        );
        assert_eq!(clip_segment((2.0, 0.5), (3.0, 0.5), &unit), None);
        assert_eq!(
            clip_segment((0.5, -1.0), (0.5, 2.0), &unit),
            Some(((0.5, 0.0), (0.5, 1.0)))
        );
    }
}
