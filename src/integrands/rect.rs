//! The indicator of a rotated rectangle (w along (cos θ, sin θ), h along
//! (−sin θ, cos θ)), centred at c, periodized.
//!
//! In the rectangle's frame the transform separates: F(k) = w·h·
//! sinc(π w k·e₁)·sinc(π h k·e₂)·e^(−2πik·c), and the overlap of the
//! rectangle with its translate by t is (w − |t·e₁|)₊(h − |t·e₂|)₊.
//! An axis-aligned rectangle is a product g(x)·k(y) of two arc indicators,
//! so its autocovariance (the autocorrelation less I²) is
//! w_x²·c_k + w_y²·c_g + c_g·c_k, each arc's c taken on the
//! shorter of the arc and its complement: a box of area 1 − 1e-8 kept
//! its digits only so (overlaps near 1 less A² near 1 lost eight).

use rustfft::num_complex::Complex64;

use super::{Integrand, IntegrandClass, nearest_image, sinc_pi, sum_over_images};
use crate::spec_params::SpecValue;
use crate::spectrum::phase::exp_neg_2pi_i;

/// Periodized rotated-rectangle indicator.
#[derive(Debug, Clone)]
pub struct Rect {
    w: f64,
    h: f64,
    centre: [f64; 2],
    angle: f64,
    e1: [f64; 2],
    e2: [f64; 2],
}

impl Rect {
    /// A w × h rectangle at `angle` degrees centred at c.
    ///
    /// # Errors
    /// A description if the rectangle overlaps its own periodic images
    /// (its bounding box exceeds the unit square), where an indicator of the
    /// union and the sum of images would differ.
    pub fn new(w: f64, h: f64, centre: [f64; 2], angle: f64) -> Result<Self, String> {
        // Exact axes at multiples of 90° (sin 180° is 1.2e-16, not 0), so
        // that axis-aligned boxes take the separable form below.
        let (s, c) = match angle.rem_euclid(360.0) {
            0.0 => (0.0, 1.0),
            90.0 => (1.0, 0.0),
            180.0 => (0.0, -1.0),
            270.0 => (-1.0, 0.0),
            _ => angle.to_radians().sin_cos(),
        };
        let (e1, e2) = ([c, s], [-s, c]);
        let extent = [w * c.abs() + h * s.abs(), w * s.abs() + h * c.abs()];
        if extent.iter().any(|&e| e > 1.0 + 1e-12) {
            return Err(format!(
                "an angle at which the {w} x {h} box fits the unit square without overlapping its periodic images \
                 (its bounding box is {:.4} x {:.4})",
                extent[0], extent[1]
            ));
        }
        Ok(Rect {
            w,
            h,
            centre,
            angle,
            e1,
            e2,
        })
    }

    pub(crate) fn boxed(self) -> Box<dyn Integrand> {
        Box::new(self)
    }

    fn area(&self) -> f64 {
        self.w * self.h
    }

    /// The side lengths along x and y when the rectangle is axis-aligned.
    fn axis_widths(&self) -> Option<[f64; 2]> {
        if self.e1[1] == 0.0 {
            Some([self.w, self.h])
        } else if self.e1[0] == 0.0 {
            Some([self.h, self.w])
        } else {
            None
        }
    }

    fn contains(&self, d: [f64; 2]) -> bool {
        let u = d[0] * self.e1[0] + d[1] * self.e1[1];
        let v = d[0] * self.e2[0] + d[1] * self.e2[1];
        u.abs() <= 0.5 * self.w && v.abs() <= 0.5 * self.h
    }
}

impl Integrand for Rect {
    fn dim(&self) -> usize {
        2
    }

    fn integral(&self) -> f64 {
        self.area()
    }

    fn variance(&self) -> f64 {
        self.area() * (1.0 - self.area())
    }

    fn eval(&self, x: &[f64]) -> f64 {
        let d = [
            nearest_image(x[0] - self.centre[0]),
            nearest_image(x[1] - self.centre[1]),
        ];
        let hit = (-1..=1)
            .any(|mx| (-1..=1).any(|my| self.contains([d[0] + mx as f64, d[1] + my as f64])));
        if hit { 1.0 } else { 0.0 }
    }

    fn fourier(&self, k: &[i64]) -> Complex64 {
        let (kx, ky) = (k[0] as f64, k[1] as f64);
        let u = self.w * kx.mul_add(self.e1[0], ky * self.e1[1]);
        let v = self.h * kx.mul_add(self.e2[0], ky * self.e2[1]);
        exp_neg_2pi_i(k, &self.centre) * (self.area() * sinc_pi(u) * sinc_pi(v))
    }

    fn autocov(&self, h: &[f64]) -> Option<f64> {
        if let Some([wx, wy]) = self.axis_widths() {
            let (cg, ck) = (arc_autocov(wx, h[0]), arc_autocov(wy, h[1]));
            return Some((wx * wx).mul_add(ck, (wy * wy).mul_add(cg, cg * ck)));
        }
        let overlap = sum_over_images(h, |t| {
            let a = self.w - (t[0] * self.e1[0] + t[1] * self.e1[1]).abs();
            let b = self.h - (t[0] * self.e2[0] + t[1] * self.e2[1]).abs();
            if a > 0.0 && b > 0.0 { a * b } else { 0.0 }
        });
        Some(overlap - self.area() * self.area())
    }

    fn autocov_support(&self) -> Option<f64> {
        Some(self.w.hypot(self.h))
    }

    fn class(&self) -> IntegrandClass {
        // A full-width band (w or h = 1 along an axis) varies across one axis only.
        IntegrandClass {
            smooth: false,
            one_axis: self.axis_widths().is_some() && (self.w == 1.0 || self.h == 1.0),
        }
    }

    fn spec(&self) -> String {
        format!(
            "box:w={},h={},cx={},cy={},angle={}",
            SpecValue(self.w),
            SpecValue(self.h),
            SpecValue(self.centre[0]),
            SpecValue(self.centre[1]),
            SpecValue(self.angle)
        )
    }
}

/// The autocovariance of an arc of length w on the unit circle at lag t:
/// its periodic overlap (w − |t|)₊ + (|t| − (1 − w))₊ (t reduced to
/// [−½, ½]) less w², on the arc of length min(w, 1 − w), which has the same
/// autocovariance (c_(1−g) = c_g) and no cancellation near w = 1.
fn arc_autocov(w: f64, t: f64) -> f64 {
    let t = nearest_image(t).abs();
    let w = if w > 0.5 { 1.0 - w } else { w };
    (w - t).max(0.0) + (t - (1.0 - w)).max(0.0) - w * w
}
