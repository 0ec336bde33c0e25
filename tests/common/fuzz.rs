//! A mutation fuzzer for every parser of user input: each input is a valid
//! seed (an example of the format) changed by one to four random edits —
//! byte flips, deletions, duplications, truncations and insertions of
//! tokens known to break parsers (NaN, infinities, huge and subnormal
//! numbers, integer overflows, a byte-order mark, NUL, separators, long
//! digit runs). A parser passes when it returns (Ok or Err) without a
//! panic, within the time limit. Shared by the bounded property test
//! (tests/fuzz_parsers.rs) and the long run (examples/fuzz_parsers.rs).

use std::io::Cursor;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::time::{Duration, Instant};

use varspec::PointSet;
use varspec::io::tables::TableFormat;
use varspec::rng::{SetRng, below, set_rng};

/// Tokens that break parsers.
const TOKENS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e308",
    "1e309",
    "-1e308",
    "4.9e-324",
    "1e-320",
    "-0",
    "0",
    "-1",
    "1",
    "0.5",
    "65536",
    "4294967296",
    "18446744073709551616",
    "99999999999999999999999",
    "-9223372036854775808",
    "9223372036854775807",
    "18446744073709551615",
    "-2147483648",
    "4294967295",
    "1e6",
    "0x10",
    "1_000",
    "\u{feff}",
    "\u{0}",
    "é",
    "\u{202e}",
    ",",
    ":",
    "=",
    ";",
    "+",
    "*",
    "/",
    "#",
    "\n",
    "\r\n",
    "\t",
    " ",
    "\"",
    "{",
    "}",
    "[",
    "]",
    "null",
    "true",
    "..",
    "../",
    "-",
    "e",
    "E",
    "x0,x1",
    "set,x0,x1",
];

/// A parser call: true if the input was accepted.
pub type Parse = Box<dyn Fn(&[u8]) -> bool + Sync + Send>;

/// One parser under test: a name, valid seeds, and the call.
pub struct Target {
    /// What it parses.
    pub name: &'static str,
    /// Valid inputs the mutations start from.
    pub seeds: Vec<Vec<u8>>,
    /// Parses one input: true if accepted (Ok and Err both pass).
    pub run: Parse,
}

/// Outcome of a run over one parser.
#[derive(Debug, Clone, Default)]
pub struct Tally {
    /// Inputs tried.
    pub inputs: u64,
    /// Inputs the parser accepted.
    pub accepted: u64,
    /// Panics (must be 0).
    pub panics: u64,
    /// Inputs slower than the time limit (hangs; must be 0).
    pub slow: u64,
    /// Slowest input.
    pub slowest: Duration,
    /// The first panicking or slow inputs with their messages.
    pub failures: Vec<(String, String)>,
}

impl Tally {
    /// Keeps an input and what went wrong with it (the first few).
    fn record(&mut self, input: String, message: String) {
        if self.failures.len() < 5 {
            self.failures.push((input, message));
        }
    }

    /// Adds another tally.
    pub fn merge(&mut self, other: Tally) {
        self.inputs += other.inputs;
        self.accepted += other.accepted;
        self.panics += other.panics;
        self.slow += other.slow;
        self.slowest = self.slowest.max(other.slowest);
        for (input, message) in other.failures {
            self.record(input, message);
        }
    }
}

/// Time an input may take before it counts as a hang.
pub const LIMIT: Duration = Duration::from_secs(1);

fn token(rng: &mut SetRng) -> Vec<u8> {
    if below(rng, 16) == 0 {
        // A long run of digits.
        return vec![b'9'; 1 + below(rng, 400) as usize];
    }
    TOKENS[below(rng, TOKENS.len() as u64) as usize]
        .as_bytes()
        .to_vec()
}

