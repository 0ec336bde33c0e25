//! File formats and atomic output.

pub mod atomic;
pub mod npy;
pub mod pointfile;
pub mod tables;

pub use atomic::{WriteError, check_output, write_atomic};
pub use pointfile::{PointFileError, PointFormat, read_point_sets, write_point_sets};
