//! The expected variance of a sheared padded 4D set, in closed form.
//!
//! A padded sampler draws an (x, y) set P and a (u, v) set Q independently
//! and pairs them by a uniformly random permutation π. Shear it,
//! x′_j = x_j + a·u_π(j), y′_j = y_j + b·v_π(j), and judge it by the
//! estimator Î(s) = (1/N) Σ_j f(x′_j + s_x, y′_j + s_y, u_π(j), v_π(j))
//! with a uniform shift s in (x, y) only: a shift in (u, v) would wrap
//! across the shear and undo it, and the (x, y) shift keeps Î unbiased for
//! any light field (docs/mathematics.md §6.2).
//!
//! Write f in (x, y) Fourier series, f = Σ_k φ_k(u, v) e^(2πik·(x,y)), with
//! φ_k = Σ_t A_t(k) e^(2πi ω_t(k)·(u,v)) ([`LightField`]). Averaging over s
//! leaves Σ_(k≠0) |(1/N) Σ_j φ_k(q_π(j)) e^(2πik·x′_j)|², and averaging over
//! the random pairing separates the pairs of P from the pairs of Q. With
//! E[N·P_P(k)] = p_k the (x, y) half's expected power and
//! C(ω, ω′) = E[Σ_(l≠m) e^(2πi(ω·q_l − ω′·q_m))] the (u, v) half's expected
//! pair sum ([`PairSpectrum`]):
//!
//!   J(a, b) = Var f / N
//!           + Σ_(k≠0) (p_k − 1)/(N²(N − 1)) · Σ_(t,t′) A_t conj(A_t′) C(ω_t + σ_k, ω_t′ + σ_k),
//!
//! σ_k = (a·k_x, b·k_y). The first term is plain random sampling; the
//! second is what the two halves' correlations buy. Where both halves have
//! closed forms (random, jitter, multi-jitter, CMJ) J is exact up to the
//! truncation of the sum, which is reported as a bound; other halves are
//! estimated from realizations with a standard error, the (u, v) half's
//! pair sums by powers of one phasor per point, or by one NUFFT per wave
//! where the terms fill a large box ([`super::layer_sums`]).
//!
//! At the shear a = b = −c of a single defocus layer, σ_k cancels ω(k) = c·k,
//! C(0, 0) = N(N − 1) and J = Σ_k |G(k)|² p_k / N: the (x, y) set integrates
//! the 2D shape g alone, which is why the light field's own shear is the
//! optimum wherever p_k < 1.

use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;

use super::super::OptimizeError;
use super::layer_sums::{LayerSums, Scratch, SumMethod};
use crate::integrands::{Integrand, LightField, PlaneWave, light_field_energy};
use crate::points::PointSet;
use crate::rng::set_rng;
use crate::samplers::{Sampler, generate_sets, sets_bytes};
use crate::spectrum::pair::PairSpectrum;
use crate::spectrum::{FrequencyBox, Method, expected_power_with};
use crate::sum::NeumaierSum;
use crate::sum::{mean, sample_variance};

/// Terms (or realizations) summed per parallel task: fixed, so the sum's
/// rounding is the same for any number of threads.
const CHUNK: usize = 32;
/// Largest box half-width of the frequency sum.
const MAX_HALF: usize = 1024;
/// Terms of the coarse J: enough for the low frequencies that set the
/// basins (the half-plane of the box |k|∞ ≤ 32 holds 2,112), a fraction of the full sum's
/// 12,500–156,000 at N = 256…4096 for an aperture with an edge.
pub const COARSE_TERMS: usize = 2048;
/// Box half-width when the (x, y) half is estimated from realizations.
const EMPIRICAL_HALF: usize = 48;
/// Stream offsets of the realizations behind empirical halves.
const XY_STREAM: u64 = 0x5859_5f48_414c_4631;
const UV_STREAM: u64 = 0x5556_5f48_414c_4632;

/// How accurate the objective must be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectiveOptions {
    /// Target of truncation bound / J at the start (relative).
    pub truncation: f64,
    /// Target relative standard error at the start, for halves estimated
    /// from realizations.
    pub stderr: f64,
    /// Realizations of an estimated half: the first try.
    pub min_realizations: usize,
    /// Realizations of an estimated half: the most.
    pub max_realizations: usize,
    /// Seed of those realizations.
    pub seed: u64,
}

