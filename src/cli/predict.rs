//! `varspec predict`: the variance of the shift-randomized estimator by the
//! Fourier, spatial and empirical predictors, side by side.

use std::time::Instant;

use anyhow::{anyhow, bail};
use clap::ValueEnum;
use serde_json::{Value, json};

use super::args;
use super::progress;
use super::source::{SourceArgs, realization_error};
use varspec::PointSet;
use varspec::integrands::{self, Integrand};
use varspec::scene::pixel::PixelIntegrand;
use varspec::source::Source;
use varspec::variance::{
    ClosedForm, DEFAULT_SHIFT_SEED, SetCount, TARGET_RELATIVE_STDERR, VarianceError, auto_set_cap,
    empirical_shifting, expected_min_half, fourier_parts, radial_from, sets_for_relative_stderr,
    spatial,
};

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MethodArg {
    Fourier,
    /// The sampler's expected variance in closed form: the exact lattice
    /// sum for regular, uniform-jitter and lattice on an integrand with a
    /// closed-form autocovariance, else the Fourier form with the sampler's
    /// expected spectrum (2D random, jitter, regular, uniform-jitter,
    /// multijitter, cmj; 4D umj and padded sets of those): no realizations,
    /// no sampling error; part of `all` where it exists.
    Expected,
    Spatial,
    Empirical,
    /// The radial (isotropic) form from radially averaged spectra, with its
    /// anisotropy bound.
    Radial,
    All,
}

/// The dimensions the empirical predictor's random shift moves.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ShiftArg {
    /// Every dimension: the shift-randomized estimator of the other
    /// predictors.
    All,
    /// Dimensions 0 and 1 only: the estimator a sheared 4D set is judged
    /// by (a shift in u or v would undo the shear; docs/mathematics.md §6.2).
    Xy,
    /// None: the plain estimator of a randomized sampler, or of a file's
    /// sets taken as independent realizations (each once).
    None,
}

impl ShiftArg {
    /// The shifted dimensions of a d-dimensional integrand.
    fn dims(self, d: usize) -> Vec<usize> {
        match self {
            ShiftArg::All => (0..d).collect(),
            ShiftArg::Xy => (0..d.min(2)).collect(),
            ShiftArg::None => Vec::new(),
        }
    }

    /// What the estimator is, for the JSON's `estimator`.
    fn estimator(self) -> &'static str {
        match self {
            ShiftArg::All => "shift-randomized: uniform toroidal shift of every dimension",
            ShiftArg::Xy => {
                "shifted in (x, y) only: uniform toroidal shift of dimensions 0 and 1 (the \
                 estimator of sheared 4D sets)"
            }
            ShiftArg::None => "unshifted: the mean of f over each realization as it is",
        }
    }
}

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    source: SourceArgs,
    /// Integrand spec, e.g. disk:r=0.3 (see `varspec integrands --list`):
    /// the torus and its shift-randomized estimator; or a scene pixel
    /// scene:NAME,px=X,py=Y (--method empirical).
    #[arg(long, required_unless_present = "family", conflicts_with = "family")]
    integrand: Option<String>,
    /// Instead: a family of integrands on the unit square (gaussians,
    /// halfplanes, disks, boxes, file:PATH) and the unshifted estimator's
    /// mean squared error over it (by brute force; the predictors' options
    /// do not apply).
    #[arg(long, conflicts_with_all = ["method", "realizations", "res", "tol"])]
    family: Option<String>,
    /// Members of the family sample (with --family; default 1024; at least
    /// 2, for the standard error).
    #[arg(value_parser = super::args::whole_at_least::<2, usize>, allow_negative_numbers = true, long)]
    members: Option<usize>,
    /// Which predictor(s) to run, comma-separated (e.g. spatial,empirical).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "all")]
    method: Vec<MethodArg>,
    /// Realizations (fresh sampler randomness and shift each) of the
    /// empirical predictor [default: 10000; a scene pixel's point file:
    /// its set count].
    #[arg(value_parser = super::args::whole::<usize>, allow_negative_numbers = true, long)]
    realizations: Option<usize>,
    /// Which dimensions the empirical predictor's random shift moves: all
    /// (the estimator of every predictor), xy (dimensions 0 and 1: how
    /// sheared 4D sets, e.g. from `optimize shear -o`, are judged) or none
    /// (a file's sets then count once each) [default: all; none for a
    /// scene pixel, the estimator its render uses].
    #[arg(long, value_enum, conflicts_with = "family")]
    shift: Option<ShiftArg>,
    /// Fourier box |k| < K/2 (default 256 in 2D, 21 in 4D: the box of
    /// converge and experiment).
    #[arg(value_parser = super::args::frequency_box, allow_negative_numbers = true, long)]
    res: Option<usize>,
    /// NUFFT tolerance of the Fourier predictor's spectrum [default: 1e-10].
    #[arg(allow_negative_numbers = true, long, value_parser = super::args::tolerance)]
    tol: Option<f64>,
    /// Print one JSON object (the scripting interface).
    #[arg(long)]
    json: bool,
}

