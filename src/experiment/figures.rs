//! Figure experiments (`"kind": "figures"`): a list of the course's figures
//! — expected spectra, their radial averages, the variance formula's
//! ingredients, convergence before and after a shear, and the rendered
//! scene's (src/experiment/scene_figures.rs) — each drawn to a PNG
//! by the same library calls the commands use, with the numbers each
//! figure shows in a `README.md` beside them (Singh, Öztireli, Pilleboue &
//! Jarosz, "Analysis of sample correlations for Monte Carlo rendering";
//! docs/formats.md, "Figure experiments").

use std::path::Path;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::planes::{METHOD, box_power, plane, plane_pngs};
use super::scene_figures::{
    MAX_RENDERS, MAX_SPP, POLICIES, REFERENCE_SAMPLER, lens_design_png, pixel_files, scene_pixels,
    scene_samplers, scene_variance,
};
use super::spec::{ExperimentError, plain_name};
use crate::design::projections::{ProjectionRequest, design_projections};
use crate::integrands;
use crate::io::write_atomic;
use crate::optimize::projections::parse_projections;
use crate::optimize::shear::Sheared;
use crate::registry;
use crate::report::plot::{LinePlot, Series, line_plot_png, power_png, spectrum_png};
use crate::rng::set_rng;
use crate::samplers::Sampler;
use crate::scene::Scene;
use crate::spectrum::Spectrum;
use crate::spectrum::radial::radial_profile;
use crate::variance::fourier::integrand_power;
use crate::variance::{VarianceError, empirical_shifting, fit_slope};

/// Largest spectrum resolution a figure may ask for (a res² box of f64).
const MAX_RES: usize = 2048;
/// Most realizations a figure may ask for.
const MAX_SETS: usize = 1 << 20;
/// Largest design a figure may ask for: points per set, sets, iterations.
const MAX_DESIGN_POINTS: usize = 1 << 16;
const MAX_DESIGN_SETS: usize = 256;
const MAX_ITERATIONS: usize = 100_000;

/// A figure experiment (see the module doc).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FigureExperiment {
    /// A plain file name: the report's title and the default folder.
    pub name: String,
    /// A paragraph for the report.
    #[serde(default)]
    pub description: String,
    /// Always `figures`.
    pub kind: String,
    /// Seed of every realization (shifts use seed + 1).
    #[serde(default)]
    pub seed: u64,
    /// The figures, drawn in order.
    pub figures: Vec<Figure>,
}

