//! The expected power spectrum E[N·P_S(k)] (docs/mathematics.md: "power"; white
//! noise ≈ 1 away from DC) averaged over realizations.

use rayon::prelude::*;
use rustfft::num_complex::Complex64;

use super::nufft::{NufftPlan, Sign, Upsampling};
use super::{FrequencyBox, SpectrumError, dft};
use crate::points::PointSet;

/// Realizations summed per task: fixed, so the reduction order — and every
/// output bit — is independent of the thread count.
const CHUNK: usize = 8;

/// How S(k) is computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Exact direct sums (the reference), O(N·K^d).
    Direct,
    /// Type-1 non-uniform FFT with relative tolerance ε, O(N·w^d + K^d log K),
    /// its upsampling chosen for the first realization's size
    /// ([`Upsampling::Auto`]).
    Fast {
        /// ε in [1e-14, 0.1].
        tolerance: f64,
    },
}

/// The transform's error per frequency as a multiple of ε·N, measured
/// (not proved) on single points, where no averaging between points helps:
/// up to 7.6·ε·N for ε = 1e-3 … 1e-10 on boxes to 513² (6.6 at 1e-6 for a
/// point at the centre), up to 14 at 1e-12 and 23 at ε = 1e-10 … 1e-14 on
/// a 4001² box (the kernels' per-axis errors add, and the transform's own
/// rounding grows with the grid); sets of 200 random points stay within
/// 1.4·ε·N. The rounding bound takes the worst with some room.
const NUFFT_ERROR_FACTOR: f64 = 25.0;

/// |ΔS(k)| of the direct sums as a multiple of u·N (u the unit roundoff):
/// each term's phase is reduced exactly and its cosine and sine are within
/// a few u, and the compensated sum adds about u·|S|; 16 leaves room.
const DIRECT_ERROR_FACTOR: f64 = 16.0;

impl Method {
    /// The bound on this method's error |ΔS(k)| for sets of (at most) `n`
    /// points: [`NUFFT_ERROR_FACTOR`]·ε·n for the transform,
    /// [`DIRECT_ERROR_FACTOR`]·u·n for the direct sums (u the unit
    /// roundoff).
    pub fn error_bound(self, n: f64) -> f64 {
        let e = match self {
            Method::Direct => DIRECT_ERROR_FACTOR * f64::EPSILON / 2.0,
            Method::Fast { tolerance } => NUFFT_ERROR_FACTOR * tolerance,
        };
        e * n
    }

    /// The largest power N·P_S = |S|²/N that a frequency whose exact power
    /// is 0 can show after this method's error, for sets of about `n`
    /// points: [`Method::error_bound`]²/n. Below it a power is
    /// indistinguishable from 0 (a lattice's empty rings read 1e-33 to
    /// 1e-21, not 0).
    pub fn power_floor(self, n: f64) -> f64 {
        // (e·n)²/n as e·e·n: the bound per point, squared, once.
        let e = self.error_bound(1.0);
        e * e * n
    }
}

/// A power spectrum on a frequency box.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectrum {
    /// The frequencies, in box order.
    pub freqs: FrequencyBox,
    /// E[N·P_S(k)] per frequency (power; N at k = 0).
    pub power: Vec<f64>,
    /// Realizations averaged.
    pub sets: usize,
}

impl Spectrum {
    /// The power at frequency `k`.
    ///
    /// # Panics
    /// If k lies outside the box.
    pub fn at(&self, k: &[i64]) -> f64 {
        let side = self.freqs.side() as i64;
        let h = self.freqs.half as i64;
        let idx = k.iter().rev().fold(0i64, |acc, &kj| {
            assert!(kj.abs() <= h, "frequency {k:?} outside the box");
            acc * side + kj + h
        });
        self.power[idx as usize]
    }
}

/// Checks that a transform on `freqs` fits in memory: the output, and for
/// the fast method one fine grid (2·side)^d of 2 complex buffers per thread.
///
/// # Errors
/// [`SpectrumError::TooLarge`] with the estimate.
pub fn check_memory(freqs: &FrequencyBox, method: Method, res: usize) -> Result<(), SpectrumError> {
    let side = freqs.side() as f64;
    let d = freqs.dim as i32;
    let threads = rayon::current_num_threads() as f64;
    let bytes = match method {
        Method::Direct => side.powi(d) * (16.0 + 8.0 * threads),
        Method::Fast { .. } => {
            side.powi(d) * 8.0 * (threads + 1.0) + threads * 2.0 * (2.0 * side).powi(d) * 16.0
        }
    };
    crate::memory::check(
        &format!("a power spectrum of resolution {res} in {}D", freqs.dim),
        Some(bytes),
        "lower --res",
    )?;
    Ok(())
}

