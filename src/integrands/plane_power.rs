//! An integrand's power spectrum P_f(k) = |F_f(k)|² on a plane of two of
//! its coordinates (the whole spectrum of a 2D integrand).
//!
//! By the Fourier slice theorem, the power on the plane of coordinates
//! (a, b) through the origin (every other frequency component 0) is the
//! power of the marginal g(x_a, x_b) = ∫ f dx_(others): the light field's
//! XU and YV planes of Singh & Jarosz (2017), where a defocused surface
//! puts its energy on the sheared line k_u = c·k_x (Soler et al. 2009).

use crate::memory;
use crate::spectrum::{FrequencyBox, Spectrum, SpectrumError};

use super::Integrand;

/// Checks that `dims` are two distinct coordinates of a `dim`-dimensional
/// integrand.
///
/// # Errors
/// [`SpectrumError::Plane`] naming the coordinates and the dimension.
pub fn check_plane(dims: [usize; 2], dim: usize) -> Result<(), SpectrumError> {
    if dims[0] == dims[1] || dims.iter().any(|&d| d >= dim) {
        return Err(SpectrumError::Plane(format!(
            "the plane must be two distinct coordinates of 0 to {} (a {dim}-dimensional integrand), not {},{}",
            dim.saturating_sub(1),
            dims[0],
            dims[1]
        )));
    }
    Ok(())
}

/// P_f(k) = |F_f(k)|² for k on the plane of coordinates `dims`, |k|∞ ≤
/// `half` (the other components 0), from the integrand's closed-form
/// Fourier coefficients. The spectrum's `sets` is 1: nothing is averaged.
///
/// # Errors
/// [`SpectrumError::Plane`] for `dims` that are not two distinct
/// coordinates of the integrand or an integrand without closed-form
/// coefficients (a scene pixel samples its own: `PixelIntegrand::plane_power`);
/// [`SpectrumError::TooLarge`] when the box does not fit in memory.
pub fn plane_power(
    f: &dyn Integrand,
    dims: [usize; 2],
    half: usize,
) -> Result<Spectrum, SpectrumError> {
    check_plane(dims, f.dim())?;
    if !f.has_fourier() {
        return Err(SpectrumError::Plane(format!(
            "{} has no closed-form Fourier coefficients",
            f.spec()
        )));
    }
    let freqs = FrequencyBox { dim: 2, half };
    let len = freqs.checked_len();
    memory::check(
        &format!("the power of {} on a {}² box", f.spec(), freqs.side()),
        len.map(|n| n as f64 * 8.0),
        "lower --res",
    )?;
    let mut k2 = [0i64; 2];
    let mut k = vec![0i64; f.dim()];
    let power = (0..freqs.len())
        .map(|i| {
            freqs.frequency(i, &mut k2);
            k[dims[0]] = k2[0];
            k[dims[1]] = k2[1];
            f.fourier(&k).norm_sqr()
        })
        .collect();
    Ok(Spectrum {
        freqs,
        power,
        sets: 1,
    })
}
