//! Convex polygons in the plane: clipping by a half-plane
//! (Sutherland & Hodgman 1974, "Reentrant polygon clipping", CACM 17(1))
//! and area by the shoelace formula. Used for exact integrals of polygonal
//! indicators (half-planes and boxes cut by the unit square).

/// The convex polygon `poly` (counter-clockwise) clipped to n·x ≥ level
/// (one Sutherland–Hodgman pass).
pub fn clip(poly: &[[f64; 2]], n: [f64; 2], level: f64) -> Vec<[f64; 2]> {
    let side = |p: [f64; 2]| p[0] * n[0] + p[1] * n[1] - level;
    let mut out = Vec::with_capacity(poly.len() + 1);
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (sa, sb) = (side(a), side(b));
        if sa >= 0.0 {
            out.push(a);
        }
        if (sa >= 0.0) != (sb >= 0.0) {
            let t = sa / (sa - sb);
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    out
}

/// Area of a simple polygon (counter-clockwise positive); 0 for fewer
/// than three vertices (an empty clip: std's empty float sum is −0, which
/// printed as `I = -0`). The vertices are taken relative to the first, so
/// a small polygon far from the origin keeps its digits (a triangle of
/// area 1.1e-8 at the corner (1, 1) lost seven of them to cross products
/// of coordinates near 1).
pub fn shoelace(poly: &[[f64; 2]]) -> f64 {
    let n = poly.len();
    if n < 3 {
        return 0.0;
    }
    let o = poly[0];
    0.5 * (1..n - 1)
        .map(|i| {
            let (a, b) = (poly[i], poly[i + 1]);
            (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
        })
        .sum::<f64>()
}

/// The unit square [0,1]², counter-clockwise.
pub const UNIT_SQUARE: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn areas_of_the_square_and_of_degenerate_polygons() {
        assert_eq!(shoelace(&UNIT_SQUARE), 1.0);
        for degenerate in [&[][..], &[[1.0, 1.0]], &[[0.0, 0.0], [1.0, 1.0]]] {
            let area = shoelace(degenerate);
            assert!(
                area == 0.0 && area.is_sign_positive(),
                "{degenerate:?}: {area}"
            );
        }
    }
}
