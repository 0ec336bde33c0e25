//! Neighbour queries on the torus with a uniform cell grid: each point is
//! binned once, and a query visits only the cells within reach, so a search
//! of radius ~ N^(−1/d) costs O(1) per point instead of O(N).

use crate::points::{PointSet, toroidal_distance_sq};

/// Points binned into g^d cells of side 1/g (counting sort, CSR layout).
pub struct CellGrid<'a> {
    points: &'a PointSet,
    g: usize,
    /// start[c]..start[c+1] indexes `order` for cell c.
    start: Vec<u32>,
    order: Vec<u32>,
}

impl<'a> CellGrid<'a> {
    /// Bins `points` with about one point per cell (g = ⌊N^(1/d)⌋, capped at
    /// 2^20 cells).
    pub fn new(points: &'a PointSet) -> Self {
        let (n, d) = (points.len(), points.dim());
        let cap = ((1usize << 20) as f64).powf(1.0 / d as f64).floor() as usize;
        let g = ((n as f64).powf(1.0 / d as f64).floor() as usize).clamp(1, cap.max(1));
        let cell_of = |p: &[f64]| {
            p.iter().rev().fold(0usize, |acc, &x| {
                acc * g + ((x * g as f64) as usize).min(g - 1)
            })
        };
        let cells = g.pow(d as u32);
        let mut start = vec![0u32; cells + 1];
        for p in points.points() {
            start[cell_of(p) + 1] += 1;
        }
        for c in 0..cells {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut order = vec![0u32; n];
        for (i, p) in points.points().enumerate() {
            let c = cell_of(p);
            order[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        CellGrid {
            points,
            g,
            start,
            order,
        }
    }

    /// Calls `visit(j, dist²)` for every point j ≠ i within toroidal distance
    /// `radius` of point i (radius < 1/2 for each periodic image to count
    /// once).
    pub fn for_each_within(&self, i: usize, radius: f64, mut visit: impl FnMut(usize, f64)) {
        let d = self.points.dim();
        let g = self.g as isize;
        let p = self.points.point(i);
        let reach = (radius * self.g as f64).ceil() as isize;
        // At most g cells per axis, so every cell (and periodic image) is
        // visited once even when the reach wraps around the torus.
        let side = (2 * reach + 1).min(g) as usize;
        let lo: Vec<isize> = p
            .iter()
            .map(|&x| ((x * g as f64) as isize).min(g - 1) - reach)
            .collect();
        let r2 = radius * radius;
        let mut offset = vec![0usize; d];
        for idx in 0..side.pow(d as u32) {
            let mut rest = idx;
            for o in offset.iter_mut() {
                *o = rest % side;
                rest /= side;
            }
            let cell = (0..d).rev().fold(0usize, |acc, j| {
                acc * self.g + (lo[j] + offset[j] as isize).rem_euclid(g) as usize
            });
            for &k in &self.order[self.start[cell] as usize..self.start[cell + 1] as usize] {
                let k = k as usize;
                if k != i {
                    let d2 = toroidal_distance_sq(p, self.points.point(k));
                    if d2 <= r2 {
                        visit(k, d2);
                    }
                }
            }
        }
    }
}

/// Distance from each point to its nearest neighbour on the torus.
///
/// Searches the cells within twice the mean spacing first and widens only
/// for points with no neighbour there.
pub fn nearest_neighbour_distances(points: &PointSet) -> Vec<f64> {
    let n = points.len();
    let d = points.dim();
    let grid = CellGrid::new(points);
    let spacing = (1.0 / n.max(1) as f64).powf(1.0 / d as f64);
    let max_radius = 0.5 * (d as f64).sqrt();
    (0..n)
        .map(|i| {
            let mut radius = 2.0 * spacing;
            loop {
                let mut best = f64::INFINITY;
                grid.for_each_within(i, radius.min(max_radius), |_, d2| best = best.min(d2));
                if best.is_finite() || radius >= max_radius || n < 2 {
                    return best.sqrt();
                }
                radius *= 2.0;
            }
        })
        .collect()
}

/// The spacing √(2/(√3 N)) of N points on the unit torus in the densest
/// packing, the hexagonal one (at least one point).
pub fn hexagonal_spacing(n: usize) -> f64 {
    packing_radius(n, 2).expect("defined in 2D")
}

/// The neighbour distance r_max of N points in the densest packing of the
/// unit d-torus, from N·V_d·(r/2)^d = Δ_d with the packing density Δ_d of
/// the integer (d = 1), hexagonal (2), face-centred cubic (3) and D4 (4)
/// lattices: 1/N, √(2/(√3 N)), (√2/N)^(1/3), (2/N)^(1/4); None beyond
/// four dimensions (at least one point).
pub fn packing_radius(n: usize, dim: usize) -> Option<f64> {
    packing_radius_at_density(n.max(1) as f64, dim)
}

/// [`packing_radius`] for a density λ (expected points per unit volume)
/// rather than a count: a random-count process's spacing is its λ's, not
/// one realization's count.
pub fn packing_radius_at_density(density: f64, dim: usize) -> Option<f64> {
    let n = density;
    match dim {
        1 => Some(1.0 / n),
        2 => Some((2.0 / (3f64.sqrt() * n)).sqrt()),
        3 => Some((2f64.sqrt() / n).cbrt()),
        4 => Some((2.0 / n).sqrt().sqrt()),
        _ => None,
    }
}

/// The relative radii of Lagae & Dutré (2008, §3) of a 2D set: its
/// minimum and mean nearest-neighbour distance (toroidal) over the
/// hexagonal spacing ([`hexagonal_spacing`]), [δ_min, δ̄]; 1 is the
/// densest packing.
pub fn relative_radii(set: &PointSet) -> [f64; 2] {
    let hex = hexagonal_spacing(set.len());
    let nn = nearest_neighbour_distances(set);
    let min = nn.iter().copied().fold(f64::INFINITY, f64::min);
    let mean = crate::sum::sum(nn.iter().copied()) / nn.len().max(1) as f64;
    [min / hex, mean / hex]
}

/// The closest pair of `set` (toroidal distance) over the hexagonal
/// spacing: δ_min of [`relative_radii`].
pub fn closest_pair_ratio(set: &PointSet) -> f64 {
    relative_radii(set)[0]
}
