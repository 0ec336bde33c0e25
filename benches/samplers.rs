//! Sampler throughput: points per second for every sampler at N = 4096 in
//! 2D and 4D (where the method allows), single-threaded, and Poisson-disk
//! sampling of 10,000 points. Seeded; construction stays outside the timed
//! loop. Goals (issue 2): ≥ 20 M points/s for random, jitter, cmj, sobol;
//! Poisson disk 10,000 points in ≤ 20 ms.

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use varspec::registry;
use varspec::registry::SAMPLERS;
use varspec::rng::set_rng;

fn throughput(c: &mut Criterion) {
    let mut group = c.benchmark_group("samplers");
    group
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(500));
    // The optimizer's speed is reported against its loss by
    // `varspec optimize points --curve`, not as points per second.
    for info in SAMPLERS.iter().filter(|s| s.name != "blue-noise") {
        for d in [2, 4] {
            let Ok(sampler) = registry::build(info.name, 4096, Some(d), &[]) else {
                continue;
            };
            group.throughput(Throughput::Elements(4096));
            let mut set = 0;
            group.bench_function(format!("{}/{}d/4096", info.name, d), |b| {
                b.iter(|| {
                    set += 1;
                    black_box(sampler.sample(&mut set_rng(1, set)).unwrap())
                })
            });
        }
    }
    let pd = registry::build("poisson-disk", 10_000, Some(2), &[]).unwrap();
    group.throughput(Throughput::Elements(10_000));
    let mut set = 0;
    group.bench_function("poisson-disk/2d/10000", |b| {
        b.iter(|| {
            set += 1;
            black_box(pd.sample(&mut set_rng(1, set)).unwrap())
        })
    });
    group.finish();
}

criterion_group!(benches, throughput);
criterion_main!(benches);
