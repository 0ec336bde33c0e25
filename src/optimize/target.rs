//! Optimization targets: the weight W(k) of the loss
//! L(X) = Σ_(0<|k|∞≤K) W(k)·P_S(k) (docs/mathematics.md §6).
//!
//! * an integrand spec: W = P_f, so L is the predicted variance itself
//!   (within the box);
//! * `family:disks`: W averaged over disks of radius r ~ U[0.05, 0.45] at
//!   uniform centres, E_r[(r·J1(2πr|k|)/|k|)²] — isotropic, ∝ |k|^-3 far out:
//!   a CCVT-like blue-noise target (the centre only changes the phase);
//! * `power:A`: W = |k|^-A;
//! * `radial:FILE.csv`: W(|k|) linearly interpolated from columns `k,weight`
//!   (0 beyond the table; scaled so that the largest weight is 1).

use std::path::Path;

use rayon::prelude::*;

use super::OptimizeError;
use crate::integrands;
use crate::quadrature::integrate_panels;
use crate::spectrum::FrequencyBox;

/// A parsed target.
#[derive(Debug, Clone)]
pub enum Target {
    /// W = P_f of this integrand.
    Integrand(String),
    /// Disks with random centre and radius in [0.05, 0.45].
    FamilyDisks,
    /// W = |k|^-A.
    Power(f64),
    /// W(|k|) from a table of (k, weight), sorted by k.
    Radial(Vec<(f64, f64)>),
}

impl Target {
    /// Parses `family:disks`, `power:A`, `radial:FILE.csv` or an integrand
    /// spec.
    ///
    /// # Errors
    /// [`OptimizeError::Target`] naming what is wrong (unknown family, bad
    /// exponent, unreadable or malformed table with its line), or the
    /// integrand's own error.
    pub fn parse(spec: &str) -> Result<Self, OptimizeError> {
        let fail = |reason: String| OptimizeError::Target {
            spec: spec.to_string(),
            reason,
        };
        if let Some(family) = spec.strip_prefix("family:") {
            return match family {
                "disks" => Ok(Target::FamilyDisks),
                other => Err(fail(format!("unknown family `{other}` (known: disks)"))),
            };
        }
        if let Some(a) = spec.strip_prefix("power:") {
            return match a.parse::<f64>() {
                Ok(a) if a.is_finite() && a > 0.0 => Ok(Target::Power(a)),
                _ => Err(fail(format!("`{a}` is not a positive exponent"))),
            };
        }
        if let Some(file) = spec.strip_prefix("radial:") {
            return read_radial(Path::new(file))
                .map(Target::Radial)
                .map_err(fail);
        }
        match integrands::parse(spec) {
            // Every set integrates a constant exactly: the descent would
            // report a loss of 0 and "improve" nothing.
            Ok(f) if f.variance() == 0.0 => Err(fail(
                "the integrand is constant (variance 0): every point set integrates it exactly, \
                 so there is nothing to design for; give one that varies"
                    .into(),
            )),
            Ok(_) => Ok(Target::Integrand(spec.to_string())),
            Err(integrands::IntegrandError::Unknown { name, .. })
                if name
                    .split_once('*')
                    .is_some_and(|(w, _)| w.trim().parse::<f64>().is_ok()) =>
            {
                Err(fail(format!(
                    "`{name}`: a weight W* belongs to a term of a sum (--domain square: \
                     `A+2*B`) or of a 4D projection target (`xy:A;2*uv:B`); a lone target takes none"
                )))
            }
            Err(integrands::IntegrandError::Unknown {
                name,
                known,
                suggestion,
            }) => Err(fail(format!(
                "`{name}`{} is neither an integrand ({known}) nor family:disks, \
                 power:A or radial:FILE.csv",
                elsewhere(&name).unwrap_or(suggestion)
            ))),
            Err(e) => Err(e.into()),
        }
    }

    /// W(k) over the box (box order), W(0) = 0.
    ///
    /// # Errors
    /// An integrand target whose dimension differs from the box's.
    pub fn weights(&self, freqs: &FrequencyBox) -> Result<Vec<f64>, OptimizeError> {
        let integrand = match self {
            Target::Integrand(spec) => {
                let f = integrands::parse(spec)?;
                if f.dim() != freqs.dim {
                    return Err(OptimizeError::Target {
                        spec: spec.clone(),
                        reason: format!(
                            "a {}D integrand cannot weight {}D points",
                            f.dim(),
                            freqs.dim
                        ),
                    });
                }
                Some(f)
            }
            _ => None,
        };
        let zero = freqs.zero_index();
        let squared_norm = |idx: usize, k: &mut [i64]| {
            freqs.frequency(idx, k);
            k.iter().map(|v| v * v).sum::<i64>()
        };
        if let Some(f) = integrand {
            let w = (0..freqs.len())
                .into_par_iter()
                .map_init(
                    || vec![0i64; freqs.dim],
                    |k, idx| {
                        freqs.frequency(idx, k);
                        if idx == zero {
                            0.0
                        } else {
                            f.fourier(k).norm_sqr()
                        }
                    },
                )
                .collect();
            return Ok(w);
        }
        // The other targets are isotropic: evaluate once per distinct |k|².
        let mut k = vec![0i64; freqs.dim];
        let mut radii: Vec<i64> = (0..freqs.len())
            .map(|idx| squared_norm(idx, &mut k))
            .collect();
        radii.sort_unstable();
        radii.dedup();
        let values: Vec<f64> = radii
            .par_iter()
            .map(|&r2| {
                let norm = (r2 as f64).sqrt();
                match self {
                    _ if r2 == 0 => 0.0,
                    Target::FamilyDisks => disk_family_power(norm),
                    Target::Power(a) => norm.powf(-a),
                    Target::Radial(table) => interpolate(table, norm),
                    Target::Integrand(_) => unreachable!("handled above"),
                }
            })
            .collect();
        let w = (0..freqs.len())
            .map(|idx| {
                values[radii
                    .binary_search(&squared_norm(idx, &mut k))
                    .expect("every radius was collected")]
            })
            .collect();
        Ok(w)
    }
}

