//! The experiment file: what to run, validated before anything runs.

use serde::{Deserialize, Serialize};

/// What is wrong with an experiment or its run.
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    /// The file is not a valid experiment.
    #[error("{file}: {reason}")]
    Invalid {
        /// The experiment file.
        file: String,
        /// What is wrong.
        reason: String,
    },
    /// A figure of a figure experiment failed.
    #[error("{file}: figures[{index}]: {reason}")]
    Figure {
        /// The experiment file.
        file: String,
        /// The figure's index in the file.
        index: usize,
        /// The error.
        reason: String,
    },
    /// A computation failed.
    #[error("{file}: {sampler} at N = {n} on {integrand}: {reason}")]
    Cell {
        /// The experiment file.
        file: String,
        /// Sampler.
        sampler: String,
        /// Requested N.
        n: usize,
        /// Integrand.
        integrand: String,
        /// The error.
        reason: String,
    },
}

/// A declarative experiment (see docs/formats.md).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Experiment {
    /// A plain file name: the report's title and results/<name>.
    pub name: String,
    /// A paragraph for the report.
    #[serde(default)]
    pub description: String,
    /// `variance` when given (the default kind; `figures` is
    /// [`super::FigureExperiment`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<String>,
    /// Sampler names (with `name:key=value` parameters if any).
    pub samplers: Vec<String>,
    /// Integrand specs, all of one dimension.
    pub integrands: Vec<String>,
    /// Requested N values (each sampler uses its nearest valid N).
    pub n: Vec<usize>,
    /// Realizations per (sampler, N).
    #[serde(default = "default_sets")]
    pub sets: usize,
    /// Seed of the realizations.
    #[serde(default)]
    pub seed: u64,
    /// Also the radial (isotropic) predictor, from the same realizations,
    /// against the reference form: where a radial average holds and where
    /// it fails (Pilleboue et al. 2015, §5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radial: Option<RadialComparison>,
}

/// The radial predictor's box (`"radial": {"half": 255}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, expecting = "radial: an object `{ \"half\": K }`")]
pub struct RadialComparison {
    /// The radial and Fourier forms' box |k|∞ ≤ half.
    pub half: usize,
}

/// Most frequencies the radial comparison's box may hold (the spectra of a
/// cell take 16 bytes each, twice).
const RADIAL_FREQUENCIES: u64 = 1 << 26;

/// Checks that `name` is a plain file name (the results folder of an
/// experiment, a figure's file): not empty, `.` or `..`, no `/` or `\\`,
/// at most 100 bytes.
pub(super) fn plain_name(name: &str) -> Result<(), String> {
    let plain = !name.is_empty()
        && !matches!(name, "." | "..")
        && !name.contains(['/', '\\', '\0'])
        && name.len() <= 100;
    if plain {
        Ok(())
    } else {
        Err(format!(
            "name `{}` must be a plain file name (no / or \\, not empty, . or .., at most 100 bytes): it names a folder or file of the results",
            name.escape_debug()
        ))
    }
}

fn default_sets() -> usize {
    16
}

impl Experiment {
    /// Parses and validates the text of file `file`.
    ///
    /// # Errors
    /// [`ExperimentError::Invalid`] naming the file and the rule broken.
    pub fn parse(text: &str, file: &str) -> Result<Self, ExperimentError> {
        let e: Experiment = crate::io::from_json(text).map_err(|err| ExperimentError::Invalid {
            file: file.to_string(),
            reason: format!("not a valid experiment: {err}"),
        })?;
        e.validate(file)?;
        Ok(e)
    }

