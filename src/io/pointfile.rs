//! Point-set files (docs/formats.md).
//!
//! * **CSV** — a header `x0,x1,…,x{d−1}` (read also as the axes' names
//!   other tools write: `x,y`, `x,y,z`, `x,y,u,v`, `x,y,z,w`), optionally
//!   preceded by a `set` column that numbers realizations 0, 1, 2, … in
//!   order; one point per row; f64 written with round-trip precision.
//! * **UTK text** — the Uni(corn|form) toolkit's format (Perrier, Coeurjolly &
//!   Ostromoukhov): whitespace-separated coordinates, one point per line, a
//!   line starting with `#` between point sets.
//!
//! * **Pattern tables** of `varspec tables` (super::tables): JSON, C
//!   headers, and raw f32/f64 read through their metadata sidecar.
//!
//! Readers detect the format from the first non-blank line (a CSV header
//! starts with a letter, a JSON table with `{`, a C header table with
//! [`tables::C_HEADER_START`]), from the `.npy` magic, or from a sidecar
//! `PATH.json` whose layout names raw f32 or f64. Values must be finite and
//! in [0, 1); exactly 1.0 is rejected (on the torus it is 0: write 0);
//! `-0.0` reads as 0.

use std::fmt;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};

use super::bounded::BOM;
use super::csv_rows::csv_io_error;
use super::npy;
use super::quote;
use super::tables::{self, TableMetadata};
use crate::points::PointSet;

/// What is wrong with a point-set file, and where.
#[derive(Debug, thiserror::Error)]
pub enum PointFileError {
    /// The file could not be opened or read.
    #[error("{path}: {cause}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error (in the message, not repeated as a source).
        cause: io::Error,
    },
    /// No points at all.
    #[error("{path}: the file holds no points")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// A malformed line.
    #[error("{path}:{line}: {problem}")]
    Line {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong on it.
        problem: LineProblem,
    },
    /// A NumPy `.npy` file that is not a point-set array.
    #[error("{path}: {problem}")]
    Npy {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
    /// A pattern table (`varspec tables`) that cannot be read back.
    #[error("{path}: {problem}")]
    Table {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
    /// The points have another dimension than the caller needs.
    #[error("{path}: points are {found}-dimensional, {expected} dimensions are needed")]
    WrongDimension {
        /// The file.
        path: PathBuf,
        /// Needed dimension.
        expected: usize,
        /// Dimension in the file.
        found: usize,
    },
}

/// The defect on one line of a point-set file.
#[derive(Debug, Clone, PartialEq)]
pub enum LineProblem {
    /// The CSV header is not `[set,]x0,x1,…`.
    Header {
        /// The header found.
        found: String,
    },
    /// A field that is not a number.
    NotANumber {
        /// 1-based field.
        field: usize,
        /// Its text.
        text: String,
    },
    /// NaN or infinity.
    NotFinite {
        /// 1-based field.
        field: usize,
        /// Its text.
        text: String,
    },
    /// A value outside [0, 1).
    OutOfRange {
        /// 1-based field.
        field: usize,
        /// The value.
        value: f64,
        /// Its text (quoted as written: `-1e-300` is not 300 digits).
        text: String,
    },
    /// A row with the wrong number of fields.
    Ragged {
        /// Fields expected.
        expected: usize,
        /// Fields found.
        found: usize,
    },
    /// Bytes that are not UTF-8 text.
    NotUtf8,
    /// A `set` value that does not continue 0, 1, 2, ….
    SetNumber {
        /// The set being read.
        current: Option<u64>,
        /// Its text.
        text: String,
    },
}

impl fmt::Display for LineProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LineProblem::Header { found } => write!(
                f,
                "CSV header must be `x0,x1,...` (or `x,y`, `x,y,z`, `x,y,u,v`, `x,y,z,w`), \
                 optionally after `set,`, found `{found}`"
            ),
            // A CSV row splits at commas, so a comma inside a field means
            // the file was read as UTK text: its first line began with `#`.
            LineProblem::NotANumber { field, text } if text.contains(',') => write!(
                f,
                "field {field} is `{text}`, not a number: the file is read as UTK text \
                 (whitespace-separated) because its first line starts with `#`; a CSV's header \
                 is a plain `x0,x1` line (numpy's savetxt writes `# x0,x1` unless given \
                 comments='')"
            ),
            LineProblem::NotANumber { field, text } => {
                write!(f, "field {field} is `{text}`, not a number")
            }
            LineProblem::NotFinite { field, text } => {
                write!(f, "field {field} is `{text}`, not a finite number")
            }
            LineProblem::OutOfRange { field, value, text } if *value == 1.0 => {
                // 0.99999999999999995 (or .99999999999999995, or
                // 9.9999999999999999e-1) reads as the double 1.
                let rounds = if decimal_is_one(text) {
                    "1,".to_string()
                } else {
                    format!("`{text}`, which rounds to the double 1,")
                };
                write!(
                    f,
                    "field {field} is {rounds} outside [0, 1) (on the torus 1 is the same point \
                     as 0: write 0; the largest double below 1 is 0.9999999999999999)"
                )
            }
            LineProblem::OutOfRange { field, text, .. } => {
                write!(f, "field {field} is `{text}`, outside [0, 1)")
            }
            LineProblem::Ragged { expected, found } => {
                let fields = if *found == 1 { "field" } else { "fields" };
                write!(f, "{found} {fields} where every row has {expected}")
            }
            LineProblem::NotUtf8 => write!(
                f,
                "not UTF-8 text (is this a point-set file? a raw f32 or f64 table is read through \
                 its metadata sidecar, the file name with `.json` appended, beside it)"
            ),
            LineProblem::SetNumber {
                current: None,
                text,
            } => {
                write!(f, "the `set` column must start at 0, found `{text}`")
            }
            LineProblem::SetNumber {
                current: Some(c),
                text,
            } => write!(
                f,
                "the `set` column must continue with {c} or {}, found `{text}`",
                c + 1
            ),
        }
    }
}

