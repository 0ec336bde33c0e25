//! Shear search on padded 4D sets (issue: "a shear search that finds the
//! light field's shear"). The closed-form objective is checked against
//! brute-force variances that only evaluate f at sampled points; the search
//! against the analytic shear −c of integrands it was not tuned on, with
//! the sign; the double-wedge call against single layers and two-layer
//! mixtures.

use varspec::integrands;
use varspec::optimize::shear::{
    ObjectiveOptions, SearchStage, ShearObjective, Sheared, search_shear, shear_set, spectral_start,
};
use varspec::registry;
use varspec::rng::set_rng;
use varspec::samplers::Sampler;
use varspec::variance::{VarianceError, empirical_shifting};

/// Two-sided z for a per-check false-alarm rate of 1e-4.
const Z: f64 = 3.89;

fn objective<'a>(
    f: &dyn integrands::Integrand,
    sampler: &'a dyn Sampler,
) -> (ShearObjective<'a>, varspec::optimize::shear::SpectralStart) {
    let start = spectral_start(f, 64, 2.0);
    let mut starts = start.candidates();
    starts.push([0.0, 0.0]);
    let objective = ShearObjective::new(f, sampler, &starts, ObjectiveOptions::default()).unwrap();
    (objective, start)
}

/// The (x, y)-shifted variance of `sampler` sheared by `shear`, from R fresh
/// realizations: mean, and the standard error of the variance estimate.
fn brute_force(
    f: &dyn integrands::Integrand,
    sampler: &dyn Sampler,
    shear: [f64; 2],
    r: usize,
) -> (f64, f64) {
    let sheared = Sheared::new(sampler, shear).unwrap();
    let e = empirical_shifting(f, r, 77, &[0, 1], |i| -> Result<_, VarianceError> {
        Ok(sheared.sample(&mut set_rng(4242, i as u64))?)
    })
    .unwrap();
    // The reported 95% interval is ±1.96 standard errors.
    (e.variance, e.stderr)
}

/// J of `sampler` on `spec` at each shear against the brute-force
/// variance from 20,000 fresh realizations: within 3.89σ of both estimates
/// (J's standard error is 0 for closed forms) plus J's truncation bound.
fn assert_matches_brute_force(spec: &str, sampler: &str, n: usize, shears: &[[f64; 2]]) {
    let f = integrands::parse(spec).unwrap();
    let s = registry::build(sampler, n, Some(4), &[]).unwrap();
    let (objective, _) = objective(f.as_ref(), s.as_ref());
    for &shear in shears {
        let j = objective.evaluate(shear).unwrap();
        let (v, se) = brute_force(f.as_ref(), s.as_ref(), shear, 20_000);
        // The bound (Parseval tail × max|p − 1| ≤ 1) may widen the
        // tolerance only by a little: a bound as large as the variance
        // would let anything pass.
        assert!(
            objective.truncation_bound() <= 0.05 * v,
            "{spec} {sampler}: truncation bound {:e} against variance {v:e}",
            objective.truncation_bound()
        );
        let sigma = se.hypot(j.stderr);
        let tolerance = Z * sigma + objective.truncation_bound();
        assert!(
            (j.value - v).abs() <= tolerance,
            "{spec} {sampler} N={n} shear {shear:?}: J {:e} ± {:e} vs brute force {v:e} ± {se:e}; \
             allowed {tolerance:e} ({Z}σ of both + truncation bound {:e})",
            j.value,
            j.stderr,
            objective.truncation_bound()
        );
    }
}

#[test]
fn closed_form_objective_matches_brute_force_variances() {
    for (spec, sampler, n, shears) in [
        (
            "defocus:shape=box,size=0.3,c=0.6",
            "umj",
            64,
            vec![[0.0, 0.0], [-0.6, -0.6], [-0.3, 0.2]],
        ),
        (
            "defocus:shape=disk,size=0.42,c=-0.35",
            "umj:pairs=cmj",
            100,
            vec![[0.0, 0.0], [0.35, 0.35], [0.5, 0.1]],
        ),
        (
            "layers:shape=gaussian,size=0.5,c1=0.7,c2=-0.1,mix=0.4",
            "padded:xy=jitter,uv=random",
            49,
            vec![[0.0, 0.0], [-0.7, -0.7], [0.1, 0.1]],
        ),
    ] {
        assert_matches_brute_force(spec, sampler, n, &shears);
    }
}

