//! The tables of an experiment, from its cells: `variances.csv`,
//! `slopes.csv` (with two or more N) and a `README.md` with the command that
//! made them. A single run and a merge of its shards write the same bytes.

use std::path::Path;

use super::run::{Cell, Shard};
use super::spec::{Experiment, ExperimentError};
use crate::integrands;
use crate::io::write_atomic;
use crate::variance::{fit_slope, theoretical_rate};

/// Writes the three files into `out` and returns the README's text.
///
/// # Errors
/// [`ExperimentError::Invalid`] naming the file that could not be written.
pub fn write_results(
    e: &Experiment,
    file: &str,
    cells: &[Cell],
    out: &Path,
) -> Result<String, ExperimentError> {
    let fail = |what: &str, err: String| ExperimentError::Invalid {
        file: file.to_string(),
        reason: format!("writing {what}: {err}"),
    };
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "sampler",
        "integrand",
        "n",
        "variance",
        "stderr",
        "method",
        "sets",
    ])
    .map_err(|err| fail("variances.csv", err.to_string()))?;
    for c in cells {
        w.write_record([
            c.sampler.clone(),
            c.integrand.clone(),
            c.n.to_string(),
            format!("{:e}", c.variance),
            c.stderr.map_or(String::new(), |s| format!("{s:e}")),
            c.method.clone(),
            e.sets.to_string(),
        ])
        .map_err(|err| fail("variances.csv", err.to_string()))?;
    }
    let bytes = w
        .into_inner()
        .map_err(|err| fail("variances.csv", err.to_string()))?;
    write_atomic(&out.join("variances.csv"), |w| w.write_all(&bytes))
        .map_err(|err| fail("variances.csv", err.to_string()))?;

    let functions: Vec<_> = e
        .integrands
        .iter()
        .map(|s| integrands::parse(s).expect("validated with the experiment"))
        .collect();
    let mut md = format!(
        "# {}\n\n{}\n\nCommand: `cargo run --release -- experiment {file} -o <this folder>`\n\n",
        e.name, e.description
    );
    md += &format!(
        "Sampler-level predictions of the shift-randomized estimator's variance, mean over {} realizations \
         (seed {}) ± standard error; spatial form unless marked (F: Fourier form).\n\n",
        e.sets, e.seed
    );
    let header: Vec<String> = functions
        .iter()
        .map(|f| format!("`{}`", f.spec()))
        .collect();
    let pick = |s: usize, i: usize| -> Vec<&Cell> {
        cells
            .iter()
            .filter(|c| c.sampler_index == s && c.integrand_index == i)
            .collect()
    };
    let table = |md: &mut String, title: &str, cell: &dyn Fn(usize, usize) -> String| {
        *md += &format!(
            "## {title}\n\n| sampler | {} |\n|---|{}\n",
            header.join(" | "),
            "---|".repeat(header.len())
        );
        for (si, s) in e.samplers.iter().enumerate() {
            let cols: Vec<String> = (0..functions.len()).map(|i| cell(si, i)).collect();
            *md += &format!("| {s} | {} |\n", cols.join(" | "));
        }
        *md += "\n";
    };
    for (ni, &requested) in e.n.iter().enumerate() {
        table(
            &mut md,
            &format!("Variance at N ≈ {requested}"),
            &|s, i| {
                pick(s, i)
                    .into_iter()
                    .find(|c| c.n_index == ni)
                    .map_or("–".into(), |c| {
                        let mark = if c.method == "fourier" { " (F)" } else { "" };
                        let n = if c.n != c.requested {
                            format!(" (N = {})", c.n)
                        } else {
                            String::new()
                        };
                        let err = c
                            .stderr
                            .map_or("± unknown (1 set)".into(), |s| format!("± {s:.1e}"));
                        format!("{:.4e} {err}{mark}{n}", c.variance)
                    })
            },
        );
    }
    if e.n.len() >= 2 {
        let fit = |s: usize, i: usize| {
            let cs = pick(s, i);
            let ns: Vec<f64> = cs.iter().map(|c| c.n as f64).collect();
            let vs: Vec<f64> = cs.iter().map(|c| c.variance).collect();
            let distinct = {
                let mut v = ns.clone();
                v.sort_by(f64::total_cmp);
                v.dedup();
                v.len()
            };
            (vs.iter().all(|&v| v > 0.0) && distinct >= 2)
                .then(|| fit_slope(&ns, &vs).ok())
                .flatten()
        };
        table(
            &mut md,
            "Fitted rate: slope of log Var on log N [95% CI] (theory)",
            &|s, i| {
                let theory =
                    theoretical_rate(&e.samplers[s], functions[i].class(), functions[i].dim());
                let th = theory.map_or(String::new(), |t| format!(" ({t})"));
                match fit(s, i) {
                    None => format!("no slope: fewer than two distinct N or a zero variance{th}"),
                    Some(f) => {
                        let ci = f
                            .slope_ci
                            .map_or(String::new(), |(l, h)| format!(" [{l:.2}, {h:.2}]"));
                        format!("{:.2}{ci}{th}", f.slope)
                    }
                }
            },
        );
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record([
            "sampler",
            "integrand",
            "slope",
            "ci_low",
            "ci_high",
            "theory",
        ])
        .map_err(|err| fail("slopes.csv", err.to_string()))?;
        for (si, s) in e.samplers.iter().enumerate() {
            for (i, f) in functions.iter().enumerate() {
                if let Some(fit) = fit(si, i) {
                    let ci = |v: Option<f64>| v.map_or(String::new(), |x| x.to_string());
                    let th = theoretical_rate(s, f.class(), f.dim())
                        .map_or(String::new(), |t| t.to_string());
                    w.write_record([
                        s.clone(),
                        f.spec(),
                        fit.slope.to_string(),
                        ci(fit.slope_ci.map(|c| c.0)),
                        ci(fit.slope_ci.map(|c| c.1)),
                        th,
                    ])
                    .map_err(|err| fail("slopes.csv", err.to_string()))?;
                }
            }
        }
        let bytes = w
            .into_inner()
            .map_err(|err| fail("slopes.csv", err.to_string()))?;
        write_atomic(&out.join("slopes.csv"), |w| w.write_all(&bytes))
            .map_err(|err| fail("slopes.csv", err.to_string()))?;
    } else if out.join("slopes.csv").exists() {
        // A previous run's slopes must not sit beside tables without them.
        std::fs::remove_file(out.join("slopes.csv"))
            .map_err(|err| fail("slopes.csv (stale)", err.to_string()))?;
    }
    write_atomic(&out.join("README.md"), |w| w.write_all(md.as_bytes()))
        .map_err(|err| fail("README.md", err.to_string()))?;
    Ok(md)
}