impl Default for ObjectiveOptions {
    fn default() -> Self {
        ObjectiveOptions {
            truncation: 0.01,
            stderr: 0.01,
            min_realizations: 16,
            max_realizations: 4096,
            seed: 0,
        }
    }
}

/// One frequency k of the half-plane (it stands for k and −k).
struct Term {
    waves: Vec<PlaneWave>,
    k: [f64; 2],
    /// (p_k − 1)·2/(N²(N − 1)).
    coefficient: f64,
    /// Index into the (x, y) spectrum box, for per-set statistics.
    box_index: Option<usize>,
}

/// The (x, y) half's expected power.
enum XyPower {
    Exact,
    /// Mean over `sets` realizations on a box.
    Empirical {
        freqs: FrequencyBox,
        power: Vec<f64>,
        sets: usize,
    },
}

/// The (u, v) half's expected pair sums: a closed form, or realizations.
enum UvPairs<'a> {
    Exact(&'a dyn PairSpectrum),
    Empirical(UvRealizations),
}

/// Realizations of the (u, v) half.
struct UvRealizations {
    sets: Vec<PointSet>,
}

/// Frequencies summed in J, with what an estimated (u, v) half needs of
/// them: their table of powers and their diagonals Σ_l |ψ_k(q_l)|², which
/// no shear changes.
#[derive(Default)]
struct TermSet {
    terms: Vec<Term>,
    layer_sums: LayerSums,
    /// Σ_k coefficient·diagonal, per (u, v) realization.
    weighted_diagonal: Vec<f64>,
    /// The mean diagonal over the (u, v) realizations, per term.
    mean_diagonal: Vec<f64>,
}

/// The objective J(a, b): the expected variance of the (x, y)-shifted
/// estimator over the sampler's randomness.
pub struct ShearObjective<'a> {
    n: usize,
    variance: f64,
    sampler: &'a dyn Sampler,
    xy: XyPower,
    uv: UvPairs<'a>,
    /// The terms of J within its truncation bound.
    full: TermSet,
    /// The [`COARSE_TERMS`] of them with the largest bounds: J at low
    /// resolution in the shear, for scans that locate basins.
    coarse: TermSet,
    half: usize,
    truncation_bound: f64,
    seed: u64,
    evaluations: AtomicU64,
    coarse_evaluations: AtomicU64,
}

/// J at one shear with its uncertainty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Evaluation {
    /// J(a, b).
    pub value: f64,
    /// Standard error from the estimated halves (0 when both are exact).
    pub stderr: f64,
}

