//! `varspec render` as users run it: identical images for any thread count,
//! every output written, scene files refused with the field named.

use crate::common;
use common::{assert_fails, temp_dir, varspec_with};

#[test]
fn renders_are_identical_on_one_and_two_threads_and_write_every_output() {
    let dir = temp_dir("render");
    let run = |threads: &str, tag: &str| {
        let p = |name: &str| {
            dir.join(format!("{tag}-{name}"))
                .to_str()
                .unwrap()
                .to_owned()
        };
        let out = varspec_with(
            &[
                "render",
                "dof",
                "--spp",
                "4",
                "--renders",
                "2",
                "--shear",
                "analytic",
                "-o",
                &p("img.png"),
                "--pfm",
                &p("img.pfm"),
                "--variance-pfm",
                &p("var.pfm"),
                "--variance-png",
                &p("var.png"),
                "--variance-npy",
                &p("var.npy"),
                "--npy",
                &p("img.npy"),
                "--analysis",
                &p("an.csv"),
                "--summary",
                &p("sum.json"),
                "--shear-png",
                &p("shear.png"),
            ],
            Some(threads),
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        // The closing line (on standard output, as every command's summary)
        // names every file written, not only the PNG.
        let stdout = String::from_utf8_lossy(&out.stdout);
        for name in [
            "img.png",
            "img.pfm",
            "img.npy",
            "var.png",
            "var.pfm",
            "var.npy",
            "an.csv",
            "shear.png",
            "sum.json",
        ] {
            assert!(stdout.contains(&p(name)), "{name} not reported: {stdout}");
        }
        (
            std::fs::read(p("img.pfm")).unwrap(),
            std::fs::read(p("var.pfm")).unwrap(),
        )
    };
    assert_eq!(
        run("1", "one"),
        run("2", "two"),
        "thread count changed the image"
    );
    let pfm = std::fs::read(dir.join("one-img.pfm")).unwrap();
    assert!(pfm.starts_with(b"Pf\n256 256\n-1.0\n"));
    assert_eq!(pfm.len(), 16 + 4 * 256 * 256);
    // The .npy maps hold the same pixels as the PFMs (which store f32 rows
    // bottom-up), top row first, as float64 [height, width].
    for (npy, pfm) in [("img.npy", "img.pfm"), ("var.npy", "var.pfm")] {
        let bytes = std::fs::read(dir.join(format!("one-{npy}"))).unwrap();
        let array = npyz::NpyFile::new(&bytes[..]).unwrap();
        assert_eq!(array.shape(), &[256, 256], "{npy}");
        let values: Vec<f64> = array.into_vec().unwrap();
        let floats = std::fs::read(dir.join(format!("one-{pfm}"))).unwrap();
        let pfm_value = |row: usize, col: usize| {
            let i = 16 + 4 * ((255 - row) * 256 + col);
            f32::from_le_bytes(floats[i..i + 4].try_into().unwrap())
        };
        for (row, col) in [(0, 0), (3, 200), (128, 77), (255, 255)] {
            assert_eq!(
                values[row * 256 + col] as f32,
                pfm_value(row, col),
                "{npy} ({row}, {col})"
            );
        }
        assert!(values.iter().any(|&v| v > 0.0), "{npy} is not all zero");
    }
    let csv = std::fs::read_to_string(dir.join("one-an.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 256 * 256);
    assert!(
        csv.contains(",single,") && csv.contains(",edge,"),
        "the dof scene has both"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("one-sum.json")).unwrap()).unwrap();
    assert!(summary["variance"]["mean"].as_f64().unwrap() > 0.0);
    // Two renders give a variance but no unbiased standard error of its
    // mean (that needs four: tests/standard_errors.rs).
    assert!(summary["variance"]["mean_stderr"].is_null(), "{summary}");
    for png in ["img.png", "var.png", "shear.png"] {
        let bytes = std::fs::read(dir.join(format!("one-{png}"))).unwrap();
        assert!(bytes.starts_with(b"\x89PNG"), "{png}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_scenes_and_requests_are_refused_with_the_field_named() {
    let dir = temp_dir("badscene");
    let base =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/dof.json")).unwrap();
    let cases = [
        (
            "\"fov_degrees\": 40",
            "\"fov_degrees\": 180",
            "camera.fov_degrees = 180",
        ),
        (
            "\"aperture\": 0.06",
            "\"aperture\": -1",
            "camera.aperture = -1",
        ),
        (
            "\"resolution\": [256, 256]",
            "\"resolution\": [0, 256]",
            "camera.resolution (width) = 0",
        ),
        (
            "\"period\": 0.25",
            "\"period\": 0",
            "objects[1].material.period = 0",
        ),
        // A period of 1e-300 overflowed the cell index.
        (
            "\"period\": 0.25",
            "\"period\": 1e-300",
            "objects[1].material.period = 1e-300: a period from 1e-6 to 1e9",
        ),
        (
            "\"high\": 0.85",
            "\"high\": 1.5",
            "objects[0].material.high = 1.5",
        ),
        (
            "\"scale\": [6, 6, 1]",
            "\"scale\": [6, 0, 1]",
            "objects[0].scale",
        ),
        (
            "\"subdivisions\": 4",
            "\"subdivisions\": 9",
            "objects[2].subdivisions = 9",
        ),
        (
            "\"shape\": \"quad\"",
            "\"shape\": \"torus\"",
            "unknown variant `torus`",
        ),
        (
            "\"integrand\": \"lens\"",
            "\"integrand\": \"light\"",
            "at least one light",
        ),
        (
            "\"look_at\": [0, 0, -1]",
            "\"look_at\": [0, 0, 0]",
            "camera.look_at",
        ),
        (
            "\"ambient\": 1.0",
            "\"ambiant\": 1.0",
            "unknown field `ambiant`",
        ),
        // A zero `up` used to pass the parallel test (0 < 0 is false) and
        // render every pixel as background; finite extremes overflowed.
        (
            "\"look_at\": [0, 0, -1],",
            "\"look_at\": [0, 0, -1], \"up\": [0, 0, 0],",
            "camera.up = [0.0, 0.0, 0.0]: a non-zero direction",
        ),
        (
            "\"ambient\": 1.0",
            "\"ambient\": 1e308",
            "ambient = 1e308: a radiance from 0 to 1e12",
        ),
        (
            "\"translate\": [0, 0, -8]",
            "\"translate\": [0, 0, -1e200]",
            "objects[0].translate = [0.0, 0.0, -1e200]: finite numbers of magnitude at most 1e9",
        ),
        (
            "\"focal_distance\": 4",
            "\"focal_distance\": 1e200",
            "camera.focal_distance = 1e200: a positive distance of at most 1e9",
        ),
        (
            "\"subdivisions\": 4",
            "\"subdivisions\": \"four\"",
            "objects[2].subdivisions: invalid type: string \"four\"",
        ),
        // A material's fields are read flat so that a wrong type names the
        // field itself, not only the material (serde's tagged enums lose it).
        (
            "\"low\": 0.15",
            "\"low\": \"0.15\"",
            "objects[0].material.low: invalid type: string \"0.15\"",
        ),
        (
            "\"low\": 0.15",
            "\"albedo\": 0.5, \"low\": 0.15",
            "objects[0].material: `albedo` is not a field of a `checker` texture (its fields: period, low, high)",
        ),
        (
            "\"low\": 0.15, ",
            "",
            "objects[0].material: missing field `low` of a `checker` texture",
        ),
        // A material that is not an object says what one is (it named the
        // reader's own type, `struct MaterialFields`).
        (
            "{\"texture\": \"checker\", \"period\": 0.8, \"low\": 0.15, \"high\": 0.85}",
            "0.5",
            "objects[0].material: invalid type: floating point `0.5`, expected a material: an object with `texture`",
        ),
        (
            "\"resolution\": [256, 256]",
            "\"resolution\": [256, 256, 3]",
            "camera.resolution: more elements than this array takes at line",
        ),
        (
            "\"aperture\": 0.06",
            "\"aperture\": NaN",
            "camera.aperture: `NaN` is not a JSON value (JSON has no NaN or infinities",
        ),
        (
            "\"aperture\": 0.06",
            "\"aperture\": -Infinity",
            "camera.aperture: `-Infinity` is not a JSON value (JSON has no NaN or infinities",
        ),
        // A name given as another JSON value: serde_json's enum reader calls
        // it a syntax error ("expected value", which read "`1` is not a JSON
        // value"); the message says what is wanted and lists the names.
        // The names come from the text with `""` there, so a wrong field
        // later in the file (`ambient`, before `integrand` in a sorted map)
        // does not hide them.
        (
            "\"integrand\": \"lens\",\n  \"ambient\": 1.0",
            "\"integrand\": 1e3,\n  \"ambient\": \"x\"",
            "integrand: `1e3` where a name (a JSON string) is expected: `lens` or `light` at line",
        ),
        (
            "\"shape\": \"quad\"",
            "\"shape\": [\"quad\"]",
            "objects[0].shape: an array where a name (a JSON string) is expected: one of `quad`, `box`, `sphere`, `obj`",
        ),
        // Fields that mean nothing where they stand were read and ignored.
        (
            "\"scale\": [6, 6, 1]",
            "\"scale\": [6, 6, 1], \"subdivisions\": 2",
            "objects[0].subdivisions = 2: only with shape `sphere`",
        ),
    ];
    for (from, to, phrase) in cases {
        assert!(base.contains(from), "{from}");
        let path = dir.join("bad.json");
        std::fs::write(&path, base.replacen(from, to, 1)).unwrap();
        assert_fails(&["render", path.to_str().unwrap(), "--spp", "4"], phrase);
    }
    // The top level is one object: serde would read an array as the
    // struct's fields in order and blame the first element.
    for (text, phrase) in [
        (format!("[{base}]"), "a JSON array, where one JSON object"),
        ("3".to_string(), "`3` at the top, where one JSON object"),
        (" \n".to_string(), "empty, where one JSON object"),
    ] {
        let path = dir.join("top.json");
        std::fs::write(&path, text).unwrap();
        assert_fails(&["render", path.to_str().unwrap()], phrase);
    }
    let square = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/shadows-square.json"
    ))
    .unwrap();
    let path = dir.join("square-sampling.json");
    std::fs::write(
        &path,
        square.replacen(
            "\"radiance\": 15.0",
            "\"radiance\": 15.0, \"sampling\": \"bounding_square\"",
            1,
        ),
    )
    .unwrap();
    assert_fails(
        &["render", path.to_str().unwrap()],
        "lights[0].sampling = \"bounding_square\": only for a `disk` light",
    );
    assert_fails(&["render", "nosuchscene"], "neither a built-in scene (dof,");
    assert_fails(
        &["render", "dof", "--sampler", "cmj"],
        "rendering needs a 4D sampler",
    );
    assert_fails(
        &["render", "dof", "--shear", "steep"],
        "--shear steep: expected",
    );
    assert_fails(
        &["render", "dof", "--variance-png", "v.png"],
        "--renders 2 or more",
    );
    assert_fails(
        &[
            "render",
            "dof",
            "--renders",
            "2",
            "--variance-png",
            "v.png",
            "--variance-range",
            "-2,-6",
        ],
        "two finite numbers with LO < HI",
    );
    // A range far below every pixel's variance paints every non-zero pixel
    // the top colour (viridis yellow): the range is the one given.
    let png = dir.join("ranged.png");
    let out = common::varspec(&[
        "render",
        "dof",
        "--spp",
        "4",
        "--renders",
        "2",
        "-o",
        dir.join("ranged-img.png").to_str().unwrap(),
        "--variance-png",
        png.to_str().unwrap(),
        "--variance-range",
        "-30,-29",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let img = image::open(&png).unwrap().to_rgb8();
    let (mut yellow, mut other) = (0, 0);
    // The heat map's middle (inside its axes), away from the colour bar.
    for y in 200..400 {
        for x in 150..450 {
            match img.get_pixel(x, y).0 {
                [r, g, b] if r > 240 && g > 215 && b < 60 => yellow += 1,
                [128, 128, 128] => {}
                _ => other += 1,
            }
        }
    }
    assert!(yellow > 20 * other.max(1), "yellow {yellow}, other {other}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_pixels_light_field_power_lies_on_its_sheared_line() {
    // Pixel (33, 1) of `dof` sees the back wall, κ = −5.28 pixels per lens
    // unit (results/scene §3): f(x, u) = g(x + κu), whose XU power lies on
    // k_u = κ·k_x. At k_x = 1 the line passes k_u = −5, the mirror k_u = +5
    // is off it (the wrong sign of the shear).
    let dir = temp_dir("pixel-power");
    let csv = dir.join("xu.csv");
    let out = varspec_with(
        &[
            "spectrum",
            "--integrand",
            "scene:dof,px=33,py=1",
            "--dims",
            "0,2",
            "--res",
            "17",
            "--csv",
            csv.to_str().unwrap(),
        ],
        None,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let at = |k: &str| -> f64 {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("{k},")))
            .unwrap_or_else(|| panic!("no row {k}"));
        line.rsplit(',').next().unwrap().parse().unwrap()
    };
    let (on, off) = (at("1,-5"), at("1,5"));
    assert!(
        on > 100.0 * off,
        "power on the line {on:e}, at its mirror {off:e}"
    );
    assert_fails(
        &["spectrum", "--integrand", "scene:dof,px=33,py=1"],
        "--dims",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A non-square image tells rows from columns: the .npy arrays are
/// [height, width] with the top row first, the PFM's rows bottom-up.
#[test]
fn npy_images_are_height_by_width_top_row_first() {
    let dir = temp_dir("render-npy");
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/dof.json")).unwrap();
    let wide = text.replace("\"resolution\": [256, 256]", "\"resolution\": [48, 20]");
    assert_ne!(text, wide);
    let scene = dir.join("wide.json");
    std::fs::write(&scene, wide).unwrap();
    let p = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let out = varspec_with(
        &[
            "render",
            &p("wide.json"),
            "--spp",
            "4",
            "--renders",
            "2",
            "-o",
            &p("img.png"),
            "--pfm",
            &p("img.pfm"),
            "--variance-pfm",
            &p("var.pfm"),
            "--variance-npy",
            &p("var.npy"),
        ],
        None,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(dir.join("var.npy")).unwrap();
    let array = npyz::NpyFile::new(&bytes[..]).unwrap();
    assert_eq!(array.shape(), &[20, 48]);
    let values: Vec<f64> = array.into_vec().unwrap();
    let pfm = std::fs::read(dir.join("var.pfm")).unwrap();
    let header = b"Pf\n48 20\n-1.0\n";
    assert!(pfm.starts_with(header));
    for row in 0..20 {
        for col in 0..48 {
            let i = header.len() + 4 * ((19 - row) * 48 + col);
            let v = f32::from_le_bytes(pfm[i..i + 4].try_into().unwrap());
            assert_eq!(values[row * 48 + col] as f32, v, "({row}, {col})");
        }
    }
    // Not symmetric under a flip, so the comparison above sees the order.
    let flipped: Vec<f64> = values.chunks(48).rev().flatten().copied().collect();
    assert_ne!(values, flipped, "an image equal to its flip tells nothing");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--shear warp:0` follows an unsheared light field: the same image as
/// `--shear none` (the warp of slope 0 itself would exchange the position
/// and lens coordinates), while a nonzero slope changes it.
#[test]
fn a_warp_of_slope_zero_is_no_shear() {
    let dir = temp_dir("render-warp0");
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/dof.json")).unwrap();
    let small = text.replace("\"resolution\": [256, 256]", "\"resolution\": [24, 16]");
    assert_ne!(text, small);
    std::fs::write(dir.join("small.json"), small).unwrap();
    let p = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let render = |shear: &str| {
        let out = varspec_with(
            &[
                "render",
                &p("small.json"),
                "--spp",
                "16",
                "--shear",
                shear,
                "-o",
                &p("img.png"),
                "--pfm",
                &p("img.pfm"),
            ],
            None,
        );
        assert!(
            out.status.success(),
            "{shear}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::fs::read(dir.join("img.pfm")).unwrap()
    };
    let none = render("none");
    assert!(render("warp:0") == none, "warp:0 differs from no shear");
    assert!(
        render("warp:0.5") != none,
        "a warp of slope 0.5 changed nothing"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `predict` on a scene pixel predicts what `render` measures there: by
/// default the unshifted estimator, the mean of f over the pixel's set as
/// drawn. The shift-randomized default of other integrands gave 1.28× the
/// render's variance on the pixel tested here and 1.5× on `dof`'s (40, 200).
/// The pixel is `dof`'s footprint size (a 32 × 32 crop of its centre: the
/// field of view scaled by 32/256) on the defocused checker; the render's
/// variance is from 3000 renders through the library, its standard error
/// from their fourth central moment; the two agree within 4 combined
/// standard errors (a two-sided 99.99% band, about ±16%). Its estimated
/// integral agrees with the renders' mean within the same band.
#[test]
fn predict_on_a_pixel_gives_the_variance_its_render_measures() {
    use varspec::scene::Scene;
    use varspec::scene::analysis::SampleShear;
    use varspec::scene::render::render;
    let dir = temp_dir("pixel-predict");
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/dof.json")).unwrap();
    let fov = 2.0
        * (20f64.to_radians().tan() * 32.0 / 256.0)
            .atan()
            .to_degrees();
    let crop = text
        .replace("\"resolution\": [256, 256]", "\"resolution\": [32, 32]")
        .replace("\"fov_degrees\": 40", &format!("\"fov_degrees\": {fov}"));
    let path = dir.join("crop.json");
    std::fs::write(&path, crop).unwrap();
    let scene = Scene::load(path.to_str().unwrap()).unwrap();
    let sampler = varspec::registry::build("umj", 16, Some(4), &[]).unwrap();
    let (px, py) = (5, 12);
    let renders = 3000;
    let values: Vec<f64> = (0..renders)
        .map(|r| {
            render(&scene, sampler.as_ref(), &[SampleShear::NONE; 1024], 9, r)
                .unwrap()
                .pixels[py * 32 + px]
        })
        .collect();
    let r = renders as f64;
    let mean = values.iter().sum::<f64>() / r;
    let m2 = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / r;
    let m4 = values.iter().map(|v| (v - mean).powi(4)).sum::<f64>() / r;
    let rendered = m2 * r / (r - 1.0);
    let rendered_se = ((m4 - m2 * m2 * (r - 3.0) / (r - 1.0)) / r).max(0.0).sqrt();
    let spec = format!("scene:{},px={px},py={py}", path.display());
    let out = common::varspec_ok(&[
        "predict",
        "--sampler",
        "umj",
        "-n",
        "16",
        "--integrand",
        &spec,
        "--realizations",
        "40000",
        "--json",
    ]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(
        report["estimator"]
            .as_str()
            .unwrap()
            .starts_with("unshifted"),
        "{}",
        report["estimator"]
    );
    let predicted = report["empirical"]["variance"].as_f64().unwrap();
    let predicted_se = report["empirical"]["stderr"].as_f64().unwrap();
    let band = 4.0 * rendered_se.hypot(predicted_se);
    assert!(
        (predicted - rendered).abs() <= band,
        "pixel {spec}: predicted {predicted:e} ± {predicted_se:e}, rendered {rendered:e} ± \
         {rendered_se:e} (99.99% band ±{band:e})"
    );
    // The pixel's estimated integral, with its standard error, against the
    // renders' mean: the same 99.99% band.
    let integral = report["integral"].as_f64().unwrap();
    let integral_se = report["integral_stderr"].as_f64().unwrap();
    let mean_se = (rendered / r).sqrt();
    let band = 4.0 * integral_se.hypot(mean_se);
    assert!(
        integral_se > 0.0 && (integral - mean).abs() <= band,
        "pixel {spec}: I ≈ {integral} ± {integral_se:e}, the renders' mean {mean} ± {mean_se:e} \
         (99.99% band ±{band:e})"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A pixel's reference (16 sets drawn in parallel) and its empirical
/// variance are the same numbers on one thread and two: the JSON of
/// `predict` is identical but for its wall times.
#[test]
fn predict_on_a_pixel_is_identical_on_one_and_two_threads() {
    let run = |threads: &str| {
        let out = varspec_with(
            &[
                "predict",
                "--integrand",
                "scene:dof,px=112,py=95",
                "--sampler",
                "umj",
                "-n",
                "16",
                "--realizations",
                "200",
                "--json",
            ],
            Some(threads),
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let mut report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        report["empirical"]
            .as_object_mut()
            .unwrap()
            .remove("seconds");
        report
    };
    let one = run("1");
    assert!(one["integral_stderr"].as_f64().unwrap() > 0.0, "{one}");
    assert_eq!(one, run("2"));
}

/// `--param` wins over the shorthand, and the outputs name the sampler that
/// ran: the image is padded:xy=jitter's, so the summary and the titles say
/// so (they said padded:xy=cmj: trial).
#[test]
fn a_param_override_renders_and_is_named_as_it_runs() {
    let dir = temp_dir("render-param");
    let render = |sampler: &[&str], tag: &str| {
        let npy = dir.join(format!("{tag}.npy"));
        let summary = dir.join(format!("{tag}.json"));
        let mut args = vec!["render", "dof", "--spp", "4"];
        args.extend_from_slice(sampler);
        let (npy_s, summary_s) = (npy.to_str().unwrap(), summary.to_str().unwrap());
        args.extend_from_slice(&["--npy", npy_s, "--summary", summary_s]);
        let out = varspec_with(&args, Some("2"));
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        (
            std::fs::read(&npy).unwrap(),
            common::read_json(&summary)["sampler"].clone(),
        )
    };
    let (overridden, named) = render(
        &["--sampler", "padded:xy=cmj", "--param", "xy=jitter"],
        "override",
    );
    let (direct, _) = render(&["--sampler", "padded:xy=jitter"], "direct");
    let (cmj, _) = render(&["--sampler", "padded:xy=cmj"], "cmj");
    assert!(
        overridden == direct,
        "--param xy=jitter did not draw jitter"
    );
    assert!(overridden != cmj, "the override drew the shorthand's cmj");
    assert_eq!(named, "padded:xy=jitter");
}
