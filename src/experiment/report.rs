//! The tables of an experiment, from its cells: `variances.csv`,
//! `slopes.csv` (with two or more N), `radial.csv` and `radial-slopes.csv`
//! (when the experiment compares the radial predictor) and a `README.md`
//! with the command that made them. A single run and a merge of its shards write the same bytes.

use std::path::Path;

use super::run::{Cell, Shard};
use super::spec::{Experiment, ExperimentError};
use crate::integrands;
use crate::io::write_atomic;
use crate::variance::{SlopeFit, fit_slope, theoretical_rate, zero_to_rounding};

/// Writes the tables into `out` and returns the README's text.
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
    let rows: Vec<Vec<String>> = cells
        .iter()
        .map(|c| {
            vec![
                c.sampler.clone(),
                c.integrand.clone(),
                c.n.to_string(),
                format!("{:e}", c.variance),
                c.stderr.map_or(String::new(), |s| format!("{s:e}")),
                c.method.clone(),
                e.sets.to_string(),
                crate::rng::level_seed(e.seed, c.n).to_string(),
                format!("{:e}", c.rounding_bound),
                format!("{:e}", c.truncation_bound),
            ]
        })
        .collect();
    write_csv(
        out,
        "variances.csv",
        &[
            "sampler",
            "integrand",
            "n",
            "variance",
            "stderr",
            "method",
            "sets",
            "seed",
            "rounding_bound",
            "truncation_bound",
        ],
        &rows,
        &fail,
    )?;
    if e.radial.is_some() {
        let rows: Vec<Vec<String>> = cells
            .iter()
            .filter_map(|c| {
                let r = c.radial?;
                Some(vec![
                    c.sampler.clone(),
                    c.integrand.clone(),
                    c.n.to_string(),
                    format!("{:e}", c.variance),
                    format!("{:e}", r.variance),
                    format!("{:e}", r.variance / c.variance - 1.0),
                    format!("{:e}", r.anisotropy_bound),
                    format!("{:e}", r.fourier),
                ])
            })
            .collect();
        write_csv(
            out,
            "radial.csv",
            &[
                "sampler",
                "integrand",
                "n",
                "reference",
                "radial",
                "radial_relative_error",
                "anisotropy_bound",
                "fourier",
            ],
            &rows,
            &fail,
        )?;
    }

    let functions: Vec<_> = e
        .integrands
        .iter()
        .map(|s| integrands::parse(s).expect("validated with the experiment"))
        .collect();
    let mut md = format!(
        "{}Command: `cargo run --release -- experiment {file} -o <this folder>`\n\n",
        heading(&e.name, &e.description)
    );
    md += &format!(
        "Sampler-level predictions of the shift-randomized estimator's variance, mean over {} \
         realization{} (seed {}; each N draws its own stream, `variances.csv`'s `seed` column) ± \
         standard error; spatial form unless marked (F: Fourier form).\n\n",
        e.sets,
        if e.sets == 1 { "" } else { "s" },
        e.seed
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
                        if zero_to_rounding(c.variance, c.rounding_bound) {
                            return format!("0 to rounding (≤ {:.0e}){mark}{n}", c.rounding_bound);
                        }
                        // Sets that all give one variance (a lattice's is
                        // the same at every offset) differ by rounding only.
                        let err = c.stderr.map_or("± unknown (1 set)".into(), |s| {
                            if zero_to_rounding(s, c.rounding_bound) {
                                "± 0 to rounding".into()
                            } else {
                                format!("± {s:.1e}")
                            }
                        });
                        format!("{:.4e} {err}{mark}{n}", c.variance)
                    })
            },
        );
    }
    if let Some(r) = e.radial {
        md += &format!(
            "Radial (isotropic) form on the box |k|∞ ≤ {} from the same realizations, \
             against the reference above: radial / reference − 1 (radial.csv has the values, \
             the Cauchy–Schwarz anisotropy bound and the Fourier form on that box).\n\n",
            r.half
        );
        for (ni, &requested) in e.n.iter().enumerate() {
            table(
                &mut md,
                &format!("Radial form's relative error at N ≈ {requested}"),
                &|s, i| {
                    let cell = pick(s, i).into_iter().find(|c| c.n_index == ni);
                    match cell.and_then(|c| c.radial.map(|r| (c, r))) {
                        // No relative error against a reference that is
                        // rounding noise.
                        Some((c, _)) if zero_to_rounding(c.variance, c.rounding_bound) => {
                            "reference 0 to rounding".into()
                        }
                        Some((c, r)) => format!("{:+.2}", r.variance / c.variance - 1.0),
                        None => "–".into(),
                    }
                },
            );
        }
    }
    if e.n.len() >= 2 {
        let fit_of = |s: usize, i: usize, value: &dyn Fn(&Cell) -> Option<f64>| {
            let cs = pick(s, i);
            let ns: Vec<f64> = cs.iter().map(|c| c.n as f64).collect();
            let vs: Vec<f64> = cs.iter().map(|c| value(c).unwrap_or(f64::NAN)).collect();
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
        // A variance zero to rounding has no logarithm worth fitting.
        let fit = |s: usize, i: usize| {
            fit_of(s, i, &|c| {
                (!zero_to_rounding(c.variance, c.rounding_bound)).then_some(c.variance)
            })
        };
        let radial_fit = |s: usize, i: usize| fit_of(s, i, &|c| c.radial.map(|r| r.variance));
        let shown = |fit: Option<SlopeFit>| {
            fit.map(|f| {
                let ci = f
                    .slope_ci
                    .map_or(String::new(), |(l, h)| format!(" [{l:.2}, {h:.2}]"));
                format!("{:.2}{ci}", f.slope)
            })
        };
        table(
            &mut md,
            "Fitted rate: slope of log Var on log N [95% CI] (theory)",
            &|s, i| {
                let theory =
                    theoretical_rate(&e.samplers[s], functions[i].class(), functions[i].dim());
                // Two decimals can round an excluding interval onto the
                // theory (-1.49575 shows as -1.50): say it outside in words.
                let outside = fit(s, i).is_some_and(|f| f.excludes(theory));
                let th = theory.map_or(String::new(), |t| {
                    if outside {
                        format!(" ({t}, outside the interval)")
                    } else {
                        format!(" ({t})")
                    }
                });
                match shown(fit(s, i)) {
                    None => format!(
                        "no slope: fewer than two distinct N, or a variance zero to rounding{th}"
                    ),
                    Some(f) => format!("{f}{th}"),
                }
            },
        );
        if e.radial.is_some() {
            table(
                &mut md,
                "Rate the radial form predicts: slope of log Var on log N [95% CI]",
                &|s, i| shown(radial_fit(s, i)).unwrap_or_else(|| "no slope".into()),
            );
        }
        let ci = |v: Option<f64>| v.map_or(String::new(), |x| x.to_string());
        let mut rows = Vec::new();
        let mut radial_rows = Vec::new();
        for (si, s) in e.samplers.iter().enumerate() {
            for (i, f) in functions.iter().enumerate() {
                if let Some(fit) = fit(si, i) {
                    let th = theoretical_rate(s, f.class(), f.dim())
                        .map_or(String::new(), |t| t.to_string());
                    rows.push(vec![
                        s.clone(),
                        f.spec(),
                        fit.slope.to_string(),
                        ci(fit.slope_ci.map(|c| c.0)),
                        ci(fit.slope_ci.map(|c| c.1)),
                        th,
                    ]);
                }
                if let Some(fit) = radial_fit(si, i) {
                    radial_rows.push(vec![
                        s.clone(),
                        f.spec(),
                        fit.slope.to_string(),
                        ci(fit.slope_ci.map(|c| c.0)),
                        ci(fit.slope_ci.map(|c| c.1)),
                    ]);
                }
            }
        }
        write_csv(
            out,
            "slopes.csv",
            &[
                "sampler",
                "integrand",
                "slope",
                "ci_low",
                "ci_high",
                "theory",
            ],
            &rows,
            &fail,
        )?;
        if e.radial.is_some() {
            write_csv(
                out,
                "radial-slopes.csv",
                &["sampler", "integrand", "slope", "ci_low", "ci_high"],
                &radial_rows,
                &fail,
            )?;
        }
    }
    // A previous run's tables must not sit beside tables without them.
    let written = |name: &str| match name {
        "slopes.csv" => e.n.len() >= 2,
        "radial.csv" => e.radial.is_some(),
        "radial-slopes.csv" => e.radial.is_some() && e.n.len() >= 2,
        _ => true,
    };
    for name in TABLES {
        if !written(name) && out.join(name).exists() {
            std::fs::remove_file(out.join(name))
                .map_err(|err| fail(&format!("{name} (stale)"), err.to_string()))?;
        }
    }
    let md = with_kept_notes(out, md);
    write_atomic(&out.join("README.md"), |w| w.write_all(md.as_bytes()))
        .map_err(|err| fail("README.md", err.to_string()))?;
    Ok(md)
}

