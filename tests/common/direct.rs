//! An independent reference for the Fourier form on fixed sets: the in-box
//! sum by a direct DFT written here (no NUFFT, no code under test), and the
//! rigorous limits of what lies outside the box.
//!
//! For sets of intensity λ the variance under a uniform shift is
//! Σ_(k≠0) |S(k)|²/λ² · P_f(k) + E[(N/λ − 1)²]·I², with S(k) = Σ_j e^(−2πik·x_j)
//! (Pilleboue et al. 2015, eq. 8; the count term for a random N,
//! Öztireli 2016). Outside a box B every |S(k)|² lies in [0, N²], so the
//! part of the variance beyond B lies in [0, max(N/λ)²·T] with
//! T = c_f(0) − Σ_(k∈B\0) P_f(k) (Parseval).

use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use varspec::PointSet;
use varspec::integrands::Integrand;

/// What a fixed collection of sets gives on the box |k|∞ ≤ half.
pub struct DirectSplit {
    /// Mean over the sets of Σ_(k∈B\0) |S(k)|²/λ² · P_f(k), by direct DFT.
    pub in_box: f64,
    /// T = c_f(0) − Σ_(k∈B\0) P_f(k).
    pub tail_mass: f64,
    /// Σ_(k∈B\0) P_f(k).
    pub box_mass: f64,
    /// max over the sets of (N/λ)²: the factor on T in the tail's limit.
    pub tail_factor: f64,
    /// Mean over the sets of (N/λ − 1)²·I².
    pub count_term: f64,
    /// The intensity λ of the first set.
    pub intensity: f64,
}

/// e^(−2πi·k·x) for k = −half..=half, with the phase reduced exactly
/// (k·x mod 1 before the multiplication by 2π).
fn phases(x: f64, half: i64) -> Vec<Complex64> {
    (-half..=half)
        .map(|k| {
            let t = (k as f64 * x).rem_euclid(1.0);
            let (s, c) = (-std::f64::consts::TAU * t).sin_cos();
            Complex64::new(c, s)
        })
        .collect()
}

/// The frequency of flat box index `idx` (dimension 0 varies slowest, the
/// order in which [`structure`] builds its outer products).
fn frequency(idx: usize, dim: usize, half: i64) -> Vec<i64> {
    let side = (2 * half + 1) as usize;
    let mut k = vec![0i64; dim];
    let mut rest = idx;
    for d in (0..dim).rev() {
        k[d] = (rest % side) as i64 - half;
        rest /= side;
    }
    k
}

/// S(k) = Σ_j e^(−2πik·x_j) on the whole box: each point's phases are
/// multiplied out into a tensor (outer products over the dimensions) and
/// added; chunks of points are reduced in a fixed order.
fn structure(set: &PointSet, half: i64) -> Vec<Complex64> {
    let side = (2 * half + 1) as usize;
    let len = side.pow(set.dim() as u32);
    let points: Vec<&[f64]> = set.points().collect();
    let partial: Vec<Vec<Complex64>> = points
        .par_chunks(64)
        .map(|chunk| {
            let mut acc = vec![Complex64::new(0.0, 0.0); len];
            let mut tensor = Vec::with_capacity(len);
            let mut next = Vec::with_capacity(len);
            for p in chunk {
                tensor.clear();
                tensor.push(Complex64::new(1.0, 0.0));
                for &x in p.iter() {
                    let e = phases(x, half);
                    next.clear();
                    for &t in &tensor {
                        next.extend(e.iter().map(|&v| t * v));
                    }
                    std::mem::swap(&mut tensor, &mut next);
                }
                for (a, t) in acc.iter_mut().zip(&tensor) {
                    *a += t;
                }
            }
            acc
        })
        .collect();
    let mut total = vec![Complex64::new(0.0, 0.0); len];
    for part in partial {
        for (a, t) in total.iter_mut().zip(part) {
            *a += t;
        }
    }
    total
}

/// |S(k)|² of fixed sets on the box |k|∞ ≤ half by direct DFT, with each
/// set's intensity and count: what the split needs of the sets, computed
/// once for every integrand they are checked against.
pub struct SetPowers {
    half: i64,
    /// Per set: |S(k)|² in box order, λ and N.
    sets: Vec<(Vec<f64>, f64, usize)>,
}

