//! [`PointSet`]: N points in d dimensions on the unit torus [0,1)^d.

use crate::rng::PREV_ONE;

/// The largest factor between a density λ given for sets and their mean
/// count that [`PointSet::all_with_density`] accepts.
pub const DENSITY_SLACK: f64 = 2.0;

/// A violated [`PointSet`] invariant, naming the point and coordinate.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PointSetError {
    /// d = 0.
    #[error("a point set needs at least one dimension")]
    ZeroDimension,
    /// The coordinate buffer is not N·d long.
    #[error("{len} coordinates do not split into points of dimension {dim}")]
    Ragged {
        /// Buffer length.
        len: usize,
        /// Requested dimension.
        dim: usize,
    },
    /// NaN or ±∞.
    #[error("point {point}, coordinate {coord} is {value}, not a finite number")]
    NotFinite {
        /// Point index.
        point: usize,
        /// Coordinate index.
        coord: usize,
        /// The value.
        value: f64,
    },
    /// Outside [0, 1).
    #[error("point {point}, coordinate {coord} is {}, outside [0, 1)", crate::spec_params::SpecValue(*value))]
    OutOfRange {
        /// Point index.
        point: usize,
        /// Coordinate index.
        coord: usize,
        /// The value.
        value: f64,
    },
    /// A projection named a dimension the set does not have, or one twice.
    #[error("cannot project onto dimensions {dims:?} of a {dim}-dimensional set: {reason}")]
    Projection {
        /// The requested dimensions.
        dims: Vec<usize>,
        /// The set's dimension.
        dim: usize,
        /// What is wrong.
        reason: &'static str,
    },
    /// A point-process density that is not a positive finite number.
    #[error("density {0} is not a positive finite number (the expected points per unit volume)")]
    Density(f64),
    /// A density far from the sets' own mean count: their estimates would
    /// be off by that factor.
    #[error(
        "density {density:e}: the sets hold {mean_count:.1} points on average, and a density is the expected count per unit volume; \
         the estimate Σ f/λ would be {factor:.3e} times the integral (give λ within a factor {DENSITY_SLACK} of the mean count)"
    )]
    DensityFarFromCount {
        /// The density given.
        density: f64,
        /// The sets' mean number of points.
        mean_count: f64,
        /// mean count / density.
        factor: f64,
    },
    /// A shift vector of the wrong length or with values outside [0,1).
    #[error("shift {shift:?} is not a vector of {dim} values in [0, 1)")]
    Shift {
        /// The shift.
        shift: Vec<f64>,
        /// The set's dimension.
        dim: usize,
    },
}

/// N points in d dimensions on the torus [0,1)^d, stored contiguously
/// point-major (`coords[i·d + j]` is coordinate j of point i).
///
/// Every coordinate is finite and in [0, 1); `-0.0` is stored as `+0.0`.
/// A set may be empty (N = 0) but never has d = 0.
///
/// A set drawn by a process whose number of points is random (isotropic
/// jitter) carries the process's density λ, the expected number of points
/// per unit volume: its estimator is Î = (1/λ) Σ f(x_j), unbiased where
/// (1/N) Σ f(x_j) is not (Öztireli 2016, "Integration with stochastic
/// point processes", ACM TOG 35(5), §4). Without a density the weight is
/// 1/N (docs/mathematics.md §2, "A random number of points").
#[derive(Debug, Clone, PartialEq)]
pub struct PointSet {
    dim: usize,
    coords: Vec<f64>,
    density: Option<f64>,
}

/// Maps any finite real onto [0, 1) modulo 1.
///
/// `v − ⌊v⌋` can round up to exactly 1 for tiny negative `v`; that case is
/// folded to 0, which is the same point of the torus.
#[inline]
pub fn wrap01(v: f64) -> f64 {
    let w = v - v.floor();
    if w >= 1.0 { 0.0 } else { w + 0.0 }
}

/// Squared toroidal distance between two points of the same dimension: each
/// coordinate difference is taken to its nearest periodic image.
#[inline]
pub fn toroidal_distance_sq(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            let d = (x - y).abs();
            let d = d.min(1.0 - d);
            d * d
        })
        .sum()
}

