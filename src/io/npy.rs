//! NumPy `.npy` arrays (the npyz crate), so a Python user loads a point set,
//! a spectrum or a variance map with one `numpy.load` call: point sets as
//! float64 `[sets, N, d]`, 2D spectra as float64 `[K, K]` (row = k_y + h,
//! column = k_x + h, DC at the centre). Point sets are also read back
//! (float64 or float32, C or Fortran order, `[N, d]` or `[sets, N, d]`).

use std::io::{self, Read, Write};

use npyz::{DType, NpyFile, Order, TypeStr, WriterBuilder};

use crate::points::PointSet;

/// Writes `values` (C order) as a float64 array of `shape`.
///
/// # Errors
/// The writer's I/O error; `InvalidInput` when the shape does not hold the
/// values.
pub fn write_npy(out: &mut dyn Write, shape: &[u64], values: &[f64]) -> io::Result<()> {
    if shape.iter().product::<u64>() != values.len() as u64 {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("shape {shape:?} does not hold {} values", values.len()),
        ));
    }
    let mut writer = npyz::WriteOptions::new()
        .default_dtype()
        .shape(shape)
        .writer(out)
        .begin_nd()?;
    writer.extend(values.iter().copied())?;
    writer.finish()
}

/// Writes point sets of one size as `[sets, N, d]`.
///
/// # Errors
/// As [`write_npy`]; `InvalidInput` for sets of different sizes.
pub fn write_point_sets_npy(out: &mut dyn Write, sets: &[PointSet]) -> io::Result<()> {
    let (n, d) = sets.first().map_or((0, 0), |s| (s.len(), s.dim()));
    if sets.iter().any(|s| s.len() != n || s.dim() != d) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "an .npy array needs every set to have the same N and d",
        ));
    }
    let values: Vec<f64> = sets
        .iter()
        .flat_map(|s| s.coords().iter().copied())
        .collect();
    write_npy(out, &[sets.len() as u64, n as u64, d as u64], &values)
}

/// The first bytes of every `.npy` file.
pub const MAGIC: &[u8] = b"\x93NUMPY";

/// Reads point sets from a `.npy` array of shape `[N, d]` (one set) or
/// `[sets, N, d]`, float64 or float32, every coordinate finite and in
/// [0, 1).
///
/// # Errors
/// A sentence saying what is wrong: header, dtype, shape, a value (with its
/// index) or a short read.
pub fn read_point_sets_npy(mut reader: impl Read) -> Result<Vec<PointSet>, String> {
    let header = read_header_checked(&mut reader)?;
    let file = NpyFile::new(io::Cursor::new(header).chain(reader)).map_err(|e| {
        // npyz's header errors quote the parser's multi-line report: its
        // first line says what is wrong.
        let text = e.to_string();
        match text.split_once('\n') {
            Some((first, _)) => format!(
                "not a readable .npy array: its header is not a NumPy dictionary {{'descr': ..., 'fortran_order': ..., 'shape': (...)}} ({})",
                first.trim()
            ),
            None => format!("not a readable .npy array: {text}"),
        }
    })?;
    let shape = file.shape().to_vec();
    let (sets, n, d) = match shape[..] {
        [n, d] => (1, n, d),
        [s, n, d] => (s, n, d),
        _ => {
            return Err(format!(
                "a point-set array has shape [N, d] or [sets, N, d], found {shape:?}"
            ));
        }
    };
    if sets == 0 || n == 0 || d == 0 {
        return Err(format!("the array of shape {shape:?} holds no points"));
    }
    let fortran = file.order() == Order::Fortran;
    let dtype = file.dtype();
    let values: Vec<f64> = match &dtype {
        DType::Plain(t) if *t == "<f8".parse::<TypeStr>().expect("valid") => {
            collect(file.data::<f64>().map_err(|e| e.to_string())?, &shape)?
        }
        DType::Plain(t) if *t == "<f4".parse::<TypeStr>().expect("valid") => {
            collect(file.data::<f32>().map_err(|e| e.to_string())?, &shape)?
                .into_iter()
                .map(f64::from)
                .collect()
        }
        other => {
            return Err(format!(
                "the array's dtype is {}, point sets are float64 or float32 (little-endian)",
                other.descr()
            ));
        }
    };
    let (sets, n, d) = (sets as usize, n as usize, d as usize);
    // The header's shape and the data must agree (a shape whose product
    // overflows would otherwise index past the data).
    let expected = sets.checked_mul(n).and_then(|c| c.checked_mul(d));
    if expected != Some(values.len()) {
        return Err(format!(
            "the array's shape {shape:?} does not match its {} values",
            values.len()
        ));
    }
    let at = |s: usize, i: usize, j: usize| {
        if fortran {
            s + sets * (i + n * j)
        } else {
            (s * n + i) * d + j
        }
    };
    (0..sets)
        .map(|s| {
            let mut coords = Vec::with_capacity(n * d);
            for i in 0..n {
                for j in 0..d {
                    let v = values[at(s, i, j)];
                    if !(v.is_finite() && (0.0..1.0).contains(&v)) {
                        // Short: -1e-300, not 300 digits.
                        let why = if v == 1.0 {
                            " (a value stored below 1 may have rounded to 1: the largest float32 \
                             below 1 is 0.99999994, the largest float64 0.9999999999999999)"
                        } else {
                            ""
                        };
                        return Err(format!(
                            "value [{s}, {i}, {j}] is {}, outside [0, 1) or not finite{why}",
                            crate::spec_params::SpecValue(v)
                        ));
                    }
                    coords.push(v);
                }
            }
            PointSet::new(d, coords).map_err(|e| e.to_string())
        })
        .collect()
}

