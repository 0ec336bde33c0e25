//! Pair correlation: white noise is 1, Poisson disk is empty below its radius.

use varspec::neighbours::hexagonal_spacing;
use varspec::registry;
use varspec::rng::set_rng;
use varspec::spectrum::pcf::pair_correlation;

#[test]
fn random_points_have_unit_pair_correlation_within_ci() {
    // On the torus every pair difference is uniform, so with the
    // kernel-smoothed normalization E[ĝ(r)] = 1 at every radius, down to
    // r = σ/2 where the kernel reaches past distance 0, and in 4D, where
    // dividing by the sphere's surface at r alone read 1.27 at 3.3σ.
    // Per-radius mean over 200 sets within z = 5 SE.
    for (d, n, r_end, bins) in [(2, 512, 0.1, 25), (4, 1024, 0.3, 12)] {
        let sigma = match d {
            2 => 0.2 * hexagonal_spacing(n),
            _ => 0.025,
        };
        let sampler = registry::build("random", n, Some(d), &[]).unwrap();
        let per_set: Vec<Vec<f64>> = (0..200)
            .map(|r| {
                let set = sampler.sample(&mut set_rng(3, r)).unwrap();
                pair_correlation(&[set], r_end, bins, sigma).unwrap().g
            })
            .collect();
        let radii = pair_correlation(
            &[sampler.sample(&mut set_rng(3, 0)).unwrap()],
            r_end,
            bins,
            sigma,
        )
        .unwrap()
        .r;
        let count = per_set.len() as f64;
        for (b, &r) in radii.iter().enumerate().filter(|(_, r)| **r >= 0.5 * sigma) {
            let mean = per_set.iter().map(|g| g[b]).sum::<f64>() / count;
            let var = per_set.iter().map(|g| (g[b] - mean).powi(2)).sum::<f64>() / (count - 1.0);
            let se = (var / count).sqrt();
            assert!(
                (mean - 1.0).abs() <= 5.0 * se + 1e-9,
                "d = {d}, r = {r} ({:.2}σ): g = {mean} ± {se} (z = 5)",
                r / sigma
            );
        }
    }
}

#[test]
fn poisson_disk_pair_correlation_vanishes_below_its_radius() {
    let n = 1024;
    let params = [("radius".to_string(), "0.75".to_string())];
    let sampler = registry::build("poisson-disk", n, Some(2), &params).unwrap();
    let sets: Vec<_> = (0..8)
        .map(|r| sampler.sample(&mut set_rng(4, r)).unwrap())
        .collect();
    let r_min = 0.75 * hexagonal_spacing(n);
    let sigma = 0.05 * r_min;
    let pcf = pair_correlation(&sets, 3.0 * r_min, 120, sigma).unwrap();
    for (&r, &g) in pcf.r.iter().zip(&pcf.g) {
        if r < r_min - 4.0 * sigma {
            // Only pairs at ≥ r_min contribute, each at most k_σ(4σ): ~3e-4 relative.
            assert!(g < 0.01, "g({r}) = {g} below the disk radius {r_min}");
        }
    }
    let peak = pcf.g.iter().copied().fold(0.0, f64::max);
    assert!(
        peak > 1.2,
        "blue noise has a first-neighbour peak above 1, found {peak}"
    );
}

#[test]
fn bad_pcf_parameters_are_errors() {
    let set = registry::build("random", 10, Some(2), &[])
        .unwrap()
        .sample(&mut set_rng(0, 0))
        .unwrap();
    assert!(pair_correlation(std::slice::from_ref(&set), 0.45, 10, 0.02).is_err());
    assert!(pair_correlation(std::slice::from_ref(&set), 0.1, 10, 0.0).is_err());
    assert!(pair_correlation(std::slice::from_ref(&set), 0.1, 0, 0.01).is_err());
    assert!(pair_correlation(&[], 0.1, 10, 0.01).is_err());
}

