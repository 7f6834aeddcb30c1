//! A mesh as a file gives it (points and cells by the file's numbers, each cell in the named
//! groups the file puts it in), turned into a [`Mesh`]: what the Gmsh and VTK readers share.
//!
//! Legend
//! ```text
//! tag          a file's number of a node or cell (Gmsh: its tag; VTK: its index from 0)
//! group        a named set of cells or nodes (Gmsh: a physical group; VTK: one value of an
//!              integer data array)
//! quads        -> Quad4, counter-clockwise (clockwise ones reordered); a quad with a repeated
//!              node or zero area is an error
//! lines        with quads: a group's lines -> edge set (each line oriented as in the quad
//!              that owns it, body on the left; a line must be a boundary side) + node set;
//!              lines without a group are ignored.
//!              Without quads the lines are rods: a group's lines -> element set + node set
//! points       (Gmsh points, VTK vertices) a group's -> node set; each node must be used
//! node groups  (VTK point data) a group's nodes that the cells use -> node set
//! nodes        those the cells use, renumbered 0..n by increasing tag; z must be 0
//! boundary     a quad mesh also gets the edge set (and node set) `boundary`: every boundary
//!              edge, counter-clockwise, chained head to tail; unless a group has that name
//! ```

use std::collections::{BTreeMap, BTreeSet, HashMap};

use super::plane::quad_area;
use super::{Cells, Mesh, chain_order};

/// One cell as read: the file's number, its nodes (by tag) and its groups (indices into
/// [`TaggedMesh::groups`]).
pub(super) struct TaggedCell<const N: usize> {
    pub tag: u64,
    pub nodes: [u64; N],
    pub groups: Vec<usize>,
}

/// How messages name what the file holds ("quadrangle 7" in Gmsh, "cell 7" in VTK).
pub(super) struct Words {
    pub quad: &'static str,
    pub line: &'static str,
    pub node: &'static str,
    /// Where the file lists the nodes ("$Nodes").
    pub nodes_section: &'static str,
    /// What to do when two groups give one set name.
    pub rename: &'static str,
    /// The cell kinds read, as the file format names them.
    pub kinds: &'static str,
}

/// A file's content before renumbering.
pub(super) struct TaggedMesh {
    pub coords: HashMap<u64, [f64; 3]>,
    pub quads: Vec<TaggedCell<4>>,
    pub lines: Vec<TaggedCell<2>>,
    pub points: Vec<TaggedCell<1>>,
    /// The groups' set names.
    pub groups: Vec<String>,
    /// Groups given per node (group -> node tags); nodes no cell uses are left out.
    pub node_groups: BTreeMap<usize, Vec<u64>>,
    pub words: Words,
}