/// One figure.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(
    tag = "figure",
    rename_all = "kebab-case",
    deny_unknown_fields,
    expecting = "a figure: an object `{ \"figure\": KIND, ... }`"
)]
pub enum Figure {
    /// Radially averaged E[N·P_S] of 2D samplers on one plot (Pilleboue et
    /// al. 2015, §4: the radial profile of an isotropic spectrum).
    RadialSpectra {
        /// PNG file name.
        file: String,
        /// 2D samplers.
        samplers: Vec<String>,
        /// Requested N (each sampler's nearest valid N).
        n: usize,
        /// Realizations averaged.
        sets: usize,
        /// Box resolution (|k|∞ < res/2).
        res: usize,
    },
    /// A 2D sampler's E[N·P_S] as an image.
    Spectrum {
        /// PNG file name.
        file: String,
        /// 2D sampler.
        sampler: String,
        /// Requested N.
        n: usize,
        /// Realizations averaged.
        sets: usize,
        /// Box resolution.
        res: usize,
    },
    /// The variance formula's ingredients, Var = (1/N) Σ_(k≠0) E[N·P_S]
    /// P_f (Pilleboue et al. 2015, Eq. (9)): `PREFIX-sampling.png`,
    /// `PREFIX-integrand.png`, `PREFIX-product.png`, and the in-box sum.
    Ingredients {
        /// File name prefix.
        prefix: String,
        /// 2D sampler.
        sampler: String,
        /// 2D integrand with a Fourier transform.
        integrand: String,
        /// Requested N.
        n: usize,
        /// Realizations averaged.
        sets: usize,
        /// Box resolution.
        res: usize,
    },
    /// Expected spectra of 2D projections of a 4D sampler (the seed's XY,
    /// UV, XU and YV planes), optionally sheared by (a, b) first:
    /// `PREFIX-PLANE.png` for each plane.
    Projections {
        /// File name prefix.
        prefix: String,
        /// 4D sampler.
        sampler: String,
        /// Shear (a, b) applied first (needs (x, y) and (u, v) halves).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        shear: Option<[f64; 2]>,
        /// Planes among `xy`, `uv`, `xu`, `yv`.
        planes: Vec<String>,
        /// Requested N.
        n: usize,
        /// Realizations averaged.
        sets: usize,
        /// Box resolution.
        res: usize,
    },
    /// The seed's design principle: 4D sets designed from umj for a target
    /// per projection (`xy:SPEC;uv:SPEC;…`, as `optimize points -d 4
    /// --target`), and the expected spectra of their projections `planes`:
    /// `PREFIX-PLANE.png`, with each term's loss before and after.
    DesignedProjections {
        /// File name prefix.
        prefix: String,
        /// The projection target.
        target: String,
        /// Points per set.
        n: usize,
        /// Sets designed (in parallel).
        sets: usize,
        /// Iteration cap (default 1000).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        iterations: Option<usize>,
        /// Planes among `xy`, `uv`, `xu`, `yv`.
        planes: Vec<String>,
        /// Box resolution.
        res: usize,
    },
    /// The depth-of-field scene's per-pixel variance over `renders`
    /// independent renders with a 4D sampler at each spp, under four shear
    /// policies: none, the best single global shear (chosen on 2 renders of
    /// another seed among fixed candidates), the per-pixel analytic warp
    /// and the per-pixel pilot choice (docs/scene.md). Writes `PREFIX.csv`
    /// (mean, median and 95th-percentile pixel variance, MSE against a
    /// reference), `PREFIX-reference.pfm` (hash-scrambled Sobol', 2 renders at
    /// `reference_spp`) and the seed's variance heat maps at `heatmap_spp`:
    /// `PREFIX-variance-{none,per-pixel-analytic,per-pixel-pilot}.png`.
    /// Each of `lens_designs` adds two rows (no shear, and the per-pixel
    /// analytic warp, with its heat map `PREFIX-variance-lens-design-I.png`).
    SceneVariance {
        /// File name prefix.
        prefix: String,
        /// A built-in scene (`dof`) or a scene file.
        scene: String,
        /// 4D sampler.
        sampler: String,
        /// 4D samplers at the same N whose (u, v) pattern is chosen for the
        /// warped integrand: the warp turns a single-depth pixel into a 2D
        /// integral over the (u, v) pattern (docs/scene.md), so that
        /// pattern decides what is left (e.g. a (0, 2)-net,
        /// `padded:xy=mj,uv=sobol:scramble=hash`).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        lens_designs: Vec<String>,
        /// Samples per pixel (each the sampler's nearest valid N).
        spp: Vec<usize>,
        /// Renders per policy and spp (at least 2).
        renders: usize,
        /// The spp of the heat maps (one of `spp`).
        heatmap_spp: usize,
        /// The reference's spp (hash-scrambled Sobol').
        reference_spp: usize,
    },
    /// The seed's soft-shadow table: 4D samplers on scenes (lights) at one
    /// spp, no shear: mean per-pixel variance over `renders` renders and
    /// the relative RMS error against a hash-scrambled Sobol' reference (2 renders at
    /// `reference_spp`) of each scene, written to `file` (a `.csv`).
    SceneSamplers {
        /// CSV file name.
        file: String,
        /// Built-in scenes or scene files.
        scenes: Vec<String>,
        /// 4D samplers.
        samplers: Vec<String>,
        /// Samples per pixel (each sampler's nearest valid N).
        spp: usize,
        /// Renders per sampler and scene (at least 2).
        renders: usize,
        /// The reference's spp (hash-scrambled Sobol').
        reference_spp: usize,
    },
    /// Single pixels of a scene as integrands: the light field's power on
    /// the XU and YV planes, the transformation the pixel's measured shear
    /// search chooses, variance before and after, and the sets' spectra
    /// before and after it (`PREFIX.csv`,
    /// `PREFIX-X-Y-{f,before,after}-{xu,yv}.png`): the seed's hairline and
    /// double-wedge pixels.
    ScenePixels {
        /// File name prefix.
        prefix: String,
        /// A built-in scene or a scene file.
        scene: String,
        /// 4D sampler.
        sampler: String,
        /// Samples per pixel (the sampler's nearest valid N).
        n: usize,
        /// Pixels (x, y), each inside the image, each once (its files are
        /// written once).
        pixels: Vec<[usize; 2]>,
        /// Realizations of the spectra before and after.
        sets: usize,
        /// Box resolution of the spectra and the light field's grid (≥ 8).
        res: usize,
    },
    /// Variance against N of a 4D sampler with (x, y) and (u, v) halves,
    /// before and after the shear (a, b), estimator shifted in (x, y) only
    /// (Singh & Jarosz 2017), with the slopes.
    ShearConvergence {
        /// PNG file name.
        file: String,
        /// 4D sampler with halves (umj, padded:...).
        sampler: String,
        /// 4D integrand.
        integrand: String,
        /// Shear (a, b).
        shear: [f64; 2],
        /// Requested N values (at least two distinct).
        n: Vec<usize>,
        /// Realizations per N.
        realizations: usize,
    },
}

