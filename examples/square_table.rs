//! Every sampler and design on both domains: the unshifted estimator on the
//! square and the estimator with one uniform torus shift per set, scored on
//! four families (members drawn with seed 31337, never used by a descent),
//! with the closest pair and the wall time per set. Writes
//! `square-table.csv`, `square-table.md` and, for the blue design at the
//! first N, `loss-vs-time-N.csv` into the folder given (default
//! `out/square`). Arguments: folder, then the N values (default 1024 4096).
//!
//! ```sh
//! cargo run --release --example square_table -- results/square 1024 4096
//! ```

use std::time::Instant;

use varspec::PointSet;
use varspec::neighbours::closest_pair_ratio;
use varspec::registry;
use varspec::rng::{set_rng, uniform};
use varspec::square::design::{default_options, design, parse_target};
use varspec::square::{Family, family_mse};

const MEMBERS: usize = 2048;
const SCORE_SEED: u64 = 31337;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = args.first().cloned().unwrap_or_else(|| "out/square".into());
    let ns: Vec<usize> = if args.len() > 1 {
        args[1..]
            .iter()
            .map(|a| a.parse())
            .collect::<Result<_, _>>()?
    } else {
        vec![1024, 4096]
    };
    std::fs::create_dir_all(&out)?;
    let families: Vec<Family> = ["halfplanes", "gaussians", "disks", "boxes"]
        .iter()
        .map(|f| Family::parse(f))
        .collect::<Result<_, _>>()?;
    let mut csv = csv::Writer::from_path(format!("{out}/square-table.csv"))?;
    let mut header = vec!["n".to_string(), "design".into(), "sets".into()];
    for f in &families {
        header.push(format!("square {}", f.spec()));
        header.push(format!("square {} stderr", f.spec()));
    }
    header.extend([
        "torus-shifted halfplanes".into(),
        "torus-shifted gaussians".into(),
    ]);
    header.extend(["closest pair / hexagonal".into(), "seconds per set".into()]);
    csv.write_record(&header)?;
    let mut md = String::from(
        "| N | design | sets | halfplanes | gaussians | disks | boxes | shifted halfplanes | shifted gaussians | closest pair | s/set |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for (index, &n) in ns.iter().enumerate() {
        let mut rows: Vec<(String, Vec<PointSet>, f64)> = Vec::new();
        for name in ["random", "jitter", "cmj", "sobol", "halton", "poisson-disk"] {
            let (s, _) = registry::build_nearest(name, n, Some(2), &[])?;
            let clock = Instant::now();
            let sets: Vec<PointSet> = (0..16)
                .map(|r| s.sample(&mut set_rng(5, r)))
                .collect::<Result<_, _>>()?;
            rows.push((name.into(), sets, clock.elapsed().as_secs_f64() / 16.0));
        }
        // The torus blue noise (the disk family), as the issue measured it.
        let torus = registry::build("blue-noise", n, Some(2), &[])?;
        let clock = Instant::now();
        let sets: Vec<PointSet> = (0..4)
            .map(|r| torus.sample(&mut set_rng(6, r)))
            .collect::<Result<_, _>>()?;
        rows.push((
            "blue-noise (torus, family:disks)".into(),
            sets,
            clock.elapsed().as_secs_f64() / 4.0,
        ));
        for (target, init) in [
            ("halfplanes+gaussians+16*blue", "jitter"),
            ("halfplanes", "jitter"),
            ("gaussians", "sobol"),
        ] {
            let terms = parse_target(target)?;
            let start = registry::build(init, n, Some(2), &[])?;
            let clock = Instant::now();
            let mut sets = Vec::new();
            for r in 0..8u64 {
                let first = start.sample(&mut set_rng(7, r))?;
                let result = design(&terms, first, 9000 + r, &default_options(), &|_, _| {});
                if r == 0 && index == 0 && target.ends_with("blue") {
                    let mut w = csv::Writer::from_path(format!("{out}/loss-vs-time-{n}.csv"))?;
                    w.write_record(["iteration", "seconds", "loss"])?;
                    for (i, (t, l)) in result.seconds.iter().zip(&result.losses).enumerate() {
                        w.write_record([i.to_string(), format!("{t:.4}"), format!("{l:e}")])?;
                    }
                    w.flush()?;
                }
                sets.push(result.points);
            }
            rows.push((
                format!("square: {target} (from {init})"),
                sets,
                clock.elapsed().as_secs_f64() / 8.0,
            ));
        }
        for (name, sets, seconds) in &rows {
            let mut record = vec![n.to_string(), name.clone(), sets.len().to_string()];
            let mut cells = Vec::new();
            for f in &families {
                let m = family_mse(sets, f, MEMBERS, SCORE_SEED);
                record.push(format!("{:e}", m.mse));
                record.push(format!("{:e}", m.stderr));
                cells.push(format!("{:.3e} ± {:.0}%", m.mse, 100.0 * m.stderr / m.mse));
            }
            // One uniform torus shift per set.
            let shifted: Vec<PointSet> = sets
                .iter()
                .enumerate()
                .map(|(r, s)| {
                    let mut rng = set_rng(77, r as u64);
                    s.shifted(&[uniform(&mut rng), uniform(&mut rng)])
                })
                .collect::<Result<_, _>>()?;
            for f in &families[..2] {
                let m = family_mse(&shifted, f, MEMBERS, SCORE_SEED);
                record.push(format!("{:e}", m.mse));
                cells.push(format!("{:.3e}", m.mse));
            }
            let closest = sets
                .iter()
                .map(closest_pair_ratio)
                .fold(f64::INFINITY, f64::min);
            record.push(format!("{closest:.3}"));
            record.push(format!("{seconds:.3}"));
            csv.write_record(&record)?;
            md.push_str(&format!(
                "| {n} | {name} | {} | {} | {closest:.2} | {seconds:.2} |\n",
                sets.len(),
                cells.join(" | ")
            ));
            eprintln!("N={n} {name} done");
        }
    }
    csv.flush()?;
    std::fs::write(format!("{out}/square-table.md"), md)?;
    Ok(())
}