#[test]
fn search_finds_the_light_field_shear_with_its_sign() {
    // Apertures, sizes and shears away from the examples in the docs.
    for (spec, n) in [
        ("defocus:shape=disk,size=0.27,c=0.73", 256),
        ("defocus:shape=box,size=0.12,c=-0.58", 64),
        ("defocus:shape=gaussian,size=0.61,c=0.21", 1024),
        ("defocus:shape=disk,size=0.04,c=-0.77", 256),
        ("defocus:shape=box,size=0.45,c=0.33", 144),
    ] {
        let f = integrands::parse(spec).unwrap();
        let c = f.light_field().unwrap().layer_shears()[0][0];
        let s = registry::build("umj", n, Some(4), &[]).unwrap();
        let (objective, start) = objective(f.as_ref(), s.as_ref());
        let found = search_shear(&objective, &start, 2.0, &|_| {}).unwrap();
        for (axis, a) in found.shear.iter().enumerate() {
            assert!(
                (a - c).abs() <= 0.02,
                "{spec} N={n}: axis {axis} shear {a} not within 0.02 of the analytic {c}"
            );
        }
        let analytic = objective.value(c, c);
        assert!(
            found.optimum.value <= 1.15 * analytic,
            "{spec} N={n}: variance {:e} above 1.15x the analytic shear's {analytic:e}",
            found.optimum.value
        );
        // A gain (≥ 1.1x: apertures as small as 0.04 gain 1.3x at N = 256, the analytic shear alike), against J at (0, 0) evaluated here
        // rather than the search's own fallback value.
        let unsheared = objective.value(0.0, 0.0);
        assert!(
            !found.kept_unsheared && found.optimum.value <= 0.9 * unsheared,
            "{spec} N={n}: variance {:e} not 0.9x below the unsheared {unsheared:e}",
            found.optimum.value
        );
        // Sharper than its neighbourhood: the optimum is a minimum.
        assert!(found.sensitivity.iter().all(|&v| v >= found.optimum.value));
    }
}

#[test]
fn the_search_gain_holds_on_fresh_realizations() {
    let f = integrands::parse("defocus:shape=disk,size=0.33,c=-0.52").unwrap();
    let s = registry::build("umj", 256, Some(4), &[]).unwrap();
    let (objective, start) = objective(f.as_ref(), s.as_ref());
    let found = search_shear(&objective, &start, 2.0, &|_| {}).unwrap();
    let (before, se_before) = brute_force(f.as_ref(), s.as_ref(), [0.0, 0.0], 4000);
    let (after, se_after) = brute_force(f.as_ref(), s.as_ref(), found.shear, 4000);
    // At least 4x lower at the unfavourable ends of the 3.89σ intervals.
    assert!(
        before - Z * se_before >= 4.0 * (after + Z * se_after),
        "variance {before:e} ± {se_before:e} -> {after:e} ± {se_after:e} at shear {:?}",
        found.shear
    );
}

