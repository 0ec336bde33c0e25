//! Scene files: JSON read with serde, every field checked with an error that
//! names it (docs/formats.md, "Scene file"). Grey-scale radiance throughout:
//! the analysis works on one scalar integrand per pixel.

use crate::spec_params::SpecValue;
use serde::Deserialize;

/// A whole scene as written in its file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// The thin-lens camera.
    pub camera: CameraFile,
    /// Triangle meshes with their materials.
    pub objects: Vec<ObjectFile>,
    /// Area lights (may be empty: then only `ambient` lights the scene).
    #[serde(default)]
    pub lights: Vec<LightFile>,
    /// Constant light from every direction, added to the area lights.
    #[serde(default)]
    pub ambient: f64,
    /// What (u, v) of the pixel integrand f(x, y, u, v) samples: the lens
    /// (depth of field) or the first light (soft shadows).
    pub integrand: IntegrandKind,
}

/// The 4D pixel integrand's (u, v) dimensions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IntegrandKind {
    /// (u, v) on the lens: depth of field; lights are lit from their centre.
    Lens,
    /// (u, v) on the light: soft shadows through a pinhole camera.
    Light,
}

/// A thin-lens camera with a square aperture.
#[derive(Debug, Clone, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a camera: an object with `resolution`, `fov_degrees`, `position`, `look_at`, `focal_distance` and `aperture`"
)]
pub struct CameraFile {
    /// Image width and height in pixels.
    pub resolution: [usize; 2],
    /// Horizontal field of view in degrees, in (0, 180).
    pub fov_degrees: f64,
    /// Centre of the lens.
    pub position: [f64; 3],
    /// A point the camera looks at.
    pub look_at: [f64; 3],
    /// Up direction (need not be orthogonal to the view).
    #[serde(default = "default_up")]
    pub up: [f64; 3],
    /// Distance F of the plane in focus, along the view axis.
    pub focal_distance: f64,
    /// Half the side of the square lens (0: a pinhole).
    pub aperture: f64,
}

fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

/// One mesh.
#[derive(Debug, Clone, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "an object: `{ \"shape\": ..., \"material\": ... }`"
)]
pub struct ObjectFile {
    /// Built-in shape: `quad` ([−1, 1]² in the xy plane, normal +z),
    /// `box` ([−1, 1]³) or `sphere` (unit radius, tessellated); or `obj`, a
    /// triangle mesh read from `file`.
    pub shape: ShapeKind,
    /// The Wavefront OBJ file of an `obj` shape (relative to the scene
    /// file's folder); model-space positions, faces triangulated as fans.
    #[serde(default)]
    pub file: Option<String>,
    /// Scale per axis, applied first.
    #[serde(default = "unit_scale")]
    pub scale: [f64; 3],
    /// Rotation about the y axis in degrees, applied second.
    #[serde(default)]
    pub rotate_y_degrees: f64,
    /// Translation, applied last.
    #[serde(default)]
    pub translate: [f64; 3],
    /// Sphere tessellation: subdivisions of an icosahedron (0 to 7; only for
    /// `sphere`, default [`DEFAULT_SUBDIVISIONS`]).
    #[serde(default)]
    pub subdivisions: Option<u32>,
    /// The diffuse material.
    pub material: MaterialFile,
}

fn unit_scale() -> [f64; 3] {
    [1.0; 3]
}

/// A sphere's subdivisions when the file gives none (1280 triangles).
pub const DEFAULT_SUBDIVISIONS: u32 = 3;

impl ObjectFile {
    /// The icosahedron subdivisions of a sphere.
    pub fn subdivisions(&self) -> u32 {
        self.subdivisions.unwrap_or(DEFAULT_SUBDIVISIONS)
    }
}

/// Built-in mesh shapes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeKind {
    /// Two triangles.
    Quad,
    /// Twelve triangles.
    Box,
    /// A subdivided icosahedron.
    Sphere,
    /// A Wavefront OBJ mesh (`file`).
    Obj,
}

