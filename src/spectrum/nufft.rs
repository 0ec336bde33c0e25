//! Non-uniform fast Fourier transforms of type 1 and type 2 in d = 1…4
//! dimensions, one generic implementation.
//!
//! * Type 1 (points → modes): F(k) = Σ_j c_j e^(±2πi k·x_j) for k in a box.
//! * Type 2 (modes → points): c_j = Σ_k F(k) e^(±2πi k·x_j).
//!
//! Method (Dutt & Rokhlin 1993; kernel and parameters of Barnett, Magland &
//! af Klinteberg 2019, "A parallel non-uniform fast Fourier transform library
//! based on an exponential of semicircle kernel", SIAM J. Sci. Comput. 41(5)):
//! spread each point onto an oversampled periodic grid (σ = 2, n ≥ 2(2h+1))
//! with the "exponential of semicircle" kernel
//! ψ(u) = exp(β(√(1 − (2u/w)²) − 1)) of width w grid points, take a d-D FFT,
//! and divide each mode by the kernel's Fourier transform ψ̂(k/n) (type 2
//! runs the same steps backwards). With w = ⌈log10(1/ε)⌉ + 1 and β = 2.30·w
//! the relative error is about ε (BMK 2019, §3 and Eq. (3.2)): |ΔF(k)| ≲
//! ε·Σ_j |c_j|.
//!
//! A plan is a value (docs/architecture.md, "Conventions"): designed once for (d, h, ε), `Send +
//! Sync`, reused across realizations with caller-supplied scratch.

use std::sync::Arc;

use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use rustfft::{Fft, FftDirection, FftPlanner};

use super::{FrequencyBox, SpectrumError};
use crate::points::PointSet;

/// The sign of the exponent: e^(−2πi k·x) (`Negative`, the sample spectrum's)
/// or e^(+2πi k·x).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sign {
    /// e^(−2πi k·x).
    Negative,
    /// e^(+2πi k·x).
    Positive,
}

/// A designed transform for one frequency box and tolerance.
pub struct NufftPlan {
    freqs: FrequencyBox,
    tolerance: f64,
    /// Fine grid points per axis.
    grid: usize,
    /// Kernel width in grid points.
    width: usize,
    beta: f64,
    /// The kernel's w weights as polynomials of the grid offset, when they
    /// reach the tolerance (see [`KernelPolynomial`]).
    polynomial: Option<KernelPolynomial>,
    /// 1/ψ̂(k/n) for k = −h..=h.
    correction: Vec<f64>,
    /// Fine-grid index k mod n for k = −h..=h.
    mode_cells: Vec<usize>,
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
}

/// Working memory for one transform at a time (one per thread).
pub struct NufftScratch {
    grid: Vec<Complex64>,
    swap: Vec<Complex64>,
    /// Point indices in bin order, and the bins' counts.
    order: (Vec<usize>, Vec<usize>),
    /// One grid slab per row group (see [`NufftPlan::spread`]).
    slabs: Vec<Vec<Complex64>>,
}

impl NufftPlan {
    /// Designs the transform on the box `freqs` with relative tolerance
    /// `tolerance`.
    ///
    /// # Errors
    /// [`SpectrumError::Tolerance`] outside [1e-14, 0.1];
    /// [`SpectrumError::UnsupportedDimension`] outside d = 1..=4.
    pub fn new(freqs: FrequencyBox, tolerance: f64) -> Result<Self, SpectrumError> {
        if !(1..=4).contains(&freqs.dim) {
            return Err(SpectrumError::UnsupportedDimension(freqs.dim));
        }
        if !(1e-14..=0.1).contains(&tolerance) {
            return Err(SpectrumError::Tolerance(tolerance));
        }
        check_nufft_memory(&freqs)?;
        let (width, beta) = kernel_shape(tolerance);
        let grid = fine_grid_size(2 * freqs.side()).max(2 * width);
        let h = freqs.half as i64;
        let correction = (-h..=h)
            .map(|k| 1.0 / kernel_transform(k as f64 / grid as f64, width, beta))
            .collect();
        let mode_cells = (-h..=h)
            .map(|k| k.rem_euclid(grid as i64) as usize)
            .collect();
        let mut planner = FftPlanner::new();
        let forward = planner.plan_fft(grid, FftDirection::Forward);
        let inverse = planner.plan_fft(grid, FftDirection::Inverse);
        Ok(NufftPlan {
            freqs,
            tolerance,
            grid,
            width,
            beta,
            polynomial: KernelPolynomial::fit(width, beta, tolerance),
            correction,
            mode_cells,
            forward,
            inverse,
        })
    }

