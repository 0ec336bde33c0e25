//! `varspec compare`: a first look. Generates every 2D sampler at one N,
//! prints a side-by-side table and writes a picture of each pattern.

use std::path::PathBuf;
use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

use anyhow::bail;

use super::progress;
use varspec::io::write_atomic;
use varspec::neighbours::relative_radii;
use varspec::registry;
use varspec::report::png::{render_points, save_png};
use varspec::rng::set_rng;
use varspec::samplers;

/// The 2D samplers compared, in table order.
const COMPARED: [&str; 11] = [
    "random",
    "regular",
    "jitter",
    "uniform-jitter",
    "nrooks",
    "multijitter",
    "cmj",
    "poisson-disk",
    "sobol",
    "halton",
    "lattice",
];

#[derive(clap::Args)]
pub struct Args {
    /// Points per set (samplers with constrained N use the nearest valid N).
    #[arg(short = 'n', long = "n", value_parser = super::args::count, allow_negative_numbers = true, default_value_t = 1024)]
    n: usize,
    /// Realizations per sampler.
    #[arg(value_parser = super::args::whole_at_least::<1, usize>, allow_negative_numbers = true, long, default_value_t = super::args::DEFAULT_SETS)]
    sets: usize,
    /// Seed.
    #[arg(value_parser = super::args::whole::<u64>, allow_negative_numbers = true, long, default_value_t = 0)]
    seed: u64,
    /// Folder for the summary CSV and one PNG per sampler.
    #[arg(short = 'o', long = "output", default_value = "out/compare")]
    output: PathBuf,
}

/// The fewest timings a sampler's speed is the best of.
const TIMED_DRAWS: usize = 5;

/// The shortest timing: draws faster than this are timed in batches.
const SHORTEST_TIMING: Duration = Duration::from_millis(2);

/// A draw at least this long is the best of two timings: warm-up is a
/// small part of it, and five timings each made `compare -n 5e7` spend
/// over 9 minutes without finishing its first samplers (fifth trial).
const LONG_DRAW: Duration = Duration::from_millis(500);

/// Seconds one set of `sampler` takes to draw on one thread: the best of
/// at least [`TIMED_DRAWS`] timings (two for a draw over [`LONG_DRAW`]),
/// since warm-up (page faults, caches, the thread pool starting) and other
/// processes' load only ever slow a draw down. `times` are the draws already made; draws shorter than
/// [`SHORTEST_TIMING`] are repeated in batches that last at least that
/// long, so the clock's resolution and jitter do not count.
fn draw_seconds(
    sampler: &dyn samplers::Sampler,
    seed: u64,
    times: &[Duration],
) -> anyhow::Result<f64> {
    let fastest = times.iter().min().copied().unwrap_or(Duration::MAX);
    let long = !times.is_empty() && fastest >= LONG_DRAW;
    if fastest >= SHORTEST_TIMING && times.len() >= if long { 2 } else { TIMED_DRAWS } {
        return Ok(fastest.as_secs_f64());
    }
    let batch = if fastest >= SHORTEST_TIMING {
        1
    } else {
        SHORTEST_TIMING.as_nanos() / fastest.as_nanos().max(1) + 1
    };
    let mut best = fastest.as_secs_f64();
    for timing in 0..if long { 1 } else { TIMED_DRAWS as u64 } {
        let start = Instant::now();
        for _ in 0..batch {
            sampler.sample(&mut set_rng(seed, timing))?;
        }
        best = best.min(start.elapsed().as_secs_f64() / batch as f64);
    }
    Ok(best)
}