/// `seed` changed by one to four random edits.
pub fn mutate(seed: &[u8], rng: &mut SetRng) -> Vec<u8> {
    let mut s = seed.to_vec();
    for _ in 0..1 + below(rng, 4) {
        let len = s.len() as u64;
        let at = below(rng, len + 1) as usize;
        match below(rng, 7) {
            0 if !s.is_empty() => {
                let i = below(rng, len) as usize;
                s[i] = below(rng, 256) as u8;
            }
            1 => {
                let t = token(rng);
                s.splice(at..at, t);
            }
            2 if !s.is_empty() => {
                let end = (at + 1 + below(rng, 8) as usize).min(s.len());
                s.drain(at.min(end)..end);
            }
            3 => {
                let end = (at + 1 + below(rng, 16) as usize).min(s.len());
                let span = s[at.min(end)..end].to_vec();
                s.splice(at..at, span);
            }
            4 => s.truncate(at),
            5 => {
                // Replace the number that starts at or after `at`.
                let start = (at..s.len()).find(|&i| s[i].is_ascii_digit());
                if let Some(start) = start {
                    let end = (start..s.len())
                        .find(|&i| !(s[i].is_ascii_digit() || s[i] == b'.'))
                        .unwrap_or(s.len());
                    let t = token(rng);
                    s.splice(start..end, t);
                }
            }
            _ => {
                let t = token(rng);
                let end = (at + t.len()).min(s.len());
                s.splice(at..end, t);
            }
        }
    }
    s
}

/// Runs `count` mutated inputs through `target`, input i drawn from stream
/// (seed, i) so a run is reproducible and splits across threads.
pub fn fuzz(target: &Target, seed: u64, first: u64, count: u64) -> Tally {
    let mut tally = Tally::default();
    for i in first..first + count {
        let mut rng = set_rng(seed, i);
        let base = &target.seeds[below(&mut rng, target.seeds.len() as u64) as usize];
        let input = mutate(base, &mut rng);
        let start = Instant::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| (target.run)(&input)));
        let took = start.elapsed();
        tally.inputs += 1;
        tally.slowest = tally.slowest.max(took);
        if took > LIMIT {
            tally.slow += 1;
            tally.record(
                String::from_utf8_lossy(&input).into_owned(),
                format!("slow: {took:?}"),
            );
        }
        if let Ok(true) = outcome {
            tally.accepted += 1;
        }
        if let Err(payload) = outcome {
            tally.panics += 1;
            let message = payload
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            tally.record(String::from_utf8_lossy(&input).into_owned(), message);
        }
    }
    tally
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn lines(items: &[&str]) -> Vec<Vec<u8>> {
    items.iter().map(|s| s.as_bytes().to_vec()).collect()
}

/// A temporary file for parsers that read paths, one per thread.
fn scratch(tag: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!(
        "varspec-fuzz-{tag}-{}-{:?}",
        std::process::id(),
        std::thread::current().id()
    ))
}