/// E_r[(r·J1(2πr|k|)/|k|)²] for r ~ U[0.05, 0.45], by panelled 16-point
/// Gauss–Legendre, a panel per four half-oscillations of J1² (0.8·|k| of
/// them over the range): four nodes per half-oscillation.
fn disk_family_power(k: f64) -> f64 {
    let panels = 2 + (0.2 * k).ceil() as usize;
    let mean = integrate_panels(0.05, 0.45, panels, |r| {
        let j = libm::j1(std::f64::consts::TAU * r * k);
        r * r * j * j
    }) / 0.4;
    mean / (k * k)
}

fn interpolate(table: &[(f64, f64)], k: f64) -> f64 {
    match table.iter().position(|&(tk, _)| tk >= k) {
        Some(0) => table[0].1,
        Some(i) => {
            let ((k0, w0), (k1, w1)) = (table[i - 1], table[i]);
            w0 + (w1 - w0) * (k - k0) / (k1 - k0)
        }
        None => 0.0,
    }
}

fn read_radial(path: &Path) -> Result<Vec<(f64, f64)>, String> {
    let text = crate::io::read_text_bounded(path, 64 << 20, "a radial weight table")
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    match lines.next() {
        Some((_, h)) if h.replace(' ', "") == "k,weight" => {}
        _ => {
            return Err(format!(
                "{}:1: the header must be `k,weight`",
                path.display()
            ));
        }
    }
    let mut table = Vec::new();
    for (i, line) in lines {
        let bad = || {
            format!(
                "{}:{}: expected two numbers `k,weight` with k increasing and weight >= 0",
                path.display(),
                i + 1
            )
        };
        let (k, w) = line.split_once(',').ok_or_else(bad)?;
        let (k, w): (f64, f64) = (
            k.trim().parse().map_err(|_| bad())?,
            w.trim().parse().map_err(|_| bad())?,
        );
        if !k.is_finite()
            || !w.is_finite()
            || w < 0.0
            || table.last().is_some_and(|&(pk, _)| k <= pk)
        {
            return Err(bad());
        }
        table.push((k, w));
    }
    let largest = table.iter().fold(0.0f64, |m, &(_, w)| m.max(w));
    if table.is_empty() || largest == 0.0 {
        return Err(format!(
            "{}: no positive weight: nothing to optimize",
            path.display()
        ));
    }
    // The optimum does not depend on the scale of W; dividing by the
    // largest weight keeps the loss and its gradient finite (weights near
    // f64::MAX would overflow them).
    Ok(table.into_iter().map(|(k, w)| (k, w / largest)).collect())
}

/// What an unknown torus target's name is where it means something: a
/// plane of a 4D set, or a family of the unit square.
fn elsewhere(name: &str) -> Option<String> {
    const PLANES: [&str; 6] = ["xy", "uv", "xu", "yv", "xv", "yu"];
    let name = name.trim().to_lowercase();
    if name.len() == 2 && name.chars().all(|c| "xyuv".contains(c)) {
        return Some(if PLANES.contains(&name.as_str()) {
            " (a plane of a 4D set: projection targets such as `xy:family:disks;uv:family:disks` \
             need -d 4)"
                .to_string()
        } else {
            format!(" (planes of a 4D set: {})", PLANES.join(", "))
        });
    }
    ["gaussians", "halfplanes", "disks", "boxes"]
        .contains(&name.as_str())
        .then(|| " (a family of the unit square: --domain square)".to_string())
}