    /// The frequency box.
    pub fn frequencies(&self) -> &FrequencyBox {
        &self.freqs
    }

    /// The requested tolerance ε.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// Fine-grid points per axis.
    pub fn grid_size(&self) -> usize {
        self.grid
    }

    /// Kernel width in grid points.
    pub fn kernel_width(&self) -> usize {
        self.width
    }

    /// Complex numbers of scratch one transform needs (two fine grids).
    pub fn scratch_len(&self) -> usize {
        2 * self.grid.pow(self.freqs.dim as u32)
    }

    /// Fresh scratch for this plan.
    pub fn make_scratch(&self) -> NufftScratch {
        let cells = self.grid.pow(self.freqs.dim as u32);
        let zero = Complex64::new(0.0, 0.0);
        NufftScratch {
            grid: vec![zero; cells],
            swap: vec![zero; cells],
            order: (Vec::new(), Vec::new()),
            slabs: Vec::new(),
        }
    }

    /// Type 1: `out[k] = Σ_j c_j e^(±2πi k·x_j)` for every k of the box (box
    /// order), with strengths c_j = `strengths[j]`, or 1 when `None`.
    ///
    /// # Panics
    /// If dimensions or lengths disagree.
    pub fn type1(
        &self,
        points: &PointSet,
        strengths: Option<&[Complex64]>,
        sign: Sign,
        out: &mut [Complex64],
        scratch: &mut NufftScratch,
    ) {
        self.check(points, out.len());
        self.spread(points, strengths, scratch);
        self.fft(scratch, sign, Prune::Type1);
        let grid = &scratch.grid;
        self.for_each_mode_row(|row, base, corr| {
            let out_row = &mut out[row * self.freqs.side()..(row + 1) * self.freqs.side()];
            for ((o, &cell), &c) in out_row
                .iter_mut()
                .zip(&self.mode_cells)
                .zip(&self.correction)
            {
                *o = grid[base + cell] * (corr * c);
            }
        });
    }

    /// Type 2: `out[j] = Σ_k coeffs[k] e^(±2πi k·x_j)` for every point.
    ///
    /// # Panics
    /// If dimensions or lengths disagree.
    pub fn type2(
        &self,
        points: &PointSet,
        coeffs: &[Complex64],
        sign: Sign,
        out: &mut [Complex64],
        scratch: &mut NufftScratch,
    ) {
        self.check(points, coeffs.len());
        assert_eq!(out.len(), points.len(), "one output per point");
        scratch.grid.fill(Complex64::new(0.0, 0.0));
        let grid = &mut scratch.grid;
        self.for_each_mode_row(|row, base, corr| {
            let in_row = &coeffs[row * self.freqs.side()..(row + 1) * self.freqs.side()];
            for ((c, &cell), &k) in in_row.iter().zip(&self.mode_cells).zip(&self.correction) {
                grid[base + cell] = c * (corr * k);
            }
        });
        self.fft(scratch, sign, Prune::Type2);
        // Interpolation only reads the grid: points in bin order, in
        // parallel chunks, each value computed on its own.
        self.bin_order(points, &mut scratch.order);
        let (order, grid) = (&scratch.order.0, &scratch.grid);
        let values: Vec<Complex64> = order
            .par_chunks(POINTS_PER_TASK)
            .flat_map_iter(|chunk| {
                chunk.iter().map(|&j| {
                    let mut acc = Complex64::new(0.0, 0.0);
                    self.for_each_grid_neighbour(points.point(j), None, |cell, weight| {
                        acc += grid[cell] * weight
                    });
                    acc
                })
            })
            .collect();
        for (&j, v) in order.iter().zip(values) {
            out[j] = v;
        }
    }

    fn check(&self, points: &PointSet, modes: usize) {
        assert_eq!(
            points.dim(),
            self.freqs.dim,
            "points and plan differ in dimension"
        );
        assert_eq!(modes, self.freqs.len(), "one value per mode of the box");
    }

