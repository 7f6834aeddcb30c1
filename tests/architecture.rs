//! The module order stated in src/lib.rs, checked on the source: a `crate::` path to a module
//! of the same or a higher layer fails, and so does an import cycle of any length among the
//! children of a module (folder modules and their mod.rs included); files stay within 700
//! code lines and functions within 120 lines.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers of src/lib.rs, from the ground up: a module may use only lower layers.
const LAYERS: [&[&str]; 10] = [
    &["profile", "reference", "mesh", "output", "ale", "curve"],
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

/// The text of a file without its `#[cfg(test)]` items (wherever they sit: code after a
/// test module counts), with its comments removed and the characters inside string and
/// character literals replaced by `_` (newlines kept, so line numbers hold): braces in a
/// `format!` string or a `'{'` no longer count, and a line of a multi-line string is still a
/// line of code.
fn code(path: &Path) -> String {
    without_tests(&strip(&std::fs::read_to_string(path).unwrap()))
}

/// `code` (stripped already) with each `#[cfg(test)]` item blanked, newlines kept: the
/// attribute, and what follows it to the end of its item, a `;` (`mod tests;`) or the brace
/// that closes the item's first one (`mod tests { .. }`, a test-only `fn` or `impl`).
fn without_tests(code: &str) -> String {
    let mut out: Vec<char> = code.chars().collect();
    let attribute: Vec<char> = "#[cfg(test)]".chars().collect();
    let mut i = 0;
    while i + attribute.len() <= out.len() {
        if out[i..i + attribute.len()] != attribute[..] {
            i += 1;
            continue;
        }
        let (mut j, mut depth) = (i + attribute.len(), 0usize);
        while j < out.len() {
            match out[j] {
                ';' if depth == 0 => break,
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        break;
                    }
                }
                _ => {}
            }
            j += 1;
        }
        let end = (j + 1).min(out.len());
        for c in &mut out[i..end] {
            if *c != '\n' {
                *c = ' ';
            }
        }
        i = end;
    }
    out.into_iter().collect()
}

