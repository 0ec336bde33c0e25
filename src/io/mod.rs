//! File formats and atomic output.

pub mod atomic;
pub mod bounded;
pub mod npy;
pub mod pointfile;
pub mod tables;

pub use atomic::{
    WriteError, all_or_nothing, check_output, read_output, write_atomic, write_atomic_now,
};
pub use bounded::{read_bounded, read_text_bounded};
pub use pointfile::{PointFileError, PointFormat, read_point_sets, write_point_sets};
