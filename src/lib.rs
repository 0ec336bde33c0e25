//! varspec: design Monte Carlo sample patterns by the integration error they
//! produce.
//!
//! The crate is library first; the `varspec` binary is a thin command-line
//! layer over it (see `DESIGN.md` §3 of the project). Data flows one way:
//! a [`samplers::Sampler`] produces [`points::PointSet`]s, which analyses and
//! reports consume. Randomness only enters through an explicit seeded
//! generator handed down ([`rng`]), so a seed fixes every output bit for any
//! number of threads.

pub mod error;
pub mod integrands;
pub mod io;
pub mod neighbours;
pub mod optimize;
pub mod points;
pub mod quadrature;
pub mod report;
pub mod rng;
pub mod samplers;
pub mod spectrum;
pub mod variance;

pub use error::Error;
pub use points::PointSet;
