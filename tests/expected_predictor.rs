//! The Fourier form with a sampler's closed-form expected spectrum
//! (`variance::fourier_expected`, `predict --method expected`) against
//! values it does not compute: white noise's Var(f)/N from the disk's area
//! alone, and the exact spatial form averaged over many realizations of the
//! stratified samplers (an independent path: pair distances and the
//! integrand's autocovariance, no spectrum and no pair-sum algebra).

use varspec::integrands;
use varspec::registry;
use varspec::rng::set_rng;
use varspec::samplers::ClosedFormSpectrum;
use varspec::variance::{ClosedForm, VarianceError, fourier, fourier_expected, spatial};

/// Two-sided normal quantile of 99.9%.
const Z999: f64 = 3.29;

#[test]
fn white_noise_expectation_is_the_integrand_variance_over_n() {
    // E[N·P_S(k)] = 1 at every k ≠ 0, so the prediction is Var(f)/N; a
    // disk of radius r has Var(f) = πr²(1 − πr²).
    for (r, n) in [(0.3, 1024), (0.05, 64), (0.45, 7)] {
        let f = integrands::parse(&format!("disk:r={r}")).unwrap();
        let random = registry::build("random", n, Some(2), &[]).unwrap();
        let e = fourier_expected(
            f.as_ref(),
            127,
            &ClosedFormSpectrum::of(random.as_ref()).unwrap(),
        )
        .unwrap()
        .estimate;
        let area = std::f64::consts::PI * r * r;
        let exact = area * (1.0 - area) / n as f64;
        assert!(
            (e.variance - exact).abs() <= 1e-12 * exact,
            "disk r={r}, N={n}: {} vs Var(f)/N = {exact}",
            e.variance
        );
        assert!(e.truncation_bound <= 1e-12 * exact, "{e:?}");
        assert_eq!((e.stderr, e.sets), (0.0, 0));
    }
}

#[test]
fn stratified_expectations_match_the_spatial_form_over_realizations() {
    // 2000 sets of 64 (or 60: a 6 × 10 grid) points; a disk, a rotated box
    // and a Gaussian, whose spectra weigh the axes, diagonals and the
    // low frequencies differently.
    let sets = 2000;
    for (name, n) in [
        ("jitter", 64),
        ("multijitter", 64),
        ("multijitter", 60),
        ("cmj", 64),
        ("cmj", 60),
        ("uniform-jitter", 64),
    ] {
        let sampler = registry::build(name, n, Some(2), &[]).unwrap();
        for spec in [
            "disk:r=0.3,cx=0.41",
            "box:w=0.5,h=0.3,angle=30",
            "gaussian:sx=0.08,sy=0.15",
        ] {
            let f = integrands::parse(spec).unwrap();
            let e = fourier_expected(
                f.as_ref(),
                127,
                &ClosedFormSpectrum::of(sampler.as_ref()).unwrap(),
            )
            .unwrap()
            .estimate;
            let s = spatial(f.as_ref(), sets, |r| -> Result<_, VarianceError> {
                Ok(sampler.sample(&mut set_rng(11, r as u64))?)
            })
            .unwrap();
            let allowed = Z999 * s.stderr + e.truncation_bound + e.rounding_bound;
            assert!(
                (e.variance - s.variance).abs() <= allowed,
                "{name} N={n} {spec}: closed form {:.6e} vs spatial {:.6e} ± {:.2e} \
                 ({sets} sets; 99.9% interval ± {:.2e} with the truncation bound {:.2e})",
                e.variance,
                s.variance,
                s.stderr,
                allowed,
                e.truncation_bound
            );
        }
    }
}