impl TaggedMesh {
    /// The mesh, its nodes renumbered and its sets named (see the module legend). Errors
    /// name the cell or node by the file's number.
    pub(super) fn into_mesh(self) -> Result<Mesh, String> {
        let rods = self.quads.is_empty();
        if rods && self.lines.is_empty() {
            return Err(format!("no {}", self.words.kinds));
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
            self.add_rod_groups(&mut mesh, &mut sets, &ids)?;
        } else {
            self.add_quad_groups(&mut mesh, &mut sets, &ids)?;
        }
        self.add_point_groups(&mut mesh, &mut sets, &ids)?;
        self.add_node_groups(&mut mesh, &mut sets, &ids)?;
        if !rods && !sets.nodes.contains("boundary") {
            mesh.add_edge_set("boundary", chain_order(mesh.boundary_edges()));
        }
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
        let words = &self.words;
        let mut points = Vec::with_capacity(used.len());
        for tag in used {
            let p = self.coords.get(tag).ok_or_else(|| {
                format!(
                    "a cell uses {} {tag}, which {} lacks",
                    words.node, words.nodes_section
                )
            })?;
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
            .find(|(_, p)| p[2].is_nan() || p[2].abs() > 1e-9 * extent)
        {
            return Err(format!(
                "{} {tag} has z = {}; impact reads 2D meshes in the plane z = 0",
                words.node, p[2]
            ));
        }
        Ok(points.iter().map(|p| [p[0], p[1]]).collect())
    }

    /// The quads counter-clockwise; a repeated node or a zero area is an error.
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
            let name = format!("{} {}", self.words.quad, quad.tag);
            if let Some(k) = (1..4).find(|&k| quad.nodes[..k].contains(&quad.nodes[k])) {
                return Err(format!(
                    "{name} is degenerate: it lists {} {} twice",
                    self.words.node, quad.nodes[k]
                ));
            }
            let [a, b, c, d] = quad.nodes.map(|t| ids[&t]);
            let area = quad_area([a, b, c, d].map(|n| nodes[n]));
            if area.abs() <= 1e-14 * scale * scale {
                return Err(format!("{name} is degenerate: it has zero area"));
            }
            quads.push(if area > 0.0 {
                [a, b, c, d]
            } else {
                [a, d, c, b]
            });
        }
        Ok(quads)
    }

    /// Quad groups -> element sets; line groups -> edge sets oriented by their quads (+ node
    /// sets).
    fn add_quad_groups(
        &self,
        mesh: &mut Mesh,
        sets: &mut SetNames,
        ids: &BTreeMap<u64, usize>,
    ) -> Result<(), String> {
        for (group, elements) in members(&self.quads) {
            let name = sets.claim_elements(&self.groups[group], &self.words)?;
            mesh.element_sets.insert(name, elements);
        }
        let owner = quad_edge_owners(mesh);
        for (group, lines) in members(&self.lines) {
            let name = sets.claim_nodes(&self.groups[group], &self.words)?;
            let mut edges = Vec::with_capacity(lines.len());
            for k in lines {
                let line = &self.lines[k];
                let [a, b] = line.nodes.map(|t| ids.get(&t).copied());
                let edge = match (a, b) {
                    (Some(a), Some(b)) => owner.get(&(a.min(b), a.max(b))),
                    _ => None,
                };
                let what = format!("{} {} of group \"{name}\"", self.words.line, line.tag);
                match edge {
                    Some((edge, 1)) => edges.push(*edge),
                    Some(_) => return Err(format!("{what} lies inside the body")),
                    None => return Err(format!("{what} is not a {} side", self.words.quad)),
                }
            }
            mesh.add_edge_set(&name, edges);
        }
        Ok(())
    }

    /// Line groups of a rod mesh -> element sets + node sets.
    fn add_rod_groups(
        &self,
        mesh: &mut Mesh,
        sets: &mut SetNames,
        ids: &BTreeMap<u64, usize>,
    ) -> Result<(), String> {
        for (group, elements) in members(&self.lines) {
            let name = &self.groups[group];
            let element_name = sets.claim_elements(name, &self.words)?;
            let node_name = sets.claim_nodes(name, &self.words)?;
            let nodes = elements
                .iter()
                .flat_map(|&k| self.lines[k].nodes.map(|t| ids[&t]))
                .collect();
            mesh.element_sets.insert(element_name, elements);
            mesh.add_node_set(&node_name, nodes);
        }
        Ok(())
    }

    /// Point groups -> node sets; every node must be used by a cell.
    fn add_point_groups(
        &self,
        mesh: &mut Mesh,
        sets: &mut SetNames,
        ids: &BTreeMap<u64, usize>,
    ) -> Result<(), String> {
        for (group, points) in members(&self.points) {
            let name = sets.claim_nodes(&self.groups[group], &self.words)?;
            let mut nodes = Vec::with_capacity(points.len());
            for k in points {
                let tag = self.points[k].nodes[0];
                let id = ids.get(&tag).ok_or_else(|| {
                    format!(
                        "point group \"{name}\" holds {} {tag}, which no cell uses",
                        self.words.node
                    )
                })?;
                nodes.push(*id);
            }
            mesh.add_node_set(&name, nodes);
        }
        Ok(())
    }

    /// Node groups -> node sets of the nodes the cells use (a group of unused nodes only
    /// gives no set).
    fn add_node_groups(
        &self,
        mesh: &mut Mesh,
        sets: &mut SetNames,
        ids: &BTreeMap<u64, usize>,
    ) -> Result<(), String> {
        for (&group, tags) in &self.node_groups {
            let nodes: Vec<usize> = tags.iter().filter_map(|t| ids.get(t).copied()).collect();
            if nodes.is_empty() {
                continue;
            }
            let name = sets.claim_nodes(&self.groups[group], &self.words)?;
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
    fn claim_elements(&mut self, name: &str, words: &Words) -> Result<String, String> {
        if name == "all" || !self.elements.insert(name.to_string()) {
            return Err(format!(
                "two element sets named \"{name}\" (\"all\" is reserved); {}",
                words.rename
            ));
        }
        Ok(name.to_string())
    }

    fn claim_nodes(&mut self, name: &str, words: &Words) -> Result<String, String> {
        if !self.nodes.insert(name.to_string()) {
            return Err(format!("two node sets named \"{name}\"; {}", words.rename));
        }
        Ok(name.to_string())
    }
}

/// Groups -> indices of their cells, in file order.
fn members<const N: usize>(cells: &[TaggedCell<N>]) -> BTreeMap<usize, Vec<usize>> {
    let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (k, cell) in cells.iter().enumerate() {
        for &group in &cell.groups {
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
