//! Sample spectra (docs/mathematics.md): S(k) = Σ_j e^(−2πi k·x_j) on a frequency
//! box, exactly ([`dft`]) or by non-uniform FFT ([`nufft`]); the expected
//! power E[N·P_S(k)] over realizations ([`expected`]); radial averages and
//! anisotropy ([`radial`]); the pair correlation function ([`pcf`]).

pub mod dft;
pub mod expected;
pub mod frequencies;
pub mod nufft;
pub mod pair;
pub mod pcf;
pub mod phase;
pub mod radial;

pub use expected::{Method, Spectrum, expected_power, expected_power_with};
pub use frequencies::FrequencyBox;
pub use nufft::{NufftPlan, Sign, Upsampling};

/// What is wrong with a spectral request.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpectrumError {
    /// Tolerance outside what the kernel can reach.
    #[error("tolerance {0} is outside [1e-14, 0.1]")]
    Tolerance(f64),
    /// The transform would need more memory than the machine gives.
    #[error(transparent)]
    TooLarge(#[from] crate::memory::TooMuchMemory),
    /// Transforms exist for d = 1..=4.
    #[error("spectra are computed in 1 to 4 dimensions, not {0} (project with --dims)")]
    UnsupportedDimension(usize),
    /// Point sets of another dimension than the transform.
    #[error("points are {found}-dimensional, the transform is {expected}-dimensional")]
    Dimension {
        /// Transform dimension.
        expected: usize,
        /// Points' dimension.
        found: usize,
    },
    /// Nothing to average.
    #[error("no point sets to analyse")]
    NoSets,
    /// A realization could not be produced (a file's set, a projection).
    #[error("realization {index}: {message}")]
    Realization {
        /// Which realization.
        index: usize,
        /// What went wrong.
        message: String,
    },
    /// A bad pair-correlation parameter.
    #[error("pair correlation: {0}")]
    Pcf(String),
    /// A bad plane or grid for an integrand's (a light field's) spectrum
    /// on a plane of its coordinates.
    #[error("spectrum on a plane: {0}")]
    Plane(String),
}
