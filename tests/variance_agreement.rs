//! The project's core regression test (docs/mathematics.md): the three predictors
//! agree for every classic sampler, reference integrand and
//! N ∈ {64, 256, 1024}:
//! * spatial and Fourier on the same 12 realizations against a direct DFT
//!   of those sets and the rigorous limits of the tail beyond the box
//!   (deterministic: tolerances are the NUFFT's accuracy and rounding);
//! * empirical vs the spatial form's mean over 32–200 realizations, within
//!   their combined standard errors (statistical: the per-set variance of
//!   random-like samplers is skewed, so its mean needs many sets before a
//!   normal interval holds).

use crate::common;

use rayon::prelude::*;
use varspec::PointSet;
use varspec::integrands::{self, Integrand};
use varspec::registry;
use varspec::rng::set_rng;
use varspec::variance::{SpatialEstimate, VarianceError, empirical, fourier, spatial};

const SAMPLERS: [&str; 9] = [
    "random",
    "jitter",
    "uniform-jitter",
    "nrooks",
    "multijitter",
    "cmj",
    "poisson-disk",
    "sobol",
    "halton",
];
const INTEGRANDS: [&str; 5] = [
    "disk:r=0.3,cx=0.43,cy=0.52",
    "box:w=0.5,h=0.25,angle=30",
    "gaussian:sx=0.1,sy=0.05,angle=20",
    "halfplane:angle=17,offset=0.07",
    "cos:kx=3,ky=2",
];
/// z for a two-sided per-comparison rate of 6.8e-6: 135 comparisons keep
/// the family-wise false-alarm rate near 1e-3.
const Z: f64 = 4.5;
const NUFFT_TOL: f64 = 1e-10;
/// The Fourier form's box |k|∞ ≤ HALF.
const HALF: usize = 63;
/// Realizations both forms and the direct DFT share.
const SETS: usize = 12;

/// Realizations for the empirical form (2000 at N = 1024, 4000 below) and
/// the spatial mean (32 and 200): drawn once per sampler, lent to every
/// integrand.
fn realizations(n: usize) -> (usize, usize) {
    if n > 256 { (2000, 32) } else { (4000, 200) }
}

/// `pool[..SETS]` go to both forms and the direct check, whose DFT
/// `powers` of those sets every integrand shares.
fn check(
    name: &str,
    f: &dyn Integrand,
    pool: &[PointSet],
    powers: &common::direct::SetPowers,
    seed: u64,
) {
    let sets = SETS;
    let n = pool[0].len();
    let (shifted, total) = realizations(n);
    let realization = |r: usize| -> Result<_, VarianceError> { Ok(pool[r].clone()) };
    let lend = realization;
    let s = spatial(f, sets, lend).unwrap();
    let four = fourier(f, HALF, NUFFT_TOL, sets, lend).unwrap();
    // Both forms on the same sets against a direct DFT written in the test
    // and the rigorous limits of the tail (tests/common/direct.rs).
    let label = format!("{name} N={n} {}", f.spec());
    common::direct::check_fourier(&label, f, powers, NUFFT_TOL, &four, Some(&s));
    // The error bar users see: the Fourier form's truncation bound must
    // cover its distance from the exact value (a test of the bound, whose
    // tolerance is therefore the bound itself, plus NUFFT and rounding).
    let nufft = f.variance() * (2.0 * NUFFT_TOL + NUFFT_TOL * NUFFT_TOL) * 1.01;
    assert!(
        (four.variance - s.variance).abs() <= four.truncation_bound + s.rounding_bound + nufft,
        "{label}: fourier {:e} vs spatial {:e}: outside its truncation bound {:e}",
        four.variance,
        s.variance,
        four.truncation_bound
    );
    // Empirical (random shifts of 2000–4000 realizations) against the exact
    // spatial form's mean over 200 realizations (32 at N = 1024, where each
    // costs N²/2 pairs): two estimates of one expectation. The first `sets`
    // realizations are those already drawn; only the rest are computed.
    let rest = spatial(f, total - sets, |r| realization(sets + r)).unwrap();
    let many = pooled(&s, &rest);
    let e = empirical(f, shifted, seed + 1, realization).unwrap();
    let combined = (e.stderr * e.stderr + many.stderr * many.stderr).sqrt();
    assert!(
        (e.variance - many.variance).abs() <= Z * combined + many.rounding_bound,
        "{name} N={n} {}: empirical {:e} [{:e}, {:e}] vs spatial {:e} ± {:e}: beyond {Z} combined standard errors",
        f.spec(),
        e.variance,
        e.ci_low,
        e.ci_high,
        many.variance,
        many.stderr,
    );
}

/// The spatial form's mean over two disjoint groups of realizations, with the
/// standard error of the pooled per-set values (the two groups' sums of
/// squared deviations plus the between-group term).
fn pooled(a: &SpatialEstimate, b: &SpatialEstimate) -> SpatialEstimate {
    let (na, nb) = (a.sets as f64, b.sets as f64);
    let n = na + nb;
    let mean = (na * a.variance + nb * b.variance) / n;
    // A group's sum of squared deviations from its standard error:
    // Σ(v − mean)² = stderr²·count·(count − 1).
    let squares = |e: &SpatialEstimate| e.stderr * e.stderr * e.sets as f64 * (e.sets as f64 - 1.0);
    let delta = a.variance - b.variance;
    let per_set = (squares(a) + squares(b) + na * nb / n * delta * delta) / (n - 1.0);
    SpatialEstimate {
        variance: mean,
        rounding_bound: a.rounding_bound.max(b.rounding_bound),
        stderr: (per_set / n).sqrt(),
        sets: a.sets + b.sets,
    }
}

fn run_for(n: usize) {
    let seed = 1000 + n as u64;
    let (shifted, total) = realizations(n);
    for name in SAMPLERS {
        let sampler = registry::build(name, n, Some(2), &[]).unwrap();
        let pool: Vec<PointSet> = (0..shifted.max(total))
            .into_par_iter()
            .map(|r| sampler.sample(&mut set_rng(seed, r as u64)).unwrap())
            .collect();
        let powers = common::direct::SetPowers::of(&pool[..SETS], HALF);
        for spec in INTEGRANDS {
            let f = integrands::parse(spec).unwrap();
            check(name, f.as_ref(), &pool, &powers, seed);
        }
    }
}

#[test]
fn predictors_agree_at_64_points() {
    run_for(64);
}

#[test]
fn predictors_agree_at_256_points() {
    run_for(256);
}

#[test]
fn predictors_agree_at_1024_points() {
    run_for(1024);
}
