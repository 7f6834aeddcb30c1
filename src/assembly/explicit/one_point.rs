//! The explicit fast path: the one-point Quad4 of `element::quad4_one_point` as a rule of the
//! explicit loop (`skeleton`: structure of arrays, chunks in parallel; docs/theory.md,
//! "Reduced explicit Quad4"). The element's kinematics, hourglass control and forces are the
//! kernel's; here the material updates the rotated stress between them.
//!
//! Legend (one element; see `element::quad4_one_point` for the kinematics)
//! ```text
//! sigma      sigma_{n+1} = material(R sigma_n R^T, d)   (back stress rotated alike)
//! W_int      t A_mid 1/2 (R sigma_n R^T + sigma_{n+1}) . d;  W_hg = 1/2 (R Q_n + Q_{n+1}) . q
//! q          the bulk viscosity's pressure from tr d / dt (by option; element::bulk_viscosity),
//!            rho, c_d, L_e on the mid configuration; the forces see sigma - q I
//! W_visc     -t A_mid 1/2 (q_n + q_{n+1}) tr d
//! s          the element's mass factor of the mass scaling (by option; 1 without it): its
//!            lumped masses are s m_a in the frequency bound and the viscous density, and
//!            an element whose bound is below the target gets a larger s (mass_scaling.rs)
//! ```

use super::skeleton::{Columns, ElementStep, Rule, Skeleton};
use super::{BodyParameters, point_step};
use crate::assembly::{ElementMasses, State};
use crate::element::bulk_viscosity::{
    BulkViscosity, ElementScale, damped_frequency_squared, damping_factor, loaded_stress,
    volumetric_increment,
};
use crate::element::quad4_one_point::{self as one_point, BoundShape, Nodes, Section, rotate};
use crate::element::{KernelError, Voigt};
use crate::material::{PointState, dissipation};
use crate::scene::Model;
use std::ops::Deref;

/// The committed state of one element as the kernel reads it.
#[derive(Debug, Clone, Copy)]
pub struct ElementState {
    /// Cauchy stress [xx yy zz xy].
    pub stress: [f64; 4],
    pub back_stress: [f64; 4],
    pub eq_plastic_strain: f64,
    /// Temperature (0 for materials that carry none).
    pub temperature: f64,
    /// Current thickness (plane stress), else 1.
    pub thickness: f64,
    /// Hourglass forces Q [x y].
    pub hourglass: [f64; 2],
    /// The bulk viscosity's pressure of the step that ended here (0 without it).
    pub viscous_pressure: f64,
}

/// What the one-point kernel knows of an element's mass: the smallest of its lumped nodal
/// masses (the stable-step bound) and their sum (its density, for the bulk viscosity).
#[derive(Debug, Clone, Copy)]
pub struct ElementMass {
    smallest: f64,
    total: f64,
}

impl ElementMass {
    /// The element's masses times the factor `factor`.
    #[inline(always)]
    fn scaled(self, factor: f64) -> ElementMass {
        ElementMass {
            smallest: self.smallest * factor,
            total: self.total * factor,
        }
    }
}

