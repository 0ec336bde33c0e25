//! A family's MSE estimated on a sample of its members, with the gradient
//! with respect to the points: for members f_1..f_B with errors
//! e_m = (1/N) Σ_i f_m(x_i) − I_m,
//!
//!   L̂ = (1/B) Σ_m e_m²,   ∂L̂/∂x_i = (2/(B·N)) Σ_m e_m ∇f_m(x_i).
//!
//! This is the kernel form (1/N²) ΣΣ K(x_i, x_j) − (2/N) Σ k(x_i) + c with
//! K(x, y) = E[f(x) f(y)], k(x) = E[f(x)·I], c = E[I²] estimated by their
//! sample means, in O(B·N) rather than O(N²) kernel evaluations. Fresh
//! members at every step make the descent a stochastic gradient method on
//! the family MSE itself, which cannot fit its own sample.

use rayon::prelude::*;

use super::family::Family;
use crate::points::PointSet;
use crate::sum::NeumaierSum;

/// Members per parallel task: fixed, so sums are thread-count independent.
const CHUNK: usize = 16;

/// Which members of a family sample: `first..first + count` of the sample
/// drawn with `seed`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Members {
    /// Seed of the sample.
    pub seed: u64,
    /// First member.
    pub first: u64,
    /// Members taken.
    pub count: usize,
}

/// L̂ over `members` of `family`;
/// adds `weight`·∂L̂/∂x into `gradient` when given. Indicators contribute
/// through their edge gradient smoothed over half-width `edge`
/// ([`super::integrands::SquareIntegrand::edge_gradient`]; 0: none). `None`
/// if a member has no gradient of either kind and a gradient was asked for.
pub fn sampled_loss(
    set: &PointSet,
    family: &Family,
    members: Members,
    weight: f64,
    edge: f64,
    gradient: Option<&mut [f64]>,
) -> Option<f64> {
    let Members {
        seed,
        first,
        count: batch,
    } = members;
    let n = set.len() as f64;
    let want_gradient = gradient.is_some();
    let len = 2 * set.len();
    let chunks: Vec<Option<(NeumaierSum, Vec<f64>)>> = (0..batch.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut loss = NeumaierSum::default();
            let mut grad = if want_gradient {
                vec![0.0; len]
            } else {
                Vec::new()
            };
            for m in c * CHUNK..((c + 1) * CHUNK).min(batch) {
                let f = family.member(seed, first + m as u64);
                let mut sum = NeumaierSum::default();
                for p in set.points() {
                    sum.add(f.eval([p[0], p[1]]));
                }
                let e = sum.value() / n - f.integral();
                loss.add(e * e);
                if want_gradient {
                    let scale = 2.0 * e / n;
                    for (i, p) in set.points().enumerate() {
                        let x = [p[0], p[1]];
                        let g = f
                            .gradient(x)
                            .or_else(|| (edge > 0.0).then(|| f.edge_gradient(x, edge)).flatten())?;
                        grad[2 * i] += scale * g[0];
                        grad[2 * i + 1] += scale * g[1];
                    }
                }
            }
            Some((loss, grad))
        })
        .collect();
    let mut loss = NeumaierSum::default();
    let mut gradient = gradient;
    for chunk in chunks {
        let (l, g) = chunk?;
        loss.merge(l);
        if let Some(out) = gradient.as_deref_mut() {
            for (o, v) in out.iter_mut().zip(&g) {
                *o += weight * v / batch as f64;
            }
        }
    }
    Some(loss.value() / batch as f64)
}
