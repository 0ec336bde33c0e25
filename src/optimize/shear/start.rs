//! Where the shear search starts: read off the integrand's spectrum, the
//! way the seed reads a light field's shear (Singh & Jarosz 2017, §3;
//! Soler et al. 2009). A layer at shear c puts its energy on the line
//! k_u = c·k_x of the (k_x, k_u) plane (and k_v = c·k_y of (k_y, k_v)), and
//! the shear that flattens it is a = −c.
//!
//! - **Principal direction**: the leading eigenvector (k_x, k_u) of the
//!   energy's second-moment matrix M = Σ E(k)·k kᵀ over the plane's
//!   frequencies, a symmetric 2×2 eigenproblem; its slope is c. Only the
//!   strongest frequencies holding [`CORE`] of the plane's energy enter M,
//!   so the sinc² side lobes a lens aperture spreads along k_u do not tilt
//!   it.
//! - **One sheared plane or two**: a single layer f = g(x + c(u − ½)) with
//!   u on [0, 1) puts, in every column k_x, exactly the profile
//!   sinc²(π(k_u − c·k_x)) times the column's energy. The misfit of that
//!   one-line model, min over s of
//!   Σ_(k_x≠0) Σ_(k_u) |E(k) − E_col(k_x)·sinc²(π(k_u − s·k_x))| / Σ E,
//!   is near 0 for one layer (only the box edge truncates the profile) and
//!   large when the energy splits between two directions: the seed's
//!   double wedge, where no single shear fits both layers (its lines are
//!   then found as below). Where the line
//!   leaves the box the model keeps the profile's share inside it, and the
//!   best slope is refined by Brent's method between scan points (a flat
//!   spectrum, a hairline aperture's, weighs every column alike, and a
//!   slope off by a scan step's 0.002 misses the far columns' peaks). Above
//!   [`DOUBLE_WEDGE_MISFIT`] the spectrum is called a double wedge; one
//!   line is the slope whose band (|k_u − s·k_x| < 1) holds the largest
//!   mean share of the energy of the columns it crosses inside the box, the
//!   other the slope holding most of the columns where its band lies apart
//!   from the first's; the line whose band holds more energy is the first.

use nalgebra::{Matrix2, SymmetricEigen};

use argmin::core::{CostFunction, Error as ArgminError, Executor, State};
use argmin::solver::brent::BrentOpt;

use super::MAX_SHEAR_RANGE;
use crate::integrands::Integrand;

/// Share of a plane's energy (largest frequencies first) in the moment
/// matrix.
const CORE: f64 = 0.9;
/// Misfit of the one-line model above which the spectrum is a double
/// wedge (the misfit ranges over [0, 2]; tests/optimize_shear.rs measures
/// single layers and two-layer mixtures on either side of it).
const DOUBLE_WEDGE_MISFIT: f64 = 0.1;
/// Columns holding at most this share of the strongest column's energy
/// (a zero of the aperture's spectrum, or underflow) do not vote on a
/// double wedge's lines.
const COLUMN_FLOOR: f64 = 1e-12;
/// Slopes closer than this are one direction.
const MIN_SEPARATION: f64 = 0.15;
/// Slope resolution of the line scan (finer slopes come from Brent's
/// method between scan points).
const SLOPE_STEP: f64 = 0.005;
/// Step of the first scan for a double wedge's lines over every slope.
const COARSE_SLOPE_STEP: f64 = 0.04;
/// The steepest slope the analysis scans: the defocus integrand's |c| ≤ 16,
/// and at 16 a line leaves the box |k|∞ ≤ 64 by k_x = 4. (A vertical
/// principal direction, a symmetric double wedge's, would otherwise widen
/// the scan to the search's limit of 64 and coarsen its step.)
const MAX_SLOPE: f64 = 16.0;
/// Most scan points on each side of slope 0: beyond
/// [`SLOPE_STEP`]·[`MAX_SCAN`] the scan's step widens.
const MAX_SCAN: f64 = 400.0;

/// The spectrum's directions in one plane, (k_x, k_u) or (k_y, k_v).
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneDirections {
    /// Slope k_u/k_x of the principal eigenvector.
    pub principal: f64,
    /// Ratio of the smaller to the larger eigenvalue of M (0 for a line).
    pub eigenvalue_ratio: f64,
    /// Slopes of the lines holding the energy: one, or two for a double
    /// wedge (strongest first).
    pub lines: Vec<f64>,
    /// Share of the energy within the first line's band.
    pub first_line_share: f64,
    /// Share within the second line's band, outside the first's.
    pub second_line_share: f64,
    /// Misfit of the best one-line model (0 for a single lens layer).
    pub one_line_misfit: f64,
}

