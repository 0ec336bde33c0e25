//! The sampler registry: names, aliases, supported dimensions, constraints on
//! N and parameters of every sampler, in one table that both the command line
//! (`varspec sample --list`) and [`build`] read. It sits above both the
//! samplers (src/samplers) and the optimizer (src/optimize), which registers
//! its descent as the `blue-noise` sampler: neither depends on the registry.

use crate::optimized;
use crate::samplers::config::Config;
pub use crate::samplers::config::{DimRange, ParamInfo};
use crate::samplers::{
    Sampler, SamplerError, halton, isotropic_jitter, jitter, multijitter, nrooks, padded,
    poisson_disk, random, sobol,
};

/// A registered sampler.
pub struct SamplerInfo {
    /// Canonical name.
    pub name: &'static str,
    /// Other accepted names.
    pub aliases: &'static [&'static str],
    /// One line on what it is, with its reference.
    pub summary: &'static str,
    /// Supported dimensions.
    pub dims: DimRange,
    /// The constraint on N, in words.
    pub count: &'static str,
    /// Accepted parameters.
    pub params: &'static [ParamInfo],
    pub(crate) build: fn(&Config) -> Result<Box<dyn Sampler>, SamplerError>,
}

const ANY: DimRange = DimRange {
    min: 1,
    max: 64,
    default: 2,
};

