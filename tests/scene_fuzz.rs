//! Scene parsing and `--set` never panic: generated inputs are either a valid model or an
//! `InputError` (exit 2) whose message names the file.
//!
//! The inputs mutate a valid scene (with a contact pair, an obstacle, loads and probes):
//! lines dropped, duplicated or cut, values replaced by numbers (NaN, inf, negative, huge,
//! zero), strings, booleans, arrays and tables, unknown keys inserted, plus random `--set`
//! assignments on real and made-up key paths. 100 000 cases by default (a few seconds in
//! release); IMPACT_FUZZ_CASES sets another number.

use impact::analysis::RunError;
use proptest::prelude::*;
use std::path::Path;

const BASE: &str = r#"title = "fuzz"

[[material]]
name = "steel"
young = 1000.0
poisson = 0.3
density = 1.0
yield_stress = 5.0
hardening_modulus = 10.0

[[body]]
name = "beam"
material = "steel"
formulation = "plane_strain"
velocity = [0.0, -0.1]
mesh = { type = "rectangle", width = 4.0, height = 1.0, nx = 4, ny = 2 }

[[support]]
set = "left"
fix = ["x", "y"]

[[load]]
type = "traction"
set = "right"
traction = [0.0, 1.0]

[[obstacle]]
name = "floor"
points = [[10.0, -1.0], [-10.0, -1.0]]

[[contact]]
name = "floor"
slave = { set = "bottom" }
obstacle = "floor"

[analysis]
type = "dynamic"
dt = 0.01
end_time = 0.1
integrator = "average"
checkpoint_every = 5

[output]
frame_every = 2

[[output.probe]]
quantity = "u_y"
set = "right"
"#;

const KEYS: &[&str] = &[
    "title",
    "name",
    "young",
    "poisson",
    "density",
    "yield_stress",
    "hardening_modulus",
    "material",
    "formulation",
    "velocity",
    "mesh",
    "set",
    "fix",
    "type",
    "traction",
    "points",
    "slave",
    "obstacle",
    "dt",
    "end_time",
    "integrator",
    "steps",
    "checkpoint_every",
    "frame_every",
    "quantity",
    "nx",
    "ny",
    "width",
    "height",
    "friction",
    "geometry",
    "newton",
    "bogus",
];

const PATHS: &[&str] = &[
    "analysis.dt",
    "analysis.end_time",
    "analysis.steps",
    "analysis.type",
    "analysis.integrator",
    "analysis.checkpoint_every",
    "analysis.newton.max_iterations",
    "analysis.newton.strategy",
    "body.beam.velocity",
    "body.beam.mesh.nx",
    "body.beam.mesh.width",
    "body.beam.formulation",
    "body.nobody.mesh.nx",
    "body.0.material",
    "material.steel.young",
    "material.steel.poisson",
    "material.0.density",
    "load.0.traction",
    "load.3.traction",
    "contact.floor.friction",
    "obstacle.floor.points",
    "output.frame_every",
    "output.probe.0.set",
    "support.0.fix",
    "",
    ".",
    "a..b",
    "analysis.dt.x",
];

fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("0".to_string()),
        Just("0.0".to_string()),
        Just("-1".to_string()),
        Just("1e308".to_string()),
        Just("-1e-320".to_string()),
        Just("18446744073709551616".to_string()),
        Just("9223372036854775807".to_string()),
        Just("4000000000".to_string()),
        (-1e6f64..1e6).prop_map(|x| format!("{x:?}")),
        (-100i64..100).prop_map(|x| x.to_string()),
        (0u64..30000).prop_map(|x| x.to_string()),
    ]
}

fn value() -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        4 => number(),
        1 => Just("true".to_string()),
        1 => Just("\"\"".to_string()),
        2 => "[a-z_]{0,12}".prop_map(|s| format!("\"{s}\"")),
        1 => prop::sample::select(KEYS).prop_map(|s| format!("\"{s}\"")),
        1 => "\\PC{0,8}".prop_map(|s| format!("{s:?}")),
        1 => "[\\[\\]{}=,\"'.#a-z0-9 ]{0,12}",
    ];
    leaf.prop_recursive(2, 8, 4, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..4).prop_map(|v| format!("[{}]", v.join(", "))),
            prop::collection::vec((prop::sample::select(KEYS), inner), 0..3).prop_map(|v| {
                let fields: Vec<String> = v.iter().map(|(k, x)| format!("{k} = {x}")).collect();
                format!("{{ {} }}", fields.join(", "))
            }),
        ]
    })
}