/// The line after which an experiment folder's README holds notes written
/// by hand (analysis, caveats), which a new run keeps below its own text.
pub const KEPT_NOTES: &str =
    "<!-- Notes below this line are written by hand; a new run of the experiment keeps them. -->";

/// `md` followed by the [`KEPT_NOTES`] line and the hand-written notes
/// below it in the README now in `out` (the line alone if there is none,
/// so a reader sees where notes go).
pub(super) fn with_kept_notes(out: &Path, md: String) -> String {
    let old = std::fs::read_to_string(out.join("README.md")).unwrap_or_default();
    let notes = match old.find(KEPT_NOTES) {
        Some(at) => old[at..].to_owned(),
        None => format!("{KEPT_NOTES}\n"),
    };
    format!("{}\n\n{notes}", md.trim_end())
}

/// An experiment shard's file name before its `i-of-n.json`
/// ([`crate::io::shards::shard_file_name`]).
pub const SHARD_PREFIX: &str = "shard-";

/// Removes what a run of the other kind left in `out`, so a folder never
/// holds tables and shards of different runs side by side: a whole run
/// (`shard` None) removes every `shard-*-of-*.json`; a shard run of a
/// split into n removes the tables (variances.csv, slopes.csv, …: `merge`
/// writes them again) and shards of other splits, and cuts README.md down
/// to its hand-written notes ([`KEPT_NOTES`]; removed if there are none
/// below the line), so
/// the merge keeps them. Other files are left alone.
///
/// # Errors
/// The first file that could not be removed or rewritten.
pub fn remove_other_runs(out: &Path, shard: Option<Shard>) -> Result<(), ExperimentError> {
    let Ok(entries) = std::fs::read_dir(out) else {
        return Ok(());
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let split = name
            .strip_prefix(SHARD_PREFIX)
            .and_then(|r| r.strip_suffix(".json"))
            .and_then(|r| r.split_once("-of-"))
            .and_then(|(_, n)| n.parse::<usize>().ok());
        let stale = match (shard, split) {
            (None, Some(_)) => true,
            (Some(s), Some(n)) => n != s.count,
            (Some(_), None) => TABLES.contains(&name.as_str()),
            (None, None) => false,
        };
        if !stale {
            continue;
        }
        let notes = (name == "README.md")
            .then(|| std::fs::read_to_string(entry.path()).ok())
            .flatten()
            .and_then(|old| old.find(KEPT_NOTES).map(|at| old[at..].to_owned()))
            .filter(|notes| notes.trim_end() != KEPT_NOTES);
        match notes {
            Some(notes) => write_atomic(&entry.path(), |w| w.write_all(notes.as_bytes()))
                .map_err(|err| err.to_string()),
            None => std::fs::remove_file(entry.path()).map_err(|err| err.to_string()),
        }
        .map_err(|err| ExperimentError::Invalid {
            file: out.display().to_string(),
            reason: format!("removing the earlier run's {name}: {err}"),
        })?;
    }
    Ok(())
}

