//! The scene renderer: pixel integrands against closed forms, the light
//! field's shear, determinism, and scene files refused with clear errors.

use varspec::registry;
use varspec::scene::Scene;
use varspec::scene::analysis::{PixelKind, analyse_pixel};

/// A fronto-parallel plane with stripes across x at depth `depth`, lit by
/// ambient light only: radiance = albedo.
fn plane_scene(depth: f64, focus: f64, aperture: f64, period: f64) -> Scene {
    let json = format!(
        r#"{{
  "camera": {{"resolution": [64, 64], "fov_degrees": 40, "position": [0, 0, 0],
              "look_at": [0, 0, -1], "focal_distance": {focus}, "aperture": {aperture}}},
  "integrand": "lens",
  "ambient": 1.0,
  "objects": [{{"shape": "quad", "scale": [50, 50, 1], "translate": [0.013, 0, -{depth}],
                "material": {{"texture": "stripes", "period": {period}, "low": 0.0, "high": 1.0}}}}]
}}"#
    );
    Scene::from_text(&json, "plane").unwrap()
}

#[test]
fn the_light_field_of_a_plane_is_constant_along_its_shear() {
    // Depth 6 behind a focus at 3: c = (F − d)/d = −0.5.
    let scene = plane_scene(6.0, 3.0, 0.05, 0.3);
    let a = analyse_pixel(&scene, 20, 30);
    assert_eq!(a.kind, PixelKind::Single);
    assert!((a.depth - 6.0).abs() < 1e-4, "depth {}", a.depth);
    let kappa = a.kappa;
    // Pixel size on the plane in focus: 2·3·tan(20°)/64; 2A/s·c.
    let s = 2.0 * 3.0 * 20f64.to_radians().tan() / 64.0;
    // The depth comes from an f32 hit distance: agree to 1e-5.
    assert!(
        (kappa / (-0.5 * 0.1 / s) - 1.0).abs() < 1e-5,
        "kappa {kappa}"
    );
    // f(x, y, u, v) = f(x − κδ, y, u + δ, v): constant along x + κu.
    let mut checked = 0;
    for i in 0..200 {
        let x = 0.005 * i as f64;
        let (u, v, y, delta) = (0.2, 0.6, 0.4, 0.3);
        let here = scene.radiance(20, 30, [x, y, u, v]);
        let along = scene.radiance(20, 30, [x - kappa * delta, y, u + delta, v]);
        let across = scene.radiance(20, 30, [x + kappa * delta, y, u + delta, v]);
        assert_eq!(here, along, "x = {x}: not constant along x + κu");
        checked += usize::from(here != across);
    }
    assert!(
        checked > 0,
        "the stripes must change across the shear somewhere"
    );
}

#[test]
fn a_plane_in_focus_renders_without_blur() {
    let scene = plane_scene(3.0, 3.0, 0.2, 0.3);
    for i in 0..50 {
        let x = 0.02 * i as f64;
        let centre = scene.radiance(10, 12, [x, 0.5, 0.5, 0.5]);
        for (u, v) in [(0.0, 0.0), (0.99, 0.3), (0.4, 0.95)] {
            assert_eq!(scene.radiance(10, 12, [x, 0.5, u, v]), centre);
        }
    }
}

/// The fraction of (x, u) ∈ [0, 1)² with c0 + cx·x + cu·u < e, cx > 0:
/// ∫₀¹ clamp((e − c0 − cu·u)/cx, 0, 1) du, integrated exactly by splitting
/// at the clamp's kinks (the integrand is linear between them).
fn fraction_below(c0: f64, cx: f64, cu: f64, e: f64) -> f64 {
    let h = |u: f64| ((e - c0 - cu * u) / cx).clamp(0.0, 1.0);
    let mut knots = vec![0.0, 1.0];
    if cu != 0.0 {
        for level in [0.0, 1.0] {
            let u = (e - c0 - cx * level) / cu;
            if u > 0.0 && u < 1.0 {
                knots.push(u);
            }
        }
    }
    knots.sort_by(f64::total_cmp);
    knots
        .windows(2)
        .map(|w| 0.5 * (h(w[0]) + h(w[1])) * (w[1] - w[0]))
        .sum()
}

/// A defocused occluder (a constant quad at depth 2, focus 3) over a
/// striped plane at depth 6, 8 × 8 pixels: its edge crosses column 4, the
/// other columns see one depth.
const OCCLUDER_SCENE: &str = r#"{
  "camera": {"resolution": [8, 8], "fov_degrees": 30, "position": [0, 0, 0],
             "look_at": [0, 0, -1], "focal_distance": 3, "aperture": 0.3},
  "integrand": "lens",
  "ambient": 1.0,
  "objects": [
    {"shape": "quad", "scale": [200, 200, 1], "translate": [0, 0, -6],
     "material": {"texture": "stripes", "period": 0.7, "low": 0.1, "high": 0.9}},
    {"shape": "quad", "scale": [10, 10, 1], "translate": [-9.95, 0, -2],
     "material": {"texture": "constant", "albedo": 0.5}}
  ]
}"#;

/// A plane at depth `depth` whose albedo is 1 left of world x = `edge` and
/// 0 right of it (stripes of period 100: one boundary in view), focus at
/// `focus`, lens half-side `aperture`, 8 × 8 pixels.
fn edge_scene(depth: f64, focus: f64, aperture: f64, edge: f64) -> Scene {
    // Stripe cells are centred on the frame origin: the first boundary is
    // at frame x = period/4 = 25.
    let json = format!(
        r#"{{
  "camera": {{"resolution": [8, 8], "fov_degrees": 30, "position": [0, 0, 0],
              "look_at": [0, 0, -1], "focal_distance": {focus}, "aperture": {aperture}}},
  "integrand": "lens",
  "ambient": 1.0,
  "objects": [{{"shape": "quad", "scale": [200, 200, 1], "translate": [{}, 0, -{depth}],
                "material": {{"texture": "stripes", "period": 100, "low": 0.0, "high": 1.0}}}}]
}}"#,
        edge - 25.0
    );
    Scene::from_text(&json, "edge").unwrap()
}

/// The closed-form value of pixel (px, ·) of [`edge_scene`]: a thin lens
/// at the origin looking down −z maps pixel point x and lens point u to
/// world X = L(1 − d/F) + P·d/F, P = (px + x − W/2)·s on the plane in
/// focus and L = A(2u − 1); the pixel is the fraction with X < edge.
fn edge_pixel(depth: f64, focus: f64, aperture: f64, edge: f64, px: usize) -> f64 {
    let s = 2.0 * focus * 15f64.to_radians().tan() / 8.0;
    let r = depth / focus;
    let c0 = (px as f64 - 4.0) * s * r - aperture * (1.0 - r);
    let cx = s * r;
    let cu = 2.0 * aperture * (1.0 - r);
    fraction_below(c0, cx, cu, edge)
}

