//! `optimize shear` on a closed-form 4D integrand as a library call: the
//! spectral start, the search on the expected variance, and an independent
//! check of the (x, y)-shifted estimator on fresh realizations that only
//! evaluates f (no spectra), with the report the command prints as JSON.

use serde_json::{Value, json};

use super::{
    MAX_SHEAR_RANGE, ObjectiveOptions, PlaneDirections, SENSITIVITY_STEP, ShearObjective,
    ShearResult, Sheared, SpectralStart, search_shear, spectral_start,
};
use crate::integrands::Integrand;
use crate::optimize::OptimizeError;
use crate::rng::set_rng;
use crate::samplers::Sampler;
use crate::variance::{
    EmpiricalEstimate, VarianceError, VarianceRatio, paired_ratio, shifted_estimates,
};

/// What the fresh-set check says of the search's claim that the shear
/// lowers the variance, from the 95% interval of the paired ratio
/// Var(after)/Var(before) (the same sets and shifts, sheared or not).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CheckVerdict {
    /// The ratio's interval lies wholly below 1.
    Confirms,
    /// The interval holds 1 (or there is no ratio: a variance of 0): the
    /// check cannot tell the shear from none.
    Inconclusive,
    /// The interval lies wholly above 1: the objective (an estimate, for
    /// halves without a closed form) misled the search.
    Contradicts,
}

impl CheckVerdict {
    /// The verdict of the paired ratio after/before.
    #[must_use]
    pub fn of(ratio: Option<&VarianceRatio>) -> Self {
        match ratio {
            Some(r) if r.ci_high < 1.0 => Self::Confirms,
            Some(r) if r.ci_low > 1.0 => Self::Contradicts,
            _ => Self::Inconclusive,
        }
    }

    /// The name the JSON report uses.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Confirms => "confirms",
            Self::Inconclusive => "inconclusive",
            Self::Contradicts => "contradicts",
        }
    }
}

/// A search with its check.
pub struct CheckedShear {
    /// The search's result.
    pub found: ShearResult,
    /// The integrand's spectral analysis the search started from.
    pub spectral: SpectralStart,
    /// Variance of the estimator unsheared and at the found shear on
    /// fresh realizations (None for `realizations` = 0).
    pub check: Option<(EmpiricalEstimate, EmpiricalEstimate)>,
    /// Var(after)/Var(before) from the check's paired realizations (None
    /// without a check, or with a variance of 0 on either side).
    pub ratio: Option<VarianceRatio>,
    /// The check's verdict on the found shear (None without a check, or
    /// when the search kept no shear: then both sides are one estimator).
    pub verdict: Option<CheckVerdict>,
    /// Wall time of the search (without the check), seconds.
    pub search_seconds: f64,
    /// What the user should know about the result (a range that cuts the
    /// spectrum's direction, an objective that cannot tell shears apart,
    /// a constant integrand).
    pub warnings: Vec<String>,
    /// Everything, as the command's JSON report.
    pub report: Value,
}

/// The search's half-width when none is given: this, or wider to hold
/// every spectral candidate with a quarter to spare (rounded up to 0.5).
pub const DEFAULT_SHEAR_RANGE: f64 = 2.0;

/// Variance, relative to the squared integral, below which an integrand
/// is constant (rounding of a variance that is 0).
const CONSTANT_VARIANCE: f64 = 1e-12;

/// Share of J above which its truncation bound gets a warning.
const LOOSE_TRUNCATION: f64 = 0.5;

/// Refuses what [`search_and_check`] cannot do, before anything is built:
/// a non-4D integrand, a range outside (0, [`MAX_SHEAR_RANGE`]], one check
/// realization.
///
/// # Errors
/// [`OptimizeError::Option`] naming what is wrong.
pub fn check_request(
    f: &dyn Integrand,
    range: Option<f64>,
    realizations: usize,
) -> Result<(), OptimizeError> {
    if f.dim() != 4 {
        return Err(OptimizeError::Option(format!(
            "the shear search needs a 4D integrand (e.g. defocus:...), {} is {}D",
            f.spec(),
            f.dim()
        )));
    }
    if realizations == 1 {
        return Err(OptimizeError::Option(
            "--realizations 1: the check needs 0 (no check) or at least 2".to_string(),
        ));
    }
    if let Some(range) = range
        && !(range.is_finite() && range > 0.0 && range <= MAX_SHEAR_RANGE)
    {
        return Err(OptimizeError::Option(format!(
            "--range {range:?}: the search's half-width must be a positive number up to {MAX_SHEAR_RANGE}"
        )));
    }
    Ok(())
}

