//! The `key=value,key=value` parameter lists of specs: a sampler's
//! `padded:xy=cmj,uv=jitter`, an integrand's `disk:r=0.3,cx=0.2`, a family's
//! `disks:rmin=0.1`, a scene pixel's `scene:dof,px=3,py=4`. One parser, so
//! every spec refuses a malformed list the same way: an empty parameter
//! (`a=1,,b=2`, a trailing comma) is a typo, never skipped.

/// Why a parameter list was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ParamListError {
    /// Nothing between two commas, or before or after the list's ends.
    #[error("parameter {position} of `{list}` is empty (two commas in a row or a comma at an end)")]
    Empty {
        /// The list.
        list: String,
        /// Its 1-based position.
        position: usize,
    },
    /// A parameter without `=`, or with nothing before it.
    #[error("`{part}` is not key=value")]
    NotKeyValue {
        /// The parameter.
        part: String,
    },
}

/// The `(key, value)` pairs of `list`, each trimmed, in order; a blank list
/// has none. Values may hold `=` and `:` (a sampler spec as a value).
///
/// # Errors
/// [`ParamListError`] naming the empty or malformed parameter.
pub fn key_values(list: &str) -> Result<Vec<(&str, &str)>, ParamListError> {
    if list.trim().is_empty() {
        return Ok(Vec::new());
    }
    list.split(',')
        .enumerate()
        .map(|(i, part)| {
            if part.trim().is_empty() {
                return Err(ParamListError::Empty {
                    list: list.to_string(),
                    position: i + 1,
                });
            }
            match part.split_once('=') {
                Some((k, v)) if !k.trim().is_empty() => Ok((k.trim(), v.trim())),
                _ => Err(ParamListError::NotKeyValue {
                    part: part.trim().to_string(),
                }),
            }
        })
        .collect()
}

/// The weights a term of a sum of losses may carry (`W*TERM`: a square
/// design's `halfplanes+16*blue`, a 4D design's `xy:A;2*uv:B`). Weights are
/// relative; far outside this range the weighted loss's squared gradients
/// leave what f64 holds (`1e308*` turned the descent's positions into NaN,
/// `1e160*` stopped it silently).
pub const TERM_WEIGHTS: std::ops::RangeInclusive<f64> = 1e-6..=1e6;

/// The weight `text` of a term `W*TERM`, a number within [`TERM_WEIGHTS`].
///
/// # Errors
/// What the weight is not, for the caller's message.
pub fn term_weight(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(w) if TERM_WEIGHTS.contains(&w) => Ok(w),
        _ => Err(format!(
            "weight `{}` is not a number in [{:e}, {:e}] (weights are relative)",
            text.trim(),
            TERM_WEIGHTS.start(),
            TERM_WEIGHTS.end()
        )),
    }
}

/// A parameter value as a canonical spec writes it: the shortest decimal
/// that reads back to the same f64, in exponent form (`1e-8`) where the
/// plain form would spell out a run of zeros (below 1e-4 or from 1e15 on).
/// The parsers read both forms.
#[derive(Debug, Clone, Copy)]
pub struct SpecValue(pub f64);

impl std::fmt::Display for SpecValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a.is_finite() && a != 0.0 && !(1e-4..1e15).contains(&a) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spec_values_are_short_and_read_back_exactly() {
        for (v, text) in [
            (0.3, "0.3"),
            (-0.15, "-0.15"),
            (0.0, "0"),
            (45.0, "45"),
            (1e-4, "0.0001"),
            (1e-8, "1e-8"),
            (-2.5e-7, "-2.5e-7"),
            (1e15, "1e15"),
            (std::f64::consts::PI * 1e-16, "3.141592653589793e-16"),
        ] {
            assert_eq!(SpecValue(v).to_string(), text);
            assert_eq!(text.parse::<f64>().unwrap().to_bits(), v.to_bits());
        }
    }

    #[test]
    fn pairs_in_order_trimmed() {
        assert_eq!(
            key_values(" r = 0.3 ,uv=sobol:scramble=hash").unwrap(),
            vec![("r", "0.3"), ("uv", "sobol:scramble=hash")]
        );
        assert_eq!(key_values("").unwrap(), Vec::<(&str, &str)>::new());
        assert_eq!(key_values("  ").unwrap(), Vec::<(&str, &str)>::new());
    }

    #[test]
    fn empty_and_malformed_parameters_are_refused() {
        for (list, position) in [("a=1,,b=2", 2), ("a=1,", 2), (",a=1", 1), ("a=1, ,b=2", 2)] {
            assert_eq!(
                key_values(list),
                Err(ParamListError::Empty {
                    list: list.into(),
                    position
                }),
                "{list}"
            );
        }
        for (list, part) in [("a=1,b", "b"), ("=3", "=3"), ("a=1, =2", "=2")] {
            assert_eq!(
                key_values(list),
                Err(ParamListError::NotKeyValue { part: part.into() }),
                "{list}"
            );
        }
    }
}
