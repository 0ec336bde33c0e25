//! Figures of the course's error-analysis part that no other command draws
//! (Singh, Öztireli, Pilleboue & Jarosz, "Analysis of sample correlations
//! for Monte Carlo rendering"): jitter against Poisson disk radial spectra;
//! the variance formula's ingredients for a disk (sampling power spectrum,
//! integrand power spectrum, their product); N-rooks' anisotropic spectrum
//! and its radial average; variance against N of 4D multi-jitter before and
//! after shearing on a defocused light field. results/README.md indexes
//! every seed figure, these and those of the other commands.
//!
//! ```sh
//! cargo run --release --example seed_figures -- results/seed-figures
//! ```

use std::path::{Path, PathBuf};

use varspec::integrands;
use varspec::optimize::shear::Sheared;
use varspec::registry;
use varspec::report::plot::{LinePlot, Series, line_plot_png, spectrum_png};
use varspec::rng::set_rng;
use varspec::samplers::Sampler;
use varspec::spectrum::radial::radial_profile;
use varspec::spectrum::{FrequencyBox, Method, Spectrum, expected_power};
use varspec::variance::fourier::integrand_power;
use varspec::variance::{VarianceError, empirical_shifting, fit_slope};

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

/// E[N·P_S] of `sets` realizations of `name` at N = `n` on the 2D box of
/// resolution `res`.
fn spectrum(name: &str, n: usize, sets: usize, res: usize) -> Result<Spectrum> {
    let sampler = registry::build(name, n, Some(2), &[])?;
    Ok(expected_power(
        FrequencyBox::from_resolution(2, res),
        Method::Fast { tolerance: 1e-9 },
        sets,
        |r| -> std::result::Result<_, VarianceError> {
            Ok(sampler.sample(&mut set_rng(2016, r as u64))?)
        },
        &|| {},
    )?)
}

fn radial_series(label: &str, s: &Spectrum) -> Series {
    Series {
        label: label.into(),
        points: radial_profile(s)
            .iter()
            .map(|b| (b.k as f64, b.power))
            .collect(),
        reference: false,
    }
}

fn radial_plot(path: &Path, title: &str, series: Vec<Series>) -> Result<()> {
    let plot = LinePlot {
        title: title.into(),
        x_label: "|k|".into(),
        y_label: "radially averaged N·P_S".into(),
        log_log: false,
        series,
    };
    Ok(line_plot_png(&plot, path)?)
}

fn main() -> Result<()> {
    let out = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "out/seed-figures".into()),
    );
    std::fs::create_dir_all(&out)?;

    // Jitter against Poisson disk: radial spectra at N = 1024.
    let jitter = spectrum("jitter", 1024, 256, 160)?;
    let poisson = spectrum("poisson-disk", 1024, 256, 160)?;
    radial_plot(
        &out.join("radial-jitter-vs-poisson-disk.png"),
        "jitter vs Poisson disk, N = 1024 (256 sets)",
        vec![
            radial_series("jitter", &jitter),
            radial_series("Poisson disk (r = 0.7 of packing)", &poisson),
        ],
    )?;

    // The variance formula's ingredients on a disk: Var = Σ_(k≠0) P_S P_f.
    let n = 256;
    let sampling = spectrum("jitter", n, 256, 64)?;
    let disk = integrands::parse("disk:r=0.3")?;
    let pf = integrand_power(disk.as_ref(), &sampling.freqs);
    let as_spectrum = |power: Vec<f64>| Spectrum {
        freqs: sampling.freqs,
        power,
        sets: sampling.sets,
    };
    spectrum_png(
        &sampling,
        "sampling power spectrum E[N·P_S], jitter N = 256",
        &out.join("ingredients-sampling.png"),
    )?;
    spectrum_png(
        &as_spectrum(pf.clone()),
        "integrand power spectrum P_f, disk r = 0.3",
        &out.join("ingredients-integrand.png"),
    )?;
    let product: Vec<f64> = sampling.power.iter().zip(&pf).map(|(s, f)| s * f).collect();
    let zero = sampling.freqs.zero_index();
    let in_box: f64 = product
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != zero)
        .map(|(_, p)| p)
        .sum::<f64>()
        / n as f64;
    spectrum_png(
        &as_spectrum(product),
        "their product E[N·P_S]·P_f (sums to N·Var)",
        &out.join("ingredients-product.png"),
    )?;

    // N-rooks: zero power on the axes, which the radial average hides.
    let rooks = spectrum("nrooks", 256, 256, 64)?;
    spectrum_png(
        &rooks,
        "N-rooks N = 256 (256 sets)",
        &out.join("nrooks-spectrum.png"),
    )?;
    radial_plot(
        &out.join("nrooks-radial.png"),
        "N-rooks N = 256: radial average",
        vec![radial_series("N-rooks", &rooks)],
    )?;

    // 4D multi-jitter on a defocused light field (c = 0.5), estimator
    // shifted in (x, y) only, before and after the analytic shear a = b = −c.
    let field = integrands::parse("defocus:shape=disk,size=0.3,c=0.5")?;
    let (mut before, mut after) = (Vec::new(), Vec::new());
    let ns = [64usize, 256, 1024, 4096];
    for &n in &ns {
        let umj = registry::build("umj", n, Some(4), &[])?;
        let sheared = Sheared::new(umj.as_ref(), [-0.5, -0.5])?;
        let measure = |s: &dyn Sampler| {
            empirical_shifting(field.as_ref(), 4000, 7, &[0, 1], |r| {
                s.sample(&mut set_rng(99, r as u64))
                    .map_err(VarianceError::from)
            })
        };
        before.push((n as f64, measure(umj.as_ref())?.variance));
        after.push((n as f64, measure(&sheared)?.variance));
    }
    let slope = |v: &[(f64, f64)]| {
        let (x, y): (Vec<f64>, Vec<f64>) = v.iter().copied().unzip();
        fit_slope(&x, &y)
            .expect("positive variances at distinct N")
            .slope
    };
    let (sb, sa) = (slope(&before), slope(&after));
    let plot = LinePlot {
        title: "umj on defocus c = 0.5: variance vs N".into(),
        x_label: "N".into(),
        y_label: "variance (4000 realizations)".into(),
        log_log: true,
        series: vec![
            Series {
                label: format!("unsheared (slope {sb:.2})"),
                points: before.clone(),
                reference: false,
            },
            Series {
                label: format!("sheared a = b = -0.5 (slope {sa:.2})"),
                points: after.clone(),
                reference: false,
            },
        ],
    };
    line_plot_png(&plot, &out.join("shear-convergence.png"))?;

    let mut summary = format!(
        "disk r = 0.3, jitter N = {n}: in-box Σ E[N·P_S]·P_f / N = {in_box:.4e}\n\
         umj on defocus c = 0.5 (N, unsheared, sheared):\n"
    );
    for ((n, b), (_, a)) in before.iter().zip(&after) {
        summary += &format!("{n} {b:.4e} {a:.4e} ({:.2}x)\n", b / a);
    }
    summary += &format!("slopes: unsheared {sb:.2}, sheared {sa:.2}\n");
    std::fs::write(out.join("summary.txt"), &summary)?;
    print!("{summary}");
    Ok(())
}
