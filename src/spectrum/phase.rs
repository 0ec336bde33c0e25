//! Exact phase reduction: e^(−2πi k·x) for large integer k without losing
//! digits to k·x's magnitude.
//!
//! A double x times an integer k ≤ 2^53 is split exactly into p + e with
//! p = fl(k·x) and e = fma(k, x, −p) (the two-product of Dekker 1971 /
//! Ogita, Rump & Oishi 2005). p − round(p) is exact, so the reduced phase
//! (p − round(p)) + e carries only the final rounding: the phase of k·x mod 1
//! is accurate to about 1e-16 whatever k, where fl(k·x) alone loses
//! log10(k) digits.

use rustfft::num_complex::Complex64;

/// k·x mod 1, reduced to about [−½, ½], accurate to a few ulps of ½.
#[inline]
pub fn reduced_phase(k: i64, x: f64) -> f64 {
    reduced_product(k as f64, x)
}

/// w·x mod 1 for any doubles w and x (a real frequency times a
/// coordinate), reduced to about [−½, ½] by the same exact two-product:
/// the product's rounding, |w·x|·2⁻⁵³, never enters the phase.
#[inline]
pub fn reduced_product(w: f64, x: f64) -> f64 {
    let p = w * x;
    let e = w.mul_add(x, -p);
    (p - p.round()) + e
}

/// e^(−2πi t) for a phase t already reduced near [−½, ½].
#[inline]
pub fn phasor(t: f64) -> Complex64 {
    let t = t - t.round();
    let (s, c) = (std::f64::consts::TAU * t).sin_cos();
    Complex64::new(c, -s)
}

/// e^(2πi t) for a real t, reduced modulo 1 first (the conjugate of
/// [`phasor`]).
#[inline]
pub fn turn(t: f64) -> Complex64 {
    phasor(t).conj()
}

/// sin(πu)/(πu), 1 at 0 (a Taylor term for |πu| < 1e-4), with |u| > 1
/// reduced modulo 2 before the sine, exactly, so large |u| keeps its
/// accuracy.
#[inline]
pub fn sinc_pi(u: f64) -> f64 {
    let pu = std::f64::consts::PI * u;
    if u.abs() <= 1.0 {
        return if pu.abs() < 1e-4 {
            1.0 - pu * pu / 6.0
        } else {
            pu.sin() / pu
        };
    }
    let r = u - 2.0 * (0.5 * u).round();
    (std::f64::consts::PI * r).sin() / pu
}

/// e^(−2πi k·x) with exact phase reduction in every coordinate.
pub fn exp_neg_2pi_i(k: &[i64], x: &[f64]) -> Complex64 {
    let t: f64 = k
        .iter()
        .zip(x)
        .map(|(&kj, &xj)| reduced_phase(kj, xj))
        .sum();
    phasor(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// x = M·2^−e exactly; k·x mod 1 is (k·M mod 2^e)·2^−e in integers.
    fn exact_phase(k: i64, x: f64) -> f64 {
        let bits = x.to_bits();
        let exponent = ((bits >> 52) & 0x7ff) as i32 - 1075;
        let mantissa = (bits & ((1 << 52) - 1)) | (1 << 52);
        assert!(exponent < 0 && -exponent < 100);
        let modulus = 1u128 << (-exponent);
        let r = ((k.unsigned_abs() as u128) * mantissa as u128) % modulus;
        let frac = r as f64 / modulus as f64;
        if k < 0 { -frac } else { frac }
    }

    #[test]
    fn large_frequencies_keep_1e_12_accuracy() {
        let x = 0.123456789;
        let mut worst_naive: f64 = 0.0;
        for k in (1..=10_000i64).step_by(7).chain([9_999, 10_000, -10_000]) {
            let reference = phasor(exact_phase(k, x));
            let ours = exp_neg_2pi_i(&[k], &[x]);
            assert!(
                (ours - reference).norm() < 1e-12,
                "k = {k}: {ours} vs {reference}"
            );
            let naive = Complex64::from_polar(1.0, -std::f64::consts::TAU * k as f64 * x);
            worst_naive = worst_naive.max((naive - reference).norm());
        }
        // The naive product loses digits (documents why the reduction exists).
        assert!(worst_naive > 1e-13, "naive error {worst_naive}");
    }

    #[test]
    fn real_frequencies_reduce_exactly() {
        // w = (2^52 + 1)/2^24 and x = m/2^20 are exact doubles whose product
        // needs 72 bits; w·x mod 1 is ((2^52 + 1)·m mod 2^44)/2^44 in
        // integers.
        let w = ((1u64 << 52) + 1) as f64 / f64::from(1u32 << 24);
        let mut worst_naive: f64 = 0.0;
        for m in [1u128, 777_777, 1_048_575, 524_289, 3] {
            let x = m as f64 / f64::from(1u32 << 20);
            let r = (((1u128 << 52) + 1) * m) % (1 << 44);
            let exact = r as f64 / (1u64 << 44) as f64;
            let exact = exact - exact.round();
            let ours = reduced_product(w, x);
            assert!((ours - exact).abs() < 1e-15, "m = {m}: {ours} vs {exact}");
            let naive = w * x - (w * x).round();
            worst_naive = worst_naive.max((naive - exact).abs());
        }
        // fl(w·x) alone is up to ~10⁸, and its rounding (up to 7e-9) lands
        // in the phase.
        assert!(worst_naive > 1e-10, "naive error {worst_naive}");
    }
}
