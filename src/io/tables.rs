//! Pattern tables for renderers: many realizations of a point set in the
//! formats renderer code reads — CSV, JSON, raw little-endian f32 or f64,
//! and a C header — with metadata (sampler, parameters, seed, version, N,
//! d, predicted variances). Raw and CSV tables carry their metadata in a
//! JSON sidecar (`PATH.json`); JSON and C headers carry it inline.
//!
//! Layout everywhere: set-major, then point, then dimension. f32 values are
//! rounded to nearest and, where that would give 1.0, replaced by the
//! largest f32 below 1, so every entry stays in [0, 1).

use std::fmt;
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};

use serde::de::{DeserializeSeed, Error as _, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};

use super::bounded::read_text_bounded;
use super::json::from_json;
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

    /// The value type the metadata's `layout` names (docs/formats.md);
    /// the raw formats' say their byte order.
    pub fn value_type(self) -> &'static str {
        match self {
            TableFormat::F32 => "f32 (float), little-endian",
            TableFormat::CHeader => "f32 (float)",
            TableFormat::F64 => "f64 (double), little-endian",
            TableFormat::Csv | TableFormat::Json => "f64 as shortest round-trip decimal text",
        }
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
    /// A digest of the values the table stores ([`values_digest`]), so a
    /// sidecar left beside a file that was overwritten since (same shape,
    /// other points) is not taken as its provenance; absent in tables
    /// written before it existed, which are matched by shape alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub values_digest: Option<String>,
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
    // The lines for people, as one text that cannot end the comment early
    // (a source path such as `a*/p.csv` did).
    // A field's line breaks become spaces, so no field starts a line.
    let one_line = |text: &str| text.replace(['\n', '\r'], " ");
    let mut people = format!(
        "/* Generated by {}: {}{}, {} {} of {} points in {}D.\n",
        one_line(&meta.generator),
        one_line(&meta.source),
        meta.seed.map_or(String::new(), |s| format!(" (seed {s})")),
        meta.sets,
        if meta.sets == 1 { "set" } else { "sets" },
        meta.n,
        meta.dim
    );
    for (k, v) in &meta.params {
        people += &format!(" * parameter {}={}\n", one_line(k), one_line(v));
    }
    if let Some(dims) = &meta.dimensions {
        people += &format!(" * {}\n", one_line(dims));
    }
    for (spec, v) in &meta.predicted_variance {
        people += &format!(" * predicted variance on {}: {v:e}\n", one_line(spec));
    }
    if let Some(why) = &meta.predicted_variance_skipped {
        people += &format!(" * no predicted variances: {}\n", one_line(why));
    }
    writeln!(out, "{}", people.trim_end().replace("*/", "* /"))?;
    // JSON has `*/` only inside strings, where `\/` is the same `/`.
    let json = serde_json::to_string(meta).map_err(io::Error::other)?;
    writeln!(out, "{C_METADATA}{}", json.replace("*/", "*\\/"))?;
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
        "{C_ARRAY} {id}[{}][{}][{}] = {{",
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

/// The file holding a raw or CSV table's metadata: `PATH.json`.
pub fn sidecar_path(table: &Path) -> PathBuf {
    let mut path = table.as_os_str().to_owned();
    path.push(".json");
    PathBuf::from(path)
}

/// The metadata sidecar of `table`: `None` when there is no `PATH.json`
/// (or it cannot be opened), `Some(Err)` saying why one that exists is not a
/// table's metadata.
pub fn read_sidecar(table: &Path) -> Option<Result<TableMetadata, String>> {
    let path = sidecar_path(table);
    if !path.is_file() {
        return None;
    }
    let text = match read_text_bounded(&path, SIDECAR_LIMIT, "a table's metadata") {
        Ok(text) => text,
        Err(e) => return Some(Err(format!("{}: {e}", path.display()))),
    };
    Some(from_json(&text).map_err(|e| format!("{}: {e}", path.display())))
}

/// The largest sidecar read: 1 MiB (one is a few hundred bytes).
const SIDECAR_LIMIT: u64 = 1 << 20;

