//! VTK time series for ParaView: DIR/NAME.pvd listing DIR/vtk/NAME_NNNNN.vtu (the output contract of docs/user-guide.md).
//!
//! Legend
//! ```text
//! Grid        all bodies merged, global node numbers
//! cells       quads (VTK_QUAD = 9) first, then rods (VTK_LINE = 3)
//! points      the grid's points as the caller places them, z = 0 (runs: the current,
//!             deformed configuration, or the reference one on request)
//! point data  displacement, velocity, acceleration, contact_force,  3 components, z = 0
//!             reference_coordinates
//!             gap, contact_status                                   1 component
//!             nodal_stress (6), nodal_von_mises, nodal_eq_plastic_strain,
//!             nodal_pressure, nodal_temperature (1): the cell values averaged to the
//!             points; body (Int64, the point's body) (only when given)
//!             contact_pressure, contact_shear (1): the contact's normal (compressive > 0)
//!             and tangential traction on the contact surfaces (only when given)
//! cell data   stress (XX YY ZZ XY YZ XZ), von_mises, eq_plastic_strain, pressure,
//!             strain (XX YY ZZ XY YZ XZ, Green-Lagrange; only when given),
//!             body (Int64: the index of the cell's body in the scene, from 0; only when
//!             given), temperature (only when given)
//! ```
//! The rigid obstacles go beside the series: at rest, once, DIR/NAME_obstacles.pvd listing
//! DIR/vtk/NAME_obstacles.vtu, their segments as lines with the cell array `obstacle`
//! (`write_obstacles`); where one moves, a file per frame, NAME_obstacles_KKKK.vtu, all
//! listed in that .pvd (`write_obstacle_frame`).
//!
//! `displacement` is the active vectors array, so ParaView's Warp By Vector picks it by
//! default (to exaggerate the motion of a frame drawn in the reference configuration);
//! `reference_coordinates` holds the initial coordinates whichever configuration the points are in.
//!
//! Each frame is a VTK XML file with its arrays appended as raw binary, optionally LZ4/ZLib
//! compressed (src/output/vtu.rs), written to a temporary name and renamed; the .pvd is then
//! rewritten the same way. A crash therefore never leaves a truncated frame or a listed frame
//! that is missing.
//!
//! With `Series::set_background(true)` (as runs do) the compression and both writes happen
//! on a thread of the series' own: one frame is written there while the next is gathered
//! (the hand-over waits for the writer), so a large frame costs the stepping only its
//! gathering and layout; `flush` (called before a checkpoint and the summary, and on drop) waits for
//! it and returns its error, if any. The order of the writes, and so the guarantee above, is
//! the same. After a writer error the series refuses every further frame and flush with it.

use std::fs;
use std::path::{Path, PathBuf};

pub use super::vtu::{Compression, Grid};
use super::vtu::{Field, Payload, Section, Source, attributes};
use super::{OutputError, format_f64, write_atomic, write_atomic_parts};

/// One frame's fields. Point fields have one entry per grid point, cell fields one per cell (quads then lines).
#[derive(Clone, Copy, Debug)]
pub struct Fields<'a> {
    pub displacement: &'a [[f64; 2]],
    pub velocity: &'a [[f64; 2]],
    pub acceleration: &'a [[f64; 2]],
    pub contact_force: &'a [[f64; 2]],
    pub gap: &'a [f64],
    pub contact_status: &'a [f64],
    /// The initial coordinates of the points.
    pub reference_coordinates: &'a [[f64; 2]],
    /// XX YY ZZ XY YZ XZ (ParaView's order, so it names the components).
    pub stress: &'a [[f64; 6]],
    pub von_mises: &'a [f64],
    pub eq_plastic_strain: &'a [f64],
    pub pressure: &'a [f64],
    /// Written only when given (materials that carry a temperature).
    pub temperature: Option<&'a [f64]>,
    /// Per cell, the index of its body in the scene (from 0): ParaView's Threshold on
    /// `body` picks one body. Written only when given.
    pub body: Option<&'a [i64]>,
    /// Per point, the cell values averaged over the cells around it, and its body. Written
    /// only when given.
    pub nodal: Option<PointValues<'a>>,
    /// Per point, the contact pressure and tangential traction (`contact::Tractions`).
    /// Written only when given.
    pub traction: Option<(&'a [f64], &'a [f64])>,
    /// Per cell, the Green-Lagrange strain XX YY ZZ XY YZ XZ (tensor shear). Written only
    /// when given.
    pub strain: Option<&'a [[f64; 6]]>,
}

/// Per point: the cell values averaged over the cells around it (`Grid::cell_to_point_mean`:
/// smooth contours of what the integration points carry), and the index of its body.
#[derive(Clone, Copy, Debug)]
pub struct PointValues<'a> {
    pub stress: &'a [[f64; 6]],
    pub von_mises: &'a [f64],
    pub eq_plastic_strain: &'a [f64],
    pub pressure: &'a [f64],
    /// Written only when given.
    pub temperature: Option<&'a [f64]>,
    pub body: &'a [i64],
}

/// A time series: DIR/NAME.pvd listing DIR/vtk/NAME_NNNNN.vtu.
#[derive(Debug)]
pub struct Series {
    dir: PathBuf,
    name: String,
    compression: Compression,
    /// The .pvd's `<DataSet .../>` lines, one per frame written (or handed to the writer).
    entries: Vec<String>,
    last_time: Option<f64>,
    background: bool,
    writer: std::cell::RefCell<Option<Writer>>,
    /// The writer's error (the file and the message), kept: once a frame failed, the series
    /// is unusable and says so at every call.
    failure: std::cell::RefCell<Option<(PathBuf, String)>>,
}

/// A frame for the writer thread: the .vtu to compress and write, then the .pvd text.
struct Job {
    path: PathBuf,
    payload: Payload,
    compression: Compression,
    pvd_path: PathBuf,
    pvd_text: String,
}

