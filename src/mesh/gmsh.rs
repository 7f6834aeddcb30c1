//! Gmsh MSH 4.1 import (ASCII; binary files parse too) through the `mshio` crate.
//!
//! Legend
//! ```text
//! cells          4-node quadrangles (type 3) -> Quad4; if the file has none, 2-node lines
//!                (type 1) -> Rod2. Points (type 15) only feed node sets. Other types: error.
//! nodes          the nodes the cells use, renumbered 0..n in increasing Gmsh tag; z dropped
//!                (it must be 0)
//! 2D group       -> element set
//! 1D group       quads: -> edge set (each line oriented as in the quad that owns it, body on
//!                the left) + node set; rods: -> element set + node set
//! 0D group       -> node set
//! group name     from $PhysicalNames, else "physical_<tag>"
//! ```
//! Quads given clockwise are reordered counter-clockwise; one with a repeated node or zero area
//! is an error. A quad mesh also gets the edge set `boundary` (unless a group has that name).
//! The sets are built as for VTK files (src/mesh/tagged.rs). mshio discards node tags when they
//! are dense (max - min + 1 = count); they are then taken as consecutive in file order, as Gmsh
//! writes them.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::Path;

use mshio::{ElementType, MshFile, MshParserError};

use super::tagged::{TaggedCell, TaggedMesh, Words};
use super::{Mesh, MeshError};

/// (dimension, physical tag) of a physical group.
type Group = (i32, i32);

/// Reads a mesh from a Gmsh MSH 4.1 file (see the module legend).
pub fn read(path: &Path) -> Result<Mesh, MeshError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| MeshError::Io {
        path: file.clone(),
        reason: e.to_string(),
    })?;
    check_binary_sizes(&file, &bytes)?;
    let msh = mshio::parse_msh_bytes(&bytes).map_err(|e| parse_error(&file, &bytes, &e))?;
    let names = physical_names(&file, &bytes)?;
    collect(&msh, &names)
        .and_then(TaggedMesh::into_mesh)
        .map_err(|reason| MeshError::Content { path: file, reason })
}

/// The file's nodes and elements, each element in the physical groups of its entity.
fn collect(
    msh: &MshFile<u64, i32, f64>,
    names: &HashMap<Group, String>,
) -> Result<TaggedMesh, String> {
    let entities = entity_groups(msh);
    // every physical group an entity names, numbered in (dimension, tag) order
    let groups: BTreeSet<Group> = entities.values().flatten().copied().collect();
    let index: HashMap<Group, usize> = groups.iter().enumerate().map(|(k, g)| (*g, k)).collect();
    let mut raw = TaggedMesh {
        coords: node_coords(msh),
        quads: Vec::new(),
        lines: Vec::new(),
        points: Vec::new(),
        groups: groups.iter().map(|g| group_name(names, *g)).collect(),
        node_groups: BTreeMap::new(),
        words: Words {
            quad: "quadrangle",
            line: "line",
            node: "node",
            nodes_section: "$Nodes",
            rename: "rename a physical group",
            kinds: "4-node quadrangles (type 3) or 2-node lines (type 1)",
        },
    };
    let blocks = msh
        .data
        .elements
        .iter()
        .flat_map(|e| e.element_blocks.iter());
    for block in blocks {
        let entity = (block.entity_dim, block.entity_tag);
        let groups: Vec<usize> = entities
            .get(&entity)
            .map(|gs| gs.iter().map(|g| index[g]).collect())
            .unwrap_or_default();
        for element in &block.elements {
            let tag = element.element_tag;
            let groups = groups.clone();
            match block.element_type {
                ElementType::Qua4 => raw.quads.push(TaggedCell {
                    tag,
                    nodes: node_tags(element)?,
                    groups,
                }),
                ElementType::Lin2 => raw.lines.push(TaggedCell {
                    tag,
                    nodes: node_tags(element)?,
                    groups,
                }),
                ElementType::Pnt => raw.points.push(TaggedCell {
                    tag,
                    nodes: node_tags(element)?,
                    groups,
                }),
                other => {
                    return Err(format!(
                        "element {tag} has type {other:?}; impact reads 4-node quadrangles \
                         (type 3), 2-node lines (type 1) and points (type 15)"
                    ));
                }
            }
        }
    }
    Ok(raw)
}

fn group_name(names: &HashMap<Group, String>, group: Group) -> String {
    names
        .get(&group)
        .cloned()
        .unwrap_or_else(|| format!("physical_{}", group.1))
}

fn node_tags<const N: usize>(element: &mshio::Element<u64>) -> Result<[u64; N], String> {
    element.nodes.as_slice().try_into().map_err(|_| {
        format!(
            "element {} has {} nodes, expected {N}",
            element.element_tag,
            element.nodes.len()
        )
    })
}

