//! The unit square as a domain (issue: "designs for the integrals renderers
//! and peers actually run"): family distributions against the peer's
//! published scores, the closed half-plane form against its O(N²) pair form
//! and against brute force, gradients against finite differences, and each
//! design claim at reduced size, scored on family members the descent never
//! saw.

use varspec::PointSet;
use varspec::neighbours::closest_pair_ratio;
use varspec::optimize::AdamOptions;
use varspec::registry;
use varspec::rng::{set_rng, uniform};
use varspec::square::design::{SquareTerm, default_options, design, parse_target};
use varspec::square::halfplanes::{
    Projection, directional_loss, directions, halfplane_mse, pair_form,
};
use varspec::square::sampled::{Members, sampled_loss};
use varspec::square::{Family, family_mse};

/// Two-sided z for a per-check false-alarm rate of 1e-4.
const Z: f64 = 3.89;

fn sets(name: &str, n: usize, count: u64, seed: u64) -> Vec<PointSet> {
    let s = registry::build(name, n, Some(2), &[]).unwrap();
    (0..count)
        .map(|r| s.sample(&mut set_rng(seed, r)).unwrap())
        .collect()
}

/// One design for `terms` from each start; set r's descent draws from
/// seed `seed + r`.
fn designed(
    terms: &[SquareTerm],
    starts: Vec<PointSet>,
    seed: u64,
    options: &AdamOptions,
) -> Vec<PointSet> {
    starts
        .into_iter()
        .enumerate()
        .map(|(r, start)| design(terms, start, seed + r as u64, options, &|_, _| {}).points)
        .collect()
}

#[test]
fn families_reproduce_the_peer_s_published_scores() {
    // UTK's integration tests, N = 1024, 16 jittered sets, 1024 integrands
    // per database (issue #9's table): Gaussians 7.3e-8, Heaviside 4.72e-6.
    // Their own sampling error is taken equal to ours (same sample sizes),
    // so the difference must lie within Z·√2 standard errors.
    let jitter = sets("jitter", 1024, 16, 3);
    for (spec, published) in [("gaussians", 7.3e-8), ("halfplanes", 4.72e-6)] {
        let m = family_mse(&jitter, &Family::parse(spec).unwrap(), 1024, 11);
        let tolerance = Z * std::f64::consts::SQRT_2 * m.stderr;
        assert!(
            (m.mse - published).abs() <= tolerance,
            "{spec}: ours {:.3e} ± {:.1e} vs UTK's {published:e} (tolerance {tolerance:.1e})",
            m.mse,
            m.stderr
        );
    }
}

#[test]
fn closed_half_plane_form_equals_the_pair_form_and_brute_force() {
    let set = sets("random", 200, 1, 5).remove(0);
    let mut order = Vec::new();
    for theta in [0.0, 0.3, 1.2, std::f64::consts::FRAC_PI_2, 2.9] {
        let p = Projection::new(theta);
        let fast = directional_loss(&set, &p, 0.0, None, &mut order);
        let reference = pair_form(&set, &p);
        assert!(
            (fast - reference).abs() <= 1e-12 * reference.abs().max(1e-3),
            "θ = {theta}: {fast:e} vs pair form {reference:e}"
        );
    }
    for name in ["jitter", "cmj", "random"] {
        let s = sets(name, 256, 4, 8);
        let closed: f64 = s.iter().map(|x| halfplane_mse(x, 4096)).sum::<f64>() / 4.0;
        let brute = family_mse(&s, &Family::HalfPlanes, 20_000, 21);
        assert!(
            (closed - brute.mse).abs() <= Z * brute.stderr,
            "{name}: closed form {closed:e} vs brute force {:e} ± {:e}",
            brute.mse,
            brute.stderr
        );
    }
}

