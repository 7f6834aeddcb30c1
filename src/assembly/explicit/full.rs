//! The explicit 2x2 Quad4 in rate form: at each Gauss point of the mid-step configuration the
//! strain increment and spin of the step (Hughes-Winget), the stress rotated by it, the
//! material's update; the nodal forces on the end configuration; mean-dilatation (B-bar)
//! volumetric strain by option. The same element as the implicit 2x2 kernel at small steps
//! (where the Green-Lagrange increment and the push-forward reduce to the rate form), without
//! its tangent: the fast path of `quadrature = "full"` on finite-strain Quad4 models, a rule
//! of the explicit loop (`skeleton`).
//!
//! Legend (element; q = 1..4 the Gauss points, a = 1..4 the nodes)
//! ```text
//! N_a,q, N_a,x, N_a,y   shape values and gradients at q on the mid configuration x + u/2
//! G_q                   sum_a u_a (x) grad N_a: the increment gradient at q
//! d_q, w_q              sym G_q ([xx yy zz xy], zz the hoop u_r / r in axisymmetry), and
//!                       w = (G_xy - G_yx) / 2
//! B-bar                 d_q,ii += (tr_mean - tr d_q) / 3, tr_mean the volume mean of tr d_q
//! sigma_q               material(R_q sigma_q,n R_q^T, d_q)
//! f_a                   sum_q W_q (B_q^T sigma_q) on the end configuration (B-bar likewise)
//! W_int                 sum_q W_q,mid 1/2 (R sigma_n R^T + sigma_{n+1}) . d_q
//! q_q                   the bulk viscosity's pressure at q from tr d_q / dt (by option;
//!                       element::bulk_viscosity), the element's rho, c_d, L_e on the mid
//!                       configuration; f_a then sums B_q^T (sigma_q - q_q I)
//! W_visc                -sum_q W_q,mid 1/2 (q_q,n + q_q,n+1) tr d_q
//! s                     the element's mass factor of the mass scaling (by option; 1
//!                       without it): its lumped masses are s m_a in the frequency bound and
//!                       the viscous density, and an element whose bound is below the target
//!                       gets a larger s (mass_scaling.rs)
//! ```

use super::BodyParameters;
use super::point_step;
use super::skeleton::{Columns, ElementStep, Rule, Skeleton};
use crate::assembly::{ElementMasses, State};
use crate::element::bulk_viscosity::{
    BulkViscosity, ElementScale, damped_frequency_squared, damping_factor, loaded_stress,
    volumetric_increment,
};
use crate::element::quad4::{self, QuadValues};
use crate::element::quad4_one_point::{Nodes, rotate};
use crate::element::{Formulation, KernelError, Voigt};
use crate::material::{PointState, dissipation};
use crate::scene::Model;
use std::ops::Deref;

/// The committed state of the four points of one element.
#[derive(Debug, Clone, Copy)]
pub struct PointsState {
    stress: [[f64; 4]; 4],
    back_stress: [[f64; 4]; 4],
    eq_plastic_strain: [f64; 4],
    /// Temperature (0 for materials that carry none).
    temperature: [f64; 4],
    thickness: [f64; 4],
    /// The bulk viscosity's pressure of the step that ended here (0 without it).
    viscous_pressure: [f64; 4],
}

/// The 2x2 rule of the explicit loop (`Skeleton`): four Gauss points, B-bar by option.
pub struct TwoByTwo;

/// The 2x2 explicit kernel over a model's Quad4 bodies.
pub type Full = Skeleton<TwoByTwo>;

impl Full {
    /// The 2x2 kernel for the Quad4 bodies of `model` from the committed `state`.
    pub fn new(model: &Model, state: &State, masses: &ElementMasses) -> Full {
        Skeleton::build(model, state, masses, 0.0)
    }
}

/// The increment gradient, strain and spin at one point.
fn point_increment(p: &quad4::PointValues, u: &Nodes, axisymmetric: bool) -> ([f64; 4], f64) {
    let (mut gxx, mut gxy, mut gyx, mut gyy) = (0.0, 0.0, 0.0, 0.0);
    for a in 0..4 {
        let [nx, ny] = p.dndx[a];
        gxx += u[a][0] * nx;
        gxy += u[a][0] * ny;
        gyx += u[a][1] * nx;
        gyy += u[a][1] * ny;
    }
    let hoop = if axisymmetric {
        (0..4).map(|a| p.shape[a] * u[a][0]).sum::<f64>() / p.radius
    } else {
        0.0
    };
    ([gxx, gyy, hoop, gxy + gyx], 0.5 * (gxy - gyx))
}

