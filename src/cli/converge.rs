//! `varspec converge`: variance against N and the fitted log-log slope with
//! its confidence interval, beside the theoretical rate.

use std::path::PathBuf;

use anyhow::bail;
use clap::ValueEnum;
use serde_json::json;

use super::args::DrawArgs;
use super::progress;
use varspec::integrands;
use varspec::io::write_atomic;
use varspec::report::plot::{LinePlot, Series, line_plot_png};
use varspec::rng::set_rng;
use varspec::samplers;
use varspec::variance::{VarianceError, fit_slope, fourier, spatial, theoretical_rate};

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MethodArg {
    /// Exact spatial form (default where the integrand has a closed-form c_f).
    Spatial,
    /// Fourier form with the Parseval tail.
    Fourier,
}

#[derive(clap::Args)]
pub struct Args {
    /// Sampler name.
    #[arg(long)]
    sampler: String,
    /// Integrand spec.
    #[arg(long)]
    integrand: String,
    /// Comma-separated N values (constrained samplers use the nearest valid N).
    #[arg(short = 'n', long = "n", value_delimiter = ',', required = true)]
    ns: Vec<usize>,
    #[command(flatten)]
    draw: DrawArgs,
    /// Predictor (default: spatial, or fourier for integrands without c_f).
    #[arg(long, value_enum)]
    method: Option<MethodArg>,
    /// Fourier box |k| < K/2 for --method fourier (default 256 in 2D, 21 in 4D).
    #[arg(long)]
    res: Option<usize>,
    /// CSV of N against variance.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Log-log PNG plot with reference slopes.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

struct Point {
    requested: usize,
    n: usize,
    variance: f64,
    stderr: f64,
    truncation_bound: f64,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    super::args::check_outputs([a.csv.as_deref(), a.png.as_deref()])?;
    let f = integrands::parse(&a.integrand)?;
    if a.ns.len() < 2 {
        bail!("--n needs at least two values to fit a slope");
    }
    if a.res.is_some_and(|r| r < 3) {
        bail!("--res must be at least 3 (the box |k| < K/2 must hold a frequency besides 0)");
    }
    let method = a.method.unwrap_or(if f.dim() == 2 {
        MethodArg::Spatial
    } else {
        MethodArg::Fourier
    });
    let bar = progress::bar(a.ns.len() as u64, "converge");
    let mut points = Vec::new();
    for &requested in &a.ns {
        let (sampler, n) =
            samplers::build_nearest(&a.sampler, requested, Some(f.dim()), &a.draw.params)?;
        let realization = |r: usize| -> Result<_, VarianceError> {
            Ok(sampler.sample(&mut set_rng(a.draw.seed, r as u64))?)
        };
        let (variance, stderr, truncation_bound) = match method {
            MethodArg::Spatial => {
                let e = spatial(f.as_ref(), a.draw.sets(), realization)?;
                (e.variance, e.stderr, 0.0)
            }
            MethodArg::Fourier => {
                let e = fourier(
                    f.as_ref(),
                    a.res.map_or(varspec::variance::fourier_half(f.dim()), |r| {
                        r.saturating_sub(1) / 2
                    }),
                    1e-10,
                    a.draw.sets(),
                    realization,
                )?;
                (e.variance, e.stderr, e.truncation_bound)
            }
        };
        if variance <= 0.0 {
            bail!(
                "N = {n}: predicted variance {variance:e} is not positive; a log-log slope needs positive values"
            );
        }
        if let Some(p) = points.iter().find(|p: &&Point| p.n == n) {
            bail!(
                "--n {} and {requested} both become N = {n} for {} (constrained N); give N values that stay distinct",
                p.requested,
                a.sampler
            );
        }
        points.push(Point {
            requested,
            n,
            variance,
            stderr,
            truncation_bound,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();
    let ns: Vec<f64> = points.iter().map(|p| p.n as f64).collect();
    let vars: Vec<f64> = points.iter().map(|p| p.variance).collect();
    let fit = fit_slope(&ns, &vars);
    let theory = theoretical_rate(&a.sampler, f.class(), f.dim());
    let adjusted: Vec<String> = points
        .iter()
        .filter(|p| p.n != p.requested)
        .map(|p| format!("{} -> {}", p.requested, p.n))
        .collect();
    if let Some(path) = &a.csv {
        write_atomic(path, |w| {
            writeln!(w, "n,variance,stderr,truncation_bound")?;
            for p in &points {
                writeln!(
                    w,
                    "{},{:?},{:?},{:?}",
                    p.n, p.variance, p.stderr, p.truncation_bound
                )?;
            }
            Ok(())
        })?;
    }
    if let Some(path) = &a.png {
        let (n0, v0) = (ns[0], vars[0]);
        let line = |slope: f64| {
            vec![
                (n0, v0),
                (ns[ns.len() - 1], v0 * (ns[ns.len() - 1] / n0).powf(slope)),
            ]
        };
        let mut series = vec![Series {
            label: format!("{} (slope {:.3})", a.sampler, fit.slope),
            points: ns.iter().copied().zip(vars.iter().copied()).collect(),
            reference: false,
        }];
        for s in [-1.0, -1.5, -2.0, -3.0] {
            series.push(Series {
                label: format!("N^{s}"),
                points: line(s),
                reference: true,
            });
        }
        let plot = LinePlot {
            title: format!("{} on {}", a.sampler, f.spec()),
            x_label: "N".into(),
            y_label: "variance".into(),
            log_log: true,
            series,
        };
        line_plot_png(&plot, path)?;
    }
    if a.json {
        let out = json!({
            "sampler": a.sampler, "integrand": f.spec(),
            "method": if method == MethodArg::Spatial { "spatial" } else { "fourier" },
            "sets": a.draw.sets(),
            "points": points.iter().map(|p| json!({"n": p.n, "requested": p.requested, "variance": p.variance, "stderr": p.stderr, "truncation_bound": p.truncation_bound})).collect::<Vec<_>>(),
            "slope": fit.slope, "slope_ci": fit.slope_ci.map(|(l, h)| vec![l, h]),
            "theory": theory, "adjusted_n": adjusted,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    if !adjusted.is_empty() {
        println!("N adjusted to fit {}: {}", a.sampler, adjusted.join(", "));
    }
    println!("{:>8} {:>14} {:>12}", "N", "variance", "stderr");
    for p in &points {
        println!("{:>8} {:>14.6e} {:>12.2e}", p.n, p.variance, p.stderr);
    }
    let ci = fit
        .slope_ci
        .map_or("n/a (needs 3 or more N)".into(), |(l, h)| {
            format!("[{l:.3}, {h:.3}]")
        });
    let theory = theory.map_or("none in the table".into(), |t| format!("{t}"));
    println!("slope {:.3}, 95% CI {ci}; theory {theory}", fit.slope);
    Ok(())
}
