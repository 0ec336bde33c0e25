//! `varspec spectrum`: expected power spectrum, radial profile, anisotropy.

use std::path::PathBuf;

use anyhow::bail;
use clap::ValueEnum;

use super::progress;
use super::source::SourceArgs;
use varspec::io::npy::write_npy;
use varspec::io::write_atomic;
use varspec::report::plot::{LinePlot, Series, line_plot_png, spectrum_png};
use varspec::spectrum::expected::check_memory;
use varspec::spectrum::radial::radial_profile;
use varspec::spectrum::{FrequencyBox, Method, expected_power};

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
    /// Resolution K: the frequency box |k| < K/2 in each axis.
    #[arg(long, default_value_t = 128)]
    res: usize,
    /// How S(k) is computed.
    #[arg(long, value_enum, default_value_t = MethodArg::Fast)]
    method: MethodArg,
    /// Relative tolerance of the fast method (1e-14 to 0.1).
    #[arg(long, default_value_t = 1e-9, allow_hyphen_values = true)]
    tol: f64,
    /// CSV of the spectrum: kx,ky,power.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// NumPy float64 array [S, S] of the spectrum, S = 2h + 1 with h the
    /// largest |k| in the box: row k_y + h, column k_x + h (DC at the centre).
    #[arg(long)]
    npy: Option<PathBuf>,
    /// CSV of the radial profile: k,power,anisotropy.
    #[arg(long)]
    radial: Option<PathBuf>,
    /// PNG heat map of the spectrum (log scale, centred at DC).
    #[arg(long)]
    png: Option<PathBuf>,
    /// PNG plot of the radial profile.
    #[arg(long)]
    radial_png: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    if a.res < 2 {
        bail!("--res {}: the box |k| < K/2 needs K >= 2", a.res);
    }
    super::args::check_outputs([
        a.csv.as_deref(),
        a.npy.as_deref(),
        a.radial.as_deref(),
        a.png.as_deref(),
        a.radial_png.as_deref(),
    ])?;
    let method = match a.method {
        MethodArg::Fast => Method::Fast { tolerance: a.tol },
        MethodArg::Direct => Method::Direct,
    };
    let freqs = FrequencyBox::from_resolution(2, a.res);
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
    let profile = radial_profile(&spectrum);
    let radial_csv = |w: &mut dyn std::io::Write| -> std::io::Result<()> {
        writeln!(w, "k,power,anisotropy")?;
        for b in &profile {
            writeln!(w, "{},{:?},{:?}", b.k, b.power, b.anisotropy)?;
        }
        Ok(())
    };
    if let Some(path) = &a.csv {
        write_atomic(path, |w| {
            writeln!(w, "kx,ky,power")?;
            let mut k = [0i64; 2];
            for (idx, p) in spectrum.power.iter().enumerate() {
                freqs.frequency(idx, &mut k);
                writeln!(w, "{},{},{:?}", k[0], k[1], p)?;
            }
            Ok(())
        })?;
    }
    if let Some(path) = &a.npy {
        let side = freqs.side() as u64;
        write_atomic(path, |w| write_npy(w, &[side, side], &spectrum.power))?;
    }
    if let Some(path) = &a.radial {
        write_atomic(path, radial_csv)?;
    }
    let title = format!("{} ({} sets)", source.name(), spectrum.sets);
    if let Some(path) = &a.png {
        spectrum_png(&spectrum, &title, path)?;
    }
    if let Some(path) = &a.radial_png {
        let plot = LinePlot {
            title: format!("radial power: {title}"),
            x_label: "|k|".into(),
            y_label: "power (N·P_S)".into(),
            log_log: false,
            series: vec![
                Series {
                    label: "radial mean".into(),
                    points: profile.iter().map(|b| (b.k as f64, b.power)).collect(),
                    reference: false,
                },
                Series {
                    label: "white noise".into(),
                    points: vec![(1.0, 1.0), (freqs.half as f64, 1.0)],
                    reference: true,
                },
            ],
        };
        line_plot_png(&plot, path)?;
    }
    if a.csv.is_none()
        && a.npy.is_none()
        && a.radial.is_none()
        && a.png.is_none()
        && a.radial_png.is_none()
    {
        let mut out = std::io::stdout().lock();
        radial_csv(&mut out)?;
    }
    Ok(())
}
