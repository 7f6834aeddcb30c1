//! impact: finite-strain elastoplastic contact-impact in 2D (plane strain, plane stress,
//! axisymmetric) and 1D rods, after Hughes et al. (1975), Erklig et al. (2010) and
//! Greco & Coda (2003). See docs/theory.md for the equations and their sources.
//!
//! Dependencies flow one way: scene -> mesh -> element / material / kinematics -> assembly
//! -> solver -> analysis -> output.

pub mod analysis;
pub mod assembly;
pub mod bench;
pub mod contact;
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
pub mod stability;
pub mod sweep;
