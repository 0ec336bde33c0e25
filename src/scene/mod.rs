//! The scene: a small obvhs ray tracer whose pixels are the 4D integrands of
//! the analysis (docs/scene.md). f(x, y, u, v) has (x, y) on the pixel's
//! footprint and (u, v) on the lens (depth of field) or on the first light
//! (soft shadows); [`Scene::radiance`] evaluates it.

pub mod analysis;
pub mod camera;
pub mod description;
pub mod geometry;
pub mod image;
pub mod mesh;
pub mod pixel;
pub mod pixel_shear;
pub mod render;

use camera::Camera;
use description::{
    IntegrandKind, LightFile, LightSampling, LightShape, MaterialFile, SceneError, SceneFile,
};
use geometry::{BvhKind, Geometry, Hit, Placement, dot};

/// The built-in scenes: name, what it shows, its JSON.
pub const BUILTIN_SCENES: [(&str, &str, &str); 4] = [
    (
        "dof",
        "depth of field: a checkered box in focus between a defocused striped sphere and a \
         checkered wall",
        include_str!("../../scenes/dof.json"),
    ),
    (
        "shadows-square",
        "soft shadows of a box on a floor under a square light",
        include_str!("../../scenes/shadows-square.json"),
    ),
    (
        "shadows-disk",
        "the same under a disk light of the same area",
        include_str!("../../scenes/shadows-disk.json"),
    ),
    (
        "shadows-disk-bounding-square",
        "the same disk light with (u, v) uniform on its bounding square (the disk an indicator \
         in (u, v): the seed's setting)",
        include_str!("../../scenes/shadows-disk-bounding-square.json"),
    ),
];

/// A scene ready to render.
pub struct Scene {
    name: String,
    file: SceneFile,
    camera: Camera,
    geometry: Geometry,
    placements: Vec<Placement>,
    lights: Vec<Light>,
}

/// An area light with its orthonormal frame.
struct Light {
    shape: LightShape,
    centre: [f64; 3],
    normal: [f64; 3],
    tangent: [f64; 3],
    bitangent: [f64; 3],
    size: f64,
    radiance: f64,
    sampling: LightSampling,
}

