//! `varspec experiment FILE`: run a declarative experiment (JSON) and write
//! its tables to a results folder, with the command that made them.
//!
//! ```json
//! { "name": "rates", "samplers": ["random", "jitter"], "integrands": ["disk:r=0.3"],
//!   "n": [64, 256, 1024, 4096], "sets": 16, "seed": 0 }
//! ```
//! Every (sampler, integrand, N) gets the sampler-level spatial prediction
//! (mean over `sets` realizations, with its standard error; the Fourier form
//! for integrands without a closed-form autocovariance). With two or more N
//! the log-log slope, its 95% CI and the theoretical rate are tabulated too.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::Deserialize;

use super::progress;
use varspec::integrands;
use varspec::io::write_atomic;
use varspec::samplers;
use varspec::variance::{VarianceError, fit_slope, fourier, spatial, theoretical_rate};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Experiment {
    name: String,
    #[serde(default)]
    description: String,
    samplers: Vec<String>,
    integrands: Vec<String>,
    n: Vec<usize>,
    #[serde(default = "default_sets")]
    sets: usize,
    #[serde(default)]
    seed: u64,
}

fn default_sets() -> usize {
    16
}

#[derive(clap::Args)]
pub struct Args {
    /// Experiment file (JSON).
    file: PathBuf,
    /// Output folder (default results/<name>).
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
}

