//! Multi-jittered sampling (Chiu, Shirley & Wang 1994, "Multi-jittered
//! sampling", Graphics Gems IV) and correlated multi-jittered sampling
//! (Kensler 2013, "Correlated multi-jittered sampling", Pixar Tech. Memo
//! 13-01), one sampler with the shuffle correlation as a parameter.
//!
//! N = m·n points on m columns and n rows. Point (i, j) — column i, row j —
//! has x in fine interval i·n + σ_i(j) and y in fine interval j·m + τ_j(i)
//! of the N intervals of each axis, with a uniform offset inside it. Any
//! permutations σ_i, τ_j keep both properties: one point per m×n cell
//! (jitter) and one per 1/N interval of each axis (N-rooks). Multi-jitter
//! shuffles every column and row independently; CMJ uses one σ for all
//! columns and one τ for all rows.

use rustfft::num_complex::Complex64;

use super::config::Config;
use super::{Sampler, SamplerError};
use crate::points::{PointSet, stratum_coord};
use crate::rng::{SetRng, permutation, uniform};
use crate::spectrum::pair::{PairSpectrum, distinct_pair_mean, geometric, uniform_char};

/// Multi-jittered N = m·n points in 2D.
#[derive(Debug, Clone)]
pub struct MultiJitter {
    columns: usize,
    rows: usize,
    correlated: bool,
}

impl MultiJitter {
    /// `columns` × `rows` strata; `correlated` selects Kensler's CMJ.
    ///
    /// # Errors
    /// As [`super::check_size`] for N = columns·rows in 2D.
    pub fn new(columns: usize, rows: usize, correlated: bool) -> Result<Self, SamplerError> {
        let n = columns.saturating_mul(rows);
        let name = if correlated { "cmj" } else { "multijitter" };
        super::check_size(name, n, 2, 2..=2)?;
        Ok(MultiJitter {
            columns,
            rows,
            correlated,
        })
    }

    /// The grid (m, n) used for N points: m = `columns` if given, else the
    /// largest divisor of N not above √N.
    pub(crate) fn grid(c: &Config) -> Result<(usize, usize), SamplerError> {
        let n = c.n;
        let m = match c.param("m") {
            "auto" => squarest_columns(n),
            text => match text.parse::<usize>() {
                Ok(m) if m >= 1 && n % m == 0 => m,
                _ => return Err(c.bad_param("m", format!("`auto` or a divisor of N = {n}"))),
            },
        };
        Ok((m, n / m))
    }

    /// Writes the set's (x, y) pairs into `out` (length 2N), point (i, j)
    /// at index j·m + i.
    pub(crate) fn fill(&self, rng: &mut SetRng, out: &mut [f64]) {
        let (m, n) = (self.columns, self.rows);
        let total = m * n;
        let shared_sigma = self.correlated.then(|| permutation(rng, n));
        let shared_tau = self.correlated.then(|| permutation(rng, m));
        for i in 0..m {
            let own;
            let sigma = match &shared_sigma {
                Some(s) => s,
                None => {
                    own = permutation(rng, n);
                    &own
                }
            };
            for (j, &s) in sigma.iter().enumerate() {
                out[2 * (j * m + i)] = stratum_coord(i * n + s as usize, uniform(rng), total);
            }
        }
        for j in 0..n {
            let own;
            let tau = match &shared_tau {
                Some(t) => t,
                None => {
                    own = permutation(rng, m);
                    &own
                }
            };
            for (i, &t) in tau.iter().enumerate() {
                out[2 * (j * m + i) + 1] = stratum_coord(j * m + t as usize, uniform(rng), total);
            }
        }
    }
}

/// The column count `m = auto` picks: the divisor of `n` nearest below √n.
fn squarest_columns(n: usize) -> usize {
    (1..=n)
        .take_while(|m| m * m <= n)
        .filter(|m| n % m == 0)
        .last()
        .unwrap_or(1)
}

pub(crate) fn multijitter_from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    let (m, n) = MultiJitter::grid(c)?;
    Ok(Box::new(MultiJitter::new(m, n, false)?))
}

pub(crate) fn cmj_from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    let (m, n) = MultiJitter::grid(c)?;
    Ok(Box::new(MultiJitter::new(m, n, true)?))
}

impl Sampler for MultiJitter {
    fn dim(&self) -> usize {
        2
    }

    fn points_per_set(&self) -> usize {
        self.columns * self.rows
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let mut coords = vec![0.0; 2 * self.points_per_set()];
        self.fill(rng, &mut coords);
        Ok(PointSet::new(2, coords).expect("stratum coordinates lie in [0,1)"))
    }

    fn pair_spectrum(&self) -> Option<&dyn PairSpectrum> {
        Some(self)
    }

    /// A grid more than 4 times longer than wide (m < √N/2): its strata
    /// are thin strips, so on a 2D integrand it converges like N-rooks
    /// (N^-1 on a disk), not like the grid's N^-1.5.
    fn caveat(&self) -> Option<String> {
        let (m, rows) = (self.columns.min(self.rows), self.columns.max(self.rows));
        (4 * m < rows).then(|| {
            let n = self.points_per_set();
            let name = if self.correlated {
                "cmj"
            } else {
                "multijitter"
            };
            let nearest = squarest_columns(n);
            if 4 * nearest < n / nearest {
                let square = (n as f64).sqrt().round() as usize;
                format!(
                    "{name} N = {n} is a {m} x {rows} grid (N has no divisor near √N): its \
                     strata are strips, it converges like N-rooks rather than a 2D grid; \
                     N = {} (or any m·n with m near √N) restores the grid",
                    square * square
                )
            } else {
                // The strips are the given m's (`--param m=8` at N = 1024).
                format!(
                    "{name} N = {n} with m = {} is a {m} x {rows} grid: its strata are strips, \
                     it converges like N-rooks rather than a 2D grid; m = {nearest} (or m = \
                     auto) gives the {nearest} x {} grid",
                    self.columns,
                    n / nearest
                )
            }
        })
    }
}

