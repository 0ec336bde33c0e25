//! Families of integrands on the unit square: the random integrands a
//! design on the square is scored on, each with a documented distribution.
//! `gaussians` and `halfplanes` have the distributions of UTK's integration
//! tests (Perrier, Doignies, Coeurjolly et al., "UTK: Unified ToolKit for
//! point sets", `GaussianIntegrands.hpp`, `HeavisideIntegrands.hpp`), so
//! scores are comparable with that peer's.
//!
//! | spec | member |
//! |---|---|
//! | `gaussians[:vmin=0.01,vmax=1]` | exp(−½(x−μ)ᵀA(x−μ)), μ ~ U[0,1]², A = R diag(1/v₁, 1/v₂) Rᵀ, v_i ~ U[vmin, vmax] (variances), R a rotation by θ ~ U[0, π) |
//! | `halfplanes` | [n·(x − p) > 0], n = (cos θ, sin θ), θ ~ U[0, 2π), p ~ U[0,1]² |
//! | `disks[:rmin=0.05,rmax=0.45]` | [|x − c| < r], c ~ U[0,1]², r ~ U[rmin, rmax] |
//! | `boxes[:smin=0.05,smax=0.45]` | a square of side s ~ U[smin, smax] centred at c ~ U[0,1]², rotated by θ ~ U[0, π/2) |
//! | `file:PATH` | the 2D catalogue integrands listed in PATH, one spec per line (`#` comments), each once |
//!
//! Member m of a family drawn with seed S comes from its own stream of
//! (S, m), apart from any sampler's streams of the same seed, so a family
//! sample is reproducible and disjoint samples use other seeds.

use std::f64::consts::PI;

use super::integrands::{Box2, Catalogue, Disk, Gaussian, HalfPlane, SquareIntegrand};
use crate::rng::{SetRng, set_rng, uniform};
use crate::spec_params::SpecValue;

/// Stream offset of family members, apart from the samplers' draws of the
/// same seed.
const MEMBER_STREAM: u64 = 0x4641_4d49_4c59_5f4d;

/// What is wrong with a family spec.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("integrand family `{spec}`: {reason}")]
pub struct FamilyError {
    /// The spec.
    pub spec: String,
    /// What is wrong.
    pub reason: String,
}

/// A family of square integrands.
#[derive(Debug, Clone, PartialEq)]
pub enum Family {
    /// Anisotropic Gaussians of peak 1 with variances in [vmin, vmax].
    Gaussians {
        /// Smallest variance.
        vmin: f64,
        /// Largest variance.
        vmax: f64,
    },
    /// Half-planes through a uniform point with a uniform direction.
    HalfPlanes,
    /// Disks of radius in [rmin, rmax] at uniform centres.
    Disks {
        /// Smallest radius.
        rmin: f64,
        /// Largest radius.
        rmax: f64,
    },
    /// Rotated square boxes of side in [smin, smax] at uniform centres.
    Boxes {
        /// Smallest side.
        smin: f64,
        /// Largest side.
        smax: f64,
    },
    /// The listed catalogue integrands.
    Listed {
        /// Where they came from.
        path: String,
        /// Their specs.
        specs: Vec<String>,
    },
}

