//! Every parser of user input against mutated inputs (issue 14): no panic
//! and no input slower than a second. Bounded here (4000 inputs per
//! parser, fixed seed); the long run of ≥ 1,000,000 per parser is
//! `cargo run --profile fuzz --example fuzz_parsers` (overflow checks on),
//! recorded in results/fuzz.

mod common;

use common::fuzz::{fuzz, targets};

#[test]
fn no_parser_panics_or_hangs_on_mutated_input() {
    std::panic::set_hook(Box::new(|_| {}));
    let mut report = Vec::new();
    for target in targets() {
        let tally = fuzz(&target, 0x00f0_2217, 0, 4000);
        report.push(format!(
            "{}: {} inputs, {} accepted, {} panics, {} slow, slowest {:?}; first failures {:?}",
            target.name,
            tally.inputs,
            tally.accepted,
            tally.panics,
            tally.slow,
            tally.slowest,
            tally.failures
        ));
        assert!(tally.inputs == 4000);
        if tally.panics > 0 || tally.slow > 0 {
            let _ = std::panic::take_hook();
            panic!("{}", report.join("\n"));
        }
    }
    let _ = std::panic::take_hook();
    eprintln!("{}", report.join("\n"));
}

#[test]
fn every_parser_is_fuzzed_once() {
    let names: Vec<&str> = targets().iter().map(|t| t.name).collect();
    let mut unique = names.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(
        unique.len(),
        names.len(),
        "a target listed twice: {names:?}"
    );
}

/// The mutations start from valid inputs: were a format change to break the
/// seeds, every mutation would stop at the first error and the fuzzing
/// above would reach nothing deeper.
#[test]
fn every_seed_input_parses() {
    for target in targets() {
        for seed in &target.seeds {
            assert!(
                (target.run)(seed),
                "{}: the seed input {:?} is refused",
                target.name,
                String::from_utf8_lossy(seed)
            );
        }
    }
}
