//! Targets per 2D projection of a 4D set, the seed's design principle
//! (Singh & Jarosz 2017, §7; the course's "desired spectra in XU and YV"):
//! one descent in 4D on
//!
//!   L(X) = Σ_t w_t · L_t(M_t X) / L_t(M_t X₀),
//!
//! where each M_t maps (x, y, u, v) linearly onto a plane, z = M_t x mod 1,
//! and L_t is the 2D spectral loss Σ_k W_t(k) P_S(k) of the projected set
//! with its own weights ([`super::descent`]: the same NUFFT gradients). The
//! gradient comes back through M_tᵀ.
//!
//! Terms (separated by `;`):
//! - `xy:SPEC`, `uv:SPEC`, `xu:SPEC`, `yv:SPEC`, `xv:SPEC`, `yu:SPEC`: a
//!   coordinate plane with a 2D target (`family:disks`, `power:A`,
//!   `radial:FILE`, a 2D integrand), or with a 4D integrand, whose spectrum
//!   on that plane (the other two frequencies zero) is the weight;
//! - a `defocus` light field: the (x, y)-shifted estimator's variance of a
//!   4D set on f(x, u) = g(x + c(u − ½)) is the torus variance of g on the
//!   sheared projection z = (x + c·u, y + c·v) (Σ_k |G(k)|² P_z(k): the
//!   phases e^(2πik·(x + c u)) are exactly z's), so that term is the plane
//!   M = [[1, 0, c, 0], [0, 1, 0, c]] with g as its 2D target.
//!
//! Each term is scaled by its value at the start so the weights compare
//! relative gains; `W*TERM` weights a term.

use std::sync::Mutex;

use super::adam::PointObjective;
use super::descent::{DescentOptions, PointOptimizer, Work};
use super::{OptimizeError, Target};
use crate::integrands;
use crate::points::{PointSet, wrap01};
use crate::spectrum::FrequencyBox;

/// One plane of a projection target.
pub struct ProjectionTerm {
    /// What the user wrote.
    pub label: String,
    /// The two rows of M.
    pub rows: [[f64; 4]; 2],
    /// w_t.
    pub weight: f64,
    optimizer: PointOptimizer,
}

impl ProjectionTerm {
    /// z = M x mod 1 for every point.
    pub fn project(&self, points: &PointSet) -> PointSet {
        let coords = points
            .points()
            .flat_map(|p| {
                self.rows
                    .map(|row| wrap01(row.iter().zip(p).map(|(m, x)| m * x).sum::<f64>()))
            })
            .collect();
        PointSet::new(2, coords).expect("wrapped coordinates lie in [0,1)")
    }

    /// The 2D loss of the projected set.
    pub fn loss(&self, points: &PointSet) -> f64 {
        self.optimizer.loss(&self.project(points))
    }

    /// Half-width of the term's frequency box on its plane.
    pub fn half(&self) -> usize {
        self.optimizer.frequencies().half
    }
}

/// Whether `spec` is a projection target rather than a plain one.
pub fn is_projection_target(spec: &str) -> bool {
    spec.contains(';')
        || ["xy:", "uv:", "xu:", "yv:", "xv:", "yu:"]
            .iter()
            .any(|p| spec.starts_with(p) || spec.contains(&format!("*{p}")))
}

