//! Checkpoints of the point descent (issue 13): a run continued from a
//! saved state ends with the same set, bit for bit, as a run never stopped;
//! a process killed with SIGKILL continues from its last save; damaged
//! checkpoints and checkpoints of another run are refused by name.

use crate::common;

use std::process::Command;
use std::sync::Mutex;
use std::time::Duration;

use varspec::optimize::adam::AdamState;
use varspec::optimize::checkpoint::{self, CheckpointError};
use varspec::optimize::{Checkpointing, DescentOptions, PointOptimizer, Target};
use varspec::registry;
use varspec::rng::set_rng;

fn optimizer(n: usize, iters: usize) -> PointOptimizer {
    let target = Target::parse("family:disks").unwrap();
    let mut options = DescentOptions::for_target(n, 2, &target);
    options.iters = iters;
    options.rel_tol = 0.0;
    PointOptimizer::new(2, &target, options).unwrap()
}

fn start(n: usize) -> varspec::points::PointSet {
    registry::build("random", n, Some(2), &[])
        .unwrap()
        .sample(&mut set_rng(5, 0))
        .unwrap()
}

#[test]
fn a_descent_continued_from_a_saved_state_takes_the_same_steps() {
    let (n, iters) = (256, 120);
    let opt = optimizer(n, iters);
    let whole = opt.optimize(start(n), &|_, _| {});
    // Save at every iteration; keep the state of iteration 57 only, write
    // it to a file and read it back, then continue from it.
    let kept = Mutex::new(None);
    let save = |s: &AdamState| {
        if s.t == 57 {
            *kept.lock().unwrap() = Some(s.clone());
        }
    };
    let every = Checkpointing {
        every: Duration::ZERO,
        save: &save,
    };
    let first = opt.optimize_from(AdamState::start(&start(n)), &|_, _| {}, Some(&every));
    assert_eq!(
        first.points.coords(),
        whole.points.coords(),
        "saving changed the run"
    );
    let state = kept.into_inner().unwrap().expect("iteration 57 was saved");
    let dir = common::temp_dir("checkpoint-lib");
    let path = dir.join("state.ckpt");
    checkpoint::save(&path, "run A", &state).unwrap();
    let loaded = checkpoint::load(&path, "run A").unwrap().unwrap();
    assert_eq!(loaded.x, state.x);
    assert_eq!(loaded.m, state.m);
    assert_eq!(loaded.v, state.v);
    assert_eq!(loaded.best_x, state.best_x);
    assert_eq!(
        (
            loaded.t,
            loaded.since_reset,
            loaded.best_score.to_bits(),
            loaded.damping.to_bits()
        ),
        (
            57,
            state.since_reset,
            state.best_score.to_bits(),
            state.damping.to_bits()
        )
    );
    let continued = opt.optimize_from(loaded, &|_, _| {}, None);
    assert_eq!(continued.points.coords(), whole.points.coords());
    assert_eq!(continued.losses, whole.losses);
    assert_eq!(continued.best_score.to_bits(), whole.best_score.to_bits());
}

#[test]
fn damaged_checkpoints_and_those_of_another_run_are_refused() {
    let dir = common::temp_dir("checkpoint-bad");
    let path = dir.join("state.ckpt");
    assert!(
        checkpoint::load(&path, "run A").unwrap().is_none(),
        "no file: a fresh start"
    );
    let mut state = AdamState::start(&start(64));
    state.t = 3;
    state.best_score = 1.0;
    checkpoint::save(&path, "run A", &state).unwrap();
    let other = checkpoint::load(&path, "run B").unwrap_err();
    assert!(matches!(other, CheckpointError::OtherRun { .. }), "{other}");
    assert!(
        other.to_string().contains("run A") && other.to_string().contains("run B"),
        "{other}"
    );
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() - 8]).unwrap();
    let cut = checkpoint::load(&path, "run A").unwrap_err();
    assert!(cut.to_string().contains("bytes of arrays"), "{cut}");
    // A header that claims 2^60 points is refused before any allocation.
    let text =
        String::from_utf8_lossy(&bytes[..bytes.iter().position(|&b| b == 0x7d).unwrap() + 1])
            .replace("\"n\":64", "\"n\":1152921504606846976");
    std::fs::write(&path, format!("{text}\n")).unwrap();
    let huge = checkpoint::load(&path, "run A").unwrap_err();
    assert!(matches!(huge, CheckpointError::Damaged { .. }), "{huge}");
    std::fs::write(&path, b"hello\nworld\n").unwrap();
    let wrong = checkpoint::load(&path, "run A").unwrap_err();
    assert!(
        wrong.to_string().contains("not a varspec checkpoint"),
        "{wrong}"
    );
}

