//! The unit mistakes a model's numbers point to, in words: the hint the set-up warnings give.

use crate::analysis::steppers::stable::wave_speed;
use crate::output::readable;
use crate::scene::{Body, Model};

/// The size a wave crosses: the shorter side of the body's bounding box (a rod: its length,
/// the longer side).
pub(super) fn body_size(body: &Body) -> f64 {
    let mut low = [f64::INFINITY; 2];
    let mut high = [f64::NEG_INFINITY; 2];
    for p in &body.mesh.nodes {
        for k in 0..2 {
            low[k] = low[k].min(p[k]);
            high[k] = high[k].max(p[k]);
        }
    }
    let sides = [high[0] - low[0], high[1] - low[1]];
    if body.kind.is_rod() {
        sides[0].max(sides[1])
    } else {
        sides[0].min(sides[1])
    }
}

/// The unit mistake the model's numbers point to, in words. Two are common: a density in
/// kg/m^3 beside moduli in MPa (lengths in mm: the density must be in t/mm^3), which makes
/// waves some 3e4 times slower than in any solid; and a geometry in mm beside SI material
/// data, which makes the bodies 1000 times too large for their m/s wave speed.
pub(super) fn unit_hint(model: &Model) -> String {
    const CONSISTENT: &str = "consistent units are m, kg, s, Pa (steel: 7850, 210e9) or mm, t, \
                s, MPa (steel: 7.85e-9, 210e3)";
    for body in &model.bodies {
        let m = &body.material;
        if m.density > 100.0 && m.elastic.young < 1e7 {
            return format!(
                "material `{}` has density = {} (kg/m^3?) with young = {} (MPa?): with moduli in \
                MPa and lengths in mm the density is in t/mm^3 (7850 kg/m^3 = 7.85e-9 t/mm^3); {CONSISTENT}",
                m.name,
                readable(m.density),
                readable(m.elastic.young)
            );
        }
    }
    for body in &model.bodies {
        if let Some(c) = wave_speed(body)
            && (1e3..=2e4).contains(&c.speed)
            && body_size(body) >= 1.0
        {
            return format!(
                "body `{}` has a wave speed of {} (a solid's in m/s) and a size of {} (m, then): \
                a geometry meant in mm must be given in m with SI material data; {CONSISTENT}",
                body.name,
                readable(c.speed),
                readable(body_size(body))
            );
        }
    }
    CONSISTENT.to_string()
}