/// See [`code`].
fn strip(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let blank = |c: char| if c == '\n' { '\n' } else { '_' };
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < chars.len() && chars[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            i += 2;
            while i < chars.len() && !(chars[i] == '*' && chars.get(i + 1) == Some(&'/')) {
                if chars[i] == '\n' {
                    out.push('\n');
                }
                i += 1;
            }
            i += 2;
        } else if c == 'r' && (next == Some('"') || next == Some('#')) && raw_string_at(&chars, i) {
            // r"..." or r#"..."#: ends at a quote followed by as many hashes
            let hashes = chars[i + 1..].iter().take_while(|c| **c == '#').count();
            out.push('"');
            i += 2 + hashes;
            while i < chars.len() {
                let closes =
                    chars[i] == '"' && (0..hashes).all(|k| chars.get(i + 1 + k) == Some(&'#'));
                if closes {
                    break;
                }
                out.push(blank(chars[i]));
                i += 1;
            }
            out.push('"');
            i += 1 + hashes;
        } else if c == '"' {
            out.push('"');
            i += 1;
            while i < chars.len() && chars[i] != '"' {
                if chars[i] == '\\' {
                    out.push('_');
                    i += 1;
                }
                if i < chars.len() {
                    out.push(blank(chars[i]));
                    i += 1;
                }
            }
            out.push('"');
            i += 1;
        } else if c == '\'' && char_literal_at(&chars, i) {
            // 'x' or '\n': a lifetime ('a) has no closing quote after one character
            let end = if next == Some('\\') {
                i + 3 + chars[i + 3..].iter().position(|c| *c == '\'').unwrap_or(0)
            } else {
                i + 2
            };
            out.push_str("'_'");
            i = end + 1;
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

/// Whether a raw string literal starts at `chars[i]` (an `r` that begins a token).
fn raw_string_at(chars: &[char], i: usize) -> bool {
    let starts_token = i == 0 || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '_');
    let hashes = chars[i + 1..].iter().take_while(|c| **c == '#').count();
    starts_token && chars.get(i + 1 + hashes) == Some(&'"')
}

/// Whether a character literal (not a lifetime) starts at the quote `chars[i]`.
fn char_literal_at(chars: &[char], i: usize) -> bool {
    match chars.get(i + 1) {
        Some('\\') => true,
        Some(_) => chars.get(i + 2) == Some(&'\''),
        None => false,
    }
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
        violations.extend(upward_uses(
            &module,
            &code(path),
            &path.display().to_string(),
        ));
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

/// The uses of `code`, a file `name` of the top module `module`, of a module of its own or a
/// higher layer.
fn upward_uses(module: &str, code: &str, name: &str) -> Vec<String> {
    let own = layer(module).unwrap_or_else(|| panic!("{module} is in no layer of lib.rs"));
    let mut violations = Vec::new();
    for used in crate_paths(code) {
        if used == module {
            continue;
        }
        let theirs = layer(&used).unwrap_or_else(|| panic!("{used} is in no layer"));
        if theirs >= own {
            violations.push(format!("{name} (layer {own}) uses {used} (layer {theirs})"));
        }
    }
    violations
}

/// Goal: the layer check and the test-code cut can fail. Setup: planted files: a `contact`
/// file that names the scene after a test module (where the cut at the first
/// `#[cfg(test)]` used to hide `contact::surface_nodes(model: &scene::Model)`), the same
/// use inside a test module, and a lower-layer use. Reference: the layers.
#[test]
fn a_planted_upward_use_is_found_wherever_it_sits() {
    let planted = "use crate::element::Voigt;\n\
        #[cfg(test)]\nmod tests {\n    use crate::scene::Model;\n    fn f() { let s = \"}\"; }\n}\n\
        pub fn surface_nodes(model: &crate::scene::Model) -> usize { 0 }\n";
    let found = upward_uses("contact", &without_tests(&strip(planted)), "planted.rs");
    assert_eq!(found, ["planted.rs (layer 3) uses scene (layer 4)"]);
    let inside_tests = "#[cfg(test)]\nmod tests {\n    use crate::scene::Model;\n}\n";
    assert!(upward_uses("contact", &without_tests(&strip(inside_tests)), "t.rs").is_empty());
    let test_file_module = "#[cfg(test)]\nmod testing;\nfn g(m: &crate::analysis::Summary) {}\n";
    let found = upward_uses("element", &without_tests(&strip(test_file_module)), "e.rs");
    assert_eq!(found, ["e.rs (layer 1) uses analysis (layer 7)"]);
    // line numbers hold: the cut keeps every newline
    assert_eq!(
        without_tests(&strip(planted)).lines().count(),
        planted.lines().count()
    );
}

/// Goal: the cycle search finds a planted cycle of three and none in a chain. Setup: two
/// planted graphs of files. Reference: the edges as written.
#[test]
fn a_planted_cycle_is_found() {
    let graph = |edges: &[(&str, &str)]| {
        let mut g: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
        for (a, b) in edges {
            g.entry(PathBuf::from(a))
                .or_default()
                .insert(PathBuf::from(b));
        }
        g
    };
    let search = |g: &BTreeMap<PathBuf, BTreeSet<PathBuf>>| {
        let (mut path, mut finished, mut cycles) = (Vec::new(), BTreeSet::new(), Vec::new());
        for node in g.keys() {
            find_cycles(node, g, &mut path, &mut finished, &mut cycles);
        }
        cycles
    };
    let cycle = graph(&[("a", "b"), ("b", "c"), ("c", "a"), ("c", "d")]);
    assert_eq!(search(&cycle), ["a -> b -> c -> a"]);
    let chain = graph(&[("a", "b"), ("b", "c"), ("a", "c")]);
    assert!(search(&chain).is_empty());
}

/// The module path of a file under src/: `analysis::steppers::stable` for
/// src/analysis/steppers/stable.rs, `analysis::steppers::explicit` for
/// src/analysis/steppers/explicit/mod.rs (a folder module is its mod.rs).
fn module_path(path: &Path) -> Vec<String> {
    let rel = path.strip_prefix("src").unwrap().with_extension("");
    let mut segments: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().to_string())
        .collect();
    if segments.last().is_some_and(|s| s == "mod") {
        segments.pop();
    }
    segments
}

/// Whether the module `path` has a file: src/PATH.rs or src/PATH/mod.rs.
fn module_exists(path: &[String]) -> bool {
    let base = path.iter().fold(PathBuf::from("src"), |p, s| p.join(s));
    !path.is_empty() && (base.with_extension("rs").is_file() || base.join("mod.rs").is_file())
}

/// The paths that follow a `crate::` or `super::` at the start of `rest`, as segments: one
/// path, or one per member of a `{...}` group (its first level).
fn paths_after(rest: &str) -> Vec<Vec<String>> {
    let word = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut prefix = Vec::new();
    let mut at = rest;
    loop {
        let name = word(at);
        let after = &at[name.len()..];
        if name.is_empty() {
            break;
        }
        if let Some(next) = after.strip_prefix("::") {
            prefix.push(name);
            at = next;
        } else {
            prefix.push(name);
            return vec![prefix];
        }
    }
    if let Some(group) = at.strip_prefix('{') {
        let inner = &group[..group.find('}').unwrap_or(group.len())];
        return inner
            .split(',')
            .map(|member| {
                let mut path = prefix.clone();
                path.extend(
                    member
                        .trim()
                        .split("::")
                        .map(word)
                        .take_while(|s| !s.is_empty()),
                );
                path
            })
            .collect();
    }
    vec![prefix]
}

/// The modules a file at module path `own` names through `crate::` and `super::` paths:
/// each path's longest prefix that is a module with a file.
fn named_modules(own: &[String], code: &str) -> BTreeSet<Vec<String>> {
    let mut out = BTreeSet::new();
    let mut from = 0;
    while let Some(found) = code[from..]
        .find("crate::")
        .into_iter()
        .chain(code[from..].find("super::"))
        .min()
    {
        let start = from + found;
        from = start + 1;
        // only at the start of a path: not the `super::` of a `super::super::` already read
        let before = code[..start].chars().last();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
            continue;
        }
        let (mut base, mut rest) = (Vec::new(), &code[start..]);
        if let Some(r) = rest.strip_prefix("crate::") {
            rest = r;
        } else {
            base = own.to_vec();
            while let Some(r) = rest.strip_prefix("super::") {
                base.pop();
                rest = r;
            }
        }
        for path in paths_after(rest) {
            let full: Vec<String> = base.iter().cloned().chain(path).collect();
            if let Some(k) = (1..=full.len()).rev().find(|k| module_exists(&full[..*k])) {
                out.insert(full[..k].to_vec());
            }
        }
    }
    out
}

