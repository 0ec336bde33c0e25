//! The score of point sets on the square: the mean squared error of the
//! unshifted estimator Î = (1/N) Σ_i f(x_i) (1/λ for a random-count set) over the members of a family,
//! by brute force (each member evaluated at every point), with standard
//! errors over the members and over the sets. This is the peer's yardstick (UTK's integration
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
    /// Standard error of `mse` as an estimate of the sampler's expected
    /// family MSE: members and sets both drawn at random ([`crossed_stderr`]).
    /// With one set, the set-to-set variation cannot be estimated and this
    /// is `stderr_members`.
    pub stderr: f64,
    /// Standard error over the members alone (the sets held fixed: the
    /// uncertainty of these sets' own MSE).
    pub stderr_members: f64,
    /// Standard error over the sets alone (the members held fixed); `None`
    /// for one set.
    pub stderr_sets: Option<f64>,
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
    let per_set: Vec<f64> = (0..sets.len())
        .map(|s| crate::sum::sum(errors.iter().map(|e| e[s])) / members as f64)
        .collect();
    let (members_part, sets_part) = (
        sample_variance(&per_member, mean) / members as f64,
        (sets.len() > 1).then(|| sample_variance(&per_set, mean) / sets.len() as f64),
    );
    let stderr = match sets_part {
        Some(sets_part) => crossed_stderr(
            &errors,
            &per_member,
            &per_set,
            mean,
            members_part,
            sets_part,
        ),
        None => members_part.sqrt(),
    };
    SquareMse {
        mse: mean,
        stderr,
        stderr_members: members_part.sqrt(),
        stderr_sets: sets_part.map(f64::sqrt),
        members,
        per_set,
    }
}

/// The sample variance of `values` about their `mean` (0 for one value).
fn sample_variance(values: &[f64], mean: f64) -> f64 {
    if values.len() < 2 {
        return 0.0;
    }
    crate::sum::sum(values.iter().map(|v| (v - mean) * (v - mean))) / (values.len() - 1) as f64
}

/// The standard error of the grand mean of a crossed design (every set
/// scored on every member, both drawn at random). With
/// e_ms = μ + a_m + b_s + ε_ms, Var(ē) = σ_a²/M + σ_b²/R + σ_ε²/(MR),
/// estimated without bias by the members' and sets' parts less the
/// residual mean square of the two-way random-effects ANOVA (Searle,
/// Casella & McCulloch 1992, *Variance Components*):
/// `members_part + sets_part − MS_ε/(MR)`. It is kept at or above the
/// larger of the two parts, each of which alone has expectation below the
/// true variance.
fn crossed_stderr(
    errors: &[Vec<f64>],
    per_member: &[f64],
    per_set: &[f64],
    mean: f64,
    members_part: f64,
    sets_part: f64,
) -> f64 {
    let (m, r) = (per_member.len(), per_set.len());
    let residual = crate::sum::sum(errors.iter().zip(per_member).flat_map(|(row, &em)| {
        row.iter()
            .zip(per_set)
            .map(move |(&e, &es)| (e - em - es + mean).powi(2))
    })) / ((m - 1) * (r - 1)).max(1) as f64;
    let unbiased = members_part + sets_part - residual / (m * r) as f64;
    unbiased.max(members_part).max(sets_part).sqrt()
}