impl PointSet {
    /// Builds a set from point-major coordinates, checking every invariant.
    ///
    /// # Errors
    /// [`PointSetError`] naming the first offending point and coordinate.
    pub fn new(dim: usize, mut coords: Vec<f64>) -> Result<Self, PointSetError> {
        if dim == 0 {
            return Err(PointSetError::ZeroDimension);
        }
        if coords.len() % dim != 0 {
            return Err(PointSetError::Ragged {
                len: coords.len(),
                dim,
            });
        }
        for (idx, v) in coords.iter_mut().enumerate() {
            let (point, coord) = (idx / dim, idx % dim);
            if !v.is_finite() {
                return Err(PointSetError::NotFinite {
                    point,
                    coord,
                    value: *v,
                });
            }
            if !(0.0..1.0).contains(v) {
                return Err(PointSetError::OutOfRange {
                    point,
                    coord,
                    value: *v,
                });
            }
            *v += 0.0; // −0.0 + 0.0 = +0.0
        }
        Ok(PointSet {
            dim,
            coords,
            density: None,
        })
    }

    /// The same points as a realization of a process of density λ
    /// (expected points per unit volume), whose estimator weight is 1/λ.
    ///
    /// # Errors
    /// [`PointSetError::Density`] unless λ is positive and finite.
    pub fn with_density(mut self, density: f64) -> Result<Self, PointSetError> {
        if !(density.is_finite() && density > 0.0) {
            return Err(PointSetError::Density(density));
        }
        self.density = Some(density);
        Ok(self)
    }

    /// `sets` as realizations of a process of density λ, checked against
    /// their own mean count: the estimator Σ f/λ is unbiased only when λ
    /// is the expected count, so a λ off by more than [`DENSITY_SLACK`]
    /// from the mean count is a mistake (a random-count process's counts
    /// scatter by ~√λ, far less).
    ///
    /// # Errors
    /// [`PointSetError::Density`] for a λ that is not positive and finite,
    /// [`PointSetError::DensityFarFromCount`] for one far from the counts.
    pub fn all_with_density(
        sets: Vec<PointSet>,
        density: f64,
    ) -> Result<Vec<PointSet>, PointSetError> {
        let sets = sets
            .into_iter()
            .map(|s| s.with_density(density))
            .collect::<Result<Vec<_>, _>>()?;
        let mean_count =
            sets.iter().map(|s| s.len() as f64).sum::<f64>() / sets.len().max(1) as f64;
        let factor = mean_count / density;
        if !(1.0 / DENSITY_SLACK..=DENSITY_SLACK).contains(&factor) {
            return Err(PointSetError::DensityFarFromCount {
                density,
                mean_count,
                factor,
            });
        }
        Ok(sets)
    }

    /// The density λ of the process that drew the set, if its number of
    /// points is random.
    pub fn density(&self) -> Option<f64> {
        self.density
    }

    /// The normalisation of the estimator and of the power spectrum: λ for
    /// a set with a density, N otherwise (Î = Σ f(x_j)/intensity,
    /// P_S(k) = |S(k)|²/intensity).
    pub fn intensity(&self) -> f64 {
        self.density.unwrap_or(self.len() as f64)
    }

    /// Number of points N.
    pub fn len(&self) -> usize {
        self.coords.len() / self.dim
    }

    /// True for N = 0.
    pub fn is_empty(&self) -> bool {
        self.coords.is_empty()
    }

    /// Dimension d.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Point-major coordinates.
    pub fn coords(&self) -> &[f64] {
        &self.coords
    }

    /// Point `i`.
    pub fn point(&self, i: usize) -> &[f64] {
        &self.coords[i * self.dim..(i + 1) * self.dim]
    }