/// Goal: the modules of every module use each other one way: no cycle of any length among
/// the children of one module, folder modules (their mod.rs) included as sources and as
/// targets. Setup: the `crate::` and `super::` paths of every file under src/ but lib.rs and
/// main.rs (the top level is the layers' test); a path from module A to module B is an edge
/// between the two children of their lowest common ancestor that hold A and B (a module
/// naming its own ancestor or descendant is its parent's or child's business, not a
/// sibling's). Reference: a dependency graph without cycles, found by depth-first search (a
/// back edge closes a cycle, reported with its modules).
#[test]
fn no_import_cycle_of_any_length_among_a_modules_children() {
    let mut files = Vec::new();
    sources(Path::new("src"), &mut files);
    let mut edges: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
    let as_node = |path: &[String]| PathBuf::from(path.join("::"));
    for path in &files {
        let own = module_path(path);
        if own.len() == 1 && (own[0] == "lib" || own[0] == "main") {
            continue;
        }
        for target in named_modules(&own, &code(path)) {
            let common = own.iter().zip(&target).take_while(|(a, b)| a == b).count();
            if common == own.len() || common == target.len() || common == 0 {
                continue;
            }
            edges
                .entry(as_node(&own[..=common]))
                .or_default()
                .insert(as_node(&target[..=common]));
        }
    }
    let mut cycles = Vec::new();
    let mut finished = BTreeSet::new();
    for start in edges.keys() {
        let mut path = Vec::new();
        find_cycles(start, &edges, &mut path, &mut finished, &mut cycles);
    }
    assert!(cycles.is_empty(), "{cycles:#?}");
}

/// Goal: the module graph of the test above sees folder modules. Setup: the module paths of
/// a folder module's mod.rs and of files beside and inside it, and the modules their
/// `super::` and `crate::` paths name. Reference: src/analysis/steppers/explicit/mod.rs is the
/// module `analysis::steppers::explicit`, the target of `super::explicit::Levels` from
/// src/analysis/steppers/stable.rs.
#[test]
fn folder_modules_are_sources_and_targets_of_the_graph() {
    let folder = module_path(Path::new("src/analysis/steppers/explicit/mod.rs"));
    assert_eq!(folder, ["analysis", "steppers", "explicit"]);
    let stable = module_path(Path::new("src/analysis/steppers/stable.rs"));
    let named = named_modules(
        &stable,
        "use super::explicit::Levels;\nuse super::clock::{Clock, Step};",
    );
    assert!(named.contains(&folder), "{named:?}");
    let inside = module_path(Path::new("src/analysis/steppers/explicit/start.rs"));
    let named = named_modules(&inside, "use super::super::stable::checked_step;");
    assert!(named.contains(&stable), "{named:?}");
    let named = named_modules(&folder, "use crate::{analysis::steppers::stable, contact};");
    assert!(named.contains(&stable), "{named:?}");
}

