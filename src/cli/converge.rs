//! `varspec converge`: variance against N and the fitted log-log slope with
//! its confidence interval, beside the theoretical rate.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::ValueEnum;
use serde_json::json;

use super::args::DrawArgs;
use super::progress;
use super::source::realization_error;
use varspec::integrands;
use varspec::io::write_atomic;
use varspec::registry;
use varspec::report::plot::{LinePlot, Series, line_plot_png};
use varspec::source::Source;
use varspec::square::{Family, family_mse};
use varspec::variance::{
    ClosedForm, SamplerVariance, VarianceForm, fit_slope, sampler_variance, theoretical_rate,
};

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MethodArg {
    /// Exact spatial form (default where the integrand has a closed-form c_f).
    Spatial,
    /// Fourier form with the Parseval tail.
    Fourier,
    /// The sampler's expected variance in closed form at each N, no sets
    /// and no sampling noise: the exact lattice sum for regular,
    /// uniform-jitter and lattice on an integrand with a closed-form
    /// autocovariance, else the Fourier form with the sampler's expected
    /// spectrum (2D random, jitter, regular, uniform-jitter, multijitter,
    /// cmj; 4D umj and padded sets of those).
    Expected,
}

#[derive(clap::Args)]
#[command(group = clap::ArgGroup::new("levels").required(true).args(["sampler", "points"]))]
#[command(group = clap::ArgGroup::new("subject").required(true).args(["integrand", "family"]))]
pub struct Args {
    /// Sampler name.
    #[arg(long)]
    sampler: Option<String>,
    /// Instead of a sampler: point-set files, one per N (e.g. designs
    /// optimized at each N), comma-separated; every set of a file is a
    /// realization.
    #[arg(long, value_delimiter = ',', conflicts_with_all = ["ns", "sets_given", "params"])]
    points: Vec<PathBuf>,
    /// Integrand spec (the torus, shift-randomized estimator).
    #[arg(long)]
    integrand: Option<String>,
    /// Fit the projection of the sets onto these dimensions, e.g. 0,2 (XU)
    /// or 1,3 (YV), one index per dimension of the integrand; a sampler
    /// then draws 4D sets when an index is 2 or more.
    #[arg(long)]
    dims: Option<String>,
    /// Instead: a family of integrands on the unit square (gaussians,
    /// halfplanes, disks, boxes, file:PATH) and the unshifted estimator's
    /// mean squared error over it, by brute force over the members.
    #[arg(long)]
    family: Option<String>,
    /// Members of the family sample (with --family; default 1024; at least
    /// 2, for the standard error).
    #[arg(value_parser = super::args::whole_at_least::<2, usize>, allow_negative_numbers = true, long)]
    members: Option<usize>,
    /// Comma-separated N values (constrained samplers use the nearest valid N).
    #[arg(short = 'n', long = "n", value_parser = super::args::count, allow_hyphen_values = true, value_delimiter = ',', required_unless_present = "points")]
    ns: Vec<usize>,
    #[command(flatten)]
    draw: DrawArgs,
    /// Predictor (default: spatial, or fourier for integrands without c_f).
    #[arg(long, value_enum)]
    method: Option<MethodArg>,
    /// Fourier box |k| < K/2 for --method fourier or expected (default 256 in
    /// 2D, 21 in 4D; for expected in 2D, at least 8√N + 1 at each N).
    #[arg(value_parser = super::args::frequency_box, allow_negative_numbers = true, long)]
    res: Option<usize>,
    /// CSV of N against variance.
    #[arg(value_parser = super::args::csv_path, long)]
    csv: Option<PathBuf>,
    /// Log-log PNG plot with reference slopes.
    #[arg(long, value_parser = super::args::png_path)]
    png: Option<PathBuf>,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

struct Point {
    requested: usize,
    n: usize,
    /// Realizations behind the variance.
    sets: usize,
    variance: f64,
    /// `None` from a single set: unknown, not 0.
    stderr: Option<f64>,
    truncation_bound: f64,
    /// The level's seed ([`varspec::rng::level_seed`]); `None` for a file.
    seed: Option<u64>,
}

/// Where the sets of one N come from.
enum Level {
    /// A sampler at the nearest valid N to this one.
    Sampler(usize),
    /// Every set of a file.
    File(PathBuf),
}

/// What the variance is of: an integrand on the torus, or a family on the
/// square.
enum Subject {
    Torus(Box<dyn integrands::Integrand>),
    Square(Family),
}

pub fn run(a: Args) -> anyhow::Result<()> {
    super::args::check_outputs_beside(
        [a.csv.as_deref(), a.png.as_deref()],
        a.points.iter().map(|p| Some(p.as_path())),
    )?;
    a.draw.check_results_memory()?;
    let members = super::args::family_members(a.members, a.family.as_deref())?;
    if a.family.is_some() {
        varspec::square::mse::check_family_memory(members, a.draw.sets())?;
    }
    let subject = match (&a.integrand, &a.family) {
        (Some(spec), _) => Subject::Torus(integrands::parse(spec)?),
        (None, Some(spec)) => {
            if a.method.is_some() || a.res.is_some() {
                bail!(
                    "--method and --res apply to --integrand; --family uses the brute-force family MSE"
                );
            }
            Subject::Square(Family::parse(spec)?)
        }
        (None, None) => bail!("give --integrand or --family"),
    };
    let (dim, name) = match &subject {
        Subject::Torus(f) => (f.dim(), f.spec()),
        Subject::Square(family) => (2, family.spec()),
    };
    let plane = a
        .dims
        .as_deref()
        .map(|d| super::args::dims(d, dim))
        .transpose()?;
    // The sets' own dimension: the integrand's, or enough for the plane's
    // largest index (4D when it names u or v, as the projections do).
    let draw_dim = plane
        .as_ref()
        .and_then(|p| p.iter().max())
        .map_or(dim, |&top| if top < dim { dim } else { 4.max(top + 1) });
    let levels: Vec<Level> = if a.points.is_empty() {
        a.ns.iter().map(|&n| Level::Sampler(n)).collect()
    } else {
        a.points.iter().cloned().map(Level::File).collect()
    };
    if levels.len() < 2 {
        bail!(
            "{} to fit a slope",
            if a.points.is_empty() {
                "--n needs at least two values"
            } else {
                "--points needs at least two files"
            }
        );
    }
    // The label of the sets: the sampler, or "point files".
    let label = match &a.sampler {
        Some(spec) => registry::label(spec, &a.draw.params)?,
        None => "point files".into(),
    };
    let method = a.method.unwrap_or(if dim == 2 {
        MethodArg::Spatial
    } else {
        MethodArg::Fourier
    });
    if a.res.is_some() && method == MethodArg::Spatial {
        bail!("--res sets the Fourier form's box: it applies to --method fourier or expected");
    }
    if method == MethodArg::Expected && a.sampler.is_none() {
        bail!(
            "--method expected takes a sampler's closed-form expected spectrum: it needs \
             --sampler (not --points)"
        );
    }
    if method == MethodArg::Expected && plane.is_some() {
        bail!(
            "--dims with --method expected: the closed-form expected spectrum is of the \
             sampler's own sets, not of a projection; use --method spatial or fourier"
        );
    }
    if method == MethodArg::Expected && a.draw.sets_were_given() {
        bail!("--sets: --method expected draws no sets (the expectation is in closed form)");
    }
    if !a.points.is_empty() && a.family.is_none() && a.draw.seed_was_given() {
        bail!(
            "--seed with --points draws only --family members; the files are the sets, and \
             --integrand has no members"
        );
    }
    // Each level's share of the work: the spatial form's pair evaluations
    // (O(N²) per set), else N; a file's N is not known before it is read.
    let spatial_on = match (&subject, method) {
        (Subject::Torus(f), MethodArg::Spatial) => Some(f.as_ref()),
        _ => None,
    };
    let sets = a.draw.sets();
    let weights: Vec<u64> = levels
        .iter()
        .map(|level| match (level, spatial_on) {
            (Level::Sampler(n), Some(f)) => {
                (sets as f64 * varspec::variance::pair_evaluations(f, *n)).max(1.0) as u64
            }
            (Level::Sampler(n), None) => *n as u64,
            (Level::File(_), _) => 1,
        })
        .collect();
    if let Some(f) = spatial_on
        && a.points.is_empty()
    {
        let runs: Vec<(usize, usize)> = a.ns.iter().map(|&n| (n, sets)).collect();
        progress::note_spatial_cost(f, &runs);
    }
    let bar = progress::share_bar(weights.iter().sum(), "converge");
    let mut points = Vec::new();
    // The closed form --method expected used (the same at every level).
    let mut expected_form = None;
    // Levels whose sampler is not what its name promises (a thin
    // multi-jittered grid): the table's rate is not theirs.
    let mut caveats = 0;
    for (level, &weight) in levels.iter().zip(&weights) {
        let (source, requested, seed) = match level {
            Level::Sampler(requested) => {
                let sampler_name = a.sampler.as_deref().unwrap_or_default();
                let build =
                    |d| registry::build_nearest(sampler_name, *requested, d, &a.draw.params);
                // A plane of a sampler's own larger sets (--dims 0,1 of
                // umj's 4D sets) is drawn in the sampler's dimension.
                let (sampler, _) = match (build(Some(draw_dim)), &plane) {
                    (Err(varspec::samplers::SamplerError::Dimension { .. }), Some(p)) => {
                        build(None).and_then(|(s, n)| {
                            let top = p.iter().max().copied().unwrap_or(0);
                            if s.dim() > top {
                                Ok((s, n))
                            } else {
                                build(Some(draw_dim))
                            }
                        })
                    }
                    (built, _) => built,
                }
                .map_err(|e| match e {
                    varspec::samplers::SamplerError::Dimension { max, .. } if max < draw_dim => {
                        let what = match &a.dims {
                            Some(d) => format!("the plane --dims {d}"),
                            None => format!("{name} is {dim}-dimensional and"),
                        };
                        anyhow::anyhow!(
                            "{e}: {what} needs {draw_dim}D sets; use a sampler that draws them \
                             (umj, padded:xy=...,uv=..., or jitter, random, sobol)"
                        )
                    }
                    e => e.into(),
                })?;
                if super::args::note_caveat(sampler.as_ref()) {
                    caveats += 1;
                }
                let seed = varspec::rng::level_seed(a.draw.seed(), sampler.points_per_set());
                let source = Source::Sampler {
                    name: format!("{label} N={}", sampler.points_per_set()),
                    sampler,
                    seed,
                    sets: a.draw.sets(),
                    dims: plane.clone(),
                };
                (source, *requested, Some(seed))
            }
            Level::File(path) => {
                let sets = if plane.is_some() {
                    varspec::io::read_point_sets(path)?
                } else {
                    varspec::io::read_point_sets_of_dim(path, dim)?
                };
                if let Some(other) = sets.iter().find(|s| s.len() != sets[0].len()) {
                    bail!(
                        "{}: its sets hold {} and {} points; a level of the fit needs one N (a \
                         random-count process such as isotropic-jitter: converge --sampler draws \
                         its levels, or predict FILE --density λ gives one level's variance)",
                        path.display(),
                        sets[0].len(),
                        other.len()
                    );
                }
                let n = sets[0].len();
                let source = Source::File {
                    sets,
                    dims: plane.clone(),
                    name: path.display().to_string(),
                };
                (source, n, None)
            }
        };
        let (n, count) = (source.points_per_set(), source.count());
        let (variance, stderr, truncation_bound) = match (&subject, method) {
            (Subject::Square(family), _) => {
                let sets = source.realizations()?;
                let e = family_mse(&sets, family, members, a.draw.seed());
                (e.mse, e.stderr, 0.0)
            }
            (Subject::Torus(f), method) => {
                let half = a.res.map_or(varspec::variance::fourier_half(dim), |r| {
                    r.saturating_sub(1) / 2
                });
                let e = match (method, &source) {
                    (MethodArg::Expected, Source::Sampler { sampler, .. }) => {
                        let closed =
                            ClosedForm::of(sampler.as_ref(), f.as_ref()).with_context(|| {
                                format!(
                                    "--method expected: {label} has no closed form for {name} in \
                                 {dim}D (a closed-form expected spectrum: 2D random, jitter, \
                                 regular, uniform-jitter, multijitter and cmj, 4D umj and padded \
                                 sets of those; or a lattice: regular, uniform-jitter and \
                                 lattice on an integrand with a closed-form autocovariance); use \
                                 --method spatial or fourier"
                                )
                            })?;
                        if expected_form.is_none()
                            && a.res.is_some()
                            && matches!(closed, ClosedForm::Lattice(_))
                        {
                            eprintln!("note: {}", super::args::LATTICE_HAS_NO_BOX);
                        }
                        expected_form = Some(closed.name());
                        // Without --res the box grows with N where that
                        // matters (variance::expected_min_half).
                        let half = match a.res {
                            None => half.max(varspec::variance::expected_min_half(dim, n)),
                            Some(_) => half,
                        };
                        let p = closed.variance(f.as_ref(), half)?;
                        SamplerVariance {
                            variance: p.variance,
                            stderr: 0.0,
                            truncation_bound: p.truncation_bound,
                            rounding_bound: p.rounding_bound,
                            method: "expected",
                        }
                    }
                    _ => {
                        let form = match method {
                            MethodArg::Spatial => VarianceForm::Spatial,
                            _ => VarianceForm::Fourier { half },
                        };
                        sampler_variance(f.as_ref(), count, form, |r| {
                            source.get(r).map_err(|e| realization_error(r, e))
                        })?
                    }
                };
                if varspec::variance::zero_to_rounding(e.variance, e.rounding_bound) {
                    bail!(
                        "N = {n}: the variance {:e} is at or below the {} form's rounding bound \
                         {:e}: it is zero to rounding ({label} integrates {name} to machine precision \
                         at this N), and a log-log slope through it would fit rounding noise",
                        e.variance,
                        e.method,
                        e.rounding_bound
                    );
                }
                (e.variance, e.stderr, e.truncation_bound)
            }
        };
        if variance <= 0.0 {
            bail!(
                "N = {n}: predicted variance {variance:e} is not positive; a log-log slope needs positive values"
            );
        }
        if let Some(p) = points.iter().find(|p: &&Point| p.n == n) {
            if a.points.is_empty() {
                bail!(
                    "--n {} and {requested} both become N = {n} for {label} (constrained N); give N values that stay distinct",
                    p.requested
                );
            }
            bail!("two of --points hold sets of N = {n}; give one file per N");
        }
        points.push(Point {
            requested,
            n,
            sets: count,
            variance,
            stderr: (count >= 2).then_some(stderr),
            truncation_bound,
            seed,
        });
        bar.inc(weight);
    }
    bar.finish_and_clear();
    let ns: Vec<f64> = points.iter().map(|p| p.n as f64).collect();
    let vars: Vec<f64> = points.iter().map(|p| p.variance).collect();
    let fit = fit_slope(&ns, &vars)?;
    let theory = match (&subject, &a.sampler) {
        // The table's rates are for default parameters: `cmj --param m=4`
        // has none, as `cmj:m=4` has none; nor has a level on a thin grid.
        // Nor has a projection: the table is of the sets themselves.
        (Subject::Torus(f), Some(sampler))
            if a.draw.params.is_empty() && caveats == 0 && plane.is_none() =>
        {
            theoretical_rate(sampler, f.class(), dim)
        }
        _ => None,
    };
    let adjusted: Vec<String> = points
        .iter()
        .filter(|p| p.n != p.requested)
        .map(|p| format!("{} -> {}", p.requested, p.n))
        .collect();
    if let Some(path) = &a.csv {
        #[derive(serde::Serialize)]
        struct Row {
            n: usize,
            variance: f64,
            stderr: Option<f64>,
            truncation_bound: f64,
            seed: Option<u64>,
        }
        write_atomic(path, |w| {
            varspec::io::write_csv_rows(
                w,
                points.iter().map(|p| Row {
                    n: p.n,
                    variance: p.variance,
                    stderr: p.stderr,
                    truncation_bound: p.truncation_bound,
                    seed: p.seed,
                }),
            )
        })?;
    }
    if let Some(path) = &a.png {
        // Reference slopes start a factor 3 below the first level, so the
        // one the data follows runs beside it rather than under it.
        let (n0, v0) = (ns[0], vars[0] / 3.0);
        let line = |slope: f64| {
            vec![
                (n0, v0),
                (ns[ns.len() - 1], v0 * (ns[ns.len() - 1] / n0).powf(slope)),
            ]
        };
        // Each level's 95% interval (normal, from its standard error over
        // the sets or members; none where one set left it unknown),
        // widened by the Fourier box's truncation bound (0 for the
        // spatial form and the square).
        let z = varspec::variance::NORMAL_95;
        let bars = points
            .iter()
            .map(|p| {
                let half = z * p.stderr.unwrap_or(0.0) + p.truncation_bound;
                (p.variance - half, p.variance + half)
            })
            .collect();
        let bars_are = match method {
            _ if matches!(subject, Subject::Square(_)) => "95% CI",
            MethodArg::Spatial => "95% CI",
            MethodArg::Fourier => "95% CI + truncation bound",
            MethodArg::Expected => "truncation bound",
        };
        let mut series = vec![Series {
            label: format!("{label} (slope {:.3}; bars: {bars_are})", fit.slope),
            points: ns.iter().copied().zip(vars.iter().copied()).collect(),
            reference: false,
            error_bars: bars,
        }];
        for s in [-1.0, -1.5, -2.0, -3.0] {
            series.push(Series {
                label: format!("N^{s}"),
                points: line(s),
                reference: true,
                error_bars: Vec::new(),
            });
        }
        let plot = LinePlot {
            title: match (&a.dims, &subject) {
                (Some(d), _) => format!("{label} (dims {d}) on {name}"),
                (None, Subject::Square(_)) => format!("{label} on {name}, unit square, no shift"),
                (None, Subject::Torus(_)) => format!("{label} on {name}"),
            },
            x_label: "N".into(),
            y_label: match subject {
                Subject::Square(_) => "MSE (unit square, no shift)".into(),
                Subject::Torus(_) => "variance".into(),
            },
            log_log: true,
            series,
        };
        line_plot_png(&plot, path)?;
    }
    if a.json {
        // One count for a sampler's --sets; per level for files.
        let points_sets = if method == MethodArg::Expected {
            json!(0)
        } else if a.points.is_empty() {
            json!(a.draw.sets())
        } else {
            json!(points.iter().map(|p| p.sets).collect::<Vec<_>>())
        };
        let out = json!({
            "sampler": a.sampler, "files": a.points.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(), "integrand": name, "dims": plane,
            "method": match (&subject, method) {
                (Subject::Square(_), _) => "square: unshifted estimator's MSE over the family (brute force)",
                (_, MethodArg::Spatial) => "spatial",
                (_, MethodArg::Fourier) => "fourier",
                (_, MethodArg::Expected) if expected_form == Some("lattice sum") => "expected: the exact lattice sum (1/N)·Σ c_f over the lattice",
                (_, MethodArg::Expected) => "expected: the sampler's closed-form expected spectrum",
            },
            "sets": points_sets,
            "points": points.iter().map(|p| json!({"n": p.n, "requested": p.requested, "variance": p.variance, "stderr": p.stderr, "truncation_bound": p.truncation_bound, "seed": p.seed})).collect::<Vec<_>>(),
            "slope": fit.slope, "slope_ci": fit.slope_ci.map(|(l, h)| vec![l, h]),
            "theory": theory, "adjusted_n": adjusted,
            // What the family's MSE was drawn over: its members and their
            // seed (with --points the seed draws nothing else).
            "members": match &subject {
                Subject::Square(family) => Some(family.sample_size(members)),
                Subject::Torus(_) => None,
            },
            "member_seed": matches!(subject, Subject::Square(_)).then(|| a.draw.seed()),
        });
        outln!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    if !adjusted.is_empty() {
        outln!("N adjusted to fit {label}: {}", adjusted.join(", "));
    }
    // The Fourier forms' truncation bound is part of a level's error:
    // shown beside it, and named when it rivals the value.
    let bounded = points.iter().any(|p| p.truncation_bound > 0.0);
    let bound_header = if bounded { "  truncation_bound" } else { "" };
    // The square's value is the unshifted estimator's MSE, not a variance.
    let value_header = match subject {
        Subject::Square(_) => "MSE",
        Subject::Torus(_) => "variance",
    };
    outln!(
        "{:>8} {:>14} {:>12}{bound_header}",
        "N",
        value_header,
        "stderr"
    );
    for p in &points {
        let stderr = match p.stderr {
            _ if method == MethodArg::Expected => "closed form".into(),
            Some(s) => format!("{s:.2e}"),
            None => "unknown".into(),
        };
        let bound = if bounded {
            format!("  {:>16.2e}", p.truncation_bound)
        } else {
            String::new()
        };
        outln!("{:>8} {:>14.6e} {stderr:>12}{bound}", p.n, p.variance);
    }
    let loose: Vec<String> = points
        .iter()
        .filter(|p| p.truncation_bound > super::args::LOOSE_TRUNCATION * p.variance)
        .map(|p| format!("N = {} ({:.2}×)", p.n, p.truncation_bound / p.variance))
        .collect();
    if !loose.is_empty() {
        // The spatial form needs a closed-form autocovariance (not defocus
        // or layers).
        let spatial = matches!(&subject, Subject::Torus(f) if f.has_autocov());
        eprintln!(
            "note: the Fourier box's truncation bound exceeds {:.0}% of the value at {}: {}, \
             so those values and the slope through them are uncertain by that much; raise \
             --res{}",
            100.0 * super::args::LOOSE_TRUNCATION,
            loose.join(", "),
            super::args::NOT_WHITE_BEYOND_THE_BOX,
            if spatial {
                ", or use --method spatial"
            } else {
                " (the spatial form needs a closed-form autocovariance, which this integrand lacks)"
            }
        );
    }
    let ci = fit
        .slope_ci
        .map_or("n/a (needs 3 or more N)".into(), |(l, h)| {
            format!("[{l:.3}, {h:.3}]")
        });
    let outside = fit.excludes(theory);
    let theory = theory.map_or(
        if plane.is_some() {
            "none (the table of known rates is of whole sets, not projections)".into()
        } else if !a.points.is_empty() {
            "none (files name no sampler, and the table of known rates is of samplers)".into()
        } else {
            "none (the table of known rates has no entry for this sampler and integrand)".into()
        },
        |t| format!("{t}"),
    );
    outln!("slope {:.3}, 95% CI {ci}; theory {theory}", fit.slope);
    if outside {
        outln!(
            "note: the theory's rate lies outside the interval. The table's rates are \
             asymptotic: over a finite range of N sub-leading terms can move a fit outside its \
             interval (Poisson disk measures -1.08 to -1.27 at N = 64…4096 against -1: \
             results/rates); and they are for edges in general position: an edge parallel to \
             an axis meets N-rooks stratification (cmj, multijitter, nrooks, sobol), which \
             integrates it faster (cmj on an axis-aligned box: -2)."
        );
    }
    super::stdout::wrote([&a.csv, &a.png].into_iter().flatten());
    Ok(())
}