impl Figure {
    /// The files it writes.
    fn files(&self) -> Vec<String> {
        match self {
            Figure::RadialSpectra { file, .. }
            | Figure::Spectrum { file, .. }
            | Figure::ShearConvergence { file, .. } => vec![file.clone()],
            Figure::Ingredients { prefix, .. } => ["sampling", "integrand", "product"]
                .iter()
                .map(|p| format!("{prefix}-{p}.png"))
                .collect(),
            Figure::Projections { prefix, planes, .. }
            | Figure::DesignedProjections { prefix, planes, .. } => {
                planes.iter().map(|p| format!("{prefix}-{p}.png")).collect()
            }
            Figure::SceneVariance {
                prefix,
                lens_designs,
                ..
            } => {
                let mut files = vec![format!("{prefix}.csv"), format!("{prefix}-reference.pfm")];
                for (name, _) in POLICIES.iter().filter(|p| p.0 != "best global") {
                    files.push(format!("{prefix}-variance-{}.png", name.replace(' ', "-")));
                }
                files.extend((0..lens_designs.len()).map(|i| lens_design_png(prefix, i)));
                files
            }
            Figure::SceneSamplers { file, .. } => vec![file.clone()],
            Figure::ScenePixels { prefix, pixels, .. } => pixel_files(prefix, pixels),
        }
    }

    /// It writes tables (and, for the scene variance, a float image)
    /// beside its PNGs.
    fn writes_tables(&self) -> bool {
        matches!(
            self,
            Figure::SceneVariance { .. }
                | Figure::SceneSamplers { .. }
                | Figure::ScenePixels { .. }
        )
    }
}