/// A file's code lines: the lines outside `#[cfg(test)]` items that hold code (blank lines
/// and comments not counted).
fn code_lines(path: &Path) -> usize {
    code(path).lines().filter(|l| !l.trim().is_empty()).count()
}

/// The functions of a file's code (outside `#[cfg(test)]` items) and their lengths in lines, from
/// the line of `fn` to the line of the closing brace.
fn function_lengths(code: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = code.lines().collect();
    let mut out = Vec::new();
    let mut k = 0;
    while k < lines.len() {
        let trimmed = lines[k].trim_start();
        let words: Vec<&str> = trimmed.split_whitespace().collect();
        let at = words.iter().position(|w| *w == "fn");
        let qualifiers = ["pub", "const", "async", "unsafe", "extern", "default"];
        let declares = at.is_some_and(|i| {
            words[..i]
                .iter()
                .all(|w| qualifiers.contains(w) || w.starts_with("pub(") || w.starts_with('"'))
        });
        if !declares {
            k += 1;
            continue;
        }
        let name: String = words[at.unwrap() + 1]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let (mut depth, mut opened, mut end) = (0i64, false, None);
        'scan: for (j, line) in lines.iter().enumerate().skip(k) {
            for c in line.chars() {
                match c {
                    '{' => {
                        depth += 1;
                        opened = true;
                    }
                    '}' => depth -= 1,
                    ';' if !opened && depth == 0 => break 'scan,
                    _ => {}
                }
                if opened && depth == 0 {
                    end = Some(j);
                    break 'scan;
                }
            }
        }
        match end {
            Some(j) => {
                out.push((name, k + 1, j - k + 1));
                k = j + 1;
            }
            None => k += 1,
        }
    }
    out
}

/// Goal: a reader holds a file of 700 lines and a function of 120 (docs: DESIGN.md, layout):
/// longer ones are split by phase or concept. Setup: every file under src/, its code outside
/// `#[cfg(test)]` items without comments and blank lines; every function there from its `fn` line
/// to its closing brace. Reference: the two limits.
#[test]
fn files_and_functions_stay_within_what_a_reader_holds() {
    const FILE_LINES: usize = 700;
    const FUNCTION_LINES: usize = 120;
    let mut files = Vec::new();
    sources(Path::new("src"), &mut files);
    let mut violations = Vec::new();
    for path in &files {
        let lines = code_lines(path);
        if lines > FILE_LINES {
            violations.push(format!("{}: {lines} code lines", path.display()));
        }
        for (name, line, length) in function_lengths(&code(path)) {
            if length > FUNCTION_LINES {
                violations.push(format!(
                    "{}:{line}: fn {name} is {length} lines",
                    path.display()
                ));
            }
        }
    }
    assert!(violations.is_empty(), "{violations:#?}");
}

/// Goal: the measures of the test above count what they say. Setup: a made-up file with a
/// comment, a blank line, a string holding braces and a `//`, a char literal `'{'`, a
/// lifetime, and two functions. Reference: counted by hand.
#[test]
fn code_lines_and_function_lengths_are_counted_by_hand() {
    let text = "// a comment\n\nfn a<'x>(s: &'x str) -> char {\n    let t = \"{ // }\";\n    '{'\n}\n/// doc\npub(crate) fn b() {}\n";
    let code = strip(text);
    assert_eq!(code.lines().filter(|l| !l.trim().is_empty()).count(), 5);
    let lengths = function_lengths(&code);
    assert_eq!(
        lengths,
        vec![("a".to_string(), 3, 4), ("b".to_string(), 8, 1)]
    );
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
/// status, the errors) and the units of its columns on the ground, the steppers on it, the set-up checks (`check`,
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
            "summary" | "units" => 0,
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
            ("units", 0),
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
