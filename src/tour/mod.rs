//! The design loop end to end on built-in defaults — the project's main
//! job: classic samplers against an optimized set with the three variance
//! predictors side by side, spectra and radial profiles, a design for the
//! unit square, a shear search on a defocus pixel, the ray-traced scene's
//! per-pixel warp, and the spectrum's speed against its error. [`run_tour`] computes it ([`Tour`], serializable);
//! [`html::render_tour`] writes the page.

pub mod html;

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use crate::integrands;
use crate::optimize::shear::Sheared;
use crate::points::PointSet;
use crate::registry;
use crate::report::plot::{LinePlot, Series, line_plot_png, spectrum_png};
use crate::report::png::{render_points, save_png};
use crate::samplers::Sampler;
use crate::spectrum::radial::radial_profile;
use crate::spectrum::{FrequencyBox, Method, expected_power};
use crate::square::Family;
use crate::variance::{DEFAULT_SHIFT_SEED, VarianceError, empirical, fourier, spatial};

/// What can stop the tour.
#[derive(Debug, thiserror::Error)]
pub enum TourError {
    /// A library error, with the step it happened in.
    #[error("{step}: {message}")]
    Step {
        /// The tour's step.
        step: &'static str,
        /// The error.
        message: String,
    },
}

fn at<E: std::fmt::Display>(step: &'static str) -> impl Fn(E) -> TourError {
    move |e| TourError::Step {
        step,
        message: e.to_string(),
    }
}

/// The tour's knobs (the defaults run in well under a minute on 2 cores).
#[derive(Debug, Clone, Serialize)]
pub struct TourOptions {
    /// Points per set of section 1.
    pub n: usize,
    /// Sets per sampler.
    pub sets: usize,
    /// Seed of everything.
    pub seed: u64,
    /// Integrand of section 1.
    pub integrand: String,
    /// Defocus pixel of section 3.
    pub pixel: String,
    /// Where the pictures and data go.
    pub folder: PathBuf,
}

impl Default for TourOptions {
    fn default() -> Self {
        TourOptions {
            n: 256,
            sets: 16,
            seed: 0,
            integrand: "disk:r=0.3".into(),
            pixel: "defocus:shape=disk,size=0.3,c=0.45".into(),
            folder: PathBuf::from("out/report"),
        }
    }
}

/// A picture: its file beside the page and a caption.
#[derive(Debug, Clone, Serialize)]
pub struct Figure {
    /// File name in the report folder.
    pub file: String,
    /// Caption.
    pub caption: String,
}

/// One sampler's row of section 1.
#[derive(Debug, Clone, Serialize)]
pub struct PredictRow {
    /// Sampler.
    pub sampler: String,
    /// N used.
    pub n: usize,
    /// Fourier form.
    pub fourier: f64,
    /// Its truncation bound.
    pub truncation_bound: f64,
    /// Spatial form.
    pub spatial: f64,
    /// Its standard error over the sets.
    pub spatial_stderr: f64,
    /// Empirical variance.
    pub empirical: f64,
    /// 95% CI, low end.
    pub ci_low: f64,
    /// 95% CI, high end.
    pub ci_high: f64,
    /// Spatial variance over jitter's.
    pub vs_jitter: f64,
    /// Drawing time per set.
    pub seconds_per_set: f64,
    /// The lowest variance of the table.
    pub best: bool,
}

/// Section 1.
#[derive(Debug, Clone, Serialize)]
pub struct PredictSection {
    /// The integrand.
    pub integrand: String,
    /// N of every sampler: the nearest N to the requested one that jitter
    /// allows (a square).
    pub n: usize,
    /// The requested N (`-n`).
    pub requested_n: usize,
    /// Sets per sampler.
    pub sets: usize,
    /// Fourier box half-width.
    pub half: usize,
    /// Empirical realizations.
    pub realizations: usize,
    /// Rows.
    pub rows: Vec<PredictRow>,
    /// Pictures of one set each.
    pub points: Vec<Figure>,
    /// Spectra and the radial profiles.
    pub spectra: Vec<Figure>,
    /// Commands.
    pub commands: Vec<String>,
}

/// One row of section 2.
#[derive(Debug, Clone, Serialize)]
pub struct SquareRow {
    /// Sampler or design.
    pub name: String,
    /// Half-plane family MSE.
    pub halfplanes: f64,
    /// Gaussian family MSE.
    pub gaussians: f64,
    /// Closest pair over the hexagonal spacing.
    pub closest: f64,
    /// The lowest half-plane MSE.
    pub best: bool,
}