/// A diffuse material: albedo in [0, 1], constant or a solid texture in the
/// object's frame (its translation and rotation, world units: scaling the
/// object does not stretch the texture), so its bandwidth is known.
#[derive(Debug, Clone, Deserialize)]
#[serde(try_from = "MaterialFields")]
pub enum MaterialFile {
    /// One albedo.
    Constant {
        /// The albedo.
        albedo: f64,
    },
    /// A 3D checkerboard of cells `period`/2 wide.
    Checker {
        /// Period in object units.
        period: f64,
        /// Albedo of the dark cells.
        low: f64,
        /// Albedo of the light cells.
        high: f64,
    },
    /// Stripes across the object's x axis.
    Stripes {
        /// Period in object units.
        period: f64,
        /// Albedo of the dark stripes.
        low: f64,
        /// Albedo of the light stripes.
        high: f64,
    },
}

/// A material as written: the texture's name and every field any texture
/// takes. Read flat rather than as a tagged enum so that a field of the
/// wrong type is named by its path (`objects[0].material.albedo`), which
/// serde's internally tagged enums lose; [`MaterialFile::try_from`] then
/// checks that the fields are the texture's own.
#[derive(Debug, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a material: an object with `texture` (constant, checker or stripes) and its fields"
)]
struct MaterialFields {
    texture: TextureKind,
    albedo: Option<f64>,
    period: Option<f64>,
    low: Option<f64>,
    high: Option<f64>,
}

/// The `texture` of a material.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "snake_case")]
enum TextureKind {
    Constant,
    Checker,
    Stripes,
}

impl TryFrom<MaterialFields> for MaterialFile {
    type Error = String;

    /// The texture's fields, each present; a field of another texture is
    /// refused by name with the texture's own fields.
    fn try_from(m: MaterialFields) -> Result<MaterialFile, String> {
        use TextureKind::{Checker, Constant, Stripes};
        match (m.texture, m.albedo, m.period, m.low, m.high) {
            (Constant, Some(albedo), None, None, None) => Ok(MaterialFile::Constant { albedo }),
            (Checker, None, Some(period), Some(low), Some(high)) => {
                Ok(MaterialFile::Checker { period, low, high })
            }
            (Stripes, None, Some(period), Some(low), Some(high)) => {
                Ok(MaterialFile::Stripes { period, low, high })
            }
            _ => Err(m.mismatch()),
        }
    }
}

impl MaterialFields {
    /// The first field that is not the texture's own, or the first of its
    /// own that is missing, named with the texture's fields.
    fn mismatch(&self) -> String {
        let (name, own): (&str, &[&str]) = match self.texture {
            TextureKind::Constant => ("constant", &["albedo"]),
            TextureKind::Checker => ("checker", &["period", "low", "high"]),
            TextureKind::Stripes => ("stripes", &["period", "low", "high"]),
        };
        let given = [
            ("albedo", self.albedo.is_some()),
            ("period", self.period.is_some()),
            ("low", self.low.is_some()),
            ("high", self.high.is_some()),
        ];
        let foreign = given.iter().find(|&&(f, set)| set && !own.contains(&f));
        let missing = given.iter().find(|&&(f, set)| !set && own.contains(&f));
        let own = own.join(", ");
        match (foreign, missing) {
            (Some((field, _)), _) => {
                format!("`{field}` is not a field of a `{name}` texture (its fields: {own})")
            }
            (None, Some((field, _))) => {
                format!("missing field `{field}` of a `{name}` texture (its fields: {own})")
            }
            (None, None) => format!("a `{name}` texture takes the fields {own}"),
        }
    }
}

/// An emitting square or disk, one-sided, facing `normal`.
#[derive(Debug, Clone, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a light: an object with `shape` and its fields"
)]
pub struct LightFile {
    /// `square` or `disk`.
    pub shape: LightShape,
    /// Centre.
    pub centre: [f64; 3],
    /// The side it emits towards.
    pub normal: [f64; 3],
    /// Side (square) or diameter (disk).
    pub size: f64,
    /// Emitted radiance.
    pub radiance: f64,
    /// How (u, v) reach the light: `area` (uniform on its area; the disk by
    /// the concentric map) or `bounding_square` (uniform on the square
    /// around it, points off a disk contributing nothing: the disk's edge
    /// then is a discontinuity in (u, v), as in the seed's light
    /// experiments). Only for a disk: a square is its own bounding square.
    #[serde(default)]
    pub sampling: Option<LightSampling>,
}