/// One element over one step of length dt: positions x at the start, increment u (`(x, u)`),
/// with the bulk viscosity `viscosity` when on (see the legend).
#[inline(always)]
fn element_step(
    p: &BodyParameters,
    (x, u): (&Nodes, &Nodes),
    committed: &ElementState,
    mass: ElementMass,
    (dt, viscosity): (f64, Option<&BulkViscosity>),
) -> Result<ElementStep<ElementState>, KernelError> {
    let t = committed.thickness;
    let section = section(p, t);
    let step = one_point::increment(x, u, section)?;
    let (c, s) = (step.cos, step.sin);
    let start = PointState {
        stress: Voigt::from(rotate(&committed.stress, c, s)),
        eq_plastic_strain: committed.eq_plastic_strain,
        back_stress: Voigt::from(rotate(&committed.back_stress, c, s)),
        temperature: committed.temperature,
    };
    let mut strain = step.strain;
    // the volumetric increment the viscous pressure follows (before plane stress writes the
    // thickness strain into it)
    let volumetric = volumetric_increment(&strain, p.formulation);
    let point = point_step(p, &start, &mut strain, dt);
    let thickness = if p.plane_stress() {
        t * point.strain_zz.exp()
    } else {
        t
    };
    let after = &point.state;
    let volume = step.gradient.area * section.weight(&step.mid);
    let work = volume
        * 0.5
        * (0..4)
            .map(|k| (start.stress[k] + after.stress[k]) * strain[k])
            .sum::<f64>();
    let hourglass = one_point::hourglass(
        &step,
        u,
        &committed.hourglass,
        p.hourglass_modulus,
        section.weight(&step.mid),
    );
    let viscous = viscosity.map(|viscosity| {
        let scale = ElementScale::new(&step.mid, mass.total, volume, p.wave_modulus);
        viscosity.step(&scale, volumetric, dt, volume, committed.viscous_pressure)
    });
    let state = ElementState {
        stress: after.stress.into(),
        back_stress: after.back_stress.into(),
        eq_plastic_strain: after.eq_plastic_strain,
        temperature: after.temperature,
        thickness,
        hourglass: hourglass.forces,
        viscous_pressure: viscous.map_or(committed.viscous_pressure, |v| v.pressure),
    };
    let section = match section {
        Section::Plane { .. } => Section::Plane {
            thickness: state.thickness,
        },
        axisymmetric => axisymmetric,
    };
    let end = match viscous {
        Some(v) => {
            let loaded = loaded_stress(&state.stress, v.pressure, p.formulation);
            one_point::force(&step.end, &loaded, section, &state.hourglass)?
        }
        None => one_point::force(&step.end, &state.stress, section, &state.hourglass)?,
    };
    let shape = BoundShape {
        gradient: &end.gradient,
        gamma: &end.gamma,
        volume: end.gradient.area * section.weight(&step.end),
        hoop_radius: p
            .axisymmetric()
            .then(|| one_point::centroid_radius(&step.end)),
    };
    let omega_squared =
        one_point::frequency_bound(shape, p.wave_modulus, p.hourglass_modulus, mass.smallest);
    let (omega_squared, viscous_work, damping) = match viscous {
        Some(v) => (
            damped_frequency_squared(omega_squared, v.damping_fraction),
            v.work,
            damping_factor(v.damping_fraction),
        ),
        None => (omega_squared, 0.0, 1.0),
    };
    // 1/2 (S_n + S_{n+1}) : d eps_p, the rule of the work above (trapezoid_dissipation)
    let plastic_work = volume
        * dissipation(
            &start.stress,
            &after.stress,
            &after.back_stress,
            point.plastic_work,
        )
        .map_err(|work| KernelError::NegativePlasticWork { point: 0, work })?;
    Ok(ElementStep {
        state,
        force: end.force,
        work,
        plastic_work,
        hourglass_work: hourglass.work,
        viscous_work,
        omega_squared,
        damping,
    })
}

/// The section of an element of body `p` of thickness `thickness` (plane stress, else 1).
#[inline(always)]
fn section(p: &BodyParameters, thickness: f64) -> Section {
    if p.axisymmetric() {
        Section::Axisymmetric
    } else {
        Section::Plane { thickness }
    }
}

/// The one-point rule of the explicit loop (`Skeleton`): the centroid's strain and stress,
/// hourglass forces for the modes the point does not see.
pub struct OnePoint;

/// The one-point explicit kernel over a model's Quad4 bodies.
pub type Reduced = Skeleton<OnePoint>;

impl Reduced {
    /// The one-point kernel for the Quad4 bodies of `model` (the scene refuses rods with
    /// it), starting from the committed `state`; `kappa` is the hourglass coefficient.
    pub fn new(model: &Model, state: &State, kappa: f64, masses: &ElementMasses) -> Reduced {
        Skeleton::build(model, state, masses, kappa)
    }
}

impl Rule for OnePoint {
    const POINTS: usize = 1;
    const HOURGLASS: usize = 2;
    type State = ElementState;
    type Mass = ElementMass;

    fn mass(lumped: &[f64; 4]) -> ElementMass {
        ElementMass {
            smallest: lumped.iter().copied().fold(f64::INFINITY, f64::min),
            total: lumped.iter().sum(),
        }
    }

    #[inline(always)]
    fn scaled(mass: ElementMass, factor: f64) -> ElementMass {
        mass.scaled(factor)
    }

    #[inline(always)]
    fn read<S: Deref<Target = [f64]>>(c: &Columns<S>, i: usize) -> ElementState {
        ElementState {
            stress: std::array::from_fn(|k| c.stress[4 * i + k]),
            back_stress: std::array::from_fn(|k| c.back[4 * i + k]),
            eq_plastic_strain: c.eps_p[i],
            temperature: c.temperature[i],
            thickness: c.thickness[i],
            hourglass: [c.hourglass[2 * i], c.hourglass[2 * i + 1]],
            viscous_pressure: c.viscous[i],
        }
    }

    #[inline(always)]
    fn write(c: &mut Columns<&mut [f64]>, i: usize, s: &ElementState) {
        c.stress[4 * i..4 * i + 4].copy_from_slice(&s.stress);
        c.back[4 * i..4 * i + 4].copy_from_slice(&s.back_stress);
        c.eps_p[i] = s.eq_plastic_strain;
        c.temperature[i] = s.temperature;
        c.thickness[i] = s.thickness;
        c.hourglass[2 * i..2 * i + 2].copy_from_slice(&s.hourglass);
        c.viscous[i] = s.viscous_pressure;
    }

