//! The .vtu frame file: VTK's XML UnstructuredGrid with every array in one appended block of
//! raw binary data (the layout VTK's own writers use; ParaView, VTK, meshio and pyvista read it).
//!
//! Legend
//! ```text
//! header_type   UInt64
//! plain array   [byte count] then the bytes                         (little endian)
//! compressed    [blocks, block size, last block size (0: a full one), compressed size of
//!               each block] then the blocks: LZ4 block format (vtkLZ4DataCompressor) or
//!               zlib streams (vtkZLibDataCompressor), each block at most 32768 bytes raw
//! offset        where an array starts, counted from the byte after the `_` that opens
//!               the appended block
//! ```
//! A frame is made in two halves so that the stepping thread does the least: [`Payload::new`]
//! checks the grid and the fields and lays each array out as little-endian bytes (in parallel
//! over the arrays), and [`Payload::into_parts`] (on the series' writer thread) compresses them
//! and puts the XML header in front. vtkio, the VTK crate, writes only inline base64 arrays,
//! which cost ~100 ms per 1e5-element frame (docs/performance.md); this layout is written at
//! the speed of a copy. [`read_frame`] reads the files back (tests and tools).

use std::path::Path;

use rayon::prelude::*;

use super::OutputError;

/// All bodies merged into one grid with global node numbering; cells are the quads first, then the lines.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Grid {
    pub points: Vec<[f64; 2]>,
    pub quads: Vec<[usize; 4]>,
    pub lines: Vec<[usize; 2]>,
}

impl Grid {
    pub fn cells(&self) -> usize {
        self.quads.len() + self.lines.len()
    }

    /// Per point, the mean of `cell_values` (one per cell: quads, then lines) over the cells
    /// that hold the point, each cell counting once; zero at a point of no cell. The nodal
    /// (averaged) field ParaView's Cell Data to Point Data would give.
    pub fn cell_to_point_mean<const N: usize>(&self, cell_values: &[[f64; N]]) -> Vec<[f64; N]> {
        let mut sum = vec![[0.0; N]; self.points.len()];
        let mut count = vec![0usize; self.points.len()];
        let cells = self
            .quads
            .iter()
            .map(|q| &q[..])
            .chain(self.lines.iter().map(|l| &l[..]));
        for (nodes, value) in cells.zip(cell_values) {
            for &n in nodes {
                for (s, v) in sum[n].iter_mut().zip(value) {
                    *s += v;
                }
                count[n] += 1;
            }
        }
        for (s, c) in sum.iter_mut().zip(count) {
            if c > 0 {
                s.iter_mut().for_each(|x| *x /= c as f64);
            }
        }
        sum
    }
}

/// The `name="value"` pairs of a tag's text (after the element name, before `>`).
pub(crate) fn attributes(mut tag: &str) -> impl Iterator<Item = (&str, &str)> {
    std::iter::from_fn(move || {
        let (name, rest) = tag.split_once('=')?;
        let rest = rest.trim_start();
        let quote = rest.chars().next().filter(|c| *c == '"' || *c == '\'')?;
        let (value, rest) = rest[1..].split_once(quote)?;
        tag = rest;
        Some((name.trim(), value))
    })
}

/// Raw bytes per compression block (VTK's default).
const BLOCK: usize = 32768;

/// Where an array belongs in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Section {
    PointData,
    CellData,
    Points,
    Cells,
}

/// The scalar types written: Float64 fields, Int64 connectivity, offsets and integer fields
/// (ids), UInt8 cell types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scalar {
    Float64,
    Int64,
    UInt8,
}

impl Scalar {
    fn size(self) -> usize {
        match self {
            Scalar::Float64 | Scalar::Int64 => 8,
            Scalar::UInt8 => 1,
        }
    }

