//! Pair sums of a (u, v) set for a light field of sheared layers, by powers
//! of one phasor per point or by a NUFFT of the scaled points.
//!
//! For frequency k of the (x, y) half and shear σ = (a·k_x, b·k_y), the
//! shear objective needs, on each realization Q = {q_l} of the (u, v) half,
//!
//!   Σ_(l≠m) ψ_k(q_l)·conj(ψ_k(q_m)) = |Σ_l ψ_k(q_l)|² − Σ_l |ψ_k(q_l)|²,
//!   ψ_k(q) = Σ_t A_t(k)·e^(2πi (s_t ⊙ k + σ)·q)
//!
//! ([`crate::integrands::LightField`]: wave t of a layer stack has the
//! frequency s_t ⊙ k). The phase (s_t,x + a)·k_x·u + (s_t,y + b)·k_y·v is
//! linear in k, so with E = e^(2πi (s_t,x + a)·u) and F = e^(2πi (s_t,y + b)·v)
//! each term is E^(k_x)·F^(k_y): one sine and cosine per point and axis,
//! then complex products, where a direct sum evaluates a sine and cosine per
//! point, wave and frequency. The powers come from repeated products, whose
//! phase error grows as k·ε (≤ 2.3e-13 at k = 1024): the order of the
//! rounding of the phase k·ω·q a direct sum would reduce. The diagonal
//! Σ_l |ψ_k(q_l)|² does not depend on σ: N·Σ_t|A_t|² plus the cross terms
//! of the waves, powers of the slope differences s_t − s_t′.
//!
//! Where the terms fill much of a box |k|∞ ≤ H and N is large (N = 4096:
//! 155,864 terms of |k|∞ ≤ 1024), one type-1 NUFFT per wave of the scaled
//! points (frac(w_x·u_l), frac(w_y·v_l)) gives every S(k) of the box at
//! once (k is an integer, so e^(2πi k·w·u) = e^(2πi k·frac(w·u))), with
//! |ΔS(k)| ≤ ε·N at tolerance ε ([`TRANSFORM_TOLERANCE`]); the terms
//! outside the box (the axes beyond H) keep the powers. A cost model of
//! sizes chooses, so the sums are the same for any thread count — except
//! where the NUFFT's memory budget (which counts a pair of grids per
//! thread against the memory free) refuses the grids: the powers then sum
//! every term, and the sums differ in their last ~10 digits.

use rayon::prelude::*;
use rustfft::num_complex::Complex64;

use crate::integrands::LightField;
use crate::points::{PointSet, wrap01};
use crate::spectrum::nufft::{NufftPlan, NufftScratch, Sign, Upsampling};
use crate::spectrum::phase::{reduced_product, turn};
use crate::spectrum::{FrequencyBox, SpectrumError};

/// Relative tolerance ε of the box transform: |ΔS(k)| ≤ ε·N (Barnett,
/// Magland & af Klinteberg 2019, §3), where the pair sums J needs are of
/// order N² at the shear that matters and 1e-2 of J is the target.
pub const TRANSFORM_TOLERANCE: f64 = 1e-9;
/// The cost model that chooses between the two, in nanoseconds on two
/// cores (`varspec bench shear` and the search at N = 4096, |k|∞ ≤ 1024):
/// a dot product costs [`DOT_NS`] per term and point; a transform
/// [`SPREAD_NS`] per point and kernel weight (w² in 2D), [`FFT_NS`] per
/// grid cell·log2(cells), and [`TRANSFORM_OVERHEAD_NS`] per call.
const DOT_NS: f64 = 0.4;
/// See [`DOT_NS`].
const SPREAD_NS: f64 = 0.5;
/// See [`DOT_NS`].
const FFT_NS: f64 = 0.53;
/// See [`DOT_NS`].
const TRANSFORM_OVERHEAD_NS: f64 = 3e5;