impl<'a> ShearObjective<'a> {
    /// The objective for light field `f` and padded sampler `sampler`,
    /// accurate to `options` at the shears `starts` (the best of them sets
    /// the scale of the targets).
    ///
    /// # Errors
    /// [`OptimizeError::Option`] when `f` has no light-field form or the
    /// sampler has no (x, y) and (u, v) halves; sampler errors of estimated
    /// halves.
    pub fn new(
        f: &dyn Integrand,
        sampler: &'a dyn Sampler,
        starts: &[[f64; 2]],
        options: ObjectiveOptions,
    ) -> Result<Self, OptimizeError> {
        let light = f.light_field().ok_or_else(|| {
            OptimizeError::Option(format!(
                "the shear search evaluates the expected variance from a light field's spectrum; \
                 {} has no light-field form (4D light fields: defocus, layers)",
                f.spec()
            ))
        })?;
        let [xy_half, uv_half] = sampler.halves().ok_or_else(|| {
            OptimizeError::Option(
                "the shear search on a light field needs a padded 4D sampler with independent \
                 (x, y) and (u, v) halves (its expected variance is computed from theirs): umj or \
                 padded:xy=...,uv=... (on a scene pixel, where each candidate's variance is \
                 measured, any 4D sampler)"
                    .into(),
            )
        })?;
        let n = sampler.points_per_set();
        if n < 2 {
            return Err(OptimizeError::Option(
                "the shear search needs at least 2 points per set".into(),
            ));
        }
        // Realizations of the (x, y) and (u, v) halves, grown separately.
        let mut counts = [options.min_realizations.max(2); 2];
        loop {
            let [xy_count, uv_count] = counts;
            let uv = match uv_half.pair_spectrum() {
                Some(s) => UvPairs::Exact(s),
                None => UvPairs::Empirical(UvRealizations {
                    sets: draw(uv_half, options.seed ^ UV_STREAM, uv_count)?,
                }),
            };
            let xy = match xy_half.pair_spectrum() {
                Some(_) => XyPower::Exact,
                None => {
                    let freqs = FrequencyBox {
                        dim: 2,
                        half: EMPIRICAL_HALF,
                    };
                    let seed = options.seed ^ XY_STREAM;
                    let (spectrum, _) = expected_power_with(
                        freqs,
                        Method::Fast { tolerance: 1e-10 },
                        xy_count,
                        |r| {
                            xy_half
                                .sample(&mut set_rng(seed, r as u64))
                                .map_err(OptimizeError::from)
                        },
                        &|_| 0.0,
                        &|| {},
                    )?;
                    XyPower::Empirical {
                        freqs,
                        power: spectrum.power,
                        sets: xy_count,
                    }
                }
            };
            let mut objective = ShearObjective {
                n,
                variance: f.variance(),
                sampler,
                xy,
                uv,
                full: TermSet::default(),
                coarse: TermSet::default(),
                half: 0,
                truncation_bound: 0.0,
                seed: options.seed,
                evaluations: 0.into(),
                coarse_evaluations: 0.into(),
            };
            objective.choose_terms(light, xy_half, starts, options.truncation)?;
            let best = starts
                .iter()
                .map(|&s| objective.value(s[0], s[1]))
                .fold(f64::INFINITY, f64::min);
            let at = starts
                .iter()
                .copied()
                .find(|s| objective.value(s[0], s[1]) == best)
                .unwrap_or([0.0, 0.0]);
            // Each estimated half gets an equal share of the target
            // variance; a half over its share grows by the ratio (the
            // variance falls as 1/R).
            let (_, variances) = objective.evaluate_parts(at)?;
            let estimated = objective.realizations().iter().filter(|&&r| r > 0).count();
            let target = (options.stderr * best.abs().max(f64::MIN_POSITIVE)).powi(2);
            let share = target / estimated.max(1) as f64;
            let mut grew = false;
            if variances.iter().sum::<f64>() > target {
                for (count, variance) in counts.iter_mut().zip(variances) {
                    if variance > share && *count < options.max_realizations {
                        // Clamped in f64: a vanishing share must not
                        // overflow the count.
                        let factor = (variance / share).ceil().clamp(2.0, 1e6) as usize;
                        *count = count.saturating_mul(factor).min(options.max_realizations);
                        grew = true;
                    }
                }
            }
            if !grew {
                objective.evaluations.store(0, Ordering::Relaxed);
                objective.coarse_evaluations.store(0, Ordering::Relaxed);
                return Ok(objective);
            }
        }
    }