/// The raw format (`F32` or `F64`) a table's `layout` names, if any.
pub fn raw_format(meta: &TableMetadata) -> Option<TableFormat> {
    [TableFormat::F32, TableFormat::F64]
        .into_iter()
        .find(|f| meta.layout.contains(f.value_type()))
}

/// Reads a raw little-endian table (`format` `F32` or `F64`) of the shape
/// `meta` gives, one set at a time (the file's bytes are never all held
/// beside the values). `len` is the file's length in bytes, checked
/// against the shape before anything is allocated.
///
/// # Errors
/// A sentence: a shape that is empty or overflows, a length that does not
/// match it, a read error, or a value outside [0, 1) (with its index).
pub fn read_raw(
    mut reader: impl Read,
    len: u64,
    format: TableFormat,
    meta: &TableMetadata,
) -> Result<Vec<PointSet>, String> {
    let width: usize = match format {
        TableFormat::F32 => 4,
        TableFormat::F64 => 8,
        _ => return Err("only raw f32 and f64 tables are read here".into()),
    };
    let (sets, n, dim) = (meta.sets, meta.n, meta.dim);
    if sets == 0 || n == 0 || dim == 0 {
        return Err(format!(
            "its metadata says {sets} sets of {n} points in {dim}D: a table holds at least one point"
        ));
    }
    let per_set = n.checked_mul(dim);
    let expected = per_set
        .and_then(|c| c.checked_mul(sets))
        .and_then(|c| c.checked_mul(width))
        .map(|c| c as u64);
    if expected != Some(len) {
        return Err(format!(
            "{len} bytes, where its metadata's {sets} sets x {n} points x {dim} dimensions x \
             {width} bytes need {}",
            expected.map_or("more than 2^64".into(), |e| e.to_string())
        ));
    }
    let per_set = per_set.expect("checked above");
    let mut bytes = vec![0; per_set * width];
    (0..sets)
        .map(|s| {
            reader
                .read_exact(&mut bytes)
                .map_err(|e| format!("set {s}: {e}"))?;
            let coords = bytes
                .chunks_exact(width)
                .map(|c| {
                    if width == 4 {
                        f64::from(f32::from_le_bytes(c.try_into().expect("4 bytes")))
                    } else {
                        f64::from_le_bytes(c.try_into().expect("8 bytes"))
                    }
                })
                .collect();
            PointSet::new(dim, coords).map_err(|e| format!("set {s}: {e}"))
        })
        .collect()
}

/// Reads a JSON table (`{"metadata": {...}, "sets": [...]}`) and checks
/// its sets against its metadata. A hand-written file may leave the
/// metadata out.
///
/// # Errors
/// A sentence: serde_json's (with line and column), a set of another size
/// or dimension than the others or the metadata say, a value outside
/// [0, 1), or a table's sidecar given in place of the table.
pub fn read_json_table(
    reader: impl Read,
) -> Result<(Vec<PointSet>, Option<TableMetadata>), String> {
    let table: JsonTable =
        serde_json::from_reader(reader).map_err(|e| format!("not a readable JSON table: {e}"))?;
    let Some(JsonSets(sets)) = table.sets else {
        return Err("a JSON table has `sets`: [[[x0, x1, ...], ...], ...] (and `metadata`)".into());
    };
    let Some(first) = sets.first() else {
        return Err("its `sets` is empty".into());
    };
    if let Some(meta) = &table.metadata
        && !has_shape_of(meta, &sets)
    {
        return Err(format!(
            "it holds {} sets of {} points in {}D, its metadata says {} of {} in {}D",
            sets.len(),
            first.len(),
            first.dim(),
            meta.sets,
            meta.n,
            meta.dim
        ));
    }
    // Values edited since the metadata was written are told by the
    // caller ([`describes`]).
    Ok((sets, table.metadata))
}