/// A point-set file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointFormat {
    /// CSV with a `[set,]x0,…` header.
    Csv,
    /// UTK's whitespace text with `#` between sets.
    Utk,
}

/// Reads every point set in `path` (CSV, UTK text, NumPy `.npy`, or a
/// pattern table of `varspec tables`: JSON, a C header, or raw f32/f64
/// described by its sidecar `PATH.json`), detected from the content and the
/// sidecar.
///
/// # Errors
/// [`PointFileError`] naming the file and, for malformed content, the line.
pub fn read_point_sets(path: &Path) -> Result<Vec<PointSet>, PointFileError> {
    read_point_sets_with_metadata(path).map(|(sets, _)| sets)
}

/// The metadata of a varspec table found with a point-set file: a JSON
/// table's own, a C header's `metadata (JSON)` comment line, or a sidecar
/// `PATH.json`.
#[derive(Debug, Default)]
pub struct FoundMetadata {
    /// Metadata that describes the sets read ([`tables::describes`]: the
    /// same N, d and count, and the values' digest where it records one).
    pub describing: Option<TableMetadata>,
    /// Where metadata was found that does not describe them (values edited
    /// or written over since, or a sidecar that cannot be read), to say
    /// that it is not carried.
    pub stale: Option<String>,
}

impl FoundMetadata {
    /// `meta`, found at `place`, sorted by whether it describes `sets`.
    fn sorted(meta: Option<TableMetadata>, place: String, sets: &[PointSet]) -> Self {
        match meta {
            Some(m) if tables::describes(&m, sets) => FoundMetadata {
                describing: Some(m),
                stale: None,
            },
            Some(_) => FoundMetadata {
                describing: None,
                stale: Some(place),
            },
            None => FoundMetadata::default(),
        }
    }
}

