//! CSV tables of serde records through the `csv` crate: the header is the
//! record's field names, numbers are written in their shortest form that
//! reads back to the same value, `None` as an empty field.

use std::io::{self, Write};

use serde::Serialize;

/// Writes `rows` as CSV with a header of the record's field names (for no
/// rows, no header either: the record type has no instance to name them).
///
/// # Errors
/// The I/O error of writing, or a record serde cannot write as one row.
pub fn write_csv_rows<R: Serialize>(
    out: &mut dyn Write,
    rows: impl IntoIterator<Item = R>,
) -> io::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    for row in rows {
        w.serialize(row).map_err(csv_io_error)?;
    }
    w.flush()
}

/// Writes `header`, then `rows` (tuples or sequences, one value per column):
/// for tables whose column names depend on the data, such as a projection's
/// frequency axes (kx, ku for the XU plane).
///
/// # Errors
/// The I/O error of writing, or a record serde cannot write as one row.
pub fn write_csv_headed<R: Serialize>(
    out: &mut dyn Write,
    header: &[&str],
    rows: impl IntoIterator<Item = R>,
) -> io::Result<()> {
    let mut w = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(out);
    w.write_record(header).map_err(csv_io_error)?;
    for row in rows {
        w.serialize(row).map_err(csv_io_error)?;
    }
    w.flush()
}

/// The I/O error under a `csv` error, its kind kept (a closed pipe stays
/// `BrokenPipe`, which the command line treats as success), or the error
/// as `InvalidData` when it is not one of I/O (a malformed record read, a
/// record serde cannot write).
pub fn csv_io_error(e: csv::Error) -> io::Error {
    match e.into_kind() {
        csv::ErrorKind::Io(cause) => cause,
        other => io::Error::new(io::ErrorKind::InvalidData, format!("{other:?}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize)]
    struct Row {
        k: i64,
        power: f64,
        stderr: Option<f64>,
    }

    #[test]
    fn header_from_field_names_and_values_that_read_back() {
        let mut out = Vec::new();
        let rows = [
            Row {
                k: -3,
                power: 0.1 + 0.2,
                stderr: None,
            },
            Row {
                k: 4,
                power: 1e-300,
                stderr: Some(2.5),
            },
        ];
        write_csv_rows(&mut out, rows).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert_eq!(
            text,
            "k,power,stderr\n-3,0.30000000000000004,\n4,1e-300,2.5\n"
        );
    }
}
