//! The unit mistakes a model's numbers point to, in words: the hint the set-up warnings give.

use crate::analysis::steppers::stable::{critical_time_step, wave_speed};
use crate::material::{Hardening, Material};
use crate::output::readable;
use crate::scene::{Body, Model};

/// The two consistent unit systems of metal impacts, in words.
const CONSISTENT: &str = "consistent units are m, kg, s, Pa (steel: 7850, 210e9) or mm, t, s, \
                          MPa (steel: 7.85e-9, 210e3)";

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
        let m = &body.material;
        if (0.5..=30.0).contains(&m.density) && (1e3..1e7).contains(&m.elastic.young) {
            return format!(
                "material `{}` has density = {} (g/cm^3?) with young = {} (MPa?): with moduli in \
                MPa and lengths in mm the density is in t/mm^3 (7.85 g/cm^3 = 7.85e-9 t/mm^3); {CONSISTENT}",
                m.name,
                readable(m.density),
                readable(m.elastic.young)
            );
        }
    }
    for body in &model.bodies {
        let m = &body.material;
        if let Some(c) = wave_speed(body)
            && m.elastic.young >= 1e7
            && c.speed > FASTEST_SOLID
        {
            return format!(
                "material `{}` has density = {} with young = {} (Pa?): its waves run at {}, \
                 faster than in any solid; in SI units the density is in kg/m^3 (7.85 g/cm^3 = \
                 7850 kg/m^3); {CONSISTENT}",
                m.name,
                readable(m.density),
                readable(m.elastic.young),
                readable(c.speed)
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

/// Yield strains sigma_y / E outside this range point to a yield stress and a modulus in
/// different units: metals yield at 1e-4 to 1e-2 (soft copper 3e-4, maraging steel 1e-2),
/// polymers up to a few per cent; a yield stress in MPa beside E in Pa gives 1e-9, one in
/// Pa beside E in MPa 1e3.
pub const YIELD_STRAIN_RANGE: (f64, f64) = (1e-5, 0.1);

/// A body whose material data are in SI or mm-t-s units ([`in_known_units`]) that starts
/// faster than this share of its dilatational wave speed warns: solid
/// impacts run at a few per cent of it (a Taylor test at 200 m/s is 0.04 c of aluminium),
/// a quarter is the hypervelocity range where the material model here does not hold, and
/// a velocity in mm/s beside lengths in m (5 m/s written 5000) lands there.
pub const SPEED_SHARE: f64 = 0.25;

/// A dynamic run of more steps than this warns: the longest shipped explicit runs take
/// some 1e5 steps; 1e7 is days of wall time and mostly an end time in other units than the
/// step (60 meant in microseconds, given in seconds).
pub const MAX_STEPS: f64 = 1e7;

/// The fastest dilatational wave in any solid in m/s (diamond: 18 km/s): a faster one in a
/// scene with SI moduli has its density in other units (g/cm^3: 7.85 for steel).
const FASTEST_SOLID: f64 = 2.5e4;

/// The warnings on material data and speeds that point to mixed units: a yield strain
/// outside [`YIELD_STRAIN_RANGE`], a hardening modulus at or above Young's, an adiabatic
/// heating beyond [`HEATING_SHARE`], a wave faster than any solid's with SI moduli (a density
/// in g/cm^3), a body starting faster than [`SPEED_SHARE`] of its wave speed.
pub(super) fn unit_warnings(model: &Model) -> Vec<String> {
    let mut out = Vec::new();
    let mut seen: Vec<&str> = Vec::new();
    for body in &model.bodies {
        let m = &body.material;
        if seen.contains(&m.name.as_str()) {
            continue;
        }
        seen.push(&m.name);
        if let Some(problem) = yield_strain_problem(body) {
            out.push(problem);
        }
        out.extend(hardening_problem(m));
        out.extend(heating_problem(m));
        out.extend(temperature_scale_problem(m));
        if let Some(c) = wave_speed(body)
            && m.elastic.young >= 1e7
            && c.speed > FASTEST_SOLID
        {
            out.push(format!(
                "material `{}` carries waves at {} (sqrt(M / rho), M = {}, density = {}): faster \
                 than in any solid ({} m/s at most) if the moduli are in Pa; the density is in \
                 kg/m^3 in SI units (steel 7850, not the 7.85 of g/cm^3); {CONSISTENT}",
                m.name,
                readable(c.speed),
                readable(c.modulus),
                readable(m.density),
                readable(FASTEST_SOLID)
            ));
        }
    }
    for body in model.bodies.iter().filter(|b| in_known_units(b)) {
        if let Some((speed, c)) = start_speed(model, body)
            && speed > SPEED_SHARE * c
        {
            out.push(format!(
                "body `{}` starts at {} ({} of its wave speed {}): faster than solid impacts go \
                 (a few per cent of the wave speed; here beyond {} of it, where the material \
                 model does not hold); a velocity in mm/s beside lengths in m? {CONSISTENT}",
                body.name,
                readable(speed),
                readable(speed / c),
                readable(c),
                readable(SPEED_SHARE)
            ));
        }
    }
    out
}

/// Whether a body's material data are those of a metal or polymer in one of the two unit
/// systems of impacts: SI (density 100 to 3e4 kg/m^3, E 1e7 to 1e13 Pa) or mm, t, s, MPa
/// (density 1e-10 to 1e-7 t/mm^3, E 1e2 to 1e7 MPa). Only there does a speed against the
/// wave speed point to a unit mistake: a scene without units (a rod as a spring, E = 1,
/// rho = 2) may move its nodes as fast as it likes.
fn in_known_units(body: &Body) -> bool {
    let m = &body.material;
    let (rho, young) = (m.density, m.elastic.young);
    let si = (100.0..=3e4).contains(&rho) && (1e7..=1e13).contains(&young);
    let mm = (1e-10..=1e-7).contains(&rho) && (1e2..=1e7).contains(&young);
    si || mm
}

/// A yield strain outside [`YIELD_STRAIN_RANGE`], in words.
fn yield_strain_problem(body: &Body) -> Option<String> {
    let m = &body.material;
    let j2 = m.plasticity.as_ref()?;
    let strain = j2.yield_stress / m.elastic.young;
    let (low, high) = YIELD_STRAIN_RANGE;
    if (low..=high).contains(&strain) {
        return None;
    }
    let likely = if strain < low {
        "a yield stress in MPa beside young in Pa? (300 MPa = 3e8 Pa)"
    } else {
        "a yield stress in Pa beside young in MPa, or young too low?"
    };
    Some(format!(
        "material `{}` yields at sigma_y / E = {} (yield stress {}, young {}), outside the {} to \
         {} of solids: {likely} {CONSISTENT}",
        m.name,
        readable(strain),
        readable(j2.yield_stress),
        readable(m.elastic.young),
        readable(low),
        readable(high)
    ))
}

/// A linear hardening modulus (isotropic or kinematic) at or above Young's modulus, in
/// words. Metals harden at about E / 1000 to E / 10 (the plastic modulus d sigma_y / d eps_p:
/// mild steel 1-2 GPa against 210 GPa); one at E or above, which makes the elastic-plastic
/// tangent E H / (E + H) more than half of E, is a modulus in other units than `young`
/// (GPa written as Pa beside E in MPa, or the reverse). A scale-free test: it holds in
/// every unit system.
fn hardening_problem(m: &Material) -> Option<String> {
    let j2 = m.plasticity.as_ref()?;
    let isotropic = match j2.hardening {
        Hardening::Linear { modulus } => modulus,
        _ => 0.0,
    };
    let (key, modulus) = match isotropic >= j2.kinematic_modulus {
        true => ("hardening_modulus", isotropic),
        false => ("kinematic_modulus", j2.kinematic_modulus),
    };
    (modulus >= m.elastic.young).then(|| {
        format!(
            "material `{}` hardens with {key} = {} at or above its young = {}: metals harden at \
             about E / 1000 to E / 10 (the plastic modulus d sigma_y / d eps_p, mild steel 1-2 \
             GPa beside 210 GPa), so the plastic flow would barely soften the response; a \
             modulus in other units than young? {CONSISTENT}",
            m.name,
            readable(modulus),
            readable(m.elastic.young)
        )
    })
}

/// The melting points of the metals impacts are run on, in K (solidus to liquidus where an
/// alloy spans one): lead 600, magnesium alloys 870-923, aluminium alloys 775-933, brass
/// and bronze 1150-1300, copper 1356, nickel alloys (Inconel) 1530-1728, irons and steels
/// 1690-1811, titanium and Ti-6Al-4V 1870-1941, tantalum 3290, tungsten 3695 (handbook
/// values, e.g. the ASM Handbook vol. 2; Johnson & Cook 1985 table 1 lists OFHC copper 1356,
/// Armco iron 1811, 4340 steel 1793).
const MELTING_POINTS_K: [(f64, f64); 10] = [
    (600.0, 600.0),
    (870.0, 923.0),
    (775.0, 933.0),
    (1150.0, 1300.0),
    (1356.0, 1356.0),
    (1530.0, 1728.0),
    (1690.0, 1811.0),
    (1870.0, 1941.0),
    (3290.0, 3290.0),
    (3695.0, 3695.0),
];

/// A Johnson-Cook room temperature below this reads as degrees Celsius (`qoi::Units`: no
/// Taylor test runs colder than liquid nitrogen, 77 K, and none of the shipped or published
/// ones below room temperature).
const CELSIUS_BELOW: f64 = 150.0;

/// A Johnson-Cook material whose room and melting temperatures read as two scales: a room
/// temperature in degrees Celsius (below [`CELSIUS_BELOW`]) beside a melting temperature
/// that is a metal's melting point in K (within 1 % of [`MELTING_POINTS_K`]) and no metal's
/// in degrees Celsius. The span from room to melting temperature, which scales the thermal
/// softening, is then off by 273 (17 % on Ti-6Al-4V).
fn temperature_scale_problem(m: &Material) -> Option<String> {
    let law = m.johnson_cook()?;
    let near = |t: f64, offset: f64| {
        (MELTING_POINTS_K.iter())
            .any(|(low, high)| t >= 0.99 * (low - offset) && t <= 1.01 * (high - offset))
    };
    let melting = law.melting_temperature;
    let mixed =
        law.room_temperature < CELSIUS_BELOW && near(melting, 0.0) && !near(melting, 273.15);
    mixed.then(|| {
        format!(
            "material `{}`: johnson_cook.room_temperature = {} reads as degrees Celsius, while \
             melting_temperature = {} is a metal's melting point in K and no metal's in \
             degrees Celsius: give both in one scale (in K: room {}, melting {}; in degrees \
             Celsius: room {}, melting {}); mixed, the span that scales the thermal softening \
             is off by 273",
            m.name,
            readable(law.room_temperature),
            readable(melting),
            readable(law.room_temperature + 273.15),
            readable(melting),
            readable(law.room_temperature),
            readable(melting - 273.15)
        )
    })
}

/// The adiabatic heating of one unit of plastic strain at Johnson-Cook's initial yield
/// stress, chi A / (rho c_p), beyond this share of the span from room to melting
/// temperature warns. Real metals heat by 0.02 to 0.3 of it (OFHC copper 24 K of 1063 K,
/// 4340 steel 191 K of 1500 K, Ti-6Al-4V 424 K of 1585 K, tungsten 522 K of 3400 K): three
/// times the span is ten times the hottest, and a specific heat in kJ / (kg K) beside SI
/// stresses gives a thousand times the right rise. Scale-free: any consistent units.
pub const HEATING_SHARE: f64 = 3.0;

/// A Johnson-Cook material whose adiabatic heating is beyond [`HEATING_SHARE`], in words.
fn heating_problem(m: &Material) -> Option<String> {
    let law = m.johnson_cook()?;
    let a = m.plasticity.as_ref()?.yield_stress;
    let rise = law.temperature_rise(a, m.density);
    let span = law.melting_temperature - law.room_temperature;
    (m.density > 0.0 && rise > HEATING_SHARE * span).then(|| {
        format!(
            "material `{}` would heat by {} per unit of plastic strain at its yield stress \
             (taylor_quinney {} x A = {} / (density {} x specific_heat {})), {} times the {} \
             from room to melting temperature: it would melt at a few per cent of strain, \
             where metals heat by a tenth to a third of that span per unit strain; a \
             specific heat in kJ / (kg K) beside SI stresses (steel 477 J / (kg K), not 0.477)? \
             {CONSISTENT}",
            m.name,
            readable(rise),
            readable(law.taylor_quinney),
            readable(a),
            readable(m.density),
            readable(law.specific_heat),
            readable(rise / span),
            readable(span)
        )
    })
}

/// The largest initial speed of a body's nodes and its wave speed (None without density
/// or motion).
fn start_speed(model: &Model, body: &Body) -> Option<(f64, f64)> {
    let c = wave_speed(body)?.speed;
    let (_, speed) = fastest_node(body, &model.initial_velocity)?;
    (speed > 0.0).then_some((speed, c))
}

/// What a failed run's state says of its units: a yield strain outside
/// [`YIELD_STRAIN_RANGE`], a body that started faster than [`SPEED_SHARE`] of its wave speed
/// (its fastest node at the failure named, `velocity` all DOFs), more than [`MAX_STEPS`]
/// central-difference stable steps to the end time of a dynamic run. A node faster than
/// that share at the failure in a run whose bodies all started below it is no sign of
/// units: the run made that speed where it blew up (an element inverting, a penetration
/// pushed out, a node past an obstacle's end), and the hint says so. None: the state says
/// nothing.
pub fn failure_hint(model: &Model, velocity: &[f64]) -> Option<String> {
    let mut signs = Vec::new();
    let mut local = None;
    for body in &model.bodies {
        if let Some(problem) = yield_strain_problem(body) {
            signs.push(problem);
        }
        let Some(c) = wave_speed(body).filter(|_| in_known_units(body)) else {
            continue;
        };
        let Some((node, speed)) = fastest_node(body, velocity) else {
            continue;
        };
        if speed <= SPEED_SHARE * c.speed {
            continue;
        }
        let moving = format!(
            "node {} of body `{}` moves at {}, {} of its wave speed {}",
            node - body.node_offset,
            body.name,
            readable(speed),
            readable(speed / c.speed),
            readable(c.speed),
        );
        let started = start_speed(model, body).map_or(0.0, |(v, _)| v);
        if started > SPEED_SHARE * c.speed {
            signs.push(format!(
                "{moving}, and the body started at {} (beyond {} of it: a velocity in mm/s \
                 beside lengths in m, or moduli or density in other units)",
                readable(started),
                readable(SPEED_SHARE)
            ));
        } else if local.is_none() {
            local = Some(format!(
                "{moving}, while the body started at {} (below {} of it): the run made that \
                 speed where it failed (an element inverting, a penetration pushed out, a node \
                 past an obstacle's end), not mixed units",
                readable(started),
                readable(SPEED_SHARE)
            ));
        }
    }
    // (a static run's pseudo time has no stable step to compare with)
    let dynamic = matches!(model.analysis, crate::scene::model::Analysis::Dynamic(_));
    let first_step = critical_time_step(model).map_or(0.0, |s| s.dt);
    let steps = model.analysis.end_time() / first_step;
    if dynamic && first_step > 0.0 && steps > MAX_STEPS {
        signs.push(format!(
            "the run would take {} stable steps of {} to end_time = {}: the end time and the \
             stable step are in different units",
            readable(steps.round()),
            readable(first_step),
            readable(model.analysis.end_time())
        ));
    }
    match (signs.is_empty(), local) {
        (false, _) => Some(format!(
            "the state points to mixed units: {}",
            signs.join("; ")
        )),
        (true, local) => local,
    }
}

/// The fastest node of `body` at `velocity` (all DOFs): (global node, speed).
fn fastest_node(body: &Body, velocity: &[f64]) -> Option<(usize, f64)> {
    (0..body.mesh.nodes.len())
        .map(|n| body.global(n))
        .filter(|n| 2 * n + 1 < velocity.len())
        .map(|n| (n, velocity[2 * n].hypot(velocity[2 * n + 1])))
        .max_by(|a, b| a.1.total_cmp(&b.1))
}
