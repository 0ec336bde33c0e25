//! One memory budget for every large allocation: sizes computed from user
//! input are estimated before anything is allocated and refused, with the
//! numbers, when they exceed what the process can get.
//!
//! The limit is `VARSPEC_MEMORY_MIB` when set, else 80 % of the smallest of
//! what the process may still use:
//! - the memory the kernel reports available (`MemAvailable` in
//!   /proc/meminfo);
//! - the headroom of the process's memory cgroup and each of its ancestors
//!   (v2: `memory.max − memory.current`; v1: `memory.limit_in_bytes −
//!   memory.usage_in_bytes`), the limit a container or a Slurm job sets;
//! - the headroom of the address-space limit (`ulimit -v`, the soft
//!   `Max address space` of /proc/self/limits, minus `VmSize`).
//!
//! Where none of these can be read (not Linux), 8 GiB.

use std::path::Path;

/// The environment variable that sets the budget.
pub const BUDGET_VARIABLE: &str = "VARSPEC_MEMORY_MIB";

/// The budget [`BUDGET_VARIABLE`] sets: `None` when it is unset.
///
/// # Errors
/// A value that is not a whole number of MiB (`2MiB`, `1.5`, `-5`, empty),
/// naming the variable: a budget the user believes is set must not be
/// dropped silently for the automatic one.
pub fn budget_from_env() -> Result<Option<u64>, String> {
    match std::env::var_os(BUDGET_VARIABLE) {
        None => Ok(None),
        Some(raw) => {
            let text = raw.to_string_lossy();
            text.trim().parse::<u64>().map(Some).map_err(|_| {
                format!(
                    "{BUDGET_VARIABLE}={text:?} is not a whole number of MiB \
                     (e.g. {BUDGET_VARIABLE}=4096); unset it for 80% of the available memory"
                )
            })
        }
    }
}

/// The budget in MiB ([`budget_from_env`] when it holds one; the command
/// line refuses a malformed value before any work).
pub fn limit_mib() -> u64 {
    if let Ok(Some(v)) = budget_from_env() {
        return v;
    }
    headroom_bytes().map_or(8 * 1024, |b| b / (1 << 20) * 4 / 5)
}

/// The smallest headroom the kernel reports, in bytes.
fn headroom_bytes() -> Option<u64> {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let meminfo = read("/proc/meminfo").and_then(|t| meminfo_available(&t));
    let cgroup =
        read("/proc/self/cgroup").and_then(|t| cgroup_headroom(&t, Path::new("/sys/fs/cgroup")));
    let address = match (read("/proc/self/limits"), read("/proc/self/status")) {
        (Some(limits), Some(status)) => address_space_headroom(&limits, &status),
        _ => None,
    };
    [meminfo, cgroup, address].into_iter().flatten().min()
}

/// `MemAvailable` of /proc/meminfo, in bytes.
fn meminfo_available(meminfo: &str) -> Option<u64> {
    kib_field(meminfo, "MemAvailable:")
}

/// A `Name:   123 kB` field, in bytes.
fn kib_field(text: &str, name: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(name))?;
    let kib: u64 = line[name.len()..].split_whitespace().next()?.parse().ok()?;
    kib.checked_mul(1024)
}

/// A cgroup limit file's value; `max` (v2) and v1's near-2⁶³ "unlimited"
/// are no limit.
fn limit_value(text: &str) -> Option<u64> {
    let v: u64 = text.trim().parse().ok()?;
    (v < 1 << 62).then_some(v)
}

/// The smallest `limit − (usage − inactive file cache)` over the process's
/// memory cgroup and its ancestors, from /proc/self/cgroup's text and the
/// cgroup mount `root`. Usage counts page cache the kernel reclaims on
/// demand; its inactive part is subtracted, as container runtimes do
/// (`inactive_file` in v2's memory.stat, `total_inactive_file` in v1's).
fn cgroup_headroom(proc_cgroup: &str, root: &Path) -> Option<u64> {
    let mut best: Option<u64> = None;
    for line in proc_cgroup.lines() {
        let mut parts = line.splitn(3, ':');
        let (Some(_), Some(controllers), Some(path)) = (parts.next(), parts.next(), parts.next())
        else {
            continue;
        };
        let (base, limit_file, usage_file, inactive_key) = if controllers.is_empty() {
            (
                root.to_path_buf(),
                "memory.max",
                "memory.current",
                "inactive_file",
            )
        } else if controllers.split(',').any(|c| c == "memory") {
            (
                root.join("memory"),
                "memory.limit_in_bytes",
                "memory.usage_in_bytes",
                "total_inactive_file",
            )
        } else {
            continue;
        };
        let mut dir = base.join(path.trim_start_matches('/'));
        loop {
            let limit = std::fs::read_to_string(dir.join(limit_file)).ok();
            if let Some(limit) = limit.as_deref().and_then(limit_value) {
                let usage = std::fs::read_to_string(dir.join(usage_file))
                    .ok()
                    .and_then(|u| u.trim().parse::<u64>().ok())
                    .unwrap_or(0);
                let inactive = std::fs::read_to_string(dir.join("memory.stat"))
                    .ok()
                    .and_then(|stat| stat_field(&stat, inactive_key))
                    .unwrap_or(0);
                let room = limit.saturating_sub(usage.saturating_sub(inactive));
                best = Some(best.map_or(room, |b| b.min(room)));
            }
            if dir == base || !dir.pop() {
                break;
            }
        }
    }
    best
}