/// How the sums of the terms in the box are taken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SumMethod {
    /// Powers of one phasor per point and axis, one dot product per term.
    Powers,
    /// One type-1 NUFFT per wave at this tolerance for the terms in the box
    /// of the off-axis terms, powers for the rest.
    Transform {
        /// Relative tolerance ε (|ΔS(k)| ≤ ε·N).
        tolerance: f64,
    },
    /// The transform at [`TRANSFORM_TOLERANCE`] where the cost model says
    /// it is cheaper for sets of `points` points, else powers. (Where the
    /// memory budget refuses the transform's grids, powers too: the sums
    /// then differ in the last ~10 digits, far inside J's truncation
    /// bound.)
    Auto {
        /// Points per (u, v) set.
        points: usize,
    },
}

/// The terms summed by a type-1 NUFFT on a box.
struct BoxTransform {
    plan: NufftPlan,
    /// (position in the term list, index in the box) of each term in it.
    terms: Vec<(usize, usize)>,
}

/// One run of frequencies (k_x, k_y0 + j), j < len, at positions
/// first + j of the term list; `e_row` and `f_row` are the table rows of
/// k_x and k_y0 (the rows of consecutive k_y are consecutive).
#[derive(Debug, Clone, Copy)]
struct Run {
    e_row: usize,
    f_row: usize,
    len: usize,
    first: usize,
}

/// The terms of a sheared layer stack: frequencies of the half-plane
/// k_x ≥ 0 (those the powers sum in runs of consecutive k_y, the rest in a
/// transform's box), the waves' slopes and amplitudes.
#[derive(Default)]
pub struct LayerSums {
    runs: Vec<Run>,
    /// The table row of E^(k_x), for the k_x in use.
    e_rows: Vec<Option<usize>>,
    /// The table row of F^(k_y) at k_y + ky_max, for the k_y in use (in
    /// the order of k_y).
    f_rows: Vec<Option<usize>>,
    terms: usize,
    slopes: Vec<[f64; 2]>,
    /// A_t(k), term-major (one per slope).
    amplitudes: Vec<Complex64>,
    /// The terms in a box, when a transform sums them (the runs hold the
    /// rest).
    transform: Option<BoxTransform>,
    /// The buffers a transform uses (its grids: 250 MB at N = 4096), kept
    /// from one call to the next rather than allocated for each.
    kept: std::sync::Mutex<Scratch>,
}

/// Buffers of one thread.
#[derive(Default)]
pub(super) struct Scratch {
    powers: PowerRows,
    tables: Tables,
    /// Σ_l of each wave's phasor, per term: re then im, wave-major.
    re: Vec<f64>,
    im: Vec<f64>,
    /// The transform's grids and box of sums.
    transform: Option<(NufftScratch, Vec<Complex64>)>,
}

impl Scratch {
    /// Zeroed sums for `len` terms.
    fn clear(&mut self, len: usize) {
        self.re.clear();
        self.re.resize(len, 0.0);
        self.im.clear();
        self.im.resize(len, 0.0);
    }
}

/// Numbers the slots that are `Some` in order.
fn number_rows(rows: &mut [Option<usize>]) -> usize {
    let mut count = 0;
    for r in rows.iter_mut().flatten() {
        *r = count;
        count += 1;
    }
    count
}

