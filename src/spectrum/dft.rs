//! The direct (naive) discrete Fourier sums: the exact reference every fast
//! path is checked against (like RustFFT's naive `Dft`, docs/architecture.md, "Conventions").
//!
//! Every exponential uses exact phase reduction ([`super::phase`]), so
//! frequencies up to 10^4 keep 1e-12 accuracy.

use rayon::prelude::*;
use rustfft::num_complex::Complex64;

use super::FrequencyBox;
use super::phase::{phasor, reduced_phase};
use crate::points::PointSet;

/// Points per block of phase tables (bounds memory at d·block·(2h+1)
/// complex numbers; the block order fixes the summation order).
const BLOCK: usize = 1024;

/// S(k) = Σ_j e^(−2πi k·x_j) (unnormalized) for every k of `freqs`, in the
/// box's order.
///
/// Cost O(N·|B|) multiply-adds after O(N·d·(2h+1)) exactly reduced
/// exponentials; parallel over rows of the box, each row summed in point
/// order, so the result does not depend on the thread count.
///
/// # Panics
/// If the points' dimension differs from the box's.
pub fn sample_spectrum(points: &PointSet, freqs: &FrequencyBox) -> Vec<Complex64> {
    let d = freqs.dim;
    assert_eq!(
        points.dim(),
        d,
        "points and frequency box differ in dimension"
    );
    let side = freqs.side();
    let h = freqs.half as i64;
    let mut out = vec![Complex64::new(0.0, 0.0); freqs.len()];
    for block in points.coords().chunks(BLOCK * d) {
        let count = block.len() / d;
        // table[(j·d + dim)·side + (k + h)] = e^(−2πi k x_j,dim)
        let mut table = vec![Complex64::new(0.0, 0.0); count * d * side];
        table.par_chunks_mut(side).enumerate().for_each(|(row, t)| {
            let x = block[row];
            for (slot, k) in t.iter_mut().zip(-h..=h) {
                *slot = phasor(reduced_phase(k, x));
            }
        });
        out.par_chunks_mut(side).enumerate().for_each(|(r, row)| {
            // r indexes the frequencies of dimensions 1..d (k_0 runs along the row).
            let mut rest = r;
            let outer: Vec<usize> = (1..d)
                .map(|_| {
                    let i = rest % side;
                    rest /= side;
                    i
                })
                .collect();
            for j in 0..count {
                let t = &table[j * d * side..(j + 1) * d * side];
                let weight = outer
                    .iter()
                    .enumerate()
                    .fold(Complex64::new(1.0, 0.0), |acc, (m, &i)| {
                        acc * t[(m + 1) * side + i]
                    });
                for (o, e) in row.iter_mut().zip(&t[..side]) {
                    *o += weight * e;
                }
            }
        });
    }
    out
}

/// The type-2 sum c_j = Σ_k F(k) e^(+2πi k·x_j) evaluated directly at every
/// point (reference for [`super::nufft::NufftPlan::type2`]).
///
/// # Panics
/// If `coeffs` is not one value per frequency of `freqs`, or dimensions differ.
pub fn evaluate_series(
    points: &PointSet,
    freqs: &FrequencyBox,
    coeffs: &[Complex64],
) -> Vec<Complex64> {
    assert_eq!(coeffs.len(), freqs.len());
    assert_eq!(points.dim(), freqs.dim);
    let d = freqs.dim;
    (0..points.len())
        .into_par_iter()
        .map(|j| {
            let x = points.point(j);
            let mut k = vec![0i64; d];
            coeffs
                .iter()
                .enumerate()
                .fold(Complex64::new(0.0, 0.0), |acc, (idx, &c)| {
                    freqs.frequency(idx, &mut k);
                    let t: f64 = k
                        .iter()
                        .zip(x)
                        .map(|(&kj, &xj)| reduced_phase(kj, xj))
                        .sum();
                    acc + c * phasor(t).conj()
                })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::phase::exp_neg_2pi_i;

    #[test]
    fn one_point_has_unit_modulus_and_its_own_phase() {
        let p = PointSet::new(2, vec![0.3, 0.7]).unwrap();
        let b = FrequencyBox { dim: 2, half: 3 };
        let s = sample_spectrum(&p, &b);
        let mut k = [0i64; 2];
        for (idx, v) in s.iter().enumerate() {
            b.frequency(idx, &mut k);
            assert!((v - exp_neg_2pi_i(&k, &[0.3, 0.7])).norm() < 1e-15);
        }
    }

    #[test]
    fn regular_lattice_is_n_at_multiples_of_m_and_zero_elsewhere() {
        let m = 8;
        let coords = (0..m * m)
            .flat_map(|i| {
                [
                    ((i % m) as f64 + 0.5) / m as f64,
                    ((i / m) as f64 + 0.5) / m as f64,
                ]
            })
            .collect();
        let p = PointSet::new(2, coords).unwrap();
        let b = FrequencyBox { dim: 2, half: 20 };
        let s = sample_spectrum(&p, &b);
        let mut k = [0i64; 2];
        for (idx, v) in s.iter().enumerate() {
            b.frequency(idx, &mut k);
            let on_lattice = k[0] % m as i64 == 0 && k[1] % m as i64 == 0;
            let power = v.norm_sqr() / (m * m) as f64;
            let expected = if on_lattice { (m * m) as f64 } else { 0.0 };
            assert!((power - expected).abs() < 1e-9, "k = {k:?}: power {power}");
        }
    }
}