/// The variance maps, which the tests below take as standard errors, are
/// the renders' sample mean and variance: recomputed here from the renders
/// themselves by the two-pass formula.
#[test]
fn the_variance_maps_are_the_renders_sample_mean_and_variance() {
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::render::{render, render_variance};
    let scene = edge_scene(6.0, 3.0, 0.3, 0.05);
    let sampler = registry::build("umj", 16, Some(4), &[]).unwrap();
    let shears = vec![SampleShear::NONE; 64];
    let renders = 9;
    let maps = render_variance(&scene, sampler.as_ref(), &shears, 21, renders, &|| {}).unwrap();
    let images: Vec<Vec<f64>> = (0..renders as u64)
        .map(|r| {
            render(&scene, sampler.as_ref(), &shears, 21, r)
                .unwrap()
                .pixels
        })
        .collect();
    let mut varying = 0;
    for i in 0..64 {
        let values: Vec<f64> = images.iter().map(|img| img[i]).collect();
        let mean = values.iter().sum::<f64>() / renders as f64;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (renders - 1) as f64;
        varying += usize::from(var > 0.0);
        assert!(
            (maps.mean.pixels[i] - mean).abs() <= 1e-14
                && (maps.variance.pixels[i] - var).abs() <= 1e-12 * var.max(1e-12),
            "pixel {i}: maps ({}, {}) vs renders ({mean}, {var})",
            maps.mean.pixels[i],
            maps.variance.pixels[i]
        );
    }
    assert!(
        varying >= 8,
        "only {varying} pixels vary: the edge must be in view"
    );
}

#[test]
fn a_defocused_edge_matches_its_closed_form_for_every_sampler_and_shear() {
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::render::render_variance;
    // Behind the focus (c < 0) and in front of it (c > 0); the edge in
    // view near pixel column 4.
    let cases = [(6.0, 3.0, 0.3, 0.05), (2.0, 3.0, 0.2, -0.02)];
    let renders = 64;
    let mut tests = 0;
    let mut worst: f64 = 0.0;
    for (depth, focus, aperture, edge) in cases {
        let scene = edge_scene(depth, focus, aperture, edge);
        let kappa = analyse_pixel(&scene, 4, 4).kappa;
        assert!(kappa.abs() > 0.3, "the case must be defocused: κ = {kappa}");
        for name in ["random", "umj", "padded:xy=jitter,uv=random", "sobol"] {
            let sampler = registry::build(name, 64, Some(4), &[]).unwrap();
            for shear in [
                SampleShear::NONE,
                SampleShear::Position([0.7, -0.3]),
                SampleShear::Warp(kappa),
                SampleShear::Warp(2.5),
            ] {
                let shears = vec![shear; 64];
                let maps = render_variance(&scene, sampler.as_ref(), &shears, 11, renders, &|| {})
                    .unwrap();
                for py in 0..8 {
                    for px in 0..8 {
                        let i = py * 8 + px;
                        let truth = edge_pixel(depth, focus, aperture, edge, px);
                        let se = (maps.variance.pixels[i] / renders as f64).sqrt();
                        let z = (maps.mean.pixels[i] - truth).abs() / (se + 1e-12);
                        // 6 standard errors: P(|t₆₃| > 6) ≈ 1e-7 per pixel,
                        // < 1e-3 family-wise over the 4096 checks.
                        assert!(
                            (maps.mean.pixels[i] - truth).abs() <= 6.0 * se + 1e-6,
                            "{name}, {shear:?}, depth {depth}, pixel ({px}, {py}): mean {} vs \
                             closed form {truth}, {z:.1} standard errors (se {se:.2e})",
                            maps.mean.pixels[i]
                        );
                        if se > 0.0 {
                            worst = worst.max(z);
                        }
                        tests += 1;
                    }
                }
            }
        }
    }
    assert_eq!(tests, 2 * 4 * 4 * 64);
    // The test has power: some pixels are estimated, not all exact.
    assert!(
        worst > 0.0,
        "every pixel was exact: the edge is not in view"
    );
}

#[test]
fn the_warp_that_follows_the_light_field_cuts_the_variance_of_a_defocused_edge() {
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::render::render_variance;
    let sampler = registry::build("umj", 64, Some(4), &[]).unwrap();
    let renders = 64;
    for (depth, focus, aperture, edge) in [(6.0, 3.0, 0.3, 0.05), (2.0, 3.0, 0.2, -0.02)] {
        let scene = edge_scene(depth, focus, aperture, edge);
        let kappa = analyse_pixel(&scene, 4, 4).kappa;
        let total = |shear| {
            let maps = render_variance(
                &scene,
                sampler.as_ref(),
                &vec![shear; 64],
                5,
                renders,
                &|| {},
            )
            .unwrap();
            maps.variance.pixels.iter().sum::<f64>()
        };
        let (none, warp, wrong) = (
            total(SampleShear::NONE),
            total(SampleShear::Warp(kappa)),
            total(SampleShear::Warp(-kappa)),
        );
        // The edge is a function of x + κu only: the warp stratifies that
        // argument with umj's 64 lens strata, the unsheared set does not.
        // Each total sums 8 rows of independent pixels, 63 degrees of
        // freedom each: a 4× margin is far outside their sampling error
        // (relative standard error of a sum of ≥ 8 variances ≤ 0.07).
        assert!(
            warp < 0.25 * none,
            "κ = {kappa}: warp {warp:.3e} vs none {none:.3e}"
        );
        assert!(
            warp < 0.25 * wrong,
            "κ = {kappa}: warp {warp:.3e} vs the opposite slope {wrong:.3e}"
        );
    }
}

#[test]
fn a_disk_light_sampled_on_its_area_or_its_bounding_square_gives_one_image() {
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::render::render_variance;
    let disk = varspec::scene::BUILTIN_SCENES[2]
        .2
        .replace("[256, 256]", "[12, 12]");
    let square = disk.replace(
        "\"radiance\": 15.0",
        "\"radiance\": 15.0, \"sampling\": \"bounding_square\"",
    );
    assert_ne!(disk, square);
    let sampler = registry::build("random", 64, Some(4), &[]).unwrap();
    let renders = 48;
    let maps = |text: &str| {
        let scene = Scene::from_text(text, "disk").unwrap();
        render_variance(
            &scene,
            sampler.as_ref(),
            &vec![SampleShear::NONE; 144],
            3,
            renders,
            &|| {},
        )
        .unwrap()
    };
    let (a, b) = (maps(&disk), maps(&square));
    let mut differ = 0;
    for i in 0..144 {
        let se = ((a.variance.pixels[i] + b.variance.pixels[i]) / renders as f64).sqrt();
        // 6 standard errors of the difference: < 1e-6 family-wise over 144.
        assert!(
            (a.mean.pixels[i] - b.mean.pixels[i]).abs() <= 6.0 * se + 1e-12,
            "pixel {i}: area {} vs bounding square {} (se {se:.2e})",
            a.mean.pixels[i],
            b.mean.pixels[i]
        );
        differ += usize::from(a.variance.pixels[i] != b.variance.pixels[i]);
    }
    assert!(differ > 0, "the two samplings must be different estimators");
}

