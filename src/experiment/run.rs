//! Running an experiment's items, whole or by shard, and merging shards.

use crate::registry;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::spec::{Experiment, ExperimentError};
use crate::integrands;
use crate::samplers;
use crate::variance::{VarianceError, VarianceForm, fourier_parts, radial_from, sampler_variance};

/// The NUFFT tolerance of the radial comparison's spectra.
const RADIAL_TOLERANCE: f64 = 1e-10;

/// One (sampler, integrand, N) result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Cell {
    /// Sampler index in the experiment.
    pub sampler_index: usize,
    /// Integrand index.
    pub integrand_index: usize,
    /// N index.
    pub n_index: usize,
    /// Sampler name.
    pub sampler: String,
    /// Canonical integrand spec.
    pub integrand: String,
    /// Requested N.
    pub requested: usize,
    /// N used.
    pub n: usize,
    /// Mean predicted variance over the sets.
    pub variance: f64,
    /// Its standard error; `None` from a single set (unknown, not 0).
    pub stderr: Option<f64>,
    /// The form's bound on its rounding (see
    /// [`SamplerVariance`](crate::variance::SamplerVariance)): a variance at
    /// or below a positive bound is zero to rounding. Required in shard files: shards written before it (and
    /// before each N drew its own seed) are refused, not merged.
    pub rounding_bound: f64,
    /// The Fourier form's bound on what its box leaves out (0 for the
    /// spatial form). Required in shard files, as `rounding_bound`.
    pub truncation_bound: f64,
    /// `spatial` or `fourier`.
    pub method: String,
    /// The radial predictor on the same realizations, when the experiment
    /// asks for it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radial: Option<RadialCell>,
}

/// The radial (isotropic) predictor of one cell, with the Fourier form on
/// the same box.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RadialCell {
    /// (1/N) Σ_r n_r P̄_S(r) P̄_f(r) + tail/N.
    pub variance: f64,
    /// Cauchy–Schwarz bound on |radial − Fourier| inside the box.
    pub anisotropy_bound: f64,
    /// The Fourier form on the same box.
    pub fourier: f64,
}

/// A deterministic 1/count of the items: those with index ≡ `index` (mod
/// `count`), 0-based.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// i.
    pub index: usize,
    /// n.
    pub count: usize,
}

impl Shard {
    /// The whole experiment.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Parses `i/n` with 0 ≤ i < n.
    ///
    /// # Errors
    /// A message stating the rule.
    pub fn parse(text: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "--shard `{text}` must be i/n with 0 <= i < n (e.g. 0/4), as Slurm's array index"
            )
        };
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count): (usize, usize) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// True for the items this shard draws: item ≡ i (mod n).
    pub fn owns(&self, item: usize) -> bool {
        item % self.count == self.index
    }

    /// Checks that `shards` are every part of one split exactly once;
    /// `same_run(j)` says whether the j-th belongs to the first one's run
    /// (an `what`, e.g. "experiment").
    ///
    /// # Errors
    /// A sentence naming the shard that is foreign, repeated or missing.
    pub fn check_split(
        shards: &[Shard],
        same_run: impl Fn(usize) -> bool,
        what: &str,
    ) -> Result<(), String> {
        let Some(first) = shards.first() else {
            return Err("no shards to merge".into());
        };
        let count = first.count;
        // The indices seen, as many as the shards given: a count read from
        // a file (2^64 − 1) is never allocated.
        let mut seen = std::collections::BTreeSet::new();
        for (j, s) in shards.iter().enumerate() {
            if !same_run(j) || s.count != count {
                return Err(format!(
                    "shard {}/{} belongs to another {what} or split than shard {}/{count}",
                    s.index, s.count, first.index
                ));
            }
            if s.index >= count {
                return Err(format!(
                    "shard {}/{count} is not a part of a {count}-way split",
                    s.index
                ));
            }
            if !seen.insert(s.index) {
                return Err(format!("shard {}/{count} given twice", s.index));
            }
        }
        match (0..count).find(|i| !seen.contains(i)) {
            Some(missing) => Err(format!("shard {missing}/{count} is missing")),
            None => Ok(()),
        }
    }
}

/// What one shard writes: the experiment, which shard, and its cells.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardFile {
    /// The experiment as run.
    pub experiment: Experiment,
    /// The experiment file's path as given.
    pub file: String,
    /// The shard.
    pub shard: Shard,
    /// Its cells, in item order.
    pub cells: Vec<Cell>,
}

