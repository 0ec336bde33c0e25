//! Integrands on the unit square, not periodic: the members of the families
//! of [`super::family`]. Each has an exact integral over [0,1]² (the part
//! of the shape the square's border cuts off does not count) and, where f
//! is smooth, its gradient.

use crate::polygon::{UNIT_SQUARE, clip, shoelace};
use crate::quadrature::integrate_panels;

/// A 2D integrand on [0,1]², evaluated without any shift.
pub trait SquareIntegrand: Send + Sync {
    /// f(x).
    fn eval(&self, x: [f64; 2]) -> f64;
    /// ∫_[0,1]² f, exactly (to rounding or to the stated quadrature error).
    fn integral(&self) -> f64;
    /// ∇f(x) where f is differentiable; `None` for indicators.
    fn gradient(&self, _x: [f64; 2]) -> Option<[f64; 2]> {
        None
    }
    /// For an indicator: ∇f_h(x), f_h the indicator smoothed across its
    /// edge by a linear ramp of half-width `h` in the signed distance to
    /// the edge, f_h = clamp(½ − sd/(2h), 0, 1) (sd > 0 outside). The
    /// members' positions are random, so a family's MSE is smooth in the
    /// points although each member jumps; its gradient is the limit h → 0 of
    /// the family average of e·∇f_h (Reynolds transport across the moving
    /// edge). `None` where f has no edge form.
    fn edge_gradient(&self, _x: [f64; 2], _h: f64) -> Option<[f64; 2]> {
        None
    }
}

/// −∇sd/(2h) inside the ramp |sd| < h, 0 outside it.
fn ramp(sd: f64, normal: [f64; 2], h: f64) -> [f64; 2] {
    if sd.abs() < h {
        [-normal[0] / (2.0 * h), -normal[1] / (2.0 * h)]
    } else {
        [0.0, 0.0]
    }
}

/// exp(−½ (x − μ)ᵀ A (x − μ)) with A = R diag(1/v₁, 1/v₂) Rᵀ, R the
/// rotation by θ: an anisotropic Gaussian of peak 1 (variances v₁, v₂ along
/// (cos θ, sin θ) and its normal), cut by the square's border.
#[derive(Debug, Clone)]
pub struct Gaussian {
    mu: [f64; 2],
    /// A as (a11, a12, a22).
    a: [f64; 3],
    integral: f64,
}

impl Gaussian {
    /// Centre `mu`, variances `v` along the axes rotated by `theta` radians.
    pub fn new(mu: [f64; 2], v: [f64; 2], theta: f64) -> Self {
        let (s, c) = theta.sin_cos();
        let (p, q) = (1.0 / v[0], 1.0 / v[1]);
        let a = [
            p * c * c + q * s * s,
            (p - q) * c * s,
            p * s * s + q * c * c,
        ];
        let mut g = Gaussian {
            mu,
            a,
            integral: 0.0,
        };
        g.integral = g.square_integral();
        g
    }

    /// ∫₀¹ (∫₀¹ f dy) dx: the inner integral is a 1D Gaussian in y (an erf
    /// difference), the outer a smooth function of x integrated by 16-point
    /// Gauss–Legendre on 8 panels (each at most 1/8 wide: with variances
    /// ≥ 0.0025 a panel spans at most 2.5 standard deviations, where the
    /// rule is exact to about 1e-15).
    fn square_integral(&self) -> f64 {
        let [a11, a12, a22] = self.a;
        let schur = a11 - a12 * a12 / a22;
        let root = (0.5 * a22).sqrt();
        let scale = (std::f64::consts::PI / (2.0 * a22)).sqrt();
        let inner = |x: f64| {
            let dx = x - self.mu[0];
            let b = a12 * dx / a22;
            let (lo, hi) = (-self.mu[1] + b, 1.0 - self.mu[1] + b);
            (-0.5 * schur * dx * dx).exp() * scale * (libm::erf(root * hi) - libm::erf(root * lo))
        };
        integrate_panels(0.0, 1.0, 8, inner)
    }

    fn quadratic(&self, x: [f64; 2]) -> (f64, [f64; 2]) {
        let d = [x[0] - self.mu[0], x[1] - self.mu[1]];
        let ad = [
            self.a[0] * d[0] + self.a[1] * d[1],
            self.a[1] * d[0] + self.a[2] * d[1],
        ];
        (d[0] * ad[0] + d[1] * ad[1], ad)
    }
}

impl SquareIntegrand for Gaussian {
    fn eval(&self, x: [f64; 2]) -> f64 {
        (-0.5 * self.quadratic(x).0).exp()
    }

    fn integral(&self) -> f64 {
        self.integral
    }

