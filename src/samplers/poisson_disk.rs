//! Poisson-disk sampling by random sequential dart throwing: uniform
//! candidates are accepted when no accepted point lies within toroidal
//! distance r, until exactly N points are placed. Accepted points are binned
//! in a grid of cells of side ≥ r (linked lists per cell), so a candidate is
//! checked against the 3^d cells around its own only.
//!
//! The radius is relative to the densest packing (Lagae & Dutré 2008, "A
//! comparison of methods for generating Poisson disk distributions",
//! Computer Graphics Forum 27(1)): r = ρ·r_max with r_max the neighbour
//! distance of N points in the densest lattice packing of the unit torus.
//! Dart throwing jams (no room for another point) at packing fraction 0.547
//! in 2D (Feder 1980), i.e. ρ ≈ 0.78; 3D and 4D jam near ρ ≈ 0.80.

use super::config::{Config, pow_saturating};
use super::{Sampler, SamplerError};
use crate::neighbours::packing_radius;
use crate::points::{PointSet, toroidal_distance_sq};
use crate::rng::{SetRng, uniform};

/// Grids beyond this many cells are refused rather than allocated.
const MAX_CELLS: usize = 1 << 28;

/// Exactly N points in d ∈ {2,3,4} dimensions, pairwise toroidal distance
/// ≥ ρ·r_max.
#[derive(Debug, Clone)]
pub struct PoissonDisk {
    n: usize,
    dim: usize,
    rho: f64,
    max_trials: u64,
}

impl PoissonDisk {
    /// N ≥ 1 points in 2 ≤ d ≤ 4 dimensions, relative radius ρ in (0, 1),
    /// at most `max_trials` ≥ 1 dart throws.
    ///
    /// # Errors
    /// [`SamplerError`] for N = 0, another dimension, ρ or `max_trials`
    /// out of range, or an acceleration grid of more than 2^28 cells.
    pub fn new(n: usize, dim: usize, rho: f64, max_trials: u64) -> Result<Self, SamplerError> {
        const NAME: &str = "poisson-disk";
        if n == 0 {
            return Err(SamplerError::ZeroPoints { sampler: NAME });
        }
        if !(2..=4).contains(&dim) {
            return Err(SamplerError::Dimension {
                sampler: NAME,
                dim,
                min: 2,
                max: 4,
            });
        }
        let param = |key, value: String, expected: &str| SamplerError::Param {
            sampler: NAME,
            key,
            value,
            expected: expected.into(),
        };
        if !(rho > 0.0 && rho < 1.0) {
            return Err(param(
                "radius",
                rho.to_string(),
                "a number in (0, 1) (relative to the densest packing)",
            ));
        }
        if max_trials == 0 {
            return Err(param(
                "max-trials",
                "0".into(),
                "`auto` or a positive integer",
            ));
        }
        let sampler = PoissonDisk {
            n,
            dim,
            rho,
            max_trials,
        };
        if pow_saturating(sampler.cells_per_axis(), dim) > MAX_CELLS {
            return Err(SamplerError::TooLarge {
                sampler: NAME,
                n,
                dim,
            });
        }
        Ok(sampler)
    }

    /// The absolute minimum distance r = ρ·r_max.
    pub fn radius(&self) -> f64 {
        self.rho * packing_radius(self.n, self.dim).expect("d in 2..=4, checked when built")
    }

    /// Cells per axis: the most whose side 1/g is still ≥ r.
    fn cells_per_axis(&self) -> usize {
        ((1.0 / self.radius()).floor() as usize).max(1)
    }
}

pub(crate) fn from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    let rho: f64 = c
        .param("radius")
        .parse()
        .ok()
        .filter(|r: &f64| *r > 0.0 && *r < 1.0)
        .ok_or_else(|| {
            c.bad_param(
                "radius",
                "a number in (0, 1) (relative to the densest packing)",
            )
        })?;
    let max_trials = match c.param("max-trials") {
        "auto" => (1000 * c.n as u64).max(10_000_000),
        text => text
            .parse::<u64>()
            .ok()
            .filter(|&t| t >= 1)
            .ok_or_else(|| c.bad_param("max-trials", "`auto` or a positive integer"))?,
    };
    Ok(Box::new(PoissonDisk::new(c.n, c.dim, rho, max_trials)?))
}

const NONE: u32 = u32::MAX;

impl Sampler for PoissonDisk {
    fn dim(&self) -> usize {
        self.dim
    }

    fn points_per_set(&self) -> usize {
        self.n
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let (n, d) = (self.n, self.dim);
        let r2 = self.radius().powi(2);
        let g = self.cells_per_axis();
        // Side ≥ r: every conflict lies in the 3^d cells around the
        // candidate's (fewer when g < 3, so no cell is visited twice).
        let offsets = neighbourhood(d, g.min(3));
        // head[c] is the last point binned in cell c, next[i] the one before i.
        let mut head = vec![NONE; pow_saturating(g, d)];
        let mut next: Vec<u32> = Vec::with_capacity(n);
        let mut coords: Vec<f64> = Vec::with_capacity(n * d);
        let mut candidate = vec![0.0; d];
        let mut cell = vec![0isize; d];
        let mut trials = 0u64;
        while next.len() < n {
            if trials == self.max_trials {
                return Err(SamplerError::Jammed {
                    placed: next.len(),
                    n,
                    trials,
                    rho: self.rho,
                });
            }
            trials += 1;
            for j in 0..d {
                candidate[j] = uniform(rng);
                cell[j] = ((candidate[j] * g as f64) as isize).min(g as isize - 1);
            }
            let clear = offsets.chunks_exact(d).all(|o| {
                let mut other = head[cell_index(&cell, o, g)];
                while other != NONE {
                    let i = other as usize;
                    if toroidal_distance_sq(&candidate, &coords[i * d..(i + 1) * d]) < r2 {
                        return false;
                    }
                    other = next[i];
                }
                true
            });
            if clear {
                let home = cell
                    .iter()
                    .rev()
                    .fold(0usize, |acc, &c| acc * g + c as usize);
                next.push(head[home]);
                head[home] = (next.len() - 1) as u32;
                coords.extend_from_slice(&candidate);
            }
        }
        Ok(PointSet::new(d, coords).expect("uniform draws lie in [0,1)"))
    }
}

/// The offsets of a `side`^d block of cells centred on 0 (side 1, 2 or 3),
/// flattened.
fn neighbourhood(d: usize, side: usize) -> Vec<isize> {
    let count = pow_saturating(side, d);
    let mut out = Vec::with_capacity(count * d);
    for idx in 0..count {
        let mut rest = idx;
        for _ in 0..d {
            out.push((rest % side) as isize - (side as isize - 1) / 2);
            rest /= side;
        }
    }
    out
}

/// Linear index of cell `cell + offset`, wrapped on the torus.
#[inline]
fn cell_index(cell: &[isize], offset: &[isize], g: usize) -> usize {
    let gi = g as isize;
    cell.iter().zip(offset).rev().fold(0usize, |acc, (c, o)| {
        acc * g + (c + o).rem_euclid(gi) as usize
    })
}
