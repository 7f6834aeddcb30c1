//! Output files read by other tools (the output contract of docs/user-guide.md): the VTK time series
//! (`vtk`: DIR/NAME.pvd + DIR/vtk/NAME_NNNNN.vtu), the history table (`history`: history.csv),
//! and charts drawn from them (`plot`: SVG and PNG with plotters).
//!
//! Every file is written whole to a temporary name and renamed, so a crash leaves either the
//! previous version or the new one, never a truncated file. Numbers are written at full
//! precision (shortest text that parses back to the same f64).

pub mod console;
pub mod history;
pub mod plot;
pub mod thinning;
pub mod vtk;
pub mod vtu;

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

/// What went wrong writing or reading an output file; the message names the file.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// A file system call failed (`action` says which: "create folder", "write", ...).
    #[error("{}: cannot {action}: {source}", .path.display())]
    Io {
        path: PathBuf,
        action: &'static str,
        #[source]
        source: io::Error,
    },
    /// An array (a field, a history row) has the wrong number of entries.
    #[error("{}: {what} has {found} entries, expected {expected}", .path.display())]
    Length {
        path: PathBuf,
        what: String,
        expected: usize,
        found: usize,
    },
    /// NaN or infinity in a field: ParaView would silently leave it out of the colour range.
    #[error("{}: {field}[{index}] component {component} is {value}; only finite values can be written", .path.display())]
    NonFinite {
        path: PathBuf,
        field: &'static str,
        index: usize,
        component: usize,
        value: f64,
    },
    /// Frame times must increase strictly: ParaView merges equal timesteps silently.
    #[error("{}: frame time {time} does not come after the previous frame's {previous}", .path.display())]
    TimeNotIncreasing {
        path: PathBuf,
        time: f64,
        previous: f64,
    },
    /// Anything else that makes the input unusable (bad name, bad connectivity, bad .pvd).
    #[error("{}: {reason}", .path.display())]
    Invalid { path: PathBuf, reason: String },
}

impl OutputError {
    pub(crate) fn io(path: &Path, action: &'static str, source: io::Error) -> OutputError {
        OutputError::Io {
            path: path.to_path_buf(),
            action,
            source,
        }
    }

    pub(crate) fn invalid(path: &Path, reason: impl Into<String>) -> OutputError {
        OutputError::Invalid {
            path: path.to_path_buf(),
            reason: reason.into(),
        }
    }
}

/// Writes bytes to `path` atomically: a temporary file in the same folder, fsync-free flush, then rename.
///
/// The temporary file is `path` with `.tmp` appended. A crash leaves the old `path` (or none)
/// and possibly a stale `.tmp`, never a truncated `path`.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_atomic_parts(path, &[bytes])
}

/// As `write_atomic`, for a file given as consecutive parts (no copy into one buffer).
pub fn write_atomic_parts(path: &Path, parts: &[impl AsRef<[u8]>]) -> Result<(), OutputError> {
    use std::io::Write;
    let tmp = temporary_path(path);
    // through a buffer: a frame comes as ~50 parts of a few kB, and a system call each was
    // most of the writer thread's time on a small mesh
    let written = fs::File::create(&tmp).and_then(|file| {
        let mut file = std::io::BufWriter::with_capacity(1 << 16, file);
        parts
            .iter()
            .try_for_each(|part| file.write_all(part.as_ref()))?;
        file.flush()
    });
    written.map_err(|e| {
        let _ = fs::remove_file(&tmp);
        OutputError::io(&tmp, "write", e)
    })?;
    fs::rename(&tmp, path).map_err(|e| {
        let _ = fs::remove_file(&tmp);
        OutputError::io(path, "rename the temporary file onto", e)
    })
}

/// `path` with `.tmp` appended to its file name.
pub(crate) fn temporary_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".tmp");
    path.with_file_name(name)
}

/// `x` as a person reads it in a message: six significant digits at most, trailing zeros
/// dropped, scientific notation when |x| < 1e-3 or |x| >= 1e6 (0.000014695294616961851
/// reads `1.46953e-5`, 0.0000002 reads `2e-7`, 1234.5678 reads `1234.57`). For messages
/// and progress lines only: files keep full precision (`format_f64`).
pub fn readable(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    // the exponent after rounding to six digits, so 999999.7 reads 1e6, not 1000000
    let scientific = format!("{x:.5e}");
    let (mantissa, exponent) = scientific
        .split_once('e')
        .expect("`{:e}` always writes an exponent");
    let exponent: i32 = exponent.parse().expect("`{:e}` writes an integer exponent");
    if (-3..6).contains(&exponent) {
        let decimals = (5 - exponent) as usize;
        trim_zeros(&format!("{x:.decimals$}")).to_string()
    } else {
        format!("{}e{exponent}", trim_zeros(mantissa))
    }
}

/// `1.50000` -> `1.5`, `2.000` -> `2`; text without a decimal point is left alone.
fn trim_zeros(text: &str) -> &str {
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        text
    }
}

/// Shortest text of `x` that parses back to the same bits: `{}` or `{:e}`, whichever is shorter.
///
/// Never fixed decimals: 1e-12 stays 1e-12, 0.1 stays 0.1.
pub(crate) fn format_f64(x: f64) -> String {
    let mut text = String::new();
    write_f64(&mut text, x);
    text
}