/// The empirical predictor's realizations without --realizations.
const DEFAULT_REALIZATIONS: usize = 10_000;
/// The Fourier form's NUFFT tolerance without --tol.
const DEFAULT_TOLERANCE: f64 = 1e-10;

/// A standard error over `sets` realizations: unknown (JSON null) from one.
fn known_stderr(stderr: f64, sets: usize) -> Option<f64> {
    (sets >= 2).then_some(stderr)
}

/// True when two or more sets gave one nonzero value (a spread within
/// rounding of it): from random sets, no evidence of their variability.
fn no_spread(variance: f64, stderr: f64, rounding_bound: f64, sets: usize) -> bool {
    sets >= 2 && variance > rounding_bound && stderr <= 1e-12 * variance
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let members = super::args::family_members(a.members, a.family.as_deref())?;
    let Some(spec) = &a.integrand else {
        return square(&a, members);
    };
    // A scene pixel has no closed form: only the empirical predictor,
    // which evaluates f, applies (`--method all` runs it alone).
    let pixel = PixelIntegrand::is_pixel_spec(spec);
    // A pixel's integral is an estimate: its standard error goes with it.
    let (f, integral_stderr): (Box<dyn Integrand>, Option<f64>) = if pixel {
        if !a
            .method
            .iter()
            .all(|m| matches!(m, MethodArg::Empirical | MethodArg::All))
        {
            bail!(
                "{spec}: a scene pixel has no closed-form spectrum or autocovariance; \
                 predict it with --method empirical"
            );
        }
        let f = PixelIntegrand::parse(spec)?;
        let stderr = f.integral_stderr();
        (Box::new(f), Some(stderr))
    } else {
        (integrands::parse(spec)?, None)
    };
    // Options of a predictor that will not run are refused, not ignored.
    let asks = |m: MethodArg| a.method.contains(&m);
    let fourier_runs =
        !pixel && (asks(MethodArg::Fourier) || asks(MethodArg::Radial) || asks(MethodArg::All));
    for (given, option, runs, methods) in [
        (
            a.res.is_some(),
            "--res sets the Fourier box",
            fourier_runs || (!pixel && asks(MethodArg::Expected)),
            "fourier, expected, radial or all",
        ),
        (
            a.tol.is_some(),
            "--tol sets the Fourier box's transform",
            fourier_runs,
            "fourier, radial or all",
        ),
    ] {
        if given && !runs {
            bail!(
                "{option}: it applies to --method {methods}{}",
                if pixel {
                    " (not to a scene pixel, which only the empirical predictor takes)"
                } else {
                    ""
                }
            );
        }
    }
    if a.realizations.is_some() && !(asks(MethodArg::Empirical) || asks(MethodArg::All)) {
        bail!("--realizations applies to the empirical predictor (--method empirical or all)");
    }
    // With a file, --seed seeds the empirical predictor's shifts (its one
    // random draw), so a user can redraw them; other predictors use
    // nothing random from a file, so there it is refused.
    let empirical_runs = pixel || asks(MethodArg::Empirical) || asks(MethodArg::All);
    let mut source = if empirical_runs {
        a.source.resolve_seeded(Some(f.dim()))?
    } else {
        a.source.resolve(Some(f.dim()))?
    };
    let shift_seed = match source {
        varspec::source::Source::File { .. } => DEFAULT_SHIFT_SEED ^ a.source.seed(),
        _ => DEFAULT_SHIFT_SEED,
    };
    let sets = source.count();
    // A render averages f over each pixel's set as it is drawn: a pixel's
    // variance is that of the unshifted estimator.
    // On a 2D integrand a shift in (x, y) is the shift in every dimension
    // (it was labelled the estimator of sheared 4D sets, and only the
    // empirical predictor took it).
    let shift = match a.shift {
        Some(ShiftArg::Xy) if f.dim() <= 2 => ShiftArg::All,
        given => given.unwrap_or(if pixel { ShiftArg::None } else { ShiftArg::All }),
    };
    // Unshifted, a file's sets count once each: the default realization
    // count becomes the file's set count.
    let realizations = match a.realizations {
        Some(r) => r,
        None if shift == ShiftArg::None && a.source.file().is_some() => {
            DEFAULT_REALIZATIONS.min(sets)
        }
        None => DEFAULT_REALIZATIONS,
    };
    if shift != ShiftArg::All {
        if !(a.method.iter().all(|&m| m == MethodArg::Empirical) || pixel) {
            bail!(
                "--shift {}: only the empirical predictor takes another shift; the Fourier, \
                 spatial and radial forms are of the estimator shifted in every dimension: run \
                 --method empirical alone",
                shift
                    .to_possible_value()
                    .map_or("?".into(), |v| v.get_name().to_string())
            );
        }
        if shift == ShiftArg::None && a.source.file().is_some() && sets < 2 {
            // Without --shift, none was the scene pixel's default: say why
            // it applies; with it, the user chose it.
            let why = if a.shift.is_none() {
                " (the default for a scene pixel, as its render)"
            } else {
                ""
            };
            bail!(
                "--shift none{why}: the file holds one set, so one estimate and no variance \
                 without a shift; give a file of 2 or more sets, or --shift all"
            );
        }
        if shift == ShiftArg::None && a.source.file().is_some() && realizations > sets {
            bail!(
                "--shift none --realizations {}: without a shift the file's {sets} set(s) give \
                 only {sets} distinct estimates, so repeating them would overstate the \
                 precision: pass --realizations {sets} or fewer",
                realizations
            );
        }
    }
    let n = source.points_per_set();
    // The sampler's closed form for f, if it has one: an exact lattice sum
    // or its expected spectrum (variance::closed_form).
    let closed = match &source {
        Source::Sampler {
            sampler,
            dims: None,
            ..
        } => ClosedForm::of(sampler.as_ref(), f.as_ref()),
        _ => None,
    };
    if asks(MethodArg::Expected) && closed.is_none() {
        bail!(
            "--method expected needs a sampler with a closed form (a closed-form expected \
             spectrum: 2D random, jitter, regular, uniform-jitter, multijitter, cmj, 4D umj and \
             padded sets of those, with an integrand that has Fourier coefficients; or a \
             lattice: regular, uniform-jitter and lattice, with an integrand that has a \
             closed-form autocovariance), not a file or a projection; {} on {} has none: use \
             --method fourier",
            source.name(),
            f.spec()
        );
    }
    let closed_form = closed.is_some();
    let wants = |m: MethodArg| {
        asks(m)
            || (asks(MethodArg::All)
                && (!pixel || m == MethodArg::Empirical)
                && (m != MethodArg::Expected || closed_form))
    };
    let mut out = serde_json::Map::new();
    out.insert("integrand".into(), json!(f.spec()));
    out.insert("source".into(), json!(source.name()));
    out.insert("seed".into(), json!(a.source.seed()));
    out.insert("n".into(), json!(n));
    out.insert("density".into(), json!(source.density()));
    out.insert("integral".into(), json!(f.integral()));
    if let Some(stderr) = integral_stderr {
        out.insert("integral_stderr".into(), json!(stderr));
        out.insert(
            "integral_note".into(),
            json!(format!(
                "estimated from {} independent multi-jittered sets of {} samples, with the \
                 standard error of their mean (a pixel has no closed form)",
                varspec::scene::pixel::REFERENCE_SETS,
                varspec::scene::pixel::REFERENCE_POINTS
            )),
        );
    }
    out.insert("estimator".into(), json!(shift.estimator()));
    if let Some(closed) = closed.filter(|_| wants(MethodArg::Expected)) {
        // Without --res the closed form's box is the Fourier form's, grown
        // with N where that matters (variance::expected_min_half).
        let res = a.res.unwrap_or_else(|| {
            let fourier = default_res(f.dim());
            fourier.max(2 * expected_min_half(f.dim(), n) + 1)
        });
        if matches!(closed, ClosedForm::Lattice(_))
            && a.res.is_some()
            && !wants(MethodArg::Fourier)
            && !wants(MethodArg::Radial)
        {
            eprintln!("note: {}", args::LATTICE_HAS_NO_BOX);
        }
        let start = Instant::now();
        let e = closed.variance(f.as_ref(), res.saturating_sub(1) / 2)?;
        let mut entry = json!({
            "variance": e.variance, "truncation_bound": e.truncation_bound,
            "rounding_bound": e.rounding_bound, "form": closed.name(),
        });
        match (&closed, &e.fourier) {
            (ClosedForm::Lattice(lattice), _) => {
                entry["lattice"] = json!(lattice);
            }
            (_, Some(p)) => {
                entry["in_box"] = json!(p.in_box);
                entry["tail"] = json!(p.tail);
                entry["axis_strips"] = json!(p.strips.map(|s| json!({
                    "half_width": s.width, "reach": s.reach,
                    "correction": s.correction / n as f64,
                })));
                entry["res"] = json!(res);
            }
            _ => {}
        }
        entry["seconds"] = json!(start.elapsed().as_secs_f64());
        out.insert("expected".into(), entry);
    }
    // The Fourier, radial and spatial forms pass over the same
    // realizations: draw them once (a sampler's draw can be costly, e.g. an
    // optimized set). Without --sets, a sampler's 16 sets are a pilot: when
    // their standard error exceeds 5% of the variance the forms run again
    // on as many sets as reach it (variance::sets).
    let mut drawn = Vec::new();
    // A sampler's sets vary from draw to draw unless they are shifts of one
    // set (regular, uniform jitter, lattices) or single points, whose
    // spatial values agree (one point's is Var f, with no pairs at all).
    let random_sets = matches!(&source, Source::Sampler { sampler, .. }
        if !sampler.shifts_of_one_set() && sampler.points_per_set() > 1);
    if wants(MethodArg::Fourier) || wants(MethodArg::Spatial) || wants(MethodArg::Radial) {
        drawn = source.realizations()?;
        let relative = set_forms(&a, f.as_ref(), &drawn, random_sets, &wants, &mut out)?;
        if let (false, Source::Sampler { sets, .. }) = (a.source.sets_were_given(), &mut source) {
            let pilot = *sets;
            let cap = auto_set_cap(n, f.dim(), wants(MethodArg::Spatial));
            let relative = relative.unwrap_or(0.0);
            // Random sets that all gave one value show no spread to scale
            // from: draw as many as the default work allows.
            let unseen = relative == f64::INFINITY;
            let count = if unseen {
                SetCount {
                    sets: cap.max(pilot),
                    wanted: cap.max(pilot),
                }
            } else {
                sets_for_relative_stderr(pilot, relative, TARGET_RELATIVE_STDERR, cap)
            };
            if count.sets > pilot {
                *sets = count.sets;
                drawn = source.realizations()?;
                set_forms(&a, f.as_ref(), &drawn, random_sets, &wants, &mut out)?;
            }
            out.insert(
                "auto_sets".into(),
                json!({
                    "pilot": pilot, "pilot_relative_stderr": relative,
                    "target_relative_stderr": TARGET_RELATIVE_STDERR, "sets": count.sets,
                    "wanted": count.wanted, "capped": count.capped(),
                }),
            );
            let most = format!(
                "drew {} sets, the most the default work allows (R·N² ≤ 2^30 point pairs, \
                 256 MiB of sets)",
                count.sets
            );
            if unseen && count.sets > pilot {
                eprintln!(
                    "note: {pilot} random sets gave one spatial value (no spread: what varies \
                     between sets, such as pairs within a small integrand's reach, did not occur \
                     in them); {most}; --sets fixes the count"
                );
            } else if count.sets > pilot || count.capped() {
                let drew = if count.capped() {
                    format!(
                        "{most}: --sets {} reaches {:.0}%",
                        count.wanted,
                        100.0 * TARGET_RELATIVE_STDERR
                    )
                } else {
                    format!(
                        "drew {} sets for {:.0}%",
                        count.sets,
                        100.0 * TARGET_RELATIVE_STDERR
                    )
                };
                eprintln!(
                    "note: {pilot} sets gave a standard error of {:.1}% of the variance (this \
                     sampler's per-set values are spread and skewed: over few sets their mean \
                     tends to come out low together with its standard error); {drew}; --sets \
                     fixes the count",
                    100.0 * relative
                );
            }
        }
    }
    if wants(MethodArg::Empirical) {
        let start = Instant::now();
        let shifted = shift.dims(f.dim());
        // Each realization is fetched once, as its estimate starts.
        let bar = progress::bar(realizations as u64, "empirical form, realizations");
        let e = empirical_shifting(f.as_ref(), realizations, shift_seed, &shifted, |r| {
            bar.inc(1);
            source.get_cyclic(r).map_err(|e| realization_error(r, e))
        });
        bar.finish_and_clear();
        let e = e?;
        out.insert(
            "empirical".into(),
            json!({
                "variance": e.variance, "stderr": e.stderr, "ci_low": e.ci_low, "ci_high": e.ci_high, "mean": e.mean,
                "realizations": e.realizations, "seconds": start.elapsed().as_secs_f64(),
            }),
        );
    }
    note_loose_bounds(&out, f.has_autocov());
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&Value::Object(out))?);
        return Ok(());
    }
    // A sampler's sets are those the Fourier and spatial forms pass over;
    // the empirical predictor alone draws its own realizations.
    let drawn_label = if a.method.iter().all(|&m| m == MethodArg::Expected) {
        "closed form, no sets".to_string()
    } else if drawn.is_empty() && a.source.file().is_none() {
        super::stdout::counted(realizations, "realization")
    } else {
        super::stdout::counted(source.count(), "set")
    };
    // An estimate is printed to the digit its standard error reaches.
    let integral = match integral_stderr {
        Some(stderr) if stderr > 0.0 => {
            let digits = (1.0 - stderr.log10().floor()).clamp(0.0, 17.0) as usize;
            format!("≈ {:.digits$} (standard error {stderr:.1e})", f.integral())
        }
        Some(_) => format!(
            "≈ {} (the same on every reference sample)",
            varspec::spec_params::SpecValue(f.integral())
        ),
        None => format!("= {}", varspec::spec_params::SpecValue(f.integral())),
    };
    outln!(
        "{} on {} ({}, {drawn_label}, seed {}), I {integral}",
        f.spec(),
        source.name(),
        source.count_label(),
        a.source.seed(),
    );
    if shift != ShiftArg::All {
        outln!("  estimator: {}", shift.estimator());
    }
    for (key, extra) in [
        ("expected", "truncation_bound"),
        ("fourier", "truncation_bound"),
        ("spatial", "stderr"),
        ("empirical", "ci_low"),
        ("radial", "anisotropy_bound"),
    ] {
        if let Some(v) = out.get(key) {
            // A value at or below its rounding bound is zero to rounding
            // (the integrand is integrated to machine precision), as
            // converge and the experiment tables say.
            let rounding = v["variance"].as_f64().zip(v["rounding_bound"].as_f64());
            let zero = rounding.is_some_and(|(x, b)| varspec::variance::zero_to_rounding(x, b));
            // A coarse --tol's transform error, not the arithmetic's, can
            // put the Fourier form below its bound: that is a value the
            // tolerance does not resolve, not a zero (jitter on a disk at
            // --tol 1e-3 read "0 to rounding" beside a spatial 7.46e-5).
            let coarse = a.tol.filter(|&t| key == "fourier" && t > DEFAULT_TOLERANCE);
            let variance = match v["variance"].as_f64() {
                _ if zero && coarse.is_some() => "unresolved".to_string(),
                _ if zero => "0 to rounding".to_string(),
                Some(x) => format!("{x:.6e}"),
                None => "n/a".to_string(),
            };
            let note = match key {
                "empirical" => match v["ci_high"].as_f64() {
                    Some(high) => format!(
                        "95% CI [{:.4e}, {high:.4e}] over {} realizations{}",
                        v["ci_low"].as_f64().unwrap_or(0.0),
                        v["realizations"].as_u64().unwrap_or(0),
                        // The default count was capped at the file's sets.
                        if shift == ShiftArg::None
                            && a.realizations.is_none()
                            && a.source.file().is_some()
                            && realizations < DEFAULT_REALIZATIONS
                        {
                            " (one per set of the file: unshifted, a set gives one estimate)"
                        } else {
                            ""
                        }
                    ),
                    None => "every realization gave the same estimate, so the interval has no upper end (the variance is 0 if the integrand is constant; otherwise raise --realizations)".to_string(),
                },
                _ if v.get("skipped").is_some() => {
                    v["skipped"].as_str().unwrap_or_default().to_string()
                }
                "expected" if v["lattice"].is_object() => format!(
                    "exact lattice sum (1/N)·Σ c_f over the {n} lattice points: no sampling error, \
                     no truncation"
                ),
                "expected" => format!(
                    "closed-form E[P_S], no sampling error  {extra} {:.2e}",
                    v[extra].as_f64().unwrap_or(f64::NAN)
                ),
                // The Fourier form has both: its sampling error over the
                // sets and the bound on its truncation.
                "fourier" => match (v["stderr"].as_f64(), v[extra].as_f64()) {
                    (Some(e), Some(x)) => format!("stderr {e:.2e}  {extra} {x:.2e}"),
                    (None, Some(x)) => format!("{extra} {x:.2e}"),
                    _ => String::new(),
                },
                _ => match v[extra].as_f64() {
                    Some(x) => format!("{extra} {x:.2e}"),
                    None if v["stderr_unknown"].is_string() => format!(
                        "{extra} unknown ({})",
                        v["stderr_unknown"].as_str().unwrap_or_default()
                    ),
                    None if a.source.file().is_some() => format!(
                        "{extra} unknown (one set: give a file of 2 or more sets)"
                    ),
                    None => format!("{extra} unknown (one set: draw 2 or more with --sets)"),
                },
            };
            let note = match (rounding, coarse) {
                (Some((x, b)), Some(t)) if zero => format!(
                    "({x:.4e} <= its error bound {b:.2e} at --tol {t:e}: a smaller --tol may resolve it)  {note}"
                ),
                (Some((x, b)), _) if zero => {
                    format!("({x:.4e} <= its rounding bound {b:.2e})  {note}")
                }
                _ => note,
            };
            outln!("  {key:<10} {variance:>14}  {note}");
        }
    }
    Ok(())
}

