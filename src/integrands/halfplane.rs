//! The indicator of the part of the unit square on one side of a line:
//! P = {x ∈ [0,1)² : (x − p)·n ≥ 0}, n = (cos θ, sin θ), p = (½,½) + offset·n.
//!
//! P is a convex polygon. Its transform follows from the divergence theorem
//! (e.g. Lee & Mittra 1983, "Fourier transform of a polygonal shape
//! function", IEEE TAP 31(1)): for k ≠ 0,
//! F(k) = i/(2π|k|²) Σ_edges (k × t_e) · sinc(π k·t_e) · e^(−2πik·m_e),
//! with t_e the edge vector (counter-clockwise), m_e its midpoint and
//! k × t = kx·ty − ky·tx. The periodic autocorrelation is a sum of four
//! overlap areas, each an axis-aligned rectangle cut by one half-plane.

use rustfft::num_complex::Complex64;

use super::{Integrand, IntegrandClass, sinc_pi};
use crate::polygon::{clip, shoelace};
use crate::spec_params::SpecValue;
use crate::spectrum::phase::exp_neg_2pi_i;

/// Half-plane ∩ unit square indicator.
#[derive(Debug, Clone)]
pub struct HalfPlane {
    angle: f64,
    offset: f64,
    n: [f64; 2],
    /// n·p: the half-plane is n·x ≥ level.
    level: f64,
    /// (midpoint, edge vector) of each non-degenerate edge, counter-clockwise.
    edges: Vec<([f64; 2], [f64; 2])>,
    area: f64,
    /// The smaller of P and its complement, (normal, level, area): c_f is
    /// the same for both (c_(1−f) = c_f), and overlaps of the smaller side
    /// do not cancel against I² (a region of area 1 − 1.1e-8 lost seven
    /// digits of its variance in overlap − I² with both near 1).
    smaller: ([f64; 2], f64, f64),
}

impl HalfPlane {
    /// The half-plane at `angle` degrees and signed `offset` ∈ [−1, 1]
    /// from the centre.
    ///
    /// # Errors
    /// [`super::IntegrandError::Value`] for a non-finite angle or an offset
    /// outside [−1, 1] (beyond, the half-plane misses or covers the square).
    pub fn new(angle: f64, offset: f64) -> Result<Self, super::IntegrandError> {
        super::require(
            angle.is_finite(),
            "halfplane",
            "angle",
            angle,
            "an angle in degrees",
        )?;
        super::require(
            offset.abs() <= 1.0,
            "halfplane",
            "offset",
            offset,
            "an offset in [-1, 1]",
        )?;
        let (s, c) = angle.to_radians().sin_cos();
        let n = [c, s];
        let level = 0.5 * (c + s) + offset;
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let polygon = clip(&square, n, level);
        let area = shoelace(&polygon);
        let complement = ([-c, -s], -level);
        let smaller = if area <= 0.5 {
            (n, level, area)
        } else {
            let area = shoelace(&clip(&square, complement.0, complement.1));
            (complement.0, complement.1, area)
        };
        let edges = (0..polygon.len())
            .map(|i| (polygon[i], polygon[(i + 1) % polygon.len()]))
            .map(|(a, b)| {
                (
                    [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])],
                    [b[0] - a[0], b[1] - a[1]],
                )
            })
            .filter(|(_, t)| t[0] != 0.0 || t[1] != 0.0)
            .collect();
        Ok(HalfPlane {
            angle,
            offset,
            n,
            level,
            edges,
            area,
            smaller,
        })
    }
}

