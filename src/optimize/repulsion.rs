//! Gaussian repulsion on the torus (Ahmed, Ren & Wonka 2022, "Gaussian
//! blue noise", ACM TOG 41(6)): E(X) = (1/N) Σ_(i≠j) exp(−|x_i − x_j|²/(2σ²))
//! with toroidal distances and σ a fixed fraction of the hexagonal spacing
//! d_hex = √(2/(√3 N)). Its minimizers are blue noise with a large closest
//! pair; as a term beside a family MSE it keeps a design blue.
//! Pairs farther than 4σ (weight < 3.4e-4) are skipped via a cell grid.

use crate::neighbours::{CellGrid, hexagonal_spacing};
use crate::points::PointSet;

/// σ as a fraction of the hexagonal spacing.
pub const SIGMA_OVER_SPACING: f64 = 0.5;

/// E(X), adding `weight`·∂E/∂x into `gradient` when given (2D).
pub fn repulsion(points: &PointSet, weight: f64, gradient: Option<&mut [f64]>) -> f64 {
    let n = points.len();
    let spacing = hexagonal_spacing(n);
    let sigma = SIGMA_OVER_SPACING * spacing;
    let radius = (4.0 * sigma).min(0.49);
    let grid = CellGrid::new(points);
    let mut energy = 0.0;
    let mut gradient = gradient;
    for i in 0..n {
        let p = points.point(i);
        grid.for_each_within(i, radius, |j, d2| {
            let e = (-d2 / (2.0 * sigma * sigma)).exp();
            energy += e;
            if let Some(g) = gradient.as_deref_mut() {
                let q = points.point(j);
                // Nearest-image displacement x_i − x_j; the pair (j, i)
                // adds the same to x_i, hence the factor 2.
                for axis in 0..2 {
                    let mut d = p[axis] - q[axis];
                    d -= d.round();
                    g[2 * i + axis] += weight * 2.0 * (-d / (sigma * sigma)) * e / n as f64;
                }
            }
        });
    }
    energy / n as f64
}

/// E for N uniform random points, (N − 1)·2πσ² (the Gaussian's integral
/// over the plane; σ ≪ 1), the same for every N since σ² ∝ 1/N.
pub fn uniform_energy(n: usize) -> f64 {
    let spacing2 = hexagonal_spacing(n).powi(2);
    let sigma2 = SIGMA_OVER_SPACING * SIGMA_OVER_SPACING * spacing2;
    (n.max(2) - 1) as f64 * 2.0 * std::f64::consts::PI * sigma2
}
