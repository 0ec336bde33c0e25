//! The request a sampler's constructor receives ([`Config`]: N, d and the
//! `key=value` parameters with their registered defaults), the descriptors
//! the registry lists ([`DimRange`], [`ParamInfo`]) and the integer helpers
//! the grid samplers share. The registry (src/registry.rs) builds a
//! [`Config`] and calls a sampler's `from_config`; samplers never see the
//! registry, so the two form no cycle.

use super::{Sampler, SamplerError};

/// The dimensions a sampler supports and the one it uses by default.
#[derive(Debug, Clone, Copy)]
pub struct DimRange {
    /// Smallest d.
    pub min: usize,
    /// Largest d.
    pub max: usize,
    /// d when none is given.
    pub default: usize,
}

/// One `--param key=value` a sampler accepts.
#[derive(Debug, Clone, Copy)]
pub struct ParamInfo {
    /// The key.
    pub key: &'static str,
    /// The default value, as text.
    pub default: &'static str,
    /// What it means.
    pub help: &'static str,
}

/// A validated request, handed to a sampler's constructor.
pub struct Config {
    pub sampler: &'static str,
    pub n: usize,
    pub dim: usize,
    params: Vec<(String, String)>,
    defaults: &'static [ParamInfo],
    build: BuildFn,
}

/// Builds a sampler by name (the registry's `build`), handed to
/// constructors that compose other samplers (padded pairs, an optimizer's
/// start) so that no sampler depends on the registry.
pub type BuildFn =
    fn(&str, usize, Option<usize>, &[(String, String)]) -> Result<Box<dyn Sampler>, SamplerError>;

impl Config {
    /// A request for sampler `sampler` with N = `n` in `dim` dimensions;
    /// `defaults` are its registered parameters, `build` builds others.
    pub fn new(
        sampler: &'static str,
        n: usize,
        dim: usize,
        params: Vec<(String, String)>,
        defaults: &'static [ParamInfo],
        build: BuildFn,
    ) -> Self {
        Config {
            sampler,
            n,
            dim,
            params,
            defaults,
            build,
        }
    }

    /// Another sampler by name, as the registry builds it (padded pairs,
    /// an optimizer's start).
    ///
    /// # Errors
    /// As the registry's `build`.
    pub fn build_other(
        &self,
        name: &str,
        n: usize,
        dim: Option<usize>,
        params: &[(String, String)],
    ) -> Result<Box<dyn Sampler>, SamplerError> {
        (self.build)(name, n, dim, params)
    }
    /// The value of `key`, or its registered default.
    pub fn param(&self, key: &'static str) -> &str {
        param_or_default(&self.params, self.defaults, key).expect("parameter keys are registered")
    }

    /// The value of `key` if it was given.
    pub fn given(&self, key: &str) -> Option<&str> {
        self.params
            .iter()
            .rev()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// An error for parameter `key` saying what is expected.
    pub fn bad_param(&self, key: &'static str, expected: impl Into<String>) -> SamplerError {
        SamplerError::Param {
            sampler: self.sampler,
            key,
            value: self.param(key).to_string(),
            expected: expected.into(),
        }
    }

    /// An error saying N must satisfy `rule`, with the nearest valid counts.
    pub fn bad_count(
        &self,
        rule: &'static str,
        below: Option<usize>,
        above: Option<usize>,
    ) -> SamplerError {
        SamplerError::Count {
            sampler: self.sampler.to_string(),
            dim: self.dim,
            n: self.n,
            rule,
            below,
            above,
        }
    }
}

/// The integer `⌊n^(1/d)⌋`, exactly.
pub(crate) fn integer_root(n: usize, d: usize) -> usize {
    let fits = |m: usize| m.checked_pow(d as u32).is_some_and(|p| p <= n);
    let mut m = (n as f64).powf(1.0 / d as f64).round() as usize;
    while m > 0 && !fits(m) {
        m -= 1;
    }
    while fits(m + 1) {
        m += 1;
    }
    m
}

/// `m^d`, saturating at `usize::MAX`.
pub(crate) fn pow_saturating(m: usize, d: usize) -> usize {
    m.checked_pow(d as u32).unwrap_or(usize::MAX)
}

/// The value of `key` in `params` (the last given wins), or its default
/// among `defaults`; `None` for a key that is neither.
pub fn param_or_default<'a>(
    params: &'a [(String, String)],
    defaults: &'a [ParamInfo],
    key: &str,
) -> Option<&'a str> {
    params
        .iter()
        .rev()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
        .or_else(|| defaults.iter().find(|p| p.key == key).map(|p| p.default))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_root_is_exact() {
        assert_eq!(integer_root(1, 2), 1);
        assert_eq!(integer_root(99, 2), 9);
        assert_eq!(integer_root(100, 2), 10);
        assert_eq!(integer_root(124, 3), 4);
        assert_eq!(integer_root(125, 3), 5);
        assert_eq!(integer_root(usize::MAX, 2), 4_294_967_295);
    }
}