    /// The frequency terms, chosen to keep the truncation bound within
    /// `target` of J at the starts (J_ref, computed on the box |k|∞ ≤ 64
    /// first):
    /// 1. the box |k|∞ ≤ h, h doubled from 64 until the Parseval tail
    ///    beyond it, (Var f − Σ_box ∫|φ_k|²)·L/(N − 1) for L plane waves and
    ///    |p − 1| ≤ 1 beyond the box, is at most 2/3 of the budget, and for
    ///    exact (x, y) halves the axes out to 4N (stratified samplers keep
    ///    their 1D structure there, p ≈ 0 far out);
    /// 2. the terms with the smallest bounds |p − 1|·(Σ_t|A_t|)²·2/(N − 1)
    ///    dropped while their sum stays within the remaining third;
    /// 3. the [`COARSE_TERMS`] kept terms with the largest bounds make the
    ///    coarse set.
    fn choose_terms(
        &mut self,
        light: &dyn LightField,
        xy_half: &dyn Sampler,
        starts: &[[f64; 2]],
        target: f64,
    ) -> Result<(), OptimizeError> {
        let n = self.n as f64;
        let exact_xy = xy_half.pair_spectrum();
        let points = self.n;
        let axes = |h: usize| exact_xy.map(|_| (4 * points).max(h));
        let first_half = match self.xy {
            XyPower::Exact => 64,
            XyPower::Empirical { freqs, .. } => freqs.half,
        };
        self.full = self.term_set(light, exact_xy, &half_plane(first_half, axes(first_half)))?;
        self.half = first_half;
        let reference = starts
            .iter()
            .map(|&s| self.value(s[0], s[1]))
            .fold(f64::INFINITY, f64::min)
            .max(f64::MIN_POSITIVE);
        let budget = target * reference;
        let mut waves_per_k = 1.0f64;
        let mut half = first_half;
        let tail = loop {
            let frequencies = half_plane(half, axes(half));
            let (energy, waves) = frequencies
                .par_iter()
                .map_init(Vec::new, |buffer, &k| {
                    buffer.clear();
                    light.plane_waves(k, buffer);
                    (2.0 * light_field_energy(buffer), buffer.len())
                })
                .fold(
                    || (NeumaierSum::default(), 0usize),
                    |(mut s, w), (e, l)| {
                        s.add(e);
                        (s, w.max(l))
                    },
                )
                .collect::<Vec<_>>()
                .into_iter()
                .fold((NeumaierSum::default(), 0usize), |(mut s, w), (t, l)| {
                    s.merge(t);
                    (s, w.max(l))
                });
            waves_per_k = waves_per_k.max(waves as f64);
            let tail = (self.variance - energy.value()).max(0.0) * waves_per_k / (n - 1.0);
            let grow = matches!(self.xy, XyPower::Exact) && 2 * half <= MAX_HALF;
            if tail > (2.0 / 3.0) * budget && grow {
                half *= 2;
            } else {
                break tail;
            }
        };
        let frequencies = half_plane(half, axes(half));
        // Bounds of every candidate, then the smallest dropped within budget.
        let bounds: Vec<f64> = frequencies
            .par_iter()
            .map_init(Vec::new, |buffer, &k| {
                buffer.clear();
                light.plane_waves(k, buffer);
                let p = self.xy_power(exact_xy, k);
                let amplitude: f64 = buffer.iter().map(|w| w.amplitude.norm()).sum();
                (p - 1.0).abs() * amplitude * amplitude * 2.0 / (n - 1.0)
            })
            .collect();
        let mut order: Vec<usize> = (0..frequencies.len()).collect();
        order.sort_by(|&i, &j| bounds[i].total_cmp(&bounds[j]).then(i.cmp(&j)));
        // At the largest box the tail may exceed its share: the dropped
        // terms still get a third of the budget.
        let allowance = (budget - tail).max(budget / 3.0);
        let mut dropped = 0.0;
        let mut keep = vec![true; frequencies.len()];
        for &i in &order {
            if dropped + bounds[i] > allowance {
                break;
            }
            dropped += bounds[i];
            keep[i] = false;
        }
        let kept: Vec<[i64; 2]> = frequencies
            .iter()
            .zip(&keep)
            .filter(|(_, k)| **k)
            .map(|(f, _)| *f)
            .collect();
        let coarse: Vec<[i64; 2]> = order
            .iter()
            .rev()
            .filter(|&&i| keep[i])
            .take(COARSE_TERMS)
            .map(|&i| frequencies[i])
            .collect();
        self.full = self.term_set(light, exact_xy, &kept)?;
        self.coarse = self.term_set(light, exact_xy, &coarse)?;
        self.half = half;
        self.truncation_bound = tail + dropped;
        Ok(())
    }

    /// E[N·P_S(k)] of the (x, y) half.
    fn xy_power(&self, exact: Option<&dyn PairSpectrum>, k: [i64; 2]) -> f64 {
        match (&self.xy, exact) {
            (XyPower::Exact, Some(s)) => s.power([k[0] as f64, k[1] as f64]),
            (XyPower::Empirical { freqs, power, .. }, _) => power[box_index(freqs, k)],
            (XyPower::Exact, None) => unreachable!("exact halves have a closed form"),
        }
    }

