//! Pattern tables: every format reads back to the values written (f32 to
//! the f32 rounding, kept below 1), metadata is present, and the C header
//! compiles.

use std::path::{Path, PathBuf};
use std::process::Command;

use varspec::PointSet;
use varspec::io::tables::{F32_PREV_ONE, TableFormat, TableMetadata, to_unit_f32, write_table};
use varspec::rng::PREV_ONE;

/// A folder of the test `tag`'s own: tests run side by side, and one that
/// removes a shared folder pulls it from under another (a CI run lost
/// `named/` to `every_format_round_trips`'s clean-up).
fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("varspec-tables-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `varspec tables --sampler cmj -n 4 --sets 1` with `args` after.
fn one_cmj_set(args: &[&str]) -> String {
    varspec(
        &[
            &["tables", "--sampler", "cmj", "-n", "4", "--sets", "1"],
            args,
        ]
        .concat(),
    )
}

/// Runs `varspec args`, asserts success and returns its standard error.
fn varspec(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_varspec"))
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{args:?}: {err}");
    err
}

fn sidecar(path: &Path) -> TableMetadata {
    let mut p = path.as_os_str().to_owned();
    p.push(".json");
    serde_json::from_str(&std::fs::read_to_string(PathBuf::from(p)).unwrap()).unwrap()
}

#[test]
fn every_format_round_trips() {
    let d = dir("round-trips");
    let reference = d.join("ref.csv");
    varspec(&[
        "sample",
        "sobol",
        "-n",
        "32",
        "--sets",
        "3",
        "--seed",
        "4",
        "-o",
        reference.to_str().unwrap(),
    ]);
    let sets = varspec::io::read_point_sets(&reference).unwrap();
    let values: Vec<f64> = sets.iter().flat_map(|s| s.coords().to_vec()).collect();
    let out = |ext: &str| d.join(format!("table.{ext}"));
    for (format, ext) in [
        ("csv", "csv"),
        ("json", "json"),
        ("f32", "f32"),
        ("f64", "f64"),
        ("c-header", "h"),
    ] {
        varspec(&[
            "tables",
            "--from",
            reference.to_str().unwrap(),
            "--format",
            format,
            "-o",
            out(ext).to_str().unwrap(),
        ]);
    }
    // CSV and f64: identical bits.
    let csv: Vec<f64> = varspec::io::read_point_sets(&out("csv"))
        .unwrap()
        .iter()
        .flat_map(|s| s.coords().to_vec())
        .collect();
    assert_eq!(csv, values);
    // Raw files decoded here, independently of the reader.
    let decode = |ext: &str, width: usize| -> Vec<f64> {
        std::fs::read(out(ext))
            .unwrap()
            .chunks_exact(width)
            .map(|c| {
                if width == 4 {
                    f64::from(f32::from_le_bytes(c.try_into().unwrap()))
                } else {
                    f64::from_le_bytes(c.try_into().unwrap())
                }
            })
            .collect()
    };
    let f64s = decode("f64", 8);
    assert_eq!(f64s, values);
    // f32: the nearest f32, below 1.
    let f32s = decode("f32", 4);
    assert_eq!(f32s.len(), values.len());
    for (a, b) in f32s.iter().zip(&values) {
        assert_eq!(*a, f64::from(f32_at_or_below(*b)));
        assert!((0.0..1.0).contains(a));
    }
    // JSON: metadata and exact values.
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out("json")).unwrap()).unwrap();
    let json: Vec<f64> = doc["sets"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|s| {
            s.as_array()
                .unwrap()
                .iter()
                .flat_map(|p| p.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()))
        })
        .collect();
    assert_eq!(json, values);
    assert_eq!(doc["metadata"]["n"].as_u64(), Some(32));
    assert_eq!(
        doc["metadata"]["predicted_variance"]
            .as_array()
            .unwrap()
            .len(),
        4
    );
    // Sidecars of the formats without inline metadata.
    for ext in ["csv", "f32", "f64"] {
        let m = sidecar(&out(ext));
        assert_eq!((m.n, m.dim, m.sets), (32, 2, 3));
        assert!(m.generator.starts_with("varspec "));
        // The file's sets were drawn elsewhere: no seed is claimed.
        assert_eq!(m.seed, None, "{}", out(ext).display());
    }
    assert!(doc["metadata"]["seed"].is_null(), "{doc}");
    // C header: the literals parse back to the f32 values, and it compiles.
    let header = std::fs::read_to_string(out("h")).unwrap();
    let body = &header[header.find("= {").unwrap()..];
    let parsed: Vec<f32> = body
        .split(|c: char| {
            c == ',' || c == '{' || c == '}' || c.is_whitespace() || c == '=' || c == ';'
        })
        .filter(|t| t.ends_with('f') && t.starts_with(|c: char| c.is_ascii_digit()))
        .map(|t| t.trim_end_matches('f').parse().unwrap())
        .collect();
    assert_eq!(parsed.len(), values.len());
    for (a, b) in parsed.iter().zip(&values) {
        assert_eq!(*a, f32_at_or_below(*b));
    }
    let c = d.join("use.c");
    std::fs::write(&c, "#include \"table.h\"\nfloat first(void) { return table[VARSPEC_TABLE_SETS - 1][VARSPEC_TABLE_N - 1][VARSPEC_TABLE_DIM - 1]; }\n").unwrap();
    let cc = Command::new("cc")
        .args([
            "-c",
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            c.to_str().unwrap(),
            "-o",
            d.join("use.o").to_str().unwrap(),
        ])
        .output()
        .expect("a C compiler `cc` (the project's machines have gcc)");
    assert!(
        cc.status.success(),
        "cc -c failed: {}",
        String::from_utf8_lossy(&cc.stderr)
    );
    // Every table reads back as point sets (raw ones through their
    // sidecar): f64 formats to the bit, f32 ones to the values decoded
    // above, with the sets' shape.
    for (ext, expected) in [
        ("csv", &values),
        ("json", &values),
        ("f64", &values),
        ("f32", &f32s),
        ("h", &f32s),
    ] {
        let back = varspec::io::read_point_sets(&out(ext))
            .unwrap_or_else(|e| panic!("table.{ext} does not read back: {e}"));
        assert_eq!(back.len(), 3, "table.{ext}");
        assert!(
            back.iter().all(|s| s.len() == 32 && s.dim() == 2),
            "table.{ext}"
        );
        let read: Vec<f64> = back.iter().flat_map(|s| s.coords().to_vec()).collect();
        assert_eq!(&read, expected, "table.{ext}");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn f32_tables_stay_below_one() {
    // 1 − 2⁻⁵³ rounds to 1.0f32; the table must hold the largest f32 below 1.
    let set = PointSet::new(2, vec![PREV_ONE, 0.0, 0.999_999_99, 0.5]).unwrap();
    let meta = TableMetadata {
        generator: "test".into(),
        source: "test".into(),
        params: vec![],
        seed: Some(0),
        n: 2,
        dim: 2,
        sets: 1,
        layout: String::new(),
        values_digest: None,
        optimized_for: "none".into(),
        predicted_variance: vec![],
        dimensions: None,
        predicted_variance_skipped: None,
    };
    let mut bytes = Vec::new();
    write_table(&mut bytes, &[set], &meta, TableFormat::F32, "t").unwrap();
    let values: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(values[0], F32_PREV_ONE);
    assert_eq!(values[2], F32_PREV_ONE);
    assert!(values.iter().all(|v| (0.0..1.0).contains(v)));
}

#[test]
fn f32_tables_keep_every_point_in_its_stratum() {
    // Jitter at m = 16 per axis (strata edges k/16 are exact in f32), and
    // points placed a hair below each upper edge, where rounding to nearest
    // f32 moves them onto the edge, into the next stratum.
    let m = 16usize;
    let below_edge: Vec<f64> = (1..=m).map(|k| k as f64 / m as f64 - 1e-12).collect();
    let sampler = varspec::registry::build("jitter", m * m, Some(2), &[]).unwrap();
    let jittered = sampler.sample(&mut varspec::rng::set_rng(1, 0)).unwrap();
    let mut checked = 0;
    for x in below_edge.iter().chain(jittered.coords()) {
        let v = f64::from(to_unit_f32(*x));
        assert!(v <= *x && v < 1.0, "{x} became {v}");
        let stratum = |t: f64| (t * m as f64).floor();
        assert_eq!(stratum(v), stratum(*x), "{x} left its stratum as {v}");
        checked += 1;
    }
    assert_eq!(checked, m + 2 * m * m);
    // Rounding to nearest would have failed this test: the check can fail.
    assert_eq!(f64::from((1.0f64 - 1e-12) as f32), 1.0);
}

/// The metadata's O(N²)-per-set predicted variances are left out, with a
/// note, beyond the budget, and computed when asked.
#[test]
fn costly_predicted_variances_are_opt_in() {
    // Its own folder: other tests here remove theirs when done.
    let d = std::env::temp_dir().join(format!("varspec-tables-opt-in-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    // A random-point CSV table of `sets` sets of `n` points, with `extra` options.
    let table = |name: &str, n: &str, sets: &str, extra: &[&str]| {
        let path = d.join(name);
        let mut args = vec![
            "tables",
            "--sampler",
            "random",
            "-n",
            n,
            "--sets",
            sets,
            "--format",
            "csv",
        ];
        args.extend_from_slice(extra);
        args.extend(["-o", path.to_str().unwrap()]);
        let err = varspec(&args);
        let meta = sidecar(&path);
        (
            meta.predicted_variance.len(),
            err,
            meta.predicted_variance_skipped,
        )
    };
    let (count, err, skipped) = table("large.csv", "5000", "4", &[]);
    assert!(err.contains("pass --variance"), "{err}");
    assert_eq!(count, 0);
    // The file says why the list is empty (it said nothing: third trial).
    assert!(
        skipped
            .as_deref()
            .is_some_and(|why| why.contains("exceed 2^28") && why.contains("pass --variance")),
        "{skipped:?}"
    );
    assert_eq!(table("small.csv", "64", "2", &[]).2, None);
    assert_eq!(table("small.csv", "64", "2", &[]).0, 4);
    assert_eq!(table("forced.csv", "5000", "1", &["--variance"]).0, 4);
    let _ = std::fs::remove_dir_all(&d);
}

/// The metadata's predicted variance on the reference disk (r = 0.3 at the
/// centre) against an independent brute-force value: the variance of
/// (1/N)·Σ 1[|x_j + s − c| < r] over a 512² grid of torus shifts s, one set
/// of 16 points. The grid's quadrature error on an indicator is far below
/// the 0.5% allowed (checked: 1024² shifts move the value by 0.04%).
#[test]
fn predicted_variance_matches_a_brute_force_shift_average() {
    use varspec::io::tables::TableFormat;
    use varspec::tables::{PredictedVariances, Provenance, metadata};
    let points: Vec<f64> = (0..16)
        .flat_map(|i| {
            let (x, y) = (
                (i % 4) as f64 / 4.0 + 0.11,
                (i / 4) as f64 / 4.0 + 0.07 * (i % 3) as f64,
            );
            [x, y]
        })
        .collect();
    let set = varspec::PointSet::new(2, points.clone()).unwrap();
    let provenance = Provenance {
        source: "test".into(),
        params: vec![],
        seed: Some(0),
        optimized_for: "none".into(),
        dimensions: None,
    };
    let (meta, status) = metadata(&[set], provenance, TableFormat::Csv, false).unwrap();
    assert_eq!(status, PredictedVariances::Computed);
    let (spec, predicted) = &meta.predicted_variance[0];
    assert!(spec.starts_with("disk:r=0.3"), "{spec}");
    let g = 512;
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for a in 0..g {
        for b in 0..g {
            let s = [(a as f64 + 0.5) / g as f64, (b as f64 + 0.5) / g as f64];
            let inside = points
                .chunks(2)
                .filter(|p| {
                    let x = (p[0] + s[0]).fract() - 0.5;
                    let y = (p[1] + s[1]).fract() - 0.5;
                    x * x + y * y < 0.09
                })
                .count();
            let estimate = inside as f64 / 16.0;
            sum += estimate;
            sum2 += estimate * estimate;
        }
    }
    let count = (g * g) as f64;
    let brute = sum2 / count - (sum / count).powi(2);
    assert!(
        (predicted / brute - 1.0).abs() < 0.005,
        "predicted {predicted:.6e}, brute force over {g}^2 shifts {brute:.6e}"
    );
}

/// An f32 table's predicted variances are those of the values it stores
/// (each coordinate truncated to f32), not of the f64 sets it was made
/// from: they differ near 1e-8 relative here, far above the 1e-13 the
/// comparison allows.
#[test]
fn an_f32_tables_predicted_variance_is_that_of_its_stored_values() {
    use varspec::io::tables::TableFormat;
    use varspec::tables::{Provenance, metadata};
    use varspec::variance::spatial_variance;
    let sampler = varspec::registry::build("random", 256, Some(2), &[]).unwrap();
    let set = sampler.sample(&mut varspec::rng::set_rng(3, 0)).unwrap();
    let stored: Vec<f64> = set
        .coords()
        .iter()
        .map(|&x| f64::from(f32_at_or_below(x)))
        .collect();
    let stored = varspec::PointSet::new(2, stored).unwrap();
    let provenance = || Provenance {
        source: "test".into(),
        params: vec![],
        seed: Some(3),
        optimized_for: "none".into(),
        dimensions: None,
    };
    let sets = [set.clone()];
    let (f32_meta, _) = metadata(&sets, provenance(), TableFormat::F32, false).unwrap();
    let (f64_meta, _) = metadata(&sets, provenance(), TableFormat::F64, false).unwrap();
    for ((spec, in_f32), (_, in_f64)) in f32_meta
        .predicted_variance
        .iter()
        .zip(&f64_meta.predicted_variance)
    {
        let f = varspec::integrands::parse(spec).unwrap();
        let of_stored = spatial_variance(&stored, f.as_ref()).unwrap().0;
        let of_f64 = spatial_variance(&set, f.as_ref()).unwrap().0;
        assert!(
            (in_f32 / of_stored - 1.0).abs() < 1e-13,
            "{spec}: f32 table {in_f32:e}, its stored values {of_stored:e}"
        );
        assert_eq!(
            *in_f64, of_f64,
            "{spec}: an f64 table stores the sets as they are"
        );
        assert!(
            (of_stored / of_f64 - 1.0).abs() > 1e-12,
            "{spec}: truncation to f32 should move the variance ({of_stored:e} vs {of_f64:e})"
        );
    }
}

/// The largest f32 not above x in [0, 1) (the test's own reference for the
/// tables' truncation): round to nearest, then step down one unit in the
/// last place when that rounded up.
fn f32_at_or_below(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x {
        f32::from_bits(f.to_bits() - 1)
    } else {
        f
    }
}

#[test]
fn a_sharded_table_run_merges_to_the_single_runs_bytes() {
    let dir = std::env::temp_dir().join(format!("varspec-table-shards-{}", std::process::id()));
    let (whole, parts) = (dir.join("whole"), dir.join("parts"));
    std::fs::create_dir_all(&whole).unwrap();
    std::fs::create_dir_all(&parts).unwrap();
    let varspec = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_varspec"))
            .args(args)
            .output()
            .unwrap()
    };
    let run = |args: &[&str]| {
        let out = varspec(args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let draw = [
        "tables",
        "--sampler",
        "cmj",
        "-n",
        "64",
        "--sets",
        "10",
        "--seed",
        "3",
    ];
    let table = |d: &std::path::Path| d.join("t.h").to_str().unwrap().to_owned();
    run(&[&draw[..], &["--format", "c-header", "-o", &table(&whole)]].concat());
    // Shards in reverse order: the merge must not depend on it.
    for i in (0..3).rev() {
        let shard = format!("{i}/3");
        run(&[&draw[..], &["--shard", &shard, "-o", &table(&parts)]].concat());
    }
    let merge = [
        "tables",
        "--merge",
        "--format",
        "c-header",
        "-o",
        &table(&parts),
    ];
    run(&merge);
    assert_eq!(
        std::fs::read(whole.join("t.h")).unwrap(),
        std::fs::read(parts.join("t.h")).unwrap(),
        "the merged table differs from the single run's"
    );
    // A shard file tampered with: a set held twice, a set cut short.
    let shard0 = parts.join("t.h.shard-0-of-3.json");
    let original = std::fs::read_to_string(&shard0).unwrap();
    type Tamper = fn(&mut serde_json::Value);
    let tampered: [(&str, Tamper); 2] = [
        ("holds set 0 twice", |v| {
            let first = v["sets"][0].clone();
            v["sets"].as_array_mut().unwrap().push(first);
        }),
        ("every set to have the same N (found 63 and 64)", |v| {
            let coords = v["sets"][0][1].as_array_mut().unwrap();
            coords.truncate(coords.len() - 2);
        }),
    ];
    for (phrase, tamper) in tampered {
        let mut v: serde_json::Value = serde_json::from_str(&original).unwrap();
        tamper(&mut v);
        std::fs::write(&shard0, v.to_string()).unwrap();
        let out = varspec(&merge);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(phrase),
            "{phrase}: {err}"
        );
    }
    std::fs::write(&shard0, original).unwrap();
    // Every shard claiming 10^18 sets: the claim is not allocated (a vector
    // of 10^18 slots aborted), the first set no shard holds is named.
    let names: Vec<_> = (0..3)
        .map(|i| parts.join(format!("t.h.shard-{i}-of-3.json")))
        .collect();
    let kept: Vec<String> = names
        .iter()
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    for (path, text) in names.iter().zip(&kept) {
        let mut v: serde_json::Value = serde_json::from_str(text).unwrap();
        v["run"]["sets"] = serde_json::json!(1_000_000_000_000_000_000u64);
        std::fs::write(path, v.to_string()).unwrap();
    }
    let out = varspec(&merge);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("set 10 is in no shard"),
        "{err}"
    );
    for (path, text) in names.iter().zip(&kept) {
        std::fs::write(path, text).unwrap();
    }
    std::fs::remove_file(parts.join("t.h.shard-1-of-3.json")).unwrap();
    let out = varspec(&merge);
    assert!(String::from_utf8_lossy(&out.stderr).contains("shard 1/3 is missing"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Without --format the output's name says it (.csv, .json, .h): the table
/// is byte for byte the one --format writes; a name that says none (raw
/// floats have no conventional extension) is refused naming the choices.
#[test]
fn the_format_follows_the_output_name() {
    let d = dir("named");
    std::fs::create_dir_all(&d).unwrap();
    for (ext, format) in [("csv", "csv"), ("json", "json"), ("h", "c-header")] {
        let (named, given) = (
            d.join(format!("named.{ext}")),
            d.join(format!("given.{ext}")),
        );
        let draw = ["tables", "--sampler", "cmj", "-n", "16", "--sets", "2"];
        varspec(&[&draw[..], &["-o", named.to_str().unwrap()]].concat());
        varspec(
            &[
                &draw[..],
                &["--format", format, "-o", given.to_str().unwrap()],
            ]
            .concat(),
        );
        let (a, b) = (
            std::fs::read(&named).unwrap(),
            std::fs::read(&given).unwrap(),
        );
        // The C header may name its file (an include guard): compare the rest.
        let strip = |bytes: &[u8], name: &str| {
            String::from_utf8_lossy(bytes)
                .replace(name, "")
                .replace(&name.to_uppercase(), "")
        };
        assert_eq!(strip(&a, "named"), strip(&b, "given"), "{ext}");
    }
    let out = Command::new(env!("CARGO_BIN_EXE_varspec"))
        .args(["tables", "--sampler", "cmj", "-n", "16", "-o"])
        .arg(d.join("t.bin"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("does not name one (.csv, .json, .h, .hpp)"),
        "{err}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

/// The sidecar records the parameters the sampler was built with, in one
/// place: `cmj:m=4 --param m=2` is cmj with m = 2 (the flag wins), and said
/// `source: cmj:m=4, params: [m=2]` before (third trial).
#[test]
fn the_metadata_names_the_parameters_used() {
    let dir = crate::common::temp_dir("tables-params");
    let both = dir.join("both.csv");
    let flag = dir.join("flag.csv");
    for (sampler, path) in [("cmj:m=4", &both), ("cmj", &flag)] {
        crate::common::varspec_ok(&[
            "tables",
            "--sampler",
            sampler,
            "-n",
            "16",
            "--param",
            "m=2",
            "--sets",
            "1",
            "-o",
            path.to_str().unwrap(),
        ]);
    }
    assert_eq!(std::fs::read(&both).unwrap(), std::fs::read(&flag).unwrap());
    let meta = crate::common::read_json(&dir.join("both.csv.json"));
    assert_eq!(meta["source"], "cmj", "{meta}");
    assert_eq!(meta["params"], serde_json::json!([["m", "2"]]), "{meta}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// docs/formats.md shows a C header with the command that writes it: the
/// example's lines up to the first point are the command's output (the
/// predicted variances in the docs had gone stale by the 10th digit:
/// third new-user trial).
#[test]
fn the_documented_c_header_is_what_the_command_writes() {
    let docs = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/formats.md"))
        .expect("docs/formats.md");
    let command =
        "varspec tables --sampler cmj -n 256 --sets 64 --param m=16 --format c-header -o cmj256.h";
    assert!(
        docs.contains(command),
        "the docs no longer show `{command}`"
    );
    let example = docs
        .split("```c\n")
        .nth(1)
        .and_then(|block| block.split("\n```").next())
        .expect("a ```c block in docs/formats.md");
    let d = dir("documented");
    let out = d.join("cmj256.h");
    let mut args: Vec<&str> = command.split(' ').skip(1).collect();
    *args.last_mut().unwrap() = out.to_str().unwrap();
    varspec(&args);
    let written = std::fs::read_to_string(&out).unwrap();
    // The example's lines up to and including the first point; the rest
    // is elided with "…".
    let shown: Vec<&str> = example.lines().take_while(|l| !l.contains('…')).collect();
    let actual: Vec<&str> = written.lines().take(shown.len()).collect();
    assert_eq!(
        shown, actual,
        "docs/formats.md's C header example differs from the output"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

/// A C header's identifier is the output's name up to its last `.`
/// (docs/formats.md): `.h` gives an empty name, so `table_` (it gave
/// `table__h`: fifth trial).
#[test]
fn a_c_header_is_named_by_the_file_name_up_to_its_last_dot() {
    let d = dir("c-names");
    for (file, id) in [
        (".h", "table_"),
        ("cmj.256.h", "cmj_256"),
        ("int.h", "table_int"),
    ] {
        let out = d.join(file);
        one_cmj_set(&["--format", "c-header", "-o", out.to_str().unwrap()]);
        let header = std::fs::read_to_string(&out).unwrap();
        assert!(
            header.contains(&format!("static const float {id}[1][4][2]")),
            "{file}: {header}"
        );
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// A padded 4D table says which dimensions are which half, and what drew
/// each (fifth trial: a renderer author could not tell).
#[test]
fn padded_tables_name_their_halves() {
    let d = dir("halves");
    for (sampler, params, expected) in [
        (
            "padded",
            vec!["--param", "xy=cmj", "--param", "uv=sobol"],
            "dims 0, 1: (x, y) drawn by cmj; dims 2, 3: (u, v) drawn by sobol, independently",
        ),
        (
            "umj",
            vec![],
            "dims 0, 1: (x, y) drawn by mj; dims 2, 3: (u, v) drawn by mj, independently",
        ),
    ] {
        let out = d.join(format!("{sampler}.h"));
        let mut args = vec!["tables", "--sampler", sampler, "-n", "16", "--sets", "1"];
        args.extend(params);
        args.extend(["-o", out.to_str().unwrap()]);
        varspec(&args);
        let header = std::fs::read_to_string(&out).unwrap();
        assert!(header.contains(expected), "{sampler}: {header}");
        let csv = d.join(format!("{sampler}.csv"));
        args.pop();
        args.push(csv.to_str().unwrap());
        varspec(&args);
        let meta = sidecar(&csv);
        assert!(
            meta.dimensions.as_deref().unwrap().starts_with(expected),
            "{meta:?}"
        );
    }
    // A sampler without halves says nothing.
    let csv = d.join("sobol.csv");
    varspec(&[
        "tables",
        "--sampler",
        "sobol",
        "-d",
        "4",
        "-n",
        "16",
        "--sets",
        "1",
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(sidecar(&csv).dimensions, None);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn tables_that_contradict_their_shape_are_refused_by_name() {
    use crate::common::assert_fails;
    let d = dir("refused");
    let t = |name: &str| d.join(name).to_str().unwrap().to_owned();
    for format in ["f32", "json", "c-header"] {
        varspec(&[
            "tables",
            "--sampler",
            "cmj",
            "-n",
            "16",
            "--sets",
            "2",
            "--format",
            format,
            "-o",
            &t(&format!("t.{format}")),
        ]);
    }
    fn spectrum(file: &str) -> [&str; 6] {
        ["spectrum", file, "--res", "4", "--csv", "/dev/null"]
    }
    // A raw table cut short: the sidecar's shape needs 256 bytes.
    let raw = std::fs::read(t("t.f32")).unwrap();
    std::fs::write(t("short.f32"), &raw[..100]).unwrap();
    std::fs::copy(t("t.f32.json"), t("short.f32.json")).unwrap();
    assert_fails(
        &spectrum(&t("short.f32")),
        "100 bytes, where its metadata's 2 sets x 16 points x 2 dimensions x 4 bytes need 256",
    );
    // The same bytes with no sidecar, and with one that is not metadata.
    std::fs::write(t("bare.f32"), &raw).unwrap();
    assert_fails(
        &spectrum(&t("bare.f32")),
        "read through its metadata sidecar",
    );
    std::fs::write(t("bad.f32"), &raw).unwrap();
    std::fs::write(t("bad.f32.json"), "[1, 2]").unwrap();
    assert_fails(&spectrum(&t("bad.f32")), "its sidecar is unreadable");
    // The sidecar given in place of its table.
    assert_fails(
        &spectrum(&t("t.f32.json")),
        "this is a table's metadata sidecar",
    );
    // A JSON table whose metadata says more sets than it holds.
    let json = std::fs::read_to_string(t("t.json")).unwrap();
    assert!(json.contains("\"sets\":2,"), "{json}");
    std::fs::write(
        t("more.json"),
        json.replacen("\"sets\":2,", "\"sets\":3,", 1),
    )
    .unwrap();
    assert_fails(
        &spectrum(&t("more.json")),
        "it holds 2 sets of 16 points in 2D, its metadata says 3 of 16 in 2D",
    );
    // Ragged points and a value of 1.
    std::fs::write(t("ragged.json"), r#"{"sets": [[[0.1, 0.2], [0.3]]]}"#).unwrap();
    assert_fails(
        &spectrum(&t("ragged.json")),
        "set 0, point 1 has 1 coordinate, where the first has 2",
    );
    std::fs::write(t("one.json"), r#"{"sets": [[[0.1, 1.0]]]}"#).unwrap();
    assert_fails(
        &spectrum(&t("one.json")),
        "coordinate 1 is 1, outside [0, 1)",
    );
    // A C header with a point removed.
    let header = std::fs::read_to_string(t("t.c-header")).unwrap();
    let first_point = header.find("    {").unwrap();
    let end = first_point + header[first_point..].find('\n').unwrap() + 1;
    std::fs::write(
        t("cut.h"),
        format!("{}{}", &header[..first_point], &header[end..]),
    )
    .unwrap();
    assert_fails(
        &spectrum(&t("cut.h")),
        "the array [2][16][2] holds 62 values",
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_table_converted_from_a_table_keeps_its_provenance() {
    let d = dir("provenance");
    let t = |name: &str| d.join(name).to_str().unwrap().to_owned();
    varspec(&[
        "tables",
        "--sampler",
        "umj",
        "-n",
        "16",
        "--sets",
        "2",
        "--seed",
        "7",
        "--format",
        "f32",
        "-o",
        &t("u.f32"),
    ]);
    varspec(&[
        "tables",
        "--from",
        &t("u.f32"),
        "--format",
        "json",
        "-o",
        &t("u.json"),
    ]);
    varspec(&["tables", "--from", &t("u.json"), "-o", &t("u.h")]);
    // The C header carries it in its comment (it lost it: `tables --from
    // t.h` recorded the header's path as the source and no seed).
    varspec(&[
        "tables",
        "--from",
        &t("u.h"),
        "--format",
        "f64",
        "-o",
        &t("u.f64"),
    ]);
    let first = sidecar(Path::new(&t("u.f32")));
    let last = sidecar(Path::new(&t("u.f64")));
    assert_eq!(last.seed, Some(7));
    assert_eq!(last.source, "umj");
    assert_eq!(
        (&last.params, &last.optimized_for, &last.dimensions),
        (&first.params, &first.optimized_for, &first.dimensions)
    );
    assert!(last.layout.contains("f64 (double)"), "{}", last.layout);
    // A CSV whose sidecar no longer describes it (a set removed by hand)
    // is converted as a plain point file: no seed is claimed.
    let cmj_csv = || {
        varspec(&[
            "tables",
            "--sampler",
            "cmj",
            "-n",
            "4",
            "--sets",
            "2",
            "--seed",
            "3",
            "-o",
            &t("c.csv"),
        ])
    };
    cmj_csv();
    let csv = std::fs::read_to_string(t("c.csv")).unwrap();
    let one_set: String = csv
        .lines()
        .filter(|l| !l.starts_with("1,"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(t("c.csv"), one_set).unwrap();
    varspec(&[
        "tables",
        "--from",
        &t("c.csv"),
        "--format",
        "f64",
        "-o",
        &t("c.f64"),
    ]);
    let stale = sidecar(Path::new(&t("c.f64")));
    assert_eq!((stale.seed, stale.sets), (None, 1));
    assert_eq!(stale.source, t("c.csv"));
    // Nor is a sidecar of the same shape left beside points written over
    // its table (they were labelled `cmj (seed 3)`: new-user trial); the
    // values' digest tells them apart, and a note says so.
    cmj_csv();
    varspec(&[
        "sample",
        "random",
        "-n",
        "4",
        "--sets",
        "2",
        "--seed",
        "9",
        "-o",
        &t("c.csv"),
    ]);
    let note = varspec(&["tables", "--from", &t("c.csv"), "-o", &t("r.json")]);
    let meta = crate::common::read_json(&d.join("r.json"))["metadata"].clone();
    assert_eq!(
        (&meta["source"], &meta["seed"]),
        (&t("c.csv").into(), &serde_json::Value::Null),
        "{meta}"
    );
    assert!(note.contains("does not describe"), "{note}");
    // A table whose own metadata no longer describes its values (one value
    // edited by hand) is not carried either, and a note names which
    // metadata it was (they were dropped without a word).
    for (format, name, values, place) in [
        (
            "c-header",
            "edited.h",
            "= {",
            "the `metadata (JSON)` line of",
        ),
        (
            "json",
            "edited.json",
            "\"sets\":[[[",
            "the `metadata` field of",
        ),
    ] {
        one_cmj_set(&["--seed", "3", "--format", format, "-o", &t(name)]);
        // The first value after the metadata, 0.0876…, becomes 0.50876….
        let mut text = std::fs::read_to_string(d.join(name)).unwrap();
        let array = text.find(values).unwrap();
        let first = array + text[array..].find("0.").unwrap();
        text.replace_range(first..first + 2, "0.5");
        std::fs::write(d.join(name), &text).unwrap();
        let note = varspec(&["tables", "--from", &t(name), "-o", &t("from-edited.json")]);
        let meta = crate::common::read_json(&d.join("from-edited.json"))["metadata"].clone();
        assert_eq!(
            (&meta["source"], &meta["seed"]),
            (&t(name).into(), &serde_json::Value::Null),
            "{format}: {meta}"
        );
        assert!(
            note.contains(&format!(
                "note: {place} {} does not describe its values",
                t(name)
            )),
            "{format}: {note}"
        );
    }
    // The input's sidecar is an input too: writing it is refused.
    crate::common::assert_fails(
        &[
            "tables",
            "--from",
            &t("u.f32"),
            "--format",
            "json",
            "-o",
            &t("u.f32.json"),
        ],
        "is both an input and an output",
    );
    // A source whose path holds `*/` does not close the header's comment
    // early, and reads back as written.
    std::fs::create_dir(d.join("a*")).unwrap();
    std::fs::write(t("a*/p.csv"), "x0,x1\n0.25,0.5\n0.75,0.125\n").unwrap();
    varspec(&["tables", "--from", &t("a*/p.csv"), "-o", &t("p.h")]);
    let header = std::fs::read_to_string(t("p.h")).unwrap();
    let comment_ends = header
        .split("#ifndef")
        .next()
        .unwrap()
        .matches("*/")
        .count();
    assert_eq!(comment_ends, 1, "{header}");
    varspec(&["tables", "--from", &t("p.h"), "-o", &t("p.json")]);
    let meta = crate::common::read_json(&d.join("p.json"))["metadata"].clone();
    assert_eq!(meta["source"], t("a*/p.csv"), "{meta}");
    // FNV-1a 64 of the four values' binary64 bytes, computed in Python
    // (struct.pack('<d', v), offset 0xcbf29ce484222325, prime 0x100000001b3).
    assert_eq!(meta["values_digest"], "fnv1a64:3ace574b5a78264d", "{meta}");
    std::fs::remove_dir_all(&d).unwrap();
}
