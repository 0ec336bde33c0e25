//! Atomic file output: write to a temporary file in the destination's folder,
//! flush it to disk, rename it over the destination and sync the folder. A
//! reader never sees a half-written file, and a failed or killed write
//! leaves the old file whole.
//!
//! Only regular files are replaced. A symbolic link is followed (its target
//! is written, the link stays); a device, FIFO or socket is written in place
//! (`-o /dev/null` must not replace /dev/null); a folder is refused.

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// An output that could not be written, naming the file.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {path}: {cause}")]
pub struct WriteError {
    /// The file that was being written.
    pub path: std::path::PathBuf,
    /// The underlying I/O error (in the message, so not repeated as a
    /// source when error chains are printed).
    pub cause: io::Error,
}

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `path` atomically with the bytes `write` produces.
///
/// # Errors
/// [`WriteError`] naming `path` if the folder is missing or not writable,
/// `write` fails, or the rename fails; the temporary file is removed.
pub fn write_atomic<F>(path: &Path, write: F) -> Result<(), WriteError>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let fail = |cause| WriteError {
        path: path.to_path_buf(),
        cause,
    };
    let target = resolve_links(path).map_err(fail)?;
    match fs::metadata(&target) {
        Ok(meta) if meta.is_dir() => {
            return Err(fail(io::Error::other(
                "it is a folder; give a file name inside it",
            )));
        }
        Ok(meta) if !meta.is_file() => return write_in_place(&target, write).map_err(fail),
        _ => {}
    }
    remove_stale_temporaries(&target);
    let tmp = temporary_sibling(&target);
    let result = (|| {
        let file = File::create(&tmp)?;
        let mut out = BufWriter::new(file);
        write(&mut out)?;
        let file = out.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        fs::rename(&tmp, &target)?;
        sync_folder(&target)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(fail)
}

/// Checks, before any work, that `path` can be written: its folder exists
/// and it is not a folder itself.
///
/// # Errors
/// [`WriteError`] naming `path` and what is wrong.
pub fn check_output(path: &Path) -> Result<(), WriteError> {
    let fail = |message: String| WriteError {
        path: path.to_path_buf(),
        cause: io::Error::other(message),
    };
    let target = resolve_links(path).map_err(|cause| WriteError {
        path: path.to_path_buf(),
        cause,
    })?;
    if target.is_dir() || path.as_os_str().to_string_lossy().ends_with('/') {
        return Err(fail("it is a folder; give a file name inside it".into()));
    }
    match target.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) if !dir.is_dir() => {
            Err(fail(format!("the folder {} does not exist", dir.display())))
        }
        _ => Ok(()),
    }
}

/// Follows symbolic links (up to 32) to the path that will be written; a
/// dangling link resolves to where its target would be.
fn resolve_links(path: &Path) -> io::Result<PathBuf> {
    let mut current = path.to_path_buf();
    for _ in 0..32 {
        match fs::symlink_metadata(&current) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let target = fs::read_link(&current)?;
                current = match current.parent() {
                    Some(dir) if target.is_relative() => dir.join(target),
                    _ => target,
                };
            }
            _ => return Ok(current),
        }
    }
    Err(io::Error::other("too many levels of symbolic links"))
}

/// Writes a device, FIFO or socket directly.
fn write_in_place<F>(path: &Path, write: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let file = fs::OpenOptions::new().write(true).open(path)?;
    let mut out = BufWriter::new(file);
    write(&mut out)?;
    out.flush()
}

/// Makes the rename durable: sync the folder that holds `path` (Unix; a
/// no-op where folders cannot be opened).
fn sync_folder(path: &Path) -> io::Result<()> {
    #[cfg(unix)]
    {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        File::open(dir)?.sync_all()?;
    }
    #[cfg(not(unix))]
    let _ = path;
    Ok(())
}

/// Removes `.NAME.tmp-PID-K` files a killed run left beside `path`, when
/// process PID no longer runs (checked in /proc; nothing is removed where
/// /proc does not exist).
fn remove_stale_temporaries(path: &Path) {
    let proc = Path::new("/proc/self");
    if !proc.exists() {
        return;
    }
    let Some(name) = path.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return;
    };
    let prefix = format!(".{name}.tmp-");
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let file = entry.file_name().to_string_lossy().into_owned();
        let Some(rest) = file.strip_prefix(&prefix) else {
            continue;
        };
        let pid = rest.split('-').next().and_then(|p| p.parse::<u32>().ok());
        if let Some(pid) = pid
            && pid != std::process::id()
            && !Path::new("/proc").join(pid.to_string()).exists()
        {
            let _ = fs::remove_file(entry.path());
        }
    }
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
    fn links_are_followed_devices_written_in_place_and_stale_temporaries_removed() {
        let dir = std::env::temp_dir().join(format!("varspec-atomic-links-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        // A symlink: the target gets the bytes, the link stays a link.
        let target = dir.join("target.txt");
        fs::write(&target, b"old").unwrap();
        let link = dir.join("link.txt");
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink("target.txt", &link).unwrap();
            write_atomic(&link, |w| w.write_all(b"new")).unwrap();
            assert!(
                fs::symlink_metadata(&link)
                    .unwrap()
                    .file_type()
                    .is_symlink()
            );
            assert_eq!(fs::read_to_string(&target).unwrap(), "new");
        }
        // A device is written in place, not replaced by a regular file.
        let null = Path::new("/dev/null");
        if null.exists() {
            write_atomic(null, |w| w.write_all(b"discarded")).unwrap();
            assert!(
                !fs::metadata(null).unwrap().is_file(),
                "/dev/null was replaced"
            );
        }
        // A temporary left by a process that no longer runs is removed by
        // the next write to the same file; pid 4194304 is above Linux's
        // largest pid.
        let stale = dir.join(".target.txt.tmp-4194304-0");
        fs::write(&stale, b"half").unwrap();
        write_atomic(&target, |w| w.write_all(b"again")).unwrap();
        if Path::new("/proc/self").exists() {
            assert!(!stale.exists(), "the stale temporary is still there");
        }
        // A folder is refused before and at writing.
        assert!(
            check_output(&dir)
                .unwrap_err()
                .to_string()
                .contains("folder")
        );
        assert!(write_atomic(&dir, |w| w.write_all(b"x")).is_err());
        assert!(
            check_output(&dir.join("nodir/x.csv"))
                .unwrap_err()
                .to_string()
                .contains("does not exist")
        );
        check_output(&dir.join("fresh.csv")).unwrap();
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn missing_folder_is_a_named_error() {
        let path = Path::new("/nonexistent-varspec-dir/out.csv");
        let err = write_atomic(path, |w| w.write_all(b"x")).unwrap_err();
        assert!(err.to_string().contains("/nonexistent-varspec-dir/out.csv"));
    }
}
