//! Pattern tables for renderers: many realizations of a point set in the
//! formats renderer code reads — CSV, JSON, raw little-endian f32 or f64,
//! and a C header — with metadata (sampler, parameters, seed, version, N,
//! d, predicted variances). Raw and CSV tables carry their metadata in a
//! JSON sidecar (`PATH.json`); JSON and C headers carry it inline.
//!
//! Layout everywhere: set-major, then point, then dimension. f32 values are
//! rounded to nearest and, where that would give 1.0, replaced by the
//! largest f32 below 1, so every entry stays in [0, 1).

use std::io::{self, Write};

use serde::{Deserialize, Serialize};

use super::pointfile::{PointFormat, write_point_sets};
use crate::points::PointSet;

/// Table formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableFormat {
    /// Point-set CSV (`set,x0,...`), metadata in a sidecar.
    Csv,
    /// One JSON object: `metadata` and `sets` (arrays of points).
    Json,
    /// Raw little-endian f32, metadata in a sidecar.
    F32,
    /// Raw little-endian f64, metadata in a sidecar.
    F64,
    /// A C header with a `static const float` array and size macros.
    CHeader,
}

impl TableFormat {
    /// Whether the metadata goes to a `PATH.json` sidecar.
    pub fn needs_sidecar(self) -> bool {
        matches!(self, TableFormat::Csv | TableFormat::F32 | TableFormat::F64)
    }
}

/// What a table holds and where it came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TableMetadata {
    /// Producer and version, e.g. `varspec 0.1.0`.
    pub generator: String,
    /// Sampler name, or the source file.
    pub source: String,
    /// Sampler parameters.
    pub params: Vec<(String, String)>,
    /// Seed of the sampler's sets; `None` (`null`) for a table converted
    /// from a point-set file, whose seed the file does not record.
    pub seed: Option<u64>,
    /// Points per set.
    pub n: usize,
    /// Dimension.
    pub dim: usize,
    /// Sets in the table.
    pub sets: usize,
    /// Layout and value type.
    pub layout: String,
    /// The domain and estimator the sets were designed for: `torus` (the
    /// shift-randomized estimator), `square` (the unshifted estimator on
    /// [0,1)²), `none` (a classic sampler), or `unknown` (a converted file).
    pub optimized_for: String,
    /// Predicted variance (shift-randomized estimator, spatial form, mean
    /// over the table's sets) on reference integrands.
    pub predicted_variance: Vec<(String, f64)>,
    /// What a padded 4D table's dimensions are (dims 0, 1 the (x, y) half,
    /// 2, 3 the (u, v) half, and the samplers of each); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dimensions: Option<String>,
    /// Why `predicted_variance` is empty, when it is (sets that are not
    /// 2D, or a cost over the budget); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub predicted_variance_skipped: Option<String>,
}

/// The largest f32 below 1.
pub const F32_PREV_ONE: f32 = 1.0 - f32::EPSILON / 2.0;

/// x truncated to f32: the largest f32 ≤ x, so a point never moves up
/// across a stratum edge that f32 represents (k/m for m a power of two),
/// and the result stays below 1 (rounding to nearest moved points of
/// [k/m, (k+1)/m) onto (k+1)/m, and 1 − 2⁻⁵³ onto 1).
#[inline]
pub fn to_unit_f32(x: f64) -> f32 {
    let v = x as f32;
    if f64::from(v) > x {
        // v > x ≥ 0: the next f32 down is one unit less in the bits.
        f32::from_bits(v.to_bits() - 1)
    } else {
        v
    }
}

