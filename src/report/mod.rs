//! Reports: pictures and tables people look at, and the tour of the
//! design loop as one HTML page.

pub mod html;
pub mod plot;
pub mod png;
pub mod tour;