    /// Calls `f(row, base, corr)` for each row of the mode box (modes with
    /// fixed k_1..k_(d−1), k_0 running): `base` is the fine-grid offset of
    /// those k_1.. and `corr` their deconvolution factor Π 1/ψ̂; the row's
    /// k_0 = −h..h then sit at `base + mode_cells[k_0 + h]`.
    fn for_each_mode_row(&self, mut f: impl FnMut(usize, usize, f64)) {
        let (side, d, n) = (self.freqs.side(), self.freqs.dim, self.grid);
        for row in 0..side.pow(d as u32 - 1) {
            let (mut rest, mut base, mut corr, mut scale) = (row, 0, 1.0, n);
            for _ in 1..d {
                let i = rest % side;
                rest /= side;
                base += self.mode_cells[i] * scale;
                corr *= self.correction[i];
                scale *= n;
            }
            f(row, base, corr);
        }
    }

    /// Spreads the points (strength 1 or `strengths`) onto `scratch.grid`.
    ///
    /// Points are taken in bin order and split into groups of G rows of the
    /// last axis (G ≥ the kernel width, a multiple of the bin height); each
    /// group spreads into its own slab of G + 2⌈w/2⌉ rows in parallel, and
    /// each grid row then adds the slabs that cover it in group order. The
    /// groups depend on the grid and the kernel alone, so the sums, and the
    /// result, are identical for any thread count.
    fn spread(
        &self,
        points: &PointSet,
        strengths: Option<&[Complex64]>,
        scratch: &mut NufftScratch,
    ) {
        let (n, d, w) = (self.grid, self.freqs.dim, self.width);
        let one = Complex64::new(1.0, 0.0);
        let zero = Complex64::new(0.0, 0.0);
        self.bin_order(points, &mut scratch.order);
        let order = &scratch.order.0;
        let bin = BIN[d - 1];
        let rows = w.div_ceil(bin).max(1) * bin;
        let margin = w.div_ceil(2);
        let height = rows + 2 * margin;
        let groups = n.div_ceil(rows);
        let row_len = n.pow(d as u32 - 1);
        // Points `indices` onto `target`, whose last axis starts at row
        // `origin` (a slab) or wraps (the whole grid).
        let spread_into = |target: &mut [Complex64], indices: &[usize], origin: Option<i64>| {
            for &j in indices {
                let c = strengths.map_or(one, |s| s[j]);
                self.for_each_grid_neighbour(points.point(j), origin, |cell, weight| {
                    target[cell] += c * weight
                });
            }
        };
        if groups < 2 || height > n {
            // One group: spread straight into the (periodic) grid.
            scratch.grid.fill(zero);
            spread_into(&mut scratch.grid, order, None);
            return;
        }
        // The group of a point: its last coordinate's row over `rows`; bin
        // order sorts the last axis slowest, so groups are contiguous.
        let group_of = |j: usize| {
            let t = points.point(j)[d - 1] * n as f64;
            ((t as usize) / rows).min(groups - 1)
        };
        let starts: Vec<usize> = (0..=groups)
            .map(|g| order.partition_point(|&j| group_of(j) < g))
            .collect();
        scratch.slabs.resize_with(groups, Vec::new);
        scratch
            .slabs
            .par_iter_mut()
            .enumerate()
            .for_each(|(g, slab)| {
                slab.clear();
                slab.resize(height * row_len, zero);
                let origin = (g * rows) as i64 - margin as i64;
                spread_into(slab, &order[starts[g]..starts[g + 1]], Some(origin));
            });
        let slabs = &scratch.slabs;
        scratch
            .grid
            .par_chunks_mut(row_len)
            .enumerate()
            .for_each(|(r, row)| {
                row.fill(zero);
                for (g, slab) in slabs.iter().enumerate() {
                    let local = (r as i64 - (g * rows) as i64 + margin as i64).rem_euclid(n as i64)
                        as usize;
                    if local < height {
                        for (v, s) in row
                            .iter_mut()
                            .zip(&slab[local * row_len..(local + 1) * row_len])
                        {
                            *v += s;
                        }
                    }
                }
            });
    }

