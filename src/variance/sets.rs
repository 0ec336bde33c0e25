//! How many realizations a per-set predictor (the Fourier and spatial forms
//! average one value per set) needs for its standard error to mean what it
//! says.
//!
//! The per-set values are exact conditional variances given the set, and
//! for samplers whose low frequencies are not suppressed (random, N-rooks,
//! Poisson disk) they are right-skewed: each is close to a weighted sum of
//! exponentials Σ_k P_f(k)·|S(k)|²/N with the few largest P_f(k) dominating
//! (Pilleboue et al. 2015, Eq. (9) per realization), with a coefficient of
//! variation near 0.35 on a disk. Over 16 sets the mean then comes out low
//! together with its sample standard deviation, and the t interval covers
//! about 90% where it claims 95% (measured: `varspec predict --sampler
//! random -n 1024 --integrand disk:r=0.3 --method spatial`, 40 seeds, 4
//! outside ±t₀.₉₇₅(15)). The skewness of a mean of R values falls as
//! 1/√R, so the remedy is more sets exactly when the values spread:
//! a pilot's relative standard error e₀ over R₀ sets predicts
//! e ≈ e₀·√(R₀/R) over R, and R = ⌈R₀·(e₀/target)²⌉ reaches the target.

/// The relative standard error an automatic set count aims at.
pub const TARGET_RELATIVE_STDERR: f64 = 0.05;

/// The most sets an automatic count draws.
pub const MAX_AUTO_SETS: usize = 1024;

/// Point pairs the spatial form may visit for an automatic count: R·N² ≤
/// 2³⁰ (about 17 s of a disk's autocovariance on 2 cores at N = 1024, where
/// it allows the full [`MAX_AUTO_SETS`]; 64 sets at N = 4096).
pub const AUTO_PAIR_BUDGET: f64 = (1u64 << 30) as f64;

/// Bytes the drawn sets may hold for an automatic count (every set is kept
/// for the forms that pass over them): 256 MiB.
pub const AUTO_MEMORY_BUDGET: f64 = (1u64 << 28) as f64;

/// The most sets an automatic count may draw for sets of `n` points in
/// `dim` dimensions, [`MAX_AUTO_SETS`] within the memory budget and, when
/// the spatial form runs (`pairs`), the pair budget. A count, not a time,
/// so the choice is the same on every machine.
pub fn auto_set_cap(n: usize, dim: usize, pairs: bool) -> usize {
    let n = n.max(1) as f64;
    let memory = AUTO_MEMORY_BUDGET / (8.0 * dim.max(1) as f64 * n);
    let work = if pairs {
        AUTO_PAIR_BUDGET / (n * n)
    } else {
        f64::INFINITY
    };
    memory.min(work).min(MAX_AUTO_SETS as f64).floor() as usize
}

/// The set count chosen from a pilot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SetCount {
    /// Realizations to average (at least the pilot's).
    pub sets: usize,
    /// The count the target asks for, cap or not.
    pub wanted: usize,
}

impl SetCount {
    /// True when the cap kept the count below the target's.
    pub fn capped(&self) -> bool {
        self.wanted > self.sets
    }
}

/// The realization count at which a mean whose `pilot` sets gave relative
/// standard error `relative` reaches `target`: ⌈pilot·(relative/target)²⌉,
/// at least `pilot`, at most `cap` (see the module doc). A relative error
/// that is not a finite positive number (a variance of zero, sets that are
/// all alike) keeps the pilot.
pub fn sets_for_relative_stderr(pilot: usize, relative: f64, target: f64, cap: usize) -> SetCount {
    if !(relative.is_finite() && relative > 0.0 && target > 0.0) || relative <= target {
        return SetCount {
            sets: pilot,
            wanted: pilot,
        };
    }
    // Saturating: a relative error of 10^300 asks for usize::MAX sets.
    let wanted = ((pilot as f64 * (relative / target).powi(2)).ceil() as usize).max(pilot);
    SetCount {
        sets: wanted.min(cap.max(pilot)),
        wanted,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_standard_error_falls_as_one_over_root_sets() {
        // 16 sets at 10% need 4× the sets for 5%.
        assert_eq!(
            sets_for_relative_stderr(16, 0.10, 0.05, 1024),
            SetCount {
                sets: 64,
                wanted: 64
            }
        );
        // 0.051 → ⌈16·1.0404⌉ = 17.
        assert_eq!(sets_for_relative_stderr(16, 0.051, 0.05, 1024).sets, 17);
    }

    #[test]
    fn a_precise_pilot_or_a_degenerate_one_keeps_its_sets() {
        for relative in [0.01, 0.05, 0.0, f64::NAN, f64::INFINITY, -1.0] {
            assert_eq!(
                sets_for_relative_stderr(16, relative, 0.05, 1024),
                SetCount {
                    sets: 16,
                    wanted: 16
                },
                "relative {relative}"
            );
        }
    }

    #[test]
    fn the_cap_follows_the_work() {
        assert_eq!(auto_set_cap(1024, 2, true), 1024);
        assert_eq!(auto_set_cap(4096, 2, true), 64);
        assert_eq!(auto_set_cap(4096, 2, false), 1024);
        // 2^20 2D points: 16 MiB a set, 16 sets in 256 MiB.
        assert_eq!(auto_set_cap(1 << 20, 2, false), 16);
    }

    #[test]
    fn the_cap_is_said() {
        let count = sets_for_relative_stderr(16, 1.0, 0.05, 1024);
        assert_eq!(
            count,
            SetCount {
                sets: 1024,
                wanted: 6400
            }
        );
        assert!(count.capped());
        // A cap below the pilot keeps the pilot.
        assert_eq!(sets_for_relative_stderr(16, 1.0, 0.05, 4).sets, 16);
        assert_eq!(sets_for_relative_stderr(16, 1e300, 0.05, 1024).sets, 1024);
    }
}
