//! VTK mesh import through the `vtkio` crate: a legacy `.vtk` file (ASCII or binary) or an
//! XML `.vtu` file whose arrays are inline (ascii or base64, optionally compressed), holding
//! an unstructured grid of one piece.
//!
//! Legend
//! ```text
//! cells        VTK_QUAD (9) -> Quad4; if the file has none, VTK_LINE (3) -> Rod2; VTK_VERTEX
//!              (1) only feeds node sets; any other type is an error naming it and the cell
//! nodes        the points the cells use, renumbered 0..n in file order; z must be 0
//! sets         each integer array named in `sets` (point or cell data, one component):
//!              value v -> set NAME_v. Cell data: quads -> element set; with quads, lines ->
//!              edge set (+ node set; a line must be a boundary side), with rods, lines ->
//!              element set + node set; vertices -> node set. Point data -> node set
//! boundary     a quad mesh also gets the edge set (and node set) `boundary`
//! numbers      messages name cells and points by their index in the file, from 0
//! ```
//! Quads given clockwise are reordered counter-clockwise; one with a repeated point or zero
//! area is an error. The sets are built as for Gmsh files (src/mesh/tagged.rs).
//!
//! A `.vtu` whose arrays are appended raw binary (`<AppendedData encoding="raw">`, the
//! default of ParaView's Save Data and of VTK's writers) is refused before vtkio sees it:
//! vtkio cannot decode raw appended data. The message says how to save the file again.
//! Legacy files with VTK's sized type names (`vtktypeint32`, as meshio writes them) are read
//! with the classic names (`int`) vtkio knows.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use vtkio::Vtk;
use vtkio::model::{
    Attribute, Attributes, CellType, DataSet, IOBuffer, Piece, UnstructuredGridPiece, VertexNumbers,
};

use super::tagged::{TaggedCell, TaggedMesh, Words};
use super::{Mesh, MeshError};

/// Reads a mesh from a legacy .vtk or an XML .vtu file; `sets` names the integer point or
/// cell data arrays whose values become sets (see the module legend).
pub fn read(path: &Path, sets: &[String]) -> Result<Mesh, MeshError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| MeshError::Io {
        path: file.clone(),
        reason: e.to_string(),
    })?;
    let content = |reason: String| MeshError::Content {
        path: file.clone(),
        reason,
    };
    let vtk = parse(&bytes, path).map_err(content)?;
    let tagged = collect(vtk, sets).map_err(content)?;
    tagged.into_mesh().map_err(content)
}

/// The file parsed by vtkio, legacy or XML by its first bytes.
fn parse(bytes: &[u8], path: &Path) -> Result<Vtk, String> {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    let text = &bytes[start..];
    if text.starts_with(b"# vtk DataFile") {
        return Vtk::parse_legacy_be(&legacy_type_names(text)[..])
            .map_err(|e| format!("not a legacy VTK file that vtkio reads ({e})"));
    }
    if !text.starts_with(b"<") {
        return Err(
            "not a VTK file: a legacy one starts with `# vtk DataFile`, an XML one with `<`"
                .to_string(),
        );
    }
    if appended_raw(text) {
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        let stem = path.file_stem().unwrap_or_default().to_string_lossy();
        return Err(format!(
            "its arrays are appended raw binary (<AppendedData encoding=\"raw\">, ParaView's \
             default), which impact cannot read; save it again from ParaView with File > Save \
             Data, Data Mode \"Ascii\" or \"Binary\" (or \"Appended\" with \"Encode Appended \
             Data\" checked), or convert it with meshio: `meshio convert {name} {stem}_inline.vtu` \
             (inline base64 arrays)"
        ));
    }
    Vtk::parse_xml(text).map_err(|e| format!("not an XML VTK file that vtkio reads ({e})"))
}

