//! The command line as scripts use it: determinism across thread counts,
//! exit codes and messages on bad input, the sampler list, pictures.

use crate::common;
use common::{temp_dir, varspec, varspec_with};

#[test]
fn same_seed_gives_identical_bytes_on_one_and_two_threads() {
    for (sampler, n, extra) in [
        ("random", "100", vec![]),
        ("jitter", "64", vec![]),
        ("cmj", "60", vec![]),
        ("umj", "64", vec![]),
        ("poisson-disk", "200", vec!["-d", "3"]),
        ("sobol", "128", vec![]),
        ("halton", "50", vec![]),
        ("nrooks", "33", vec!["-d", "4"]),
        ("blue-noise", "64", vec!["--param", "iters=50"]),
    ] {
        let mut args = vec!["sample", sampler, "-n", n, "--sets", "16", "--seed", "42"];
        args.extend(extra);
        let one = varspec_with(&args, Some("1"));
        let two = varspec_with(&args, Some("2"));
        assert!(
            one.status.success(),
            "{sampler}: {}",
            String::from_utf8_lossy(&one.stderr)
        );
        assert!(
            one.stdout == two.stdout,
            "{sampler}: output differs between 1 and 2 threads"
        );
        assert!(
            one.stderr.is_empty(),
            "{sampler}: no progress bar off a terminal"
        );
        let other_seed = varspec_with(
            &["sample", sampler, "-n", n, "--sets", "16", "--seed", "43"],
            Some("2"),
        );
        assert!(one.stdout != other_seed.stdout, "{sampler}: seed ignored");
    }
}

