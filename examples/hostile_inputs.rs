//! Writes results/hostile-inputs.md: every row of the hostile-input table
//! (tests/data/hostile-inputs.tsv) with what the binary now answers.
//! tests/hostile_inputs.rs asserts the same rows.
//!
//! `cargo build --release && cargo run --release --example hostile_inputs -- results/hostile-inputs.md`

#[path = "../tests/common/hostile.rs"]
mod hostile;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = PathBuf::from(
        args.next()
            .unwrap_or_else(|| "results/hostile-inputs.md".into()),
    );
    let exe = args.next().map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("target/release/varspec"),
        PathBuf::from,
    );
    if !exe.exists() {
        return Err(format!(
            "{} does not exist: run `cargo build --release` first",
            exe.display()
        )
        .into());
    }
    let dir = std::env::temp_dir().join(format!("varspec-hostile-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    hostile::write_fixtures(&dir);
    let mut table = String::from(
        "# Hostile inputs and what they answer\n\n\
         Every row of tests/data/hostile-inputs.tsv (issues 14 and 15), run in a\n\
         folder of fixtures with `VARSPEC_MEMORY_MIB=4096`; tests/hostile_inputs.rs\n\
         asserts each (exit status, the phrase, no panic or abort, no file written\n\
         by a failed command).\n\n\
         `cargo build --release && cargo run --release --example hostile_inputs -- results/hostile-inputs.md`\n\n\
         | input | exit | answer | meets its row |\n|---|---|---|---|\n",
    );
    let mut met = 0;
    let cases = hostile::cases();
    for case in &cases {
        let run = hostile::run(&exe, &dir, case);
        let verdict = run.meets(case);
        met += usize::from(verdict.is_ok());
        let mut answer: String = run.answer(&case.phrase).chars().take(220).collect();
        if answer.is_empty() {
            answer = format!("(no output; wrote {})", run.new_files.join(", "));
        }
        writeln!(
            table,
            "| `varspec {}` | {} | {} | {} |",
            case.args.join(" "),
            run.code.map_or("signal".into(), |c| c.to_string()),
            answer.replace('|', "\\|").replace('`', "'"),
            verdict.map_or_else(
                |e| format!(
                    "**no**: {}",
                    e.replace('|', "\\|").chars().take(120).collect::<String>()
                ),
                |()| "yes".into()
            )
        )?;
    }
    writeln!(
        table,
        "\n{met} of {} inputs answered as their row says.",
        cases.len()
    )?;
    std::fs::remove_dir_all(&dir)?;
    std::fs::write(&out, table)?;
    println!("{met} of {} rows met; wrote {}", cases.len(), out.display());
    Ok(())
}
