//! `varspec render`: render a scene's pixels as 4D integrands with any 4D
//! sampler, per-pixel shears from local analysis, and variance heat maps.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, bail};

use super::{args, progress};
use varspec::io::write_atomic;
use varspec::optimize::shear::MAX_SHEAR_RANGE;
use varspec::registry;
use varspec::report::plot::{HeatMap, heatmap_png};
use varspec::samplers::Sampler;
use varspec::scene::analysis::{PixelKind, SampleShear};
use varspec::scene::image::GreyImage;
use varspec::scene::render::{
    DEFAULT_PILOTS, MAX_PILOTS, MAX_RENDERS, PixelStatistics, ShearPolicy, VarianceMaps, analyse,
    mse_against, pilot_estimates, pixel_shears, render, render_variance,
};
use varspec::scene::{BUILTIN_SCENES, Scene};

#[derive(clap::Args)]
pub struct Args {
    /// A built-in scene (see --list) or a scene file (JSON, docs/scene.md).
    #[arg(default_value = "dof")]
    scene: String,
    /// Any 4D sampler of the registry, with `name:key=value` parameters.
    #[arg(long, default_value = "umj")]
    sampler: String,
    /// Samples per pixel (the sampler's N). `-n`/`--n` as in every other
    /// command.
    #[arg(value_parser = super::args::count, allow_negative_numbers = true, short = 'n', long, visible_alias = "n", default_value_t = 16)]
    spp: usize,
    /// Shear of each pixel's set: none; analytic (the warp following the
    /// centre depth's light field); pilot (analytic on single-depth pixels;
    /// on occlusion edges the best of none and every probed depth's shears
    /// by --pilots pilot estimates); A (x′ = x + A·u, y′ = y + A·v
    /// everywhere); warp:K (the footprint warp of slope K everywhere).
    #[arg(long, default_value = "none", allow_hyphen_values = true)]
    shear: String,
    /// Pilot estimates per candidate shear (--shear pilot; 2 to 2^20;
    /// default 32).
    #[arg(value_parser = super::args::whole_in::<2, { MAX_PILOTS as u64 }, usize>, allow_negative_numbers = true, long)]
    pilots: Option<usize>,
    /// Seed: the same seed gives the same image for any thread count.
    #[arg(value_parser = super::args::whole::<u64>, allow_negative_numbers = true, long, default_value_t = 0)]
    seed: u64,
    /// Independent renders (1 to 2^30); 2 or more also give the per-pixel
    /// variance.
    #[arg(value_parser = super::args::whole_in::<1, { MAX_RENDERS as u64 }, usize>, allow_negative_numbers = true, long, default_value_t = 1)]
    renders: usize,
    /// Tone-mapped PNG of the (mean) image (default out/render/SCENE.png).
    #[arg(short = 'o', long = "output", value_parser = super::args::png_path)]
    output: Option<PathBuf>,
    /// Multiplier before tone mapping.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    exposure: f64,
    /// Float image (PFM) of the (mean) image.
    #[arg(value_parser = super::args::pfm_path, long)]
    pfm: Option<PathBuf>,
    /// NumPy array (.npy, float64 [height, width], top row first) of the
    /// (mean) image.
    #[arg(value_parser = super::args::npy_path, long)]
    npy: Option<PathBuf>,
    /// Heat map PNG of log10 per-pixel variance, with a colour bar.
    #[arg(long, value_parser = super::args::png_path)]
    variance_png: Option<PathBuf>,
    /// Colour range of --variance-png as log10 variance LO,HI, e.g. -6,-2
    /// (default: the image's own): give two renders the same to compare
    /// their maps.
    #[arg(long, value_name = "LO,HI", value_parser = log_range, requires = "variance_png", allow_hyphen_values = true)]
    variance_range: Option<(f64, f64)>,
    /// Float image (PFM) of the per-pixel variance.
    #[arg(value_parser = super::args::pfm_path, long)]
    variance_pfm: Option<PathBuf>,
    /// NumPy array (.npy, float64 [height, width]) of the per-pixel variance.
    #[arg(value_parser = super::args::npy_path, long)]
    variance_npy: Option<PathBuf>,
    /// Reference image (PFM) for the MSE in the summary.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Summary JSON: variance statistics, MSE, time.
    #[arg(value_parser = super::args::json_path, long)]
    summary: Option<PathBuf>,
    /// Per-pixel analysis CSV: px,py,kind,depth,kappa,shear_form,a,b.
    #[arg(value_parser = super::args::csv_path, long)]
    analysis: Option<PathBuf>,
    /// Heat map PNG of the light-field slope κ each pixel's shear follows.
    #[arg(long, value_parser = super::args::png_path)]
    shear_png: Option<PathBuf>,
    /// Sampler parameter key=value (repeatable; wins over the same key in
    /// the NAME:key=value shorthand).
    #[arg(long = "param", value_parser = args::key_value)]
    params: Vec<(String, String)>,
    /// List the built-in scenes (and nothing else: no scene is rendered).
    #[arg(long, conflicts_with = "scene")]
    list: bool,
}

