//! Integrands: spectra and autocovariances checked against independent
//! computations, the spec parser's errors.

use rustfft::num_complex::Complex64;
use varspec::integrands::{self, Integrand, IntegrandError};

fn parse(spec: &str) -> Box<dyn Integrand> {
    integrands::parse(spec).unwrap_or_else(|e| panic!("{spec}: {e}"))
}

/// F(k) by the M×M midpoint rule on eval. For an indicator the error is at
/// most the measure of the cells the boundary crosses, ≤ 2·perimeter/M
/// (each crossed cell mis-weights by at most its area 1/M², and a curve of
/// length L crosses at most 2L·M cells); for smooth periodic integrands the
/// rule is spectrally accurate.
fn quadrature(f: &dyn Integrand, k: [i64; 2], m: usize) -> Complex64 {
    let mut sum = Complex64::new(0.0, 0.0);
    for i in 0..m {
        for j in 0..m {
            let x = [(i as f64 + 0.5) / m as f64, (j as f64 + 0.5) / m as f64];
            let v = f.eval(&x);
            if v != 0.0 {
                sum += varspec::spectrum::phase::exp_neg_2pi_i(&k, &x) * v;
            }
        }
    }
    sum / (m * m) as f64
}

#[test]
fn fourier_coefficients_match_quadrature() {
    let m = 1024;
    let cases: [(&str, f64); 6] = [
        (
            "disk:r=0.3,cx=0.4,cy=0.55",
            2.0 * std::f64::consts::PI * 0.3,
        ),
        ("box:w=0.5,h=0.25,angle=30,cx=0.45", 1.5),
        ("halfplane:angle=17,offset=0.07", 4.0),
        ("halfplane:angle=45,offset=0", 4.0),
        ("gaussian:sx=0.1,sy=0.05,angle=20,cx=0.3", 0.0),
        ("cos:kx=3,ky=-2", 0.0),
    ];
    for (spec, perimeter) in cases {
        let f = parse(spec);
        let tol = if perimeter > 0.0 {
            2.0 * perimeter / m as f64
        } else {
            1e-12
        };
        for k in [[0, 0], [1, 0], [0, 1], [3, -2], [-5, 7], [11, 4]] {
            let exact = f.fourier(&k);
            let numeric = quadrature(f.as_ref(), k, m);
            assert!(
                (exact - numeric).norm() <= tol,
                "{spec} k={k:?}: {exact} vs quadrature {numeric} (tol {tol:e})"
            );
        }
    }
}

#[test]
fn axis_aligned_halfplane_is_a_box() {
    // Two independent transforms: polygon edges vs product of sincs.
    for (angle, offset) in [(0.0, 0.1), (90.0, -0.2), (180.0, 0.05), (270.0, 0.0)] {
        let hp = parse(&format!("halfplane:angle={angle},offset={offset}"));
        let width = 0.5 - offset;
        let (n, c) = match angle as i64 {
            0 => ([1.0, 0.0], [1.0 - width / 2.0, 0.5]),
            90 => ([0.0, 1.0], [0.5, 1.0 - width / 2.0]),
            180 => ([-1.0, 0.0], [width / 2.0, 0.5]),
            _ => ([0.0, -1.0], [0.5, width / 2.0]),
        };
        let (w, h) = if n[0] != 0.0 {
            (width, 1.0)
        } else {
            (1.0, width)
        };
        let rect = parse(&format!("box:w={w},h={h},cx={},cy={}", c[0], c[1]));
        assert!((hp.integral() - rect.integral()).abs() < 1e-15);
        for k in [[1, 0], [0, 1], [2, 3], [-7, 1], [40, -33], [1000, 1]] {
            let (a, b) = (hp.fourier(&k), rect.fourier(&k));
            assert!((a - b).norm() < 1e-13, "angle {angle} k={k:?}: {a} vs {b}");
        }
        for h in [[0.1, 0.2], [0.7, 0.05], [0.5, 0.5], [0.0, 0.3]] {
            let (a, b) = (hp.autocov(&h).unwrap(), rect.autocov(&h).unwrap());
            assert!((a - b).abs() < 1e-14, "angle {angle} h={h:?}: {a} vs {b}");
        }
    }
}

