//! The triangles of a scene object in model space: a built-in shape's, or
//! a Wavefront OBJ file's, read by the `tobj` crate (polygons triangulated
//! as fans; points and lines ignored; materials ignored: the scene file
//! gives the object's material).

use std::path::Path;

use super::description::{MAX_LENGTH, ObjectFile, SceneError, cross, norm, sub};
use super::geometry::{ModelTriangle, Placement, shape_triangles};
use crate::spec_params::SpecValue;

/// An upper bound on the bytes a mesh takes per byte of its OBJ text: a
/// face line of 8 bytes (`f 1 2 3`) becomes a 72-byte f64 triangle, tobj's
/// 12 bytes of indices, a 48-byte f32 BVH triangle and its share of the
/// BVH's nodes.
const BYTES_PER_OBJ_BYTE: f64 = 32.0;

/// Object `index`'s triangles: its built-in shape's, or its OBJ file's
/// (`file` relative to `folder`).
///
/// # Errors
/// [`SceneError::Field`] on `objects[index].file`: unreadable, too large
/// for memory, malformed, no faces (or only faces of zero area), a
/// position that is not finite or beyond [`MAX_LENGTH`], or a face that
/// refers to a missing vertex; on `objects[index].scale` when the placed
/// vertices reach beyond [`MAX_LENGTH`] (an OBJ's 1e9 times a scale of
/// 1e9), on `objects[index].translate` when only the translation takes
/// them there.
pub fn object_triangles(
    object: &ObjectFile,
    index: usize,
    source_name: &str,
    folder: &Path,
) -> Result<Vec<ModelTriangle>, SceneError> {
    let triangles = match shape_triangles(object.shape, object.subdivisions()) {
        Some(triangles) => triangles,
        None => {
            let file = object.file.clone().unwrap_or_default();
            read_obj(&folder.join(&file)).map_err(|expected| SceneError::Field {
                source_name: source_name.into(),
                field: format!("objects[{index}].file"),
                value: file,
                expected,
            })?
        }
    };
    let place = Placement::of(object);
    // How far the placed vertices reach, and how far they would without
    // the translation: the field to blame is `scale` when the scaled
    // (and rotated) model alone is too large, else `translate`.
    let (reach, unmoved) = triangles.iter().flatten().map(|&p| place.apply(p)).fold(
        (0.0_f64, 0.0_f64),
        |(all, own), w| {
            let moved = (0..3).map(|i| w[i].abs()).fold(0.0, f64::max);
            let kept = (0..3)
                .map(|i| (w[i] - object.translate[i]).abs())
                .fold(0.0, f64::max);
            (all.max(moved), own.max(kept))
        },
    );
    if reach > MAX_LENGTH {
        let (field, value) = if unmoved > MAX_LENGTH {
            ("scale", object.scale)
        } else {
            ("translate", object.translate)
        };
        return Err(SceneError::Field {
            source_name: source_name.into(),
            field: format!("objects[{index}].{field}"),
            value: format!("{value:?}"),
            expected: format!(
                "a placement whose vertices (scale × model + translate) stay within {MAX_LENGTH:e} \
                 of the origin (the BVH intersects in f32); this object reaches {}",
                SpecValue(reach)
            ),
        });
    }
    Ok(triangles)
}

/// The triangles of an OBJ file; the error says what a usable file is and
/// what this one is not.
pub fn read_obj(path: &Path) -> Result<Vec<ModelTriangle>, String> {
    let meta = std::fs::metadata(path)
        .map_err(|e| format!("a readable Wavefront OBJ file ({}: {e})", path.display()))?;
    if !meta.is_file() {
        return Err(format!(
            "a readable Wavefront OBJ file ({} is not a regular file)",
            path.display()
        ));
    }
    let bytes = meta.len();
    crate::memory::check(
        &format!("the mesh {}", path.display()),
        Some(bytes as f64 * BYTES_PER_OBJ_BYTE),
        "use a smaller mesh",
    )
    .map_err(|e| e.to_string())?;
    let options = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let (models, _materials) = tobj::load_obj(path, &options)
        .map_err(|e| format!("a Wavefront OBJ file ({}: {e})", path.display()))?;
    let mut triangles = Vec::new();
    for model in &models {
        let positions = &model.mesh.positions;
        if let Some(bad) = positions
            .iter()
            .find(|v| !v.is_finite() || f64::from(v.abs()) > MAX_LENGTH)
        {
            return Err(format!(
                "finite vertex positions of magnitude at most {MAX_LENGTH:e} (model `{}` has {bad})",
                model.name
            ));
        }
        let vertex = |i: u32| {
            let at = 3 * i as usize;
            positions
                .get(at..at + 3)
                .map(|p| [p[0] as f64, p[1] as f64, p[2] as f64])
                .ok_or_else(|| {
                    format!(
                        "faces that refer to the {} vertices (model `{}` refers to vertex {})",
                        positions.len() / 3,
                        model.name,
                        i as u64 + 1
                    )
                })
        };
        for face in model.mesh.indices.chunks_exact(3) {
            triangles.push([vertex(face[0])?, vertex(face[1])?, vertex(face[2])?]);
        }
    }
    if triangles.is_empty() {
        return Err(format!(
            "a mesh with at least one face ({} has none)",
            path.display()
        ));
    }
    if triangles
        .iter()
        .all(|&[a, b, c]| norm(cross(sub(b, a), sub(c, a))) == 0.0)
    {
        return Err(format!(
            "a mesh with at least one face of non-zero area (all {1} faces of {0} have zero area)",
            path.display(),
            triangles.len()
        ));
    }
    Ok(triangles)
}
