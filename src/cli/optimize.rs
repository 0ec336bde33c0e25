//! `varspec optimize`: gradient descent on point positions toward a target
//! spectrum, with a report against the classic samplers.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::bail;
use clap::Subcommand;
use rayon::prelude::*;
use serde_json::json;

use super::progress;
use varspec::io::{PointFormat, write_atomic, write_point_sets};
use varspec::optimize::{DescentOptions, PointOptimizer, Target};
use varspec::rng::set_rng;
use varspec::samplers;

#[derive(Subcommand)]
pub enum OptimizeCommand {
    /// Move points to minimize Σ W(k)·P_S(k) for a target weight W.
    Points(PointsArgs),
}

#[derive(clap::Args)]
pub struct PointsArgs {
    /// Points per set.
    #[arg(short = 'n')]
    n: usize,
    /// Dimension (1 to 4).
    #[arg(short = 'd', long = "dim", default_value_t = 2)]
    dim: usize,
    /// Target: an integrand spec (W = P_f), family:disks, power:A or radial:FILE.csv.
    #[arg(long)]
    target: String,
    /// Independent realizations, optimized in parallel.
    #[arg(long, default_value_t = 1)]
    sets: usize,
    /// Maximum iterations per set.
    #[arg(long, default_value_t = 2000)]
    iters: usize,
    /// Seed of the starting sets.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Sampler of the starting sets.
    #[arg(long, default_value = "random")]
    init: String,
    /// Box half-width K of the loss (default: 2.5·N^(1/d) for families and
    /// power laws, 8·N^(1/d) within [32, 128] for integrands).
    #[arg(long)]
    half: Option<usize>,
    /// NUFFT tolerance of the loss and gradient.
    #[arg(long, default_value_t = 1e-6)]
    tol: f64,
    /// Stop when the loss improves by less than this over 50 iterations.
    #[arg(long, default_value_t = 1e-4)]
    rel_tol: f64,
    /// Output point-set file (CSV).
    #[arg(short = 'o', long = "output")]
    output: PathBuf,
    /// JSON report: loss curve, wall time, loss beside the classic samplers.
    #[arg(long)]
    report: Option<PathBuf>,
}

pub fn run(c: OptimizeCommand) -> anyhow::Result<()> {
    match c {
        OptimizeCommand::Points(a) => points(a),
    }
}

fn points(a: PointsArgs) -> anyhow::Result<()> {
    if a.sets == 0 {
        bail!("--sets must be at least 1");
    }
    let target = Target::parse(&a.target)?;
    let mut options = DescentOptions::for_target(a.n, a.dim, &target);
    options.iters = a.iters;
    options.tolerance = a.tol;
    options.rel_tol = a.rel_tol;
    if let Some(h) = a.half {
        options.half = h;
    }
    let half = options.half;
    let optimizer = PointOptimizer::new(a.dim, &target, options)?;
    let init = samplers::build(&a.init, a.n, Some(a.dim), &[])?;
    let bar = progress::bar((a.sets * a.iters) as u64, "optimizing");
    let start = Instant::now();
    let results = (0..a.sets)
        .into_par_iter()
        .map(|r| -> anyhow::Result<_> {
            let first = init.sample(&mut set_rng(a.seed, r as u64))?;
            Ok(optimizer.optimize(first, &|_, _| bar.inc(1)))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    let sets: Vec<_> = results.iter().map(|r| r.points.clone()).collect();
    write_atomic(&a.output, |w| write_point_sets(w, &sets, PointFormat::Csv))?;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let final_losses: Vec<f64> = results
        .iter()
        .map(|r| r.losses.iter().copied().fold(f64::INFINITY, f64::min))
        .collect();
    let mut comparison = serde_json::Map::new();
    comparison.insert(
        "optimized".into(),
        json!({"n": a.n, "loss": mean(&final_losses)}),
    );
    for name in ["jitter", "cmj", "sobol", "poisson-disk"] {
        if let Ok((s, n)) = samplers::build_nearest(name, a.n, Some(a.dim), &[]) {
            let losses: Vec<f64> = (0..a.sets.max(8) as u64)
                .into_par_iter()
                .map(|r| {
                    s.sample(&mut set_rng(a.seed ^ 0x5eed, r))
                        .map(|p| optimizer.loss(&p))
                })
                .collect::<Result<_, _>>()?;
            comparison.insert(name.into(), json!({"n": n, "loss": mean(&losses)}));
        }
    }
    let iterations: Vec<usize> = results.iter().map(|r| r.losses.len()).collect();
    println!(
        "{} set(s) of {} points optimized for {} in {seconds:.2} s ({} iterations for set 0); loss {:.4e}",
        a.sets,
        a.n,
        a.target,
        iterations[0],
        mean(&final_losses)
    );
    for (name, v) in &comparison {
        println!(
            "  {name:<14} loss {:.4e}",
            v["loss"].as_f64().unwrap_or(f64::NAN)
        );
    }
    if let Some(path) = &a.report {
        let report = json!({
            "target": a.target, "n": a.n, "dim": a.dim, "sets": a.sets, "seed": a.seed, "init": a.init,
            "half": half, "tolerance": a.tol, "seconds": seconds, "iterations": iterations,
            "loss": "sum over 0 < |k|inf <= half of W(k) P_S(k)  (for an integrand target: its predicted variance within the box)",
            "loss_curve": results[0].losses, "comparison": comparison,
        });
        write_atomic(path, |w| {
            w.write_all(serde_json::to_string_pretty(&report)?.as_bytes())
        })?;
    }
    Ok(())
}