/// Area of {x ∈ [0, 1]²: (x − p)·n ≥ 0}, n = (cos θ, sin θ), p = (½, ½) +
/// offset·n, by the midpoint rule over x of the clipped length in y: the
/// length is piecewise linear in x with at most four kinks, so only the
/// cells holding a kink err, each by O(1/M²).
fn halfplane_area(angle_deg: f64, offset: f64) -> f64 {
    let (s, c) = angle_deg.to_radians().sin_cos();
    let d = offset + 0.5 * (c + s);
    let m = 1_000_000;
    let mut area = 0.0;
    for i in 0..m {
        let x = (i as f64 + 0.5) / m as f64;
        // y·s ≥ d − x·c
        let bound = d - x * c;
        let len = if s.abs() < 1e-15 {
            if bound <= 0.0 { 1.0 } else { 0.0 }
        } else if s > 0.0 {
            1.0 - (bound / s).clamp(0.0, 1.0)
        } else {
            (bound / s).clamp(0.0, 1.0)
        };
        area += len;
    }
    area / m as f64
}

/// ∫ g(x) g(x + m) dx over the plane for the peak-1 Gaussian of standard
/// deviations (sx, sy) rotated by θ, summed over the lattice translations
/// m: the periodized bump's ∫_torus f².
fn periodized_gaussian_square_integral(sx: f64, sy: f64, angle_deg: f64) -> f64 {
    let (s, c) = angle_deg.to_radians().sin_cos();
    let quad = |m: [f64; 2]| {
        let a = c * m[0] + s * m[1];
        let b = -s * m[0] + c * m[1];
        a * a / (sx * sx) + b * b / (sy * sy)
    };
    let mut sum = 0.0;
    for i in -6..=6 {
        for j in -6..=6 {
            sum += (-0.25 * quad([f64::from(i), f64::from(j)])).exp();
        }
    }
    std::f64::consts::PI * sx * sy * sum
}

/// c_f(h) = Σ_(k≠0) P_f(k) cos(2πk·h); truncated to |k|∞ ≤ K the series
/// misses at most the tail mass Var f − Σ_(k∈B\0) P_f(k) (Parseval), a
/// rigorous tolerance with Var f = ∫f² − (∫f)² worked out here by hand.
#[test]
fn autocovariance_matches_its_fourier_series_within_the_tail_mass() {
    use std::f64::consts::PI;
    let kmax = 100i64;
    let indicator = |area: f64| area * (1.0 - area);
    let gaussian = |sx: f64, sy: f64, angle: f64| {
        let mean = 2.0 * PI * sx * sy;
        periodized_gaussian_square_integral(sx, sy, angle) - mean * mean
    };
    for (spec, variance) in [
        ("disk:r=0.3,cx=0.4,cy=0.55", indicator(PI * 0.09)),
        ("disk:r=0.5", indicator(PI * 0.25)),
        ("box:w=0.5,h=0.25,angle=30", indicator(0.125)),
        ("box:w=1,h=0.3", indicator(0.3)),
        (
            "halfplane:angle=17,offset=0.07",
            indicator(halfplane_area(17.0, 0.07)),
        ),
        (
            "gaussian:sx=0.1,sy=0.05,angle=20",
            gaussian(0.1, 0.05, 20.0),
        ),
        ("gaussian:sx=0.3,sy=0.25", gaussian(0.3, 0.25, 0.0)),
        ("cos:kx=3,ky=2", 0.5),
    ] {
        let f = parse(spec);
        let mut powers = Vec::new();
        for kx in -kmax..=kmax {
            for ky in -kmax..=kmax {
                if (kx, ky) != (0, 0) {
                    powers.push(([kx, ky], f.fourier(&[kx, ky]).norm_sqr()));
                }
            }
        }
        let mass: f64 = powers.iter().map(|p| p.1).sum();
        // The box holds part of the variance, never more (to rounding).
        assert!(
            mass <= variance * (1.0 + 1e-9),
            "{spec}: Σ P_f = {mass} above Var f = {variance}"
        );
        let tail = variance - mass;
        assert!(
            (f.variance() - variance).abs() <= 1e-9 * variance,
            "{spec}: variance {} vs {variance} by hand",
            f.variance()
        );
        for h in [
            [0.0, 0.0],
            [0.13, 0.71],
            [0.5, 0.5],
            [0.9, 0.02],
            [0.31, 0.3],
        ] {
            let series: f64 = powers
                .iter()
                .map(|(k, p)| {
                    p * (std::f64::consts::TAU * (k[0] as f64 * h[0] + k[1] as f64 * h[1])).cos()
                })
                .sum();
            let c = f.autocov(&h).unwrap();
            assert!(
                (c - series).abs() <= tail + 1e-12,
                "{spec} h={h:?}: c = {c}, series = {series}, tail {tail:e}"
            );
        }
    }
}

