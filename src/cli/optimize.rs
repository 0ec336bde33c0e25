//! `varspec optimize`: gradient descent on point positions toward a target
//! spectrum, with a report against the classic samplers.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::bail;
use clap::Subcommand;
use serde_json::json;

use super::{args, progress};
use varspec::baseline::CLASSIC;
use varspec::design::torus::{TorusPlan, TorusRequest, results_bytes};
use varspec::io::write_atomic;
use varspec::optimize::adapted::{
    CheckpointEvent, CheckpointPlan, checkpoint_path, remove_checkpoints, stray_checkpoints,
};
use varspec::registry;
use varspec::spectrum::Upsampling;

#[derive(Subcommand)]
pub enum OptimizeCommand {
    /// Move points to minimize Σ W(k)·P_S(k) for a target weight W.
    Points(PointsArgs),
    /// Shear a structured 4D sampler (x += a·u, y += b·v) to minimize the
    /// variance of the (x, y)-shifted estimator on a 4D integrand.
    Shear(ShearArgs),
}

#[derive(clap::Args)]
pub struct ShearArgs {
    /// Padded 4D sampler to shear: umj, or padded:xy=SAMPLER,uv=SAMPLER.
    #[arg(long, default_value = "umj")]
    sampler: String,
    /// Sampler parameter key=value (repeatable; see `varspec sample
    /// --list`; wins over the same key in the shorthand; a nested spec with
    /// commas goes here: --param 'uv=poisson-disk:radius=0.6,max-trials=1000000').
    #[arg(long = "param", value_parser = super::args::key_value)]
    params: Vec<(String, String)>,
    /// Points per set.
    #[arg(short = 'n', long = "n", value_parser = super::args::count, allow_negative_numbers = true)]
    n: usize,
    /// 4D light field, e.g. defocus:shape=box,size=0.3,c=0.6 or layers:c1=0.5,c2=-0.2,
    /// or a scene pixel scene:NAME,px=X,py=Y.
    #[arg(long)]
    integrand: String,
    /// Sheared sets written with -o (the search itself uses the expected
    /// variance over the sampler's randomness, not these sets).
    #[arg(value_parser = super::args::whole_at_least::<1, usize>, allow_negative_numbers = true, long, default_value_t = super::args::DEFAULT_SETS)]
    sets: usize,
    /// Seed of the written sets, of the independent check and of any
    /// realizations behind an estimated half.
    #[arg(value_parser = super::args::whole::<u64>, allow_negative_numbers = true, long, default_value_t = 0)]
    seed: u64,
    /// Shears searched in [−range, range] on each axis [default: 2, or
    /// wider to hold the integrand spectrum's directions].
    #[arg(allow_negative_numbers = true, long)]
    range: Option<f64>,
    /// Fresh realizations of the independent before/after check (0: skip it).
    #[arg(value_parser = super::args::whole::<usize>, allow_negative_numbers = true, long, default_value_t = 4000)]
    realizations: usize,
    /// Write the sheared sets here (point-set CSV; NumPy .npy when the name ends in .npy).
    #[arg(value_parser = args::point_file_path, short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Write XU and YV projection spectra before and after as PREFIX-{xu,yv}-{before,after}.png.
    #[arg(long)]
    png_prefix: Option<String>,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
pub struct PointsArgs {
    /// Points per set.
    #[arg(short = 'n', long = "n", value_parser = super::args::count, allow_negative_numbers = true)]
    n: usize,
    /// Dimension (1 to 4).
    #[arg(value_parser = super::args::whole::<usize>, allow_negative_numbers = true, short = 'd', long = "dim", default_value_t = 2)]
    dim: usize,
    /// Where the points are used: on the torus under a random shift, or
    /// on the unit square as they are (no shift).
    #[arg(long, value_enum, default_value_t = DomainArg::Torus)]
    domain: DomainArg,
    /// Target. Torus: an integrand spec (W = P_f), family:disks, power:A or
    /// radial:FILE.csv. Square: family MSEs and repulsion, e.g.
    /// halfplanes+gaussians+16*blue (families: halfplanes, gaussians[:vmin=,vmax=], disks[:rmin=,rmax=], boxes[:smin=,smax=]).
    #[arg(long)]
    target: String,
    /// Independent realizations, optimized in parallel.
    #[arg(value_parser = super::args::whole_at_least::<1, usize>, allow_negative_numbers = true, long, default_value_t = super::args::DEFAULT_SETS)]
    sets: usize,
    /// Maximum iterations per set (default 1000 on the torus, 2000 on the square).
    #[arg(value_parser = super::args::whole::<usize>, allow_negative_numbers = true, long)]
    iters: Option<usize>,
    /// Seed of the starting sets.
    #[arg(value_parser = super::args::whole::<u64>, allow_negative_numbers = true, long, default_value_t = 0)]
    seed: u64,
    /// Sampler of the starting sets (default: lattice, the best integration
    /// lattice by the exact variance, for 2D integrands with a closed-form
    /// autocovariance; cmj for other 2D integrand targets; random for other
    /// torus targets; umj for projection targets; on the square jitter, or
    /// cmj where N is not m²).
    #[arg(long, value_name = "SAMPLER")]
    init: Option<String>,
    /// The same as --init (the sampler, as in every other command).
    #[arg(long = "sampler", value_name = "SAMPLER", conflicts_with = "init")]
    sampler_flag: Option<String>,
    /// Parameter of the starting sampler, key=value (repeatable; see
    /// `varspec sample --list`; wins over the same key in the shorthand;
    /// a nested spec with commas goes here: --param 'uv=poisson-disk:radius=0.6,max-trials=1000000').
    #[arg(long = "param", value_parser = super::args::key_value)]
    params: Vec<(String, String)>,
    /// Square: family members the result and the classic samplers are scored
    /// on (at least 2, for the standard error) [default: 1024].
    #[arg(value_parser = super::args::whole_at_least::<2, usize>, allow_negative_numbers = true, long)]
    members: Option<usize>,
    /// Square: seed of the scoring members (the descent draws its own members
    /// from --seed on other streams) [default: 1].
    #[arg(value_parser = super::args::whole::<u64>, allow_negative_numbers = true, long)]
    score_seed: Option<u64>,
    /// Frequency box |k| < K/2 of the loss, as in spectrum and predict
    /// (default K = 2h + 1 with h = 2.5·N^(1/d) within [16, 400] for families
    /// and power laws, 8·N^(1/d) within [32, 256] for integrands).
    #[arg(value_parser = super::args::frequency_box, allow_negative_numbers = true, long)]
    res: Option<usize>,
    /// NUFFT tolerance of the loss and gradient (the speed/accuracy knob;
    /// default 1e-6, as the blue-noise sampler).
    #[arg(allow_negative_numbers = true, long, value_parser = args::tolerance)]
    tol: Option<f64>,
    /// Stop when the loss improves by less than this, relatively, over 50
    /// iterations (default 1e-3 for blue-noise targets: the same variance on
    /// unseen disks and boxes as 1e-4 in half the time; 1e-4 for integrand
    /// and projection targets; 0: never). Not for --domain square, whose
    /// stochastic descent runs its --iters (2000) to the cap.
    #[arg(allow_negative_numbers = true, long)]
    rel_tol: Option<f64>,
    /// The non-uniform FFT's upsampling factor σ: the fine grid has σ times
    /// the box's side per axis. `1.25` shrinks the FFT (2.6× in 2D) for a
    /// wider kernel (reaches --tol down to 1e-9); `auto` picks the faster
    /// for this N (1.25 below about 200,000 points in 2D).
    #[arg(long, value_enum, default_value_t = UpsamplingArg::Auto)]
    upsampling: UpsamplingArg,
    /// Output point-set file (CSV; NumPy .npy when the name ends in .npy).
    #[arg(value_parser = args::point_file_path, short = 'o', long = "output")]
    output: PathBuf,
    /// JSON report: loss curve, wall time, loss beside the classic samplers.
    #[arg(value_parser = super::args::json_path, long)]
    report: Option<PathBuf>,
    /// CSV of set 0's loss against wall time: iteration,seconds,loss.
    #[arg(value_parser = super::args::csv_path, long)]
    curve: Option<PathBuf>,
    /// Log-log PNG of set 0's loss against wall time, with the classic samplers' losses.
    #[arg(long, value_parser = super::args::png_path)]
    curve_png: Option<PathBuf>,
    /// Torus, 2D blue-noise targets: coarse-to-fine, a first phase (at most
    /// 300 iterations) on a quarter of the box, then the full box from a
    /// fifth of the step. The default from 4096 points on (lower variance on
    /// unseen disks and boxes from 4096 to 65,536 points; worse at 1024)
    #[arg(long, conflicts_with = "no_coarse")]
    coarse: bool,
    /// Torus, 2D blue-noise targets: one phase on the full box, whatever N
    #[arg(long)]
    no_coarse: bool,
    /// Torus designs toward one target (not 4D projection or square
    /// designs): save the descent's whole state here while it runs
    /// (set r of several in PATH.r); a run given the same path continues
    /// from it, with the same result as a run never stopped, and removes it
    /// once the output is written.
    #[arg(long)]
    checkpoint: Option<PathBuf>,
    /// Least wall time between two checkpoint saves, in seconds.
    #[arg(allow_negative_numbers = true, long, default_value_t = 60.0)]
    checkpoint_every: f64,
}

pub fn run(c: OptimizeCommand) -> anyhow::Result<()> {
    match c {
        OptimizeCommand::Points(a) => points(a),
        OptimizeCommand::Shear(a) => shear(a),
    }
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum UpsamplingArg {
    Auto,
    #[value(name = "2")]
    Two,
    #[value(name = "1.25")]
    FiveFourths,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum DomainArg {
    Torus,
    Square,
}

fn points(mut a: PointsArgs) -> anyhow::Result<()> {
    a.init = a.init.take().or(a.sampler_flag.take());
    args::check_outputs_beside(
        [
            Some(a.output.as_path()),
            a.report.as_deref(),
            a.curve.as_deref(),
            a.curve_png.as_deref(),
        ],
        varspec::optimize::target::files_read(
            &a.target,
            match a.domain {
                DomainArg::Torus => varspec::optimize::adam::Domain::Torus,
                DomainArg::Square => varspec::optimize::adam::Domain::Square,
            },
        )
        .into_iter()
        .map(Some),
    )?;
    varspec::memory::check(
        &format!(
            "the results of {} designed sets of {} points (with their loss curves)",
            a.sets, a.n
        ),
        Some(results_bytes(a.sets, a.n, a.dim, a.iters)),
        "lower --sets or --iters",
    )?;
    if !(a.checkpoint_every >= 0.0 && a.checkpoint_every.is_finite()) {
        bail!(
            "--checkpoint-every {}: give a number of seconds >= 0",
            a.checkpoint_every
        );
    }
    let projections = a.dim == 4 && varspec::optimize::projections::is_projection_target(&a.target);
    if a.dim == 4
        && !projections
        && varspec::integrands::parse(&a.target)
            .ok()
            .and_then(|f| f.light_field().map(|l| l.layer_shears().len() == 1))
            .unwrap_or(false)
    {
        eprintln!(
            "note: --target {t} alone descends the fully shifted estimator's 4D loss on a small \
             box; for the (x, y)-shifted variance sheared sets are judged by, give it as a \
             projection target: --target '{t};' (or with xy:/uv: terms), faster and blue",
            t = a.target
        );
    }
    if a.checkpoint.is_some() && (a.domain == DomainArg::Square || projections) {
        bail!(
            "--checkpoint saves torus descents toward one target; {} designs do not take it",
            if projections {
                "4D projection-target"
            } else {
                "--domain square"
            }
        );
    }
    if let Some(path) = &a.checkpoint {
        for r in 0..a.sets {
            varspec::io::check_output(&checkpoint_path(path, r, a.sets))?;
        }
    }
    if a.domain == DomainArg::Square || projections {
        // Knobs of the spectral descent toward one torus target: the other
        // designs have their own and would silently ignore these.
        let given: Vec<&str> = [
            (a.tol.is_some(), "--tol"),
            (a.res.is_some(), "--res"),
            (a.upsampling != UpsamplingArg::Auto, "--upsampling"),
            (a.coarse, "--coarse"),
            (a.no_coarse, "--no-coarse"),
            (
                a.domain == DomainArg::Square && a.rel_tol.is_some(),
                "--rel-tol",
            ),
        ]
        .into_iter()
        .filter_map(|(on, flag)| on.then_some(flag))
        .collect();
        if !given.is_empty() {
            bail!(
                "{}: options of the descent toward one torus target; {} designs do not take {}",
                given.join(", "),
                if projections {
                    "4D projection-target"
                } else {
                    "--domain square"
                },
                if given.len() == 1 { "it" } else { "them" }
            );
        }
    }
    if a.domain == DomainArg::Square {
        return points_square(a);
    }
    if a.members.is_some() || a.score_seed.is_some() {
        bail!(
            "--members and --score-seed choose the family members --domain square designs are \
             scored on; a torus design is scored by its target's loss"
        );
    }
    if projections {
        return points_projections(a);
    }
    let plan = TorusPlan::new(TorusRequest {
        n: a.n,
        dim: a.dim,
        target: a.target.clone(),
        sets: a.sets,
        iters: a.iters,
        seed: a.seed,
        init: a.init.clone(),
        init_params: a.params.clone(),
        tol: a.tol,
        rel_tol: a.rel_tol,
        upsampling: match a.upsampling {
            UpsamplingArg::Auto => None,
            UpsamplingArg::Two => Some(Upsampling::Two),
            UpsamplingArg::FiveFourths => Some(Upsampling::FiveFourths),
        },
        res: a.res,
        coarse: match (a.coarse, a.no_coarse) {
            (true, _) => Some(true),
            (_, true) => Some(false),
            _ => None,
        },
    })?;
    if let Some(found) = plan.lattice() {
        let h = found.lattice.shortest_dual();
        outln!(
            "start: the best of {} integration lattices of {} points (dual basis ({}, 0), ({}, {}); shortest dual vector ({}, {}): on lines {:.3} apart), exact variance {:.4e}",
            found.candidates,
            a.n,
            found.lattice.a,
            found.lattice.b,
            found.lattice.c,
            h[0],
            h[1],
            1.0 / ((h[0] * h[0] + h[1] * h[1]) as f64).sqrt(),
            found.variance
        );
        if let Some((sum, half)) = found.dual_sum {
            outln!(
                "  (at the spatial form's rounding floor {:.1e}; ranked by the dual sum over |k|inf <= {half}: {sum:.4e})",
                found.rounding_bound
            );
        }
    }
    let frequencies = plan.optimizer().frequencies();
    outln!(
        "memory: about {:.0} MiB (box |k| <= {}: {} frequencies; {} set(s) at a time)",
        plan.memory_bytes() / (1024.0 * 1024.0),
        frequencies.half,
        frequencies.len(),
        rayon::current_num_threads().min(a.sets)
    );
    let bar = progress::bar((a.sets * (plan.iters() + 1)) as u64, "optimizing");
    let run = plan.run_line();
    let on_event = |event: CheckpointEvent| match event {
        CheckpointEvent::Resumed {
            set,
            iteration,
            path,
        } => {
            bar.inc(iteration as u64);
            bar.suspend(|| {
                eprintln!(
                    "set {set}: continuing from iteration {iteration} saved in {}",
                    path.display()
                )
            });
        }
        CheckpointEvent::Saved { .. } => {}
        CheckpointEvent::Failed { set, error } => {
            bar.suspend(|| {
                eprintln!("warning: set {set}: checkpoint not saved ({error}); the descent goes on")
            });
        }
    };
    if let Some(path) = &a.checkpoint {
        let stray = stray_checkpoints(path, a.sets);
        if !stray.is_empty() {
            let names: Vec<String> = stray.iter().map(|p| p.display().to_string()).collect();
            eprintln!(
                "note: {} {} of a run with another --sets: this run of {} reads and removes only {}; \
                 the others stay",
                names.join(", "),
                if names.len() == 1 {
                    "is a checkpoint"
                } else {
                    "are checkpoints"
                },
                super::stdout::counted(a.sets, "set"),
                if a.sets == 1 {
                    path.display().to_string()
                } else {
                    format!(
                        "{} to {}",
                        checkpoint_path(path, 0, a.sets).display(),
                        checkpoint_path(path, a.sets - 1, a.sets).display()
                    )
                }
            );
        }
    }
    let checkpoint = a.checkpoint.as_deref().map(|path| CheckpointPlan {
        path,
        run: &run,
        every: std::time::Duration::from_secs_f64(a.checkpoint_every),
        on_event: &on_event,
    });
    // The classic samplers' exact variances come after the descent: the
    // bar ends with it, and a long comparison is said before it starts.
    let on_designed = || {
        bar.finish_and_clear();
        if let Some(s) = plan.comparison_estimate().filter(|&s| s > LONG_COMPARISON) {
            eprintln!(
                "comparing with {} classic samplers x {} sets by the exact variance (spatial form, O(N^2) per set): about {}",
                CLASSIC.len(),
                a.sets.max(8),
                progress::duration_words(std::time::Duration::from_secs_f64(s))
            );
        }
    };
    let design = plan.run(&|_, _| bar.inc(1), checkpoint.as_ref(), &on_designed)?;
    varspec::io::write_point_file(&a.output, &design.points)?;
    if let Some(path) = &a.checkpoint {
        for (file, e) in remove_checkpoints(path, a.sets) {
            eprintln!("warning: checkpoint {} not removed: {e}", file.display());
        }
    }
    // Steps taken: a loss curve holds the start's loss and each step's.
    let coarse = match (design.coarse_iterations[0], plan.coarse_half()) {
        (c, Some(h)) if c > 0 => format!("{} on the box |k| <= {h} then ", c - 1),
        _ => String::new(),
    };
    let steps = design.iterations[0].saturating_sub(1);
    outln!(
        "{} set(s) of {} points for {} in {:.2} s ({coarse}{steps} step{} for set 0, {}); loss {:.4e}; compared with the classic samplers in {:.2} s",
        a.sets,
        a.n,
        a.target,
        design.run.seconds,
        if steps == 1 { "" } else { "s" },
        design.stopped[0].describe(),
        design.mean_loss,
        design.comparison_seconds
    );
    if let Some(v) = design.exact_variance {
        if v <= design.rounding {
            outln!(
                "  exact variance (spatial form, no box) {v:.4e}: at the form's rounding floor ({:.1e}); the in-box loss resolves it",
                design.rounding
            );
        } else {
            outln!(
                "  exact variance (spatial form, no box) {v:.4e}: {:.0}% of it lies beyond the box",
                100.0 * (1.0 - design.mean_loss / v).max(0.0)
            );
        }
    }
    if design.kept_start > 0 {
        outln!(
            "  {} of {} set(s): the descent did not lower the {}, so the start ({}) is returned unchanged",
            design.kept_start,
            a.sets,
            if design.exact_variance.is_some() {
                "exact variance"
            } else {
                "loss"
            },
            design.run.init
        );
    }
    for (name, v) in &design.comparison {
        let exact = v["exact_variance"]
            .as_f64()
            .map(|e| format!("  exact variance {e:.4e}"))
            .unwrap_or_default();
        outln!(
            "  {name:<14} loss {:.4e}{exact}{}",
            v["loss"].as_f64().unwrap_or(f64::NAN),
            other_n(v, a.n)
        );
    }
    if let Some((name, v)) = design.beaten_by() {
        // Why, where it is known: a start returned unchanged.
        let why = if design.kept_start > 0 {
            format!(
                "the start ({}) is a point the descent does not leave (a lattice aliases a \
                 target whose frequencies are multiples of N); ",
                design.run.init
            )
        } else {
            "more --iters may help; ".into()
        };
        eprintln!(
            "warning: the design's exact variance {:.4e} is above {name}'s {v:.4e} on its own \
             target: {why}try --init {name}",
            design.exact_variance.unwrap_or(f64::NAN),
        );
    }
    let baselines: Vec<(&str, f64)> = design.baselines.iter().map(|b| (b.name, b.score)).collect();
    design_outputs(
        &a,
        &format!("{} N={}", a.target, a.n),
        (&design.loss_curve_seconds, &design.loss_curve),
        &baselines,
        &design,
    )
}

/// `optimize points -d 4` with targets per projection: one 4D descent on
/// the planes' spectral losses, from umj by default.
fn points_projections(a: PointsArgs) -> anyhow::Result<()> {
    use varspec::design::projections::{ProjectionRequest, design_projections};
    let request = ProjectionRequest {
        n: a.n,
        target: a.target.clone(),
        sets: a.sets,
        iters: a.iters,
        rel_tol: a.rel_tol,
        seed: a.seed,
        init: a.init.clone(),
        init_params: a.params.clone(),
    };
    let bar = progress::bar(
        (a.sets * (a.iters.unwrap_or(1000) + 1)) as u64,
        "optimizing",
    );
    let design = design_projections(&request, &|_, _| bar.inc(1))?;
    bar.finish_and_clear();
    varspec::io::write_point_file(&a.output, &design.points)?;
    outln!(
        "{} set(s) of {} 4D points optimized for {} projection term(s) in {:.2} s (from {}; set 0: {})",
        a.sets,
        a.n,
        design.terms.len(),
        design.run.seconds,
        design.run.init,
        design.stopped[0].describe()
    );
    for t in &design.terms {
        outln!(
            "  {:<40} loss {:.4e} -> {:.4e}  (box |k| <= {} on its plane)",
            t.term,
            t.loss_before,
            t.loss_after,
            t.half
        );
    }
    let closest = design.closest_pair_over_hexagonal;
    outln!(
        "  closest pair / hexagonal spacing: XY {}, UV {}",
        spacing(closest.xy),
        spacing(closest.uv)
    );
    design_outputs(
        &a,
        &format!("{} N={} in 4D", a.target, a.n),
        (&design.loss_curve_seconds, &design.loss_curve),
        &[],
        &design,
    )
}

/// A closest pair over the hexagonal spacing, or why there is none (a set
/// of one point has no pair: NaN or infinite, `null` in the JSON).
fn spacing(ratio: f64) -> String {
    if ratio.is_finite() {
        format!("{ratio:.3}")
    } else {
        "n/a (one point)".into()
    }
}

/// A note for a comparison row whose sampler drew another N than the
/// design's (the nearest its structure allows: jitter's m^d), empty
/// otherwise: its scores are not at equal N.
fn other_n(row: &serde_json::Value, n: usize) -> String {
    match row["n"].as_u64() {
        Some(m) if m != n as u64 => {
            format!("  (at N = {m}, the nearest N it draws: not at equal N)")
        }
        _ => String::new(),
    }
}

/// A comparison with the classic samplers estimated longer than this many
/// seconds is said before it starts.
const LONG_COMPARISON: f64 = 10.0;

/// The family members a square design is scored on without --members.
const DEFAULT_SCORE_MEMBERS: usize = 1024;
/// The seed of those members without --score-seed.
const DEFAULT_SCORE_SEED: u64 = 1;

/// `optimize points --domain square`: descend on family MSEs of the
/// unshifted estimator, then score the result and the classic samplers on
/// family members the descent never saw.
fn points_square(a: PointsArgs) -> anyhow::Result<()> {
    use varspec::design::square::{SquareRequest, design_on_square};
    if a.dim != 2 {
        bail!("the square holds 2D point sets (got -d {})", a.dim);
    }
    let (members, score_seed) = (
        a.members.unwrap_or(DEFAULT_SCORE_MEMBERS),
        a.score_seed.unwrap_or(DEFAULT_SCORE_SEED),
    );
    let request = SquareRequest {
        n: a.n,
        target: a.target.clone(),
        sets: a.sets,
        iters: a.iters,
        seed: a.seed,
        init: a.init.clone(),
        init_params: a.params.clone(),
        members,
        score_seed,
    };
    let iters = a
        .iters
        .unwrap_or(varspec::square::design::default_options().iters);
    let bar = progress::bar((a.sets * (iters + 1)) as u64, "optimizing");
    let design = design_on_square(&request, &|_, _| bar.inc(1))?;
    bar.finish_and_clear();
    varspec::io::write_point_file(&a.output, &design.points)?;
    outln!(
        "{} set(s) of {} points designed on the square for {} in {:.2} s (from {}; set 0: {}); \
         unshifted estimator, scored on {} members per family (seed {})",
        a.sets,
        a.n,
        a.target,
        design.run.seconds,
        design.run.init,
        match design.stopped[0] {
            // The stochastic descent has no stopping test: the cap is its
            // length, not a failure to converge.
            varspec::optimize::Stop::Cap => format!(
                "its {} iterations (a fixed-length stochastic descent)",
                design.max_iterations
            ),
            other => other.describe().to_string(),
        },
        members,
        score_seed
    );
    for (name, v) in &design.comparison {
        let mses: String = design
            .families
            .iter()
            .map(|f| {
                format!(
                    "  {f} {:.3e}",
                    v[f.as_str()]["mse"].as_f64().unwrap_or(f64::NAN)
                )
            })
            .collect();
        outln!(
            "  {name:<14}{mses}  closest pair {}{}",
            spacing(
                v["closest_pair_over_hexagonal"]
                    .as_f64()
                    .unwrap_or(f64::NAN)
            ),
            other_n(v, a.n)
        );
    }
    // A listed family has no other members to hold out.
    let listed: Vec<&str> = design
        .families
        .iter()
        .map(String::as_str)
        .filter(|f| f.starts_with("file:"))
        .collect();
    if !listed.is_empty() {
        eprintln!(
            "note: {} scored on the members the descent fitted (a listed family's members are \
             its list, none held out), so its score is not a held-out one",
            listed.join(", ")
        );
    }
    design_outputs(
        &a,
        &format!("{} N={} on the square", a.target, a.n),
        (&design.loss_curve_seconds, &design.loss_curve),
        &[],
        &design,
    )
}

/// The XU and YV planes of a 4D set: name, coordinates, frequency axes.
const PLANES: [(&str, [usize; 2], [&str; 2]); 2] =
    [("xu", [0, 2], ["kx", "ku"]), ("yv", [1, 3], ["ky", "kv"])];

/// XU and YV expected spectra (K = 64) of `sets` and `sheared` as
/// PREFIX-{xu,yv}-{before,after}.png, titled by `what`.
fn projection_pngs(
    prefix: &str,
    what: &str,
    n: usize,
    sets: &[varspec::PointSet],
    sheared: &[varspec::PointSet],
) -> anyhow::Result<()> {
    use varspec::report::plot::power_png;
    use varspec::spectrum::{FrequencyBox, Method, expected_power};
    let freqs = FrequencyBox::from_resolution(2, 64);
    for (label, sets) in [("before", sets), ("after", sheared)] {
        for (name, dims, axes) in PLANES {
            let spectrum = expected_power(
                freqs,
                Method::Fast { tolerance: 1e-9 },
                sets.len(),
                |r| sets[r].projected(&dims).map_err(|e| anyhow::anyhow!(e)),
                &|| {},
            )?;
            let title = format!("{what} N={n} {name} projection, {label} shear");
            power_png(
                &spectrum,
                &title,
                axes,
                "log10 power (N·P_S)",
                std::path::Path::new(&format!("{prefix}-{name}-{label}.png")),
            )?;
        }
    }
    Ok(())
}

/// The `--sets` sets of `optimize shear` (seeded by `--seed`) transformed
/// by `transform`, written with `-o`, and their XU/YV spectra before and
/// after with `--png-prefix`.
fn sheared_outputs(
    a: &ShearArgs,
    spec: &str,
    sampler: &dyn varspec::samplers::Sampler,
    transform: impl Fn(&varspec::PointSet) -> anyhow::Result<varspec::PointSet>,
) -> anyhow::Result<()> {
    let sets = varspec::samplers::generate_sets(sampler, a.seed, a.sets, &|_| {})?;
    let sheared: Vec<_> = sets.iter().map(transform).collect::<Result<_, _>>()?;
    if let Some(path) = &a.output {
        varspec::io::write_point_file(path, &sheared)?;
    }
    if let Some(prefix) = &a.png_prefix {
        projection_pngs(
            prefix,
            &format!("{} {spec}", a.sampler_label()),
            a.n,
            &sets,
            &sheared,
        )?;
    }
    Ok(())
}

/// The pictures `--png-prefix` names: per plane the sets' spectra before
/// and after the shear, and for a scene pixel its light field's.
fn shear_pictures(a: &ShearArgs, pixel: bool) -> Vec<std::path::PathBuf> {
    a.png_prefix
        .iter()
        .flat_map(|prefix| {
            PLANES.iter().flat_map(move |(name, _, _)| {
                let light_field = pixel.then(|| format!("{prefix}-f-{name}.png"));
                [
                    Some(format!("{prefix}-{name}-before.png")),
                    Some(format!("{prefix}-{name}-after.png")),
                    light_field,
                ]
                .into_iter()
                .flatten()
                .map(std::path::PathBuf::from)
            })
        })
        .collect()
}

/// Says which files `optimize shear` wrote (`-o` and [`shear_pictures`]),
/// once its results are printed; JSON output stays one document.
fn report_shear_outputs(a: &ShearArgs, pixel: bool) {
    if !a.json {
        super::stdout::wrote(a.output.iter().cloned().chain(shear_pictures(a, pixel)));
    }
}

/// `optimize shear` on a scene pixel: the candidates of its local analysis
/// measured by the render's (unshifted) estimator.
fn shear_pixel(a: ShearArgs) -> anyhow::Result<()> {
    use varspec::integrands::Integrand;
    use varspec::scene::pixel::PixelIntegrand;
    use varspec::scene::pixel_shear::MIN_REALIZATIONS;
    use varspec::scene::pixel_shear::{Measured, PixelShearOptions, search_pixel_shear};
    if let Some(range) = a.range {
        bail!(
            "--range {range}: a scene pixel's candidate shears come from its local analysis \
             (the depths its rays meet), not from a searched range; --range applies to \
             light-field integrands (defocus, layers)"
        );
    }
    if a.realizations < MIN_REALIZATIONS {
        bail!(
            "--realizations {}: on a scene pixel it is the first round of realizations every \
             candidate shear is measured on (more are added until the best is known to 2%); \
             pixel estimates take few distinct values, so fewer than {MIN_REALIZATIONS} can \
             agree by chance and fake a variance of 0",
            a.realizations
        );
    }
    let f = PixelIntegrand::parse(&a.integrand)?;
    let sampler = registry::build(&a.sampler, a.n, Some(4), &a.params)?;
    if sampler.points_per_set() < 2 {
        bail!(
            "the shear search needs at least 2 points per set (as on a light field): every \
             candidate moves one uniform point to a uniform point, so their variances are equal \
             and a measured difference is noise"
        );
    }
    let start = Instant::now();
    let options = PixelShearOptions {
        seed: a.seed,
        min_realizations: a.realizations,
        ..PixelShearOptions::default()
    };
    let spinner = progress::spinner("searching the pixel's shear");
    let found = search_pixel_shear(&f, sampler.as_ref(), options);
    spinner.finish_and_clear();
    let found = found?;
    let seconds = start.elapsed().as_secs_f64();
    let best = found.best();
    sheared_outputs(&a, &f.spec(), sampler.as_ref(), |s| {
        Ok(best.shear.apply(s.clone()))
    })?;
    if let Some(prefix) = &a.png_prefix {
        // The pixel's own light-field power on the same planes: where the
        // sets' dark regions should lie.
        for (name, dims, axes) in PLANES {
            let power = f.plane_power(dims, 128, PixelIntegrand::RAYS_PER_CELL, a.seed)?;
            varspec::report::plot::power_png(
                &power,
                &format!("{} light field, {name} plane", f.spec()),
                axes,
                "log10 |F_f(k)|^2",
                std::path::Path::new(&format!("{prefix}-f-{name}.png")),
            )?;
        }
    }
    let row = |m: &Measured| {
        let e = &m.estimate;
        json!({"form": m.shear.form(), "amounts": m.shear.amounts(), "variance": e.variance,
               "stderr": e.stderr, "ci_low": e.ci_low, "ci_high": e.ci_high, "realizations": e.realizations})
    };
    let analysis = &found.analysis;
    let reduction = found.unsheared().estimate.variance / best.estimate.variance;
    let out = json!({
        "sampler": a.sampler_label(), "integrand": f.spec(), "n": a.n, "sets": a.sets, "seed": a.seed,
        "estimator": "unshifted: mean of f over the transformed set (the render's); unbiased for every candidate",
        "pixel": {"kind": analysis.kind.name(), "depth": analysis.depth, "kappa": analysis.kappa, "kappas": analysis.kappas,
                  "footprint_kappa_range": found.slopes.range, "footprint_slope_spread": found.slopes.spread},
        "candidates": found.candidates.iter().map(row).collect::<Vec<_>>(),
        "chosen": row(best), "double_wedge": found.double_wedge, "hairline": found.hairline,
        "sensitivity": found.sensitivity.as_ref().map(|s| json!({"step": varspec::optimize::shear::SENSITIVITY_STEP, "minus": row(&s[0]), "plus": row(&s[1])})),
        "reduction": reduction, "seconds": seconds,
    });
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    outln!(
        "{} ({} pixel, depth {:.4}, κ {:.4} ({:.4} to {:.4} over the footprint){}{}) with {} N={}, {} realizations per candidate:",
        f.spec(),
        analysis.kind.name(),
        analysis.depth,
        analysis.kappa,
        found.slopes.range[0],
        found.slopes.range[1],
        if found.double_wedge {
            "; double wedge"
        } else {
            ""
        },
        if found.hairline { "; hairline" } else { "" },
        a.sampler_label(),
        a.n,
        best.estimate.realizations
    );
    for (i, m) in found.candidates.iter().enumerate() {
        let e = &m.estimate;
        outln!(
            "  {} {:<8} ({:>8.4}, {:>8.4})  variance {:.4e} ± {:.1e}",
            if i == found.chosen { "*" } else { " " },
            m.shear.form(),
            m.shear.amounts()[0],
            m.shear.amounts()[1],
            e.variance,
            e.stderr
        );
    }
    if found.candidates.len() == 1 {
        let why = f.scene().why_no_slope().unwrap_or(
            "every probe ray missed the geometry (a constant pixel) or met depths in focus",
        );
        eprintln!(
            "note: only the unsheared set was measured: {why}, so the pixel has no light-field slope to shear along"
        );
    }
    outln!(
        "chosen: {} ({:.4}, {:.4}), {} than no shear, search {seconds:.2} s",
        best.shear.form(),
        best.shear.amounts()[0],
        best.shear.amounts()[1],
        if reduction > 1.0 {
            format!("{reduction:.2}x lower")
        } else {
            "no lower".to_string()
        }
    );
    let relative = best.estimate.stderr / best.estimate.variance;
    let defaults = PixelShearOptions::default();
    if relative > defaults.target_stderr {
        eprintln!(
            "note: the chosen shear's variance is known to {:.1}% (the search aims at {:.0}%) after \
             {} realizations per candidate ({}): candidates closer than that are not told apart",
            100.0 * relative,
            100.0 * defaults.target_stderr,
            best.estimate.realizations,
            if best.estimate.realizations >= defaults.max_realizations {
                "the most it draws"
            } else {
                "its last round"
            }
        );
    }
    report_shear_outputs(&a, true);
    Ok(())
}

impl ShearArgs {
    /// The sampler as the outputs name it: its spec with the --param
    /// values folded in.
    fn sampler_label(&self) -> String {
        registry::label(&self.sampler, &self.params).unwrap_or_else(|_| self.sampler.clone())
    }
}

fn shear(a: ShearArgs) -> anyhow::Result<()> {
    use varspec::integrands;
    use varspec::optimize::shear::checked::{CheckVerdict, check_request, search_and_check};
    use varspec::optimize::shear::shear_set;
    // The pictures --png-prefix names (a pixel also gets its light field's).
    // Every picture either kind of integrand may write is checked.
    let pictures = shear_pictures(&a, true);
    let scene_files = varspec::scene::pixel::PixelIntegrand::files_read(&a.integrand);
    args::check_outputs_beside(
        std::iter::once(a.output.as_deref()).chain(pictures.iter().map(|p| Some(p.as_path()))),
        scene_files.iter().map(|p| Some(p.as_path())),
    )?;
    if varspec::scene::pixel::PixelIntegrand::is_pixel_spec(&a.integrand) {
        return shear_pixel(a);
    }

    let f = integrands::parse(&a.integrand)?;
    check_request(f.as_ref(), a.range, a.realizations)?;
    let sampler = registry::build(&a.sampler, a.n, Some(4), &a.params)?;
    // The written sets, drawn and sheared (two copies), and a few numbers
    // per realization of the check.
    let bytes = 2.0 * a.sets as f64 * sampler.points_per_set() as f64 * 4.0 * 8.0
        + a.realizations as f64 * 64.0;
    varspec::memory::check(
        &format!(
            "{} written sets and {} check realizations",
            a.sets, a.realizations
        ),
        Some(bytes),
        "lower --sets or --realizations",
    )?;
    let spinner = progress::spinner("searching the shear");
    let run = search_and_check(
        f.as_ref(),
        sampler.as_ref(),
        &a.sampler_label(),
        a.seed,
        a.range,
        a.realizations,
        &|stage| spinner.set_message(format!("searching the shear: {stage}")),
    );
    spinner.finish_and_clear();
    let run = run?;
    let (found, check, search_seconds) = (&run.found, &run.check, run.search_seconds);
    sheared_outputs(&a, &f.spec(), sampler.as_ref(), |s| {
        Ok(shear_set(s, found.shear)?)
    })?;
    let mut out = run.report.clone();
    out["sets"] = json!(a.sets);
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        let ratio = if found.optimum.value == found.unsheared.value {
            1.0
        } else {
            found.optimum.value / found.unsheared.value
        };
        outln!(
            "shear a = {:.4}, b = {:.4} (spectral start {:.4}, {:.4}{}); expected variance {:.4e} -> {:.4e} ({}), search {search_seconds:.2} s",
            found.shear[0],
            found.shear[1],
            found.initial.0[0],
            found.initial.0[1],
            if run.spectral.double_wedge {
                "; double wedge"
            } else {
                ""
            },
            found.unsheared.value,
            found.optimum.value,
            if ratio == 1.0 {
                "unchanged".to_string()
            } else if ratio < 1.0 {
                format!("{:.2}x lower", 1.0 / ratio)
            } else {
                format!("{ratio:.2}x higher")
            }
        );
        if let Some((before, after)) = check {
            // An interval with no upper end (every estimate equal) is said
            // so, as the JSON's null does.
            let upper = |v: f64| {
                if v.is_finite() {
                    format!("{v:.4e}")
                } else {
                    "no upper end".into()
                }
            };
            outln!(
                "check on {} fresh sets: {:.4e} [{:.4e}, {}] -> {:.4e} [{:.4e}, {}]{}",
                after.realizations,
                before.variance,
                before.ci_low,
                upper(before.ci_high),
                after.variance,
                after.ci_low,
                upper(after.ci_high),
                run.ratio.map_or(String::new(), |r| format!(
                    "; paired ratio {:.3} [{:.3}, {}]",
                    r.ratio,
                    r.ci_low,
                    if r.ci_high.is_finite() {
                        format!("{:.3}", r.ci_high)
                    } else {
                        "no upper end".into()
                    }
                ))
            );
        }
    }
    report_shear_outputs(&a, false);
    for warning in &run.warnings {
        eprintln!("warning: {warning}");
    }
    match run.verdict {
        Some(CheckVerdict::Contradicts) => eprintln!(
            "warning: the fresh-set check finds the shear worse than none (the paired ratio's 95% interval lies above 1), against the search's objective: do not use it; try another --seed, or keep the sets unsheared"
        ),
        Some(CheckVerdict::Inconclusive) if !a.json => outln!(
            "the check cannot tell the shear from none (the paired ratio's 95% interval holds 1): raise --realizations to separate them"
        ),
        _ => {}
    }
    Ok(())
}

/// The files every `optimize points` design writes beside its points:
/// `--curve` (CSV) and `--curve-png` (log-log against time, with the
/// classic samplers' losses as flat references where the design has them)
/// of set 0's loss curve (`seconds`, `loss`), and `--report` (the design as
/// JSON); then says which files were written.
fn design_outputs(
    a: &PointsArgs,
    what: &str,
    (seconds, loss): (&[f64], &[f64]),
    baselines: &[(&str, f64)],
    design: &impl serde::Serialize,
) -> anyhow::Result<()> {
    use varspec::report::plot::{LinePlot, Series, line_plot_png};
    let curve: Vec<(f64, f64)> = seconds.iter().copied().zip(loss.iter().copied()).collect();
    if let Some(path) = &a.curve {
        write_loss_curve(path, curve.iter().copied())?;
    }
    if let Some(path) = &a.curve_png {
        let (t0, t1) = (
            curve
                .iter()
                .map(|c| c.0)
                .fold(f64::INFINITY, f64::min)
                .max(1e-4),
            curve.last().map_or(1.0, |c| c.0),
        );
        let series = std::iter::once(Series {
            label: "optimized (set 0)".into(),
            points: curve.clone(),
            reference: false,
            error_bars: Vec::new(),
        })
        .chain(baselines.iter().map(|&(name, score)| Series {
            label: name.into(),
            points: vec![(t0, score), (t1, score)],
            reference: true,
            error_bars: Vec::new(),
        }))
        .collect();
        let plot = LinePlot {
            title: format!("loss against time: {what}"),
            x_label: "seconds".into(),
            y_label: "loss".into(),
            log_log: true,
            series,
        };
        line_plot_png(&plot, path)?;
    }
    if let Some(path) = &a.report {
        write_atomic(path, |w| {
            w.write_all(serde_json::to_string_pretty(design)?.as_bytes())
        })?;
    }
    super::stdout::wrote(
        std::iter::once(&a.output)
            .chain(&a.curve)
            .chain(&a.curve_png)
            .chain(&a.report),
    );
    Ok(())
}

/// The loss curve CSV (`--curve`): iteration, wall seconds, loss.
fn write_loss_curve(
    path: &std::path::Path,
    curve: impl Iterator<Item = (f64, f64)>,
) -> anyhow::Result<()> {
    #[derive(serde::Serialize)]
    struct Row {
        iteration: usize,
        seconds: f64,
        loss: f64,
    }
    write_atomic(path, |w| {
        varspec::io::write_csv_rows(
            w,
            curve.enumerate().map(|(iteration, (seconds, loss))| Row {
                iteration,
                seconds,
                loss,
            }),
        )
    })?;
    Ok(())
}