/// (entity dimension, entity tag) -> its physical groups.
fn entity_groups(msh: &MshFile<u64, i32, f64>) -> HashMap<(i32, i32), Vec<Group>> {
    let mut groups = HashMap::new();
    let Some(entities) = &msh.data.entities else {
        return groups;
    };
    let mut add = |dim: i32, tag: i32, physical: &[i32]| {
        groups.insert((dim, tag), physical.iter().map(|&p| (dim, p)).collect());
    };
    entities
        .points
        .iter()
        .for_each(|e| add(0, e.tag, &e.physical_tags));
    entities
        .curves
        .iter()
        .for_each(|e| add(1, e.tag, &e.physical_tags));
    entities
        .surfaces
        .iter()
        .for_each(|e| add(2, e.tag, &e.physical_tags));
    groups
}

/// Node tag -> [x, y, z]. Dense tags, which mshio does not keep, run consecutively.
fn node_coords(msh: &MshFile<u64, i32, f64>) -> HashMap<u64, [f64; 3]> {
    let mut coords = HashMap::new();
    let Some(nodes) = &msh.data.nodes else {
        return coords;
    };
    let mut next_tag = nodes.min_node_tag;
    for block in &nodes.node_blocks {
        match &block.node_tags {
            Some(tags) => {
                for (&tag, &k) in tags {
                    let n = &block.nodes[k];
                    coords.insert(tag, [n.x, n.y, n.z]);
                }
            }
            None => {
                for n in &block.nodes {
                    coords.insert(next_tag, [n.x, n.y, n.z]);
                    next_tag += 1;
                }
            }
        }
    }
    coords
}

/// `$PhysicalNames` (mshio skips the section): (dimension, tag) -> name.
fn physical_names(file: &str, bytes: &[u8]) -> Result<HashMap<Group, String>, MeshError> {
    let mut names = HashMap::new();
    let mut lines = bytes
        .split(|&b| b == b'\n')
        .map(|l| String::from_utf8_lossy(l).trim().to_string());
    let Some(start) = lines.position(|l| l == "$PhysicalNames") else {
        return Ok(names);
    };
    let error = |line: usize, reason: String| MeshError::Parse {
        path: file.to_string(),
        line,
        reason,
    };
    let count_line = start + 2;
    let count: usize = lines
        .next()
        .and_then(|l| l.parse().ok())
        .ok_or_else(|| error(count_line, "expected the number of physical names".into()))?;
    for k in 0..count {
        let line = count_line + 1 + k;
        let text = lines.next().unwrap_or_default();
        let (group, name) = parse_physical_name(&text).ok_or_else(|| {
            error(
                line,
                format!("expected `dimension tag \"name\"`, got `{text}`"),
            )
        })?;
        names.insert(group, name);
    }
    Ok(names)
}

/// `dim tag "name"` -> ((dim, tag), name).
fn parse_physical_name(text: &str) -> Option<(Group, String)> {
    let mut parts = text.splitn(3, char::is_whitespace);
    let dim = parts.next()?.parse().ok()?;
    let tag = parts.next()?.parse().ok()?;
    let name = parts.next()?.trim().strip_prefix('"')?.strip_suffix('"')?;
    Some(((dim, tag), name.to_string()))
}

/// mshio panics on binary files whose size_t is not 1, 2, 4, 8 or 16 bytes: reject them first.
fn check_binary_sizes(file: &str, bytes: &[u8]) -> Result<(), MeshError> {
    let mut lines = bytes
        .split(|&b| b == b'\n')
        .map(|l| String::from_utf8_lossy(l).trim().to_string());
    if lines.next().as_deref() != Some("$MeshFormat") {
        return Ok(());
    }
    let header = lines.next().unwrap_or_default();
    let fields: Vec<&str> = header.split_whitespace().collect();
    if let [_, "1", size] = fields.as_slice()
        && !["1", "2", "4", "8", "16"].contains(size)
    {
        let reason = format!("binary size_t of {size} bytes is not supported");
        return Err(MeshError::Parse {
            path: file.to_string(),
            line: 2,
            reason,
        });
    }
    Ok(())
}

/// A parse error with the line where mshio stopped and its chain of contexts.
fn parse_error(file: &str, bytes: &[u8], error: &MshParserError<&[u8]>) -> MeshError {
    let line = error
        .backtrace
        .first()
        .map(|(rest, _)| line_of(bytes, rest))
        .unwrap_or(0);
    let kinds: Vec<String> = error
        .filter_msh_errors()
        .map(|(_, kind)| kind.to_string())
        .collect();
    let reason = match kinds.split_first() {
        Some((innermost, outer)) if !outer.is_empty() => {
            let contexts: Vec<&str> = outer.iter().rev().map(String::as_str).collect();
            format!("{}: {innermost}", contexts.join(" > "))
        }
        Some((innermost, _)) => innermost.clone(),
        None => "not a valid MSH 4.1 file".to_string(),
    };
    MeshError::Parse {
        path: file.to_string(),
        line,
        reason,
    }
}