#[test]
fn gradients_match_finite_differences() {
    let set = sets("jitter", 64, 1, 2).remove(0);
    let n = set.len();
    let bump = |i: usize, h: f64| {
        let mut c = set.coords().to_vec();
        c[i] += h;
        PointSet::new(2, c).unwrap()
    };
    // Half-planes, one direction.
    let p = Projection::new(0.7);
    let mut order = Vec::new();
    let mut g = vec![0.0; 2 * n];
    directional_loss(&set, &p, 1.0, Some(&mut g), &mut order);
    // Gaussians, a fixed sample of members.
    let gaussians = Family::parse("gaussians").unwrap();
    let mut gg = vec![0.0; 2 * n];
    sampled_loss(
        &set,
        &gaussians,
        Members {
            seed: 4,
            first: 0,
            count: 32,
        },
        1.0,
        0.0,
        Some(&mut gg),
    )
    .unwrap();
    let h = 1e-7;
    for i in [0, 7, 33, 2 * n - 1] {
        let fd = (directional_loss(&bump(i, h), &p, 0.0, None, &mut order)
            - directional_loss(&bump(i, -h), &p, 0.0, None, &mut order))
            / (2.0 * h);
        assert!(
            (fd - g[i]).abs() <= 1e-6 * g[i].abs().max(1e-6),
            "half-plane coordinate {i}: {fd} vs {}",
            g[i]
        );
        let loss = |s: &PointSet| {
            sampled_loss(
                s,
                &gaussians,
                Members {
                    seed: 4,
                    first: 0,
                    count: 32,
                },
                0.0,
                0.0,
                None,
            )
            .unwrap()
        };
        let fd = (loss(&bump(i, h)) - loss(&bump(i, -h))) / (2.0 * h);
        assert!(
            (fd - gg[i]).abs() <= 1e-5 * gg[i].abs().max(1e-9),
            "Gaussian coordinate {i}: {fd} vs {}",
            gg[i]
        );
    }
    // The direction grid's offset shifts every direction.
    let d: Vec<f64> = directions(4, 0.5).collect();
    assert!((d[0] - std::f64::consts::PI / 8.0).abs() < 1e-15);
}

/// Scores of `sets` on members of seed 977 (never used by a descent).
fn score(sets: &[PointSet], family: &str) -> (f64, f64) {
    let m = family_mse(sets, &Family::parse(family).unwrap(), 8192, 977);
    (m.mse, m.stderr)
}

/// a/b with its standard error by the delta method (independent estimates).
fn ratio((a, sa): (f64, f64), (b, sb): (f64, f64)) -> (f64, f64) {
    let r = a / b;
    (r, r * ((sa / a).powi(2) + (sb / b).powi(2)).sqrt())
}

#[test]
fn blue_noise_for_the_square_beats_cmj_and_jitter_and_stays_blue() {
    // Reduced size: N = 256, 3 sets. Claims at N = 1024 and 4096 are in
    // results/square.
    let terms = parse_target("halfplanes+gaussians+16*blue").unwrap();
    let designed = designed(&terms, sets("jitter", 256, 3, 40), 500, &default_options());
    let cmj = sets("cmj", 256, 16, 41);
    let jitter = sets("jitter", 256, 16, 42);
    let (r, se) = ratio(score(&designed, "halfplanes"), score(&cmj, "halfplanes"));
    assert!(
        r + Z * se <= 0.8,
        "half-planes: designed / CMJ = {r:.3} ± {se:.3}, not below 0.8 at {Z}σ"
    );
    let (gd, gd_se) = score(&designed, "gaussians");
    let (gj, gj_se) = score(&jitter, "gaussians");
    assert!(
        gd + Z * gd_se <= gj - Z * gj_se,
        "Gaussians: designed {gd:e} ± {gd_se:e} vs jitter {gj:e} ± {gj_se:e}"
    );
    for set in &designed {
        let ratio = closest_pair_ratio(set);
        assert!(
            ratio >= 0.7,
            "closest pair {ratio} of the hexagonal spacing"
        );
    }
}

#[test]
fn gaussian_adapted_design_beats_owen_sobol() {
    let terms = parse_target("gaussians").unwrap();
    let options = AdamOptions {
        iters: 600,
        ..default_options()
    };
    let designed = designed(&terms, sets("sobol", 256, 3, 50), 600, &options);
    let sobol = sets("sobol", 256, 16, 51);
    let (gd, gd_se) = score(&designed, "gaussians");
    let (gs, gs_se) = score(&sobol, "gaussians");
    assert!(
        gd + Z * gd_se <= gs - Z * gs_se,
        "Gaussians: designed {gd:e} ± {gd_se:e} vs Sobol' {gs:e} ± {gs_se:e}"
    );
}