/// Section 2.
#[derive(Debug, Clone, Serialize)]
pub struct SquareSection {
    /// N.
    pub n: usize,
    /// Design target.
    pub target: String,
    /// Designed sets.
    pub sets: usize,
    /// Wall time of the design, all sets (designed in parallel).
    pub seconds: f64,
    /// Members per family.
    pub members: usize,
    /// Rows.
    pub rows: Vec<SquareRow>,
    /// Pictures.
    pub pictures: Vec<Figure>,
    /// Commands.
    pub commands: Vec<String>,
}

impl SquareSection {
    /// The design's half-plane MSE over that of the sampler `name` (None
    /// if the section has no such row).
    pub fn halfplanes_against(&self, name: &str) -> Option<f64> {
        let other = self.rows.iter().find(|r| r.name == name)?;
        Some(self.rows.first()?.halfplanes / other.halfplanes)
    }
}

/// Section 3.
#[derive(Debug, Clone, Serialize)]
pub struct ShearSection {
    /// The pixel.
    pub integrand: String,
    /// N.
    pub n: usize,
    /// Found shear.
    pub shear: [f64; 2],
    /// Spectral start.
    pub initial: [f64; 2],
    /// J there.
    pub initial_value: f64,
    /// Analytic shear (−c, −c) of each layer of the light field (two for
    /// `layers`: a double wedge, which no single shear follows).
    pub analytic: Vec<[f64; 2]>,
    /// J at (0, 0).
    pub unsheared: f64,
    /// J at the optimum.
    pub optimum: f64,
    /// Relative truncation bound.
    pub truncation_bound: f64,
    /// unsheared / optimum.
    pub reduction: f64,
    /// Empirical check before.
    pub check_before: f64,
    /// Its CI.
    pub check_before_low: f64,
    /// Its CI.
    pub check_before_high: f64,
    /// Empirical check after.
    pub check_after: f64,
    /// Its CI.
    pub check_after_low: f64,
    /// Its CI.
    pub check_after_high: f64,
    /// Search time.
    pub seconds: f64,
    /// XU/YV spectra before and after.
    pub spectra: Vec<Figure>,
    /// Commands.
    pub commands: Vec<String>,
}

/// One row of the scene section.
#[derive(Debug, Clone, Serialize)]
pub struct SceneRow {
    /// What the pixels' sets were.
    pub method: String,
    /// Mean over pixels of the per-pixel variance.
    pub mean_variance: f64,
    /// Its standard error ([`crate::scene::render::VarianceMaps::mean_variance`];
    /// None below 4 renders).
    pub mean_variance_stderr: Option<f64>,
    /// Wall time (analysis, choice and renders).
    pub seconds: f64,
}

/// The scene section: ray-traced pixels as 4D integrands.
#[derive(Debug, Clone, Serialize)]
pub struct SceneSection {
    /// Built-in scene.
    pub scene: String,
    /// Samples per pixel.
    pub spp: usize,
    /// Independent renders behind each variance.
    pub renders: usize,
    /// Pixels seeing one depth, and two or more (the double wedge).
    pub single: usize,
    /// See `single`.
    pub edge: usize,
    /// Rows: unsheared and the per-pixel warp.
    pub rows: Vec<SceneRow>,
    /// none / warp mean variance.
    pub reduction: f64,
    /// The image and the variance heat maps.
    pub pictures: Vec<Figure>,
    /// Commands.
    pub commands: Vec<String>,
}

/// One row of section 4.
#[derive(Debug, Clone, Serialize)]
pub struct SpeedRow {
    /// Method.
    pub method: String,
    /// Wall time.
    pub seconds: f64,
    /// Largest error against the direct sums.
    pub max_error: f64,
    /// Direct time / this time.
    pub speedup: f64,
}

/// Section 4.
#[derive(Debug, Clone, Serialize)]
pub struct SpeedSection {
    /// N.
    pub n: usize,
    /// Sets.
    pub sets: usize,
    /// Box half-width.
    pub half: usize,
    /// Rows.
    pub rows: Vec<SpeedRow>,
    /// Commands.
    pub commands: Vec<String>,
}