/// 1-based line of the first non-blank byte of `rest`, a tail of `bytes`.
fn line_of(bytes: &[u8], rest: &[u8]) -> usize {
    let start = bytes.as_ptr() as usize;
    let offset = (rest.as_ptr() as usize)
        .saturating_sub(start)
        .min(bytes.len());
    let blank = bytes[offset..]
        .iter()
        .take_while(|b| b.is_ascii_whitespace())
        .count();
    let offset = (offset + blank).min(bytes.len());
    1 + bytes[..offset].iter().filter(|&&b| b == b'\n').count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Cells;
    use crate::mesh::plane::quad_area;

    fn data(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name)
    }

    /// Two quads (the second written clockwise), named groups body (2D), bottom and top (1D,
    /// top written against the body's orientation), corner (0D), and an unused node.
    #[test]
    fn reads_two_quads_with_named_groups() {
        let mesh = read(&data("two_quads.msh")).unwrap();
        assert_eq!(
            mesh.nodes,
            vec![
                [0.0, 0.0],
                [2.0, 0.0],
                [2.0, 1.0],
                [0.0, 1.0],
                [1.0, 0.0],
                [1.0, 1.0]
            ]
        );
        let Cells::Quad4(quads) = &mesh.cells else {
            panic!("quads expected")
        };
        assert_eq!(quads, &vec![[0, 4, 5, 3], [4, 1, 2, 5]]);
        for q in quads {
            assert!(quad_area(q.map(|n| mesh.nodes[n])) > 0.0);
        }
        assert_eq!(mesh.element_sets["all"], vec![0, 1]);
        assert_eq!(mesh.element_sets["body"], vec![0, 1]);
        assert_eq!(mesh.edge_sets["bottom"], vec![[0, 4], [4, 1]]);
        assert_eq!(mesh.edge_sets["top"], vec![[5, 3], [2, 5]]);
        assert_eq!(mesh.node_sets["top"], vec![2, 3, 5]);
        assert_eq!(mesh.node_sets["corner"], vec![0]);
        let boundary = mesh.boundary_edges();
        for e in mesh.edge_sets.values().flatten() {
            assert!(boundary.contains(e), "{e:?} is not a ccw boundary edge");
        }
        // no group is named `boundary`: the whole boundary, counter-clockwise, chained
        assert_eq!(
            mesh.edge_sets["boundary"],
            vec![[3, 0], [0, 4], [4, 1], [1, 2], [2, 5], [5, 3]]
        );
        assert_eq!(mesh.node_sets["boundary"], vec![0, 1, 2, 3, 4, 5]);
    }

    /// Goal: a quadrangle that lists a node twice is refused naming it (it has an area, so
    /// only the node check catches it). Setup: two_quads.msh with quadrangle 7's third node
    /// replaced by its second. Reference: the edit.
    #[test]
    fn quadrangle_with_a_repeated_node_is_refused() {
        let text = std::fs::read_to_string(data("two_quads.msh")).unwrap();
        let edited = text.replace("7 5 6 3 2\n", "7 5 6 6 2\n");
        assert_ne!(edited, text);
        let path = std::env::temp_dir().join(format!("repeated-{}.msh", std::process::id()));
        std::fs::write(&path, edited).unwrap();
        let err = read(&path).unwrap_err();
        std::fs::remove_file(&path).unwrap();
        assert!(
            err.to_string()
                .contains("quadrangle 7 is degenerate: it lists node 6 twice"),
            "{err}"
        );
    }

    /// Lines only: rods; dense node tags; an unnamed 1D group and a named point.
    #[test]
    fn reads_rods_when_there_are_no_quads() {
        let mesh = read(&data("rods.msh")).unwrap();
        assert_eq!(mesh.nodes, vec![[0.0, 0.0], [1.0, 0.0], [0.5, 0.0]]);
        assert_eq!(mesh.cells, Cells::Rod2(vec![[0, 2], [2, 1]]));
        assert_eq!(mesh.element_sets["physical_7"], vec![0, 1]);
        assert_eq!(mesh.node_sets["physical_7"], vec![0, 1, 2]);
        assert_eq!(mesh.node_sets["fixed"], vec![0]);
    }

    /// A broken element line is a parse error naming that line.
    #[test]
    fn malformed_file_reports_the_line() {
        match read(&data("malformed.msh")) {
            Err(MeshError::Parse { line, reason, path }) => {
                assert_eq!(line, 59, "{reason}");
                assert!(path.ends_with("malformed.msh"));
                assert!(reason.contains("element"), "{reason}");
            }
            other => panic!("expected a parse error, got {other:?}"),
        }
    }

    #[test]
    fn missing_file_is_an_io_error_naming_the_path() {
        let err = read(&data("no_such_file.msh")).unwrap_err();
        assert!(matches!(err, MeshError::Io { .. }));
        assert!(err.to_string().contains("no_such_file.msh"));
    }

    /// A file with only points has no cells to read.
    #[test]
    fn file_without_quads_or_lines_is_a_content_error() {
        let err = read(&data("points_only.msh")).unwrap_err();
        assert!(matches!(err, MeshError::Content { .. }), "{err}");
    }

    #[test]
    fn physical_name_lines_parse() {
        assert_eq!(
            parse_physical_name("2 1 \"my body\""),
            Some(((2, 1), "my body".to_string()))
        );
        assert_eq!(parse_physical_name("1 3"), None);
        assert_eq!(parse_physical_name("x 3 \"a\""), None);
    }
}