impl LayerSums {
    /// `ks` in the order of (k_x, k_y), each with k_x ≥ 0, and the
    /// amplitudes of its waves (one per slope), summed by `method`.
    ///
    /// # Errors
    /// The NUFFT's refusal of a transform the method asks for or the cost
    /// model picks (a tolerance outside [1e-14, 0.1], grids past the memory
    /// budget).
    ///
    /// # Panics
    /// If `ks` is not sorted with k_x ≥ 0 or the amplitudes are not one per
    /// slope and frequency (callers build both from one light field).
    pub(super) fn new(
        ks: &[[i64; 2]],
        amplitudes: Vec<Complex64>,
        slopes: Vec<[f64; 2]>,
        method: SumMethod,
    ) -> Result<Self, SpectrumError> {
        assert!(
            ks.windows(2).all(|w| w[0] < w[1]) && ks.iter().all(|k| k[0] >= 0),
            "layer sums need distinct frequencies sorted by (k_x, k_y) with k_x >= 0"
        );
        assert_eq!(
            amplitudes.len(),
            ks.len() * slopes.len(),
            "one amplitude per wave"
        );
        let transform = box_transform(ks, method)?;
        let by_powers: Vec<usize> = match &transform {
            Some(t) => {
                let mut in_box = vec![false; ks.len()];
                for &(i, _) in &t.terms {
                    in_box[i] = true;
                }
                (0..ks.len()).filter(|&i| !in_box[i]).collect()
            }
            None => (0..ks.len()).collect(),
        };
        let kx_max = by_powers.iter().map(|&i| ks[i][0]).max().unwrap_or(0);
        let ky_max = by_powers.iter().map(|&i| ks[i][1].abs()).max().unwrap_or(0);
        let mut e_rows = vec![None; kx_max as usize + 1];
        let mut f_rows = vec![None; 2 * ky_max as usize + 1];
        for &i in &by_powers {
            e_rows[ks[i][0] as usize] = Some(0);
            f_rows[(ks[i][1] + ky_max) as usize] = Some(0);
        }
        number_rows(&mut e_rows);
        number_rows(&mut f_rows);
        let mut runs: Vec<Run> = Vec::new();
        for (j, &i) in by_powers.iter().enumerate() {
            let k = ks[i];
            let extends = j > 0 && {
                let p = by_powers[j - 1];
                p + 1 == i && ks[p][0] == k[0] && ks[p][1] + 1 == k[1]
            };
            match runs.last_mut() {
                Some(r) if extends => r.len += 1,
                _ => runs.push(Run {
                    e_row: e_rows[k[0] as usize].expect("k_x is in use"),
                    f_row: f_rows[(k[1] + ky_max) as usize].expect("k_y is in use"),
                    len: 1,
                    first: i,
                }),
            }
        }
        Ok(LayerSums {
            runs,
            e_rows,
            f_rows,
            terms: ks.len(),
            slopes,
            amplitudes,
            transform,
            kept: std::sync::Mutex::default(),
        })
    }

    /// The terms of light field `light` at the frequencies `ks` (k_x ≥ 0,
    /// sorted by (k_x, k_y)), summed by `method`.
    ///
    /// # Errors
    /// As [`LayerSums::new`].
    ///
    /// # Panics
    /// If `ks` is not sorted with k_x ≥ 0.
    pub fn for_light_field(
        light: &dyn LightField,
        ks: &[[i64; 2]],
        method: SumMethod,
    ) -> Result<Self, SpectrumError> {
        let mut amplitudes = Vec::new();
        for &k in ks {
            light.wave_amplitudes(k, &mut amplitudes);
        }
        Self::new(ks, amplitudes, light.wave_slopes(), method)
    }

    /// Whether a transform sums terms: it runs in parallel itself, and its
    /// grids are large, so callers take the sets one at a time.
    pub fn transforms(&self) -> bool {
        self.transform.is_some()
    }

    /// `each` of every one of `items` with buffers, in the items' order:
    /// one at a time on the buffers kept between calls when a transform
    /// sums terms (it runs in parallel itself, on grids too large to hold
    /// one per task), else in parallel with buffers per task. The same
    /// results for any number of threads.
    pub(super) fn map_items<I: Sync, T: Send>(
        &self,
        items: &[I],
        each: impl Fn(&I, &mut Scratch) -> T + Sync,
    ) -> Vec<T> {
        if self.transforms() {
            // A poisoned lock only means a panic elsewhere mid-call; the
            // buffers are overwritten before use.
            let mut kept = self
                .kept
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            return items.iter().map(|item| each(item, &mut kept)).collect();
        }
        items
            .par_iter()
            .map_init(Scratch::default, |scratch, item| each(item, scratch))
            .collect()
    }

