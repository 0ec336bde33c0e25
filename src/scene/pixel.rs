//! One pixel of a scene as a 4D integrand, for the analysis tools:
//! `scene:NAME,px=X,py=Y` (NAME a built-in scene or a scene file).
//!
//! f(x, y, u, v) is the pixel's radiance ([`Scene::radiance`]): (x, y) on
//! the pixel footprint, (u, v) on the lens or the light. It has no closed
//! form: the empirical predictor, which only evaluates f, applies as is;
//! the integral and ∫f² − I² are estimates from [`REFERENCE_SETS`]
//! independent multi-jittered sets of [`REFERENCE_POINTS`] samples (the
//! integral with its standard error from the spread of the sets' means),
//! and there are no Fourier coefficients or autocovariance (the
//! closed-form predictors refuse it).

use std::sync::Arc;

use rustfft::num_complex::Complex64;

use super::Scene;
use super::description::SceneError;
use crate::integrands::{Integrand, IntegrandClass, check_plane};
use crate::points::PointSet;
use crate::rng::{set_rng, uniform};
use crate::spectrum::{FrequencyBox, NufftPlan, Sign, Spectrum, SpectrumError};
use crate::sum::{NeumaierSum, sum};

/// Points in each set behind the reference integral and variance (umj).
pub const REFERENCE_POINTS: usize = 1 << 16;

/// Independent sets behind the reference integral: their means' spread is
/// its standard error (Student t with 15 degrees of freedom), which a
/// single stratified set cannot give. 2^20 rays in all, about 0.1 s.
pub const REFERENCE_SETS: usize = 16;

/// Seed of the reference sets (one stream per pixel and set).
const REFERENCE_SEED: u64 = 0x5049_5845_4c52_4546;

/// Pixel (px, py) of a scene as an integrand on [0, 1)^4.
pub struct PixelIntegrand {
    scene: Arc<Scene>,
    px: usize,
    py: usize,
    /// Estimated I, its standard error and ∫f² − I² (from the reference
    /// sets).
    integral: f64,
    integral_stderr: f64,
    variance: f64,
}

/// What is wrong with a `scene:` spec.
#[derive(Debug, thiserror::Error)]
pub enum PixelError {
    /// Malformed spec.
    #[error(
        "`{spec}`: {message} (expected scene:NAME,px=X,py=Y with NAME a built-in scene or a scene file)"
    )]
    Syntax {
        /// The spec.
        spec: String,
        /// What is wrong.
        message: String,
    },
    /// The scene could not be loaded.
    #[error(transparent)]
    Scene(#[from] SceneError),
}

impl PixelIntegrand {
    /// True for a spec this type parses (`scene:...`, whitespace around
    /// `scene` ignored as in every spec).
    pub fn is_pixel_spec(spec: &str) -> bool {
        crate::integrands::scene_pixel_rest(spec).is_some()
    }

    /// The files a pixel spec reads ([`Scene::files_read`] of its scene;
    /// none for another spec or a malformed one).
    pub fn files_read(spec: &str) -> Vec<std::path::PathBuf> {
        Self::parse_spec(spec).map_or_else(|_| Vec::new(), |(name, _, _)| Scene::files_read(name))
    }

    /// Parses `scene:NAME,px=X,py=Y`, loads the scene and computes the
    /// reference integral.
    ///
    /// # Errors
    /// [`PixelError::Syntax`] for a malformed spec or a pixel outside the
    /// image; [`PixelError::Scene`] when the scene does not load.
    pub fn parse(spec: &str) -> Result<PixelIntegrand, PixelError> {
        let (name, px, py) = Self::parse_spec(spec)?;
        let scene = Scene::load(name)?;
        let [w, h] = scene.camera().resolution();
        if px >= w || py >= h {
            return Err(PixelError::Syntax {
                spec: spec.into(),
                message: format!("pixel ({px}, {py}) is outside the {w}x{h} image of `{name}`"),
            });
        }
        Ok(PixelIntegrand::new(Arc::new(scene), px, py))
    }