#[test]
fn no_shear_is_kept_when_nothing_is_better() {
    let f = integrands::parse("defocus:shape=box,size=0.3,c=0").unwrap();
    let s = registry::build("umj", 64, Some(4), &[]).unwrap();
    let (objective, start) = objective(f.as_ref(), s.as_ref());
    let stages = std::cell::RefCell::new(Vec::new());
    let found = search_shear(&objective, &start, 2.0, &|s| stages.borrow_mut().push(s)).unwrap();
    // The progress display hears every stage, in order.
    assert_eq!(
        stages.into_inner(),
        [
            SearchStage::Candidates,
            SearchStage::Line(0),
            SearchStage::Line(1),
            SearchStage::Polish,
            SearchStage::Sensitivity
        ]
    );
    // (0, 0) itself, said so: the in-focus layer and the symmetric double
    // wedge (whose optimum is (0, 0) by symmetry; the polish used to return
    // a shear of 1e-9 there, a gain J could not resolve, as a found shear).
    let symmetric = integrands::parse("layers:c1=0.3,c2=-0.3,mix=0.5").unwrap();
    let (wedge, wedge_start) = self::objective(symmetric.as_ref(), s.as_ref());
    let wedge_found = search_shear(&wedge, &wedge_start, 2.0, &|_| {}).unwrap();
    for (what, r) in [("c = 0", &found), ("c = ±0.3", &wedge_found)] {
        assert!(
            r.kept_unsheared && r.shear == [0.0, 0.0] && r.optimum.value == r.unsheared.value,
            "{what}: kept {} at {:?}, J {:e} against the unsheared {:e}",
            r.kept_unsheared,
            r.shear,
            r.optimum.value,
            r.unsheared.value
        );
    }
    assert!(search_shear(&objective, &start, f64::INFINITY, &|_| {}).is_err());
    assert!(search_shear(&objective, &start, 0.0, &|_| {}).is_err());
}

#[test]
fn double_wedges_are_told_from_single_layers() {
    for spec in [
        "defocus:shape=box,size=0.3,c=0.6",
        "defocus:shape=gaussian,size=0.9,c=-0.5",
        "defocus:shape=disk,size=0.02,c=0.8",
        "defocus:shape=disk,size=0.6,c=0",
        // A hairline aperture: its spectrum is flat in k_x, so every
        // column weighs alike and the slope must be exact to the far ones.
        "defocus:shape=box,size=0.0001,c=0.7931",
        // A slope beyond the range the analysis is given.
        "defocus:shape=disk,size=0.3,c=3.3",
    ] {
        let f = integrands::parse(spec).unwrap();
        let c = f.light_field().unwrap().layer_shears()[0][0];
        // The analysis describes the spectrum whatever the search's range.
        for range in [2.0, 0.1] {
            let start = spectral_start(f.as_ref(), 64, range);
            assert!(
                !start.double_wedge,
                "{spec}, range {range}: {:?}",
                start.planes[0]
            );
            assert!(
                (start.planes[0].lines[0] + c).abs() <= 0.002,
                "{spec}, range {range}: {:?}",
                start.planes[0]
            );
        }
    }
    for spec in [
        "layers:shape=box,size=0.3,c1=0.5,c2=-0.2",
        "layers:shape=disk,size=0.1,c1=0.6,c2=-0.4,mix=0.3",
        "layers:shape=gaussian,size=0.2,c1=-0.7,c2=0.7",
        // Close layers share their cells at low k_x: a share of the energy
        // read their second lines at −0.015 and −1.015.
        "layers:shape=box,size=0.3,c1=0.37,c2=0.1",
        "layers:shape=box,size=0.3,c1=0.6,c2=0.3",
        "layers:shape=box,size=0.2,c1=0.8,c2=0.55",
        // A steep layer leaves the box early; with most of the energy it
        // is still the first line (review: it was reported second).
        "layers:shape=box,size=0.3,c1=4,c2=0.5,mix=0.3",
        // ... and a steep weak layer beyond the fit's range (read as 0.645).
        "layers:shape=box,size=0.3,c1=4,c2=0.5,mix=0.7",
    ] {
        let f = integrands::parse(spec).unwrap();
        let start = spectral_start(f.as_ref(), 64, 2.0);
        assert!(start.double_wedge, "{spec}: {:?}", start.planes[0]);
        // Its two lines are the layers' slopes: to the scan's 0.005 step on
        // box and disk apertures, or to what bands of width 1 resolve where
        // the line stays in the box |k|∞ ≤ 64 (|k_x| ≤ 64/|c|: 0.0625 at
        // c = 4, measured 3.95); a Gaussian's energy lies at k_x ≤ ~10,
        // where they resolve the slope to ~0.05 (measured −0.71 and 0.695
        // for ±0.7).
        let tolerance = |c: f64| {
            if spec.contains("gaussian") {
                0.06
            } else {
                (c.abs() / 64.0).max(0.0051)
            }
        };
        let mut lines = start.planes[0].lines.clone();
        let mut layers: Vec<f64> = f
            .light_field()
            .unwrap()
            .layer_shears()
            .iter()
            .map(|s| -s[0])
            .collect();
        // Strongest first: the layers weigh 1 − mix and mix; with equal
        // weights either order.
        let mix: f64 = spec
            .split_once("mix=")
            .map_or(0.5, |(_, m)| m.parse().unwrap());
        if mix > 0.5 {
            layers.reverse();
        } else if mix == 0.5 {
            lines.sort_by(f64::total_cmp);
            layers.sort_by(f64::total_cmp);
        }
        assert!(
            lines.len() == 2
                && lines
                    .iter()
                    .zip(&layers)
                    .all(|(l, c)| (l - c).abs() <= tolerance(*c)),
            "{spec}: lines {lines:?} against the layers' {layers:?}"
        );
        let s = registry::build("umj", 64, Some(4), &[]).unwrap();
        let objective = ShearObjective::new(
            f.as_ref(),
            s.as_ref(),
            &start.candidates(),
            ObjectiveOptions::default(),
        )
        .unwrap();
        let found = search_shear(&objective, &start, 2.0, &|_| {}).unwrap();
        // The best single shear: no point of a 0.1 grid over [−1, 1]²,
        // evaluated here, is lower (the layers' own shears and (0, 0)
        // among them; with two planes the best may lie between them).
        let grid = (-10..=10)
            .flat_map(|i| (-10..=10).map(move |j| [0.1 * f64::from(i), 0.1 * f64::from(j)]));
        let (best, at) = grid
            .map(|p| (objective.value(p[0], p[1]), p))
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .unwrap();
        assert!(
            found.optimum.value <= best * (1.0 + 1e-9),
            "{spec}: J {:e} at {:?} above the grid's {best:e} at {at:?}",
            found.optimum.value,
            found.shear
        );
    }
}