#[test]
fn a_killed_descent_continues_from_its_checkpoint_to_the_same_set() {
    let dir = common::temp_dir("checkpoint-kill");
    // Coarse-to-fine, so the resumed run's report must carry the coarse
    // phase it did not run again.
    let args = |out: &str| -> Vec<String> {
        let report = format!("{out}.json");
        [
            "optimize",
            "points",
            "-n",
            "256",
            "--target",
            "family:disks",
            "--iters",
            "400",
            "--rel-tol",
            "0",
            "--sets",
            "1",
            "--coarse",
            "-o",
            out,
            "--report",
            &report,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let whole = dir.join("whole.csv");
    let run = common::varspec(
        &args(whole.to_str().unwrap())
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert!(run.status.success(), "{run:?}");
    let resumed = dir.join("resumed.csv");
    let ckpt = dir.join("run.ckpt");
    let mut with_checkpoint = args(resumed.to_str().unwrap());
    with_checkpoint.extend([
        "--checkpoint".into(),
        ckpt.to_str().unwrap().into(),
        "--checkpoint-every".into(),
        "0".into(),
    ]);
    let mut child = Command::new(env!("CARGO_BIN_EXE_varspec"))
        .args(&with_checkpoint)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let (saved, status) = common::kill_when(&mut child, Duration::from_secs(120), || ckpt.exists());
    assert!(
        saved,
        "no checkpoint appeared before the run ended: nothing was tested"
    );
    assert!(
        !status.success(),
        "the run finished before it was killed: nothing was tested"
    );
    assert!(!resumed.exists(), "a killed run wrote its output");
    let again = common::varspec(
        &with_checkpoint
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert!(again.status.success(), "{again:?}");
    let said = String::from_utf8_lossy(&again.stderr);
    assert!(
        said.contains("continuing from iteration"),
        "the second run did not resume: {said}"
    );
    assert_eq!(
        std::fs::read(&resumed).unwrap(),
        std::fs::read(&whole).unwrap(),
        "the resumed run's set differs from the run never stopped"
    );
    assert!(
        !ckpt.exists(),
        "the checkpoint was not removed after the output was written"
    );
    let report = |csv: &std::path::Path| {
        common::read_json(&std::path::PathBuf::from(format!("{}.json", csv.display())))
    };
    let (whole, resumed) = (report(&whole), report(&resumed));
    assert!(
        whole["coarse_iterations"][0].as_u64().unwrap() > 0,
        "no coarse phase: nothing was tested"
    );
    assert_eq!(
        resumed["coarse_iterations"], whole["coarse_iterations"],
        "the resumed report lost the coarse phase"
    );
    assert_eq!(resumed["iterations"], whole["iterations"]);
}

#[test]
fn checkpoints_of_a_run_with_another_set_count_are_named() {
    let dir = common::temp_dir("checkpoint-stray");
    let base = dir.join("run.ckpt");
    for stray in ["run.ckpt.0", "run.ckpt.1", "run.ckpt.x"] {
        std::fs::write(dir.join(stray), b"").unwrap();
    }
    let out = dir.join("x.csv");
    let run = common::varspec_ok(&[
        "optimize",
        "points",
        "-n",
        "64",
        "--target",
        "family:disks",
        "--sets",
        "1",
        "--iters",
        "5",
        "--checkpoint",
        base.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    let said = String::from_utf8_lossy(&run.stderr);
    let (zero, one) = (dir.join("run.ckpt.0"), dir.join("run.ckpt.1"));
    assert!(
        said.contains(&format!(
            "{}, {} are checkpoints of a run with another --sets",
            zero.display(),
            one.display()
        )),
        "{said}"
    );
    assert!(
        !said.contains("run.ckpt.x"),
        "not a checkpoint name: {said}"
    );
    assert!(
        zero.exists() && one.exists(),
        "another run's files are left alone"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