    /// The point indices sorted by the fine-grid bin (BIN^d cells) that
    /// holds each point, a stable counting sort: spreading and interpolating
    /// in this order touch the grid tile by tile instead of at random, which
    /// is what makes them fast once the grid outgrows the caches (Barnett,
    /// Magland & af Klinteberg 2019, §4.1). The order depends on the points
    /// alone, so results stay identical for any thread count.
    fn bin_order(&self, points: &PointSet, (order, counts): &mut (Vec<usize>, Vec<usize>)) {
        let d = self.freqs.dim;
        let bin = BIN[d - 1];
        let per_axis = self.grid.div_ceil(bin);
        let scale = self.grid as f64 / bin as f64;
        let bin_of = |x: &[f64]| {
            x.iter().rev().fold(0usize, |acc, &v| {
                acc * per_axis + ((v * scale) as usize).min(per_axis - 1)
            })
        };
        counts.clear();
        counts.resize(per_axis.pow(d as u32) + 1, 0);
        for x in points.points() {
            counts[bin_of(x) + 1] += 1;
        }
        for b in 1..counts.len() {
            counts[b] += counts[b - 1];
        }
        order.clear();
        order.resize(points.len(), 0);
        for (j, x) in points.points().enumerate() {
            let slot = &mut counts[bin_of(x)];
            order[*slot] = j;
            *slot += 1;
        }
    }

    /// Calls `f(cell, ψ-weight)` for the w^d fine-grid cells around x; with
    /// `origin`, cells of the last axis count from that (unwrapped) row, the
    /// first of a slab, instead of wrapping around the grid.
    fn for_each_grid_neighbour(
        &self,
        x: &[f64],
        origin: Option<i64>,
        mut f: impl FnMut(usize, f64),
    ) {
        let (w, n, d) = (self.width, self.grid, self.freqs.dim);
        let mut weights = [[0.0f64; 16]; 4];
        let mut cells = [[0usize; 16]; 4];
        for (dim, &xj) in x.iter().enumerate() {
            let t = xj * n as f64;
            let start = t - 0.5 * w as f64;
            let first = start.ceil();
            match &self.polynomial {
                Some(p) => p.eval(2.0 * (first - start) - 1.0, &mut weights[dim][..w]),
                None => {
                    for (a, weight) in weights[dim][..w].iter_mut().enumerate() {
                        let z = 2.0 * (first + a as f64 - t) / w as f64;
                        *weight = kernel(z, self.beta);
                    }
                }
            }
            let first = first as i64;
            for (a, cell) in cells[dim][..w].iter_mut().enumerate() {
                let l = first + a as i64;
                *cell = match origin {
                    Some(o) if dim == d - 1 => (l - o) as usize,
                    _ => l.rem_euclid(n as i64) as usize,
                };
            }
        }
        // Odometer over dimensions 1..d; dimension 0 runs contiguously inside.
        let mut a = [0usize; 4];
        loop {
            let (mut base, mut weight) = (0usize, 1.0);
            for dim in (1..d).rev() {
                base = base * n + cells[dim][a[dim]];
                weight *= weights[dim][a[dim]];
            }
            base *= n;
            for a0 in 0..w {
                f(base + cells[0][a0], weight * weights[0][a0]);
            }
            let mut dim = 1;
            while dim < d {
                a[dim] += 1;
                if a[dim] < w {
                    break;
                }
                a[dim] = 0;
                dim += 1;
            }
            if dim >= d {
                return;
            }
        }
    }

    /// In-place d-D FFT of the fine grid, axis by axis, pruned to the lines
    /// that matter: a type-1 transform keeps only modes |k| ≤ h, so after an
    /// axis is transformed only its kept indices are carried on; a type-2
    /// grid is zero outside the kept modes, so lines through untransformed
    /// zero indices are skipped. Lines are transformed in parallel; each line
    /// is one FFT, so the result does not depend on the thread count.
    fn fft(&self, scratch: &mut NufftScratch, sign: Sign, prune: Prune) {
        let fft = match sign {
            Sign::Negative => &self.forward,
            Sign::Positive => &self.inverse,
        };
        for axis in 0..self.freqs.dim {
            self.fft_axis(scratch, axis, prune, fft);
        }
    }

    /// Whether grid index `i` of an axis holds a kept mode (k mod n, |k| ≤ h).
    #[inline]
    fn kept(&self, i: usize) -> bool {
        i <= self.freqs.half || i >= self.grid - self.freqs.half
    }

