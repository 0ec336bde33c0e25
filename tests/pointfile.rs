//! Point-set files: exact round trips and a clear, located error for every
//! kind of malformed input.

use std::path::Path;

use varspec::PointSet;
use varspec::io::pointfile::{
    LineProblem, PointFileError, parse_point_sets, read_point_sets_of_dim,
};
use varspec::io::{PointFormat, read_point_sets, write_atomic, write_point_sets};
use varspec::registry;
use varspec::rng::{PREV_ONE, set_rng};

fn parse(text: &str) -> Result<Vec<PointSet>, PointFileError> {
    parse_point_sets(text.as_bytes(), Path::new("in.csv"))
}

fn line_problem(text: &str) -> (usize, LineProblem, String) {
    match parse(text) {
        Err(e @ PointFileError::Line { .. }) => {
            let message = e.to_string();
            let PointFileError::Line { line, problem, .. } = e else {
                unreachable!()
            };
            (line, problem, message)
        }
        other => panic!("expected a line error for {text:?}, got {other:?}"),
    }
}

#[test]
fn round_trip_is_bit_exact_in_both_formats() {
    let sampler = registry::build("random", 50, Some(3), &[]).unwrap();
    let mut sets: Vec<PointSet> = (0..3)
        .map(|r| sampler.sample(&mut set_rng(9, r)).unwrap())
        .collect();
    // Awkward values: 0, the largest double below 1, tiny and subnormal numbers.
    sets.push(PointSet::new(3, vec![0.0, PREV_ONE, 1e-300, 5e-324, 0.1, 1.0 / 3.0]).unwrap());
    let dir = std::env::temp_dir().join(format!("varspec-roundtrip-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (format, name) in [(PointFormat::Csv, "p.csv"), (PointFormat::Utk, "p.dat")] {
        for subset in [&sets[..1], &sets[..]] {
            let path = dir.join(name);
            write_atomic(&path, |w| write_point_sets(w, subset, format)).unwrap();
            let back = read_point_sets(&path).unwrap();
            assert_eq!(back.len(), subset.len());
            for (a, b) in subset.iter().zip(&back) {
                let bits =
                    |s: &PointSet| s.coords().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(a), bits(b), "{format:?} round trip changed bits");
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn csv_with_set_column_splits_realizations() {
    let sets = parse("set,x0,x1\n0,0.1,0.2\n0,0.3,0.4\n1,0.5,0.6\n").unwrap();
    assert_eq!(sets.len(), 2);
    assert_eq!(sets[1].coords(), &[0.5, 0.6]);
    // The axes' names other tools write read as x0, x1, …; other names and
    // orders are refused.
    for header in ["x,y", "x,y,z", "x,y,u,v", "x,y,z,w", "set,x,y"] {
        let dim = header.split(',').filter(|n| *n != "set").count();
        let set = if header.starts_with("set") { "0," } else { "" };
        let row = vec!["0.25"; dim].join(",");
        let sets = parse(&format!("{header}\n{set}{row}\n")).unwrap();
        assert_eq!((sets.len(), sets[0].dim()), (1, dim), "{header}");
    }
    for header in ["y,x", "x,y,v,u", "a,b"] {
        let e = parse(&format!("{header}\n0.1,0.2\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("CSV header must be"), "{header}: {e}");
    }
    let utk = parse("# comment\n0.1 0.2\n0.3 0.4\n#\n0.5\t0.6\n#\n").unwrap();
    assert_eq!(utk.len(), 2);
    assert_eq!(utk[0].coords(), &[0.1, 0.2, 0.3, 0.4]);
}

#[test]
fn negative_zero_reads_as_zero() {
    let sets = parse("x0,x1\n-0.0,0.5\r\n").unwrap();
    assert!(sets[0].coords()[0] == 0.0 && sets[0].coords()[0].is_sign_positive());
}

#[test]
fn bytes_that_are_not_utf8_are_named_with_their_line() {
    // Was the csv crate's debug dump: `Utf8 { pos: Some(Position { .. }) }`.
    for (bytes, line) in [
        (&b"x0,x1\n0.1,0.2\n\xff,0.5\n"[..], 3),
        (b"\xff0.1 0.2\n", 1),
        (b"0.1 0.2\n0.3 \xff\n", 2),
    ] {
        match parse_point_sets(bytes, Path::new("in.csv")) {
            Err(
                e @ PointFileError::Line {
                    problem: LineProblem::NotUtf8,
                    ..
                },
            ) => assert!(
                e.to_string()
                    .starts_with(&format!("in.csv:{line}: not UTF-8")),
                "{e}"
            ),
            other => panic!("{bytes:?}: {other:?}"),
        }
    }
}

#[test]
fn every_malformed_input_names_its_line() {
    type Case = (&'static str, usize, fn(&LineProblem) -> bool, &'static str);
    let cases: Vec<Case> = vec![
        (
            "x0,x1\n0.1,0.2\n0.3,NaN\n",
            3,
            |p| matches!(p, LineProblem::NotFinite { field: 2, .. }),
            "NaN",
        ),
        (
            "x0,x1\n0.1,inf\n",
            2,
            |p| matches!(p, LineProblem::NotFinite { .. }),
            "inf",
        ),
        // A UTK file whose first value is a float spelt with letters: its
        // value is refused, the line is not read as a CSV header.
        (
            "inf 0.5\n0.1 0.2\n",
            1,
            |p| matches!(p, LineProblem::NotFinite { field: 1, .. }),
            "inf",
        ),
        (
            "0.1 0.2\nNaN 0.5\n",
            2,
            |p| matches!(p, LineProblem::NotFinite { field: 1, .. }),
            "NaN",
        ),
        (
            "x0,x1\n0.1,1.0\n",
            2,
            |p| matches!(p, LineProblem::OutOfRange { .. }),
            "write 0",
        ),
        (
            "x0,x1\n-0.5,0.1\n",
            2,
            |p| matches!(p, LineProblem::OutOfRange { field: 1, .. }),
            "-0.5",
        ),
        // Quoted as written (Display printed 300 digits of -1e-300).
        (
            "x0,x1\n-1e-300,0.1\n",
            2,
            |p| matches!(p, LineProblem::OutOfRange { field: 1, .. }),
            "field 1 is `-1e-300`, outside [0, 1)",
        ),
        // A decimal below 1 that reads as the double 1 says so.
        (
            "x0,x1\n0.1,0.99999999999999995\n",
            2,
            |p| matches!(p, LineProblem::OutOfRange { field: 2, .. }),
            "`0.99999999999999995`, which rounds to the double 1,",
        ),
        // Whatever its spelling (these read as "field 2 is 1": review).
        (
            "x0,x1\n0.1,.99999999999999995\n",
            2,
            |p| matches!(p, LineProblem::OutOfRange { field: 2, .. }),
            "`.99999999999999995`, which rounds to the double 1,",
        ),
        (
            "x0,x1\n0.1,9.9999999999999999e-1\n",
            2,
            |p| matches!(p, LineProblem::OutOfRange { field: 2, .. }),
            "`9.9999999999999999e-1`, which rounds to the double 1,",
        ),
        // Spellings of exactly 1 are 1.
        (
            "x0,x1\n0.1,10e-1\n",
            2,
            |p| matches!(p, LineProblem::OutOfRange { field: 2, .. }),
            "field 2 is 1, outside",
        ),
        (
            "x0,x1\n0.1,0.0100E2\n",
            2,
            |p| matches!(p, LineProblem::OutOfRange { field: 2, .. }),
            "field 2 is 1, outside",
        ),
        (
            "x0,x1\n0.1,0.2\n0.3\n",
            3,
            |p| {
                matches!(
                    p,
                    LineProblem::Ragged {
                        expected: 2,
                        found: 1
                    }
                )
            },
            "1 field where",
        ),
        (
            "x0,x1\n0.1,0.2,0.3\n",
            2,
            |p| {
                matches!(
                    p,
                    LineProblem::Ragged {
                        expected: 2,
                        found: 3
                    }
                )
            },
            "3 fields",
        ),
        (
            "x0,x1\n0.1,abc\n",
            2,
            |p| matches!(p, LineProblem::NotANumber { field: 2, .. }),
            "abc",
        ),
        (
            "y,x\n0.1,0.2\n",
            1,
            |p| matches!(p, LineProblem::Header { .. }),
            "header",
        ),
        (
            "0.1,0.2\n",
            1,
            |p| matches!(p, LineProblem::Header { .. }),
            "header",
        ),
        (
            "set,x0\n1,0.5\n",
            2,
            |p| matches!(p, LineProblem::SetNumber { current: None, .. }),
            "start at 0",
        ),
        (
            "set,x0\n0,0.5\n2,0.5\n",
            3,
            |p| {
                matches!(
                    p,
                    LineProblem::SetNumber {
                        current: Some(0),
                        ..
                    }
                )
            },
            "0 or 1",
        ),
        (
            "set,x0\n0,0.5\nx,0.5\n",
            3,
            |p| matches!(p, LineProblem::SetNumber { .. }),
            "`x`",
        ),
        (
            "0.1 0.2\n0.3\n",
            2,
            |p| {
                matches!(
                    p,
                    LineProblem::Ragged {
                        expected: 2,
                        found: 1
                    }
                )
            },
            "1 field where",
        ),
        (
            "0.1 0.2\n#\n0.1 0.2 0.3\n",
            3,
            |p| matches!(p, LineProblem::Ragged { .. }),
            "3 fields",
        ),
    ];
    for (text, line, kind, phrase) in cases {
        let (got_line, problem, message) = line_problem(text);
        assert_eq!(got_line, line, "{text:?}: {message}");
        assert!(kind(&problem), "{text:?}: unexpected problem {problem:?}");
        assert!(
            message.starts_with(&format!("in.csv:{line}: ")),
            "{message}"
        );
        assert!(
            message.contains(phrase),
            "{message:?} should mention {phrase:?}"
        );
    }
}

#[test]
fn empty_files_and_wrong_dimensions_are_errors() {
    for text in ["", "\n\n", "x0,x1\n", "#\n#\n"] {
        assert!(
            matches!(parse(text), Err(PointFileError::Empty { .. })),
            "{text:?}"
        );
    }
    let dir = std::env::temp_dir().join(format!("varspec-dim-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("three.csv");
    std::fs::write(&path, "x0,x1,x2\n0.1,0.2,0.3\n").unwrap();
    let err = read_point_sets_of_dim(&path, 2).unwrap_err();
    assert!(matches!(
        err,
        PointFileError::WrongDimension {
            expected: 2,
            found: 3,
            ..
        }
    ));
    assert!(err.to_string().contains("three.csv"));
    let missing = read_point_sets(&dir.join("missing.csv")).unwrap_err();
    assert!(missing.to_string().contains("missing.csv"), "{missing}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn limits_and_encodings() {
    // A byte-order mark (as spreadsheets write) is skipped.
    let sets = parse("\u{feff}x0,x1\n0.1,0.2\n").unwrap();
    assert_eq!(sets[0].coords(), &[0.1, 0.2]);
    // Quoted fields and CRLF line ends, as RFC 4180 allows.
    let sets = parse("x0,x1\r\n\"0.25\",0.5\r\n").unwrap();
    assert_eq!(sets[0].coords(), &[0.25, 0.5]);
    // An endless line (a device, a binary file) is refused, not read into memory.
    let huge = "1".repeat(2 << 20);
    let err = parse(&huge).unwrap_err().to_string();
    assert!(err.contains("longer than"), "{err}");
    // A long bad header is quoted by a short, escaped prefix.
    let header = format!("{}\0,x1\n0.1,0.2\n", "y".repeat(100_000));
    let err = parse(&header).unwrap_err().to_string();
    assert!(err.len() < 300 && err.contains('…'), "{err}");
}

/// A version-1.0 `.npy` file built by hand from the format's specification
/// (numpy.lib.format: magic, version, little-endian u16 header length, an
/// ASCII dict padded with spaces and `\n` to a multiple of 64 bytes).
fn npy_by_hand(descr: &str, fortran: bool, shape: &str, data: &[u8]) -> Vec<u8> {
    let dict = format!(
        "{{'descr': '{descr}', 'fortran_order': {}, 'shape': {shape}, }}",
        if fortran { "True" } else { "False" }
    );
    let unpadded = 10 + dict.len() + 1;
    let pad = unpadded.next_multiple_of(64) - unpadded;
    let header = format!("{dict}{}\n", " ".repeat(pad));
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(data);
    out
}

#[test]
fn npy_point_sets_round_trip_and_read_what_numpy_writes() {
    let dir = std::env::temp_dir().join(format!("varspec-npy-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sampler = registry::build("random", 5, Some(3), &[]).unwrap();
    let sets: Vec<PointSet> = (0..2)
        .map(|r| sampler.sample(&mut set_rng(4, r)).unwrap())
        .collect();
    let path = dir.join("sets.npy");
    write_atomic(&path, |w| varspec::io::npy::write_point_sets_npy(w, &sets)).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    // The header numpy.load reads, then the coordinates as little-endian f64.
    assert!(bytes.starts_with(b"\x93NUMPY"));
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert!(header.contains("'descr': '<f8'"), "{header}");
    assert!(header.contains("'fortran_order': False"), "{header}");
    // A Python tuple: a trailing comma is allowed.
    let tuple = header.replace(" ", "").replace(",)", ")");
    assert!(tuple.contains("'shape':(2,5,3)"), "{header}");
    let data: Vec<f64> = bytes[10 + header_len..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let expected: Vec<f64> = sets.iter().flat_map(|s| s.coords().to_vec()).collect();
    assert_eq!(data, expected);
    assert_eq!(read_point_sets(&path).unwrap(), sets);

    // float32 in Fortran order, shape [N, d] = [3, 2]: column-major data.
    let points = [[0.5f32, 0.25], [0.125, 0.75], [0.0, 0.5]];
    let mut data = Vec::new();
    for j in 0..2 {
        for p in &points {
            data.extend_from_slice(&p[j].to_le_bytes());
        }
    }
    let path = dir.join("fortran.npy");
    std::fs::write(&path, npy_by_hand("<f4", true, "(3, 2)", &data)).unwrap();
    let read = read_point_sets(&path).unwrap();
    assert_eq!(read.len(), 1);
    assert_eq!(read[0].coords(), &[0.5, 0.25, 0.125, 0.75, 0.0, 0.5]);

    // What is refused, and how it is said.
    let refuse = |name: &str, bytes: Vec<u8>, needle: &str| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let message = read_point_sets(&path).unwrap_err().to_string();
        assert!(
            message.contains(name) && message.contains(needle),
            "{name}: {message}"
        );
    };
    let one = 1.0f64.to_le_bytes().to_vec();
    refuse(
        "one.npy",
        npy_by_hand("<f8", false, "(1, 1)", &one),
        "[0, 0, 0] is 1",
    );
    refuse(
        "flat.npy",
        npy_by_hand("<f8", false, "(1,)", &[0; 8]),
        "shape",
    );
    refuse(
        "ints.npy",
        npy_by_hand("<i8", false, "(1, 1)", &[0; 8]),
        "dtype",
    );
    refuse(
        "short.npy",
        npy_by_hand("<f8", false, "(4, 2)", &[0; 8]),
        "states 8 values, the file holds 1",
    );
    // A shape of 2e11 values over 16 bytes: read as it grows, never
    // allocated from the header.
    refuse(
        "huge.npy",
        npy_by_hand("<f8", false, "(100000000000, 2)", &[0; 16]),
        "states 200000000000 values, the file holds 2",
    );
    refuse(
        "empty.npy",
        npy_by_hand("<f8", false, "(0, 2)", &[]),
        "no points",
    );
    // A header that is no dictionary: one line, not the parser's report.
    let mut garbage = b"\x93NUMPY\x01\x00\x36\x00garbage".to_vec();
    garbage.resize(10 + 0x36 - 1, b' ');
    garbage.push(b'\n');
    refuse(
        "garbage.npy",
        garbage.clone(),
        "its header is not a NumPy dictionary",
    );
    let path = dir.join("garbage.npy");
    let message = read_point_sets(&path).unwrap_err().to_string();
    assert!(!message.contains('\n'), "{message}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_npy_shape_whose_product_overflows_is_refused() {
    // Found by the fuzzer: a shape whose product of dimensions does not fit
    // 64 bits, over 48 bytes of data. The reader indexed past the data
    // (the product wrapped) and npyz, multiplying it out, panicked where
    // overflow is checked; `--` is Python's double negation.
    // The long fuzz run found `a-b` in a shape, which npyz evaluates and
    // then overflows multiplying out: any dimension that is not a whole
    // number is refused before npyz reads it.
    for (shape, phrase) in [
        ("(9223372036854775808, 3, 2)", "holds more values"),
        ("(9223372036854775807, 3, 2)", "holds more values"),
        ("(--9223372036854775808, 3, 2)", "holds more values"),
        ("(18446744073709551615, 3, 2)", "holds more values"),
        (
            "(18446744073709551615-9223372036854775808, 3, 2,99999999999 )",
            "not a whole number",
        ),
        // The same in a list, and under a double-quoted key (both Python).
        ("[9223372036854775808, 3, 2]", "holds more values"),
        ("\"(18446744073709551615, 3, 2)", "holds more values"),
    ] {
        let (key, shape) = match shape.strip_prefix('"') {
            Some(rest) => ("\"shape\"", rest),
            None => ("'shape'", shape),
        };
        let mut header = format!("{{'descr': '<f8', 'fortran_order': False, {key}: {shape}, }}");
        while (10 + header.len() + 1) % 64 != 0 {
            header.push(' ');
        }
        header.push('\n');
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
        bytes.extend_from_slice(header.as_bytes());
        bytes.extend_from_slice(&[0u8; 48]);
        let err = varspec::io::npy::read_point_sets_npy(&bytes[..]).unwrap_err();
        assert!(err.contains(phrase), "{shape}: {err}");
    }
}