/// As [`read_point_sets`], with the table metadata found with the file
/// ([`FoundMetadata`]; none for other files).
///
/// # Errors
/// As [`read_point_sets`].
pub fn read_point_sets_with_metadata(
    path: &Path,
) -> Result<(Vec<PointSet>, FoundMetadata), PointFileError> {
    let io = |cause| PointFileError::Io {
        path: path.into(),
        cause,
    };
    let file = File::open(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    let mut reader = BufReader::new(file);
    let table = |problem| PointFileError::Table {
        path: path.into(),
        problem,
    };
    let sidecar = tables::read_sidecar(path);
    if let Some(Ok(meta)) = &sidecar
        && let Some(raw) = tables::raw_format(meta)
    {
        // Read by the sidecar's shape; its provenance only if its values
        // are these.
        return tables::read_raw(reader, len, raw, meta)
            .map(|sets| {
                let found = FoundMetadata::sorted(Some(meta.clone()), sidecar_place(path), &sets);
                (sets, found)
            })
            .map_err(table);
    }
    let head = reader.fill_buf().map_err(io)?;
    let described = |sets: Vec<PointSet>| {
        let found = match &sidecar {
            Some(Ok(meta)) => FoundMetadata::sorted(Some(meta.clone()), sidecar_place(path), &sets),
            Some(Err(_)) => FoundMetadata {
                describing: None,
                stale: Some(sidecar_place(path)),
            },
            None => FoundMetadata::default(),
        };
        (sets, found)
    };
    if head.starts_with(npy::MAGIC) {
        return npy::read_point_sets_npy(reader)
            .map(described)
            .map_err(|problem| PointFileError::Npy {
                path: path.into(),
                problem,
            });
    }
    let bom = head.starts_with(BOM);
    let text = head.strip_prefix(BOM).unwrap_or(head).trim_ascii_start();
    let (json, c_header) = (
        text.starts_with(b"{"),
        text.starts_with(tables::C_HEADER_START.as_bytes()),
    );
    if json || c_header {
        if bom {
            reader.consume(BOM.len());
        }
        if json {
            return tables::read_json_table(reader)
                .map(|(sets, meta)| {
                    let found = FoundMetadata::sorted(meta, "the `metadata` field".into(), &sets);
                    (sets, found)
                })
                .map_err(table);
        }
        let mut text = String::new();
        reader.read_to_string(&mut text).map_err(io)?;
        return tables::read_c_header(&text)
            .map(|sets| {
                let meta = tables::read_c_header_metadata(&text);
                let found = FoundMetadata::sorted(meta, "the `metadata (JSON)` line".into(), &sets);
                (sets, found)
            })
            .map_err(table);
    }
    let sets = parse_point_sets(reader, path).map_err(|e| match (e, &sidecar) {
        // Bytes that are not text beside a sidecar that is not a raw
        // table's metadata: say what is wrong with the sidecar.
        (
            PointFileError::Line {
                problem: LineProblem::NotUtf8,
                ..
            },
            Some(Err(why)),
        ) => table(format!(
            "not UTF-8 text, and not a raw table: its sidecar is unreadable ({why})"
        )),
        (e, _) => e,
    })?;
    Ok(described(sets))
}

/// How a note names `path`'s sidecar.
fn sidecar_place(path: &Path) -> String {
    format!("the sidecar {}", tables::sidecar_path(path).display())
}

/// Reads `path` and checks that its points have dimension `dim`.
///
/// # Errors
/// As [`read_point_sets`], plus [`PointFileError::WrongDimension`].
pub fn read_point_sets_of_dim(path: &Path, dim: usize) -> Result<Vec<PointSet>, PointFileError> {
    let sets = read_point_sets(path)?;
    match sets[0].dim() {
        d if d == dim => Ok(sets),
        found => Err(PointFileError::WrongDimension {
            path: path.into(),
            expected: dim,
            found,
        }),
    }
}

/// The longest line a point-set file may have: 1 MiB, far above any row of
/// coordinates (a 64-dimensional row of round-trip f64 is about 1.5 kB).
pub const MAX_LINE: usize = 1 << 20;

/// Parses point sets from `reader`; `path` names the source in errors.
///
/// The format is detected from the first non-blank line. CSV goes through
/// the `csv` crate (quoting, CRLF and trimming as its RFC 4180 reader does);
/// UTK text is not CSV (whitespace-separated, `#` separators) and keeps its
/// own line reader. A UTF-8 byte-order mark at the start is skipped. No line
/// may exceed [`MAX_LINE`] bytes (a device such as /dev/zero is refused
/// instead of read into memory), and a bad header is quoted by a short,
/// escaped prefix.
///
/// # Errors
/// As [`read_point_sets`].
pub fn parse_point_sets<R: BufRead>(
    reader: R,
    path: &Path,
) -> Result<Vec<PointSet>, PointFileError> {
    let mut parser = Parser {
        path,
        sets: Vec::new(),
        current: Vec::new(),
        dim: 0,
        set_column: false,
        set_id: None,
        format: None,
    };
    let io = |cause: io::Error| PointFileError::Io {
        path: path.into(),
        cause,
    };
    let at = |line: usize| {
        move |problem| PointFileError::Line {
            path: path.into(),
            line,
            problem,
        }
    };
    let mut reader = BufReader::new(LineLimit {
        inner: reader,
        column: 0,
        line: 1,
    });
    // The first non-blank line decides the format.
    let mut first = String::new();
    let mut line = 0;
    loop {
        first.clear();
        let read = reader.read_line(&mut first).map_err(|e| {
            if is_not_utf8(&e) {
                at(line + 1)(LineProblem::NotUtf8)
            } else {
                io(e)
            }
        })?;
        if read == 0 {
            return parser.finish();
        }
        line += 1;
        if line == 1 && first.starts_with('\u{feff}') {
            first.drain(..'\u{feff}'.len_utf8());
        }
        if !first.trim().is_empty() {
            break;
        }
    }
    let text = first.trim();
    if is_csv_header(text) {
        parser.csv_header(text).map_err(at(line))?;
        let mut csv = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(csv::Trim::All)
            .from_reader(reader);
        let mut record = csv::StringRecord::new();
        loop {
            let more = csv.read_record(&mut record).map_err(|e| match e.kind() {
                csv::ErrorKind::Utf8 { pos, .. } => PointFileError::Line {
                    path: path.into(),
                    line: line + pos.as_ref().map_or(1, |p| p.line() as usize),
                    problem: LineProblem::NotUtf8,
                },
                _ => io(csv_io_error(e)),
            })?;
            if !more {
                break;
            }
            let row = line + record.position().map_or(0, |p| p.line() as usize);
            if record.len() == 1 && record[0].is_empty() {
                continue;
            }
            let fields: Vec<&str> = record.iter().collect();
            parser.csv_fields(&fields).map_err(at(row))?;
        }
        return parser.finish();
    }
    parser.line(text).map_err(at(line))?;
    for next in reader.lines() {
        line += 1;
        let next = next.map_err(|e| {
            if is_not_utf8(&e) {
                at(line)(LineProblem::NotUtf8)
            } else {
                io(e)
            }
        })?;
        parser.line(next.trim_end_matches('\r')).map_err(at(line))?;
    }
    parser.finish()
}

/// True for the error of `read_line` on bytes that are not UTF-8: std's bare
/// `InvalidData` (the long-line refusal below carries its own message).
fn is_not_utf8(e: &io::Error) -> bool {
    e.kind() == io::ErrorKind::InvalidData && e.get_ref().is_none()
}

/// A reader that refuses lines longer than [`MAX_LINE`] bytes.
struct LineLimit<R> {
    inner: R,
    column: usize,
    line: usize,
}

impl<R: io::Read> io::Read for LineLimit<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        for &b in &buf[..n] {
            if b == b'\n' {
                self.column = 0;
                self.line += 1;
            } else {
                self.column += 1;
                if self.column > MAX_LINE {
                    return Err(io::Error::new(
                        io::ErrorKind::InvalidData,
                        format!(
                            "line {} is longer than {MAX_LINE} bytes: not a point-set file",
                            self.line
                        ),
                    ));
                }
            }
        }
        Ok(n)
    }
}