/// The whole tour.
#[derive(Debug, Clone, Serialize)]
pub struct Tour {
    /// The options it ran with.
    pub options: TourOptions,
    /// Section 1.
    pub predict: PredictSection,
    /// Section 2.
    pub square: SquareSection,
    /// Section 3.
    pub shear: ShearSection,
    /// The scene.
    pub scene: SceneSection,
    /// Section 4.
    pub speed: SpeedSection,
    /// Total wall time.
    pub seconds: f64,
}

impl TourOptions {
    /// The integrand is a 2D one (the sampler comparison) and the pixel a
    /// light field (the shear search), checked before any work is done or
    /// any folder made.
    ///
    /// # Errors
    /// [`TourError`] naming the option and what it must be.
    pub fn check(&self) -> Result<(), TourError> {
        let f = integrands::parse(&self.integrand).map_err(at("the integrand (--integrand)"))?;
        if f.dim() != 2 {
            return Err(at("the integrand (--integrand)")(format!(
                "`{}` is {}D; the sampler comparison takes a 2D integrand",
                self.integrand,
                f.dim()
            )));
        }
        // A constant has no error to compare (every ratio 0/0).
        let constant = |option: &'static str, spec: &str| {
            Err(at(option)(format!(
                "`{spec}` is constant (variance 0): every point set integrates it exactly, so \
                 there is nothing to compare; give one that varies"
            )))
        };
        if f.variance() == 0.0 {
            return constant("the integrand (--integrand)", &self.integrand);
        }
        // Section 1's exact spatial form is O(N²) per set.
        let pairs = SECTION_ONE_SAMPLERS as f64
            * self.sets as f64
            * crate::variance::pair_evaluations(f.as_ref(), self.n);
        if pairs > REPORT_PAIRS {
            let hours = crate::variance::estimated_seconds(f.as_ref(), &[(self.n, self.sets)])
                .map_or(f64::NAN, |s| s * SECTION_ONE_SAMPLERS as f64 / 3600.0);
            return Err(at("the sampler comparison (-n, --sets)")(format!(
                "-n {} with --sets {} costs {pairs:.1e} pair evaluations of the exact spatial \
                 form ({SECTION_ONE_SAMPLERS} samplers x sets x N(N-1)/2, within the \
                 autocovariance's support), about {hours:.0} h here, over the report's \
                 {REPORT_PAIRS:.1e}; lower -n or --sets (predict --method expected handles a \
                 large N alone)",
                self.n, self.sets,
            )));
        }
        let pixel = integrands::parse(&self.pixel).map_err(at("the pixel (--pixel)"))?;
        if pixel.light_field().is_none() {
            return Err(at("the pixel (--pixel)")(format!(
                "`{}` is not a light field; the shear search takes defocus:… or layers:…",
                self.pixel
            )));
        }
        if pixel.variance() == 0.0 {
            return constant("the pixel (--pixel)", &self.pixel);
        }
        Ok(())
    }
}

/// Samplers in section 1's table.
const SECTION_ONE_SAMPLERS: usize = 6;

/// Pair evaluations of section 1's spatial form a report may cost (2^34;
/// -n 16384 with 16 sets fits: 1.3e10, about 13 minutes on the default
/// disk on 2 cores).
const REPORT_PAIRS: f64 = 17_179_869_184.0;

fn draw(sampler: &dyn Sampler, seed: u64, sets: usize) -> Result<Vec<PointSet>, TourError> {
    crate::samplers::generate_sets(sampler, seed, sets, &|_| {}).map_err(at("drawing sets"))
}

/// Runs the tour, writing its pictures into `options.folder`;
/// `progress(step)` names each step as it starts.
///
/// # Errors
/// [`TourError`] naming the step that failed.
pub fn run_tour(options: &TourOptions, progress: &dyn Fn(&str)) -> Result<Tour, TourError> {
    let clock = Instant::now();
    options.check()?;
    std::fs::create_dir_all(&options.folder)
        .map_err(|e| format!("{}: {e}", options.folder.display()))
        .map_err(at("creating the report folder"))?;
    progress("samplers and predictors");
    let predict = predict_section(options)?;
    progress("a design for the square");
    let square = square_section(options)?;
    progress("shear search");
    let shear = shear_section(options)?;
    progress("the scene");
    let scene = scene_section(options)?;
    progress("speed against error");
    let speed = speed_section(options)?;
    Ok(Tour {
        options: options.clone(),
        predict,
        square,
        shear,
        scene,
        speed,
        seconds: clock.elapsed().as_secs_f64(),
    })
}

