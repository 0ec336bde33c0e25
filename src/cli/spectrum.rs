//! `varspec spectrum`: expected power spectrum, radial profile, anisotropy.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::ValueEnum;

use super::progress;
use super::source::SourceArgs;
use varspec::integrands::Integrand;
use varspec::io::npy::write_npy;
use varspec::io::{write_atomic, write_csv_headed, write_csv_rows};
use varspec::report::plot::{LinePlot, Series, line_plot_png, power_png};
use varspec::scene::pixel::PixelIntegrand;
use varspec::spectrum::expected::check_memory;
use varspec::spectrum::radial::radial_profile;
use varspec::spectrum::{FrequencyBox, Method, Spectrum, expected_power};

#[derive(Clone, Copy, ValueEnum)]
enum MethodArg {
    /// Non-uniform FFT with tolerance --tol.
    Fast,
    /// Exact direct sums (slow reference).
    Direct,
}

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    source: SourceArgs,
    /// Instead of points: the power spectrum P_f = |F_f(k)|² of this
    /// integrand (e.g. disk:r=0.3), a 4D one on the plane --dims (0,2 is
    /// XU, 1,3 is YV). A scene pixel (scene:NAME,px=X,py=Y) has no closed
    /// form: its marginal on the plane is averaged over a 4h × 4h grid of
    /// cells (h = (K − 1)/2, the box's largest |k|), 16 random rays each
    /// (seeded by --seed), then transformed.
    #[arg(long, conflicts_with_all = ["points", "points_flag", "sampler", "n", "sets_given", "params", "density", "method", "tol"])]
    integrand: Option<String>,
    /// Resolution K: the frequency box |k| < K/2 in each axis.
    #[arg(value_parser = super::args::frequency_box, allow_negative_numbers = true, long, default_value_t = 128)]
    res: usize,
    /// How S(k) is computed (default fast).
    #[arg(long, value_enum)]
    method: Option<MethodArg>,
    /// Relative tolerance of the fast method (1e-14 to 0.1; default 1e-9).
    #[arg(value_parser = super::args::tolerance, long, allow_hyphen_values = true)]
    tol: Option<f64>,
    /// CSV of the spectrum: kx,ky,power (a projection's axes: kx,ku,power
    /// for --dims 0,2).
    #[arg(value_parser = super::args::csv_path, long)]
    csv: Option<PathBuf>,
    /// NumPy float64 array [S, S] of the spectrum, S = 2h + 1 with h the
    /// largest |k| in the box: row k_y + h, column k_x + h (DC at the centre).
    #[arg(value_parser = super::args::npy_path, long)]
    npy: Option<PathBuf>,
    /// CSV of the radial profile: k,power,anisotropy.
    #[arg(value_parser = super::args::csv_path, long)]
    radial: Option<PathBuf>,
    /// PNG heat map of the spectrum (log scale, centred at DC).
    #[arg(long, value_parser = super::args::png_path)]
    png: Option<PathBuf>,
    /// PNG plot of the radial profile.
    #[arg(long, value_parser = super::args::png_path)]
    radial_png: Option<PathBuf>,
}

/// The names of coordinate `d`'s frequency axis and of the coordinate in a
/// plane's title: kx/X, ky/Y, ku/U, kv/V, then by index (k4/X4, so that no
/// two columns share a name).
fn axis_names(d: usize) -> (String, String) {
    match ["x", "y", "u", "v"].get(d) {
        Some(letter) => (format!("k{letter}"), letter.to_uppercase()),
        None => (format!("k{d}"), format!("X{d}")),
    }
}

