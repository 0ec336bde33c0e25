//! The Fourier form (docs/mathematics.md; Pilleboue et al. 2015, Eq. (9) on the
//! torus): Var[Î] = Σ_(k≠0) E[P_S(k)]·P_f(k), truncated to a frequency box B
//! and completed by the Parseval tail: Σ_(k∉B) P_f(k) = c_f(0) − Σ_(k∈B\0)
//! P_f(k) exactly, weighted by 1/N, the white-noise level E[P_S] tends to
//! far from DC for non-lattice samplers.
//!
//! The error of that tail is Σ_(k∉B) (N·E[P_S(k)] − 1)·P_f(k)/N. It is
//! estimated from the outer shell of B (|k|∞ > h/2), where the deviation
//! δ(k) = N·P_S(k) − 1 is observed, weighting each frequency by the
//! integrand's P_f(k) so that structure shared by both spectra counts (an
//! N-rooks set has δ ≈ −1 on the axes, where a half-plane's square edges put
//! their energy). The bound is a bias term max(2|μ_w|, |μ|)·T/N — the
//! P_f-weighted mean deviation doubled for the extrapolation beyond the
//! shell, or the plain mean — plus three weighted standard deviations of a
//! fluctuation term, σ_w·√(T·max P_f)/N (using Σ_(k∉B) P_f² ≤ max P_f · T),
//! with T the tail mass and max P_f taken over the shell. Lattices (regular
//! grids) show large δ in the shell — N·P_S = N at their dual points: when
//! some shell frequency carries more than max(20, N/4)× the white-noise
//! power, the tail is bounded by max|δ|·T/N instead, the worst case the
//! shell shows. Below that, peaks are a random set's structure, not a
//! lattice's: a single periodogram's maximum over 10⁵ frequencies is about
//! 12, and correlated multi-jitter's averaged spectrum has near-axis peaks
//! of N·P_S ≈ 20, 58 and 98 at N = 256, 1024 and 4096, which the worst-case
//! bound turned into up to 65× the variance it bounds. When most of the integrand's energy lies beyond the box (tiny
//! disks, hairlines, k₀ outside B) the shell's max P_f says nothing about
//! the outside and the fluctuation term uses Σ_(k∉B) P_f² ≤ T² instead: the
//! bound is then wide, and says so. When the whole shell is dark (every
//! N·P_S below 1/20: a lattice-like set, uniform jitter or a rank-1
//! lattice, whose first dual ring lies beyond the box) the shell cannot
//! stand for what lies beyond — that ring may carry N·P_S = N where P_f is
//! large — and the bound is the rigorous one, (max_S |S|²/N − 1)·T/N with
//! |S| ≤ N: wide, and a sign that the box must grow. Otherwise the bound is
//! an estimate from the data, not a theorem: it assumes the shell
//! represents the frequencies beyond it.
//!
//! With a 2D closed-form expected spectrum ([`fourier_expected`]) the tail
//! is summed exactly over the axis strips beyond the box, where N-rooks
//! samplers are far from white ([`super::strips`]); the shell then leaves
//! out its frequencies within the strips' half-width of an axis, and the
//! bound adds the strips' continuation beyond their reach, twice their
//! outer half's mean deviation over the rest's mass.
//!
//! Rounding: a set that integrates f exactly (uniform jitter on a smooth
//! bump) has a Fourier variance of zero, and the computed one is what the
//! arithmetic leaves. Two sources bound it. The transform's error is
//! |ΔS(k)| ≤ e = 25·ε·N at tolerance ε (measured: [`Method::error_bound`](crate::spectrum::Method::error_bound)), so
//! N·P_S = |S|²/N is off by at most (2|S|·e + e²)/N per frequency, with
//! E|S| ≤ √(E|S|²) (Jensen) from the expected power; weighted by P_f and
//! summed over the box. The tail T = c_f(0) − Σ_(k∈B) P_f is a difference
//! of computed sums, off by about 4u·(c_f(0) + I² + Σ P_f) for the unit
//! roundoff u (c_f(0) is itself a difference of its closed form's terms).
//! The bound is their sum over N; for a white-noise-like set it is about
//! 50ε√N relative, for a lattice on a smooth f it is the tail's rounding,
//! which is what an unguarded log-log fit would otherwise fit.
//!
//! Sets with a density λ (a random number of points, weight 1/λ) use
//! P_S = |S|²/λ and λ in place of N throughout, plus the k = 0 term
//! E[(N/λ − 1)²]·I², the variance the random count adds (docs/mathematics.md
//! §2, "A random number of points"); it is 0 for a fixed N.