/// Runs the items of `shard` in parallel, as many at a time as rayon's pool
/// has threads (each item's realizations and cells depend only on the item,
/// so the cells, returned in item order, are the same for any thread
/// count); `on_cell` is called per cell.
///
/// # Errors
/// [`ExperimentError::Cell`] naming the sampler, N and integrand that failed
/// (the first in item order).
pub fn run_items(
    e: &Experiment,
    file: &str,
    shard: Shard,
    on_cell: &(dyn Fn() + Sync),
) -> Result<Vec<Cell>, ExperimentError> {
    let functions: Vec<_> = e
        .integrands
        .iter()
        .map(|s| integrands::parse(s).expect("validated with the experiment"))
        .collect();
    let dim = e.dim();
    let owned: Vec<(usize, usize)> = e
        .items()
        .into_iter()
        .enumerate()
        .filter(|&(item, _)| shard.owns(item))
        .map(|(_, sn)| sn)
        .collect();
    check_memory(e, file, owned.len())?;
    let per_item: Vec<Result<Vec<Cell>, ExperimentError>> = owned
        .into_par_iter()
        .map(|(si, ni)| {
            let mut cells = Vec::new();
            let (sampler, requested) = (&e.samplers[si], e.n[ni]);
            let fail = |integrand: &str, reason: String| ExperimentError::Cell {
                file: file.to_string(),
                sampler: sampler.clone(),
                n: requested,
                integrand: integrand.to_string(),
                reason,
            };
            let (s, n) = registry::build_nearest(sampler, requested, Some(dim), &[])
                .map_err(|err| fail("-", err.to_string()))?;
            // Realizations drawn once per item and shared by every integrand.
            // Each N its own stream, so the levels of a slope are independent.
            let seed = crate::rng::level_seed(e.seed, n);
            let sets = samplers::generate_sets(s.as_ref(), seed, e.sets, &|_| {})
                .map_err(|err| fail("-", err.to_string()))?;
            for (fi, f) in functions.iter().enumerate() {
                let p = sampler_variance(f.as_ref(), e.sets, VarianceForm::Auto, |r| {
                    Ok::<_, VarianceError>(sets[r].clone())
                })
                .map_err(|err| fail(&f.spec(), err.to_string()))?;
                let radial = match e.radial {
                    None => None,
                    Some(r) => {
                        let parts =
                            fourier_parts(f.as_ref(), r.half, RADIAL_TOLERANCE, e.sets, |r| {
                                Ok::<_, VarianceError>(sets[r].clone())
                            })
                            .map_err(|err| fail(&f.spec(), err.to_string()))?;
                        let radial = radial_from(&parts);
                        Some(RadialCell {
                            variance: radial.variance,
                            anisotropy_bound: radial.anisotropy_bound,
                            fourier: parts.estimate.variance,
                        })
                    }
                };
                cells.push(Cell {
                    sampler_index: si,
                    integrand_index: fi,
                    n_index: ni,
                    sampler: sampler.clone(),
                    integrand: f.spec(),
                    requested,
                    n,
                    variance: p.variance,
                    stderr: (e.sets >= 2).then_some(p.stderr),
                    rounding_bound: p.rounding_bound,
                    truncation_bound: p.truncation_bound,
                    method: p.method.to_string(),
                    radial,
                });
                on_cell();
            }
            Ok(cells)
        })
        .collect();
    let mut cells = Vec::new();
    for item in per_item {
        cells.extend(item?);
    }
    Ok(cells)
}

/// Items run concurrently, each checking its own allocations against the
/// same free memory: the budget must hold as many items at once as rayon
/// runs (its threads, at most `items`), each with its sets at the largest N
/// and, with the radial comparison, a plan and the spectra of its box.
fn check_memory(e: &Experiment, file: &str, items: usize) -> Result<(), ExperimentError> {
    let at_once = rayon::current_num_threads().min(items).max(1) as f64;
    let dim = e.dim();
    let largest = e
        .samplers
        .iter()
        .flat_map(|s| {
            e.n.iter().map(move |&n| {
                registry::build_nearest(s, n, Some(dim), &[]).map_or(n, |(_, used)| used)
            })
        })
        .max()
        .unwrap_or(0) as f64;
    let sets = e.sets as f64 * largest * dim as f64 * 8.0;
    let radial = match e.radial {
        None => Some(0.0),
        Some(r) => {
            let freqs = crate::spectrum::FrequencyBox { dim, half: r.half };
            // The plan, and per frequency the mean power, P_f, the ring
            // index and a shell entry (8 bytes each).
            crate::spectrum::nufft::nufft_memory_bytes(&freqs)
                .zip(freqs.checked_len())
                .map(|(plan, len)| plan + 32.0 * len as f64)
        }
    };
    let what = match at_once as usize {
        1 => "one experiment item".to_string(),
        k => format!("{k} experiment items at once"),
    };
    let lower = if e.radial.is_some() {
        "lower radial.half, n or sets, or run fewer threads (RAYON_NUM_THREADS)"
    } else {
        "lower n or sets, or run fewer threads (RAYON_NUM_THREADS)"
    };
    crate::memory::check(&what, radial.map(|r| at_once * (sets + r)), lower).map_err(|err| {
        ExperimentError::Invalid {
            file: file.to_string(),
            reason: err.to_string(),
        }
    })
}