/// The legacy file with VTK's sized type names (`vtktypeint32`, which meshio writes for data
/// arrays) replaced by the classic names vtkio parses (`int`); the OFFSETS and CONNECTIVITY
/// lines keep `vtktypeint64`, which vtkio expects there. A type name ends its line.
fn legacy_type_names(text: &[u8]) -> std::borrow::Cow<'_, [u8]> {
    const NAMES: [(&[u8], &[u8]); 9] = [
        (b"vtktypeint8", b"char"),
        (b"vtktypeuint8", b"unsigned_char"),
        (b"vtktypeint16", b"short"),
        (b"vtktypeint32", b"int"),
        (b"vtktypeuint32", b"unsigned_int"),
        (b"vtktypeint64", b"long"),
        (b"vtktypeuint64", b"unsigned_long"),
        (b"vtktypefloat32", b"float"),
        (b"vtktypefloat64", b"double"),
    ];
    let renamed = |line: &[u8]| -> Option<Vec<u8>> {
        if line.starts_with(b"OFFSETS") || line.starts_with(b"CONNECTIVITY") {
            return None;
        }
        let body = line.trim_ascii_end();
        let (sized, classic) = NAMES.iter().find(|(sized, _)| {
            body.ends_with(sized) && body[..body.len() - sized.len()].ends_with(b" ")
        })?;
        let mut out = body[..body.len() - sized.len()].to_vec();
        out.extend_from_slice(classic);
        out.extend_from_slice(&line[body.len()..]);
        Some(out)
    };
    if !text
        .split(|&b| b == b'\n')
        .any(|line| renamed(line).is_some())
    {
        return std::borrow::Cow::Borrowed(text);
    }
    let lines: Vec<Vec<u8>> = text
        .split(|&b| b == b'\n')
        .map(|line| renamed(line).unwrap_or_else(|| line.to_vec()))
        .collect();
    std::borrow::Cow::Owned(lines.join(&b'\n'))
}

/// Whether an XML file's `<AppendedData>` block holds raw binary.
fn appended_raw(text: &[u8]) -> bool {
    let marker = b"<AppendedData";
    let Some(at) = text.windows(marker.len()).position(|w| w == marker) else {
        return false;
    };
    let tag: Vec<u8> = text[at + marker.len()..]
        .iter()
        .take_while(|&&b| b != b'>')
        .copied()
        .collect();
    let tag = String::from_utf8_lossy(&tag);
    let encoding = tag
        .split_once("encoding")
        .and_then(|(_, rest)| rest.trim_start().strip_prefix('='))
        .map(|rest| rest.trim_start().trim_start_matches(['"', '\'']))
        .map(|value| {
            value
                .split(['"', '\''])
                .next()
                .unwrap_or_default()
                .to_string()
        });
    // VTK reads appended data without an encoding attribute as raw
    encoding.is_none_or(|e| e == "raw")
}

/// The grid's points, cells and sets, not yet checked or renumbered.
fn collect(vtk: Vtk, sets: &[String]) -> Result<TaggedMesh, String> {
    let piece = one_inline_piece(vtk)?;
    let coords: Vec<f64> = piece
        .points
        .cast_into()
        .ok_or("the points are not numbers vtkio converts")?;
    if !coords.len().is_multiple_of(3) {
        return Err(format!(
            "the points array has {} values, not 3 per point",
            coords.len()
        ));
    }
    let points = coords.len() / 3;
    let cells = cell_nodes(piece.cells.cell_verts, piece.cells.types.len())?;
    let tags = set_tags(&piece.data, sets, points, cells.len())?;
    let mut tagged = TaggedMesh {
        coords: (0..points)
            .map(|k| {
                (
                    k as u64,
                    [coords[3 * k], coords[3 * k + 1], coords[3 * k + 2]],
                )
            })
            .collect::<HashMap<_, _>>(),
        quads: Vec::new(),
        lines: Vec::new(),
        points: Vec::new(),
        groups: tags.groups.names,
        node_groups: tags.node_groups,
        words: Words {
            quad: "cell",
            line: "cell",
            node: "point",
            nodes_section: "the points",
            rename: "one value of an array may tag lines, vertices or points, not two of them",
            kinds: "quads (VTK_QUAD, 9) or lines (VTK_LINE, 3)",
        },
    };
    let typed = cells.into_iter().zip(piece.cells.types);
    for (k, ((nodes, kind), groups)) in typed.zip(tags.cell_groups).enumerate() {
        add_cell(&mut tagged, k, (nodes, kind, groups), points)?;
    }
    Ok(tagged)
}

/// The one inline piece of an unstructured grid; other data sets are refused with the ParaView
/// filter that converts them.
fn one_inline_piece(vtk: Vtk) -> Result<UnstructuredGridPiece, String> {
    match vtk.data {
        DataSet::UnstructuredGrid { mut pieces, .. } => match (pieces.len(), pieces.pop()) {
            (1, Some(Piece::Inline(piece))) => Ok(*piece),
            (n, _) => Err(format!(
                "the grid has {n} pieces, or pieces in other files; impact reads one inline piece"
            )),
        },
        other => {
            let kind = match other {
                DataSet::ImageData { .. } => "image data",
                DataSet::StructuredGrid { .. } => "a structured grid",
                DataSet::RectilinearGrid { .. } => "a rectilinear grid",
                DataSet::PolyData { .. } => "poly data",
                _ => "field data",
            };
            Err(format!(
                "the file holds {kind}; impact reads an unstructured grid \
                 (in ParaView: Filters > Clean to Grid, then save as .vtu or .vtk)"
            ))
        }
    }
}