use rayon::prelude::*;

use super::VarianceError;
use crate::integrands::Integrand;
use crate::points::PointSet;
use crate::samplers::ClosedFormSpectrum;
use crate::spectrum::{FrequencyBox, Method, Spectrum, expected_power_with};
use crate::sum::NeumaierSum;

use super::strips::{AxisStrips, axis_strips};

/// Shell deviation |N·P_S − 1| above which the spectrum is treated as a
/// lattice's, when N/4 is smaller (see the module doc).
const LATTICE_SPIKE: f64 = 20.0;
/// Shell power N·P_S below which every shell frequency counts as dark (see
/// the module doc).
const DARK_SHELL: f64 = 0.05;

/// The Fourier prediction.
#[derive(Debug, Clone, PartialEq)]
pub struct FourierEstimate {
    /// Σ_(k∈B\0) E[P_S] P_f + tail/N + count term.
    pub variance: f64,
    /// Standard error of `variance` over realizations (0 for one).
    pub stderr: f64,
    /// Bound on the error of the tail term (see the module doc).
    pub truncation_bound: f64,
    /// Bound on what the transform's tolerance and floating point put into
    /// the value (see the module doc, "Rounding"): a variance at or below
    /// it is zero to rounding (a lattice integrating f exactly).
    pub rounding_bound: f64,
    /// The part from inside the box.
    pub in_box: f64,
    /// The Parseval tail term T/N.
    pub tail: f64,
    /// The k = 0 term E[(N/λ − 1)²]·I² of a random-count process (0 for a
    /// fixed N).
    pub count_term: f64,
    /// The box half-width h.
    pub half: usize,
    /// Realizations averaged (0 for a closed-form expected spectrum).
    pub sets: usize,
    /// The axis strips beyond the box summed with a 2D closed form
    /// ([`super::strips`]; already in `tail`), if any.
    pub strips: Option<AxisStrips>,
}

/// P_f(k) over the box, in box order (parallel; each value independent).
pub fn integrand_power(f: &dyn Integrand, freqs: &FrequencyBox) -> Vec<f64> {
    (0..freqs.len())
        .into_par_iter()
        .map_init(
            || vec![0i64; freqs.dim],
            |k, idx| {
                freqs.frequency(idx, k);
                f.fourier(k).norm_sqr()
            },
        )
        .collect()
}

/// The Fourier prediction over the box |k|∞ ≤ `half` from the expected
/// power of `sets` realizations (fast spectrum at tolerance `tolerance`).
///
/// # Errors
/// [`VarianceError`] for a dimension mismatch, sets of different N, a
/// failing realization or spectrum, or an integrand without Fourier
/// coefficients ([`VarianceError::NoFourier`]).
pub fn fourier<E>(
    f: &dyn Integrand,
    half: usize,
    tolerance: f64,
    sets: usize,
    realization: impl Fn(usize) -> Result<PointSet, E> + Sync,
) -> Result<FourierEstimate, VarianceError>
where
    VarianceError: From<E>,
    E: Send,
{
    fourier_parts(f, half, tolerance, sets, realization).map(|p| p.estimate)
}

/// The Fourier prediction with what it was computed from: the expected
/// power E[N·P_S] and P_f on the box (the radial form reuses them).
#[derive(Debug, Clone)]
pub struct FourierParts {
    /// The prediction.
    pub estimate: FourierEstimate,
    /// E[N·P_S(k)] on the box.
    pub spectrum: Spectrum,
    /// P_f(k) on the box, in box order.
    pub integrand_power: Vec<f64>,
    /// The normalisation: N, or the density λ of a random-count process.
    pub intensity: f64,
}

