//! history.csv: one row of scalars per output step (the output contract of docs/user-guide.md).
//!
//! ```text
//! time,kinetic_energy,internal_energy,...     header: column names, first is `time`
//! 0,0,0,...                                   one row per `append`, comma-separated, no spaces
//! ```
//! Numbers use the shortest text that parses back to the same f64 (`0.1`, `1e-12`); NaN and
//! infinities are written as `NaN`, `inf`, `-inf` so a diverging run stays visible.

use std::cell::RefCell;
use std::fs::{self, File};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use super::{OutputError, write_f64};

/// Rows are written when this much text is waiting, or when the first row waiting is this
/// old: a system call a row was a quarter of an explicit Taylor run (6 463 rows).
const FLUSH_BYTES: usize = 1 << 16;
const FLUSH_AFTER: Duration = Duration::from_millis(200);

/// history.csv: header line, one row per call. Rows are written whole, in one call for
/// those waiting, at most `FLUSH_AFTER` after they were appended, and before a checkpoint
/// measures the file, at `flush` and when the history is dropped: a crash leaves whole rows,
/// the last fraction of a second of them possibly missing.
#[derive(Debug)]
pub struct History {
    path: PathBuf,
    file: File,
    columns: usize,
    /// Whole rows not yet written, and when the first of them was appended.
    pending: RefCell<(String, Option<Instant>)>,
}

impl Drop for History {
    fn drop(&mut self) {
        // rows appended are written before the history goes (an error here was, or will
        // never be, reported by `flush`)
        let _ = self.flush();
    }
}

impl History {
    /// Creates (or truncates) the file and its folder and writes the header.
    ///
    /// The first column must be `time`; names must be unique, non-empty, and free of commas,
    /// quotes and line breaks.
    pub fn create(path: &Path, columns: &[String]) -> Result<History, OutputError> {
        check_columns(path, columns)?;
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            fs::create_dir_all(dir).map_err(|e| OutputError::io(dir, "create folder", e))?;
        }
        let file = File::create(path).map_err(|e| OutputError::io(path, "create", e))?;
        let mut history = History {
            path: path.to_path_buf(),
            file,
            columns: columns.len(),
            pending: RefCell::default(),
        };
        history.write_line(&columns.join(","))?;
        Ok(history)
    }

    /// Appends one row; its length must match the header's.
    pub fn append(&mut self, row: &[f64]) -> Result<(), OutputError> {
        if row.len() != self.columns {
            return Err(OutputError::Length {
                path: self.path.clone(),
                what: "history row".into(),
                expected: self.columns,
                found: row.len(),
            });
        }
        let due = {
            let mut pending = self.pending.borrow_mut();
            let (text, first) = &mut *pending;
            for (i, x) in row.iter().enumerate() {
                if i > 0 {
                    text.push(',');
                }
                write_f64(text, *x);
            }
            text.push('\n');
            let first = *first.get_or_insert_with(Instant::now);
            text.len() >= FLUSH_BYTES || first.elapsed() >= FLUSH_AFTER
        };
        if due { self.flush() } else { Ok(()) }
    }

    /// Writes the rows waiting, in one call (whole rows).
    pub fn flush(&self) -> Result<(), OutputError> {
        let mut pending = self.pending.borrow_mut();
        let (text, first) = &mut *pending;
        if !text.is_empty() {
            (&self.file)
                .write_all(text.as_bytes())
                .map_err(|e| OutputError::io(&self.path, "write", e))?;
            text.clear();
        }
        *first = None;
        Ok(())
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file's length in bytes so far (whole rows only, the waiting ones written first),
    /// for a checkpoint.
    pub fn byte_len(&self) -> Result<u64, OutputError> {
        self.flush()?;
        self.file
            .metadata()
            .map(|m| m.len())
            .map_err(|e| OutputError::io(&self.path, "measure", e))
    }

    /// Reopens a history for appending, cut back to `len` bytes (its length at a checkpoint:
    /// rows written after it, by a run that was then killed, are dropped). The header must
    /// be the one given.
    pub fn resume(path: &Path, columns: &[String], len: u64) -> Result<History, OutputError> {
        check_columns(path, columns)?;
        let file = fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|e| OutputError::io(path, "open", e))?;
        let found = file
            .metadata()
            .map_err(|e| OutputError::io(path, "measure", e))?
            .len();
        if found < len {
            return Err(OutputError::invalid(
                path,
                format!("has {found} bytes, fewer than the {len} at the checkpoint"),
            ));
        }
        let header = format!("{}\n", columns.join(","));
        let mut start = vec![0u8; header.len()];
        use std::io::Read;
        (&file)
            .read_exact(&mut start)
            .map_err(|e| OutputError::io(path, "read", e))?;
        if start != header.as_bytes() {
            return Err(OutputError::invalid(
                path,
                "its header is not the scene's (another run wrote it)",
            ));
        }
        file.set_len(len)
            .map_err(|e| OutputError::io(path, "truncate", e))?;
        let mut file = file;
        use std::io::Seek;
        file.seek(std::io::SeekFrom::End(0))
            .map_err(|e| OutputError::io(path, "seek", e))?;
        Ok(History {
            path: path.to_path_buf(),
            file,
            columns: columns.len(),
            pending: RefCell::default(),
        })
    }

    /// Writes `text` and a newline in one call on the unbuffered file, so rows land whole.
    fn write_line(&mut self, text: &str) -> Result<(), OutputError> {
        let line = format!("{text}\n");
        self.file
            .write_all(line.as_bytes())
            .and_then(|()| self.file.flush())
            .map_err(|e| OutputError::io(&self.path, "write", e))
    }
}

