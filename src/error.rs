//! The crate-wide error type: one enum wrapping each module's typed errors, so
//! callers can match on the exact condition (docs/architecture.md, "Conventions").

use crate::io::WriteError;
use crate::io::pointfile::PointFileError;
use crate::points::PointSetError;
use crate::samplers::SamplerError;

/// Every error the library reports.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A point set violates its invariants (dimension, range, finiteness).
    #[error(transparent)]
    PointSet(#[from] PointSetError),
    /// A point-set file could not be read or written.
    #[error(transparent)]
    PointFile(#[from] PointFileError),
    /// A sampler could not be configured or could not produce its points.
    #[error(transparent)]
    Sampler(#[from] SamplerError),
    /// An output file could not be written.
    #[error(transparent)]
    Write(#[from] WriteError),
}