/// A scene's world unit does not change its image: a disk light over a
/// plane, its lengths in metres and in millimetres, gives the same pixels
/// up to rounding (shadow rays leave the surface by an offset relative to
/// the f32 coordinates the BVH intersects; a fixed 1e-4 let them hit the
/// plane they leave in millimetres, 6% darker on average).
#[test]
fn a_scene_in_millimetres_renders_as_in_metres() {
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::render::render;
    let text = |k: f64| {
        format!(
            r#"{{
  "camera": {{"resolution": [12, 12], "fov_degrees": 60, "position": [0, 0, 0],
              "look_at": [0, 0, -1], "focal_distance": {f}, "aperture": 0}},
  "integrand": "light",
  "ambient": 0.0,
  "objects": [{{"shape": "quad", "scale": [{s}, {s}, 1], "translate": [0, 0, -{d}],
                "material": {{"texture": "constant", "albedo": 0.5}}}}],
  "lights": [{{"shape": "disk", "centre": [{lx}, {ly}, -{lz}], "normal": [0, 0, -1],
               "size": {size}, "radiance": 10.0}}]
}}"#,
            f = 4.0 * k,
            s = 20.0 * k,
            d = 5.0 * k,
            lx = 0.3 * k,
            ly = 0.2 * k,
            lz = 3.0 * k,
            size = k
        )
    };
    let sampler = registry::build("random", 64, Some(4), &[]).unwrap();
    let image = |k: f64| {
        let scene = Scene::from_text(&text(k), "disk").unwrap();
        render(
            &scene,
            sampler.as_ref(),
            &vec![SampleShear::NONE; 144],
            5,
            0,
        )
        .unwrap()
    };
    let (metres, millimetres) = (image(1.0), image(1000.0));
    let lit = metres.pixels.iter().filter(|&&v| v > 0.0).count();
    assert!(lit > 100, "only {lit} of 144 pixels lit");
    for (i, (a, b)) in metres.pixels.iter().zip(&millimetres.pixels).enumerate() {
        // Rounding of the scaled coordinates (f32 in the BVH): far below
        // the 4-9% the fixed offset lost.
        assert!(
            (a - b).abs() <= 1e-5 * a.abs(),
            "pixel {i}: {a} in metres, {b} in millimetres"
        );
    }
}

/// A scene placed far from the world origin renders as at it: the BVH's
/// f32 coordinates are relative to the camera (in world coordinates f32
/// spacing at 1e8 is 8: the dof scene's sphere of radius 0.3 vanished and
/// its box was distorted). The dof scene (textures, defocus) and the disk
/// light over a plane (shadow-ray offsets) moved by 1e8 along every axis.
#[test]
fn a_scene_far_from_the_origin_renders_as_at_it() {
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::render::render;
    let moved = |text: &str, by: f64| {
        let mut file: serde_json::Value = serde_json::from_str(text).unwrap();
        let shift = |v: &mut serde_json::Value| {
            for c in v.as_array_mut().unwrap() {
                *c = serde_json::json!(c.as_f64().unwrap() + by);
            }
        };
        file["camera"]["resolution"] = serde_json::json!([16, 16]);
        shift(&mut file["camera"]["position"]);
        shift(&mut file["camera"]["look_at"]);
        for o in file["objects"].as_array_mut().unwrap() {
            shift(&mut o["translate"]);
        }
        if let Some(lights) = file.get_mut("lights").and_then(|l| l.as_array_mut()) {
            for l in lights {
                shift(&mut l["centre"]);
            }
        }
        file.to_string()
    };
    let disk_light = r#"{
  "camera": {"resolution": [12, 12], "fov_degrees": 60, "position": [0, 0, 0],
             "look_at": [0, 0, -1], "focal_distance": 4, "aperture": 0},
  "integrand": "light", "ambient": 0.0,
  "objects": [{"shape": "quad", "scale": [20, 20, 1], "translate": [0, 0, -5],
               "material": {"texture": "constant", "albedo": 0.5}}],
  "lights": [{"shape": "disk", "centre": [0.3, 0.2, -3], "normal": [0, 0, -1],
              "size": 1, "radiance": 10.0}]
}"#;
    let dof =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/dof.json")).unwrap();
    let sampler = registry::build("umj", 16, Some(4), &[]).unwrap();
    for (name, text) in [("dof", dof.as_str()), ("disk light", disk_light)] {
        let image = |by: f64| {
            let scene = Scene::from_text(&moved(text, by), name).unwrap();
            render(
                &scene,
                sampler.as_ref(),
                &vec![SampleShear::NONE; 256],
                3,
                0,
            )
            .unwrap()
        };
        let (here, far) = (image(0.0), image(1e8));
        let lit = here.pixels.iter().filter(|&&v| v > 0.0).count();
        assert!(lit > 200, "{name}: only {lit} of 256 pixels lit");
        for (i, (a, b)) in here.pixels.iter().zip(&far.pixels).enumerate() {
            // The placements' f64 rounding at 1e8 (1.5e-8) only.
            assert!(
                (a - b).abs() <= 1e-6 * a.abs().max(1e-3),
                "{name} pixel {i}: {a} at the origin, {b} at 1e8"
            );
        }
    }
}

/// A distant light (a sun 1e5 away) keeps the shadow of an occluder half
/// a unit above the floor: the shadow ray's offset follows the rounding at
/// its start, not the light's distance (a first version scaled it by the
/// light's coordinates too, 0.76 here, and the umbra vanished).
#[test]
fn a_distant_light_keeps_nearby_shadows() {
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::render::render;
    let text = r#"{"camera": {"resolution": [16, 16], "fov_degrees": 30, "position": [0, 0, 0],
      "look_at": [0, 0, -1], "focal_distance": 4, "aperture": 0},
     "integrand": "light", "ambient": 0.0,
     "objects": [
      {"shape": "quad", "scale": [3, 3, 1], "translate": [0, 0, -5], "material": {"texture": "constant", "albedo": 0.5}},
      {"shape": "quad", "scale": [0.5, 0.5, 1], "translate": [0, 0, -4.5], "material": {"texture": "constant", "albedo": 0.5}}
     ],
     "lights": [{"shape": "square", "centre": [1e5, 0, 1e5], "normal": [-1, 0, -1], "size": 1000, "radiance": 1e4}]}"#;
    let scene = Scene::from_text(text, "sun").unwrap();
    let sampler = registry::build("random", 16, Some(4), &[]).unwrap();
    let image = render(&scene, sampler.as_ref(), &[SampleShear::NONE; 256], 1, 0).unwrap();
    // Row 7: lit floor, the umbra the occluder casts on it, the occluder.
    let row = &image.pixels[7 * 16..8 * 16];
    assert!(row[0] > 0.01, "{row:?}");
    assert!(row[2] == 0.0 && row[3] == 0.0, "the umbra is lit: {row:?}");
}

