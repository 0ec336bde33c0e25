//! Declarative experiments, as a library. Figure experiments
//! (`"kind": "figures"`, [`FigureExperiment`]) draw a list of figures. Variance
//! experiments (the default kind): a JSON file names samplers,
//! integrands and sizes ([`Experiment`]); the work splits into items — one
//! per (sampler, N), whose realizations every integrand shares — in a fixed
//! order, so any 1/n of it ([`Shard`]) is a pure function of (i, n) and the
//! shards' cells, merged in that order, are exactly the single run's
//! (the partitioning of cargo-nextest's `--partition count:i/n` and of a
//! Slurm job array). [`report`] writes the tables from the cells.

mod figures;
mod file;
mod planes;
mod report;
mod run;
mod scene_figures;
mod spec;

pub use figures::{Figure, FigureExperiment};

pub use file::ExperimentFile;
pub use report::{
    KEPT_NOTES, SHARD_PREFIX, remove_other_runs, remove_variance_runs, write_results,
};
pub use run::{Cell, RadialCell, Shard, ShardFile, merge_shards, run_items};
pub use spec::{Experiment, ExperimentError, RadialComparison};
