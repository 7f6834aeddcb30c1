//! impact: finite-strain elastoplastic contact-impact in 2D (plane strain, plane stress,
//! axisymmetric) and 1D rods, after Hughes, Taylor & Sackman (1975), Erklig, Guzelbey &
//! Cevik (2010) and Greco & Coda (2003) (the three source documents; docs/theory.md gives the
//! equations with their numbers).
//!
//! Dependencies flow one way, from the ground up: a module uses only modules of lower
//! layers (tests/architecture.rs checks it on the source).
//! ```text
//! 1  profile, reference, mesh, output,  timing, closed forms, meshes, writers, the ALE
//!    ale, curve                         smoother and remap on plain arrays, time curves
//! 2  element                            pure kernels and the small fixed-size types
//! 3  material, kinematics               constitutive update, objective push-forward
//! 4  contact, solver, integrator        contact on plain arrays, faer, step coefficients
//! 5  scene                              TOML -> validated Model (owns every enum a scene names)
//! 6  assembly                           element dispatch, scatter, parallel loops
//! 7  buckling                           inertia of K_T, linearized buckling
//! 8  analysis                           the run scaffold and its steppers
//! 9  sweep                              studies: variations, measures, extrapolation
//! 10 bench                              speed (its Taylor charts extrapolate as the sweeps do)
//! ```
//! The binary (src/main.rs) sits on top and calls analysis, sweep, bench and output.

pub mod ale;
pub mod analysis;
pub mod assembly;
pub mod bench;
pub mod buckling;
pub mod contact;
pub mod curve;
pub mod element;
pub mod integrator;
pub mod kinematics;
pub mod material;
pub mod mesh;
pub mod output;
pub mod profile;
pub mod reference;
pub mod scene;
pub mod solver;
pub mod sweep;
