//! Every row of the hostile-input table (tests/data/hostile-inputs.tsv,
//! issues 14 and 15): the command fails or succeeds as the row says, says
//! the row's phrase, never panics or aborts, and a failed command writes no
//! file. results/hostile-inputs.md shows what each input answers.

use crate::common;

use common::hostile::{cases, run, write_fixtures};

#[test]
fn every_hostile_input_gets_its_answer() {
    let dir = common::temp_dir("hostile");
    write_fixtures(&dir);
    let exe = std::path::Path::new(env!("CARGO_BIN_EXE_varspec"));
    let rows = cases();
    assert!(rows.len() >= 40, "the table lost rows: {}", rows.len());
    let failures: Vec<String> = rows
        .iter()
        .filter_map(|case| {
            run(exe, &dir, case)
                .meets(case)
                .err()
                .map(|why| format!("varspec {}: {why}", case.args.join(" ")))
        })
        .collect();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