/// Every sampler, in the order `--list` shows them.
pub const SAMPLERS: &[SamplerInfo] = &[
    SamplerInfo {
        name: "random",
        aliases: &[],
        summary: "independent uniform points (white noise)",
        dims: ANY,
        count: "any N",
        params: &[],
        build: random::from_config,
    },
    SamplerInfo {
        name: "regular",
        aliases: &["grid"],
        summary: "centres of the m^d grid cells (deterministic; randomize by shifting)",
        dims: ANY,
        count: "N = m^d",
        params: &[],
        build: jitter::regular_from_config,
    },
    SamplerInfo {
        name: "jitter",
        aliases: &["stratified"],
        summary: "one uniform point in each of the m^d grid strata",
        dims: ANY,
        count: "N = m^d",
        params: &[],
        build: jitter::jitter_from_config,
    },
    SamplerInfo {
        name: "uniform-jitter",
        aliases: &[],
        summary: "one random offset shared by all m^d strata (Ramamoorthi et al. 2012)",
        dims: ANY,
        count: "N = m^d",
        params: &[],
        build: jitter::uniform_jitter_from_config,
    },
    SamplerInfo {
        name: "isotropic-jitter",
        aliases: &["ijitter"],
        summary: "jittered grid of spacing 1/m, randomly rotated and shifted, clipped to the square: a random count of mean m^2, weight 1/lambda (Oztireli 2016)",
        dims: DimRange {
            min: 2,
            max: 2,
            default: 2,
        },
        count: "N = m^2, the expected count (each set's count is random)",
        params: &[],
        build: isotropic_jitter::from_config,
    },
    SamplerInfo {
        name: "nrooks",
        aliases: &["lhs"],
        summary: "N-rooks / Latin hypercube: one point per 1/N interval of every axis (McKay et al. 1979)",
        dims: ANY,
        count: "any N",
        params: &[],
        build: nrooks::from_config,
    },
    SamplerInfo {
        name: "multijitter",
        aliases: &["mj"],
        summary: "multi-jittered: jittered on an m x n grid and N-rooks (Chiu, Shirley & Wang 1994)",
        dims: DimRange {
            min: 2,
            max: 2,
            default: 2,
        },
        count: "any N = m*n; best when N has a divisor near sqrt(N)",
        params: &[ParamInfo {
            key: "m",
            default: "auto",
            help: "grid columns (a divisor of N); auto = largest divisor <= sqrt(N)",
        }],
        build: multijitter::multijitter_from_config,
    },
    SamplerInfo {
        name: "cmj",
        aliases: &[],
        summary: "correlated multi-jittered: one shuffle shared by all columns and one by all rows (Kensler 2013)",
        dims: DimRange {
            min: 2,
            max: 2,
            default: 2,
        },
        count: "any N = m*n; best when N has a divisor near sqrt(N)",
        params: &[ParamInfo {
            key: "m",
            default: "auto",
            help: "grid columns (a divisor of N); auto = largest divisor <= sqrt(N)",
        }],
        build: multijitter::cmj_from_config,
    },
    SamplerInfo {
        name: "lattice",
        aliases: &["rank1", "korobov"],
        summary: "randomly shifted integration lattice (Cranley & Patterson 1976): by default the one of N points with the best spectral test, rank-1 or not (Knuth, TAOCP 3.3.4)",
        dims: DimRange {
            min: 2,
            max: 2,
            default: 2,
        },
        count: "any N up to 2^20",
        params: &[ParamInfo {
            key: "g",
            default: "auto",
            help: "Korobov generator: the rank-1 lattice (i/N, g*i/N mod 1), 1 <= g < N; auto = the best spectral test over every lattice of N points",
        }],
        build: crate::samplers::lattice::from_config,
    },
    SamplerInfo {
        name: "umj",
        aliases: &[],
        summary: "4D (x,y,u,v): multi-jittered (x,y) and (u,v) sets paired by a random permutation",
        dims: DimRange {
            min: 4,
            max: 4,
            default: 4,
        },
        count: "any N = m*n; best when N has a divisor near sqrt(N)",
        params: &[
            ParamInfo {
                key: "pairs",
                default: "mj",
                help: "2D sets to pair: mj (multijitter) or cmj (correlated multi-jitter)",
            },
            ParamInfo {
                key: "m",
                default: "auto",
                help: "grid columns of each 2D set (a divisor of N); auto = largest divisor <= sqrt(N)",
            },
        ],
        build: padded::umj_from_config,
    },
    SamplerInfo {
        name: "padded",
        aliases: &[],
        summary: "4D (x,y,u,v): any 2D sampler on (x,y) and any on (u,v), paired by a random permutation (Cook 1986)",
        dims: DimRange {
            min: 4,
            max: 4,
            default: 4,
        },
        count: "an N both 2D samplers accept",
        params: &[
            ParamInfo {
                key: "xy",
                default: "jitter",
                help: "2D sampler of (x,y), with its default parameters",
            },
            ParamInfo {
                key: "uv",
                default: "jitter",
                help: "2D sampler of (u,v), with its default parameters",
            },
        ],
        build: padded::padded_from_config,
    },
    SamplerInfo {
        name: "poisson-disk",
        aliases: &["pd"],
        summary: "exactly N points at least r apart (toroidal), by grid-accelerated dart throwing",
        dims: DimRange {
            min: 2,
            max: 4,
            default: 2,
        },
        count: "any N",
        params: &[
            ParamInfo {
                key: "radius",
                default: "0.7",
                help: "r as a fraction of the densest-packing radius (2D: sqrt(2/(sqrt(3) N)), Lagae & Dutre 2008); jams near 0.78",
            },
            ParamInfo {
                key: "max-trials",
                default: "auto",
                help: "dart throws before giving up (a torus with no room left is reported at once); auto = max(10^7, 1000 N)",
            },
        ],
        build: poisson_disk::from_config,
    },
    SamplerInfo {
        name: "sobol",
        aliases: &[],
        summary: "Owen-scrambled Sobol' points (Joe & Kuo 2008 directions; nested uniform scrambling, Owen 1995)",
        dims: DimRange {
            min: 1,
            max: sobol::MAX_DIM,
            default: 2,
        },
        count: "any N with N*d < 2^32; (0,m,2)-net in dims 0,1 when N = 2^m",
        params: &[ParamInfo {
            key: "scramble",
            default: "owen",
            help: "owen: an independent flip per tree node; hash: Burley's faster Laine-Karras approximation (2020)",
        }],
        build: sobol::from_config,
    },
    SamplerInfo {
        name: "halton",
        aliases: &[],
        summary: "Halton points with random digit permutations (Matousek 1998 random digit scrambling)",
        dims: DimRange {
            min: 1,
            max: halton::MAX_DIM,
            default: 2,
        },
        count: "any N",
        params: &[],
        build: halton::from_config,
    },
    SamplerInfo {
        name: "blue-noise",
        aliases: &["optimized"],
        summary: "descent toward a target: on the torus (default: disk family, CCVT-like blue noise) or, with domain=square, on family MSEs of the unshifted estimator",
        dims: DimRange {
            min: 1,
            max: 4,
            default: 2,
        },
        count: "any N",
        params: &[
            ParamInfo {
                key: "domain",
                default: "torus",
                help: "torus (shift-randomized estimator) or square (unshifted, d = 2; starts from jitter, or CMJ where N is not m^2)",
            },
            ParamInfo {
                key: "target",
                default: "family:disks",
                help: "torus: family:disks, power:A, radial:FILE.csv or an integrand spec; square: default halfplanes+gaussians+16*blue (see varspec optimize points)",
            },
            ParamInfo {
                key: "iters",
                default: "1000",
                help: "maximum descent iterations per set (square: default 2000)",
            },
        ],
        build: optimized::from_config,
    },
];