/// What the spectrum says about the shear.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralStart {
    /// The (k_x, k_u) and (k_y, k_v) planes.
    pub planes: [PlaneDirections; 2],
    /// The initial shear (a, b) = −(principal slopes).
    pub shear: [f64; 2],
    /// Whether the energy splits between two directions in either plane.
    pub double_wedge: bool,
}

impl SpectralStart {
    /// The shear of each plane's first (strongest) line: −c for a single
    /// defocus layer, where the principal direction of the moments is
    /// tilted by the aperture's side lobes.
    pub fn line_shear(&self) -> [f64; 2] {
        let [x, y] = &self.planes;
        [shear_of(x.lines[0]), shear_of(y.lines[0])]
    }

    /// Shears worth trying first: the principal one and each line's.
    pub fn candidates(&self) -> Vec<[f64; 2]> {
        let mut out = vec![self.shear];
        let [x, y] = &self.planes;
        for &sx in &x.lines {
            for &sy in &y.lines {
                out.push([shear_of(sx), shear_of(sy)]);
            }
        }
        out
    }
}

/// The shear that flattens a line of slope k_u/k_x = `slope`: −slope,
/// written 0 − slope so that a zero slope gives +0, not −0, in the output.
fn shear_of(slope: f64) -> f64 {
    0.0 - slope
}

/// Reads the directions of a 4D integrand's spectrum on the slices
/// k_y = k_v = 0 and k_x = k_u = 0 of the box |k|∞ ≤ `half`: slopes in
/// [−`range`, `range`], widened to hold the principal direction (up to
/// [`MAX_SLOPE`]), so that the analysis describes the spectrum whatever
/// range the search is given.
pub fn spectral_start(f: &dyn Integrand, half: i64, range: f64) -> SpectralStart {
    let plane = |axis: usize| {
        let side = (2 * half + 1) as usize;
        let mut grid = vec![0.0; side * side];
        for (i, k1) in (-half..=half).enumerate() {
            for (j, k2) in (-half..=half).enumerate() {
                if k1 == 0 && k2 == 0 {
                    continue;
                }
                let mut k = [0i64; 4];
                k[axis] = k1;
                k[axis + 2] = k2;
                grid[i * side + j] = f.fourier(&k).norm_sqr();
            }
        }
        directions(&grid, half, range)
    };
    let planes = [plane(0), plane(1)];
    let shear = [shear_of(planes[0].principal), shear_of(planes[1].principal)];
    let double_wedge = planes.iter().any(|p| p.lines.len() > 1);
    SpectralStart {
        planes,
        shear,
        double_wedge,
    }
}

