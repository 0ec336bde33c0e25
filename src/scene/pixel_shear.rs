//! The shear search on one pixel of a scene, by measurement: a pixel has no
//! closed-form light field, so each candidate transformation of the sample
//! set is scored by the empirical variance of the render's estimator
//! (the unshifted mean of f over the transformed set, unbiased for every
//! candidate: each keeps the points uniform), all candidates on the same
//! realizations (common random numbers), with as many realizations as the
//! best candidate's relative standard error asks for.
//!
//! Candidates come from the pixel's local analysis ([`analyse_pixel`]): no
//! shear, and for every depth the probes met the position shear a = b = −κ
//! and the footprint warp of slope κ ([`SampleShear`]); on a slanted
//! single-depth pixel, whose κ changes across the footprint by a tenth of
//! a stratum or more ([`FootprintSlopes`]), also warps across that range
//! (measured on the dof scene's near-focus box pixel (112, 95): the best
//! slope lies at the low end of its range, with 2.6× less variance than the
//! centre's). The pixel is a **double wedge** when the probes met two
//! depths (or hits and misses); a **hairline** when moving the chosen
//! warp's slope by [`SENSITIVITY_STEP`] raises the variance by more than
//! half (the spectrum is so thin that a shear error of 0.01 matters, Singh
//! & Jarosz 2017). The choice never has a variance above the unsheared
//! one: no shear is a candidate.

use super::analysis::{
    FootprintSlopes, MIN_WARP_SLOPE, PixelAnalysis, PixelKind, SampleShear, analyse_pixel,
};
use super::pixel::PixelIntegrand;
use crate::optimize::shear::SENSITIVITY_STEP;
use crate::rng::set_rng;
use crate::samplers::Sampler;
use crate::variance::{EmpiricalEstimate, VarianceError, empirical_shifting};

/// Knobs of the search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelShearOptions {
    /// Seed of the realizations.
    pub seed: u64,
    /// Relative standard error wanted on the chosen candidate's variance.
    pub target_stderr: f64,
    /// Realizations of the first round (at least [`MIN_REALIZATIONS`]).
    pub min_realizations: usize,
    /// Most realizations per candidate.
    pub max_realizations: usize,
}

impl Default for PixelShearOptions {
    fn default() -> Self {
        PixelShearOptions {
            seed: 0,
            target_stderr: 0.02,
            min_realizations: 1000,
            max_realizations: 1 << 17,
        }
    }
}

/// Fewest realizations a candidate is compared on. Pixel estimates take
/// few distinct values (a hit or a miss per ray), so a handful of
/// realizations can agree exactly by chance: two gave a variance of 0 and
/// the choice of a shear 7.5× worse than the best. When 100 independent
/// estimates agree exactly, the modal value has probability ≥ 0.97 (95%
/// confidence) and the variance is indeed negligible.
pub const MIN_REALIZATIONS: usize = 100;

/// A candidate and its measured variance.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The transformation.
    pub shear: SampleShear,
    /// The estimator's empirical variance under it.
    pub estimate: EmpiricalEstimate,
}

/// What the search found.
#[derive(Debug, Clone, PartialEq)]
pub struct PixelShear {
    /// The pixel's local analysis.
    pub analysis: PixelAnalysis,
    /// How κ changes across its footprint.
    pub slopes: FootprintSlopes,
    /// Every candidate (no shear first), measured on the same realizations.
    pub candidates: Vec<Measured>,
    /// Index of the chosen (lowest-variance) candidate.
    pub chosen: usize,
    /// The chosen warp's slope moved by ∓[`SENSITIVITY_STEP`], when the
    /// choice is a warp.
    pub sensitivity: Option<[Measured; 2]>,
    /// A shear error of [`SENSITIVITY_STEP`] raises the variance by more
    /// than half.
    pub hairline: bool,
    /// The probes met two or more depths (or hits and misses).
    pub double_wedge: bool,
}