#[test]
fn defocus_energy_lies_on_the_sheared_plane() {
    let f = parse("defocus:shape=box,size=0.3,c=0.6");
    let g = parse("box:w=0.3,h=0.3");
    // On the plane ku = c·kx (c·kx an integer) the sinc is 1: |F| = |G|.
    for (kx, ky) in [(5, 0), (10, -5), (0, 0)] {
        let k = [kx, ky, (0.6 * kx as f64) as i64, (0.6 * ky as f64) as i64];
        assert!((f.fourier(&k).norm() - g.fourier(&[kx, ky]).norm()).abs() < 1e-15);
    }
    // Off the plane by one integer step in ku, sinc(π(ku − c kx)) at a
    // nonzero integer argument vanishes.
    assert!(f.fourier(&[5, 0, 4, 0]).norm() < 1e-15);
    assert_eq!(f.autocov(&[0.1, 0.2, 0.3, 0.4]), None);
    assert!((f.variance() - g.variance()).abs() < 1e-15);
    // Evaluation follows the shear: x + c(u − ½).
    assert_eq!(f.eval(&[0.5, 0.5, 0.5, 0.5]), 1.0);
    assert_eq!(f.eval(&[0.5 - 0.6 * 0.4, 0.5, 0.9, 0.5]), 1.0);
    assert_eq!(f.eval(&[0.5, 0.5, 0.9, 0.5]), 0.0);
}

#[test]
fn bad_specs_are_clear_errors() {
    let err = |s: &str| {
        integrands::parse(s)
            .err()
            .unwrap_or_else(|| panic!("{s} should fail"))
    };
    assert!(matches!(
        err("sphere:r=0.1"),
        IntegrandError::Unknown { .. }
    ));
    assert!(matches!(
        err("disk:radius=0.1"),
        IntegrandError::UnknownKey { .. }
    ));
    assert!(matches!(err("disk:r"), IntegrandError::Syntax { .. }));
    for (spec, phrase) in [
        (
            "disk:r=abc",
            "r=abc is invalid: expected a number (a radius in (0, 0.5])",
        ),
        ("disk:r=0.6", "(0, 0.5]"),
        ("disk:r=-0.1", "(0, 0.5]"),
        ("disk:r=NaN", "(0, 0.5]"),
        ("box:w=-0.5", "(0, 1]"),
        ("box:w=0.9,h=0.9,angle=45", "periodic images"),
        ("gaussian:sx=0", "(0, 0.5]"),
        ("cos:kx=1.5", "integer"),
        // The bound is named (it read "an integer" for a 13-digit integer).
        ("cos:kx=2000000000000", "an integer in [-2^40, 2^40]"),
        ("cos:ky=1e3", "without a decimal point or exponent"),
        ("defocus:shape=star", "box, disk or gaussian"),
        ("halfplane:offset=inf", "[-1, 1]"),
        ("layers:c1=0.3,c2=0.26", "at least 0.05 from c1"),
    ] {
        let e = err(spec).to_string();
        assert!(
            e.contains(phrase),
            "{spec}: {e:?} should mention {phrase:?}"
        );
    }
    assert_eq!(
        parse("gaussian:sx=0.2").spec(),
        "gaussian:sx=0.2,sy=0.2,angle=0,cx=0.5,cy=0.5"
    );
    // Exactly 0.05 apart as written (0.0499…9 in binary) is allowed.
    for spec in ["layers:c1=0.3,c2=0.25", "layers:c1=0.5,c2=0.45"] {
        assert!(integrands::parse(spec).is_ok(), "{spec} refused");
    }
}