#[test]
fn estimated_halves_report_their_standard_error() {
    // Poisson disk has no closed form: the (u, v) half is estimated.
    let f = integrands::parse("defocus:shape=disk,size=0.3,c=0.4").unwrap();
    let s = registry::build("padded:xy=cmj,uv=poisson-disk", 64, Some(4), &[]).unwrap();
    // A coarser truncation target than the default (fewer terms, each
    // costing a pass over the estimated half's realizations): this test is
    // about the standard error, which does not depend on it.
    let start = spectral_start(f.as_ref(), 64, 2.0);
    let mut starts = start.candidates();
    starts.push([0.0, 0.0]);
    let options = ObjectiveOptions {
        truncation: 0.1,
        ..ObjectiveOptions::default()
    };
    let objective = ShearObjective::new(f.as_ref(), s.as_ref(), &starts, options).unwrap();
    let [xy, uv] = objective.realizations();
    assert!(
        xy == 0 && uv >= 2,
        "only the (u, v) half is estimated: {xy}, {uv}"
    );
    let found = search_shear(&objective, &start, 2.0, &|_| {}).unwrap();
    assert!(
        found.shear.iter().all(|a| (a + 0.4).abs() <= 0.02),
        "{:?}",
        found.shear
    );
    let at_zero = objective.evaluate([0.0, 0.0]).unwrap();
    assert!(at_zero.stderr > 0.0 && at_zero.stderr <= 0.02 * at_zero.value);
}

