//! An experiment file of either kind, told apart by its `kind` field:
//! variance experiments ([`Experiment`]) and figure experiments
//! ([`FigureExperiment`]).

use super::figures::FigureExperiment;
use super::spec::{Experiment, ExperimentError};

/// An experiment file of either kind.
#[derive(Debug, Clone, PartialEq)]
pub enum ExperimentFile {
    /// Variances of samplers on integrands over N ([`Experiment`]).
    Variance(Experiment),
    /// Figures ([`FigureExperiment`]).
    Figures(FigureExperiment),
}

impl ExperimentFile {
    /// Parses file `file`'s text by its `kind` (absent: `variance`).
    ///
    /// # Errors
    /// As [`Experiment::parse`] and [`FigureExperiment::parse`].
    pub fn parse(text: &str, file: &str) -> Result<Self, ExperimentError> {
        // Not JSON at all (a trailing comma, a missing brace): say so here,
        // before guessing a kind the file never got to name.
        let value: serde_json::Value =
            crate::io::from_json(text).map_err(|reason| ExperimentError::Invalid {
                file: file.to_string(),
                reason: format!("not valid JSON: {reason}"),
            })?;
        let kind = value
            .get("kind")
            .and_then(|k| k.as_str())
            .map(str::to_owned);
        match kind.as_deref() {
            Some("figures") => FigureExperiment::parse(text, file).map(ExperimentFile::Figures),
            None | Some("variance") => Experiment::parse(text, file).map(ExperimentFile::Variance),
            Some(other) => Err(ExperimentError::Invalid {
                file: file.to_string(),
                reason: format!(
                    "kind `{other}`: an experiment's kind is `variance` (the default) or `figures`"
                ),
            }),
        }
    }

    /// Its name (the default output folder).
    pub fn name(&self) -> &str {
        match self {
            ExperimentFile::Variance(e) => &e.name,
            ExperimentFile::Figures(e) => &e.name,
        }
    }
}