struct Parser<'a> {
    path: &'a Path,
    sets: Vec<PointSet>,
    current: Vec<f64>,
    dim: usize,
    set_column: bool,
    set_id: Option<u64>,
    format: Option<PointFormat>,
}

impl Parser<'_> {
    fn line(&mut self, line: &str) -> Result<(), LineProblem> {
        let text = line.trim();
        if text.is_empty() {
            return Ok(());
        }
        match self.format {
            None if text.starts_with('#') => {
                self.format = Some(PointFormat::Utk);
                Ok(())
            }
            None if text.contains(',') => Err(LineProblem::Header { found: quote(text) }),
            None => {
                self.format = Some(PointFormat::Utk);
                self.utk_row(text)
            }
            Some(PointFormat::Csv) => unreachable!("CSV rows go through the csv reader"),
            Some(PointFormat::Utk) if text.starts_with('#') => {
                self.close_set();
                Ok(())
            }
            Some(PointFormat::Utk) => self.utk_row(text),
        }
    }

    fn csv_header(&mut self, text: &str) -> Result<(), LineProblem> {
        let names: Vec<&str> = text.split(',').map(str::trim).collect();
        self.set_column = names[0] == "set";
        let coords = &names[usize::from(self.set_column)..];
        // The axes' names of 2D, 3D, light-field and 4D sets.
        const NAMED: [&[&str]; 4] = [
            &["x", "y"],
            &["x", "y", "z"],
            &["x", "y", "u", "v"],
            &["x", "y", "z", "w"],
        ];
        let numbered = coords
            .iter()
            .enumerate()
            .all(|(j, n)| *n == format!("x{j}"));
        let ok = !coords.is_empty() && (numbered || NAMED.contains(&coords));
        if !ok {
            return Err(LineProblem::Header { found: quote(text) });
        }
        self.dim = coords.len();
        self.format = Some(PointFormat::Csv);
        Ok(())
    }

    fn csv_fields(&mut self, fields: &[&str]) -> Result<(), LineProblem> {
        let expected = self.dim + usize::from(self.set_column);
        if fields.len() != expected {
            return Err(LineProblem::Ragged {
                expected,
                found: fields.len(),
            });
        }
        let coords = if self.set_column {
            self.set_number(fields[0])?;
            &fields[1..]
        } else {
            fields
        };
        let offset = usize::from(self.set_column);
        for (j, f) in coords.iter().enumerate() {
            self.current.push(coordinate(f, j + 1 + offset)?);
        }
        Ok(())
    }

    fn set_number(&mut self, text: &str) -> Result<(), LineProblem> {
        let problem = || LineProblem::SetNumber {
            current: self.set_id,
            text: quote(text),
        };
        let id: u64 = text.parse().map_err(|_| problem())?;
        match self.set_id {
            None if id == 0 => self.set_id = Some(0),
            Some(c) if id == c => {}
            Some(c) if id == c + 1 => {
                self.close_set();
                self.set_id = Some(id);
            }
            _ => return Err(problem()),
        }
        Ok(())
    }

    fn utk_row(&mut self, text: &str) -> Result<(), LineProblem> {
        let fields: Vec<&str> = text.split_whitespace().collect();
        if self.dim == 0 {
            self.dim = fields.len();
        }
        if fields.len() != self.dim {
            return Err(LineProblem::Ragged {
                expected: self.dim,
                found: fields.len(),
            });
        }
        for (j, f) in fields.iter().enumerate() {
            self.current.push(coordinate(f, j + 1)?);
        }
        Ok(())
    }

    fn close_set(&mut self) {
        if !self.current.is_empty() {
            let coords = std::mem::take(&mut self.current);
            // Values were validated field by field; dimension by row length.
            let set = PointSet::new(self.dim, coords).expect("validated rows form a point set");
            self.sets.push(set);
        }
    }

    fn finish(mut self) -> Result<Vec<PointSet>, PointFileError> {
        self.close_set();
        if self.sets.is_empty() {
            return Err(PointFileError::Empty {
                path: self.path.into(),
            });
        }
        Ok(self.sets)
    }
}