/// The sets that the scene's `sets` arrays give: per cell its set indices, per set its points.
struct SetTags {
    groups: Groups,
    cell_groups: Vec<Vec<usize>>,
    node_groups: BTreeMap<usize, Vec<u64>>,
}

/// Each distinct value of each named integer point or cell array becomes a set.
fn set_tags(
    data: &Attributes,
    sets: &[String],
    points: usize,
    cells: usize,
) -> Result<SetTags, String> {
    let mut tags = SetTags {
        groups: Groups::default(),
        cell_groups: vec![Vec::new(); cells],
        node_groups: BTreeMap::new(),
    };
    let mut seen = Vec::new();
    for name in sets {
        if seen.contains(&name) {
            continue;
        }
        seen.push(name);
        let on_points = integer_array(&data.point, name, points, "point")?;
        let on_cells = integer_array(&data.cell, name, cells, "cell")?;
        if on_points.is_none() && on_cells.is_none() {
            let mut known: Vec<&str> = (data.point.iter())
                .chain(&data.cell)
                .flat_map(array_names)
                .collect();
            known.sort_unstable();
            known.dedup();
            return Err(format!(
                "`sets` names \"{name}\", but the file has no point or cell data array of that \
                 name (arrays: {known:?})"
            ));
        }
        for (k, value) in on_points.into_iter().flatten().enumerate() {
            let group = tags.groups.index(name, "point", value);
            tags.node_groups.entry(group).or_default().push(k as u64);
        }
        for (k, value) in on_cells.into_iter().flatten().enumerate() {
            tags.cell_groups[k].push(tags.groups.index(name, "cell", value));
        }
    }
    Ok(tags)
}

/// Cell `k` (its points, VTK type and groups) as a quad, line or vertex of the mesh; its
/// points must exist (`points` of them) and match its type.
fn add_cell(
    tagged: &mut TaggedMesh,
    k: usize,
    (nodes, kind, groups): (Vec<u64>, CellType, Vec<usize>),
    points: usize,
) -> Result<(), String> {
    if let Some(&node) = nodes.iter().find(|&&n| n as usize >= points) {
        return Err(format!(
            "cell {k} uses point {node}, but the file has {points} points"
        ));
    }
    let tag = k as u64;
    let count = |n: usize| -> Result<(), String> {
        if nodes.len() == n {
            Ok(())
        } else {
            Err(format!(
                "cell {k} ({kind:?}) has {} points, expected {n}",
                nodes.len()
            ))
        }
    };
    match kind {
        CellType::Quad => {
            count(4)?;
            let nodes = [nodes[0], nodes[1], nodes[2], nodes[3]];
            tagged.quads.push(TaggedCell { tag, nodes, groups });
        }
        CellType::Line => {
            count(2)?;
            let nodes = [nodes[0], nodes[1]];
            tagged.lines.push(TaggedCell { tag, nodes, groups });
        }
        CellType::Vertex => {
            count(1)?;
            let nodes = [nodes[0]];
            tagged.points.push(TaggedCell { tag, nodes, groups });
        }
        other => {
            return Err(format!(
                "cell {k} has type {other:?} (VTK type {}); impact reads quads (VTK_QUAD, \
                 9), lines (VTK_LINE, 3) and vertices (VTK_VERTEX, 1)",
                other as u8
            ));
        }
    }
    Ok(())
}