impl FigureExperiment {
    /// Parses and validates the text of file `file`: every sampler and
    /// integrand exists in its dimension, sizes are bounded, file names are
    /// plain names written once (`.png`, but for the scene figures' tables
    /// and reference).
    ///
    /// # Errors
    /// [`ExperimentError::Invalid`] naming the file, the figure and the rule.
    pub fn parse(text: &str, file: &str) -> Result<Self, ExperimentError> {
        let invalid = |reason: String| ExperimentError::Invalid {
            file: file.to_string(),
            reason,
        };
        let e: FigureExperiment = crate::io::from_json(text)
            .map_err(|err| invalid(format!("not a valid figure experiment: {err}")))?;
        plain_name(&e.name).map_err(invalid)?;
        if e.kind != "figures" {
            return Err(invalid(format!(
                "kind `{}`: a figure experiment has kind `figures`",
                e.kind
            )));
        }
        if e.figures.is_empty() {
            return Err(invalid("figures must be non-empty".into()));
        }
        let mut written: Vec<String> = Vec::new();
        for (i, figure) in e.figures.iter().enumerate() {
            let at = |reason: String| invalid(format!("figures[{i}]: {reason}"));
            for name in figure.files() {
                plain_name(&name).map_err(at)?;
                if !name.ends_with(".png") && !figure.writes_tables() {
                    return Err(at(format!("file `{name}` must end in .png")));
                }
                if written.contains(&name) {
                    return Err(at(format!("file `{name}` is written twice")));
                }
                written.push(name);
            }
            let sampler_at = |name: &str, n: usize, dim: usize| {
                registry::build_nearest(name, n, Some(dim), &[])
                    .map(|_| ())
                    .map_err(|err| at(format!("sampler `{name}` at n = {n}: {err}")))
            };
            let counted = |what: &str, value: usize, most: usize| {
                if value == 0 || value > most {
                    Err(at(format!("{what} = {value} must be in 1 ..= {most}")))
                } else {
                    Ok(())
                }
            };
            // A spectrum's samplers (in dimension `dim`), sets and box.
            let spectra = |samplers: &[String], n: usize, dim: usize, sets: usize, res: usize| {
                if samplers.is_empty() {
                    return Err(at("samplers must be non-empty".into()));
                }
                for s in samplers {
                    sampler_at(s, n, dim)?;
                }
                counted("sets", sets, MAX_SETS)?;
                counted("res", res, MAX_RES)
            };
            // Projection planes: non-empty, each one of xy, uv, xu, yv.
            let planes_ok = |planes: &[String]| {
                if planes.is_empty() {
                    return Err(at("planes must be non-empty".into()));
                }
                planes
                    .iter()
                    .try_for_each(|p| plane(p).map(|_| ()).map_err(at))
            };
            // A finite shear that `sampler` at N = n can take.
            let shear_ok = |sampler: &str, n: usize, shear: [f64; 2]| {
                if !shear.iter().all(|a| a.is_finite()) {
                    return Err(at("shear must be finite".into()));
                }
                let (s, used) = registry::build_nearest(sampler, n, Some(4), &[])
                    .map_err(|err| at(format!("sampler `{sampler}` at n = {n}: {err}")))?;
                Sheared::new(s.as_ref(), shear).map_err(|err| at(err.to_string()))?;
                Ok(used)
            };
            // Renders of a per-pixel variance.
            let renders_ok = |renders: usize| {
                if !(2..=MAX_RENDERS).contains(&renders) {
                    Err(at(format!(
                        "renders = {renders} must be in 2 ..= {MAX_RENDERS} (a variance needs two)"
                    )))
                } else {
                    Ok(())
                }
            };
            // Sizes that stay distinct after each becomes its nearest valid N.
            let distinct = |what: &str, used: &[(usize, usize)]| {
                for (i, &(requested, n)) in used.iter().enumerate() {
                    if let Some(&(earlier, _)) = used[..i].iter().find(|u| u.1 == n) {
                        return Err(at(format!(
                            "{what} {earlier} and {requested} both become N = {n}: give values that stay distinct"
                        )));
                    }
                }
                Ok(())
            };
            // Names (samplers, scenes) given once each.
            let given_once = |what: &str, list: &[String]| match list
                .iter()
                .enumerate()
                .find(|(j, s)| list[..*j].contains(s))
            {
                Some((j, name)) => Err(at(format!("{what} `{name}` is given twice (at {j})"))),
                None => Ok(()),
            };
            match figure {
                Figure::RadialSpectra {
                    samplers,
                    n,
                    sets,
                    res,
                    ..
                } => spectra(samplers, *n, 2, *sets, *res)?,
                Figure::Spectrum {
                    sampler,
                    n,
                    sets,
                    res,
                    ..
                } => spectra(std::slice::from_ref(sampler), *n, 2, *sets, *res)?,
                Figure::Ingredients {
                    sampler,
                    integrand,
                    n,
                    sets,
                    res,
                    ..
                } => {
                    spectra(std::slice::from_ref(sampler), *n, 2, *sets, *res)?;
                    let f = integrands::parse(integrand).map_err(|err| at(err.to_string()))?;
                    if f.dim() != 2 || !f.has_fourier() {
                        return Err(at(format!(
                            "integrand `{integrand}` must be 2D with a Fourier transform"
                        )));
                    }
                }
                Figure::Projections {
                    sampler,
                    shear,
                    planes,
                    n,
                    sets,
                    res,
                    ..
                } => {
                    spectra(std::slice::from_ref(sampler), *n, 4, *sets, *res)?;
                    if let Some(shear) = shear {
                        shear_ok(sampler, *n, *shear)?;
                    }
                    planes_ok(planes)?;
                }
                Figure::DesignedProjections {
                    target,
                    n,
                    sets,
                    iterations,
                    planes,
                    res,
                    ..
                } => {
                    counted("n", *n, MAX_DESIGN_POINTS)?;
                    // The design starts from umj at exactly N.
                    registry::build("umj", *n, Some(4), &[])
                        .map_err(|err| at(format!("the umj start at n = {n}: {err}")))?;
                    parse_projections(target, *n).map_err(|err| at(err.to_string()))?;
                    counted("sets", *sets, MAX_DESIGN_SETS)?;
                    if let Some(i) = iterations {
                        counted("iterations", *i, MAX_ITERATIONS)?;
                    }
                    counted("res", *res, MAX_RES)?;
                    planes_ok(planes)?;
                }
                Figure::SceneVariance {
                    scene,
                    sampler,
                    lens_designs,
                    spp,
                    renders,
                    heatmap_spp,
                    reference_spp,
                    ..
                } => {
                    Scene::load(scene).map_err(|err| at(err.to_string()))?;
                    if spp.is_empty() {
                        return Err(at("spp must be non-empty".into()));
                    }
                    for &n in spp.iter().chain([heatmap_spp, reference_spp]) {
                        counted("spp", n, MAX_SPP)?;
                    }
                    let mut used = Vec::new();
                    for &n in spp {
                        let (_, m) = registry::build_nearest(sampler, n, Some(4), &[])
                            .map_err(|err| at(format!("sampler `{sampler}` at n = {n}: {err}")))?;
                        used.push((n, m));
                    }
                    distinct("spp", &used)?;
                    given_once("lens design", lens_designs)?;
                    if lens_designs.contains(sampler) {
                        return Err(at(format!(
                            "lens design `{sampler}` is the sampler itself: its rows are there"
                        )));
                    }
                    for design in lens_designs {
                        for &(n, m) in &used {
                            let (_, k) = registry::build_nearest(design, m, Some(4), &[]).map_err(
                                |err| at(format!("lens design `{design}` at n = {n}: {err}")),
                            )?;
                            if k != m {
                                return Err(at(format!(
                                    "lens design `{design}` takes {k} spp where `{sampler}` \
                                     takes {m} (spp {n}): the rows compare equal spp"
                                )));
                            }
                        }
                    }
                    if !spp.contains(heatmap_spp) {
                        return Err(at(format!(
                            "heatmap_spp = {heatmap_spp} must be one of spp {spp:?}"
                        )));
                    }
                    sampler_at(REFERENCE_SAMPLER, *reference_spp, 4)?;
                    renders_ok(*renders)?;
                }
                Figure::SceneSamplers {
                    file,
                    scenes,
                    samplers,
                    spp,
                    renders,
                    reference_spp,
                } => {
                    if !file.ends_with(".csv") {
                        return Err(at(format!("file `{file}` must end in .csv")));
                    }
                    if scenes.is_empty() || samplers.is_empty() {
                        return Err(at("scenes and samplers must be non-empty".into()));
                    }
                    given_once("scene", scenes)?;
                    given_once("sampler", samplers)?;
                    for scene in scenes {
                        Scene::load(scene).map_err(|err| at(err.to_string()))?;
                    }
                    counted("spp", *spp, MAX_SPP)?;
                    counted("reference_spp", *reference_spp, MAX_SPP)?;
                    for s in samplers {
                        sampler_at(s, *spp, 4)?;
                    }
                    sampler_at(REFERENCE_SAMPLER, *reference_spp, 4)?;
                    renders_ok(*renders)?;
                }
                Figure::ScenePixels {
                    scene,
                    sampler,
                    n,
                    pixels,
                    sets,
                    res,
                    ..
                } => {
                    let loaded = Scene::load(scene).map_err(|err| at(err.to_string()))?;
                    let [w, h] = loaded.camera().resolution();
                    if pixels.is_empty() {
                        return Err(at("pixels must be non-empty".into()));
                    }
                    // (A pixel given twice writes its files twice: refused above.)
                    for p in pixels {
                        if p[0] >= w || p[1] >= h {
                            return Err(at(format!(
                                "pixel {p:?} is outside the {w}x{h} image of `{scene}`"
                            )));
                        }
                    }
                    counted("n", *n, MAX_SPP)?;
                    sampler_at(sampler, *n, 4)?;
                    counted("sets", *sets, MAX_SETS)?;
                    if *res < 8 || *res > MAX_RES {
                        return Err(at(format!("res = {res} must be in 8 ..= {MAX_RES}")));
                    }
                }
                Figure::ShearConvergence {
                    sampler,
                    integrand,
                    shear,
                    n,
                    realizations,
                    ..
                } => {
                    let f = integrands::parse(integrand).map_err(|err| at(err.to_string()))?;
                    if f.dim() != 4 {
                        return Err(at(format!("integrand `{integrand}` must be 4D")));
                    }
                    let mut used = Vec::new();
                    for &m in n {
                        used.push((m, shear_ok(sampler, m, *shear)?));
                    }
                    distinct("n", &used)?;
                    if used.len() < 2 {
                        return Err(at("n must hold at least two N for a slope".into()));
                    }
                    counted("realizations", *realizations, MAX_SETS)?;
                }
            }
        }
        Ok(e)
    }