impl LightFile {
    /// How (u, v) reach the light (`area` when the file does not say).
    pub fn sampling(&self) -> LightSampling {
        self.sampling.unwrap_or_default()
    }
}

/// How a light's (u, v) map onto it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LightSampling {
    /// Uniform on the light's area.
    #[default]
    Area,
    /// Uniform on its bounding square; an indicator of the light's shape.
    BoundingSquare,
}

/// Area-light shapes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LightShape {
    /// A square.
    Square,
    /// A disk (sampled by the concentric map, Shirley & Chiu 1997).
    Disk,
}

/// What is wrong with a scene.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// Unreadable file.
    #[error("{path}: {cause}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        cause: std::io::Error,
    },
    /// Malformed JSON or a field of the wrong type (the message names the
    /// field, line and column).
    #[error("{source_name}: {message}")]
    Syntax {
        /// File or built-in name.
        source_name: String,
        /// serde_json's message.
        message: String,
    },
    /// A value out of its range.
    #[error("{source_name}: {field} = {value}: {expected}")]
    Field {
        /// File or built-in name.
        source_name: String,
        /// Path of the field, e.g. `objects[2].scale`.
        field: String,
        /// The value found.
        value: String,
        /// What is accepted.
        expected: String,
    },
    /// No built-in scene and no file of that name.
    #[error("no scene `{name}`{suggestion}: neither a built-in scene ({known}) nor a file{place}")]
    Unknown {
        /// The name given.
        name: String,
        /// " (did you mean `…`?)" or empty ([`crate::suggest`]).
        suggestion: String,
        /// The built-in names.
        known: String,
        /// Where a relative path was looked for (" in the working
        /// directory /…"), or empty.
        place: String,
    },
}

/// The largest image side accepted (pixels).
pub const MAX_SIDE: usize = 16384;

/// Bytes a render holds per pixel (analysis, shear, image, variance maps),
/// an upper bound checked against the memory budget when a scene is read.
const PIXEL_BYTES: f64 = 256.0;

impl SceneFile {
    /// Parses and checks a scene; `source_name` names it in errors.
    ///
    /// # Errors
    /// [`SceneError::Syntax`] or [`SceneError::Field`].
    pub fn parse(text: &str, source_name: &str) -> Result<SceneFile, SceneError> {
        let scene: SceneFile =
            crate::io::from_json(text).map_err(|message| SceneError::Syntax {
                source_name: source_name.into(),
                message,
            })?;
        scene.check(source_name)?;
        Ok(scene)
    }