    /// The points in order.
    pub fn points(&self) -> std::slice::ChunksExact<'_, f64> {
        self.coords.chunks_exact(self.dim)
    }

    /// The set translated by `shift` on the torus: x ↦ x + s mod 1 (the
    /// Cranley–Patterson rotation of the shift-randomized estimator).
    ///
    /// # Errors
    /// [`PointSetError::Shift`] if `shift` is not d values in [0, 1).
    pub fn shifted(&self, shift: &[f64]) -> Result<PointSet, PointSetError> {
        if shift.len() != self.dim || shift.iter().any(|s| !(0.0..1.0).contains(s)) {
            return Err(PointSetError::Shift {
                shift: shift.to_vec(),
                dim: self.dim,
            });
        }
        let coords = self
            .points()
            .flat_map(|p| {
                p.iter().zip(shift).map(|(x, s)| {
                    // x, s < 1 so x + s < 2, and (x + s) − 1 is exact (Sterbenz).
                    let y = x + s;
                    if y >= 1.0 { y - 1.0 } else { y }
                })
            })
            .collect();
        Ok(PointSet {
            dim: self.dim,
            coords,
            density: self.density,
        })
    }

    /// The projection onto dimensions `dims` (in that order), e.g. `[0, 2]`
    /// for the XU projection of (x, y, u, v) points.
    ///
    /// # Errors
    /// [`PointSetError::Projection`] for an empty list, an index ≥ d, or a
    /// repeated index.
    pub fn projected(&self, dims: &[usize]) -> Result<PointSet, PointSetError> {
        let fail = |reason| PointSetError::Projection {
            dims: dims.to_vec(),
            dim: self.dim,
            reason,
        };
        if dims.is_empty() {
            return Err(fail("no dimension given"));
        }
        if dims.iter().any(|&j| j >= self.dim) {
            return Err(fail(
                "a dimension index is out of range (they count from 0)",
            ));
        }
        if (1..dims.len()).any(|a| dims[..a].contains(&dims[a])) {
            return Err(fail("a dimension is repeated"));
        }
        let coords = self
            .points()
            .flat_map(|p| dims.iter().map(|&j| p[j]))
            .collect();
        Ok(PointSet {
            dim: dims.len(),
            coords,
            density: self.density,
        })
    }
}

/// `(i + ξ)/m` for stratum `i` of `m` with offset `ξ ∈ [0,1)`, kept below 1.
///
/// In floating point `i + ξ` can round up to `m` when `i = m − 1`; the
/// result is then clamped to the largest double below 1 so the point stays on
/// the torus (an O(2⁻⁵³) change in a measure-zero event).
#[inline]
pub fn stratum_coord(i: usize, xi: f64, m: usize) -> f64 {
    ((i as f64 + xi) / m as f64).min(PREV_ONE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_point_and_coordinate() {
        assert_eq!(
            PointSet::new(2, vec![0.1, 0.2, 0.3, 1.0]),
            Err(PointSetError::OutOfRange {
                point: 1,
                coord: 1,
                value: 1.0
            })
        );
        assert!(matches!(
            PointSet::new(2, vec![0.1, f64::NAN]),
            Err(PointSetError::NotFinite {
                point: 0,
                coord: 1,
                ..
            })
        ));
        assert_eq!(
            PointSet::new(2, vec![0.1]),
            Err(PointSetError::Ragged { len: 1, dim: 2 })
        );
        assert_eq!(PointSet::new(0, vec![]), Err(PointSetError::ZeroDimension));
        let z = PointSet::new(1, vec![-0.0]).unwrap();
        assert!(z.coords()[0].is_sign_positive());
    }

    #[test]
    fn shift_wraps_and_stays_in_unit_interval() {
        let p = PointSet::new(2, vec![0.75, PREV_ONE]).unwrap();
        let s = p.shifted(&[0.5, PREV_ONE]).unwrap();
        assert_eq!(s.coords()[0], 0.25);
        assert!(s.coords()[1] < 1.0 && s.coords()[1] >= 0.0);
        assert!(p.shifted(&[0.5]).is_err());
        assert!(p.shifted(&[0.5, 1.0]).is_err());
    }

    #[test]
    fn projection_selects_and_checks_dimensions() {
        let p = PointSet::new(4, vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8]).unwrap();
        let xu = p.projected(&[0, 2]).unwrap();
        assert_eq!(xu.coords(), &[0.1, 0.3, 0.5, 0.7]);
        assert!(p.projected(&[0, 4]).is_err());
        assert!(p.projected(&[1, 1]).is_err());
        assert!(p.projected(&[]).is_err());
    }

    #[test]
    fn wrap_and_distance_respect_the_torus() {
        assert_eq!(wrap01(-1e-300), 0.0);
        assert_eq!(wrap01(1.25), 0.25);
        assert!((toroidal_distance_sq(&[0.05, 0.5], &[0.95, 0.5]) - 0.01).abs() < 1e-15);
        assert_eq!(stratum_coord(15, PREV_ONE, 16), PREV_ONE);
    }
}