/// As [`fourier`], keeping the spectra.
///
/// # Errors
/// As [`fourier`].
pub fn fourier_parts<E>(
    f: &dyn Integrand,
    half: usize,
    tolerance: f64,
    sets: usize,
    realization: impl Fn(usize) -> Result<PointSet, E> + Sync,
) -> Result<FourierParts, VarianceError>
where
    VarianceError: From<E>,
    E: Send,
{
    if !f.has_fourier() {
        return Err(VarianceError::NoFourier { spec: f.spec() });
    }
    let freqs = FrequencyBox { dim: f.dim(), half };
    // P_f, the expected power and the transform all live on the box: check
    // it fits before drawing anything.
    crate::spectrum::nufft::check_nufft_memory(&freqs)?;
    let first = realization(0)?;
    let n = first.len();
    if n == 0 && first.density().is_none() {
        // Î = (1/N) Σ f(x_i) is undefined, and P_S = |S|²/N with it.
        return Err(VarianceError::NoPoints {
            what: "the Fourier predictor",
        });
    }
    if first.dim() != f.dim() {
        return Err(VarianceError::Dimension {
            integrand: f.dim(),
            points: first.dim(),
        });
    }
    let pf = integrand_power(f, &freqs);
    let intensity = first.intensity();
    // Every set's N, to form the count term E[(N/λ − 1)²]·I² exactly.
    let counts = std::sync::Mutex::new(vec![0usize; sets]);
    let zero = freqs.zero_index();
    // Each realization's in-box sum Σ_(k≠0) N·P_S(k)·P_f(k), for the standard error.
    let in_box_of = |power: &[f64]| {
        let mut s = NeumaierSum::default();
        for (idx, (&p, &w)) in power.iter().zip(&pf).enumerate() {
            if idx != zero {
                s.add(p * w);
            }
        }
        s.value()
    };
    let (spectrum, per_set) = expected_power_with(
        freqs,
        Method::Fast { tolerance },
        sets,
        |r| -> Result<PointSet, VarianceError> {
            // Realization 0 was drawn above for N and d: lend it, do not redraw.
            let set = if r == 0 {
                first.clone()
            } else {
                realization(r)?
            };
            match (first.density(), set.density()) {
                (Some(a), Some(b)) if a == b => {}
                (None, None) if set.len() == n => {}
                (None, None) => {
                    return Err(VarianceError::MixedSizes {
                        first: n,
                        other: set.len(),
                    });
                }
                (a, b) => return Err(VarianceError::MixedDensity { first: a, other: b }),
            }
            counts.lock().expect("no panics while held")[r] = set.len();
            Ok(set)
        },
        &in_box_of,
        &|| {},
    )?;
    let counts = counts.into_inner().expect("no panics while held");
    let sums = SetSums {
        intensity,
        counts: &counts,
        per_set: &per_set,
    };
    Ok(assemble(f, tolerance, pf, spectrum, sums, None))
}

