//! `varspec bench`: speed against error, printed side by side and written as
//! CSV. Timing goals live here and in criterion benches, never in tests.

use std::path::PathBuf;
use std::time::Instant;

use clap::Subcommand;
use rustfft::num_complex::Complex64;

use varspec::io::write_atomic;
use varspec::rng::set_rng;
use varspec::samplers;
use varspec::spectrum::dft::sample_spectrum;
use varspec::spectrum::{FrequencyBox, Method, NufftPlan, Sign, SpectrumError, expected_power};

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Spectrum: direct vs fast (NUFFT) time and error at several tolerances.
    Spectrum(SpectrumArgs),
}

#[derive(clap::Args)]
pub struct SpectrumArgs {
    /// CSV of the table.
    #[arg(long, default_value = "results/bench-spectrum.csv")]
    csv: PathBuf,
    /// Skip the 1,048,576-point case.
    #[arg(long)]
    quick: bool,
}

pub fn run(c: BenchCommand) -> anyhow::Result<()> {
    match c {
        BenchCommand::Spectrum(a) => spectrum(a),
    }
}

struct Row {
    case: String,
    method: String,
    seconds: f64,
    max_power_error: Option<f64>,
    max_rel_error: Option<f64>,
}

/// Best of `repeats` wall times of `f`.
fn time<T>(repeats: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..repeats {
        let start = Instant::now();
        let v = f();
        best = best.min(start.elapsed().as_secs_f64());
        out = Some(v);
    }
    (best, out.expect("at least one repeat"))
}

fn spectrum(a: SpectrumArgs) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    let threads = rayon::current_num_threads();
    println!(
        "speed against error, {threads} threads; errors are max over k against the direct sums"
    );
    println!(
        "{:<44} {:<16} {:>11} {:>14} {:>14}",
        "case", "method", "seconds", "max |dP|", "max |dS|/N"
    );

    // N = 4096 random points on the 256² box (|k| < 128).
    let n = 4096;
    let points = samplers::build("random", n, Some(2), &[])?.sample(&mut set_rng(1, 0))?;
    let freqs = FrequencyBox::from_resolution(2, 256);
    let case = format!("random N={n}, 256^2 box");
    let (direct_s, exact) = time(2, || sample_spectrum(&points, &freqs));
    let push = |rows: &mut Vec<Row>, r: Row| {
        println!(
            "{:<44} {:<16} {:>11.5} {:>14} {:>14}",
            r.case,
            r.method,
            r.seconds,
            r.max_power_error.map_or("-".into(), |e| format!("{e:.3e}")),
            r.max_rel_error.map_or("-".into(), |e| format!("{e:.3e}"))
        );
        rows.push(r);
    };
    push(
        &mut rows,
        Row {
            case: case.clone(),
            method: "direct".into(),
            seconds: direct_s,
            max_power_error: Some(0.0),
            max_rel_error: Some(0.0),
        },
    );
    for tol in [1e-3, 1e-6, 1e-9, 1e-12] {
        let plan = NufftPlan::new(freqs, tol)?;
        let mut scratch = plan.make_scratch();
        let mut out = vec![Complex64::new(0.0, 0.0); freqs.len()];
        let (secs, ()) = time(5, || {
            plan.type1(&points, None, Sign::Negative, &mut out, &mut scratch)
        });
        let (dp, ds) = out
            .iter()
            .zip(&exact)
            .fold((0.0f64, 0.0f64), |(dp, ds), (f, e)| {
                (
                    dp.max((f.norm_sqr() - e.norm_sqr()).abs() / n as f64),
                    ds.max((f - e).norm() / n as f64),
                )
            });
        push(
            &mut rows,
            Row {
                case: case.clone(),
                method: format!("fast tol={tol:e} ({:.0}x)", direct_s / secs),
                seconds: secs,
                max_power_error: Some(dp),
                max_rel_error: Some(ds),
            },
        );
    }

    // Expected spectrum of 1000 jittered 1024-point sets on 128².
    let jitter = samplers::build("jitter", 1024, Some(2), &[])?;
    let freqs = FrequencyBox::from_resolution(2, 128);
    let (secs, _) = time(2, || {
        expected_power(
            freqs,
            Method::Fast { tolerance: 1e-6 },
            1000,
            |r| {
                jitter
                    .sample(&mut set_rng(2, r as u64))
                    .map_err(|e| SpectrumError::Pcf(e.to_string()))
            },
            &|| {},
        )
    });
    push(
        &mut rows,
        Row {
            case: "expected, 1000 x jitter N=1024, 128^2".into(),
            method: "fast tol=1e-6".into(),
            seconds: secs,
            max_power_error: None,
            max_rel_error: None,
        },
    );

    // Growth with N and K: 512² box, fast only.
    let sizes: &[usize] = if a.quick {
        &[65_536]
    } else {
        &[65_536, 1_048_576]
    };
    for &n in sizes {
        let points = samplers::build("random", n, Some(2), &[])?.sample(&mut set_rng(3, 0))?;
        let freqs = FrequencyBox::from_resolution(2, 512);
        for tol in [1e-6, 1e-12] {
            let plan = NufftPlan::new(freqs, tol)?;
            let mut scratch = plan.make_scratch();
            let mut out = vec![Complex64::new(0.0, 0.0); freqs.len()];
            let (secs, ()) = time(3, || {
                plan.type1(&points, None, Sign::Negative, &mut out, &mut scratch)
            });
            push(
                &mut rows,
                Row {
                    case: format!("random N={n}, 512^2 box"),
                    method: format!("fast tol={tol:e}"),
                    seconds: secs,
                    max_power_error: None,
                    max_rel_error: None,
                },
            );
        }
    }
    write_atomic(&a.csv, |w| {
        writeln!(
            w,
            "case,method,seconds,max_power_error,max_rel_error,threads"
        )?;
        for r in &rows {
            let opt = |v: Option<f64>| v.map_or(String::new(), |e| format!("{e:e}"));
            writeln!(
                w,
                "\"{}\",\"{}\",{},{},{},{threads}",
                r.case,
                r.method,
                r.seconds,
                opt(r.max_power_error),
                opt(r.max_rel_error)
            )?;
        }
        Ok(())
    })?;
    println!("wrote {}", a.csv.display());
    Ok(())
}
