//! Closed-form expected pair sums C(ω, ω′) of the stratified samplers
//! against Monte Carlo averages over their own realizations (independent of
//! the algebra), and jitter's power against Pilleboue et al. (2015)'s
//! E[N·P_S(k)] = 1 − sinc²(πk_x/m)·sinc²(πk_y/m).

use rustfft::num_complex::Complex64;
use varspec::registry;
use varspec::rng::set_rng;
use varspec::spectrum::pair::EmpiricalPairs;

/// Two-sided z for a per-check false-alarm rate of 1e-5 (≈ 600 checks keep
/// the family-wise rate near 0.6%).
const Z: f64 = 4.42;

/// Real frequencies, integer ones among them, with ω ≠ ω′ and ω = ω′.
const PAIRS: &[([f64; 2], [f64; 2])] = &[
    ([1.0, 0.0], [1.0, 0.0]),
    ([3.0, 2.0], [3.0, 2.0]),
    ([0.37, 0.0], [0.37, 0.0]),
    ([2.6, -1.3], [2.6, -1.3]),
    ([0.4, 0.9], [-0.7, 0.2]),
    ([5.25, 0.5], [1.5, -2.0]),
    ([0.0, 0.0], [0.0, 0.0]),
    ([11.3, 7.9], [11.3, 7.9]),
];

fn check(name: &str, n: usize, params: &[(String, String)]) {
    let sampler = registry::build(name, n, Some(2), params).unwrap();
    let exact = sampler
        .pair_spectrum()
        .unwrap_or_else(|| panic!("{name} has a closed form"));
    let r: usize = 20_000;
    let sets = (0..r)
        .map(|i| sampler.sample(&mut set_rng(11, i as u64)).unwrap())
        .collect();
    let empirical = EmpiricalPairs::new(sets);
    for &(w1, w2) in PAIRS {
        let values: Vec<Complex64> = (0..r).map(|i| empirical.pair_sum_of(i, w1, w2)).collect();
        let mean: Complex64 = values.iter().sum::<Complex64>() / r as f64;
        let sd = |part: fn(&Complex64) -> f64| {
            let mu = part(&mean);
            (values.iter().map(|v| (part(v) - mu).powi(2)).sum::<f64>() / (r - 1) as f64).sqrt()
        };
        let ours = exact.pair_sum(w1, w2);
        for (label, part) in [
            ("re", (|c: &Complex64| c.re) as fn(&Complex64) -> f64),
            ("im", |c: &Complex64| c.im),
        ] {
            // Parts with no spread are exact in every realization: compare
            // them to rounding.
            let tol = Z * sd(part) / (r as f64).sqrt() + 1e-9 * (n * n) as f64;
            assert!(
                (part(&ours) - part(&mean)).abs() <= tol,
                "{name} N={n} C({w1:?}, {w2:?}).{label}: closed form {} vs Monte Carlo {} ± {tol:e} ({Z}σ, R = {r})",
                part(&ours),
                part(&mean)
            );
        }
    }
}

#[test]
fn closed_forms_match_monte_carlo() {
    for n in [1, 9, 25] {
        check("random", n, &[]);
        check("jitter", n, &[]);
        check("regular", n, &[]);
        check("uniform-jitter", n, &[]);
    }
    // Square, oblong (4 × 6) and prime (1 × 7) grids.
    for n in [16, 24, 7] {
        check("multijitter", n, &[]);
        check("cmj", n, &[]);
    }
}

#[test]
fn jitter_power_is_pilleboue_s_formula() {
    let m = 8;
    let jitter = registry::build("jitter", m * m, Some(2), &[]).unwrap();
    let spectrum = jitter.pair_spectrum().unwrap();
    let sinc = |x: f64| if x == 0.0 { 1.0 } else { x.sin() / x };
    for kx in -20i64..=20 {
        for ky in -20i64..=20 {
            if kx == 0 && ky == 0 {
                continue;
            }
            let pi = std::f64::consts::PI;
            let s = sinc(pi * kx as f64 / m as f64) * sinc(pi * ky as f64 / m as f64);
            let expected = 1.0 - s * s;
            let ours = spectrum.power([kx as f64, ky as f64]);
            assert!(
                (ours - expected).abs() < 1e-10,
                "k = ({kx}, {ky}): {ours} vs {expected}"
            );
        }
    }
}

#[test]
fn power_grid_is_the_power_at_each_frequency() {
    // Multi-jitter and CMJ share each axis's factors across the grid;
    // jitter takes the default, frequency by frequency. Real and integer
    // frequencies, both signs, square and oblong grids.
    let xs = [-37.0, -2.5, 0.0, 1.0, 6.0, 129.0, 1000.25];
    let ys = [-5.0, -0.75, 0.0, 3.0, 64.0];
    for (name, n) in [
        ("multijitter", 64),
        ("cmj", 64),
        ("cmj", 24),
        ("jitter", 49),
    ] {
        let sampler = registry::build(name, n, Some(2), &[]).unwrap();
        let pairs = sampler.pair_spectrum().unwrap();
        let grid = pairs.power_grid(&xs, &ys);
        assert_eq!(grid.len(), xs.len() * ys.len());
        for (i, &x) in xs.iter().enumerate() {
            for (j, &y) in ys.iter().enumerate() {
                let one = pairs.power([x, y]);
                assert!(
                    (grid[i * ys.len() + j] - one).abs() <= 1e-12 * one.abs().max(1.0),
                    "{name} N={n} at ({x}, {y}): grid {} vs power {one}",
                    grid[i * ys.len() + j]
                );
            }
        }
    }
}
