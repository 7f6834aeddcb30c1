//! External forces and prescribed displacements at a given (pseudo) time.

use crate::assembly::State;
use crate::element::quad4;
use crate::scene::{Continuum, Load, Model};

/// Prescribed total displacements (DOF, value) at time t: supports give 0; a DOF named by
/// several loads takes the last one's value.
pub fn prescribed(model: &Model, initial: &[[f64; 2]], t: f64) -> Vec<(usize, f64)> {
    let mut out: Vec<(usize, f64)> = model.fixed_dofs.iter().map(|d| (*d, 0.0)).collect();
    for load in &model.loads {
        match load {
            Load::Displacement { nodes, x, y, curve } => {
                let s = curve.value(t);
                for n in nodes {
                    if let Some(x) = x {
                        out.push((2 * n, x * s));
                    }
                    if let Some(y) = y {
                        out.push((2 * n + 1, y * s));
                    }
                }
            }
            Load::Rotation {
                nodes,
                center,
                angle,
                curve,
            } => {
                let (sin, cos) = (angle * curve.value(t)).sin_cos();
                for n in nodes {
                    let (dx, dy) = (initial[*n][0] - center[0], initial[*n][1] - center[1]);
                    out.push((2 * n, cos * dx - sin * dy - dx));
                    out.push((2 * n + 1, sin * dx + cos * dy - dy));
                }
            }
            Load::Affine {
                nodes,
                gradient: g,
                offset,
                curve,
            } => {
                let s = curve.value(t);
                for n in nodes {
                    let [x, y] = initial[*n];
                    out.push((2 * n, s * (offset[0] + g[0][0] * x + g[0][1] * y)));
                    out.push((2 * n + 1, s * (offset[1] + g[1][0] * x + g[1][1] * y)));
                }
            }
            _ => {}
        }
    }
    out
}

/// External force vector over all DOFs at time t. Tractions act on the initial edges;
/// pressures on the edges of the reference (last converged) configuration.
pub fn external_force(model: &Model, state: &State, initial: &[[f64; 2]], t: f64) -> Vec<f64> {
    let mut f = vec![0.0; model.dofs()];
    add_external_force(model, state, initial, t, &mut f);
    f
}

/// Whether the scene has loads that give an external force (nodal forces, tractions,
/// pressures): without them the external force is zero at all times.
pub fn has_external_force(model: &Model) -> bool {
    model.loads.iter().any(|load| {
        !matches!(
            load,
            Load::Displacement { .. } | Load::Rotation { .. } | Load::Affine { .. }
        )
    })
}

/// Adds the external force at time t to `f` (as `external_force`, into a buffer of the caller's).
pub fn add_external_force(
    model: &Model,
    state: &State,
    initial: &[[f64; 2]],
    t: f64,
    f: &mut [f64],
) {
    for load in &model.loads {
        match load {
            Load::NodalForce {
                nodes,
                force,
                curve,
            } => {
                let s = curve.value(t);
                for n in nodes {
                    f[2 * n] += force[0] * s;
                    f[2 * n + 1] += force[1] * s;
                }
            }
            Load::Traction {
                body,
                edges,
                traction,
                curve,
            } => {
                let s = curve.value(t);
                let t = [traction[0] * s, traction[1] * s];
                add_edge_forces(model, *body, edges, initial, |_, _| t, f);
            }
            Load::Pressure {
                body,
                edges,
                pressure,
                curve,
            } => {
                let p = pressure * curve.value(t);
                add_edge_forces(
                    model,
                    *body,
                    edges,
                    &state.coordinates,
                    |a, b| {
                        let n = quad4::outward_normal(a, b);
                        [-p * n[0], -p * n[1]]
                    },
                    f,
                );
            }
            Load::Displacement { .. } | Load::Rotation { .. } | Load::Affine { .. } => {}
        }
    }
}

fn add_edge_forces(
    model: &Model,
    body: usize,
    edges: &[[usize; 2]],
    coords: &[[f64; 2]],
    traction: impl Fn([f64; 2], [f64; 2]) -> [f64; 2],
    f: &mut [f64],
) {
    let Some(Continuum {
        formulation,
        thickness,
        ..
    }) = model.bodies[body].kind.continuum()
    else {
        return;
    };
    for [a, b] in edges {
        let (xa, xb) = (coords[*a], coords[*b]);
        let fe = quad4::edge_force(xa, xb, traction(xa, xb), formulation, thickness);
        f[2 * a] += fe[0];
        f[2 * a + 1] += fe[1];
        f[2 * b] += fe[2];
        f[2 * b + 1] += fe[3];
    }
}
