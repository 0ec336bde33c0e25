//! The thin-lens camera (Kolb et al. 1995; pbrt-v4 §5.2.3) with a square
//! aperture, so that the lens coordinates (u, v) enter the light field
//! linearly: a surface at depth d, seen through a lens focused at F, shears
//! the pixel's light field by c = (F − d)/d (Soler et al. 2009), which in
//! the pixel integrand's units (pixels per unit of u) is
//! κ = c · (2A / s): A the lens half-side, s the size of a pixel on the plane
//! in focus. Along the lines x + κ·u = const the integrand of a
//! fronto-parallel plane is constant (the `defocus` integrand's form with
//! c = κ); the sample shear that follows them is a = b = −κ.

use super::description::{CameraFile, cross, norm, sub, unit};
use super::geometry::dot;

/// A camera ray: origin on the lens, unit direction.
#[derive(Debug, Clone, Copy)]
pub struct CameraRay {
    /// Point on the lens.
    pub origin: [f64; 3],
    /// Unit direction.
    pub direction: [f64; 3],
}

/// The thin-lens camera of a scene.
#[derive(Debug, Clone)]
pub struct Camera {
    position: [f64; 3],
    right: [f64; 3],
    down: [f64; 3],
    forward: [f64; 3],
    width: usize,
    height: usize,
    focal_distance: f64,
    aperture: f64,
    pixel: f64,
}

impl Camera {
    /// From a checked camera description.
    ///
    /// # Panics
    /// On a description its check refuses (a zero or non-finite view or
    /// `up`, or `up` parallel to the view).
    pub fn new(c: &CameraFile) -> Camera {
        // The description's check refused zero, non-finite and parallel
        // directions.
        let unit = |v| unit(v).expect("a checked camera has non-zero directions");
        let forward = unit(sub(c.look_at, c.position));
        let right = unit(cross(forward, unit(c.up)));
        let down = cross(forward, right);
        let [width, height] = c.resolution;
        let pixel =
            2.0 * c.focal_distance * (0.5 * c.fov_degrees.to_radians()).tan() / width as f64;
        Camera {
            position: c.position,
            right,
            down,
            forward,
            width,
            height,
            focal_distance: c.focal_distance,
            aperture: c.aperture,
            pixel,
        }
    }

    /// Image width and height in pixels.
    pub fn resolution(&self) -> [usize; 2] {
        [self.width, self.height]
    }

    /// The ray through image point (px + x, py + y) (pixels, x and y in
    /// [0, 1) across the pixel) from lens point (u, v) ∈ [0, 1)², (½, ½)
    /// the lens centre.
    pub fn ray(&self, px: usize, py: usize, [x, y, u, v]: [f64; 4]) -> CameraRay {
        let (f, s, a) = (self.focal_distance, self.pixel, self.aperture);
        let ix = (px as f64 + x - 0.5 * self.width as f64) * s;
        let iy = (py as f64 + y - 0.5 * self.height as f64) * s;
        let (lx, ly) = (a * (2.0 * u - 1.0), a * (2.0 * v - 1.0));
        let at = |k: usize, p: [f64; 3]| p[k];
        let focus: [f64; 3] = std::array::from_fn(|k| {
            at(k, self.position) + f * self.forward[k] + ix * self.right[k] + iy * self.down[k]
        });
        let origin: [f64; 3] =
            std::array::from_fn(|k| self.position[k] + lx * self.right[k] + ly * self.down[k]);
        let d = sub(focus, origin);
        let n = norm(d);
        CameraRay {
            origin,
            direction: [d[0] / n, d[1] / n, d[2] / n],
        }
    }

    /// Depth of a point: its distance from the lens along the view axis.
    pub fn depth(&self, point: [f64; 3]) -> f64 {
        dot(sub(point, self.position), self.forward)
    }

    /// The light-field shear κ (pixels per unit of u) of a surface at
    /// `depth`: κ = (F − d)/d · 2A/s; 0 for a pinhole.
    pub fn shear_at_depth(&self, depth: f64) -> f64 {
        (self.focal_distance - depth) / depth * 2.0 * self.aperture / self.pixel
    }
}