/// The writer thread: jobs in order, handed over one at a time (a rendezvous channel); it
/// stops at its first error and returns it.
#[derive(Debug)]
struct Writer {
    jobs: std::sync::mpsc::SyncSender<Job>,
    handle: std::thread::JoinHandle<Result<(), OutputError>>,
}

impl std::fmt::Debug for Job {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Job({})", self.path.display())
    }
}

impl Writer {
    fn start(pvd: &Path) -> Result<Writer, OutputError> {
        let (jobs, queue) = std::sync::mpsc::sync_channel::<Job>(0);
        let handle = std::thread::Builder::new()
            .name("vtk-writer".into())
            .spawn(move || {
                // a frame's buffers are freed only after the next frame's: freed first, they
                // sat at the top of the heap, which the allocator then gave back to the
                // system and faulted in again for the next frame (the 224-rod bars: 128
                // frames, 0.93x with this)
                let mut written = Vec::new();
                for job in queue {
                    let parts = job.payload.into_parts(job.compression);
                    write_atomic_parts(&job.path, &parts)?;
                    write_atomic(&job.pvd_path, job.pvd_text.as_bytes())?;
                    written = parts;
                }
                drop(written);
                Ok(())
            })
            .map_err(|e| OutputError::io(pvd, "start the frame writer thread", e))?;
        Ok(Writer { jobs, handle })
    }

    /// Waits for the frames handed over and returns the first error.
    fn finish(self, pvd: &Path) -> Result<(), OutputError> {
        drop(self.jobs);
        self.handle
            .join()
            .unwrap_or_else(|_| Err(OutputError::invalid(pvd, "the frame writer panicked")))
    }
}

impl Drop for Series {
    fn drop(&mut self) {
        // frames handed over are written before the series goes (an error here was, or will
        // never be, reported by `flush`)
        let _ = self.flush();
    }
}

impl Series {
    /// Creates DIR/vtk/ (removes stale NAME_*.vtu frames of an earlier run there) and remembers the name.
    ///
    /// Also writes DIR/NAME.pvd listing no frames, so an old .pvd never points at removed files.
    /// `name` may hold ASCII letters, digits, `_`, `-` and `.` (not first).
    pub fn create(dir: &Path, name: &str, compression: Compression) -> Result<Series, OutputError> {
        check_name(dir, name)?;
        let vtk_dir = dir.join("vtk");
        fs::create_dir_all(&vtk_dir).map_err(|e| OutputError::io(&vtk_dir, "create folder", e))?;
        remove_stale_frames(&vtk_dir, name)?;
        let series = Series {
            dir: dir.to_path_buf(),
            name: name.to_string(),
            compression,
            entries: Vec::new(),
            last_time: None,
            background: false,
            writer: std::cell::RefCell::new(None),
            failure: std::cell::RefCell::new(None),
        };
        series.write_pvd()?;
        Ok(series)
    }

    /// Writes the next frame (to a temporary name, then renamed), then rewrites NAME.pvd atomically
    /// listing every frame written so far. Returns the frame's path.
    ///
    /// Errors, with nothing written: `time` not finite or not after the previous frame's, a field
    /// of the wrong length, NaN or infinity in a field or a point, a cell naming a missing point.
    pub fn write_frame(
        &mut self,
        time: f64,
        grid: &Grid,
        fields: &Fields,
    ) -> Result<PathBuf, OutputError> {
        let file_name = format!("{}_{:05}.vtu", self.name, self.frames());
        let path = self.dir.join("vtk").join(&file_name);
        self.check_time(&path, time)?;
        let payload = payload(&path, grid, fields)?.at_time(time);
        if !self.background {
            write_atomic_parts(&path, &payload.into_parts(self.compression))?;
            self.entries
                .push(pvd_entry(time, &format!("vtk/{file_name}")));
            self.last_time = Some(time);
            self.write_pvd()?;
            return Ok(path);
        }
        self.failed()?;
        let previous_time = self.last_time;
        self.entries
            .push(pvd_entry(time, &format!("vtk/{file_name}")));
        self.last_time = Some(time);
        let job = Job {
            path: path.clone(),
            payload,
            compression: self.compression,
            pvd_path: self.pvd_path(),
            pvd_text: self.pvd_text(),
        };
        let mut writer = self.writer.borrow_mut();
        if writer.is_none() {
            *writer = Some(Writer::start(&self.pvd_path())?);
        }
        let sent = writer.as_ref().expect("started above").jobs.send(job);
        drop(writer);
        if sent.is_err() {
            // the writer stopped at an error: this frame is not written, and the error is
            // the one to report
            self.entries.pop();
            self.last_time = previous_time;
            self.flush()?;
            return Err(OutputError::invalid(&path, "the frame writer stopped"));
        }
        Ok(path)
    }

    /// Writes frames on a thread of their own from now on (`flush` waits for them).
    pub fn set_background(&mut self, on: bool) {
        if !on {
            let _ = self.flush();
        }
        self.background = on;
    }

    /// Waits until every frame handed over is on disk (and listed by the .pvd); returns the
    /// writer's error, if it met one.
    pub fn flush(&self) -> Result<(), OutputError> {
        let writer = self.writer.borrow_mut().take();
        if let Some(writer) = writer
            && let Err(e) = writer.finish(&self.pvd_path())
        {
            *self.failure.borrow_mut() = Some((self.pvd_path(), e.to_string()));
            return Err(e);
        }
        self.failed()
    }

    /// The kept writer error, if any.
    fn failed(&self) -> Result<(), OutputError> {
        match &*self.failure.borrow() {
            Some((path, message)) => Err(OutputError::invalid(
                path,
                format!("an earlier frame could not be written: {message}"),
            )),
            None => Ok(()),
        }
    }

    pub fn frames(&self) -> usize {
        self.entries.len()
    }

