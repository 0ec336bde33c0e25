//! Command-line parsing and dispatch. Each subcommand lives in its own file;
//! errors are printed once, here, and turn into a non-zero exit.

#[macro_use]
mod stdout;
mod args;
mod bench;
mod compare;
mod converge;
mod experiment;
mod integrands;
mod optimize;
mod pcf;
mod plot;
mod predict;
mod progress;
mod render;
mod report;
mod sample;
mod source;
mod spectrum;
mod tables;

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

/// Design Monte Carlo sample patterns by the integration error they produce.
#[derive(Parser)]
#[command(name = "varspec", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The command line's grammar: every option that takes a value takes a
/// negative number too (`--range -1` reaches the option's own check, which
/// says what the range must be, instead of clap's "unexpected argument").
fn grammar() -> clap::Command {
    fn negative_values(command: clap::Command) -> clap::Command {
        command
            .mut_args(|a| {
                if a.get_action().takes_values() {
                    a.allow_negative_numbers(true)
                } else {
                    a
                }
            })
            .mut_subcommands(negative_values)
    }
    negative_values(Cli::command())
}

#[derive(Subcommand)]
enum Command {
    /// The main job: the design loop end to end on built-in defaults, as one
    /// self-contained HTML page (out/report/index.html) with its data.
    Report(report::Args),
    /// Generate point sets with a sampler and write them as CSV, UTK text or NumPy .npy.
    Sample(sample::Args),
    /// Draw pictures (PNG) of point sets.
    #[command(subcommand)]
    Plot(plot::PlotCommand),
    /// Expected power spectrum of point sets (or a 2D projection): CSV,
    /// radial profile with anisotropy, PNG pictures.
    Spectrum(spectrum::Args),
    /// Pair correlation function g(r) of point sets (Gaussian kernel estimator).
    Pcf(pcf::Args),
    /// Variance of a point set's estimate of an integral (shift-randomized
    /// on the torus by default, or as drawn; on the unit square; a scene
    /// pixel): Fourier, spatial and empirical predictors side by side.
    Predict(predict::Args),
    /// Variance against N, the fitted log-log slope with its CI, and theory.
    Converge(converge::Args),
    /// Run a declarative experiment file (whole, or one --shard i/n of it)
    /// and write its tables.
    Experiment(experiment::Args),
    /// Merge an experiment's shard files into exactly the tables a single
    /// run writes.
    Merge(experiment::MergeArgs),
    /// Optimizers: point positions toward a target (blue noise, an
    /// integrand, 4D spectra per projection) and the shear of 4D sets.
    #[command(subcommand)]
    Optimize(optimize::OptimizeCommand),
    /// Render a scene whose pixels are 4D integrands (depth of field, soft
    /// shadows) with any 4D sampler and per-pixel shears; variance heat maps.
    Render(render::Args),
    /// Pattern tables for renderers: csv, json, raw f32/f64, C header, with metadata.
    Tables(tables::Args),
    /// The reference integrands (with --list: their parameters).
    Integrands(integrands::Args),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell).
    Completions {
        /// The shell.
        shell: clap_complete::Shell,
    },
    /// Benchmarks that print speed against error.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// Generate every 2D sampler at one N and compare them side by side:
    /// speed, spacing, pictures.
    Compare(compare::Args),
}

/// Parses the arguments, runs the subcommand, reports any error on stderr.
pub fn main() -> ExitCode {
    let cli = Cli::from_arg_matches(&grammar().get_matches()).unwrap_or_else(|e| e.exit());
    // A command's outputs appear together or not at all; a standard
    // output that failed (not merely closed: see `stdout`) fails it.
    let stdout_failed = || match stdout::finish() {
        Some(e) => Err(anyhow::anyhow!("cannot write to standard output: {e}")),
        None => Ok(()),
    };
    let result = varspec::io::all_or_nothing(|| {
        varspec::memory::budget_from_env().map_err(anyhow::Error::msg)?;
        run(cli.command)?;
        stdout_failed()?;
        // "wrote …" only once the writes that can still fail have
        // succeeded (a device such as /dev/full fails when written; the
        // renames that remain do not run out of space).
        varspec::io::write_staged_devices()?;
        stdout::release_announcements();
        stdout_failed()
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Runs one subcommand.
fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Report(a) => report::run(a),
        Command::Sample(a) => sample::run(a),
        Command::Plot(c) => plot::run(c),
        Command::Compare(a) => compare::run(a),
        Command::Spectrum(a) => spectrum::run(a),
        Command::Pcf(a) => pcf::run(a),
        Command::Bench(c) => bench::run(c),
        Command::Predict(a) => predict::run(a),
        Command::Converge(a) => converge::run(a),
        Command::Experiment(a) => experiment::run(a),
        Command::Merge(a) => experiment::merge(a),
        Command::Completions { shell } => {
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut grammar(), "varspec", &mut script);
            stdout::bytes(&script);
            Ok(())
        }
        Command::Optimize(c) => optimize::run(c),
        Command::Render(a) => render::run(a),
        Command::Tables(a) => tables::run(a),
        Command::Integrands(a) => integrands::run(a),
    }
}

/// Output piped into `head` and closed early is not an error.
fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}
