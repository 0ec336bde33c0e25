//! Argument value parsers shared by subcommands.

use anyhow::{Context, bail};

/// Parses `key=value`.
pub fn key_value(text: &str) -> Result<(String, String), String> {
    match text.split_once('=') {
        Some((k, v)) if !k.trim().is_empty() => Ok((k.trim().to_string(), v.trim().to_string())),
        _ => Err(format!("`{text}` is not of the form key=value")),
    }
}

/// Parses a list of dimension indices such as `0,2`, requiring `count` of them.
pub fn dims(text: &str, count: usize) -> anyhow::Result<Vec<usize>> {
    let dims = text
        .split(',')
        .map(|t| t.trim().parse::<usize>())
        .collect::<Result<Vec<_>, _>>()
        .with_context(|| {
            format!("--dims `{text}`: expected {count} comma-separated indices such as 0,2")
        })?;
    if dims.len() != count {
        bail!(
            "--dims `{text}`: expected {count} indices, found {}",
            dims.len()
        );
    }
    Ok(dims)
}

/// How realizations of a sampler are drawn: how many, from which seed, with
/// which sampler parameters (shared by the commands that draw sets).
#[derive(clap::Args)]
pub struct DrawArgs {
    /// Realizations to draw (with a sampler; default 16).
    #[arg(long = "sets")]
    sets_given: Option<usize>,
    /// Seed: the same seed gives bit-identical realizations for any thread count.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Sampler parameter key=value (repeatable; see `varspec sample --list`).
    #[arg(long = "param", value_parser = key_value)]
    pub params: Vec<(String, String)>,
}

impl DrawArgs {
    /// Realizations to draw: --sets, default 16.
    pub fn sets(&self) -> usize {
        self.sets_given.unwrap_or(16)
    }

    /// Refuses more sets than the machine can hold results for: analyses
    /// draw sets one at a time but keep a few numbers per set (estimates,
    /// sums), 64 bytes an ample bound.
    pub fn check_results_memory(&self) -> anyhow::Result<()> {
        varspec::memory::check(
            &format!("the per-set results of {} realizations", self.sets()),
            Some(self.sets() as f64 * 64.0),
            "lower --sets",
        )?;
        Ok(())
    }

    /// Refuses --sets and --param where sets come from a file (they would
    /// be silently ignored).
    pub fn refuse_with_file(&self, file: &std::path::Path) -> anyhow::Result<()> {
        if self.sets_given.is_some() || !self.params.is_empty() {
            anyhow::bail!(
                "--sets and --param apply to --sampler; {} is read whole, every set in it is used",
                file.display()
            );
        }
        Ok(())
    }
}

/// Checks every output before any work starts (a missing folder, a folder
/// given as a file), so a long run does not end in a failed write.
pub fn check_outputs<'a>(
    paths: impl IntoIterator<Item = Option<&'a std::path::Path>>,
) -> anyhow::Result<()> {
    for path in paths.into_iter().flatten() {
        varspec::io::check_output(path)?;
    }
    Ok(())
}

/// A point count N: a whole number ≥ 1, written plainly (1024) or in
/// scientific notation when that is whole (1e6, 2.5e5); negative, fractional
/// and huge values are refused with what was typed.
pub fn count(text: &str) -> Result<usize, String> {
    if let Ok(n) = text.parse::<usize>() {
        return if n >= 1 {
            Ok(n)
        } else {
            Err("a count of points must be at least 1".into())
        };
    }
    match text.parse::<f64>() {
        Ok(v) if v < 0.0 => Err(format!(
            "`{text}` is negative; a count of points is a whole number >= 1"
        )),
        Ok(v) if v.fract() != 0.0 => Err(format!("`{text}` is not a whole number of points")),
        Ok(v) if v >= 1.0 && v < 2f64.powi(52) => Ok(v as usize),
        Ok(v) if v >= 1.0 => Err(format!(
            "`{text}` is more points than this tool holds (fewer than 2^32 coordinates)"
        )),
        Ok(_) => Err("a count of points must be at least 1".into()),
        Err(_) => Err(format!(
            "`{text}` is not a count of points (a whole number such as 1024 or 1e6)"
        )),
    }
}
