//! The score of point sets on the square: the mean squared error of the
//! unshifted estimator Î = (1/N) Σ_i f(x_i) (1/λ for a random-count set) over the members of a family,
//! by brute force (each member evaluated at every point), with a standard
//! error over the members. This is the peer's yardstick (UTK's integration
//! tests: the average of (Î − I)² over a database of integrands) and the
//! independent check of the kernel forms the optimizers use.

use rayon::prelude::*;

use super::family::Family;
use crate::points::PointSet;
use crate::sum::NeumaierSum;

/// A family MSE with its uncertainty.
#[derive(Debug, Clone, PartialEq)]
pub struct SquareMse {
    /// Mean of (Î − I)² over members and sets.
    pub mse: f64,
    /// Standard error over the members (the sets held fixed).
    pub stderr: f64,
    /// Members of the family sample.
    pub members: usize,
    /// MSE of each set over the members.
    pub per_set: Vec<f64>,
}

impl SquareMse {
    /// The normal 95% interval of the MSE from its standard error over the
    /// members, clamped at 0.
    pub fn interval_95(&self) -> (f64, f64) {
        let half = crate::variance::NORMAL_95 * self.stderr;
        ((self.mse - half).max(0.0), self.mse + half)
    }
}

/// Refuses a family MSE of `sets` sets over `members` members that would
/// not fit in memory ([`family_mse`] keeps every member's squared error of
/// every set: 8 bytes each, and 32 per member).
///
/// # Errors
/// [`TooMuchMemory`](crate::memory::TooMuchMemory) with the estimate.
pub fn check_family_memory(
    members: usize,
    sets: usize,
) -> Result<(), crate::memory::TooMuchMemory> {
    crate::memory::check(
        &format!("the squared errors of {sets} sets on {members} family members"),
        Some(members as f64 * (sets as f64 * 8.0 + 32.0)),
        "lower --members",
    )
}

/// The family MSE of `sets` over `members` members drawn with `seed`.
///
/// # Panics
/// If a set is not 2D (callers check).
pub fn family_mse(sets: &[PointSet], family: &Family, members: usize, seed: u64) -> SquareMse {
    assert!(
        sets.iter().all(|s| s.dim() == 2),
        "the square holds 2D sets"
    );
    let members = family.sample_size(members);
    // Per member: the squared error of every set.
    let errors: Vec<Vec<f64>> = (0..members as u64)
        .into_par_iter()
        .map(|m| {
            let f = family.member(seed, m);
            let integral = f.integral();
            sets.iter()
                .map(|set| {
                    let mut sum = NeumaierSum::default();
                    for p in set.points() {
                        sum.add(f.eval([p[0], p[1]]));
                    }
                    let e = sum.value() / set.intensity() - integral;
                    e * e
                })
                .collect()
        })
        .collect();
    let per_member: Vec<f64> = errors
        .iter()
        .map(|e| crate::sum::sum(e.iter().copied()) / e.len().max(1) as f64)
        .collect();
    let mean = crate::sum::sum(per_member.iter().copied()) / members as f64;
    let spread = if members > 1 {
        crate::sum::sum(per_member.iter().map(|v| (v - mean) * (v - mean))) / (members - 1) as f64
    } else {
        0.0
    };
    let per_set = (0..sets.len())
        .map(|s| crate::sum::sum(errors.iter().map(|e| e[s])) / members as f64)
        .collect();
    SquareMse {
        mse: mean,
        stderr: (spread / members as f64).sqrt(),
        members,
        per_set,
    }
}