/// The set names handed out: (array, point or cell, value) -> index.
#[derive(Default)]
struct Groups {
    index: HashMap<(String, &'static str, i64), usize>,
    names: Vec<String>,
}

impl Groups {
    fn index(&mut self, array: &str, section: &'static str, value: i64) -> usize {
        let next = self.names.len();
        let key = (array.to_string(), section, value);
        *self.index.entry(key).or_insert_with(|| {
            self.names.push(format!("{array}_{value}"));
            next
        })
    }
}

/// The point numbers of each cell; `types` cells are expected.
fn cell_nodes(numbers: VertexNumbers, types: usize) -> Result<Vec<Vec<u64>>, String> {
    let mut cells = Vec::with_capacity(types);
    match numbers {
        VertexNumbers::Legacy { vertices, .. } => {
            let mut rest = &vertices[..];
            while let Some((&n, tail)) = rest.split_first() {
                let n = n as usize;
                if tail.len() < n {
                    return Err(format!(
                        "cell {} lists more points than the file holds",
                        cells.len()
                    ));
                }
                cells.push(tail[..n].iter().map(|&v| v as u64).collect());
                rest = &tail[n..];
            }
        }
        VertexNumbers::XML {
            connectivity,
            mut offsets,
        } => {
            // legacy files of version 5 give the offsets with a leading 0
            if offsets.len() == types + 1 && offsets.first() == Some(&0) {
                offsets.remove(0);
            }
            let mut start = 0;
            for &end in &offsets {
                let end = usize::try_from(end).unwrap_or(usize::MAX);
                if end < start || end > connectivity.len() {
                    return Err(format!(
                        "the offset of cell {} is {end}, outside {start}..={}",
                        cells.len(),
                        connectivity.len()
                    ));
                }
                cells.push(connectivity[start..end].to_vec());
                start = end;
            }
        }
    }
    if cells.len() != types {
        return Err(format!(
            "the file lists {} cells but {types} cell types",
            cells.len()
        ));
    }
    Ok(cells)
}

/// The names of the arrays of an attribute (a field's arrays for a legacy FIELD).
fn array_names(attribute: &Attribute) -> Vec<&str> {
    match attribute {
        Attribute::DataArray(array) => vec![array.name.as_str()],
        Attribute::Field { data_array, .. } => data_array.iter().map(|a| a.name.as_str()).collect(),
    }
}

/// The values of the integer array `name` among `attributes` (None if there is none): one
/// component and `entries` values, else an error naming it and the `section`.
fn integer_array(
    attributes: &[Attribute],
    name: &str,
    entries: usize,
    section: &str,
) -> Result<Option<Vec<i64>>, String> {
    let found = attributes.iter().find_map(|a| match a {
        Attribute::DataArray(array) if array.name == name => Some((array.num_comp(), &array.data)),
        Attribute::DataArray(_) => None,
        Attribute::Field { data_array, .. } => data_array
            .iter()
            .find(|array| array.name == name)
            .map(|array| (array.num_comp(), &array.data)),
    });
    let Some((components, data)) = found else {
        return Ok(None);
    };
    let what = format!("{section} data array \"{name}\"");
    if matches!(data, IOBuffer::F32(_) | IOBuffer::F64(_) | IOBuffer::Bit(_)) {
        return Err(format!(
            "{what} holds {:?} values; sets come from integer arrays",
            data.scalar_type()
        ));
    }
    if components != 1 || data.len() != entries {
        return Err(format!(
            "{what} has {components} components and {} values; sets need 1 component, one \
             value per {section} ({entries})",
            data.len()
        ));
    }
    let values = data
        .cast_into::<i64>()
        .ok_or_else(|| format!("{what} holds values beyond the range of a 64-bit integer"))?;
    Ok(Some(values))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: raw appended data is recognized whatever the quoting, and only it (an encoding
    /// of base64 is read by vtkio; no encoding attribute means raw to VTK).
    #[test]
    fn appended_raw_is_recognized_by_its_encoding() {
        let file = |tag: &str| format!("<VTKFile><UnstructuredGrid/>{tag}_binary</VTKFile>");
        for raw in [
            "<AppendedData encoding=\"raw\">",
            "<AppendedData encoding = 'raw' >",
            "<AppendedData>",
        ] {
            assert!(appended_raw(file(raw).as_bytes()), "{raw}");
        }
        for other in ["<AppendedData encoding=\"base64\">", "<Piece/>"] {
            assert!(!appended_raw(file(other).as_bytes()), "{other}");
        }
    }

    /// Goal: VTK's sized type names at the end of a data array line become the classic ones;
    /// OFFSETS and CONNECTIVITY keep theirs, and other lines and bytes are unchanged.
    #[test]
    fn sized_type_names_become_classic_names() {
        let text = b"CELLS 2 8\nOFFSETS vtktypeint64\n0 4\nCONNECTIVITY vtktypeint64\n\
                     FIELD FieldData 2\nside 1 2 vtktypeint32\n\x00\x01\nx 3 1 vtktypefloat64\r\n";
        let out = legacy_type_names(text);
        assert_eq!(
            &out[..],
            &b"CELLS 2 8\nOFFSETS vtktypeint64\n0 4\nCONNECTIVITY vtktypeint64\n\
               FIELD FieldData 2\nside 1 2 int\n\x00\x01\nx 3 1 double\r\n"[..]
        );
        let classic = b"SCALARS side int 1\n";
        assert!(matches!(
            legacy_type_names(classic),
            std::borrow::Cow::Borrowed(_)
        ));
    }
}