    /// The pair sums Σ_(l≠m) ψ_k(q_l)·conj(ψ_k(q_m)) of every term on each
    /// (u, v) set of `sets` at shear `shear`.
    pub fn pair_sums(&self, sets: &[PointSet], shear: [f64; 2]) -> Vec<Vec<f64>> {
        self.map_items(sets, |set, scratch| {
            let mut power = vec![0.0; self.terms];
            self.power_sums(set, shear, scratch, &mut power);
            let mut diagonal = vec![0.0; self.terms];
            self.diagonals(set, scratch, &mut diagonal);
            power.iter().zip(&diagonal).map(|(p, d)| p - d).collect()
        })
    }

    /// Writes |Σ_l ψ_k(q_l)|² on the (u, v) set `set` at shear (a, b) to
    /// `out`, one per term.
    pub(super) fn power_sums(
        &self,
        set: &PointSet,
        [a, b]: [f64; 2],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) {
        let waves = self.slopes.len();
        let terms = self.terms;
        scratch.clear(waves * terms);
        for (t, s) in self.slopes.iter().enumerate() {
            self.add_phasor_sums(set, [s[0] + a, s[1] + b], scratch, t * terms);
        }
        for (i, o) in out.iter_mut().enumerate().take(terms) {
            let mut total = Complex64::new(0.0, 0.0);
            for (t, a) in self.amplitudes[i * waves..(i + 1) * waves]
                .iter()
                .enumerate()
            {
                total += a * Complex64::new(scratch.re[t * terms + i], scratch.im[t * terms + i]);
            }
            *o = total.norm_sqr();
        }
    }

    /// Writes the diagonal Σ_l |ψ_k(q_l)|² of the set `set` to `out`, one
    /// per term: N·Σ_t|A_t|² + 2·Re Σ_(t<t′) A_t·conj(A_t′)·Σ_l e^(2πi (s_t − s_t′)⊙k·q_l),
    /// the same at every shear.
    pub(super) fn diagonals(&self, set: &PointSet, scratch: &mut Scratch, out: &mut [f64]) {
        let waves = self.slopes.len();
        let terms = self.terms;
        let n = set.len() as f64;
        for (i, o) in out.iter_mut().enumerate().take(terms) {
            *o = n * self.amplitudes[i * waves..(i + 1) * waves]
                .iter()
                .map(|a| a.norm_sqr())
                .sum::<f64>();
        }
        for t in 0..waves {
            for t2 in t + 1..waves {
                let d = [
                    self.slopes[t][0] - self.slopes[t2][0],
                    self.slopes[t][1] - self.slopes[t2][1],
                ];
                scratch.clear(terms);
                self.add_phasor_sums(set, d, scratch, 0);
                for (i, o) in out.iter_mut().enumerate().take(terms) {
                    let cross = self.amplitudes[i * waves + t]
                        * self.amplitudes[i * waves + t2].conj()
                        * Complex64::new(scratch.re[i], scratch.im[i]);
                    *o += 2.0 * cross.re;
                }
            }
        }
    }