    /// Indices (little-endian over `axes` axes of size n) whose every digit
    /// is kept, or all of them.
    fn positions(&self, axes: usize, restricted: bool) -> Vec<usize> {
        let n = self.grid;
        (0..n.pow(axes as u32))
            .filter(|&p| {
                !restricted || {
                    let mut rest = p;
                    (0..axes).all(|_| {
                        let ok = self.kept(rest % n);
                        rest /= n;
                        ok
                    })
                }
            })
            .collect()
    }

    fn fft_axis(
        &self,
        scratch: &mut NufftScratch,
        axis: usize,
        prune: Prune,
        fft: &Arc<dyn Fft<f64>>,
    ) {
        const LINES_PER_TASK: usize = 16;
        let (n, d) = (self.grid, self.freqs.dim);
        let inner = self.positions(axis, prune == Prune::Type1);
        let outer = self.positions(d - 1 - axis, prune == Prune::Type2);
        let fft_scratch = fft.get_inplace_scratch_len();
        let zero = Complex64::new(0.0, 0.0);
        if axis == 0 {
            // Lines are contiguous rows: transform the needed ones in place.
            let mut wanted = vec![false; scratch.grid.len() / n];
            for &o in &outer {
                wanted[o] = true;
            }
            scratch
                .grid
                .par_chunks_mut(n * LINES_PER_TASK)
                .enumerate()
                .for_each_init(
                    || vec![zero; fft_scratch],
                    |buf, (task, rows)| {
                        for (r, row) in rows.chunks_exact_mut(n).enumerate() {
                            if wanted[task * LINES_PER_TASK + r] {
                                fft.process_with_scratch(row, buf);
                            }
                        }
                    },
                );
            return;
        }
        // Line (o, q) runs through o·n^(axis+1) + t·n^axis + q, t = 0..n:
        // gather the lines contiguously, transform them, scatter them back.
        let stride = n.pow(axis as u32);
        let lines = outer.len() * inner.len();
        let grid = &scratch.grid;
        let buf = &mut scratch.swap[..lines * n];
        buf.par_chunks_mut(n).enumerate().for_each(|(l, line)| {
            let base = outer[l / inner.len()] * stride * n + inner[l % inner.len()];
            for (t, v) in line.iter_mut().enumerate() {
                *v = grid[base + t * stride];
            }
        });
        buf.par_chunks_mut(n * LINES_PER_TASK).for_each_init(
            || vec![zero; fft_scratch],
            |s, chunk| fft.process_with_scratch(chunk, s),
        );
        let buf = &scratch.swap[..lines * n];
        let mut outer_index = vec![None; n.pow((d - 1 - axis) as u32)];
        for (i, &o) in outer.iter().enumerate() {
            outer_index[o] = Some(i);
        }
        // Each chunk of n^axis elements is one (o, t) row: disjoint writes.
        scratch
            .grid
            .par_chunks_mut(stride)
            .enumerate()
            .for_each(|(c, row)| {
                if let Some(oi) = outer_index[c / n] {
                    let t = c % n;
                    for (qi, &q) in inner.iter().enumerate() {
                        row[q] = buf[(oi * inner.len() + qi) * n + t];
                    }
                }
            });
    }
}

/// Fine-grid cells per bin edge in d = 1..4 dimensions (bins of about 4096
/// cells in 2D, fitting the L1 cache with their kernel margins).
const BIN: [usize; 4] = [64, 16, 8, 4];

/// Points per parallel task of the interpolation.
const POINTS_PER_TASK: usize = 4096;

/// Which lines a pruned FFT may skip.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Prune {
    /// Only kept output modes are read afterwards.
    Type1,
    /// Only kept input modes are nonzero.
    Type2,
}

