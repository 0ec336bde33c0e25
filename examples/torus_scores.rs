//! Torus designs scored on integrands nobody tuned them for: the variance
//! of the shift-randomized estimator (Fourier form on |k|∞ ≤ 511 plus the
//! Parseval tail) averaged over random disks (r ~ U[0.05, 0.45]) and random
//! rotated boxes (sides ~ U[0.05, 0.5], angle ~ U[0°, 180°)), drawn with a
//! seed no optimizer uses, for each sampler given and relative to jitter and
//! CMJ at the same N.
//!
//! ```sh
//! cargo run --release --example torus_scores -- 1024 blue-noise
//! ```
//! Arguments: N, then samplers (name or name:key=value,...) beside jitter and cmj.

use varspec::integrands::{self, Integrand};
use varspec::registry;
use varspec::rng::{set_rng, uniform};
use varspec::spectrum::{FrequencyBox, Method, expected_power};
use varspec::variance::fourier::integrand_power;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().map_or(Ok(1024), |a| a.parse())?;
    let mut names = vec!["jitter".to_string(), "cmj".to_string()];
    names.extend(args.iter().skip(1).cloned());
    let freqs = FrequencyBox { dim: 2, half: 511 };
    let mut rng = set_rng(0x7e57, 0);
    let members: Vec<Box<dyn Integrand>> = (0..48)
        .map(|m| {
            let spec = if m % 2 == 0 {
                format!("disk:r={}", 0.05 + 0.4 * uniform(&mut rng))
            } else {
                format!(
                    "box:w={},h={},angle={}",
                    0.05 + 0.45 * uniform(&mut rng),
                    0.05 + 0.45 * uniform(&mut rng),
                    180.0 * uniform(&mut rng)
                )
            };
            integrands::parse(&spec).expect("valid spec")
        })
        .collect();
    let powers: Vec<Vec<f64>> = members
        .iter()
        .map(|f| integrand_power(f.as_ref(), &freqs))
        .collect();
    let zero = freqs.zero_index();
    let mut table: Vec<(String, Vec<f64>)> = Vec::new();
    for name in &names {
        // A point-set file, or a sampler.
        let drawn: Vec<varspec::PointSet> = if name.ends_with(".csv") {
            varspec::io::read_point_sets(std::path::Path::new(name))?
        } else {
            let (s, _) = registry::build_nearest(name, n, Some(2), &[])?;
            let count = if name.starts_with("blue") { 4 } else { 16 };
            (0..count)
                .map(|r| s.sample(&mut set_rng(11, r)))
                .collect::<Result<_, _>>()?
        };
        let n_used = drawn[0].len();
        let spectrum = expected_power(
            freqs,
            Method::Fast { tolerance: 1e-9 },
            drawn.len(),
            |r| Ok::<_, varspec::spectrum::SpectrumError>(drawn[r].clone()),
            &|| {},
        )?;
        let variances: Vec<f64> = members
            .iter()
            .zip(&powers)
            .map(|(f, pf)| {
                let mut in_box = 0.0;
                let mut energy = 0.0;
                for (i, (&p, &w)) in spectrum.power.iter().zip(pf).enumerate() {
                    if i != zero {
                        in_box += p * w;
                        energy += w;
                    }
                }
                (in_box + (f.variance() - energy).max(0.0)) / n_used as f64
            })
            .collect();
        // How much of the variance lies beyond the descent's box for the
        // disk family at this N: the tail no in-box design can change.
        let box_half = varspec::optimize::DescentOptions::for_target(
            n,
            2,
            &varspec::optimize::Target::FamilyDisks,
        )
        .half as i64;
        let outside: f64 = members
            .iter()
            .zip(&powers)
            .zip(&variances)
            .map(|((f, pf), v)| {
                let mut energy = 0.0;
                for (i, &w) in pf.iter().enumerate() {
                    let mut k = [0i64; 2];
                    freqs.frequency(i, &mut k);
                    if i != zero && k[0].abs() <= box_half && k[1].abs() <= box_half {
                        energy += w;
                    }
                }
                ((f.variance() - energy).max(0.0) / n_used as f64) / v
            })
            .sum::<f64>()
            / members.len() as f64;
        eprintln!(
            "{name}: share of the variance beyond |k| = 80 at white-noise level: {outside:.3}"
        );
        table.push((format!("{name} (N={n_used})"), variances));
    }
    let (jitter, cmj) = (table[0].1.clone(), table[1].1.clone());
    println!("N = {n}: mean over 24 disks and 24 boxes of Var / Var(jitter), Var / Var(CMJ)");
    for (name, v) in &table {
        let ratio = |base: &[f64], parity: usize| {
            let r: Vec<f64> = v
                .iter()
                .zip(base)
                .enumerate()
                .filter(|(i, _)| parity == 2 || i % 2 == parity)
                .map(|(_, (a, b))| a / b)
                .collect();
            r.iter().sum::<f64>() / r.len() as f64
        };
        println!(
            "  {name:<40} vs jitter: disks {:.3} boxes {:.3} all {:.3}   vs CMJ: disks {:.3} boxes {:.3} all {:.3}",
            ratio(&jitter, 0),
            ratio(&jitter, 1),
            ratio(&jitter, 2),
            ratio(&cmj, 0),
            ratio(&cmj, 1),
            ratio(&cmj, 2)
        );
    }
    Ok(())
}
