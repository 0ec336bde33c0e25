//! Padded 4D samplers (Cook 1986, "Stochastic sampling in computer
//! graphics", ACM TOG 5(1)): an independent 2D set on (x, y) and one on
//! (u, v), paired by a uniformly random permutation. Each half keeps its
//! own 2D spectrum in the XY and UV projections while the pairing leaves the
//! XU and YV projections white. Uncorrelated multi-jitter (`umj`, Singh &
//! Jarosz 2017, "Convergence analysis for anisotropic Monte Carlo sampling
//! spectra", ACM TOG 36(4)) is the case of two multi-jittered halves.

use super::config::Config;
use super::multijitter::MultiJitter;
use super::{Sampler, SamplerError};
use crate::points::PointSet;
use crate::rng::{SetRng, permutation};

/// Points (x, y, u, v): two independent 2D samplers of N points each,
/// randomly paired.
pub struct Padded {
    xy: Box<dyn Sampler>,
    uv: Box<dyn Sampler>,
}

impl Padded {
    /// Pairs `xy` and `uv`.
    ///
    /// # Errors
    /// [`SamplerError::Param`] unless both are 2D with the same fixed N.
    pub fn new(xy: Box<dyn Sampler>, uv: Box<dyn Sampler>) -> Result<Self, SamplerError> {
        // The half at fault is named (both were reported together as
        // "xy/uv=2D with 4 points / 2D with 4 points").
        for (key, half) in [("xy", &xy), ("uv", &uv)] {
            let fault = if half.dim() != 2 {
                Some((format!("a {}D sampler", half.dim()), "a 2D sampler"))
            } else if half.density().is_some() {
                Some((
                    "a random-count sampler".to_string(),
                    "a sampler of a fixed N (a random count, as isotropic-jitter's, cannot be \
                     paired point by point)",
                ))
            } else {
                None
            };
            if let Some((value, expected)) = fault {
                return Err(SamplerError::Param {
                    sampler: "padded",
                    key,
                    value,
                    expected: expected.into(),
                });
            }
        }
        if xy.points_per_set() != uv.points_per_set() {
            return Err(SamplerError::Param {
                sampler: "padded",
                key: "xy/uv",
                value: format!("{} / {} points", xy.points_per_set(), uv.points_per_set()),
                expected: "two 2D samplers of the same N".into(),
            });
        }
        Ok(Padded { xy, uv })
    }
}

pub(crate) fn umj_from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    let correlated = match c.param("pairs") {
        "mj" | "multijitter" => false,
        "cmj" => true,
        _ => return Err(c.bad_param("pairs", "mj or cmj")),
    };
    let (m, n) = MultiJitter::grid(c)?;
    let half = || -> Result<Box<dyn Sampler>, SamplerError> {
        Ok(Box::new(MultiJitter::new(m, n, correlated)?))
    };
    Ok(Box::new(Padded::new(half()?, half()?)?))
}

pub(crate) fn padded_from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    let half = |key: &'static str| {
        let name = c.param(key);
        if matches!(name.trim(), "" | "padded" | "umj") {
            return Err(c.bad_param(key, "a 2D sampler (see varspec sample --list)"));
        }
        // A half's count rule is the padded sampler's: say which half.
        c.build_other(name, c.n, Some(2), &[]).map_err(|mut e| {
            if let SamplerError::Count { sampler, .. } = &mut e {
                *sampler = format!("{}'s {key} half, {sampler},", c.sampler);
            }
            e
        })
    };
    Ok(Box::new(Padded::new(half("xy")?, half("uv")?)?))
}

impl Sampler for Padded {
    fn dim(&self) -> usize {
        4
    }

    fn points_per_set(&self) -> usize {
        self.xy.points_per_set()
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let xy = self.xy.sample(rng)?;
        let uv = self.uv.sample(rng)?;
        let pairing = permutation(rng, xy.len());
        let mut coords = Vec::with_capacity(4 * xy.len());
        for (p, &i) in xy.points().zip(&pairing) {
            coords.extend_from_slice(p);
            coords.extend_from_slice(uv.point(i as usize));
        }
        Ok(PointSet::new(4, coords).expect("both halves lie in [0,1)"))
    }

    fn halves(&self) -> Option<[&dyn Sampler; 2]> {
        Some([self.xy.as_ref(), self.uv.as_ref()])
    }
}