    fn gradient(&self, x: [f64; 2]) -> Option<[f64; 2]> {
        let (q, ad) = self.quadratic(x);
        let f = (-0.5 * q).exp();
        Some([-f * ad[0], -f * ad[1]])
    }
}

/// The indicator of {x : n·(x − p) > 0} on the square.
#[derive(Debug, Clone)]
pub struct HalfPlane {
    n: [f64; 2],
    level: f64,
    integral: f64,
}

impl HalfPlane {
    /// The side n·x > n·p of the line through `p` with unit normal at
    /// angle `theta` radians.
    pub fn new(theta: f64, p: [f64; 2]) -> Self {
        let (s, c) = theta.sin_cos();
        let n = [c, s];
        let level = n[0] * p[0] + n[1] * p[1];
        let integral = shoelace(&clip(&UNIT_SQUARE, n, level));
        HalfPlane { n, level, integral }
    }
}

impl SquareIntegrand for HalfPlane {
    fn eval(&self, x: [f64; 2]) -> f64 {
        f64::from(u8::from(self.n[0] * x[0] + self.n[1] * x[1] > self.level))
    }

    fn integral(&self) -> f64 {
        self.integral
    }

    fn edge_gradient(&self, x: [f64; 2], h: f64) -> Option<[f64; 2]> {
        // Inside is n·x > level: sd = level − n·x, ∇sd = −n.
        let sd = self.level - (self.n[0] * x[0] + self.n[1] * x[1]);
        Some(ramp(sd, [-self.n[0], -self.n[1]], h))
    }
}

/// The indicator of a disk, cut by the square's border.
#[derive(Debug, Clone)]
pub struct Disk {
    c: [f64; 2],
    r: f64,
    integral: f64,
}

impl Disk {
    /// Centre `c`, radius `r` > 0.
    pub fn new(c: [f64; 2], r: f64) -> Self {
        // The square relative to the centre, by inclusion–exclusion of
        // signed quadrant areas.
        let g = |x: f64, y: f64| quadrant_area(x, y, r);
        let (x0, x1, y0, y1) = (-c[0], 1.0 - c[0], -c[1], 1.0 - c[1]);
        let integral = g(x1, y1) - g(x0, y1) - g(x1, y0) + g(x0, y0);
        Disk { c, r, integral }
    }
}

/// Signed area of {(u, v) between 0 and x, between 0 and y : u² + v² ≤ r²}
/// (negative when exactly one of x, y is), in closed form with
/// ∫₀ᵗ √(r² − u²) du = ½(t√(r² − t²) + r² asin(t/r)).
fn quadrant_area(x: f64, y: f64, r: f64) -> f64 {
    let sign = x.signum() * y.signum();
    let (x, y) = (x.abs().min(r), y.abs().min(r));
    if x == 0.0 || y == 0.0 {
        return 0.0;
    }
    let h = |t: f64| {
        0.5 * (t * (r * r - t * t).max(0.0).sqrt() + r * r * (t / r).clamp(-1.0, 1.0).asin())
    };
    let area = if x * x + y * y <= r * r {
        x * y
    } else {
        // The arc meets v = y at u₀ = √(r² − y²) < x.
        let u0 = (r * r - y * y).max(0.0).sqrt();
        u0 * y + h(x) - h(u0)
    };
    sign * area
}

impl SquareIntegrand for Disk {
    fn eval(&self, x: [f64; 2]) -> f64 {
        let d = [x[0] - self.c[0], x[1] - self.c[1]];
        f64::from(u8::from(d[0] * d[0] + d[1] * d[1] < self.r * self.r))
    }

    fn integral(&self) -> f64 {
        self.integral
    }

    fn edge_gradient(&self, x: [f64; 2], h: f64) -> Option<[f64; 2]> {
        let d = [x[0] - self.c[0], x[1] - self.c[1]];
        let len = d[0].hypot(d[1]);
        if len == 0.0 {
            // The centre: on no edge (r > 0).
            return Some([0.0, 0.0]);
        }
        Some(ramp(len - self.r, [d[0] / len, d[1] / len], h))
    }
}

/// The indicator of a rotated square box, cut by the square's border.
#[derive(Debug, Clone)]
pub struct Box2 {
    c: [f64; 2],
    half: f64,
    axes: [[f64; 2]; 2],
    integral: f64,
}

impl Box2 {
    /// Centre `c`, side `side`, rotated by `theta` radians.
    pub fn new(c: [f64; 2], side: f64, theta: f64) -> Self {
        let (s, co) = theta.sin_cos();
        let axes = [[co, s], [-s, co]];
        let half = 0.5 * side;
        let mut poly = UNIT_SQUARE.to_vec();
        for axis in axes {
            let centre = axis[0] * c[0] + axis[1] * c[1];
            poly = clip(&poly, axis, centre - half);
            poly = clip(&poly, [-axis[0], -axis[1]], -(centre + half));
        }
        let integral = shoelace(&poly);
        Box2 {
            c,
            half,
            axes,
            integral,
        }
    }
}