/// The range searched: `given`, or [`DEFAULT_SHEAR_RANGE`] widened to hold
/// the `widest` spectral candidate with a quarter to spare.
fn search_range(given: Option<f64>, widest: f64) -> f64 {
    given.unwrap_or_else(|| {
        DEFAULT_SHEAR_RANGE
            .max((2.5 * widest).ceil() / 2.0)
            .min(MAX_SHEAR_RANGE)
    })
}

/// Searches the shear of `sampler` (named `sampler_name`) for `f` within
/// [−range, range]² (by default [`DEFAULT_SHEAR_RANGE`], widened to hold the
/// spectrum's directions) and checks it on `realizations` fresh
/// realizations (0: no check), telling `progress` what it does next.
/// An integrand constant in (x, y) gives variance 0 at every shear: it is
/// not searched and keeps no shear.
///
/// # Errors
/// [`OptimizeError::Option`] for a non-4D integrand, a bad range or
/// realization count; the search's and the check's errors.
pub fn search_and_check(
    f: &dyn Integrand,
    sampler: &dyn Sampler,
    sampler_name: &str,
    seed: u64,
    range: Option<f64>,
    realizations: usize,
    progress: &dyn Fn(String),
) -> Result<CheckedShear, OptimizeError> {
    check_request(f, range, realizations)?;
    let start = std::time::Instant::now();
    progress("the integrand's spectrum and the frequency terms".into());
    let spectral = spectral_start(f, 64, range.unwrap_or(DEFAULT_SHEAR_RANGE));
    let mut starts = spectral.candidates();
    // The lines' slopes, not the principal direction: a symmetric double
    // wedge's is vertical, and no layer asks for it.
    let widest = spectral
        .planes
        .iter()
        .flat_map(|p| p.lines.iter().map(|v| v.abs()))
        .fold(0.0, f64::max);
    let range = search_range(range, widest);
    let mut warnings = Vec::new();
    if widest > range {
        warnings.push(format!(
            "the spectrum asks for a shear of up to {widest:.3} on an axis, outside --range {}: the search stops at the range; widen it (or leave --range out)",
            crate::spec_params::SpecValue(range)
        ));
    }
    starts.push([0.0, 0.0]);
    let options = ObjectiveOptions {
        seed,
        ..ObjectiveOptions::default()
    };
    let objective = ShearObjective::new(f, sampler, &starts, options)?;
    // Constant up to rounding: a layer stack of constant layers sums its
    // variance from terms that cancel to ~1e-17 of I², not to 0.
    let constant = f.variance() <= CONSTANT_VARIANCE * f.integral().powi(2);
    let found = if constant {
        warnings.push(
            "the integrand is constant in (x, y): every shear gives variance 0, so none is applied"
                .to_string(),
        );
        ShearResult::constant()
    } else {
        search_shear(&objective, &spectral, range, &|s| {
            progress(s.to_string());
        })?
    };
    let search_seconds = start.elapsed().as_secs_f64();
    if !constant && objective.truncation_bound() > LOOSE_TRUNCATION * found.optimum.value.abs() {
        warnings.push(format!(
            "the objective's truncation bound is {:.2} of J ({} frequency terms of |k|∞ ≤ {}): the integrand's energy lies mostly beyond the sum, J may not tell shears apart{}",
            objective.truncation_bound() / found.optimum.value.abs(),
            objective.terms(),
            objective.half(),
            if found.shear == found.initial.0 && found.shear != [0.0, 0.0] {
                ", and the shear is the spectrum's direction"
            } else {
                ""
            }
        ));
    }
    let eval_seed = seed ^ 0x0e7a_1000;
    // Realization r draws the same set and shift at every shear: the two
    // sides are paired.
    let estimates = |shear: [f64; 2]| -> Result<Vec<f64>, OptimizeError> {
        let sheared = Sheared::new(sampler, shear)?;
        Ok(shifted_estimates(
            f,
            realizations,
            seed ^ 1,
            &[0, 1],
            |r| -> Result<_, VarianceError> {
                Ok(sheared.sample(&mut set_rng(eval_seed, r as u64))?)
            },
        )?)
    };
    let check = if realizations >= 2 {
        let timer = std::time::Instant::now();
        sampler.sample(&mut set_rng(eval_seed ^ 1, 0))?;
        let per_set = timer.elapsed().as_secs_f64();
        progress(format!(
            "checking on {realizations} fresh realizations (about {:.0} s of sampling at {per_set:.2e} s a set; --realizations sets the count)",
            2.0 * realizations as f64 * per_set / rayon::current_num_threads() as f64
        ));
        Some((estimates([0.0, 0.0])?, estimates(found.shear)?))
    } else {
        None
    };
    let ratio = check.as_ref().and_then(|(b, a)| paired_ratio(b, a));
    let verdict = check
        .as_ref()
        .filter(|_| found.shear != [0.0, 0.0])
        .map(|_| CheckVerdict::of(ratio.as_ref()));
    let check = check.map(|(b, a)| (EmpiricalEstimate::of(&b), EmpiricalEstimate::of(&a)));
    let analytic = f.light_field().map(|l| l.layer_shears());
    let plane = |p: &PlaneDirections| {
        json!({"principal_slope": p.principal, "eigenvalue_ratio": p.eigenvalue_ratio,
               "line_slopes": p.lines, "first_line_share": p.first_line_share,
               "second_line_share": p.second_line_share, "one_line_misfit": p.one_line_misfit})
    };
    let ci = |e: &EmpiricalEstimate| json!({"variance": e.variance, "stderr": e.stderr, "ci_low": e.ci_low, "ci_high": e.ci_high, "realizations": e.realizations});
    let report = json!({
        "sampler": sampler_name, "integrand": f.spec(), "n": sampler.points_per_set(), "seed": seed,
        "shear": found.shear, "initial_shear": found.initial.0, "analytic_shear": analytic,
        "double_wedge": spectral.double_wedge, "kept_unsheared": found.kept_unsheared,
        "spectrum": {"xu": plane(&spectral.planes[0]), "yv": plane(&spectral.planes[1])},
        "estimator": "(x,y)-shifted: mean of f(x'+sx, y'+sy, u, v) over the sheared set, s uniform in (x,y); unbiased for any shear",
        "objective": {
            "description": objective_description(objective.realizations()),
            "unsheared": found.unsheared.value, "initial": found.initial.1, "optimum": found.optimum.value,
            "stderr": (found.optimum.value > 0.0).then(|| found.optimum.stderr / found.optimum.value),
            "unsheared_stderr": (found.unsheared.value > 0.0).then(|| found.unsheared.stderr / found.unsheared.value),
            "truncation_bound": (found.optimum.value > 0.0).then(|| objective.truncation_bound() / found.optimum.value),
            "evaluations": found.evaluations, "coarse_evaluations": found.coarse_evaluations,
            "terms": objective.terms(), "coarse_terms": objective.coarse_terms(), "half": objective.half(),
            "realizations": objective.realizations(),
        },
        "sensitivity": {"step": SENSITIVITY_STEP, "a_minus": found.sensitivity[0], "a_plus": found.sensitivity[1],
                        "b_minus": found.sensitivity[2], "b_plus": found.sensitivity[3]},
        "variance_before": check.as_ref().map(|c| ci(&c.0)),
        "variance_after": check.as_ref().map(|c| ci(&c.1)),
        "check_ratio": ratio.map(|r| json!({"ratio": r.ratio, "ci_low": r.ci_low, "ci_high": r.ci_high})),
        "check_verdict": verdict.map(CheckVerdict::name),
        "reduction": (found.optimum.value > 0.0).then(|| found.unsheared.value / found.optimum.value),
        "range": range, "warnings": warnings,
        "seconds": search_seconds,
    });
    Ok(CheckedShear {
        found,
        spectral,
        check,
        ratio,
        verdict,
        search_seconds,
        warnings,
        report,
    })
}