    /// The text of a spec: (scene name, px, py), without loading anything.
    ///
    /// # Errors
    /// [`PixelError::Syntax`] naming what is wrong.
    pub fn parse_spec(spec: &str) -> Result<(&str, usize, usize), PixelError> {
        let fail = |message: String| PixelError::Syntax {
            spec: spec.into(),
            message,
        };
        let rest = crate::integrands::scene_pixel_rest(spec)
            .ok_or_else(|| fail("no `scene:` prefix".into()))?;
        let (name, params) = rest
            .split_once(',')
            .ok_or_else(|| fail("no pixel given".into()))?;
        let name = name.trim();
        if name.is_empty() || name.contains('=') {
            return Err(fail(format!(
                "no scene name (the built-in scenes: {})",
                crate::scene::BUILTIN_SCENES
                    .iter()
                    .map(|s| s.0)
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        let (mut px, mut py) = (None, None);
        for (key, value) in
            crate::spec_params::key_values(params).map_err(|e| fail(e.to_string()))?
        {
            let slot = match key {
                "px" => &mut px,
                "py" => &mut py,
                other => {
                    return Err(fail(format!(
                        "unknown parameter `{other}`; its parameters: px, py"
                    )));
                }
            };
            if slot.is_some() {
                return Err(fail(format!("`{key}` given twice")));
            }
            let v: usize = value.parse().map_err(|_| {
                let digits = !value.is_empty() && value.bytes().all(|b| b.is_ascii_digit());
                fail(if digits {
                    format!("{key} = {value}: beyond any image (more than 2^64 pixels across)")
                } else {
                    format!(
                        "{key} = {value}: a pixel index is written in digits, counted from 0 \
                         (px from the left, py from the top)"
                    )
                })
            })?;
            *slot = Some(v);
        }
        let (Some(px), Some(py)) = (px, py) else {
            return Err(fail("both px and py are needed".into()));
        };
        Ok((name, px, py))
    }

    /// Pixel (px, py) of `scene` (inside its image).
    ///
    /// # Panics
    /// If the pixel is outside the image.
    pub fn new(scene: Arc<Scene>, px: usize, py: usize) -> PixelIntegrand {
        let [w, h] = scene.camera().resolution();
        assert!(px < w && py < h, "pixel ({px}, {py}) outside {w}x{h}");
        use rayon::prelude::*;
        let umj = crate::registry::build("umj", REFERENCE_POINTS, Some(4), &[])
            .expect("umj makes 2^16 4D points");
        // Each set's values, in set order whatever the thread count; each
        // pixel has its own streams, so the references of two pixels are
        // independent.
        let first = ((py * w + px) * REFERENCE_SETS) as u64;
        let sets: Vec<Vec<f64>> = (0..REFERENCE_SETS as u64)
            .into_par_iter()
            .map(|r| {
                let set = umj
                    .sample(&mut set_rng(REFERENCE_SEED, first + r))
                    .expect("umj draws 2^16 4D points");
                set.points()
                    .map(|p| scene.radiance(px, py, [p[0], p[1], p[2], p[3]]))
                    .collect()
            })
            .collect();
        let means: Vec<f64> = sets
            .iter()
            .map(|v| sum(v.iter().copied()) / v.len() as f64)
            .collect();
        let r = REFERENCE_SETS as f64;
        let integral = sum(means.iter().copied()) / r;
        let spread = sum(means.iter().map(|m| (m - integral).powi(2))) / (r - 1.0);
        let n = r * REFERENCE_POINTS as f64;
        let squares = sum(sets.iter().flatten().map(|v| (v - integral).powi(2)));
        PixelIntegrand {
            scene,
            px,
            py,
            integral,
            integral_stderr: (spread / r).sqrt(),
            variance: squares / (n - 1.0),
        }
    }

    /// The standard error of [`Integrand::integral`], an estimate here:
    /// the sample standard deviation of the [`REFERENCE_SETS`] sets' means
    /// over √[`REFERENCE_SETS`] (0 when f is constant on them).
    pub fn integral_stderr(&self) -> f64 {
        self.integral_stderr
    }

    /// The pixel.
    pub fn pixel(&self) -> [usize; 2] {
        [self.px, self.py]
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The random points per cell of [`PixelIntegrand::plane_power`] that
    /// every command and figure uses.
    pub const RAYS_PER_CELL: usize = 16;

    /// The pixel's light-field power in the plane of coordinates `dims`
    /// (e.g. [0, 2], XU): |F_g(k)|² of the marginal g = ∫∫ f over the other
    /// two coordinates, which is the 4D power P_f on that plane through the
    /// origin (k of the other two = 0). g is averaged over `per_cell`
    /// random points in each cell of a `grid` × `grid` partition of the
    /// plane (seeded per cell: the same for any thread count), and F_g by a
    /// type-1 NUFFT (ε = 1e-9) of the cell averages at the cell centres,
    /// on |k| ≤ grid/4, where the cells' box filter (sinc² ≥ 0.81) and the
    /// aliasing of frequencies beyond grid/2 distort it least.
    ///
    /// # Errors
    /// [`SpectrumError::Plane`] for `dims` not two distinct coordinates of
    /// 0..4, a grid below 8 or no sample per cell.
    pub fn plane_power(
        &self,
        dims: [usize; 2],
        grid: usize,
        per_cell: usize,
        seed: u64,
    ) -> Result<Spectrum, SpectrumError> {
        use rayon::prelude::*;
        check_plane(dims, 4)?;
        if grid < 8 || per_cell == 0 {
            return Err(SpectrumError::Plane(format!(
                "a grid of at least 8 cells per axis and a sample per cell, not {grid} and {per_cell}"
            )));
        }
        // Cell averages, their centres and strengths: 40 bytes a cell.
        crate::memory::check(
            &format!("the pixel's {grid}² cell averages"),
            grid.checked_mul(grid).map(|n| n as f64 * 40.0),
            "lower the resolution",
        )?;
        let cells: Vec<f64> = (0..grid * grid)
            .into_par_iter()
            .map(|c| {
                let mut rng = set_rng(seed, c as u64);
                let mut sum = NeumaierSum::default();
                for _ in 0..per_cell {
                    let mut p: [f64; 4] = std::array::from_fn(|_| uniform(&mut rng));
                    p[dims[0]] = ((c % grid) as f64 + p[dims[0]]) / grid as f64;
                    p[dims[1]] = ((c / grid) as f64 + p[dims[1]]) / grid as f64;
                    sum.add(self.scene.radiance(self.px, self.py, p));
                }
                sum.value() / per_cell as f64
            })
            .collect();
        let centres: Vec<f64> = (0..grid * grid)
            .flat_map(|c| {
                [
                    ((c % grid) as f64 + 0.5) / grid as f64,
                    ((c / grid) as f64 + 0.5) / grid as f64,
                ]
            })
            .collect();
        let points = PointSet::new(2, centres).expect("cell centres lie in [0,1)");
        let area = 1.0 / (grid * grid) as f64;
        let strengths: Vec<Complex64> = cells
            .iter()
            .map(|&g| Complex64::new(g * area, 0.0))
            .collect();
        let freqs = FrequencyBox {
            dim: 2,
            half: grid / 4,
        };
        let plan = NufftPlan::new(freqs, 1e-9)?;
        let mut out = vec![Complex64::new(0.0, 0.0); freqs.len()];
        plan.type1(
            &points,
            Some(&strengths),
            Sign::Negative,
            &mut out,
            &mut plan.make_scratch(),
        );
        Ok(Spectrum {
            freqs,
            power: out.iter().map(|c| c.norm_sqr()).collect(),
            sets: 1,
        })
    }
}

impl Integrand for PixelIntegrand {
    fn dim(&self) -> usize {
        4
    }

    /// An estimate: the mean of f over [`REFERENCE_SETS`] umj sets of
    /// [`REFERENCE_POINTS`] points; [`PixelIntegrand::integral_stderr`] is
    /// its standard error.
    fn integral(&self) -> f64 {
        self.integral
    }

    /// An estimate: the sample variance of f over all the same points.
    fn variance(&self) -> f64 {
        self.variance
    }

    fn eval(&self, x: &[f64]) -> f64 {
        self.scene
            .radiance(self.px, self.py, [x[0], x[1], x[2], x[3]])
    }

    /// Not known: NaN (a pixel has no closed-form spectrum; see
    /// [`Self::plane_power`] for a measured one).
    fn fourier(&self, _k: &[i64]) -> Complex64 {
        Complex64::new(f64::NAN, f64::NAN)
    }

    /// False: the Fourier predictors refuse a pixel.
    fn has_fourier(&self) -> bool {
        false
    }

    fn autocov(&self, _h: &[f64]) -> Option<f64> {
        None
    }

    fn class(&self) -> IntegrandClass {
        IntegrandClass {
            smooth: false,
            one_axis: false,
        }
    }

    fn spec(&self) -> String {
        format!("scene:{},px={},py={}", self.scene.name(), self.px, self.py)
    }
}

#[cfg(test)]
mod tests {
    use super::PixelIntegrand;

    /// Whitespace around `scene`, the name, keys and values is ignored, as
    /// in every spec (`scene:dof ,px=3,py=4` looked for a scene `dof `).
    #[test]
    fn whitespace_around_the_parts_of_a_pixel_spec_is_ignored() {
        for spec in [
            "scene:dof,px=3,py=4",
            " scene : dof , px = 3 , py = 4 ",
            "scene:dof ,px=3,py=4",
        ] {
            assert!(PixelIntegrand::is_pixel_spec(spec), "{spec}");
            assert_eq!(
                PixelIntegrand::parse_spec(spec).unwrap(),
                ("dof", 3, 4),
                "{spec}"
            );
        }
        assert!(!PixelIntegrand::is_pixel_spec("scenery:dof,px=3,py=4"));
        assert!(PixelIntegrand::parse_spec("disk:r=0.3").is_err());
    }
}