/// The nodal forces sum_q W_q B_q^T sigma_q on the configuration of `values` (B-bar: the
/// volumetric rows averaged over the element).
fn forces(values: &QuadValues, stress: &[[f64; 4]; 4], bbar: bool) -> [f64; 8] {
    let axisymmetric = values.formulation == Formulation::Axisymmetric;
    let mut f = [0.0; 8];
    let mut mean_b = [[0.0; 2]; 4];
    let mut volume = 0.0;
    let mut pressure_weight = 0.0;
    for (p, s) in values.points.iter().zip(stress) {
        let w = p.weight;
        let mean = (s[0] + s[1] + s[2]) / 3.0;
        for a in 0..4 {
            let [nx, ny] = p.dndx[a];
            let hoop = if axisymmetric {
                p.shape[a] / p.radius
            } else {
                0.0
            };
            f[2 * a] += w * (s[0] * nx + s[3] * ny + s[2] * hoop);
            f[2 * a + 1] += w * (s[3] * nx + s[1] * ny);
            if bbar {
                // minus the point's own volumetric row times its mean stress
                f[2 * a] -= w * mean * (nx + hoop);
                f[2 * a + 1] -= w * mean * ny;
                mean_b[a][0] += w * (nx + hoop);
                mean_b[a][1] += w * ny;
            }
        }
        volume += w;
        pressure_weight += w * mean;
    }
    if bbar {
        for a in 0..4 {
            f[2 * a] += mean_b[a][0] / volume * pressure_weight;
            f[2 * a + 1] += mean_b[a][1] / volume * pressure_weight;
        }
    }
    f
}

/// One element over one step of length dt: positions x at the start, increment u (`(x, u)`),
/// with the bulk viscosity `viscosity` when on (see the legend).
fn element_step(
    p: &BodyParameters,
    (x, u): (&Nodes, &Nodes),
    committed: &PointsState,
    lumped: [f64; 4],
    (dt, viscosity): (f64, Option<&BulkViscosity>),
) -> Result<ElementStep<PointsState>, KernelError> {
    let axisymmetric = p.axisymmetric();
    let mid: Nodes = std::array::from_fn(|a| [x[a][0] + 0.5 * u[a][0], x[a][1] + 0.5 * u[a][1]]);
    let end: Nodes = std::array::from_fn(|a| [x[a][0] + u[a][0], x[a][1] + u[a][1]]);
    let at_mid = quad4::values(&mid, p.formulation, &committed.thickness)?;
    let mut strain = [[0.0; 4]; 4];
    let mut spin = [0.0; 4];
    for q in 0..4 {
        (strain[q], spin[q]) = point_increment(&at_mid.points[q], u, axisymmetric);
    }
    if p.bbar {
        let volume = at_mid.volume();
        let trace = |d: &[f64; 4]| d[0] + d[1] + d[2];
        let mean: f64 = (0..4)
            .map(|q| at_mid.points[q].weight * trace(&strain[q]))
            .sum::<f64>()
            / volume;
        for d in &mut strain {
            let shift = (mean - trace(d)) / 3.0;
            for c in 0..3 {
                d[c] += shift;
            }
        }
    }
    // the volumetric increments the viscous pressures follow (before plane stress writes the
    // thickness strain into the increments)
    let viscous = viscosity.map(|viscosity| {
        let scale = ElementScale::new(&mid, lumped.iter().sum(), at_mid.volume(), p.wave_modulus);
        let volumetric: [f64; 4] =
            std::array::from_fn(|q| volumetric_increment(&strain[q], p.formulation));
        (viscosity, scale, volumetric)
    });
    let mut state = *committed;
    let (mut work, mut plastic_work) = (0.0, 0.0);
    for q in 0..4 {
        let w = spin[q];
        let scale = 1.0 / (1.0 + 0.25 * w * w);
        let (c, s) = ((1.0 - 0.25 * w * w) * scale, w * scale);
        let start = PointState {
            stress: Voigt::from(rotate(&committed.stress[q], c, s)),
            eq_plastic_strain: committed.eq_plastic_strain[q],
            back_stress: Voigt::from(rotate(&committed.back_stress[q], c, s)),
            temperature: committed.temperature[q],
        };
        let step = point_step(p, &start, &mut strain[q], dt);
        if p.plane_stress() {
            state.thickness[q] = committed.thickness[q] * step.strain_zz.exp();
        }
        let end = &step.state;
        let weight = at_mid.points[q].weight;
        work += weight
            * 0.5
            * (0..4)
                .map(|k| (start.stress[k] + end.stress[k]) * strain[q][k])
                .sum::<f64>();
        // 1/2 (S_n + S_{n+1}) : d eps_p, the rule of the work above (trapezoid_dissipation)
        plastic_work += weight
            * dissipation(
                &start.stress,
                &end.stress,
                &end.back_stress,
                step.plastic_work,
            )
            .map_err(|work| KernelError::NegativePlasticWork { point: q, work })?;
        state.stress[q] = end.stress.into();
        state.back_stress[q] = end.back_stress.into();
        state.eq_plastic_strain[q] = end.eq_plastic_strain;
        state.temperature[q] = end.temperature;
    }
    let at_end = quad4::values(&end, p.formulation, &state.thickness)?;
    let omega_squared = quad4::frequency_bound(&at_end, p.wave_lambda, p.mu, &lumped);
    let Some((viscosity, scale, volumetric)) = viscous else {
        return Ok(ElementStep {
            force: forces(&at_end, &state.stress, p.bbar),
            omega_squared,
            state,
            work,
            plastic_work,
            hourglass_work: 0.0,
            viscous_work: 0.0,
            damping: 1.0,
        });
    };
    let mut loaded = state.stress;
    let (mut viscous_work, mut damping_fraction) = (0.0, 0.0);
    for q in 0..4 {
        let weight = at_mid.points[q].weight;
        let v = viscosity.step(
            &scale,
            volumetric[q],
            dt,
            weight,
            committed.viscous_pressure[q],
        );
        viscous_work += v.work;
        // the most compressed point sets the element's damping
        damping_fraction = f64::max(damping_fraction, v.damping_fraction);
        state.viscous_pressure[q] = v.pressure;
        loaded[q] = loaded_stress(&state.stress[q], v.pressure, p.formulation);
    }
    Ok(ElementStep {
        force: forces(&at_end, &loaded, p.bbar),
        omega_squared: damped_frequency_squared(omega_squared, damping_fraction),
        state,
        work,
        plastic_work,
        hourglass_work: 0.0,
        viscous_work,
        damping: damping_factor(damping_fraction),
    })
}