/// Writes `sets` in `format` (the sidecar, if any, is the caller's:
/// [`TableFormat::needs_sidecar`]).
///
/// # Errors
/// The writer's I/O error.
pub fn write_table(
    out: &mut dyn Write,
    sets: &[PointSet],
    meta: &TableMetadata,
    format: TableFormat,
    name: &str,
) -> io::Result<()> {
    match format {
        TableFormat::Csv => write_point_sets(out, sets, PointFormat::Csv),
        TableFormat::F64 => {
            for v in sets.iter().flat_map(|s| s.coords()) {
                out.write_all(&v.to_le_bytes())?;
            }
            Ok(())
        }
        TableFormat::F32 => {
            for v in sets.iter().flat_map(|s| s.coords()) {
                out.write_all(&to_unit_f32(*v).to_le_bytes())?;
            }
            Ok(())
        }
        TableFormat::Json => write_json(out, sets, meta),
        TableFormat::CHeader => write_c_header(out, sets, meta, name),
    }
}

/// The JSON table `{"metadata": {...}, "sets": [[[x0, x1, ...], ...], ...]}`,
/// streamed point by point (building the document first took ~90 bytes of
/// memory per coordinate: 21 GiB for 10⁸ 2D points). The metadata's keys
/// are sorted, as a `serde_json::Value` writes them.
fn write_json(out: &mut dyn Write, sets: &[PointSet], meta: &TableMetadata) -> io::Result<()> {
    let meta = serde_json::to_value(meta).map_err(io::Error::other)?;
    out.write_all(b"{\"metadata\":")?;
    serde_json::to_writer(&mut *out, &meta).map_err(io::Error::other)?;
    out.write_all(b",\"sets\":[")?;
    for (r, set) in sets.iter().enumerate() {
        out.write_all(if r == 0 { b"[" } else { b",[" })?;
        for (i, point) in set.points().enumerate() {
            if i > 0 {
                out.write_all(b",")?;
            }
            serde_json::to_writer(&mut *out, point).map_err(io::Error::other)?;
        }
        out.write_all(b"]")?;
    }
    out.write_all(b"]}")
}

/// C (C23) and C++ keywords, which a table name must not become.
const C_KEYWORDS: [&str; 92] = [
    "alignas",
    "alignof",
    "and",
    "and_eq",
    "asm",
    "auto",
    "bitand",
    "bitor",
    "bool",
    "break",
    "case",
    "catch",
    "char",
    "char8_t",
    "char16_t",
    "char32_t",
    "class",
    "compl",
    "concept",
    "const",
    "consteval",
    "constexpr",
    "constinit",
    "const_cast",
    "continue",
    "co_await",
    "co_return",
    "co_yield",
    "decltype",
    "default",
    "delete",
    "do",
    "double",
    "dynamic_cast",
    "else",
    "enum",
    "explicit",
    "export",
    "extern",
    "false",
    "float",
    "for",
    "friend",
    "goto",
    "if",
    "inline",
    "int",
    "long",
    "mutable",
    "namespace",
    "new",
    "noexcept",
    "not",
    "not_eq",
    "nullptr",
    "operator",
    "or",
    "or_eq",
    "private",
    "protected",
    "public",
    "register",
    "reinterpret_cast",
    "requires",
    "restrict",
    "return",
    "short",
    "signed",
    "sizeof",
    "static",
    "static_assert",
    "static_cast",
    "struct",
    "switch",
    "template",
    "this",
    "thread_local",
    "throw",
    "true",
    "try",
    "typedef",
    "typeid",
    "typename",
    "union",
    "unsigned",
    "using",
    "virtual",
    "void",
    "volatile",
    "wchar_t",
    "while",
    "xor",
];

/// A C identifier from `name`: letters, digits and underscores, not
/// starting with a digit, not a C or C++ keyword, not reserved (a leading
/// underscore): `table_` is put in front where needed.
pub fn c_identifier(name: &str) -> String {
    let mut id: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    if id.is_empty()
        || id.starts_with(|c: char| c.is_ascii_digit() || c == '_')
        || C_KEYWORDS.contains(&id.as_str())
    {
        id.insert_str(0, "table_");
    }
    id
}