/// An anisotropy bound above this fraction of its value is named: it is a
/// Cauchy–Schwarz bound, several times the radial form's actual error on
/// nearly isotropic spectra (jitter on a disk: bound 14% of the value,
/// error 2%).
const LOOSE_ANISOTROPY: f64 = 0.5;

/// Notes (on stderr) the predictors whose own bound rivals their value: the
/// Fourier forms' truncation bound (the box leaves out energy the sampler
/// does not whiten) and the radial form's anisotropy bound. The values are
/// printed either way; the note says they are uncertain by that much.
fn note_loose_bounds(out: &serde_json::Map<String, Value>, spatial: bool) {
    let truncation = format!(
        "{}: raise --res, or {}",
        args::NOT_WHITE_BEYOND_THE_BOX,
        if spatial {
            "trust spatial"
        } else {
            "compare --method empirical (this integrand has no closed-form autocovariance for the spatial form)"
        }
    );
    for (key, bound, loose, why) in [
        (
            "expected",
            "truncation_bound",
            args::LOOSE_TRUNCATION,
            truncation.as_str(),
        ),
        (
            "fourier",
            "truncation_bound",
            args::LOOSE_TRUNCATION,
            truncation.as_str(),
        ),
        (
            "radial",
            "anisotropy_bound",
            LOOSE_ANISOTROPY,
            "the spectra are not isotropic enough for ring averages (axis-aligned structure)",
        ),
    ] {
        let Some(v) = out.get(key) else { continue };
        let rounding = v["rounding_bound"].as_f64().unwrap_or(0.0);
        if let (Some(value), Some(b)) = (v["variance"].as_f64(), v[bound].as_f64())
            && value > 0.0
            && !varspec::variance::zero_to_rounding(value, rounding)
            && b > loose * value
        {
            eprintln!(
                "note: {key}: its {bound} is {:.2}× the value, so the value is uncertain by that \
                 much: {why}",
                b / value
            );
        }
    }
}