/// Removes every table and shard a variance run left in `out`, before a
/// figure experiment writes its own README.md there (a figure run never
/// leaves a folder mixing the two kinds; its own earlier PNGs are
/// overwritten or, for a figure since removed from the file, left). The
/// README itself stays until the run replaces it, keeping its notes
/// ([`KEPT_NOTES`]), so a failed run leaves it whole.
///
/// # Errors
/// The first file that could not be removed.
pub fn remove_variance_runs(out: &Path) -> Result<(), ExperimentError> {
    remove_other_runs(out, None)?;
    for name in TABLES.iter().filter(|&&name| name != "README.md") {
        let path = out.join(name);
        if path.exists() {
            std::fs::remove_file(&path).map_err(|err| ExperimentError::Invalid {
                file: out.display().to_string(),
                reason: format!("removing the earlier run's {name}: {err}"),
            })?;
        }
    }
    Ok(())
}

/// The files a whole run (or `merge`) writes.
const TABLES: [&str; 5] = [
    "README.md",
    "variances.csv",
    "slopes.csv",
    "radial.csv",
    "radial-slopes.csv",
];

/// Writes `rows` under `header` to `out/name` through the csv crate,
/// atomically.
pub(super) fn write_csv(
    out: &Path,
    name: &str,
    header: &[&str],
    rows: &[Vec<String>],
    fail: &dyn Fn(&str, String) -> ExperimentError,
) -> Result<(), ExperimentError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(header)
        .map_err(|err| fail(name, err.to_string()))?;
    for row in rows {
        w.write_record(row)
            .map_err(|err| fail(name, err.to_string()))?;
    }
    let bytes = w.into_inner().map_err(|err| fail(name, err.to_string()))?;
    write_atomic(&out.join(name), |w| w.write_all(&bytes))
        .map_err(|err| fail(name, err.to_string()))
}

/// An experiment README's title and description paragraph (none for an
/// empty description, which left an empty paragraph).
pub(crate) fn heading(name: &str, description: &str) -> String {
    if description.trim().is_empty() {
        format!("# {name}\n\n")
    } else {
        format!("# {name}\n\n{description}\n\n")
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn an_empty_description_leaves_no_empty_paragraph() {
        assert_eq!(super::heading("x", " "), "# x\n\n");
        assert_eq!(super::heading("x", "A sweep."), "# x\n\nA sweep.\n\n");
    }
}