impl Light {
    fn new(l: &LightFile) -> Light {
        let normal = description::unit(l.normal).expect("a checked light has a non-zero normal");
        // Any vector not parallel to the normal gives the frame.
        let helper = if normal[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let t = description::cross(helper, normal);
        let tn = description::norm(t);
        let tangent = t.map(|c| c / tn);
        let bitangent = description::cross(normal, tangent);
        Light {
            shape: l.shape,
            centre: l.centre,
            normal,
            tangent,
            bitangent,
            size: l.size,
            radiance: l.radiance,
            sampling: l.sampling(),
        }
    }

    /// The light's area.
    fn area(&self) -> f64 {
        match self.shape {
            LightShape::Square => self.size * self.size,
            LightShape::Disk => std::f64::consts::PI * 0.25 * self.size * self.size,
        }
    }

    /// The area (u, v) are spread over: the light's, or its bounding
    /// square's.
    fn sampled_area(&self) -> f64 {
        match self.sampling {
            LightSampling::Area => self.area(),
            LightSampling::BoundingSquare => self.size * self.size,
        }
    }

    /// The point of the light at (u, v) ∈ [0, 1)², uniform on the sampled
    /// area: the square directly, the disk by the concentric map (Shirley &
    /// Chiu 1997, which keeps strata compact) or through its bounding
    /// square (`None` off the disk).
    fn point(&self, u: f64, v: f64) -> Option<[f64; 3]> {
        let (a, b) = match (self.shape, self.sampling) {
            (LightShape::Square, _) => (self.size * (u - 0.5), self.size * (v - 0.5)),
            (LightShape::Disk, LightSampling::BoundingSquare) => {
                let (a, b) = (self.size * (u - 0.5), self.size * (v - 0.5));
                if a * a + b * b > 0.25 * self.size * self.size {
                    return None;
                }
                (a, b)
            }
            (LightShape::Disk, LightSampling::Area) => {
                let (p, q) = (2.0 * u - 1.0, 2.0 * v - 1.0);
                let (r, phi) = if p == 0.0 && q == 0.0 {
                    (0.0, 0.0)
                } else if p.abs() > q.abs() {
                    (p, std::f64::consts::FRAC_PI_4 * (q / p))
                } else {
                    (
                        q,
                        std::f64::consts::FRAC_PI_2 - std::f64::consts::FRAC_PI_4 * (p / q),
                    )
                };
                let r = 0.5 * self.size * r;
                (r * phi.cos(), r * phi.sin())
            }
        };
        Some(std::array::from_fn(|k| {
            self.centre[k] + a * self.tangent[k] + b * self.bitangent[k]
        }))
    }
}

/// The least offset that keeps secondary rays off the surface they leave.
const RAY_EPSILON: f64 = 1e-4;
/// The offset in f32 units of the coordinates involved: the BVH intersects
/// in f32 (relative precision 1.2e-7), so in a scene of large world units a
/// fixed offset would let a shadow ray hit the surface it leaves (a scene
/// scaled by 1000 rendered its lit pixels 4–9% too dark).
const RAY_EPSILON_ULPS: f64 = 64.0;

/// The offset of a shadow ray leaving a point of f32 magnitude `point`
/// ([`Geometry::magnitude`]), whose position came from a camera ray of
/// reach `reach` (its origin's magnitude + t): the rounding is at the ray's
/// start, whatever the light's distance (a light's coordinates in the scale
/// would let a distant sun's shadow rays skip nearby occluders).
fn ray_offset(point: f64, reach: f64) -> f64 {
    RAY_EPSILON.max(RAY_EPSILON_ULPS * f64::from(f32::EPSILON) * point.max(reach))
}

/// The largest scene file read (its meshes are OBJ files of their own).
const MAX_SCENE_BYTES: u64 = 64 << 20;

impl Scene {
    /// A built-in scene by name, or a scene file by path.
    ///
    /// # Errors
    /// [`SceneError`] naming the file and field.
    pub fn load(name_or_path: &str) -> Result<Scene, SceneError> {
        if let Some((name, _, json)) = BUILTIN_SCENES.iter().find(|s| s.0 == name_or_path) {
            return Scene::from_text(json, name);
        }
        let path = std::path::Path::new(name_or_path);
        if !path.exists() {
            return Err(SceneError::Unknown {
                name: name_or_path.into(),
                suggestion: crate::suggest::did_you_mean(
                    name_or_path,
                    BUILTIN_SCENES.iter().map(|s| s.0),
                ),
                known: BUILTIN_SCENES.map(|s| s.0).join(", "),
                // Relative paths (also in experiment files) are read from
                // the working directory, not the naming file's folder.
                place: match std::env::current_dir() {
                    Ok(dir) if std::path::Path::new(name_or_path).is_relative() => {
                        format!(" in the working directory {}", dir.display())
                    }
                    _ => String::new(),
                },
            });
        }
        let text = crate::io::read_text_bounded(path, MAX_SCENE_BYTES, "a scene file").map_err(
            |cause| SceneError::Io {
                path: name_or_path.into(),
                cause,
            },
        )?;
        let folder = path.parent().unwrap_or(std::path::Path::new(""));
        Scene::build(&text, name_or_path, folder, BvhKind::Bvh2)
    }

    /// The files [`Self::load`] reads for `name_or_path`: none for a
    /// built-in scene; the scene file and the OBJ files of its `obj` shapes
    /// (relative to its folder) otherwise, or the scene file alone when it
    /// does not read or parse (loading it will say why). Commands refuse
    /// outputs that are one of them.
    pub fn files_read(name_or_path: &str) -> Vec<std::path::PathBuf> {
        if BUILTIN_SCENES.iter().any(|s| s.0 == name_or_path) {
            return Vec::new();
        }
        let path = std::path::Path::new(name_or_path);
        let mut files = vec![path.to_path_buf()];
        let parsed = crate::io::read_text_bounded(path, MAX_SCENE_BYTES, "a scene file")
            .ok()
            .and_then(|text| SceneFile::parse(&text, name_or_path).ok());
        if let Some(file) = parsed {
            let folder = path.parent().unwrap_or(std::path::Path::new(""));
            files.extend(
                file.objects
                    .iter()
                    .filter_map(|o| o.file.as_ref())
                    .map(|obj| folder.join(obj)),
            );
        }
        files
    }

    /// A scene from JSON text; `name` names it in errors and reports.
    ///
    /// # Errors
    /// [`SceneError::Syntax`] or [`SceneError::Field`].
    pub fn from_text(text: &str, name: &str) -> Result<Scene, SceneError> {
        Scene::from_text_with(text, name, BvhKind::Bvh2)
    }