impl Args {
    /// The files asked for beside the tone-mapped image, in the order the
    /// closing line names them.
    fn side_outputs(&self) -> [Option<&std::path::Path>; 8] {
        [
            self.pfm.as_deref(),
            self.npy.as_deref(),
            self.variance_png.as_deref(),
            self.variance_pfm.as_deref(),
            self.variance_npy.as_deref(),
            self.analysis.as_deref(),
            self.shear_png.as_deref(),
            self.summary.as_deref(),
        ]
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    if a.list {
        for (name, about, _) in BUILTIN_SCENES {
            outln!("{name}\n    {about}");
        }
        return Ok(());
    }
    if !(a.exposure.is_finite() && a.exposure > 0.0) {
        bail!("--exposure {}: expected a positive number", a.exposure);
    }
    if a.renders < 2
        && (a.variance_png.is_some() || a.variance_pfm.is_some() || a.variance_npy.is_some())
    {
        bail!("a variance needs --renders 2 or more");
    }
    if a.pilots.is_some() && a.shear != "pilot" {
        bail!("--pilots applies to --shear pilot, not --shear {}", a.shear);
    }
    let policy = match a.shear.as_str() {
        "none" => ShearPolicy::None,
        "analytic" => ShearPolicy::Analytic,
        "pilot" => ShearPolicy::Pilot {
            pilots: a.pilots.unwrap_or(DEFAULT_PILOTS),
        },
        text => {
            let (warp, number) = match text.strip_prefix("warp:") {
                Some(rest) => (true, rest),
                None => (false, text),
            };
            match number.parse::<f64>() {
                // The warp of slope 0 would exchange position and lens
                // coordinates; following an unsheared field is no shear.
                Ok(s) if s.is_finite() && warp => ShearPolicy::Global(SampleShear::following(s)),
                Ok(s) if s.abs() <= MAX_SHEAR_RANGE => {
                    ShearPolicy::Global(SampleShear::Position([s, s]))
                }
                _ => bail!(
                    "--shear {text}: expected none, analytic, pilot, a number A in [-{MAX_SHEAR_RANGE}, {MAX_SHEAR_RANGE}] or warp:K (K finite)"
                ),
            }
        }
    };
    let scene_files = Scene::files_read(&a.scene);
    args::check_outputs_beside(
        std::iter::once(a.output.as_deref()).chain(a.side_outputs()),
        std::iter::once(a.reference.as_deref())
            .chain(scene_files.iter().map(|p| Some(p.as_path()))),
    )?;
    let scene = Scene::load(&a.scene)?;
    // Every thread holds one pixel's set (and its sheared copy) at a time.
    varspec::memory::check(
        &format!("{} spp per pixel", a.spp),
        Some(rayon::current_num_threads() as f64 * 2.0 * a.spp as f64 * 4.0 * 8.0),
        "lower --spp",
    )?;
    let sampler = registry::build(&a.sampler, a.spp, Some(4), &a.params).map_err(|e| match e {
        varspec::samplers::SamplerError::Dimension { .. } => anyhow::anyhow!(
            "--sampler {}: rendering needs a 4D sampler (x, y on the pixel, u, v on the lens or light): {e}",
            a.sampler
        ),
        e => e.into(),
    })?;
    // From here on titles and the summary name the sampler as it runs
    // (--param wins over the shorthand).
    let a = Args {
        sampler: registry::label(&a.sampler, &a.params)?,
        ..a
    };
    let [w, h] = scene.camera().resolution();
    // Read and check the reference before the renders, not after them.
    let reference = match &a.reference {
        Some(path) => {
            let r = GreyImage::read_pfm(path).map_err(anyhow::Error::msg)?;
            if (r.width, r.height) != (w, h) {
                bail!(
                    "{}: the reference is {}×{}, the scene renders {w}×{h}",
                    path.display(),
                    r.width,
                    r.height
                );
            }
            Some(r)
        }
        None => None,
    };
    if let (ShearPolicy::Analytic | ShearPolicy::Pilot { .. }, Some(why)) =
        (policy, scene.why_no_slope())
    {
        eprintln!(
            "note: --shear {} leaves every pixel unsheared on {}: {why}, so no pixel has a light-field slope",
            a.shear,
            scene.name()
        );
    }
    let start = Instant::now();
    let analysis = analyse(&scene);
    let analysed = start.elapsed();
    let pilots = pilot_estimates(policy, &analysis);
    warn_slow_sets(
        sampler.as_ref(),
        &a.sampler,
        a.seed,
        (w * h) as u64 * a.renders as u64,
        pilots,
    )?;
    // The render's time counts the analysis, not the probe draw above.
    let start = Instant::now().checked_sub(analysed).unwrap_or(start);
    let edges = analysis
        .iter()
        .filter(|p| p.kind == PixelKind::Edge)
        .count();
    let pilot_bar = match policy {
        ShearPolicy::Pilot { .. } => progress::bar(edges as u64, "pilots on edge pixels"),
        _ => indicatif::ProgressBar::hidden(),
    };
    let shears = pixel_shears(&scene, sampler.as_ref(), policy, &analysis, a.seed, &|| {
        pilot_bar.inc(1)
    })?;
    pilot_bar.finish_and_clear();
    let bar = progress::bar(a.renders as u64, &format!("render {}", scene.name()));
    let (image, maps) = if a.renders >= 2 {
        let maps = render_variance(
            &scene,
            sampler.as_ref(),
            &shears,
            a.seed,
            a.renders,
            &|| bar.inc(1),
        )?;
        (maps.mean.clone(), Some(maps))
    } else {
        let img = render(&scene, sampler.as_ref(), &shears, a.seed, 0)?;
        bar.inc(1);
        (img, None)
    };
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    let output = a.output.clone().unwrap_or_else(|| {
        let stem = std::path::Path::new(&a.scene)
            .file_stem()
            .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from(format!("out/render/{stem}.png"))
    });
    if let Some(dir) = output.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    image.write_png(a.exposure, &output)?;
    if let Some(path) = &a.pfm {
        image.write_pfm(path)?;
    }
    if let Some(path) = &a.npy {
        image.write_npy(path)?;
    }
    let title = format!(
        "{}: {} at {} spp, shear {}",
        scene.name(),
        a.sampler,
        a.spp,
        a.shear
    );
    if let Some(var) = maps.as_ref().map(|m| &m.variance) {
        if let Some(path) = &a.variance_pfm {
            var.write_pfm(path)?;
        }
        if let Some(path) = &a.variance_npy {
            var.write_npy(path)?;
        }
        if let Some(path) = &a.variance_png {
            var.write_variance_png(
                &format!("variance over {} renders, {title}", a.renders),
                a.variance_range,
                path,
            )?;
        }
    }
    if let Some(path) = &a.analysis {
        #[derive(serde::Serialize)]
        struct Row<'a> {
            px: usize,
            py: usize,
            kind: &'a str,
            depth: f64,
            kappa: f64,
            shear_form: &'a str,
            a: f64,
            b: f64,
        }
        write_atomic(path, |out| {
            varspec::io::write_csv_rows(
                out,
                analysis.iter().zip(&shears).enumerate().map(|(i, (p, s))| {
                    let [a, b] = s.amounts();
                    Row {
                        px: i % w,
                        py: i / w,
                        kind: p.kind.name(),
                        depth: p.depth,
                        kappa: p.kappa,
                        shear_form: s.form(),
                        a,
                        b,
                    }
                }),
            )
        })?;
    }
    if let Some(path) = &a.shear_png {
        let values: Vec<f64> = shears.iter().map(SampleShear::slope).collect();
        // Symmetric about 0; ±1 when every pixel is unsheared (a bar from
        // −1e-9 to 1e-9 read "0" at every tick).
        let lim = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let lim = if lim > 0.0 { lim } else { 1.0 };
        heatmap_png(
            &HeatMap {
                title: format!("light-field slope the shear follows, {title}"),
                values: &values,
                width: w,
                x_range: (0.0, w as f64),
                y_range: (h as f64, 0.0),
                x_label: "pixel x".into(),
                y_label: "pixel y (from the top)".into(),
                bar_label: "κ (pixels per unit u)".into(),
                colour_range: (-lim, lim),
            },
            path,
        )?;
    }
    let summary = summary_json(
        &a,
        &scene,
        &analysis,
        maps.as_ref(),
        &image,
        reference.as_ref(),
        seconds,
    );
    if let Some(path) = &a.summary {
        write_atomic(path, |out| writeln!(out, "{summary:#}"))?;
    }
    outln!(
        "{title}: {w}×{h}, {} render(s) in {seconds:.2} s ({:.1} M samples/s){}",
        a.renders,
        (w * h * a.spp * a.renders) as f64 / seconds / 1e6,
        match &maps {
            Some(maps) => {
                let (mean, stderr) = maps.mean_variance();
                let stderr = stderr.map_or(String::new(), |e| format!(" ± {e:.1e}"));
                format!(", mean pixel variance {mean:.4e}{stderr}")
            }
            None => String::new(),
        }
    );
    if let Some(mse) = summary["mse_against_reference"].as_f64() {
        outln!("MSE against the reference {mse:.4e}");
    }
    let written: Vec<String> = std::iter::once(Some(output.as_path()))
        .chain(a.side_outputs())
        .flatten()
        .map(|p| p.display().to_string())
        .collect();
    announce!("wrote {}", written.join(", "));
    Ok(())
}