/// Indicator families as targets (their edge gradients): designed for
/// `disks` and for `boxes` from jitter at N = 256, each below CMJ on its
/// own family (held-out members) at Zσ, and below 0.6 of jitter's
/// (measured: 0.47–0.48).
#[test]
fn disk_and_box_designs_beat_cmj_on_their_family() {
    let cmj = sets("cmj", 256, 16, 61);
    let jitter = sets("jitter", 256, 16, 62);
    for family in ["disks", "boxes"] {
        let terms = parse_target(family).unwrap();
        let designed = designed(&terms, sets("jitter", 256, 2, 60), 700, &default_options());
        let (rc, sc) = ratio(score(&designed, family), score(&cmj, family));
        assert!(
            rc + Z * sc < 1.0,
            "{family}: designed / CMJ = {rc:.3} ± {sc:.3}, not below 1 at {Z}σ"
        );
        let (rj, sj) = ratio(score(&designed, family), score(&jitter, family));
        assert!(
            rj + Z * sj < 0.6,
            "{family}: designed / jitter = {rj:.3} ± {sj:.3}, not below 0.6 at {Z}σ"
        );
        eprintln!("{family}: designed / CMJ = {rc:.3} ± {sc:.3}, / jitter = {rj:.3} ± {sj:.3}");
    }
}

