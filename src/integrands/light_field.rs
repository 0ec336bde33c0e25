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
use rustfft::num_complex::Complex64;

/// A 4D integrand in light-field form: a stack of sheared layers, wave t
/// of φ_k having the frequency ω_t(k) = (s_t,x·k_x, s_t,y·k_y) for a fixed
/// slope s_t (a layer of shear c has s = (c, c)). So ω_t(0) = 0: the
/// (x, y) average φ_0 does not depend on (u, v), and the (x, y)-shifted
/// estimator is unbiased for every pairing of (x, y) and (u, v).
pub trait LightField: Send + Sync {
    /// The slope s_t of each wave.
    fn wave_slopes(&self) -> Vec<[f64; 2]>;
    /// Appends the amplitudes A_t(k) of φ_k to `out`, one per slope, in
    /// the order of [`Self::wave_slopes`].
    fn wave_amplitudes(&self, k: [i64; 2], out: &mut Vec<Complex64>);
    /// The 2D shape g of each layer, as a catalogue spec (in the order of
    /// [`Self::wave_slopes`]).
    fn layer_shapes(&self) -> Vec<String>;
    /// Appends the plane waves of φ_k to `out`: amplitudes with their
    /// frequencies s_t ⊙ k.
    fn plane_waves(&self, k: [i64; 2], out: &mut Vec<PlaneWave>) {
        let mut amplitudes = Vec::new();
        self.wave_amplitudes(k, &mut amplitudes);
        out.extend(
            amplitudes
                .into_iter()
                .zip(self.wave_slopes())
                .map(|(amplitude, s)| PlaneWave {
                    amplitude,
                    frequency: [s[0] * k[0] as f64, s[1] * k[1] as f64],
                }),
        );
    }
    /// The shear (a, b) that makes each layer constant along (u, v): the
    /// analytic answer a = b = −c for a layer of shear c, −s_t.
    fn layer_shears(&self) -> Vec<[f64; 2]> {
        self.wave_slopes()
            .into_iter()
            // 0 − s, not −s: no −0.0 for a layer in focus.
            .map(|s| [0.0 - s[0], 0.0 - s[1]])
            .collect()
    }
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
