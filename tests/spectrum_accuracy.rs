//! Fast transforms against the direct reference (docs/architecture.md, "Conventions"), spectra with
//! closed forms, large-frequency phase accuracy.

use rustfft::num_complex::Complex64;
use varspec::PointSet;
use varspec::registry;
use varspec::rng::{set_rng, uniform};
use varspec::spectrum::dft::{evaluate_series, sample_spectrum};
use varspec::spectrum::{FrequencyBox, Method, NufftPlan, Sign, Upsampling, expected_power};

fn draw(name: &str, n: usize, d: usize, seed: u64) -> PointSet {
    registry::build(name, n, Some(d), &[])
        .unwrap()
        .sample(&mut set_rng(seed, 0))
        .unwrap()
}

fn zero() -> Complex64 {
    Complex64::new(0.0, 0.0)
}

/// Plans on `b` at each tolerance with σ = 2, and with σ = 5/4 where it
/// reaches the tolerance: (tolerance, description, plan).
fn plans(b: FrequencyBox, tolerances: &[f64]) -> Vec<(f64, String, NufftPlan)> {
    let mut out = Vec::new();
    for &tol in tolerances {
        for up in [Upsampling::Two, Upsampling::FiveFourths] {
            if up == Upsampling::FiveFourths && tol < Upsampling::FIVE_FOURTHS_MIN_TOLERANCE {
                continue;
            }
            let plan = NufftPlan::with_upsampling(b, tol, up).unwrap();
            let what = format!("tol={tol:e} sigma={}", plan.upsampling());
            out.push((tol, what, plan));
        }
    }
    out
}

/// max_i |a_i − b_i|.
fn max_difference(a: &[Complex64], b: &[Complex64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max)
}

/// The type-1 error bound of the ES-kernel NUFFT (Barnett et al. 2019):
/// |ΔS(k)| ≤ ε·Σ_j |c_j| = ε·N, and so for the power N·P_S = |S|²/N,
/// |ΔP| ≤ (2|S|·εN + (εN)²)/N.
#[test]
fn type1_matches_direct_within_its_tolerance() {
    let cases = [
        ("random", 1000, 2, 40),
        ("jitter", 1024, 2, 63),
        ("cmj", 900, 2, 50),
        ("umj", 256, 4, 5),
        ("random", 500, 3, 8),
        ("random", 300, 1, 200),
    ];
    for (name, n, d, half) in cases {
        let p = draw(name, n, d, 3);
        let b = FrequencyBox { dim: d, half };
        let exact = sample_spectrum(&p, &b);
        for (tol, what, plan) in plans(b, &[1e-3, 1e-6, 1e-9, 1e-12]) {
            let mut fast = vec![zero(); b.len()];
            plan.type1(
                &p,
                None,
                Sign::Negative,
                &mut fast,
                &mut plan.make_scratch(),
            );
            let bound = tol * n as f64;
            for (f, e) in fast.iter().zip(&exact) {
                assert!(
                    (f - e).norm() <= bound,
                    "{name} d={d} {what}: |dS| = {} > eps*N = {bound}",
                    (f - e).norm()
                );
                let dp = (f.norm_sqr() - e.norm_sqr()).abs() / n as f64;
                let power_bound = (2.0 * e.norm() * bound + bound * bound) / n as f64;
                assert!(
                    dp <= power_bound * (1.0 + 1e-9) + 1e-12,
                    "{name} {what}: power error {dp} > {power_bound}"
                );
            }
        }
    }
}

/// Type 1 with complex strengths (the optimizer's gradients) against the
/// direct sums F(k) = Σ_j c_j e^(−2πi k·x_j), written here, in d = 1…4 and
/// on grids with one slab and with many: |ΔF| ≤ ε·Σ_j |c_j|.
#[test]
fn type1_with_strengths_matches_direct_sums() {
    for (d, half, n) in [
        (1, 150, 300),
        (2, 100, 400),
        (2, 3, 50),
        (3, 7, 200),
        (4, 3, 100),
    ] {
        let p = draw("random", n, d, 21);
        let b = FrequencyBox { dim: d, half };
        let mut rng = set_rng(6, 6);
        let c: Vec<Complex64> = (0..n)
            .map(|_| Complex64::new(uniform(&mut rng) - 0.5, uniform(&mut rng) - 0.5))
            .collect();
        let l1: f64 = c.iter().map(|c| c.norm()).sum();
        let mut k = vec![0i64; d];
        let exact: Vec<Complex64> = (0..b.len())
            .map(|i| {
                b.frequency(i, &mut k);
                p.points()
                    .zip(&c)
                    .map(|(x, cj)| {
                        // Phase reduced exactly: k·x mod 1 summed term by term.
                        let t: f64 = x
                            .iter()
                            .zip(&k)
                            .map(|(xj, kj)| (xj * *kj as f64).fract())
                            .sum();
                        cj * Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * t.fract())
                    })
                    .sum()
            })
            .collect();
        for (tol, what, plan) in plans(b, &[1e-4, 1e-9, 1e-12]) {
            let mut fast = vec![zero(); b.len()];
            plan.type1(
                &p,
                Some(&c),
                Sign::Negative,
                &mut fast,
                &mut plan.make_scratch(),
            );
            let worst = max_difference(&fast, &exact);
            assert!(
                worst <= tol * l1,
                "d={d} half={half} {what}: |dF| = {worst:e} > eps*sum|c| = {:e}",
                tol * l1
            );
        }
    }
}

