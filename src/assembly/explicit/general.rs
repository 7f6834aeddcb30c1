//! The general element loop behind the explicit kernels' interface: what central difference
//! runs where neither Quad4 kernel does (rods, small strain, Quad4 with 2x2 quadrature at
//! small strain). Each step is the implicit path's evaluation (`assembly::evaluate`, no
//! tangent) and commit on the kernel's own copy of the state; the stable step is the
//! closed-form element bound of the committed configuration (`assembly::bound_stable_step`).

use super::{ExplicitKernel, StepWork};
use crate::assembly::mass_scaling::ElementScaling;
use crate::assembly::{
    self, ElementFailure, ElementMasses, StableStep, State, StepIncrement, evaluate_elements,
    largest_frequency_bound,
};
use crate::element::Strain;
use crate::scene::Model;
use crate::scene::spec::Tangent;

/// The general element loop of a model.
pub struct General<'a> {
    model: &'a Model,
    /// The committed state of the elements (the driver's `State` takes its points from it,
    /// `write_points`).
    state: State,
    masses: ElementMasses,
    geometry: Strain,
    tangent: Tangent,
    /// The first element of each body in the kernel's numbering.
    offsets: Vec<usize>,
}

impl<'a> General<'a> {
    pub fn new(
        model: &'a Model,
        state: &State,
        masses: &ElementMasses,
        geometry: Strain,
        tangent: Tangent,
    ) -> General<'a> {
        let offsets = model
            .bodies
            .iter()
            .scan(0, |first, body| {
                let this = *first;
                *first += body.elements();
                Some(this)
            })
            .collect();
        General {
            model,
            state: state.clone(),
            masses: masses.clone(),
            geometry,
            tangent,
            offsets,
        }
    }
}

impl ExplicitKernel for General<'_> {
    fn elements(&self) -> usize {
        self.model.elements()
    }

    fn locate(&self, element: usize) -> (usize, usize) {
        let body = self.offsets.partition_point(|first| *first <= element) - 1;
        (body, element - self.offsets[body])
    }

    fn internal_force(&mut self, _x: &[[f64; 2]], force: &mut [f64]) -> Result<(), ElementFailure> {
        let zero = vec![0.0; self.model.dofs()];
        // a zero increment: no step, no rate
        let evaluation = evaluate_elements(
            self.model,
            &self.state,
            StepIncrement {
                d: &zero,
                dt: f64::INFINITY,
                geometry: self.geometry,
            },
            None,
            self.tangent,
        )?;
        force.copy_from_slice(&evaluation.force);
        Ok(())
    }

    fn step(
        &mut self,
        _x: &[[f64; 2]],
        du: &[f64],
        dt: f64,
        force: &mut [f64],
    ) -> Result<StepWork, ElementFailure> {
        let evaluation = evaluate_elements(
            self.model,
            &self.state,
            StepIncrement {
                d: du,
                dt,
                geometry: self.geometry,
            },
            None,
            self.tangent,
        )?;
        force.copy_from_slice(&evaluation.force);
        let (internal, plastic) = (evaluation.work, evaluation.plastic_work);
        let bodies = evaluation.body_work.iter().copied().enumerate().collect();
        assembly::commit(self.model, &mut self.state, du, evaluation, self.geometry);
        let (omega_squared, body, element) =
            largest_frequency_bound(self.model, &self.state, &self.masses)?;
        Ok(StepWork {
            internal,
            plastic,
            omega_squared,
            critical_element: self.offsets[body] + element,
            bodies,
            ..StepWork::default()
        })
    }

    fn stable_step(&self, _x: &[[f64; 2]]) -> Result<StableStep, ElementFailure> {
        assembly::bound_stable_step(self.model, &self.state, &self.masses)
    }

    fn write_points(&self, _model: &Model, state: &mut State) {
        for (to, from) in state.bodies.iter_mut().zip(&self.state.bodies) {
            to.points.clone_from(&from.points);
            to.thickness.clone_from(&from.thickness);
        }
    }

    fn viscous_pressure(&self) -> &[f64] {
        &[]
    }

    fn restore_viscous_pressure(&mut self, _values: &[f64]) {}

    fn eq_plastic_strain(&self) -> Vec<f64> {
        self.state
            .bodies
            .iter()
            .flat_map(|b| b.points.iter().map(|p| p.eq_plastic_strain))
            .collect()
    }

    fn mass_scaling(&self) -> Option<&ElementScaling> {
        None
    }

    fn mass_scaling_mut(&mut self) -> Option<&mut ElementScaling> {
        None
    }
}
