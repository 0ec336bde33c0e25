//! Designs adapted to one integrand (torus, shift-randomized estimator):
//! the integration-lattice search against the generic O(N²) spatial form,
//! the choice between a descent and its start, and the goal of issue 8 §2
//! on half-planes no default was tuned on.

use crate::common;

use varspec::integrands;
use varspec::optimize::adapted::{design_sets, keep_lower_variance};
use varspec::optimize::lattice::best_lattice;
use varspec::optimize::{DescentOptions, DescentResult, PointOptimizer, Target};
use varspec::registry;
use varspec::rng::set_rng;
use varspec::samplers::Sampler;
use varspec::samplers::lattice::lattices;
use varspec::variance::{SpatialEstimate, VarianceError, spatial, spatial_variance};

/// The lattice rule's N-term form equals the generic all-pairs spatial
/// form evaluated on a shifted copy of its points, and every lattice of N
/// points is listed once (σ(N) of them).
#[test]
fn lattice_variance_is_the_spatial_form_of_its_points() {
    assert_eq!(lattices(48).len(), 124, "σ(48) = 124");
    assert_eq!(lattices(97).len(), 98, "σ(97) = 98 for a prime");
    for spec in [
        "halfplane:angle=61,offset=-0.17",
        "box:w=0.3,h=0.45,angle=12,cx=0.4",
        "disk:r=0.27,cx=0.6",
        "gaussian:sx=0.2,sy=0.1,angle=30",
    ] {
        let f = integrands::parse(spec).unwrap();
        let found = best_lattice(48, f.as_ref()).unwrap();
        let points = found.lattice.sample(&mut set_rng(5, 0)).unwrap();
        let (all_pairs, rounding) = spatial_variance(&points, f.as_ref()).unwrap();
        assert!(
            (all_pairs - found.variance).abs()
                <= 1e-9 * all_pairs + rounding + found.rounding_bound,
            "{spec}: lattice form {:e}, all-pairs form {all_pairs:e}",
            found.variance
        );
        // No lattice of 48 points does better (the search is exhaustive).
        for l in lattices(48) {
            let p = l.sample(&mut set_rng(5, 1)).unwrap();
            let (v, r) = spatial_variance(&p, f.as_ref()).unwrap();
            assert!(
                v >= found.variance - r - found.rounding_bound - 1e-12 * v,
                "{spec}: {l:?} has {v:e} below the best {:e} ({:?})",
                found.variance,
                found.lattice
            );
        }
    }
}

/// A descent that raises the exact variance returns its start, and says
/// so; one that lowers it returns its own set.
#[test]
fn the_lower_exact_variance_is_kept() {
    let f = integrands::parse("halfplane:angle=33,offset=0.1").unwrap();
    let lattice = best_lattice(64, f.as_ref()).unwrap().lattice;
    let good = lattice.sample(&mut set_rng(1, 0)).unwrap();
    let bad = registry::build("random", 64, Some(2), &[])
        .unwrap()
        .sample(&mut set_rng(1, 0))
        .unwrap();
    let result = |points: &varspec::PointSet| DescentResult {
        points: points.clone(),
        losses: vec![1.0, 0.5],
        seconds: vec![0.0, 0.1],
        best_score: 0.5,
        start_score: 1.0,
        coarse_iterations: 0,
        stop: varspec::optimize::Stop::Converged,
    };
    let kept = keep_lower_variance(good.clone(), result(&bad), f.as_ref()).unwrap();
    let e = kept.exact.unwrap();
    assert!(e.kept_start && kept.points == good, "{e:?}");
    assert!(e.start < e.descended);
    let kept = keep_lower_variance(bad.clone(), result(&good), f.as_ref()).unwrap();
    let e = kept.exact.unwrap();
    assert!(!e.kept_start && kept.points == good, "{e:?}");
}