    fn from_name(name: &str) -> Option<Scalar> {
        match name {
            "Float64" => Some(Scalar::Float64),
            "Int64" => Some(Scalar::Int64),
            "UInt8" => Some(Scalar::UInt8),
            _ => None,
        }
    }
}

/// Compression of the arrays (ParaView reads all three).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Compression {
    #[default]
    None,
    Lz4,
    Zlib,
}

impl Compression {
    /// The VTKFile's `compressor` attribute.
    fn compressor(self) -> Option<&'static str> {
        match self {
            Compression::None => None,
            Compression::Lz4 => Some("vtkLZ4DataCompressor"),
            Compression::Zlib => Some("vtkZLibDataCompressor"),
        }
    }
}

/// One array of a frame, laid out as little-endian bytes.
#[derive(Debug)]
pub struct Array {
    pub section: Section,
    pub name: &'static str,
    pub scalar: Scalar,
    pub components: usize,
    bytes: Vec<u8>,
}

/// The values of one field, for [`Payload::new`]: rows of N components written as `width`
/// components (zero-padded: vectors get z = 0).
#[derive(Clone, Copy, Debug)]
pub enum Source<'a> {
    Pairs(&'a [[f64; 2]]),
    Sixes(&'a [[f64; 6]]),
    Singles(&'a [f64]),
    /// One integer per row, written as Int64 (ids).
    Integers(&'a [i64]),
}

impl Source<'_> {
    fn len(&self) -> usize {
        match self {
            Source::Pairs(v) => v.len(),
            Source::Sixes(v) => v.len(),
            Source::Singles(v) => v.len(),
            Source::Integers(v) => v.len(),
        }
    }
}

/// A field to write: its section, name, values and width in the file.
#[derive(Clone, Copy, Debug)]
pub struct Field<'a> {
    pub section: Section,
    pub name: &'static str,
    pub source: Source<'a>,
    pub width: usize,
}

/// A frame's arrays, checked and laid out, before compression and the header.
#[derive(Debug)]
pub struct Payload {
    points: usize,
    cells: usize,
    /// The point data array named as the active vectors (Warp By Vector picks it).
    vectors: Option<&'static str>,
    arrays: Vec<Array>,
    /// The frame's time, written as the grid's `TimeValue` field (ParaView's reader shows
    /// it for a .vtu opened alone, without the .pvd).
    time: Option<f64>,
}

impl Payload {
    /// Checks and lays out a frame: the grid's points (written with z = 0) and cells (quads
    /// as VTK_QUAD, then lines as VTK_LINE), and the point and cell fields.
    ///
    /// Errors (naming `path`): a field whose length is not the number of points or cells, a
    /// NaN or infinity in a field or a point, a cell naming a missing point; of several, the
    /// first of the fields in order, then the points, then the cells.
    pub fn new(
        path: &Path,
        grid: &Grid,
        fields: &[Field],
        vectors: Option<&'static str>,
    ) -> Result<Payload, OutputError> {
        let geometry = Field {
            section: Section::Points,
            name: "Points",
            source: Source::Pairs(&grid.points),
            width: 3,
        };
        let (encoded, cells) = rayon::join(
            || {
                fields
                    .par_iter()
                    .chain(rayon::iter::once(&geometry))
                    .map(|field| {
                        let expected = match field.section {
                            Section::CellData => grid.cells(),
                            _ => grid.points.len(),
                        };
                        float_array(path, field, expected)
                    })
                    .collect::<Vec<Result<Array, OutputError>>>()
            },
            || cell_arrays(path, grid),
        );
        let mut arrays = Vec::with_capacity(encoded.len() + 3);
        for array in encoded {
            arrays.push(array?);
        }
        arrays.extend(cells?);
        Ok(Payload {
            points: grid.points.len(),
            cells: grid.cells(),
            vectors,
            arrays,
            time: None,
        })
    }

    /// The payload with the frame's `time` (written as the `TimeValue` field data).
    pub fn at_time(mut self, time: f64) -> Payload {
        self.time = Some(time);
        self
    }

    /// The file as consecutive parts (XML header, the arrays' blocks, the closing tags),
    /// compressed as asked.
    pub fn into_parts(mut self, compression: Compression) -> Vec<Vec<u8>> {
        // each array's block in the appended data: its header, then its (compressed) bytes
        let blocks: Vec<[Vec<u8>; 2]> = self
            .arrays
            .iter_mut()
            .map(|a| {
                let bytes = std::mem::take(&mut a.bytes);
                match compression {
                    Compression::None => [(bytes.len() as u64).to_le_bytes().to_vec(), bytes],
                    Compression::Lz4 | Compression::Zlib => compress(&bytes, compression),
                }
            })
            .collect();
        let mut header = String::new();
        header.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\"");
        if let Some(compressor) = compression.compressor() {
            header.push_str(&format!(" compressor=\"{compressor}\""));
        }
        header.push_str(">\n  <UnstructuredGrid>\n");
        if let Some(time) = self.time {
            // the shortest text that reads back as the same f64 (Rust's Display)
            header.push_str(&format!(
                "    <FieldData>\n      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">{time:?}</DataArray>\n    </FieldData>\n"
            ));
        }
        header.push_str(&format!(
            "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n",
            self.points, self.cells
        ));
        let offsets: Vec<usize> = blocks
            .iter()
            .scan(0, |end, [lead, body]| {
                let start = *end;
                *end += lead.len() + body.len();
                Some(start)
            })
            .collect();
        for section in [
            Section::PointData,
            Section::CellData,
            Section::Points,
            Section::Cells,
        ] {
            let tag = match section {
                Section::PointData => "PointData",
                Section::CellData => "CellData",
                Section::Points => "Points",
                Section::Cells => "Cells",
            };
            match (section, self.vectors) {
                (Section::PointData, Some(name)) => {
                    header.push_str(&format!("      <{tag} Vectors=\"{name}\">\n"))
                }
                _ => header.push_str(&format!("      <{tag}>\n")),
            }
            for (array, offset) in self.arrays.iter().zip(&offsets) {
                if array.section == section {
                    header.push_str(&format!(
                        "        <DataArray type=\"{:?}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"appended\" offset=\"{offset}\"/>\n",
                        array.scalar, array.name, array.components
                    ));
                }
            }
            header.push_str(&format!("      </{tag}>\n"));
        }
        header.push_str(
            "    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _",
        );
        let mut parts = vec![header.into_bytes()];
        parts.extend(blocks.into_iter().flatten());
        parts.push(b"\n  </AppendedData>\n</VTKFile>\n".to_vec());
        parts
    }
}

