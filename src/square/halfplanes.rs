//! The half-plane family's MSE in closed form per direction.
//!
//! For half-planes [n·x > t] with n = (cos θ, sin θ) and t the projection
//! n·p of a uniform point p of the square (the `halfplanes` family), fix θ
//! and let F_θ be the distribution function of n·p (a trapezoid: the sum
//! of two uniforms of widths |cos θ| and |sin θ|). With u_i = F_θ(n·x_i)
//! sorted, u_(1) ≤ … ≤ u_(N), the error of Î at level t is the gap between
//! the empirical and the true distribution of the projections, and its
//! mean square over t is the Cramér–von Mises statistic (Cramér 1928; von
//! Mises 1931):
//!
//!   L_θ = E_t[(Î − I)²] = 1/(12N²) + (1/N) Σ_k (u_(k) − (2k − 1)/(2N))²,
//!
//! a sum of squares (no cancellation). The family MSE is its average over
//! θ ∈ [0, π) (θ + π gives the complementary half-plane, the same squared
//! error), by the midpoint rule on equally spaced directions — spectrally
//! accurate for this π-periodic function up to the kinks where two
//! projections swap order. Cost O(N log N) per direction, against the
//! O(N²) pair form
//!
//!   L_θ = (1/N²) Σ_(i,j) F_θ(min(a_i, a_j)) − (2/N) Σ_i (F_θ(a_i) − F_θ(a_i)²/2) + 1/3,
//!
//! kept beside it as the reference ([`pair_form`]).

use std::f64::consts::PI;

use crate::points::PointSet;

/// The trapezoid distribution of n·p for p uniform on the square.
#[derive(Debug, Clone, Copy)]
pub struct Projection {
    n: [f64; 2],
    /// Lowest value of n·p.
    low: f64,
    /// The two widths, smaller first.
    alpha: f64,
    beta: f64,
}

impl Projection {
    /// Direction θ (radians).
    pub fn new(theta: f64) -> Self {
        let (s, c) = theta.sin_cos();
        let (a, b) = (c.abs(), s.abs());
        Projection {
            n: [c, s],
            low: c.min(0.0) + s.min(0.0),
            alpha: a.min(b),
            beta: a.max(b),
        }
    }

    /// n·x.
    pub fn project(&self, x: &[f64]) -> f64 {
        self.n[0] * x[0] + self.n[1] * x[1]
    }

    /// The unit normal n.
    pub fn normal(&self) -> [f64; 2] {
        self.n
    }

    /// (F(a), F′(a)).
    pub fn cdf(&self, a: f64) -> (f64, f64) {
        let (al, be) = (self.alpha, self.beta);
        let z = a - self.low;
        if z <= 0.0 {
            return (0.0, 0.0);
        }
        if z >= al + be {
            return (1.0, 0.0);
        }
        if al <= 1e-12 * be {
            // θ on an axis: a uniform of width β.
            return (z / be, 1.0 / be);
        }
        if z <= al {
            (z * z / (2.0 * al * be), z / (al * be))
        } else if z <= be {
            ((z - 0.5 * al) / be, 1.0 / be)
        } else {
            let w = al + be - z;
            (1.0 - w * w / (2.0 * al * be), w / (al * be))
        }
    }
}

/// L_θ of `set` and, if `gradient` is given, adds w·∂L_θ/∂x into it
/// (point-major, 2 per point).
pub fn directional_loss(
    set: &PointSet,
    projection: &Projection,
    weight: f64,
    gradient: Option<&mut [f64]>,
    order: &mut Vec<(f64, usize)>,
) -> f64 {
    let n = set.len();
    let nf = n as f64;
    order.clear();
    order.extend(
        set.points()
            .enumerate()
            .map(|(i, p)| (projection.project(p), i)),
    );
    order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut sum = crate::sum::NeumaierSum::default();
    let mut grad = gradient;
    let normal = projection.normal();
    for (k, &(a, i)) in order.iter().enumerate() {
        let (u, density) = projection.cdf(a);
        let gap = u - (2 * k + 1) as f64 / (2.0 * nf);
        sum.add(gap * gap);
        if let Some(g) = grad.as_deref_mut() {
            let d = weight * 2.0 / nf * gap * density;
            g[2 * i] += d * normal[0];
            g[2 * i + 1] += d * normal[1];
        }
    }
    1.0 / (12.0 * nf * nf) + sum.value() / nf
}

/// Directions θ_j = π(j + offset)/q, j < q.
pub fn directions(q: usize, offset: f64) -> impl Iterator<Item = f64> {
    (0..q).map(move |j| PI * (j as f64 + offset) / q as f64)
}

/// The family MSE of one set by the midpoint rule over `q` directions.
pub fn halfplane_mse(set: &PointSet, q: usize) -> f64 {
    let mut order = Vec::with_capacity(set.len());
    let total: f64 = directions(q, 0.5)
        .map(|t| directional_loss(set, &Projection::new(t), 0.0, None, &mut order))
        .sum();
    total / q as f64
}

/// The O(N²) pair form of L_θ (the reference for [`directional_loss`]).
pub fn pair_form(set: &PointSet, projection: &Projection) -> f64 {
    let a: Vec<f64> = set.points().map(|p| projection.project(p)).collect();
    let n = a.len() as f64;
    let mut pairs = crate::sum::NeumaierSum::default();
    for &ai in &a {
        for &aj in &a {
            pairs.add(projection.cdf(ai.min(aj)).0);
        }
    }
    let singles: f64 = a
        .iter()
        .map(|&ai| {
            let f = projection.cdf(ai).0;
            f - 0.5 * f * f
        })
        .sum();
    pairs.value() / (n * n) - 2.0 * singles / n + 1.0 / 3.0
}