/// Issue 8 §2 on half-planes drawn for this test (no default was chosen on
/// them). Ratios are to CMJ's mean minus three standard errors over 64
/// realizations, so each is an upper bound at ~99.9% confidence. N = 1024:
/// the goal, ≤ 0.15×. N = 256: the goal is ≤ 0.20×; the lattice design's
/// point estimates are 0.14–0.20 over twelve random half-planes
/// (results/optimize-adapted), so the bound asserted is 0.22, a regression
/// guard rather than the goal.
#[test]
fn adapted_design_beats_cmj_on_unseen_halfplanes() {
    for (n, bound) in [(256, 0.22), (1024, 0.15)] {
        for spec in [
            "halfplane:angle=139.7,offset=-0.23",
            "halfplane:angle=33.3,offset=0.19",
        ] {
            let ours = default_design_variance(spec, n);
            let c = cmj_variance(spec, n, 17);
            let ratio = ours / (c.variance - 3.0 * c.stderr);
            assert!(
                ratio <= bound,
                "{spec}, N = {n}: variance {ours:e} is {ratio:.3} of CMJ's {:e} ± {:e} \
                 (mean − 3 s.e.); bound {bound}",
                c.variance,
                c.stderr
            );
            eprintln!(
                "{spec}, N = {n}: {:.3} of CMJ (bound {ratio:.3})",
                ours / c.variance
            );
        }
    }
}