impl SquareIntegrand for Box2 {
    fn eval(&self, x: [f64; 2]) -> f64 {
        let d = [x[0] - self.c[0], x[1] - self.c[1]];
        let inside = self
            .axes
            .iter()
            .all(|a| (a[0] * d[0] + a[1] * d[1]).abs() < self.half);
        f64::from(u8::from(inside))
    }

    fn integral(&self) -> f64 {
        self.integral
    }

    fn edge_gradient(&self, x: [f64; 2], h: f64) -> Option<[f64; 2]> {
        // The edge nearest in the square's own frame: the axis along which
        // the point is farthest out.
        let d = [x[0] - self.c[0], x[1] - self.c[1]];
        let q = self.axes.map(|a| a[0] * d[0] + a[1] * d[1]);
        let i = usize::from(q[1].abs() > q[0].abs());
        let s = q[i].signum();
        let normal = [s * self.axes[i][0], s * self.axes[i][1]];
        Some(ramp(q[i].abs() - self.half, normal, h))
    }
}

/// A torus integrand of the catalogue evaluated on the square as it is
/// (its integral over one period is its integral over the square).
pub struct Catalogue(pub Box<dyn crate::integrands::Integrand>);

impl SquareIntegrand for Catalogue {
    fn eval(&self, x: [f64; 2]) -> f64 {
        self.0.eval(&x)
    }

    fn integral(&self) -> f64 {
        self.0.integral()
    }

    /// Central differences of step h, one-sided at the border: the gradient
    /// of f box-filtered over [x − h, x + h] along each axis, which is the
    /// smoothed indicator's for an indicator and tends to ∇f for a smooth f.
    fn edge_gradient(&self, x: [f64; 2], h: f64) -> Option<[f64; 2]> {
        let mut g = [0.0; 2];
        for (axis, out) in g.iter_mut().enumerate() {
            let (mut lo, mut hi) = (x, x);
            lo[axis] = (x[axis] - h).max(0.0);
            hi[axis] = (x[axis] + h).min(crate::rng::PREV_ONE);
            let span = hi[axis] - lo[axis];
            if span > 0.0 {
                *out = (self.0.eval(&hi) - self.0.eval(&lo)) / span;
            }
        }
        Some(g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ by a 2000 × 2000 midpoint rule (independent of the closed forms).
    fn midpoint(f: &dyn SquareIntegrand) -> f64 {
        let m = 2000;
        let mut total = 0.0;
        for i in 0..m {
            for j in 0..m {
                total += f.eval([(i as f64 + 0.5) / m as f64, (j as f64 + 0.5) / m as f64]);
            }
        }
        total / (m * m) as f64
    }

    #[test]
    fn integrals_match_a_fine_midpoint_rule() {
        let cases: Vec<(Box<dyn SquareIntegrand>, f64)> = vec![
            (Box::new(Gaussian::new([0.3, 0.8], [0.01, 0.6], 0.7)), 1e-6),
            (
                Box::new(Gaussian::new([0.95, 0.02], [0.0025, 0.02], 2.0)),
                1e-6,
            ),
            (Box::new(HalfPlane::new(2.2, [0.4, 0.1])), 2e-3),
            (Box::new(Disk::new([0.1, 0.9], 0.3)), 2e-3),
            (Box::new(Disk::new([0.5, 0.5], 0.2)), 2e-3),
            (Box::new(Disk::new([0.5, 0.5], 0.8)), 2e-3),
            (Box::new(Box2::new([0.9, 0.3], 0.4, 0.5)), 2e-3),
        ];
        for (f, tol) in cases {
            let (exact, numeric) = (f.integral(), midpoint(f.as_ref()));
            assert!((exact - numeric).abs() <= tol, "{exact} vs {numeric}");
        }
        // Whole disk inside: πr².
        let d = Disk::new([0.5, 0.5], 0.2);
        assert!((d.integral() - std::f64::consts::PI * 0.04).abs() < 1e-14);
    }

    #[test]
    fn gaussian_gradient_matches_finite_differences() {
        let g = Gaussian::new([0.3, 0.6], [0.02, 0.3], 1.1);
        let x = [0.41, 0.52];
        let grad = g.gradient(x).unwrap();
        let h = 1e-6;
        for axis in 0..2 {
            let (mut a, mut b) = (x, x);
            a[axis] += h;
            b[axis] -= h;
            let fd = (g.eval(a) - g.eval(b)) / (2.0 * h);
            assert!(
                (fd - grad[axis]).abs() < 1e-7,
                "axis {axis}: {fd} vs {}",
                grad[axis]
            );
        }
    }
}