    /// The terms of the frequencies `ks` (of the half-plane k_x ≥ 0), in
    /// the order of (k_x, k_y).
    fn term_set(
        &self,
        light: &dyn LightField,
        exact: Option<&dyn PairSpectrum>,
        ks: &[[i64; 2]],
    ) -> Result<TermSet, OptimizeError> {
        let mut ks = ks.to_vec();
        ks.sort_unstable();
        let n = self.n as f64;
        let scale = 2.0 / (n * n * (n - 1.0));
        let terms: Vec<Term> = ks
            .par_iter()
            .map(|&k| {
                let mut waves = Vec::new();
                light.plane_waves(k, &mut waves);
                let box_index = match &self.xy {
                    XyPower::Empirical { freqs, .. } => Some(box_index(freqs, k)),
                    XyPower::Exact => None,
                };
                Term {
                    waves,
                    k: [k[0] as f64, k[1] as f64],
                    coefficient: (self.xy_power(exact, k) - 1.0) * scale,
                    box_index,
                }
            })
            .collect();
        let amplitudes = terms
            .iter()
            .flat_map(|t| t.waves.iter().map(|w| w.amplitude))
            .collect();
        let mut set = TermSet {
            terms,
            layer_sums: LayerSums::new(
                &ks,
                amplitudes,
                light.wave_slopes(),
                SumMethod::Auto { points: self.n },
            )?,
            weighted_diagonal: Vec::new(),
            mean_diagonal: Vec::new(),
        };
        if let UvPairs::Empirical(uv) = &self.uv {
            let (weighted, total) = sum_over_sets(
                &set,
                &uv.sets,
                |q, scratch, d| set.layer_sums.diagonals(q, scratch, d),
                |_, d| crate::sum::sum(set.terms.iter().zip(d).map(|(t, d)| t.coefficient * d)),
            );
            let r = uv.sets.len() as f64;
            set.weighted_diagonal = weighted;
            set.mean_diagonal = total.iter().map(|t| t / r).collect();
        }
        Ok(set)
    }

    /// J(a, b).
    pub fn value(&self, a: f64, b: f64) -> f64 {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        self.value_on(&self.full, [a, b])
    }

    /// J(a, b) summed over the coarse set only: the [`COARSE_TERMS`]
    /// frequencies with the largest bounds (for the spectra of apertures,
    /// the low ones, which vary slowest with the shear). Not J (the other
    /// terms are left out, without a bound); the search only uses it to
    /// locate basins, which J then compares and refines, and it costs a
    /// fraction of J at large N.
    pub fn coarse_value(&self, a: f64, b: f64) -> f64 {
        self.coarse_evaluations.fetch_add(1, Ordering::Relaxed);
        self.value_on(&self.coarse, [a, b])
    }

    /// The sum of J over the terms of `set`.
    fn value_on(&self, set: &TermSet, [a, b]: [f64; 2]) -> f64 {
        let base = self.variance / self.n as f64;
        let uv = match &self.uv {
            UvPairs::Empirical(uv) => {
                return base + mean(&self.per_realization(set, uv, [a, b]));
            }
            UvPairs::Exact(uv) => *uv,
        };
        let partial: Vec<NeumaierSum> = set
            .terms
            .par_chunks(CHUNK)
            .map(|chunk| {
                let mut s = NeumaierSum::default();
                for t in chunk {
                    s.add(t.coefficient * uv.wave_pair_sum(&t.waves, [a * t.k[0], b * t.k[1]]));
                }
                s
            })
            .collect();
        let mut total = NeumaierSum::default();
        total.add(base);
        for p in partial {
            total.merge(p);
        }
        total.value()
    }

    /// J − Var f/N on each realization of the (u, v) half (the (x, y) half
    /// at its mean), computed per realization so the result is the same
    /// for any number of threads.
    fn per_realization(&self, terms: &TermSet, uv: &UvRealizations, shear: [f64; 2]) -> Vec<f64> {
        let items: Vec<(&PointSet, f64)> = uv
            .sets
            .iter()
            .zip(terms.weighted_diagonal.iter().copied())
            .collect();
        terms
            .layer_sums
            .map_items(&items, |&(set, diagonal), scratch| {
                let mut sums = vec![0.0; terms.terms.len()];
                terms.layer_sums.power_sums(set, shear, scratch, &mut sums);
                realization_part(terms, &sums, diagonal)
            })
    }

    /// [`Self::per_realization`] of the full J and, from the same power
    /// sums (one pass over the realizations, not two), the mean over the
    /// (u, v) realizations of each term's pair sum, which an estimated
    /// (x, y) half weighs.
    fn per_realization_and_mean_pair_sums(
        &self,
        uv: &UvRealizations,
        shear: [f64; 2],
    ) -> (Vec<f64>, Vec<f64>) {
        let full = &self.full;
        let (per_set, total) = sum_over_sets(
            full,
            &uv.sets,
            |set, scratch, sums| full.layer_sums.power_sums(set, shear, scratch, sums),
            |i, sums| realization_part(full, sums, full.weighted_diagonal[i]),
        );
        let r = uv.sets.len() as f64;
        let mean = total
            .iter()
            .zip(&full.mean_diagonal)
            .map(|(t, d)| t / r - d)
            .collect();
        (per_set, mean)
    }

