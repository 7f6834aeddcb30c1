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
//! Quads given clockwise are reordered counter-clockwise. mshio discards node tags when they are
//! dense (max - min + 1 = count); they are then taken as consecutive in file order, as Gmsh
//! writes them.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::Path;

use mshio::{ElementType, MshFile, MshParserError};

use super::plane::quad_area;
use super::{Cells, Mesh, MeshError};

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
    let raw = RawMesh::collect(&msh).map_err(|reason| MeshError::Content {
        path: file.clone(),
        reason,
    })?;
    raw.into_mesh(&names)
        .map_err(|reason| MeshError::Content { path: file, reason })
}

/// One element as read: Gmsh tag, node tags, physical groups of its entity.
struct RawElement<const N: usize> {
    tag: u64,
    nodes: [u64; N],
    groups: Vec<Group>,
}

/// The file's content before renumbering.
struct RawMesh {
    coords: HashMap<u64, [f64; 3]>,
    quads: Vec<RawElement<4>>,
    lines: Vec<RawElement<2>>,
    points: Vec<RawElement<1>>,
}

impl RawMesh {
    fn collect(msh: &MshFile<u64, i32, f64>) -> Result<RawMesh, String> {
        let groups = entity_groups(msh);
        let mut raw = RawMesh {
            coords: node_coords(msh),
            quads: Vec::new(),
            lines: Vec::new(),
            points: Vec::new(),
        };
        let blocks = msh
            .data
            .elements
            .iter()
            .flat_map(|e| e.element_blocks.iter());
        for block in blocks {
            let entity = (block.entity_dim, block.entity_tag);
            let groups: Vec<Group> = groups.get(&entity).cloned().unwrap_or_default();
            for element in &block.elements {
                let tag = element.element_tag;
                let groups = groups.clone();
                match block.element_type {
                    ElementType::Qua4 => raw.quads.push(RawElement {
                        tag,
                        nodes: node_tags(element)?,
                        groups,
                    }),
                    ElementType::Lin2 => raw.lines.push(RawElement {
                        tag,
                        nodes: node_tags(element)?,
                        groups,
                    }),
                    ElementType::Pnt => raw.points.push(RawElement {
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

    fn into_mesh(self, names: &HashMap<Group, String>) -> Result<Mesh, String> {
        let rods = self.quads.is_empty();
        if rods && self.lines.is_empty() {
            return Err("no 4-node quadrangles (type 3) or 2-node lines (type 1)".to_string());
        }
        let used = self.used_nodes(rods);
        let ids: BTreeMap<u64, usize> = used.iter().enumerate().map(|(k, &tag)| (tag, k)).collect();
        let nodes = self.planar_nodes(&used)?;
        let cells = if rods {
            Cells::Rod2(
                self.lines
                    .iter()
                    .map(|l| l.nodes.map(|t| ids[&t]))
                    .collect(),
            )
        } else {
            Cells::Quad4(self.counter_clockwise_quads(&ids, &nodes)?)
        };
        let mut mesh = Mesh::new(nodes, cells);
        let mut sets = SetNames::default();
        if rods {
            self.add_rod_groups(&mut mesh, &mut sets, &ids, names)?;
        } else {
            self.add_quad_groups(&mut mesh, &mut sets, &ids, names)?;
        }
        self.add_point_groups(&mut mesh, &mut sets, &ids, names)?;
        Ok(mesh)
    }

    /// Node tags used by the cells, increasing.
    fn used_nodes(&self, rods: bool) -> Vec<u64> {
        let tags: BTreeSet<u64> = if rods {
            self.lines.iter().flat_map(|l| l.nodes).collect()
        } else {
            self.quads.iter().flat_map(|q| q.nodes).collect()
        };
        tags.into_iter().collect()
    }

    /// [x, y] of the used nodes; every node must exist and lie in the plane z = 0.
    fn planar_nodes(&self, used: &[u64]) -> Result<Vec<[f64; 2]>, String> {
        let mut points = Vec::with_capacity(used.len());
        for tag in used {
            let p = self
                .coords
                .get(tag)
                .ok_or_else(|| format!("an element uses node {tag}, which $Nodes lacks"))?;
            points.push(*p);
        }
        let extent = points
            .iter()
            .flat_map(|p| [p[0].abs(), p[1].abs()])
            .fold(0.0, f64::max)
            .max(1e-300);
        if let Some((tag, p)) = used
            .iter()
            .zip(&points)
            .find(|(_, p)| p[2].abs() > 1e-9 * extent)
        {
            return Err(format!(
                "node {tag} has z = {}; impact reads 2D meshes in the plane z = 0",
                p[2]
            ));
        }
        Ok(points.iter().map(|p| [p[0], p[1]]).collect())
    }

    fn counter_clockwise_quads(
        &self,
        ids: &BTreeMap<u64, usize>,
        nodes: &[[f64; 2]],
    ) -> Result<Vec<[usize; 4]>, String> {
        let scale = nodes
            .iter()
            .flat_map(|p| [p[0].abs(), p[1].abs()])
            .fold(0.0, f64::max);
        let mut quads = Vec::with_capacity(self.quads.len());
        for quad in &self.quads {
            let [a, b, c, d] = quad.nodes.map(|t| ids[&t]);
            let area = quad_area([a, b, c, d].map(|n| nodes[n]));
            if area.abs() <= 1e-14 * scale * scale {
                return Err(format!("quadrangle {} has zero area", quad.tag));
            }
            quads.push(if area > 0.0 {
                [a, b, c, d]
            } else {
                [a, d, c, b]
            });
        }
        Ok(quads)
    }

    /// 2D groups -> element sets; 1D groups -> edge sets oriented by their quads (+ node sets).
    fn add_quad_groups(
        &self,
        mesh: &mut Mesh,
        sets: &mut SetNames,
        ids: &BTreeMap<u64, usize>,
        names: &HashMap<Group, String>,
    ) -> Result<(), String> {
        for (group, elements) in members(&self.quads, 2) {
            let name = sets.claim_elements(group_name(names, group))?;
            mesh.element_sets.insert(name, elements);
        }
        let owner = quad_edge_owners(mesh);
        for (group, lines) in members(&self.lines, 1) {
            let name = sets.claim_nodes(group_name(names, group))?;
            let mut edges = Vec::with_capacity(lines.len());
            for k in lines {
                let line = &self.lines[k];
                let [a, b] = line.nodes.map(|t| ids.get(&t).copied());
                let edge = match (a, b) {
                    (Some(a), Some(b)) => owner.get(&(a.min(b), a.max(b))),
                    _ => None,
                };
                match edge {
                    Some((edge, 1)) => edges.push(*edge),
                    Some(_) => {
                        return Err(format!(
                            "line {} of group \"{name}\" lies inside the body",
                            line.tag
                        ));
                    }
                    None => {
                        return Err(format!(
                            "line {} of group \"{name}\" is not a quadrangle side",
                            line.tag
                        ));
                    }
                }
            }
            mesh.add_edge_set(&name, edges);
        }
        Ok(())
    }

    /// 1D groups of a rod mesh -> element sets + node sets.
    fn add_rod_groups(
        &self,
        mesh: &mut Mesh,
        sets: &mut SetNames,
        ids: &BTreeMap<u64, usize>,
        names: &HashMap<Group, String>,
    ) -> Result<(), String> {
        for (group, elements) in members(&self.lines, 1) {
            let name = group_name(names, group);
            let element_name = sets.claim_elements(name.clone())?;
            let node_name = sets.claim_nodes(name)?;
            let nodes = elements
                .iter()
                .flat_map(|&k| self.lines[k].nodes.map(|t| ids[&t]))
                .collect();
            mesh.element_sets.insert(element_name, elements);
            mesh.add_node_set(&node_name, nodes);
        }
        Ok(())
    }

    /// 0D groups -> node sets.
    fn add_point_groups(
        &self,
        mesh: &mut Mesh,
        sets: &mut SetNames,
        ids: &BTreeMap<u64, usize>,
        names: &HashMap<Group, String>,
    ) -> Result<(), String> {
        for (group, points) in members(&self.points, 0) {
            let name = sets.claim_nodes(group_name(names, group))?;
            let mut nodes = Vec::with_capacity(points.len());
            for k in points {
                let tag = self.points[k].nodes[0];
                let id = ids.get(&tag).ok_or_else(|| {
                    format!("point group \"{name}\" holds node {tag}, which no cell uses")
                })?;
                nodes.push(*id);
            }
            mesh.add_node_set(&name, nodes);
        }
        Ok(())
    }
}

/// Set names handed out so far; a second group with the same name would overwrite a set.
#[derive(Default)]
struct SetNames {
    elements: BTreeSet<String>,
    nodes: BTreeSet<String>,
}

impl SetNames {
    fn claim_elements(&mut self, name: String) -> Result<String, String> {
        if name == "all" || !self.elements.insert(name.clone()) {
            return Err(format!(
                "two element sets named \"{name}\" (\"all\" is reserved); rename a physical group"
            ));
        }
        Ok(name)
    }

    fn claim_nodes(&mut self, name: String) -> Result<String, String> {
        if !self.nodes.insert(name.clone()) {
            return Err(format!(
                "two node sets named \"{name}\"; rename a physical group"
            ));
        }
        Ok(name)
    }
}

/// Physical groups of dimension `dim` -> indices of their elements, in file order.
fn members<const N: usize>(elements: &[RawElement<N>], dim: i32) -> BTreeMap<Group, Vec<usize>> {
    let mut groups: BTreeMap<Group, Vec<usize>> = BTreeMap::new();
    for (k, element) in elements.iter().enumerate() {
        for &group in element.groups.iter().filter(|g| g.0 == dim) {
            groups.entry(group).or_default().push(k);
        }
    }
    groups
}

/// Unordered quad side -> (side as the quad runs it, number of quads sharing it).
fn quad_edge_owners(mesh: &Mesh) -> HashMap<(usize, usize), ([usize; 2], usize)> {
    let mut owners = HashMap::new();
    let Cells::Quad4(quads) = &mesh.cells else {
        return owners;
    };
    for q in quads {
        for k in 0..4 {
            let edge = [q[k], q[(k + 1) % 4]];
            owners
                .entry((edge[0].min(edge[1]), edge[0].max(edge[1])))
                .or_insert((edge, 0))
                .1 += 1;
        }
    }
    owners
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