impl Rule for TwoByTwo {
    const POINTS: usize = 4;
    const HOURGLASS: usize = 0;
    type State = PointsState;
    type Mass = [f64; 4];

    fn mass(lumped: &[f64; 4]) -> [f64; 4] {
        *lumped
    }

    #[inline(always)]
    fn scaled(lumped: [f64; 4], factor: f64) -> [f64; 4] {
        lumped.map(|m| m * factor)
    }

    #[inline(always)]
    fn read<S: Deref<Target = [f64]>>(c: &Columns<S>, i: usize) -> PointsState {
        PointsState {
            stress: std::array::from_fn(|q| std::array::from_fn(|k| c.stress[16 * i + 4 * q + k])),
            back_stress: std::array::from_fn(|q| {
                std::array::from_fn(|k| c.back[16 * i + 4 * q + k])
            }),
            eq_plastic_strain: std::array::from_fn(|q| c.eps_p[4 * i + q]),
            temperature: std::array::from_fn(|q| c.temperature[4 * i + q]),
            thickness: std::array::from_fn(|q| c.thickness[4 * i + q]),
            viscous_pressure: std::array::from_fn(|q| c.viscous[4 * i + q]),
        }
    }

    #[inline(always)]
    fn write(c: &mut Columns<&mut [f64]>, i: usize, s: &PointsState) {
        for q in 0..4 {
            c.stress[16 * i + 4 * q..16 * i + 4 * q + 4].copy_from_slice(&s.stress[q]);
            c.back[16 * i + 4 * q..16 * i + 4 * q + 4].copy_from_slice(&s.back_stress[q]);
        }
        c.eps_p[4 * i..4 * i + 4].copy_from_slice(&s.eq_plastic_strain);
        c.temperature[4 * i..4 * i + 4].copy_from_slice(&s.temperature);
        c.thickness[4 * i..4 * i + 4].copy_from_slice(&s.thickness);
        c.viscous[4 * i..4 * i + 4].copy_from_slice(&s.viscous_pressure);
    }

    fn fresh(state: &PointsState) -> PointsState {
        PointsState {
            stress: [[0.0; 4]; 4],
            back_stress: [[0.0; 4]; 4],
            eq_plastic_strain: [0.0; 4],
            viscous_pressure: [0.0; 4],
            ..*state
        }
    }

    #[inline(always)]
    fn step(
        p: &BodyParameters,
        motion: (&Nodes, &Nodes),
        committed: &PointsState,
        lumped: [f64; 4],
        step: (f64, Option<&BulkViscosity>),
    ) -> Result<ElementStep<PointsState>, KernelError> {
        element_step(p, motion, committed, lumped, step)
    }

    fn bound(
        p: &BodyParameters,
        x: &Nodes,
        state: &PointsState,
        lumped: [f64; 4],
    ) -> Result<f64, KernelError> {
        let values = quad4::values(x, p.formulation, &state.thickness)?;
        Ok(quad4::frequency_bound(
            &values,
            p.wave_lambda,
            p.mu,
            &lumped,
        ))
    }

    fn force(
        p: &BodyParameters,
        x: &Nodes,
        state: &PointsState,
        viscous: bool,
    ) -> Result<[f64; 8], KernelError> {
        let values = quad4::values(x, p.formulation, &state.thickness)?;
        let loaded = match viscous {
            true => std::array::from_fn(|q| {
                loaded_stress(&state.stress[q], state.viscous_pressure[q], p.formulation)
            }),
            false => state.stress,
        };
        Ok(forces(&values, &loaded, p.bbar))
    }
}