fn summary_json(
    a: &Args,
    scene: &Scene,
    analysis: &[varspec::scene::analysis::PixelAnalysis],
    maps: Option<&VarianceMaps>,
    image: &GreyImage,
    reference: Option<&GreyImage>,
    seconds: f64,
) -> serde_json::Value {
    let count = |k: PixelKind| analysis.iter().filter(|p| p.kind == k).count();
    let mut out = serde_json::json!({
        "scene": scene.name(),
        "sampler": a.sampler,
        "spp": a.spp,
        "shear": a.shear,
        "seed": a.seed,
        "renders": a.renders,
        "resolution": scene.camera().resolution(),
        "triangles": scene.geometry().triangle_count(),
        "pixels": {
            "background": count(PixelKind::Background),
            "single": count(PixelKind::Single),
            "edge": count(PixelKind::Edge),
        },
        "seconds": seconds,
    });
    if let Some(m) = maps {
        let stats = PixelStatistics::of(&m.variance.pixels);
        out["variance"] = serde_json::json!({
            "mean": stats.mean,
            "mean_stderr": m.mean_variance().1,
            "median": stats.median,
            "p95": stats.p95,
        });
    }
    if let Some(r) = reference {
        let mse = mse_against(
            &image.pixels,
            maps.map(|m| m.variance.pixels.as_slice()),
            a.renders,
            &r.pixels,
        );
        out["mse_against_reference"] = serde_json::json!(mse);
    }
    out
}