/// Area of the rectangle [x0, x0+w] × [y0, y0+h] where n·x ≥ level, in
/// closed form: highest − n·x over the rectangle (highest its largest
/// value) is the sum of two uniform variables of widths p = |n_x|·w and
/// q = |n_y|·h, whose distribution function at t = highest − level is
/// t²/(2pq), (t − p/2)/q, 1 − (p+q−t)²/(2pq) on the three pieces (p ≤ q).
/// Measured from the highest corner, a sliver above the level is computed
/// directly (as 1 − the rest it lost seven digits at an area of 1e-8).
/// Only the middle piece divides by the larger width, so the formula stays
/// exact as p → 0 (edges at 1e-9 degrees).
fn rect_above(w: f64, h: f64, corner: [f64; 2], n: [f64; 2], level: f64) -> f64 {
    let (pw, qh) = ((n[0] * w).abs(), (n[1] * h).abs());
    let (p, q) = if pw <= qh { (pw, qh) } else { (qh, pw) };
    let highest = n[0] * corner[0] + n[1] * corner[1] + (n[0] * w).max(0.0) + (n[1] * h).max(0.0);
    let t = highest - level;
    let above = if t <= 0.0 {
        0.0
    } else if t >= p + q {
        1.0
    } else if t <= p {
        t * (t / p) / (2.0 * q)
    } else if t <= q {
        (t - 0.5 * p) / q
    } else {
        let r = p + q - t;
        1.0 - r * (r / p) / (2.0 * q)
    };
    w * h * above
}

impl Integrand for HalfPlane {
    fn dim(&self) -> usize {
        2
    }

    fn integral(&self) -> f64 {
        self.area
    }

    fn variance(&self) -> f64 {
        let a = self.smaller.2;
        a * (1.0 - a)
    }

    fn eval(&self, x: &[f64]) -> f64 {
        if x[0] * self.n[0] + x[1] * self.n[1] >= self.level {
            1.0
        } else {
            0.0
        }
    }

    fn fourier(&self, k: &[i64]) -> Complex64 {
        if k[0] == 0 && k[1] == 0 {
            return Complex64::new(self.area, 0.0);
        }
        let (kx, ky) = (k[0] as f64, k[1] as f64);
        let sum = self
            .edges
            .iter()
            .fold(Complex64::new(0.0, 0.0), |acc, (m, t)| {
                let cross = kx * t[1] - ky * t[0];
                acc + exp_neg_2pi_i(k, m) * (cross * sinc_pi(kx.mul_add(t[0], ky * t[1])))
            });
        sum * Complex64::new(0.0, 1.0 / (std::f64::consts::TAU * (kx * kx + ky * ky)))
    }

    fn autocov(&self, h: &[f64]) -> Option<f64> {
        // ∫ f(x) f(x+h) over the torus: for t = h + m ∈ (−1,1)², the overlap
        // P ∩ (P + t) is the rectangle [0,1]² ∩ ([0,1]² + t) cut by
        // n·x ≥ level + max(0, n·t).
        let h = [h[0] - h[0].floor(), h[1] - h[1].floor()];
        let (n, level, area) = self.smaller;
        let mut overlap = 0.0;
        for mx in [-1.0, 0.0] {
            for my in [-1.0, 0.0] {
                let t = [h[0] + mx, h[1] + my];
                let (x0, x1) = (t[0].max(0.0), (1.0 + t[0]).min(1.0));
                let (y0, y1) = (t[1].max(0.0), (1.0 + t[1]).min(1.0));
                if x1 > x0 && y1 > y0 {
                    let level = level + (n[0] * t[0] + n[1] * t[1]).max(0.0);
                    overlap += rect_above(x1 - x0, y1 - y0, [x0, y0], n, level);
                }
            }
        }
        Some(overlap - area * area)
    }

    fn class(&self) -> IntegrandClass {
        IntegrandClass {
            smooth: false,
            one_axis: self.n[0] == 0.0
                || self.n[1] == 0.0
                || self.n[0].abs() == 1.0
                || self.n[1].abs() == 1.0,
        }
    }

    fn spec(&self) -> String {
        format!(
            "halfplane:angle={},offset={}",
            SpecValue(self.angle),
            SpecValue(self.offset)
        )
    }
}
