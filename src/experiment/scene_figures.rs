//! The figures drawn from the ray-traced scene (docs/scene.md): the seed's
//! variance heat map original against sheared ([`scene_variance`]), its
//! soft-shadow table of samplers on lights ([`scene_samplers`]) and single
//! pixels' light fields with the shear their measurement chooses — the
//! hairline and double-wedge cases ([`scene_pixels`]). Singh, Öztireli,
//! Pilleboue & Jarosz, "Analysis of sample correlations for Monte Carlo
//! rendering"; Soler et al. 2009 for the sheared light field of a pixel.

use std::path::Path;
use std::sync::Arc;

use super::planes::{plane, plane_pngs};
use super::report::write_csv;
use super::spec::ExperimentError;
use crate::optimize::shear::SENSITIVITY_STEP;
use crate::registry;
use crate::report::plot::power_png;
use crate::rng::set_rng;
use crate::samplers::Sampler;
use crate::scene::Scene;
use crate::scene::analysis::SampleShear;
use crate::scene::pixel::PixelIntegrand;
use crate::scene::pixel_shear::{Measured, PixelShearOptions, search_pixel_shear};
use crate::scene::render::{
    DEFAULT_PILOTS, PixelStatistics, ShearPolicy, analyse, pixel_shears, reference_image,
    render_variance,
};
use crate::sum::ratio_and_stderr;

/// Most samples per pixel a scene figure may ask for.
pub(super) const MAX_SPP: usize = 1 << 16;
/// Most renders per policy of a scene figure.
pub(super) const MAX_RENDERS: usize = 4096;
/// Stream offsets of the scene figures' references and of the choice of
/// the best global shear (independent of the renders they score).
const REFERENCE_STREAM: u64 = 0x7e_fe7e;
const SELECTION_STREAM: u64 = 0x5e_1ec7;
/// The references' sampler: Owen-scrambled Sobol' by Burley's hash
/// (JCGT 9(4), 2020), unbiased like the nested scramble and faster to
/// draw: a 1024-spp render of `dof` takes 6.6 s against 11.3 s with the
/// nested scramble (25.7 s before the nested scramble drew only its top
/// ⌈log₂ N⌉ levels), 2 cores.
pub(super) const REFERENCE_SAMPLER: &str = "sobol:scramble=hash";
/// The planes of a pixel figure: the seed's XU and YV.
const PIXEL_PLANES: [&str; 2] = ["xu", "yv"];

/// The scene-variance figure's shear policies, in table order ("best
/// global" takes the chosen shear).
pub(super) const POLICIES: [(&str, ShearPolicy); 4] = [
    ("none", ShearPolicy::None),
    ("best global", ShearPolicy::Global(SampleShear::NONE)),
    ("per-pixel analytic", ShearPolicy::Analytic),
    (
        "per-pixel pilot",
        ShearPolicy::Pilot {
            pilots: DEFAULT_PILOTS,
        },
    ),
];

/// Files of a pixel figure: `PREFIX.csv` and, per pixel,
/// `PREFIX-X-Y-{f,before,after}-{xu,yv}.png`.
pub(super) fn pixel_files(prefix: &str, pixels: &[[usize; 2]]) -> Vec<String> {
    let mut files = vec![format!("{prefix}.csv")];
    for [x, y] in pixels {
        for what in ["f", "before", "after"] {
            for p in PIXEL_PLANES {
                files.push(format!("{prefix}-{x}-{y}-{what}-{p}.png"));
            }
        }
    }
    files
}

/// How a table fails to be written, in the figures' error.
fn table_error(what: &str, err: String) -> ExperimentError {
    ExperimentError::Invalid {
        file: what.to_string(),
        reason: err,
    }
}

/// "a/b× (± its standard error)" for two mean pixel variances with their
/// standard errors ([`ratio_and_stderr`]; without one below 4 renders).
fn gain(a: (f64, Option<f64>), b: (f64, Option<f64>)) -> String {
    match (a.1, b.1) {
        (Some(sa), Some(sb)) => {
            let (ratio, stderr) = ratio_and_stderr((a.0, sa), (b.0, sb));
            format!("{ratio:.2}× (± {stderr:.2})")
        }
        _ => format!("{:.2}×", a.0 / b.0),
    }
}

/// File of the heat map of lens design `i` (0-based) at the heat-map spp.
pub(super) fn lens_design_png(prefix: &str, i: usize) -> String {
    format!("{prefix}-variance-lens-design-{}.png", i + 1)
}

