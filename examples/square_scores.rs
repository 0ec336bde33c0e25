//! Classic samplers scored on the square (no shift) by the UTK-style
//! families: the brute-force family MSE over 1024 members, and for
//! half-planes the closed form (Cramér–von Mises over 4096 directions).
//!
//! ```sh
//! cargo run --release --example square_scores
//! ```

use varspec::registry;
use varspec::rng::set_rng;
use varspec::square::halfplanes::halfplane_mse;
use varspec::square::{Family, family_mse};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: usize = std::env::args().nth(1).map_or(Ok(1024), |a| a.parse())?;
    let families = [Family::parse("gaussians")?, Family::parse("halfplanes")?];
    println!("N = {n}, 16 sets, 1024 members per family (seed 99)");
    for name in ["random", "jitter", "cmj", "sobol", "halton", "poisson-disk"] {
        let (sampler, n_used) = registry::build_nearest(name, n, Some(2), &[])?;
        let sets: Vec<_> = (0..16)
            .map(|r| sampler.sample(&mut set_rng(1, r)))
            .collect::<Result<_, _>>()?;
        let closed: f64 = sets.iter().map(|s| halfplane_mse(s, 4096)).sum::<f64>() / 16.0;
        print!("{name:<14} N={n_used:<5}");
        for f in &families {
            let m = family_mse(&sets, f, 1024, 99);
            print!("  {}: {:.3e} ± {:.1e}", f.spec(), m.mse, m.stderr);
        }
        println!("  halfplanes closed form: {closed:.3e}");
    }
    Ok(())
}
