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
    let text = obj_text(path)?;
    let no_materials = |_: &Path| Err(tobj::LoadError::OpenFileFailed);
    let parsed = tobj::load_obj_buf(&mut text.as_bytes(), &options, no_materials);
    let (models, _materials) = parsed.map_err(|e| {
        // tobj's errors do not say where; the line is found again in the text.
        match obj_error_line(&text, &e) {
            Some((number, line)) => format!(
                "a Wavefront OBJ file ({} line {number}: {e}: `{}`)",
                path.display(),
                crate::io::quote(line)
            ),
            None => format!("a Wavefront OBJ file ({}: {e})", path.display()),
        }
    })?;
    let mut triangles = Vec::new();
    for model in &models {
        let positions = &model.mesh.positions;
        let out_of_range = |v: f32| !v.is_finite() || f64::from(v.abs()) > MAX_LENGTH;
        if let Some(bad) = positions.iter().copied().find(|&v| out_of_range(v)) {
            let expected = format!("finite vertex positions of magnitude at most {MAX_LENGTH:e}");
            // The line, where the value stands as written (a `w` divides it).
            let line = text.lines().enumerate().find(|(_, l)| {
                let mut words = l.split_whitespace();
                words.next() == Some("v")
                    && words
                        .take(3)
                        // The value itself, not just any out of range: tobj
                        // keeps only vertices that faces use.
                        .any(|w| {
                            w.parse::<f32>().is_ok_and(|v| {
                                v.to_bits() == bad.to_bits() || (v.is_nan() && bad.is_nan())
                            })
                        })
            });
            return Err(match line {
                Some((number, line)) => format!(
                    "{expected} ({} line {}: `{}`)",
                    path.display(),
                    number + 1,
                    crate::io::quote(line)
                ),
                None => format!("{expected} (model `{}` has {bad})", model.name),
            });
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

/// An OBJ file's text as tobj reads it: UTF-8 (ASCII in practice), a
/// leading byte-order mark dropped (read as part of the first line, it hid
/// that line's `v` and every face index then named the next vertex), and
/// material lines blanked with the numbering kept (surfaces take the scene
/// file's material; a `usemtl` without a name or before a tab fails tobj's
/// parse, and without materials none splits a model). UTF-16 and bytes that
/// are not UTF-8 are refused with their line.
fn obj_text(path: &Path) -> Result<String, String> {
    let bytes = std::fs::read(path)
        .map_err(|e| format!("a readable Wavefront OBJ file ({}: {e})", path.display()))?;
    if bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0xFE, 0xFF]) {
        return Err(format!(
            "a Wavefront OBJ file in UTF-8 or ASCII ({} is UTF-16: save it as UTF-8)",
            path.display()
        ));
    }
    let body = bytes
        .strip_prefix(crate::io::bounded::BOM)
        .unwrap_or(&bytes);
    match std::str::from_utf8(body) {
        Ok(text) => Ok(text
            .lines()
            .map(|line| match line.split_whitespace().next() {
                Some("usemtl" | "mtllib") => "",
                _ => line,
            })
            .collect::<Vec<_>>()
            .join("\n")),
        Err(e) => {
            let line = 1 + body[..e.valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            Err(format!(
                "a Wavefront OBJ file in UTF-8 or ASCII ({} line {line}: bytes that are not UTF-8)",
                path.display()
            ))
        }
    }
}

/// The first line of an OBJ text that tobj's `error` is about (1-based, with
/// its text), for the errors one line causes: a position (`v`), texture
/// coordinate (`vt`) or normal (`vn`) that does not parse, a face (`f`, `l`)
/// that does not, or a face index past the vertices, coordinates or normals.
/// tobj checks a relative index against those before its face, and the
/// others when it closes the face's model (at the next `g` or `o` line after
/// faces, or the end of the file) against those read by then; `usemtl`
/// closes none (its lines are blanked: no materials are read).
/// `None` for other errors, or where the text shows none.
fn obj_error_line<'a>(text: &'a str, error: &tobj::LoadError) -> Option<(usize, &'a str)> {
    use tobj::LoadError as E;
    let floats = |words: &[&str], n: usize| {
        words.len() >= n && words[..n].iter().all(|w| w.parse::<f32>().is_ok())
    };
    // The slots of `v/vt/vn`, each an index or empty; None if it is not one.
    let slots = |word: &str| -> Option<Vec<Option<isize>>> {
        let parts: Vec<&str> = word.split('/').collect();
        // tobj skips empty parts, so only a fourth that holds something
        // fails (`1/1/1/` is read).
        if parts.iter().skip(3).any(|p| !p.is_empty()) {
            return None;
        }
        parts
            .iter()
            .map(|p| {
                (!p.is_empty())
                    .then(|| p.parse::<isize>().ok())
                    .map_or(Some(None), |i| i.map(Some))
            })
            .collect()
    };
    let slot = match error {
        E::FaceVertexOutOfBounds => Some(0),
        E::FaceTexCoordOutOfBounds => Some(1),
        E::FaceNormalOutOfBounds => Some(2),
        _ => None,
    };
    let keys = ["v", "vt", "vn"];
    // Whether a face's index in slot k falls outside the `seen` elements at
    // its model's close, `before` them at the face itself (relative ones).
    // tobj checks the indices of faces of 3 or more vertices only (points
    // and lines are ignored), coordinates and normals only when the file
    // has some by then; a coordinate or normal index 0 reads as missing.
    let out_of_bounds = |words: &[&str], k: usize, before: [usize; 3], seen: [usize; 3]| {
        words.len() >= 3
            && (k == 0 || seen[k] > 0)
            && words.iter().filter_map(|w| slots(w)).any(|s| {
                s.get(k).copied().flatten().is_some_and(|i| {
                    (i == 0 && k == 0)
                        || (i > 0 && i.unsigned_abs() > seen[k])
                        || (i < 0 && i.unsigned_abs() > before[k])
                })
            })
    };
    let mut before = [0usize; 3];
    // The current model's faces: line number, text, words, counts before.
    let mut faces: Vec<(usize, &str, Vec<&str>, [usize; 3])> = Vec::new();
    let close = |faces: &[(usize, &'a str, Vec<&str>, [usize; 3])], seen: [usize; 3]| {
        let k = slot?;
        faces
            .iter()
            .find(|(_, _, words, at)| out_of_bounds(words, k, *at, seen))
            .map(|&(number, line, _, _)| (number, line))
    };
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let key = words.next();
        let words: Vec<&str> = words.collect();
        let bad = match (key, error) {
            (Some("v"), E::PositionParseError) => {
                !floats(&words, 3) || (words.len() == 4 && words[3].parse::<f32>().is_err())
            }
            (Some("v"), E::ScalingByZeroError) => {
                words.len() == 4 && words[3].parse::<f32>() == Ok(0.0)
            }
            (Some("v"), E::ColorParseError) => words.len() == 5 || words.len() > 6,
            (Some("vt"), E::TexcoordParseError) => !floats(&words, 2),
            (Some("vn"), E::NormalParseError) => !floats(&words, 3),
            (Some("f" | "l"), E::FaceParseError) => words.iter().any(|w| slots(w).is_none()),
            _ => false,
        };
        if bad {
            return Some((number + 1, line));
        }
        match key {
            Some("f" | "l") => faces.push((number + 1, line, words, before)),
            Some("g" | "o") if !faces.is_empty() => {
                if let Some(found) = close(&faces, before) {
                    return Some(found);
                }
                faces.clear();
            }
            _ => {}
        }
        if let Some(k) = keys.iter().position(|&k| Some(k) == key) {
            before[k] += 1;
        }
    }
    close(&faces, before)
}
