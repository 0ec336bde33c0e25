//! Atomic file output: write to a temporary file in the destination's folder,
//! flush it to disk, rename it over the destination and sync the folder. A
//! reader never sees a half-written file, and a failed or killed write
//! leaves the old file whole.
//!
//! Only regular files are replaced. A symbolic link is followed (its target
//! is written, the link stays); a device, FIFO or socket is written in place
//! (`-o /dev/null` must not replace /dev/null); a folder is refused.
//!
//! [`all_or_nothing`] groups a command's outputs: inside it every write is
//! staged (temporary files written and synced, device bytes held in
//! memory) and nothing appears until the group succeeds; when any output or
//! the work fails, no output is written.

use std::cell::RefCell;
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

/// An output written but not yet made visible (inside [`all_or_nothing`]).
enum Staged {
    /// A temporary file to rename over `target`.
    Rename {
        path: PathBuf,
        tmp: PathBuf,
        target: PathBuf,
    },
    /// Bytes for a device, FIFO or socket, written in place at the end.
    InPlace {
        path: PathBuf,
        target: PathBuf,
        bytes: Vec<u8>,
    },
}

thread_local! {
    /// The outputs staged by the innermost active [`all_or_nothing`] on
    /// this thread (`None` outside one: writes are immediate).
    static STAGED: RefCell<Option<Vec<Staged>>> = const { RefCell::new(None) };
}

/// Runs `work` with every [`write_atomic`] on this thread staged, and makes
/// the outputs visible only when `work` succeeds: device bytes are written
/// first (the writes that can still fail, e.g. a full device), then the
/// temporary files are renamed over their destinations. When `work` or a
/// staged write fails, every temporary is removed and no output changes
/// (a device written before a later one failed is the exception: device
/// bytes cannot be taken back). Nested calls join the outermost group.
///
/// # Errors
/// The error of `work`, or the [`WriteError`] of the output that could not
/// be made visible.
pub fn all_or_nothing<T, E: From<WriteError>>(work: impl FnOnce() -> Result<T, E>) -> Result<T, E> {
    if STAGED.with(|s| s.borrow().is_some()) {
        return work();
    }
    STAGED.with(|s| *s.borrow_mut() = Some(Vec::new()));
    let result = work();
    let staged = STAGED.with(|s| s.borrow_mut().take()).unwrap_or_default();
    let value = match result {
        Ok(value) => value,
        Err(e) => {
            discard(&staged);
            return Err(e);
        }
    };
    if let Err(e) = write_devices(&staged) {
        discard(&staged);
        return Err(e.into());
    }
    for (i, item) in staged.iter().enumerate() {
        if let Staged::Rename { path, tmp, target } = item
            && let Err(cause) = rename_durably(tmp, target)
        {
            discard(&staged[i..]);
            return Err(WriteError {
                path: path.clone(),
                cause,
            }
            .into());
        }
    }
    Ok(value)
}

/// Writes the device bytes staged so far in the active [`all_or_nothing`]
/// group now, in order, and forgets them: the writes that can still fail
/// at the end (a full device), done before what the caller does next
/// (announcing the outputs). The renamed files still wait for the group.
///
/// # Errors
/// The [`WriteError`] of the first device that failed; the group then
/// fails when its work returns the error.
pub fn write_staged_devices() -> Result<(), WriteError> {
    let devices: Vec<Staged> = STAGED.with(|s| {
        let mut s = s.borrow_mut();
        let Some(list) = s.as_mut() else {
            return Vec::new();
        };
        let (devices, files) = std::mem::take(list)
            .into_iter()
            .partition(|item| matches!(item, Staged::InPlace { .. }));
        *list = files;
        devices
    });
    write_devices(&devices)
}

/// Writes the [`Staged::InPlace`] items of `staged` in order.
fn write_devices(staged: &[Staged]) -> Result<(), WriteError> {
    for item in staged {
        if let Staged::InPlace {
            path,
            target,
            bytes,
        } = item
            && let Err(cause) = write_in_place(target, |w| w.write_all(bytes))
        {
            return Err(WriteError {
                path: path.clone(),
                cause,
            });
        }
    }
    Ok(())
}

/// [`write_atomic`] made visible at once even inside [`all_or_nothing`]:
/// for files that must survive the command being killed (a checkpoint).
///
/// # Errors
/// As [`write_atomic`].
pub fn write_atomic_now<F>(path: &Path, write: F) -> Result<(), WriteError>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let outer = STAGED.with(|s| s.borrow_mut().take());
    let result = write_atomic(path, write);
    STAGED.with(|s| *s.borrow_mut() = outer);
    result
}