/// Type 2 against direct evaluation of the series: |Δc_j| ≤ ε·Σ_k |F(k)|.
#[test]
fn type2_matches_direct_within_its_tolerance() {
    for (d, half, n) in [(1, 100, 200), (2, 20, 300), (3, 6, 200), (4, 3, 100)] {
        let p = draw("random", n, d, 8);
        let b = FrequencyBox { dim: d, half };
        let mut rng = set_rng(5, 5);
        let coeffs: Vec<Complex64> = (0..b.len())
            .map(|_| Complex64::new(uniform(&mut rng) - 0.5, uniform(&mut rng) - 0.5))
            .collect();
        let l1: f64 = coeffs.iter().map(|c| c.norm()).sum();
        let exact = evaluate_series(&p, &b, &coeffs);
        for (tol, what, plan) in plans(b, &[1e-4, 1e-8, 1e-12]) {
            let mut fast = vec![zero(); n];
            plan.type2(
                &p,
                &coeffs,
                Sign::Positive,
                &mut fast,
                &mut plan.make_scratch(),
            );
            let worst = max_difference(&fast, &exact);
            assert!(
                worst <= tol * l1,
                "d={d} {what}: |dc| = {worst} > eps*sum|F| = {}",
                tol * l1
            );
        }
        // The negative sign is the conjugate transform.
        let plan = NufftPlan::new(b, 1e-12).unwrap();
        let mut neg = vec![zero(); n];
        let conj: Vec<Complex64> = coeffs.iter().map(|c| c.conj()).collect();
        plan.type2(
            &p,
            &conj,
            Sign::Negative,
            &mut neg,
            &mut plan.make_scratch(),
        );
        for (a, e) in neg.iter().zip(&exact) {
            assert!((a - e.conj()).norm() <= 1e-12 * l1);
        }
    }
}

#[test]
fn regular_grid_has_power_n_at_multiples_of_m_and_zero_elsewhere() {
    let m = 16;
    let set = draw("regular", m * m, 2, 0);
    let b = FrequencyBox { dim: 2, half: 40 };
    for method in [Method::Direct, Method::Fast { tolerance: 1e-12 }] {
        let s = expected_power(
            b,
            method,
            1,
            |_| Ok::<_, varspec::spectrum::SpectrumError>(set.clone()),
            &|| {},
        )
        .unwrap();
        let mut k = [0i64; 2];
        for (idx, &p) in s.power.iter().enumerate() {
            b.frequency(idx, &mut k);
            let expected = if k[0] % m as i64 == 0 && k[1] % m as i64 == 0 {
                (m * m) as f64
            } else {
                0.0
            };
            assert!(
                (p - expected).abs() < 1e-9,
                "{method:?} k={k:?}: {p} vs {expected}"
            );
        }
    }
}

/// A point at x = 0.123456789 and k up to 10^4 against the exact rational
/// phase (x is M·2^−e exactly, so k·x mod 1 = (k·M mod 2^e)·2^−e).
#[test]
fn large_frequency_phases_are_exact_to_1e_12() {
    let x = 0.123456789f64;
    let p = PointSet::new(1, vec![x]).unwrap();
    let b = FrequencyBox {
        dim: 1,
        half: 10_000,
    };
    let s = sample_spectrum(&p, &b);
    let bits = x.to_bits();
    let shift = 1075 - ((bits >> 52) & 0x7ff) as u32;
    let mantissa = ((bits & ((1 << 52) - 1)) | (1 << 52)) as u128;
    for (idx, v) in s.iter().enumerate() {
        let k = idx as i64 - 10_000;
        let r = (k.unsigned_abs() as u128 * mantissa) % (1u128 << shift);
        let frac = r as f64 / (1u128 << shift) as f64 * k.signum() as f64;
        let exact = Complex64::from_polar(1.0, -std::f64::consts::TAU * frac);
        assert!((v - exact).norm() < 1e-12, "k = {k}: {v} vs {exact}");
    }
}

