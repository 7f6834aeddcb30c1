//! The arrays of a frame that are recovered from the integration points: per cell the mean
//! over its points, per grid point the mean of the cells around it (smooth contours in
//! ParaView of what the cells carry; `Grid::cell_to_point_mean`), and the points' bodies.

use crate::assembly::State;
use crate::material::{pressure, von_mises};
use crate::output::vtk::{Grid, PointValues};
use crate::scene::Model;
use rayon::prelude::*;

pub(super) struct CellFields {
    pub stress: Vec<[f64; 6]>,
    pub von_mises: Vec<f64>,
    pub eq_plastic_strain: Vec<f64>,
    pub pressure: Vec<f64>,
    /// When some material carries a temperature (0 in the cells of the bodies whose
    /// material carries none: their points keep 0).
    pub temperature: Option<Vec<f64>>,
}

/// Per cell, the mean over its points; quads first, then rods (as in `grid`). Parallel over
/// the cells, each written in its own slot.
pub(super) fn cell_fields(model: &Model, state: &State) -> CellFields {
    let quads_first = model
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| b.points_per_element() == 4)
        .chain(
            model
                .bodies
                .iter()
                .enumerate()
                .filter(|(_, b)| b.points_per_element() == 1),
        );
    let cells: usize = model.bodies.iter().map(|b| b.elements()).sum();
    let mut out = CellFields {
        stress: vec![[0.0; 6]; cells],
        von_mises: vec![0.0; cells],
        eq_plastic_strain: vec![0.0; cells],
        pressure: vec![0.0; cells],
        temperature: model.carries_temperature().then(|| vec![0.0; cells]),
    };
    let mut first = 0;
    for (b, body) in quads_first {
        let ppe = body.points_per_element();
        let last = first + body.elements();
        if let Some(temperature) = out.temperature.as_mut() {
            temperature[first..last]
                .par_iter_mut()
                .zip(state.bodies[b].points.par_chunks_exact(ppe))
                .for_each(|(t, points)| {
                    *t = points.iter().map(|p| p.temperature).sum::<f64>() / ppe as f64;
                });
        }
        (
            &mut out.stress[first..last],
            &mut out.von_mises[first..last],
            &mut out.eq_plastic_strain[first..last],
            &mut out.pressure[first..last],
        )
            .into_par_iter()
            .zip(state.bodies[b].points.par_chunks_exact(ppe))
            .for_each(|((stress, mises, eps_p, p), points)| {
                let mean = |f: &dyn Fn(&crate::material::PointState) -> f64| {
                    points.iter().map(f).sum::<f64>() / ppe as f64
                };
                let s: [f64; 4] = std::array::from_fn(|k| mean(&|p| p.stress[k]));
                *stress = [s[0], s[1], s[2], s[3], 0.0, 0.0];
                *mises = mean(&|p| von_mises(&p.stress));
                *eps_p = mean(&|p| p.eq_plastic_strain);
                *p = mean(&|p| pressure(&p.stress));
            });
        first = last;
    }
    out
}

/// The cell values averaged to the grid's points.
pub(super) struct PointArrays {
    stress: Vec<[f64; 6]>,
    von_mises: Vec<f64>,
    eq_plastic_strain: Vec<f64>,
    pressure: Vec<f64>,
    temperature: Option<Vec<f64>>,
}

impl PointArrays {
    pub(super) fn of(grid: &Grid, cells: &CellFields) -> PointArrays {
        let scalar = |values: &[f64]| -> Vec<f64> {
            let rows: Vec<[f64; 1]> = values.iter().map(|v| [*v]).collect();
            grid.cell_to_point_mean(&rows)
                .into_iter()
                .map(|[v]| v)
                .collect()
        };
        PointArrays {
            stress: grid.cell_to_point_mean(&cells.stress),
            von_mises: scalar(&cells.von_mises),
            eq_plastic_strain: scalar(&cells.eq_plastic_strain),
            pressure: scalar(&cells.pressure),
            temperature: cells.temperature.as_deref().map(scalar),
        }
    }

    /// The frame's point values, with the points' bodies `body`.
    pub(super) fn values<'a>(&'a self, body: &'a [i64]) -> PointValues<'a> {
        PointValues {
            stress: &self.stress,
            von_mises: &self.von_mises,
            eq_plastic_strain: &self.eq_plastic_strain,
            pressure: &self.pressure,
            temperature: self.temperature.as_deref(),
            body,
        }
    }
}

/// Per point of the grid (global node order), the index of its body in the scene.
pub(crate) fn point_body_ids(model: &Model) -> Vec<i64> {
    model
        .bodies
        .iter()
        .enumerate()
        .flat_map(|(i, b)| std::iter::repeat_n(i as i64, b.mesh.nodes.len()))
        .collect()
}
