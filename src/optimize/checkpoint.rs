//! Checkpoint files of a point descent: the whole [`AdamState`] so a killed
//! run continues from its last save instead of from zero, with the same
//! result bit for bit as a run never stopped.
//!
//! Format (docs/formats.md): a first line `varspec-checkpoint 1`, a second
//! line of JSON naming the run (a text the command builds from everything
//! that shapes the descent) and the sizes, then the arrays as little-endian
//! f64: x, m, v, best x (N·d each), scores, losses, seconds. Scalars that
//! may be infinite or NaN travel as the bits of their f64.

use std::io;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::adam::AdamState;
use crate::io::{WriteError, write_atomic_now};

const MAGIC: &str = "varspec-checkpoint 1";

/// The header line.
#[derive(Serialize, Deserialize)]
struct Header {
    run: String,
    dim: usize,
    n: usize,
    t: usize,
    best_score_bits: u64,
    start_score_bits: u64,
    damping_bits: u64,
    since_reset: i32,
    scores: usize,
    losses: usize,
    /// Absent in checkpoints written before it was kept (read as 0).
    #[serde(default)]
    coarse_iterations: usize,
}

/// What stops a checkpoint from being read.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// The file could not be read.
    #[error("checkpoint {path}: {cause}")]
    Read {
        /// The file.
        path: String,
        /// The cause.
        cause: io::Error,
    },
    /// Not a checkpoint, or a damaged one.
    #[error("checkpoint {path}: {reason}; delete it to start afresh")]
    Damaged {
        /// The file.
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// A checkpoint of another run.
    #[error(
        "checkpoint {path} belongs to another run:\n  it holds  {found}\n  this run {expected}\ngive another --checkpoint path, or delete it to start afresh"
    )]
    OtherRun {
        /// The file.
        path: String,
        /// The run it was written by.
        found: String,
        /// This run.
        expected: String,
    },
}

/// Writes `state` of the run described by `run` to `path`, atomically.
///
/// # Errors
/// The file cannot be written.
pub fn save(path: &Path, run: &str, state: &AdamState) -> Result<(), WriteError> {
    let header = Header {
        run: run.to_owned(),
        dim: state.dim,
        n: state.len(),
        t: state.t,
        best_score_bits: state.best_score.to_bits(),
        start_score_bits: state.start_score.to_bits(),
        damping_bits: state.damping.to_bits(),
        since_reset: state.since_reset,
        scores: state.scores.len(),
        losses: state.losses.len(),
        coarse_iterations: state.coarse_iterations,
    };
    write_atomic_now(path, |w| {
        writeln!(w, "{MAGIC}")?;
        serde_json::to_writer(&mut *w, &header)?;
        writeln!(w)?;
        for array in [
            &state.x,
            &state.m,
            &state.v,
            &state.best_x,
            &state.scores,
            &state.losses,
            &state.seconds,
        ] {
            let mut bytes = Vec::with_capacity(8 * array.len());
            for v in array.iter() {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
            w.write_all(&bytes)?;
        }
        Ok(())
    })
}

/// The state saved at `path` by the run described by `run`, or `None` when
/// there is no file there.
///
/// # Errors
/// An unreadable or damaged file, or a checkpoint of another run. The
/// file's size is checked against its header before anything is allocated.
pub fn load(path: &Path, run: &str) -> Result<Option<AdamState>, CheckpointError> {
    let name = path.display().to_string();
    // A checkpoint is a regular file this tool wrote (not a device such as
    // /dev/zero) holding the points and two moment vectors: never more
    // than the memory budget.
    match std::fs::metadata(path) {
        Ok(meta) if !meta.is_file() => {
            return Err(CheckpointError::Read {
                path: name,
                cause: io::Error::other("not a regular file: not a varspec checkpoint"),
            });
        }
        _ => {}
    }
    let limit = crate::memory::limit_mib().saturating_mul(1 << 20);
    let bytes = match crate::io::read_bounded(path, limit, "a varspec checkpoint") {
        Ok(b) => b,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
        Err(cause) => return Err(CheckpointError::Read { path: name, cause }),
    };
    let damaged = |reason: String| CheckpointError::Damaged {
        path: name.clone(),
        reason,
    };
    let mut lines = bytes.splitn(3, |&b| b == b'\n');
    let (Some(magic), Some(header), Some(body)) = (lines.next(), lines.next(), lines.next()) else {
        return Err(damaged("not a varspec checkpoint".into()));
    };
    if magic != MAGIC.as_bytes() {
        return Err(damaged(format!(
            "not a varspec checkpoint (its first line is not `{MAGIC}`)"
        )));
    }
    let h: Header =
        serde_json::from_slice(header).map_err(|e| damaged(format!("unreadable header: {e}")))?;
    if h.run != run {
        return Err(CheckpointError::OtherRun {
            path: name,
            found: h.run,
            expected: run.to_owned(),
        });
    }
    let nd = h.n.checked_mul(h.dim);
    let expected = nd
        .and_then(|nd| nd.checked_mul(4))
        .and_then(|v| v.checked_add(h.scores))
        .and_then(|v| v.checked_add(h.losses.checked_mul(2)?))
        .and_then(|v| v.checked_mul(8));
    if h.dim == 0 || expected != Some(body.len()) {
        return Err(damaged(format!(
            "{} bytes of arrays where the header ({} points in {}D, {} scores, {} losses) needs {}",
            body.len(),
            h.n,
            h.dim,
            h.scores,
            h.losses,
            expected.map_or("more than the machine can address".into(), |e| e
                .to_string())
        )));
    }
    let nd = nd.unwrap_or(0);
    let mut values = body
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("chunks of 8 bytes")));
    let mut take = |len: usize| -> Vec<f64> { values.by_ref().take(len).collect() };
    let (x, m, v, best_x) = (take(nd), take(nd), take(nd), take(nd));
    let (scores, losses, seconds) = (take(h.scores), take(h.losses), take(h.losses));
    if x.iter().chain(&best_x).any(|c| !(0.0..1.0).contains(c)) {
        return Err(damaged("a coordinate outside [0, 1)".into()));
    }
    Ok(Some(AdamState {
        dim: h.dim,
        t: h.t,
        x,
        m,
        v,
        best_score: f64::from_bits(h.best_score_bits),
        best_x,
        start_score: f64::from_bits(h.start_score_bits),
        damping: f64::from_bits(h.damping_bits),
        since_reset: h.since_reset,
        scores,
        losses,
        seconds,
        seconds_offset: 0.0,
        coarse_iterations: h.coarse_iterations,
    }))
}