    fn check(&self, source_name: &str) -> Result<(), SceneError> {
        let bad = |field: String, value: String, expected: &str| SceneError::Field {
            source_name: source_name.into(),
            field,
            value,
            expected: expected.into(),
        };
        let c = &self.camera;
        for (axis, &side) in ["width", "height"].iter().zip(&c.resolution) {
            if side == 0 || side > MAX_SIDE {
                return Err(bad(
                    format!("camera.resolution ({axis})"),
                    side.to_string(),
                    &format!("an integer from 1 to {MAX_SIDE}"),
                ));
            }
        }
        // A render holds per pixel its analysis, its shear, the image and
        // the variance maps: 256 bytes a pixel is an ample bound.
        let [w, h] = c.resolution;
        if let Err(e) = crate::memory::check(
            &format!("a {w} x {h} image"),
            Some(w as f64 * h as f64 * PIXEL_BYTES),
            "lower camera.resolution",
        ) {
            return Err(bad(
                "camera.resolution".into(),
                format!("[{w}, {h}]"),
                &e.to_string(),
            ));
        }
        if !(c.fov_degrees > 0.0 && c.fov_degrees < 180.0) {
            return Err(bad(
                "camera.fov_degrees".into(),
                SpecValue(c.fov_degrees).to_string(),
                "a number of degrees in (0, 180)",
            ));
        }
        bounded3("camera.position", &c.position).map_err(|(f, v)| bad(f, v, BOUNDED))?;
        bounded3("camera.look_at", &c.look_at).map_err(|(f, v)| bad(f, v, BOUNDED))?;
        let Some(view) = unit(sub(c.look_at, c.position)) else {
            return Err(bad(
                "camera.look_at".into(),
                format!("{:?}", c.look_at),
                "a point other than camera.position",
            ));
        };
        let up = unit(c.up).ok_or_else(|| {
            bad(
                "camera.up".into(),
                format!("{:?}", c.up),
                "a non-zero direction of finite numbers",
            )
        })?;
        if norm(cross(view, up)) < 1e-9 {
            return Err(bad(
                "camera.up".into(),
                format!("{:?}", c.up),
                "a direction not parallel to the view (look_at − position)",
            ));
        }
        if !(c.focal_distance > 0.0 && c.focal_distance <= MAX_LENGTH) {
            return Err(bad(
                "camera.focal_distance".into(),
                SpecValue(c.focal_distance).to_string(),
                &format!("a positive distance of at most {MAX_LENGTH:e}"),
            ));
        }
        if !(c.aperture >= 0.0 && c.aperture <= MAX_LENGTH) {
            return Err(bad(
                "camera.aperture".into(),
                SpecValue(c.aperture).to_string(),
                &format!("a half-side from 0 (a pinhole) to {MAX_LENGTH:e}"),
            ));
        }
        if self.objects.is_empty() {
            return Err(bad("objects".into(), "[]".into(), "at least one object"));
        }
        for (i, o) in self.objects.iter().enumerate() {
            let field = |name: &str| format!("objects[{i}].{name}");
            bounded3(&field("translate"), &o.translate).map_err(|(f, v)| bad(f, v, BOUNDED))?;
            if o.scale.iter().any(|s| !(*s > 0.0 && *s <= MAX_LENGTH)) {
                return Err(bad(
                    field("scale"),
                    format!("{:?}", o.scale),
                    &format!("three positive scale factors of at most {MAX_LENGTH:e}"),
                ));
            }
            if !o.rotate_y_degrees.is_finite() {
                return Err(bad(
                    field("rotate_y_degrees"),
                    SpecValue(o.rotate_y_degrees).to_string(),
                    "a finite number of degrees",
                ));
            }
            match (o.shape, &o.file) {
                (ShapeKind::Obj, None) => {
                    return Err(bad(
                        field("file"),
                        "(missing)".into(),
                        "the OBJ file of an `obj` shape",
                    ));
                }
                (ShapeKind::Obj, Some(_)) | (_, None) => {}
                (_, Some(file)) => {
                    return Err(bad(
                        field("file"),
                        file.clone(),
                        "only with shape `obj` (built-in shapes have no file)",
                    ));
                }
            }
            match (o.shape, o.subdivisions) {
                (ShapeKind::Sphere, Some(s)) if s > 7 => {
                    return Err(bad(
                        field("subdivisions"),
                        s.to_string(),
                        "0 to 7 (7 is 327,680 triangles)",
                    ));
                }
                (ShapeKind::Sphere, _) | (_, None) => {}
                (_, Some(s)) => {
                    return Err(bad(
                        field("subdivisions"),
                        s.to_string(),
                        "only with shape `sphere` (the other shapes are not tessellated)",
                    ));
                }
            }
            o.material.check().map_err(|(name, value, expected)| {
                bad(field(&format!("material.{name}")), value, expected)
            })?;
        }
        for (i, l) in self.lights.iter().enumerate() {
            let field = |name: &str| format!("lights[{i}].{name}");
            bounded3(&field("centre"), &l.centre).map_err(|(f, v)| bad(f, v, BOUNDED))?;
            if unit(l.normal).is_none() {
                return Err(bad(
                    field("normal"),
                    format!("{:?}", l.normal),
                    "a non-zero direction of finite numbers",
                ));
            }
            if !(l.size > 0.0 && l.size <= MAX_LENGTH) {
                return Err(bad(
                    field("size"),
                    SpecValue(l.size).to_string(),
                    &format!("a positive size of at most {MAX_LENGTH:e}"),
                ));
            }
            if l.shape == LightShape::Square && l.sampling.is_some() {
                return Err(bad(
                    field("sampling"),
                    match l.sampling() {
                        LightSampling::Area => "\"area\"",
                        LightSampling::BoundingSquare => "\"bounding_square\"",
                    }
                    .into(),
                    "only for a `disk` light (a square light is its own bounding square)",
                ));
            }
            if !(l.radiance >= 0.0 && l.radiance <= MAX_RADIANCE) {
                return Err(bad(
                    field("radiance"),
                    SpecValue(l.radiance).to_string(),
                    &format!("a radiance from 0 to {MAX_RADIANCE:e}"),
                ));
            }
        }
        if !(self.ambient >= 0.0 && self.ambient <= MAX_RADIANCE) {
            return Err(bad(
                "ambient".into(),
                SpecValue(self.ambient).to_string(),
                &format!("a radiance from 0 to {MAX_RADIANCE:e}"),
            ));
        }
        match self.integrand {
            IntegrandKind::Light if self.lights.is_empty() => Err(bad(
                "integrand".into(),
                "\"light\"".into(),
                "a scene with at least one light (soft shadows sample the first)",
            )),
            IntegrandKind::Light if c.aperture > 0.0 => Err(bad(
                "camera.aperture".into(),
                SpecValue(c.aperture).to_string(),
                "0 for the \"light\" integrand (its (u, v) sample the light, not the lens)",
            )),
            _ => Ok(()),
        }
    }
}