    /// J at `shear` with its standard error: for an estimated half, the
    /// spread of J over its realizations (the other half at its mean), the
    /// two halves' variances added.
    ///
    /// # Errors
    /// Sampler errors while redrawing an estimated (x, y) half.
    pub fn evaluate(&self, shear: [f64; 2]) -> Result<Evaluation, OptimizeError> {
        let (value, [xy, uv]) = self.evaluate_parts(shear)?;
        Ok(Evaluation {
            value,
            stderr: (xy + uv).sqrt(),
        })
    }

    /// J at `shear` and the variances of its estimate from the (x, y) and
    /// the (u, v) half (0 for an exact half).
    fn evaluate_parts(&self, [a, b]: [f64; 2]) -> Result<(f64, [f64; 2]), OptimizeError> {
        let base = self.variance / self.n as f64;
        let mut variances = [0.0; 2];
        let xy_estimated = matches!(self.xy, XyPower::Empirical { .. });
        let mut uv_mean_sums = None;
        let value = match &self.uv {
            UvPairs::Empirical(uv) => {
                self.evaluations.fetch_add(1, Ordering::Relaxed);
                let per_set = if xy_estimated {
                    let (per_set, mean_sums) = self.per_realization_and_mean_pair_sums(uv, [a, b]);
                    uv_mean_sums = Some(mean_sums);
                    per_set
                } else {
                    self.per_realization(&self.full, uv, [a, b])
                };
                variances[1] = sample_variance(&per_set) / per_set.len() as f64;
                base + mean(&per_set)
            }
            UvPairs::Exact(_) => self.value(a, b),
        };
        if let XyPower::Empirical { freqs, sets, .. } = &self.xy {
            let n = self.n as f64;
            let scale = 2.0 / (n * n * (n - 1.0));
            let uv_sums: Vec<f64> = match (&self.uv, uv_mean_sums) {
                (_, Some(mean_sums)) => mean_sums,
                (UvPairs::Empirical(_), None) => unreachable!("computed with J above"),
                (UvPairs::Exact(uv), None) => self
                    .full
                    .terms
                    .iter()
                    .map(|t| uv.wave_pair_sum(&t.waves, [a * t.k[0], b * t.k[1]]))
                    .collect(),
            };
            let uv_part: Vec<(usize, f64)> = self
                .full
                .terms
                .iter()
                .zip(uv_sums)
                .map(|(t, sum)| {
                    let index = t.box_index.expect("empirical terms index the box");
                    (index, scale * sum)
                })
                .collect();
            let seed = self.seed ^ XY_STREAM;
            let [xy_half, _] = self.sampler.halves().expect("checked at construction");
            let statistic = |power: &[f64]| {
                let mut s = NeumaierSum::default();
                s.add(base);
                for &(i, x) in &uv_part {
                    s.add((power[i] - 1.0) * x);
                }
                s.value()
            };
            let (_, per_set) = expected_power_with(
                *freqs,
                Method::Fast { tolerance: 1e-10 },
                *sets,
                |r| {
                    xy_half
                        .sample(&mut set_rng(seed, r as u64))
                        .map_err(OptimizeError::from)
                },
                &statistic,
                &|| {},
            )?;
            variances[0] = sample_variance(&per_set) / per_set.len() as f64;
        }
        Ok((value, variances))
    }

    /// Bound on the error of J from the frequencies left out (assuming
    /// |E[N·P_S] − 1| ≤ 1 beyond the box for the (x, y) half).
    pub fn truncation_bound(&self) -> f64 {
        self.truncation_bound
    }

    /// Frequencies k (of the half-plane, each standing for ±k) in the sum.
    pub fn terms(&self) -> usize {
        self.full.terms.len()
    }

    /// Frequencies in the coarse J ([`ShearObjective::coarse_value`]).
    pub fn coarse_terms(&self) -> usize {
        self.coarse.terms.len()
    }

    /// Box half-width h of the sum.
    pub fn half(&self) -> usize {
        self.half
    }

