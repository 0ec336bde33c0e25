//! varspec: design Monte Carlo sample patterns by the integration error they
//! produce.
//!
//! The crate is library first; the `varspec` binary is a thin command-line
//! layer over it (see docs/architecture.md). Data flows one way:
//! a [`samplers::Sampler`] (built by name through [`registry`]) produces [`points::PointSet`]s, which analyses and
//! reports consume. Randomness only enters through an explicit seeded
//! generator handed down ([`rng`]), so a seed fixes every output bit for any
//! number of threads.
//!
//! ```
//! use varspec::{integrands, registry, variance};
//! use varspec::rng::set_rng;
//!
//! // 256 jittered points, one realization from stream (seed 7, set 0).
//! let jitter = registry::build("jitter", 256, Some(2), &[]).unwrap();
//! let points = jitter.sample(&mut set_rng(7, 0)).unwrap();
//!
//! // The variance of the shift-randomized estimator on a disk, exactly
//! // (spatial form) and from the spectrum (Fourier form + Parseval tail).
//! let disk = integrands::parse("disk:r=0.3").unwrap();
//! let (exact, rounding) = variance::spatial_variance(&points, disk.as_ref()).unwrap();
//! let fourier = variance::fourier(disk.as_ref(), 127, 1e-10, 1, |_| {
//!     Ok::<_, variance::VarianceError>(points.clone())
//! })
//! .unwrap();
//! assert!((fourier.variance - exact).abs() <= fourier.truncation_bound + rounding);
//! // Jitter beats white noise (variance πr²(1 − πr²)/N) several times over.
//! assert!(exact < 0.3 * disk.variance() / 256.0);
//! ```

pub mod baseline;
pub mod design;
pub mod error;
pub mod experiment;
pub mod integrands;
pub mod io;
pub mod memory;
pub mod neighbours;
pub mod optimize;
pub mod optimized;
pub mod points;
pub mod polygon;
pub mod quadrature;
pub mod registry;
pub mod report;
pub mod rng;
pub mod samplers;
pub mod scene;
pub mod source;
pub mod spec_params;
pub mod spectrum;
pub mod square;
pub mod suggest;
pub mod sum;
pub mod tables;
pub mod tour;
pub mod variance;

pub use error::Error;
pub use points::PointSet;