/// Isotropic jitter has a random count: its radii come from the density
/// λ = N, not from set 0's count, so every seed gives the same grid (r at
/// r_rel = 2.5 is 2.5·√(2/(√3·1024)) = 0.0839514); seeds 0, 1, 2 used to
/// give 0.083828, 0.084281, 0.084033 (their first sets hold 1027, 1016 and
/// 1022 points).
#[test]
fn a_random_count_process_takes_its_radii_from_its_density() {
    let radii = |seed: &str| -> Vec<f64> {
        let out = crate::common::varspec_ok(&[
            "pcf",
            "--sampler",
            "ijitter",
            "-n",
            "1024",
            "--sets",
            "4",
            "--seed",
            seed,
            "--bins",
            "4",
        ]);
        String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().unwrap().parse().unwrap())
            .collect()
    };
    let expected = 2.5 * (2.0 / (3f64.sqrt() * 1024.0)).sqrt();
    for seed in ["0", "1", "2"] {
        let r = radii(seed);
        assert_eq!(r.len(), 4);
        assert!(
            (r[3] - expected).abs() < 1e-12,
            "seed {seed}: r at r_rel = 2.5 is {} against {expected}",
            r[3]
        );
    }
}

/// With few points in 4D the default range (2.5 packing distances) would
/// reach half the torus (1.682 r_max for N = 256): range and bandwidth
/// shrink together, range = 10σ = 0.99·(1.682 − 6σ), σ = 0.99·1.682/15.94
/// = 0.1045, with a note (the range alone shrank to 0.774 r_max, short of
/// the nearest-neighbour peak at 1); a range given is kept or refused,
/// never changed.
#[test]
fn the_default_range_fits_the_torus_and_a_given_one_is_kept() {
    let dir = crate::common::temp_dir("pcf-range");
    let csv = dir.join("g.csv");
    let base = ["pcf", "--sampler", "umj", "-n", "256", "--sets", "4"];
    let out = crate::common::varspec_ok(&[&base[..], &["--csv", csv.to_str().unwrap()]].concat());
    assert!(
        String::from_utf8_lossy(&out.stderr)
            .contains("note: --range 1.045 r_max (not 2.5) and --bandwidth 0.1045 (not 0.15)"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let last = std::fs::read_to_string(&csv).unwrap();
    let r_rel: f64 = last
        .lines()
        .last()
        .unwrap()
        .split(',')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        (r_rel - 10.0 * 0.99 * 1.682 / 15.94).abs() < 2e-3,
        "{r_rel}"
    );
    crate::common::assert_fails(
        &[&base[..], &["--range", "2.5"]].concat(),
        "lower --range to below 0.782",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Where even a range down to the bandwidth would reach half the torus
/// (N = 4 in 2D: half the torus is 0.931 r_max, and 6 default kernel
/// widths alone take 0.9), the default range and bandwidth shrink
/// together, range = 10σ, σ = 0.99·0.931/15.94 (the note was documented,
/// but the command refused instead); a bandwidth given is kept, and then
/// refused.
#[test]
fn few_points_shrink_the_default_bandwidth_with_the_range() {
    let dir = crate::common::temp_dir("pcf-few");
    let points = dir.join("p4.csv");
    std::fs::write(&points, "x0,x1\n0.1,0.2\n0.6,0.3\n0.35,0.85\n0.9,0.7\n").unwrap();
    let out = crate::common::varspec_ok(&["pcf", points.to_str().unwrap()]);
    let note = String::from_utf8_lossy(&out.stderr);
    // r_max = √(2/(√3·4)) = 0.537285, half the torus 0.930605 r_max.
    assert!(
        note.contains("--range 0.578 r_max (not 2.5) and --bandwidth 0.0578 (not 0.15)"),
        "{note}"
    );
    crate::common::assert_fails(
        &["pcf", points.to_str().unwrap(), "--bandwidth", "0.15"],
        "use more points (or a smaller --bandwidth)",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A range given below 10 default bandwidths takes a tenth of it as the
/// bandwidth, with a note (the default 0.15 was refused against
/// `--range 0.001`, an option the user never gave); a bandwidth given is
/// still checked against the range.
#[test]
fn a_small_range_given_takes_a_bandwidth_to_fit() {
    let base = ["pcf", "--sampler", "jitter", "-n", "1024", "--sets", "1"];
    for (range, note) in [
        ("0.5", "note: --bandwidth 0.05 r_max (not 0.15)"),
        ("0.7", "note: --bandwidth 0.07 r_max (not 0.15)"),
        ("0.001", "note: --bandwidth 0.001 r_max (not 0.15)"),
    ] {
        let out = crate::common::varspec_ok(&[&base[..], &["--range", range]].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(note), "--range {range}: {err}");
        let rows = String::from_utf8_lossy(&out.stdout).lines().count();
        assert_eq!(rows, 101, "--range {range}: header and 100 radii");
    }
    crate::common::assert_fails(
        &[&base[..], &["--range", "0.1", "--bandwidth", "0.15"]].concat(),
        "--bandwidth 0.15: the kernel's σ",
    );
}