/// The forms that pass over the drawn sets (Fourier, radial, spatial, as
/// `wants` asks) into `out`, returning the largest relative standard error
/// among the Fourier and spatial values that are not zero to rounding
/// (`None` when none is), for the automatic set count.
fn set_forms(
    a: &Args,
    f: &dyn Integrand,
    drawn: &[PointSet],
    random_sets: bool,
    wants: &dyn Fn(MethodArg) -> bool,
    out: &mut serde_json::Map<String, Value>,
) -> anyhow::Result<Option<f64>> {
    let sets = drawn.len();
    let lend = |r: usize| -> Result<PointSet, VarianceError> { Ok(drawn[r].clone()) };
    let mut relative: Option<f64> = None;
    let mut note = |variance: f64, stderr: f64, rounding: f64, sets: usize| {
        if sets >= 2 && variance > rounding && variance > 0.0 {
            let r = stderr / variance;
            relative = Some(relative.map_or(r, |m| m.max(r)));
        }
    };
    if wants(MethodArg::Fourier) || wants(MethodArg::Radial) {
        let res = a.res.unwrap_or(default_res(f.dim()));
        let half = res.saturating_sub(1) / 2;
        let start = Instant::now();
        let bar = progress::bar(sets as u64, "Fourier form, sets");
        let parts = fourier_parts(f, half, a.tol.unwrap_or(DEFAULT_TOLERANCE), sets, |r| {
            bar.inc(1);
            lend(r)
        })?;
        bar.finish_and_clear();
        let seconds = start.elapsed().as_secs_f64();
        if wants(MethodArg::Radial) {
            // The radial form averages the same pass's spectrum over rings:
            // its time is that pass plus the averaging.
            let own = Instant::now();
            let r = radial_from(&parts);
            out.insert(
                "radial".into(),
                json!({
                    "variance": r.variance, "anisotropy_bound": r.anisotropy_bound,
                    "truncation_bound": r.truncation_bound, "rings": r.rings, "res": res,
                    "seconds": seconds + own.elapsed().as_secs_f64(),
                }),
            );
        }
        let e = parts.estimate;
        note(e.variance, e.stderr, e.rounding_bound, e.sets);
        if wants(MethodArg::Fourier) {
            out.insert(
                "fourier".into(),
                json!({
                    "variance": e.variance, "truncation_bound": e.truncation_bound, "rounding_bound": e.rounding_bound, "in_box": e.in_box,
                    "tail": e.tail, "count_term": e.count_term, "stderr": known_stderr(e.stderr, e.sets), "res": res, "sets": e.sets,
                    "seconds": seconds,
                }),
            );
        }
    }
    if wants(MethodArg::Spatial) {
        let n = drawn.iter().map(PointSet::len).max().unwrap_or(0);
        progress::note_spatial_cost(f, &[(n, sets)]);
        let start = Instant::now();
        let bar = progress::bar(sets as u64, "spatial form, sets");
        // The spatial form takes its sets in order: set r starts when r are done.
        let spatial = spatial(f, sets, |r| {
            bar.set_position(r as u64);
            lend(r)
        });
        bar.finish_and_clear();
        let value = match spatial {
            Ok(e) => {
                let mut value = json!({
                "variance": e.variance, "stderr": known_stderr(e.stderr, e.sets),
                "rounding_bound": e.rounding_bound,
                "sets": e.sets, "seconds": start.elapsed().as_secs_f64(),
                });
                if random_sets && no_spread(e.variance, e.stderr, e.rounding_bound, e.sets) {
                    // Every random set gave the same value: what varies
                    // between sets (pairs within the integrand's reach) was
                    // not seen, so the spread says nothing; the automatic
                    // count draws as many sets as it may.
                    relative = Some(f64::INFINITY);
                    value["stderr"] = Value::Null;
                    value["stderr_unknown"] = json!(format!(
                        "all {} sets gave the same value: what varies between random sets (for \
                         an integrand of small support, pairs closer than its reach) did not \
                         occur in them, so their spread of 0 is no standard error; draw more \
                         with --sets, or use --method expected where the sampler has a closed \
                         form",
                        e.sets
                    ));
                } else {
                    note(e.variance, e.stderr, e.rounding_bound, e.sets);
                }
                value
            }
            Err(e @ VarianceError::NoAutocovariance { .. }) => {
                json!({"variance": Value::Null, "skipped": e.to_string()})
            }
            Err(e) => return Err(anyhow!(e)),
        };
        out.insert("spatial".into(), value);
    }
    Ok(relative)
}