/// Connectivity, end offsets and VTK cell types (quads, then lines); every node must be a
/// point of the grid.
fn cell_arrays(path: &Path, grid: &Grid) -> Result<[Array; 3], OutputError> {
    const VTK_QUAD: u8 = 9;
    const VTK_LINE: u8 = 3;
    let points = grid.points.len();
    let quads = grid.quads.iter().map(|q| (&q[..], VTK_QUAD));
    let lines = grid.lines.iter().map(|l| (&l[..], VTK_LINE));
    let mut connectivity = Vec::with_capacity(8 * (4 * grid.quads.len() + 2 * grid.lines.len()));
    let mut offsets = Vec::with_capacity(8 * grid.cells());
    let mut types = Vec::with_capacity(grid.cells());
    let mut end = 0u64;
    for (cell, (nodes, kind)) in quads.chain(lines).enumerate() {
        if let Some(&node) = nodes.iter().find(|&&n| n >= points) {
            let reason =
                format!("cell {cell} refers to node {node}, but the grid has {points} points");
            return Err(OutputError::invalid(path, reason));
        }
        for &n in nodes {
            connectivity.extend_from_slice(&(n as u64).to_le_bytes());
        }
        end += nodes.len() as u64;
        offsets.extend_from_slice(&end.to_le_bytes());
        types.push(kind);
    }
    let array = |name, scalar, bytes| Array {
        section: Section::Cells,
        name,
        scalar,
        components: 1,
        bytes,
    };
    Ok([
        array("connectivity", Scalar::Int64, connectivity),
        array("offsets", Scalar::Int64, offsets),
        array("types", Scalar::UInt8, types),
    ])
}