/// Reads the magic, version, length and header text (returned as bytes,
/// to be read again by npyz) and refuses a `shape` whose product of
/// dimensions does not fit 64 bits: npyz multiplies it out and would
/// overflow (a panic where overflow is checked).
fn read_header_checked(reader: &mut impl Read) -> Result<Vec<u8>, String> {
    let short = |e: io::Error| format!("not a readable .npy array: {e}");
    let mut bytes = vec![0u8; 8];
    reader.read_exact(&mut bytes).map_err(short)?;
    if !bytes.starts_with(MAGIC) {
        return Err("not a readable .npy array: no NumPy magic string".into());
    }
    let len_bytes = if bytes[6] == 1 { 2 } else { 4 };
    let mut len = vec![0u8; len_bytes];
    reader.read_exact(&mut len).map_err(short)?;
    let header_len = len.iter().rev().fold(0usize, |a, &b| (a << 8) | b as usize);
    if header_len > 1 << 20 {
        return Err(format!(
            "not a readable .npy array: a header of {header_len} bytes"
        ));
    }
    bytes.extend_from_slice(&len);
    let start = bytes.len();
    bytes.resize(start + header_len, 0);
    reader.read_exact(&mut bytes[start..]).map_err(short)?;
    let text = String::from_utf8_lossy(&bytes[start..]);
    // The shape's key in either quote, then its tuple or list.
    let after_key = text
        .split_once("'shape'")
        .or_else(|| text.split_once("\"shape\""))
        .map(|(_, rest)| rest);
    let dims = after_key.and_then(|rest| {
        let open = rest.find(['(', '['])?;
        let close = if rest.as_bytes()[open] == b'(' {
            ')'
        } else {
            ']'
        };
        let inner = &rest[open + 1..];
        inner.find(close).map(|end| &inner[..end])
    });
    if let Some(dims) = dims {
        // Each dimension's magnitude, whatever signs a Python literal puts
        // before it (npyz reads `--5` as 5); a digit run beyond u64 counts
        // as overflowing. Anything else (npyz would evaluate `a-b`, whose
        // product it then overflows) is not a shape.
        let items: Vec<&str> = dims
            .split(',')
            .map(|d| d.trim().trim_start_matches(['-', '+']))
            .filter(|d| !d.is_empty())
            .collect();
        if let Some(bad) = items
            .iter()
            .find(|d| !d.bytes().all(|b| b.is_ascii_digit()))
        {
            return Err(format!(
                "the array's shape ({}) holds `{bad}`, not a whole number",
                dims.trim()
            ));
        }
        let magnitudes: Vec<Option<u64>> = items.iter().map(|d| d.parse::<u64>().ok()).collect();
        let product = magnitudes
            .iter()
            .try_fold(1u64, |a, d| d.and_then(|d| a.checked_mul(d)));
        if product.is_none() {
            return Err(format!(
                "the array's shape ({}) holds more values than 2^64: not a point-set array",
                dims.trim()
            ));
        }
    }
    Ok(bytes)
}

/// Every element of a reader, or how many of the `shape`'s values a
/// truncated file holds (grown as read: a header's shape is never
/// allocated up front).
fn collect<T, R: Read>(data: npyz::NpyReader<T, R>, shape: &[u64]) -> Result<Vec<T>, String>
where
    T: npyz::Deserialize,
{
    let mut values = Vec::new();
    for value in data {
        match value {
            Ok(v) => values.push(v),
            Err(e) => {
                let stated: u64 = shape.iter().product();
                return Err(format!(
                    "the array's data is cut short: its shape {shape:?} states {stated} values, \
                     the file holds {} ({e})",
                    values.len()
                ));
            }
        }
    }
    Ok(values)
}
