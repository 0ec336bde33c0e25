//! Sampler-level predictions against exact expected variances computed
//! outside the project (tests/data/expected-variance.csv, closed forms for
//! random and jitter, relative accuracy ~1e-6; provenance in
//! tests/data/README.md).

use varspec::integrands;
use varspec::registry;
use varspec::rng::set_rng;
use varspec::variance::{VarianceError, fourier, spatial};

/// z for a two-sided per-check rate of 6e-5: ~40 checks keep the
/// family-wise false-alarm rate near 2.5e-3.
const Z: f64 = 4.0;

fn rows() -> Vec<(String, String, usize, f64)> {
    // Compiled in, so the test cannot run without its reference values.
    let text = include_str!("data/expected-variance.csv");
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let (spec, rest) = match line.strip_prefix('"') {
                Some(quoted) => {
                    let end = quoted.find('"').expect("closing quote");
                    (&quoted[..end], &quoted[end + 2..])
                }
                None => line.split_once(',').expect("four fields"),
            };
            let f: Vec<&str> = rest.split(',').collect();
            (
                spec.to_string(),
                f[0].to_string(),
                f[1].parse().unwrap(),
                f[2].parse().unwrap(),
            )
        })
        .collect()
}

#[test]
fn reference_file_is_present_and_complete() {
    let rows = rows();
    assert_eq!(rows.len(), 24, "3 integrands x 2 samplers x 4 N");
}

#[test]
fn fourier_predictions_match_the_exact_expected_variances() {
    for (spec, sampler, n, exact) in rows() {
        let f = integrands::parse(&spec).unwrap();
        let s = registry::build(&sampler, n, Some(2), &[]).unwrap();
        let realization =
            |r: usize| -> Result<_, VarianceError> { Ok(s.sample(&mut set_rng(77, r as u64))?) };
        let e = fourier(f.as_ref(), 63, 1e-10, 400, realization).unwrap();
        // The predictor completes the box |k|∞ ≤ 63 with the white tail
        // T/N, T = c_f(0) − Σ_(box) P_f (Parseval, computed here from the
        // closed forms). For random N·E[P_S(k)] = 1 and for jitter it lies
        // in [0, 1] at every k ≠ 0 (tests/data/README.md), so that tail
        // errs by at most T/N: a bound that holds for these samplers, not
        // the predictor's own estimate.
        let mut in_box = 0.0;
        for kx in -63i64..=63 {
            for ky in -63i64..=63 {
                if (kx, ky) != (0, 0) {
                    in_box += f.fourier(&[kx, ky]).norm_sqr();
                }
            }
        }
        let tail = (f.variance() - in_box).max(0.0) / n as f64;
        let allowed = Z * e.stderr + tail + 2e-6 * exact;
        assert!(
            (e.variance - exact).abs() <= allowed,
            "{spec} {sampler} N={n}: fourier {:e} ± {:e} (tail bound {tail:e}) vs exact {exact:e}",
            e.variance,
            e.stderr,
        );
    }
}

#[test]
fn spatial_predictions_match_the_exact_expected_variances() {
    for (spec, sampler, n, exact) in rows().into_iter().filter(|r| r.2 <= 256) {
        let f = integrands::parse(&spec).unwrap();
        let s = registry::build(&sampler, n, Some(2), &[]).unwrap();
        let realization =
            |r: usize| -> Result<_, VarianceError> { Ok(s.sample(&mut set_rng(78, r as u64))?) };
        let e = spatial(f.as_ref(), 400, realization).unwrap();
        assert!(
            (e.variance - exact).abs() <= Z * e.stderr + 2e-6 * exact,
            "{spec} {sampler} N={n}: spatial {:e} ± {:e} vs exact {exact:e}",
            e.variance,
            e.stderr
        );
    }
}