#[test]
fn estimated_objective_matches_brute_force_variances() {
    // Halves without a closed form: J is estimated from the sampler's own
    // realizations (the (u, v) half's pair sums by powers of one phasor,
    // the (x, y) half's power on a box), end to end against variances that
    // only evaluate f on fresh sheared sets.
    for (spec, sampler, n, shears) in [
        (
            "defocus:shape=disk,size=0.3,c=0.4",
            "padded:xy=cmj,uv=poisson-disk",
            64,
            vec![[0.0, 0.0], [-0.4, -0.4], [-0.25, 0.3]],
        ),
        (
            "layers:shape=gaussian,size=0.35,c1=-0.45,c2=0.25,mix=0.6",
            "padded:xy=poisson-disk,uv=jitter",
            49,
            vec![[0.0, 0.0], [0.45, 0.45], [-0.25, -0.25]],
        ),
        // Both halves estimated: J and the (x, y) half's weights from one
        // pass over the (u, v) realizations.
        (
            "defocus:shape=gaussian,size=0.4,c=-0.3",
            "padded:xy=poisson-disk,uv=poisson-disk",
            64,
            vec![[0.0, 0.0], [0.3, 0.3]],
        ),
    ] {
        assert_matches_brute_force(spec, sampler, n, &shears);
    }
}

#[test]
fn the_coarse_objective_has_the_basin_of_the_full_one() {
    // The search scans the coarse J (the 2048 largest-bound terms) to
    // locate basins: on apertures with edges at N = 1024, where it drops
    // most terms, its minimum along each axis is the light
    // field's shear, as J's is.
    for spec in [
        "defocus:shape=disk,size=0.3,c=0.62",
        "defocus:shape=box,size=0.15,c=-0.37",
    ] {
        let f = integrands::parse(spec).unwrap();
        let c = f.light_field().unwrap().layer_shears()[0][0];
        let s = registry::build("padded:xy=cmj,uv=jitter", 1024, Some(4), &[]).unwrap();
        let (objective, _) = objective(f.as_ref(), s.as_ref());
        assert!(
            objective.coarse_terms() < objective.terms() / 10,
            "{spec}: coarse {} of {} terms",
            objective.coarse_terms(),
            objective.terms()
        );
        let grid: Vec<f64> = (-20..=20).map(|i| 0.1 * i as f64).collect();
        let argmin = |values: Vec<f64>| {
            let i = (0..values.len())
                .min_by(|&i, &j| values[i].total_cmp(&values[j]))
                .unwrap();
            grid[i]
        };
        let coarse = argmin(grid.iter().map(|&a| objective.coarse_value(a, c)).collect());
        let full = argmin(grid.iter().map(|&a| objective.value(a, c)).collect());
        assert!(
            (coarse - c).abs() <= 0.05 + 1e-12 && (full - c).abs() <= 0.05 + 1e-12,
            "{spec}: coarse J's grid minimum at {coarse}, J's at {full}, light field's shear {c}"
        );
    }
}

#[test]
fn integrands_and_samplers_without_the_structure_are_refused() {
    let umj = registry::build("umj", 16, Some(4), &[]).unwrap();
    let sobol = registry::build("sobol", 16, Some(4), &[]).unwrap();
    let defocus = integrands::parse("defocus:c=0.5").unwrap();
    let disk = integrands::parse("disk:r=0.2").unwrap();
    let err = ShearObjective::new(
        defocus.as_ref(),
        sobol.as_ref(),
        &[[0.0, 0.0]],
        ObjectiveOptions::default(),
    )
    .err()
    .unwrap()
    .to_string();
    assert!(err.contains("padded"), "{err}");
    let err = ShearObjective::new(
        disk.as_ref(),
        umj.as_ref(),
        &[[0.0, 0.0]],
        ObjectiveOptions::default(),
    )
    .err()
    .unwrap()
    .to_string();
    assert!(err.contains("light-field"), "{err}");
    let set = registry::build("cmj", 16, Some(2), &[])
        .unwrap()
        .sample(&mut set_rng(0, 0))
        .unwrap();
    assert!(shear_set(&set, [0.5, 0.5]).is_err());
}