/// A checked array: `expected` rows; Float64 rows finite and padded with zeros to the
/// width, integers as Int64.
fn float_array(path: &Path, field: &Field, expected: usize) -> Result<Array, OutputError> {
    if field.source.len() != expected {
        return Err(OutputError::Length {
            path: path.to_path_buf(),
            what: format!("field `{}`", field.name),
            expected,
            found: field.source.len(),
        });
    }
    if let Source::Integers(values) = field.source {
        return Ok(Array {
            section: field.section,
            name: field.name,
            scalar: Scalar::Int64,
            components: 1,
            bytes: values.iter().flat_map(|v| v.to_le_bytes()).collect(),
        });
    }
    let mut bytes = Vec::with_capacity(expected * field.width * 8);
    let mut push = |index: usize, row: &[f64]| -> Result<(), OutputError> {
        if let Some(component) = row.iter().position(|x| !x.is_finite()) {
            return Err(OutputError::NonFinite {
                path: path.to_path_buf(),
                field: field.name,
                index,
                component,
                value: row[component],
            });
        }
        for x in row {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
        for _ in row.len()..field.width {
            bytes.extend_from_slice(&0f64.to_le_bytes());
        }
        Ok(())
    };
    match field.source {
        Source::Pairs(rows) => rows.iter().enumerate().try_for_each(|(i, r)| push(i, r))?,
        Source::Sixes(rows) => rows.iter().enumerate().try_for_each(|(i, r)| push(i, r))?,
        Source::Singles(values) => values
            .iter()
            .enumerate()
            .try_for_each(|(i, r)| push(i, std::slice::from_ref(r)))?,
        Source::Integers(_) => unreachable!("written above"),
    }
    Ok(Array {
        section: field.section,
        name: field.name,
        scalar: Scalar::Float64,
        components: field.width,
        bytes,
    })
}

/// VTK's compressed layout of one array: [the header, the compressed blocks].
fn compress(bytes: &[u8], compression: Compression) -> [Vec<u8>; 2] {
    let blocks: Vec<Vec<u8>> = bytes
        .chunks(BLOCK)
        .map(|block| match compression {
            Compression::Lz4 => lz4_flex::block::compress(block),
            Compression::Zlib | Compression::None => {
                use std::io::Write;
                let mut encoder =
                    flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::new(6));
                encoder.write_all(block).expect("writing to memory");
                encoder.finish().expect("writing to memory")
            }
        })
        .collect();
    let last = bytes.len() % BLOCK;
    let mut header = Vec::with_capacity(8 * (3 + blocks.len()));
    for n in [blocks.len(), BLOCK, last]
        .into_iter()
        .chain(blocks.iter().map(Vec::len))
    {
        header.extend_from_slice(&(n as u64).to_le_bytes());
    }
    [header, blocks.concat()]
}

/// A frame read back by [`read_frame`].
#[derive(Debug, Clone, PartialEq)]
pub struct FrameData {
    pub points: usize,
    pub cells: usize,
    /// The PointData attribute `Vectors`, if any.
    pub vectors: Option<String>,
    pub arrays: Vec<ReadArray>,
}

/// One array of a frame read back.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadArray {
    pub section: Section,
    pub name: String,
    pub components: usize,
    pub values: Values,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    Float64(Vec<f64>),
    Int64(Vec<i64>),
    UInt8(Vec<u8>),
}

