//! Pictures and plots people look at: point sets, spectra and heat maps,
//! line plots (PNG). The tour page that assembles them is `crate::tour`.

pub mod plot;
pub mod png;
