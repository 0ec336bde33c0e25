//! Design runs as library calls, one per domain: the optimizers of
//! [`crate::optimize`] and [`crate::square`] applied to a request, started
//! from the registry's samplers and scored against the classic samplers
//! ([`crate::baseline`]), with the report `optimize points` writes. They sit
//! above the registry (which registers the optimizer as a sampler), so the
//! optimizers themselves never name it.

pub mod projections;
pub mod square;
pub mod torus;