fn predict_section(o: &TourOptions) -> Result<PredictSection, TourError> {
    let f = integrands::parse(&o.integrand).map_err(at("the integrand"))?;
    let half = 127;
    let realizations = 4000;
    let names: [&str; SECTION_ONE_SAMPLERS] = [
        "random",
        "jitter",
        "cmj",
        "sobol",
        "poisson-disk",
        "blue-noise",
    ];
    let mut rows = Vec::new();
    let mut points = Vec::new();
    let mut spectra = Vec::new();
    let mut profiles = Vec::new();
    let freqs = FrequencyBox::from_resolution(2, 64);
    // One N for every row: the nearest N jitter allows (a square), which
    // every other sampler of the table takes as it is; a comparison at
    // -n 17 compared random at 17 with jitter at 16.
    let (_, n) =
        registry::build_nearest("jitter", o.n, Some(2), &[]).map_err(at("building a sampler"))?;
    for name in names {
        let sampler = registry::build(name, n, Some(2), &[]).map_err(at("building a sampler"))?;
        let start = Instant::now();
        let sets = draw(sampler.as_ref(), o.seed, o.sets)?;
        let seconds_per_set = start.elapsed().as_secs_f64() / o.sets as f64;
        let lend = |r: usize| Ok::<_, VarianceError>(sets[r].clone());
        let fe = fourier(f.as_ref(), half, 1e-10, sets.len(), lend).map_err(at("Fourier form"))?;
        let se = spatial(f.as_ref(), sets.len(), lend).map_err(at("spatial form"))?;
        // As `predict FILE --realizations R` on these sets (cyclic, the
        // default shift seed): the printed commands give these numbers.
        let ee = empirical(f.as_ref(), realizations, DEFAULT_SHIFT_SEED, |r| {
            Ok::<_, VarianceError>(&sets[r % sets.len()])
        })
        .map_err(at("empirical form"))?;
        rows.push(PredictRow {
            sampler: name.into(),
            n,
            fourier: fe.variance,
            truncation_bound: fe.truncation_bound,
            spatial: se.variance,
            spatial_stderr: se.stderr,
            empirical: ee.variance,
            ci_low: ee.ci_low,
            ci_high: ee.ci_high,
            vs_jitter: 0.0,
            seconds_per_set,
            best: false,
        });
        let file = format!("points-{name}.png");
        let img = render_points(&sets[0], [0, 1], 320).map_err(at("drawing points"))?;
        save_png(&img, &o.folder.join(&file)).map_err(at("writing a picture"))?;
        points.push(Figure {
            file,
            caption: format!("{name}, N = {n}"),
        });
        let method = Method::Fast { tolerance: 1e-9 };
        let spectrum = expected_power(
            freqs,
            method,
            sets.len(),
            |r| Ok::<_, crate::spectrum::SpectrumError>(sets[r].clone()),
            &|| {},
        )
        .map_err(at("spectrum"))?;
        let floor = method.power_floor(n as f64);
        if matches!(name, "jitter" | "cmj" | "blue-noise") {
            let file = format!("spectrum-{name}.png");
            spectrum_png(&spectrum, &format!("{name} N={n}"), &o.folder.join(&file))
                .map_err(at("writing a picture"))?;
            spectra.push(Figure {
                file,
                caption: format!("{name}: E[N·P_S(k)], |k| < 32"),
            });
        }
        profiles.push(Series {
            label: name.into(),
            points: radial_profile(&spectrum, floor)
                .iter()
                .filter(|b| b.k > 0)
                .map(|b| (b.k as f64, b.power))
                .collect(),
            reference: false,
            error_bars: Vec::new(),
        });
    }
    let jitter = rows[1].spatial;
    let best = rows.iter().map(|r| r.spatial).fold(f64::INFINITY, f64::min);
    for r in &mut rows {
        r.vs_jitter = r.spatial / jitter;
        r.best = r.spatial == best;
    }
    let file = "radial-profiles.png".to_string();
    line_plot_png(
        &LinePlot {
            title: format!("radial power, N = {}", n),
            x_label: "|k|".into(),
            y_label: "E[N P_S]".into(),
            log_log: false,
            series: profiles,
        },
        &o.folder.join(&file),
    )
    .map_err(at("writing a picture"))?;
    spectra.push(Figure {
        file,
        caption: "radial averages".into(),
    });
    let commands = vec![
        format!(
            "varspec sample cmj -n {} --sets {} --seed {} -o cmj.csv",
            n, o.sets, o.seed
        ),
        format!(
            "varspec predict cmj.csv --integrand {} --res {} --realizations {realizations}",
            o.integrand,
            2 * half + 1
        ),
        format!(
            "varspec sample blue-noise -n {} --sets {} --seed {} -o bn.csv",
            n, o.sets, o.seed
        ),
        format!(
            "varspec predict bn.csv --integrand {} --res {} --realizations {realizations}",
            o.integrand,
            2 * half + 1
        ),
        format!(
            "varspec spectrum --sampler jitter -n {} --sets {} --seed {} --res 64 --png s.png --radial r.csv",
            n, o.sets, o.seed
        ),
    ];
    Ok(PredictSection {
        integrand: f.spec(),
        n,
        requested_n: o.n,
        sets: o.sets,
        half,
        realizations,
        rows,
        points,
        spectra,
        commands,
    })
}

