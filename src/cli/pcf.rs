//! `varspec pcf`: the pair correlation function.

use std::path::PathBuf;

use anyhow::bail;

use super::progress;
use super::source::SourceArgs;
use varspec::io::{write_atomic, write_csv_rows};
use varspec::neighbours::packing_radius_at_density;
use varspec::report::plot::{LinePlot, Series, line_plot_png};
use varspec::spectrum::pcf::{KERNEL_REACH, kernel_evaluations, pair_correlation};

/// Kernel evaluations above which pcf says before it starts that it will
/// take long: 3e9 took about 20 s on 2 busy cores (4 cmj sets of 1024
/// points, --bins 10000: 6.8e8 in 4.95 s).
const LONG_WORK: f64 = 3e9;

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    source: SourceArgs,
    /// Largest radius, in units of the densest-packing distance r_max
    /// [default: 2.5, or less, with the bandwidth, where that would reach
    /// half the torus (few points)].
    #[arg(allow_negative_numbers = true, long)]
    range: Option<f64>,
    /// Radii evaluated in (0, range].
    #[arg(value_parser = super::args::whole::<usize>, allow_negative_numbers = true, long, default_value_t = 100)]
    bins: usize,
    /// Gaussian kernel standard deviation σ, in units of r_max [default:
    /// 0.15, or less, with the range, where the default range would reach
    /// half the torus (few points); a tenth of a --range below 1.5].
    #[arg(allow_negative_numbers = true, long)]
    bandwidth: Option<f64>,
    /// CSV output: r,r_rel,g (r_rel = r / r_max). Default: standard output.
    #[arg(value_parser = super::args::csv_path, long)]
    csv: Option<PathBuf>,
    /// PNG plot of g against r / r_max.
    #[arg(long, value_parser = super::args::png_path)]
    png: Option<PathBuf>,
}

/// `--range` when not given, where it fits the torus.
const DEFAULT_RANGE: f64 = 2.5;

/// `--bandwidth` when not given, where the default range fits the torus.
const DEFAULT_BANDWIDTH: f64 = 0.15;

/// The fewest kernel widths a shrunk default range spans: below it the
/// bandwidth shrinks with the range.
const MIN_RANGE_IN_BANDWIDTHS: f64 = 10.0;

