//! Reference integrands with exact integral, Fourier coefficients and (in
//! 2D) periodic autocovariance (docs/mathematics.md).
//!
//! Every integrand is a function on the unit torus; F_f(k) are its Fourier
//! coefficients, P_f(k) = |F_f(k)|², and
//! c_f(h) = ∫ f(x) f(x+h) dx − I² = Σ_(k≠0) P_f(k) e^(2πik·h) its periodic
//! autocovariance, evaluated in closed form where the geometry allows, never
//! as a difference of nearly equal large numbers.

mod cos;
mod defocus;
mod disk;
mod gaussian;
mod halfplane;
mod layers;
mod light_field;
mod plane_power;
mod rect;
mod spec;

pub use cos::Cosine;
pub use defocus::{Defocus, DefocusShape};
pub use disk::Disk;
pub use gaussian::Gaussian;
pub use halfplane::HalfPlane;
pub use layers::Layers;
pub use light_field::{LightField, PlaneWave, energy as light_field_energy};
pub use plane_power::{check_plane, plane_power};
pub use rect::Rect;
pub use spec::{INTEGRANDS, IntegrandInfo, parse, scene_pixel_rest};

use rustfft::num_complex::Complex64;

/// A test integrand on the unit torus.
pub trait Integrand: Send + Sync {
    /// Dimension d.
    fn dim(&self) -> usize;
    /// The exact integral I = F_f(0).
    fn integral(&self) -> f64;
    /// The variance of f under uniform sampling, ∫f² − I² = c_f(0) =
    /// Σ_(k≠0) P_f(k), computed without cancellation.
    fn variance(&self) -> f64;
    /// f(x) for x in [0,1)^d.
    fn eval(&self, x: &[f64]) -> f64;
    /// f(x + s mod 1) for x and a shift s in [0,1)^d (at most 4
    /// coordinates), the shift-randomized estimator's evaluation (Pilleboue
    /// et al. 2015, §3), with the sum taken exactly where rounding it would
    /// show: the cosine at |k| up to 2^40 turns k·2⁻⁵³ of a period over the
    /// rounding of x + s (a spread of 1e-4 turn between points whose exact
    /// phases agree), so it reduces the phases of x and s apart.
    fn eval_shifted(&self, x: &[f64], s: &[f64]) -> f64 {
        debug_assert!(x.len() <= 4 && s.len() == x.len(), "a point and its shift");
        let mut y = [0.0; 4];
        for ((yj, a), b) in y.iter_mut().zip(x).zip(s) {
            let v = a + b;
            *yj = if v >= 1.0 { v - 1.0 } else { v };
        }
        self.eval(&y[..x.len().min(4)])
    }
    /// The Fourier coefficient F_f(k) = ∫ f(x) e^(−2πik·x) dx.
    fn fourier(&self, k: &[i64]) -> Complex64;
    /// False when [`Integrand::fourier`] has no closed form (it then
    /// returns NaN), e.g. a scene pixel: the Fourier predictors refuse such
    /// an integrand instead of summing NaN.
    fn has_fourier(&self) -> bool {
        true
    }
    /// The periodic autocovariance c_f(h), or `None` where no closed form is
    /// implemented (4D integrands).
    fn autocov(&self, h: &[f64]) -> Option<f64>;
    /// c_f(x − y) for two points `x` and `y` (of at most 4 coordinates),
    /// with the difference taken exactly where rounding it would show: the
    /// cosine at |k| up to 2^40 turns k·2⁻⁵⁴ of a period over the rounding
    /// of x − y (1.5e-4 relative error in a variance at k = 2^40), so it
    /// reduces the phases of x and y apart. Passing `y = −lo` evaluates
    /// c_f at hi + lo, a point known to more than a double's precision (a
    /// lattice point p/q and its rounding remainder).
    fn autocov_between(&self, x: &[f64], y: &[f64]) -> Option<f64> {
        let mut h = [0.0; 4];
        for ((hk, a), b) in h.iter_mut().zip(x).zip(y) {
            *hk = a - b;
        }
        self.autocov(&h[..x.len().min(4)])
    }
    /// True when [`Integrand::autocov`] has a closed form: the exact spatial
    /// form of the variance applies (and the lattice search).
    fn has_autocov(&self) -> bool {
        self.autocov(&vec![0.0; self.dim()]).is_some()
    }
    /// Radius beyond which c_f(h) = −I² exactly (the autocorrelation has
    /// compact support there), if any: lets the spatial predictor visit only
    /// close pairs and count the rest exactly.
    fn autocov_support(&self) -> Option<f64> {
        None
    }
    /// Smoothness and axis structure, for the theoretical convergence rate.
    fn class(&self) -> IntegrandClass;
    /// The canonical spec string, e.g. `disk:r=0.3,cx=0.5,cy=0.5`.
    fn spec(&self) -> String;
    /// The light-field form of a 4D integrand ([`LightField`]), if it has
    /// one: what the shear search evaluates exactly.
    fn light_field(&self) -> Option<&dyn LightField> {
        None
    }
}

