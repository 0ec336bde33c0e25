//! File formats and atomic output.

pub mod atomic;
pub mod bounded;
pub mod csv_rows;
pub mod json;
pub mod npy;
pub mod pointfile;
pub mod shards;
pub mod tables;

pub use atomic::{
    WriteError, all_or_nothing, check_output, file_identity, folder_of, is_standard_output,
    read_output, write_atomic, write_atomic_now, write_staged_devices,
};
pub use bounded::{read_bounded, read_text_bounded};
pub use csv_rows::{write_csv_headed, write_csv_rows};
pub use json::from_json;
pub use pointfile::{
    PointFileError, PointFormat, read_point_sets, read_point_sets_of_dim,
    read_point_sets_with_metadata, write_point_sets,
};

/// Writes point sets to `path` atomically, as NumPy `.npy` when its
/// extension says so (any case), else as CSV: the rule of every command's
/// `-o` (`sample --format` can also choose UTK text).
///
/// # Errors
/// [`WriteError`] naming `path`.
pub fn write_point_file(
    path: &std::path::Path,
    sets: &[crate::PointSet],
) -> Result<(), WriteError> {
    let npy = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"));
    write_atomic(path, |w| {
        if npy {
            npy::write_point_sets_npy(w, sets)
        } else {
            write_point_sets(w, sets, PointFormat::Csv)
        }
    })
}

/// At most 60 characters of `text`, escaped, for an error message that
/// quotes a line of a file.
pub fn quote(text: &str) -> String {
    let short: String = text.chars().take(60).collect();
    let mut out = short.escape_debug().to_string();
    if text.chars().count() > 60 {
        out.push('…');
    }
    out
}