/// The files a target spec of `optimize points` reads on `domain`, split
/// as its parser splits it: on the torus `radial:FILE` (the whole target,
/// or a projection's `xu:radial:FILE` between `;`, see
/// [`crate::optimize::projections`]: a `+` belongs to the file name); on
/// the square a family's `file:PATH` (a term between `+`, after an
/// optional `W*`, see [`crate::square::design::parse_target`]). Callers
/// keep their outputs off these files.
pub fn files_read(spec: &str, domain: crate::optimize::adam::Domain) -> Vec<&Path> {
    use crate::optimize::adam::Domain;
    let (separator, prefix) = match domain {
        Domain::Torus => (';', "radial:"),
        Domain::Square => ('+', "file:"),
    };
    let mut files: Vec<&Path> = spec
        .split(separator)
        .filter_map(|part| {
            let part = match domain {
                Domain::Square => part.split_once('*').map_or(part, |(_, family)| family),
                Domain::Torus => part,
            };
            part.find(prefix).map(|at| &part[at + prefix.len()..])
        })
        .map(|path| Path::new(path.trim()))
        .collect();
    // A 2D or 3D torus target is one `radial:FILE`, whose name may hold a
    // `;` (only 4D projection targets are split there).
    if let (Domain::Torus, Some(whole)) = (domain, spec.strip_prefix("radial:")) {
        let whole = Path::new(whole.trim());
        if !files.contains(&whole) {
            files.push(whole);
        }
    }
    files
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_files_a_target_reads_in_every_grammar() {
        use crate::optimize::adam::Domain::{Square, Torus};
        for (spec, domain, files) in [
            ("family:disks", Torus, vec![]),
            ("radial:w.csv", Torus, vec!["w.csv"]),
            // A `+` in a torus target's file name is part of it.
            ("radial:w+1.csv", Torus, vec!["w+1.csv"]),
            // ... and so may a `;` (the 4D reading is kept too).
            ("radial:w;1.csv", Torus, vec!["w", "w;1.csv"]),
            (
                "xu:radial:a+b.csv;yv:power:3;uv:radial:b.csv",
                Torus,
                vec!["a+b.csv", "b.csv"],
            ),
            ("halfplanes+2*file:m.txt+16*blue", Square, vec!["m.txt"]),
            ("disk:r=0.3", Torus, vec![]),
        ] {
            let found: Vec<&str> = files_read(spec, domain)
                .iter()
                .map(|p| p.to_str().unwrap())
                .collect();
            assert_eq!(found, files, "{spec}");
        }
    }

    #[test]
    fn disk_family_decays_like_k_cubed() {
        // Far out J1(z)² averages to 1/(πz): W → E[r]/(2π²|k|³) = 0.25/(2π²k³).
        for k in [200.0, 400.0] {
            let ratio =
                disk_family_power(k) / (0.25 / (2.0 * std::f64::consts::PI.powi(2) * k * k * k));
            assert!((ratio - 1.0).abs() < 0.02, "k = {k}: ratio {ratio}");
        }
        assert!(disk_family_power(1.0) > disk_family_power(5.0));
        // Four times finer panels change nothing at 1e-9.
        for k in [3.0f64, 47.0, 301.0] {
            let fine = crate::quadrature::integrate_panels(
                0.05,
                0.45,
                2 + (0.8 * k).ceil() as usize,
                |r| {
                    let j = libm::j1(std::f64::consts::TAU * r * k);
                    r * r * j * j
                },
            ) / 0.4
                / (k * k);
            assert!((disk_family_power(k) / fine - 1.0).abs() < 1e-9, "k = {k}");
        }
    }

    #[test]
    fn targets_parse_and_refuse() {
        assert!(matches!(
            Target::parse("family:disks"),
            Ok(Target::FamilyDisks)
        ));
        assert!(matches!(Target::parse("power:3"), Ok(Target::Power(a)) if a == 3.0));
        assert!(Target::parse("power:-1").is_err());
        assert!(
            Target::parse("family:boxes")
                .unwrap_err()
                .to_string()
                .contains("unknown family")
        );
        assert!(
            Target::parse("radial:/nonexistent.csv")
                .unwrap_err()
                .to_string()
                .contains("/nonexistent.csv")
        );
        assert!(matches!(
            Target::parse("disk:r=0.2"),
            Ok(Target::Integrand(_))
        ));
        assert!(Target::parse("disk:r=0.7").is_err());
        // Constant integrands leave nothing to design for.
        for constant in ["cos:kx=0,ky=0", "box:w=1,h=1"] {
            assert!(
                matches!(Target::parse(constant), Err(OptimizeError::Target { ref reason, .. }) if reason.contains("constant")),
                "{constant}"
            );
        }
    }

    #[test]
    fn radial_tables_are_scaled_to_a_largest_weight_of_one() {
        let dir = std::env::temp_dir().join(format!("varspec-radial-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("w.csv");
        std::fs::write(&path, "k,weight\n1,1e308\n10,5e307\n30,0\n").unwrap();
        assert_eq!(
            read_radial(&path).unwrap(),
            vec![(1.0, 1.0), (10.0, 0.5), (30.0, 0.0)]
        );
        std::fs::write(&path, "k,weight\n1,0\n2,0\n").unwrap();
        assert!(
            read_radial(&path)
                .unwrap_err()
                .contains("no positive weight")
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn radial_table_interpolates() {
        let t = vec![(1.0, 2.0), (3.0, 4.0)];
        assert_eq!(interpolate(&t, 2.0), 3.0);
        assert_eq!(interpolate(&t, 0.5), 2.0);
        assert_eq!(interpolate(&t, 5.0), 0.0);
    }
}