#[derive(Debug, Clone)]
enum Mutation {
    Drop(usize),
    Duplicate(usize),
    Replace(usize, String),
    Insert(usize, &'static str, String),
    Cut(usize),
    Char(usize, char),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        2 => any::<usize>().prop_map(Mutation::Drop),
        1 => any::<usize>().prop_map(Mutation::Duplicate),
        6 => (any::<usize>(), value()).prop_map(|(i, v)| Mutation::Replace(i, v)),
        2 => (any::<usize>(), prop::sample::select(KEYS), value()).prop_map(|(i, k, v)| Mutation::Insert(i, k, v)),
        1 => any::<usize>().prop_map(Mutation::Cut),
        1 => (any::<usize>(), any::<char>()).prop_map(|(i, c)| Mutation::Char(i, c)),
    ]
}

fn mutate(mutations: &[Mutation]) -> String {
    let mut lines: Vec<String> = BASE.lines().map(str::to_string).collect();
    for m in mutations {
        let n = lines.len().max(1);
        match m {
            Mutation::Drop(i) if !lines.is_empty() => {
                lines.remove(i % n);
            }
            Mutation::Duplicate(i) if !lines.is_empty() => {
                let l = lines[i % n].clone();
                lines.insert(i % n, l);
            }
            Mutation::Replace(i, v) if !lines.is_empty() => {
                let l = &mut lines[i % n];
                if let Some((key, _)) = l.split_once(" = ") {
                    *l = format!("{key} = {v}");
                }
            }
            Mutation::Insert(i, k, v) => lines.insert(i % (lines.len() + 1), format!("{k} = {v}")),
            Mutation::Cut(i) => {
                let text = lines.join("\n");
                let mut at = i % (text.len() + 1);
                while !text.is_char_boundary(at) {
                    at -= 1;
                }
                lines = text[..at].lines().map(str::to_string).collect();
            }
            Mutation::Char(i, c) if !lines.is_empty() => {
                let l = &mut lines[i % n];
                let mut at = i % (l.len() + 1);
                while !l.is_char_boundary(at) {
                    at -= 1;
                }
                l.insert(at, *c);
            }
            _ => {}
        }
    }
    lines.join("\n")
}

fn assignment() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (prop::sample::select(PATHS), value()).prop_map(|(p, v)| format!("{p}={v}")),
        1 => "\\PC{0,20}",
        1 => prop::sample::select(PATHS).prop_map(str::to_string),
    ]
}

fn cases() -> u32 {
    std::env::var("IMPACT_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000)
}

/// Parses and validates; a panic or an error without the file's name fails the case.
fn check(text: &str, overrides: &[String]) -> Result<bool, TestCaseError> {
    let outcome = std::panic::catch_unwind(|| {
        impact::scene::from_str(text, Path::new("fuzz.toml"), overrides)
    });
    match outcome {
        Err(_) => Err(TestCaseError::fail(format!(
            "panic on\n{text}\n--set {overrides:?}"
        ))),
        Ok(Ok(_)) => Ok(true),
        Ok(Err(e)) => {
            let message = e.to_string();
            prop_assert!(
                message.starts_with("fuzz.toml: ") && message.len() > "fuzz.toml: ".len() + 3,
                "message {message:?}"
            );
            prop_assert_eq!(RunError::from(e).exit_code(), 2);
            Ok(false)
        }
    }
}

/// Goal: the base scene is valid (so mutations start from a real model).
#[test]
fn fuzz_base_scene_is_valid() {
    impact::scene::from_str(BASE, Path::new("fuzz.toml"), &[]).unwrap();
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: cases(),
        failure_persistence: None,
        max_shrink_iters: 2000,
        ..ProptestConfig::default()
    })]

    /// Goal: mutated scene texts with random --set assignments never panic; every rejection
    /// is exit 2 with a message naming the file.
    #[test]
    fn mutated_scenes_and_overrides_never_panic(
        mutations in prop::collection::vec(mutation(), 0..4),
        overrides in prop::collection::vec(assignment(), 0..3),
    ) {
        let text = mutate(&mutations);
        check(&text, &overrides)?;
    }
}