/// The Fourier form with the sampler's closed-form expected power
/// E[N·P_S(k)] ([`ClosedFormSpectrum`]: random, jitter, multi-jitter and
/// CMJ in 2D through their pair sums, 1 + C(k, k)/N; padded 4D samplers
/// such as umj whose halves have them) in place of realizations: the
/// expectation Σ_(k≠0) E[P_S(k)]·P_f(k) of Pilleboue et al. 2015, Eq. (9),
/// itself, with no sampling error (`stderr` 0, `sets` 0), and the same
/// Parseval tail, whose bound now reads an exact shell.
///
/// # Errors
/// [`VarianceError::NoFourier`] for an integrand without Fourier
/// coefficients, [`VarianceError::Dimension`] for one of another dimension
/// than the points, and a box too large for memory.
pub fn fourier_expected(
    f: &dyn Integrand,
    half: usize,
    closed: &ClosedFormSpectrum,
) -> Result<FourierParts, VarianceError> {
    if !f.has_fourier() {
        return Err(VarianceError::NoFourier { spec: f.spec() });
    }
    let dim = closed.dim();
    if f.dim() != dim {
        return Err(VarianceError::Dimension {
            integrand: f.dim(),
            points: dim,
        });
    }
    let n = closed.points();
    if n == 0 {
        return Err(VarianceError::NoPoints {
            what: "the Fourier predictor",
        });
    }
    let freqs = FrequencyBox { dim, half };
    // No transform here: P_f and the closed-form power (8 bytes each per
    // frequency) and `assemble`'s shell of (δ, P_f) pairs (16 bytes for
    // each of 3/4 of the frequencies in 2D, 15/16 in 4D, in a vector grown
    // by doubling): at most 40 bytes per frequency (measured 27.9 in 2D
    // and 31.0 in 4D; the former 24 let runs 16–29% over the limit pass).
    crate::memory::check(
        &format!(
            "the closed-form expected power on the {}^{} frequency box (|k| <= {half})",
            freqs.side(),
            dim
        ),
        freqs.checked_len().map(|len| len as f64 * 40.0),
        if dim == 4 {
            "lower --res (4D boxes grow as K^4)"
        } else {
            "lower --res"
        },
    )?;
    let pf = integrand_power(f, &freqs);
    let power: Vec<f64> = (0..freqs.len())
        .into_par_iter()
        .map_init(
            || vec![0i64; dim],
            |k, idx| {
                freqs.frequency(idx, k);
                closed.power(k)
            },
        )
        .collect();
    let spectrum = Spectrum {
        freqs,
        power,
        sets: 0,
    };
    let sums = SetSums {
        intensity: n as f64,
        counts: &[n],
        per_set: &[],
    };
    let strips = axis_strips(f, closed, half);
    Ok(assemble(f, 0.0, pf, spectrum, sums, strips))
}

/// What the realizations (or a closed form) bring beside the power.
struct SetSums<'a> {
    /// The normalisation: N, or the density λ of a random-count process.
    intensity: f64,
    /// Every set's N (one entry, N, for a closed form).
    counts: &'a [usize],
    /// Each set's in-box sum (none for a closed form).
    per_set: &'a [f64],
}

