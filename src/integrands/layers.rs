//! Two defocused layers in one pixel: the same 2D shape g at two depths,
//! f = (1 − μ)·g(x + c₁(u−½), y + c₁(v−½)) plus μ·g(x + c₂(u−½), y + c₂(v−½)).
//! Its spectrum lies on two sheared planes, k_u = c₁k_x and k_u = c₂k_x: the
//! "double wedge" of an occlusion edge (Soler et al. 2009; Singh & Jarosz
//! 2017, §6), where no single shear fits both layers.

use std::sync::OnceLock;

use rustfft::num_complex::Complex64;

use super::{Defocus, DefocusShape, Integrand, IntegrandClass, LightField, sinc_pi};
use crate::spec_params::SpecValue;

/// Frequencies per axis of the series for the layers' cross term.
const CROSS_HALF: i64 = 256;

/// Two defocus layers of one shape, mixed with weights 1 − μ and μ.
pub struct Layers {
    layers: [Defocus; 2],
    mix: f64,
    variance: OnceLock<f64>,
}

impl Layers {
    /// Shape `shape` of `size` at shears `c1` and `c2`, the second with
    /// weight `mix` ∈ [0, 1].
    ///
    /// # Errors
    /// As [`Defocus::new`]; a `mix` outside [0, 1].
    pub fn new(
        shape: DefocusShape,
        size: f64,
        c1: f64,
        c2: f64,
        mix: f64,
    ) -> Result<Self, super::IntegrandError> {
        super::require(
            (0.0..=1.0).contains(&mix),
            "layers",
            "mix",
            mix,
            "a weight in [0, 1]",
        )?;
        Ok(Layers {
            layers: [
                Defocus::new(shape, size, c1)?,
                Defocus::new(shape, size, c2)?,
            ],
            mix,
            variance: OnceLock::new(),
        })
    }

    fn weights(&self) -> [f64; 2] {
        [1.0 - self.mix, self.mix]
    }

    /// ∫∫ c_g(Δc·(u − ½, v − ½)) du dv, the covariance of the two layers:
    /// with c_g(h) = Σ_(k≠0) |G(k)|² e^(2πik·h) and
    /// ∫₀¹ e^(2πiΔc k(u−½)) du = sinc(πΔc k), it is
    /// Σ_(k≠0) |G(k)|²·sinc(πΔc k_x)·sinc(πΔc k_y), summed over |k|∞ ≤ 256.
    /// The omitted terms are bounded by the Parseval tail of g's energy times
    /// the largest |sinc·sinc| beyond the box, 1/(π|Δc|·256) or less: below
    /// 1e-6 of var g for the shapes and |Δc| ≥ 0.05 the parser allows.
    fn cross_covariance(&self) -> f64 {
        let dc = self.layers[1].shear() - self.layers[0].shear();
        let g = self.layers[0].shape();
        let mut total = crate::sum::NeumaierSum::default();
        for kx in -CROSS_HALF..=CROSS_HALF {
            for ky in -CROSS_HALF..=CROSS_HALF {
                if kx == 0 && ky == 0 {
                    continue;
                }
                let weight = sinc_pi(dc * kx as f64) * sinc_pi(dc * ky as f64);
                total.add(g.fourier(&[kx, ky]).norm_sqr() * weight);
            }
        }
        total.value()
    }
}

impl Integrand for Layers {
    fn dim(&self) -> usize {
        4
    }

    fn integral(&self) -> f64 {
        self.layers[0].integral()
    }

    /// ∫f² − I² = Σ_(t,t′) w_t w_t′ ∫∫ c_g((c_t′ − c_t)·((u,v) − ½)) du dv:
    /// var g on the diagonal, the cross covariance off it.
    fn variance(&self) -> f64 {
        *self.variance.get_or_init(|| {
            let [w1, w2] = self.weights();
            (w1 * w1 + w2 * w2) * self.layers[0].variance()
                + 2.0 * w1 * w2 * self.cross_covariance()
        })
    }

    fn eval(&self, x: &[f64]) -> f64 {
        let [w1, w2] = self.weights();
        w1 * self.layers[0].eval(x) + w2 * self.layers[1].eval(x)
    }

    fn fourier(&self, k: &[i64]) -> Complex64 {
        let [w1, w2] = self.weights();
        self.layers[0].fourier(k) * w1 + self.layers[1].fourier(k) * w2
    }

    fn autocov(&self, _h: &[f64]) -> Option<f64> {
        None
    }

    fn class(&self) -> IntegrandClass {
        self.layers[0].class()
    }

    fn spec(&self) -> String {
        format!(
            "layers:shape={},size={},c1={},c2={},mix={}",
            self.layers[0].shape_name(),
            SpecValue(self.layers[0].size()),
            SpecValue(self.layers[0].shear()),
            SpecValue(self.layers[1].shear()),
            SpecValue(self.mix)
        )
    }

    fn light_field(&self) -> Option<&dyn LightField> {
        Some(self)
    }
}

impl LightField for Layers {
    fn wave_slopes(&self) -> Vec<[f64; 2]> {
        self.layers.iter().flat_map(|l| l.wave_slopes()).collect()
    }

    fn wave_amplitudes(&self, k: [i64; 2], out: &mut Vec<Complex64>) {
        for (layer, w) in self.layers.iter().zip(self.weights()) {
            let start = out.len();
            layer.wave_amplitudes(k, out);
            for a in &mut out[start..] {
                *a *= w;
            }
        }
    }

    fn layer_shapes(&self) -> Vec<String> {
        self.layers.iter().flat_map(|l| l.layer_shapes()).collect()
    }
}