/// The bytes of an output this thread wrote: its staged temporary inside
/// [`all_or_nothing`] (the destination does not hold them yet), else the
/// file itself.
///
/// # Errors
/// The I/O error of reading it.
pub fn read_output(path: &Path) -> io::Result<Vec<u8>> {
    let target = resolve_links(path)?;
    let staged = STAGED.with(|s| {
        s.borrow().as_ref().and_then(|list| {
            list.iter().rev().find_map(|item| match item {
                Staged::Rename { tmp, target: t, .. } if *t == target => Some(tmp.clone()),
                _ => None,
            })
        })
    });
    fs::read(staged.unwrap_or(target))
}

/// Removes the temporary files of staged outputs.
fn discard(staged: &[Staged]) {
    for item in staged {
        if let Staged::Rename { tmp, .. } = item {
            let _ = fs::remove_file(tmp);
        }
    }
}

fn staging() -> bool {
    STAGED.with(|s| s.borrow().is_some())
}

fn stage(item: Staged) {
    STAGED.with(|s| {
        if let Some(list) = s.borrow_mut().as_mut() {
            list.push(item);
        }
    });
}

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
    // This process's standard output, whatever it is (a pipe, a terminal, a
    // file the shell opened for >>), is written in place through the
    // descriptor, never replaced by a rename or reopened at offset 0.
    let stdout = is_standard_output(path);
    let target = if stdout {
        path.to_path_buf()
    } else {
        resolve_links(path).map_err(fail)?
    };
    match fs::metadata(&target) {
        Ok(meta) if meta.is_dir() => {
            return Err(fail(io::Error::other(
                "it is a folder; give a file name inside it",
            )));
        }
        Ok(meta) if stdout || !meta.is_file() => {
            if staging() {
                let mut bytes = Vec::new();
                write(&mut bytes).map_err(fail)?;
                // Refuse now what cannot be opened, before the group ends.
                probe_in_place(&target, &meta).map_err(fail)?;
                stage(Staged::InPlace {
                    path: path.to_path_buf(),
                    target,
                    bytes,
                });
                return Ok(());
            }
            return write_in_place(&target, write).map_err(fail);
        }
        _ => {}
    }
    remove_stale_temporaries(&target);
    let tmp = temporary_sibling(&target);
    let result = (|| {
        let file = create_temporary(&tmp)?;
        let mut out = BufWriter::new(file);
        write(&mut out)?;
        let file = out.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        if staging() {
            return Ok(true);
        }
        rename_durably(&tmp, &target).map(|()| false)
    })();
    match result {
        Ok(true) => {
            stage(Staged::Rename {
                path: path.to_path_buf(),
                tmp,
                target,
            });
            Ok(())
        }
        Ok(false) => Ok(()),
        Err(cause) => {
            let _ = fs::remove_file(&tmp);
            Err(fail(cause))
        }
    }
}

/// Checks, before any work, that `path` can be written: it is not `-`
/// (which other tools read as standard output), its folder exists, it is
/// not a folder itself, and a file can be created there (or the device
/// opened).
///
/// # Errors
/// [`WriteError`] naming `path` and what is wrong.
pub fn check_output(path: &Path) -> Result<(), WriteError> {
    let fail = |message: String| WriteError {
        path: path.to_path_buf(),
        cause: io::Error::other(message),
    };
    // Many tools read `-` as standard output; here it would be a file
    // named `-`.
    if path.as_os_str() == "-" {
        return Err(fail(
            "`-` would be a file of that name: give /dev/stdout for standard output".into(),
        ));
    }
    let target = resolve_links(path).map_err(|cause| WriteError {
        path: path.to_path_buf(),
        cause,
    })?;
    if target.is_dir() || path.as_os_str().to_string_lossy().ends_with('/') {
        return Err(fail("it is a folder; give a file name inside it".into()));
    }
    match target.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) if !dir.is_dir() => {
            return Err(fail(format!("the folder {} does not exist", dir.display())));
        }
        _ => {}
    }
    // Probe: the destination (a device) opens for writing, or a file can be
    // created beside it (a read-only or virtual file system refuses here,
    // before the work, rather than after it).
    let probe = match fs::metadata(&target) {
        Ok(meta) if !meta.is_file() => probe_in_place(&target, &meta),
        _ => {
            let tmp = temporary_sibling(&target);
            let created = create_temporary(&tmp).map(drop);
            let _ = fs::remove_file(&tmp);
            created
        }
    };
    probe.map_err(|cause| WriteError {
        path: path.to_path_buf(),
        cause,
    })
}

/// The file `path` names, to tell whether two paths are one file: links
/// resolved and the folder made canonical. `None` for a device, FIFO or
/// socket (`-o /dev/null` may be named twice) and for a path whose folder
/// does not resolve (its write is refused on its own).
pub fn file_identity(path: &Path) -> Option<PathBuf> {
    let target = resolve_links(path).ok()?;
    if fs::metadata(&target).is_ok_and(|m| !m.is_file()) {
        return None;
    }
    let name = target.file_name()?;
    let dir = match target.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => fs::canonicalize(dir).ok()?,
        None => std::env::current_dir().ok()?,
    };
    Some(dir.join(name))
}