/// E[N·P_S(k)] over `sets` realizations on the box `freqs` (E[|S(k)|²/λ]
/// for sets with a density λ, which tends to 1 far from the origin just the
/// same); realization r is
/// `realization(r)` (a set from a file, or a fresh sampler draw), projected
/// by the caller as needed. Parallel over realizations in fixed chunks.
///
/// # Errors
/// [`SpectrumError`] for no sets, a dimension mismatch, a bad tolerance or
/// too much memory; `realization`'s own error converted.
pub fn expected_power<E>(
    freqs: FrequencyBox,
    method: Method,
    sets: usize,
    realization: impl Fn(usize) -> Result<PointSet, E> + Sync,
    on_set_done: &(dyn Fn() + Sync),
) -> Result<Spectrum, E>
where
    E: From<SpectrumError> + Send,
{
    expected_power_with(freqs, method, sets, realization, &|_| 0.0, on_set_done).map(|(s, _)| s)
}

/// As [`expected_power`], and also `statistic(power_r)` of every
/// realization's own power spectrum N·P_S (box order), returned in
/// realization order — e.g. its inner product with an integrand's P_f, for
/// per-set variances and their standard error.
///
/// # Errors
/// As [`expected_power`].
pub fn expected_power_with<E>(
    freqs: FrequencyBox,
    method: Method,
    sets: usize,
    realization: impl Fn(usize) -> Result<PointSet, E> + Sync,
    statistic: &(dyn Fn(&[f64]) -> f64 + Sync),
    on_set_done: &(dyn Fn() + Sync),
) -> Result<(Spectrum, Vec<f64>), E>
where
    E: From<SpectrumError> + Send,
{
    if sets == 0 {
        return Err(SpectrumError::NoSets.into());
    }
    // The first realization is drawn up front: its size picks the
    // transform's upsampling (the same choice for any thread count).
    let first = realization(0)?;
    let plan = match method {
        Method::Fast { tolerance } => Some(NufftPlan::with_upsampling(
            freqs,
            tolerance,
            Upsampling::Auto {
                points: first.len(),
            },
        )?),
        Method::Direct => None,
    };
    let len = freqs.len();
    let chunks: Vec<(Vec<f64>, Vec<f64>)> = (0..sets.div_ceil(CHUNK))
        .into_par_iter()
        .map_init(
            || {
                let zero = Complex64::new(0.0, 0.0);
                (
                    plan.as_ref().map(NufftPlan::make_scratch),
                    vec![zero; len],
                    vec![0.0; len],
                )
            },
            |(scratch, s, power), c| -> Result<(Vec<f64>, Vec<f64>), E> {
                let mut sum = vec![0.0; len];
                let mut stats = Vec::with_capacity(CHUNK);
                for r in c * CHUNK..((c + 1) * CHUNK).min(sets) {
                    let points = if r == 0 {
                        first.clone()
                    } else {
                        realization(r)?
                    };
                    if points.dim() != freqs.dim {
                        return Err(SpectrumError::Dimension {
                            expected: freqs.dim,
                            found: points.dim(),
                        }
                        .into());
                    }
                    match (&plan, scratch.as_mut()) {
                        (Some(plan), Some(scratch)) => {
                            plan.type1(&points, None, Sign::Negative, s, scratch)
                        }
                        _ => s.copy_from_slice(&dft::sample_spectrum(&points, &freqs)),
                    }
                    // |S|²/N, or |S|²/λ for a random-count set (an empty one
                    // has S = 0 and power 0 either way).
                    let n = if points.is_empty() {
                        1.0
                    } else {
                        points.intensity()
                    };
                    for ((acc, p), v) in sum.iter_mut().zip(power.iter_mut()).zip(s.iter()) {
                        *p = v.norm_sqr() / n;
                        *acc += *p;
                    }
                    stats.push(statistic(power));
                    on_set_done();
                }
                Ok((sum, stats))
            },
        )
        .collect::<Result<_, E>>()?;
    let mut power = vec![0.0; len];
    let mut stats = Vec::with_capacity(sets);
    for (chunk, chunk_stats) in &chunks {
        for (p, v) in power.iter_mut().zip(chunk) {
            *p += v;
        }
        stats.extend_from_slice(chunk_stats);
    }
    for p in &mut power {
        *p /= sets as f64;
    }
    Ok((Spectrum { freqs, power, sets }, stats))
}
