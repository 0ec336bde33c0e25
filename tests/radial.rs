//! The radial (isotropic) predictor: its anisotropy bound is a theorem
//! (Cauchy–Schwarz on each ring), it agrees with the exact form where both
//! spectra are nearly isotropic, and it fails where the seed says it does:
//! N-rooks on an axis-aligned band.

use varspec::integrands;
use varspec::registry;
use varspec::rng::set_rng;
use varspec::variance::{VarianceError, fit_slope, fourier_parts, radial_from, spatial};

fn draw(name: &str, n: usize, sets: usize) -> Vec<varspec::PointSet> {
    let s = registry::build(name, n, Some(2), &[]).unwrap();
    (0..sets as u64)
        .map(|r| s.sample(&mut set_rng(5, r)).unwrap())
        .collect()
}

#[test]
fn the_anisotropy_bound_holds_for_every_sampler_and_integrand() {
    let mut largest_share: f64 = 0.0;
    for name in ["random", "jitter", "nrooks", "cmj", "poisson-disk"] {
        let sets = draw(name, 256, 8);
        for spec in [
            "disk:r=0.3",
            "box:w=1,h=0.3",
            "gaussian:sx=0.1,sy=0.05,angle=20",
        ] {
            let f = integrands::parse(spec).unwrap();
            let parts = fourier_parts(f.as_ref(), 40, 1e-10, sets.len(), |r| {
                Ok::<_, VarianceError>(sets[r].clone())
            })
            .unwrap();
            let r = radial_from(&parts);
            let gap = (r.variance - parts.estimate.tail - parts.estimate.in_box).abs();
            assert!(
                gap <= r.anisotropy_bound * (1.0 + 1e-9) + 1e-18,
                "{name} on {spec}: |radial - fourier| = {gap:e} > bound {:e}",
                r.anisotropy_bound
            );
            largest_share = largest_share.max(gap / r.anisotropy_bound);
        }
    }
    // The bound is not vacuous: somewhere the gap uses a good part of it.
    assert!(largest_share > 0.2, "largest gap / bound {largest_share}");
}

/// Radial prediction, its anisotropy + truncation bound, and the exact
/// spatial form, on 8 sets.
fn radial_and_exact(name: &str, spec: &str, n: usize) -> (f64, f64, f64) {
    let f = integrands::parse(spec).unwrap();
    let sets = draw(name, n, 8);
    let parts = fourier_parts(f.as_ref(), 127, 1e-10, sets.len(), |r| {
        Ok::<_, VarianceError>(sets[r].clone())
    })
    .unwrap();
    let exact = spatial(f.as_ref(), sets.len(), |r| {
        Ok::<_, VarianceError>(sets[r].clone())
    })
    .unwrap();
    let r = radial_from(&parts);
    (
        r.variance,
        r.anisotropy_bound + r.truncation_bound,
        exact.variance,
    )
}

#[test]
fn isotropic_cases_agree_and_n_rooks_on_a_band_does_not() {
    // Poisson disk on a disk: both spectra nearly isotropic. The radial
    // form is within its own bound of the exact value, and the bound is
    // small against the value.
    let (radial, bound, exact) = radial_and_exact("poisson-disk", "disk:r=0.3", 1024);
    assert!(
        (radial - exact).abs() <= bound && bound < 0.25 * exact,
        "poisson-disk on a disk: radial {radial:e} ± {bound:e} vs exact {exact:e}"
    );
    // N-rooks on an axis-aligned band: its zero power along the axes, where
    // the band's energy lies, is averaged away over each ring. The radial
    // value is far off, and its bound says it cannot be trusted.
    let ns = [64usize, 256, 1024, 4096];
    let (mut radial, mut exact) = (Vec::new(), Vec::new());
    for &n in &ns {
        let (r, b, e) = radial_and_exact("nrooks", "box:w=1,h=0.3", n);
        assert!((r - e).abs() <= b, "N = {n}: the bound must still hold");
        if n == 1024 {
            assert!(r > 10.0 * e, "N = 1024: radial {r:e} vs exact {e:e}");
            assert!(
                b > 0.5 * r,
                "N = 1024: bound {b:e} should flag radial {r:e}"
            );
        }
        radial.push(r);
        exact.push(e);
    }
    let nf: Vec<f64> = ns.iter().map(|&n| n as f64).collect();
    let (slope_radial, slope_exact) = (
        fit_slope(&nf, &radial).unwrap().slope,
        fit_slope(&nf, &exact).unwrap().slope,
    );
    // The truth: N-rooks on a one-axis discontinuity decays like N^-2; the
    // radial form sees white noise on the rings, N^-1.
    assert!(slope_radial > -1.3, "radial slope {slope_radial}");
    assert!(slope_exact < -1.7, "exact slope {slope_exact}");
}

/// The shipped experiments/radial-failure.json at reduced size (N = 64,
/// 256, 1024, 4 sets), through the experiment runner: its claims hold —
/// N-rooks, multi-jitter and CMJ on the band are far steeper than the
/// radial form says, N-rooks off by more than 10× at N = 1024, while
/// jitter's 2D strata make the radial form right on the band, and the
/// isotropic disk is within 25% for jitter and Poisson disk.
#[test]
fn the_radial_failure_experiment_shows_its_claims_at_reduced_size() {
    use varspec::experiment::{Experiment, Shard, run_items};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("experiments")
        .join("radial-failure.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut e = Experiment::parse(&text, "radial-failure.json").unwrap();
    e.n = vec![64, 256, 1024];
    e.sets = 4;
    let cells = run_items(&e, "radial-failure.json", Shard::ALL, &|| {}).unwrap();
    let series = |sampler: &str, integrand: &str| -> Vec<(f64, f64, f64)> {
        let f = integrands::parse(integrand).unwrap().spec();
        cells
            .iter()
            .filter(|c| c.sampler == sampler && c.integrand == f)
            .map(|c| (c.n as f64, c.variance, c.radial.unwrap().variance))
            .collect()
    };
    let band = "box:w=1,h=0.3";
    for sampler in ["nrooks", "multijitter", "cmj"] {
        let s = series(sampler, band);
        let ns: Vec<f64> = s.iter().map(|x| x.0).collect();
        let exact = fit_slope(&ns, &s.iter().map(|x| x.1).collect::<Vec<_>>()).unwrap();
        let radial = fit_slope(&ns, &s.iter().map(|x| x.2).collect::<Vec<_>>()).unwrap();
        assert!(
            exact.slope < -1.8 && radial.slope > exact.slope + 0.4,
            "{sampler} on the band: exact slope {:.2}, radial {:.2}",
            exact.slope,
            radial.slope
        );
    }
    let (_, exact, radial) = series("nrooks", band)[2];
    assert!(
        radial > 10.0 * exact,
        "N-rooks at 1024 on the band: radial {radial:e} vs exact {exact:e}"
    );
    for (sampler, integrand) in [
        ("jitter", band),
        ("jitter", "disk:r=0.3"),
        ("poisson-disk", "disk:r=0.3"),
    ] {
        for (n, exact, radial) in series(sampler, integrand) {
            assert!(
                (radial / exact - 1.0).abs() < 0.25,
                "{sampler} on {integrand} at N = {n}: radial {radial:e} vs exact {exact:e}"
            );
        }
    }
}
