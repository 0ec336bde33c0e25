//! Gauss–Legendre quadrature, shared by the NUFFT's kernel transform and
//! the optimizer's family-averaged weights.

/// Nodes and weights of q-point Gauss–Legendre quadrature on [−1, 1]: roots
/// of P_q by Newton's method from z ≈ cos(π(i − ¼)/(q + ½)), weights
/// 2/((1 − z²) P_q'(z)²) (Abramowitz & Stegun 25.4.29).
pub fn gauss_legendre(q: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = Vec::with_capacity(q);
    let mut weights = Vec::with_capacity(q);
    for i in 1..=q {
        let mut z = (std::f64::consts::PI * (i as f64 - 0.25) / (q as f64 + 0.5)).cos();
        let mut derivative = 0.0;
        for _ in 0..100 {
            // P_q(z) by the three-term recurrence; P_q' from P_q and P_(q−1).
            let (mut p0, mut p1) = (1.0, z);
            for m in 2..=q {
                let p2 = ((2 * m - 1) as f64 * z * p1 - (m - 1) as f64 * p0) / m as f64;
                p0 = p1;
                p1 = p2;
            }
            derivative = q as f64 * (z * p1 - p0) / (z * z - 1.0);
            let step = p1 / derivative;
            z -= step;
            if step.abs() < 1e-16 {
                break;
            }
        }
        nodes.push(z);
        weights.push(2.0 / ((1.0 - z * z) * derivative * derivative));
    }
    (nodes, weights)
}

/// ∫_a^b g(x) dx by 16-point Gauss–Legendre on each of `panels` equal
/// panels (nodes computed once): for oscillatory integrands, choose a few
/// panels per oscillation.
pub fn integrate_panels(a: f64, b: f64, panels: usize, g: impl Fn(f64) -> f64) -> f64 {
    static RULE: std::sync::OnceLock<(Vec<f64>, Vec<f64>)> = std::sync::OnceLock::new();
    let (nodes, weights) = RULE.get_or_init(|| gauss_legendre(16));
    let width = (b - a) / panels as f64;
    (0..panels)
        .map(|p| {
            let mid = a + (p as f64 + 0.5) * width;
            0.5 * width
                * nodes
                    .iter()
                    .zip(weights)
                    .map(|(z, w)| w * g(mid + 0.5 * width * z))
                    .sum::<f64>()
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadrature_integrates_polynomials_exactly() {
        let (z, w) = gauss_legendre(10);
        let integral: f64 = z.iter().zip(&w).map(|(z, w)| w * z.powi(18)).sum();
        assert!((integral - 2.0 / 19.0).abs() < 1e-14);
        assert!((w.iter().sum::<f64>() - 2.0).abs() < 1e-14);
    }

    #[test]
    fn panels_integrate_oscillations() {
        let exact = (1.0 - (2.0 * 50.0f64).cos()) / 50.0; // ∫_0^2 sin(50x) dx
        assert!((integrate_panels(0.0, 2.0, 40, |x| (50.0 * x).sin()) - exact).abs() < 1e-13);
    }
}