/// The prediction from the expected power on the box: the in-box sum, the
/// Parseval tail and its bound, the rounding bound, and the standard error
/// from the per-set in-box sums (none for a closed form: 0). With `strips`
/// the tail is exact on them and the shell that estimates the rest leaves
/// out its frequencies within the strips' half-width of an axis.
fn assemble(
    f: &dyn Integrand,
    tolerance: f64,
    pf: Vec<f64>,
    spectrum: Spectrum,
    sums: SetSums,
    strips: Option<AxisStrips>,
) -> FourierParts {
    let SetSums {
        intensity,
        counts,
        per_set,
    } = sums;
    let freqs = spectrum.freqs;
    let half = freqs.half;
    let zero = freqs.zero_index();
    let (mut in_box, mut mass) = (NeumaierSum::default(), NeumaierSum::default());
    // Shell statistics of δ = power − 1 (two passes) and max P_f there.
    let mut k = vec![0i64; freqs.dim];
    let shell: Vec<(f64, f64)> = (0..freqs.len())
        .filter(|&idx| {
            freqs.frequency(idx, &mut k);
            let abs = k.iter().map(|v| v.unsigned_abs() as usize);
            let on_strip = strips.is_some_and(|s| abs.clone().min().unwrap_or(0) <= s.width);
            2 * abs.max().unwrap_or(0) > half && !on_strip
        })
        .map(|idx| (spectrum.power[idx] - 1.0, pf[idx]))
        .collect();
    // Σ √(N·P_S)·P_f for the rounding bound, in the same pass.
    let mut root_weighted = NeumaierSum::default();
    for (idx, (&p, &w)) in spectrum.power.iter().zip(&pf).enumerate() {
        if idx != zero {
            in_box.add(p * w);
            mass.add(w);
            root_weighted.add(p.max(0.0).sqrt() * w);
        }
    }
    let nf = intensity;
    let count_bias = |c: usize| super::count_term(c, intensity, f.integral());
    let count_term = crate::sum::sum(counts.iter().map(|&c| count_bias(c))) / counts.len() as f64;
    let tail_mass = (f.variance() - mass.value()).max(0.0);
    // What the shell's estimate must cover: the tail less the strips.
    let rest_mass = (tail_mass - strips.map_or(0.0, |s| s.mass)).max(0.0);
    let (bias, spread, pf_max) = if shell.is_empty() {
        (1.0, 0.0, 0.0)
    } else {
        let m = shell.len() as f64;
        let mean = shell.iter().map(|s| s.0).sum::<f64>() / m;
        let weight: f64 = shell.iter().map(|s| s.1).sum();
        let (mean_w, sd_w) = if weight > 0.0 {
            let mw = shell.iter().map(|s| s.0 * s.1).sum::<f64>() / weight;
            let var = shell.iter().map(|s| s.1 * (s.0 - mw).powi(2)).sum::<f64>() / weight;
            (mw, var.sqrt())
        } else {
            let sd = (shell.iter().map(|s| (s.0 - mean).powi(2)).sum::<f64>() / m).sqrt();
            (mean, sd)
        };
        let pf_max = shell.iter().map(|s| s.1).fold(0.0, f64::max);
        ((2.0 * mean_w.abs()).max(mean.abs()), sd_w, pf_max)
    };
    let worst = shell.iter().map(|s| s.0.abs()).fold(0.0, f64::max);
    let dark = !shell.is_empty() && shell.iter().all(|s| s.0 + 1.0 < DARK_SHELL);
    let truncation_bound = if worst > LATTICE_SPIKE.max(0.25 * nf) {
        worst * rest_mass / nf
    } else if dark {
        // |S(k)|² ≤ c² for c points: N·P_S = |S|²/λ ≤ c²/λ beyond the box.
        let largest = counts.iter().copied().max().unwrap_or(0) as f64;
        (largest * largest / nf - 1.0).max(1.0) * rest_mass / nf
    } else if rest_mass > mass.value() {
        // Most of the energy lies beyond the box, where the shell's max P_f
        // says nothing: use the rigorous Σ_(k∉B) P_f² ≤ T².
        (bias * rest_mass + 3.0 * spread * rest_mass) / nf
    } else {
        (bias * rest_mass + 3.0 * spread * (rest_mass * pf_max).sqrt()) / nf
    } + strips.map_or(0.0, |s| {
        // The strips go on beyond their reach as their outer half did
        // (doubled, as the shell's mean), over at most the rest's mass.
        2.0 * s.outer_deviation.abs() * rest_mass / nf
    });
    let rounding_bound = {
        let largest = counts.iter().copied().max().unwrap_or(0) as f64;
        let e = crate::spectrum::Method::Fast { tolerance }.error_bound(largest);
        // Σ (2|S|·e + e²)/N·P_f with |S| = √(N·P_S): the two sums the box
        // pass gathered.
        let transform = (2.0 * e * root_weighted.value() * nf.sqrt() + e * e * mass.value()) / nf;
        let integral = f.integral();
        let sums = f.variance().abs() + integral * integral + mass.value() + in_box.value();
        (transform + 4.0 * f64::EPSILON * sums) / nf
    };
    let in_box = in_box.value() / nf;
    let tail = (tail_mass + strips.map_or(0.0, |s| s.correction)) / nf;
    // Per-set values (in-box part and count term) for the standard error.
    let per_set: Vec<f64> = per_set
        .iter()
        .zip(counts)
        .map(|(v, &c)| v / nf + count_bias(c))
        .collect();
    // A closed form has no per-set values and no sampling error.
    let stderr = if per_set.is_empty() {
        0.0
    } else {
        crate::sum::mean_and_stderr(&per_set).1
    };
    let sets = spectrum.sets;
    FourierParts {
        estimate: FourierEstimate {
            variance: in_box + tail + count_term,
            stderr,
            truncation_bound,
            rounding_bound,
            in_box,
            tail,
            count_term,
            half,
            sets,
            strips,
        },
        spectrum,
        integrand_power: pf,
        intensity,
    }
}