impl PixelShear {
    /// The chosen candidate.
    pub fn best(&self) -> &Measured {
        &self.candidates[self.chosen]
    }

    /// The unsheared candidate.
    pub fn unsheared(&self) -> &Measured {
        &self.candidates[0]
    }
}

/// Searches the transformation of `sampler`'s sets with the lowest variance
/// on pixel `f`.
///
/// # Errors
/// [`VarianceError`] for a sampler that is not 4D or fails, or fewer than
/// [`MIN_REALIZATIONS`] realizations.
pub fn search_pixel_shear(
    f: &PixelIntegrand,
    sampler: &dyn Sampler,
    options: PixelShearOptions,
) -> Result<PixelShear, VarianceError> {
    let first = options.min_realizations.min(options.max_realizations);
    if first < MIN_REALIZATIONS {
        return Err(VarianceError::TooFew {
            what: "comparing shears on a pixel",
            needed: MIN_REALIZATIONS,
            got: first,
        });
    }
    let [px, py] = f.pixel();
    let analysis = analyse_pixel(f.scene(), px, py);
    let slopes = FootprintSlopes::probe(f.scene(), px, py, &analysis, sampler.points_per_set());
    let mut shears = vec![SampleShear::NONE];
    if analysis.kind != PixelKind::Background {
        for &k in analysis.kappas.iter().filter(|k| k.abs() >= MIN_WARP_SLOPE) {
            shears.push(SampleShear::Position([-k, -k]));
            shears.push(SampleShear::Warp(k));
        }
    }
    shears.extend(slopes.candidates().into_iter().map(SampleShear::Warp));
    let measure = |shear: SampleShear, realizations: usize| -> Result<Measured, VarianceError> {
        let estimate = empirical_shifting(f, realizations, options.seed, &[], |r| {
            let set = sampler.sample(&mut set_rng(options.seed, r as u64))?;
            Ok::<_, VarianceError>(shear.apply(set))
        })?;
        Ok(Measured { shear, estimate })
    };
    let measure_all = |realizations: usize| -> Result<Vec<Measured>, VarianceError> {
        shears.iter().map(|&s| measure(s, realizations)).collect()
    };
    let lowest = |c: &[Measured]| {
        (0..c.len())
            .min_by(|&i, &j| c[i].estimate.variance.total_cmp(&c[j].estimate.variance))
            .expect("no shear is always a candidate")
    };
    let mut realizations = first;
    let mut candidates = measure_all(realizations)?;
    // At most three rounds: the count for the target is estimated from the
    // previous round's error, which is itself noisy.
    for _ in 0..3 {
        let best = &candidates[lowest(&candidates)].estimate;
        let relative = best.stderr / best.variance;
        // NaN: a constant pixel (zero variance) needs no more.
        let precise = relative.is_nan() || relative <= options.target_stderr;
        if precise || realizations >= options.max_realizations {
            break;
        }
        let factor = (relative / options.target_stderr).powi(2) * 1.1;
        realizations =
            ((realizations as f64 * factor).ceil() as usize).min(options.max_realizations);
        candidates = measure_all(realizations)?;
    }
    let chosen = lowest(&candidates);
    let sensitivity = match candidates[chosen].shear {
        SampleShear::Warp(k) => Some([
            measure(SampleShear::following(k - SENSITIVITY_STEP), realizations)?,
            measure(SampleShear::following(k + SENSITIVITY_STEP), realizations)?,
        ]),
        SampleShear::Position(_) => None,
    };
    let best = candidates[chosen].estimate.variance;
    let hairline = sensitivity
        .as_ref()
        .is_some_and(|s| s.iter().any(|m| m.estimate.variance > 1.5 * best));
    Ok(PixelShear {
        double_wedge: analysis.kind == PixelKind::Edge,
        analysis,
        slopes,
        candidates,
        chosen,
        sensitivity,
        hairline,
    })
}
