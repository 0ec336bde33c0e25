//! The adapted design on half-planes at every edge angle (torus,
//! shift-randomized estimator): where the issue's ≤ 0.20× CMJ at N = 256 is
//! reached and where it is not. Angles 0°, 2.5°, …, 177.5° and four within
//! 1° of an axis; offsets drawn at random in [−0.3, 0.3] (a seed no default
//! was tuned on). The design is the default (best integration lattice, then
//! the spectral descent, kept by the exact form); CMJ's variance is the
//! mean over 64 realizations, with its standard error. With `--cosets`,
//! also the best union of two shifted lattices of N/2 points (every lattice
//! of N/2 points, the shift on a 16 × 16 grid then refined by compass
//! search): a family that holds every N-point lattice, to test whether
//! leaving the lattices helps. All variances by the exact spatial form.
//!
//! ```sh
//! cargo run --release --example halfplane_sweep -- results/optimize-adapted/sweep-256.csv 256 --cosets
//! ```

use rayon::prelude::*;

use varspec::integrands::{self, Integrand};
use varspec::optimize::adapted::design_sets;
use varspec::optimize::lattice::best_lattice;
use varspec::optimize::{DescentOptions, PointOptimizer, Target};
use varspec::registry;
use varspec::rng::{set_rng, uniform};
use varspec::samplers::Lattice;
use varspec::variance::{VarianceError, spatial};

/// (1/N) Σ_i Σ_j c_f(x_i − x_j)/N for the union of `points` and `points` +
/// `shift`, each of M = N/2 points: (Σ_x c_f(x) + Σ_x c_f(x + s)) / (2M),
/// the sums over the M points of one lattice (c_f is even).
fn union_variance(f: &dyn Integrand, points: &[[f64; 2]], own: f64, shift: [f64; 2]) -> f64 {
    let moved: f64 = points
        .iter()
        .map(|x| {
            f.autocov(&[
                (x[0] + shift[0]).rem_euclid(1.0),
                (x[1] + shift[1]).rem_euclid(1.0),
            ])
            .expect("half-planes have an autocovariance")
        })
        .sum();
    (own + moved) / (2 * points.len()) as f64
}

/// The lowest variance of a union of two shifted lattices of N/2 points.
fn best_coset_union(f: &dyn Integrand, n: usize) -> f64 {
    let m = n / 2;
    let lattices: Vec<Lattice> = (1..=m)
        .filter(|a| m % a == 0)
        .flat_map(|a| (0..a).map(move |b| Lattice { a, b, c: m / a }))
        .collect();
    lattices
        .par_iter()
        .map(|l| {
            let points: Vec<[f64; 2]> = l
                .points([0.0, 0.0])
                .points()
                .map(|q| [q[0], q[1]])
                .collect();
            let own: f64 = points
                .iter()
                .map(|x| f.autocov(x).expect("autocovariance"))
                .sum();
            const GRID: usize = 16;
            let mut best = (f64::INFINITY, [0.0, 0.0]);
            for i in 0..GRID {
                for j in 0..GRID {
                    let s = [i as f64 / GRID as f64, j as f64 / GRID as f64];
                    let v = union_variance(f, &points, own, s);
                    if v < best.0 {
                        best = (v, s);
                    }
                }
            }
            let mut h = 0.5 / GRID as f64;
            while h > 1e-5 {
                let (v, s) = best;
                let step = [[h, 0.0], [-h, 0.0], [0.0, h], [0.0, -h]]
                    .into_iter()
                    .map(|d| [s[0] + d[0], s[1] + d[1]])
                    .map(|t| (union_variance(f, &points, own, t), t))
                    .find(|(w, _)| *w < v);
                match step {
                    Some(better) => best = better,
                    None => h *= 0.5,
                }
            }
            best.0
        })
        .reduce(|| f64::INFINITY, f64::min)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = args
        .first()
        .cloned()
        .unwrap_or_else(|| "out/sweep.csv".into());
    let n: usize = args.get(1).map_or(Ok(256), |a| a.parse())?;
    let cosets = args.iter().any(|a| a == "--cosets");
    let mut angles: Vec<f64> = vec![0.15, 0.5, 1.0, 89.0];
    angles.extend((0..72).map(|i| 2.5 * i as f64));
    angles.sort_by(f64::total_cmp);
    let mut rng = set_rng(0x5eed_a91e, 0);
    let mut csv = csv::Writer::from_path(&out)?;
    csv.write_record([
        "n",
        "integrand",
        "design_variance",
        "cmj_variance",
        "cmj_stderr",
        "ratio_to_cmj",
        "coset_union_ratio",
    ])?;
    let mut ratios = Vec::new();
    for angle in angles {
        let offset = ((0.6 * uniform(&mut rng) - 0.3) * 1000.0).round() / 1000.0;
        let spec = format!("halfplane:angle={angle},offset={offset}");
        let f = integrands::parse(&spec)?;
        let cmj = registry::build("cmj", n, Some(2), &[])?;
        let c = spatial(f.as_ref(), 64, |r| -> Result<_, VarianceError> {
            Ok(cmj.sample(&mut set_rng(17, r as u64))?)
        })?;
        let target = Target::parse(&spec)?;
        let optimizer = PointOptimizer::new(2, &target, DescentOptions::for_target(n, 2, &target))?;
        let start = best_lattice(n, f.as_ref())?;
        let kept = design_sets(
            &optimizer,
            &start.lattice,
            Some(f.as_ref()),
            9,
            1,
            &|_, _| {},
            None,
        )?;
        let ours = kept[0].variance().expect("exact form");
        let union = if cosets {
            best_coset_union(f.as_ref(), n) / c.variance
        } else {
            f64::NAN
        };
        csv.write_record([
            n.to_string(),
            spec.clone(),
            format!("{ours:e}"),
            format!("{:e}", c.variance),
            format!("{:e}", c.stderr),
            format!("{:.4}", ours / c.variance),
            format!("{union:.4}"),
        ])?;
        println!(
            "{spec}: {:.3} of CMJ (± {:.0}%), coset union {union:.3}",
            ours / c.variance,
            100.0 * c.stderr / c.variance
        );
        ratios.push((ours / c.variance, angle));
    }
    csv.flush()?;
    ratios.sort_by(|a, b| a.0.total_cmp(&b.0));
    let k = ratios.len();
    let mean = ratios.iter().map(|r| r.0).sum::<f64>() / k as f64;
    println!(
        "N = {n}: {k} half-planes, mean {mean:.3}, median {:.3}, max {:.3} (angle {}), ≤ 0.20 on {}, ≤ 0.15 on {}",
        ratios[k / 2].0,
        ratios[k - 1].0,
        ratios[k - 1].1,
        ratios.iter().filter(|r| r.0 <= 0.20).count(),
        ratios.iter().filter(|r| r.0 <= 0.15).count()
    );
    Ok(())
}
