//! The seed's design principle on a defocus pixel: a 4D set optimized with
//! targets per projection (blue XY and UV, and the light field's sheared
//! projection) against umj sheared by the light field's own shear, both
//! judged by the (x, y)-shifted estimator's variance, with the closest pair
//! of the XY and UV projections.
//!
//! ```sh
//! cargo run --release --example projection_design -- 256 "defocus:shape=disk,size=0.3,c=0.45"
//! ```

use varspec::integrands;
use varspec::neighbours::closest_pair_ratio;
use varspec::optimize::projections::{ProjectionObjective, parse_projections};
use varspec::optimize::shear::Sheared;
use varspec::optimize::{AdamOptions, Domain, adam};
use varspec::registry;
use varspec::rng::set_rng;
use varspec::samplers::Sampler;
use varspec::variance::{VarianceError, empirical_shifting};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().map_or(Ok(256), |a| a.parse())?;
    let spec = args
        .get(1)
        .cloned()
        .unwrap_or_else(|| "defocus:shape=disk,size=0.3,c=0.45".into());
    let iters: usize = args.get(2).map_or(Ok(1000), |a| a.parse())?;
    let f = integrands::parse(&spec)?;
    let c = -f.light_field().ok_or("a light field")?.layer_shears()[0][0];
    let target = format!("xy:family:disks;uv:family:disks;{spec}");
    let terms = parse_projections(&target, n)?;
    let umj = registry::build("umj", n, Some(4), &[])?;
    let options = AdamOptions {
        iters,
        rel_tol: 0.0,
        step: 0.05,
        final_step: 0.002,
        score_every: 1,
        floor: 0.0,
    };
    let sets = 8u64;
    let clock = std::time::Instant::now();
    let designed: Vec<_> = (0..sets)
        .map(|r| {
            let first = umj.sample(&mut set_rng(3, r)).expect("umj draws");
            let objective = ProjectionObjective::new(&terms, &first);
            adam(first, &objective, &options, Domain::Torus, &|_, _| {}).points
        })
        .collect();
    let seconds = clock.elapsed().as_secs_f64() / sets as f64;
    // Variance of the (x, y)-shifted estimator: 2000 shifts per fixed set.
    let per_set = |set: &varspec::PointSet| {
        empirical_shifting(
            f.as_ref(),
            2000,
            5,
            &[0, 1],
            |_| -> Result<_, VarianceError> { Ok(set.clone()) },
        )
        .expect("4D")
        .variance
    };
    let designed_var = designed.iter().map(per_set).sum::<f64>() / sets as f64;
    let sheared = Sheared::new(umj.as_ref(), [-c, -c])?;
    let umj_sets: Vec<_> = (0..64u64)
        .map(|r| sheared.sample(&mut set_rng(4, r)))
        .collect::<Result<_, _>>()?;
    let umj_var = umj_sets.iter().map(per_set).sum::<f64>() / 64.0;
    let closest = |sets: &[varspec::PointSet], dims: [usize; 2]| {
        sets.iter()
            .map(|s| closest_pair_ratio(&s.projected(&dims).expect("4D")))
            .fold(f64::INFINITY, f64::min)
    };
    println!(
        "N={n} {spec}: designed {designed_var:.4e} (XY {:.2}, UV {:.2}; {seconds:.1} s/set) vs umj sheared by {:.2}: {umj_var:.4e} (XY {:.2}, UV {:.2}); ratio {:.3}",
        closest(&designed, [0, 1]),
        closest(&designed, [2, 3]),
        -c,
        closest(&umj_sets, [0, 1]),
        closest(&umj_sets, [2, 3]),
        designed_var / umj_var
    );
    Ok(())
}
