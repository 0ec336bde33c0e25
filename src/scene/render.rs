//! Rendering with any 4D sampler of the registry: each pixel draws its own
//! realization, seeded by (seed, render, pixel), so images are identical for
//! any thread count; the pixel value is the sample mean of f(x, y, u, v),
//! optionally after shearing the set by a per-pixel (a, b) (x′ = x + a·u,
//! y′ = y + b·v mod 1, which keeps every point uniform: the estimate stays
//! unbiased for any shear).

use rayon::prelude::*;

use super::Scene;
use super::analysis::{MIN_WARP_SLOPE, PixelAnalysis, PixelKind, SampleShear, analyse_pixel};
use super::image::GreyImage;
use crate::rng::set_rng;
use crate::samplers::{Sampler, SamplerError};
use crate::sum::{NeumaierSum, RunningMoments};

/// How each pixel's sample set is sheared.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShearPolicy {
    /// No shear.
    None,
    /// One shear for every pixel.
    Global(SampleShear),
    /// The shear the pixel's analysis gives ([`PixelAnalysis::shear`]):
    /// the warp of the depth its centre ray sees.
    Analytic,
    /// The analytic shear where the analysis is unambiguous (one depth:
    /// there the warp of its slope is the light field's alignment to first
    /// order), and on occlusion edges (two depths, which no single shear
    /// aligns) the candidate (none, and the position shear and the warp of
    /// every depth the probes met) with the lowest sample variance over
    /// `pilots` pilot estimates drawn from a stream independent of the
    /// render's.
    Pilot {
        /// Pilot estimates per candidate.
        pilots: usize,
    },
}

/// Pilot estimates per candidate of [`ShearPolicy::Pilot`] by default.
/// Measured on the dof scene at 64 spp (32 renders): mean pixel variance
/// 5.47e-5 with 8, 5.36e-5 with 32, against 5.50e-5 for the analytic warp;
/// a sample variance of 8 estimates is off by ~50%, too noisy to rank
/// candidates whose variances differ by less.
pub const DEFAULT_PILOTS: usize = 32;

/// What is wrong with a render request.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The sampler cannot make 4D sets.
    #[error(
        "rendering needs a 4D sampler (x, y on the pixel, u, v on the {on}); this one is {dim}D"
    )]
    NotFourD {
        /// Its dimension.
        dim: usize,
        /// Lens or light.
        on: &'static str,
    },
    /// A sampler failure.
    #[error(transparent)]
    Sampler(#[from] SamplerError),
    /// Renders or pilots out of range.
    #[error("{what} must be at least {min} and at most {max}")]
    Count {
        /// Which count.
        what: &'static str,
        /// Its minimum.
        min: usize,
        /// Its maximum.
        max: usize,
    },
}

/// The stream of pixel `pixel` in render `render` (pilots use renders from
/// [`PILOT_STREAM`] on).
fn pixel_stream(render: u64, pixel: usize) -> u64 {
    (render << 32) | pixel as u64
}

/// First render index of the pilot streams, beyond the last render's
/// ([`MAX_RENDERS`]); with [`MAX_PILOTS`] the stream stays below 2^32.
const PILOT_STREAM: u64 = 1 << 30;

/// Renders one request may ask for: render r's streams are its own below
/// the pilots' ([`PILOT_STREAM`]).
pub const MAX_RENDERS: usize = 1 << 30;

/// Pilot estimates per candidate one request may ask for (the sample
/// variance of 2^20 estimates is within 0.3% at 95%; more only costs).
pub const MAX_PILOTS: usize = 1 << 20;

/// The candidates [`ShearPolicy::Pilot`] tries on an edge pixel: none,
/// then the position shear and the warp of every depth the probes met.
fn pilot_candidates(a: &PixelAnalysis) -> impl Iterator<Item = SampleShear> + '_ {
    std::iter::once(SampleShear::NONE).chain(
        a.kappas
            .iter()
            .filter(|k| k.abs() >= MIN_WARP_SLOPE)
            .flat_map(|&k| [SampleShear::Position([-k, -k]), SampleShear::Warp(k)]),
    )
}

/// The pilot estimates (sets drawn and traced) [`pixel_shears`] makes
/// under `policy`: `pilots` per candidate of every edge pixel (0 unless
/// [`ShearPolicy::Pilot`]), for a time estimate before they start.
pub fn pilot_estimates(policy: ShearPolicy, analysis: &[PixelAnalysis]) -> u64 {
    match policy {
        ShearPolicy::Pilot { pilots } => analysis
            .iter()
            .filter(|a| a.kind == PixelKind::Edge)
            .map(|a| pilot_candidates(a).count() as u64 * pilots as u64)
            .sum(),
        _ => 0,
    }
}

