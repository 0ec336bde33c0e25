//! A thin-lens light field (docs/mathematics.md): f(x,y,u,v) = g(x + c(u−½),
//! y + c(v−½)) with g a 2D shape centred at (½,½). Depth of field shears the
//! light field by c = (F − d)/d (Singh & Jarosz 2017, §3).
//!
//! Integrating x, y over a period for fixed (u,v) gives
//! F(k) = G(kx,ky)·(−1)^(ku+kv)·sinc(π(ku − c·kx))·sinc(π(kv − c·ky)):
//! the energy lies on the sheared plane ku = c·kx, kv = c·ky. No closed-form
//! 4D autocovariance is implemented; the spatial predictor does not apply.

use rustfft::num_complex::Complex64;

use super::{Disk, Gaussian, Integrand, IntegrandClass, IntegrandError, LightField, Rect, sinc_pi};
use crate::points::wrap01;
use crate::spec_params::SpecValue;

/// The 2D shape g of a defocus light field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DefocusShape {
    /// Square of side `size`.
    Box,
    /// Disk of diameter `size`.
    Disk,
    /// Gaussian with 4σ = `size`.
    Gaussian,
}

/// Sheared thin-lens light field in 4D.
pub struct Defocus {
    shape: DefocusShape,
    size: f64,
    c: f64,
    g: Box<dyn Integrand>,
}

/// Smallest shape size: below it the disk radius or Gaussian σ underflows
/// and no sample count resolves the shape.
pub const MIN_SIZE: f64 = 1e-4;

impl Defocus {
    /// Shape g of the given size, shear c.
    ///
    /// # Errors
    /// [`IntegrandError::Value`] for a size outside [[`MIN_SIZE`], 1] (the
    /// disk radius or Gaussian σ would underflow or leave the torus).
    pub fn new(shape: DefocusShape, size: f64, c: f64) -> Result<Self, IntegrandError> {
        if !(MIN_SIZE..=1.0).contains(&size) {
            return Err(IntegrandError::Value {
                integrand: "defocus",
                key: "size",
                value: size.to_string(),
                expected: "a size in [1e-4, 1]".into(),
            });
        }
        let centre = [0.5, 0.5];
        let g: Box<dyn Integrand> =
            match shape {
                DefocusShape::Box => Box::new(Rect::new(size, size, centre, 0.0).map_err(|e| {
                    IntegrandError::Value {
                        integrand: "defocus",
                        key: "size",
                        value: size.to_string(),
                        expected: e,
                    }
                })?),
                DefocusShape::Disk => Box::new(Disk::new(0.5 * size, centre)?),
                DefocusShape::Gaussian => {
                    Box::new(Gaussian::new(0.25 * size, 0.25 * size, 0.0, centre)?)
                }
            };
        Ok(Defocus { shape, size, c, g })
    }

    /// The shear c.
    pub fn shear(&self) -> f64 {
        self.c
    }

    /// The shape's size (box side, disk diameter, Gaussian 4σ).
    pub fn size(&self) -> f64 {
        self.size
    }

    /// The shape's name in specs.
    pub(super) fn shape_name(&self) -> &'static str {
        match self.shape {
            DefocusShape::Box => "box",
            DefocusShape::Disk => "disk",
            DefocusShape::Gaussian => "gaussian",
        }
    }

    /// The 2D shape g.
    pub(super) fn shape(&self) -> &dyn Integrand {
        self.g.as_ref()
    }
}

/// φ_k(u, v) = G(k)·e^(2πi c k·((u,v) − ½)): one plane wave of frequency c·k.
impl LightField for Defocus {
    fn wave_slopes(&self) -> Vec<[f64; 2]> {
        vec![[self.c, self.c]]
    }

    fn wave_amplitudes(&self, k: [i64; 2], out: &mut Vec<Complex64>) {
        out.push(
            self.g.fourier(&k)
                * crate::spectrum::phase::turn(crate::spectrum::phase::reduced_product(
                    -0.5 * self.c,
                    (k[0] + k[1]) as f64,
                )),
        );
    }

    fn layer_shapes(&self) -> Vec<String> {
        vec![self.g.spec()]
    }
}

impl Integrand for Defocus {
    fn dim(&self) -> usize {
        4
    }

    fn integral(&self) -> f64 {
        self.g.integral()
    }

    fn variance(&self) -> f64 {
        self.g.variance()
    }

    fn eval(&self, x: &[f64]) -> f64 {
        self.g.eval(&[
            wrap01(x[0] + self.c * (x[2] - 0.5)),
            wrap01(x[1] + self.c * (x[3] - 0.5)),
        ])
    }

    fn fourier(&self, k: &[i64]) -> Complex64 {
        let sign = if (k[2] + k[3]).rem_euclid(2) == 0 {
            1.0
        } else {
            -1.0
        };
        let su = sinc_pi((-self.c).mul_add(k[0] as f64, k[2] as f64));
        let sv = sinc_pi((-self.c).mul_add(k[1] as f64, k[3] as f64));
        self.g.fourier(&k[..2]) * (sign * su * sv)
    }

    fn autocov(&self, _h: &[f64]) -> Option<f64> {
        None
    }

    fn class(&self) -> IntegrandClass {
        IntegrandClass {
            smooth: self.shape == DefocusShape::Gaussian,
            one_axis: false,
        }
    }

    fn spec(&self) -> String {
        format!(
            "defocus:shape={},size={},c={}",
            self.shape_name(),
            SpecValue(self.size),
            SpecValue(self.c)
        )
    }

    fn light_field(&self) -> Option<&dyn LightField> {
        Some(self)
    }
}