    /// Draws every figure into `out` (which must exist) and writes its
    /// `README.md`; returns the README's text. `on_figure(index, seconds)`
    /// is called after each figure with its wall time, which the files do
    /// not hold (they are the same for any thread count and machine).
    ///
    /// # Errors
    /// [`ExperimentError::Figure`] naming the figure that failed.
    pub fn run(
        &self,
        file: &str,
        out: &Path,
        on_figure: &dyn Fn(usize, f64),
    ) -> Result<String, ExperimentError> {
        let mut md = format!(
            "{}Command: `cargo run --release -- experiment {file} -o <this folder>` (seed {}).\n\n",
            super::report::heading(&self.name, &self.description),
            self.seed
        );
        for (i, figure) in self.figures.iter().enumerate() {
            let fail = |reason: String| ExperimentError::Figure {
                file: file.to_string(),
                index: i,
                reason,
            };
            let clock = Instant::now();
            md += &self
                .draw(figure, out)
                .map_err(|err| fail(err.to_string()))?;
            md += "\n";
            on_figure(i, clock.elapsed().as_secs_f64());
        }
        let md = super::report::with_kept_notes(out, md);
        write_atomic(&out.join("README.md"), |w| w.write_all(md.as_bytes())).map_err(|err| {
            ExperimentError::Invalid {
                file: file.to_string(),
                reason: format!("writing README.md: {err}"),
            }
        })?;
        Ok(md)
    }

