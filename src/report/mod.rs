//! Reports: pictures and tables people look at.

pub mod png;