impl MaterialFile {
    fn check(&self) -> Result<(), (&'static str, String, &'static str)> {
        let albedo = |name, v: f64| {
            if (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err((name, SpecValue(v).to_string(), "an albedo in [0, 1]"))
            }
        };
        match *self {
            MaterialFile::Constant { albedo: a } => albedo("albedo", a),
            MaterialFile::Checker { period, low, high }
            | MaterialFile::Stripes { period, low, high } => {
                if !(MIN_PERIOD..=MAX_LENGTH).contains(&period) {
                    return Err((
                        "period",
                        SpecValue(period).to_string(),
                        "a period from 1e-6 to 1e9 (cells are counted exactly only while \
                         coordinate / period stays below 2^53)",
                    ));
                }
                albedo("low", low)?;
                albedo("high", high)
            }
        }
    }
}

/// The largest magnitude of a length or coordinate in a scene: the BVH
/// intersects in f32, whose products of coordinates overflow near 1e19
/// and whose rounding at 1e9 is already 64 units.
pub const MAX_LENGTH: f64 = 1e9;
/// The smallest texture period: a hit point's coordinate in its object's
/// frame (at most about 3e9 once placed vertices are within
/// [`MAX_LENGTH`]) over the period stays below 2^53, so the cell index is
/// an exact integer (a period of 1e-300 used to overflow it).
const MIN_PERIOD: f64 = 1e-6;
/// The largest radiance (lights and ambient): sums of many samples stay
/// far from overflow.
pub const MAX_RADIANCE: f64 = 1e12;

const BOUNDED: &str = "finite numbers of magnitude at most 1e9 (the BVH intersects in f32)";

fn bounded3(field: &str, v: &[f64; 3]) -> Result<(), (String, String)> {
    if v.iter().all(|x| x.abs() <= MAX_LENGTH) {
        Ok(())
    } else {
        Err((field.into(), format!("{v:?}")))
    }
}

/// `v` over its length, or `None` for a zero or non-finite vector. Where
/// the squared length could underflow or overflow (a 1e-200 or 1e200
/// direction) the components are first divided by the largest magnitude.
pub(crate) fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    if v.iter().any(|c| !c.is_finite()) {
        return None;
    }
    let n = norm(v);
    if n > 1e-150 && n < 1e150 {
        return Some(v.map(|c| c / n));
    }
    let big = v.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
    if big == 0.0 {
        return None;
    }
    let w = v.map(|c| c / big);
    let n = norm(w);
    Some(w.map(|c| c / n))
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
