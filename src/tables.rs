//! Pattern tables for renderers (docs/formats.md, "Pattern tables"): the
//! metadata a table carries — where its sets came from, their layout, what
//! they were designed for, and their predicted variance on reference
//! integrands. The formats themselves are written by [`crate::io::tables`].

pub mod shard;

use crate::integrands;
use crate::io::tables::{TableFormat, TableMetadata, to_unit_f32, values_digest};
use crate::points::PointSet;
use crate::registry;
use crate::samplers::SamplerError;
use crate::variance::{VarianceError, spatial_variance};

/// Reference integrands whose predicted variance goes into the metadata.
pub const REFERENCE_INTEGRANDS: [&str; 4] = [
    "disk:r=0.3",
    "box:w=0.5,h=0.25,angle=30",
    "gaussian:sx=0.1,sy=0.05,angle=20",
    "halfplane:angle=17,offset=0.07",
];

/// Pair evaluations (reference integrands × N² × sets) the predicted
/// variances may cost unless asked for (~10 s on 2 cores).
pub const VARIANCE_BUDGET: u128 = 1 << 28;

/// Where a table's sets came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Provenance {
    /// Sampler spec, or the source file.
    pub source: String,
    /// Sampler parameters.
    pub params: Vec<(String, String)>,
    /// Seed of the sampler's sets; `None` for sets read from a file (drawn
    /// elsewhere, with a seed the file does not record).
    pub seed: Option<u64>,
    /// What the sets were designed for ([`optimized_for`]).
    pub optimized_for: String,
    /// What a padded 4D table's dimensions are ([`dimensions`]).
    pub dimensions: Option<String>,
}

/// Whether the predicted variances are in the metadata.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PredictedVariances {
    /// Computed.
    Computed,
    /// Left out: the reference integrands are 2D.
    NotTwoD,
    /// Left out: this many pair evaluations exceed [`VARIANCE_BUDGET`].
    OverBudget {
        /// Pair evaluations they would cost.
        pairs: u128,
    },
}

