//! history.csv's columns: which a model's run writes, in order (the output contract of
//! docs/user-guide.md section 5; columns are only ever added at the end).

use crate::contact::{Friction, Master};
use crate::scene::Model;

/// The history.csv columns a run of `model` writes, in order.
pub fn column_names(model: &Model) -> Vec<String> {
    columns(model).0
}

/// The history.csv columns of a model, and whether the negative-pivot column is among them.
pub(super) fn columns(model: &Model) -> (Vec<String>, bool) {
    let mut columns: Vec<String> = [
        "time",
        "kinetic_energy",
        "internal_energy",
        "plastic_work",
        "external_work",
        "contact_work",
        "dt",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    // a balanced pair's reverse pass is folded into its pair's columns (`fold_passes`)
    let reported = || model.contacts.iter().filter(|c| c.balances.is_none());
    columns.extend(reported().map(|c| format!("contact_force[{}]", c.name)));
    columns.extend(
        reported()
            .filter(|c| c.options.friction != Friction::None)
            .map(|c| format!("tangential_force[{}]", c.name)),
    );
    columns.extend(model.probes.iter().map(|p| p.column.clone()));
    let pivots_column = model.analysis.buckling().is_some_and(|b| b.check);
    if pivots_column {
        columns.push("tangent_negative_pivots".to_string());
    }
    if hourglass_column(model) {
        columns.push("hourglass_energy".to_string());
    }
    if error_column(model) {
        // the local error estimate of the step (theory 8.2a)
        columns.push("error_estimate".to_string());
    }
    if !model.contacts.is_empty() {
        // the deepest penetration of either surface into the other body after the step
        columns.push("penetration".to_string());
    }
    if super::contact_record::averages(model) {
        // the pairs' forces averaged over output.contact_force_window
        columns.extend(reported().map(|c| format!("contact_force_avg[{}]", c.name)));
    }
    if bulk_viscosity_column(model) {
        // the cumulative work of the bulk viscosity's pressure
        columns.push("bulk_viscosity_work".to_string());
    }
    if mass_scaling_columns(model) {
        // the kinetic energy lost as added mass joined the nodes, and the mass added so far
        columns.push("mass_scaling_loss".to_string());
        columns.push("added_mass".to_string());
    }
    if model.analysis.ale().is_some() {
        // the kinetic energy the ALE remaps took out of the motion
        columns.push("remap_loss".to_string());
    }
    if friction_column(model) {
        // the energy Coulomb friction dissipated (the normal rows' share is contact_work)
        columns.push("friction_work".to_string());
    }
    if load_factor_column(model) {
        // the share of the scene's loads (at end_time) the arc-length path has reached
        columns.push("load_factor".to_string());
    }
    if body_columns(model) {
        // each body's kinetic energy, stored energy and plastic work (the totals' shares)
        for body in &model.bodies {
            columns.extend(
                ["kinetic_energy", "internal_energy", "plastic_work"]
                    .map(|quantity| format!("{quantity}[{}]", body.name)),
            );
        }
    }
    if pair_columns(model) {
        // each pair's contact work and, with Coulomb friction, its friction work (the
        // totals' shares, contact::energy)
        for pair in reported() {
            columns.push(format!("contact_work[{}]", pair.name));
            if matches!(pair.options.friction, Friction::Coulomb { .. }) {
                columns.push(format!("friction_work[{}]", pair.name));
            }
        }
    }
    for obstacle in moving_obstacles(model) {
        // a moving obstacle's displacement (prescribed, or a projectile's flight), its
        // velocity and the force the bodies exert on it
        columns.extend(
            [
                "obstacle_u_x",
                "obstacle_u_y",
                "obstacle_v_x",
                "obstacle_v_y",
                "obstacle_force_x",
                "obstacle_force_y",
            ]
            .map(|quantity| format!("{quantity}[{}]", obstacle.name)),
        );
        // a rotating projectile's rotation about its centre and its rate
        if obstacle
            .projectile
            .as_ref()
            .is_some_and(|p| p.spin.is_some())
        {
            columns.extend(
                ["obstacle_rotation", "obstacle_omega"]
                    .map(|quantity| format!("{quantity}[{}]", obstacle.name)),
            );
        }
    }
    (columns, pivots_column)
}

/// The obstacles of the scene that move (driven, or projectiles) and that a pair uses, in
/// the scene's order: each has its displacement, velocity and force columns.
pub(super) fn moving_obstacles(model: &Model) -> impl Iterator<Item = &crate::contact::Obstacle> {
    model.obstacles.iter().filter(|o| {
        (o.motion.is_some() || o.projectile.is_some())
            && (model.contacts.iter())
                .any(|p| matches!(&p.master, Master::Obstacle(m) if m.name == o.name))
    })
}

/// Whether the history has each pair's energies: a dynamic run with two pairs or more (a
/// balanced pair's passes counted once).
pub fn pair_columns(model: &Model) -> bool {
    matches!(model.analysis, crate::scene::model::Analysis::Dynamic(_))
        && (model.contacts.iter())
            .filter(|c| c.balances.is_none())
            .count()
            > 1
}

/// Whether the history has each body's energies: a model of two bodies or more.
pub fn body_columns(model: &Model) -> bool {
    model.bodies.len() > 1
}

/// Whether the history has `friction_work`: a dynamic run with a Coulomb pair (statics books
/// no energy of its contact).
pub fn friction_column(model: &Model) -> bool {
    matches!(model.analysis, crate::scene::model::Analysis::Dynamic(_))
        && (model.contacts.iter()).any(|c| matches!(c.options.friction, Friction::Coulomb { .. }))
}

/// Whether the history has `load_factor`: a static run by arc length.
pub(super) fn load_factor_column(model: &Model) -> bool {
    matches!(&model.analysis, crate::scene::model::Analysis::Static(s) if s.arc_length.is_some())
}

pub(super) fn bulk_viscosity_column(model: &Model) -> bool {
    model.analysis.bulk_viscosity().is_some()
}

pub(super) fn mass_scaling_columns(model: &Model) -> bool {
    model.analysis.mass_scaling().is_some()
}

pub(super) fn error_column(model: &Model) -> bool {
    matches!(&model.analysis, crate::scene::model::Analysis::Dynamic(d) if d.has_error_estimate())
}

pub(super) fn hourglass_column(model: &Model) -> bool {
    model.analysis.one_point()
}
