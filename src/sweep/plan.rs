//! The plan of a sweep: the scene, its fixed `--set` overrides and the `--vary` variations;
//! the cases (their cross product), their folders and shards.
//!
//! ```text
//! --vary KEY=v1,v2,v3               one key, one case per value
//! --vary K1,K2,K3=a1,a2,a3;b1,b2,b3  keys varied together (zipped): one case per group
//! ```
//! Several `--vary` make the cross product, the first one outermost. Values are TOML values
//! as in `--set` (arrays keep their commas: `body.ball.velocity=[0,-1],[0,-2]`).

use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// One `--vary`: keys varied together and their options (one value per key each).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Variation {
    pub keys: Vec<String>,
    pub options: Vec<Vec<String>>,
}

/// Parses `KEY=v1,v2` or `K1,K2=a1,a2;b1,b2`; the message says what is malformed.
pub fn parse_variation(text: &str) -> Result<Variation, String> {
    let (keys, values) = text
        .split_once('=')
        .ok_or("expected KEY=v1,v2,... or KEY1,KEY2=a1,a2;b1,b2")?;
    let keys: Vec<String> = keys.split(',').map(|k| k.trim().to_string()).collect();
    for key in &keys {
        if key.is_empty() || key.split('.').any(str::is_empty) {
            return Err(format!("empty key or key segment in `{text}`"));
        }
    }
    if let Some(k) = (0..keys.len()).find(|k| keys[..*k].contains(&keys[*k])) {
        return Err(format!("key `{}` is listed twice", keys[k]));
    }
    let options: Vec<Vec<String>> = if keys.len() == 1 {
        split_top(values, &[',', ';'])
            .into_iter()
            .map(|v| vec![v])
            .collect()
    } else {
        split_top(values, &[';'])
            .into_iter()
            .map(|group| split_top(&group, &[',']))
            .collect()
    };
    if options.is_empty() || options.iter().flatten().any(String::is_empty) {
        return Err(format!("empty value in `{text}`"));
    }
    for (g, group) in options.iter().enumerate() {
        if group.len() != keys.len() {
            return Err(format!(
                "group {} (`{}`) has {} values for {} keys ({}); separate groups by `;`",
                g + 1,
                group.join(","),
                group.len(),
                keys.len(),
                keys.join(",")
            ));
        }
    }
    Ok(Variation { keys, options })
}

/// Splits at the separators outside brackets, braces and quotes; trims each part.
fn split_top(text: &str, separators: &[char]) -> Vec<String> {
    let mut parts = Vec::new();
    let (mut depth, mut quoted, mut current) = (0i32, None::<char>, String::new());
    for c in text.chars() {
        match (quoted, c) {
            (Some(q), c) if c == q => quoted = None,
            (Some(_), _) => {}
            (None, '"' | '\'') => quoted = Some(c),
            (None, '[' | '{') => depth += 1,
            (None, ']' | '}') => depth -= 1,
            (None, c) if depth == 0 && separators.contains(&c) => {
                parts.push(current.trim().to_string());
                current.clear();
                continue;
            }
            _ => {}
        }
        current.push(c);
    }
    parts.push(current.trim().to_string());
    parts
}

/// `--shard i/n`: this run does the cases k with k mod n = i (0 <= i < n).
pub fn parse_shard(text: &str) -> Result<(usize, usize), String> {
    let bad = || format!("--shard `{text}`: expected i/n with 0 <= i < n, e.g. 0/4");
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let (i, n) = (
        i.trim().parse::<usize>().map_err(|_| bad())?,
        n.trim().parse::<usize>().map_err(|_| bad())?,
    );
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

/// What a sweep runs; written to DIR/sweep.json so `--merge` and reruns know it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Plan {
    pub scene: PathBuf,
    /// `--set` overrides common to all cases.
    pub sets: Vec<String>,
    pub variations: Vec<Variation>,
}

/// One case: its index in the cross product and its (key, value) assignments.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Case {
    pub index: usize,
    pub values: Vec<(String, String)>,
}

impl Plan {
    /// Whether this plan holds every case of `earlier` and more of the same kind: the same
    /// scene, `--set` and varied keys, each variation's earlier values among its own (a
    /// finer level added to a finished study). A case's folder depends on its overrides
    /// alone, so the earlier cases' folders stay this plan's.
    pub fn extends(&self, earlier: &Plan) -> bool {
        self.scene == earlier.scene
            && self.sets == earlier.sets
            && self.variations.len() == earlier.variations.len()
            && (self.variations.iter().zip(&earlier.variations)).all(|(now, then)| {
                now.keys == then.keys && then.options.iter().all(|o| now.options.contains(o))
            })
    }

    /// Checks that no key is varied twice.
    pub fn validate(&self) -> Result<(), String> {
        let keys = self.keys();
        if let Some(k) = (0..keys.len()).find(|k| keys[..*k].contains(&keys[*k])) {
            return Err(format!("key `{}` is varied twice", keys[k]));
        }
        Ok(())
    }

    /// The varied keys in the order of the `--vary` options.
    pub fn keys(&self) -> Vec<String> {
        self.variations
            .iter()
            .flat_map(|v| v.keys.iter().cloned())
            .collect()
    }