/// The sampler registered under `name` or one of its aliases.
///
/// # Errors
/// [`SamplerError::Unknown`] listing the known names.
pub fn find(name: &str) -> Result<&'static SamplerInfo, SamplerError> {
    // Whitespace around names is ignored, as in integrand specs.
    let name = name.trim();
    SAMPLERS
        .iter()
        .find(|s| s.name == name || s.aliases.contains(&name))
        .ok_or_else(|| SamplerError::Unknown {
            name: name.to_string(),
            suggestion: crate::suggest::did_you_mean(
                name,
                SAMPLERS
                    .iter()
                    .flat_map(|s| std::iter::once(s.name).chain(s.aliases.iter().copied())),
            ),
            known: SAMPLERS
                .iter()
                .map(|s| s.name)
                .collect::<Vec<_>>()
                .join(", "),
        })
}

/// Sampler parameters as (key, value) pairs, later ones winning.
pub type Params = Vec<(String, String)>;

/// Splits `name:key=value,...` (shorthand for `name` with those
/// parameters) into the name and the parameters, `params` appended after
/// the shorthand's so they win.
///
/// # Errors
/// [`SamplerError::Syntax`] for a part that is not key=value,
/// [`SamplerError::RepeatedParam`] for a key given twice in one place.
pub fn split_spec<'a>(
    name: &'a str,
    params: &[(String, String)],
) -> Result<(&'a str, Params), SamplerError> {
    let repeated = |list: &[(String, String)]| {
        list.iter()
            .enumerate()
            .find(|(i, (k, _))| list[..*i].iter().any(|(j, _)| j == k))
            .map(|(_, (k, _))| SamplerError::RepeatedParam {
                spec: name.to_string(),
                key: k.clone(),
            })
    };
    if let Some(e) = repeated(params) {
        return Err(e);
    }
    let Some((name, rest)) = name.split_once(':') else {
        return Ok((name, params.to_vec()));
    };
    let mut all: Vec<(String, String)> = crate::spec_params::key_values(rest)
        .map_err(|reason| SamplerError::Syntax {
            spec: format!("{name}:{rest}"),
            reason,
        })?
        .into_iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    if let Some(e) = repeated(&all) {
        return Err(e);
    }
    all.extend_from_slice(params);
    Ok((name, all))
}

/// The parameters a sampler is built with, one per key: [`split_spec`]'s
/// with each key's last value (`--param` overrides the shorthand), in the
/// order the keys first appear.
///
/// # Errors
/// As [`split_spec`].
pub fn resolved_params<'a>(
    name: &'a str,
    params: &[(String, String)],
) -> Result<(&'a str, Params), SamplerError> {
    let (base, given) = split_spec(name, params)?;
    let mut resolved: Params = Vec::with_capacity(given.len());
    for (key, value) in given {
        match resolved.iter_mut().find(|(k, _)| *k == key) {
            Some(slot) => slot.1 = value,
            None => resolved.push((key, value)),
        }
    }
    Ok((base, resolved))
}

/// The sampler as it runs, for titles and metadata: `spec` as written when
/// no `--param` is given, else its name with the resolved parameters
/// (`padded:xy=cmj` with `--param xy=jitter` is `padded:xy=jitter`).
///
/// # Errors
/// As [`split_spec`].
pub fn label(spec: &str, params: &[(String, String)]) -> Result<String, SamplerError> {
    if params.is_empty() {
        return Ok(spec.trim().to_string());
    }
    let (base, resolved) = resolved_params(spec, params)?;
    let pairs: Vec<String> = resolved.iter().map(|(k, v)| format!("{k}={v}")).collect();
    Ok(format!("{}:{}", base.trim(), pairs.join(",")))
}