/// Every parser of user input, with valid seeds.
pub fn targets() -> Vec<Target> {
    let set = PointSet::new(2, vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6]).unwrap();
    let mut npy = Vec::new();
    varspec::io::npy::write_point_sets_npy(&mut npy, &[set.clone(), set.clone()]).unwrap();
    let table = |format: TableFormat| {
        let sets = [set.clone(), set.clone()];
        let (meta, _) = varspec::tables::metadata(
            &sets,
            varspec::tables::Provenance {
                source: "fuzz".into(),
                params: vec![("m".into(), "4".into())],
                seed: Some(3),
                optimized_for: "none".into(),
                dimensions: None,
            },
            format,
            false,
        )
        .unwrap();
        let mut bytes = Vec::new();
        varspec::io::tables::write_table(&mut bytes, &sets, &meta, format, "fuzz").unwrap();
        let sidecar = serde_json::to_vec_pretty(&meta).unwrap();
        (bytes, sidecar)
    };
    let (json_table, _) = table(TableFormat::Json);
    let (c_header, _) = table(TableFormat::CHeader);
    let (_, sidecar) = table(TableFormat::F32);
    vec![
        Target {
            name: "integrand spec",
            seeds: lines(&[
                "disk:r=0.3,cx=0.5,cy=0.5",
                "box:w=0.5,h=0.25,angle=30",
                "gaussian:sx=0.1,sy=0.2,angle=10",
                "halfplane:angle=23,offset=0.11",
                "cos:kx=3,ky=-2",
                "defocus:shape=disk,size=0.3,c=0.45",
                "layers:shape=box,size=0.3,c1=0.5,c2=-0.2",
            ]),
            run: Box::new(|b| varspec::integrands::parse(&text(b)).is_ok()),
        },
        Target {
            name: "torus target",
            seeds: lines(&[
                "family:disks",
                "power:3",
                "halfplane:angle=23,offset=0.11",
                "disk:r=0.3",
            ]),
            run: Box::new(|b| varspec::optimize::Target::parse(&text(b)).is_ok()),
        },
        Target {
            name: "projection target (4D)",
            seeds: lines(&[
                "xy:family:disks;uv:family:disks;defocus:shape=disk,size=0.3,c=0.45",
                "xu:power:3;yv:power:2",
                "xy:family:disks;uv:family:disks",
            ]),
            run: Box::new(|b| {
                varspec::optimize::projections::parse_projections(&text(b), 64).is_ok()
            }),
        },
        Target {
            name: "scene pixel spec",
            seeds: lines(&[
                "scene:dof,px=142,py=64",
                "scene:shadows-disk,py=3,px=0",
                "scene:shadows-square,px=0,py=255",
                "scene:scenes/dof.json,px=10,py=20",
                "scene:some/file.json,px=1,py=2",
            ]),
            run: Box::new(|b| varspec::scene::pixel::PixelIntegrand::parse_spec(&text(b)).is_ok()),
        },
        Target {
            name: "square target and family",
            seeds: lines(&[
                "halfplanes+gaussians+16*blue",
                "gaussians:vmin=0.01,vmax=1",
                "disks:rmin=0.05,rmax=0.45+0.5*boxes",
                "boxes:smin=0.1,smax=0.2",
            ]),
            run: Box::new(|b| varspec::square::design::parse_target(&text(b)).is_ok()),
        },
        Target {
            name: "radial target table",
            seeds: lines(&["k,weight\n0,0\n10,0.5\n20,1\n", "k,weight\n1,1\n2,0.25\n"]),
            run: Box::new(|b| {
                let path = scratch("radial");
                let accepted = std::fs::write(&path, b).is_ok()
                    && varspec::optimize::Target::parse(&format!("radial:{}", path.display()))
                        .is_ok();
                let _ = std::fs::remove_file(&path);
                accepted
            }),
        },
        Target {
            name: "point file (CSV, UTK text)",
            seeds: lines(&[
                "x0,x1\n0.1,0.2\n0.3,0.4\n",
                "set,x0,x1\n0,0.1,0.2\n0,0.3,0.4\n1,0.5,0.6\n1,0.7,0.8\n",
                "x0,x1,x2,x3\n0.1,0.2,0.3,0.4\n",
                "0.1 0.2\n0.3 0.4\n#\n0.5 0.6\n0.7 0.8\n",
            ]),
            run: Box::new(|b| {
                varspec::io::pointfile::parse_point_sets(Cursor::new(b), Path::new("fuzz.csv"))
                    .is_ok()
            }),
        },
        Target {
            name: "pattern table (JSON)",
            seeds: vec![json_table],
            run: Box::new(|b| varspec::io::tables::read_json_table(Cursor::new(b)).is_ok()),
        },
        Target {
            name: "pattern table (C header)",
            seeds: vec![c_header],
            run: Box::new(|b| varspec::io::tables::read_c_header(&text(b)).is_ok()),
        },
        Target {
            name: "pattern table sidecar",
            seeds: vec![sidecar],
            run: Box::new(|b| {
                varspec::io::from_json::<varspec::io::tables::TableMetadata>(&text(b)).is_ok()
            }),
        },
        Target {
            name: "point file (NumPy .npy)",
            seeds: vec![npy],
            run: Box::new(|b| varspec::io::npy::read_point_sets_npy(Cursor::new(b)).is_ok()),
        },
        Target {
            name: "experiment file",
            seeds: lines(&[
                include_str!("../../experiments/rates.json"),
                include_str!("../../experiments/uniform-jitter-lights.json"),
            ]),
            run: Box::new(|b| {
                varspec::experiment::Experiment::parse(&text(b), "fuzz.json").is_ok()
            }),
        },
        Target {
            name: "scene file",
            seeds: lines(&[
                include_str!("../../scenes/dof.json"),
                include_str!("../../scenes/shadows-disk.json"),
            ]),
            run: Box::new(|b| {
                varspec::scene::description::SceneFile::parse(&text(b), "fuzz.json").is_ok()
            }),
        },
        Target {
            name: "shard spec",
            seeds: lines(&["0/4", "3/8", "0/1"]),
            run: Box::new(|b| varspec::experiment::Shard::parse(&text(b)).is_ok()),
        },
    ]
}
