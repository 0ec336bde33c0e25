//! Targets per projection of 4D sets (the seed's design principle): the
//! sheared-projection identity behind a light-field term, the gradient, and
//! the design claim at reduced size.

use varspec::PointSet;
use varspec::integrands;
use varspec::neighbours::closest_pair_ratio;
use varspec::optimize::projections::{ProjectionObjective, parse_projections};
use varspec::optimize::shear::Sheared;
use varspec::optimize::{AdamOptions, Domain, PointObjective, adam};
use varspec::registry;
use varspec::rng::set_rng;
use varspec::samplers::Sampler;
use varspec::variance::{VarianceError, empirical_shifting, spatial_variance};

/// Two-sided z for a per-check false-alarm rate of 1e-4.
const Z: f64 = 3.89;

/// The (x, y)-shifted variance of one fixed 4D set, with its standard error.
fn shifted_variance(f: &dyn integrands::Integrand, set: &PointSet, shifts: usize) -> (f64, f64) {
    let e = empirical_shifting(f, shifts, 3, &[0, 1], |_| -> Result<_, VarianceError> {
        Ok(set.clone())
    })
    .unwrap();
    (e.variance, e.stderr)
}

#[test]
fn a_light_field_term_is_the_torus_variance_of_its_sheared_projection() {
    // Var over (x, y) shifts of the 4D set on g(x + c(u − ½)) equals the
    // exact spatial variance of g on z = x + c·u (an independent predictor).
    let f = integrands::parse("defocus:shape=disk,size=0.34,c=-0.37").unwrap();
    let g = integrands::parse("disk:r=0.17").unwrap();
    let terms = parse_projections("defocus:shape=disk,size=0.34,c=-0.37", 64).unwrap();
    let set = registry::build("umj", 64, Some(4), &[])
        .unwrap()
        .sample(&mut set_rng(8, 0))
        .unwrap();
    let z = terms[0].project(&set);
    let (exact, _) = spatial_variance(&z, g.as_ref()).unwrap();
    let (v, se) = shifted_variance(f.as_ref(), &set, 200_000);
    assert!(
        (v - exact).abs() <= Z * se,
        "shifted 4D variance {v:e} ± {se:e} vs spatial variance of the projection {exact:e}"
    );
}

#[test]
fn the_gradient_matches_finite_differences() {
    let terms = parse_projections(
        "xy:family:disks;0.5*xu:power:3;defocus:shape=box,size=0.3,c=0.6",
        16,
    )
    .unwrap();
    let set = registry::build("random", 16, Some(4), &[])
        .unwrap()
        .sample(&mut set_rng(2, 0))
        .unwrap();
    let objective = ProjectionObjective::new(&terms, &set);
    let mut g = vec![0.0; 64];
    objective.loss_and_gradient(&set, 0, &mut g);
    // A step well above the NUFFT's 1e-6 tolerance, so the difference
    // quotient does not divide the transform's error by a tiny step.
    let h = 1e-4;
    // The NUFFT's error is relative to the whole transform: compare on the
    // scale of the largest gradient component.
    let scale = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for i in [0, 2, 5, 63] {
        let bump = |d: f64| {
            let mut c = set.coords().to_vec();
            c[i] += d;
            PointSet::new(4, c).unwrap()
        };
        let mut scratch = vec![0.0; 64];
        let plus = objective.loss_and_gradient(&bump(h), 0, &mut scratch);
        let minus = objective.loss_and_gradient(&bump(-h), 0, &mut scratch);
        let fd = (plus - minus) / (2.0 * h);
        assert!(
            (fd - g[i]).abs() <= 1e-4 * scale,
            "coordinate {i}: finite difference {fd} vs gradient {}",
            g[i]
        );
    }
}