/// Builds sampler `name` for N = `n` points in `dim` dimensions (the
/// sampler's default when `None`) with `key=value` parameters.
///
/// # Errors
/// [`SamplerError`] for an unknown name or parameter, an unsupported
/// dimension, N = 0, an N that does not fit (naming the nearest valid N), or
/// an invalid parameter value.
pub fn build(
    name: &str,
    n: usize,
    dim: Option<usize>,
    params: &[(String, String)],
) -> Result<Box<dyn Sampler>, SamplerError> {
    let (name, params) = split_spec(name, params)?;
    let params = params.as_slice();
    let info = find(name)?;
    let sampler = info.name;
    let dim = dim.unwrap_or(info.dims.default);
    crate::samplers::check_size(sampler, n, dim, info.dims.min..=info.dims.max)?;
    // One set is held at a time per thread (and one more by the caller):
    // refuse a single set that does not fit before drawing it.
    let threads = rayon::current_num_threads() as f64 + 1.0;
    crate::memory::check(
        &format!(
            "{sampler}: a set of {n} points in {dim}D, {threads} sets held at once (one per \
             thread and one being written)"
        ),
        Some(n as f64 * dim as f64 * 8.0 * threads),
        "lower -n",
    )?;
    if let Some((key, _)) = params
        .iter()
        .find(|(k, _)| !info.params.iter().any(|p| p.key == k))
    {
        let known = info.params.iter().map(|p| p.key).collect::<Vec<_>>();
        // `padded:uv=poisson-disk:radius=0.5,max-trials=9` splits at every
        // comma: the nested spec's second parameter lands here.
        let hint = params
            .iter()
            .find(|(_, v)| v.contains(':'))
            .map(|(k, v)| {
                format!(
                    " (if `{key}` belongs to `{k}={v}`: the shorthand splits at every comma, so give a nested spec with several parameters as --param '{k}={v},{key}=...')"
                )
            })
            .unwrap_or_default();
        return Err(SamplerError::UnknownParam {
            sampler,
            key: key.clone(),
            suggestion: crate::suggest::did_you_mean(key, known.iter().copied()),
            known: if known.is_empty() {
                "none".into()
            } else {
                known.join(", ")
            },
            hint,
        });
    }
    let config = Config::new(sampler, n, dim, params.to_vec(), info.params, build);
    (info.build)(&config)
}

/// Like [`build`], but when N does not fit the sampler's structure, uses the
/// nearest valid N instead (the larger one on a tie) and returns it.
///
/// # Errors
/// As [`build`] for everything but the count.
pub fn build_nearest(
    name: &str,
    n: usize,
    dim: Option<usize>,
    params: &[(String, String)],
) -> Result<(Box<dyn Sampler>, usize), SamplerError> {
    match build(name, n, dim, params) {
        Err(SamplerError::Count { below, above, .. }) => {
            let nearest = match (below, above) {
                (Some(b), Some(a)) if n - b < a - n => b,
                (_, Some(a)) => a,
                (Some(b), None) => b,
                (None, None) => n,
            };
            build(name, nearest, dim, params).map(|s| (s, nearest))
        }
        other => other.map(|s| (s, n)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_aliases_are_unique() {
        let mut all: Vec<&str> = SAMPLERS
            .iter()
            .flat_map(|s| std::iter::once(s.name).chain(s.aliases.iter().copied()))
            .collect();
        let count = all.len();
        all.sort_unstable();
        all.dedup();
        assert_eq!(all.len(), count);
    }

    #[test]
    fn names_are_found_whatever_whitespace_surrounds_them() {
        assert_eq!(find(" cmj ").unwrap().name, "cmj");
        assert_eq!(
            build(" cmj:m=4", 16, None, &[]).unwrap().points_per_set(),
            16
        );
    }

    #[test]
    fn request_errors_are_specific() {
        assert!(matches!(
            build("nope", 4, None, &[]),
            Err(SamplerError::Unknown { .. })
        ));
        assert!(matches!(
            build("random", 0, None, &[]),
            Err(SamplerError::ZeroPoints { .. })
        ));
        assert!(matches!(
            build("cmj", 16, Some(3), &[]),
            Err(SamplerError::Dimension { dim: 3, .. })
        ));
        let p = vec![("radius".to_string(), "0.5".to_string())];
        assert!(matches!(
            build("random", 4, None, &p),
            Err(SamplerError::UnknownParam { .. })
        ));
        let e = build("jitter", 1000, None, &[]).err().unwrap();
        assert_eq!(
            e,
            SamplerError::Count {
                sampler: "jitter".into(),
                dim: 2,
                n: 1000,
                rule: "N = m^d",
                below: Some(961),
                above: Some(1024)
            }
        );
        assert!(e.to_string().contains("961 or 1024"), "{e}");
    }
}
