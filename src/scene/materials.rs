//! `[[material]]`: elastic constants, density and the optional J2 plasticity with its
//! hardening (linear, a table, or Johnson-Cook), checked and keyed by name.

use super::InputError;
use super::context::{Context, positive};
use super::spec::{JohnsonCookSpec, MaterialSpec, Scene};
use crate::material::{Elastic, Hardening, J2, JohnsonCook, Material};
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
            elastic: Elastic::new(m.young, m.poisson),
            plasticity: plasticity(cx, &key, m)?,
        };
        if out.insert(m.name.clone(), material).is_some() {
            return Err(cx.err(format!("{key}.name: `{}` is used twice", m.name)));
        }
    }
    Ok(out)
}

/// The J2 plasticity of a material: Johnson-Cook with `johnson_cook`, none without
/// `yield_stress`, else its hardening.
fn plasticity(cx: &Context, key: &str, m: &MaterialSpec) -> Result<Option<J2>, InputError> {
    if let Some(spec) = &m.johnson_cook {
        return johnson_cook(cx, key, m, spec).map(Some);
    }
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

/// Johnson-Cook plasticity: alone (no `yield_stress` or hardening keys beside it), every
/// parameter in its range, and a density for the heating.
fn johnson_cook(
    cx: &Context,
    key: &str,
    m: &MaterialSpec,
    spec: &JohnsonCookSpec,
) -> Result<J2, InputError> {
    for (present, name) in [
        (m.yield_stress.is_some(), "yield_stress"),
        (m.hardening_modulus.is_some(), "hardening_modulus"),
        (m.hardening_table.is_some(), "hardening_table"),
        (m.kinematic_modulus.is_some(), "kinematic_modulus"),
    ] {
        if present {
            return Err(cx.err(format!(
                "{key}.{name}: give `johnson_cook` or `yield_stress` with its hardening, not \
                 both (Johnson-Cook hardens isotropically, `a` is its yield stress)"
            )));
        }
    }
    let jc = format!("{key}.johnson_cook");
    let non_negative = |name: &str, v: f64| -> Result<f64, InputError> {
        if v >= 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(cx.err(format!("{jc}.{name}: must be >= 0, got {v}")))
        }
    };
    let finite = |name: &str, v: f64| -> Result<f64, InputError> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(cx.err(format!("{jc}.{name}: must be a finite number, got {v}")))
        }
    };
    let a = positive(cx, &format!("{jc}.a"), spec.a)?;
    let b = non_negative("b", spec.b)?;
    let n = positive(cx, &format!("{jc}.n"), spec.n)?;
    let c = non_negative("c", spec.c)?;
    let reference_rate = positive(cx, &format!("{jc}.reference_rate"), spec.reference_rate)?;
    let m_exponent = positive(cx, &format!("{jc}.m"), spec.m)?;
    let room = finite("room_temperature", spec.room_temperature)?;
    let melting = finite("melting_temperature", spec.melting_temperature)?;
    if melting <= room {
        return Err(cx.err(format!(
            "{jc}.melting_temperature: must exceed room_temperature ({room}), got {melting}"
        )));
    }
    let specific_heat = positive(cx, &format!("{jc}.specific_heat"), spec.specific_heat)?;
    let taylor_quinney = non_negative("taylor_quinney", spec.taylor_quinney)?;
    if taylor_quinney > 1.0 {
        return Err(cx.err(format!(
            "{jc}.taylor_quinney: must lie in [0, 1], got {taylor_quinney}"
        )));
    }
    let initial = finite(
        "initial_temperature",
        spec.initial_temperature.unwrap_or(room),
    )?;
    if initial >= melting {
        return Err(cx.err(format!(
            "{jc}.initial_temperature: must be below melting_temperature ({melting}), got \
             {initial}"
        )));
    }
    if !(m.density > 0.0) {
        return Err(cx.err(format!(
            "{key}.density: johnson_cook needs a density > 0 (the heating is per unit mass), \
             got {}",
            m.density
        )));
    }
    Ok(J2 {
        yield_stress: a,
        hardening: Hardening::JohnsonCook(JohnsonCook {
            b,
            n,
            c,
            reference_rate,
            m: m_exponent,
            room_temperature: room,
            melting_temperature: melting,
            specific_heat,
            taylor_quinney,
            initial_temperature: initial,
        }),
        kinematic_modulus: 0.0,
    })
}
