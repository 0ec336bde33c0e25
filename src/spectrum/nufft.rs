//! Non-uniform fast Fourier transforms of type 1 and type 2 in d = 1…4
//! dimensions, one generic implementation.
//!
//! * Type 1 (points → modes): F(k) = Σ_j c_j e^(±2πi k·x_j) for k in a box.
//! * Type 2 (modes → points): c_j = Σ_k F(k) e^(±2πi k·x_j).
//!
//! Method (Dutt & Rokhlin 1993; kernel and parameters of Barnett, Magland &
//! af Klinteberg 2019, "A parallel non-uniform fast Fourier transform library
//! based on an exponential of semicircle kernel", SIAM J. Sci. Comput. 41(5)):
//! spread each point onto an oversampled periodic grid (n ≥ σ(2h+1) points
//! per axis, upsampling factor σ = 2 or 5/4) with the "exponential of
//! semicircle" kernel ψ(u) = exp(β(√(1 − (2u/w)²) − 1)) of width w grid
//! points, take a d-D FFT, and divide each mode by the kernel's Fourier
//! transform ψ̂(k/n) (type 2 runs the same steps backwards). With
//! w = ⌈log10(1/ε)⌉ + 1 and β = 2.30·w at σ = 2, and
//! w = ⌈ln(1/ε)/(π√(1 − 1/σ))⌉ + 1 and β = 0.97·π·w·(1 − 1/(2σ)) otherwise, the
//! relative error is about ε (BMK 2019, §3, Eq. (3.2) and §4.3):
//! |ΔF(k)| ≲ ε·Σ_j |c_j|. σ = 5/4 shrinks the grid (and the FFT) by
//! (5/8)^d for a wider kernel: [`Upsampling::Auto`] picks the cheaper of the
//! two from the number of points, as FINUFFT does since version 2.3.
//!
//! A plan is a value (docs/architecture.md, "Conventions"): designed once for (d, h, ε), `Send +
//! Sync`, reused across realizations with caller-supplied scratch.

use std::sync::Arc;

use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use rustfft::{Fft, FftDirection, FftPlanner};

use super::{FrequencyBox, SpectrumError};
use crate::points::PointSet;

/// Evaluates `$body` with the kernel width `$width` (2..=16) as the
/// constant `$w`, so that the per-point kernel loops have fixed lengths
/// the compiler unrolls and vectorises (one copy per width, as FINUFFT
/// templates its spreaders on the width).
macro_rules! with_width {
    ($width:expr, $w:ident => $body:expr) => {
        match $width {
            2 => {
                const $w: usize = 2;
                $body
            }
            3 => {
                const $w: usize = 3;
                $body
            }
            4 => {
                const $w: usize = 4;
                $body
            }
            5 => {
                const $w: usize = 5;
                $body
            }
            6 => {
                const $w: usize = 6;
                $body
            }
            7 => {
                const $w: usize = 7;
                $body
            }
            8 => {
                const $w: usize = 8;
                $body
            }
            9 => {
                const $w: usize = 9;
                $body
            }
            10 => {
                const $w: usize = 10;
                $body
            }
            11 => {
                const $w: usize = 11;
                $body
            }
            12 => {
                const $w: usize = 12;
                $body
            }
            13 => {
                const $w: usize = 13;
                $body
            }
            14 => {
                const $w: usize = 14;
                $body
            }
            15 => {
                const $w: usize = 15;
                $body
            }
            16 => {
                const $w: usize = 16;
                $body
            }
            other => unreachable!("kernel widths are 2..=16 (kernel_shape), not {other}"),
        }
    };
}

/// The sign of the exponent: e^(−2πi k·x) (`Negative`, the sample spectrum's)
/// or e^(+2πi k·x).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sign {
    /// e^(−2πi k·x).
    Negative,
    /// e^(+2πi k·x).
    Positive,
}

/// The upsampling factor σ of the fine grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Upsampling {
    /// σ = 2: the narrowest kernel (every tolerance).
    Two,
    /// σ = 5/4: a grid (5/8)^d the size of σ = 2's and a kernel about 1.4
    /// times wider; tolerances down to 1e-9 (the kernel is at most 16
    /// points wide).
    FiveFourths,
    /// The one of the two with the smaller modelled cost for this many
    /// points ([`Upsampling::choose`]).
    Auto {
        /// Points per transform.
        points: usize,
    },
}

impl Upsampling {
    /// The smallest tolerance σ = 5/4 reaches with a kernel of at most
    /// [`MAX_WIDTH`] points.
    pub const FIVE_FOURTHS_MIN_TOLERANCE: f64 = 1e-9;

    /// σ for `points` points on `freqs` at `tolerance`: the factor whose
    /// modelled time, N·w^d kernel weights applied plus n^d·log2(n^d) FFT
    /// work, is smaller. The two cost about the same per unit (fitted to
    /// `varspec bench spectrum` on 2 cores, about 0.3 ns each at 65,536 and
    /// 1,048,576 points on the 512² box, where σ = 5/4 is 1.3–1.4× faster
    /// and 1.1–1.4× slower); in 2D at ε = 1e-6 on that box σ = 5/4 wins
    /// below about 200,000 points. A function of its arguments only, so the
    /// transform is the same for every thread count.
    pub fn choose(freqs: &FrequencyBox, tolerance: f64, points: usize) -> f64 {
        if tolerance < Self::FIVE_FOURTHS_MIN_TOLERANCE {
            return 2.0;
        }
        let cost = |sigma: f64| {
            let (width, _) = kernel_shape(tolerance, sigma);
            let n = grid_size(freqs.side(), sigma, width) as f64;
            let cells = n.powi(freqs.dim as i32);
            let spread = points as f64 * (width as f64).powi(freqs.dim as i32);
            spread + cells * cells.log2()
        };
        if cost(1.25) < cost(2.0) { 1.25 } else { 2.0 }
    }

    fn sigma(self, freqs: &FrequencyBox, tolerance: f64) -> f64 {
        match self {
            Upsampling::Two => 2.0,
            Upsampling::FiveFourths => 1.25,
            Upsampling::Auto { points } => Upsampling::choose(freqs, tolerance, points),
        }
    }
}

