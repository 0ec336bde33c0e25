//! Every integration test in one binary: one link of the library instead
//! of one per file, and tests of different files run side by side. Each
//! file below is a module; run one with `cargo test --test suite FILE::`.
//! tests/fuzz_parsers.rs stays a binary of its own: it silences the
//! process-wide panic hook and times every input, which the other tests
//! running beside it would disturb.

mod common;

mod architecture;
mod checkpoint;
mod cli;
mod cli_spectrum;
mod cli_variance;
mod convergence_rates;
mod expected_predictor;
mod experiment;
mod faults;
mod hard_cases;
mod hostile_inputs;
mod integrands;
mod isotropic_jitter;
mod optimize_lattice;
mod optimize_points;
mod optimize_shear;
mod pair_spectrum;
mod pcf;
mod pointfile;
mod projections;
mod radial;
mod reference_values;
mod sampler_properties;
mod scene;
mod scene_cli;
mod seed_figures;
mod source;
mod spectrum_accuracy;
mod square;
mod standard_errors;
mod tables;
mod unbiasedness;
mod variance_agreement;
