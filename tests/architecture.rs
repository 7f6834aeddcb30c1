//! The module order stated in src/lib.rs, checked on the source: a `crate::` path to a module
//! of the same or a higher layer fails, and so does a file-level import cycle of any length
//! inside a module.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers of src/lib.rs, from the ground up: a module may use only lower layers.
const LAYERS: [&[&str]; 10] = [
    &["profile", "reference", "mesh", "output"],
    &["element"],
    &["material", "kinematics"],
    &["contact", "solver", "integrator"],
    &["scene"],
    &["assembly"],
    &["buckling"],
    &["analysis"],
    &["sweep"],
    &["bench"],
];

fn layer(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a file without its `#[cfg(test)]` part and its comments.
fn code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let text = match text.find("#[cfg(test)]") {
        Some(cut) => &text[..cut],
        None => &text,
    };
    text.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The top-level module of a file under src/ (`analysis` for src/analysis/run/mod.rs).
fn module_of(path: &Path) -> String {
    let rel = path.strip_prefix("src").unwrap();
    let first = rel
        .components()
        .next()
        .unwrap()
        .as_os_str()
        .to_string_lossy();
    first.trim_end_matches(".rs").to_string()
}

/// The modules a file names through `crate::NAME` paths (in `use` lines and in paths).
fn crate_paths(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (i, _) in code.match_indices("crate::") {
        let rest = &code[i + "crate::".len()..];
        let name: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if !name.is_empty() {
            out.insert(name);
        }
        // `use crate::{a, b}` names several
        if rest.starts_with('{') {
            let inner = &rest[1..rest.find('}').unwrap_or(rest.len())];
            for part in inner.split(',') {
                let name: String = part
                    .trim()
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !name.is_empty() {
                    out.insert(name);
                }
            }
        }
    }
    out
}

/// Goal: dependencies flow one way, as src/lib.rs states. Setup: every file under src/
/// except lib.rs and main.rs (the binary sits above every layer). Reference: the layer list
/// above, which mirrors lib.rs; a module may name only modules of lower layers.
#[test]
fn modules_use_only_lower_layers() {
    let mut files = Vec::new();
    sources(Path::new("src"), &mut files);
    let mut violations = Vec::new();
    for path in &files {
        let module = module_of(path);
        if module == "lib" || module == "main" {
            continue;
        }
        let own = layer(&module).unwrap_or_else(|| panic!("{module} is in no layer of lib.rs"));
        for used in crate_paths(&code(path)) {
            if used == module {
                continue;
            }
            let theirs = layer(&used).unwrap_or_else(|| panic!("{used} is in no layer"));
            if theirs >= own {
                violations.push(format!(
                    "{} (layer {own}) uses {used} (layer {theirs})",
                    path.display()
                ));
            }
        }
    }
    assert!(violations.is_empty(), "{violations:#?}");
    // lib.rs states the same order
    let lib = std::fs::read_to_string("src/lib.rs").unwrap();
    for (k, modules) in LAYERS.iter().enumerate() {
        for m in *modules {
            assert!(lib.contains(m), "lib.rs does not name {m} (layer {k})");
        }
    }
}

/// Goal: the files of one module import each other without a cycle of any length (a
/// module's mod.rs, or the file that declares a folder's files, is their parent, not a
/// sibling). Setup: `super::NAME` and `crate::PATH::NAME` paths between the files of each
/// folder under src/, at any depth. Reference: a file-level import graph without cycles,
/// found by depth-first search (a back edge closes a cycle, reported with its files).
#[test]
fn no_import_cycle_of_any_length_among_a_modules_files() {
    let mut files = Vec::new();
    sources(Path::new("src"), &mut files);
    let mut edges: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
    for path in &files {
        let dir = path.parent().unwrap();
        if dir == Path::new("src") || path.file_stem().is_some_and(|s| s == "mod") {
            continue;
        }
        let module_path: Vec<String> = dir
            .strip_prefix("src")
            .unwrap()
            .components()
            .map(|c| c.as_os_str().to_string_lossy().to_string())
            .collect();
        let code = code(path);
        let mut siblings = BTreeSet::new();
        for prefix in [
            "super::".to_string(),
            format!("crate::{}::", module_path.join("::")),
        ] {
            for (i, _) in code.match_indices(prefix.as_str()) {
                let name: String = code[i + prefix.len()..]
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                let target = dir.join(format!("{name}.rs"));
                if target.exists() && &target != path && name != "mod" {
                    siblings.insert(target);
                }
            }
        }
        edges.insert(path.clone(), siblings);
    }
    let mut cycles = Vec::new();
    let mut finished = BTreeSet::new();
    for start in edges.keys() {
        let mut path = Vec::new();
        find_cycles(start, &edges, &mut path, &mut finished, &mut cycles);
    }
    assert!(cycles.is_empty(), "{cycles:#?}");
}

/// Depth-first search from `node` along `edges`: a target on the current `path` closes a
/// cycle, pushed to `cycles` as its files joined by arrows; `finished` holds the nodes whose
/// every path has been walked.
fn find_cycles(
    node: &PathBuf,
    edges: &BTreeMap<PathBuf, BTreeSet<PathBuf>>,
    path: &mut Vec<PathBuf>,
    finished: &mut BTreeSet<PathBuf>,
    cycles: &mut Vec<String>,
) {
    if finished.contains(node) {
        return;
    }
    if let Some(at) = path.iter().position(|p| p == node) {
        let mut cycle: Vec<String> = path[at..].iter().map(|p| p.display().to_string()).collect();
        cycle.push(node.display().to_string());
        cycles.push(cycle.join(" -> "));
        return;
    }
    path.push(node.clone());
    for next in edges.get(node).into_iter().flatten() {
        find_cycles(next, edges, path, finished, cycles);
    }
    path.pop();
    finished.insert(node.clone());
}

/// Goal: the analyses' rooms stand on each other one way: the summary (summary.json, the
/// status, the errors) on the ground, the steppers on it, the set-up checks (`check`,
/// `plausibility`) on those, the run scaffold above them, the entry (analysis/mod.rs) on
/// top; no stepper knows the scaffold that drives it. Setup: every file of src/analysis.
/// Reference: that order; a file may name only rooms below its own (its own room too).
#[test]
fn the_analysis_rooms_are_layered() {
    let room = |path: &Path| -> usize {
        let rel = path.strip_prefix("src/analysis").unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        match first.trim_end_matches(".rs") {
            "summary" => 0,
            "steppers" => 1,
            "check" | "plausibility" => 2,
            "run" => 3,
            "mod" => 4,
            other => panic!("src/analysis/{other} is in no room of this test"),
        }
    };
    let named = |code: &str, path: &Path| -> BTreeSet<usize> {
        let mut out = BTreeSet::new();
        for (name, level) in [
            ("summary", 0),
            ("steppers", 1),
            ("check", 2),
            ("plausibility", 2),
            ("run", 3),
        ] {
            let absolute = format!("crate::analysis::{name}");
            // `super::NAME` from a file directly under src/analysis or a folder's mod.rs,
            // `super::super::NAME` from another file of a folder
            let below = path.components().count() - 3;
            let depth = if path.file_stem().is_some_and(|s| s == "mod") {
                below.saturating_sub(1)
            } else {
                below
            };
            let relative = format!("{}{name}", "super::".repeat(depth + 1));
            let top_mod = path == Path::new("src/analysis/mod.rs");
            if code.contains(&absolute) || (!top_mod && code.contains(&relative)) {
                out.insert(level);
            }
        }
        out
    };
    let mut files = Vec::new();
    sources(Path::new("src/analysis"), &mut files);
    let mut violations = Vec::new();
    for path in &files {
        let own = room(path);
        for level in named(&code(path), path) {
            if level > own {
                violations.push(format!(
                    "{} (room {own}) names room {level}",
                    path.display()
                ));
            }
        }
    }
    assert!(violations.is_empty(), "{violations:#?}");
}