fn square_section(o: &TourOptions) -> Result<SquareSection, TourError> {
    use crate::design::square::{SquareRequest, design_on_square};
    let n = 256;
    let target = "halfplanes+gaussians+16*blue";
    let request = SquareRequest {
        n,
        target: target.into(),
        sets: 2,
        iters: None,
        seed: o.seed,
        init: None,
        init_params: Vec::new(),
        members: 1024,
        score_seed: 1,
    };
    // As `optimize points --domain square` runs it, so the printed
    // commands give these numbers.
    let design = design_on_square(&request, &|_, _| {}).map_err(at("square design"))?;
    let gaussians = Family::parse("gaussians").map_err(at("family"))?.spec();
    let mse = |v: &serde_json::Value, family: &str| v[family]["mse"].as_f64().unwrap_or(f64::NAN);
    // The design first, then the classic samplers.
    let order = std::iter::once("optimized").chain(
        design
            .comparison
            .keys()
            .map(String::as_str)
            .filter(|k| *k != "optimized"),
    );
    let mut rows: Vec<SquareRow> = order
        .filter_map(|name| design.comparison.get(name).map(|v| (name.to_string(), v)))
        .map(|(name, v)| SquareRow {
            name: if name == "optimized" {
                format!("designed ({target})")
            } else {
                name
            },
            halfplanes: mse(v, "halfplanes"),
            gaussians: mse(v, &gaussians),
            closest: v["closest_pair_over_hexagonal"]
                .as_f64()
                .unwrap_or(f64::NAN),
            best: false,
        })
        .collect();
    let best = rows
        .iter()
        .map(|r| r.halfplanes)
        .fold(f64::INFINITY, f64::min);
    for r in &mut rows {
        r.best = r.halfplanes == best;
    }
    let file = "square-design.png".to_string();
    let img = render_points(&design.points[0], [0, 1], 320).map_err(at("drawing points"))?;
    save_png(&img, &o.folder.join(&file)).map_err(at("writing a picture"))?;
    Ok(SquareSection {
        n,
        target: target.into(),
        sets: request.sets,
        seconds: design.run.seconds,
        members: request.members,
        rows,
        pictures: vec![Figure {
            file,
            caption: format!("designed for the square, N = {n}"),
        }],
        commands: vec![
            format!(
                "varspec optimize points --domain square -n {n} --target '{target}' --sets {} --seed {} --score-seed {} -o sq.csv --report sq.json",
                request.sets, request.seed, request.score_seed
            ),
            format!(
                "varspec predict --family halfplanes sq.csv --members {} --seed {}",
                request.members, request.score_seed
            ),
        ],
    })
}