/// Whether `meta` has the shape of `sets` (its N, d and count).
fn has_shape_of(meta: &TableMetadata, sets: &[PointSet]) -> bool {
    sets.len() == meta.sets
        && sets
            .iter()
            .all(|s| s.len() == meta.n && s.dim() == meta.dim)
}

/// Whether `meta` describes `sets`: their shape, and their values when it
/// records a [`values_digest`].
pub fn describes(meta: &TableMetadata, sets: &[PointSet]) -> bool {
    has_shape_of(meta, sets)
        && meta
            .values_digest
            .as_ref()
            .is_none_or(|d| *d == values_digest(sets.iter().flat_map(|s| s.coords()).copied()))
}

/// The digest of a table's values: FNV-1a (64-bit) over the bytes of each
/// value's IEEE-754 binary64 bit pattern, little-endian, in
/// [set][point][dimension] order (an f32 table's values widened to
/// binary64 exactly), written `fnv1a64:` and 16 hex digits. It tells a
/// table's own metadata from a stale one; it is not a cryptographic hash.
pub fn values_digest(values: impl Iterator<Item = f64>) -> String {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let mut h = OFFSET;
    for byte in values.flat_map(|x| x.to_bits().to_le_bytes()) {
        h = (h ^ u64::from(byte)).wrapping_mul(PRIME);
    }
    format!("fnv1a64:{h:016x}")
}

/// The top level of a JSON table.
#[derive(Deserialize)]
struct JsonTable {
    metadata: Option<TableMetadata>,
    sets: Option<JsonSets>,
}

/// A JSON table's `sets`, each read straight into one point-major vector
/// (a vector per point would take three to four times the memory).
struct JsonSets(Vec<PointSet>);

impl<'de> Deserialize<'de> for JsonSets {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(SetsVisitor).map(JsonSets)
    }
}

struct SetsVisitor;

impl<'de> Visitor<'de> for SetsVisitor {
    type Value = Vec<PointSet>;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("an array of sets, each an array of points")
    }

    /// `sets` a count: the metadata of a raw or CSV table, given in place
    /// of the table.
    fn visit_u64<E: serde::de::Error>(self, _: u64) -> Result<Self::Value, E> {
        Err(E::custom(
            "`sets` is a count: this is a table's metadata sidecar, which holds no points; give \
             the table it describes (the same name without `.json`)",
        ))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut sets: Vec<PointSet> = Vec::new();
        let mut shape = None;
        while let Some((dim, coords)) = seq.next_element_seed(SetSeed {
            set: sets.len(),
            dim: shape.map(|(_, d)| d),
        })? {
            let s = sets.len();
            let n = coords.len() / dim;
            match shape {
                None => shape = Some((n, dim)),
                Some((n0, _)) if n != n0 => {
                    return Err(A::Error::custom(format!(
                        "set {s} holds {n} points, set 0 holds {n0}"
                    )));
                }
                Some(_) => {}
            }
            sets.push(
                PointSet::new(dim, coords)
                    .map_err(|e| A::Error::custom(format!("set {s}: {e}")))?,
            );
        }
        Ok(sets)
    }
}

/// One set: its dimension (that of its first point, or `dim` when the
/// sets before fixed it) and its coordinates.
struct SetSeed {
    set: usize,
    dim: Option<usize>,
}

impl<'de> DeserializeSeed<'de> for SetSeed {
    type Value = (usize, Vec<f64>);

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for SetSeed {
    type Value = (usize, Vec<f64>);

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "set {}: an array of points", self.set)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut coords = Vec::new();
        let mut dim = self.dim;
        let mut point = 0;
        while let Some(found) = seq.next_element_seed(PointSeed(&mut coords))? {
            match dim {
                None if found > 0 => dim = Some(found),
                Some(d) if d == found => {}
                _ => {
                    let coordinates = if found == 1 {
                        "coordinate"
                    } else {
                        "coordinates"
                    };
                    return Err(A::Error::custom(format!(
                        "set {}, point {point} has {found} {coordinates}, where {}",
                        self.set,
                        dim.map_or("a point has at least one".into(), |d| format!(
                            "the first has {d}"
                        ))
                    )));
                }
            }
            point += 1;
        }
        match dim {
            Some(d) if point > 0 => Ok((d, coords)),
            _ => Err(A::Error::custom(format!(
                "set {} holds no points",
                self.set
            ))),
        }
    }
}