/// The objective in words, per half: closed form, or estimated from how
/// many realizations (`realizations` as [`ShearObjective::realizations`]:
/// 0 for a closed form).
fn objective_description([xy, uv]: [usize; 2]) -> String {
    let half = |name: &str, sets: usize| match sets {
        0 => format!("{name} half in closed form"),
        r => format!("{name} half estimated from {r} realizations"),
    };
    format!(
        "expected variance of the estimator over the sampler's randomness: {}, {}",
        half("(x, y)", xy),
        half("(u, v)", uv)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn interval(ci_low: f64, ci_high: f64) -> VarianceRatio {
        VarianceRatio {
            ratio: (ci_low * ci_high).sqrt(),
            ci_low,
            ci_high,
        }
    }

    #[test]
    fn the_verdict_needs_the_ratio_s_interval_off_one() {
        let of = |lo, hi| CheckVerdict::of(Some(&interval(lo, hi)));
        assert_eq!(of(0.5, 0.99), CheckVerdict::Confirms);
        assert_eq!(of(0.5, 1.01), CheckVerdict::Inconclusive);
        assert_eq!(of(0.99, 2.0), CheckVerdict::Inconclusive);
        assert_eq!(of(1.01, 2.0), CheckVerdict::Contradicts);
        assert_eq!(CheckVerdict::of(None), CheckVerdict::Inconclusive);
    }
}