#[test]
fn axis_aligned_edges_against_n_rooks_strata_are_summed_beyond_the_box() {
    // An axis-aligned edge puts its energy on the axes far beyond the box,
    // where N-rooks strata (multi-jitter, CMJ) are far from white: the
    // white tail predicted 2× the variance of CMJ on the default box at
    // N = 1024 (7.04e-7 against 3.50e-7). Summed along the axis strips
    // the closed form must match the spatial form within 99.9% and its
    // own bound, and that bound must be under a tenth of the value. Jitter
    // (square strata) and a rotated box are the controls.
    let sets = 100;
    let n = 1024;
    let half = varspec::variance::expected_min_half(2, n);
    for name in ["cmj", "multijitter", "jitter"] {
        let sampler = registry::build(name, n, Some(2), &[]).unwrap();
        let closed = ClosedFormSpectrum::of(sampler.as_ref()).unwrap();
        for spec in [
            "box",
            "box:w=0.3,h=0.55,cx=0.41,cy=0.6",
            "box:w=0.4,h=0.2,angle=60",
        ] {
            let f = integrands::parse(spec).unwrap();
            let e = fourier_expected(f.as_ref(), half, &closed)
                .unwrap()
                .estimate;
            let s = spatial(f.as_ref(), sets, |r| -> Result<_, VarianceError> {
                Ok(sampler.sample(&mut set_rng(23, r as u64))?)
            })
            .unwrap();
            let allowed = Z999 * s.stderr + e.truncation_bound + e.rounding_bound;
            assert!(
                (e.variance - s.variance).abs() <= allowed,
                "{name} N={n} {spec}: closed form {:.6e} (bound {:.2e}) vs spatial {:.6e} ± \
                 {:.2e} over {sets} sets (99.9% with the bound: ± {allowed:.2e})",
                e.variance,
                e.truncation_bound,
                s.variance,
                s.stderr
            );
            assert!(
                e.truncation_bound <= 0.1 * e.variance,
                "{name} N={n} {spec}: truncation bound {:.2e} is over a tenth of {:.6e}",
                e.truncation_bound,
                e.variance
            );
        }
    }
}

#[test]
fn padded_expectations_match_the_fourier_form_over_realizations() {
    // Umj (multi-jittered halves), its CMJ variant and a padded jitter ×
    // random set, on defocused light fields (whose energy lies on sheared
    // planes, across both halves) and a double wedge: the closed form
    // against the Fourier form on the same box averaged over 400 sets, so
    // the in-box sums are compared and the tails are the same term.
    let sets = 400;
    for (name, params) in [
        ("umj", vec![]),
        ("umj", vec![("pairs".to_string(), "cmj".to_string())]),
        (
            "padded",
            vec![
                ("xy".to_string(), "jitter".to_string()),
                ("uv".to_string(), "random".to_string()),
            ],
        ),
    ] {
        let sampler = registry::build(name, 64, Some(4), &params).unwrap();
        let closed = ClosedFormSpectrum::of(sampler.as_ref()).unwrap();
        for spec in [
            "defocus:shape=disk,size=0.3,c=0.5",
            "defocus:shape=box,size=0.4,c=-0.3",
            "layers:c1=0.4,c2=-0.3,size=0.3",
        ] {
            let f = integrands::parse(spec).unwrap();
            let e = fourier_expected(f.as_ref(), 7, &closed).unwrap().estimate;
            let s = fourier(
                f.as_ref(),
                7,
                1e-10,
                sets,
                |r| -> Result<_, VarianceError> { Ok(sampler.sample(&mut set_rng(5, r as u64))?) },
            )
            .unwrap();
            assert!(
                (e.variance - s.variance).abs() <= Z999 * s.stderr + e.rounding_bound,
                "{name} {params:?} {spec}: closed form {:.6e} vs Fourier {:.6e} ± {:.2e} over \
                 {sets} sets (99.9%: ± {:.2e})",
                e.variance,
                s.variance,
                s.stderr,
                Z999 * s.stderr
            );
        }
    }
}

#[test]
fn integrands_without_a_spectrum_or_of_another_dimension_are_refused() {
    let random = registry::build("random", 64, Some(2), &[]).unwrap();
    let closed = ClosedFormSpectrum::of(random.as_ref()).unwrap();
    let defocus = integrands::parse("defocus:shape=disk,size=0.3,c=0.5").unwrap();
    assert!(matches!(
        fourier_expected(defocus.as_ref(), 15, &closed),
        Err(VarianceError::Dimension { integrand: 4, .. })
    ));
    // A padded sampler whose half has no closed form has none.
    let padded = registry::build(
        "padded",
        64,
        Some(4),
        &[("uv".to_string(), "sobol".to_string())],
    )
    .unwrap();
    assert!(ClosedFormSpectrum::of(padded.as_ref()).is_none());
}