    /// As [`Self::from_text`] with a chosen BVH (OBJ files relative to
    /// the current folder).
    ///
    /// # Errors
    /// [`SceneError::Syntax`] or [`SceneError::Field`].
    pub fn from_text_with(text: &str, name: &str, bvh: BvhKind) -> Result<Scene, SceneError> {
        Scene::build(text, name, std::path::Path::new(""), bvh)
    }

    /// Parses, reads the OBJ meshes (relative to `folder`) and builds.
    fn build(
        text: &str,
        name: &str,
        folder: &std::path::Path,
        bvh: BvhKind,
    ) -> Result<Scene, SceneError> {
        let file = SceneFile::parse(text, name)?;
        let meshes = file
            .objects
            .iter()
            .enumerate()
            .map(|(i, o)| mesh::object_triangles(o, i, name, folder))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Scene {
            name: name.into(),
            camera: Camera::new(&file.camera),
            geometry: Geometry::build_with(&file.objects, &meshes, bvh, file.camera.position),
            placements: file.objects.iter().map(Placement::of).collect(),
            lights: file.lights.iter().map(Light::new).collect(),
            file,
        })
    }

    /// The scene's name (built-in name or path).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The camera.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The geometry.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// Whether the lens has an area (aperture > 0).
    pub fn has_aperture(&self) -> bool {
        self.file.camera.aperture > 0.0
    }