/// Directions are directions at any length: an `up` of 1e-200 or 1e200 and
/// a light normal of 1e-10 render exactly as unit ones (they underflowed
/// to a blank image, overflowed to a degenerate one, or were refused).
#[test]
fn tiny_and_huge_directions_render_as_unit_ones() {
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::render::render;
    let text = |up: &str, normal: &str| {
        format!(
            r#"{{
  "camera": {{"resolution": [8, 8], "fov_degrees": 40, "position": [0, 0, 0],
              "look_at": [0, 0, -1], "up": {up}, "focal_distance": 4, "aperture": 0}},
  "integrand": "light",
  "ambient": 0.5,
  "objects": [{{"shape": "quad", "scale": [10, 10, 1], "translate": [0, 0, -4],
                "material": {{"texture": "checker", "period": 0.7, "low": 0.2, "high": 0.9}}}}],
  "lights": [{{"shape": "square", "centre": [0.2, 0, -2], "normal": {normal}, "size": 1, "radiance": 1}}]
}}"#
        )
    };
    let sampler = registry::build("random", 16, Some(4), &[]).unwrap();
    let image = |up: &str, normal: &str| {
        let scene = Scene::from_text(&text(up, normal), "directions").unwrap();
        render(&scene, sampler.as_ref(), &vec![SampleShear::NONE; 64], 2, 0)
            .unwrap()
            .pixels
    };
    let unit = image("[0, 1, 0]", "[0, 0, -1]");
    assert!(unit.iter().all(|v| v.is_finite() && *v > 0.0), "{unit:?}");
    for (up, normal) in [
        ("[0, 1e-200, 0]", "[0, 0, -1]"),
        ("[0, 1e200, 0]", "[0, 0, -1e200]"),
        ("[0, 1, 0]", "[0, 0, -1e-10]"),
    ] {
        assert_eq!(image(up, normal), unit, "up {up}, normal {normal}");
    }
}

/// A striped 3 × 2 rectangle at depth 6, its edges inside the view
/// (misses see the ambient 1; the stripes are 0.2 and 0.8), its quad given by `shape` (e.g.
/// `"shape": "quad"` or an OBJ file).
fn plane_text(shape: &str) -> String {
    format!(
        r#"{{
  "camera": {{"resolution": [16, 16], "fov_degrees": 40, "position": [0, 0, 0],
              "look_at": [0, 0, -1], "focal_distance": 3, "aperture": 0.1}},
  "integrand": "lens",
  "ambient": 1.0,
  "objects": [{{{shape}, "scale": [1.5, 1, 1], "translate": [0.013, 0, -6],
                "material": {{"texture": "stripes", "period": 0.3, "low": 0.2, "high": 0.8}}}}]
}}"#
    )
}

