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