    /// Why the scene's pixels have no light-field slope κ, so that every
    /// analytic shear is none (`None`: (u, v) are on a lens with an area,
    /// and a pixel's slope follows its depth).
    pub fn why_no_slope(&self) -> Option<&'static str> {
        if self.integrand() == IntegrandKind::Light {
            Some("its (u, v) sample the light (soft shadows through a pinhole camera), not a lens")
        } else if !self.has_aperture() {
            Some("its camera is a pinhole (aperture 0)")
        } else {
            None
        }
    }

    /// What (u, v) sample.
    pub fn integrand(&self) -> IntegrandKind {
        self.file.integrand
    }

    /// The pixel integrand f(x, y, u, v) of pixel (px, py), `p` in
    /// [0, 1)^4: the radiance along the camera ray. Lens integrand: (u, v)
    /// on the lens, each light seen as a point at its centre (shadowed);
    /// light integrand: a pinhole ray and (u, v) on the first light, one
    /// sample of each light's direct illumination (its area times L_e
    /// cosθ cosθ′ / (π r²), shadowed). Misses see the ambient radiance.
    pub fn radiance(&self, px: usize, py: usize, p: [f64; 4]) -> f64 {
        let lens = self.file.integrand == IntegrandKind::Lens;
        let ray_point = if lens { p } else { [p[0], p[1], 0.5, 0.5] };
        let ray = self.camera.ray(px, py, ray_point);
        let Some(hit) = self.geometry.closest(ray.origin, ray.direction, 0.0) else {
            return self.file.ambient;
        };
        let albedo = self.albedo(hit.object, hit.point);
        let reach = self.geometry.magnitude(ray.origin) + hit.t;
        let mut irradiance = self.file.ambient;
        for light in &self.lights {
            let (at, area) = if lens {
                (Some(light.centre), light.area())
            } else {
                (light.point(p[2], p[3]), light.sampled_area())
            };
            if let Some(at) = at {
                irradiance += area * self.direct(light, at, &hit, reach);
            }
        }
        albedo * irradiance
    }

    /// Direct illumination from `light` through its point `at` per unit of
    /// light area, L_e cosθ cosθ′ / (π r²), shadowed (times the sampled
    /// area it is one sample of an irradiance/π, so ambient and lights add).
    fn direct(&self, light: &Light, at: [f64; 3], hit: &Hit, reach: f64) -> f64 {
        let (point, normal) = (hit.point, hit.normal);
        let to = description::sub(at, point);
        let r2 = dot(to, to);
        // A surface point on the light point itself: no direction to it
        // (a light lying on a surface meets it at cos θ′ = 0 anyway); a
        // set of measure zero, given 0 rather than a NaN pixel.
        if r2 <= 0.0 {
            return 0.0;
        }
        let r = r2.sqrt();
        let dir = to.map(|c| c / r);
        let cos_surface = dot(normal, dir);
        let cos_light = -dot(light.normal, dir);
        if cos_surface <= 0.0 || cos_light <= 0.0 {
            return 0.0;
        }
        // Leave the surface by the offset along its normal and stop that
        // far short of the light: once at each end (the segment used to
        // skip it twice at each, missing occluders within 2·eps).
        let eps = ray_offset(self.geometry.magnitude(point), reach);
        let origin: [f64; 3] = std::array::from_fn(|k| point[k] + eps * normal[k]);
        let span = description::sub(at, origin);
        let length = dot(span, span).sqrt();
        let towards = span.map(|c| c / length);
        if !self.geometry.unoccluded(origin, towards, length - eps) {
            return 0.0;
        }
        light.radiance * cos_surface * cos_light / (std::f64::consts::PI * r2)
    }

    /// The material's albedo at a world point of object `object`. Solid
    /// textures have their cells centred on the object's origin, so faces
    /// through the origin or at whole multiples of a cell do not fall on a
    /// cell boundary.
    fn albedo(&self, object: usize, point: [f64; 3]) -> f64 {
        let q = self.placements[object].frame(point);
        let cell = |x: f64, period: f64| (2.0 * x / period + 0.5).floor() as i64;
        match self.file.objects[object].material {
            MaterialFile::Constant { albedo } => albedo,
            MaterialFile::Checker { period, low, high } => {
                let parity = cell(q[0], period) + cell(q[1], period) + cell(q[2], period);
                if parity.rem_euclid(2) == 0 { high } else { low }
            }
            MaterialFile::Stripes { period, low, high } => {
                if cell(q[0], period).rem_euclid(2) == 0 {
                    high
                } else {
                    low
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_surface_point_on_the_light_point_gets_no_light_not_nan() {
        let scene = Scene::from_text(
            r#"{"camera": {"resolution": [1, 1], "fov_degrees": 30, "position": [0, 0, 0],
                           "look_at": [0, 0, -1], "focal_distance": 1, "aperture": 0},
                "integrand": "light",
                "objects": [{"shape": "quad", "translate": [0, 0, -5],
                             "material": {"texture": "constant", "albedo": 0.5}}],
                "lights": [{"shape": "disk", "size": 0.2, "centre": [0, 0, -4],
                            "normal": [0, 0, -1], "radiance": 1}]}"#,
            "t",
        )
        .unwrap();
        let light = &scene.lights[0];
        let on = |point| Hit {
            t: 1.0,
            point,
            normal: [0.0, 0.0, 1.0],
            object: 0,
        };
        assert_eq!(
            scene.direct(light, light.centre, &on(light.centre), 5.0),
            0.0
        );
        // One unit below, straight under it: L_e/π.
        let below = scene.direct(light, light.centre, &on([0.0, 0.0, -5.0]), 5.0);
        assert!(
            (below - 1.0 / std::f64::consts::PI).abs() < 1e-12,
            "{below}"
        );
    }

    /// Unit normal and area of a triangle.
    fn normal_area([a, b, c]: [[f64; 3]; 3]) -> ([f64; 3], f64) {
        let n = description::cross(description::sub(b, a), description::sub(c, a));
        let len = description::norm(n);
        (n.map(|x| x / len), len / 2.0)
    }

    /// Every undirected edge in exactly two triangles: a closed surface.
    fn closed(triangles: &[[[f64; 3]; 3]]) -> bool {
        let key = |p: [f64; 3]| p.map(|x| (x * 1e9).round() as i64);
        let mut edges = std::collections::HashMap::new();
        for t in triangles {
            for (i, j) in [(0, 1), (1, 2), (2, 0)] {
                let (p, q) = (key(t[i]), key(t[j]));
                *edges
                    .entry(if p < q { (p, q) } else { (q, p) })
                    .or_insert(0) += 1;
            }
        }
        edges.values().all(|&n| n == 2)
    }

    #[test]
    fn built_in_box_and_sphere_are_closed_surfaces_of_their_size() {
        use description::ShapeKind;
        use geometry::shape_triangles;
        let cube = shape_triangles(ShapeKind::Box, 0).unwrap();
        let area: f64 = cube.iter().map(|&t| normal_area(t).1).sum();
        // The cube [−1, 1]³: six faces of area 4.
        assert_eq!((cube.len(), area), (12, 24.0));
        assert!(closed(&cube));
        for levels in 0..=4 {
            let sphere = shape_triangles(ShapeKind::Sphere, levels).unwrap();
            assert_eq!(sphere.len(), 20 << (2 * levels));
            assert!(closed(&sphere), "level {levels}");
            assert!(
                sphere
                    .iter()
                    .flatten()
                    .all(|p| (description::norm(*p) - 1.0).abs() < 1e-15),
                "vertices on the unit sphere"
            );
            // A convex polyhedron between the balls of radius ρ (its
            // faces' least distance from the centre) and 1 has a surface
            // area between theirs.
            let rho = sphere
                .iter()
                .map(|&t| dot(normal_area(t).0, t[0]).abs())
                .fold(1.0, f64::min);
            let area: f64 = sphere.iter().map(|&t| normal_area(t).1).sum();
            let ball = 4.0 * std::f64::consts::PI;
            assert!(
                ball * rho * rho <= area && area <= ball,
                "level {levels}: area {area}, ρ {rho}"
            );
            if levels == 4 {
                assert!(rho > 0.99, "ρ {rho}");
            }
        }
    }

    /// Rays toward a placed (scaled, rotated, translated) box and sphere
    /// hit where the closed forms say: the box at 6 − min_i h_i/|d_i| (d in
    /// the box's frame, h its half sides), with the face's normal; the
    /// sphere of radius r between 6 − r and 6 − r·ρ (ρ its tessellation's
    /// inner radius).
    #[test]
    fn rays_hit_placed_boxes_and_spheres_where_the_closed_forms_say() {
        use crate::rng::{set_rng, uniform};
        let centre = [1.0, 2.0, -3.0];
        let (half, angle, r) = ([0.5, 1.0, 2.0], 30f64.to_radians(), 0.7);
        let scene = |object: &str| {
            Scene::from_text(
                &format!(
                    r#"{{"camera": {{"resolution": [1, 1], "fov_degrees": 30, "position": [0, 0, 0],
                                   "look_at": [0, 0, -1], "focal_distance": 1, "aperture": 0}},
                        "integrand": "lens", "ambient": 1,
                        "objects": [{{{object}, "translate": [1, 2, -3],
                                     "material": {{"texture": "constant", "albedo": 0.5}}}}]}}"#
                ),
                "t",
            )
            .unwrap()
        };
        let cuboid = scene(r#""shape": "box", "scale": [0.5, 1, 2], "rotate_y_degrees": 30"#);
        let ball = scene(r#""shape": "sphere", "subdivisions": 4, "scale": [0.7, 0.7, 0.7]"#);
        let rho = geometry::shape_triangles(description::ShapeKind::Sphere, 4)
            .unwrap()
            .iter()
            .map(|&t| dot(normal_area(t).0, t[0]).abs())
            .fold(1.0, f64::min);
        // World to the box's frame: the inverse rotation about y.
        let to_frame = |d: [f64; 3]| {
            [
                angle.cos() * d[0] - angle.sin() * d[2],
                d[1],
                angle.sin() * d[0] + angle.cos() * d[2],
            ]
        };
        let mut rng = set_rng(5, 0);
        for _ in 0..200 {
            // A uniform direction.
            let z = 2.0 * uniform(&mut rng) - 1.0;
            let phi = 2.0 * std::f64::consts::PI * uniform(&mut rng);
            let s = (1.0 - z * z).sqrt();
            let d = [s * phi.cos(), s * phi.sin(), z];
            let origin: [f64; 3] = std::array::from_fn(|k| centre[k] - 6.0 * d[k]);
            let local = to_frame(d);
            let (axis, reach) = (0..3)
                .map(|i| (i, half[i] / local[i].abs()))
                .fold((0, f64::INFINITY), |m, c| if c.1 < m.1 { c } else { m });
            let hit = cuboid.geometry().closest(origin, d, 0.0).expect("the box");
            assert!(
                (hit.t - (6.0 - reach)).abs() < 1e-5,
                "box: t {} vs {}",
                hit.t,
                6.0 - reach
            );
            let n = to_frame(hit.normal);
            assert!(
                (n[axis].abs() - 1.0).abs() < 1e-5 && dot(hit.normal, d) < 0.0,
                "box normal {:?} (frame {n:?}), face axis {axis}",
                hit.normal
            );
            let hit = ball.geometry().closest(origin, d, 0.0).expect("the sphere");
            assert!(
                hit.t >= 6.0 - r - 1e-5 && hit.t <= 6.0 - r * rho + 1e-5,
                "sphere: t {} outside [{}, {}]",
                hit.t,
                6.0 - r,
                6.0 - r * rho
            );
        }
    }
}
