//! The long fuzz run of issue 14: every parser of user input against
//! mutated inputs (tests/common/fuzz.rs), 1,000,000 per parser by default,
//! in parallel chunks (input i comes from stream (seed, i): reproducible
//! for any thread count). Prints a markdown table and writes `fuzz.csv` to
//! the folder given. The `fuzz` profile keeps overflow checks and debug
//! assertions on (a wrapped integer is a panic there, as in `cargo test`).
//!
//! ```sh
//! cargo run --profile fuzz --example fuzz_parsers -- results/fuzz 1000000
//! ```
//!
//! A fourth argument runs only the parsers whose name contains it
//! (`-- out 1000000 1592651810 "pattern table"`).

#[path = "../tests/common/fuzz.rs"]
mod fuzz;

use std::time::Instant;

use rayon::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = args.first().cloned().unwrap_or_else(|| "out/fuzz".into());
    let count: u64 = args.get(1).map_or(Ok(1_000_000), |a| a.parse())?;
    let seed: u64 = args.get(2).map_or(Ok(0x5eed_f022), |a| a.parse())?;
    let only = args.get(3).cloned().unwrap_or_default();
    std::fs::create_dir_all(&out)?;
    std::panic::set_hook(Box::new(|_| {}));
    let mut csv = csv::Writer::from_path(format!("{out}/fuzz.csv"))?;
    csv.write_record([
        "parser",
        "inputs",
        "accepted",
        "panics",
        "slow",
        "slowest_ms",
        "seconds",
    ])?;
    println!("| parser | inputs | accepted | panics | slower than 1 s | slowest | wall time |");
    println!("|---|---|---|---|---|---|---|");
    let mut failed = false;
    for target in fuzz::targets()
        .into_iter()
        .filter(|t| t.name.contains(&only))
    {
        let start = Instant::now();
        const CHUNK: u64 = 10_000;
        let tally = (0..count.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| fuzz::fuzz(&target, seed, c * CHUNK, CHUNK.min(count - c * CHUNK)))
            .reduce(fuzz::Tally::default, |mut a, b| {
                a.merge(b);
                a
            });
        let seconds = start.elapsed().as_secs_f64();
        csv.write_record([
            target.name.to_string(),
            tally.inputs.to_string(),
            tally.accepted.to_string(),
            tally.panics.to_string(),
            tally.slow.to_string(),
            format!("{:.3}", tally.slowest.as_secs_f64() * 1e3),
            format!("{seconds:.1}"),
        ])?;
        println!(
            "| {} | {} | {} | {} | {} | {:.2} ms | {seconds:.0} s |",
            target.name,
            tally.inputs,
            tally.accepted,
            tally.panics,
            tally.slow,
            tally.slowest.as_secs_f64() * 1e3
        );
        for (input, message) in &tally.failures {
            eprintln!("  {}: `{message}` on {input:?}", target.name);
        }
        failed |= tally.panics > 0 || tally.slow > 0;
    }
    csv.flush()?;
    if failed {
        return Err("a parser panicked or hung (inputs above)".into());
    }
    Ok(())
}