/// Principal direction and lines of one plane's energy E(k₁, k₂) on the
/// box |k|∞ ≤ `half` (row k₁, column k₂; the origin holds 0).
fn directions(grid: &[f64], half: i64, range: f64) -> PlaneDirections {
    let side = (2 * half + 1) as usize;
    let mut energy: Vec<(f64, f64, f64)> = Vec::new();
    for (i, k1) in (-half..=half).enumerate() {
        for (j, k2) in (-half..=half).enumerate() {
            let e = grid[i * side + j];
            if e > 0.0 {
                energy.push((k1 as f64, k2 as f64, e));
            }
        }
    }
    energy.sort_by(|a, b| b.2.total_cmp(&a.2));
    let total: f64 = energy.iter().map(|e| e.2).sum();
    let mut moments = Matrix2::zeros();
    let mut kept = 0.0;
    for &(k1, k2, e) in &energy {
        if kept >= CORE * total {
            break;
        }
        kept += e;
        moments += Matrix2::new(k1 * k1, k1 * k2, k1 * k2, k2 * k2) * e;
    }
    let eigen = SymmetricEigen::new(moments);
    let (big, small) = if eigen.eigenvalues[0] >= eigen.eigenvalues[1] {
        (0, 1)
    } else {
        (1, 0)
    };
    let v = eigen.eigenvectors.column(big);
    let principal = if v[0].abs() * MAX_SHEAR_RANGE >= v[1].abs() {
        v[1] / v[0]
    } else {
        MAX_SHEAR_RANGE.copysign(v[1] * v[0])
    };
    let limit = range.max(1.25 * principal.abs() + 0.1).min(MAX_SLOPE);
    let eigenvalue_ratio = if eigen.eigenvalues[big] > 0.0 {
        (eigen.eigenvalues[small] / eigen.eigenvalues[big]).max(0.0)
    } else {
        0.0
    };

    // Columns k₁ ≠ 0 (on k₁ = 0 every slope passes through the same points).
    let columns: Vec<(f64, &[f64], f64)> = (-half..=half)
        .enumerate()
        .filter(|&(_, k1)| k1 != 0)
        .map(|(i, k1)| {
            let column = &grid[i * side..(i + 1) * side];
            (k1 as f64, column, column.iter().sum::<f64>())
        })
        .collect();
    let off_total: f64 = columns.iter().map(|c| c.2).sum();
    let step = SLOPE_STEP.max(limit / MAX_SCAN);
    let steps = (limit / step).round() as i64;
    let slopes: Vec<f64> = (-steps..=steps).map(|i| i as f64 * step).collect();
    if off_total <= 0.0 {
        return PlaneDirections {
            principal,
            eigenvalue_ratio,
            lines: vec![0.0],
            first_line_share: 0.0,
            second_line_share: 0.0,
            one_line_misfit: 0.0,
        };
    }
    let misfit = |s: f64| -> f64 {
        let mut total = 0.0;
        for &(k1, column, sum) in &columns {
            let profile = in_box_profile(s * k1, half);
            for (&e, &p) in column.iter().zip(&profile) {
                total += (e - sum * p).abs();
            }
        }
        total / off_total
    };
    let in_band = |s: f64, k1: f64, k2: f64| (k2 - s * k1).abs() < 1.0;
    let share = |s: f64, exclude: Option<f64>| -> f64 {
        let mut captured = 0.0;
        for &(k1, column, _) in &columns {
            for (j, &e) in column.iter().enumerate() {
                let k2 = j as f64 - half as f64;
                if in_band(s, k1, k2) && exclude.is_none_or(|x| !in_band(x, k1, k2)) {
                    captured += e;
                }
            }
        }
        captured / off_total
    };
    let scanned = slopes
        .iter()
        .map(|&s| (s, misfit(s)))
        .fold(
            (0.0, f64::INFINITY),
            |acc, c| if c.1 < acc.1 { c } else { acc },
        );
    let (fitted, one_line_misfit) = refine_slope(&misfit, scanned, step, limit);
    // A line's hold on the columns: the mean over columns of the share of
    // each column's energy within the band, counting only columns where the
    // band lies apart from `other`'s (|s − other|·|k₁| ≥ 2). Columns weigh
    // alike: near k₁ = 0, where most energy lies, a band of width 2 spans
    // every slope within 1/|k₁| and two close layers share their cells; the
    // far columns tell the slopes apart (energy-weighted shares read layers
    // at 0.37 and 0.1 as 0.37 and −0.015, at 0.6 and 0.3 as 0.3 and −1.015).
    let peak = columns.iter().map(|c| c.2).fold(0.0, f64::max);
    let hold = |s: f64, other: Option<f64>| -> f64 {
        let (mut total, mut counted) = (0.0, 0usize);
        for &(k1, column, sum) in &columns {
            // Columns where the band has left the box do not vote (a steep
            // layer scored 0 there and lost the first place to a shallow
            // one of a third of its energy).
            if sum <= COLUMN_FLOOR * peak
                || (s * k1).abs() > half as f64 + 1.0
                || other.is_some_and(|o| (s - o).abs() * k1.abs() < 2.0)
            {
                continue;
            }
            let captured: f64 = column
                .iter()
                .enumerate()
                .filter(|&(j, _)| in_band(s, k1, j as f64 - half as f64))
                .map(|(_, &e)| e)
                .sum();
            total += captured / sum;
            counted += 1;
        }
        if counted > 0 {
            total / counted as f64
        } else {
            0.0
        }
    };
    // One line: the fitted slope. A double wedge: the fit lies between the
    // layers, so one line is the slope holding the columns best, the other
    // the one holding best the columns where it lies apart from the first,
    // each sought over every slope the analysis reads (±16), not only the
    // range the fit scanned (a second layer at c = 4 beside a strong 0.5
    // read as 0.645); the one whose band holds more energy (the strongest
    // layer) is reported first.
    let double_wedge = one_line_misfit > DOUBLE_WEDGE_MISFIT;
    let best_hold = |other: Option<f64>| {
        most_held(&|s| {
            if other.is_some_and(|o| (s - o).abs() < MIN_SEPARATION) {
                f64::NEG_INFINITY
            } else {
                hold(s, other)
            }
        })
    };
    let s1 = if double_wedge {
        best_hold(None)
    } else {
        fitted
    };
    let s2 = best_hold(Some(s1));
    let (share1, share2) = (share(s1, None), share(s2, None));
    let (s1, s2, first_line_share) = if double_wedge && share2 > share1 {
        (s2, s1, share2)
    } else {
        (s1, s2, share1)
    };
    let second_line_share = share(s2, Some(s1));
    let lines = if double_wedge { vec![s1, s2] } else { vec![s1] };
    PlaneDirections {
        principal,
        eigenvalue_ratio,
        lines,
        first_line_share,
        second_line_share,
        one_line_misfit,
    }
}

