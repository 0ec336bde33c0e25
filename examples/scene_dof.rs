//! The scene experiments (docs/scene.md), written to the folder given as
//! the first argument (default `out/scene`):
//!
//! 1. Depth of field (`dof`, umj): no transformation, the best single global
//!    one (chosen on 2 renders from candidates, evaluated on 16 fresh
//!    ones), the per-pixel analytic warp and the pilot choice, at 16, 64 and
//!    256 spp: mean, median and 95th-percentile pixel variance, MSE against
//!    a 4096-spp Sobol reference, time; variance heat maps at 64 spp.
//! 2. Soft shadows under a square and a disk light of equal area (the
//!    square's edges along the light's (u, v) axes): 4D samplers at 16 spp,
//!    among them jitter and uniform jitter on the light, relative RMS error
//!    per pixel against a 4096-spp reference (the seed's table).
//!
//! ```sh
//! cargo run --release --example scene_dof -- results/scene [all|dof|shadows]
//! ```

use std::time::Instant;

use varspec::registry;
use varspec::samplers::Sampler;
use varspec::scene::Scene;
use varspec::scene::analysis::SampleShear;
use varspec::scene::image::GreyImage;
use varspec::scene::render::{
    PixelStatistics, ShearPolicy, analyse, mse_against, pixel_shears, render, render_variance,
};

const RENDERS: usize = 16;

/// A reference image: the mean of 2 renders of Sobol at 4096 spp.
fn reference_image(scene: &Scene) -> Result<GreyImage, Box<dyn std::error::Error>> {
    let sobol = registry::build("sobol", 4096, Some(4), &[])?;
    let none = vec![SampleShear::NONE; pixel_count(scene)];
    let a = render(scene, sobol.as_ref(), &none, 900, 0)?;
    let b = render(scene, sobol.as_ref(), &none, 900, 1)?;
    Ok(GreyImage {
        pixels: a
            .pixels
            .iter()
            .zip(&b.pixels)
            .map(|(x, y)| 0.5 * (x + y))
            .collect(),
        ..a
    })
}

fn pixel_count(scene: &Scene) -> usize {
    let [w, h] = scene.camera().resolution();
    w * h
}

struct Row {
    variance: Vec<f64>,
    mse: f64,
    seconds: f64,
}