#[test]
fn output_file_matches_stdout_and_reads_back() {
    let dir = temp_dir("sample-out");
    let path = dir.join("j.csv");
    let file_run = varspec(&[
        "sample",
        "jitter",
        "-n",
        "16",
        "--sets",
        "3",
        "-o",
        path.to_str().unwrap(),
    ]);
    assert!(file_run.status.success());
    // A file written is confirmed with what it holds.
    assert_eq!(
        String::from_utf8_lossy(&file_run.stdout),
        format!("wrote {}: 3 sets of jitter N=16 in 2D\n", path.display())
    );
    let stdout_run = varspec(&["sample", "jitter", "-n", "16", "--sets", "3"]);
    assert_eq!(std::fs::read(&path).unwrap(), stdout_run.stdout);
    let sets = varspec::io::read_point_sets(&path).unwrap();
    assert_eq!((sets.len(), sets[0].len(), sets[0].dim()), (3, 16, 2));
    // Scientific notation names a whole count too.
    let sci = varspec(&["sample", "random", "-n", "1e3", "--sets", "1"]);
    assert_eq!(String::from_utf8_lossy(&sci.stdout).lines().count(), 1001);
    let utk = varspec(&[
        "sample", "sobol", "-n", "8", "--sets", "1", "--format", "utk",
    ]);
    let text = String::from_utf8(utk.stdout).unwrap();
    assert_eq!(text.lines().count(), 8);
    assert!(text.lines().all(|l| l.split(' ').count() == 2));
    // -o /dev/stdout into a pipe (Output captures stdout through one):
    // /dev/stdout leads to /proc/self/fd/1, whose link text "pipe:[…]" is
    // no path; the bytes must go through the link.
    #[cfg(target_os = "linux")]
    {
        let piped = common::varspec_ok(&[
            "sample",
            "jitter",
            "-n",
            "16",
            "--sets",
            "3",
            "-o",
            "/dev/stdout",
        ]);
        assert_eq!(piped.stdout, stdout_run.stdout);
        // Standard output appending to a file (`>> log`): the bytes go
        // through the descriptor, after what the file held, not over it.
        let log = dir.join("log.txt");
        std::fs::write(&log, "kept\n").unwrap();
        let appending = std::fs::OpenOptions::new().append(true).open(&log).unwrap();
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_varspec"))
            .args([
                "sample",
                "jitter",
                "-n",
                "16",
                "--sets",
                "3",
                "-o",
                "/dev/stdout",
            ])
            .stdout(appending)
            .status()
            .unwrap();
        assert!(status.success());
        let mut expected = b"kept\n".to_vec();
        expected.extend_from_slice(&stdout_run.stdout);
        assert_eq!(std::fs::read(&log).unwrap(), expected);
        // A command's own lines go to standard error while standard output
        // carries a file: a PNG through a pipe stays a PNG.
        let png = common::varspec_ok(&[
            "spectrum",
            "--sampler",
            "jitter",
            "-n",
            "64",
            "--res",
            "32",
            "--png",
            "/dev/stdout",
        ]);
        assert!(
            png.stdout.starts_with(b"\x89PNG\r\n\x1a\n"),
            "{:?}",
            &png.stdout[..16.min(png.stdout.len())]
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_requests_fail_with_a_specific_message() {
    for (args, phrase) in [
        (
            vec!["sample", "jitter", "-n", "1000"],
            "nearest valid N: 961 or 1024",
        ),
        (vec!["sample", "jitter", "-n", "30", "-d", "3"], "27 or 64"),
        // predict draws jitter in the integrand's dimension (4 here, though
        // no -d was given): the refusal says which, as N = m^d depends on it.
        (
            vec![
                "predict",
                "--sampler",
                "jitter",
                "-n",
                "200",
                "--integrand",
                "defocus:c=0.5",
            ],
            "jitter in 4D: N = 200 does not fit",
        ),
        (vec!["sample", "nope", "-n", "10"], "known samplers: random"),
        // A close miss names what was meant (src/suggest.rs); a far one not.
        (
            vec!["sample", "poison-disk", "-n", "10"],
            "unknown sampler `poison-disk` (did you mean `poisson-disk`?); known samplers",
        ),
        (
            vec!["sample", "Sobol", "-n", "10"],
            "(did you mean `sobol`?)",
        ),
        (
            vec![
                "predict",
                "--sampler",
                "jitter",
                "-n",
                "16",
                "--integrand",
                "gausian",
            ],
            "unknown integrand `gausian` (did you mean `gaussian`?)",
        ),
        (
            vec![
                "predict",
                "--sampler",
                "jitter",
                "-n",
                "16",
                "--integrand",
                "box:angel=3",
            ],
            "unknown parameter `angel` (did you mean `angle`?)",
        ),
        (
            vec!["render", "shadows-sqare", "-o", "never.png"],
            "no scene `shadows-sqare` (did you mean `shadows-square`?)",
        ),
        (
            vec!["sample", "cmj", "-n", "10", "-d", "3"],
            "dimension 3 is not supported",
        ),
        (vec!["sample", "random", "-n", "0"], "at least 1"),
        (
            vec!["sample", "random", "-n", "10", "--param", "radius=2"],
            "unknown parameter `radius`",
        ),
        (
            vec![
                "sample",
                "poisson-disk",
                "-n",
                "10",
                "--param",
                "radius=1.5",
            ],
            "radius=1.5 is invalid",
        ),
        (
            vec!["sample", "multijitter", "-n", "10", "--param", "m=3"],
            "a divisor of N = 10",
        ),
        (
            vec!["sample", "random", "-n", "10", "--param", "novalue"],
            "key=value",
        ),
        (
            vec![
                "sample",
                "random",
                "-n",
                "4",
                "-o",
                "/nonexistent-dir/x.csv",
            ],
            "/nonexistent-dir/x.csv",
        ),
        (
            vec![
                "optimize",
                "shear",
                "-n",
                "64",
                "--integrand",
                "defocus:c=0.5",
                "--range",
                "1e300",
            ],
            "--range 1e300: the search's half-width must be a positive number up to 64",
        ),
        (
            vec![
                "optimize",
                "shear",
                "-n",
                "64",
                "--integrand",
                "defocus:c=0.5",
                "--range",
                "inf",
            ],
            "--range inf: the search's half-width",
        ),
        (
            vec![
                "predict",
                "--sampler",
                "jitter",
                "-n",
                "64",
                "--integrand",
                "disk:r=0.3,r=0.2",
            ],
            "`r` is given twice",
        ),
        (
            vec![
                "predict",
                "--sampler",
                "jitter",
                "-n",
                "64",
                "--integrand",
                "disk:r=0.3",
                "--res",
                "2",
            ],
            "`2`: the box |k| < K/2 needs a whole K >= 3",
        ),
        (
            vec!["spectrum", "--sampler", "jitter", "-n", "64", "--res", "2"],
            "`2`: the box |k| < K/2 needs a whole K >= 3",
        ),
        (
            vec![
                "pcf",
                "--sampler",
                "jitter",
                "-n",
                "64",
                "--bandwidth",
                "1e-300",
            ],
            "--bandwidth 1e-300: the kernel's σ",
        ),
        (
            vec![
                "optimize", "points", "-n", "64", "--target", "blue", "-o", "x.csv",
            ],
            "nor family:disks, power:A or radial:FILE.csv",
        ),
        (
            vec![
                "optimize",
                "points",
                "-n",
                "64",
                "--target",
                "family:disks",
                "--iters",
                "0",
                "-o",
                "x.csv",
            ],
            "the number of iterations (--iters) is 0",
        ),
        (
            vec![
                "predict",
                "--sampler",
                "cmj",
                "-n",
                "64",
                "--integrand",
                "defocus",
            ],
            "draw them in 4D with -d 4",
        ),
        (
            vec!["sample", "random", "-n", "-1"],
            "`-1` is negative; a count of points is a whole number >= 1",
        ),
        (
            vec!["sample", "random", "-n", "2.5"],
            "`2.5` is not a whole number of points",
        ),
        (
            vec![
                "predict",
                "--sampler",
                "jitter",
                "-n",
                "1e300",
                "--integrand",
                "disk",
            ],
            "`1e300` is more points than this tool holds",
        ),
        (
            vec!["sample", "random", "-n", "4", "-o", "."],
            "it is a folder; give a file name inside it",
        ),
        (
            vec!["sample", "random", "-n", "4", "-o", "somedir/"],
            "it is a folder",
        ),
    ] {
        common::assert_fails(&args, phrase);
    }
}

/// The label of a drawn source is the sampler as it runs: `--param` wins
/// over the shorthand, in the sets and in the name (the name kept the
/// shorthand's cmj while jitter ran: trial).
#[test]
fn a_param_override_names_the_sampler_as_it_runs() {
    let predict = |extra: &[&str]| {
        let mut args = vec![
            "predict",
            "-n",
            "16",
            "--dims",
            "0,1",
            "--integrand",
            "disk:r=0.3",
        ];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--method", "spatial", "--json"]);
        let out = varspec(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (
            v["source"].clone(),
            v["spatial"]["variance"].as_f64().unwrap(),
        )
    };
    let (name, overridden) = predict(&[
        "--sampler",
        "padded:xy=cmj,uv=jitter",
        "--param",
        "xy=jitter",
    ]);
    let (_, direct) = predict(&["--sampler", "padded:xy=jitter,uv=jitter"]);
    let (_, cmj) = predict(&["--sampler", "padded:xy=cmj,uv=jitter"]);
    assert_eq!(name, "padded:xy=jitter,uv=jitter N=16");
    assert_eq!(overridden, direct, "--param xy=jitter did not draw jitter");
    assert_ne!(overridden, cmj);
}

#[test]
fn a_file_source_refuses_the_sampler_options_it_would_ignore() {
    let dir = temp_dir("filesrc");
    let path = dir.join("j.csv");
    let file = path.to_str().unwrap();
    assert!(
        varspec(&["sample", "jitter", "-n", "64", "--sets", "2", "-o", file])
            .status
            .success()
    );
    for extra in [
        vec!["-n", "100"],
        vec!["--sets", "4"],
        vec!["--param", "m=2"],
        vec!["-d", "2"],
    ] {
        let mut args = vec!["predict", file, "--integrand", "disk:r=0.3"];
        args.extend(extra);
        common::assert_fails(&args, "apply to --sampler");
    }
    let mut tables = vec![
        "tables", "--from", file, "--format", "csv", "--sets", "3", "-o",
    ];
    let out = dir.join("t.csv");
    tables.push(out.to_str().unwrap());
    common::assert_fails(&tables, "apply to --sampler");
    // One set: the spatial form's standard error is unknown, not 0.
    let one = varspec(&[
        "predict",
        "--sampler",
        "jitter",
        "-n",
        "64",
        "--sets",
        "1",
        "--integrand",
        "disk:r=0.3",
    ]);
    let text = String::from_utf8_lossy(&one.stdout);
    assert!(text.contains("stderr unknown (one set"), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_search_that_finds_nothing_better_says_so() {
    // No defocus: the answer is no shear, and the report must not claim a gain.
    let out = common::varspec(&[
        "optimize",
        "shear",
        "-n",
        "64",
        "--integrand",
        "defocus:c=0",
        "--realizations",
        "0",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("(unchanged)"), "{text}");
    assert!(text.contains("shear a = 0.0000, b = 0.0000"), "{text}");
}

#[test]
fn outputs_are_checked_before_the_work_starts() {
    // Each of these would run for minutes before writing; the bad output
    // must be refused at once, before any progress is made.
    for args in [
        vec![
            "optimize",
            "points",
            "-n",
            "4096",
            "--target",
            "blue",
            "--iters",
            "100000",
            "-o",
            "/nodir/x.csv",
        ],
        vec![
            "optimize",
            "points",
            "-n",
            "16",
            "--target",
            "blue",
            "-o",
            "ok.csv",
            "--report",
            "/nodir/r.json",
        ],
        vec![
            "spectrum",
            "--sampler",
            "random",
            "-n",
            "64",
            "--csv",
            "ok.csv",
            "--png",
            "/nodir/x.png",
        ],
        vec![
            "render",
            "dof",
            "--spp",
            "1024",
            "--renders",
            "64",
            "--summary",
            "/nodir/s.json",
        ],
        vec![
            "tables",
            "--sampler",
            "cmj",
            "-n",
            "64",
            "--format",
            "csv",
            "-o",
            "/nodir/t.csv",
        ],
    ] {
        let start = std::time::Instant::now();
        common::assert_fails(&args, "the folder /nodir does not exist");
        // Not a timing goal: a generous bound that only a run doing the
        // work first (minutes) would exceed.
        assert!(
            start.elapsed().as_secs() < 20,
            "{args:?} did the work first"
        );
    }
    assert!(
        !std::path::Path::new("ok.csv").exists(),
        "a partial output was written"
    );
}

#[test]
fn list_names_every_sampler_with_constraints() {
    let out = varspec(&["sample", "--list"]);
    let text = String::from_utf8(out.stdout).unwrap();
    for info in varspec::registry::SAMPLERS {
        assert!(
            text.contains(info.name) && text.contains(info.count),
            "{} missing from --list",
            info.name
        );
        for p in info.params {
            assert!(text.contains(&format!("--param {}=", p.key)));
        }
    }
}

#[test]
fn plot_draws_a_projection_and_reports_bad_files_by_line() {
    let dir = temp_dir("plot");
    let points = dir.join("umj.csv");
    let png = dir.join("xu.png");
    assert!(
        varspec(&["sample", "umj", "-n", "64", "-o", points.to_str().unwrap()])
            .status
            .success()
    );
    let out = varspec(&[
        "plot",
        "points",
        points.to_str().unwrap(),
        "--dims",
        "0,2",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        format!(
            "wrote {}: set 0 of {}, dimensions 0 and 2\n",
            png.display(),
            points.display()
        )
    );
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (512, 512));
    let bad_dims = varspec(&[
        "plot",
        "points",
        points.to_str().unwrap(),
        "--dims",
        "0,4",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(String::from_utf8_lossy(&bad_dims.stderr).contains("out of range"));
    // An empty name is refused before the work (it printed "wrote :" and
    // then failed: fifth trial).
    let empty = varspec(&["plot", "points", points.to_str().unwrap(), "-o", ""]);
    let err = String::from_utf8_lossy(&empty.stderr);
    assert!(
        !empty.status.success() && empty.stdout.is_empty() && err.contains("an empty file name"),
        "{err}"
    );
    // A 1D set is a strip of ticks (it was refused: third trial): at 64
    // pixels, the points 0.25 and 0.75 ink exactly the column pairs their
    // centres 15.5 and 47.5 straddle.
    let line = dir.join("line.csv");
    std::fs::write(&line, "x0\n0.25\n0.75\n").unwrap();
    common::varspec_ok(&[
        "plot",
        "points",
        line.to_str().unwrap(),
        "--size",
        "64",
        "-o",
        png.to_str().unwrap(),
    ]);
    let strip = image::open(&png).unwrap().to_rgb8();
    assert_eq!(strip.dimensions(), (64, 16));
    let inked: Vec<u32> = (1..63)
        .filter(|&x| strip.get_pixel(x, 8).0 != [255, 255, 255])
        .collect();
    assert_eq!(inked, [15, 16, 47, 48]);
    let broken = dir.join("broken.csv");
    std::fs::write(&broken, "x0,x1\n0.5,0.5\n0.5,1.5\n").unwrap();
    let out = varspec(&[
        "plot",
        "points",
        broken.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("broken.csv:3:") && err.contains("1.5"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn compare_writes_a_table_and_pictures() {
    let dir = temp_dir("compare");
    let out = varspec(&[
        "compare",
        "-n",
        "100",
        "--sets",
        "2",
        "--seed",
        "11",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8(out.stdout).unwrap();
    assert!(table.contains("poisson-disk") && table.contains("sobol") && table.contains("lattice"));
    let summary = std::fs::read_to_string(dir.join("summary.csv")).unwrap();
    assert_eq!(summary.lines().count(), 12, "a header and 11 samplers");
    // The seed is recorded, so the pictures can be redrawn (trial).
    assert!(
        summary.starts_with("sampler,n,sets,seed,") && summary.contains(",2,11,"),
        "{summary}"
    );
    assert!(dir.join("cmj.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The report's integrand and pixel are checked before any work: a bad
/// one fails at once, naming the option, and leaves no folder (it used to
/// run two sections, 17 s, then fail with an empty folder left behind).
#[test]
fn a_bad_report_option_fails_before_any_work_and_leaves_no_folder() {
    let dir = std::env::temp_dir().join(format!("varspec-badreport-{}", std::process::id()));
    let out = dir.join("rep");
    let o = out.to_str().unwrap();
    common::assert_fails(&["report", "-o", o, "--pixel", "disk:r=0.3"], "--pixel");
    common::assert_fails(
        &["report", "-o", o, "--integrand", "defocus:c=0.5"],
        "--integrand",
    );
    assert!(!out.exists(), "a failed report left {}", out.display());
    // A folder that cannot be created is named (it said only "Not a
    // directory": trial).
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("afile");
    std::fs::write(&file, "").unwrap();
    let under = file.join("sub");
    common::assert_fails(
        &["report", "-o", under.to_str().unwrap()],
        &format!("creating the report folder: {}", under.display()),
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_main_job_writes_a_self_contained_report() {
    let dir = std::env::temp_dir().join(format!("varspec-report-{}", std::process::id()));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_varspec"))
        .args([
            "report",
            "-n",
            // Not a square: jitter needs 64, and every row is compared
            // there (random ran at 63 beside jitter at 64: third trial).
            "63",
            "--sets",
            "4",
            // Not the default, so the printed commands must carry it (the
            // scene's and a spectrum's did not: second trial).
            "--seed",
            "5",
            "-o",
            dir.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    for section in [
        "1. Classic samplers",
        "2. Designs for the unit square",
        "3. Shear search",
        "4. The scene",
        "5. Speed against error",
    ] {
        assert!(html.contains(section), "missing section {section}");
    }
    // The scene's per-pixel warp lowers the mean pixel variance (measured
    // 2.8x at 64 spp over 16 renders; 4 renders of 65,536 pixels leave the
    // mean's relative error near 1%, so 1.5x is far outside noise).
    // Pictures are embedded, so the page stands alone.
    assert!(html.matches("data:image/png;base64,").count() >= 10);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    // The summary line's square ratio is the design's half-plane MSE over
    // CMJ's row (it once divided by the third row, jitter's).
    let square = report["square"]["rows"].as_array().unwrap();
    let halfplanes = |name: &str| {
        square
            .iter()
            .find(|r| r["name"].as_str().unwrap().starts_with(name))
            .unwrap_or_else(|| panic!("no {name} row: {square:?}"))["halfplanes"]
            .as_f64()
            .unwrap()
    };
    let ratio = halfplanes("designed") / halfplanes("cmj");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!("square design {ratio:.2}x CMJ")),
        "{stdout} vs {ratio:.2}"
    );
    let rows = report["predict"]["rows"].as_array().unwrap();
    assert!(
        rows.iter().all(|r| r["n"] == 64) && report["predict"]["n"] == 64,
        "rows at other N than jitter's 64: {rows:?}"
    );
    assert!(
        html.contains("the nearest N to the requested 63 that jitter allows"),
        "the page does not say N moved"
    );
    // The three predictors agree: spatial, and Fourier up to its
    // truncation bound, within the empirical 95% CI for jitter.
    let jitter = &rows[1];
    assert_eq!(jitter["sampler"], "jitter");
    let value = |key: &str| jitter[key].as_f64().unwrap();
    let (low, high) = (value("ci_low"), value("ci_high"));
    let spatial = value("spatial");
    assert!(low <= spatial && spatial <= high, "spatial: {jitter}");
    let (fourier, bound) = (value("fourier"), value("truncation_bound"));
    assert!(
        bound <= 0.1 * fourier && low - bound <= fourier && fourier <= high + bound,
        "fourier: {jitter}"
    );
    // The commands the page prints give its numbers: run them (file names
    // moved into the test's folder, --json where the numbers are printed).
    let run_printed = |section: &str, prefix: &str, json: bool| -> Vec<u8> {
        let commands = report[section]["commands"].as_array().unwrap();
        let line = commands
            .iter()
            .filter_map(|c| c.as_str())
            .find(|c| c.starts_with(prefix))
            .unwrap_or_else(|| panic!("{section}: no command `{prefix}…`"));
        let mut args: Vec<String> = line
            .split_whitespace()
            .skip(1)
            .map(|a| a.trim_matches('\'').to_string())
            .collect();
        for i in 0..args.len() {
            let file = [".csv", ".json", ".png"]
                .iter()
                .any(|ext| args[i].ends_with(ext));
            if file || (i > 0 && args[i - 1] == "--png-prefix") {
                args[i] = dir.join(&args[i]).to_str().unwrap().to_string();
            }
        }
        if json && !args.iter().any(|a| a == "--json") {
            args.push("--json".into());
        }
        let run = varspec(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(run.status.success(), "{line}: {run:?}");
        run.stdout
    };
    run_printed("predict", "varspec sample cmj ", false);
    let printed: serde_json::Value =
        serde_json::from_slice(&run_printed("predict", "varspec predict cmj.csv ", true)).unwrap();
    let cmj = &rows[2];
    assert_eq!(cmj["sampler"], "cmj");
    for (column, method) in [
        ("fourier", "fourier"),
        ("spatial", "spatial"),
        ("empirical", "empirical"),
    ] {
        assert_eq!(
            cmj[column].as_f64(),
            printed[method]["variance"].as_f64(),
            "the page's {column} column vs its printed predict command"
        );
    }
    let shear: serde_json::Value =
        serde_json::from_slice(&run_printed("shear", "varspec optimize shear ", true)).unwrap();
    let page = &report["shear"];
    for (column, value) in [
        ("optimum", &shear["objective"]["optimum"]),
        ("unsheared", &shear["objective"]["unsheared"]),
        ("check_before", &shear["variance_before"]["variance"]),
        ("check_after", &shear["variance_after"]["variance"]),
    ] {
        assert_eq!(page[column].as_f64(), value.as_f64(), "shear {column}");
    }
    run_printed("square", "varspec optimize points --domain square ", false);
    let square: serde_json::Value =
        serde_json::from_slice(&run_printed("square", "varspec predict --family ", true)).unwrap();
    let designed = &report["square"]["rows"][0];
    assert!(designed["name"].as_str().unwrap().starts_with("designed"));
    assert_eq!(
        designed["halfplanes"].as_f64(),
        square["brute_force"]["mse"].as_f64(),
        "the square section's design vs its printed commands"
    );
    // Section 5's commands write the two spectra its 1e-6 row compares
    // (it printed `bench spectrum`, which measures other sets: third
    // trial).
    let prefix = "varspec spectrum --sampler jitter -n 1024 --sets 8 --seed 5 --res 129";
    run_printed("speed", &format!("{prefix} --method direct"), false);
    run_printed("speed", &format!("{prefix} --tol 1e-6"), false);
    let column = |file: &str| -> Vec<f64> {
        let mut r = csv::Reader::from_path(dir.join(file)).unwrap();
        r.records()
            .map(|x| x.unwrap()[2].parse().unwrap())
            .collect()
    };
    let (exact, fast) = (column("exact.csv"), column("fast.csv"));
    assert_eq!(exact.len(), 129 * 129);
    let max_error = exact
        .iter()
        .zip(&fast)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let row = report["speed"]["rows"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["method"] == "NUFFT, tolerance 1e-6")
        .expect("a 1e-6 row");
    assert_eq!(row["max_error"].as_f64(), Some(max_error), "{row}");
    let scene = &report["scene"];
    assert!(scene["reduction"].as_f64().unwrap() > 1.5, "{scene}");
    // The scene's printed render gives its unsheared row.
    let summary = dir.join("render.json");
    let mut render: Vec<String> = report["scene"]["commands"][0]
        .as_str()
        .unwrap()
        .split_whitespace()
        .skip(1)
        .map(|a| match a {
            "none.png" => dir.join(a).to_str().unwrap().to_string(),
            _ => a.to_string(),
        })
        .collect();
    render.extend(["--summary".into(), summary.to_str().unwrap().into()]);
    render.extend(["-o".into(), dir.join("image.png").to_str().unwrap().into()]);
    common::varspec_ok(&render.iter().map(String::as_str).collect::<Vec<_>>());
    let rendered = common::read_json(&summary);
    assert_eq!(
        rendered["variance"]["mean"].as_f64(),
        scene["rows"][0]["mean_variance"].as_f64(),
        "the scene's printed render vs the page: {rendered}"
    );
    assert!(
        std::fs::read_to_string(dir.join("variances.csv"))
            .unwrap()
            .lines()
            .count()
            == 7
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn one_grammar_across_commands() {
    let dir = temp_dir("grammar");
    let out = |args: &[&str]| {
        let o = varspec(args);
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        o.stdout
    };
    // -n and --n, positional and --sampler, give the same sets.
    let a = out(&["sample", "cmj", "-n", "16", "--seed", "4"]);
    let b = out(&["sample", "--sampler", "cmj", "--n", "16", "--seed", "4"]);
    assert_eq!(a, b);
    // converge takes -n like every other command.
    out(&[
        "converge",
        "--sampler",
        "jitter",
        "--integrand",
        "disk:r=0.3",
        "-n",
        "16,64",
    ]);
    // The blue-noise sampler and optimize points share their descent defaults.
    let (s1, s2) = (dir.join("s1.csv"), dir.join("s2.csv"));
    out(&[
        "sample",
        "blue-noise",
        "-n",
        "64",
        "--seed",
        "3",
        "-o",
        s1.to_str().unwrap(),
    ]);
    let design = ["optimize", "points", "-n", "64", "--target", "family:disks"];
    out(&[&design[..], &["--seed", "3", "-o", s2.to_str().unwrap()]].concat());
    assert_eq!(std::fs::read(&s1).unwrap(), std::fs::read(&s2).unwrap());
    // optimize points takes its starting sampler as --init or --sampler;
    // both at once are refused naming the two.
    let (i1, i2) = (dir.join("i1.csv"), dir.join("i2.csv"));
    for (flag, path) in [("--init", &i1), ("--sampler", &i2)] {
        let start = [flag, "jitter", "--iters", "5", "-o", path.to_str().unwrap()];
        out(&[&design[..], &start].concat());
    }
    assert_eq!(std::fs::read(&i1).unwrap(), std::fs::read(&i2).unwrap());
    common::assert_fails(
        &[
            &design[..],
            &["--init", "cmj", "--sampler", "jitter", "-o", "x.csv"],
        ]
        .concat(),
        "'--init <SAMPLER>' cannot be used with '--sampler <SAMPLER>'",
    );
    // integrands lists names; --list adds the parameters.
    let short = String::from_utf8(out(&["integrands"])).unwrap();
    let long = String::from_utf8(out(&["integrands", "--list"])).unwrap();
    assert!(short.contains("layers") && !short.contains("c1=0.5"));
    assert!(long.contains("c1=0.5"));
    // Scene pixels are integrands too; the lists and the commands taking
    // them name the form (only spectrum --help and cli.md did).
    for text in [
        short,
        long,
        String::from_utf8(out(&["predict", "--help"])).unwrap(),
        String::from_utf8(out(&["optimize", "shear", "--help"])).unwrap(),
    ] {
        assert!(text.contains("scene:NAME,px=X,py=Y"), "{text}");
    }
    // Shell completions.
    let bash = String::from_utf8(out(&["completions", "bash"])).unwrap();
    assert!(bash.contains("varspec") && bash.contains("optimize"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn numpy_outputs_load_back() {
    let dir = temp_dir("npy");
    let pts = dir.join("j.npy");
    let run = varspec(&[
        "sample",
        "jitter",
        "-n",
        "16",
        "--sets",
        "3",
        "-o",
        pts.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(std::fs::read(&pts).unwrap().starts_with(b"\x93NUMPY"));
    let csv = varspec(&["sample", "jitter", "-n", "16", "--sets", "3"]);
    let csv_path = dir.join("j.csv");
    std::fs::write(&csv_path, &csv.stdout).unwrap();
    assert_eq!(
        varspec::io::read_point_sets(&pts).unwrap(),
        varspec::io::read_point_sets(&csv_path).unwrap()
    );
    // The spectrum of the .npy sets as an array: [2h+1, 2h+1] with h = 7
    // for --res 16, DC (= N) at the centre.
    let spec = dir.join("s.npy");
    let run = varspec(&[
        "spectrum",
        pts.to_str().unwrap(),
        "--res",
        "16",
        "--method",
        "direct",
        "--npy",
        spec.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let bytes = std::fs::read(&spec).unwrap();
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = String::from_utf8_lossy(&bytes[10..10 + header_len]).replace(' ', "");
    assert!(header.contains("'shape':(15,15"), "{header}");
    let at = |row: usize, col: usize| {
        let o = 10 + header_len + 8 * (row * 15 + col);
        f64::from_le_bytes(bytes[o..o + 8].try_into().unwrap())
    };
    assert!((at(7, 7) - 16.0).abs() < 1e-12, "DC power {}", at(7, 7));
    // Layout: one value against the CSV form of the same spectrum.
    let csv_spec = dir.join("s.csv");
    let run = varspec(&[
        "spectrum",
        pts.to_str().unwrap(),
        "--res",
        "16",
        "--method",
        "direct",
        "--csv",
        csv_spec.to_str().unwrap(),
    ]);
    assert!(run.status.success());
    let text = std::fs::read_to_string(&csv_spec).unwrap();
    let row = text.lines().find(|l| l.starts_with("3,-2,")).unwrap();
    let power: f64 = row.rsplit(',').next().unwrap().parse().unwrap();
    assert_eq!(at(7 - 2, 7 + 3), power, "row ky + h, column kx + h");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn sizes_beyond_memory_are_refused_before_allocating() {
    let run = |args: &[&str], limit: Option<&str>| {
        let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_varspec"));
        cmd.args(args);
        if let Some(l) = limit {
            cmd.env("VARSPEC_MEMORY_MIB", l);
        }
        cmd.output().unwrap()
    };
    for (args, limit, phrase) in [
        // A lone light field in 4D is the slow full-shift loss: the note
        // (printed before the memory refusal) points to the projection path.
        (
            vec![
                "optimize",
                "points",
                "-d",
                "4",
                "-n",
                "16",
                "--target",
                "defocus:c=0.5",
                "-o",
                "x.csv",
            ],
            Some("1"),
            "give it as a projection target: --target 'defocus:c=0.5;'",
        ),
        (
            vec![
                "predict",
                "--sampler",
                "umj",
                "-n",
                "64",
                "--integrand",
                "defocus",
                "--res",
                "255",
            ],
            None,
            "the closed-form expected power on the 255^4 frequency box (|k| <= 127) needs about 161295 MiB",
        ),
        (
            vec![
                "predict",
                "--sampler",
                "umj",
                "-n",
                "64",
                "--integrand",
                "defocus",
                "--res",
                "1000000000000",
            ],
            None,
            "more bytes than a 64-bit size can count",
        ),
        (
            vec![
                "optimize", "points", "-n", "256", "-d", "4", "--target", "defocus", "--res",
                "101", "-o", "x.csv",
            ],
            None,
            "lower --res (4D boxes grow as K^4)",
        ),
        (
            vec![
                "spectrum",
                "--sampler",
                "random",
                "-n",
                "64",
                "--res",
                "512",
            ],
            Some("1"),
            "more than the 1 MiB available (VARSPEC_MEMORY_MIB overrides the limit)",
        ),
        // The closed form is estimated by its own arrays, at most 40 bytes
        // per frequency: 8001² of them is 2443 MiB (it was refused as a
        // non-uniform FFT needing 34028 MiB, a transform it never runs).
        (
            vec![
                "predict",
                "--sampler",
                "random",
                "-n",
                "1000000",
                "--integrand",
                "disk:r=0.3",
                "--method",
                "expected",
            ],
            Some("1000"),
            "the closed-form expected power on the 8001^2 frequency box (|k| <= 4000) needs about 2443 MiB",
        ),
        // A budget that does not parse is refused, not replaced silently by
        // the automatic one (it was, and the command ran).
        (
            vec!["sample", "random", "-n", "16"],
            Some("2MiB"),
            "VARSPEC_MEMORY_MIB=\"2MiB\" is not a whole number of MiB",
        ),
        (
            vec!["sample", "random", "-n", "16"],
            Some("1.5"),
            "VARSPEC_MEMORY_MIB=\"1.5\" is not a whole number of MiB",
        ),
        (
            vec!["sample", "random", "-n", "16"],
            Some(""),
            "VARSPEC_MEMORY_MIB=\"\" is not a whole number of MiB",
        ),
    ] {
        let out = run(&args, limit);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(phrase),
            "{args:?}: {err}"
        );
        assert!(
            !err.contains("panicked") && !err.contains("memory allocation"),
            "{err}"
        );
    }
    // The 4D default box runs (it asked for 6.9 GB per allocation before).
    let dir = temp_dir("mem4d");
    let out_path = dir.join("o.csv");
    let out = run(
        &[
            "optimize",
            "points",
            "-n",
            "256",
            "-d",
            "4",
            "--target",
            "defocus",
            "--iters",
            "2",
            "-o",
            out_path.to_str().unwrap(),
        ],
        None,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn experiment_help_describes_the_file() {
    let out = varspec(&["experiment", "--help"]);
    let text = String::from_utf8_lossy(&out.stdout);
    for field in [
        "name ",
        "description ",
        "samplers ",
        "integrands ",
        "n ",
        "sets ",
        "seed ",
        "radial ",
    ] {
        assert!(
            text.contains(&format!("\n  {field}")),
            "--help lacks `{field}`: {text}"
        );
    }
}

#[test]
fn a_radial_table_of_huge_weights_is_optimized_not_returned_as_its_start() {
    // Weights near f64's limit once made the loss overflow and the start
    // came back as "optimized" (issue: hostile input, part two). Scaled to a
    // largest weight of 1 the descent must move: its final loss far below
    // the start's and below jitter's on the same weights.
    let dir = temp_dir("huge-radial");
    let table = dir.join("w.csv");
    std::fs::write(&table, "k,weight\n1,1e200\n4,1e200\n8,1e199\n").unwrap();
    let (out, report) = (dir.join("o.csv"), dir.join("r.json"));
    let target = format!("radial:{}", table.display());
    common::varspec_ok(&[
        "optimize",
        "points",
        "-n",
        "64",
        "--target",
        &target,
        "-o",
        out.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    let r = common::read_json(&report);
    let curve = r["loss_curve"].as_array().unwrap();
    let (start, end) = (
        curve[0].as_f64().unwrap(),
        curve.last().unwrap().as_f64().unwrap(),
    );
    let jitter = r["comparison"]["jitter"]["loss"].as_f64().unwrap();
    assert!(
        start.is_finite() && end < start / 10.0,
        "loss {start} -> {end}"
    );
    assert!(end < jitter, "optimized {end} against jitter {jitter}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_closed_standard_output_is_not_an_error() {
    // `varspec … | head -1`: the reader leaves after the first line. print!
    // panicked with "failed printing to stdout: Broken pipe" and a
    // backtrace; CSV written through the csv crate (sample, pcf) lost the
    // error's kind and exited 1 with "Broken pipe".
    for args in [
        &[
            "converge",
            "--sampler",
            "jitter",
            "--n",
            "16,64,256,1024",
            "--integrand",
            "disk:r=0.3",
        ][..],
        &["sample", "random", "-n", "100000", "--sets", "4"],
        &["pcf", "--sampler", "jitter", "-n", "64", "--bins", "100000"],
    ] {
        with_stdout_closed(args);
    }
    // The files a command was asked for are written all the same (the
    // report and the curve were lost when the first print stopped it).
    let dir = temp_dir("closed-stdout");
    let p = |name: &str| dir.join(name).to_str().unwrap().to_string();
    with_stdout_closed(&[
        "optimize",
        "points",
        "-n",
        "64",
        "--target",
        "disk",
        "--sets",
        "1",
        "--iters",
        "20",
        "-o",
        &p("k.csv"),
        "--report",
        &p("k.json"),
        "--curve",
        &p("kc.csv"),
    ]);
    for name in ["k.csv", "k.json", "kc.csv"] {
        assert!(dir.join(name).is_file(), "{name} not written");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs varspec with `args`, its standard output closed before it writes:
/// it must succeed without a panic.
fn with_stdout_closed(args: &[&str]) {
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_varspec"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{args:?}: {:?}: {err}", out.status);
    assert!(!err.contains("panicked"), "{args:?}: {err}");
}

#[cfg(target_os = "linux")]
#[test]
fn a_full_standard_output_is_an_error_and_no_file_appears() {
    // `varspec … > /dev/full`: print! panicked with a backtrace (exit 101)
    // and left the staged temporaries of the command's files behind.
    let dir = temp_dir("full-stdout");
    let table = dir.join("t.csv");
    for args in [
        vec!["integrands", "--list"],
        // Its radial table went to stdout past the command's output
        // (a bare "No space left on device": fourth trial).
        vec!["spectrum", "--sampler", "jitter", "-n", "64"],
        vec![
            "tables",
            "--sampler",
            "jitter",
            "-n",
            "64",
            "--format",
            "csv",
            "-o",
            table.to_str().unwrap(),
        ],
    ] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .expect("Linux has /dev/full");
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_varspec"))
            .args(&args)
            .stdout(full)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("error: cannot write to standard output: No space left on device")
                && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert!(left.is_empty(), "files left: {left:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(target_os = "linux")]
#[test]
fn a_failed_write_is_never_announced_as_written() {
    // `sample -o /dev/full` printed "wrote /dev/full: …" and then the
    // error: device bytes are written when the command's outputs are made
    // visible, after the lines (third new-user trial).
    let dir = temp_dir("never-announced");
    let beside = dir.join("beside.csv");
    let out = varspec(&["sample", "random", "-n", "4", "-o", "/dev/full"]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("cannot write /dev/full: No space left on device"),
        "{stderr}"
    );
    assert!(!stdout.contains("wrote"), "announced: {stdout}");
    // With a file beside the device, neither is announced and the file
    // does not appear.
    let out = varspec(&[
        "spectrum",
        "--sampler",
        "jitter",
        "-n",
        "64",
        "--csv",
        beside.to_str().unwrap(),
        "--png",
        "/dev/full",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1));
    assert!(!stdout.contains("wrote"), "announced: {stdout}");
    assert!(
        !beside.exists(),
        "the file beside the failed device appeared"
    );
    // A write that succeeds is announced.
    let out = varspec(&[
        "sample",
        "random",
        "-n",
        "4",
        "-o",
        beside.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && stdout.contains(&format!("wrote {}", beside.display())),
        "{stdout}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_benchmark_refuses_its_csv_path_before_measuring() {
    // `bench samplers --csv DIR` ran the whole benchmark, printed its table
    // and only then failed to write (third new-user trial).
    let dir = temp_dir("bench-folder");
    let out = varspec(&["bench", "samplers", "--csv", dir.to_str().unwrap()]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(
        !out.status.success() && stderr.contains("it is a folder"),
        "{stderr}"
    );
    assert!(stdout.is_empty(), "measured before refusing: {stdout}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn long_work_off_a_terminal_logs_its_progress() {
    // A progress bar is drawn only on a terminal; a batch job's log said
    // nothing for hours (third new-user trial). Off a terminal a line comes
    // every VARSPEC_PROGRESS_SECONDS (default 60; this run takes ~3 s on 2
    // cores, so at 1 s it logs and by default it does not).
    let dir = temp_dir("progress-log");
    let out = dir.join("bn.csv");
    let run = |every: Option<&str>| {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_varspec"));
        c.args(["sample", "blue-noise", "-n", "1024", "--sets", "8", "-o"])
            .arg(&out)
            .env_remove("VARSPEC_PROGRESS_SECONDS");
        if let Some(every) = every {
            c.env("VARSPEC_PROGRESS_SECONDS", every);
        }
        let o = c.output().unwrap();
        assert!(o.status.success());
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let logged = run(Some("1"));
    assert!(
        logged.contains("varspec: blue-noise N=1024: ") && logged.contains(" of 8 after "),
        "{logged}"
    );
    assert!(
        !run(None).contains("varspec: blue-noise"),
        "logged before a minute"
    );
    assert!(
        !run(Some("0")).contains("varspec: blue-noise"),
        "0 turns it off"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn work_of_unknown_length_off_a_terminal_logs_its_stage() {
    // `optimize shear` shows a spinner with its stage on a terminal; off
    // one it said nothing for minutes (helper's probe: 40 s silent at
    // VARSPEC_PROGRESS_SECONDS=5). This search takes ~2 s on 2 cores.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_varspec"))
        .args([
            "optimize",
            "shear",
            "-n",
            "1024",
            "--integrand",
            "defocus:c=0.5",
        ])
        .env("VARSPEC_PROGRESS_SECONDS", "1")
        .output()
        .unwrap();
    let logged = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{logged}");
    assert!(
        logged.contains("varspec: searching the shear") && logged.contains(": running for "),
        "{logged}"
    );
}

#[test]
fn the_spatial_forms_cost_is_told_before_it_runs() {
    // `predict -n 1e6 --method spatial` ran for hours with no word (fourth
    // trial). The note comes before the work: read it, then stop the run.
    use std::io::BufRead;
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_varspec"))
        .args([
            "predict",
            "--sampler",
            "random",
            "-n",
            "1e6",
            "--integrand",
            "disk",
            "--method",
            "spatial",
            "--sets",
            "1",
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    std::io::BufReader::new(child.stderr.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    child.kill().unwrap();
    child.wait().unwrap();
    // 10⁶·(10⁶ − 1)/2 pairs (the disk's support, 0.6, is past the cell
    // grid's 0.25); the time is this machine's and only has to be named.
    assert!(
        line.starts_with(
            "note: the spatial form is O(N^2) per set: 5.0e11 pair evaluations, about "
        ),
        "{line}"
    );
    // Quick work gets no note (the count within a small support is
    // checked by the unit test of pair_evaluations).
    let out = varspec(&[
        "predict",
        "--sampler",
        "random",
        "-n",
        "2e4",
        "--integrand",
        "disk:r=0.05",
        "--method",
        "spatial",
        "--sets",
        "1",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && !err.contains("O(N^2)"), "{err}");
}

#[test]
fn a_variance_zero_to_rounding_is_printed_as_such() {
    // A Gaussian integrated to machine precision by uniform jitter printed
    // 2.710505e-20 as a value, and a note to raise --res (fourth trial).
    let out = varspec(&[
        "predict",
        "--sampler",
        "uniform-jitter",
        "-n",
        "256",
        "--integrand",
        "gaussian",
        "--method",
        "expected,spatial",
    ]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{stderr}");
    for key in ["expected", "spatial"] {
        assert!(
            stdout
                .lines()
                .any(|l| l.trim_start().starts_with(key) && l.contains("0 to rounding")),
            "{key}: {stdout}"
        );
    }
    assert!(!stderr.contains("raise --res"), "{stderr}");
}

/// docs/formats.md's predict JSON example is what the command prints: the
/// same keys, the same values (times aside; the Fourier form's sums to
/// 1e-9 relative, as the docs allow). Its `expected` part had gone stale
/// (res 256, no axis_strips, another variance: fourth trial).
#[test]
fn the_documented_predict_json_is_what_the_command_prints() {
    let docs =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/formats.md")).unwrap();
    let section = docs.split("### predict JSON").nth(1).expect("the section");
    let example = section
        .split("```json\n")
        .nth(1)
        .and_then(|b| b.split("\n```").next())
        .expect("a json block");
    let shown: serde_json::Value = serde_json::from_str(example).expect("the example parses");
    let command = "varspec predict --sampler jitter -n 1024 --integrand disk:r=0.3 --json";
    assert!(
        section.contains(command),
        "the docs no longer show `{command}`"
    );
    let args: Vec<&str> = command.split(' ').skip(1).collect();
    let out = varspec(&args);
    assert!(out.status.success());
    let printed: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    fn same(path: &str, a: &serde_json::Value, b: &serde_json::Value) {
        use serde_json::Value::{Number, Object};
        match (a, b) {
            (Object(x), Object(y)) => {
                let (kx, ky): (Vec<_>, Vec<_>) = (x.keys().collect(), y.keys().collect());
                assert_eq!(kx, ky, "{path}: keys of the docs vs the output");
                for (k, v) in x {
                    same(&format!("{path}.{k}"), v, &y[k]);
                }
            }
            (Number(x), Number(y)) => {
                if path.ends_with(".seconds") {
                    return;
                }
                let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
                let fourier = path.starts_with(".fourier") || path.starts_with(".radial");
                let tolerance = if fourier { 1e-9 * y.abs() } else { 0.0 };
                assert!(
                    (x - y).abs() <= tolerance,
                    "{path}: docs {x:e}, output {y:e}"
                );
            }
            _ => assert_eq!(a, b, "{path}"),
        }
    }
    same("", &shown, &printed);
}

/// A CSV file's header and records, read by the csv crate.
fn csv_table(path: &std::path::Path) -> (Vec<String>, Vec<csv::StringRecord>) {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header = r.headers().unwrap().iter().map(str::to_string).collect();
    (header, r.records().map(|x| x.unwrap()).collect())
}

/// `bench render` and `bench predict` write CSV through serde records that
/// the csv crate reads back: the header names the columns, both BVHs find
/// the same hits, and the spatial row is the exact reference of its group.
#[test]
fn bench_tables_are_csv_with_named_columns() {
    let dir = temp_dir("bench-csv");
    let render = dir.join("render.csv");
    let run = varspec_with(
        &[
            "bench",
            "render",
            "--subdivisions",
            "1",
            "--csv",
            render.to_str().unwrap(),
        ],
        Some("2"),
    );
    assert!(run.status.success(), "{run:?}");
    let (header, rows) = csv_table(&render);
    assert_eq!(
        header,
        [
            "bvh",
            "triangles",
            "threads",
            "build_seconds",
            "camera_rays_per_second",
            "shadow_rays_per_second",
            "hits"
        ]
    );
    assert_eq!(rows.len(), 2);
    assert_eq!((&rows[0][0], &rows[1][0]), ("cwbvh", "bvh2"));
    assert_eq!(
        rows[0][6], rows[1][6],
        "the two BVHs must hit the same rays"
    );
    assert_eq!(&rows[0][2], "2");
    assert!(rows[0][4].parse::<f64>().unwrap() > 0.0);

    let predict = dir.join("predict.csv");
    let run = varspec(&[
        "bench",
        "predict",
        "--quick",
        "--csv",
        predict.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{run:?}");
    let (header, rows) = csv_table(&predict);
    assert_eq!(
        header,
        [
            "case",
            "method",
            "seconds",
            "variance",
            "relative_error",
            "threads"
        ]
    );
    let spatial: Vec<_> = rows
        .iter()
        .filter(|r| r[1].starts_with("spatial"))
        .collect();
    assert_eq!(spatial.len(), 2, "one exact row per integrand");
    assert!(spatial.iter().all(|r| r[4].parse::<f64>().unwrap() == 0.0));
    // A comma inside a field is quoted, not a column break.
    assert!(rows.iter().any(|r| r[1] == *"fourier K=64, no tail"));
}

/// `bench samplers --quick` times every listed sampler at each (N, d) it
/// makes: 4D-only samplers (umj, padded) have no 2D rows, 2D-only ones
/// (multijitter, cmj) no 4D rows, and every time is positive and finite.
#[test]
fn bench_samplers_lists_each_sampler_at_the_sizes_it_makes() {
    let dir = temp_dir("bench-samplers");
    let path = dir.join("samplers.csv");
    let run = varspec(&[
        "bench",
        "samplers",
        "--quick",
        "--csv",
        path.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{run:?}");
    let (header, rows) = csv_table(&path);
    assert_eq!(
        header,
        [
            "sampler",
            "n",
            "dim",
            "sets",
            "seconds",
            "ns_per_coordinate"
        ]
    );
    let count = |name: &str, dim: &str| {
        rows.iter()
            .filter(|r| &r[0] == name && &r[2] == dim)
            .count()
    };
    assert_eq!((count("sobol", "2"), count("sobol", "4")), (3, 3));
    assert_eq!((count("umj", "2"), count("umj", "4")), (0, 3));
    assert_eq!((count("cmj", "2"), count("cmj", "4")), (3, 0));
    assert!(rows.iter().all(|r| {
        let ns: f64 = r[5].parse().unwrap();
        ns.is_finite() && ns > 0.0
    }));
}

/// `bench shear --quick`: the shear objective's pair sums by powers of one
/// phasor per point agree with the direct sums (a sine and cosine per
/// point, wave and term) to rounding, in units of the bound N(N − 1)(Σ|A|)²
/// per realization: the products' phase error is ~k·ε at |k| ≤ 32; by a
/// NUFFT at tolerance ε, within 2ε (|ΔS| ≤ ε·N moves |S|² by ≤ 2ε·N²).
#[test]
fn bench_shear_powers_agree_with_the_direct_sums() {
    let dir = temp_dir("bench-shear");
    let path = dir.join("shear.csv");
    let run = varspec(&["bench", "shear", "--quick", "--csv", path.to_str().unwrap()]);
    assert!(run.status.success(), "{run:?}");
    let (header, rows) = csv_table(&path);
    assert_eq!(
        header,
        [
            "case",
            "method",
            "terms",
            "seconds",
            "max_rel_error",
            "threads"
        ]
    );
    // Two light fields at N = 64 and 256: direct, powers, two NUFFTs each.
    assert_eq!(rows.len(), 16);
    for r in rows.iter().filter(|r| r[1] == *"powers") {
        let error: f64 = r[4].parse().unwrap();
        assert!(error <= 1e-13, "{}: {error:e}", &r[0]);
    }
    for (method, tolerance) in [("nufft 1e-6", 1e-6), ("nufft 1e-9", 1e-9)] {
        let transformed: Vec<_> = rows.iter().filter(|r| r[1] == *method).collect();
        assert_eq!(transformed.len(), 4, "{method}: {rows:?}");
        for r in transformed {
            let error: f64 = r[4].parse().unwrap();
            assert!(error <= 2.0 * tolerance, "{} {method}: {error:e}", &r[0]);
        }
    }
    assert_eq!(rows.iter().filter(|r| r[1] == *"direct").count(), 4);
}

/// The shear search with both halves estimated from realizations (the
/// (x, y) power by NUFFT, the (u, v) pair sums by tables of powers) gives
/// the same JSON on one and two threads, all but its wall time.
#[test]
fn estimated_shear_search_is_identical_on_one_and_two_threads() {
    let args = [
        "optimize",
        "shear",
        "--sampler",
        "padded:xy=poisson-disk,uv=poisson-disk",
        "-n",
        "64",
        "--integrand",
        "layers:c1=0.5,c2=-0.2,size=0.3",
        "--realizations",
        "50",
        "--json",
    ];
    let run = |threads| {
        let out = varspec_with(&args, Some(threads));
        assert!(out.status.success(), "{out:?}");
        let mut json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        json.as_object_mut().unwrap().remove("seconds");
        json
    };
    let one = run("1");
    let estimated = |h: usize| one["objective"]["realizations"][h].as_u64().unwrap() > 0;
    assert!(estimated(0) && estimated(1), "both halves estimated: {one}");
    // Estimated halves leave J(unsheared) a standard error of its own.
    let unsheared = one["objective"]["unsheared_stderr"].as_f64();
    assert!(unsheared.is_some_and(|s| s > 0.0 && s < 0.5), "{one}");
    assert_eq!(one, run("2"));
}