    fn fresh(state: &ElementState) -> ElementState {
        ElementState {
            stress: [0.0; 4],
            back_stress: [0.0; 4],
            eq_plastic_strain: 0.0,
            hourglass: [0.0; 2],
            viscous_pressure: 0.0,
            ..*state
        }
    }

    #[inline(always)]
    fn step(
        p: &BodyParameters,
        motion: (&Nodes, &Nodes),
        committed: &ElementState,
        mass: ElementMass,
        step: (f64, Option<&BulkViscosity>),
    ) -> Result<ElementStep<ElementState>, KernelError> {
        element_step(p, motion, committed, mass, step)
    }

    fn bound(
        p: &BodyParameters,
        x: &Nodes,
        state: &ElementState,
        mass: ElementMass,
    ) -> Result<f64, KernelError> {
        let section = section(p, state.thickness);
        let end = one_point::force(x, &state.stress, section, &state.hourglass)?;
        let shape = BoundShape {
            gradient: &end.gradient,
            gamma: &end.gamma,
            volume: end.gradient.area * section.weight(x),
            hoop_radius: p.axisymmetric().then(|| one_point::centroid_radius(x)),
        };
        Ok(one_point::frequency_bound(
            shape,
            p.wave_modulus,
            p.hourglass_modulus,
            mass.smallest,
        ))
    }

    fn force(
        p: &BodyParameters,
        x: &Nodes,
        state: &ElementState,
        viscous: bool,
    ) -> Result<[f64; 8], KernelError> {
        let stress = match viscous {
            true => loaded_stress(&state.stress, state.viscous_pressure, p.formulation),
            false => state.stress,
        };
        let section = section(p, state.thickness);
        Ok(one_point::force(x, &stress, section, &state.hourglass)?.force)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::Formulation;
    use crate::material::{Elastic, Material};

    fn parameters() -> BodyParameters {
        let material = Material {
            name: "m".into(),
            density: 1.0,
            elastic: Elastic::new(200.0, 0.3),
            plasticity: None,
        };
        let (lambda, mu) = material.elastic.lame();
        BodyParameters {
            name: "b".into(),
            material,
            formulation: Formulation::PlaneStrain,
            bbar: false,
            mu,
            hourglass_modulus: 0.1 * (lambda + 3.0 * mu) / 24.0,
            wave_modulus: lambda + 2.0 * mu,
            wave_lambda: lambda,
            first_element: 0,
            model_body: 0,
        }
    }

    const SQUARE: Nodes = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.5], [0.0, 1.5]];

    /// A rigid rotation by 0.3 rad in 100 increments leaves a stressed element's stress
    /// invariants unchanged (Hughes-Winget is exactly orthogonal) and its forces in
    /// equilibrium with the rotated stress.
    #[test]
    fn rigid_rotation_keeps_the_invariants() {
        let p = parameters();
        let mut x = SQUARE;
        let mut state = ElementState {
            stress: [1.0, -0.5, 0.2, 0.3],
            back_stress: [0.0; 4],
            eq_plastic_strain: 0.0,
            temperature: 0.0,
            thickness: 1.0,
            hourglass: [0.0; 2],
            viscous_pressure: 0.0,
        };
        let step: f64 = 0.003;
        let (c, s) = (step.cos(), step.sin());
        for _ in 0..100 {
            let u: Nodes = std::array::from_fn(|a| {
                let [px, py] = x[a];
                [c * px - s * py - px, s * px + c * py - py]
            });
            let mass = ElementMass {
                smallest: 1.0,
                total: 4.0,
            };
            state = element_step(&p, (&x, &u), &state, mass, (1.0, None))
                .unwrap()
                .state;
            x = std::array::from_fn(|a| [x[a][0] + u[a][0], x[a][1] + u[a][1]]);
        }
        // round-off: E ~ 200 times strains of ~1e-16 per step
        let [a, b, zz, t] = state.stress;
        assert!((a + b - 0.5).abs() < 1e-11, "trace {}", a + b);
        assert!((a * b - t * t - (-0.5 - 0.09)).abs() < 1e-11);
        assert!((zz - 0.2).abs() < 1e-11, "zz {zz}");
        // and it turned with the body (counter-clockwise by phi = 0.3):
        // sigma_xy = (a0 - b0)/2 sin 2 phi + t0 cos 2 phi
        let expected = 0.5 * (1.0 + 0.5) * 0.6f64.sin() + 0.3 * 0.6f64.cos();
        assert!((t - expected).abs() < 1e-11, "xy {t} vs {expected}");
    }
}