#[test]
fn a_designed_set_beats_sheared_umj_and_stays_blue() {
    let spec = "defocus:shape=disk,size=0.3,c=0.45";
    let f = integrands::parse(spec).unwrap();
    let terms = parse_projections(&format!("xy:family:disks;uv:family:disks;{spec}"), 64).unwrap();
    let umj = registry::build("umj", 64, Some(4), &[]).unwrap();
    let options = AdamOptions {
        iters: 400,
        rel_tol: 0.0,
        step: 0.05,
        final_step: 0.002,
        score_every: 1,
        floor: 0.0,
    };
    let designed: Vec<PointSet> = (0..4)
        .map(|r| {
            let first = umj.sample(&mut set_rng(3, r)).unwrap();
            let objective = ProjectionObjective::new(&terms, &first);
            adam(first, &objective, &options, Domain::Torus, &|_, _| {}).points
        })
        .collect();
    let mean = |sets: &[PointSet]| {
        let v: Vec<(f64, f64)> = sets
            .iter()
            .map(|s| shifted_variance(f.as_ref(), s, 4000))
            .collect();
        let m = v.iter().map(|x| x.0).sum::<f64>() / v.len() as f64;
        let spread = v.iter().map(|x| (x.0 - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
        (m, (spread / v.len() as f64).sqrt())
    };
    let sheared = Sheared::new(umj.as_ref(), [-0.45, -0.45]).unwrap();
    let reference: Vec<PointSet> = (0..32)
        .map(|r| sheared.sample(&mut set_rng(4, r)).unwrap())
        .collect();
    let ((d, dse), (u, use_)) = (mean(&designed), mean(&reference));
    assert!(
        d + Z * dse <= u - Z * use_,
        "designed {d:e} ± {dse:e} vs sheared umj {u:e} ± {use_:e}"
    );
    for s in &designed {
        for dims in [[0, 1], [2, 3]] {
            let r = closest_pair_ratio(&s.projected(&dims).unwrap());
            assert!(r >= 0.6, "closest pair {r} in projection {dims:?}");
        }
    }
}

#[test]
fn bad_projection_targets_are_refused() {
    assert!(parse_projections("layers:c1=0.5,c2=-0.2", 64).is_err());
    assert!(parse_projections("zz:family:disks", 64).is_err());
    assert!(parse_projections("-1*xy:family:disks", 64).is_err());
    // Beyond 1e6 the weighted loss's squares overflowed: positions of NaN.
    let huge = match parse_projections("1e308*xy:family:disks", 64) {
        Ok(_) => panic!("a weight of 1e308 was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(huge.contains("not a number in [1e-6, 1e6]"), "{huge}");
    assert!(parse_projections("1e6*xy:family:disks;uv:family:disks", 64).is_ok());
    assert!(parse_projections("xy:family:cubes", 64).is_err());
}

/// The report of a 4D projection design counts each set's iterations (as
/// the torus report does) beside the cap; it used to give the cap alone.
#[test]
fn the_projection_report_counts_each_sets_iterations() {
    let dir = crate::common::temp_dir("projection-report");
    let report = dir.join("r.json");
    crate::common::varspec_ok(&[
        "optimize",
        "points",
        "-d",
        "4",
        "-n",
        "16",
        "--sets",
        "2",
        "--iters",
        "7",
        "--target",
        "xy:family:disks;defocus:c=0.4",
        "-o",
        dir.join("d.csv").to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "--curve",
        dir.join("c.csv").to_str().unwrap(),
        "--curve-png",
        dir.join("c.png").to_str().unwrap(),
    ]);
    let r = crate::common::read_json(&report);
    // 7 steps: 8 losses, the start's included.
    assert_eq!(r["iterations"], serde_json::json!([8, 8]), "{r}");
    assert_eq!(r["max_iterations"], 7);
    // The loss curve options are honoured here too (they were ignored by
    // 4D projection designs): the CSV holds set 0's curve of the report.
    let csv = std::fs::read_to_string(dir.join("c.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        1 + r["loss_curve"].as_array().unwrap().len(),
        "{csv}"
    );
    assert!(
        std::fs::read(dir.join("c.png"))
            .unwrap()
            .starts_with(b"\x89PNG")
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