/// The kernel on the w cells around a point as polynomials of its offset:
/// with δ ∈ [0, 1) the distance from the kernel's left end to the first
/// cell, cell a sits at z_a = −1 + 2(a + δ)/w, and on each cell φ(z_a) is
/// smooth in s = 2δ − 1 ∈ [−1, 1] (φ's only non-smooth points, z = ±1, are
/// cell ends). Each is interpolated at Chebyshev nodes, converted to
/// monomials, and evaluated by Horner's rule for all w cells at once — no
/// exponential or square root per point (the piecewise-polynomial kernel of
/// Barnett, Magland & af Klinteberg 2019, §5.1). The degree is raised until
/// the Horner values are within ε/4 of φ on a check grid of 2001 offsets.
/// What limits the fit is the edge cell, where φ has a square-root
/// singularity at z = −1 of height e^(−β) = ε/10 (the size of the kernel's
/// own cut-off): degree w + 1 reaches 0.15–0.19ε for ε = 1e-3 … 1e-12 and
/// no degree does much better. Where ε/4 is not reached (ε = 1e-14, where
/// the monomial form's rounding is as large), there is no polynomial and
/// the plan evaluates φ exactly. The transform's error against the direct
/// sums is checked in tests/spectrum_accuracy.rs.
struct KernelPolynomial {
    width: usize,
    /// Monomial coefficients, `coeffs[j * width + a]` for s^j of cell a.
    coeffs: Vec<f64>,
    degree: usize,
}

impl KernelPolynomial {
    fn fit(width: usize, beta: f64, tolerance: f64) -> Option<Self> {
        let w = width as f64;
        let exact = |a: usize, s: f64| kernel(-1.0 + (2.0 * a as f64 + s + 1.0) / w, beta);
        let mut check = vec![0.0; width];
        for degree in (width + 1..=24).step_by(2) {
            let q = degree + 1;
            // Chebyshev coefficients from values at the q Chebyshev nodes.
            let mut cheb = vec![0.0; q * width];
            for i in 0..q {
                let theta = std::f64::consts::PI * (i as f64 + 0.5) / q as f64;
                for a in 0..width {
                    let f = exact(a, theta.cos());
                    for j in 0..q {
                        let scale = if j == 0 { 1.0 } else { 2.0 };
                        cheb[j * width + a] += scale * f * (j as f64 * theta).cos() / q as f64;
                    }
                }
            }
            // T_j in monomials: T_0 = 1, T_1 = s, T_(j+1) = 2s·T_j − T_(j−1)
            // (integer coefficients, exact in f64 at these degrees).
            let mut coeffs = vec![0.0; q * width];
            let (mut prev, mut cur) = (vec![0.0; q], vec![0.0; q]);
            cur[0] = 1.0;
            for j in 0..q {
                for (k, &t) in cur.iter().enumerate().take(j + 1) {
                    for a in 0..width {
                        coeffs[k * width + a] += cheb[j * width + a] * t;
                    }
                }
                let factor = if j == 0 { 1.0 } else { 2.0 };
                let mut next: Vec<f64> = prev.iter().map(|p| -p).collect();
                for k in 1..q {
                    next[k] += factor * cur[k - 1];
                }
                prev = std::mem::replace(&mut cur, next);
            }
            let fit = KernelPolynomial {
                width,
                coeffs,
                degree,
            };
            let worst = (0..=2000)
                .map(|i| {
                    let s = -1.0 + i as f64 / 1000.0;
                    fit.eval(s, &mut check);
                    (0..width)
                        .map(|a| (check[a] - exact(a, s)).abs())
                        .fold(0.0, f64::max)
                })
                .fold(0.0, f64::max);
            if worst <= 0.25 * tolerance {
                return Some(fit);
            }
        }
        None
    }

    /// φ at the w cells for offset s = 2δ − 1, into `out`.
    #[inline]
    fn eval(&self, s: f64, out: &mut [f64]) {
        let w = self.width;
        out.copy_from_slice(&self.coeffs[self.degree * w..(self.degree + 1) * w]);
        for j in (0..self.degree).rev() {
            let c = &self.coeffs[j * w..(j + 1) * w];
            for (o, &cj) in out.iter_mut().zip(c) {
                *o = *o * s + cj;
            }
        }
    }
}

/// Width w = ⌈log10(1/ε)⌉ + 1 grid points (2 to 16) and β = 2.30·w of the
/// kernel for tolerance ε (BMK 2019, §3 and Eq. (3.2)).
fn kernel_shape(tolerance: f64) -> (usize, f64) {
    let width = ((1.0 / tolerance).log10().ceil() as usize + 1).clamp(2, 16);
    (width, 2.30 * width as f64)
}

/// The ES kernel φ(z) = exp(β(√(1 − z²) − 1)) on [−1, 1], 0 outside
/// (BMK 2019, Eq. (1.8)).
#[inline]
fn kernel(z: f64, beta: f64) -> f64 {
    if z.abs() >= 1.0 {
        0.0
    } else {
        (beta * ((1.0 - z * z).sqrt() - 1.0)).exp()
    }
}