/// The per-pixel analysis of the whole image, row by row from the top.
pub fn analyse(scene: &Scene) -> Vec<PixelAnalysis> {
    let [w, h] = scene.camera().resolution();
    (0..w * h)
        .into_par_iter()
        .map(|i| analyse_pixel(scene, i % w, i / w))
        .collect()
}

/// The (a, b) of every pixel under `policy`; `progress` is called once per
/// edge pixel whose pilots are done (never under other policies).
///
/// # Errors
/// [`RenderError`] from the pilot renders; pilots outside [2,
/// [`MAX_PILOTS`]].
pub fn pixel_shears(
    scene: &Scene,
    sampler: &dyn Sampler,
    policy: ShearPolicy,
    analysis: &[PixelAnalysis],
    seed: u64,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<SampleShear>, RenderError> {
    check_sampler(scene, sampler)?;
    let w = scene.camera().resolution()[0];
    match policy {
        ShearPolicy::None => Ok(vec![SampleShear::NONE; analysis.len()]),
        ShearPolicy::Global(s) => Ok(vec![s; analysis.len()]),
        ShearPolicy::Analytic => Ok(analysis.iter().map(PixelAnalysis::shear).collect()),
        ShearPolicy::Pilot { pilots } => {
            if !(2..=MAX_PILOTS).contains(&pilots) {
                return Err(RenderError::Count {
                    what: "pilot estimates per candidate",
                    min: 2,
                    max: MAX_PILOTS,
                });
            }
            analysis
                .par_iter()
                .enumerate()
                .map(|(i, a)| {
                    if a.kind != PixelKind::Edge {
                        return Ok(a.shear());
                    }
                    let mut best = (SampleShear::NONE, f64::INFINITY);
                    for shear in pilot_candidates(a) {
                        // One pass, no buffer of `pilots` values.
                        let mut moments = RunningMoments::default();
                        for p in 0..pilots {
                            let stream = pixel_stream(PILOT_STREAM + p as u64, i);
                            moments.add(estimate(
                                scene,
                                sampler,
                                shear,
                                i % w,
                                i / w,
                                seed,
                                stream,
                            )?);
                        }
                        if moments.variance() < best.1 {
                            best = (shear, moments.variance());
                        }
                    }
                    progress();
                    Ok(best.0)
                })
                .collect()
        }
    }
}

fn check_sampler(scene: &Scene, sampler: &dyn Sampler) -> Result<(), RenderError> {
    if sampler.dim() == 4 {
        return Ok(());
    }
    Err(RenderError::NotFourD {
        dim: sampler.dim(),
        on: match scene.integrand() {
            super::description::IntegrandKind::Lens => "lens",
            super::description::IntegrandKind::Light => "light",
        },
    })
}

/// One pixel's estimate: the compensated mean of f over one sheared set.
fn estimate(
    scene: &Scene,
    sampler: &dyn Sampler,
    shear: SampleShear,
    px: usize,
    py: usize,
    seed: u64,
    stream: u64,
) -> Result<f64, RenderError> {
    let set = shear.apply(sampler.sample(&mut set_rng(seed, stream))?);
    let mut sum = NeumaierSum::default();
    for p in set.points() {
        sum.add(scene.radiance(px, py, [p[0], p[1], p[2], p[3]]));
    }
    Ok(sum.value() / set.len() as f64)
}

/// Render number `render` with the per-pixel shears.
///
/// # Errors
/// [`RenderError`].
pub fn render(
    scene: &Scene,
    sampler: &dyn Sampler,
    shears: &[SampleShear],
    seed: u64,
    render: u64,
) -> Result<GreyImage, RenderError> {
    check_sampler(scene, sampler)?;
    let [width, height] = scene.camera().resolution();
    let pixels = (0..width * height)
        .into_par_iter()
        .map(|i| {
            estimate(
                scene,
                sampler,
                shears[i],
                i % width,
                i / width,
                seed,
                pixel_stream(render, i),
            )
        })
        .collect::<Result<Vec<f64>, RenderError>>()?;
    Ok(GreyImage {
        width,
        height,
        pixels,
    })
}

/// Per-pixel mean and unbiased variance over `renders` independent renders.
#[derive(Debug, Clone)]
pub struct VarianceMaps {
    /// Mean of the renders.
    pub mean: GreyImage,
    /// Sample variance of each pixel's estimate (R − 1 in the denominator).
    pub variance: GreyImage,
    /// R.
    pub renders: usize,
    /// Each pixel's unbiased estimate of Var(s²), the variance of its
    /// sample variance ([`crate::sum::unbiased_variance_of_sample_variance`];
    /// None below 4 renders).
    variance_of_variance: Option<Vec<f64>>,
}

impl VarianceMaps {
    /// [`mse_against`] `reference` of these renders: the mean over pixels
    /// of the per-render squared error.
    pub fn mse_against(&self, reference: &GreyImage) -> f64 {
        mse_against(
            &self.mean.pixels,
            Some(&self.variance.pixels),
            self.renders,
            &reference.pixels,
        )
    }

    /// The mean pixel variance and its standard error (None below 4
    /// renders). Pixels are independent (each has its own random stream),
    /// so the variance of the mean of P sample variances is Σ Var(s²_p)/P²,
    /// estimated without bias from each pixel's second and fourth central
    /// sums over the R renders.
    pub fn mean_variance(&self) -> (f64, Option<f64>) {
        let p = self.variance.pixels.len() as f64;
        let mean = crate::sum::mean(&self.variance.pixels);
        let stderr = self.variance_of_variance.as_ref().map(|v| {
            let total = crate::sum::sum(v.iter().copied());
            total.max(0.0).sqrt() / p
        });
        (mean, stderr)
    }
}

/// A reference image: the mean of renders 0 and 1 of `seed` with `sampler`
/// and no shear (the scene figures use Sobol' with Burley's hash scramble).
///
/// # Errors
/// [`RenderError`].
pub fn reference_image(
    scene: &Scene,
    sampler: &dyn Sampler,
    seed: u64,
) -> Result<GreyImage, RenderError> {
    let [w, h] = scene.camera().resolution();
    let none = vec![SampleShear::NONE; w * h];
    let a = render(scene, sampler, &none, seed, 0)?;
    let b = render(scene, sampler, &none, seed, 1)?;
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

/// Renders `renders` times (renders 0 … R−1 of `seed`) and accumulates the
/// per-pixel mean, variance and fourth moment (Pébay's one-pass update,
/// [`RunningMoments`]: no difference of large sums). `progress` is called
/// once per render.
///
/// # Errors
/// [`RenderError`]; fewer than 2 renders.
pub fn render_variance(
    scene: &Scene,
    sampler: &dyn Sampler,
    shears: &[SampleShear],
    seed: u64,
    renders: usize,
    progress: &dyn Fn(),
) -> Result<VarianceMaps, RenderError> {
    if !(2..=MAX_RENDERS).contains(&renders) {
        return Err(RenderError::Count {
            what: "renders for a variance",
            min: 2,
            max: MAX_RENDERS,
        });
    }
    let [width, height] = scene.camera().resolution();
    let mut moments = vec![RunningMoments::default(); width * height];
    for r in 0..renders {
        let img = render(scene, sampler, shears, seed, r as u64)?;
        for (m, &x) in moments.iter_mut().zip(&img.pixels) {
            m.add(x);
        }
        progress();
    }
    let image = |value: fn(&RunningMoments) -> f64| GreyImage {
        width,
        height,
        pixels: moments.iter().map(value).collect(),
    };
    Ok(VarianceMaps {
        mean: image(RunningMoments::mean),
        variance: image(RunningMoments::variance),
        renders,
        variance_of_variance: moments
            .iter()
            .map(RunningMoments::variance_of_variance)
            .collect(),
    })
}

/// The mean over pixels of the per-render squared error against
/// `reference`: per pixel (R − 1)/R · s² + (mean − reference)², the mean
/// over R renders of (estimate − reference)² rewritten with their mean and
/// sample variance (no variance: one render, R = 1).
pub fn mse_against(
    mean: &[f64],
    variance: Option<&[f64]>,
    renders: usize,
    reference: &[f64],
) -> f64 {
    let r = renders as f64;
    let per_pixel = mean.iter().zip(reference).enumerate().map(|(i, (m, x))| {
        let s2 = variance.map_or(0.0, |v| v[i]);
        (r - 1.0) / r * s2 + (m - x) * (m - x)
    });
    crate::sum::sum(per_pixel) / mean.len() as f64
}

/// Mean (compensated), median and 95th percentile (nearest rank) of
/// per-pixel values, e.g. a variance map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelStatistics {
    /// Mean.
    pub mean: f64,
    /// Median.
    pub median: f64,
    /// 95th percentile.
    pub p95: f64,
}

impl PixelStatistics {
    /// The statistics of `values` (non-empty).
    pub fn of(values: &[f64]) -> PixelStatistics {
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let rank =
            |q: f64| sorted[((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len()) - 1];
        PixelStatistics {
            mean: crate::sum::sum(values.iter().copied()) / values.len() as f64,
            median: rank(0.5),
            p95: rank(0.95),
        }
    }
}