/// A first line that begins with a letter is a CSV header, unless it is a
/// comma-free row whose first field Rust reads as a float (`inf 0.5`,
/// `NaN 0.1`): a UTK row, whose value is then refused by name.
fn is_csv_header(text: &str) -> bool {
    let utk_number_row = !text.contains(',')
        && text
            .split_whitespace()
            .next()
            .is_some_and(|f| f.parse::<f64>().is_ok());
    text.starts_with(|c: char| c.is_ascii_alphabetic()) && !utk_number_row
}

fn coordinate(text: &str, field: usize) -> Result<f64, LineProblem> {
    let v: f64 = text.parse().map_err(|_| LineProblem::NotANumber {
        field,
        text: quote(text),
    })?;
    if !v.is_finite() {
        return Err(LineProblem::NotFinite {
            field,
            text: quote(text),
        });
    }
    if !(0.0..1.0).contains(&v) {
        return Err(LineProblem::OutOfRange {
            field,
            value: v,
            text: quote(text),
        });
    }
    Ok(v + 0.0)
}

/// Writes point sets in `format`. CSV gets a `set` column when there is more
/// than one set. Values use Rust's shortest round-trip representation, so
/// reading the file back gives identical bits.
///
/// # Errors
/// The writer's I/O error; `InvalidInput` for an empty set, which neither
/// format can hold (a CSV's `set` column and a UTK file's `#` lines number
/// only sets that have points, so reading the file back would lose it).
pub fn write_point_sets(
    out: &mut dyn Write,
    sets: &[PointSet],
    format: PointFormat,
) -> io::Result<()> {
    if let Some(empty) = sets.iter().position(PointSet::is_empty) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "set {empty} of {} holds no points (a random-count sampler such as \
                 isotropic-jitter can draw none at small N), and a point-set file cannot hold \
                 an empty set: reading it back would lose or renumber the set; draw a larger N",
                sets.len()
            ),
        ));
    }
    let dim = sets.first().map_or(0, PointSet::dim);
    let numbered = sets.len() > 1;
    if format == PointFormat::Csv {
        let mut csv = csv::Writer::from_writer(out);
        let mut header: Vec<String> = (0..dim).map(|j| format!("x{j}")).collect();
        if numbered {
            header.insert(0, "set".into());
        }
        csv.write_record(&header).map_err(csv_io_error)?;
        let mut row = Vec::with_capacity(dim + 1);
        for (s, set) in sets.iter().enumerate() {
            for p in set.points() {
                row.clear();
                if numbered {
                    row.push(s.to_string());
                }
                row.extend(p.iter().map(|v| format!("{v:?}")));
                csv.write_record(&row).map_err(csv_io_error)?;
            }
        }
        return csv.flush();
    }
    for (s, set) in sets.iter().enumerate() {
        if s > 0 {
            writeln!(out, "#")?;
        }
        for p in set.points() {
            for (j, v) in p.iter().enumerate() {
                if j > 0 {
                    write!(out, " ")?;
                }
                write!(out, "{v:?}")?;
            }
            writeln!(out)?;
        }
    }
    Ok(())
}

/// True when the decimal `text` (as f64 parsing accepts it: sign, digits,
/// point, exponent) is exactly 1, not merely a number that rounds to it.
fn decimal_is_one(text: &str) -> bool {
    let text = text.trim().trim_start_matches('+');
    let (mantissa, exponent) = match text.split_once(['e', 'E']) {
        Some((m, e)) => match e.parse::<i64>() {
            Ok(e) => (m, e),
            Err(_) => return false,
        },
        None => (text, 0),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let digits = format!("{int}{frac}");
    let significant = digits.trim_start_matches('0');
    let trimmed = significant.trim_end_matches('0');
    // digits·10^(exponent − |frac|); trailing zeros raise the power.
    let power = exponent - frac.len() as i64 + (significant.len() - trimmed.len()) as i64;
    trimmed == "1" && power == 0
}
