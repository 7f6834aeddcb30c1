//! The units of a scene's numbers as far as its material data tell, and the unit of each
//! history.csv column (summary.json `column_units`; the sweep's and `impact plot`'s axes).

use crate::element::Formulation;
use crate::scene::Model;
use std::collections::BTreeMap;

/// The units a scene's numbers are in, as far as its material data tell (no unit system
/// is imposed): SI (every density 100 to 3e4, every Young's modulus 1e7 to 1e13: kg/m^3 and
/// Pa) or mm-t-s (densities 1e-10 to 1e-7 t/mm^3, moduli 1e2 to 1e7 MPa); else the
/// dimension's name in brackets. Temperatures are in the scene's own scale: C when a
/// Johnson-Cook room temperature is below 150 (degrees Celsius), else K.
#[derive(Debug, Clone, PartialEq)]
pub struct Units {
    pub length: &'static str,
    pub time: &'static str,
    pub force: &'static str,
    pub energy: &'static str,
    pub stress: &'static str,
    pub mass: &'static str,
    pub temperature: &'static str,
    /// `/m`, `/mm` (or `/[length]`) for forces and energies of a plane-strain body: per unit
    /// depth; empty otherwise.
    pub per_depth: String,
}

impl Units {
    pub fn of(model: &Model) -> Units {
        let all = |density: (f64, f64), young: (f64, f64)| {
            model.bodies.iter().all(|b| {
                let (rho, e) = (b.material.density, b.material.elastic.young);
                (density.0..=density.1).contains(&rho) && (young.0..=young.1).contains(&e)
            })
        };
        let (length, time, force, energy, stress, mass) = if all((100.0, 3e4), (1e7, 1e13)) {
            ("m", "s", "N", "J", "Pa", "kg")
        } else if all((1e-10, 1e-7), (1e2, 1e7)) {
            ("mm", "s", "N", "mJ", "MPa", "t")
        } else {
            (
                "[length]", "[time]", "[force]", "[energy]", "[stress]", "[mass]",
            )
        };
        let celsius = model.bodies.iter().any(|b| {
            b.material
                .johnson_cook()
                .is_some_and(|law| law.room_temperature < 150.0)
        });
        let plane_strain = model
            .bodies
            .iter()
            .any(|b| b.kind.formulation() == Some(Formulation::PlaneStrain));
        Units {
            length,
            time,
            force,
            energy,
            stress,
            mass,
            temperature: if celsius { "C" } else { "K" },
            per_depth: if plane_strain {
                format!("/{length}")
            } else {
                String::new()
            },
        }
    }

    /// The unit of a history.csv column of `model` (empty for a count or a strain).
    pub fn of_column(&self, model: &Model, column: &str) -> String {
        let per = |unit: &str| format!("{unit}{}", self.per_depth);
        if let Some(probe) = model.probes.iter().find(|p| p.column == column) {
            return match probe.quantity.unit() {
                "m" => self.length.to_string(),
                "m/s" => format!("{}/{}", self.length, self.time),
                "m/s^2" => format!("{}/{}^2", self.length, self.time),
                "N" => per(self.force),
                "kg m/s" => per(&format!("{} {}", self.force, self.time)),
                "Pa" => self.stress.to_string(),
                "K" => self.temperature.to_string(),
                other => other.to_string(),
            };
        }
        let name = column.split('[').next().unwrap_or(column);
        match name {
            "time" | "dt" => self.time.to_string(),
            "kinetic_energy"
            | "internal_energy"
            | "plastic_work"
            | "external_work"
            | "contact_work"
            | "hourglass_energy"
            | "bulk_viscosity_work"
            | "mass_scaling_loss"
            | "remap_loss"
            | "friction_work" => per(self.energy),
            "added_mass" => per(self.mass),
            "contact_force" | "tangential_force" => per(self.force),
            "penetration" => self.length.to_string(),
            _ => String::new(),
        }
    }
}

/// Each of the history.csv `columns` of a run of `model` with a unit, and its unit
/// (summary.json `column_units`; counts and strains have none and are left out).
pub fn column_units(model: &Model, columns: Vec<String>) -> BTreeMap<String, String> {
    let units = Units::of(model);
    columns
        .into_iter()
        .filter_map(|column| {
            let unit = units.of_column(model, &column);
            (!unit.is_empty()).then_some((column, unit))
        })
        .collect()
}
