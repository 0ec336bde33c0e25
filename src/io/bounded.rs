//! Reading a whole input file with a size limit, so `/dev/zero` or a huge
//! file given by mistake is refused instead of filling the memory.

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

/// The UTF-8 byte order mark some editors put at the start of a file.
pub(crate) const BOM: &[u8] = b"\xEF\xBB\xBF";

/// Reads at most `limit` bytes of `path`.
///
/// # Errors
/// The I/O error of opening or reading it, or one saying the file is
/// larger than `limit` bytes and is not `what` (e.g. "an experiment file").
pub fn read_bounded(path: &Path, limit: u64, what: &str) -> io::Result<Vec<u8>> {
    let file = File::open(path)?;
    // A regular file says its size: refuse before reading.
    if file
        .metadata()
        .is_ok_and(|m| m.is_file() && m.len() > limit)
    {
        return Err(too_large(limit, what));
    }
    let mut bytes = Vec::new();
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(limit, what));
    }
    Ok(bytes)
}

fn too_large(limit: u64, what: &str) -> io::Error {
    io::Error::other(format!(
        "it is larger than {} MiB: not {what}",
        limit.div_ceil(1 << 20)
    ))
}

/// As [`read_bounded`] for a text file: UTF-8, a leading byte order mark
/// skipped.
///
/// # Errors
/// As [`read_bounded`], or one naming the first byte that is not UTF-8.
pub fn read_text_bounded(path: &Path, limit: u64, what: &str) -> io::Result<String> {
    let bytes = read_bounded(path, limit, what)?;
    let body = bytes.strip_prefix(BOM).unwrap_or(&bytes);
    String::from_utf8(body.to_vec()).map_err(|e| {
        io::Error::other(format!(
            "byte {} is not UTF-8 text: not {what}",
            e.utf8_error().valid_up_to() + 1
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_inputs_are_refused_and_a_byte_order_mark_skipped() {
        let err = read_bounded(Path::new("/dev/zero"), 1 << 20, "a table").unwrap_err();
        assert!(
            err.to_string().contains("larger than 1 MiB: not a table"),
            "{err}"
        );
        let dir = std::env::temp_dir().join(format!("varspec-bounded-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("bom.json");
        std::fs::write(&file, b"\xEF\xBB\xBF{\"a\": 1}").unwrap();
        assert_eq!(read_text_bounded(&file, 100, "x").unwrap(), "{\"a\": 1}");
        std::fs::write(&file, b"ab\xFFc").unwrap();
        let err = read_text_bounded(&file, 100, "a JSON file").unwrap_err();
        assert!(err.to_string().contains("byte 3 is not UTF-8"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