/// A designed transform for one frequency box and tolerance.
pub struct NufftPlan {
    freqs: FrequencyBox,
    /// Upsampling factor σ (2 or 5/4).
    sigma: f64,
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
    /// Point indices in bin order.
    order: BinOrder,
    /// The points' coordinates (and strengths) in bin order: gathered
    /// once, in parallel, so the spreading and interpolation read them in
    /// sequence (read through `order` they were a cache miss per point, 40%
    /// of the spreading's time at a million points).
    sorted: (Vec<f64>, Vec<Complex64>),
    /// One real slab per row group (see [`NufftPlan::spread`]).
    slabs: Vec<Vec<f64>>,
}

impl NufftPlan {
    /// Designs the transform on the box `freqs` with relative tolerance
    /// `tolerance` and upsampling σ = 2.
    ///
    /// # Errors
    /// [`SpectrumError::Tolerance`] outside [1e-14, 0.1];
    /// [`SpectrumError::UnsupportedDimension`] outside d = 1..=4.
    pub fn new(freqs: FrequencyBox, tolerance: f64) -> Result<Self, SpectrumError> {
        Self::with_upsampling(freqs, tolerance, Upsampling::Two)
    }

    /// Designs the transform with the upsampling factor `upsampling`.
    ///
    /// # Errors
    /// As [`NufftPlan::new`]; [`SpectrumError::Tolerance`] also for σ = 5/4
    /// below [`Upsampling::FIVE_FOURTHS_MIN_TOLERANCE`].
    pub fn with_upsampling(
        freqs: FrequencyBox,
        tolerance: f64,
        upsampling: Upsampling,
    ) -> Result<Self, SpectrumError> {
        if !(1..=4).contains(&freqs.dim) {
            return Err(SpectrumError::UnsupportedDimension(freqs.dim));
        }
        if !(1e-14..=0.1).contains(&tolerance) {
            return Err(SpectrumError::Tolerance(tolerance));
        }
        let sigma = upsampling.sigma(&freqs, tolerance);
        if sigma < 2.0 && tolerance < Upsampling::FIVE_FOURTHS_MIN_TOLERANCE {
            return Err(SpectrumError::Tolerance(tolerance));
        }
        check_nufft_memory(&freqs)?;
        let (width, beta) = kernel_shape(tolerance, sigma);
        let grid = grid_size(freqs.side(), sigma, width);
        let h = freqs.half as i64;
        let rule = crate::quadrature::gauss_legendre(4 * width + 40);
        let correction = (-h..=h)
            .map(|k| 1.0 / kernel_transform(k as f64 / grid as f64, width, beta, &rule))
            .collect();
        let mode_cells = (-h..=h)
            .map(|k| k.rem_euclid(grid as i64) as usize)
            .collect();
        let mut planner = FftPlanner::new();
        let forward = planner.plan_fft(grid, FftDirection::Forward);
        let inverse = planner.plan_fft(grid, FftDirection::Inverse);
        Ok(NufftPlan {
            freqs,
            sigma,
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

    /// The upsampling factor σ in use.
    pub fn upsampling(&self) -> f64 {
        self.sigma
    }

    /// Fine-grid points per axis.
    pub fn grid_size(&self) -> usize {
        self.grid
    }

    /// Kernel width in grid points.
    pub fn kernel_width(&self) -> usize {
        self.width
    }

    /// Fresh scratch for this plan.
    pub fn make_scratch(&self) -> NufftScratch {
        let cells = self.grid.pow(self.freqs.dim as u32);
        let zero = Complex64::new(0.0, 0.0);
        NufftScratch {
            grid: vec![zero; cells],
            swap: vec![zero; cells],
            order: BinOrder::default(),
            sorted: (Vec::new(), Vec::new()),
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
        out.par_chunks_mut(self.freqs.side())
            .enumerate()
            .with_min_len(MODE_ROWS_PER_TASK)
            .for_each(|(row, out_row)| {
                let (base, corr) = self.mode_row(row);
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
        // Grid rows along axis 0, each zeroed and given its mode row, if any.
        let side = self.freqs.side();
        scratch
            .grid
            .par_chunks_mut(self.grid)
            .enumerate()
            .with_min_len(MODE_ROWS_PER_TASK)
            .for_each(|(g, grid_row)| {
                grid_row.fill(Complex64::new(0.0, 0.0));
                if let Some(row) = self.mode_row_at(g) {
                    let (_, corr) = self.mode_row(row);
                    let in_row = &coeffs[row * side..(row + 1) * side];
                    for ((c, &cell), &k) in
                        in_row.iter().zip(&self.mode_cells).zip(&self.correction)
                    {
                        grid_row[cell] = c * (corr * k);
                    }
                }
            });
        self.fft(scratch, sign, Prune::Type2);
        // Interpolation only reads the grid: points in bin order, in
        // parallel chunks, each value computed on its own and written to
        // its point's slot by the task that computed it.
        self.bin_order(points, &mut scratch.order);
        gather_sorted(points, None, &scratch.order.order, &mut scratch.sorted);
        let (order, grid, coords) = (&scratch.order.order, &scratch.grid, &scratch.sorted.0);
        let d = self.freqs.dim;
        let slots = Scatter::new(out);
        with_width!(self.width, W => coords
        .par_chunks(POINTS_PER_TASK * d)
        .zip(order.par_chunks(POINTS_PER_TASK))
        .for_each(|(chunk, indices)| {
            for (&j, v) in indices.iter().zip(self.interpolate_fastest::<W>(chunk, grid)) {
                // SAFETY: `order` is a permutation of the points (a
                // stable counting sort places each index once), and
                // the chunks split it: every slot is written once.
                unsafe { slots.write(j, v) };
            }
        }));
    }

    fn check(&self, points: &PointSet, modes: usize) {
        assert_eq!(
            points.dim(),
            self.freqs.dim,
            "points and plan differ in dimension"
        );
        assert_eq!(modes, self.freqs.len(), "one value per mode of the box");
    }

    /// Row `row` of the mode box (modes with fixed k_1..k_(d−1), k_0
    /// running): `(base, corr)`, the fine-grid offset of those k_1.. and
    /// their deconvolution factor Π 1/ψ̂; the row's k_0 = −h..h then sit at
    /// `base + mode_cells[k_0 + h]`.
    #[inline]
    fn mode_row(&self, row: usize) -> (usize, f64) {
        let (side, n) = (self.freqs.side(), self.grid);
        let (mut rest, mut base, mut corr, mut scale) = (row, 0, 1.0, n);
        for _ in 1..self.freqs.dim {
            let i = rest % side;
            rest /= side;
            base += self.mode_cells[i] * scale;
            corr *= self.correction[i];
            scale *= n;
        }
        (base, corr)
    }

    /// The mode row held by fine-grid row `g` (its cells along axes
    /// 1..d, little-endian), if every one of them is a kept mode: the
    /// inverse of [`Self::mode_row`]'s `base / n`.
    #[inline]
    fn mode_row_at(&self, g: usize) -> Option<usize> {
        let (side, n, h) = (self.freqs.side(), self.grid, self.freqs.half);
        let (mut rest, mut row, mut scale) = (g, 0, 1);
        for _ in 1..self.freqs.dim {
            let cell = rest % n;
            rest /= n;
            let i = if cell <= h {
                cell + h
            } else if cell >= n - h {
                cell + h - n
            } else {
                return None;
            };
            row += i * scale;
            scale *= side;
        }
        Some(row)
    }

    /// Spreads the points (strength 1 or `strengths`) onto `scratch.grid`.
    ///
    /// Points are taken in bin order and split into groups of G rows of the
    /// last axis (G ≥ the kernel width, a multiple of the bin height; one
    /// group of all n rows when the grid is too small for two); each group
    /// spreads into its own slab in parallel, and each grid row then adds
    /// the slab rows that fall on it, slab by slab in group order. The
    /// groups depend on the grid and the kernel alone, so the sums, and the
    /// result, are identical for any thread count.
    ///
    /// A slab is real (f64), not complex: one value per cell without
    /// strengths (the sample spectrum's case, half the memory traffic), two
    /// with. Its first axis is padded by the kernel's reach on both sides
    /// instead of wrapping, so each kernel row is one contiguous multiply-add
    /// of w (or 2w) values, which the compiler vectorises; the padding is
    /// folded back onto the periodic grid in the reduction.
    fn spread(
        &self,
        points: &PointSet,
        strengths: Option<&[Complex64]>,
        scratch: &mut NufftScratch,
    ) {
        let (n, d) = (self.grid, self.freqs.dim);
        let layout = SlabLayout::new(n, d, self.width, strengths.is_some());
        self.bin_order(points, &mut scratch.order);
        let order = &scratch.order.order;
        // The group of a point: its last coordinate's row over `rows`; bin
        // order sorts the last axis slowest, so groups are contiguous.
        let group_of = |j: usize| {
            let t = points.point(j)[d - 1] * n as f64;
            ((t as usize) / layout.rows).min(layout.groups - 1)
        };
        let starts: Vec<usize> = (0..=layout.groups)
            .map(|g| order.partition_point(|&j| group_of(j) < g))
            .collect();
        gather_sorted(points, strengths, order, &mut scratch.sorted);
        let (coords, sorted_strengths) = (&scratch.sorted.0, &scratch.sorted.1);
        scratch.slabs.resize_with(layout.groups, Vec::new);
        scratch.slabs.truncate(layout.groups);
        scratch
            .slabs
            .par_iter_mut()
            .enumerate()
            .for_each(|(g, slab)| {
                slab.clear();
                slab.resize(layout.height * layout.row_len, 0.0);
                let (range, origin) = (starts[g]..starts[g + 1], layout.origin(g));
                let x = &coords[range.start * d..range.end * d];
                let job = SlabJob {
                    coords: x,
                    strengths: strengths.map(|_| &sorted_strengths[range]),
                    layout: &layout,
                    origin,
                };
                with_width!(self.width, W => match strengths {
                    None => self.spread_slab_fastest::<W, 1>(&job, slab),
                    Some(_) => self.spread_slab_fastest::<W, 2>(&job, slab),
                });
            });
        let slabs = &scratch.slabs;
        let grid_row = n.pow(d as u32 - 1);
        let (line_in, line_out, pad) = if d == 1 {
            (1, 1, 0)
        } else {
            (layout.line, n, layout.margin)
        };
        scratch
            .grid
            .par_chunks_mut(grid_row)
            .enumerate()
            .for_each(|(r, row)| {
                row.fill(Complex64::new(0.0, 0.0));
                for (g, slab) in slabs.iter().enumerate() {
                    let mut local = (r as i64 - layout.origin(g)).rem_euclid(n as i64) as usize;
                    while local < layout.height {
                        let from = &slab[local * layout.row_len..(local + 1) * layout.row_len];
                        for (out, line) in row
                            .chunks_exact_mut(line_out)
                            .zip(from.chunks_exact(line_in * layout.comps))
                        {
                            fold_line(out, line, pad, layout.comps);
                        }
                        local += n;
                    }
                }
            });
    }

    /// [`Self::spread_slab`] compiled for AVX2 where the processor has it
    /// (twice the vector width of baseline x86-64's SSE2), else as is. The
    /// same operations in the same order either way, never fused into FMAs
    /// (Rust does not contract a·b + c), so the bits do not depend on the
    /// processor.
    fn spread_slab_fastest<const W: usize, const C: usize>(&self, job: &SlabJob, slab: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2, checked just above.
            unsafe { self.spread_slab_avx2::<W, C>(job, slab) };
            return;
        }
        self.spread_slab::<W, C>(job, slab)
    }

    /// [`Self::spread_slab`] with AVX2 enabled.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn spread_slab_avx2<const W: usize, const C: usize>(&self, job: &SlabJob, slab: &mut [f64]) {
        self.spread_slab::<W, C>(job, slab)
    }

    /// Adds the kernels of the job's points to its slab. `W` is the kernel
    /// width and `C` the values per cell (1 real, 2 complex): constants, so
    /// every loop over a kernel row has a fixed length.
    #[inline(always)]
    fn spread_slab<const W: usize, const C: usize>(&self, job: &SlabJob, slab: &mut [f64]) {
        let SlabJob {
            coords,
            strengths,
            layout,
            origin,
        } = *job;
        let (n, d) = (self.grid as i64, self.freqs.dim);
        for (j, x) in coords.chunks_exact(d).enumerate() {
            let (mut weights, mut first) = ([[0.0f64; W]; 4], [0i64; 4]);
            self.point_kernel::<W>(x, &mut weights, &mut first);
            // The first axis's weights times c, interleaved re, im when
            // complex (c = 1 leaves them exact).
            let c = strengths.map_or(Complex64::new(1.0, 0.0), |s| s[j]);
            let mut lead = [[0.0f64; C]; W];
            for (cell, &wt) in lead.iter_mut().zip(&weights[0]) {
                cell[0] = c.re * wt;
                if let Some(im) = cell.get_mut(1) {
                    *im = c.im * wt;
                }
            }
            let lead = lead.as_flattened();
            let start0 = if d == 1 {
                first[0] - origin
            } else {
                first[0] + layout.margin as i64
            } as usize;
            // Odometer over axes 1..d: the last counts slab rows from
            // `origin`, the middle ones wrap around the grid.
            let mut a = [0usize; 4];
            loop {
                let (mut base, mut weight) = (0usize, 1.0);
                if d > 1 {
                    base = (first[d - 1] + a[d - 1] as i64 - origin) as usize;
                    weight = weights[d - 1][a[d - 1]];
                    for dim in (1..d - 1).rev() {
                        base = base * n as usize + wrap(first[dim] + a[dim] as i64, n as usize);
                        weight *= weights[dim][a[dim]];
                    }
                    base *= layout.line;
                }
                let at = (base + start0) * C;
                for (s, &l) in slab[at..at + W * C].iter_mut().zip(lead) {
                    *s += weight * l;
                }
                if !next_cell::<W>(&mut a, 1, d) {
                    break;
                }
            }
        }
    }

    /// The kernel's weights on each axis around the point `x` into
    /// `weights`, and the (unwrapped) grid index of each axis's first cell
    /// into `first`.
    #[inline(always)]
    fn point_kernel<const W: usize>(
        &self,
        x: &[f64],
        weights: &mut [[f64; W]; 4],
        first: &mut [i64; 4],
    ) {
        for (dim, &xj) in x.iter().enumerate() {
            first[dim] = self.kernel_weights(xj, &mut weights[dim]);
        }
    }

    /// The kernel's w weights around coordinate `xj` into `out` (of length
    /// w); returns the (unwrapped) grid index of the first.
    #[inline(always)]
    fn kernel_weights(&self, xj: f64, out: &mut [f64]) -> i64 {
        let w = out.len();
        let t = xj * self.grid as f64;
        let start = t - 0.5 * w as f64;
        // ⌈start⌉ by truncation (|start| ≤ n): exact, and without the
        // libm call `ceil` costs on baseline x86-64 (no SSE4.1 `roundsd`),
        // which was a third of the spreading's time.
        let truncated = start as i64;
        let first = (truncated + i64::from((truncated as f64) < start)) as f64;
        match &self.polynomial {
            Some(p) => p.eval(2.0 * (first - start) - 1.0, out),
            None => {
                for (a, weight) in out.iter_mut().enumerate() {
                    let z = 2.0 * (first + a as f64 - t) / w as f64;
                    *weight = kernel(z, self.beta);
                }
            }
        }
        first as i64
    }

    /// The point indices sorted by the fine-grid bin (BIN^d cells) that
    /// holds each point, a stable counting sort: spreading and interpolating
    /// in this order touch the grid tile by tile instead of at random, which
    /// is what makes them fast once the grid outgrows the caches (Barnett,
    /// Magland & af Klinteberg 2019, §4.1). The order depends on the points
    /// alone, so results stay identical for any thread count.
    ///
    /// In parallel: the bins of the points in chunks, then one task per
    /// thread for a contiguous range of bins (a contiguous range of the
    /// output), each scanning every point's bin and placing those in its
    /// range. A stable sort has one result, whatever the split.
    fn bin_order(&self, points: &PointSet, scratch: &mut BinOrder) {
        let d = self.freqs.dim;
        let bin = BIN[d - 1];
        let per_axis = self.grid.div_ceil(bin);
        let scale = self.grid as f64 / bin as f64;
        let bin_of = |x: &[f64]| {
            x.iter().rev().fold(0usize, |acc, &v| {
                acc * per_axis + ((v * scale) as usize).min(per_axis - 1)
            })
        };
        let BinOrder {
            order,
            starts,
            bins,
        } = scratch;
        bins.resize(points.len(), 0);
        bins.par_chunks_mut(POINTS_PER_TASK)
            .zip(points.coords().par_chunks(POINTS_PER_TASK * d))
            .for_each(|(b, x)| {
                for (b, x) in b.iter_mut().zip(x.chunks_exact(d)) {
                    *b = bin_of(x);
                }
            });
        // starts[b]: the first output slot of bin b (exclusive prefix sum).
        let total = per_axis.pow(d as u32);
        starts.clear();
        starts.resize(total + 1, 0);
        for &b in bins.iter() {
            starts[b + 1] += 1;
        }
        for b in 1..starts.len() {
            starts[b] += starts[b - 1];
        }
        // Bin ranges of about equal point counts, one per thread.
        let tasks = rayon::current_num_threads().max(1);
        let cuts: Vec<usize> = (0..=tasks)
            .map(|t| {
                starts
                    .partition_point(|&s| s < points.len() * t / tasks)
                    .min(total)
            })
            .collect();
        order.resize(points.len(), 0);
        let mut pieces = Vec::with_capacity(tasks);
        let mut rest = &mut order[..];
        for t in 0..tasks {
            let (piece, tail) = rest.split_at_mut(starts[cuts[t + 1]] - starts[cuts[t]]);
            pieces.push((cuts[t]..cuts[t + 1], piece));
            rest = tail;
        }
        let (bins, starts) = (&*bins, &*starts);
        pieces.into_par_iter().for_each(|(range, piece)| {
            let base = starts[range.start];
            let mut next: Vec<usize> = starts[range.clone()].iter().map(|s| s - base).collect();
            for (j, &b) in bins.iter().enumerate() {
                if range.contains(&b) {
                    let slot = &mut next[b - range.start];
                    piece[*slot] = j;
                    *slot += 1;
                }
            }
        });
    }

    /// [`Self::interpolate`] compiled for AVX2 where the processor has it,
    /// else as is (the same bits either way: see
    /// [`Self::spread_slab_fastest`]).
    fn interpolate_fastest<const W: usize>(
        &self,
        coords: &[f64],
        grid: &[Complex64],
    ) -> Vec<Complex64> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2, checked just above.
            return unsafe { self.interpolate_avx2::<W>(coords, grid) };
        }
        self.interpolate::<W>(coords, grid)
    }

    /// [`Self::interpolate`] with AVX2 enabled.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn interpolate_avx2<const W: usize>(
        &self,
        coords: &[f64],
        grid: &[Complex64],
    ) -> Vec<Complex64> {
        self.interpolate::<W>(coords, grid)
    }

    /// Σ_cells grid·ψ-weight around each point of `coords` (d per point):
    /// the type-2 interpolation, for a kernel of width `W`. The kernel's rows
    /// along the first axis, each weighted by the other axes' product, are
    /// added column by column (independent real sums, two per column; see
    /// [`add_row`] for how a row is read), then the columns are
    /// weighted along the first axis. The W rows of axis 1 are a
    /// fixed-length loop inside the odometer over the axes above, so the
    /// columns stay in registers: inside a generic odometer they lived in
    /// memory, and each row waited for the last one's stores.
    #[inline(always)]
    fn interpolate<const W: usize>(&self, coords: &[f64], grid: &[Complex64]) -> Vec<Complex64> {
        let (n, d) = (self.grid, self.freqs.dim);
        let zero = Complex64::new(0.0, 0.0);
        // A plain loop, not an iterator adapter: an adapter's `fold` is a
        // function of its own, compiled without the caller's AVX2.
        let mut values = Vec::with_capacity(coords.len() / d);
        for x in coords.chunks_exact(d) {
            let (mut weights, mut first) = ([[0.0f64; W]; 4], [0i64; 4]);
            self.point_kernel::<W>(x, &mut weights, &mut first);
            let wrapped = |dim: usize, a: usize| wrap(first[dim] + a as i64, n);
            let mut columns = [[0.0f64; 2]; MAX_WIDTH];
            if d == 1 {
                add_row::<W>(&mut columns, grid, (0, first[0], n), 1.0);
            } else {
                // Odometer over axes 2..d; the W rows of axis 1 inside, a
                // fixed-length loop.
                let mut a = [0usize; 4];
                loop {
                    let (mut outer, mut outer_weight) = (0usize, 1.0);
                    for dim in (2..d).rev() {
                        outer = outer * n + wrapped(dim, a[dim]);
                        outer_weight *= weights[dim][a[dim]];
                    }
                    for (a1, &w1) in weights[1].iter().enumerate() {
                        let base = (outer * n + wrapped(1, a1)) * n;
                        add_row::<W>(&mut columns, grid, (base, first[0], n), outer_weight * w1);
                    }
                    if !next_cell::<W>(&mut a, 2, d) {
                        break;
                    }
                }
            }
            let mut value = zero;
            for (c, &w0) in columns.iter().zip(&weights[0]) {
                value += Complex64::new(c[0], c[1]) * w0;
            }
            values.push(value);
        }
        values
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
        // LINE_BLOCK lines at a time, so each step along t reads neighbouring
        // cells (whole cache lines) instead of one cell a stride away: with
        // a power-of-two grid the stride maps every cell of a line to the
        // same cache set.
        buf.par_chunks_mut(n * LINE_BLOCK)
            .enumerate()
            .for_each(|(block, chunk)| {
                let mut bases = [0usize; LINE_BLOCK];
                let bases = &mut bases[..chunk.len() / n];
                for (b, base) in bases.iter_mut().enumerate() {
                    let l = block * LINE_BLOCK + b;
                    *base = outer[l / inner.len()] * stride * n + inner[l % inner.len()];
                }
                for t in 0..n {
                    for (b, &base) in bases.iter().enumerate() {
                        chunk[b * n + t] = grid[base + t * stride];
                    }
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
        // Each chunk of n^axis elements is one (o, t) row: disjoint writes,
        // `block` rows of one o at a time (block divides n; grid sides are
        // even), so each line is read several cells at a time, as in the
        // gather.
        let block = 1 << n.trailing_zeros().min(LINE_BLOCK.trailing_zeros());
        scratch
            .grid
            .par_chunks_mut(stride * block)
            .enumerate()
            .for_each(|(c, rows)| {
                let row = c * block;
                if let Some(oi) = outer_index[row / n] {
                    let t = row % n;
                    for (qi, &q) in inner.iter().enumerate() {
                        let line = &buf[(oi * inner.len() + qi) * n + t..][..block];
                        for (r, &v) in line.iter().enumerate() {
                            rows[r * stride + q] = v;
                        }
                    }
                }
            });
    }
}

/// Grid index `i` of an axis of `n` cells taken periodically, for
/// i ∈ [−n, 2n) (a kernel's cells around a coordinate in [0, 1)): one
/// conditional wrap, not an integer division.
#[inline(always)]
fn wrap(i: i64, n: usize) -> usize {
    let n = n as i64;
    debug_assert!((-n..2 * n).contains(&i), "cell {i} beyond one wrap of {n}");
    let i = if i < 0 { i + n } else { i };
    (if i >= n { i - n } else { i }) as usize
}

/// Adds the kernel row of the fine grid (row offset `base`, first cell
/// `first` of a row of `n` cells, possibly wrapping) times `weight` onto
/// `columns`, column by column (re and im apart). A row whose `span` cells
/// (the width rounded up to whole AVX2 registers of two cells) fit without
/// wrapping is read contiguously, an odd width's extra cell landing in a
/// column that is never used; other rows cell by cell.
#[inline(always)]
fn add_row<const W: usize>(
    columns: &mut [[f64; 2]; MAX_WIDTH],
    grid: &[Complex64],
    (base, first, n): (usize, i64, usize),
    weight: f64,
) {
    let span = W.next_multiple_of(2);
    if first >= 0 && first as usize + span <= n {
        let start = base + first as usize;
        for (c, g) in columns[..span].iter_mut().zip(&grid[start..start + span]) {
            c[0] += g.re * weight;
            c[1] += g.im * weight;
        }
    } else {
        for (a0, c) in columns[..W].iter_mut().enumerate() {
            let g = grid[base + wrap(first + a0 as i64, n)];
            c[0] += g.re * weight;
            c[1] += g.im * weight;
        }
    }
}

/// Writes into a slice from parallel tasks at indices that are, together, a
/// permutation: the bin order's scatter of type-2 values back to their
/// points, which would otherwise be one serial pass of random writes (a
/// twentieth of the transform at a million points).
struct Scatter<'a> {
    slots: *mut Complex64,
    len: usize,
    _out: std::marker::PhantomData<&'a mut [Complex64]>,
}

// SAFETY: `write` is unsafe and requires distinct indices over all tasks,
// so no two tasks touch the same slot.
unsafe impl Sync for Scatter<'_> {}

impl<'a> Scatter<'a> {
    fn new(out: &'a mut [Complex64]) -> Self {
        Scatter {
            slots: out.as_mut_ptr(),
            len: out.len(),
            _out: std::marker::PhantomData,
        }
    }

    /// `out[j] = v`.
    ///
    /// # Safety
    /// No other call, from any task, may write index `j` while `out` is
    /// borrowed (here: the entries of the bin order, a permutation of the
    /// points, each written once).
    #[inline]
    unsafe fn write(&self, j: usize, v: Complex64) {
        assert!(j < self.len, "scatter index {j} beyond {}", self.len);
        // SAFETY: in bounds (checked above); no other call writes slot j
        // (the caller's contract) while `out` is borrowed for 'a.
        unsafe { self.slots.add(j).write(v) };
    }
}

/// The points' indices in bin order, with the working memory that finds it.
#[derive(Default)]
struct BinOrder {
    /// Point indices, sorted by bin (stable).
    order: Vec<usize>,
    /// The first slot of each bin in `order`, and the total at the end.
    starts: Vec<usize>,
    /// Each point's bin.
    bins: Vec<usize>,
}

/// Fine-grid cells per bin edge in d = 1..4 dimensions (bins of about 4096
/// cells in 2D, fitting the L1 cache with their kernel margins).
const BIN: [usize; 4] = [64, 16, 8, 4];

/// Points per parallel task of the interpolation.
const POINTS_PER_TASK: usize = 4096;
/// Rows of the mode box one task copies into or out of the fine grid.
const MODE_ROWS_PER_TASK: usize = 16;
/// Lines an FFT pass gathers and scatters together along a strided axis (a
/// power of two): each grid row then gives a 256-byte run, not one cell.
/// In a stand-alone transpose of a 1024² grid, whose power-of-two stride
/// maps a line's cells to one cache set, 16 at a time was 2.2× faster than
/// one (4 at a time was slower than 1, 64 slower than 16).
const LINE_BLOCK: usize = 16;

/// Which lines a pruned FFT may skip.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Prune {
    /// Only kept output modes are read afterwards.
    Type1,
    /// Only kept input modes are nonzero.
    Type2,
}

/// The shape of the spreading slabs ([`NufftPlan::spread`]) for a grid of
/// n cells per axis in d dimensions and a kernel of width w.
struct SlabLayout {
    /// Grid rows of the last axis whose points each slab takes.
    rows: usize,
    /// Number of slabs.
    groups: usize,
    /// Cells a kernel reaches beyond its point's row on either side.
    margin: usize,
    /// Rows of a slab: `rows` plus the margins (and one for a coordinate
    /// that rounds up to n).
    height: usize,
    /// Cells of the first axis in a slab line (padded; d ≥ 2).
    line: usize,
    /// Values per slab row: lines × (n^(d−2)) × `comps`.
    row_len: usize,
    /// Values per cell: 1 (real strengths of 1) or 2 (complex).
    comps: usize,
}

impl SlabLayout {
    fn new(n: usize, d: usize, width: usize, complex: bool) -> SlabLayout {
        let (rows, margin) = SlabLayout::rows(n, d, width);
        let comps = if complex { 2 } else { 1 };
        let line = if d == 1 { 1 } else { n + 2 * margin + 1 };
        let middle = if d > 2 { n.pow(d as u32 - 2) } else { 1 };
        SlabLayout {
            rows,
            groups: n.div_ceil(rows),
            margin,
            height: rows + 2 * margin + 1,
            line,
            row_len: line * middle * comps,
            comps,
        }
    }

    /// The grid row (unwrapped) of slab `g`'s first row.
    fn origin(&self, g: usize) -> i64 {
        (g * self.rows) as i64 - self.margin as i64
    }

    /// Bytes the slabs take with complex strengths (in floating point, so
    /// that sizes beyond usize are estimated, not overflowed).
    fn bytes(n: usize, d: usize, width: usize) -> f64 {
        let (rows, margin) = SlabLayout::rows(n, d, width);
        let line = if d == 1 {
            1.0
        } else {
            (n + 2 * margin + 1) as f64
        };
        let middle = (n as f64).powi(d.saturating_sub(2) as i32);
        n.div_ceil(rows) as f64 * (rows + 2 * margin + 1) as f64 * line * middle * 2.0 * 8.0
    }

    /// Rows per group and the kernel's margin.
    fn rows(n: usize, d: usize, width: usize) -> (usize, usize) {
        let bin = BIN[d - 1];
        let margin = width.div_ceil(2);
        let rows = width.div_ceil(bin).max(1) * bin;
        if n.div_ceil(rows) < 2 || rows + 2 * margin + 1 > n {
            (n, margin)
        } else {
            (rows, margin)
        }
    }
}

/// Advances the odometer `a` over the kernel's cells on axes `from`..d (the
/// axes below are run through inside); false when every cell has been
/// visited.
#[inline(always)]
fn next_cell<const W: usize>(a: &mut [usize; 4], from: usize, d: usize) -> bool {
    let mut dim = from;
    while dim < d {
        a[dim] += 1;
        if a[dim] < W {
            return true;
        }
        a[dim] = 0;
        dim += 1;
    }
    false
}

/// Copies the points' coordinates (and strengths, when given) in `order`
/// into `sorted`, in parallel chunks: independent loads the processor
/// overlaps, unlike the same reads interleaved with the kernel arithmetic.
fn gather_sorted(
    points: &PointSet,
    strengths: Option<&[Complex64]>,
    order: &[usize],
    (coords, sorted_strengths): &mut (Vec<f64>, Vec<Complex64>),
) {
    let d = points.dim();
    coords.resize(order.len() * d, 0.0);
    coords
        .par_chunks_mut(POINTS_PER_TASK * d)
        .zip(order.par_chunks(POINTS_PER_TASK))
        .for_each(|(out, indices)| {
            for (x, &j) in out.chunks_exact_mut(d).zip(indices) {
                // Element by element: `copy_from_slice` of d values was a
                // memcpy call per point (a tenth of the transform's time).
                let p = points.point(j);
                #[allow(clippy::manual_memcpy)]
                for k in 0..d {
                    x[k] = p[k];
                }
            }
        });
    if let Some(s) = strengths {
        sorted_strengths.clear();
        sorted_strengths.par_extend(order.par_iter().map(|&j| s[j]));
    }
}

/// One slab's share of the spreading: the points `coords` (d per point, in
/// bin order), their `strengths` (1 when `None`), the slabs' `layout` and
/// the grid row (unwrapped) of this slab's first row.
#[derive(Clone, Copy)]
struct SlabJob<'a> {
    coords: &'a [f64],
    strengths: Option<&'a [Complex64]>,
    layout: &'a SlabLayout,
    origin: i64,
}

/// Adds a padded slab line (`pad` cells before the grid's first, the rest
/// after its last; `comps` values per cell) onto a periodic grid line.
#[inline]
fn fold_line(out: &mut [Complex64], line: &[f64], pad: usize, comps: usize) {
    let n = out.len();
    let mut t = (n - pad % n) % n;
    for v in line.chunks_exact(comps) {
        let cell = &mut out[t];
        cell.re += v[0];
        if comps == 2 {
            cell.im += v[1];
        }
        t += 1;
        if t == n {
            t = 0;
        }
    }
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
    /// Monomial coefficients, `coeffs[j * lanes + a]` for s^j of cell a,
    /// each degree's row padded with zeros to `lanes` (the width rounded up
    /// to whole vector registers), so Horner's rule runs on full registers.
    coeffs: Vec<f64>,
    degree: usize,
}

/// Values per vector register the kernel's lanes are padded to (AVX2's four
/// f64).
const LANES: usize = 4;

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
            // Rows of `lanes` values, the cells past the width left zero.
            let lanes = width.next_multiple_of(LANES);
            let mut coeffs = vec![0.0; q * lanes];
            let (mut prev, mut cur) = (vec![0.0; q], vec![0.0; q]);
            cur[0] = 1.0;
            for j in 0..q {
                for (k, &t) in cur.iter().enumerate().take(j + 1) {
                    for a in 0..width {
                        coeffs[k * lanes + a] += cheb[j * width + a] * t;
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

    /// φ at the w cells for offset s = 2δ − 1, into `out` (of length w: a
    /// fixed-size array there makes every loop below fixed-length).
    #[inline(always)]
    fn eval(&self, s: f64, out: &mut [f64]) {
        let w = out.len();
        debug_assert_eq!(w, self.width);
        // Fixed-length loops over whole registers where `out` is an array.
        let lanes = w.next_multiple_of(LANES);
        let mut acc = [0.0; MAX_WIDTH.next_multiple_of(LANES)];
        let acc = &mut acc[..lanes];
        acc.copy_from_slice(&self.coeffs[self.degree * lanes..(self.degree + 1) * lanes]);
        for j in (0..self.degree).rev() {
            let c = &self.coeffs[j * lanes..(j + 1) * lanes];
            for (o, &cj) in acc.iter_mut().zip(c) {
                *o = *o * s + cj;
            }
        }
        out.copy_from_slice(&acc[..w]);
    }
}

/// The widest kernel, in grid points (ε = 1e-14 and below).
const MAX_WIDTH: usize = 16;

/// Width w (2 to 16 grid points) and β of the kernel for tolerance ε and
/// upsampling σ: w = ⌈log10(1/ε)⌉ + 1 and β = 2.30·w at σ = 2 (BMK 2019, §3
/// and Eq. (3.2)); w = ⌈ln(1/ε)/(π√(1 − 1/σ))⌉ + 1 and
/// β = 0.97·π·w·(1 − 1/(2σ)) below (BMK 2019, §4.3, the error estimate
/// e^(−πw√(1−1/σ)); one point more than that estimate asks, because without
/// it the error exceeded ε·Σ|c_j| by up to 1.8× against direct sums).
fn kernel_shape(tolerance: f64, sigma: f64) -> (usize, f64) {
    if sigma >= 2.0 {
        let width = ((1.0 / tolerance).log10().ceil() as usize + 1).clamp(2, MAX_WIDTH);
        return (width, 2.30 * width as f64);
    }
    let reach = std::f64::consts::PI * (1.0 - 1.0 / sigma).sqrt();
    let width = (((1.0 / tolerance).ln() / reach).ceil() as usize + 1).clamp(2, MAX_WIDTH);
    let beta = 0.97 * std::f64::consts::PI * width as f64 * (1.0 - 0.5 / sigma);
    (width, beta)
}

/// Fine-grid points per axis: the smallest fast size at or above σ times
/// the box's side, and at least two kernel widths.
fn grid_size(side: usize, sigma: f64, width: usize) -> usize {
    fine_grid_size((sigma * side as f64).ceil() as usize).max(2 * width)
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
/// Gauss–Legendre quadrature `(nodes, weights)` with enough nodes for
/// double precision (4w + 40, computed once per plan).
fn kernel_transform(
    xi: f64,
    width: usize,
    beta: f64,
    (nodes, weights): &(Vec<f64>, Vec<f64>),
) -> f64 {
    let w = width as f64;
    let sum: f64 = nodes
        .iter()
        .zip(weights)
        .map(|(&z, &q)| q * kernel(z, beta) * (std::f64::consts::PI * w * xi * z).cos())
        .sum();
    0.5 * w * sum
}

/// Bytes a plan on `freqs` holds at most: per thread, two complex fine
/// grids and the spreading slabs (sized for the widest kernel), and 24
/// bytes per frequency; `None` when the box's size overflows.
pub fn nufft_memory_bytes(freqs: &FrequencyBox) -> Option<f64> {
    let len = freqs.checked_len()?;
    let threads = rayon::current_num_threads() as f64;
    let d = freqs.dim;
    let n = grid_size(freqs.side(), 2.0, MAX_WIDTH);
    let grid = (n as f64).powi(d as i32) * 16.0;
    Some(threads * (2.0 * grid + SlabLayout::bytes(n, d, MAX_WIDTH)) + len as f64 * 24.0)
}

/// Bytes a transform's scratch holds per point, besides its grids: the bin
/// order, each point's bin, and the coordinates and strengths copied in
/// bin order.
pub fn nufft_point_bytes(dim: usize) -> f64 {
    8.0 * 2.0 + 8.0 * dim as f64 + 16.0
}

/// Refuses a box whose transform would not fit in memory
/// ([`nufft_memory_bytes`]).
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

/// The smallest even 2^a·3^b·5^c ≥ `min` (sizes RustFFT handles fastest).
fn fine_grid_size(min: usize) -> usize {
    // Every even 2^a·3^b·5^c is 2·3^b·5^c times a power of two: for each
    // (b, c) with 2·3^b·5^c below `min`, the first power-of-two multiple
    // at or above it. O(log³ min) steps, so a huge box is estimated (and
    // refused) at once instead of searched number by number.
    let mut best = usize::MAX;
    let mut p3 = 2usize;
    loop {
        let mut p35 = p3;
        loop {
            let mut n = p35;
            while n < min {
                n = n.saturating_mul(2);
            }
            best = best.min(n);
            if p35 >= min {
                break;
            }
            p35 = match p35.checked_mul(5) {
                Some(v) => v,
                None => break,
            };
        }
        if p3 >= min {
            break;
        }
        p3 = match p3.checked_mul(3) {
            Some(v) => v,
            None => break,
        };
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_sizes_are_even_and_smooth() {
        assert_eq!(fine_grid_size(510), 512);
        assert_eq!(fine_grid_size(7), 8);
        assert_eq!(fine_grid_size(250), 250);
        assert_eq!(fine_grid_size(13), 16);
        assert_eq!(fine_grid_size(2 * 513), 1080);
        // Against the definition, number by number.
        for min in 1..3000 {
            let smooth = |n: usize| {
                let mut m = n;
                for p in [2, 3, 5] {
                    while m % p == 0 {
                        m /= p;
                    }
                }
                m == 1 && n % 2 == 0
            };
            let first = (min..).find(|&n| smooth(n)).unwrap();
            assert_eq!(fine_grid_size(min), first, "min = {min}");
        }
        assert!(fine_grid_size(usize::MAX / 3) >= usize::MAX / 3);
    }

    #[test]
    fn the_polynomial_kernel_reaches_every_usual_tolerance() {
        // The fast kernel must not silently fall back to exp/sqrt: for
        // ε = 1e-3 … 1e-12 a low degree fits within ε/4 (checked against φ
        // at 2001 offsets here independently of the fit's own check), for
        // both upsampling factors.
        let shapes = [1e-3, 1e-6, 1e-9, 1e-12]
            .map(|tol| (tol, 2.0))
            .into_iter()
            .chain([1e-3, 1e-6, 1e-9].map(|tol| (tol, 1.25)));
        for (tol, sigma) in shapes {
            let (w, beta) = kernel_shape(tol, sigma);
            let p = KernelPolynomial::fit(w, beta, tol).expect("a polynomial");
            assert!(
                p.degree <= w + 3,
                "tol {tol:e} sigma {sigma}: degree {}",
                p.degree
            );
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
    fn auto_upsampling_follows_the_measured_break_even() {
        // On the 512² box at ε = 1e-6, `varspec bench spectrum` measured
        // σ = 5/4 1.4× faster at 65,536 points and 1.3× slower at 1,048,576.
        let b = FrequencyBox::from_resolution(2, 512);
        assert_eq!(Upsampling::choose(&b, 1e-6, 65_536), 1.25);
        assert_eq!(Upsampling::choose(&b, 1e-6, 1_048_576), 2.0);
        // Below 1e-9 only σ = 2 reaches the tolerance.
        assert_eq!(Upsampling::choose(&b, 1e-12, 1), 2.0);
    }

    #[test]
    fn bad_tolerances_are_refused() {
        let b = FrequencyBox { dim: 2, half: 4 };
        assert!(NufftPlan::new(b, 0.0).is_err());
        assert!(NufftPlan::new(b, 1e-16).is_err());
        assert!(NufftPlan::new(b, f64::NAN).is_err());
        assert!(NufftPlan::new(b, 1e-6).is_ok());
        // σ = 5/4 stops at 1e-9 (the kernel would be wider than 16 points).
        assert!(NufftPlan::with_upsampling(b, 1e-9, Upsampling::FiveFourths).is_ok());
        assert!(NufftPlan::with_upsampling(b, 1e-10, Upsampling::FiveFourths).is_err());
        // Auto falls back to σ = 2 there.
        let auto = Upsampling::Auto { points: 10 };
        assert_eq!(
            NufftPlan::with_upsampling(b, 1e-12, auto)
                .unwrap()
                .upsampling(),
            2.0
        );
    }
}