/// The depth-of-field scene's per-pixel variance under the four
/// [`POLICIES`] at each spp, and each lens design with no shear and with
/// the per-pixel analytic warp (see [`super::Figure::SceneVariance`]);
/// returns its README entry.
#[allow(clippy::too_many_arguments)]
pub(super) fn scene_variance(
    seed: u64,
    out: &Path,
    prefix: &str,
    scene: &str,
    (sampler, lens_designs): (&str, &[String]),
    spp: &[usize],
    renders: usize,
    (heatmap_spp, reference_spp): (usize, usize),
) -> Result<String, Box<dyn std::error::Error>> {
    let scene = Scene::load(scene)?;
    let analysis = analyse(&scene);
    let (sobol, reference_n) =
        registry::build_nearest(REFERENCE_SAMPLER, reference_spp, Some(4), &[])?;
    let reference = reference_image(&scene, sobol.as_ref(), seed ^ REFERENCE_STREAM)?;
    reference.write_pfm(&out.join(format!("{prefix}-reference.pfm")))?;
    let mut candidates = vec![SampleShear::NONE];
    for k in [-8.0, -6.0, -4.0, -2.0, -1.0, 1.0, 2.0, 4.0, 6.0, 8.0] {
        candidates.push(SampleShear::Warp(k));
    }
    for a in [-1.0, -0.5, 0.5, 1.0] {
        candidates.push(SampleShear::Position([a, a]));
    }
    let mut rows: Vec<Vec<String>> = Vec::new();
    let mut table = String::from(
        "| spp | sampler | policy | shear | mean variance | ± (standard error) | median | 95th percentile | MSE vs reference |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    let mut gains = String::new();
    for &requested in spp {
        let (s, n) = registry::build_nearest(sampler, requested, Some(4), &[])?;
        // The best global transformation on 2 renders of another seed.
        let mut best = (SampleShear::NONE, f64::INFINITY);
        for &c in &candidates {
            let shears = vec![c; analysis.len()];
            let maps = render_variance(
                &scene,
                s.as_ref(),
                &shears,
                seed ^ SELECTION_STREAM,
                2,
                &|| {},
            )?;
            let v = maps.mean_variance().0;
            if v < best.1 {
                best = (c, v);
            }
        }
        // One row: the mean pixel variance of `policy` with sampler `s`
        // (named `who`), and its heat map when `png` gives one (file, and
        // who in its title: a sampler's full name can be too long for one).
        let mut row = |s: &dyn Sampler,
                       who: &str,
                       name: &str,
                       policy: ShearPolicy,
                       png: Option<(String, String)>|
         -> Result<(f64, Option<f64>), Box<dyn std::error::Error>> {
            let shears = pixel_shears(&scene, s, policy, &analysis, seed, &|| {})?;
            let maps = render_variance(&scene, s, &shears, seed, renders, &|| {})?;
            let mse = maps.mse_against(&reference);
            let stats = PixelStatistics::of(&maps.variance.pixels);
            let (mean, stderr) = maps.mean_variance();
            let shear = match policy {
                ShearPolicy::Global(c) => format!("{} {}", c.form(), c.amounts()[0]),
                ShearPolicy::None => "none".into(),
                _ => "per pixel".into(),
            };
            table += &format!(
                "| {n} | {who} | {name} | {shear} | {mean:.3e} | {} | {:.3e} | {:.3e} | {mse:.3e} |\n",
                stderr.map_or("—".into(), |e| format!("{e:.1e}")),
                stats.median,
                stats.p95
            );
            rows.push(vec![
                n.to_string(),
                name.into(),
                shear,
                renders.to_string(),
                format!("{mean:e}"),
                stderr.map_or(String::new(), |e| format!("{e:e}")),
                format!("{:e}", stats.median),
                format!("{:e}", stats.p95),
                format!("{mse:e}"),
                who.into(),
            ]);
            if let Some((png, titled)) = png.filter(|_| requested == heatmap_spp) {
                maps.variance.write_variance_png(
                    &format!(
                        "{}, {titled} {n} spp, {name}: per-pixel variance ({renders} renders)",
                        scene.name()
                    ),
                    Some((-6.0, -2.0)),
                    &out.join(png),
                )?;
            }
            Ok((mean, stderr))
        };
        let mut means = Vec::new();
        for &(name, policy) in &POLICIES {
            let policy = match policy {
                ShearPolicy::Global(_) => ShearPolicy::Global(best.0),
                p => p,
            };
            let png = (name != "best global").then(|| {
                let file = format!("{prefix}-variance-{}.png", name.replace(' ', "-"));
                (file, sampler.to_string())
            });
            means.push(row(s.as_ref(), sampler, name, policy, png)?);
        }
        gains += &format!(
            "- {n} spp: per-pixel analytic {} below none, {} below the best global shear; \
             pilot {} below none",
            gain(means[0], means[2]),
            gain(means[1], means[2]),
            gain(means[0], means[3])
        );
        for (i, design) in lens_designs.iter().enumerate() {
            let (d, m) = registry::build_nearest(design, n, Some(4), &[])?;
            debug_assert_eq!(m, n, "validation compares the designs' N");
            let own = row(d.as_ref(), design, "none", ShearPolicy::None, None)?;
            let png = Some((lens_design_png(prefix, i), format!("lens design {}", i + 1)));
            let warped = row(
                d.as_ref(),
                design,
                "per-pixel analytic",
                ShearPolicy::Analytic,
                png,
            )?;
            gains += &format!(
                "; {design} with the per-pixel analytic warp {} below {sampler}'s none \
                 ({} below its own)",
                gain(means[0], warped),
                gain(own, warped)
            );
        }
        gains += ".\n";
    }
    write_csv(
        out,
        &format!("{prefix}.csv"),
        &[
            "spp",
            "method",
            "shear",
            "renders",
            "mean_variance",
            "mean_variance_stderr",
            "median_variance",
            "p95_variance",
            "mse_vs_reference",
            "sampler",
        ],
        &rows,
        &table_error,
    )?;
    let designs: String = lens_designs
        .iter()
        .enumerate()
        .map(|(i, d)| format!(", `{}` ({d})", lens_design_png(prefix, i)))
        .collect();
    Ok(format!(
        "- `{prefix}.csv`, `{prefix}-variance-{{none,per-pixel-analytic,per-pixel-pilot}}.png`{designs} \
         (at {heatmap_spp} spp), `{prefix}-reference.pfm` (hash-scrambled Sobol' {reference_n} spp, 2 renders): \
         scene `{}` with {sampler}, per-pixel variance over {renders} renders, MSE against the \
         reference. The standard errors are of the mean over pixels (each pixel's from its \
         fourth moment over the renders, from 4 renders on); a gain's treats its two rows as \
         independent.\n\n{table}\n{gains}",
        scene.name()
    ))
}

/// The seed's soft-shadow table: every sampler on every scene at one spp,
/// without shear, the mean per-pixel variance over `renders` renders and
/// the relative RMS error √(mean per-render MSE) / (mean reference value)
/// against a [`REFERENCE_SAMPLER`] reference of each scene; returns its README entry.
#[allow(clippy::too_many_arguments)]
pub(super) fn scene_samplers(
    seed: u64,
    out: &Path,
    file: &str,
    scenes: &[String],
    samplers: &[String],
    spp: usize,
    renders: usize,
    reference_spp: usize,
) -> Result<String, Box<dyn std::error::Error>> {
    let (sobol, reference_n) =
        registry::build_nearest(REFERENCE_SAMPLER, reference_spp, Some(4), &[])?;
    let mut rows: Vec<Vec<String>> = Vec::new();
    // cells[sampler][scene]: "variance (relative RMS)".
    let mut cells = vec![Vec::new(); samplers.len()];
    let mut used = vec![String::new(); samplers.len()];
    for name in scenes {
        let scene = Scene::load(name)?;
        let [w, h] = scene.camera().resolution();
        let reference = reference_image(&scene, sobol.as_ref(), seed ^ REFERENCE_STREAM)?;
        let level = PixelStatistics::of(&reference.pixels).mean;
        if level <= 0.0 {
            return Err(format!(
                "scene `{name}`: the reference image is black (mean {level:e}): a relative error \
                 needs a lit scene"
            )
            .into());
        }
        let none = vec![SampleShear::NONE; w * h];
        for (i, sampler) in samplers.iter().enumerate() {
            let (s, n) = registry::build_nearest(sampler, spp, Some(4), &[])?;
            let maps = render_variance(&scene, s.as_ref(), &none, seed, renders, &|| {})?;
            let mse = maps.mse_against(&reference);
            let (variance, stderr) = maps.mean_variance();
            let relative = mse.sqrt() / level;
            let stderr_text = stderr.map_or(String::new(), |e| format!(" ± {e:.1e}"));
            cells[i].push(format!(
                "{variance:.3e}{stderr_text} ({:.2}%)",
                100.0 * relative
            ));
            used[i] = format!("{sampler} ({n} spp)");
            rows.push(vec![
                name.clone(),
                sampler.clone(),
                n.to_string(),
                renders.to_string(),
                format!("{variance:e}"),
                stderr.map_or(String::new(), |e| format!("{e:e}")),
                format!("{mse:e}"),
                format!("{relative:e}"),
            ]);
        }
    }
    write_csv(
        out,
        file,
        &[
            "scene",
            "sampler",
            "spp",
            "renders",
            "mean_variance",
            "mean_variance_stderr",
            "mse_vs_reference",
            "relative_rms_error",
        ],
        &rows,
        &table_error,
    )?;
    let mut table = format!(
        "| sampler | {} |\n|---|{}\n",
        scenes
            .iter()
            .map(|s| format!("`{s}`"))
            .collect::<Vec<_>>()
            .join(" | "),
        "---|".repeat(scenes.len())
    );
    for (name, row) in used.iter().zip(&cells) {
        table += &format!("| {name} | {} |\n", row.join(" | "));
    }
    Ok(format!(
        "- `{file}`: mean per-pixel variance over {renders} renders ± its standard error \
         (relative RMS error against a hash-scrambled Sobol' {reference_n}-spp reference of 2 \
         renders, in parentheses; the standard error needs 4 renders or more), no shear.\n\n{table}"
    ))
}

/// Single pixels of a scene as integrands ([`PixelIntegrand`]): each
/// pixel's light-field power on the XU and YV planes, the transformation
/// its measured search chooses ([`search_pixel_shear`]: the render's
/// unshifted estimator, all candidates on the same realizations, until the
/// chosen one's relative standard error is 2%), and the spectra of `sets`
/// realizations before and after it; returns the README entry.
#[allow(clippy::too_many_arguments)]
pub(super) fn scene_pixels(
    seed: u64,
    out: &Path,
    prefix: &str,
    scene: &str,
    sampler: &str,
    n: usize,
    pixels: &[[usize; 2]],
    (sets, res): (usize, usize),
) -> Result<String, Box<dyn std::error::Error>> {
    let scene = Arc::new(Scene::load(scene)?);
    let (s, n) = registry::build_nearest(sampler, n, Some(4), &[])?;
    let planes: Vec<String> = PIXEL_PLANES.iter().map(|p| p.to_string()).collect();
    let mut rows: Vec<Vec<String>> = Vec::new();
    let mut table = format!(
        "| pixel | kind | κ of the probed depths | κ over the footprint | no shear | chosen | \
         variance | lower by | variance with the slope −{SENSITIVITY_STEP} / +{SENSITIVITY_STEP} \
         | realizations |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for &[px, py] in pixels {
        let f = PixelIntegrand::new(Arc::clone(&scene), px, py);
        let found = search_pixel_shear(
            &f,
            s.as_ref(),
            PixelShearOptions {
                seed,
                ..PixelShearOptions::default()
            },
        )?;
        let (none, best) = (found.unsheared(), found.best());
        let here = format!("{prefix}-{px}-{py}");
        for p in &planes {
            let (dims, axes) = plane(p)?;
            let power = f.plane_power(dims, res, PixelIntegrand::RAYS_PER_CELL, seed)?;
            power_png(
                &power,
                &format!(
                    "pixel ({px}, {py}) of {}: light field, {p} plane",
                    scene.name()
                ),
                axes,
                "log10 |F_f(k)|^2",
                &out.join(format!("{here}-f-{p}.png")),
            )?;
        }
        let draw = |r: usize| s.sample(&mut set_rng(seed, r as u64));
        let title = format!("{sampler} N = {n}");
        plane_pngs(
            out,
            &format!("{here}-before"),
            &format!("{title}, no shear"),
            &planes,
            (sets, res),
            &draw,
        )?;
        plane_pngs(
            out,
            &format!("{here}-after"),
            &format!(
                "{title}, {} {:.3}",
                best.shear.form(),
                best.shear.amounts()[0]
            ),
            &planes,
            (sets, res),
            &|r| Ok(best.shear.apply(draw(r)?)),
        )?;
        let a = &found.analysis;
        let kappas: Vec<String> = a.kappas.iter().map(|k| format!("{k:e}")).collect();
        let kappas_shown: Vec<String> = a.kappas.iter().map(|k| format!("{k:.3}")).collect();
        let kind = if found.hairline {
            format!("{} (hairline)", a.kind.name())
        } else if found.double_wedge {
            format!("{} (double wedge)", a.kind.name())
        } else {
            a.kind.name().to_string()
        };
        // A constant pixel (variance 0) has no relative error or ratio.
        let cell = |m: &Measured| match m.estimate.variance {
            0.0 => "0 (constant)".to_string(),
            v => format!("{v:.3e} ± {:.0}%", 100.0 * m.estimate.stderr / v),
        };
        let lower = match best.estimate.variance {
            0.0 => "—".to_string(),
            v => format!("{:.2}×", none.estimate.variance / v),
        };
        // Probed on single-depth pixels only.
        let footprint = if a.kind == crate::scene::analysis::PixelKind::Single {
            format!(
                "{:.3} to {:.3}",
                found.slopes.range[0], found.slopes.range[1]
            )
        } else {
            "—".to_string()
        };
        let sensitivity = found.sensitivity.as_ref().map_or("—".to_string(), |s| {
            format!(
                "{:.3}× / {:.3}×",
                s[0].estimate.variance / best.estimate.variance,
                s[1].estimate.variance / best.estimate.variance
            )
        });
        table += &format!(
            "| ({px}, {py}) | {kind} | {} | {footprint} | {} | {} {:.3} | {} | {lower} | {sensitivity} | {} |\n",
            kappas_shown.join(", "),
            cell(none),
            best.shear.form(),
            best.shear.amounts()[0],
            cell(best),
            best.estimate.realizations
        );
        let [a0, a1] = best.shear.amounts();
        let variance_at = |i: usize| {
            found
                .sensitivity
                .as_ref()
                .map_or(String::new(), |s| format!("{:e}", s[i].estimate.variance))
        };
        rows.push(vec![
            px.to_string(),
            py.to_string(),
            a.kind.name().into(),
            format!("{:e}", a.depth),
            format!("{:e}", a.kappa),
            kappas.join(";"),
            format!("{:e}", found.slopes.range[0]),
            format!("{:e}", found.slopes.range[1]),
            best.shear.form().into(),
            format!("{a0:e}"),
            format!("{a1:e}"),
            format!("{:e}", none.estimate.variance),
            format!("{:e}", none.estimate.stderr),
            format!("{:e}", best.estimate.variance),
            format!("{:e}", best.estimate.stderr),
            best.estimate.realizations.to_string(),
            variance_at(0),
            variance_at(1),
            found.double_wedge.to_string(),
            found.hairline.to_string(),
        ]);
    }
    let (minus, plus) = (
        format!("variance_slope_minus_{SENSITIVITY_STEP}"),
        format!("variance_slope_plus_{SENSITIVITY_STEP}"),
    );
    write_csv(
        out,
        &format!("{prefix}.csv"),
        &[
            "px",
            "py",
            "kind",
            "depth",
            "kappa",
            "kappas",
            "kappa_footprint_min",
            "kappa_footprint_max",
            "chosen_form",
            "chosen_a",
            "chosen_b",
            "variance_unsheared",
            "stderr_unsheared",
            "variance_chosen",
            "stderr_chosen",
            "realizations",
            &minus,
            &plus,
            "double_wedge",
            "hairline",
        ],
        &rows,
        &table_error,
    )?;
    Ok(format!(
        "- `{prefix}.csv`, `{prefix}-X-Y-{{f,before,after}}-{{xu,yv}}.png`: pixels of `{}` as \
         integrands with {sampler} at N = {n}: the light field's power (`f`, a {res}² grid), the \
         transformation the measured search chooses among no shear and, per probed depth, the \
         position shear −κ and the footprint warp κ, and where κ changes across the footprint by \
         a tenth of a stratum of t or more, warps across that range (the render's unshifted \
         estimator, common \
         realizations, 2% relative standard error on the choice), and the spectra of {sets} sets \
         before and after it. A pixel is a double wedge when its probes meet two depths, a \
         hairline when moving the warp's slope by ±{SENSITIVITY_STEP} raises the variance by \
         half.\n\n{table}",
        scene.name()
    ))
}