/// A shadow segment covers its whole length, from its origin on: an
/// occluder 1.5e-4 in front of a shadow ray's offset origin blocks it (the
/// segment once skipped the offset again at each end, so contact shadows
/// within 2e-4 went missing), one just beyond its end does not. Both BVHs.
#[test]
fn shadow_segments_start_at_their_origin_and_end_at_their_length() {
    use varspec::scene::geometry::BvhKind;
    for kind in [BvhKind::Cwbvh, BvhKind::Bvh2] {
        let scene =
            Scene::from_text_with(&plane_text(r#""shape": "quad""#), "plane", kind).unwrap();
        // The quad lies in z = −6; the ray leaves z = −6 + 1.5e-4 towards it.
        let origin = [0.2, 0.1, -6.0 + 1.5e-4];
        let down = [0.0, 0.0, -1.0];
        let g = scene.geometry();
        assert!(
            !g.unoccluded(origin, down, 3e-4),
            "{kind:?}: the quad at 1.5e-4 missed"
        );
        assert!(
            g.unoccluded(origin, down, 1e-4),
            "{kind:?}: hit beyond the segment's end"
        );
        assert!(
            g.unoccluded(origin, [0.0, 0.0, 1.0], 10.0),
            "{kind:?}: hit behind the origin"
        );
    }
}

/// An OBJ file holding the built-in quad (one polygon face, triangulated as
/// a fan into the built-in quad's two triangles), read relative to the
/// scene file's folder, renders exactly the built-in quad's pixels.
#[test]
fn an_obj_mesh_renders_as_the_built_in_shape_it_holds() {
    let dir = std::env::temp_dir().join(format!("varspec-obj-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    std::fs::write(
        dir.join("meshes/quad.obj"),
        "# the built-in quad\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n",
    )
    .unwrap();
    let scene_path = dir.join("plane.json");
    std::fs::write(
        &scene_path,
        plane_text(r#""shape": "obj", "file": "meshes/quad.obj""#),
    )
    .unwrap();
    let from_obj = Scene::load(scene_path.to_str().unwrap()).unwrap();
    let built_in = Scene::from_text(&plane_text(r#""shape": "quad""#), "quad").unwrap();
    assert_eq!(from_obj.geometry().triangle_count(), 2);
    let mut lit = 0;
    for i in 0..400 {
        let p = [
            0.37 * i as f64 % 1.0,
            0.61 * i as f64 % 1.0,
            0.13 * i as f64 % 1.0,
            0.29 * i as f64 % 1.0,
        ];
        let (px, py) = (i % 16, (i / 16) % 16);
        let value = from_obj.radiance(px, py, p);
        assert_eq!(
            value,
            built_in.radiance(px, py, p),
            "pixel ({px}, {py}) at {p:?}"
        );
        lit += usize::from(value != 1.0);
    }
    assert!(
        lit > 40 && lit < 360,
        "the rectangle and the background must both show ({lit} of 400 on the rectangle)"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Bad `obj` objects and bad OBJ files are refused with an error that names
/// the field (and, for the file, what is wrong with it).
#[test]
fn bad_obj_meshes_are_refused_naming_the_field() {
    let dir = std::env::temp_dir().join(format!("varspec-badobj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let files = [
        // tobj's errors do not say where; the message names the line.
        (
            "far.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
            "far.obj line 4: face vertex index out of bounds: `f 1 2 9`",
        ),
        // tobj ignores a face of two vertices (a line) and checks the next
        // one; a texture index 0 reads as missing (review).
        (
            "line.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1 9\nf 1/0 2/1 3/1\nf 1 2 8\n",
            "line.obj line 7: face vertex index out of bounds",
        ),
        // The vertex a face uses, not an unused one out of range before it.
        (
            "unused.obj",
            "v 0 0 0\nv 1e30 0 0\nv 1 0 0\nv 0 1 0\nv inf 0 0\nf 1 3 5\n",
            "unused.obj line 5: `v inf 0 0`",
        ),
        (
            "before.obj",
            "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\nf 1 2 3\n",
            "before.obj line 3: face vertex index out of bounds",
        ),
        // tobj checks a model's faces when a `g`/`o` line closes it,
        // against the vertices read by then (a later vertex does not count).
        (
            "split.obj",
            "v 0 0 0\nv 1 0 0\nf 1 2 3\ng second\nv 0 1 0\nf 1 2 3\n",
            "split.obj line 3: face vertex index out of bounds: `f 1 2 3`",
        ),
        (
            "normal.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1//1 2//1 3//2\n",
            "normal.obj line 6: face normal index out of bounds",
        ),
        (
            "word.obj",
            "v 0 0 0\nv 1 0 0\n\nv 0 1 x\nf 1 2 3\n",
            "word.obj line 4: position parse error: `v 0 1 x`",
        ),
        (
            "face.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1/1/1/1 2 3\n",
            "face.obj line 5: face parse error",
        ),
        ("empty.obj", "v 0 0 0\nv 1 0 0\n", "at least one face"),
        (
            "nan.obj",
            // The line, where the value stands as written.
            "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n",
            "nan.obj line 2: `v nan 0 0`)",
        ),
        (
            "huge.obj",
            "v 0 0 0\nv 2e9 0 0\nv 0 1 0\nf 1 2 3\n",
            "magnitude at most 1e9",
        ),
        (
            "flat.obj",
            "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\nf 1 1 2\n",
            "(all 2 faces of",
        ),
        // Every vertex is within 1e9, but the scene's x scale of 1.5
        // places one at 1.35e9.
        (
            "placed.obj",
            "v 0 0 0\nv 9e8 0 0\nv 0 1 0\nf 1 2 3\n",
            "objects[0].scale = [1.5, 1.0, 1.0]: a placement whose vertices",
        ),
        // Within 1e9 after scaling; the translation's z of −6 takes a
        // vertex to −1.000000005e9: the translation is to blame.
        (
            "moved.obj",
            "v 0 0 0\nv 1 0 0\nv 0 0 -999999999\nf 1 2 3\n",
            "objects[0].translate = [0.013, 0.0, -6.0]: a placement whose vertices",
        ),
    ];
    let mut cases: Vec<(String, &str)> = vec![
        (r#""shape": "obj""#.into(), "objects[0].file"),
        (
            r#""shape": "quad", "file": "a.obj""#.into(),
            "only with shape `obj`",
        ),
        (
            r#""shape": "obj", "file": "missing.obj""#.into(),
            "missing.obj",
        ),
        (
            r#""shape": "obj", "file": "folder.obj""#.into(),
            "folder.obj is not a regular file",
        ),
    ];
    for (name, text, _) in &files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    std::fs::create_dir_all(dir.join("folder.obj")).unwrap();
    for (name, _, phrase) in &files {
        cases.push((format!(r#""shape": "obj", "file": "{name}""#), phrase));
    }
    for (shape, phrase) in cases {
        let path = dir.join("scene.json");
        std::fs::write(&path, plane_text(&shape)).unwrap();
        let message = match Scene::load(path.to_str().unwrap()) {
            Ok(_) => panic!("{shape}: accepted"),
            Err(e) => e.to_string(),
        };
        assert!(
            message.contains(phrase) && message.contains("objects[0]"),
            "{shape}: {message:?} should name objects[0] and say {phrase:?}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A byte-order mark before an OBJ's first line is dropped (read as part
/// of that line it hid the first `v`, and every face then named the next
/// vertex: a wrong mesh without an error); material lines are not read;
/// UTF-16 and bytes that are not UTF-8 are refused with their line.
#[test]
fn obj_text_encodings_are_read_or_refused_by_line() {
    use varspec::scene::mesh::read_obj;
    let dir = crate::common::temp_dir("obj-encodings");
    let plain = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv 50 50 50\nf 1 2 3\n";
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    };
    let read = read_obj(&write("plain.obj", plain.as_bytes())).unwrap();
    assert_eq!(read[0][0], [-1.0, -1.0, 0.0], "{read:?}");
    let with_bom = [b"\xEF\xBB\xBF".as_slice(), plain.as_bytes()].concat();
    assert_eq!(read_obj(&write("bom.obj", &with_bom)).unwrap(), read);
    // Surfaces take the scene file's material: a `usemtl` without a name,
    // or before a tab, failed tobj's parse ("material parse error").
    let materials = format!("mtllib nosuch.mtl\nusemtl\n{plain}usemtl\tred\n");
    assert_eq!(
        read_obj(&write("materials.obj", materials.as_bytes())).unwrap(),
        read
    );
    let utf16: Vec<u8> = [0xFF, 0xFE]
        .into_iter()
        .chain(plain.encode_utf16().flat_map(u16::to_le_bytes))
        .collect();
    let refused = read_obj(&write("wide.obj", &utf16)).unwrap_err();
    assert!(refused.contains("wide.obj is UTF-16"), "{refused}");
    let latin1 = b"v 0 0 0\nv 1 0 0\n# caf\xE9\nv 0 1 0\nf 1 2 3\n";
    let refused = read_obj(&write("latin1.obj", latin1)).unwrap_err();
    assert!(
        refused.contains("latin1.obj line 3: bytes that are not UTF-8"),
        "{refused}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_pixel_as_an_integrand_has_its_closed_form_integral_and_variance() {
    use std::sync::Arc;
    use varspec::integrands::Integrand;
    use varspec::rng::set_rng;
    use varspec::scene::pixel::{PixelIntegrand, REFERENCE_POINTS};
    use varspec::variance::empirical;
    // A defocused edge pixel: f ∈ {0, 1} (albedo 0 or 1, ambient 1), so
    // I = the closed-form fraction and ∫f² − I² = I(1 − I).
    let (depth, focus, aperture, edge) = (6.0, 3.0, 0.3, 0.05);
    let f = PixelIntegrand::new(Arc::new(edge_scene(depth, focus, aperture, edge)), 4, 4);
    let truth = edge_pixel(depth, focus, aperture, edge, 4);
    let var_f = truth * (1.0 - truth);
    assert!(var_f > 0.05, "the edge must cross the pixel: I = {truth}");
    // The reference set is umj (stratified in (x, y) and (u, v), randomly
    // paired: at most N/(N−1) times random sampling's variance, Owen 1997):
    // 6 standard errors of random sampling.
    let se = (2.0 * var_f / REFERENCE_POINTS as f64).sqrt();
    assert!(
        (f.integral() - truth).abs() <= 6.0 * se,
        "integral {} vs closed form {truth} (6 se = {:.2e})",
        f.integral(),
        6.0 * se
    );
    assert!(
        (f.variance() - var_f).abs() <= 6.0 * se + 1e-4,
        "variance {} vs I(1 − I) = {var_f}",
        f.variance()
    );
    // The empirical predictor on it: random points under a uniform shift
    // are iid, so Î = Binomial(N, I)/N with variance σ² = I(1 − I)/N and
    // fourth central moment σ⁴(3 + (1 − 6I(1 − I))/(N·I(1 − I))); the
    // sample variance of R such Î has standard error √((μ₄ − σ⁴)/R).
    let (n, r) = (64usize, 20_000usize);
    let sampler = registry::build("random", n, Some(4), &[]).unwrap();
    let e = empirical(&f, r, 5, |i| sampler.sample(&mut set_rng(9, i as u64))).unwrap();
    let sigma2 = var_f / n as f64;
    let mu4 = sigma2 * sigma2 * (3.0 + (1.0 - 6.0 * var_f) / (n as f64 * var_f));
    let stderr = ((mu4 - sigma2 * sigma2) / r as f64).sqrt();
    // 5 standard errors: a two-sided normal tail of 6e-7.
    assert!(
        (e.variance - sigma2).abs() <= 5.0 * stderr,
        "empirical {} vs I(1 − I)/N = {sigma2}: 5 se = {:.2e}",
        e.variance,
        5.0 * stderr
    );
    assert!(
        f.fourier(&[1, 0, 0, 0]).re.is_nan(),
        "no closed-form spectrum"
    );
    // ... so the Fourier predictor refuses it instead of summing NaN.
    let refused = varspec::variance::fourier(&f, 4, 1e-9, 2, |i| {
        sampler.sample(&mut set_rng(9, i as u64))
    });
    assert!(
        matches!(
            refused,
            Err(varspec::variance::VarianceError::NoFourier { .. })
        ),
        "{refused:?}"
    );
    assert_eq!(f.spec(), "scene:edge,px=4,py=4");
}

/// A pixel's estimated integral comes with a standard error (the spread
/// of independent sets' means): over 40 pixels crossed by the edge (each
/// pixel draws its own reference sets), the closed form's
/// z = (I ≈ − I)/se are independent Student t with 15 degrees of freedom,
/// so the mean of the 40 z² lies in [0.45, 2.50] with probability 99.9%
/// (its 0.05% and 99.95% quantiles, from 4·10^5 simulated means). An error
/// bar half the true one fails this in 98.6% of cases, twice it in 97.5%.
#[test]
fn a_pixel_integral_s_standard_error_covers_the_closed_form() {
    use std::sync::Arc;
    use varspec::integrands::Integrand;
    use varspec::scene::pixel::PixelIntegrand;
    let (depth, focus, aperture) = (6.0, 3.0, 0.3);
    let mut squares = Vec::new();
    for px in 2..=6 {
        // Pixel px's footprint on the plane spans X from c − 0.6 to
        // c + 0.402: one edge position per row across it.
        let c = (px as f64 - 4.0) * 0.402 + 0.3;
        for py in 0..8 {
            let edge = c - 0.58 + 0.96 * (py as f64 + 0.5) / 8.0;
            let scene = Arc::new(edge_scene(depth, focus, aperture, edge));
            let f = PixelIntegrand::new(scene, px, py);
            let truth = edge_pixel(depth, focus, aperture, edge, px);
            assert!(
                truth > 0.0 && truth < 1.0 && f.integral_stderr() > 0.0,
                "pixel ({px}, {py}), edge {edge}: I = {truth}, se {}",
                f.integral_stderr()
            );
            squares.push(((f.integral() - truth) / f.integral_stderr()).powi(2));
        }
    }
    let mean = squares.iter().sum::<f64>() / squares.len() as f64;
    assert!(
        (0.45..=2.50).contains(&mean),
        "mean z² {mean:.3} outside the 99.9% range [0.45, 2.50] of t²(15): {squares:.2?}"
    );
}

#[test]
fn the_pixel_shear_search_picks_the_warp_of_a_defocused_edge_and_sees_double_wedges() {
    use std::sync::Arc;
    use varspec::rng::set_rng;
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::pixel::PixelIntegrand;
    use varspec::scene::pixel_shear::{PixelShearOptions, search_pixel_shear};
    use varspec::variance::{VarianceError, empirical_shifting};
    let sampler = registry::build("umj", 64, Some(4), &[]).unwrap();
    let options = PixelShearOptions {
        seed: 3,
        ..PixelShearOptions::default()
    };
    // A shear's variance on 4000 fresh realizations (another seed than the
    // search's), so the comparison is not biased by the choice.
    let fresh = |f: &PixelIntegrand, shear: SampleShear| {
        empirical_shifting(f, 4000, 99, &[], |r| {
            let set = sampler.sample(&mut set_rng(99, r as u64))?;
            Ok::<_, VarianceError>(shear.apply(set))
        })
        .unwrap()
    };
    let show = |e: &varspec::variance::EmpiricalEstimate| {
        format!("{:.3e} [{:.3e}, {:.3e}]", e.variance, e.ci_low, e.ci_high)
    };
    // One depth: the warp following κ, several times below no shear (the
    // render test above measures < 0.25× over whole images).
    let f = PixelIntegrand::new(Arc::new(edge_scene(6.0, 3.0, 0.3, 0.05)), 4, 4);
    let found = search_pixel_shear(&f, sampler.as_ref(), options).unwrap();
    let kappa = found.analysis.kappa;
    assert!(!found.double_wedge);
    let best = found.best();
    assert_eq!(best.shear, SampleShear::Warp(found.analysis.kappas[0]));
    assert!((found.analysis.kappas[0] - kappa).abs() < 0.05 * kappa.abs());
    let (none, chosen) = (fresh(&f, SampleShear::NONE), fresh(&f, best.shear));
    // Both variances with their own 95% intervals: the chosen one's upper
    // end below a third of the unsheared one's lower end.
    assert!(
        chosen.ci_high < none.ci_low / 3.0,
        "warp {} vs none {}",
        show(&chosen),
        show(&none)
    );
    // An occluder at depth 2 in front of the plane at 6 with its edge
    // across the pixel: two depths, a double wedge; no candidate may end
    // above no shear.
    let scene = Arc::new(Scene::from_text(OCCLUDER_SCENE, "occluder").unwrap());
    let found = search_pixel_shear(
        &PixelIntegrand::new(scene.clone(), 4, 4),
        sampler.as_ref(),
        options,
    )
    .unwrap();
    assert!(
        found.double_wedge,
        "the occluder's edge crosses pixel 4: {:?}",
        found.analysis
    );
    assert!(found.analysis.kappas.len() >= 2);
    // Whatever it picks is not worse than no shear on fresh realizations
    // (95% intervals overlap or lie below).
    let f = PixelIntegrand::new(scene, 4, 4);
    let (none, chosen) = (fresh(&f, SampleShear::NONE), fresh(&f, found.best().shear));
    assert!(
        chosen.ci_low <= none.ci_high,
        "{:?}: {} vs none {}",
        found.best().shear,
        show(&chosen),
        show(&none)
    );
}

#[test]
fn a_pixel_light_field_plane_matches_its_closed_form_marginal() {
    use std::sync::Arc;
    use varspec::scene::pixel::PixelIntegrand;
    // The defocused edge pixel f = 1[c0 + cx·x + cu·u < e] does not depend
    // on y or v: its XU marginal is the indicator itself, with
    // F(k, 0) = ∫ h(x) e^(−2πikx) dx, h(x) = |{u : c0 + cx·x + cu·u < e}|
    // (clamped linear), integrated here by the midpoint rule on 2^16 cells.
    let (depth, focus, aperture, edge) = (6.0, 3.0, 0.3, 0.05);
    let f = PixelIntegrand::new(Arc::new(edge_scene(depth, focus, aperture, edge)), 4, 4);
    let s = 2.0 * focus * 15f64.to_radians().tan() / 8.0;
    let r = depth / focus;
    let (c0, cx, cu) = (
        (4.0 - 4.0) * s * r - aperture * (1.0 - r),
        s * r,
        2.0 * aperture * (1.0 - r),
    );
    let h = |x: f64| {
        let t = (edge - c0 - cx * x) / cu;
        if cu > 0.0 {
            t.clamp(0.0, 1.0)
        } else {
            (1.0 - t).clamp(0.0, 1.0)
        }
    };
    let m = 1 << 16;
    let exact = |k: f64| {
        let (mut re, mut im) = (0.0, 0.0);
        for i in 0..m {
            let x = (i as f64 + 0.5) / m as f64;
            let phase = -std::f64::consts::TAU * k * x;
            re += h(x) * phase.cos();
            im += h(x) * phase.sin();
        }
        (re * re + im * im) / (m as f64 * m as f64)
    };
    let xu = f.plane_power([0, 2], 64, 64, 1).unwrap();
    let yv = f.plane_power([1, 3], 64, 64, 1).unwrap();
    for k in 1..=3i64 {
        let truth = exact(k as f64);
        let got = xu.at(&[k, 0]);
        // Cell noise: each average of 64 binary values has variance
        // ≤ 1/256, so F's noise has sd ≤ √(1/256/64²) = 9.8e-4; with the
        // cells' box filter (1 − sinc² ≤ 0.003 at k ≤ 3) and aliasing, 5%
        // of a power of ~1e-2 is several standard errors wide.
        assert!(
            (got - truth).abs() <= 0.05 * truth,
            "XU power at ({k}, 0): {got:.4e} vs closed form {truth:.4e}"
        );
        // The YV marginal is constant: only noise away from DC.
        assert!(
            yv.at(&[k, 0]) < 0.01 * truth,
            "YV power at ({k}, 0) = {:.3e} is not noise",
            yv.at(&[k, 0])
        );
    }
}

#[test]
fn the_pilot_measures_only_occlusion_edges_and_pinhole_pixels_are_not_warped() {
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::render::{ShearPolicy, analyse, pixel_shears};
    let scene = Scene::from_text(OCCLUDER_SCENE, "occluder").unwrap();
    let sampler = registry::build("umj", 16, Some(4), &[]).unwrap();
    let analysis = analyse(&scene);
    let analytic = pixel_shears(
        &scene,
        sampler.as_ref(),
        ShearPolicy::Analytic,
        &analysis,
        5,
        &|| {},
    )
    .unwrap();
    let pilot = pixel_shears(
        &scene,
        sampler.as_ref(),
        ShearPolicy::Pilot { pilots: 4 },
        &analysis,
        5,
        &|| {},
    )
    .unwrap();
    let edges = analysis
        .iter()
        .filter(|a| a.kind == PixelKind::Edge)
        .count();
    assert!(
        (1..analysis.len() / 2).contains(&edges),
        "{edges} edge pixels"
    );
    for ((a, analytic), pilot) in analysis.iter().zip(&analytic).zip(&pilot) {
        assert_eq!(*analytic, SampleShear::Warp(a.kappa), "{a:?}");
        if a.kind == PixelKind::Edge {
            // One of the candidates: none, or a shear of a probed depth.
            let probed = a.kappas.iter().any(|&k| {
                *pilot == SampleShear::Warp(k) || *pilot == SampleShear::Position([-k, -k])
            });
            assert!(*pilot == SampleShear::NONE || probed, "{a:?}: {pilot:?}");
        } else {
            assert_eq!(pilot, analytic, "{a:?}");
        }
    }
    // A pinhole looks at one point of the lens: κ = 0 and no shear (a warp
    // of slope 0 would exchange the pixel and lens coordinates).
    let shadows = Scene::load("shadows-square").unwrap();
    let a = analyse_pixel(&shadows, 100, 100);
    assert_eq!(a.kappa, 0.0);
    assert_eq!(a.shear(), SampleShear::NONE);
}

/// A slanted surface near the focal plane (the dof scene's box at pixel
/// (112, 95)): κ changes across the footprint by over a third of a stratum
/// of t at 64 samples, and the search measures warps across that range.
/// Its choice holds on fresh realizations (another seed): below half the
/// centre slope's variance, 95% intervals apart; a slope error of 0.01
/// raises the variance by over half, so the pixel is a hairline. The
/// fronto-parallel wall (33, 1) has one κ (to rounding) and gets no extra
/// candidates.
#[test]
fn the_pixel_search_measures_slopes_across_a_slanted_footprint() {
    use varspec::rng::set_rng;
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::pixel::PixelIntegrand;
    use varspec::scene::pixel_shear::{PixelShearOptions, search_pixel_shear};
    use varspec::variance::{VarianceError, empirical_shifting};
    let sampler = registry::build("umj", 64, Some(4), &[]).unwrap();
    let options = PixelShearOptions {
        seed: 3,
        ..PixelShearOptions::default()
    };
    let f = PixelIntegrand::parse("scene:dof,px=112,py=95").unwrap();
    let found = search_pixel_shear(&f, sampler.as_ref(), options).unwrap();
    let [lo, hi] = found.slopes.range;
    let kappa = found.analysis.kappa;
    assert!(
        lo <= kappa && kappa <= hi && hi - lo > 0.02 && found.slopes.spread > 0.3,
        "{:?}, κ {kappa}",
        found.slopes
    );
    assert!(found.hairline, "{:?}", found.sensitivity);
    let fresh = |shear: SampleShear| {
        empirical_shifting(&f, 4000, 99, &[], |r| {
            let set = sampler.sample(&mut set_rng(99, r as u64))?;
            Ok::<_, VarianceError>(shear.apply(set))
        })
        .unwrap()
    };
    let chosen = fresh(found.best().shear);
    let centre = fresh(SampleShear::following(kappa));
    assert!(
        chosen.ci_high < centre.ci_low / 2.0,
        "chosen {:?}: {:.3e} [{:.3e}, {:.3e}]; centre κ {kappa}: {:.3e} [{:.3e}, {:.3e}]",
        found.best().shear,
        chosen.variance,
        chosen.ci_low,
        chosen.ci_high,
        centre.variance,
        centre.ci_low,
        centre.ci_high
    );
    let wall = search_pixel_shear(
        &PixelIntegrand::parse("scene:dof,px=33,py=1").unwrap(),
        sampler.as_ref(),
        options,
    )
    .unwrap();
    // One depth up to rounding of the hit points.
    assert!(wall.slopes.spread < 1e-4, "{:?}", wall.slopes);
    assert_eq!(wall.candidates.len(), 3, "none, position shear, warp");
}

/// Slopes below MIN_WARP_SLOPE follow no shear; at the threshold the
/// warp still keeps its lens coordinate uniform: the Kolmogorov–Smirnov
/// distance of 4096 warped u from U[0, 1) is below 1.63/√4096, the 99%
/// critical value, for stratified inputs (whose own distance is ≤ 1/4096).
#[test]
fn the_smallest_warp_keeps_the_lens_coordinate_uniform() {
    use varspec::scene::analysis::{MIN_WARP_SLOPE, SampleShear, footprint_warp};
    assert_eq!(SampleShear::following(1e-12), SampleShear::NONE);
    assert_eq!(SampleShear::following(-1e-12), SampleShear::NONE);
    assert_eq!(
        SampleShear::following(MIN_WARP_SLOPE),
        SampleShear::Warp(MIN_WARP_SLOPE)
    );
    let n = 4096;
    for kappa in [MIN_WARP_SLOPE, -MIN_WARP_SLOPE, 1e-3] {
        let mut u: Vec<f64> = (0..n)
            .map(|i| {
                let xi1 = (i as f64 + 0.5) / n as f64;
                let xi2 = ((i * 2731) % n) as f64 / n as f64 + 0.5 / n as f64;
                footprint_warp(kappa, xi1, xi2).1
            })
            .collect();
        let ks = crate::common::ks_from_uniform(&mut u);
        assert!(
            ks < 1.63 / (n as f64).sqrt(),
            "κ = {kappa:e}: KS distance {ks} of the warped u"
        );
    }
}

/// Configuration factor from a point to a parallel disk of radius `r` at
/// height `h` whose axis passes `a` from the point (Howell's catalogue of
/// configuration factors, B-13: F = ½[1 − (h² + a² − r²)/√((h² + a² + r²)² − 4a²r²)]).
fn disk_factor(h: f64, a: f64, r: f64) -> f64 {
    let (h2, a2, r2) = (h * h, a * a, r * r);
    0.5 * (1.0 - (h2 + a2 - r2) / ((h2 + a2 + r2).powi(2) - 4.0 * a2 * r2).sqrt())
}

/// Configuration factor from a point to a parallel `x` × `y` rectangle at
/// height `h` with one corner straight above it (Howell, B-3).
fn corner_rectangle_factor(h: f64, x: f64, y: f64) -> f64 {
    let (x, y) = (x / h, y / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
}

/// Soft shadows in absolute units: a pinhole camera looks straight down on
/// a grey plane (albedo ρ) lit by one area light of radiance L parallel to
/// it at height h. The centre pixel's radiance is ρ·L·F, F the point's
/// configuration factor to the light, in closed form for a disk (on the
/// axis and off it) and a square; the footprint is 0.035 wide, so F's
/// curvature across it shifts the pixel by < 1e-4 of its value. Tolerance:
/// 4.5 standard errors of the mean over 64 renders (two-sided 7e-6 each;
/// a 1% error in the light's normalization is 5–40 standard errors).
#[test]
fn soft_shadows_match_the_closed_form_irradiance_of_disk_and_square_lights() {
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::render::render_variance;
    let (albedo, radiance, h) = (0.5, 10.0, 1.0);
    // (shape, size: side or diameter, offset of its centre from the point's normal)
    let cases = [
        ("disk", 0.7, 0.0),
        ("disk", 0.7, 0.6),
        ("disk", 1.0, 1.5),
        ("square", 0.8, 0.0),
    ];
    let renders = 64;
    let sampler = registry::build("random", 1024, Some(4), &[]).unwrap();
    for (shape, size, offset) in cases {
        let factor = match shape {
            "disk" => disk_factor(h, offset, size / 2.0),
            _ => 4.0 * corner_rectangle_factor(h, size / 2.0, size / 2.0),
        };
        let text = format!(
            r#"{{"camera": {{"resolution": [5, 5], "fov_degrees": 2, "position": [0, 0, 0],
                 "look_at": [0, 0, -1], "focal_distance": 5, "aperture": 0}},
               "integrand": "light", "ambient": 0.0,
               "objects": [{{"shape": "quad", "scale": [20, 20, 1], "translate": [0, 0, -5],
                             "material": {{"texture": "constant", "albedo": {albedo}}}}}],
               "lights": [{{"shape": "{shape}", "centre": [{offset}, 0, {z}], "normal": [0, 0, -1],
                            "size": {size}, "radiance": {radiance}}}]}}"#,
            z = -5.0 + h
        );
        let scene = Scene::from_text(&text, shape).unwrap();
        let maps = render_variance(
            &scene,
            sampler.as_ref(),
            &[SampleShear::NONE; 25],
            11,
            renders,
            &|| {},
        )
        .unwrap();
        let (mean, se) = (
            maps.mean.pixels[12],
            (maps.variance.pixels[12] / renders as f64).sqrt(),
        );
        let expected = albedo * radiance * factor;
        assert!(
            (mean - expected).abs() <= 4.5 * se,
            "{shape} of size {size} offset {offset}: pixel {mean:.6} ± {se:.2e}, closed form {expected:.6} (F = {factor:.6})"
        );
        assert!(
            se < 0.01 * expected,
            "{shape}: standard error {se:.2e} too wide to test {expected:.4}"
        );
    }
}
