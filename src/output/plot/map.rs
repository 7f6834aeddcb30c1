//! Stability maps: a grid of cells (method by step ratio, say) coloured by what a run did.

use super::{Format, SIZE, encode_png, register_embedded_font};
use crate::output::{OutputError, write_atomic};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// What a cell of a [`Map`] shows; the kind sets its colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellKind {
    /// Green.
    Stable,
    /// Light blue (bounded but dissipative).
    Damped,
    /// Amber.
    Drift,
    /// Red.
    Unstable,
    /// Grey (refused, missing).
    Other,
}

/// One cell of a [`Map`]: a short text and its kind.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    pub text: String,
    pub kind: CellKind,
}

/// A table of coloured cells (a stability map): named rows and columns, a cell per pair or
/// none.
#[derive(Debug, Clone)]
pub struct Map {
    pub title: String,
    pub x_label: String,
    pub columns: Vec<String>,
    pub rows: Vec<String>,
    /// cells[row][column]
    pub cells: Vec<Vec<Option<Cell>>>,
}

/// Writes `map` to `path` (PNG or SVG by the extension, 800 x 500) like [`write`].
pub fn write_map(map: &Map, path: &Path) -> Result<(), OutputError> {
    let format = Format::of(path)?;
    if map.rows.is_empty() || map.columns.is_empty() {
        return Err(OutputError::invalid(
            path,
            "the map has no rows or no columns",
        ));
    }
    register_embedded_font();
    let drawing_error = |e: String| OutputError::invalid(path, format!("cannot draw the map: {e}"));
    match format {
        Format::Svg => {
            let mut text = String::new();
            draw_map(
                SVGBackend::with_string(&mut text, SIZE).into_drawing_area(),
                map,
            )
            .map_err(drawing_error)?;
            write_atomic(path, text.as_bytes())
        }
        Format::Png => {
            let (width, height) = SIZE;
            let mut pixels = vec![0u8; 3 * width as usize * height as usize];
            draw_map(
                BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area(),
                map,
            )
            .map_err(drawing_error)?;
            let bytes = encode_png(&pixels, SIZE)
                .map_err(|e| OutputError::invalid(path, format!("cannot encode the PNG: {e}")))?;
            write_atomic(path, &bytes)
        }
    }
}

/// The map in pixels: row labels on the left, column labels and the axis label below.
fn draw_map<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, map: &Map) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let root = root
        .titled(&map.title, (FontFamily::SansSerif, 20))
        .map_err(e)?;
    let (width, height) = root.dim_in_pixel();
    let (left, right, top, bottom) = (190i32, 16i32, 8i32, 64i32);
    let columns = map.columns.len() as i32;
    let rows = map.rows.len() as i32;
    let cell_w = (width as i32 - left - right) / columns;
    let cell_h = ((height as i32 - top - bottom) / rows).min(60);
    let centered = |size: u32| {
        TextStyle::from((FontFamily::SansSerif, size)).pos(Pos::new(HPos::Center, VPos::Center))
    };
    for (i, label) in map.rows.iter().enumerate() {
        let y = top + i as i32 * cell_h + cell_h / 2;
        let style =
            TextStyle::from((FontFamily::SansSerif, 14)).pos(Pos::new(HPos::Right, VPos::Center));
        root.draw(&Text::new(label.clone(), (left - 8, y), style))
            .map_err(e)?;
        for j in 0..map.columns.len() {
            let (x0, y0) = (left + j as i32 * cell_w, top + i as i32 * cell_h);
            let corners = [(x0 + 1, y0 + 1), (x0 + cell_w - 1, y0 + cell_h - 1)];
            match map
                .cells
                .get(i)
                .and_then(|r| r.get(j))
                .and_then(Option::as_ref)
            {
                Some(cell) => {
                    let color = match cell.kind {
                        CellKind::Stable => RGBColor(150, 210, 150),
                        CellKind::Damped => RGBColor(160, 200, 235),
                        CellKind::Drift => RGBColor(250, 200, 110),
                        CellKind::Unstable => RGBColor(235, 120, 110),
                        CellKind::Other => RGBColor(200, 200, 200),
                    };
                    root.draw(&Rectangle::new(corners, color.filled()))
                        .map_err(e)?;
                    root.draw(&Text::new(
                        cell.text.clone(),
                        (x0 + cell_w / 2, y0 + cell_h / 2),
                        centered(13),
                    ))
                    .map_err(e)?;
                }
                None => root
                    .draw(&Rectangle::new(corners, BLACK.mix(0.15)))
                    .map_err(e)?,
            }
        }
    }
    let below = top + rows * cell_h;
    for (j, label) in map.columns.iter().enumerate() {
        let x = left + j as i32 * cell_w + cell_w / 2;
        root.draw(&Text::new(label.clone(), (x, below + 14), centered(14)))
            .map_err(e)?;
    }
    let middle = left + columns * cell_w / 2;
    root.draw(&Text::new(
        map.x_label.clone(),
        (middle, below + 40),
        centered(16),
    ))
    .map_err(e)?;
    root.present().map_err(e)
}