/// A user-given list of integrands as a target (their box-filtered
/// gradients): the design fits its members far below CMJ's MSE on them.
#[test]
fn listed_family_design_fits_its_members() {
    let list = std::env::temp_dir().join(format!("varspec-listed-{}.txt", std::process::id()));
    std::fs::write(
        &list,
        "# two indicators and a smooth bump\ndisk:r=0.2,cx=0.3,cy=0.6\nbox:w=0.3,h=0.1,angle=20,cx=0.6,cy=0.4\ngaussian:sx=0.1,sy=0.05,angle=40\n",
    )
    .unwrap();
    let spec = format!("file:{}", list.display());
    let terms = parse_target(&spec).unwrap();
    let designed = designed(&terms, sets("jitter", 256, 2, 80), 800, &default_options());
    let family = Family::parse(&spec).unwrap();
    let ours = family_mse(&designed, &family, 3, 0).mse;
    let cmj = family_mse(&sets("cmj", 256, 16, 81), &family, 3, 0).mse;
    assert!(
        ours < 0.2 * cmj,
        "listed family: designed {ours:e} against CMJ's {cmj:e}"
    );
    // The command says that score is not held out (it printed it beside
    // held-out ones, "scored on 1024 members per family": second trial).
    let out = crate::common::varspec_ok(&[
        "optimize",
        "points",
        "--domain",
        "square",
        "-n",
        "16",
        "--sets",
        "1",
        "--iters",
        "3",
        "--target",
        &spec,
        "-o",
        "/dev/null",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("none held out"), "{err}");
    std::fs::remove_file(&list).unwrap();
}

#[test]
fn targets_and_families_refuse_what_they_cannot_do() {
    let list = std::env::temp_dir().join(format!("varspec-list-{}.txt", std::process::id()));
    std::fs::write(&list, "disk:r=0.2\nbox:w=0.3,h=0.1\n").unwrap();
    assert!(parse_target(&format!("file:{}", list.display())).is_ok());
    assert!(parse_target("disks+boxes").is_ok());
    assert!(parse_target("halfplanes+-1*gaussians").is_err());
    // Weights are relative and bounded: 1e308 turned positions into NaN.
    for weight in ["1e308", "1e-320", "inf", "nan"] {
        let e = parse_target(&format!("{weight}*halfplanes")).unwrap_err();
        assert!(
            e.to_string().contains("is not a number in [1e-6, 1e6]"),
            "{e}"
        );
    }
    assert!(Family::parse("gaussians:vmin=2,vmax=1").is_err());
    assert!(
        Family::parse("gaussians:size=1")
            .unwrap_err()
            .to_string()
            .contains("vmin")
    );
    assert!(
        Family::parse("cubes")
            .unwrap_err()
            .to_string()
            .contains("halfplanes")
    );
    assert!(
        Family::parse("file:/nonexistent")
            .unwrap_err()
            .to_string()
            .contains("/nonexistent")
    );
    // The members of a sample are reproducible and lie in their ranges.
    let f = Family::parse("disks:rmin=0.1,rmax=0.2").unwrap();
    let (a, b) = (f.member(3, 9), f.member(3, 9));
    let mut rng = set_rng(1, 1);
    for _ in 0..100 {
        let x = [uniform(&mut rng), uniform(&mut rng)];
        assert_eq!(a.eval(x), b.eval(x));
    }
    assert!(a.integral() <= std::f64::consts::PI * 0.04 + 1e-15);
}

#[test]
fn command_line_designs_scores_and_labels_the_square() {
    let dir = std::env::temp_dir().join(format!("varspec-square-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bin = env!("CARGO_BIN_EXE_varspec");
    let run = |args: &[&str]| {
        let out = std::process::Command::new(bin).args(args).output().unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        out.stdout
    };
    let (sets, report) = (dir.join("sq.csv"), dir.join("sq.json"));
    run(&[
        "optimize",
        "points",
        "--domain",
        "square",
        "-n",
        "64",
        "--target",
        "halfplanes+gaussians+16*blue",
        "--iters",
        "60",
        "--sets",
        "2",
        "--members",
        "256",
        "-o",
        sets.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "--curve-png",
        dir.join("c.png").to_str().unwrap(),
    ]);
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["domain"], "square");
    // --curve-png is honoured on the square too (it was ignored).
    assert!(
        std::fs::read(dir.join("c.png"))
            .unwrap()
            .starts_with(b"\x89PNG")
    );
    // 60 iterations hold fewer than the 51 scores the stopping rule needs.
    assert_eq!(r["stopped"], serde_json::json!(["cap", "cap"]));
    // Per set what ran (as the torus report), beside the cap.
    assert_eq!(r["iterations"], serde_json::json!([61, 61]));
    assert_eq!(r["max_iterations"], 60);
    let ours = r["comparison"]["optimized"]["halfplanes"]["mse"]
        .as_f64()
        .unwrap();
    let jitter = r["comparison"]["jitter"]["halfplanes"]["mse"]
        .as_f64()
        .unwrap();
    assert!(ours < jitter, "{ours} vs jitter {jitter}");
    let p: serde_json::Value = serde_json::from_slice(&run(&[
        "predict",
        "--family",
        "halfplanes",
        sets.to_str().unwrap(),
        "--members",
        "4000",
        "--json",
    ]))
    .unwrap();
    let (brute, closed) = (
        p["brute_force"]["mse"].as_f64().unwrap(),
        p["closed_form"]["mse"].as_f64().unwrap(),
    );
    let se = p["brute_force"]["stderr"].as_f64().unwrap();
    assert!(
        (brute - closed).abs() <= Z * se,
        "{brute} vs {closed} ± {se}"
    );
    let table = dir.join("t.csv");
    run(&[
        "tables",
        "--sampler",
        "blue-noise:domain=square",
        "--param",
        "iters=30",
        "-n",
        "16",
        "--sets",
        "1",
        "--format",
        "csv",
        "-o",
        table.to_str().unwrap(),
    ]);
    let meta = std::fs::read_to_string(dir.join("t.csv.json")).unwrap();
    assert!(meta.contains("\"optimized_for\": \"square\""), "{meta}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The edge gradient that makes indicator families targets (Reynolds
/// transport: the family average of e·∇f_h, f_h the indicator smoothed over
/// h) against the half-plane family's gradient in closed form (Cramér–von
/// Mises per direction, 4096 directions): the two are computed entirely
/// differently and must agree to within the sampling noise and the O(h)
/// smoothing bias.
#[test]
fn edge_gradient_of_indicator_members_matches_the_closed_form() {
    let set = sets("jitter", 16, 1, 9).remove(0);
    let n = set.len();
    let q = 4096;
    let mut exact = vec![0.0; 2 * n];
    let mut order = Vec::new();
    for theta in directions(q, 0.5) {
        directional_loss(
            &set,
            &Projection::new(theta),
            1.0 / q as f64,
            Some(&mut exact),
            &mut order,
        );
    }
    let mut edge = vec![0.0; 2 * n];
    sampled_loss(
        &set,
        &Family::parse("halfplanes").unwrap(),
        Members {
            seed: 12,
            first: 0,
            count: 400_000,
        },
        1.0,
        0.01,
        Some(&mut edge),
    )
    .unwrap();
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let diff: Vec<f64> = exact.iter().zip(&edge).map(|(a, b)| a - b).collect();
    let rel = norm(&diff) / norm(&exact);
    eprintln!("edge vs closed-form gradient: relative difference {rel:.4}");
    assert!(
        rel < 0.1,
        "relative difference {rel:.3}: {edge:?} vs {exact:?}"
    );
}
