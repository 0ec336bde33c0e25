//! Helpers shared by the test files (the suite and the fuzz binary, each
//! its own crate, use subsets, hence the `dead_code` allowance).
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// Runs the built `varspec` binary with `args`.
pub fn varspec(args: &[&str]) -> Output {
    varspec_with(args, None)
}

/// Runs `varspec` with `args`, which must succeed (the assertion shows
/// its standard error), and returns its output.
pub fn varspec_ok(args: &[&str]) -> Output {
    let out = varspec(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The JSON object in the file at `path` (a command's report).
pub fn read_json(path: &std::path::Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).expect("the report exists");
    serde_json::from_str(&text).expect("one JSON object")
}

/// Runs `varspec` with `RAYON_NUM_THREADS` set when `threads` is given.
pub fn varspec_with(args: &[&str], threads: Option<&str>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_varspec"));
    cmd.args(args);
    if let Some(t) = threads {
        cmd.env("RAYON_NUM_THREADS", t);
    }
    cmd.output().expect("the varspec binary runs")
}

/// Kills `child` with SIGKILL as soon as `ready()` holds (polled every
/// 2 ms, for at most `limit`); returns whether it held before the child
/// ended on its own, and the child's exit status.
pub fn kill_when(
    child: &mut std::process::Child,
    limit: std::time::Duration,
    ready: impl Fn() -> bool,
) -> (bool, std::process::ExitStatus) {
    let clock = std::time::Instant::now();
    let mut held = false;
    while clock.elapsed() < limit {
        if ready() {
            held = true;
            break;
        }
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    child.kill().unwrap(); // SIGKILL on Unix
    (held, child.wait().unwrap())
}

/// A fresh folder for one test's files.
pub fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("varspec-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `sets` sets of `n` points of `sampler` (seed 0) to `path`.
pub fn sample_file(sampler: &str, n: usize, sets: usize, path: &std::path::Path) {
    let (n, sets) = (n.to_string(), sets.to_string());
    let path = path.to_str().unwrap();
    varspec_ok(&["sample", sampler, "-n", &n, "--sets", &sets, "-o", path]);
}

/// Asserts that `varspec args` fails with a message containing `phrase`
/// and without a panic.
pub fn assert_fails(args: &[&str], phrase: &str) {
    let out = varspec(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} should fail");
    assert!(
        err.contains(phrase),
        "{args:?}: {err:?} should contain {phrase:?}"
    );
    assert!(!err.contains("panicked"), "{args:?}: {err}");
}
/// The Kolmogorov–Smirnov distance of `values` from U[0, 1) (sorts them).
/// Its 99% critical value for n values is about 1.63/√n.
pub fn ks_from_uniform(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len() as f64;
    values
        .iter()
        .enumerate()
        .map(|(i, &v)| (v - i as f64 / n).abs().max((v - (i + 1) as f64 / n).abs()))
        .fold(0.0, f64::max)
}

pub mod direct;
pub mod fuzz;
pub mod hostile;
