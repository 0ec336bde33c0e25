//! The scene's soft-shadow experiment (docs/scene.md), written to the
//! folder given as the first argument (default `out/scene`): soft shadows
//! under a square and a disk light of equal area (the square's edges along
//! the light's (u, v) axes), 4D samplers at 16 spp, among them jitter and
//! uniform jitter on the light, relative RMS error per pixel against a
//! 4096-spp reference (the seed's table). The depth-of-field experiment is
//! `varspec experiment experiments/scene-dof.json`.
//!
//! ```sh
//! cargo run --release --example scene_shadows -- results/scene
//! ```

use varspec::registry;
use varspec::samplers::Sampler;
use varspec::scene::Scene;
use varspec::scene::analysis::SampleShear;
use varspec::scene::image::GreyImage;
use varspec::scene::render::{PixelStatistics, mse_against, reference_image, render_variance};

const RENDERS: usize = 16;

/// The reference: Sobol' at 4096 spp, 2 renders of seed 900.
fn reference(scene: &Scene) -> Result<GreyImage, Box<dyn std::error::Error>> {
    let sobol = registry::build("sobol", 4096, Some(4), &[])?;
    Ok(reference_image(scene, sobol.as_ref(), 900)?)
}

fn pixel_count(scene: &Scene) -> usize {
    let [w, h] = scene.camera().resolution();
    w * h
}

struct Row {
    variance: Vec<f64>,
    mse: f64,
}

fn evaluate(
    scene: &Scene,
    sampler: &dyn Sampler,
    shears: &[SampleShear],
    seed: u64,
    renders: usize,
    reference: &GreyImage,
) -> Result<Row, Box<dyn std::error::Error>> {
    let maps = render_variance(scene, sampler, shears, seed, renders, &|| {})?;
    Ok(Row {
        mse: mse_against(
            &maps.mean.pixels,
            Some(&maps.variance.pixels),
            renders,
            &reference.pixels,
        ),
        variance: maps.variance.pixels,
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "out/scene".into());
    std::fs::create_dir_all(&out)?;
    shadows(&out)
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
        let reference = reference(&scene)?;
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