/// ψ̂(ξ) = ∫ ψ(u) e^(−2πiξu) du = (w/2) ∫_(−1)^(1) φ(z) cos(π w ξ z) dz, by
/// Gauss–Legendre quadrature with enough nodes for double precision.
fn kernel_transform(xi: f64, width: usize, beta: f64) -> f64 {
    let (nodes, weights) = crate::quadrature::gauss_legendre(4 * width + 40);
    let w = width as f64;
    let sum: f64 = nodes
        .iter()
        .zip(&weights)
        .map(|(&z, &q)| q * kernel(z, beta) * (std::f64::consts::PI * w * xi * z).cos())
        .sum();
    0.5 * w * sum
}

/// Bytes a plan on `freqs` holds at most: a fine grid of twice the box's
/// side per thread (four buffers) and 24 bytes per frequency; `None` when
/// the box's size overflows.
pub fn nufft_memory_bytes(freqs: &FrequencyBox) -> Option<f64> {
    let threads = rayon::current_num_threads() as f64;
    let side = freqs.side() as f64;
    let d = freqs.dim as i32;
    freqs
        .checked_len()
        .map(|len| threads * 4.0 * (2.0 * side).powi(d) * 16.0 + len as f64 * 24.0)
}

/// The smallest 2^a·3^b·5^c ≥ `min` (sizes RustFFT handles fastest).
/// Refuses a box whose transform would not fit in memory: each thread holds
/// two complex fine grids of at least (2(2h+1))^d cells and the spreading
/// slabs (at most two grids more), plus the box's coefficients.
///
/// # Errors
/// [`SpectrumError::TooLarge`] with the estimate.
pub fn check_nufft_memory(freqs: &FrequencyBox) -> Result<(), SpectrumError> {
    let bytes = nufft_memory_bytes(freqs);
    crate::memory::check(
        &format!(
            "a non-uniform FFT on the {}^{} frequency box (|k| <= {})",
            freqs.side(),
            freqs.dim,
            freqs.half
        ),
        bytes,
        "lower --res (4D boxes grow as K^4)",
    )?;
    Ok(())
}

fn fine_grid_size(min: usize) -> usize {
    (min..)
        .find(|&n| {
            let mut m = n;
            for p in [2, 3, 5] {
                while m % p == 0 {
                    m /= p;
                }
            }
            m == 1 && n % 2 == 0
        })
        .expect("a smooth number exists")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_sizes_are_even_and_smooth() {
        assert_eq!(fine_grid_size(510), 512);
        assert_eq!(fine_grid_size(7), 8);
        assert_eq!(fine_grid_size(250), 250);
    }

    #[test]
    fn the_polynomial_kernel_reaches_every_usual_tolerance() {
        // The fast kernel must not silently fall back to exp/sqrt: for
        // ε = 1e-3 … 1e-12 a low degree fits within ε/4 (checked against φ
        // at 2001 offsets here independently of the fit's own check).
        for tol in [1e-3, 1e-6, 1e-9, 1e-12] {
            let (w, beta) = kernel_shape(tol);
            let p = KernelPolynomial::fit(w, beta, tol).expect("a polynomial");
            assert!(p.degree <= w + 3, "tol {tol:e}: degree {}", p.degree);
            let mut out = vec![0.0; w];
            for i in 0..=2000 {
                let delta = i as f64 / 2001.0;
                p.eval(2.0 * delta - 1.0, &mut out);
                for (a, v) in out.iter().enumerate() {
                    let z = -1.0 + 2.0 * (a as f64 + delta) / w as f64;
                    assert!(
                        (v - kernel(z, beta)).abs() <= 0.25 * tol,
                        "tol {tol:e}, cell {a}, δ {delta}"
                    );
                }
            }
        }
    }

    #[test]
    fn bad_tolerances_are_refused() {
        let b = FrequencyBox { dim: 2, half: 4 };
        assert!(NufftPlan::new(b, 0.0).is_err());
        assert!(NufftPlan::new(b, 1e-16).is_err());
        assert!(NufftPlan::new(b, f64::NAN).is_err());
        assert!(NufftPlan::new(b, 1e-6).is_ok());
    }
}