#[test]
fn layers_variance_matches_monte_carlo() {
    // ∫f² − I² by plain Monte Carlo on uniform points (independent of the
    // Fourier series behind Layers::variance).
    for spec in [
        "layers:shape=disk,size=0.3,c1=0.5,c2=-0.2",
        "layers:shape=box,size=0.2,c1=0.8,c2=0.1,mix=0.3",
    ] {
        let f = integrands::parse(spec).unwrap();
        let mut rng = set_rng(5, 0);
        let r = 400_000;
        let values: Vec<f64> = (0..r)
            .map(|_| {
                let x: Vec<f64> = (0..4).map(|_| varspec::rng::uniform(&mut rng)).collect();
                f.eval(&x) - f.integral()
            })
            .collect();
        let m2 = values.iter().map(|v| v * v).sum::<f64>() / r as f64;
        let m4 = values.iter().map(|v| v.powi(4)).sum::<f64>() / r as f64;
        let se = ((m4 - m2 * m2) / r as f64).sqrt();
        assert!(
            (f.variance() - m2).abs() <= Z * se,
            "{spec}: variance {} vs Monte Carlo {m2} ± {} ({Z}σ)",
            f.variance(),
            Z * se
        );
    }
}

/// The seed's convergence figure at reduced size (results/seed-figures,
/// `shear-convergence.png`): shearing umj by the light field's −c does not
/// just lower the variance by a constant, it steepens the rate, so the gain
/// grows with N. Empirical variances (shift in x, y only, 3000
/// realizations each) with z = 3.89 intervals; the gain at N = 1024 must
/// exceed twice the gain at N = 64 even at the intervals' unfavourable ends
/// (measured with 4000 realizations: 3.4× at 64, 12.5× at 1024).
#[test]
fn shearing_steepens_the_convergence_rate() {
    let field = integrands::parse("defocus:shape=disk,size=0.3,c=0.5").unwrap();
    let gain = |n: usize| {
        let umj = registry::build("umj", n, Some(4), &[]).unwrap();
        let sheared = Sheared::new(umj.as_ref(), [-0.5, -0.5]).unwrap();
        let measure = |s: &dyn Sampler| {
            empirical_shifting(field.as_ref(), 3000, 11, &[0, 1], |r| {
                s.sample(&mut set_rng(23, r as u64))
                    .map_err(VarianceError::from)
            })
            .unwrap()
        };
        let (before, after) = (measure(umj.as_ref()), measure(&sheared));
        let low = (before.variance - Z * before.stderr) / (after.variance + Z * after.stderr);
        let high =
            (before.variance + Z * before.stderr) / (after.variance - Z * after.stderr).max(0.0);
        (before.variance / after.variance, low, high)
    };
    let (g64, _, high64) = gain(64);
    let (g1024, low1024, _) = gain(1024);
    assert!(
        low1024 > 2.0 * high64,
        "gain at N = 1024: {g1024:.2} (lower end {low1024:.2}); at N = 64: {g64:.2} (upper end {high64:.2})"
    );
}