/// The cells of a complete set of shards of one experiment, in the single
/// run's order. Shard files are read back from disk, so the experiment they
/// carry is validated again, and each shard must hold exactly the cells its
/// items give (every integrand of every item it owns, once, labelled as the
/// experiment says).
///
/// # Errors
/// [`ExperimentError::Invalid`] when the shards disagree on the experiment,
/// miss or repeat a shard, carry an invalid experiment, or hold a cell that
/// is missing, repeated, foreign to the shard or mislabelled.
pub fn merge_shards(
    shards: &[ShardFile],
) -> Result<(Experiment, String, Vec<Cell>), ExperimentError> {
    let first = shards.first().ok_or_else(|| ExperimentError::Invalid {
        file: "-".into(),
        reason: "no shard files to merge".into(),
    })?;
    let invalid = |reason: String| ExperimentError::Invalid {
        file: first.file.clone(),
        reason,
    };
    let parts: Vec<Shard> = shards.iter().map(|s| s.shard).collect();
    Shard::check_split(
        &parts,
        |j| shards[j].experiment == first.experiment,
        "experiment",
    )
    .map_err(invalid)?;
    let e = &first.experiment;
    e.validate(&first.file)?;
    let canonical: Vec<String> = e
        .integrands
        .iter()
        .map(|spec| integrands::parse(spec).map(|f| f.spec()))
        .collect::<Result<_, _>>()
        .map_err(|err| invalid(err.to_string()))?;
    for s in shards {
        check_shard_cells(e, &canonical, s).map_err(|reason| {
            invalid(format!(
                "shard {}/{}: {reason}",
                s.shard.index, s.shard.count
            ))
        })?;
    }
    let mut cells: Vec<Cell> = shards
        .iter()
        .flat_map(|s| s.cells.iter().cloned())
        .collect();
    let items = first.experiment.items();
    let order = |c: &Cell| {
        (
            items
                .iter()
                .position(|&(s, n)| s == c.sampler_index && n == c.n_index)
                .unwrap_or(usize::MAX),
            c.integrand_index,
        )
    };
    cells.sort_by_key(order);
    Ok((first.experiment.clone(), first.file.clone(), cells))
}

/// Checks that shard `s` of experiment `e` holds each cell its items give
/// exactly once and nothing else; `canonical` are the integrands' specs as
/// cells name them.
fn check_shard_cells(e: &Experiment, canonical: &[String], s: &ShardFile) -> Result<(), String> {
    let describe = |(si, ni, fi): (usize, usize, usize)| match (
        e.samplers.get(si),
        e.n.get(ni),
        canonical.get(fi),
    ) {
        (Some(sampler), Some(n), Some(f)) => format!("`{sampler}` at n = {n} on `{f}`"),
        _ => format!("sampler {si}, n index {ni}, integrand {fi} (out of range)"),
    };
    let owned: std::collections::BTreeSet<(usize, usize, usize)> = e
        .items()
        .into_iter()
        .enumerate()
        .filter(|&(item, _)| s.shard.owns(item))
        .flat_map(|(_, (si, ni))| (0..canonical.len()).map(move |fi| (si, ni, fi)))
        .collect();
    let mut expected = owned.clone();
    for c in &s.cells {
        let key = (c.sampler_index, c.n_index, c.integrand_index);
        if !owned.contains(&key) {
            return Err(format!(
                "holds the cell of {}, which is not one of its items",
                describe(key)
            ));
        }
        if !expected.remove(&key) {
            return Err(format!("holds the cell of {} twice", describe(key)));
        }
        let (si, ni, fi) = key;
        if c.sampler != e.samplers[si] || c.requested != e.n[ni] || c.integrand != canonical[fi] {
            return Err(format!(
                "the cell of {} is labelled `{}` at n = {} on `{}`",
                describe(key),
                c.sampler,
                c.requested,
                c.integrand
            ));
        }
    }
    if let Some(key) = expected.into_iter().next() {
        return Err(format!("misses the cell of {}", describe(key)));
    }
    // What a run computes from the experiment alone: the N each sampler
    // uses (the seed follows from it) and the form each integrand takes.
    // A hand-edited shard (n: 256 -> 257) was merged as if it had run.
    for c in &s.cells {
        let key = (c.sampler_index, c.n_index, c.integrand_index);
        let (_, n) = registry::build_nearest(&c.sampler, c.requested, Some(e.dim()), &[])
            .map_err(|err| format!("the cell of {}: {err}", describe(key)))?;
        if c.n != n {
            return Err(format!(
                "the cell of {} says N = {}, but that sampler runs at N = {n}: the shard was \
                 edited or written by another version",
                describe(key),
                c.n
            ));
        }
        let f = integrands::parse(&c.integrand).map_err(|err| err.to_string())?;
        let method = if f.autocov(&vec![0.0; f.dim()]).is_some() {
            "spatial"
        } else {
            "fourier"
        };
        if c.method != method {
            return Err(format!(
                "the cell of {} says method `{}`, but a run uses `{method}` there",
                describe(key),
                c.method
            ));
        }
    }
    Ok(())
}