/// Parses a projection target for N points in 4D.
///
/// # Errors
/// [`OptimizeError::Target`] naming the bad term.
pub fn parse_projections(spec: &str, n: usize) -> Result<Vec<ProjectionTerm>, OptimizeError> {
    let fail = |reason: String| OptimizeError::Target {
        spec: spec.to_string(),
        reason,
    };
    let mut terms = Vec::new();
    let parts: Vec<&str> = spec.split(';').map(str::trim).collect();
    for (i, &part) in parts.iter().enumerate() {
        if part.is_empty() {
            // One trailing `;` marks a lone term as a projection target
            // (`'defocus:…;'`); any other empty term is a typing slip.
            if i > 0 && i == parts.len() - 1 {
                continue;
            }
            return Err(fail(format!(
                "term {} of {} is empty (a leading `;` or `;;`): remove it",
                i + 1,
                parts.len()
            )));
        }
        if parts[..i].contains(&part) {
            return Err(fail(format!(
                "`{part}` is given twice: write one term with a weight (2*TERM) instead"
            )));
        }
        let (weight, part) = match part.split_once('*') {
            Some((w, rest)) if w.trim().parse::<f64>().is_ok() => (
                crate::spec_params::term_weight(w).map_err(fail)?,
                rest.trim(),
            ),
            _ => (1.0, part),
        };
        let planes = [
            ("xy", [0, 1]),
            ("uv", [2, 3]),
            ("xu", [0, 2]),
            ("yv", [1, 3]),
            ("xv", [0, 3]),
            ("yu", [1, 2]),
        ];
        let plane = planes
            .iter()
            .find(|(name, _)| part.strip_prefix(name).is_some_and(|r| r.starts_with(':')));
        let (rows, target, slice) = match plane {
            Some(&(name, [i, j])) => {
                let inner = &part[name.len() + 1..];
                let mut rows = [[0.0; 4]; 2];
                rows[0][i] = 1.0;
                rows[1][j] = 1.0;
                match integrands::parse(inner) {
                    Ok(f) if f.dim() == 4 => (rows, None, Some((f, [i, j]))),
                    _ => (rows, Some(Target::parse(inner)?), None),
                }
            }
            None => {
                let f = integrands::parse(part).map_err(|e| {
                    fail(format!(
                        "`{part}` is neither PLANE:SPEC nor a 4D light field: {e}"
                    ))
                })?;
                let light = f.light_field().filter(|l| l.layer_shears().len() == 1).ok_or_else(|| {
                    fail(format!(
                        "`{part}`: a 4D term must be a one-layer light field (defocus), whose variance is a sheared projection's"
                    ))
                })?;
                let c = -light.layer_shears()[0][0];
                let g = light.layer_shapes().remove(0);
                (
                    [[1.0, 0.0, c, 0.0], [0.0, 1.0, 0.0, c]],
                    Some(Target::parse(&g)?),
                    None,
                )
            }
        };
        let optimizer = match (target, slice) {
            (Some(t), _) => PointOptimizer::new(2, &t, DescentOptions::for_target(n, 2, &t))?,
            (None, Some((f, [i, j]))) => {
                let t = Target::Integrand(f.spec());
                let options = DescentOptions::for_target(n, 2, &t);
                let freqs = FrequencyBox {
                    dim: 2,
                    half: options.half,
                };
                let zero = freqs.zero_index();
                let weights = (0..freqs.len())
                    .map(|idx| {
                        let mut k2 = [0i64; 2];
                        freqs.frequency(idx, &mut k2);
                        let mut k = [0i64; 4];
                        k[i] = k2[0];
                        k[j] = k2[1];
                        if idx == zero {
                            0.0
                        } else {
                            f.fourier(&k).norm_sqr()
                        }
                    })
                    .collect();
                PointOptimizer::with_weights(freqs, weights, options)?
            }
            (None, None) => unreachable!("every term has a target or a slice"),
        };
        terms.push(ProjectionTerm {
            label: part.to_string(),
            rows,
            weight,
            optimizer,
        });
    }
    if terms.is_empty() {
        return Err(fail("no terms".into()));
    }
    Ok(terms)
}

/// The weighted projection losses as a point objective.
pub struct ProjectionObjective<'a> {
    terms: &'a [ProjectionTerm],
    scale: Vec<f64>,
    work: Vec<Mutex<Work>>,
}

impl<'a> ProjectionObjective<'a> {
    /// The objective for `terms`, scaled at `start`.
    pub fn new(terms: &'a [ProjectionTerm], start: &PointSet) -> Self {
        ProjectionObjective {
            scale: terms
                .iter()
                .map(|t| t.loss(start).max(f64::MIN_POSITIVE))
                .collect(),
            work: terms
                .iter()
                .map(|t| Mutex::new(t.optimizer.work(start.len())))
                .collect(),
            terms,
        }
    }
}

impl PointObjective for ProjectionObjective<'_> {
    fn loss_and_gradient(&self, points: &PointSet, _t: usize, gradient: &mut [f64]) -> f64 {
        let mut total = 0.0;
        for ((term, scale), work) in self.terms.iter().zip(&self.scale).zip(&self.work) {
            let z = term.project(points);
            let mut work = work.lock().expect("one descent at a time");
            let (loss, grad) = term.optimizer.loss_and_gradient(&z, &mut work);
            let w = term.weight / scale;
            total += w * loss;
            for (i, g) in grad.chunks_exact(2).enumerate() {
                for (axis, m) in (0..4).map(|a| (a, [term.rows[0][a], term.rows[1][a]])) {
                    gradient[4 * i + axis] += w * (m[0] * g[0] + m[1] * g[1]);
                }
            }
        }
        total
    }
}