impl FrameData {
    /// The Float64 array `name` of `section`: (components, values).
    pub fn floats(&self, section: Section, name: &str) -> Option<(usize, &[f64])> {
        self.arrays.iter().find_map(|a| match &a.values {
            Values::Float64(v) if a.section == section && a.name == name => {
                Some((a.components, v.as_slice()))
            }
            _ => None,
        })
    }

    /// The Int64 array `name` of `section` (cell data: ids).
    pub fn ids(&self, section: Section, name: &str) -> Option<&[i64]> {
        self.arrays.iter().find_map(|a| match &a.values {
            Values::Int64(v) if a.section == section && a.name == name => Some(v.as_slice()),
            _ => None,
        })
    }

    /// The Int64 array `name` of the cells (connectivity, offsets).
    pub fn integers(&self, name: &str) -> Option<&[i64]> {
        self.arrays.iter().find_map(|a| match &a.values {
            Values::Int64(v) if a.section == Section::Cells && a.name == name => Some(v.as_slice()),
            _ => None,
        })
    }

    /// The VTK cell types.
    pub fn types(&self) -> Option<&[u8]> {
        self.arrays.iter().find_map(|a| match &a.values {
            Values::UInt8(v) if a.name == "types" => Some(v.as_slice()),
            _ => None,
        })
    }

    /// The names of the arrays of a section, in file order.
    pub fn names(&self, section: Section) -> Vec<&str> {
        self.arrays
            .iter()
            .filter(|a| a.section == section)
            .map(|a| a.name.as_str())
            .collect()
    }
}

/// Reads a frame written here (appended raw arrays, UInt64 headers, optionally LZ4 or zlib),
/// checking every array's length against the piece's points and cells.
pub fn read_frame(path: &Path) -> Result<FrameData, OutputError> {
    let bad = |reason: String| OutputError::invalid(path, reason);
    let file = std::fs::read(path).map_err(|e| OutputError::io(path, "read", e))?;
    let marker = b"<AppendedData";
    let start = file
        .windows(marker.len())
        .position(|w| w == marker)
        .ok_or_else(|| bad("no <AppendedData> block".into()))?;
    let underscore = file[start..]
        .iter()
        .position(|b| *b == b'_')
        .ok_or_else(|| bad("no `_` opening the appended data".into()))?;
    let data = &file[start + underscore + 1..];
    let header = std::str::from_utf8(&file[..start + underscore])
        .map_err(|_| bad("the XML header is not UTF-8".into()))?;
    let mut compression = Compression::None;
    let mut frame = FrameData {
        points: 0,
        cells: 0,
        vectors: None,
        arrays: Vec::new(),
    };
    let mut section = None;
    // the grid's field data (the frame's `TimeValue`) is not a frame array
    let mut field_data = false;
    for tag in header.split('<').skip(1) {
        let tag = tag.split('>').next().unwrap_or_default();
        let (element, rest) = tag.split_once(char::is_whitespace).unwrap_or((tag, ""));
        let element = element.trim_end_matches('/');
        let attribute = |key: &str| attributes(rest).find(|(k, _)| *k == key).map(|(_, v)| v);
        let number = |key: &str| -> Result<usize, OutputError> {
            attribute(key)
                .ok_or_else(|| bad(format!("<{element}> has no {key}")))?
                .parse()
                .map_err(|_| bad(format!("<{element}> has a bad {key}")))
        };
        match element {
            "VTKFile" => {
                if attribute("header_type") != Some("UInt64") {
                    return Err(bad("only header_type=\"UInt64\" is read".into()));
                }
                compression = match attribute("compressor") {
                    None => Compression::None,
                    Some("vtkLZ4DataCompressor") => Compression::Lz4,
                    Some("vtkZLibDataCompressor") => Compression::Zlib,
                    Some(other) => return Err(bad(format!("compressor {other} is not read"))),
                };
            }
            "Piece" => {
                frame.points = number("NumberOfPoints")?;
                frame.cells = number("NumberOfCells")?;
            }
            "PointData" => {
                section = Some(Section::PointData);
                frame.vectors = attribute("Vectors").map(str::to_string);
            }
            "CellData" => section = Some(Section::CellData),
            "Points" => section = Some(Section::Points),
            "Cells" => section = Some(Section::Cells),
            "FieldData" => field_data = true,
            "/FieldData" => field_data = false,
            "DataArray" if field_data => {}
            "DataArray" => {
                let section = section.ok_or_else(|| bad("a DataArray outside a section".into()))?;
                let name = attribute("Name").unwrap_or_default().to_string();
                let scalar = attribute("type")
                    .and_then(Scalar::from_name)
                    .ok_or_else(|| bad(format!("array {name}: type not read")))?;
                if attribute("format") != Some("appended") {
                    return Err(bad(format!("array {name}: only appended arrays are read")));
                }
                let components = match attribute("NumberOfComponents") {
                    Some(_) => number("NumberOfComponents")?,
                    None => 1,
                };
                let offset = number("offset")?;
                let bytes = array_bytes(data, offset, compression)
                    .ok_or_else(|| bad(format!("array {name}: the appended data is cut short")))?;
                let entries = match (section, name.as_str()) {
                    (Section::PointData | Section::Points, _) => frame.points * components,
                    (Section::CellData, _) | (Section::Cells, "offsets" | "types") => {
                        frame.cells * components
                    }
                    (Section::Cells, _) => bytes.len() / scalar.size(),
                };
                if bytes.len() != entries * scalar.size() {
                    return Err(bad(format!(
                        "array {name} has {} bytes, expected {}",
                        bytes.len(),
                        entries * scalar.size()
                    )));
                }
                let values = match scalar {
                    Scalar::Float64 => Values::Float64(
                        bytes
                            .chunks_exact(8)
                            .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
                            .collect(),
                    ),
                    Scalar::Int64 => Values::Int64(
                        bytes
                            .chunks_exact(8)
                            .map(|b| i64::from_le_bytes(b.try_into().expect("8 bytes")))
                            .collect(),
                    ),
                    Scalar::UInt8 => Values::UInt8(bytes),
                };
                frame.arrays.push(ReadArray {
                    section,
                    name,
                    components,
                    values,
                });
            }
            _ => {}
        }
    }
    Ok(frame)
}