impl Family {
    /// Parses a family spec (see the module table).
    ///
    /// # Errors
    /// [`FamilyError`] naming the unknown family, key or value, or the
    /// file and line of a bad integrand.
    pub fn parse(spec: &str) -> Result<Self, FamilyError> {
        let fail = |reason: String| FamilyError {
            spec: spec.to_string(),
            reason,
        };
        let (name, rest) = spec.split_once(':').unwrap_or((spec, ""));
        if name == "file" {
            return read_list(rest).map_err(fail);
        }
        let keys: &[(&str, f64)] = match name {
            "gaussians" => &[("vmin", 0.01), ("vmax", 1.0)],
            "halfplanes" => &[],
            "disks" => &[("rmin", 0.05), ("rmax", 0.45)],
            "boxes" => &[("smin", 0.05), ("smax", 0.45)],
            "family" | "power" | "radial" => {
                return Err(fail(format!(
                    "`{name}:` is a torus target; on the square a term is a family (gaussians, halfplanes, disks, boxes, file:PATH) or `blue`, e.g. `halfplanes+gaussians+16*blue`"
                )));
            }
            _ => {
                return Err(fail(format!(
                    "unknown family `{name}`{} (known: gaussians, halfplanes, disks, boxes, \
                     file:PATH)",
                    crate::suggest::did_you_mean(
                        name,
                        ["gaussians", "halfplanes", "disks", "boxes", "file"]
                    )
                )));
            }
        };
        let mut pairs: Vec<(String, f64)> = Vec::new();
        for (k, v) in crate::spec_params::key_values(rest).map_err(|e| fail(e.to_string()))? {
            let value: f64 = v
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite())
                .ok_or_else(|| fail(format!("{k}={v} is not a number")))?;
            if pairs.iter().any(|(seen, _)| seen == k) {
                return Err(fail(format!("`{k}` is given twice (each parameter once)")));
            }
            pairs.push((k.to_string(), value));
        }
        if let Some((k, _)) = pairs
            .iter()
            .find(|(k, _)| !keys.iter().any(|(n, _)| n == k))
        {
            let known: Vec<&str> = keys.iter().map(|k| k.0).collect();
            return Err(fail(format!(
                "unknown parameter `{k}` (parameters: {})",
                if known.is_empty() {
                    "none".into()
                } else {
                    known.join(", ")
                }
            )));
        }
        let get = |key: &str| {
            pairs
                .iter()
                .find(|(k, _)| k == key)
                .map(|p| p.1)
                .or_else(|| keys.iter().find(|k| k.0 == key).map(|k| k.1))
                .expect("registered key")
        };
        let range = |lo: &str, hi: &str, max: f64| {
            let (a, b) = (get(lo), get(hi));
            if a > 0.0 && a <= b && b <= max {
                Ok((a, b))
            } else {
                Err(fail(format!(
                    "need 0 < {lo} <= {hi} <= {max}, got {a} and {b}"
                )))
            }
        };
        Ok(match name {
            "gaussians" => {
                let (vmin, vmax) = range("vmin", "vmax", 100.0)?;
                if vmin < 0.0025 {
                    return Err(fail(format!(
                        "vmin={vmin} is below 0.0025 (a standard deviation of 0.05), where the exact integral's quadrature is not checked"
                    )));
                }
                Family::Gaussians { vmin, vmax }
            }
            "halfplanes" => Family::HalfPlanes,
            "disks" => {
                let (rmin, rmax) = range("rmin", "rmax", 2.0)?;
                Family::Disks { rmin, rmax }
            }
            _ => {
                let (smin, smax) = range("smin", "smax", 2.0)?;
                Family::Boxes { smin, smax }
            }
        })
    }

    /// The canonical spec.
    pub fn spec(&self) -> String {
        match self {
            Family::Gaussians { vmin, vmax } => format!(
                "gaussians:vmin={},vmax={}",
                SpecValue(*vmin),
                SpecValue(*vmax)
            ),
            Family::HalfPlanes => "halfplanes".into(),
            Family::Disks { rmin, rmax } => {
                format!("disks:rmin={},rmax={}", SpecValue(*rmin), SpecValue(*rmax))
            }
            Family::Boxes { smin, smax } => {
                format!("boxes:smin={},smax={}", SpecValue(*smin), SpecValue(*smax))
            }
            Family::Listed { path, .. } => format!("file:{path}"),
        }
    }

    /// Members in a sample of `requested` (a listed family has exactly its
    /// own members).
    pub fn sample_size(&self, requested: usize) -> usize {
        match self {
            Family::Listed { specs, .. } => specs.len(),
            _ => requested,
        }
    }

    /// Member `m` of the sample drawn with `seed`.
    pub fn member(&self, seed: u64, m: u64) -> Box<dyn SquareIntegrand> {
        let mut rng = set_rng(seed ^ MEMBER_STREAM, m);
        let point = |rng: &mut SetRng| [uniform(rng), uniform(rng)];
        let between = |rng: &mut SetRng, a: f64, b: f64| a + (b - a) * uniform(rng);
        match self {
            Family::Gaussians { vmin, vmax } => {
                let mu = point(&mut rng);
                let v = [
                    between(&mut rng, *vmin, *vmax),
                    between(&mut rng, *vmin, *vmax),
                ];
                Box::new(Gaussian::new(mu, v, PI * uniform(&mut rng)))
            }
            Family::HalfPlanes => {
                let theta = 2.0 * PI * uniform(&mut rng);
                Box::new(HalfPlane::new(theta, point(&mut rng)))
            }
            Family::Disks { rmin, rmax } => {
                let c = point(&mut rng);
                Box::new(Disk::new(c, between(&mut rng, *rmin, *rmax)))
            }
            Family::Boxes { smin, smax } => {
                let c = point(&mut rng);
                let side = between(&mut rng, *smin, *smax);
                Box::new(Box2::new(c, side, 0.5 * PI * uniform(&mut rng)))
            }
            Family::Listed { specs, .. } => Box::new(Catalogue(
                crate::integrands::parse(&specs[m as usize % specs.len()])
                    .expect("checked when the list was read"),
            )),
        }
    }
}

/// The largest family file read: 16 MiB, some 300,000 specs (a device
/// such as /dev/zero was read until memory ran out).
const FAMILY_FILE_LIMIT: u64 = 16 << 20;

/// A `file:PATH` family: one 2D catalogue spec per line, `#` comments and
/// blank lines skipped (docs/formats.md, "Family file").
fn read_list(path: &str) -> Result<Family, String> {
    let text = crate::io::read_text_bounded(
        std::path::Path::new(path),
        FAMILY_FILE_LIMIT,
        "a family file",
    )
    .map_err(|e| format!("{path}: {e}"))?;
    let mut specs = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let f = crate::integrands::parse(line).map_err(|e| format!("{path}:{}: {e}", i + 1))?;
        if f.dim() != 2 {
            return Err(format!(
                "{path}:{}: `{line}` is {}D; the square holds 2D integrands",
                i + 1,
                f.dim()
            ));
        }
        specs.push(line.to_string());
    }
    if specs.is_empty() {
        return Err(format!("{path}: no integrand specs"));
    }
    Ok(Family::Listed {
        path: path.to_string(),
        specs,
    })
}