/// Removes what a run of the other kind left in `out`, so a folder never
/// holds tables and shards of different runs side by side: a whole run
/// (`shard` None) removes every `shard-*-of-*.json`; a shard run of a
/// split into n removes the tables (README.md, variances.csv, slopes.csv:
/// `merge` writes them again) and shards of other splits. Other files are
/// left alone.
///
/// # Errors
/// The first file that could not be removed.
pub fn remove_other_runs(out: &Path, shard: Option<Shard>) -> Result<(), ExperimentError> {
    let Ok(entries) = std::fs::read_dir(out) else {
        return Ok(());
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let split = name
            .strip_prefix("shard-")
            .and_then(|r| r.strip_suffix(".json"))
            .and_then(|r| r.split_once("-of-"))
            .and_then(|(_, n)| n.parse::<usize>().ok());
        let stale = match (shard, split) {
            (None, Some(_)) => true,
            (Some(s), Some(n)) => n != s.count,
            (Some(_), None) => TABLES.contains(&name.as_str()),
            (None, None) => false,
        };
        if stale {
            std::fs::remove_file(entry.path()).map_err(|err| ExperimentError::Invalid {
                file: out.display().to_string(),
                reason: format!("removing the earlier run's {name}: {err}"),
            })?;
        }
    }
    Ok(())
}

/// The files a whole run (or `merge`) writes.
const TABLES: [&str; 3] = ["README.md", "variances.csv", "slopes.csv"];