/// The raw bytes of the array at `offset` of the appended block (None: cut short or corrupt).
fn array_bytes(data: &[u8], offset: usize, compression: Compression) -> Option<Vec<u8>> {
    let word = |at: usize| -> Option<usize> {
        let bytes = data.get(at..at + 8)?;
        usize::try_from(u64::from_le_bytes(bytes.try_into().ok()?)).ok()
    };
    if compression == Compression::None {
        let n = word(offset)?;
        return data.get(offset + 8..offset + 8 + n).map(<[u8]>::to_vec);
    }
    let (blocks, size, last) = (word(offset)?, word(offset + 8)?, word(offset + 16)?);
    let mut at = offset + 24 + 8 * blocks;
    let mut out = Vec::with_capacity(blocks * size);
    for b in 0..blocks {
        let compressed = word(offset + 24 + 8 * b)?;
        let block = data.get(at..at + compressed)?;
        let raw = if b + 1 == blocks && last > 0 {
            last
        } else {
            size
        };
        let decoded = match compression {
            Compression::Lz4 => lz4_flex::block::decompress(block, raw).ok()?,
            Compression::Zlib | Compression::None => {
                use std::io::Read;
                let mut decoded = Vec::with_capacity(raw);
                flate2::read::ZlibDecoder::new(block)
                    .read_to_end(&mut decoded)
                    .ok()?;
                decoded
            }
        };
        if decoded.len() != raw {
            return None;
        }
        out.extend_from_slice(&decoded);
        at += compressed;
    }
    Some(out)
}
