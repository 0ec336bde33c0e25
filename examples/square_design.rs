//! A design for the square: start from a classic sampler, descend on a
//! weighted sum of family MSEs, and score before and after on families
//! drawn with seeds the descent never saw.
//!
//! ```sh
//! cargo run --release --example square_design -- halfplanes+gaussians jitter 1024 300
//! ```
//! Arguments: target, start sampler, N, iterations, initial step.

use varspec::optimize::{AdamOptions, Domain, adam};
use varspec::registry;
use varspec::rng::set_rng;
use varspec::square::design::{SquareObjective, parse_target};
use varspec::square::{Family, family_mse};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, default: &str| args.get(i).cloned().unwrap_or_else(|| default.into());
    let target = parse_target(&arg(1, "halfplanes+gaussians"))?;
    let init = arg(2, "jitter");
    let n: usize = arg(3, "1024").parse()?;
    let iters: usize = arg(4, "300").parse()?;
    let step: f64 = arg(5, "0.05").parse()?;
    let sets = 4;
    let (sampler, n) = registry::build_nearest(&init, n, Some(2), &[])?;
    let families = [Family::parse("halfplanes")?, Family::parse("gaussians")?];
    let options = AdamOptions {
        iters,
        rel_tol: 0.0,
        step,
        final_step: step / 25.0,
        score_every: 20,
        floor: 0.0,
    };
    let start = std::time::Instant::now();
    let mut before = Vec::new();
    let mut after = Vec::new();
    for r in 0..sets {
        let first = sampler.sample(&mut set_rng(7, r))?;
        let objective = SquareObjective::new(target.clone(), &first, 1000 + r);
        let result = adam(
            first.clone(),
            &objective,
            &options,
            Domain::Square,
            &|_, _| {},
        );
        eprintln!(
            "set {r}: score {:.4} -> {:.4}",
            result.start_score, result.best_score
        );
        before.push(first);
        after.push(result.points);
    }
    let seconds = start.elapsed().as_secs_f64() / sets as f64;
    for (label, s) in [("start", &before), ("designed", &after)] {
        print!("{label:<9} N={n}");
        for f in &families {
            let m = family_mse(s, f, 2048, 424242);
            print!("  {}: {:.3e} ± {:.1e}", f.spec(), m.mse, m.stderr);
        }
        let min_d = s
            .iter()
            .map(|set| {
                let mut best = f64::INFINITY;
                for i in 0..set.len() {
                    for j in 0..i {
                        let (a, b) = (set.point(i), set.point(j));
                        best = best.min(varspec::points::toroidal_distance_sq(a, b));
                    }
                }
                best.sqrt()
            })
            .fold(f64::INFINITY, f64::min);
        let hex = (2.0 / (3f64.sqrt() * n as f64)).sqrt();
        println!("  closest pair (torus) {:.3} of hexagonal", min_d / hex);
    }
    println!("{seconds:.2} s per set");
    Ok(())
}
