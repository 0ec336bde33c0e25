//! Designs adapted to one integrand, on integrands drawn at random (torus,
//! shift-randomized estimator): the default design (best integration
//! lattice, then the spectral descent, kept by the exact form) and the
//! previous default (descent from CMJ) against CMJ, Owen-scrambled Sobol',
//! jitter and Poisson disk, all scored by the exact spatial form (no frequency box).
//! Classic samplers: mean over 64 realizations with its standard error.
//!
//! ```sh
//! cargo run --release --example adapted_matrix -- results/optimize-adapted 256 1024
//! ```
//! Writes `matrix.csv` to the folder and prints a markdown table.

use std::time::Instant;

use varspec::integrands;
use varspec::optimize::adapted::design_sets;
use varspec::optimize::lattice::best_lattice;
use varspec::optimize::{DescentOptions, PointOptimizer, Target};
use varspec::registry;
use varspec::rng::{set_rng, uniform};
use varspec::samplers;
use varspec::variance::{VarianceError, spatial};

/// Targets: four random half-planes, two random boxes, a random disk and a
/// random anisotropic Gaussian, drawn with a seed no default was tuned on.
fn targets() -> Vec<String> {
    let mut rng = set_rng(0x0ada_97ed, 0);
    let mut u = |a: f64, b: f64| {
        let v = a + (b - a) * uniform(&mut rng);
        (v * 1000.0).round() / 1000.0
    };
    let mut specs = Vec::new();
    for _ in 0..4 {
        specs.push(format!(
            "halfplane:angle={},offset={}",
            u(0.0, 180.0),
            u(-0.3, 0.3)
        ));
    }
    for _ in 0..2 {
        specs.push(format!(
            "box:w={},h={},angle={},cx={},cy={}",
            u(0.1, 0.6),
            u(0.1, 0.6),
            u(0.0, 90.0),
            u(0.3, 0.7),
            u(0.3, 0.7)
        ));
    }
    specs.push(format!(
        "disk:r={},cx={},cy={}",
        u(0.1, 0.45),
        u(0.3, 0.7),
        u(0.3, 0.7)
    ));
    specs.push(format!(
        "gaussian:sx={},sy={},angle={}",
        u(0.03, 0.15),
        u(0.03, 0.15),
        u(0.0, 180.0)
    ));
    specs
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = args
        .first()
        .cloned()
        .unwrap_or_else(|| "out/adapted".into());
    let sizes: Vec<usize> = if args.len() > 1 {
        args[1..]
            .iter()
            .map(|a| a.parse())
            .collect::<Result<_, _>>()?
    } else {
        vec![256, 1024]
    };
    std::fs::create_dir_all(&out)?;
    let mut csv = csv::Writer::from_path(format!("{out}/matrix.csv"))?;
    csv.write_record([
        "n",
        "integrand",
        "design",
        "variance",
        "stderr",
        "ratio_to_cmj",
        "seconds",
    ])?;
    println!(
        "| N | integrand | lattice+descent / CMJ | descent from CMJ / CMJ | Sobol' / CMJ | jitter / CMJ | Poisson disk / CMJ | CMJ variance | design s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for &n in &sizes {
        for spec in targets() {
            let f = integrands::parse(&spec)?;
            let mut classic = Vec::new();
            for name in ["cmj", "sobol", "jitter", "poisson-disk"] {
                let s = registry::build(name, n, Some(2), &[])?;
                let e = spatial(f.as_ref(), 64, |r| -> Result<_, VarianceError> {
                    Ok(s.sample(&mut set_rng(0x5c0e, r as u64))?)
                })?;
                classic.push((name, e.variance, e.stderr));
            }
            let cmj = classic[0].1;
            let target = Target::parse(&spec)?;
            let optimizer =
                PointOptimizer::new(2, &target, DescentOptions::for_target(n, 2, &target))?;
            let design =
                |start: &dyn samplers::Sampler| -> Result<(f64, f64), Box<dyn std::error::Error>> {
                    let t = Instant::now();
                    let kept =
                        design_sets(&optimizer, start, Some(f.as_ref()), 3, 1, &|_, _| {}, None)?;
                    Ok((
                        kept[0].variance().expect("exact form"),
                        t.elapsed().as_secs_f64(),
                    ))
                };
            let t = Instant::now();
            let lattice = best_lattice(n, f.as_ref())?;
            let search = t.elapsed().as_secs_f64();
            let (ours, seconds) = design(&lattice.lattice)?;
            let seconds = seconds + search;
            let cmj_sampler = registry::build("cmj", n, Some(2), &[])?;
            let (old, old_seconds) = design(cmj_sampler.as_ref())?;
            let mut row = |design: &str, v: f64, se: f64, s: f64| {
                csv.write_record([
                    n.to_string(),
                    spec.clone(),
                    design.to_string(),
                    format!("{v:e}"),
                    format!("{se:e}"),
                    format!("{:.4}", v / cmj),
                    format!("{s:.3}"),
                ])
            };
            row("lattice+descent", ours, 0.0, seconds)?;
            row("descent from cmj", old, 0.0, old_seconds)?;
            for (name, v, se) in &classic {
                row(name, *v, *se, 0.0)?;
            }
            println!(
                "| {n} | `{spec}` | **{:.3}** | {:.3} | {:.3} | {:.3} | {:.3} | {:.3e} ± {:.0}% | {seconds:.2} |",
                ours / cmj,
                old / cmj,
                classic[1].1 / cmj,
                classic[2].1 / cmj,
                classic[3].1 / cmj,
                cmj,
                100.0 * classic[0].2 / cmj
            );
        }
    }
    csv.flush()?;
    Ok(())
}
