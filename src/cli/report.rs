//! `varspec report`: the main job — the design loop end to end on built-in
//! defaults, as one self-contained HTML page with its data.

use std::path::PathBuf;

use varspec::tour::html::render_tour;
use varspec::tour::{TourOptions, run_tour, write_data};

#[derive(clap::Args)]
pub struct Args {
    /// Folder of the page (index.html), its pictures and data.
    #[arg(short = 'o', long = "output", default_value = "out/report")]
    output: PathBuf,
    /// Points per set of the sampler comparison.
    #[arg(short = 'n', long = "n", value_parser = super::args::count, allow_negative_numbers = true, default_value_t = 256)]
    n: usize,
    /// Sets per sampler.
    #[arg(value_parser = super::args::whole_at_least::<1, usize>, allow_negative_numbers = true, long, default_value_t = super::args::DEFAULT_SETS)]
    sets: usize,
    /// Seed of everything.
    #[arg(value_parser = super::args::whole::<u64>, allow_negative_numbers = true, long, default_value_t = 0)]
    seed: u64,
    /// Integrand of the sampler comparison.
    #[arg(long, default_value = "disk:r=0.3")]
    integrand: String,
    /// Light field of the shear search: a defocus pixel, or `layers:…` (two
    /// depths, a double wedge).
    #[arg(long, default_value = "defocus:shape=disk,size=0.3,c=0.45")]
    pixel: String,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    if a.n < 4 || a.sets < 2 {
        anyhow::bail!("report needs -n >= 4 and --sets >= 2");
    }
    // The tour makes the folder once its options pass.
    super::args::check_folder(&a.output, "-o")?;
    let options = TourOptions {
        n: a.n,
        sets: a.sets,
        seed: a.seed,
        integrand: a.integrand,
        pixel: a.pixel,
        folder: a.output.clone(),
    };
    let tour = run_tour(&options, &|step| eprintln!("varspec report: {step} ..."))?;
    write_data(&tour, &a.output)?;
    render_tour(&tour, &a.output)?;
    let best = tour
        .predict
        .rows
        .iter()
        .find(|r| r.best)
        .map_or("?", |r| r.sampler.as_str());
    announce!(
        "wrote {} in {:.1} s: lowest variance on {} at N = {}: {best}; square design {:.2}x CMJ on half-planes; \
         shear ({:.3}, {:.3}) for c = {}, {:.2}x lower",
        a.output.join("index.html").display(),
        tour.seconds,
        tour.predict.integrand,
        tour.predict.n,
        tour.square.halfplanes_against("cmj").unwrap_or(f64::NAN),
        tour.shear.shear[0],
        tour.shear.shear[1],
        tour.shear
            .analytic
            .iter()
            .map(|a| format!("{:.2}", -a[0]))
            .collect::<Vec<_>>()
            .join(" and "),
        tour.shear.reduction
    );
    Ok(())
}