#[test]
fn the_search_widens_its_range_warns_and_handles_degenerate_integrands() {
    use varspec::optimize::shear::checked::search_and_check;
    let s = registry::build("umj", 64, Some(4), &[]).unwrap();
    let run = |spec: &str, range: Option<f64>| {
        let f = integrands::parse(spec).unwrap();
        search_and_check(f.as_ref(), s.as_ref(), "umj", 1, range, 0, &|_| {}).unwrap()
    };
    // A light field sheared beyond the default range of 2: found without
    // --range, the range reported; with --range 1 the search stops there
    // and says why.
    let wide = run("defocus:shape=disk,size=0.3,c=3.3", None);
    assert!(
        wide.found.shear.iter().all(|a| (a + 3.3).abs() <= 0.02),
        "{:?}",
        wide.found.shear
    );
    assert!(wide.report["range"].as_f64().unwrap() >= 3.3);
    assert!(wide.warnings.is_empty(), "{:?}", wide.warnings);
    let cut = run("defocus:shape=disk,size=0.3,c=3.3", Some(1.0));
    assert!(cut.found.shear.iter().all(|a| a.abs() <= 1.0));
    assert!(
        cut.warnings.iter().any(|w| w.contains("outside --range 1")),
        "{:?}",
        cut.warnings
    );
    // Constant in (x, y): every shear gives 0; no shear, no ratio.
    for spec in [
        "defocus:shape=box,size=1,c=0.3",
        // Two constant layers: the variance sums to rounding, not to 0.
        "layers:shape=box,size=1,c1=0.5,c2=-0.2",
    ] {
        let constant = run(spec, None);
        assert_eq!(constant.found.shear, [0.0, 0.0], "{spec}");
        assert!(constant.report["reduction"].is_null(), "{spec}");
        assert!(
            constant.warnings.iter().any(|w| w.contains("constant")),
            "{spec}: {:?}",
            constant.warnings
        );
    }
    // An aperture whose spectrum lies beyond the sum: J cannot tell shears
    // apart, so the spectrum's direction decides, with a warning.
    let hairline = run("defocus:shape=box,size=0.0001,c=0.7931", None);
    assert!(
        hairline
            .found
            .shear
            .iter()
            .all(|a| (a + 0.7931).abs() <= 0.002),
        "{:?}",
        hairline.found.shear
    );
    assert!(
        hairline
            .warnings
            .iter()
            .any(|w| w.contains("truncation bound")),
        "{:?}",
        hairline.warnings
    );
    // An estimated (x, y) half on a smooth aperture: J is nearly flat about
    // −c, and the search must not trade the line's exact shear for a point
    // J cannot tell from it (it returned −1.1857 here, J 2.1% higher, with
    // the principal direction as the fallback).
    let sobol = registry::build("padded:xy=sobol,uv=sobol", 64, Some(4), &[]).unwrap();
    let f = integrands::parse("defocus:shape=gaussian,size=0.3,c=1.2").unwrap();
    let estimated =
        search_and_check(f.as_ref(), sobol.as_ref(), "sobol", 7, None, 0, &|_| {}).unwrap();
    assert!(
        estimated
            .found
            .shear
            .iter()
            .all(|a| (a + 1.2).abs() <= 0.002),
        "{:?}",
        estimated.found.shear
    );
    // In focus: the analytic shear is 0, not -0.
    let focus = run("defocus:shape=disk,size=0.3,c=0", None);
    assert_eq!(
        serde_json::to_string(&focus.report["analytic_shear"]).unwrap(),
        "[[0.0,0.0]]"
    );
    // Nor is the spectral start.
    assert_eq!(
        serde_json::to_string(&focus.report["initial_shear"]).unwrap(),
        "[0.0,0.0]"
    );
}