/// `format_f64` appended to `out`, from one conversion: `{:e}` gives the shortest digits
/// and the exponent, from which the length of `{}` (the same digits, the point placed, zeros
/// padded) follows without forming it; `{}` is formed only where it is the shorter (a
/// history row converted every number twice).
pub(crate) fn write_f64(out: &mut String, x: f64) {
    use std::fmt::Write;
    if !x.is_finite() || x == 0.0 {
        // NaN, inf, -inf, 0, -0: `{}` is the shorter or as short
        let _ = write!(out, "{x}");
        return;
    }
    let start = out.len();
    let _ = write!(out, "{x:e}");
    let (mantissa, exponent) = out[start..]
        .split_once('e')
        .expect("{:e} of a finite number has an exponent");
    let exponent: i64 = exponent.parse().expect("{:e}'s exponent is an integer");
    let sign = i64::from(x < 0.0);
    let digits = (mantissa.len() as i64) - sign - i64::from(mantissa.contains('.'));
    // `{}`: digits with the point inside, or zeros padded after them, or 0.00ddd
    let plain = sign
        + if exponent >= digits - 1 {
            exponent + 1
        } else if exponent >= 0 {
            digits + 1
        } else {
            1 + 1 + (-exponent - 1) + digits
        };
    if ((out.len() - start) as i64) >= plain {
        out.truncate(start);
        let _ = write!(out, "{x}");
    }
}

/// A fresh, empty folder under the system temp dir for one test.
#[cfg(test)]
pub(crate) fn test_dir(name: &str) -> PathBuf {
    use std::time::{SystemTime, UNIX_EPOCH};
    let nanos = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let dir = std::env::temp_dir().join(format!(
        "impact-output-{name}-{}-{nanos}",
        std::process::id()
    ));
    fs::create_dir_all(&dir).unwrap();
    dir
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: write_atomic replaces the file's contents and leaves no temporary file behind.
    #[test]
    fn write_atomic_replaces_contents_without_leftovers() {
        let dir = test_dir("atomic");
        let path = dir.join("a.txt");
        write_atomic(&path, b"first").unwrap();
        write_atomic(&path, b"second").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"second");
        assert!(!temporary_path(&path).exists());
        let missing = dir.join("no_such_folder").join("a.txt");
        let err = write_atomic(&missing, b"x").unwrap_err();
        assert!(err.to_string().contains("no_such_folder"), "{err}");
        fs::remove_dir_all(&dir).unwrap();
    }

    /// Goal: numbers round-trip bit-exactly and never use fixed decimals.
    #[test]
    fn format_f64_round_trips_and_is_short() {
        let values = [
            0.0,
            -0.0,
            0.1,
            1.0 / 3.0,
            1e-12,
            -2.5e-300,
            6.02e23,
            f64::MIN_POSITIVE,
            f64::MAX,
            5e-324,
            123456.789,
        ];
        for x in values {
            let text = format_f64(x);
            assert_eq!(
                text.parse::<f64>().unwrap().to_bits(),
                x.to_bits(),
                "{text}"
            );
        }
        assert_eq!(format_f64(0.1), "0.1");
        assert_eq!(format_f64(1e-12), "1e-12");
        assert_eq!(format_f64(2.0), "2");
    }

    /// Goal: the one-conversion form writes what the definition does. Reference: the
    /// definition itself, `{}` or `{:e}` (std's shortest round-trip text), whichever is
    /// shorter, `{}` on a tie; over powers of ten and their neighbours, whole numbers, the
    /// specials, and 200 000 pseudo-random bit patterns across the whole exponent range.
    #[test]
    fn write_f64_is_the_shorter_of_the_two_forms() {
        let reference = |x: f64| {
            let (plain, exponent) = (format!("{x}"), format!("{x:e}"));
            if exponent.len() < plain.len() {
                exponent
            } else {
                plain
            }
        };
        let mut values = vec![0.0, -0.0, f64::NAN, f64::INFINITY, -f64::INFINITY, 5e-324];
        for k in -30..30 {
            let p = 10f64.powi(k);
            values.extend([
                p,
                -p,
                1.5 * p,
                p * (1.0 + f64::EPSILON),
                123.0 * p,
                99999.0 * p,
            ]);
        }
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..200_000 {
            // xorshift64*: bit patterns, so every exponent appears
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            values.push(f64::from_bits(state.wrapping_mul(0x2545_F491_4F6C_DD1D)));
        }
        for x in values {
            let mut text = String::from("row,");
            write_f64(&mut text, x);
            assert_eq!(&text[4..], reference(x), "{:016x}", x.to_bits());
        }
    }

    /// Goal: message numbers read as a person writes them. Reference: the values written by
    /// hand at six significant digits (the times and steps of the messages a user reported).
    #[test]
    fn readable_numbers_have_six_significant_digits_at_most() {
        let cases = [
            (0.000014695294616961851, "1.46953e-5"),
            (0.0000002, "2e-7"),
            (1.742757e-7, "1.74276e-7"),
            (0.05, "0.05"),
            (0.001, "0.001"),
            (0.00099999995, "0.001"),
            (1234.5678, "1234.57"),
            (123456.7, "123457"),
            (999999.7, "1e6"),
            (2.1e11, "2.1e11"),
            (-0.5, "-0.5"),
            (-3.0e-9, "-3e-9"),
            (200.0, "200"),
            (0.0, "0"),
        ];
        for (x, expected) in cases {
            assert_eq!(readable(x), expected, "{x:e}");
        }
        assert_eq!(readable(f64::INFINITY), "inf");
    }
}
