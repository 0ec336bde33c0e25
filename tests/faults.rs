//! Fault tests (issue 14 §4): a write killed with SIGKILL halfway leaves
//! the old file whole, and the next write to the same path removes the
//! killed run's temporary file; an address-space limit lowers the memory
//! budget so a request beyond it is refused instead of aborting.

use crate::common;

use std::process::Command;
use std::time::Duration;

fn temporaries(dir: &std::path::Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".old.csv.tmp-"))
        .collect()
}

#[test]
fn a_killed_write_leaves_the_old_file_whole_and_no_temporary_behind() {
    let dir = common::temp_dir("sigkill");
    let target = dir.join("old.csv");
    let small = common::varspec(&[
        "sample",
        "random",
        "-n",
        "10",
        "-o",
        target.to_str().unwrap(),
    ]);
    assert!(small.status.success(), "{small:?}");
    let before = std::fs::read(&target).unwrap();
    // A write large enough (~80 MB) to be caught in the middle.
    let mut child = Command::new(env!("CARGO_BIN_EXE_varspec"))
        .args(["sample", "random", "-n", "2000000", "--sets", "1", "-o"])
        .arg(&target)
        .spawn()
        .unwrap();
    let (caught, _) = common::kill_when(&mut child, Duration::from_secs(60), || {
        temporaries(&dir)
            .iter()
            .any(|name| std::fs::metadata(dir.join(name)).is_ok_and(|m| m.len() > 1 << 20))
    });
    assert!(
        caught,
        "the write finished before it could be killed: nothing was tested"
    );
    assert_eq!(
        std::fs::read(&target).unwrap(),
        before,
        "the old file changed although the write was killed"
    );
    assert!(
        !temporaries(&dir).is_empty(),
        "a killed run leaves its temporary (removed by the next write)"
    );
    let again = common::varspec(&[
        "sample",
        "random",
        "-n",
        "10",
        "--seed",
        "3",
        "-o",
        target.to_str().unwrap(),
    ]);
    assert!(again.status.success(), "{again:?}");
    assert!(
        temporaries(&dir).is_empty(),
        "stale temporaries left: {:?}",
        temporaries(&dir)
    );
    assert_ne!(std::fs::read(&target).unwrap(), before);
}

/// The memory budget follows an address-space limit (`ulimit -v`), not only
/// the machine's free memory: a 4.5 GiB spectrum is refused, with the
/// numbers, under a 1 GiB limit instead of aborting when the allocation
/// fails (without the limit the budget would be 80% of the machine's
/// available memory, above 1024 MiB on any machine that builds this).
#[test]
fn an_address_space_limit_lowers_the_memory_budget() {
    let out = Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 1048576 && exec \"$0\" spectrum --sampler jitter -n 64 --res 4096")
        .arg(env!("CARGO_BIN_EXE_varspec"))
        .env_remove("VARSPEC_MEMORY_MIB")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let limit: u64 = stderr
        .split("more than the ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no budget named: {stderr}"));
    assert!(
        limit <= 1024 && stderr.contains("needs about"),
        "budget {limit} MiB under a 1 GiB address-space limit: {stderr}"
    );
}