fn shear_section(o: &TourOptions) -> Result<ShearSection, TourError> {
    let n = 256;
    let f = integrands::parse(&o.pixel).map_err(at("the pixel"))?;
    let analytic = f
        .light_field()
        .map(|l| l.layer_shears())
        .ok_or_else(|| at("the pixel")("not a light field"))?;
    let umj = registry::build("umj", n, Some(4), &[]).map_err(at("umj"))?;
    // The search and its check as `optimize shear` runs them (defaults:
    // range 2 or wider, 4000 check realizations), so the printed command
    // gives these numbers.
    let run = crate::optimize::shear::checked::search_and_check(
        f.as_ref(),
        umj.as_ref(),
        "umj",
        o.seed,
        None,
        4000,
        &|_| {},
    )
    .map_err(at("shear search"))?;
    let (found, seconds) = (&run.found, run.search_seconds);
    let (before, after) = run
        .check
        .clone()
        .ok_or_else(|| at("shear check")("no check was run"))?;
    let truncation_bound = run.report["objective"]["truncation_bound"]
        .as_f64()
        .unwrap_or(f64::NAN);
    let mut spectra = Vec::new();
    let freqs = FrequencyBox::from_resolution(2, 64);
    for (label, shear) in [("before", [0.0, 0.0]), ("after", found.shear)] {
        let sheared = Sheared::new(umj.as_ref(), shear).map_err(at("shearing"))?;
        let sets = draw(&sheared, o.seed, 16)?;
        for (name, dims) in [("xu", [0usize, 2]), ("yv", [1, 3])] {
            let spectrum = expected_power(
                freqs,
                Method::Fast { tolerance: 1e-9 },
                sets.len(),
                |r| {
                    sets[r].projected(&dims).map_err(|e| {
                        crate::spectrum::SpectrumError::Realization {
                            index: r,
                            message: format!("projection onto {dims:?}: {e}"),
                        }
                    })
                },
                &|| {},
            )
            .map_err(at("projection spectrum"))?;
            let file = format!("shear-{name}-{label}.png");
            spectrum_png(
                &spectrum,
                &format!("umj {name}, {label} shear"),
                &o.folder.join(&file),
            )
            .map_err(at("writing a picture"))?;
            spectra.push(Figure {
                file,
                caption: format!("{} projection, {label}", name.to_uppercase()),
            });
        }
    }
    Ok(ShearSection {
        integrand: f.spec(),
        n,
        shear: found.shear,
        initial: found.initial.0,
        initial_value: found.initial.1,
        analytic,
        unsheared: found.unsheared.value,
        optimum: found.optimum.value,
        truncation_bound,
        reduction: found.unsheared.value / found.optimum.value,
        check_before: before.variance,
        check_before_low: before.ci_low,
        check_before_high: before.ci_high,
        check_after: after.variance,
        check_after_low: after.ci_low,
        check_after_high: after.ci_high,
        seconds,
        spectra,
        commands: vec![format!(
            "varspec optimize shear -n {n} --integrand {} --seed {} --png-prefix shear --json",
            o.pixel, o.seed
        )],
    })
}

fn scene_section(o: &TourOptions) -> Result<SceneSection, TourError> {
    use crate::scene::Scene;
    use crate::scene::analysis::PixelKind;
    use crate::scene::render::{ShearPolicy, analyse, pixel_shears, render_variance};
    let (spp, renders) = (64, 4);
    let scene = Scene::load("dof").map_err(at("the scene"))?;
    let umj = registry::build("umj", spp, Some(4), &[]).map_err(at("umj"))?;
    let analysis = analyse(&scene);
    let count = |k: PixelKind| analysis.iter().filter(|p| p.kind == k).count();
    let mut rows = Vec::new();
    let mut pictures = Vec::new();
    for (method, file, policy) in [
        (
            "unsheared umj",
            "scene-variance-none.png",
            ShearPolicy::None,
        ),
        (
            "per-pixel warp",
            "scene-variance-warp.png",
            ShearPolicy::Analytic,
        ),
    ] {
        let start = Instant::now();
        let shears = pixel_shears(&scene, umj.as_ref(), policy, &analysis, o.seed, &|| {})
            .map_err(at("per-pixel shears"))?;
        let maps = render_variance(&scene, umj.as_ref(), &shears, o.seed, renders, &|| {})
            .map_err(at("rendering"))?;
        let seconds = start.elapsed().as_secs_f64();
        if rows.is_empty() {
            maps.mean
                .write_png(1.0, &o.folder.join("scene.png"))
                .map_err(at("writing a picture"))?;
            pictures.push(Figure {
                file: "scene.png".into(),
                caption: format!("dof, mean of {renders} renders at {spp} spp"),
            });
        }
        maps.variance
            .write_variance_png(
                &format!("{method}: per-pixel variance"),
                Some((-6.0, -2.0)),
                &o.folder.join(file),
            )
            .map_err(at("writing a picture"))?;
        pictures.push(Figure {
            file: file.into(),
            caption: format!("{method}: per-pixel variance over {renders} renders"),
        });
        let (mean_variance, mean_variance_stderr) = maps.mean_variance();
        rows.push(SceneRow {
            method: method.into(),
            mean_variance,
            mean_variance_stderr,
            seconds,
        });
    }
    Ok(SceneSection {
        scene: scene.name().into(),
        spp,
        renders,
        single: count(PixelKind::Single),
        edge: count(PixelKind::Edge),
        reduction: rows[0].mean_variance / rows[1].mean_variance,
        rows,
        pictures,
        commands: vec![
            format!(
                "varspec render dof --spp {spp} --renders {renders} --seed {} --variance-png none.png",
                o.seed
            ),
            format!(
                "varspec render dof --spp {spp} --renders {renders} --seed {} --shear analytic --variance-png warp.png --shear-png slope.png",
                o.seed
            ),
        ],
    })
}

