//! Large table runs split over machines: a shard draws a deterministic
//! 1/n of the sets (set r goes to shard r mod n, as an experiment's items)
//! and keeps them with the run's configuration; merging every shard gives
//! back the sets in order, so the table written from them is byte for byte
//! the one a single run writes (set r is always drawn from stream
//! (seed, r)).

use serde::{Deserialize, Serialize};

use crate::experiment::Shard;
use crate::points::PointSet;
use crate::rng::set_rng;
use crate::samplers::{Sampler, SamplerError};

/// What a table run draws: the same in every shard of one run.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TableRun {
    /// Sampler spec as given.
    pub sampler: String,
    /// Points per set as given.
    pub n: usize,
    /// Dimension as given.
    pub dim: Option<usize>,
    /// Sampler parameters.
    pub params: Vec<(String, String)>,
    /// Seed.
    pub seed: u64,
    /// Sets in the whole table.
    pub sets: usize,
}

/// One shard's sets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TableShard {
    /// The run it belongs to.
    pub run: TableRun,
    /// Which part.
    pub shard: Shard,
    /// Dimension of the sets.
    pub dim: usize,
    /// (set index, coordinates) of the sets r ≡ i (mod n), in order.
    pub sets: Vec<(usize, Vec<f64>)>,
}

/// Draws shard `shard` of `run` from `sampler` (built from the run's spec).
///
/// # Errors
/// The sampler's error.
pub fn draw_shard(
    sampler: &dyn Sampler,
    run: TableRun,
    shard: Shard,
    on_set: &(dyn Fn() + Sync),
) -> Result<TableShard, SamplerError> {
    use rayon::prelude::*;
    let sets = (shard.index..run.sets)
        .step_by(shard.count)
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|r| {
            let set = sampler.sample(&mut set_rng(run.seed, r as u64))?;
            on_set();
            Ok((r, set.coords().to_vec()))
        })
        .collect::<Result<Vec<_>, SamplerError>>()?;
    Ok(TableShard {
        run,
        shard,
        dim: sampler.dim(),
        sets,
    })
}

/// The run and its sets in order from every shard of one split.
///
/// # Errors
/// A sentence naming what is wrong: no shards, shards of different runs or
/// splits, a shard twice or missing, a set that is not a point set.
pub fn merge_table_shards(shards: &[TableShard]) -> Result<(TableRun, Vec<PointSet>), String> {
    let first = shards.first().ok_or("no table shards to merge")?;
    let parts: Vec<Shard> = shards.iter().map(|s| s.shard).collect();
    Shard::check_split(
        &parts,
        |j| shards[j].run == first.run && shards[j].dim == first.dim,
        "table run",
    )?;
    let count = first.shard.count;
    // Keyed by index, as many as the shards hold: the set count a file
    // states is never allocated before the sets are there.
    let mut sets = std::collections::BTreeMap::new();
    for s in shards {
        for (r, coords) in &s.sets {
            if *r >= first.run.sets || !s.shard.owns(*r) {
                return Err(format!(
                    "shard {}/{count} holds set {r}, not its own",
                    s.shard.index
                ));
            }
            let set = PointSet::new(first.dim, coords.clone())
                .map_err(|e| format!("set {r} of shard {}/{count}: {e}", s.shard.index))?;
            if sets.insert(*r, set).is_some() {
                return Err(format!(
                    "shard {}/{count} holds set {r} twice",
                    s.shard.index
                ));
            }
        }
    }
    if let Some(r) = (0..first.run.sets).find(|r| !sets.contains_key(r)) {
        return Err(format!("set {r} is in no shard"));
    }
    Ok((first.run.clone(), sets.into_values().collect()))
}