    /// E[N·P_S] of `sets` realizations of a 2D sampler on a res² box; the
    /// N used.
    fn spectrum(
        &self,
        name: &str,
        n: usize,
        sets: usize,
        res: usize,
    ) -> Result<(Spectrum, usize), Box<dyn std::error::Error>> {
        let (sampler, n) = registry::build_nearest(name, n, Some(2), &[])?;
        let spectrum = box_power(sets, res, |r| {
            Ok(sampler.sample(&mut set_rng(self.seed, r as u64))?)
        })?;
        Ok((spectrum, n))
    }

    /// Draws one figure; returns its README entry.
    fn draw(&self, figure: &Figure, out: &Path) -> Result<String, Box<dyn std::error::Error>> {
        match figure {
            Figure::RadialSpectra {
                file,
                samplers,
                n,
                sets,
                res,
            } => {
                let mut series = Vec::new();
                let mut used = Vec::new();
                for name in samplers {
                    let (s, m) = self.spectrum(name, *n, *sets, *res)?;
                    used.push(format!("{name} ({})", size_used(*n, m)));
                    series.push(Series {
                        label: name.clone(),
                        points: radial_profile(&s, METHOD.power_floor(m as f64))
                            .iter()
                            .map(|b| (b.k as f64, b.power))
                            .collect(),
                        reference: false,
                        error_bars: Vec::new(),
                    });
                }
                let plot = LinePlot {
                    title: format!("radially averaged spectra, N ≈ {n} ({sets} sets)"),
                    x_label: "|k|".into(),
                    y_label: "radially averaged N·P_S".into(),
                    log_log: false,
                    series,
                };
                line_plot_png(&plot, &out.join(file))?;
                Ok(format!(
                    "- `{file}`: radially averaged E[N·P_S] of {}, {sets} sets, box {res}².\n",
                    used.join(", ")
                ))
            }
            Figure::Spectrum {
                file,
                sampler,
                n,
                sets,
                res,
            } => {
                let (s, m) = self.spectrum(sampler, *n, *sets, *res)?;
                spectrum_png(
                    &s,
                    &format!("{sampler}, N = {m} ({sets} sets)"),
                    &out.join(file),
                )?;
                Ok(format!(
                    "- `{file}`: E[N·P_S] of {sampler} at {}, {sets} sets, box {res}².\n",
                    size_used(*n, m)
                ))
            }
            Figure::Ingredients {
                prefix,
                sampler,
                integrand,
                n,
                sets,
                res,
            } => {
                let (sampling, m) = self.spectrum(sampler, *n, *sets, *res)?;
                let f = integrands::parse(integrand)?;
                let pf = integrand_power(f.as_ref(), &sampling.freqs);
                let as_spectrum = |power: Vec<f64>| Spectrum {
                    freqs: sampling.freqs,
                    power,
                    sets: sampling.sets,
                };
                let product: Vec<f64> =
                    sampling.power.iter().zip(&pf).map(|(s, f)| s * f).collect();
                let zero = sampling.freqs.zero_index();
                let in_box = crate::sum::sum(
                    product
                        .iter()
                        .enumerate()
                        .filter(|&(i, _)| i != zero)
                        .map(|(_, p)| *p),
                ) / m as f64;
                spectrum_png(
                    &sampling,
                    &format!("sampling power spectrum E[N·P_S], {sampler} N = {m}"),
                    &out.join(format!("{prefix}-sampling.png")),
                )?;
                power_png(
                    &as_spectrum(pf),
                    &format!("integrand power spectrum P_f, {}", f.spec()),
                    ["kx", "ky"],
                    "log10 P_f",
                    &out.join(format!("{prefix}-integrand.png")),
                )?;
                power_png(
                    &as_spectrum(product),
                    "their product E[N·P_S]·P_f (sums to N·Var)",
                    ["kx", "ky"],
                    "log10 E[N·P_S]·P_f",
                    &out.join(format!("{prefix}-product.png")),
                )?;
                Ok(format!(
                    "- `{prefix}-{{sampling,integrand,product}}.png`: E[N·P_S] of {sampler} at {} \
                     ({sets} sets), P_f of `{}` and their product; in-box sum \
                     (1/N) Σ_(k≠0) E[N·P_S]·P_f = {in_box:.4e} on the box {res}².\n",
                    size_used(*n, m),
                    f.spec()
                ))
            }
            Figure::Projections {
                prefix,
                sampler,
                shear,
                planes,
                n,
                sets,
                res,
            } => {
                let (s, m) = registry::build_nearest(sampler, *n, Some(4), &[])?;
                let sheared = shear.map(|a| Sheared::new(s.as_ref(), a)).transpose()?;
                let drawn: &dyn Sampler = match &sheared {
                    Some(t) => t,
                    None => s.as_ref(),
                };
                let what = match shear {
                    Some([a, b]) => format!("{sampler} sheared by (a, b) = ({a}, {b})"),
                    None => sampler.clone(),
                };
                let title = format!("{what}, N = {m}");
                plane_pngs(out, prefix, &title, planes, (*sets, *res), &|r| {
                    drawn.sample(&mut set_rng(self.seed, r as u64))
                })?;
                Ok(format!(
                    "- `{}`: E[N·P_S] of the {} projections of {what} at {}, {sets} sets, box \
                     {res}².\n",
                    plane_files(prefix, planes),
                    planes.join(", "),
                    size_used(*n, m)
                ))
            }
            Figure::DesignedProjections {
                prefix,
                target,
                n,
                sets,
                iterations,
                planes,
                res,
            } => {
                let design = design_projections(
                    &ProjectionRequest {
                        n: *n,
                        target: target.clone(),
                        sets: *sets,
                        iters: *iterations,
                        rel_tol: None,
                        seed: self.seed,
                        init: None,
                        init_params: Vec::new(),
                    },
                    &|_, _| {},
                )?;
                let title = format!("designed 4D sets, N = {n}");
                plane_pngs(out, prefix, &title, planes, (*sets, *res), &|r| {
                    Ok(design.points[r].clone())
                })?;
                let mut terms = String::from(
                    "| term | weight | loss of the umj starts | loss of the designs |\n|---|---|---|---|\n",
                );
                for t in &design.terms {
                    terms += &format!(
                        "| `{}` | {} | {:.4e} | {:.4e} |\n",
                        t.term, t.weight, t.loss_before, t.loss_after
                    );
                }
                Ok(format!(
                    "- `{}`: E[N·P_S] of the {} projections of {sets} 4D sets of \
                     N = {n} designed from umj for the projection target `{target}` (the seed's \
                     design principle: a target spectrum per projection), {} iterations at most; \
                     closest pair over the hexagonal spacing: XY {:.2}, UV {:.2}.\n\n{terms}",
                    plane_files(prefix, planes),
                    planes.join(", "),
                    design.max_iterations,
                    design.closest_pair_over_hexagonal.xy,
                    design.closest_pair_over_hexagonal.uv
                ))
            }
            Figure::SceneVariance {
                prefix,
                scene,
                sampler,
                lens_designs,
                spp,
                renders,
                heatmap_spp,
                reference_spp,
            } => scene_variance(
                self.seed,
                out,
                prefix,
                scene,
                (sampler, lens_designs),
                spp,
                *renders,
                (*heatmap_spp, *reference_spp),
            ),
            Figure::SceneSamplers {
                file,
                scenes,
                samplers,
                spp,
                renders,
                reference_spp,
            } => scene_samplers(
                self.seed,
                out,
                file,
                scenes,
                samplers,
                *spp,
                *renders,
                *reference_spp,
            ),
            Figure::ScenePixels {
                prefix,
                scene,
                sampler,
                n,
                pixels,
                sets,
                res,
            } => scene_pixels(
                self.seed,
                out,
                prefix,
                scene,
                sampler,
                *n,
                pixels,
                (*sets, *res),
            ),
            Figure::ShearConvergence {
                file,
                sampler,
                integrand,
                shear,
                n,
                realizations,
            } => {
                let f = integrands::parse(integrand)?;
                let (mut before, mut after) = (Vec::new(), Vec::new());
                let mut rows = String::new();
                for &requested in n {
                    let (s, m) = registry::build_nearest(sampler, requested, Some(4), &[])?;
                    let sheared = Sheared::new(s.as_ref(), *shear)?;
                    // Each N its own stream, as converge's levels.
                    let seed = crate::rng::level_seed(self.seed, m);
                    let measure = |s: &dyn Sampler| {
                        empirical_shifting(
                            f.as_ref(),
                            *realizations,
                            seed.wrapping_add(1),
                            &[0, 1],
                            |r| {
                                s.sample(&mut set_rng(seed, r as u64))
                                    .map_err(VarianceError::from)
                            },
                        )
                    };
                    let (b, a) = (measure(s.as_ref())?, measure(&sheared)?);
                    rows += &format!(
                        "| {m} | {:.4e} ± {:.1e} | {:.4e} ± {:.1e} | {:.2}× |\n",
                        b.variance,
                        b.stderr,
                        a.variance,
                        a.stderr,
                        b.variance / a.variance
                    );
                    before.push((m as f64, b.variance));
                    after.push((m as f64, a.variance));
                }
                let slope = |v: &[(f64, f64)]| -> Result<f64, Box<dyn std::error::Error>> {
                    let (x, y): (Vec<f64>, Vec<f64>) = v.iter().copied().unzip();
                    Ok(fit_slope(&x, &y)?.slope)
                };
                let (sb, sa) = (slope(&before)?, slope(&after)?);
                let plot = LinePlot {
                    title: format!("{sampler} on {}: variance vs N", f.spec()),
                    x_label: "N".into(),
                    y_label: format!("variance ({realizations} realizations)"),
                    log_log: true,
                    series: vec![
                        Series {
                            label: format!("unsheared (slope {sb:.2})"),
                            points: before,
                            reference: false,
                            error_bars: Vec::new(),
                        },
                        Series {
                            label: format!(
                                "sheared a = {}, b = {} (slope {sa:.2})",
                                shear[0], shear[1]
                            ),
                            points: after,
                            reference: false,
                            error_bars: Vec::new(),
                        },
                    ],
                };
                line_plot_png(&plot, &out.join(file))?;
                Ok(format!(
                    "- `{file}`: {sampler} on `{}`, estimator shifted in (x, y) only (each N \
                     draws its sets and shifts from its own seed, derived from {}), {realizations} \
                     realizations per N; slope {sb:.2} unsheared, {sa:.2} sheared \
                     by (a, b) = ({}, {}).\n\n\
                     | N | unsheared | sheared | ratio |\n|---|---|---|---|\n{rows}",
                    f.spec(),
                    self.seed,
                    shear[0],
                    shear[1]
                ))
            }
        }
    }
}

/// "N = m" for the N a sampler used, with the request beside it when the
/// sampler's nearest valid N differs (a README must not hide the change).
fn size_used(requested: usize, used: usize) -> String {
    if requested == used {
        format!("N = {used}")
    } else {
        format!("N = {used} ({requested} requested: the sampler's nearest valid N)")
    }
}

/// The projection pictures' names: `PREFIX-xu.png` for one plane,
/// `PREFIX-{xu,yv}.png` for several.
fn plane_files(prefix: &str, planes: &[String]) -> String {
    match planes {
        [one] => format!("{prefix}-{one}.png"),
        _ => format!("{prefix}-{{{}}}.png", planes.join(",")),
    }
}