/// P_f of the integrand `spec` on `plane` (a 2D integrand's own plane by
/// default) on |k|∞ ≤ `half`, and its name.
fn integrand_power(
    spec: &str,
    plane: Option<[usize; 2]>,
    half: usize,
    seed: u64,
) -> anyhow::Result<(Spectrum, String)> {
    if PixelIntegrand::is_pixel_spec(spec) {
        let f = PixelIntegrand::parse(spec)?;
        let dims = plane.context(
            "a pixel is a 4D integrand: choose the plane of its spectrum with --dims (0,2 is XU, 1,3 is YV)",
        )?;
        let grid = half
            .checked_mul(4)
            .filter(|&g| g >= 8)
            .context("--res must be at least 5 for a pixel (and at most 2^60)")?;
        let power = f.plane_power(dims, grid, PixelIntegrand::RAYS_PER_CELL, seed)?;
        return Ok((power, f.spec()));
    }
    let f = varspec::integrands::parse(spec)?;
    let dims = match (plane, f.dim()) {
        (Some(dims), _) => dims,
        (None, 2) => [0, 1],
        (None, d) => bail!(
            "{} is {d}-dimensional: choose the plane of its spectrum with --dims (0,2 is XU, 1,3 is YV)",
            f.spec()
        ),
    };
    Ok((varspec::integrands::plane_power(&*f, dims, half)?, f.spec()))
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let pixel_files = a
        .integrand
        .as_deref()
        .map_or_else(Vec::new, PixelIntegrand::files_read);
    super::args::check_outputs_beside(
        [
            a.csv.as_deref(),
            a.npy.as_deref(),
            a.radial.as_deref(),
            a.png.as_deref(),
            a.radial_png.as_deref(),
        ],
        std::iter::once(a.source.file()).chain(pixel_files.iter().map(|p| Some(p.as_path()))),
    )?;
    let freqs = FrequencyBox::from_resolution(2, a.res);
    let plane = a.source.plane()?;
    let [(kx, x), (ky, y)] = plane.unwrap_or([0, 1]).map(axis_names);
    let axes = [kx.as_str(), ky.as_str()];
    // A projection's title names its plane (XU for dims 0,2; X4X5).
    let plane_name = plane.map_or(String::new(), |_| format!(", {x}{y} plane"));
    // The floor: the power an exact zero can show after the method's error
    // (0 for an integrand's closed-form power).
    let (spectrum, title, bar_label, floor) = match &a.integrand {
        Some(spec) => {
            let (power, name) = integrand_power(spec, plane, freqs.half, a.source.seed())?;
            (
                power,
                format!("{name}{plane_name}, P_f"),
                "log10 |F_f(k)|^2",
                0.0,
            )
        }
        None => {
            if !a.source.given() {
                bail!(
                    "nothing to analyse: name a point-set file (or --points FILE), draw sets with \
                     --sampler NAME -n N, or give --integrand SPEC for an integrand's power"
                );
            }
            let method = match a.method.unwrap_or(MethodArg::Fast) {
                MethodArg::Fast => Method::Fast {
                    tolerance: a.tol.unwrap_or(1e-9),
                },
                MethodArg::Direct if a.tol.is_some() => {
                    bail!("--tol applies to --method fast; the direct sums are exact")
                }
                MethodArg::Direct => Method::Direct,
            };
            check_memory(&freqs, method, a.res)?;
            let source = a.source.resolve(Some(2))?;
            let bar = progress::bar(source.count() as u64, "spectrum");
            let spectrum = expected_power(
                freqs,
                method,
                source.count(),
                |r| source.get(r).map_err(anyhow::Error::from),
                &|| bar.inc(1),
            )?;
            bar.finish_and_clear();
            let title = format!(
                "{}{plane_name} ({})",
                source.name(),
                super::stdout::counted(spectrum.sets, "set")
            );
            let n = spectrum.power[freqs.zero_index()];
            (
                spectrum,
                title,
                "log10 power (N·P_S)",
                method.power_floor(n),
            )
        }
    };
    let profile = radial_profile(&spectrum, floor);
    // Rings a coarse --tol cannot tell from empty are said, not hidden.
    let within: Vec<String> = profile
        .iter()
        .filter(|b| b.within_error && b.power > 0.0)
        .map(|b| b.k.to_string())
        .collect();
    if !within.is_empty() && a.integrand.is_none() {
        eprintln!(
            "note: ring(s) {} hold only powers within what an exact 0 reads after the \
             transform's error (<= {floor:.2e}): their anisotropy is written as 0{}",
            within.join(", "),
            match a.method.unwrap_or(MethodArg::Fast) {
                MethodArg::Fast =>
                    "; a smaller --tol (or --method direct) resolves rings that are not empty",
                MethodArg::Direct => "",
            }
        );
    }
    #[derive(serde::Serialize)]
    struct RadialRow {
        k: usize,
        power: f64,
        anisotropy: f64,
    }
    let radial_csv = |w: &mut dyn std::io::Write| -> std::io::Result<()> {
        write_csv_rows(
            w,
            profile.iter().map(|b| RadialRow {
                k: b.k,
                power: b.power,
                anisotropy: b.anisotropy,
            }),
        )
    };
    if let Some(path) = &a.csv {
        write_atomic(path, |w| {
            let mut k = [0i64; 2];
            write_csv_headed(
                w,
                &[axes[0], axes[1], "power"],
                spectrum.power.iter().enumerate().map(|(idx, &power)| {
                    freqs.frequency(idx, &mut k);
                    (k[0], k[1], power)
                }),
            )
        })?;
    }
    if let Some(path) = &a.npy {
        let side = freqs.side() as u64;
        write_atomic(path, |w| write_npy(w, &[side, side], &spectrum.power))?;
    }
    if let Some(path) = &a.radial {
        write_atomic(path, radial_csv)?;
    }
    if let Some(path) = &a.png {
        power_png(&spectrum, &title, axes, bar_label, path)?;
    }
    if let Some(path) = &a.radial_png {
        let plot = LinePlot {
            title: format!("radial power: {title}"),
            x_label: "|k|".into(),
            y_label: if a.integrand.is_some() {
                "power P_f".into()
            } else {
                "power (N·P_S)".into()
            },
            // An integrand's power decays over decades; a set's is read
            // against white noise.
            log_log: a.integrand.is_some(),
            series: std::iter::once(Series {
                label: "radial mean".into(),
                points: profile
                    .iter()
                    .filter(|b| a.integrand.is_none() || b.k > 0)
                    .map(|b| (b.k as f64, b.power))
                    .collect(),
                reference: false,
                error_bars: Vec::new(),
            })
            .chain(a.integrand.is_none().then(|| Series {
                label: "white noise".into(),
                points: vec![(1.0, 1.0), (freqs.half as f64, 1.0)],
                reference: true,
                error_bars: Vec::new(),
            }))
            .collect(),
        };
        line_plot_png(&plot, path)?;
    }
    let written: Vec<_> = [&a.csv, &a.npy, &a.radial, &a.png, &a.radial_png]
        .into_iter()
        .flatten()
        .collect();
    if written.is_empty() {
        // Through the command's standard output, which reports a failed
        // write as such (`> /dev/full`) and a reader that left as none.
        let mut table = Vec::new();
        radial_csv(&mut table)?;
        super::stdout::bytes(&table);
    }
    super::stdout::wrote(written);
    Ok(())
}