#[test]
fn integrand_constructors_refuse_what_their_closed_forms_cannot_hold() {
    use varspec::integrands::{Cosine, DefocusShape, Gaussian, HalfPlane, Layers};
    // A negative or NaN deviation gave a negative variance or NaN.
    assert!(Gaussian::new(-0.1, 0.1, 0.0, [0.5, 0.5]).is_err());
    assert!(Gaussian::new(f64::NAN, 0.1, 0.0, [0.5, 0.5]).is_err());
    assert!(Gaussian::new(0.1, 0.6, 0.0, [0.5, 0.5]).is_err());
    assert!(Gaussian::new(0.1, 0.1, 0.0, [f64::INFINITY, 0.5]).is_err());
    assert!(Gaussian::new(0.1, 0.05, 30.0, [0.5, 0.5]).is_ok());
    assert!(HalfPlane::new(f64::NAN, 0.0).is_err());
    assert!(HalfPlane::new(30.0, 1.5).is_err());
    assert!(HalfPlane::new(30.0, -0.2).is_ok());
    // |i64::MIN| wrapped to a negative number and passed the 2^40 check.
    assert!(Cosine::new([i64::MIN, 0]).is_err());
    assert!(Cosine::new([3, 1 << 41]).is_err());
    assert!(Cosine::new([-(1 << 40), 7]).is_ok());
    // A mix outside [0, 1] gave a variance of 5.15 (not a mixture).
    assert!(Layers::new(DefocusShape::Disk, 0.3, 0.5, -0.2, 7.0).is_err());
    assert!(Layers::new(DefocusShape::Disk, 0.3, 0.5, -0.2, 0.5).is_ok());
}

/// Axis-aligned boxes of area near 1 (a band of height 1 − 1e-8, a square
/// of side 1 − 1e-8) and two ordinary ones, one at 90°: the shift variance
/// of four points against exact rationals for the boxes as represented in
/// doubles (every periodic overlap in Python's fractions, outside the
/// project). The near-1 boxes read 4.4e-9 and 3.6e-8 relative off before
/// (overlaps near 1 less A² near 1).
#[test]
fn boxes_of_area_near_one_keep_their_variance_digits() {
    four_point_variances_match(
        &[
            ("box:w=1,h=0.99999999", 2.4999999125618973e-9),
            ("box:w=0.99999999,h=0.99999999", 4.9999997501237975e-9),
            ("box:w=1,h=0.3,angle=90", 0.010000000000000005),
            ("box:w=0.3,h=0.2", 0.0114),
        ],
        1e-13,
    );
}

/// The shift variance of the four points (0.1, 0.2), (0.6, 0.3),
/// (0.35, 0.85), (0.9, 0.7) on each integrand, within `relative` of its
/// exact value.
fn four_point_variances_match(cases: &[(&str, f64)], relative: f64) {
    let coords = vec![0.1, 0.2, 0.6, 0.3, 0.35, 0.85, 0.9, 0.7];
    let set = varspec::points::PointSet::new(2, coords).unwrap();
    for &(spec, exact) in cases {
        let (v, _) = varspec::variance::spatial_variance(&set, &*parse(spec)).unwrap();
        assert!(
            (v - exact).abs() <= relative * exact,
            "{spec}: {v:e} against {exact:e} ({:.1e} relative)",
            (v - exact).abs() / exact
        );
    }
}

/// A half-plane covering all but a sliver of the square (area 1 − 1.14e-8)
/// and its complement: the shift variance of four points, against the
/// exact rational value for the integrand as represented in doubles (its
/// f64 normal and level; the clipped polygon and every periodic overlap
/// P ∩ (P + h + m) in Python's fractions, outside the project). Both read
/// 2.85055532833e-9 before, 2.9e-9 relative off (the sliver's area was 1
/// minus the rest of its rectangle), and the large side 1.4e-8 off
/// (overlaps near 1 minus I² near 1).
#[test]
fn a_sliver_and_its_complement_keep_their_variance_digits() {
    // The level's own rounding (about 2e-16 of a distance of 1.1e-4 from
    // the corner) moves the exact value by about 2e-12.
    four_point_variances_match(
        &[
            ("halfplane:angle=135,offset=-0.707", 2.8505553201182595e-9),
            ("halfplane:angle=45,offset=0.707", 2.850555320124187e-9),
            ("halfplane:angle=17,offset=0.07", 0.019292486633437588),
        ],
        1e-11,
    );
    // The sliver's integral, exact for its f64 normal and level.
    let sliver = parse("halfplane:angle=45,offset=0.707");
    let exact = 1.1402221800539396e-8;
    assert!(
        (sliver.integral() - exact).abs() <= 1e-11 * exact,
        "{:e}",
        sliver.integral()
    );
}