/// The regular grid, uniform jitter and the lattice rule are shifted
/// lattices: their closed form is the exact N-term lattice sum
/// (`variance::lattice`), not the Fourier form, whose tail beyond the box
/// is not white for a lattice.
#[test]
fn lattice_samplers_expected_variance_is_the_exact_lattice_sum() {
    // Independent values (Python, math.fsum): c_f from the lens area of two
    // disks, 2r²·acos(d/2r) − (d/2)·√(4r² − d²), over the 3 × 3 nearest
    // images, minus (πr²)², summed over the m × m grid and over the rank-1
    // lattice (i/N, (239·i mod N)/N). The regular one agrees with a brute force over
    // 10⁶ shifts of the grid on a 1000² midpoint rule (4.29387e-5, its
    // quadrature error ~2e-4 relative).
    let disk = integrands::parse("disk:r=0.3").unwrap();
    for (name, params, python) in [
        ("uniform-jitter", vec![], 4.2946259087892774e-05),
        ("regular", vec![], 4.2946259087892774e-05),
        ("lattice", vec![("g", "239")], 2.9982138681864507e-05),
    ] {
        let params: Vec<(String, String)> = params
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        let sampler = registry::build(name, 256, Some(2), &params).unwrap();
        let closed = ClosedForm::of(sampler.as_ref(), disk.as_ref()).unwrap();
        assert_eq!(closed.name(), "lattice sum", "{name}");
        let e = closed.variance(disk.as_ref(), 127).unwrap();
        assert!(
            (e.variance - python).abs() <= 1e-12 * python,
            "{name}: lattice sum {:.16e} vs Python {python:.16e}",
            e.variance
        );
        assert_eq!(e.truncation_bound, 0.0);
        assert!(e.fourier.is_none());
    }
    // Against the generic O(N²) spatial form of one drawn set (exact for a
    // lattice, whatever the shift) and within the Fourier form's bound.
    for (name, n) in [("uniform-jitter", 64), ("regular", 1024), ("lattice", 97)] {
        let sampler = registry::build(name, n, Some(2), &[]).unwrap();
        for spec in [
            "disk:r=0.3,cx=0.41",
            "box:w=0.5,h=0.3,angle=30",
            "halfplane:angle=23,offset=0.11",
        ] {
            let f = integrands::parse(spec).unwrap();
            let e = ClosedForm::of(sampler.as_ref(), f.as_ref())
                .unwrap()
                .variance(f.as_ref(), 127)
                .unwrap();
            let s = spatial(f.as_ref(), 1, |r| -> Result<_, VarianceError> {
                Ok(sampler.sample(&mut set_rng(5, r as u64))?)
            })
            .unwrap();
            let allowed = 1e-9 * s.variance + e.rounding_bound;
            assert!(
                (e.variance - s.variance).abs() <= allowed,
                "{name} N={n} {spec}: lattice sum {:.12e} vs spatial {:.12e}",
                e.variance,
                s.variance
            );
            if let Some(spectrum) = ClosedFormSpectrum::of(sampler.as_ref()) {
                let p = fourier_expected(f.as_ref(), 127, &spectrum)
                    .unwrap()
                    .estimate;
                assert!(
                    (p.variance - e.variance).abs() <= p.truncation_bound + p.rounding_bound,
                    "{name} N={n} {spec}: Fourier {:.6e} ± {:.2e} vs lattice sum {:.6e}",
                    p.variance,
                    p.truncation_bound,
                    e.variance
                );
            }
        }
    }
    // Independent strata are no lattice: jitter keeps the Fourier form.
    let jitter = registry::build("jitter", 64, Some(2), &[]).unwrap();
    assert_eq!(
        ClosedForm::of(jitter.as_ref(), disk.as_ref())
            .unwrap()
            .name(),
        "fourier"
    );
}