/// A `key value` line of a cgroup's memory.stat.
fn stat_field(stat: &str, key: &str) -> Option<u64> {
    stat.lines().find_map(|l| {
        let (k, v) = l.split_once(' ')?;
        (k == key).then(|| v.trim().parse().ok()).flatten()
    })
}

/// The soft address-space limit of /proc/self/limits minus the process's
/// `VmSize` (/proc/self/status), in bytes; None when unlimited.
fn address_space_headroom(limits: &str, status: &str) -> Option<u64> {
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    let soft: u64 = line["Max address space".len()..]
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let used = kib_field(status, "VmSize:").unwrap_or(0);
    Some(soft.saturating_sub(used))
}

/// What does not fit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{what} needs {}, more than the {limit_mib} MiB available \
     (VARSPEC_MEMORY_MIB overrides the limit); {hint}",
    needed_text(*needed_mib)
)]
pub struct TooMuchMemory {
    /// What would be allocated.
    pub what: String,
    /// The estimate.
    pub needed_mib: u64,
    /// The budget.
    pub limit_mib: u64,
    /// What to change.
    pub hint: String,
}

fn needed_text(mib: u64) -> String {
    if mib == u64::MAX {
        "more bytes than a 64-bit size can count".into()
    } else {
        format!("about {mib} MiB")
    }
}

/// Checks an estimate of `bytes` (None: it overflows) against the budget.
///
/// # Errors
/// [`TooMuchMemory`] naming `what`, the numbers and `hint`.
pub fn check(what: &str, bytes: Option<f64>, hint: &str) -> Result<(), TooMuchMemory> {
    let limit_mib = limit_mib();
    let needed_mib = match bytes {
        Some(b) if b.is_finite() => (b / (1024.0 * 1024.0)).ceil() as u64,
        _ => u64::MAX,
    };
    if needed_mib > limit_mib {
        return Err(TooMuchMemory {
            what: what.into(),
            needed_mib,
            limit_mib,
            hint: hint.into(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_with_the_numbers_and_overflow_is_refused() {
        let err = check("a test grid", Some(1e18), "lower --res").unwrap_err();
        let message = err.to_string();
        assert!(
            message.contains("a test grid needs about 953674316407 MiB"),
            "{message}"
        );
        assert!(message.contains("lower --res"), "{message}");
        assert_eq!(check("x", None, "h").unwrap_err().needed_mib, u64::MAX);
        check("a small table", Some(1024.0), "").unwrap();
    }

    #[test]
    fn meminfo_and_address_space_fields_are_read_in_bytes() {
        let meminfo =
            "MemTotal:       24000000 kB\nMemFree:  100 kB\nMemAvailable:   20000000 kB\n";
        assert_eq!(meminfo_available(meminfo), Some(20_000_000 * 1024));
        assert_eq!(meminfo_available("MemTotal: 5 kB\n"), None);
        let limits = "Limit                     Soft Limit           Hard Limit           Units\n\
                      Max stack size            8388608              unlimited            bytes\n\
                      Max address space         2147483648           unlimited            bytes\n";
        let status = "Name:\tvarspec\nVmPeak:\t  600000 kB\nVmSize:\t  524288 kB\n";
        assert_eq!(
            address_space_headroom(limits, status),
            Some(2_147_483_648 - 524_288 * 1024)
        );
        let unlimited = limits.replace("2147483648", "unlimited");
        assert_eq!(address_space_headroom(&unlimited, status), None);
    }

    #[test]
    fn cgroup_headroom_is_the_smallest_over_the_ancestors() {
        let root = std::env::temp_dir().join(format!("varspec-cgroup-{}", std::process::id()));
        let job = root.join("slurm/job_7");
        std::fs::create_dir_all(&job).unwrap();
        let write =
            |dir: &Path, name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
        // v2: the job may use 3 GiB and has 1 GiB; its parent allows more.
        write(&job, "memory.max", "3221225472\n");
        // 1.5 GiB in use, of which 0.5 GiB inactive page cache: 2 GiB free.
        write(&job, "memory.current", "1610612736\n");
        write(
            &job,
            "memory.stat",
            "anon 1073741824\nfile 536870912\ninactive_file 536870912\nactive_file 0\n",
        );
        write(&root.join("slurm"), "memory.max", "max\n");
        write(&root, "memory.max", "17179869184\n");
        write(&root, "memory.current", "0\n");
        assert_eq!(
            cgroup_headroom("0::/slurm/job_7\n", &root),
            Some(2 * 1024 * 1024 * 1024)
        );
        // v1: the memory controller's own hierarchy; "unlimited" ignored.
        let v1 = root.join("memory/box");
        std::fs::create_dir_all(&v1).unwrap();
        write(&v1, "memory.limit_in_bytes", "1000000\n");
        write(&v1, "memory.usage_in_bytes", "500000\n");
        write(
            &v1,
            "memory.stat",
            "cache 200000\ninactive_file 1\ntotal_inactive_file 100000\n",
        );
        write(
            &root.join("memory"),
            "memory.limit_in_bytes",
            "9223372036854771712\n",
        );
        assert_eq!(
            cgroup_headroom("4:cpu,cpuacct:/box\n3:memory:/box\n", &root),
            Some(600_000)
        );
        // No memory controller named, nothing read.
        assert_eq!(cgroup_headroom("2:cpu:/box\n", &root), None);
        // A malformed line is skipped, not the end of the reading.
        assert_eq!(
            cgroup_headroom("garbage\n3:memory:/box\n", &root),
            Some(600_000)
        );
        std::fs::remove_dir_all(&root).unwrap();
    }
}