struct Cell {
    sampler: String,
    integrand: String,
    requested: usize,
    n: usize,
    variance: f64,
    stderr: f64,
    method: &'static str,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(&a.file)
        .with_context(|| format!("cannot read {}", a.file.display()))?;
    let e: Experiment = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a valid experiment", a.file.display()))?;
    if e.samplers.is_empty() || e.integrands.is_empty() || e.n.is_empty() || e.sets == 0 {
        bail!(
            "{}: samplers, integrands and n must be non-empty and sets >= 1",
            a.file.display()
        );
    }
    let functions = e
        .integrands
        .iter()
        .map(|s| integrands::parse(s))
        .collect::<Result<Vec<_>, _>>()?;
    let out = a
        .output
        .clone()
        .unwrap_or_else(|| Path::new("results").join(&e.name));
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    let bar = progress::bar(
        (e.samplers.len() * functions.len() * e.n.len()) as u64,
        &e.name,
    );
    // Realizations are drawn once per (sampler, N) and shared by every
    // integrand (optimized samplers cost a descent per set).
    let mut cells_by_key = std::collections::BTreeMap::new();
    for (si, sampler) in e.samplers.iter().enumerate() {
        for (ni, &requested) in e.n.iter().enumerate() {
            let dim = functions[0].dim();
            if functions.iter().any(|f| f.dim() != dim) {
                bail!(
                    "{}: all integrands of an experiment must have the same dimension",
                    a.file.display()
                );
            }
            let (s, n) = samplers::build_nearest(sampler, requested, Some(dim), &[])?;
            let sets = samplers::generate_sets(s.as_ref(), e.seed, e.sets, &|| {})?;
            for (fi, f) in functions.iter().enumerate() {
                let realization = |r: usize| -> Result<_, VarianceError> { Ok(sets[r].clone()) };
                let (variance, stderr, method) = match spatial(f.as_ref(), e.sets, realization) {
                    Ok(p) => (p.variance, p.stderr, "spatial"),
                    Err(VarianceError::NoAutocovariance { .. }) => {
                        let p = fourier(f.as_ref(), 127, 1e-10, e.sets, realization)?;
                        (p.variance, p.stderr, "fourier")
                    }
                    Err(err) => return Err(err.into()),
                };
                let cell = Cell {
                    sampler: sampler.clone(),
                    integrand: f.spec(),
                    requested,
                    n,
                    variance,
                    stderr,
                    method,
                };
                cells_by_key.insert((si, fi, ni), cell);
                bar.inc(1);
            }
        }
    }
    let cells: Vec<Cell> = cells_by_key.into_values().collect();
    bar.finish_and_clear();
    write_atomic(&out.join("variances.csv"), |w| {
        writeln!(w, "sampler,integrand,n,variance,stderr,method,sets")?;
        for c in &cells {
            writeln!(
                w,
                "{},\"{}\",{},{:e},{:e},{},{}",
                c.sampler, c.integrand, c.n, c.variance, c.stderr, c.method, e.sets
            )?;
        }
        Ok(())
    })?;
    let mut md = format!(
        "# {}\n\n{}\n\nCommand: `cargo run --release -- experiment {}`\n\n",
        e.name,
        e.description,
        a.file.display()
    );
    md += &format!(
        "Sampler-level predictions of the shift-randomized estimator's variance, mean over {} realizations \
         (seed {}) ± standard error; spatial form unless marked.\n\n",
        e.sets, e.seed
    );
    let header: Vec<String> = functions
        .iter()
        .map(|f| format!("`{}`", f.spec()))
        .collect();
    let table = |rows: &mut String, title: &str, cell: &dyn Fn(&str, usize) -> String| {
        *rows += &format!(
            "## {title}\n\n| sampler | {} |\n|---|{}\n",
            header.join(" | "),
            "---|".repeat(header.len())
        );
        for s in &e.samplers {
            let cols: Vec<String> = (0..functions.len()).map(|i| cell(s, i)).collect();
            *rows += &format!("| {s} | {} |\n", cols.join(" | "));
        }
        *rows += "\n";
    };
    let pick = |s: &str, i: usize| -> Vec<&Cell> {
        cells
            .iter()
            .filter(|c| c.sampler == s && c.integrand == functions[i].spec())
            .collect()
    };
    for &requested in &e.n {
        table(
            &mut md,
            &format!("Variance at N ≈ {requested}"),
            &|s, i| {
                let c = pick(s, i).into_iter().find(|c| c.requested == requested);
                c.map_or("–".into(), |c| {
                    let mark = if c.method == "fourier" { " (F)" } else { "" };
                    let n = if c.n != c.requested {
                        format!(" (N = {})", c.n)
                    } else {
                        String::new()
                    };
                    format!("{:.4e} ± {:.1e}{mark}{n}", c.variance, c.stderr)
                })
            },
        );
    }
    if e.n.len() >= 2 {
        let mut slopes = String::from("sampler,integrand,slope,ci_low,ci_high,theory\n");
        table(
            &mut md,
            "Fitted rate: slope of log Var on log N [95% CI] (theory)",
            &|s, i| {
                let cs = pick(s, i);
                let ns: Vec<f64> = cs.iter().map(|c| c.n as f64).collect();
                let vs: Vec<f64> = cs.iter().map(|c| c.variance).collect();
                if vs.iter().any(|&v| v <= 0.0) {
                    return "variance 0".into();
                }
                let fit = fit_slope(&ns, &vs);
                let theory = theoretical_rate(s, functions[i].class(), functions[i].dim());
                let ci = fit
                    .slope_ci
                    .map_or(String::new(), |(l, h)| format!(" [{l:.2}, {h:.2}]"));
                let th = theory.map_or(String::new(), |t| format!(" ({t})"));
                format!("{:.2}{ci}{th}", fit.slope)
            },
        );
        for s in &e.samplers {
            for (i, f) in functions.iter().enumerate() {
                let cs = pick(s, i);
                let ns: Vec<f64> = cs.iter().map(|c| c.n as f64).collect();
                let vs: Vec<f64> = cs.iter().map(|c| c.variance).collect();
                if vs.iter().all(|&v| v > 0.0) {
                    let fit = fit_slope(&ns, &vs);
                    let (l, h) = fit.slope_ci.unwrap_or((f64::NAN, f64::NAN));
                    let th = theoretical_rate(s, f.class(), f.dim())
                        .map_or(String::new(), |t| t.to_string());
                    slopes += &format!("{s},\"{}\",{},{l},{h},{th}\n", f.spec(), fit.slope);
                }
            }
        }
        write_atomic(&out.join("slopes.csv"), |w| w.write_all(slopes.as_bytes()))?;
    }
    write_atomic(&out.join("README.md"), |w| w.write_all(md.as_bytes()))?;
    print!("{md}");
    println!("wrote {}", out.display());
    Ok(())
}