    /// Where the series stands (the frames listed so far), for a checkpoint.
    pub fn position(&self) -> SeriesPosition {
        SeriesPosition {
            entries: self.entries.clone(),
            last_time: self.last_time,
        }
    }

    /// Continues a series from a checkpoint's [`SeriesPosition`]: frames numbered past it
    /// (written after the checkpoint, or half-written when the run was killed) are removed
    /// and DIR/NAME.pvd is rewritten listing exactly the checkpoint's frames.
    pub fn resume(
        dir: &Path,
        name: &str,
        compression: Compression,
        position: SeriesPosition,
    ) -> Result<Series, OutputError> {
        check_name(dir, name)?;
        let vtk_dir = dir.join("vtk");
        fs::create_dir_all(&vtk_dir).map_err(|e| OutputError::io(&vtk_dir, "create folder", e))?;
        let listing = fs::read_dir(&vtk_dir).map_err(|e| OutputError::io(&vtk_dir, "list", e))?;
        for entry in listing {
            let entry = entry.map_err(|e| OutputError::io(&vtk_dir, "list", e))?;
            let file_name = entry.file_name();
            let Some(file_name) = file_name.to_str() else {
                continue;
            };
            let later = file_name.ends_with(".tmp")
                || frame_number(file_name, name).is_some_and(|k| k >= position.entries.len());
            if is_frame_file(file_name, name) && later {
                let path = entry.path();
                fs::remove_file(&path).map_err(|e| {
                    OutputError::io(&path, "remove a frame after the checkpoint", e)
                })?;
            }
        }
        for k in 0..position.entries.len() {
            let path = vtk_dir.join(format!("{name}_{k:05}.vtu"));
            if !path.is_file() {
                return Err(OutputError::invalid(
                    &path,
                    "a frame listed at the checkpoint is missing",
                ));
            }
        }
        let series = Series {
            dir: dir.to_path_buf(),
            name: name.to_string(),
            compression,
            entries: position.entries,
            last_time: position.last_time,
            background: false,
            writer: std::cell::RefCell::new(None),
            failure: std::cell::RefCell::new(None),
        };
        series.write_pvd()?;
        Ok(series)
    }

    pub fn pvd_path(&self) -> PathBuf {
        self.dir.join(format!("{}.pvd", self.name))
    }

    fn check_time(&self, path: &Path, time: f64) -> Result<(), OutputError> {
        if !time.is_finite() {
            return Err(OutputError::invalid(
                path,
                format!("frame time {time} is not finite"),
            ));
        }
        match self.last_time {
            Some(previous) if time <= previous => Err(OutputError::TimeNotIncreasing {
                path: path.to_path_buf(),
                time,
                previous,
            }),
            _ => Ok(()),
        }
    }

    fn write_pvd(&self) -> Result<(), OutputError> {
        write_atomic(&self.pvd_path(), self.pvd_text().as_bytes())
    }

    fn pvd_text(&self) -> String {
        collection(&self.entries)
    }
}

/// A .pvd's text listing the `<DataSet>` lines `entries`.
fn collection(entries: &[String]) -> String {
    let mut text = String::from(concat!(
        "<?xml version=\"1.0\"?>\n",
        "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n",
        "  <Collection>\n",
    ));
    entries.iter().for_each(|entry| text.push_str(entry));
    text.push_str("  </Collection>\n</VTKFile>\n");
    text
}

/// A rigid obstacle for the frames: its polyline and whether it closes on itself.
#[derive(Clone, Copy, Debug)]
pub struct Polyline<'a> {
    pub points: &'a [[f64; 2]],
    pub closed: bool,
}

/// Writes the rigid obstacles beside the bodies' series: DIR/vtk/NAME_obstacles.vtu, their
/// segments as lines (VTK_LINE) with the cell array `obstacle` (Int64: the obstacle's index
/// in the scene, from 0), and DIR/NAME_obstacles.pvd listing it at time 0, so ParaView shows
/// them at every time of the bodies' series (obstacles at rest). Returns the .pvd's path.
pub fn write_obstacles(
    dir: &Path,
    name: &str,
    obstacles: &[Polyline],
    compression: Compression,
) -> Result<PathBuf, OutputError> {
    let file_name = format!("{name}_obstacles.vtu");
    write_obstacle_file(dir, &file_name, obstacles, compression)?;
    let pvd = dir.join(format!("{name}_obstacles.pvd"));
    let entry = pvd_entry(0.0, &format!("vtk/{file_name}"));
    write_atomic(&pvd, collection(&[entry]).as_bytes())?;
    Ok(pvd)
}

/// Writes the obstacles where they are at a frame of a scene whose obstacles move:
/// DIR/vtk/NAME_obstacles_KKKK.vtu (K: the `index`-th such frame, from 0; the arrays of
/// `write_obstacles`), adds it to `listed` (time, file relative to DIR) and rewrites
/// DIR/NAME_obstacles.pvd with every listed file. Returns the .pvd's path.
pub fn write_obstacle_frame(
    dir: &Path,
    name: &str,
    (index, time): (usize, f64),
    obstacles: &[Polyline],
    (compression, listed): (Compression, &mut Vec<(f64, String)>),
) -> Result<PathBuf, OutputError> {
    let file_name = format!("{name}_obstacles_{index:04}.vtu");
    write_obstacle_file(dir, &file_name, obstacles, compression)?;
    listed.push((time, format!("vtk/{file_name}")));
    let entries: Vec<String> = listed.iter().map(|(t, f)| pvd_entry(*t, f)).collect();
    let pvd = dir.join(format!("{name}_obstacles.pvd"));
    write_atomic(&pvd, collection(&entries).as_bytes())?;
    Ok(pvd)
}

