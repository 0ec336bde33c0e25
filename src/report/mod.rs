//! Reports: pictures and tables people look at.

pub mod plot;
pub mod png;