pub fn run(a: Args) -> anyhow::Result<()> {
    super::args::check_outputs_beside([a.csv.as_deref(), a.png.as_deref()], [a.source.file()])?;
    let given = a.range;
    if let Some(range) = given
        && !(range.is_finite() && range >= 1e-3)
    {
        bail!(
            "--range {range:?}: the largest radius, in units of the packing distance r_max, must \
             be a finite number of at least 0.001, the smallest --bandwidth (default 2.5)"
        );
    }
    let mut range = given.unwrap_or(DEFAULT_RANGE);
    if a.bins == 0 {
        bail!("--bins 0: the number of radii must be at least 1 (default 100)");
    }
    // A range given below 10 default bandwidths takes a bandwidth spanning
    // a tenth of it, as a shrunk default range does (the default 0.15 was
    // refused against --range 0.001, an option the user never gave).
    let mut bandwidth = a.bandwidth.unwrap_or_else(|| {
        let fitted = (range / MIN_RANGE_IN_BANDWIDTHS).clamp(1e-3, DEFAULT_BANDWIDTH);
        if fitted < DEFAULT_BANDWIDTH {
            // To 4 decimals, without float noise (0.06999999999999999).
            let shown = (fitted * 1e4).round() / 1e4;
            eprintln!(
                "note: --bandwidth {shown} r_max (not {DEFAULT_BANDWIDTH}): a tenth of --range \
                 {range}, at least 0.001"
            );
        }
        fitted.min(range)
    });
    if !(bandwidth.is_finite() && bandwidth >= 1e-3 && bandwidth <= range) {
        bail!(
            "--bandwidth {:?}: the kernel's σ, in units of the packing distance r_max, must be in \
             [0.001, --range = {range:?}] (default 0.15; below 0.001 no pair falls within a kernel width)",
            bandwidth,
        );
    }
    let source = a.source.resolve(None)?;
    let bar = progress::bar(source.count() as u64, "pcf");
    let sets = (0..source.count())
        .map(|r| {
            bar.inc(1);
            source.get(r)
        })
        .collect::<Result<Vec<_>, _>>()?;
    bar.finish_and_clear();
    // A random-count process's spacing is its density's, not set 0's count.
    let (n, d) = (sets[0].len(), sets[0].dim());
    let Some(unit) = packing_radius_at_density(sets[0].density().unwrap_or(n as f64), d) else {
        bail!("pair correlation covers 1 to 4 dimensions; the points are {d}-dimensional");
    };
    // The estimator needs (range + 6σ)·r_max < 1/2 (beyond, toroidal
    // distances alias): say so in the units the options are given in.
    // The default shrinks to fit (to 99% of the largest range that does),
    // saying so; a range given is kept or refused.
    let half = 0.5 / unit;
    // What the spacing is of, as the messages name it.
    let spaced = match sets[0].density() {
        Some(density) => format!("density {}", varspec::spec_params::SpecValue(density)),
        None => format!("N = {n}"),
    };
    let mut largest = half - KERNEL_REACH * bandwidth;
    if given.is_none() && range >= largest {
        // The range alone while it spans MIN_RANGE_IN_BANDWIDTHS kernel
        // widths (and always with a given bandwidth); below that, with the
        // bandwidth at its default, both shrink keeping that ratio:
        // range = 0.99·(half − 6σ) = q·σ, continuous in N where the two
        // meet (the range alone reached down to the bandwidth, then jumped
        // up to 16.7 bandwidths: 0.76 r_max at N = 5 in 2D, 0.24 at 6).
        let q = MIN_RANGE_IN_BANDWIDTHS;
        let (shrunk_range, shrunk_bandwidth) =
            if 0.99 * largest >= q * bandwidth || a.bandwidth.is_some() {
                (0.99 * largest, bandwidth)
            } else {
                let sigma = 0.99 * half / (q + 0.99 * KERNEL_REACH);
                (q * sigma, sigma)
            };
        if shrunk_range >= shrunk_bandwidth && shrunk_bandwidth >= 1e-3 {
            let narrower = shrunk_bandwidth < bandwidth;
            (range, bandwidth) = (shrunk_range, shrunk_bandwidth);
            largest = half - KERNEL_REACH * bandwidth;
            eprintln!(
                "note: --range {range:.3} r_max (not {DEFAULT_RANGE}){}: with {spaced} in {d}D \
                 half the torus is {half:.3} r_max, and the range plus 6 kernel widths \
                 ({:.3} r_max) must stay below it, where the pair correlation would alias",
                if narrower {
                    format!(" and --bandwidth {bandwidth:.4} (not {DEFAULT_BANDWIDTH})")
                } else {
                    String::new()
                },
                KERNEL_REACH * bandwidth
            );
        }
    }
    let reach = range + KERNEL_REACH * bandwidth;
    if reach * unit >= 0.5 {
        bail!(
            "{}--range {:?} + 6 x --bandwidth {:?} = {} packing distances reaches half the torus \
             (r_max = {unit:.4} for {spaced}: the pair correlation aliases beyond {:.3} r_max); {}",
            // Not given: the default could not shrink below the bandwidth.
            if given.is_none() { "the default " } else { "" },
            range,
            bandwidth,
            // Three decimals, in exponent form beyond (--range 1e300 printed
            // 300 digits).
            if reach < 1e6 {
                format!("{reach:.3}")
            } else {
                format!("{reach:.3e}")
            },
            0.5 / unit,
            if largest > bandwidth {
                format!("lower --range to below {largest:.3}, or use more points")
            } else {
                "use more points (or a smaller --bandwidth)".to_string()
            }
        );
    }
    let work = kernel_evaluations(&sets, range * unit, a.bins, bandwidth * unit);
    if work > LONG_WORK {
        eprintln!(
            "note: about {work:.1e} kernel evaluations (pairs within reach x the bins within \
             {KERNEL_REACH} bandwidths of each): this may take a long time; fewer --bins (the \
             kernel spans {:.0} of them) or a smaller --bandwidth make it faster",
            (2.0 * KERNEL_REACH * bandwidth / (range / a.bins as f64)).min(a.bins as f64)
        );
    }
    let pcf = pair_correlation(&sets, range * unit, a.bins, bandwidth * unit)?;
    #[derive(serde::Serialize)]
    struct Row {
        r: f64,
        r_rel: f64,
        g: f64,
    }
    let write = |w: &mut dyn std::io::Write| -> std::io::Result<()> {
        write_csv_rows(
            w,
            pcf.r.iter().zip(&pcf.g).map(|(&r, &g)| Row {
                r,
                r_rel: r / unit,
                g,
            }),
        )
    };
    match &a.csv {
        Some(path) => write_atomic(path, write)?,
        None if a.png.is_none() => write(&mut std::io::stdout().lock())?,
        None => {}
    }
    if let Some(path) = &a.png {
        let plot = LinePlot {
            title: format!(
                "pair correlation: {} ({})",
                source.name(),
                super::stdout::counted(sets.len(), "set")
            ),
            x_label: "r / r_max".into(),
            y_label: "g(r)".into(),
            log_log: false,
            series: vec![
                Series {
                    label: "g".into(),
                    points: pcf
                        .r
                        .iter()
                        .map(|r| r / unit)
                        .zip(pcf.g.iter().copied())
                        .collect(),
                    reference: false,
                    error_bars: Vec::new(),
                },
                Series {
                    label: "white noise".into(),
                    points: vec![(0.0, 1.0), (range, 1.0)],
                    reference: true,
                    error_bars: Vec::new(),
                },
            ],
        };
        line_plot_png(&plot, path)?;
    }
    super::stdout::wrote([&a.csv, &a.png].into_iter().flatten());
    Ok(())
}