/// What stops a table's metadata.
#[derive(Debug, thiserror::Error)]
pub enum TablesError {
    /// No sets.
    #[error("a table needs at least one set")]
    NoSets,
    /// Sets of different sizes.
    #[error(
        "{source_name}: a table needs every set to have the same N (found {first} and {other})"
    )]
    MixedSizes {
        /// The source.
        source_name: String,
        /// N of the first set.
        first: usize,
        /// Another N.
        other: usize,
    },
    /// A predicted variance failed.
    #[error(transparent)]
    Variance(#[from] VarianceError),
    /// A sampler spec that does not resolve.
    #[error(transparent)]
    Sampler(#[from] SamplerError),
}

/// The domain and estimator sets of sampler `spec` (with `params`) were
/// designed for: `torus` or `square` for the blue-noise sampler (its
/// `domain` parameter), `none` for a classic sampler, `unknown` without a
/// sampler (a converted file).
///
/// # Errors
/// An unknown sampler.
pub fn optimized_for(
    spec: Option<&str>,
    params: &[(String, String)],
) -> Result<String, SamplerError> {
    let Some(spec) = spec else {
        return Ok("unknown".into());
    };
    let (name, params) = registry::split_spec(spec, params)?;
    Ok(if registry::find(name)?.name == "blue-noise" {
        params
            .iter()
            .rev()
            .find(|(k, _)| k == "domain")
            .map_or_else(|| "torus".to_string(), |(_, v)| v.clone())
    } else {
        "none".to_string()
    })
}

/// What the dimensions of a padded 4D table are, from the sampler's spec
/// and parameters: dims 0, 1 the (x, y) half and 2, 3 the (u, v) half, two
/// independent 2D sets whose points are paired by a uniformly random
/// permutation (padding: Cook 1986; Singh & Jarosz 2017, §5). `None` for
/// every other sampler (their dimensions are symmetric, or a sequence's
/// own) and for sets read from a file.
///
/// # Errors
/// An unknown sampler or a malformed spec ([`registry::split_spec`]).
pub fn dimensions(
    spec: Option<&str>,
    params: &[(String, String)],
) -> Result<Option<String>, SamplerError> {
    let Some(spec) = spec else {
        return Ok(None);
    };
    let (name, params) = registry::split_spec(spec, params)?;
    let info = registry::find(name)?;
    let param = |key: &str| {
        crate::samplers::config::param_or_default(&params, info.params, key)
            .unwrap_or_default()
            .to_string()
    };
    let halves = match info.name {
        "umj" => {
            let half = param("pairs");
            [half.clone(), half]
        }
        "padded" => [param("xy"), param("uv")],
        _ => return Ok(None),
    };
    Ok(Some(format!(
        "dims 0, 1: (x, y) drawn by {}; dims 2, 3: (u, v) drawn by {}, independently; point i \
         of the table pairs them by a uniformly random permutation (padding)",
        halves[0], halves[1]
    )))
}

/// The metadata of a table of `sets` in `format`; the predicted variances
/// (spatial form, mean over the sets, of the values the format stores:
/// f32 tables' truncated ones) are computed for 2D sets when
/// `force_variance` or when they cost at most [`VARIANCE_BUDGET`] pair
/// evaluations, and the second value says which.
///
/// # Errors
/// No sets, sets of different N, or a failed prediction.
pub fn metadata(
    sets: &[PointSet],
    provenance: Provenance,
    format: TableFormat,
    force_variance: bool,
) -> Result<(TableMetadata, PredictedVariances), TablesError> {
    let first = sets.first().ok_or(TablesError::NoSets)?;
    let (n, dim) = (first.len(), first.dim());
    if let Some(other) = sets.iter().find(|s| s.len() != n) {
        return Err(TablesError::MixedSizes {
            source_name: provenance.source,
            first: n,
            other: other.len(),
        });
    }
    let pairs = REFERENCE_INTEGRANDS.len() as u128 * (n as u128).pow(2) * sets.len() as u128;
    let status = if dim != 2 {
        PredictedVariances::NotTwoD
    } else if force_variance || pairs <= VARIANCE_BUDGET {
        PredictedVariances::Computed
    } else {
        PredictedVariances::OverBudget { pairs }
    };
    // A single-precision table is predicted on the values it stores.
    let single = matches!(format, TableFormat::F32 | TableFormat::CHeader);
    let stored: Option<Vec<PointSet>> =
        (single && status == PredictedVariances::Computed).then(|| {
            sets.iter()
                .map(|s| {
                    let coords = s
                        .coords()
                        .iter()
                        .map(|&x| f64::from(to_unit_f32(x)))
                        .collect();
                    let stored = PointSet::new(dim, coords)
                        .expect("f32 values of [0, 1) points lie in [0, 1)");
                    match s.density() {
                        Some(density) => stored.with_density(density),
                        None => Ok(stored),
                    }
                })
                .collect::<Result<_, _>>()
                .expect("the density was valid on the f64 set")
        });
    let sets = stored.as_deref().unwrap_or(sets);
    let predicted_variance = if status == PredictedVariances::Computed {
        REFERENCE_INTEGRANDS
            .iter()
            .map(|spec| -> Result<(String, f64), TablesError> {
                let f = integrands::parse(spec).expect("the reference integrands parse");
                let mut total = 0.0;
                for s in sets {
                    total += spatial_variance(s, f.as_ref())?.0;
                }
                Ok((f.spec(), total / sets.len() as f64))
            })
            .collect::<Result<_, _>>()?
    } else {
        Vec::new()
    };
    let value_type = format.value_type();
    let predicted_variance_skipped = match status {
        PredictedVariances::Computed => None,
        PredictedVariances::NotTwoD => Some(format!(
            "the reference integrands are 2D and the sets are {dim}D"
        )),
        PredictedVariances::OverBudget { pairs } => Some(format!(
            "{pairs:.3e} pair evaluations ({} integrands x N^2 x {} sets) exceed 2^28; pass \
             --variance to compute them",
            REFERENCE_INTEGRANDS.len(),
            sets.len()
        )),
    };
    let meta = TableMetadata {
        generator: format!("varspec {}", env!("CARGO_PKG_VERSION")),
        source: provenance.source,
        params: provenance.params,
        seed: provenance.seed,
        n,
        dim,
        sets: sets.len(),
        layout: format!("[set][point][dimension], {value_type}, values in [0, 1)"),
        values_digest: Some(values_digest(sets.iter().flat_map(|s| s.coords()).map(
            |&x| {
                if single { f64::from(to_unit_f32(x)) } else { x }
            },
        ))),
        optimized_for: provenance.optimized_for,
        dimensions: provenance.dimensions,
        predicted_variance,
        predicted_variance_skipped,
    };
    Ok((meta, status))
}
