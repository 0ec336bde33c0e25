//! Atomic file output: write to a temporary file in the destination's folder,
//! flush it to disk, then rename it over the destination. A reader never sees
//! a half-written file, and a failed write leaves the old file untouched.

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::Error;

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `path` atomically with the bytes `write` produces.
///
/// # Errors
/// [`Error::Write`] naming `path` if the folder is missing or not writable,
/// `write` fails, or the rename fails; the temporary file is removed.
pub fn write_atomic<F>(path: &Path, write: F) -> Result<(), Error>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let fail = |cause| Error::Write {
        path: path.to_path_buf(),
        cause,
    };
    let tmp = temporary_sibling(path);
    let result = (|| {
        let file = File::create(&tmp)?;
        let mut out = BufWriter::new(file);
        write(&mut out)?;
        let file = out.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(fail)
}

fn temporary_sibling(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let unique = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp_name = format!(".{name}.tmp-{}-{unique}", std::process::id());
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.join(tmp_name),
        _ => PathBuf::from(tmp_name),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_whole_file_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("varspec-atomic-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.txt");
        write_atomic(&path, |w| w.write_all(b"first")).unwrap();
        write_atomic(&path, |w| w.write_all(b"second")).unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "second");
        let err = write_atomic(&path, |_| Err(io::Error::other("boom"))).unwrap_err();
        assert!(err.to_string().contains("a.txt") && err.to_string().contains("boom"));
        assert_eq!(fs::read_to_string(&path).unwrap(), "second");
        let leftovers = fs::read_dir(&dir).unwrap().count();
        assert_eq!(leftovers, 1, "temporary files were left behind");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn missing_folder_is_a_named_error() {
        let path = Path::new("/nonexistent-varspec-dir/out.csv");
        let err = write_atomic(path, |w| w.write_all(b"x")).unwrap_err();
        assert!(err.to_string().contains("/nonexistent-varspec-dir/out.csv"));
    }
}