/// The slope in [−[`MAX_SLOPE`], [`MAX_SLOPE`]] of the largest `score`:
/// a scan at [`COARSE_SLOPE_STEP`], then one at [`SLOPE_STEP`] within a
/// coarse step of the best (a band's hold falls off over ~1/|k₁| of slope
/// from its layer's, so the coarse scan lands on the peak's flank).
fn most_held(score: &dyn Fn(f64) -> f64) -> f64 {
    let best = |slopes: &mut dyn Iterator<Item = f64>| {
        slopes
            .map(|s| (s, score(s)))
            .fold(
                (0.0, f64::NEG_INFINITY),
                |acc, c| if c.1 > acc.1 { c } else { acc },
            )
            .0
    };
    let coarse = (MAX_SLOPE / COARSE_SLOPE_STEP).round() as i64;
    let centre = best(&mut (-coarse..=coarse).map(|i| i as f64 * COARSE_SLOPE_STEP));
    let fine = (COARSE_SLOPE_STEP / SLOPE_STEP).round() as i64;
    best(
        &mut (-fine..=fine)
            .map(|i| ((centre / SLOPE_STEP).round() + i as f64) * SLOPE_STEP)
            .filter(|s| s.abs() <= MAX_SLOPE),
    )
}

/// The misfit as an argmin cost of the slope.
struct Misfit<'m>(&'m dyn Fn(f64) -> f64);

impl CostFunction for Misfit<'_> {
    type Param = f64;
    type Output = f64;

    fn cost(&self, s: &f64) -> Result<f64, ArgminError> {
        Ok((self.0)(*s))
    }
}

/// The slope of least `misfit` within one scan `step` of the scan's best
/// `(slope, misfit)`, by Brent's method (the scan's best if Brent's method
/// finds nothing lower).
fn refine_slope(
    misfit: &dyn Fn(f64) -> f64,
    (s, value): (f64, f64),
    step: f64,
    limit: f64,
) -> (f64, f64) {
    let (lo, hi) = ((s - step).max(-limit), (s + step).min(limit));
    let brent = BrentOpt::new(lo, hi).set_tolerance(1e-6, 1e-9);
    let refined = Executor::new(Misfit(misfit), brent)
        .configure(|state| state.max_iters(40))
        .run()
        .ok()
        .and_then(|r| r.state().get_best_param().copied());
    match refined.map(|t| (t, misfit(t))) {
        Some((t, v)) if v < value => (t, v),
        _ => (s, value),
    }
}

/// The profile sinc²(π(k₂ − x)) over the integers k₂ of [−half, half],
/// scaled to sum to 1 there (a line that leaves the box keeps its in-box
/// share). On the integers sin²(π(k₂ − x)) is the same for every k₂, so the
/// scaled profile is 1/(k₂ − x)² over its sum, with no division by a
/// vanishing sine; at an integer x it is 1 at k₂ = x, or 0 everywhere when
/// x lies outside the box (the line's energy is then all outside).
fn in_box_profile(x: f64, half: i64) -> Vec<f64> {
    let nearest = x.round();
    if (x - nearest).abs() < 1e-9 {
        return (-half..=half)
            .map(|k2| if k2 as f64 == nearest { 1.0 } else { 0.0 })
            .collect();
    }
    let raw: Vec<f64> = (-half..=half).map(|k2| (k2 as f64 - x).powi(-2)).collect();
    let total: f64 = raw.iter().sum();
    raw.into_iter().map(|r| r / total).collect()
}
