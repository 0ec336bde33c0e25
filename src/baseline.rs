//! The classic samplers every design is compared with: jitter, CMJ,
//! Owen-scrambled Sobol' and Poisson disk, each at its nearest valid N,
//! scored by the same function as the design (the optimizer's loss on the
//! torus, the family MSEs on the square).

use serde::Serialize;

use crate::points::PointSet;
use crate::registry;
use crate::samplers::{SamplerError, generate_sets};

/// The classic samplers of the comparison.
pub const CLASSIC: [&str; 4] = ["jitter", "cmj", "sobol", "poisson-disk"];

/// One classic sampler's score.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Baseline<T> {
    /// Sampler name.
    pub name: &'static str,
    /// The N it was drawn at (its nearest valid N to the design's).
    pub n: usize,
    /// Its score.
    pub score: T,
}

/// Scores `realizations` sets of each classic sampler that has a
/// d-dimensional form, at its nearest valid N to `n`; realization r is drawn
/// from stream (`seed` ^ 0x5eed, r), so the baselines differ from the
/// designs' starts. Samplers without a d-dimensional form are left out.
///
/// # Errors
/// A failed realization, or `score`'s error.
pub fn classic_baselines<T, E>(
    n: usize,
    dim: usize,
    realizations: usize,
    seed: u64,
    score: impl Fn(&[PointSet]) -> Result<T, E>,
) -> Result<Vec<Baseline<T>>, E>
where
    E: From<SamplerError>,
{
    let mut out = Vec::new();
    for name in CLASSIC {
        if let Ok((sampler, n)) = registry::build_nearest(name, n, Some(dim), &[]) {
            let sets = generate_sets(sampler.as_ref(), seed ^ 0x5eed, realizations, &|_| {})?;
            out.push(Baseline {
                name,
                n,
                score: score(&sets)?,
            });
        }
    }
    Ok(out)
}