fn write_c_header(
    out: &mut dyn Write,
    sets: &[PointSet],
    meta: &TableMetadata,
    name: &str,
) -> io::Result<()> {
    let id = c_identifier(name);
    let upper = id.to_ascii_uppercase();
    writeln!(
        out,
        "/* Generated by {}: {}{}, {} {} of {} points in {}D.",
        meta.generator,
        meta.source,
        meta.seed.map_or(String::new(), |s| format!(" (seed {s})")),
        meta.sets,
        if meta.sets == 1 { "set" } else { "sets" },
        meta.n,
        meta.dim
    )?;
    for (k, v) in &meta.params {
        writeln!(out, " * parameter {k}={v}")?;
    }
    if let Some(dims) = &meta.dimensions {
        writeln!(out, " * {dims}")?;
    }
    for (spec, v) in &meta.predicted_variance {
        writeln!(out, " * predicted variance on {spec}: {v:e}")?;
    }
    if let Some(why) = &meta.predicted_variance_skipped {
        writeln!(out, " * no predicted variances: {why}")?;
    }
    writeln!(
        out,
        " * Values are floats in [0, 1), indexed [set][point][dimension]. */"
    )?;
    writeln!(
        out,
        "#ifndef VARSPEC_{upper}_H\n#define VARSPEC_{upper}_H\n"
    )?;
    writeln!(
        out,
        "#define VARSPEC_{upper}_SETS {}\n#define VARSPEC_{upper}_N {}\n#define VARSPEC_{upper}_DIM {}\n",
        meta.sets, meta.n, meta.dim
    )?;
    writeln!(
        out,
        "static const float {id}[{}][{}][{}] = {{",
        meta.sets, meta.n, meta.dim
    )?;
    for set in sets {
        writeln!(out, "  {{")?;
        for p in set.points() {
            let values: Vec<String> = p.iter().map(|&x| c_float(to_unit_f32(x))).collect();
            writeln!(out, "    {{{}}},", values.join(", "))?;
        }
        writeln!(out, "  }},")?;
    }
    writeln!(out, "}};\n\n#endif")
}

/// A C float literal that parses back to exactly `v` (shortest round-trip
/// decimal, with a decimal point and an `f` suffix).
fn c_float(v: f32) -> String {
    let mut s = format!("{v}");
    if !s.contains('.') {
        s.push_str(".0");
    }
    s.push('f');
    s
}

/// Reads raw little-endian tables back (for round trips and tools).
///
/// # Errors
/// [`io::ErrorKind::InvalidData`] when the byte count does not match.
pub fn read_raw(
    bytes: &[u8],
    format: TableFormat,
    sets: usize,
    n: usize,
    dim: usize,
) -> io::Result<Vec<Vec<f64>>> {
    let width = match format {
        TableFormat::F32 => 4,
        TableFormat::F64 => 8,
        _ => return Err(io::Error::other("only raw f32/f64 tables are read here")),
    };
    if bytes.len() != sets * n * dim * width {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "{} bytes, expected {} x {} x {} x {width}",
                bytes.len(),
                sets,
                n,
                dim
            ),
        ));
    }
    let values: Vec<f64> = bytes
        .chunks_exact(width)
        .map(|c| {
            if width == 4 {
                f32::from_le_bytes(c.try_into().expect("4 bytes")) as f64
            } else {
                f64::from_le_bytes(c.try_into().expect("8 bytes"))
            }
        })
        .collect();
    Ok(values.chunks(n * dim).map(<[f64]>::to_vec).collect())
}

#[cfg(test)]
mod tests {
    use super::c_identifier;

    #[test]
    fn table_names_become_valid_non_keyword_identifiers() {
        assert_eq!(c_identifier("int"), "table_int");
        assert_eq!(c_identifier("Float"), "table_float");
        assert_eq!(c_identifier("class"), "table_class");
        assert_eq!(c_identifier("_x"), "table__x");
        assert_eq!(c_identifier("3d"), "table_3d");
        assert_eq!(c_identifier(""), "table_");
        assert_eq!(c_identifier("cmj-256.h"), "cmj_256_h");
        assert_eq!(c_identifier("integer"), "integer");
    }
}