/// Mean and standard error of N·P_S(k) over `sets` realizations, per k.
fn mean_and_se(name: &str, n: usize, b: FrequencyBox, sets: u64) -> (Vec<f64>, Vec<f64>) {
    let sampler = registry::build(name, n, Some(b.dim), &[]).unwrap();
    let plan = NufftPlan::new(b, 1e-10).unwrap();
    let mut scratch = plan.make_scratch();
    let mut s = vec![zero(); b.len()];
    let (mut mean, mut m2) = (vec![0.0; b.len()], vec![0.0; b.len()]);
    for r in 0..sets {
        let p = sampler.sample(&mut set_rng(77, r)).unwrap();
        plan.type1(&p, None, Sign::Negative, &mut s, &mut scratch);
        // Welford's update: no E[X²] − E[X]² cancellation.
        for ((m, q), v) in mean.iter_mut().zip(m2.iter_mut()).zip(&s) {
            let x = v.norm_sqr() / n as f64;
            let delta = x - *m;
            *m += delta / (r + 1) as f64;
            *q += delta * (x - *m);
        }
    }
    let se = m2
        .iter()
        .map(|q| (q / (sets - 1) as f64 / sets as f64).sqrt())
        .collect();
    (mean, se)
}

fn sinc2(x: f64) -> f64 {
    if x == 0.0 { 1.0 } else { (x.sin() / x).powi(2) }
}

/// Checks E[N·P_S(k)] = `expected(k)` at every k ≠ 0 within z = 5.5
/// standard errors: with ~1000 frequencies per test, two-sided per-k rate
/// 3.8e-8, family-wise < 1e-4.
fn check_expected(
    name: &str,
    n: usize,
    half: usize,
    sets: u64,
    expected: impl Fn(i64, i64) -> f64,
) {
    const Z: f64 = 5.5;
    let b = FrequencyBox { dim: 2, half };
    let (mean, se) = mean_and_se(name, n, b, sets);
    let mut k = [0i64; 2];
    for (idx, (m, s)) in mean.iter().zip(&se).enumerate() {
        b.frequency(idx, &mut k);
        if k == [0, 0] {
            continue;
        }
        let e = expected(k[0], k[1]);
        assert!(
            (m - e).abs() <= Z * s + 1e-9,
            "{name} k={k:?}: mean power {m} vs expected {e}, outside ± {Z} x SE {s} ({sets} sets)"
        );
    }
}

#[test]
fn random_points_have_flat_unit_spectrum() {
    check_expected("random", 256, 16, 2000, |_, _| 1.0);
}

#[test]
fn jitter_matches_its_closed_form() {
    let m = 16.0;
    let pi = std::f64::consts::PI;
    check_expected("jitter", 256, 20, 2000, |kx, ky| {
        1.0 - sinc2(pi * kx as f64 / m) * sinc2(pi * ky as f64 / m)
    });
}

/// N-rooks: for i ≠ j the x strata are two distinct uniform cells, so
/// E[e^(−2πi kx(x_i−x_j))] = −sinc²(πkx/N)/(N−1) for kx ≢ 0 (mod N), and the
/// y part is independent. Hence E[N·P_S(k)] = 1 − sinc²(πkx/N) on the axis
/// ky = 0 (1D jitter with N strata) and 1 + s_x·s_y/(N−1) off the axes
/// (≈ 1: white), with s = sinc²(πk/N).
#[test]
fn nrooks_is_1d_jitter_on_the_axes_and_white_elsewhere() {
    let n = 64.0;
    let s = |k: i64| sinc2(std::f64::consts::PI * k as f64 / n);
    check_expected("nrooks", 64, 20, 3000, |kx, ky| match (kx, ky) {
        (kx, 0) => 1.0 - s(kx),
        (0, ky) => 1.0 - s(ky),
        (kx, ky) => 1.0 + s(kx) * s(ky) / (n - 1.0),
    });
}

/// The spreading runs in parallel slabs and the interpolation in parallel
/// chunks: both transforms must give the same bits on one thread and two,
/// and still match the direct sums (the slab path with many groups: a
/// 2D box of half-width 100 has a fine grid of 450 rows, 28 slab groups).
#[test]
fn parallel_spreading_is_thread_count_independent_and_accurate() {
    let p = draw("random", 20000, 2, 17);
    let b = FrequencyBox { dim: 2, half: 100 };
    let plan = NufftPlan::new(b, 1e-9).unwrap();
    let coeffs: Vec<Complex64> = (0..b.len())
        .map(|i| Complex64::new((i % 7) as f64 - 3.0, (i % 5) as f64 * 0.5))
        .collect();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut scratch = plan.make_scratch();
            let mut modes = vec![zero(); b.len()];
            plan.type1(&p, None, Sign::Negative, &mut modes, &mut scratch);
            let mut values = vec![zero(); p.len()];
            plan.type2(&p, &coeffs, Sign::Positive, &mut values, &mut scratch);
            (modes, values)
        })
    };
    let (one, two) = (run(1), run(2));
    assert!(one == two, "results differ between 1 and 2 threads");
    let exact = sample_spectrum(&p, &b);
    let worst = max_difference(&one.0, &exact);
    assert!(
        worst <= 1e-9 * p.len() as f64,
        "type 1: max |ΔS| = {worst:e} above ε·N"
    );
}
