//! Light fields: 4D integrands f(x, y, u, v) whose Fourier coefficients in
//! (x, y) are finite sums of plane waves in (u, v),
//!
//!   φ_k(u, v) = ∫∫ f(x, y, u, v) e^(−2πi k·(x,y)) dx dy
//!             = Σ_t A_t(k) e^(2πi ω_t(k)·(u,v)),
//!
//! as a thin lens makes them: a shape at depth d seen through a lens focused
//! at F is sheared by c = (F − d)/d, so its layer has ω(k) = c·k
//! (Soler et al. 2009, "Fourier depth of field", ACM TOG 28(2); Singh &
//! Jarosz 2017, §3). The shear search evaluates the expected variance of
//! sheared padded sets exactly from this form (docs/mathematics.md §6.2).

pub use crate::spectrum::pair::PlaneWave;
use crate::spectrum::pair::uniform_char;

/// A 4D integrand in light-field form. Its (x, y) average φ_0 must not
/// depend on (u, v) (ω_t(0) = 0), so the (x, y)-shifted estimator is
/// unbiased for every pairing of (x, y) and (u, v).
pub trait LightField: Send + Sync {
    /// Appends the plane waves of φ_k to `out`.
    fn plane_waves(&self, k: [i64; 2], out: &mut Vec<PlaneWave>);
    /// The shear (a, b) that makes each layer constant along (u, v): the
    /// analytic answer a = b = −c for a layer of shear c.
    fn layer_shears(&self) -> Vec<[f64; 2]>;
    /// The 2D shape g of each layer, as a catalogue spec (in the order of
    /// [`Self::layer_shears`]).
    fn layer_shapes(&self) -> Vec<String>;
}

/// ∫∫ |φ_k(u, v)|² du dv = Σ_(t,t′) A_t·conj(A_t′)·χ(ω_t − ω_t′), χ the
/// characteristic function of the unit square.
pub fn energy(waves: &[PlaneWave]) -> f64 {
    let mut total = 0.0;
    for a in waves {
        for b in waves {
            let d = [
                a.frequency[0] - b.frequency[0],
                a.frequency[1] - b.frequency[1],
            ];
            total +=
                (a.amplitude * b.amplitude.conj() * uniform_char(d[0]) * uniform_char(d[1])).re;
        }
    }
    total.max(0.0)
}
