//! The shear search on a matrix of defocus pixels, two-layer pixels and
//! sizes of N: the found shear beside the analytic one, the expected
//! variance before, at the analytic shear and at the found shear, and the
//! search time. Writes `shear-matrix.csv` and a markdown table to the folder
//! given as the first argument (default `out/shear-matrix`). The second
//! argument is the padded sampler (default `umj`; another sampler's files
//! are named after it), the third the sizes N (default `64,256,1024`).
//!
//! ```sh
//! cargo run --release --example shear_matrix -- results/optimize-shear
//! cargo run --release --example shear_matrix -- results/optimize-shear padded:xy=cmj,uv=poisson-disk 256
//! ```

use std::time::Instant;

use varspec::integrands;
use varspec::optimize::shear::{ObjectiveOptions, ShearObjective, search_shear, spectral_start};
use varspec::registry;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = args.next().unwrap_or_else(|| "out/shear-matrix".into());
    let sampler_name = args.next().unwrap_or_else(|| "umj".into());
    let ns = match args.next() {
        Some(list) => list
            .split(',')
            .map(str::parse)
            .collect::<Result<Vec<usize>, _>>()?,
        None => vec![64, 256, 1024],
    };
    let stem = if sampler_name == "umj" {
        "shear-matrix".to_string()
    } else {
        format!(
            "shear-matrix-{}",
            sampler_name.replace([':', ',', '='], "-")
        )
    };
    std::fs::create_dir_all(&out)?;
    let mut specs = Vec::new();
    for shape in ["box", "disk", "gaussian"] {
        for size in [0.05, 0.2, 0.5] {
            for c in [-0.8, -0.35, 0.15, 0.55, 0.8] {
                specs.push(format!("defocus:shape={shape},size={size},c={c}"));
            }
        }
    }
    for layers in [
        "layers:shape=box,size=0.3,c1=0.5,c2=-0.2",
        "layers:shape=disk,size=0.1,c1=0.6,c2=-0.4,mix=0.3",
        "layers:shape=gaussian,size=0.3,c1=0.3,c2=0.2",
    ] {
        specs.push(layers.into());
    }
    let mut csv = csv::Writer::from_path(format!("{out}/{stem}.csv"))?;
    csv.write_record([
        "integrand",
        "n",
        "a",
        "b",
        "analytic",
        "double_wedge",
        "variance_unsheared",
        "variance_analytic",
        "variance_found",
        "found_over_analytic",
        "found_over_unsheared",
        "seconds",
    ])?;
    let mut table = String::from(
        "| integrand | N | found (a, b) | analytic | found / analytic | found / unsheared | s |\n|---|---|---|---|---|---|---|\n",
    );
    for spec in &specs {
        for &n in &ns {
            let f = integrands::parse(spec)?;
            let sampler = registry::build(&sampler_name, n, Some(4), &[])?;
            let start = Instant::now();
            let spectral = spectral_start(f.as_ref(), 64, 2.0);
            let mut starts = spectral.candidates();
            starts.push([0.0, 0.0]);
            let objective = ShearObjective::new(
                f.as_ref(),
                sampler.as_ref(),
                &starts,
                ObjectiveOptions::default(),
            )?;
            let found = search_shear(&objective, &spectral, 2.0, &|_| {})?;
            let seconds = start.elapsed().as_secs_f64();
            let layers = f
                .light_field()
                .map(|l| l.layer_shears())
                .unwrap_or_default();
            // The analytic reference: the best of the layers' own shears.
            let analytic = layers
                .iter()
                .map(|s| (s[0], objective.value(s[0], s[1])))
                .fold((0.0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
            let (j0, j) = (found.unsheared.value, found.optimum.value);
            csv.write_record([
                spec.clone(),
                n.to_string(),
                format!("{:.5}", found.shear[0]),
                format!("{:.5}", found.shear[1]),
                format!("{:.5}", analytic.0),
                spectral.double_wedge.to_string(),
                format!("{j0:e}"),
                format!("{:e}", analytic.1),
                format!("{j:e}"),
                format!("{:.4}", j / analytic.1),
                format!("{:.4}", j / j0),
                format!("{seconds:.2}"),
            ])?;
            table.push_str(&format!(
                "| `{spec}` | {n} | ({:.3}, {:.3}) | {:.3} | {:.3} | {:.3} | {seconds:.1} |\n",
                found.shear[0],
                found.shear[1],
                analytic.0,
                j / analytic.1,
                j / j0
            ));
        }
    }
    csv.flush()?;
    std::fs::write(format!("{out}/{stem}.md"), table)?;
    Ok(())
}