/// One point, appended to the set's coordinates; its value is the count of
/// coordinates it had.
struct PointSeed<'a>(&'a mut Vec<f64>);

impl<'de> DeserializeSeed<'de> for PointSeed<'_> {
    type Value = usize;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for PointSeed<'_> {
    type Value = usize;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a point: an array of numbers")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<usize, A::Error> {
        let mut count = 0;
        while let Some(v) = seq.next_element::<f64>()? {
            self.0.push(v);
            count += 1;
        }
        Ok(count)
    }
}

/// The declaration of a C header table's array, written and read back.
const C_ARRAY: &str = "static const float";

/// The first words of a C header table.
pub const C_HEADER_START: &str = "/* Generated by varspec";

/// The comment line of a C header table that holds its metadata as JSON,
/// for tools (the lines above it say the same for people).
const C_METADATA: &str = " * metadata (JSON): ";

/// The metadata a C header table's comment records ([`C_METADATA`]), if
/// its comment has the line and the line parses (a header written before
/// the line existed, or edited by hand, has none: its provenance is
/// unknown, as a point file's).
pub fn read_c_header_metadata(text: &str) -> Option<TableMetadata> {
    let comment = text.split("*/").next()?;
    // The last such line: the tool's, written after the lines for people.
    let line = comment
        .lines()
        .filter_map(|l| l.strip_prefix(C_METADATA))
        .next_back()?;
    serde_json::from_str(line).ok()
}

/// Reads a C header table back: the array `static const float
/// NAME[SETS][N][DIM] = { ... };` its values exactly as the floats they
/// declare (any layout of braces, commas and white space).
///
/// # Errors
/// A sentence: no such array, a shape that is empty or overflows, a token
/// that is not a float literal, a count of values other than the shape's,
/// or a value outside [0, 1).
pub fn read_c_header(text: &str) -> Result<Vec<PointSet>, String> {
    let missing = || format!("no `{C_ARRAY} NAME[SETS][N][DIM] = {{ ... }};` array");
    let start = text.find(C_ARRAY).ok_or_else(missing)?;
    let (head, body) = text[start..].split_once('=').ok_or_else(missing)?;
    let shape: Vec<&str> = head
        .split('[')
        .skip(1)
        .map(|p| p.split(']').next().unwrap_or_default().trim())
        .collect();
    let shape: Vec<usize> = match shape[..] {
        [_, _, _] => shape
            .iter()
            .map(|t| t.parse::<usize>().ok().filter(|&v| v > 0))
            .collect::<Option<_>>()
            .ok_or_else(|| {
                format!(
                    "array shape [{}] is not three positive counts",
                    shape.join("][")
                )
            })?,
        _ => {
            return Err(format!(
                "the array has {} dimensions, a table's has 3 [SETS][N][DIM]",
                shape.len()
            ));
        }
    };
    let (sets, n, dim) = (shape[0], shape[1], shape[2]);
    let body = body.split("};").next().unwrap_or_default();
    let mut values = Vec::new();
    for token in body
        .split(|c: char| c == '{' || c == '}' || c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
    {
        let v: f32 = token
            .strip_suffix(['f', 'F'])
            .unwrap_or(token)
            .parse()
            .map_err(|_| format!("`{token}` in the array is not a float literal"))?;
        values.push(f64::from(v));
    }
    let expected = sets.checked_mul(n).and_then(|c| c.checked_mul(dim));
    if expected != Some(values.len()) {
        return Err(format!(
            "the array [{sets}][{n}][{dim}] holds {} values",
            values.len()
        ));
    }
    values
        .chunks_exact(n * dim)
        .enumerate()
        .map(|(s, c)| PointSet::new(dim, c.to_vec()).map_err(|e| format!("set {s}: {e}")))
        .collect()
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