/// DIR/vtk/FILE_NAME: the obstacles' segments as lines with their `obstacle` index.
fn write_obstacle_file(
    dir: &Path,
    file_name: &str,
    obstacles: &[Polyline],
    compression: Compression,
) -> Result<(), OutputError> {
    let path = dir.join("vtk").join(file_name);
    fs::create_dir_all(dir.join("vtk"))
        .map_err(|e| OutputError::io(&dir.join("vtk"), "create folder", e))?;
    let mut grid = Grid {
        points: Vec::new(),
        quads: Vec::new(),
        lines: Vec::new(),
    };
    let mut ids = Vec::new();
    for (index, obstacle) in obstacles.iter().enumerate() {
        let first = grid.points.len();
        let n = obstacle.points.len();
        grid.points.extend_from_slice(obstacle.points);
        let segments = if obstacle.closed {
            n
        } else {
            n.saturating_sub(1)
        };
        for i in 0..segments {
            grid.lines.push([first + i, first + (i + 1) % n]);
            ids.push(index as i64);
        }
    }
    let ids_field = Field {
        section: Section::CellData,
        name: "obstacle",
        source: Source::Integers(&ids),
        width: 1,
    };
    let payload = Payload::new(&path, &grid, &[ids_field], None)?;
    write_atomic_parts(&path, &payload.into_parts(compression))
}

/// One `<DataSet>` line of the .pvd; `file` is relative to the .pvd, with forward slashes.
fn pvd_entry(time: f64, file: &str) -> String {
    let time = format_f64(time);
    format!("    <DataSet timestep=\"{time}\" group=\"\" part=\"0\" file=\"{file}\"/>\n")
}

/// Reads back a .pvd's listed (time, path) entries, for tests and tools.
///
/// Paths are resolved against the .pvd's folder. Handles the simple files written here and by
/// ParaView (attributes in any order, either quote); XML entities and comments are not supported.
pub fn read_pvd(path: &Path) -> Result<Vec<(f64, PathBuf)>, OutputError> {
    let text = fs::read_to_string(path).map_err(|e| OutputError::io(path, "read", e))?;
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut listed = Vec::new();
    for (i, tag) in text.split("<DataSet").skip(1).enumerate() {
        let tag = tag.split('>').next().unwrap_or_default();
        let attribute = |key: &str| {
            attributes(tag)
                .find(|(k, _)| *k == key)
                .map(|(_, v)| v)
                .ok_or_else(|| OutputError::invalid(path, format!("DataSet {i} has no `{key}`")))
        };
        let (time, file) = (attribute("timestep")?, attribute("file")?);
        let time: f64 = time.parse().map_err(|_| {
            OutputError::invalid(path, format!("DataSet {i} has timestep {time:?}"))
        })?;
        if file.contains('&') {
            let reason = format!("DataSet {i}: XML entities in {file:?} are not supported");
            return Err(OutputError::invalid(path, reason));
        }
        listed.push((time, folder.join(file)));
    }
    Ok(listed)
}

fn check_name(dir: &Path, name: &str) -> Result<(), OutputError> {
    let allowed = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.');
    if name.is_empty() || name.starts_with('.') || !name.chars().all(allowed) {
        let reason = format!("series name {name:?} must be ASCII letters, digits, `_`, `-`, `.`");
        return Err(OutputError::invalid(dir, reason));
    }
    Ok(())
}

/// Removes `NAME_NNNNN.vtu` (and leftover `.vtu.tmp`) files of an earlier run from `vtk_dir`.
fn remove_stale_frames(vtk_dir: &Path, name: &str) -> Result<(), OutputError> {
    let listing = fs::read_dir(vtk_dir).map_err(|e| OutputError::io(vtk_dir, "list", e))?;
    for entry in listing {
        let entry = entry.map_err(|e| OutputError::io(vtk_dir, "list", e))?;
        let file_name = entry.file_name();
        if file_name.to_str().is_some_and(|f| is_frame_file(f, name)) {
            let path = entry.path();
            fs::remove_file(&path).map_err(|e| OutputError::io(&path, "remove stale frame", e))?;
        }
    }
    Ok(())
}

/// The number of a frame file `NAME_NNNNN.vtu`.
fn frame_number(file_name: &str, name: &str) -> Option<usize> {
    file_name
        .strip_suffix(".vtu")
        .and_then(|f| f.strip_prefix(name))
        .and_then(|f| f.strip_prefix('_'))
        .and_then(|digits| digits.parse().ok())
}

/// A series' frames so far (the .pvd lines and the last frame time), kept in checkpoints.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SeriesPosition {
    entries: Vec<String>,
    last_time: Option<f64>,
}

/// True for `NAME_` + at least five digits + `.vtu`, optionally followed by `.tmp`.
fn is_frame_file(file_name: &str, name: &str) -> bool {
    let file_name = file_name.strip_suffix(".tmp").unwrap_or(file_name);
    file_name
        .strip_suffix(".vtu")
        .and_then(|f| f.strip_prefix(name))
        .and_then(|f| f.strip_prefix('_'))
        .is_some_and(|digits| digits.len() >= 5 && digits.bytes().all(|b| b.is_ascii_digit()))
}