/// One axis's factors of C(ω, ω′) (the names of the `PairSpectrum` impl's doc):
/// (Q, D, c, R, U, χ(ω/cells)·conj(χ(ω′/cells))).
type AxisFactors = (
    Complex64,
    Complex64,
    Complex64,
    Complex64,
    Complex64,
    Complex64,
);

impl MultiJitter {
    /// The x factors (`cells` = m columns, `fine` = n) or the y factors
    /// (n rows, m) at the frequencies (a, b).
    fn axis_factors(&self, cells: usize, fine: usize, a: f64, b: f64) -> AxisFactors {
        let total = (self.columns * self.rows) as f64;
        let c = cells as f64;
        let d = geometric((a - b) / c, cells);
        let q = geometric(a / c, cells) * geometric(b / c, cells).conj() - d;
        let offsets = uniform_char(a / total) * uniform_char(b / total).conj();
        let r = distinct_pair_mean(a / total, b / total, fine);
        let u = geometric((a - b) / total, fine) / fine as f64;
        let coarse = uniform_char(a / c) * uniform_char(b / c).conj();
        (q, d, offsets, r, u, coarse)
    }

    fn x_factors(&self, a: f64, b: f64) -> AxisFactors {
        self.axis_factors(self.columns, self.rows, a, b)
    }

    fn y_factors(&self, a: f64, b: f64) -> AxisFactors {
        self.axis_factors(self.rows, self.columns, a, b)
    }

    /// C from the two axes' factors.
    fn combine(&self, x: &AxisFactors, y: &AxisFactors) -> Complex64 {
        let (qx, dx, cx, rx, ux, px) = *x;
        let (qy, dy, cy, ry, uy, py) = *y;
        if self.correlated {
            cx * cy * (qx * qy * rx * ry + dx * qy * rx * uy + qx * dy * ux * ry)
        } else {
            let (pair_x, pair_y) = (px * qx, py * qy);
            let (within_x, within_y) = (dx * cx * rx, dy * cy * ry);
            pair_x * pair_y + within_x * pair_y + pair_x * within_y
        }
    }
}

/// C(ω, ω′) in closed form. The x coordinates depend only on the σ shuffles
/// and x offsets, the y coordinates only on τ and the y offsets, so each
/// pair's expectation is an x factor times a y factor, and the sum over the
/// pairs (i, j) ≠ (i′, j′) splits into three cases — other column and other
/// row (A), same column (B), same row (C) — each a product of geometric
/// sums over columns, rows and fine intervals.
///
/// Multi-jitter (σ_i, τ_j independent per column and row): a point of
/// column i is uniform over the column, two points of one column sit in
/// distinct fine intervals drawn without replacement:
/// C = P_x·P_y + W_x·P_y + P_x·W_y, with P_x = χ(ω_x/m)conj(χ(ω′_x/m))·Q_x
/// (pairs of distinct columns) and W_x = D_x·χ(ω_x/N)conj(χ(ω′_x/N))·R_x
/// (pairs within a column).
///
/// CMJ (one σ, one τ): the fine interval of x depends on the row j only, so
/// two points in distinct rows have distinct σ values (R_x) and two in one
/// row share it (U_x):
/// C = c_x c_y (Q_x Q_y R_x R_y + D_x Q_y R_x U_y + Q_x D_y U_x R_y).
///
/// Here Q_x = Σ_(i≠i′) e^(2πi(ω_x i − ω′_x i′)/m), D_x = Σ_i e^(2πi(ω_x−ω′_x)i/m),
/// R_x the mean of e^(2πi(ω_x t − ω′_x t′)/N) over distinct t, t′ < n,
/// U_x = (1/n) Σ_(t<n) e^(2πi(ω_x−ω′_x)t/N), c_x = χ(ω_x/N)conj(χ(ω′_x/N)),
/// and the y terms likewise with the roles of m and n exchanged.
impl PairSpectrum for MultiJitter {
    fn points(&self) -> usize {
        self.points_per_set()
    }

    fn pair_sum(&self, w1: [f64; 2], w2: [f64; 2]) -> Complex64 {
        self.combine(&self.x_factors(w1[0], w2[0]), &self.y_factors(w1[1], w2[1]))
    }

    /// Each axis's factors once per frequency of `xs` and of `ys`, then
    /// combined: O(|xs| + |ys|) transcendental work instead of O(|xs|·|ys|).
    fn power_grid(&self, xs: &[f64], ys: &[f64]) -> Vec<f64> {
        let n = self.points_per_set() as f64;
        let fy: Vec<AxisFactors> = ys.iter().map(|&b| self.y_factors(b, b)).collect();
        let mut out = Vec::with_capacity(xs.len() * ys.len());
        for &a in xs {
            let fx = self.x_factors(a, a);
            out.extend(fy.iter().map(|y| 1.0 + self.combine(&fx, y).re / n));
        }
        out
    }
}