fn speed_section(o: &TourOptions) -> Result<SpeedSection, TourError> {
    let (n, sets, half) = (1024, 8, 64);
    let jitter = registry::build("jitter", n, Some(2), &[]).map_err(at("jitter"))?;
    let drawn = draw(jitter.as_ref(), o.seed, sets)?;
    let freqs = FrequencyBox { dim: 2, half };
    let run = |method: Method| -> Result<(f64, Vec<f64>), TourError> {
        let start = Instant::now();
        let s = expected_power(
            freqs,
            method,
            sets,
            |r| Ok::<_, crate::spectrum::SpectrumError>(drawn[r].clone()),
            &|| {},
        )
        .map_err(at("spectrum"))?;
        Ok((start.elapsed().as_secs_f64(), s.power))
    };
    let (direct_time, exact) = run(Method::Direct)?;
    let mut rows = vec![SpeedRow {
        method: "direct (exact)".into(),
        seconds: direct_time,
        max_error: 0.0,
        speedup: 1.0,
    }];
    for tolerance in [1e-3, 1e-6, 1e-9, 1e-12] {
        let (t, power) = run(Method::Fast { tolerance })?;
        let max_error = power
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        rows.push(SpeedRow {
            method: format!("NUFFT, tolerance {tolerance:e}"),
            seconds: t,
            max_error,
            speedup: direct_time / t,
        });
    }
    Ok(SpeedSection {
        n,
        sets,
        half,
        rows,
        // The two spectra the first rows compare (their CSVs give the
        // maximum error), then the fuller benchmark.
        commands: vec![
            format!(
                "varspec spectrum --sampler jitter -n {n} --sets {sets} --seed {} --res {} \
                 --method direct --csv exact.csv",
                o.seed,
                2 * half + 1
            ),
            format!(
                "varspec spectrum --sampler jitter -n {n} --sets {sets} --seed {} --res {} \
                 --tol 1e-6 --csv fast.csv",
                o.seed,
                2 * half + 1
            ),
            "varspec bench spectrum".into(),
        ],
    })
}

/// Writes `tour` as `report.json`, `variances.csv` and `square.csv` into
/// `folder`.
///
/// # Errors
/// [`TourError`] naming the file.
pub fn write_data(tour: &Tour, folder: &Path) -> Result<(), TourError> {
    let json = serde_json::to_string_pretty(tour).map_err(at("report.json"))?;
    crate::io::write_atomic(&folder.join("report.json"), |w| {
        w.write_all(json.as_bytes())
    })
    .map_err(at("report.json"))?;
    let mut bytes = Vec::new();
    {
        let mut w = csv::Writer::from_writer(&mut bytes);
        for row in &tour.predict.rows {
            w.serialize(row).map_err(at("variances.csv"))?;
        }
        w.flush().map_err(at("variances.csv"))?;
    }
    crate::io::write_atomic(&folder.join("variances.csv"), |w| w.write_all(&bytes))
        .map_err(at("variances.csv"))?;
    let mut bytes = Vec::new();
    {
        let mut w = csv::Writer::from_writer(&mut bytes);
        for row in &tour.square.rows {
            w.serialize(row).map_err(at("square.csv"))?;
        }
        w.flush().map_err(at("square.csv"))?;
    }
    crate::io::write_atomic(&folder.join("square.csv"), |w| w.write_all(&bytes))
        .map_err(at("square.csv"))
}