    /// Realizations behind each estimated half (0 when exact): (x, y), (u, v).
    pub fn realizations(&self) -> [usize; 2] {
        let xy = match &self.xy {
            XyPower::Exact => 0,
            XyPower::Empirical { sets, .. } => *sets,
        };
        let uv = match &self.uv {
            UvPairs::Exact(_) => 0,
            UvPairs::Empirical(uv) => uv.sets.len(),
        };
        [xy, uv]
    }

    /// Evaluations of J so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations.load(Ordering::Relaxed)
    }

    /// Evaluations of the coarse J ([`ShearObjective::coarse_value`]) so far.
    pub fn coarse_evaluations(&self) -> u64 {
        self.coarse_evaluations.load(Ordering::Relaxed)
    }
}

/// Frequencies of the half-plane (k_x > 0, or k_x = 0 and k_y > 0) in the
/// box |k|∞ ≤ `half`, plus the axes out to `axes` when given.
fn half_plane(half: usize, axes: Option<usize>) -> Vec<[i64; 2]> {
    let h = half as i64;
    let mut out = Vec::with_capacity((2 * half + 1) * (half + 1));
    for kx in 0..=h {
        for ky in -h..=h {
            if kx > 0 || ky > 0 {
                out.push([kx, ky]);
            }
        }
    }
    if let Some(axes) = axes {
        for k in h + 1..=axes as i64 {
            out.push([k, 0]);
            out.push([0, k]);
        }
    }
    out
}

/// Index of k in a 2D box (k_x fastest).
fn box_index(freqs: &FrequencyBox, k: [i64; 2]) -> usize {
    let side = freqs.side() as i64;
    let h = freqs.half as i64;
    ((k[1] + h) * side + k[0] + h) as usize
}

/// J − Var f/N on one (u, v) realization from its power sums `sums` of
/// the terms and its weighted diagonal.
fn realization_part(terms: &TermSet, sums: &[f64], diagonal: f64) -> f64 {
    let power = terms.terms.iter().zip(sums).map(|(t, p)| t.coefficient * p);
    crate::sum::sum(power.chain([-diagonal]))
}

/// The per-term vectors `fill` writes for each of `sets`, summed over
/// the sets, and `scalar(index, vector)` of each set, in fixed chunks of
/// [`CHUNK`] sets (memory: chunks × terms, not sets × terms; the same
/// sums for any number of threads), the chunks run as the terms' layer
/// sums run items ([`LayerSums::map_items`]).
fn sum_over_sets(
    terms: &TermSet,
    sets: &[PointSet],
    fill: impl Fn(&PointSet, &mut Scratch, &mut [f64]) + Sync,
    scalar: impl Fn(usize, &[f64]) -> f64 + Sync,
) -> (Vec<f64>, Vec<f64>) {
    let len = terms.terms.len();
    let chunks: Vec<(usize, &[PointSet])> = sets.chunks(CHUNK).enumerate().collect();
    let partial = terms.layer_sums.map_items(&chunks, |&(c, chunk), scratch| {
        let mut v = vec![0.0; len];
        let mut total = vec![0.0; len];
        let mut scalars = Vec::with_capacity(chunk.len());
        for (j, set) in chunk.iter().enumerate() {
            fill(set, scratch, &mut v);
            scalars.push(scalar(c * CHUNK + j, &v));
            for (t, x) in total.iter_mut().zip(&v) {
                *t += x;
            }
        }
        (scalars, total)
    });
    let scalars = partial
        .iter()
        .flat_map(|(s, _)| s.iter().copied())
        .collect();
    let total = (0..len)
        .map(|i| crate::sum::sum(partial.iter().map(|(_, t)| t[i])))
        .collect();
    (scalars, total)
}

/// Realizations 0..count of `sampler` from `seed` ([`generate_sets`]),
/// refused first, naming the objective, when they would not fit in memory
/// (up to 4096 realizations of N points: 268 MB at N = 4096); the count is
/// the objective's, not `--sets`, which generate_sets' own refusal names.
fn draw(sampler: &dyn Sampler, seed: u64, count: usize) -> Result<Vec<PointSet>, OptimizeError> {
    crate::memory::check(
        &format!(
            "the shear objective's {count} realizations of the estimated half ({} points)",
            sampler.points_per_set()
        ),
        Some(sets_bytes(sampler, count)),
        "lower -n",
    )?;
    Ok(generate_sets(sampler, seed, count, &|_| {})?)
}