/// Follows symbolic links (up to 32) to the path that will be written; a
/// dangling link resolves to where its target would be, and a link to a
/// device, FIFO or socket stops at the link (written through it).
fn resolve_links(path: &Path) -> io::Result<PathBuf> {
    let mut current = path.to_path_buf();
    for _ in 0..32 {
        match fs::symlink_metadata(&current) {
            // A link to a device, FIFO or socket is written through the
            // link: /dev/stdout leads to /proc/self/fd/1, whose target
            // reads "pipe:[…]", a name no path reaches (only the kernel's
            // own resolution of the link opens it).
            Ok(meta)
                if meta.file_type().is_symlink()
                    && fs::metadata(&current).is_ok_and(|m| !m.is_file() && !m.is_dir()) =>
            {
                return Ok(current);
            }
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

/// Checks that a device opens for writing. A FIFO or socket is not
/// opened: opening a FIFO for writing waits for a reader.
fn probe_in_place(target: &Path, meta: &fs::Metadata) -> io::Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = meta.file_type();
        if kind.is_fifo() || kind.is_socket() {
            return Ok(());
        }
    }
    #[cfg(not(unix))]
    let _ = meta;
    fs::OpenOptions::new().write(true).open(target).map(drop)
}

/// Whether `path` is this process's standard output: the same file as
/// descriptor 1 (`/dev/stdout`, or the file or pipe it leads to). Linux,
/// through /proc; elsewhere false.
pub fn is_standard_output(path: &Path) -> bool {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(a), Ok(b)) = (fs::metadata(path), fs::metadata("/proc/self/fd/1")) {
            return a.dev() == b.dev() && a.ino() == b.ino();
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = path;
    false
}

/// Writes a device, FIFO or socket directly; standard output through the
/// process's own descriptor.
fn write_in_place<F>(path: &Path, write: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    if is_standard_output(path) {
        let mut out = io::stdout().lock();
        write(&mut out)?;
        return out.flush();
    }
    let file = fs::OpenOptions::new().write(true).open(path)?;
    let mut out = BufWriter::new(file);
    write(&mut out)?;
    out.flush()
}

/// Renames the synced temporary over `target`, then syncs the folder that
/// holds it so the rename itself survives a crash (Unix; folders cannot be
/// opened elsewhere).
fn rename_durably(tmp: &Path, target: &Path) -> io::Result<()> {
    fs::rename(tmp, target)?;
    #[cfg(test)]
    tests::JOURNAL.with(|j| j.borrow_mut().push(format!("rename {}", target.display())));
    #[cfg(unix)]
    {
        let dir = folder_of(target);
        File::open(dir)?.sync_all()?;
        #[cfg(test)]
        tests::JOURNAL.with(|j| j.borrow_mut().push(format!("sync {}", dir.display())));
    }
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
    let dir = folder_of(path);
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

/// The folder holding `path`: its parent, or `.` for a bare file name.
pub fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Creates the temporary an output is written to before its rename; a
/// refusal says so (in /proc, for one, an existing file can be opened but
/// nothing created beside it, and the bare error was "No such file").
fn create_temporary(tmp: &Path) -> io::Result<File> {
    File::create(tmp).map_err(|e| {
        io::Error::new(
            e.kind(),
            format!(
                "no file can be created in {} (an output is written to a temporary file beside \
                 it, then renamed): {e}",
                folder_of(tmp).display()
            ),
        )
    })
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

    thread_local! {
        /// What `rename_durably` did on this thread, in order.
        pub(super) static JOURNAL: std::cell::RefCell<Vec<String>> =
            const { std::cell::RefCell::new(Vec::new()) };
    }

    #[test]
    fn every_rename_is_followed_by_a_sync_of_its_folder() {
        let dir = std::env::temp_dir().join(format!("varspec-atomic-sync-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("a.csv"), dir.join("b.csv"));
        JOURNAL.with(|j| j.borrow_mut().clear());
        write_atomic(&a, |w| w.write_all(b"one")).unwrap();
        all_or_nothing(|| -> Result<(), WriteError> {
            write_atomic(&a, |w| w.write_all(b"two"))?;
            write_atomic(&b, |w| w.write_all(b"three"))
        })
        .unwrap();
        let expected: Vec<String> = [&a, &a, &b]
            .iter()
            .flat_map(|p| {
                [
                    format!("rename {}", p.display()),
                    format!("sync {}", dir.display()),
                ]
            })
            .collect();
        assert_eq!(JOURNAL.with(|j| j.borrow().clone()), expected);
        fs::remove_dir_all(&dir).unwrap();
    }

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
        // (The device, FIFO and /proc checks below run on Linux, where CI
        // runs; elsewhere the paths they need may not exist.)
        #[cfg(target_os = "linux")]
        {
            let null = Path::new("/dev/null");
            write_atomic(null, |w| w.write_all(b"discarded")).unwrap();
            assert!(
                !fs::metadata(null).unwrap().is_file(),
                "/dev/null was replaced"
            );
        }
        // A FIFO is written in place (a reader gets the bytes) and stays a
        // FIFO.
        #[cfg(target_os = "linux")]
        {
            let made = std::process::Command::new("mkfifo")
                .arg(dir.join("pipe"))
                .status();
            assert!(
                made.as_ref().is_ok_and(|s| s.success()),
                "mkfifo (coreutils) failed: {made:?}"
            );
            use std::os::unix::fs::FileTypeExt;
            let pipe = dir.join("pipe");
            let reader = {
                let pipe = pipe.clone();
                std::thread::spawn(move || fs::read(pipe).unwrap())
            };
            check_output(&pipe).unwrap();
            write_atomic(&pipe, |w| w.write_all(b"through")).unwrap();
            assert_eq!(reader.join().unwrap(), b"through");
            assert!(fs::metadata(&pipe).unwrap().file_type().is_fifo());
            fs::remove_file(&pipe).unwrap();
        }
        // A temporary left by a process that no longer runs is removed by
        // the next write to the same file; pid 4194304 is above Linux's
        // largest pid.
        let stale = dir.join(".target.txt.tmp-4194304-0");
        fs::write(&stale, b"half").unwrap();
        write_atomic(&target, |w| w.write_all(b"again")).unwrap();
        #[cfg(target_os = "linux")]
        assert!(!stale.exists(), "the stale temporary is still there");
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
    fn a_group_of_outputs_appears_whole_or_not_at_all() {
        let dir = std::env::temp_dir().join(format!("varspec-atomic-group-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("a.txt"), dir.join("b.txt"));
        fs::write(&a, b"old a").unwrap();
        // The second output fails: the first keeps its old bytes.
        let failed: Result<(), WriteError> = all_or_nothing(|| {
            write_atomic(&a, |w| w.write_all(b"new a"))?;
            assert_eq!(read_output(&a).unwrap(), b"new a", "staged bytes");
            assert_eq!(fs::read(&a).unwrap(), b"old a", "visible too early");
            write_atomic(&b, |_| Err(io::Error::other("boom")))
        });
        assert!(failed.unwrap_err().to_string().contains("boom"));
        assert_eq!(fs::read(&a).unwrap(), b"old a");
        assert!(!b.exists());
        // The work fails after both were written: neither appears.
        let failed: Result<(), WriteError> = all_or_nothing(|| {
            write_atomic(&a, |w| w.write_all(b"new a"))?;
            write_atomic(&b, |w| w.write_all(b"new b"))?;
            Err(WriteError {
                path: dir.clone(),
                cause: io::Error::other("later work failed"),
            })
        });
        assert!(failed.is_err());
        assert_eq!(fs::read(&a).unwrap(), b"old a");
        assert!(!b.exists());
        // A device that fails when written (Linux's /dev/full) stops the
        // group before any file is renamed.
        #[cfg(target_os = "linux")]
        {
            let full = Path::new("/dev/full");
            let failed: Result<(), WriteError> = all_or_nothing(|| {
                write_atomic(&a, |w| w.write_all(b"new a"))?;
                write_atomic(full, |w| w.write_all(b"bytes"))
            });
            assert!(failed.unwrap_err().to_string().contains("/dev/full"));
            assert_eq!(fs::read(&a).unwrap(), b"old a");
        }
        // Success: both appear; a checkpoint written inside appears at once.
        let ckpt = dir.join("c.txt");
        all_or_nothing(|| {
            write_atomic(&a, |w| w.write_all(b"new a"))?;
            write_atomic_now(&ckpt, |w| w.write_all(b"now"))?;
            assert_eq!(fs::read(&ckpt).unwrap(), b"now");
            write_atomic(&b, |w| w.write_all(b"new b"))
        })
        .unwrap();
        assert_eq!(fs::read(&a).unwrap(), b"new a");
        assert_eq!(fs::read(&b).unwrap(), b"new b");
        let names: Vec<String> = fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names.len(), 3, "temporaries left behind: {names:?}");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn missing_folder_is_a_named_error() {
        let path = Path::new("/nonexistent-varspec-dir/out.csv");
        let err = write_atomic(path, |w| w.write_all(b"x")).unwrap_err();
        assert!(err.to_string().contains("/nonexistent-varspec-dir/out.csv"));
    }
}
