//! The project's core regression test (docs/mathematics.md): the three predictors
//! agree for every classic sampler, reference integrand and
//! N ∈ {64, 256, 1024}:
//! * spatial vs Fourier on the same 12 realizations, within the Fourier
//!   truncation bound plus rounding (a deterministic comparison: both are
//!   exact functions of the same sets up to truncation);
//! * empirical vs Fourier on 200 realizations, within their combined
//!   standard errors plus the truncation bound (statistical: the per-set
//!   variance of random-like samplers is strongly skewed, so its mean needs
//!   many sets before a normal interval holds — the cheap Fourier form
//!   provides them).

use varspec::integrands::{self, Integrand};
use varspec::registry;
use varspec::rng::set_rng;
use varspec::samplers::Sampler;
use varspec::variance::{VarianceError, empirical, fourier, spatial};

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

fn check(sampler: &dyn Sampler, name: &str, f: &dyn Integrand, sets: usize, seed: u64) {
    let n = sampler.points_per_set();
    let realization = |r: usize| -> Result<_, VarianceError> {
        Ok(sampler.sample(&mut set_rng(seed, r as u64))?)
    };
    let s = spatial(f, sets, realization).unwrap();
    let four = fourier(f, 127, NUFFT_TOL, sets, realization).unwrap();
    // The NUFFT perturbs each power by ≤ 2·tol·N + tol²·N (|ΔS| ≤ tol·N),
    // so the in-box sum by at most that times Σ P_f/N ≤ c_f(0)·(2·tol + tol²).
    let nufft = f.variance() * (2.0 * NUFFT_TOL + NUFFT_TOL * NUFFT_TOL) * 1.01;
    let allowed = four.truncation_bound + s.rounding_bound + nufft;
    assert!(
        (four.variance - s.variance).abs() <= allowed,
        "{name} N={n} {}: fourier {:e} vs spatial {:e}: |diff| {:e} > truncation bound {:e} + rounding {:e} + nufft {:e}",
        f.spec(),
        four.variance,
        s.variance,
        (four.variance - s.variance).abs(),
        four.truncation_bound,
        s.rounding_bound,
        nufft
    );
    let many = fourier(f, 63, NUFFT_TOL, 200, realization).unwrap();
    let e = empirical(f, if n > 256 { 2000 } else { 4000 }, seed + 1, realization).unwrap();
    let combined = (e.stderr * e.stderr + many.stderr * many.stderr).sqrt();
    assert!(
        (e.variance - many.variance).abs() <= Z * combined + many.truncation_bound + nufft,
        "{name} N={n} {}: empirical {:e} [{:e}, {:e}] vs fourier {:e} ± {:e} (bound {:e}): beyond {Z} combined standard errors",
        f.spec(),
        e.variance,
        e.ci_low,
        e.ci_high,
        many.variance,
        many.stderr,
        many.truncation_bound
    );
}

fn run_for(n: usize) {
    for spec in INTEGRANDS {
        let f = integrands::parse(spec).unwrap();
        for name in SAMPLERS {
            let sampler = registry::build(name, n, Some(2), &[]).unwrap();
            check(sampler.as_ref(), name, f.as_ref(), 12, 1000 + n as u64);
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