fn check_columns(path: &Path, columns: &[String]) -> Result<(), OutputError> {
    if columns.first().map(String::as_str) != Some("time") {
        return Err(OutputError::invalid(
            path,
            format!("the first history column must be `time`, got {columns:?}"),
        ));
    }
    for (i, name) in columns.iter().enumerate() {
        if name.is_empty() || name.contains([',', '"', '\n', '\r']) {
            return Err(OutputError::invalid(
                path,
                format!("history column {i} has an unusable name {name:?}"),
            ));
        }
        if columns[..i].contains(name) {
            return Err(OutputError::invalid(
                path,
                format!("history column {name:?} appears twice"),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::test_dir;

    fn names(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    /// Goal: every value written parses back bit-equal, rows are whole, the header is as given.
    /// Setup: three rows of awkward values (1/3, 1e-300, -0, subnormal, large).
    #[test]
    fn history_rows_round_trip_bit_exact() {
        let dir = test_dir("history");
        let path = dir.join("sub").join("history.csv");
        let columns = names(&["time", "kinetic_energy", "contact_force[a-b]", "u_x[tip]"]);
        let rows = [
            [0.0, 0.0, -0.0, 5e-324],
            [1e-7, 1.0 / 3.0, 1e-300, -123456.789],
            [2e-7, f64::MAX, 0.1 + 0.2, std::f64::consts::PI],
        ];
        let mut history = History::create(&path, &columns).unwrap();
        for row in &rows {
            history.append(row).unwrap();
        }
        // the rows waiting are written when the history goes
        drop(history);
        let text = fs::read_to_string(&path).unwrap();
        let mut lines = text.lines();
        assert_eq!(
            lines.next(),
            Some("time,kinetic_energy,contact_force[a-b],u_x[tip]")
        );
        for (line, row) in lines.zip(&rows) {
            assert!(!line.contains(' '), "{line}");
            let back: Vec<f64> = line.split(',').map(|s| s.parse().unwrap()).collect();
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&back), bits(row), "{line}");
        }
        assert_eq!(text.lines().count(), 1 + rows.len());
        assert!(text.ends_with('\n'));
        fs::remove_dir_all(&dir).unwrap();
    }

    /// Goal: a wrong row length or a bad header is an error naming the file; nothing is written.
    #[test]
    fn history_rejects_bad_rows_and_headers() {
        let dir = test_dir("history-bad");
        let path = dir.join("history.csv");
        let mut history = History::create(&path, &names(&["time", "e"])).unwrap();
        history.append(&[0.0, 1.0]).unwrap();
        let err = history.append(&[1.0]).unwrap_err();
        assert!(matches!(
            err,
            OutputError::Length {
                expected: 2,
                found: 1,
                ..
            }
        ));
        assert!(err.to_string().contains("history.csv"), "{err}");
        history.flush().unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "time,e\n0,1\n");

        let other = dir.join("other.csv");
        for bad in [&["t", "e"][..], &["time", "a,b"], &["time", "e", "e"], &[]] {
            assert!(History::create(&other, &names(bad)).is_err(), "{bad:?}");
        }
        fs::remove_dir_all(&dir).unwrap();
    }
}