/// What the convergence theory needs to know of an integrand
/// (Pilleboue et al. 2015, Table 1; docs/mathematics.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IntegrandClass {
    /// C^∞ (Gaussian, cosine) rather than discontinuous (indicators).
    pub smooth: bool,
    /// Varies along one coordinate axis only (e.g. `box:w=1`): N-rooks then
    /// behaves like 1D jitter.
    pub one_axis: bool,
}

/// What is wrong with an integrand spec.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IntegrandError {
    /// No integrand of that name.
    #[error("unknown integrand `{name}`{suggestion}; known: {known}")]
    Unknown {
        /// The name.
        name: String,
        /// " (did you mean `…`?)" or empty ([`crate::suggest`]).
        suggestion: String,
        /// Known names.
        known: String,
    },
    /// A scene pixel given where a closed-form integrand is needed.
    #[error(
        "`scene:` pixels are integrands of predict, spectrum and optimize shear only (their values \
         come from rendering: no closed form and no family to draw from); here use one of: {known}"
    )]
    ScenePixel {
        /// Known names.
        known: String,
    },
    /// A key the integrand does not take.
    #[error("{integrand}: unknown parameter `{key}`{suggestion}; its parameters: {known}")]
    UnknownKey {
        /// Integrand name.
        integrand: &'static str,
        /// The key.
        key: String,
        /// " (did you mean `…`?)" or empty ([`crate::suggest`]).
        suggestion: String,
        /// Its keys.
        known: String,
    },
    /// A malformed `key=value` list.
    #[error("integrand spec `{spec}`: {reason}")]
    Syntax {
        /// The whole spec.
        spec: String,
        /// What is wrong with its list.
        reason: crate::spec_params::ParamListError,
    },
    /// A key given twice.
    #[error("integrand spec `{spec}`: `{key}` is given twice (each parameter once)")]
    Repeated {
        /// The whole spec.
        spec: String,
        /// The repeated key.
        key: String,
    },
    /// A value out of its domain.
    #[error("{integrand}: {key}={value} is invalid: expected {expected}")]
    Value {
        /// Integrand name.
        integrand: &'static str,
        /// The key.
        key: &'static str,
        /// The value text.
        value: String,
        /// What is accepted.
        expected: String,
    },
}

/// x reduced to its nearest periodic image, in [−½, ½].
#[inline]
/// `Ok` when `ok`, else [`IntegrandError::Value`] naming the integrand,
/// the key, the value and what was expected: the constructors' checks.
pub(crate) fn require(
    ok: bool,
    integrand: &'static str,
    key: &'static str,
    value: impl std::fmt::Debug,
    expected: &str,
) -> Result<(), IntegrandError> {
    if ok {
        return Ok(());
    }
    Err(IntegrandError::Value {
        integrand,
        key,
        value: format!("{value:?}"),
        expected: expected.into(),
    })
}

pub(crate) fn nearest_image(x: f64) -> f64 {
    x - x.round()
}

/// The periodic autocorrelation ∫ f(x) f(x+h) dx of a shape that overlaps
/// its translates only within one period: the sum, over the images
/// t = h + m (h reduced to its nearest image, m ∈ {−1, 0, 1}²), of the
/// overlap area of the shape with itself shifted by t.
#[inline]
pub(crate) fn sum_over_images(h: &[f64], overlap: impl Fn([f64; 2]) -> f64) -> f64 {
    let (hx, hy) = (nearest_image(h[0]), nearest_image(h[1]));
    let mut total = 0.0;
    for mx in -1..=1 {
        for my in -1..=1 {
            total += overlap([hx + mx as f64, hy + my as f64]);
        }
    }
    total
}

pub(crate) use crate::spectrum::phase::sinc_pi;