    /// The cross product of the variations, the first outermost (one case without any).
    pub fn cases(&self) -> Vec<Case> {
        let mut cases = vec![Vec::new()];
        for variation in &self.variations {
            cases = cases
                .into_iter()
                .flat_map(|prefix: Vec<(String, String)>| {
                    variation.options.iter().map(move |option| {
                        let mut values = prefix.clone();
                        values.extend(variation.keys.iter().cloned().zip(option.iter().cloned()));
                        values
                    })
                })
                .collect();
        }
        cases
            .into_iter()
            .enumerate()
            .map(|(index, values)| Case { index, values })
            .collect()
    }

    /// The `--set` list of a case: no VTK frames (a scene or `--set output.frame_every=N`
    /// may ask for them), a history row every step (the force measures integrate and time
    /// the rows; `--set output.history_every=N` thins them), the plan's fixed overrides, then
    /// the case's values.
    pub fn overrides(&self, case: &Case) -> Vec<String> {
        ["output.frame_every=0", "output.history_every=1"]
            .into_iter()
            .map(String::from)
            .chain(self.sets.iter().cloned())
            .chain(case.values.iter().map(|(k, v)| format!("{k}={v}")))
            .collect()
    }

    /// The case's folder name: `case-` and a 64-bit FNV-1a hash of the scene's file name and
    /// the case's overrides, so it stays the same when variations are added or reordered.
    pub fn folder(&self, case: &Case) -> String {
        let scene = self
            .scene
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let mut sets = self.overrides(case);
        sets.sort();
        let text = std::iter::once(scene)
            .chain(sets)
            .collect::<Vec<_>>()
            .join("\n");
        format!("case-{:016x}", fnv1a(text.as_bytes()))
    }
}

/// 64-bit FNV-1a: a hash that does not change between Rust versions or machines.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf29ce484222325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x100000001b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: a study takes a finer level in its own folder. Reference: the plans themselves:
    /// a value added to a variation extends the plan; a value dropped, another key, another
    /// `--set` or another scene does not.
    #[test]
    fn a_plan_with_a_level_more_extends_the_earlier() {
        let plan = |values: &str, sets: &[&str]| Plan {
            scene: PathBuf::from("models/block_on_plate.toml"),
            sets: sets.iter().map(|s| s.to_string()).collect(),
            variations: vec![parse_variation(values).unwrap()],
        };
        let earlier = plan("body.plate.mesh.nx,body.plate.mesh.ny=40,4;80,8", &[]);
        let finer = plan(
            "body.plate.mesh.nx,body.plate.mesh.ny=40,4;80,8;160,16",
            &[],
        );
        assert!(finer.extends(&earlier));
        assert!(earlier.extends(&earlier));
        assert!(!earlier.extends(&finer));
        let other_key = plan("body.plate.mesh.nx=40,80,160", &[]);
        assert!(!other_key.extends(&earlier));
        let other_set = plan(
            "body.plate.mesh.nx,body.plate.mesh.ny=40,4;80,8;160,16",
            &["analysis.end_time=1e-5"],
        );
        assert!(!other_set.extends(&earlier));
    }

    #[test]
    fn parses_single_zipped_and_array_values() {
        let v = parse_variation("analysis.dt=0.01, 0.005,0.0025").unwrap();
        assert_eq!(v.options, [["0.01"], ["0.005"], ["0.0025"]]);
        let v = parse_variation("body.a.mesh.n,analysis.dt=14,0.005;28,0.0025").unwrap();
        assert_eq!(v.keys, ["body.a.mesh.n", "analysis.dt"]);
        assert_eq!(v.options, [["14", "0.005"], ["28", "0.0025"]]);
        let v = parse_variation("body.b.velocity=[0,-1],[0, -2]").unwrap();
        assert_eq!(v.options, [["[0,-1]"], ["[0, -2]"]]);
    }

    #[test]
    fn malformed_variations_and_shards_are_errors() {
        assert!(parse_variation("analysis.dt").is_err());
        assert!(parse_variation("analysis.dt=").is_err());
        assert!(parse_variation("analysis.dt=0.1,,0.2").is_err());
        assert!(parse_variation("a,b=1,2;3").is_err());
        assert!(parse_variation("a,a=1,2").is_err());
        assert!(parse_variation("a..b=1").is_err());
        assert_eq!(parse_shard("1/3"), Ok((1, 3)));
        for bad in ["3/3", "1", "a/2", "0/0", "-1/2"] {
            assert!(parse_shard(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn cases_are_the_cross_product_with_stable_folders() {
        let plan = Plan {
            scene: "models/two_bars.toml".into(),
            sets: vec![],
            variations: vec![
                parse_variation("analysis.integrator=average,hu").unwrap(),
                parse_variation("analysis.dt=0.01,0.005,0.0025").unwrap(),
            ],
        };
        let cases = plan.cases();
        assert_eq!(cases.len(), 6);
        assert_eq!(cases[4].values[0].1, "hu");
        assert_eq!(cases[4].values[1].1, "0.005");
        // the folder does not depend on the order of the variations
        let swapped = Plan {
            variations: vec![plan.variations[1].clone(), plan.variations[0].clone()],
            ..plan.clone()
        };
        let a: std::collections::BTreeSet<_> = cases.iter().map(|c| plan.folder(c)).collect();
        let b: std::collections::BTreeSet<_> =
            swapped.cases().iter().map(|c| swapped.folder(c)).collect();
        assert_eq!(a.len(), 6);
        assert_eq!(a, b);
    }
}
