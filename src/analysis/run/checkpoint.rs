//! Checkpoints: DIR/checkpoint.bin holds everything a driver's step loop carries, so
//! `impact resume DIR` continues a stopped run and ends bit-identical to an uninterrupted one.
//!
//! Layout
//! ```text
//! b"IMPACTCP"  magic (8 bytes)
//! u32 LE       format version (FORMAT)
//! postcard     Checkpoint: the scene text and --set overrides, the summary so far, the
//!              counters, the output position and the driver's carry (state, kinematics,
//!              contact status, step control, energies)
//! ```
//! The file is written whole to a temporary name and renamed. The solver's factorization is
//! not stored: the step after a checkpoint refactors K* in the run that wrote it and in the
//! resumed one alike, so both take the same path (one extra factorization per checkpoint).

use super::record::RecorderPosition;
use super::tally::StepIterations;
use crate::analysis::steppers::carry::Carry;
use crate::analysis::steppers::newton::Counters;
use crate::analysis::summary::{BucklingSummary, Summary};
use crate::output::{OutputError, write_atomic};
use crate::scene::{InputError, SceneSource};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The checkpoint's file name inside the output folder.
pub const FILE: &str = "checkpoint.bin";
const MAGIC: &[u8; 8] = b"IMPACTCP";
/// Bumped whenever a stored type changes: an old checkpoint is refused, not misread.
/// 2: material points carry a temperature, the explicit carry its clock.
/// 4: the implicit dynamic carry holds the last step's mean velocity (the predictor).
/// 5: the explicit clock keeps the range of the steps it set apart from the clipped ones.
/// 6: the implicit error watch, rejected steps, the probes' last values, the summary's
///    error fields.
/// 7: the bulk viscosity's work in the energies and the summary, its pressures in the
///    explicit carry.
/// 8: the mass scaling's loss in the energies and the summary, its factors and the nodal
///    masses in the explicit carry; central difference's kinetic shadow in the energies.
/// 9: the mortar pairs' master block in the contact state.
/// 10: the subcycling's element bounds and counts in the explicit carry.
/// 12: the history's window since its last row (rows at a cadence, `output::thinning`).
/// 13: the tight stable step's ratios in the explicit carry.
/// 14: the ALE remaps' kinetic energy loss in the energies and the summary, their element
///     masses and counts in the explicit carry.
/// 15: the global stable step's element stiffnesses and last estimate in the tight step's
///     carry.
/// 16: each body's internal and plastic work in the state, each body's energies in the
///     summary.
/// 17: the one-point kernel's hourglass forces and their work in the explicit carry.
/// 18: the first slave past an obstacle's end and the time of the peak force in the contact
///     record and the summary.
/// 19: the step ratios a subcycled run's levels were graded with in its carry.
/// 20: the last increment, the next one's start, in the static carry; the Newton iterations
///     of each step, tallied.
/// 21: the arc-length carry (an arc-length run writes checkpoints).
const FORMAT: u32 = 21;

/// A whole run at the end of a converged step.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Checkpoint {
    /// The scene file as the run named it (messages, relative mesh files).
    pub scene_path: String,
    pub source: SceneSource,
    /// The summary so far (steps, drift, counters are filled from `counters` at the end).
    pub summary: Summary,
    pub counters: Counters,
    pub step_iterations: StepIterations,
    pub factorizations: usize,
    pub back_substitutions: usize,
    pub wall_seconds: f64,
    pub recorder: RecorderPosition,
    pub buckling: Option<BucklingSummary>,
    pub carry: Carry,
}

pub fn path(dir: &Path) -> PathBuf {
    dir.join(FILE)
}

/// Writes DIR/checkpoint.bin atomically.
pub fn write(dir: &Path, checkpoint: &Checkpoint) -> Result<(), OutputError> {
    let path = path(dir);
    let body = postcard::to_stdvec(checkpoint)
        .map_err(|e| OutputError::invalid(&path, format!("cannot encode the checkpoint: {e}")))?;
    let mut bytes = Vec::with_capacity(body.len() + 12);
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&FORMAT.to_le_bytes());
    bytes.extend_from_slice(&body);
    write_atomic(&path, &bytes)
}

/// Reads DIR/checkpoint.bin; a missing, foreign, old or damaged file is bad input.
pub fn read(dir: &Path) -> Result<Checkpoint, InputError> {
    let path = path(dir);
    let bytes = std::fs::read(&path).map_err(|e| {
        InputError::new(
            &path,
            format!(
                "cannot read the checkpoint ({e}); run with analysis.checkpoint_every = N \
                 (or --checkpoint-every N) to write one"
            ),
        )
    })?;
    if bytes.len() < 12 || &bytes[..8] != MAGIC {
        return Err(InputError::new(&path, "not an impact checkpoint"));
    }
    let format = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if format != FORMAT {
        return Err(InputError::new(
            &path,
            format!(
                "checkpoint format {format}, this impact reads format {FORMAT}: rerun the scene"
            ),
        ));
    }
    postcard::from_bytes(&bytes[12..])
        .map_err(|e| InputError::new(&path, format!("damaged checkpoint: {e}")))
}
