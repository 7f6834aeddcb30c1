//! `--set KEY=VALUE`: edits the parsed TOML before it is deserialized.
//!
//! KEY is a dotted path. A segment that meets an array of tables picks the element whose
//! `name` equals the segment (or, if the segment is a number, the element at that index):
//! `body.sphere.velocity=[0,-0.8]`, `analysis.dt=0.001`, `material.0.young=200`.
//! VALUE is parsed as a TOML value; if that fails it is taken as a string, so
//! `--set analysis.integrator=hu` needs no quotes. Missing tables along the path are created.

use toml::{Table, Value};

pub fn apply(table: &mut Table, assignment: &str) -> Result<(), String> {
    let (key, raw) = assignment.split_once('=').ok_or("expected KEY=VALUE")?;
    let value = parse_value(raw.trim());
    let segments: Vec<&str> = key.trim().split('.').collect();
    if segments.iter().any(|s| s.is_empty()) {
        return Err(format!("empty segment in key `{key}`"));
    }
    set(table, &segments, value, key)
}

fn parse_value(raw: &str) -> Value {
    format!("v = {raw}")
        .parse::<Table>()
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| Value::String(raw.to_string()))
}

fn set(table: &mut Table, segments: &[&str], value: Value, key: &str) -> Result<(), String> {
    let (first, rest) = segments.split_first().expect("non-empty path");
    if rest.is_empty() {
        table.insert(first.to_string(), value);
        return Ok(());
    }
    let entry = table
        .entry(first.to_string())
        .or_insert_with(|| Value::Table(Table::new()));
    match entry {
        Value::Table(inner) => set(inner, rest, value, key),
        Value::Array(items) => {
            let (selector, rest) = rest.split_first().expect("checked above");
            let names: Vec<String> = items
                .iter()
                .filter_map(|v| v.get("name").and_then(Value::as_str).map(str::to_string))
                .collect();
            let item = select(items, selector).ok_or_else(|| {
                format!(
                    "`{first}` has no entry named `{selector}` (entries: {})",
                    names.join(", ")
                )
            })?;
            if rest.is_empty() {
                *item = value;
                return Ok(());
            }
            match item {
                Value::Table(inner) => set(inner, rest, value, key),
                _ => Err(format!("`{first}.{selector}` is not a table")),
            }
        }
        _ => Err(format!("`{first}` is a value, not a table, in `{key}`")),
    }
}

fn select<'a>(items: &'a mut [Value], selector: &str) -> Option<&'a mut Value> {
    let by_name = items
        .iter()
        .position(|v| v.get("name").and_then(Value::as_str) == Some(selector));
    let index = by_name.or_else(|| selector.parse::<usize>().ok().filter(|i| *i < items.len()))?;
    items.get_mut(index)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> Table {
        "[analysis]\ndt = 0.01\n[[body]]\nname = \"sphere\"\nvelocity = [0.0, -3.0]\n[[body]]\nname = \"wall\"\n"
            .parse()
            .unwrap()
    }

    #[test]
    fn sets_nested_and_named_array_entries() {
        let mut t = scene();
        apply(&mut t, "analysis.dt=0.001").unwrap();
        apply(&mut t, "body.sphere.velocity=[0,-0.8]").unwrap();
        apply(&mut t, "body.1.material=steel").unwrap();
        assert_eq!(t["analysis"]["dt"].as_float(), Some(0.001));
        assert_eq!(t["body"][0]["velocity"][0].as_integer(), Some(0));
        assert_eq!(
            t["body"][0]["velocity"].as_array().unwrap()[1].as_float(),
            Some(-0.8)
        );
        assert_eq!(t["body"][1]["material"].as_str(), Some("steel"));
    }

    #[test]
    fn unknown_entry_and_malformed_assignment_are_errors() {
        let mut t = scene();
        let e = apply(&mut t, "body.cube.velocity=[0,0]").unwrap_err();
        assert!(e.contains("cube") && e.contains("sphere"), "{e}");
        assert!(apply(&mut t, "analysis.dt").is_err());
        assert!(apply(&mut t, "analysis..dt=1").is_err());
        assert!(apply(&mut t, "analysis.dt.x=1").is_err());
    }
}