/// `predict --family`: the unshifted estimator's MSE over a family of
/// square integrands, by brute force (every member at every point), and
/// for half-planes by the closed form beside it (two independent ways).
fn square(a: &Args, members: usize) -> anyhow::Result<()> {
    use varspec::square::halfplanes::halfplane_mse;
    use varspec::square::{Family, family_mse};

    let family = Family::parse(a.family.as_deref().unwrap_or_default())?;
    let source = a.source.resolve_seeded(Some(2))?;
    varspec::square::mse::check_family_memory(members, source.count())?;
    let sets = source.realizations()?;
    let n = source.points_per_set();
    let start = Instant::now();
    let seed = a.source.seed();
    let brute = family_mse(&sets, &family, members, seed);
    let mut out = serde_json::Map::new();
    out.insert("domain".into(), json!("square"));
    out.insert(
        "estimator".into(),
        json!("unshifted: sum of f over the set on [0,1)^2 divided by N (by the density for a random-count process); error averaged over the family"),
    );
    out.insert("family".into(), json!(family.spec()));
    out.insert("source".into(), json!(source.name()));
    out.insert("seed".into(), json!(seed));
    out.insert("n".into(), json!(n));
    out.insert("sets".into(), json!(sets.len()));
    out.insert(
        "brute_force".into(),
        json!({"mse": brute.mse, "stderr": brute.stderr, "stderr_members": brute.stderr_members,
               "stderr_sets": brute.stderr_sets, "ci_low": brute.interval_95().0,
               "ci_high": brute.interval_95().1, "members": brute.members, "member_seed": seed,
               "seconds": start.elapsed().as_secs_f64()}),
    );
    // The closed form weighs points by 1/N: not for random-count sets.
    if family == Family::HalfPlanes && sets.iter().all(|s| s.density().is_none()) {
        let start = Instant::now();
        let q = 4096;
        let closed =
            varspec::sum::sum(sets.iter().map(|s| halfplane_mse(s, q))) / sets.len() as f64;
        out.insert(
            "closed_form".into(),
            json!({"mse": closed, "directions": q, "seconds": start.elapsed().as_secs_f64()}),
        );
    }
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&Value::Object(out))?);
        return Ok(());
    }
    outln!(
        "{} on {} ({}, {}, seed {seed}), unshifted estimator on the square",
        family.spec(),
        source.name(),
        source.count_label(),
        super::stdout::counted(sets.len(), "set")
    );
    outln!(
        "  brute force  {:.6e}  95% CI [{:.4e}, {:.4e}] over {} members",
        brute.mse,
        brute.interval_95().0,
        brute.interval_95().1,
        brute.members
    );
    if let Some(v) = out.get("closed_form") {
        outln!(
            "  closed form  {:.6e}  (Cramér–von Mises over {} directions)",
            v["mse"].as_f64().unwrap_or(f64::NAN),
            v["directions"]
        );
    }
    Ok(())
}

/// The Fourier box K without --res: 256 in 2D (half-width 127), and in 4D
/// the box of converge and experiment, 2·10 + 1 (variance::fourier_half).
fn default_res(dim: usize) -> usize {
    if dim == 2 {
        256
    } else {
        2 * varspec::variance::fourier_half(dim) + 1
    }
}
