//! The hostile-input table (tests/data/hostile-inputs.tsv): its fixtures,
//! its cases, and one run of a case. Shared by tests/hostile_inputs.rs,
//! which asserts every row, and examples/hostile_inputs.rs, which writes
//! the table with what each input now answers into results/.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

/// One row of the table.
pub struct Case {
    /// Whether the command must fail.
    pub fails: bool,
    /// A phrase its output must contain, or `file:NAME`: a file it must
    /// write.
    pub phrase: String,
    /// Its arguments.
    pub args: Vec<String>,
}

/// What one run did.
pub struct Run {
    /// Exit code (None: killed by a signal).
    pub code: Option<i32>,
    /// Standard error and output, in that order.
    pub said: String,
    /// Files the run left in the folder that were not there before.
    pub new_files: Vec<String>,
}

impl Run {
    /// The first line of the output holding `phrase`, else the first line.
    pub fn answer(&self, phrase: &str) -> &str {
        let mut lines = self.said.lines().filter(|l| !l.trim().is_empty());
        let first = lines.clone().next().unwrap_or("");
        lines.find(|l| l.contains(phrase)).unwrap_or(first)
    }

    /// Whether the run meets its row: the exit status, the phrase, no
    /// panic or abort, and a failed command writes no file.
    pub fn meets(&self, case: &Case) -> Result<(), String> {
        let failed = self.code != Some(0);
        if self.code.is_none() || self.code == Some(101) || self.said.contains("panicked") {
            return Err(format!("crashed ({:?}): {}", self.code, self.said));
        }
        if failed != case.fails {
            return Err(format!(
                "exit {:?}, expected {}",
                self.code,
                if case.fails { "failure" } else { "success" }
            ));
        }
        if let Some(name) = case.phrase.strip_prefix("file:") {
            if !self.new_files.iter().any(|f| f == name) {
                return Err(format!("it did not write {name}: {}", self.said));
            }
        } else if !self.said.contains(&case.phrase) {
            return Err(format!("output lacks {:?}: {}", case.phrase, self.said));
        }
        if failed && !self.new_files.is_empty() {
            return Err(format!("a failed command wrote {:?}", self.new_files));
        }
        Ok(())
    }
}

/// The rows of the table.
pub fn cases() -> Vec<Case> {
    include_str!("../data/hostile-inputs.tsv")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|line| {
            let mut cols = line.splitn(3, '\t');
            let (outcome, phrase, args) = (
                cols.next().unwrap(),
                cols.next().unwrap(),
                cols.next().unwrap(),
            );
            assert!(matches!(outcome, "fails" | "ok"), "bad outcome in {line:?}");
            Case {
                fails: outcome == "fails",
                phrase: phrase.to_string(),
                args: args.split(' ').map(str::to_string).collect(),
            }
        })
        .collect()
}

/// Writes the fixtures the rows name into `dir`.
pub fn write_fixtures(dir: &Path) {
    let mut points = String::from("x0,x1\n");
    for i in 0..16 {
        points.push_str(&format!(
            "{},{}\n",
            (i as f64 + 0.5) / 16.0,
            ((i * 7 % 16) as f64 + 0.5) / 16.0
        ));
    }
    let experiment = |name: &str, integrands: &str, n: &str| {
        format!(
            r#"{{"name": "{name}", "samplers": ["jitter"], "integrands": [{integrands}], "n": [{n}], "sets": 2}}"#
        )
    };
    // A scene whose one object is an OBJ mesh beside it.
    let scene = r#"{"camera": {"resolution": [8, 8], "fov_degrees": 40, "position": [0, 0, 0],
        "look_at": [0, 0, -1], "focal_distance": 4, "aperture": 0.06}, "integrand": "lens",
        "objects": [{"shape": "obj", "file": "m.obj", "translate": [0, 0, -4],
        "material": {"texture": "checker", "period": 0.5, "low": 0.2, "high": 0.8}}]}"#;
    // A 4 × 4 grey PFM (little-endian), a reference of the wrong size.
    let mut pfm = b"Pf\n4 4\n-1.0\n".to_vec();
    pfm.extend((0..16).flat_map(|i| (i as f32 / 16.0).to_le_bytes()));
    let files: [(&str, Vec<u8>); 16] = [
        (
            "three.csv",
            "set,x0,x1\n0,0.1,0.2\n0,0.6,0.7\n1,0.3,0.4\n1,0.8,0.9\n2,0.5,0.1\n2,0.0,0.6\n".into(),
        ),
        ("s.json", scene.into()),
        ("m.obj", "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n".into()),
        ("r4.pfm", pfm),
        ("p.csv", points.into_bytes()),
        ("long-line.csv", vec![b'0'; (1 << 20) + 10]),
        ("bom.csv", "\u{feff}x0,x1\n0.1,0.2\n".into()),
        ("bom-bad-header.csv", "\u{feff}a,b\n0.1,0.2\n".into()),
        ("numpy-hash.csv", "# x0,x1\n0.1,0.2\n0.3,0.4\n".into()),
        ("huge-weights.csv", "k,weight\n1,1e308\n2,1e308\n".into()),
        ("bom-weights.csv", "\u{feff}k,weight\n1,1\n2,0.5\n".into()),
        ("garbage.bin", "garbage\n".into()),
        (
            "small-exp.json",
            experiment("small", r#""disk""#, "16, 64").into(),
        ),
        (
            "escape.json",
            experiment("../../escaped", r#""disk""#, "64, 256").into(),
        ),
        (
            "duplicate-n.json",
            experiment("dup", r#""disk""#, "60, 64").into(),
        ),
        (
            "duplicate-integrand.json",
            experiment("dup", r#""disk", "disk:r=0.3""#, "64, 256").into(),
        ),
    ];
    for (name, bytes) in files {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
}

fn listing(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect()
}

/// Runs `case` with the binary `exe` in `dir` (which holds the fixtures),
/// with a fixed memory budget of 4 GiB; removes what a successful run wrote.
pub fn run(exe: &Path, dir: &Path, case: &Case) -> Run {
    let before = listing(dir);
    let out = Command::new(exe)
        .args(&case.args)
        .current_dir(dir)
        .env("VARSPEC_MEMORY_MIB", "4096")
        .output()
        .expect("the varspec binary runs");
    let new_files: Vec<String> = listing(dir).difference(&before).cloned().collect();
    for name in &new_files {
        let path = dir.join(name);
        let _ = std::fs::remove_file(&path).or_else(|_| std::fs::remove_dir_all(&path));
    }
    Run {
        code: out.status.code(),
        said: format!(
            "{}{}",
            String::from_utf8_lossy(&out.stderr),
            String::from_utf8_lossy(&out.stdout)
        ),
        new_files,
    }
}