impl SetPowers {
    /// The powers of `sets` on the box |k|∞ ≤ half.
    pub fn of(sets: &[PointSet], half: usize) -> SetPowers {
        let half = half as i64;
        SetPowers {
            half,
            sets: sets
                .iter()
                .map(|set| {
                    let power = structure(set, half).iter().map(|v| v.norm_sqr()).collect();
                    (power, set.intensity(), set.len())
                })
                .collect(),
        }
    }
}

/// The direct split of the sets behind `powers` against `f`.
pub fn split(f: &dyn Integrand, powers: &SetPowers) -> DirectSplit {
    let (dim, half) = (f.dim(), powers.half);
    let len = ((2 * half + 1) as usize).pow(dim as u32);
    let pf: Vec<f64> = (0..len)
        .map(|idx| {
            let k = frequency(idx, dim, half);
            if k.iter().all(|&v| v == 0) {
                0.0
            } else {
                f.fourier(&k).norm_sqr()
            }
        })
        .collect();
    let box_mass: f64 = pf.iter().sum();
    let integral = f.fourier(&vec![0; dim]).re;
    let (mut in_box, mut tail_factor, mut count_term) = (0.0, 0.0f64, 0.0);
    for (power, lam, count) in &powers.sets {
        assert_eq!(power.len(), len, "powers of {}D sets", f.dim());
        in_box += power.iter().zip(&pf).map(|(v, w)| v * w).sum::<f64>() / (lam * lam);
        let ratio = *count as f64 / lam;
        tail_factor = tail_factor.max(ratio * ratio);
        count_term += (ratio - 1.0) * (ratio - 1.0) * integral * integral;
    }
    let r = powers.sets.len() as f64;
    DirectSplit {
        in_box: in_box / r,
        tail_mass: (f.variance() - box_mass).max(0.0),
        box_mass,
        tail_factor,
        count_term: count_term / r,
        intensity: powers.sets[0].1,
    }
}

/// Checks a Fourier estimate of the sets behind `powers` (on their box,
/// NUFFT `tolerance`) piece by piece against the direct split, and the exact spatial variance
/// (with its rounding bound), when there is one, against the split's
/// rigorous limits. The tolerances are the NUFFT's accuracy and
/// floating-point rounding, none from the code's own error estimates.
pub fn check_fourier(
    label: &str,
    f: &dyn Integrand,
    powers: &SetPowers,
    tolerance: f64,
    four: &varspec::variance::FourierEstimate,
    spatial: Option<&varspec::variance::SpatialEstimate>,
) {
    let d = split(f, powers);
    // c_f(0) sets the scale; the box's own mass too where the closed forms
    // of c_f(0) and P_f disagree in the last bits (a degenerate f ≈ 0).
    let scale = f.variance().max(d.box_mass);
    // |ΔS| ≤ tol·N per frequency moves |S|²/λ² by ≤ (2·tol + tol²)·(N/λ)²,
    // so the in-box sum by at most that times Σ P_f ≤ c_f(0).
    let nufft = scale * d.tail_factor * (2.0 * tolerance + tolerance * tolerance) * 1.01;
    // Plus an absolute floor: a coefficient that should be 0 comes out of
    // a closed form (a polygon's edge sum) as about ε/|k|, so P_f as
    // (ε/|k|)², and the box's sum of them near 1e-31 (a half-plane whose
    // f64 normal leaves a sliver of area 0 read 1.4e-70 in the box, where
    // the spatial form, on the smaller side since, sums to exactly 0).
    let rounding = 1e-11 * scale + 1e-30;
    assert!(
        (four.in_box - d.in_box).abs() <= nufft + rounding,
        "{label}: Fourier in-box {:e} vs direct DFT {:e} (allowed {:e})",
        four.in_box,
        d.in_box,
        nufft + rounding
    );
    let white = d.tail_mass / d.intensity;
    assert!(
        (four.tail - white).abs() <= rounding,
        "{label}: Fourier tail {:e} vs Parseval T/λ {white:e}",
        four.tail
    );
    assert!(
        (four.count_term - d.count_term).abs() <= rounding,
        "{label}: count term {:e} vs {:e}",
        four.count_term,
        d.count_term
    );
    if let Some(s) = spatial {
        let beyond = s.variance - d.count_term - d.in_box;
        let slack = s.rounding_bound + rounding;
        let most = d.tail_factor * d.tail_mass;
        assert!(
            (-slack..=most + slack).contains(&beyond),
            "{label}: spatial {:e} leaves {beyond:e} beyond the box, outside [0, {most:e}] ± {slack:e}",
            s.variance
        );
    }
}
