//! One memory budget for every large allocation: sizes computed from user
//! input are estimated before anything is allocated and refused, with the
//! numbers, when they exceed what the machine can give.
//!
//! The limit is `VARSPEC_MEMORY_MIB` when set, else 80 % of the memory
//! the kernel reports available (`MemAvailable` in /proc/meminfo), else
//! 8 GiB where that file does not exist.

/// The budget in MiB.
pub fn limit_mib() -> u64 {
    if let Some(v) = std::env::var("VARSPEC_MEMORY_MIB")
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
    {
        return v;
    }
    available_mib().map_or(8 * 1024, |a| a * 4 / 5)
}

fn available_mib() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024)
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
}