/// The command line starts 2D integrand targets from the lattice, reports
/// it, and refuses a lattice start where there is no exact form.
#[test]
fn optimize_points_reports_the_lattice_start() {
    let dir = common::temp_dir("optimize-lattice");
    let out = dir.join("hp.csv");
    let report = dir.join("hp.json");
    let run = common::varspec(&[
        "optimize",
        "points",
        "-n",
        "64",
        "--target",
        "halfplane:angle=33,offset=0.1",
        "--sets",
        "2",
        "--iters",
        "40",
        "-o",
        out.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{run:?}");
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        stdout.contains("the best of 127 integration lattices"),
        "{stdout}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(json["init"], "lattice");
    assert_eq!(json["exact"].as_array().unwrap().len(), 2);
    assert!(json["lattice"]["variance"].as_f64().unwrap() > 0.0);
    common::assert_fails(
        &[
            "optimize",
            "points",
            "-n",
            "64",
            "--target",
            "family:disks",
            "--init",
            "lattice",
            "-o",
            out.to_str().unwrap(),
        ],
        "needs a 2D integrand target with a closed-form autocovariance (cos, disk, box, gaussian, halfplane); to start from one given rank-1 lattice, name it: --init lattice:g=G",
    );
}

/// Why ≤ 0.20× CMJ cannot hold on every half-plane: for an edge parallel to
/// an axis the estimate depends on the points' projections onto the edge
/// normal alone. Under a random shift the count in the band of width A (the
/// half-plane's area) takes values in −NA + Z with mean 0, so its variance
/// is at least f(1 − f) with f = {N·A} (the two-point law on the nearest
/// values), reached by points with equispaced projections: Var ≥
/// f(1 − f)/N² for every N-point set. CMJ's projections are jittered, one
/// per 1/N stratum: each end of the band falls in a stratum covered by a
/// fraction p ~ U[0, 1), independent jitter, Var = 2·E[p(1 − p)]/N² =
/// 1/(3N²). Hence no design goes below 3f(1 − f) of CMJ (0.40 and 0.59
/// here); the lattice design reaches the floor exactly, and CMJ's variance
/// over 64 realizations holds 1/(3N²) within three standard errors.
#[test]
fn axis_aligned_halfplanes_have_a_floor_the_design_reaches() {
    let n = 256;
    for (spec, area) in [
        ("halfplane:angle=0,offset=0.265", 0.235),
        ("halfplane:angle=90,offset=0.212", 0.288),
    ] {
        let nf = n as f64;
        let frac = (nf * area).fract();
        let floor = frac * (1.0 - frac) / (nf * nf);
        let ours = default_design_variance(spec, n);
        assert!(
            (ours - floor).abs() <= 1e-9 * floor,
            "{spec}: design variance {ours:e}, the 1D floor f(1 − f)/N² = {floor:e}"
        );
        let c = cmj_variance(spec, n, 23);
        let expected = 1.0 / (3.0 * nf * nf);
        assert!(
            (c.variance - expected).abs() <= 3.0 * c.stderr,
            "{spec}: CMJ variance {:e} ± {:e} (64 sets; 99.7% CI ± 3 s.e.) against 1/(3N²) = {expected:e}",
            c.variance,
            c.stderr
        );
    }
}

/// The default adapted design for the 2D integrand `spec` at N (the best
/// lattice, the descent, kept by the exact form; seed 9): its exact
/// variance.
fn default_design_variance(spec: &str, n: usize) -> f64 {
    let f = integrands::parse(spec).unwrap();
    let target = Target::parse(spec).unwrap();
    let optimizer =
        PointOptimizer::new(2, &target, DescentOptions::for_target(n, 2, &target)).unwrap();
    let start = best_lattice(n, f.as_ref()).unwrap();
    let kept = design_sets(
        &optimizer,
        &start.lattice,
        Some(f.as_ref()),
        9,
        1,
        &|_, _| {},
        None,
    )
    .unwrap();
    kept[0].variance().unwrap()
}

/// CMJ's shift-randomized variance on `spec` at N by the spatial form,
/// over 64 realizations of stream `seed`.
fn cmj_variance(spec: &str, n: usize, seed: u64) -> SpatialEstimate {
    let f = integrands::parse(spec).unwrap();
    let cmj = registry::build("cmj", n, Some(2), &[]).unwrap();
    spatial(f.as_ref(), 64, |r| -> Result<_, VarianceError> {
        Ok(cmj.sample(&mut set_rng(seed, r as u64))?)
    })
    .unwrap()
}

/// The reduced basis's shortest dual vector equals the shortest found by
/// enumerating the dual points k·x ∈ Z for every point x of the lattice
/// (|k|∞ ≤ N), for every lattice of several N.
#[test]
fn the_shortest_dual_vector_is_the_enumerated_one() {
    for n in [12, 64, 89, 100] {
        for l in lattices(n) {
            let points = l.points([0.0, 0.0]);
            let on_dual = |k: [i64; 2]| {
                points.points().all(|x| {
                    let t = k[0] as f64 * x[0] + k[1] as f64 * x[1];
                    (t - t.round()).abs() < 1e-9
                })
            };
            let span = n as i64;
            let shortest = (-span..=span)
                .flat_map(|k0| (-span..=span).map(move |k1| [k0, k1]))
                .filter(|&k| k != [0, 0] && on_dual(k))
                .map(|k| k[0] * k[0] + k[1] * k[1])
                .min()
                .unwrap();
            let h = l.shortest_dual();
            assert!(on_dual(h), "{l:?}: {h:?} is not a dual vector");
            assert_eq!(h[0] * h[0] + h[1] * h[1], shortest, "{l:?}: {h:?}");
        }
    }
}

/// A cosine of frequency (3, 2) is integrated exactly by every lattice
/// whose dual misses ±(3, 2): the tie goes to the lattice best for
/// integrands in general, not to the first listed (64 points on one
/// vertical line, shortest dual vector (1, 0)).
#[test]
fn lattices_tied_on_the_target_go_to_the_most_two_dimensional() {
    let f = integrands::parse("cos:kx=3,ky=2").unwrap();
    let found = best_lattice(64, f.as_ref()).unwrap();
    let h = found.lattice.shortest_dual();
    let length = ((h[0] * h[0] + h[1] * h[1]) as f64).sqrt();
    // The hexagonal bound √(2N/√3) = 8.6 for N = 64; no lattice of 64
    // points exceeds it, and the best integer ones reach 8.06 (|(7, 4)|).
    assert!(
        length >= 8.0,
        "{:?}: shortest dual vector {h:?} (|h| = {length:.2})",
        found.lattice
    );
    assert!(found.variance <= found.rounding_bound, "{found:?}");
}

/// The shortest nonzero k with k·(x_i − x_0) ∈ Z for every point of `set`
/// (its dual lattice's shortest vector, squared length), by brute force
/// over |k|∞ ≤ `reach`: independent of the sampler's reduction.
fn shortest_dual_of_points(set: &varspec::PointSet, reach: i64) -> i64 {
    let p: Vec<&[f64]> = set.points().collect();
    let mut best = i64::MAX;
    for k1 in -reach..=reach {
        for k2 in 0..=reach {
            let len = k1 * k1 + k2 * k2;
            if len == 0 || len >= best {
                continue;
            }
            let on_lines = p.iter().all(|q| {
                let t = k1 as f64 * (q[0] - p[0][0]) + k2 as f64 * (q[1] - p[0][1]);
                (t - t.round()).abs() < 1e-9
            });
            if on_lines {
                best = len;
            }
        }
    }
    best
}

/// The `lattice` sampler: each realization is a group (its differences are
/// its points, shifted), it passes the spectral test at least as well as
/// every rank-1 lattice of its N (every generator tried here by brute force
/// on the dual, {k : k₁ + g·k₂ ≡ 0 mod N}), and `g` gives the Korobov
/// lattice asked for.
#[test]
fn the_lattice_sampler_is_a_shifted_lattice_with_the_best_spectral_test() {
    for n in [233usize, 256, 100] {
        let s = registry::build("lattice", n, Some(2), &[]).unwrap();
        let set = s.sample(&mut set_rng(5, n as u64)).unwrap();
        assert_eq!(set.len(), n);
        // A group under addition mod 1: x_i − x_j runs over the same set for
        // every j.
        let sorted_differences = |j: usize| {
            let p: Vec<&[f64]> = set.points().collect();
            let mut d: Vec<(i64, i64)> = p
                .iter()
                .map(|q| {
                    let w = |t: f64| ((t - t.floor()) * n as f64 * 64.0).round() as i64;
                    (
                        w(q[0] - p[j][0]) % (64 * n as i64),
                        w(q[1] - p[j][1]) % (64 * n as i64),
                    )
                })
                .collect();
            d.sort_unstable();
            d
        };
        let first = sorted_differences(0);
        for j in [1, n / 3, n - 1] {
            assert_eq!(
                sorted_differences(j),
                first,
                "N = {n}: not a lattice at point {j}"
            );
        }
        // Hermite: the dual (determinant N) has a vector of squared length
        // ≤ 2N/√3, so |k|∞ ≤ √(2N/√3) holds it.
        let reach = (2.0 * n as f64 / 3f64.sqrt()).sqrt().ceil() as i64;
        let ours = shortest_dual_of_points(&set, reach);
        let best_rank1 = (1..n as i64)
            .map(|g| {
                let mut best = i64::MAX;
                for k2 in 0..=reach {
                    for k1 in -reach..=reach {
                        let len = k1 * k1 + k2 * k2;
                        if len > 0 && (k1 + g * k2).rem_euclid(n as i64) == 0 {
                            best = best.min(len);
                        }
                    }
                }
                best
            })
            .max()
            .unwrap();
        assert!(
            ours >= best_rank1 && ours <= (2.0 * n as f64 / 3f64.sqrt()) as i64,
            "N = {n}: shortest dual |h|² = {ours}, best rank-1 {best_rank1}"
        );
    }
    // N = 233 = F13 with g = F12 = 144: the Fibonacci lattice, y = 144·x mod 1
    // up to the shift.
    let params = [("g".to_string(), "144".to_string())];
    let s = registry::build("lattice", 233, Some(2), &params).unwrap();
    let set = s.sample(&mut set_rng(1, 0)).unwrap();
    let p: Vec<&[f64]> = set.points().collect();
    for q in &p {
        let t = 233.0 * ((q[1] - p[0][1]) - 144.0 * (q[0] - p[0][0]));
        assert!(
            (t - t.round()).abs() < 1e-6,
            "{q:?} is off the Fibonacci lattice"
        );
    }
    for bad in ["0", "233", "-3", "1.5"] {
        let params = [("g".to_string(), bad.to_string())];
        let Err(err) = registry::build("lattice", 233, Some(2), &params) else {
            panic!("g = {bad} was accepted")
        };
        assert!(err.to_string().contains("1 <= g < N = 233"), "{bad}: {err}");
    }
}
