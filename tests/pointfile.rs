//! Point-set files: exact round trips and a clear, located error for every
//! kind of malformed input.

use std::path::Path;

use varspec::PointSet;
use varspec::io::pointfile::{
    LineProblem, PointFileError, parse_point_sets, read_point_sets_of_dim,
};
use varspec::io::{PointFormat, read_point_sets, write_atomic, write_point_sets};
use varspec::rng::{PREV_ONE, set_rng};
use varspec::samplers;

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
    let sampler = samplers::build("random", 50, Some(3), &[]).unwrap();
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
            "1 fields",
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
            "x,y\n0.1,0.2\n",
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
            "1 fields",
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
