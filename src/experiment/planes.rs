//! Expected spectra of 2D projections of 4D sets drawn as PNGs: the seed's
//! XY, UV, XU and YV planes (Singh, Öztireli, Pilleboue & Jarosz, the 4D
//! slides), shared by the figures that draw projections.

use std::path::Path;

use crate::points::PointSet;
use crate::report::plot::power_png;
use crate::samplers::SamplerError;
use crate::spectrum::{FrequencyBox, Method, Spectrum, expected_power};
use crate::variance::VarianceError;

/// The NUFFT tolerance of the figures' spectra.
const TOLERANCE: f64 = 1e-9;

/// The transform every figure's spectrum uses.
pub(super) const METHOD: Method = Method::Fast {
    tolerance: TOLERANCE,
};

/// A projection plane of a 4D set: its coordinates and frequency axes.
pub(super) fn plane(name: &str) -> Result<([usize; 2], [&'static str; 2]), String> {
    match name {
        "xy" => Ok(([0, 1], ["kx", "ky"])),
        "uv" => Ok(([2, 3], ["ku", "kv"])),
        "xu" => Ok(([0, 2], ["kx", "ku"])),
        "yv" => Ok(([1, 3], ["ky", "kv"])),
        other => Err(format!("plane `{other}`: one of xy, uv, xu, yv")),
    }
}

/// E[N·P_S] of the 2D sets `realization(r)`, r < `sets`, on a res² box by
/// the NUFFT at [`TOLERANCE`]: every spectrum the figures draw.
pub(super) fn box_power(
    sets: usize,
    res: usize,
    realization: impl Fn(usize) -> Result<PointSet, VarianceError> + Sync,
) -> Result<Spectrum, VarianceError> {
    expected_power(
        FrequencyBox::from_resolution(2, res),
        METHOD,
        sets,
        realization,
        &|| {},
    )
}

/// E[N·P_S] of the projections `planes` of the 4D sets `realization(r)`,
/// r < `sets`, on a res² box, as `PREFIX-PLANE.png` in `out`.
pub(super) fn plane_pngs(
    out: &Path,
    prefix: &str,
    title: &str,
    planes: &[String],
    (sets, res): (usize, usize),
    realization: &(dyn Fn(usize) -> Result<PointSet, SamplerError> + Sync),
) -> Result<(), Box<dyn std::error::Error>> {
    for p in planes {
        let (dims, axes) = plane(p)?;
        let spectrum = box_power(sets, res, |r| {
            Ok(realization(r)?
                .projected(&dims)
                .expect("a plane of a 4D set (checked with the experiment)"))
        })?;
        power_png(
            &spectrum,
            &format!("{title}: {p} projection ({sets} sets)"),
            axes,
            "log10 power (N·P_S)",
            &out.join(format!("{prefix}-{p}.png")),
        )?;
    }
    Ok(())
}