/// Checks the grid and the fields and lays out one frame's arrays.
fn payload(path: &Path, grid: &Grid, fields: &Fields) -> Result<Payload, OutputError> {
    let field = |section, name, source, width| Field {
        section,
        name,
        source,
        width,
    };
    use Section::{CellData, PointData};
    use Source::{Integers, Pairs, Singles, Sixes};
    let list = [
        field(PointData, "displacement", Pairs(fields.displacement), 3),
        field(PointData, "velocity", Pairs(fields.velocity), 3),
        field(PointData, "acceleration", Pairs(fields.acceleration), 3),
        field(PointData, "contact_force", Pairs(fields.contact_force), 3),
        field(PointData, "gap", Singles(fields.gap), 1),
        field(
            PointData,
            "contact_status",
            Singles(fields.contact_status),
            1,
        ),
        field(
            PointData,
            "reference_coordinates",
            Pairs(fields.reference_coordinates),
            3,
        ),
        field(CellData, "stress", Sixes(fields.stress), 6),
        field(CellData, "von_mises", Singles(fields.von_mises), 1),
        field(
            CellData,
            "eq_plastic_strain",
            Singles(fields.eq_plastic_strain),
            1,
        ),
        field(CellData, "pressure", Singles(fields.pressure), 1),
    ];
    let temperature = fields
        .temperature
        .map(|t| field(CellData, "temperature", Singles(t), 1));
    let body = fields.body.map(|b| field(CellData, "body", Integers(b), 1));
    let nodal = fields.nodal.into_iter().flat_map(|v| {
        [
            Some(field(PointData, "nodal_stress", Sixes(v.stress), 6)),
            Some(field(PointData, "nodal_von_mises", Singles(v.von_mises), 1)),
            Some(field(
                PointData,
                "nodal_eq_plastic_strain",
                Singles(v.eq_plastic_strain),
                1,
            )),
            Some(field(PointData, "nodal_pressure", Singles(v.pressure), 1)),
            v.temperature
                .map(|t| field(PointData, "nodal_temperature", Singles(t), 1)),
            Some(field(PointData, "body", Integers(v.body), 1)),
        ]
        .into_iter()
        .flatten()
    });
    let traction = fields.traction.into_iter().flat_map(|(pressure, shear)| {
        [
            field(PointData, "contact_pressure", Singles(pressure), 1),
            field(PointData, "contact_shear", Singles(shear), 1),
        ]
    });
    let strain = fields
        .strain
        .map(|s| field(CellData, "strain", Sixes(s), 6));
    let list: Vec<Field> = list
        .into_iter()
        .chain(nodal)
        .chain(traction)
        .chain(strain)
        .chain(body)
        .chain(temperature)
        .collect();
    Payload::new(path, grid, &list, Some("displacement"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: cell values averaged to the points count each cell around a point once.
    /// Reference: two quads sharing an edge (points 1 and 4) and a line hanging off point 2:
    /// shared points take the mean of their cells, the others their one cell's value.
    #[test]
    fn cell_values_average_to_the_points_around_them() {
        let grid = Grid {
            points: vec![[0.0, 0.0]; 7],
            quads: vec![[0, 1, 4, 3], [1, 2, 5, 4]],
            lines: vec![[2, 6]],
        };
        let mean = grid.cell_to_point_mean(&[[1.0, 10.0], [3.0, 30.0], [8.0, 80.0]]);
        assert_eq!(
            mean,
            [
                [1.0, 10.0],
                [2.0, 20.0],
                [5.5, 55.0],
                [1.0, 10.0],
                [2.0, 20.0],
                [3.0, 30.0],
                [8.0, 80.0]
            ]
        );
    }
    use crate::output::vtu::{FrameData, read_frame};
    use crate::output::{temporary_path, test_dir};

    /// Owned fields of one frame, with values that differ per entry, component and frame.
    struct Frame {
        vectors: [Vec<[f64; 2]>; 4],
        reference: Vec<[f64; 2]>,
        point_scalars: [Vec<f64>; 2],
        stress: Vec<[f64; 6]>,
        cell_scalars: [Vec<f64>; 3],
    }

    impl Frame {
        fn new(grid: &Grid, k: usize) -> Frame {
            let value = |field: usize, i: usize, c: usize| {
                (k as f64 + 1.0) * (1.0 / 3.0 + field as f64) + i as f64 * 1e-3 - c as f64 * 1e-7
            };
            let (np, nc) = (grid.points.len(), grid.cells());
            let vector = |f| (0..np).map(|i| [value(f, i, 0), value(f, i, 1)]).collect();
            let scalar = |f, n| (0..n).map(|i| value(f, i, 0)).collect();
            Frame {
                vectors: [vector(0), vector(1), vector(2), vector(3)],
                reference: vector(10),
                point_scalars: [scalar(4, np), scalar(5, np)],
                stress: (0..nc)
                    .map(|i| std::array::from_fn(|c| value(6, i, c)))
                    .collect(),
                cell_scalars: [scalar(7, nc), scalar(8, nc), scalar(9, nc)],
            }
        }

        fn fields(&self) -> Fields<'_> {
            Fields {
                displacement: &self.vectors[0],
                velocity: &self.vectors[1],
                acceleration: &self.vectors[2],
                contact_force: &self.vectors[3],
                gap: &self.point_scalars[0],
                contact_status: &self.point_scalars[1],
                reference_coordinates: &self.reference,
                stress: &self.stress,
                von_mises: &self.cell_scalars[0],
                eq_plastic_strain: &self.cell_scalars[1],
                pressure: &self.cell_scalars[2],
                temperature: None,
                body: None,
                nodal: None,
                traction: None,
                strain: None,
            }
        }

        /// (name, components, flattened values as they should appear in the file).
        fn point_arrays(&self) -> Vec<(&'static str, usize, Vec<f64>)> {
            let pad = |v: &[[f64; 2]]| v.iter().flat_map(|a| [a[0], a[1], 0.0]).collect();
            let names = ["displacement", "velocity", "acceleration", "contact_force"];
            let mut arrays: Vec<_> = (0..4)
                .map(|f| (names[f], 3, pad(&self.vectors[f])))
                .collect();
            arrays.push(("gap", 1, self.point_scalars[0].clone()));
            arrays.push(("contact_status", 1, self.point_scalars[1].clone()));
            arrays.push(("reference_coordinates", 3, pad(&self.reference)));
            arrays
        }

        fn cell_arrays(&self) -> Vec<(&'static str, usize, Vec<f64>)> {
            vec![
                ("stress", 6, self.stress.concat()),
                ("von_mises", 1, self.cell_scalars[0].clone()),
                ("eq_plastic_strain", 1, self.cell_scalars[1].clone()),
                ("pressure", 1, self.cell_scalars[2].clone()),
            ]
        }
    }

    /// Two quads side by side and a separate rod.
    fn two_quads_and_a_rod() -> Grid {
        Grid {
            points: vec![
                [0.0, 0.0],
                [1.0, 0.0],
                [2.0, 0.0],
                [0.0, 1.0],
                [1.0, 1.0],
                [2.0, 1.0],
                [3.0, 0.5],
                [4.0, 0.5],
            ],
            quads: vec![[0, 1, 4, 3], [1, 2, 5, 4]],
            lines: vec![[6, 7]],
        }
    }

    fn import(path: &Path) -> FrameData {
        read_frame(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    }

    fn bits(values: &[f64]) -> Vec<u64> {
        values.iter().map(|x| x.to_bits()).collect()
    }

    /// Checks that `section` holds exactly the `expected` arrays, bit for bit.
    fn assert_arrays(
        path: &Path,
        frame: &FrameData,
        section: Section,
        expected: &[(&str, usize, Vec<f64>)],
    ) {
        let names: Vec<&str> = expected.iter().map(|(name, ..)| *name).collect();
        assert_eq!(frame.names(section), names, "{}", path.display());
        for (name, components, values) in expected {
            let (found, read) = frame
                .floats(section, name)
                .unwrap_or_else(|| panic!("{}: no Float64 array {name}", path.display()));
            assert_eq!(found, *components, "{name}");
            assert_eq!(bits(read), bits(values), "{name}");
        }
    }

    /// Checks one written frame against the grid and the fields it was written from.
    fn assert_frame(path: &Path, grid: &Grid, frame: &Frame) {
        let read = import(path);
        assert_eq!((read.points, read.cells), (grid.points.len(), grid.cells()));
        assert_eq!(read.vectors.as_deref(), Some("displacement"));
        let points: Vec<f64> = grid.points.iter().flat_map(|p| [p[0], p[1], 0.0]).collect();
        assert_arrays(path, &read, Section::Points, &[("Points", 3, points)]);
        let mut types = vec![9u8; grid.quads.len()];
        types.resize(grid.cells(), 3);
        assert_eq!(read.types().unwrap(), types);
        let nodes = grid
            .quads
            .iter()
            .map(|q| &q[..])
            .chain(grid.lines.iter().map(|l| &l[..]));
        let offsets: Vec<i64> = nodes
            .clone()
            .scan(0, |end, cell| {
                *end += cell.len() as i64;
                Some(*end)
            })
            .collect();
        let expected: Vec<i64> = nodes.flatten().map(|&n| n as i64).collect();
        assert_eq!(read.integers("connectivity").unwrap(), expected);
        assert_eq!(read.integers("offsets").unwrap(), offsets);
        assert_arrays(path, &read, Section::PointData, &frame.point_arrays());
        assert_arrays(path, &read, Section::CellData, &frame.cell_arrays());
    }

    const TIMES: [f64; 3] = [0.0, 1e-5, 1.0 / 3.0];

    /// Goal: a 3-frame series reads back through the .pvd and `read_frame` exactly as written.
    /// Setup: 2 quads + 1 rod, all fields distinct per entry, times 0, 1e-5, 1/3.
    /// Reference: the written values themselves (binary arrays must be bit-exact).
    fn assert_series_round_trips(compression: Compression) {
        let dir = test_dir(&format!("series-{compression:?}"));
        let grid = two_quads_and_a_rod();
        let frames: Vec<Frame> = (0..3).map(|k| Frame::new(&grid, k)).collect();
        let mut series = Series::create(&dir, "run", compression).unwrap();
        let written: Vec<PathBuf> = (0..3)
            .map(|k| {
                series
                    .write_frame(TIMES[k], &grid, &frames[k].fields())
                    .unwrap()
            })
            .collect();
        assert_eq!(series.frames(), 3);
        assert_eq!(written[2], dir.join("vtk").join("run_00002.vtu"));

        let listed = read_pvd(&dir.join("run.pvd")).unwrap();
        let times: Vec<f64> = listed.iter().map(|(t, _)| *t).collect();
        assert_eq!(bits(&times), bits(&TIMES));
        assert!(times.windows(2).all(|w| w[0] < w[1]));
        let pvd = fs::read_to_string(dir.join("run.pvd")).unwrap();
        assert!(pvd.contains("timestep=\"0.3333333333333333\""), "{pvd}");
        assert!(pvd.contains("file=\"vtk/run_00001.vtu\""), "{pvd}");
        for ((_, path), (frame, written)) in listed.iter().zip(frames.iter().zip(&written)) {
            assert_eq!(path, written);
            assert!(!temporary_path(path).exists());
            assert_frame(path, &grid, frame);
        }
        fs::remove_dir_all(&dir).unwrap();
    }

    /// Goal: frames written by the writer thread are the synchronous ones: in order, each
    /// listed once complete, all on disk after `flush`; a writer error is reported by the
    /// next call and by every call after it, and the .pvd keeps listing only the frames
    /// that were written. Reference: the frames' own data (read back).
    #[test]
    fn background_writer_keeps_order_and_reports_its_error() {
        let dir = test_dir("background");
        let grid = two_quads_and_a_rod();
        let frames: Vec<Frame> = (0..3).map(|k| Frame::new(&grid, k)).collect();
        let mut series = Series::create(&dir, "run", Compression::Lz4).unwrap();
        series.set_background(true);
        for (k, frame) in frames.iter().enumerate() {
            series
                .write_frame(TIMES[k], &grid, &frame.fields())
                .unwrap();
        }
        series.flush().unwrap();
        let listed = read_pvd(&dir.join("run.pvd")).unwrap();
        assert_eq!(listed.len(), 3);
        for ((time, path), (k, frame)) in listed.iter().zip(frames.iter().enumerate()) {
            assert_eq!(time.to_bits(), TIMES[k].to_bits());
            assert_frame(path, &grid, frame);
        }
        // the frames folder turns into a file: the next frame cannot be written
        fs::remove_dir_all(dir.join("vtk")).unwrap();
        fs::write(dir.join("vtk"), b"not a folder").unwrap();
        let next = Frame::new(&grid, 3);
        let handed = series.write_frame(3.0, &grid, &next.fields());
        let first = match handed {
            Err(e) => e,
            Ok(_) => series.flush().expect_err("the writer met an error"),
        };
        assert!(first.to_string().contains("vtk"), "{first}");
        let again = series.flush().expect_err("the error is kept");
        assert!(
            again.to_string().contains("could not be written"),
            "{again}"
        );
        assert!(series.write_frame(4.0, &grid, &next.fields()).is_err());
        // the .pvd still lists the three frames written
        assert_eq!(read_pvd(&dir.join("run.pvd")).unwrap().len(), 3);
        drop(series);
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn series_round_trips_through_pvd_uncompressed() {
        assert_series_round_trips(Compression::None);
    }

    #[test]
    fn series_round_trips_through_pvd_lz4() {
        assert_series_round_trips(Compression::Lz4);
    }

    #[test]
    fn series_round_trips_through_pvd_zlib() {
        assert_series_round_trips(Compression::Zlib);
    }

    /// A 64 x 64 node grid with 63 x 63 quads and 127 rods: 4096 points and 4096 cells, so
    /// every array is a whole number of the 32768-byte compression blocks.
    fn block_sized_grid() -> Grid {
        let n = 64;
        let points = (0..n * n)
            .map(|i| [(i % n) as f64, (i / n) as f64])
            .collect();
        let quads = (0..n - 1)
            .flat_map(|j| (0..n - 1).map(move |i| j * n + i))
            .map(|a| [a, a + 1, a + n + 1, a + n])
            .collect();
        let lines = (0..127).map(|i| [i, i + 1]).collect();
        Grid {
            points,
            quads,
            lines,
        }
    }

    /// Goal: compressed arrays whose size is an exact multiple of the 32768-byte block (the
    /// last block size in the header is then 0: a full block) still read back exactly.
    #[test]
    fn compressed_arrays_of_whole_blocks_round_trip() {
        let grid = block_sized_grid();
        assert_eq!((grid.points.len(), grid.cells()), (4096, 4096));
        let frame = Frame::new(&grid, 0);
        for compression in [Compression::Lz4, Compression::Zlib] {
            let dir = test_dir(&format!("blocks-{compression:?}"));
            let mut series = Series::create(&dir, "big", compression).unwrap();
            let path = series.write_frame(0.5, &grid, &frame.fields()).unwrap();
            assert_frame(&path, &grid, &frame);
            fs::remove_dir_all(&dir).unwrap();
        }
    }

    /// Writes the series that tests/vtk/check_with_vtk.py reads with VTK's own reader (the
    /// independent check of the file layout, docs/validation.md): for each compression,
    /// output/vtk_reader_check/COMPRESSION/{small,blocks}.pvd with the frames of `Frame::new`.
    /// Run: cargo test --release --lib vtk_reader_check -- --ignored, then the script.
    #[test]
    #[ignore = "writes files for tests/vtk/check_with_vtk.py"]
    fn vtk_reader_check_frames() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("output/vtk_reader_check");
        for compression in [Compression::None, Compression::Lz4, Compression::Zlib] {
            let dir = root.join(
                serde_json::to_string(&compression)
                    .unwrap()
                    .trim_matches('"'),
            );
            for (name, grid) in [
                ("small", two_quads_and_a_rod()),
                ("blocks", block_sized_grid()),
            ] {
                let mut series = Series::create(&dir, name, compression).unwrap();
                for (k, time) in TIMES.iter().enumerate() {
                    let frame = Frame::new(&grid, k);
                    series.write_frame(*time, &grid, &frame.fields()).unwrap();
                }
            }
        }
    }

    /// Goal: a frame file cut short, or with a header this code does not write, is an error
    /// naming the file, not a panic or wrong values.
    #[test]
    fn damaged_frames_are_read_as_errors() {
        let dir = test_dir("damaged");
        let grid = block_sized_grid();
        let frame = Frame::new(&grid, 0);
        for compression in [Compression::None, Compression::Lz4, Compression::Zlib] {
            let mut series = Series::create(&dir, "run", compression).unwrap();
            let path = series.write_frame(0.0, &grid, &frame.fields()).unwrap();
            let bytes = fs::read(&path).unwrap();
            for cut in [bytes.len() / 3, bytes.len() - 40] {
                fs::write(&path, &bytes[..cut]).unwrap();
                let err = read_frame(&path).expect_err("a cut file");
                assert!(err.to_string().contains("run_00000.vtu"), "{err}");
            }
            let text = String::from_utf8_lossy(&bytes[..200]).replace("UInt64", "UInt32");
            let mut other = text.into_bytes();
            other.extend_from_slice(&bytes[200..]);
            fs::write(&path, &other).unwrap();
            assert!(
                read_frame(&path)
                    .unwrap_err()
                    .to_string()
                    .contains("header_type")
            );
        }
        fs::remove_dir_all(&dir).unwrap();
    }

    /// Goal: a bad frame is an error naming the problem, and the frames and .pvd already
    /// written stay as they were; the next good frame still gets the next number.
    #[test]
    fn bad_frames_are_rejected_and_earlier_output_kept() {
        let dir = test_dir("bad-frames");
        let grid = two_quads_and_a_rod();
        let good = Frame::new(&grid, 0);
        let mut series = Series::create(&dir, "run", Compression::None).unwrap();
        for time in [0.0, 1.0] {
            series.write_frame(time, &grid, &good.fields()).unwrap();
        }
        let pvd_before = fs::read(dir.join("run.pvd")).unwrap();
        let frames_before: Vec<Vec<u8>> = (0..2)
            .map(|k| fs::read(dir.join(format!("vtk/run_{k:05}.vtu"))).unwrap())
            .collect();

        let mut nan = Frame::new(&grid, 1);
        nan.vectors[1][5][1] = f64::NAN;
        let err = series.write_frame(2.0, &grid, &nan.fields()).unwrap_err();
        assert!(
            matches!(
                err,
                OutputError::NonFinite {
                    field: "velocity",
                    index: 5,
                    component: 1,
                    ..
                }
            ),
            "{err}"
        );
        assert!(err.to_string().contains("run_00002.vtu"), "{err}");

        let mut inf = Frame::new(&grid, 1);
        inf.cell_scalars[2][2] = f64::INFINITY;
        let err = series.write_frame(2.0, &grid, &inf.fields()).unwrap_err();
        assert!(matches!(
            err,
            OutputError::NonFinite {
                field: "pressure",
                index: 2,
                ..
            }
        ));

        let mut short = Frame::new(&grid, 1);
        short.stress.pop();
        let err = series.write_frame(2.0, &grid, &short.fields()).unwrap_err();
        assert!(
            matches!(
                err,
                OutputError::Length {
                    expected: 3,
                    found: 2,
                    ..
                }
            ),
            "{err}"
        );
        assert!(err.to_string().contains("stress"), "{err}");

        let err = series.write_frame(1.0, &grid, &good.fields()).unwrap_err();
        assert!(
            matches!(err, OutputError::TimeNotIncreasing { .. }),
            "{err}"
        );
        let err = series
            .write_frame(f64::NAN, &grid, &good.fields())
            .unwrap_err();
        assert!(matches!(err, OutputError::Invalid { .. }), "{err}");

        let mut broken = grid.clone();
        broken.lines[0][1] = 8;
        let err = series
            .write_frame(2.0, &broken, &good.fields())
            .unwrap_err();
        assert!(err.to_string().contains("cell 2 refers to node 8"), "{err}");

        assert_eq!(series.frames(), 2);
        assert_eq!(fs::read(dir.join("run.pvd")).unwrap(), pvd_before);
        for (k, bytes) in frames_before.iter().enumerate() {
            assert_eq!(
                &fs::read(dir.join(format!("vtk/run_{k:05}.vtu"))).unwrap(),
                bytes
            );
        }
        let mut files: Vec<_> = fs::read_dir(dir.join("vtk"))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        files.sort();
        assert_eq!(files, ["run_00000.vtu", "run_00001.vtu"]);

        let path = series.write_frame(2.0, &grid, &good.fields()).unwrap();
        assert!(path.ends_with("vtk/run_00002.vtu"));
        assert_eq!(read_pvd(&series.pvd_path()).unwrap().len(), 3);
        fs::remove_dir_all(&dir).unwrap();
    }

    /// Goal: a new series removes the earlier run's frames of its own name, and only those,
    /// and lists no frames until it writes one.
    #[test]
    fn create_removes_only_stale_frames_of_its_name() {
        let dir = test_dir("stale");
        let grid = two_quads_and_a_rod();
        let frame = Frame::new(&grid, 0);
        let mut old = Series::create(&dir, "run", Compression::None).unwrap();
        let mut other = Series::create(&dir, "run_1", Compression::None).unwrap();
        for time in [0.0, 1.0] {
            old.write_frame(time, &grid, &frame.fields()).unwrap();
            other.write_frame(time, &grid, &frame.fields()).unwrap();
        }
        fs::write(dir.join("vtk/run_00007.vtu.tmp"), b"crashed").unwrap();
        fs::write(dir.join("vtk/run_notes.vtu"), b"keep").unwrap();

        let new = Series::create(&dir, "run", Compression::None).unwrap();
        assert_eq!(new.frames(), 0);
        assert!(read_pvd(&dir.join("run.pvd")).unwrap().is_empty());
        let mut files: Vec<_> = fs::read_dir(dir.join("vtk"))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        files.sort();
        assert_eq!(
            files,
            ["run_1_00000.vtu", "run_1_00001.vtu", "run_notes.vtu"]
        );
        assert_eq!(read_pvd(&dir.join("run_1.pvd")).unwrap().len(), 2);

        for bad in ["", ".hidden", "a/b", "a b", "x&y"] {
            assert!(
                Series::create(&dir, bad, Compression::None).is_err(),
                "{bad:?}"
            );
        }
        fs::remove_dir_all(&dir).unwrap();
    }

    /// Goal: read_pvd takes ParaView-style files too (attribute order, quotes, no part).
    #[test]
    fn read_pvd_accepts_other_writers_layout() {
        let dir = test_dir("pvd");
        let path = dir.join("x.pvd");
        let text = "<VTKFile type='Collection'><Collection>\n<DataSet file='a/f0.vtu' timestep='1e-3'/>\n<DataSet part=\"0\" timestep=\"2.5\" file=\"f1.vtu\"></DataSet></Collection></VTKFile>";
        fs::write(&path, text).unwrap();
        let listed = read_pvd(&path).unwrap();
        assert_eq!(
            listed,
            [(1e-3, dir.join("a/f0.vtu")), (2.5, dir.join("f1.vtu"))]
        );
        fs::write(&path, "<DataSet file=\"f.vtu\"/>").unwrap();
        assert!(
            read_pvd(&path)
                .unwrap_err()
                .to_string()
                .contains("timestep")
        );
        fs::remove_dir_all(&dir).unwrap();
    }

    /// Goal: the scene's spelling of the compression option.
    #[test]
    fn compression_uses_snake_case_names() {
        let names: Vec<String> = [Compression::None, Compression::Lz4, Compression::Zlib]
            .iter()
            .map(|c| serde_json::to_string(c).unwrap())
            .collect();
        assert_eq!(names, ["\"none\"", "\"lz4\"", "\"zlib\""]);
        assert_eq!(Compression::default(), Compression::None);
    }
}