    /// Adds Σ_l e^(2πi (w_x·k_x·u_l + w_y·k_y·v_l)) for every term to the
    /// scratch sums from position `offset`: the terms in the transform's box
    /// (if any) from one type-1 NUFFT of the scaled points; the others per
    /// block of points (the whole set where its tables fit in
    /// [`TABLE_BYTES`]), the rows of E_l^(k_x) and F_l^(k_y) in use (points
    /// innermost), then one dot product per term.
    fn add_phasor_sums(&self, set: &PointSet, w: [f64; 2], scratch: &mut Scratch, offset: usize) {
        let Scratch {
            powers,
            tables,
            re,
            im,
            transform,
        } = scratch;
        let kx_max = self.e_rows.len() - 1;
        let ky_max = (self.f_rows.len() - 1) / 2;
        let re = &mut re[offset..offset + self.terms];
        let im = &mut im[offset..offset + self.terms];
        if let Some(t) = &self.transform {
            // A scratch made for another plan's box is made anew.
            if transform
                .as_ref()
                .is_some_and(|(_, out)| out.len() != t.plan.frequencies().len())
            {
                *transform = None;
            }
            let (grids, out) = transform.get_or_insert_with(|| {
                let zero = Complex64::new(0.0, 0.0);
                (
                    t.plan.make_scratch(),
                    vec![zero; t.plan.frequencies().len()],
                )
            });
            let coords = set
                .coords()
                .chunks_exact(2)
                .flat_map(|q| [wrap01(w[0] * q[0]), wrap01(w[1] * q[1])])
                .collect();
            let scaled = PointSet::new(2, coords).expect("wrapped coordinates lie in [0, 1)");
            t.plan.type1(&scaled, None, Sign::Positive, out, grids);
            for &(i, b) in &t.terms {
                re[i] += out[b].re;
                im[i] += out[b].im;
            }
            if self.runs.is_empty() {
                return;
            }
        }
        for block in set.coords().chunks(2 * self.points_per_block()) {
            let n = block.len() / 2;
            let rows = |table: &[Option<usize>]| table.iter().flatten().count() * n;
            let Tables {
                e_re,
                e_im,
                f_re,
                f_im,
            } = tables;
            e_re.resize(rows(&self.e_rows), 0.0);
            e_im.resize(rows(&self.e_rows), 0.0);
            f_re.resize(rows(&self.f_rows), 0.0);
            f_im.resize(rows(&self.f_rows), 0.0);
            powers.each(block, 0, w[0], kx_max, |k, pr, pi| {
                if let Some(row) = self.e_rows[k] {
                    e_re[row * n..(row + 1) * n].copy_from_slice(pr);
                    e_im[row * n..(row + 1) * n].copy_from_slice(pi);
                }
            });
            // F^(−k) is the conjugate of F^k.
            powers.each(block, 1, w[1], ky_max, |k, pr, pi| {
                if let Some(row) = self.f_rows[ky_max + k] {
                    f_re[row * n..(row + 1) * n].copy_from_slice(pr);
                    f_im[row * n..(row + 1) * n].copy_from_slice(pi);
                }
                if let Some(row) = self.f_rows[ky_max - k].filter(|_| k > 0) {
                    f_re[row * n..(row + 1) * n].copy_from_slice(pr);
                    for (o, v) in f_im[row * n..(row + 1) * n].iter_mut().zip(pi) {
                        *o = -v;
                    }
                }
            });
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the processor supports AVX2, checked just above.
                unsafe { self.add_dots_avx2(tables, n, re, im) };
                continue;
            }
            self.add_dots(tables, n, re, im);
        }
    }

    /// Points per block: as many as keep the tables within [`TABLE_BYTES`]
    /// (16 bytes per row and point), at least [`MIN_BLOCK`].
    fn points_per_block(&self) -> usize {
        let rows = self.e_rows.iter().chain(&self.f_rows).flatten().count();
        (TABLE_BYTES / (16 * rows.max(1))).max(MIN_BLOCK)
    }

    /// Adds E^(k_x)·F^(k_y) summed over the points to each term's sums.
    /// Compiled once more with AVX2 ([`Self::add_dots_avx2`]), which runs
    /// the same operations in the same order (Rust does not fuse a·b + c),
    /// so the bits do not depend on the processor.
    #[inline(always)]
    fn add_dots(&self, tables: &Tables, n: usize, re: &mut [f64], im: &mut [f64]) {
        for run in &self.runs {
            let er = &tables.e_re[run.e_row * n..(run.e_row + 1) * n];
            let ei = &tables.e_im[run.e_row * n..(run.e_row + 1) * n];
            for j in 0..run.len {
                let row = (run.f_row + j) * n;
                let (fr, fi) = (&tables.f_re[row..row + n], &tables.f_im[row..row + n]);
                let (sr, si) = dot(er, ei, fr, fi);
                re[run.first + j] += sr;
                im[run.first + j] += si;
            }
        }
    }

    /// [`Self::add_dots`] with AVX2 enabled (twice SSE2's vector width).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn add_dots_avx2(&self, tables: &Tables, n: usize, re: &mut [f64], im: &mut [f64]) {
        self.add_dots(tables, n, re, im);
    }
}

