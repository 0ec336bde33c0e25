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

/// What rounding can put into a fitted slope: a least-squares slope of
/// logarithms of values correct to ~1e-15 relative, far below this.
pub const SLOPE_ROUNDING: f64 = 1e-9;

impl SlopeFit {
    /// Whether the 95% interval excludes `rate` (false without an
    /// interval, or without a rate). The interval is widened by
    /// [`SLOPE_ROUNDING`]: a noiseless fit (a closed form, random sampling's
    /// exact N^-1) has a zero-width interval that rounding alone moves off
    /// the rate (−0.9999999999999997 against −1).
    pub fn excludes(&self, rate: Option<f64>) -> bool {
        match (rate, self.slope_ci) {
            (Some(t), Some((low, high))) => t < low - SLOPE_ROUNDING || t > high + SLOPE_ROUNDING,
            _ => false,
        }
    }
}

/// The 97.5% quantiles of Student's t for 1..=30 degrees of freedom (the
/// two-sided 95% interval), to 9 decimals (scipy.stats.t.ppf(0.975, ν);
/// Abramowitz & Stegun Table 26.10 gives the first 3).
const T975: [f64; 30] = [
    12.706204736,
    4.302652730,
    3.182446305,
    2.776445105,
    2.570581836,
    2.446911851,
    2.364624252,
    2.306004135,
    2.262157163,
    2.228138852,
    2.200985160,
    2.178812830,
    2.160368656,
    2.144786688,
    2.131449546,
    2.119905299,
    2.109815578,
    2.100922040,
    2.093024054,
    2.085963447,
    2.079613845,
    2.073873068,
    2.068657610,
    2.063898562,
    2.059538553,
    2.055529439,
    2.051830516,
    2.048407142,
    2.045229642,
    2.042272456,
];

/// The 97.5% quantile of Student's t with `dof` degrees of freedom: the
/// table to 30, then the Cornish–Fisher expansion in 1/ν around the normal
/// quantile z (Abramowitz & Stegun 26.7.5, four terms; relative error
/// below 2e-8 from ν = 31 on).
pub(super) fn t975(dof: usize) -> f64 {
    if let Some(&t) = T975.get(dof.wrapping_sub(1)) {
        return t;
    }
    let (z, nu) = (super::NORMAL_95, dof as f64);
    let z2 = z * z;
    z + z * (z2 + 1.0) / (4.0 * nu)
        + z * ((5.0 * z2 + 16.0) * z2 + 3.0) / (96.0 * nu * nu)
        + z * (((3.0 * z2 + 19.0) * z2 + 17.0) * z2 - 15.0) / (384.0 * nu.powi(3))
        + z * ((((79.0 * z2 + 776.0) * z2 + 1482.0) * z2 - 1920.0) * z2 - 945.0)
            / (92160.0 * nu.powi(4))
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
/// gives one. `sampler` is a registry name with its default parameters; a
/// spec with parameters (`cmj:m=4`: a fixed column count, not strata near
/// 1/√N on each side) has none. The rate is an asymptotic one, which fits over a finite range of N can
/// miss by sub-leading terms (results/rates). CMJ on smooth integrands has
/// none: its correlated strata are not jitter's independent ones, and it
/// measures N^−3.06 on a Gaussian (results/rates), beyond jitter's N^−2.
/// Shifted lattices (`uniform-jitter`, `regular`, `lattice`) have none:
/// their rate depends on the integrand's shape, not its class (N^−3/2 on
/// average over a disk's radii, Kendall 1948; N^−1 on an axis-aligned
/// edge; results/rates).
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
        "cmj" if dim == 2 && class.smooth && !class.one_axis => None,
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
    fn a_noiseless_fit_agrees_with_its_rate_to_rounding() {
        // White noise's closed form, Var(f)/N, fitted over N = 64…1024:
        // slope and interval came out −0.9999999999999997.
        let exact = SlopeFit {
            slope: -0.9999999999999997,
            slope_ci: Some((-0.9999999999999997, -0.9999999999999997)),
            intercept: 0.0,
        };
        assert!(!exact.excludes(Some(-1.0)));
        // A real miss is still one, however narrow the interval.
        assert!(exact.excludes(Some(-1.0001)));
        let noisy = SlopeFit {
            slope: -1.4,
            slope_ci: Some((-1.43, -1.37)),
            intercept: 0.0,
        };
        assert!(noisy.excludes(Some(-1.5)) && !noisy.excludes(Some(-1.4)));
    }

    #[test]
    fn t_quantiles_match_scipy() {
        // scipy.stats.t.ppf(0.975, ν), computed outside the project.
        for (dof, t) in [
            (1, 12.706204736174698),
            (4, 2.7764451051977987),
            (30, 2.0422724563012373),
            (31, 2.039513446396408),
            (40, 2.021075390306273),
            (100, 1.9839715185235518),
            (1000, 1.9623390808264083),
        ] {
            assert!(
                (t975(dof) - t).abs() < 2e-8 * t,
                "ν = {dof}: {} vs {t}",
                t975(dof)
            );
        }
    }

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