/// `LO,HI`: two finite numbers with LO < HI (a log10 colour range).
fn log_range(text: &str) -> Result<(f64, f64), String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let numbers: Vec<f64> = parts.iter().filter_map(|p| p.parse().ok()).collect();
    match numbers[..] {
        [lo, hi] if parts.len() == 2 && lo.is_finite() && hi.is_finite() && lo < hi => Ok((lo, hi)),
        _ => Err(format!(
            "expected LO,HI: two finite numbers with LO < HI (log10 variance, e.g. -6,-2), got `{text}`"
        )),
    }
}

/// Draws one set and, when the render's sets (`sets` for the pixels of
/// every render, `pilots` for the pilot estimates of `--shear pilot`) would
/// take more than [`SLOW_DRAWING`] seconds in all, says how long drawing
/// them takes (optimized samplers such as blue-noise descend per set: a
/// 4-point 4D set takes seconds, a 256×256 image hours).
fn warn_slow_sets(
    sampler: &dyn Sampler,
    name: &str,
    seed: u64,
    sets: u64,
    pilots: u64,
) -> anyhow::Result<()> {
    let start = Instant::now();
    sampler.sample(&mut varspec::rng::set_rng(seed, 0))?;
    let one = start.elapsed().as_secs_f64();
    let threads = rayon::current_num_threads();
    let total = one * (sets + pilots) as f64 / threads as f64;
    if total > SLOW_DRAWING {
        let pilots = if pilots > 0 {
            format!(" and {pilots} pilot estimates")
        } else {
            String::new()
        };
        eprintln!(
            "note: one {} set takes {} to draw; {sets} sets (pixels × renders){pilots} on \
             {threads} thread(s) take about {} in drawing alone",
            name,
            if one >= 1.0 {
                format!("{one:.1} s")
            } else {
                format!("{:.2} ms", one * 1e3)
            },
            super::progress::duration_words(std::time::Duration::from_secs_f64(total))
        );
    }
    Ok(())
}

/// Seconds of set drawing above which [`warn_slow_sets`] speaks.
const SLOW_DRAWING: f64 = 30.0;
