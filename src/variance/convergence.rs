//! Convergence rates: the least-squares slope of log Var against log N with
//! its 95% confidence interval (Student t with n − 2 degrees of freedom on
//! the residual scatter), and the theoretical rates of docs/mathematics.md
//! (Pilleboue et al. 2015, Table 1; Singh & Jarosz 2017).

use crate::integrands::IntegrandClass;

/// A fitted power law Var ≈ a·N^slope.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SlopeFit {
    /// The slope of log Var on log N.
    pub slope: f64,
    /// 95% confidence interval of the slope; `None` with fewer than 3 points.
    pub slope_ci: Option<(f64, f64)>,
    /// log Var at log N = 0.
    pub intercept: f64,
}

/// Two-sided 97.5% quantiles of Student's t for 1..=30 degrees of freedom.
const T975: [f64; 30] = [
    12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
    2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
    2.052, 2.048, 2.045, 2.042,
];

fn t975(dof: usize) -> f64 {
    T975.get(dof.wrapping_sub(1))
        .copied()
        .unwrap_or(1.96 + 2.4 / dof as f64)
}

/// Why no slope can be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("no convergence slope: {0}")]
pub struct SlopeError(String);

/// Least-squares fit of log(var) on log(n).
///
/// # Errors
/// [`SlopeError`] for lists of different lengths, fewer than two distinct
/// N (the slope is undefined), or an N or a variance that is not a finite
/// positive number (its logarithm is undefined).
pub fn fit_slope(ns: &[f64], vars: &[f64]) -> Result<SlopeFit, SlopeError> {
    if ns.len() != vars.len() {
        return Err(SlopeError(format!(
            "{} N values against {} variances",
            ns.len(),
            vars.len()
        )));
    }
    if let Some(v) = ns
        .iter()
        .chain(vars)
        .find(|v| !(v.is_finite() && **v > 0.0))
    {
        return Err(SlopeError(format!(
            "{v} is not a positive number (N and variances are fitted on a log scale)"
        )));
    }
    if ns.iter().all(|&n| n == ns[0]) {
        return Err(SlopeError(format!(
            "fewer than two distinct N ({:?})",
            ns.first()
        )));
    }
    let x: Vec<f64> = ns.iter().map(|n| n.ln()).collect();
    let y: Vec<f64> = vars.iter().map(|v| v.ln()).collect();
    let m = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / m, y.iter().sum::<f64>() / m);
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let slope_ci = (x.len() > 2).then(|| {
        let rss: f64 = x
            .iter()
            .zip(&y)
            .map(|(a, b)| (b - intercept - slope * a).powi(2))
            .sum();
        let se = (rss / (m - 2.0) / sxx).sqrt();
        let t = t975(x.len() - 2);
        (slope - t * se, slope + t * se)
    });
    Ok(SlopeFit {
        slope,
        slope_ci,
        intercept,
    })
}

/// The theoretical variance rate (exponent of N) of `sampler` on an
/// integrand of class `class` in `dim` dimensions, where the theory table
/// gives one.
pub fn theoretical_rate(sampler: &str, class: IntegrandClass, dim: usize) -> Option<f64> {
    let d = dim as f64;
    let jitter = if class.smooth {
        -(1.0 + 2.0 / d)
    } else {
        -(1.0 + 1.0 / d)
    };
    // 1D stratification: smooth −3, a step −2.
    let one_axis = if class.smooth { -3.0 } else { -2.0 };
    match sampler {
        "random" | "poisson-disk" | "pd" => Some(-1.0),
        "jitter" | "stratified" => Some(jitter),
        "nrooks" | "lhs" => Some(if class.one_axis { one_axis } else { -1.0 }),
        "multijitter" | "mj" | "cmj" if dim == 2 => {
            Some(if class.one_axis { one_axis } else { jitter })
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_power_law_has_its_slope_and_a_tight_interval() {
        let ns = [64.0, 256.0, 1024.0, 4096.0];
        let vars: Vec<f64> = ns.iter().map(|n: &f64| 3.0 * n.powf(-1.5)).collect();
        let fit = fit_slope(&ns, &vars).unwrap();
        assert!((fit.slope + 1.5).abs() < 1e-12);
        let (lo, hi) = fit.slope_ci.unwrap();
        assert!(lo <= -1.5 + 1e-9 && hi >= -1.5 - 1e-9 && hi - lo < 1e-9);
    }

    #[test]
    fn scatter_widens_the_interval() {
        let ns = [64.0, 256.0, 1024.0, 4096.0, 16384.0];
        let noise = [1.1, 0.9, 1.05, 0.95, 1.0];
        let vars: Vec<f64> = ns
            .iter()
            .zip(noise)
            .map(|(n, e): (&f64, f64)| e * n.powi(-2))
            .collect();
        let fit = fit_slope(&ns, &vars).unwrap();
        let (lo, hi) = fit.slope_ci.unwrap();
        // Reference: NumPy's lstsq and SciPy's t.ppf(0.975, 3) = 3.18245 on
        // the same five points give slope −2.0098502 and half-width
        // 0.0639771 (the table's t = 3.182 moves it by 1e-5).
        assert!((fit.slope + 2.009_850_2).abs() < 1e-6, "{}", fit.slope);
        assert!(((hi - lo) / 2.0 - 0.063_977).abs() < 5e-5, "{lo} {hi}");
    }

    #[test]
    fn undefined_slopes_are_errors() {
        for (ns, vars, phrase) in [
            (&[16.0, 16.0][..], &[1e-3, 2e-3][..], "distinct N"),
            (&[16.0, 64.0], &[1e-3, 0.0], "positive"),
            (&[16.0, 64.0], &[1e-3, f64::NAN], "positive"),
            (&[16.0, 64.0, 256.0], &[1e-3, 2e-3], "N values against"),
        ] {
            let e = fit_slope(ns, vars).unwrap_err().to_string();
            assert!(e.contains(phrase), "{e}");
        }
    }
}
