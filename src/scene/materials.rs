//! `[[material]]`: elastic constants, density and the optional J2 plasticity with its
//! hardening, checked and keyed by name.

use super::InputError;
use super::context::{Context, positive};
use super::spec::{MaterialSpec, Scene};
use crate::material::{Elastic, Hardening, J2, Material};
use std::collections::BTreeMap;

/// The `[[material]]` tables by name, each checked.
pub(super) fn materials(
    cx: &Context,
    scene: &Scene,
) -> Result<BTreeMap<String, Material>, InputError> {
    let mut out = BTreeMap::new();
    for (k, m) in scene.material.iter().enumerate() {
        let key = format!("material[{k}] (`{}`)", m.name);
        positive(cx, &format!("{key}.young"), m.young)?;
        if !(m.poisson > -1.0 && m.poisson < 0.5) {
            return Err(cx.err(format!(
                "{key}.poisson: must lie in (-1, 0.5), got {}",
                m.poisson
            )));
        }
        if !(m.density >= 0.0 && m.density.is_finite()) {
            return Err(cx.err(format!("{key}.density: must be >= 0, got {}", m.density)));
        }
        let material = Material {
            name: m.name.clone(),
            density: m.density,
            elastic: Elastic {
                young: m.young,
                poisson: m.poisson,
            },
            plasticity: plasticity(cx, &key, m)?,
        };
        if out.insert(m.name.clone(), material).is_some() {
            return Err(cx.err(format!("{key}.name: `{}` is used twice", m.name)));
        }
    }
    Ok(out)
}

/// The J2 plasticity of a material: none without `yield_stress`, else its hardening.
fn plasticity(cx: &Context, key: &str, m: &MaterialSpec) -> Result<Option<J2>, InputError> {
    let Some(yield_stress) = m.yield_stress else {
        for (present, name) in [
            (m.hardening_modulus.is_some(), "hardening_modulus"),
            (m.hardening_table.is_some(), "hardening_table"),
            (m.kinematic_modulus.is_some(), "kinematic_modulus"),
        ] {
            if present {
                return Err(cx.err(format!(
                    "{key}.{name}: needs `yield_stress` (an elastic material does not harden)"
                )));
            }
        }
        return Ok(None);
    };
    positive(cx, &format!("{key}.yield_stress"), yield_stress)?;
    let non_negative = |name: &str, v: Option<f64>| -> Result<f64, InputError> {
        let v = v.unwrap_or(0.0);
        if v >= 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(cx.err(format!("{key}.{name}: must be >= 0, got {v}")))
        }
    };
    let hardening = match (&m.hardening_table, m.hardening_modulus) {
        (Some(_), Some(_)) => {
            return Err(cx.err(format!(
                "{key}: give `hardening_modulus` or `hardening_table`, not both"
            )));
        }
        (Some(points), None) => {
            let mut previous = [0.0, yield_stress];
            for (i, p) in points.iter().enumerate() {
                if !(p[0] > previous[0] && p[1].is_finite() && p[0].is_finite()) {
                    return Err(cx.err(format!(
                        "{key}.hardening_table[{i}]: eps_p must increase from 0 (got {} after {})",
                        p[0], previous[0]
                    )));
                }
                if p[1] <= 0.0 {
                    return Err(cx.err(format!(
                        "{key}.hardening_table[{i}]: sigma_y must stay positive"
                    )));
                }
                previous = *p;
            }
            if points.is_empty() {
                return Err(cx.err(format!(
                    "{key}.hardening_table: give at least one [eps_p, sigma_y] point"
                )));
            }
            Hardening::Table {
                points: points.clone(),
            }
        }
        (None, h) => Hardening::Linear {
            modulus: non_negative("hardening_modulus", h)?,
        },
    };
    Ok(Some(J2 {
        yield_stress,
        hardening,
        kinematic_modulus: non_negative("kinematic_modulus", m.kinematic_modulus)?,
    }))
}