/// `-o` writes the `--sets` sets `sample` draws with the same seed, each
/// sheared by the reported shear (x′ = x + a·u, y′ = y + b·v mod 1);
/// `--png-prefix` their XU and YV spectra before and after; the text
/// output names every file written.
#[test]
fn the_written_sets_are_the_seeded_sets_sheared_by_the_found_shear() {
    let dir = crate::common::temp_dir("shear-outputs");
    let (sheared, drawn) = (dir.join("sheared.csv"), dir.join("drawn.csv"));
    let prefix = dir.join("p");
    let spec = "defocus:shape=disk,size=0.3,c=0.5";
    // The sets both commands draw.
    let draw = ["-n", "64", "--sets", "3", "--seed", "11"];
    let outputs = [
        "--integrand",
        spec,
        "-o",
        sheared.to_str().unwrap(),
        "--png-prefix",
        prefix.to_str().unwrap(),
    ];
    let common = [&draw[..], &outputs].concat();
    let json = crate::common::varspec_ok(&[&["optimize", "shear", "--json"][..], &common].concat());
    let report: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let [a, b] = [0, 1].map(|i| report["shear"][i].as_f64().unwrap());
    assert!(
        a < -0.3 && b < -0.3,
        "the shear of c = 0.5 is near −0.5: {a}, {b}"
    );
    crate::common::varspec_ok(
        &[
            &["sample", "umj"][..],
            &draw,
            &["-o", drawn.to_str().unwrap()],
        ]
        .concat(),
    );
    let (after, before) = (
        varspec::io::read_point_sets(&sheared).unwrap(),
        varspec::io::read_point_sets(&drawn).unwrap(),
    );
    assert_eq!((after.len(), after[0].len(), after[0].dim()), (3, 64, 4));
    for (s, d) in after.iter().zip(&before) {
        for (p, q) in s.points().zip(d.points()) {
            let x = (q[0] + a * q[2]).rem_euclid(1.0);
            let y = (q[1] + b * q[3]).rem_euclid(1.0);
            assert!(
                (p[0] - x).abs() < 1e-12 && (p[1] - y).abs() < 1e-12 && p[2..] == q[2..],
                "{p:?} is not {q:?} sheared by ({a}, {b})"
            );
        }
    }
    let pictures: Vec<String> = ["xu-before", "xu-after", "yv-before", "yv-after"]
        .iter()
        .map(|name| format!("{}-{name}.png", prefix.display()))
        .collect();
    for png in &pictures {
        assert!(std::fs::read(png).unwrap().starts_with(b"\x89PNG"), "{png}");
    }
    // The text output ends by naming them all.
    let text = crate::common::varspec_ok(&[&["optimize", "shear"][..], &common].concat());
    let last = String::from_utf8_lossy(&text.stdout)
        .lines()
        .last()
        .unwrap_or_default()
        .to_string();
    assert_eq!(
        last,
        format!("wrote {}, {}", sheared.display(), pictures.join(", "))
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The objective's description says, per half, whether it is a closed
/// form or estimated (it was one sentence for every sampler: second
/// trial).
#[test]
fn the_objective_says_which_half_is_estimated() {
    for (sampler, said) in [
        (
            "umj",
            "(x, y) half in closed form, (u, v) half in closed form",
        ),
        (
            "padded:xy=cmj,uv=poisson-disk",
            "(x, y) half in closed form, (u, v) half estimated from",
        ),
    ] {
        let out = crate::common::varspec_ok(&[
            "optimize",
            "shear",
            "--sampler",
            sampler,
            "-n",
            "16",
            "--integrand",
            "defocus:c=0.5",
            "--realizations",
            "0",
            "--json",
        ]);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let description = v["objective"]["description"].as_str().unwrap();
        assert!(description.contains(said), "{sampler}: {description}");
    }
}

/// A padded half with several parameters is given with --param (the
/// shorthand splits at every comma, and the error says so): the sampler
/// built and named is the one asked for, in `optimize shear` and as the
/// start of `optimize points`.
#[test]
fn nested_sampler_specs_go_through_param() {
    let half = "uv=poisson-disk:radius=0.6,max-trials=100000";
    let out = crate::common::varspec_ok(&[
        "optimize",
        "shear",
        "-n",
        "16",
        "--sampler",
        "padded",
        "--param",
        "xy=cmj",
        "--param",
        half,
        "--integrand",
        "defocus:c=0.5",
        "--realizations",
        "0",
        "--json",
    ]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        json["sampler"],
        format!("padded:xy=cmj,{half}"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let dir = crate::common::temp_dir("nested-init");
    let report = dir.join("r.json");
    crate::common::varspec_ok(&[
        "optimize",
        "points",
        "-n",
        "16",
        "-d",
        "4",
        "--init",
        "padded",
        "--param",
        half,
        "--target",
        "xu:family:disks",
        "--sets",
        "1",
        "--iters",
        "2",
        "-o",
        dir.join("p.csv").to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    let r = crate::common::read_json(&report);
    assert_eq!(r["init"], format!("padded:{half}"), "{r}");
}