/// The transform for the terms of `ks` in the box of its off-axis terms,
/// when `method` asks for one (or the cost model prefers it).
fn box_transform(
    ks: &[[i64; 2]],
    method: SumMethod,
) -> Result<Option<BoxTransform>, SpectrumError> {
    let Some(half) = ks
        .iter()
        .filter(|k| k[0] != 0 && k[1] != 0)
        .map(|k| k[0].max(k[1].abs()))
        .max()
    else {
        return Ok(None);
    };
    let half = half as usize;
    let in_box = |k: &[i64; 2]| k[0].max(k[1].abs()) as usize <= half;
    let freqs = FrequencyBox { dim: 2, half };
    let (tolerance, points) = match method {
        SumMethod::Powers => return Ok(None),
        SumMethod::Transform { tolerance } => (tolerance, 0),
        // Dot products cheaper than a transform's overhead alone: no plan.
        SumMethod::Auto { points }
            if DOT_NS * (ks.len() * points) as f64 <= TRANSFORM_OVERHEAD_NS =>
        {
            return Ok(None);
        }
        SumMethod::Auto { points } => (TRANSFORM_TOLERANCE, points),
    };
    // A refusal (a tolerance out of range, grids past the memory budget) is
    // an error, not a quiet switch to the powers: the memory budget scales
    // with the threads, and the method must not (the sums differ by the
    // transform's tolerance).
    let plan = NufftPlan::with_upsampling(freqs, tolerance, Upsampling::Auto { points })?;
    let side = freqs.side();
    let terms: Vec<(usize, usize)> = ks
        .iter()
        .enumerate()
        .filter(|(_, k)| in_box(k))
        .map(|(i, k)| {
            let b = (k[1] + half as i64) as usize * side + (k[0] + half as i64) as usize;
            (i, b)
        })
        .collect();
    if let SumMethod::Auto { points } = method {
        let cells = (plan.grid_size() as f64).powi(2);
        let n = points as f64;
        let transform = SPREAD_NS * n * (plan.kernel_width() as f64).powi(2)
            + FFT_NS * cells * cells.log2()
            + TRANSFORM_OVERHEAD_NS;
        if DOT_NS * terms.len() as f64 * n <= transform {
            return Ok(None);
        }
    }
    Ok(Some(BoxTransform { plan, terms }))
}

/// The tables' size per thread that sets the points per block: whole sets
/// where they fit (N = 256 with |k|∞ ≤ 1024: 12.6 MB), else blocks of at
/// least [`MIN_BLOCK`] points; with the axes out to 4N = 16384 (N = 4096)
/// whole tables would take gigabytes.
const TABLE_BYTES: usize = 16 << 20;
/// The fewest points per block (50 MB of tables at 49,154 rows), enough
/// for the dot products to amortize their per-term work.
const MIN_BLOCK: usize = 64;

/// The rows of E_l^(k_x) and of F_l^(k_y) in use over one block of points,
/// the points innermost.
#[derive(Default)]
struct Tables {
    e_re: Vec<f64>,
    e_im: Vec<f64>,
    f_re: Vec<f64>,
    f_im: Vec<f64>,
}

/// Rows of powers z_l^k over the points of a set.
#[derive(Default)]
struct PowerRows {
    re: Vec<f64>,
    im: Vec<f64>,
    step_re: Vec<f64>,
    step_im: Vec<f64>,
}

impl PowerRows {
    /// Calls `row(k, re, im)` with z_l^k over the 2D points l of `coords`,
    /// for k = 0..=max, z_l = e^(2πi w·q_l[axis]), by the recurrence
    /// z^k = z^(k−1)·z (the points innermost, so it vectorizes). Its phase
    /// error grows as k·ε (≤ 2.3e-13 at k = 1024): the order of the
    /// rounding of the phase k·w·q that a direct evaluation would reduce.
    fn each(
        &mut self,
        coords: &[f64],
        axis: usize,
        w: f64,
        max: usize,
        mut row: impl FnMut(usize, &[f64], &[f64]),
    ) {
        let n = coords.len() / 2;
        self.step_re.clear();
        self.step_im.clear();
        for q in coords.chunks_exact(2) {
            let z = turn(reduced_product(w, q[axis]));
            self.step_re.push(z.re);
            self.step_im.push(z.im);
        }
        self.re.clear();
        self.re.resize(n, 1.0);
        self.im.clear();
        self.im.resize(n, 0.0);
        row(0, &self.re, &self.im);
        for k in 1..=max {
            let steps = self.step_re.iter().zip(&self.step_im);
            for ((r, i), (sr, si)) in self.re.iter_mut().zip(self.im.iter_mut()).zip(steps) {
                let (a, b) = (*r, *i);
                *r = a * sr - b * si;
                *i = a * si + b * sr;
            }
            row(k, &self.re, &self.im);
        }
    }
}