    /// Checks the rules [`Experiment::parse`] enforces, for an experiment
    /// read some other way (e.g. inside a shard file); `file` names it in
    /// the error.
    ///
    /// # Errors
    /// [`ExperimentError::Invalid`] naming the file and the rule broken.
    pub fn validate(&self, file: &str) -> Result<(), ExperimentError> {
        let e = self;
        let invalid = |reason: String| ExperimentError::Invalid {
            file: file.to_string(),
            reason,
        };
        plain_name(&e.name).map_err(invalid)?;
        if let Some(kind) = e.kind.as_deref().filter(|k| *k != "variance") {
            return Err(invalid(format!(
                "kind `{kind}`: this reads variance experiments (kind `variance`, the default); \
                 ExperimentFile::parse reads either kind"
            )));
        }
        for (field, empty) in [
            ("samplers", e.samplers.is_empty()),
            ("integrands", e.integrands.is_empty()),
            ("n", e.n.is_empty()),
        ] {
            if empty {
                return Err(invalid(format!("`{field}` is empty; give at least one")));
            }
        }
        if e.sets == 0 {
            return Err(invalid("`sets` is 0; give at least 1".into()));
        }
        let mut dims = Vec::new();
        let mut canonical: Vec<String> = Vec::new();
        for spec in &e.integrands {
            let f = crate::integrands::parse(spec).map_err(|err| invalid(err.to_string()))?;
            if let Some(i) = canonical.iter().position(|c| *c == f.spec()) {
                return Err(invalid(format!(
                    "integrands `{}` and `{spec}` are the same integrand ({}): list each once",
                    e.integrands[i],
                    f.spec()
                )));
            }
            canonical.push(f.spec());
            dims.push(f.dim());
        }
        if let Some(i) = dims.iter().position(|&d| d != dims[0]) {
            return Err(invalid(format!(
                "all integrands of an experiment must have the same dimension: `{}` is {}D, \
                 `{}` is {}D",
                e.integrands[0], dims[0], e.integrands[i], dims[i]
            )));
        }
        if let Some(r) = e.radial {
            if let Some(spec) = e
                .integrands
                .iter()
                .find(|s| crate::integrands::parse(s).is_ok_and(|f| !f.has_fourier()))
            {
                return Err(invalid(format!(
                    "radial: integrand `{spec}` has no Fourier transform, which the radial and Fourier forms need"
                )));
            }
            let side = 2 * r.half as u64 + 1;
            let frequencies = side.checked_pow(dims[0] as u32).unwrap_or(u64::MAX);
            if r.half == 0 {
                return Err(invalid(
                    "radial.half = 0: the box |k| <= half must hold a frequency besides 0; give \
                     at least 1"
                        .into(),
                ));
            }
            if frequencies > RADIAL_FREQUENCIES {
                return Err(invalid(format!(
                    "radial.half = {}: the box of (2·half + 1)^{} = {frequencies} frequencies in \
                     {}D is over the {RADIAL_FREQUENCIES} allowed",
                    r.half, dims[0], dims[0]
                )));
            }
        }
        for (i, sampler) in e.samplers.iter().enumerate() {
            if e.samplers[..i].contains(sampler) {
                return Err(invalid(format!("sampler `{sampler}` is listed twice")));
            }
            let mut used: Vec<(usize, usize)> = Vec::new();
            for &requested in &e.n {
                let (_, n) = crate::registry::build_nearest(sampler, requested, Some(dims[0]), &[])
                    .map_err(|err| {
                        invalid(format!("sampler `{sampler}` at n = {requested}: {err}"))
                    })?;
                if let Some((earlier, _)) = used.iter().find(|(_, m)| *m == n) {
                    return Err(invalid(format!(
                        "n = {earlier} and {requested} both become N = {n} for `{sampler}` (its nearest valid N): give N values that stay distinct"
                    )));
                }
                used.push((requested, n));
            }
        }
        Ok(())
    }

    /// The dimension of its integrands.
    pub fn dim(&self) -> usize {
        crate::integrands::parse(&self.integrands[0]).map_or(2, |f| f.dim())
    }

    /// Work items in their fixed order: (sampler index, N index).
    pub fn items(&self) -> Vec<(usize, usize)> {
        (0..self.samplers.len())
            .flat_map(|s| (0..self.n.len()).map(move |n| (s, n)))
            .collect()
    }
}