fn evaluate(
    scene: &Scene,
    sampler: &dyn Sampler,
    shears: &[SampleShear],
    seed: u64,
    renders: usize,
    reference: &GreyImage,
) -> Result<Row, Box<dyn std::error::Error>> {
    let start = Instant::now();
    let maps = render_variance(scene, sampler, shears, seed, renders, &|| {})?;
    let seconds = start.elapsed().as_secs_f64();
    Ok(Row {
        mse: mse_against(
            &maps.mean.pixels,
            Some(&maps.variance.pixels),
            renders,
            &reference.pixels,
        ),
        variance: maps.variance.pixels,
        seconds,
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "out/scene".into());
    let part = std::env::args().nth(2).unwrap_or_else(|| "all".into());
    std::fs::create_dir_all(&out)?;
    if part == "all" || part == "dof" {
        dof(&out)?;
    }
    if part == "all" || part == "shadows" {
        shadows(&out)?;
    }
    Ok(())
}

fn dof(out: &str) -> Result<(), Box<dyn std::error::Error>> {
    let scene = Scene::load("dof")?;
    let width = scene.camera().resolution()[0];
    let analysis = analyse(&scene);
    let reference = reference_image(&scene)?;
    reference.write_pfm(std::path::Path::new(&format!("{out}/dof-reference.pfm")))?;
    let mut csv = csv::Writer::from_path(format!("{out}/dof.csv"))?;
    csv.write_record([
        "spp",
        "method",
        "shear",
        "renders",
        "mean_variance",
        "median_variance",
        "p95_variance",
        "mse_vs_reference",
        "seconds",
    ])?;
    let mut candidates = vec![SampleShear::NONE];
    for k in [-8.0, -6.0, -4.0, -2.0, -1.0, 1.0, 2.0, 4.0, 6.0, 8.0] {
        candidates.push(SampleShear::Warp(k));
    }
    for a in [-1.0, -0.5, 0.5, 1.0] {
        candidates.push(SampleShear::Position([a, a]));
    }
    for spp in [16, 64, 256] {
        let sampler = registry::build("umj", spp, Some(4), &[])?;
        // The best global transformation on 2 renders of another seed.
        let mut best = (SampleShear::NONE, f64::INFINITY);
        for &c in &candidates {
            let shears = vec![c; analysis.len()];
            let maps = render_variance(&scene, sampler.as_ref(), &shears, 7, 2, &|| {})?;
            let v = PixelStatistics::of(&maps.variance.pixels).mean;
            if v < best.1 {
                best = (c, v);
            }
        }
        let methods: Vec<(&str, ShearPolicy)> = vec![
            ("none", ShearPolicy::None),
            ("best global", ShearPolicy::Global(best.0)),
            ("per-pixel analytic", ShearPolicy::Analytic),
            ("per-pixel pilot", ShearPolicy::Pilot { pilots: 8 }),
        ];
        for (name, policy) in methods {
            let start = Instant::now();
            let shears = pixel_shears(&scene, sampler.as_ref(), policy, &analysis, 1)?;
            let choose = start.elapsed().as_secs_f64();
            let row = evaluate(&scene, sampler.as_ref(), &shears, 1, RENDERS, &reference)?;
            let label = match policy {
                ShearPolicy::Global(s) => format!("{} {:?}", s.form(), s.amounts()[0]),
                ShearPolicy::None => "none".into(),
                _ => "per pixel".into(),
            };
            let stats = PixelStatistics::of(&row.variance);
            println!(
                "dof umj {spp:>3} spp  {name:<20} {label:<16} mean var {:.3e}  mse {:.3e}  {:.1} s",
                stats.mean,
                row.mse,
                row.seconds + choose
            );
            csv.write_record([
                spp.to_string(),
                name.into(),
                label,
                RENDERS.to_string(),
                format!("{:e}", stats.mean),
                format!("{:e}", stats.median),
                format!("{:e}", stats.p95),
                format!("{:e}", row.mse),
                format!("{:.2}", row.seconds + choose),
            ])?;
            if spp == 64 && name != "best global" {
                let image = GreyImage {
                    width,
                    height: row.variance.len() / width,
                    pixels: row.variance.clone(),
                };
                image.write_variance_png(
                    &format!("dof, umj 64 spp, {name}: per-pixel variance ({RENDERS} renders)"),
                    Some((-6.0, -2.0)),
                    std::path::Path::new(&format!(
                        "{out}/dof-variance-{}.png",
                        name.replace(' ', "-")
                    )),
                )?;
            }
        }
        csv.flush()?;
    }
    Ok(())
}

fn shadows(out: &str) -> Result<(), Box<dyn std::error::Error>> {
    let mut shadows = csv::Writer::from_path(format!("{out}/shadows.csv"))?;
    shadows.write_record([
        "light",
        "sampler",
        "spp",
        "mean_variance",
        "relative_rms_error",
    ])?;
    let disk = varspec::scene::BUILTIN_SCENES[2].2;
    // The seed's setting: (u, v) uniform on the disk's bounding square, the
    // disk an indicator in it.
    let disk_square = disk.replace(
        "\"radiance\": 15.0",
        "\"radiance\": 15.0, \"sampling\": \"bounding_square\"",
    );
    assert_ne!(disk, disk_square, "the disk light's radiance is 15");
    for (light, text) in [
        ("square", varspec::scene::BUILTIN_SCENES[1].2),
        ("disk (area)", disk),
        ("disk (bounding square)", disk_square.as_str()),
    ] {
        let scene = Scene::from_text(text, light)?;
        let reference = reference_image(&scene)?;
        for name in [
            "random",
            "jitter",
            "padded:xy=jitter,uv=jitter",
            "padded:xy=jitter,uv=uniform-jitter",
            "umj",
            "sobol",
        ] {
            let sampler = registry::build(name, 16, Some(4), &[])?;
            let none = vec![SampleShear::NONE; pixel_count(&scene)];
            let row = evaluate(&scene, sampler.as_ref(), &none, 3, RENDERS, &reference)?;
            // Relative RMS error over the lit pixels: √(mean MSE) / mean value.
            let rel = row.mse.sqrt() / PixelStatistics::of(&reference.pixels).mean;
            println!(
                "{light:<24} {name:<36} 16 spp  mean var {:.3e}  relative rms {rel:.4}",
                PixelStatistics::of(&row.variance).mean
            );
            shadows.write_record([
                light.to_string(),
                name.into(),
                "16".into(),
                format!("{:e}", PixelStatistics::of(&row.variance).mean),
                format!("{rel:.5}"),
            ])?;
        }
    }
    shadows.flush()?;
    Ok(())
}