/// Σ_l (er_l + i·ei_l)·(fr_l + i·fi_l), in interleaved partial sums.
#[inline(always)]
fn dot(er: &[f64], ei: &[f64], fr: &[f64], fi: &[f64]) -> (f64, f64) {
    const LANES: usize = 4;
    fn lanes(v: &[f64]) -> impl Iterator<Item = [f64; LANES]> + '_ {
        v.chunks_exact(LANES)
            .map(|c| <[f64; LANES]>::try_from(c).expect("chunks_exact yields full chunks"))
    }
    let mut sr = [0.0; LANES];
    let mut si = [0.0; LANES];
    for (((a, b), x), y) in lanes(er).zip(lanes(ei)).zip(lanes(fr)).zip(lanes(fi)) {
        for j in 0..LANES {
            sr[j] += a[j] * x[j] - b[j] * y[j];
            si[j] += a[j] * y[j] + b[j] * x[j];
        }
    }
    let mut r = sr.iter().sum::<f64>();
    let mut i = si.iter().sum::<f64>();
    let split = er.len() - er.len() % LANES;
    for l in split..er.len() {
        r += er[l] * fr[l] - ei[l] * fi[l];
        i += er[l] * fi[l] + ei[l] * fr[l];
    }
    (r, i)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::{set_rng, uniform};
    use crate::spectrum::pair::{EmpiricalPairs, PlaneWave};

    /// The table equals the direct sum (one sine and cosine per point, wave
    /// and frequency) of `EmpiricalPairs`, including frequencies out to
    /// 6000 on the axes, where the powers' rounding is largest and the
    /// points are summed in blocks.
    #[test]
    fn layer_sums_equal_direct_sums() {
        let mut rng = set_rng(7, 0);
        let coords: Vec<f64> = (0..2 * 97).map(|_| uniform(&mut rng)).collect();
        let set = PointSet::new(2, coords).unwrap();
        let slopes = vec![[0.5, 0.5], [-0.2, -0.2], [0.83, -1.7]];
        let mut ks: Vec<[i64; 2]> = Vec::new();
        for kx in 0..=9i64 {
            for ky in -9..=9i64 {
                // Holes split the runs.
                if (kx > 0 || ky > 0) && (kx + ky) % 5 != 0 {
                    ks.push([kx, ky]);
                }
            }
        }
        ks.extend([[0, 1024], [300, 0], [1024, 0]]);
        // Axes out to 6000 take the tables past TABLE_BYTES: the 97
        // points are summed in two blocks.
        ks.extend((1025..=6000).flat_map(|k| [[k, 0], [0, k], [0, -k]]));
        ks.sort();
        let amplitudes: Vec<Complex64> = (0..ks.len() * slopes.len())
            .map(|_| Complex64::new(uniform(&mut rng) - 0.5, uniform(&mut rng) - 0.5))
            .collect();
        let sums =
            LayerSums::new(&ks, amplitudes.clone(), slopes.clone(), SumMethod::Powers).unwrap();
        assert!(sums.points_per_block() < 97, "{}", sums.points_per_block());
        // The box |k|∞ ≤ 9 by a transform at 1e-12, the axes beyond by powers.
        let transformed = LayerSums::new(
            &ks,
            amplitudes.clone(),
            slopes.clone(),
            SumMethod::Transform { tolerance: 1e-12 },
        )
        .unwrap();
        assert!(transformed.transforms() && !sums.transforms());
        // A transform the NUFFT refuses is an error, never a quiet switch
        // to the powers (whose sums differ in the last bits).
        assert!(matches!(
            LayerSums::new(
                &ks,
                amplitudes.clone(),
                slopes.clone(),
                SumMethod::Transform { tolerance: 0.5 },
            ),
            Err(SpectrumError::Tolerance(_))
        ));
        let direct = EmpiricalPairs::new(vec![set.clone()]);
        let shear = [-0.37, 1.21];
        let mut scratch = Scratch::default();
        let mut power = vec![0.0; ks.len()];
        sums.power_sums(&set, shear, &mut scratch, &mut power);
        let mut diagonal = vec![0.0; ks.len()];
        sums.diagonals(&set, &mut scratch, &mut diagonal);
        let mut scratch = Scratch::default();
        let mut power_t = vec![0.0; ks.len()];
        transformed.power_sums(&set, shear, &mut scratch, &mut power_t);
        let mut diagonal_t = vec![0.0; ks.len()];
        transformed.diagonals(&set, &mut scratch, &mut diagonal_t);
        for (i, k) in ks.iter().enumerate() {
            let waves: Vec<PlaneWave> = slopes
                .iter()
                .enumerate()
                .map(|(t, s)| PlaneWave {
                    amplitude: amplitudes[i * slopes.len() + t],
                    frequency: [s[0] * k[0] as f64, s[1] * k[1] as f64],
                })
                .collect();
            let expected = direct.wave_pair_sum_of(
                0,
                &waves,
                [shear[0] * k[0] as f64, shear[1] * k[1] as f64],
            );
            let scale: f64 = waves
                .iter()
                .map(|w| w.amplitude.norm())
                .sum::<f64>()
                .powi(2)
                * 97.0;
            let ours = power[i] - diagonal[i];
            assert!(
                (ours - expected).abs() <= 1e-11 * scale,
                "k = {k:?}: table {ours} vs direct {expected}"
            );
            // |ΔS| ≤ ε·N per wave moves |Σ_t A_t S_t|² by at most
            // 2·ε·N·(Σ_t|A_t|)²·N (+ its square): 2e-12 of the scale, and
            // the diagonal's cross terms as much again.
            let transform = power_t[i] - diagonal_t[i];
            assert!(
                (transform - expected).abs() <= 1e-11 * scale,
                "k = {k:?}: transform {transform} vs direct {expected}"
            );
        }
    }

    /// The transform runs in parallel inside: its sums are the same bits
    /// on one thread and on three.
    #[test]
    fn transformed_sums_do_not_depend_on_the_thread_count() {
        let mut rng = set_rng(11, 0);
        // More points than one spreading task takes (4096).
        let coords: Vec<f64> = (0..2 * 10_000).map(|_| uniform(&mut rng)).collect();
        let set = PointSet::new(2, coords).unwrap();
        let slopes = vec![[0.45, 0.45], [-0.3, -0.3]];
        let ks: Vec<[i64; 2]> = (0..=40i64)
            .flat_map(|kx| (-40..=40i64).map(move |ky| [kx, ky]))
            .filter(|k| k[0] > 0 || k[1] > 0)
            .chain((41..=300).flat_map(|k| [[0, k], [k, 0]]))
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect();
        let amplitudes: Vec<Complex64> = (0..ks.len() * slopes.len())
            .map(|_| Complex64::new(uniform(&mut rng) - 0.5, uniform(&mut rng) - 0.5))
            .collect();
        let sums = LayerSums::new(
            &ks,
            amplitudes,
            slopes,
            SumMethod::Transform { tolerance: 1e-9 },
        )
        .unwrap();
        assert!(sums.transforms());
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| sums.pair_sums(std::slice::from_ref(&set), [0.2, -0.7]))
        };
        let one = on(1).remove(0);
        let three = on(3).remove(0);
        assert!(!one.is_empty() && one.len() == three.len());
        assert!(
            one.iter()
                .zip(&three)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "sums differ between one and three threads"
        );
    }
}