struct Row {
    name: &'static str,
    n: usize,
    mpts_per_s: f64,
    min_rel: f64,
    mean_rel: f64,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    // At N = 2 the m² samplers' nearest valid N is 1, which has no
    // nearest neighbour.
    if a.n < 3 {
        bail!("compare needs at least 3 points (-n)");
    }
    super::args::create_folder(&a.output, "-o")?;
    let bar = progress::bar(COMPARED.len() as u64, "sampling");
    let mut rows = Vec::new();
    let mut caveats = Vec::new();
    for name in COMPARED {
        let (sampler, n) = registry::build_nearest(name, a.n, Some(2), &[])?;
        caveats.extend(sampler.caveat());
        let times = Mutex::new(Vec::with_capacity(a.sets));
        let sets = samplers::generate_sets(sampler.as_ref(), a.seed, a.sets, &|t| {
            times.lock().unwrap_or_else(PoisonError::into_inner).push(t);
        })?;
        let times = times.into_inner().unwrap_or_else(PoisonError::into_inner);
        let seconds = draw_seconds(sampler.as_ref(), a.seed, &times)?;
        // Lagae & Dutré (2008) relative radii: distances over the hexagonal
        // packing distance, the minimum (δ_min) and mean (δ̄) nearest-neighbour
        // distance, averaged over sets.
        let (mut min_rel, mut mean_rel) = (0.0, 0.0);
        for set in &sets {
            let [min, mean] = relative_radii(set);
            min_rel += min;
            mean_rel += mean;
        }
        let k = sets.len() as f64;
        let png = a.output.join(format!("{name}.png"));
        save_png(&render_points(&sets[0], [0, 1], 512)?, &png)?;
        rows.push(Row {
            name,
            n,
            mpts_per_s: n as f64 / seconds / 1e6,
            min_rel: min_rel / k,
            mean_rel: mean_rel / k,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();

    let sets = if a.sets == 1 { "set" } else { "sets" };
    outln!("2D samplers, {} {sets} each, seed {}:", a.sets, a.seed);
    outln!(
        "{:<16} {:>6} {:>10} {:>8} {:>8}",
        "sampler",
        "N",
        "Mpoints/s",
        "nn_min",
        "nn_mean"
    );
    for r in &rows {
        outln!(
            "{:<16} {:>6} {:>10.2} {:>8.3} {:>8.3}",
            r.name,
            r.n,
            r.mpts_per_s,
            r.min_rel,
            r.mean_rel
        );
    }
    let moved: Vec<String> = rows
        .iter()
        .filter(|r| r.n != a.n)
        .map(|r| format!("{} N = {}", r.name, r.n))
        .collect();
    if !moved.is_empty() {
        outln!(
            "N: {} (the nearest N their structure allows to -n {})",
            moved.join(", "),
            a.n
        );
    }
    outln!(
        "Mpoints/s: N over the time one set takes to draw on one thread (the best of at least {TIMED_DRAWS} \
         timings, each of at least {} ms; of two for draws over {} ms).",
        SHORTEST_TIMING.as_millis(),
        LONG_DRAW.as_millis()
    );
    outln!(
        "nn_min / nn_mean: minimum and mean nearest-neighbour distance over the hexagonal packing distance \
         sqrt(2/(sqrt(3) N)) (Lagae & Dutre 2008; 1 = densest packing, random ~ 0.01 / 0.5)."
    );
    // After the table: the progress bar no longer shares the terminal.
    for c in caveats {
        eprintln!("note: {c}");
    }
    let csv = a.output.join("summary.csv");
    #[derive(serde::Serialize)]
    struct Summary<'a> {
        sampler: &'a str,
        n: usize,
        sets: usize,
        seed: u64,
        mpoints_per_s: f64,
        nn_min_rel: f64,
        nn_mean_rel: f64,
    }
    write_atomic(&csv, |w| {
        varspec::io::write_csv_rows(
            w,
            rows.iter().map(|r| Summary {
                sampler: r.name,
                n: r.n,
                sets: a.sets,
                seed: a.seed,
                mpoints_per_s: r.mpts_per_s,
                nn_min_rel: r.min_rel,
                nn_mean_rel: r.mean_rel,
            }),
        )
    })?;
    announce!(
        "wrote {} and one PNG per sampler in {}",
        csv.display(),
        a.output.display()
    );
    Ok(())
}
