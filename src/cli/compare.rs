//! `varspec compare`: a first look. Generates every 2D sampler at one N,
//! prints a side-by-side table and writes a picture of each pattern.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, bail};

use super::progress;
use varspec::io::write_atomic;
use varspec::neighbours::relative_radii;
use varspec::registry;
use varspec::report::png::{render_points, save_png};
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
    std::fs::create_dir_all(&a.output)
        .with_context(|| format!("cannot create folder {}", a.output.display()))?;
    let bar = progress::bar(COMPARED.len() as u64, "sampling");
    let mut rows = Vec::new();
    for name in COMPARED {
        let (sampler, n) = registry::build_nearest(name, a.n, Some(2), &[])?;
        let start = Instant::now();
        let sets = samplers::generate_sets(sampler.as_ref(), a.seed, a.sets, &|| {})?;
        let seconds = start.elapsed().as_secs_f64();
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
            mpts_per_s: (n * sets.len()) as f64 / seconds / 1e6,
            min_rel: min_rel / k,
            mean_rel: mean_rel / k,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();

    outln!("2D samplers, {} sets each, seed {}:", a.sets, a.seed);
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
        "nn_min / nn_mean: minimum and mean nearest-neighbour distance over the hexagonal packing distance \
         sqrt(2/(sqrt(3) N)) (Lagae & Dutre 2008; 1 = densest packing, random ~ 0.01 / 0.5)."
    );
    let csv = a.output.join("summary.csv");
    #[derive(serde::Serialize)]
    struct Summary<'a> {
        sampler: &'a str,
        n: usize,
        sets: usize,
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
                mpoints_per_s: r.mpts_per_s,
                nn_min_rel: r.min_rel,
                nn_mean_rel: r.mean_rel,
            }),
        )
    })?;
    outln!(
        "wrote {} and one PNG per sampler in {}",
        csv.display(),
        a.output.display()
    );
    Ok(())
}
