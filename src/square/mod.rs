//! The unit square as a domain of its own (docs/mathematics.md §7).
//!
//! Renderers and the field's integration tests average f over a point set
//! as it is, Î = (1/N) Σ_i f(x_i) on [0,1)², with integrands that are not
//! periodic and no random shift. The error of a set is then judged over a
//! family of integrands: MSE(X) = E_f[(Î − I_f)²]. Torus designs cannot see
//! the square's border, where these integrands jump.
//!
//! - [`integrands`]: members (Gaussians, half-planes, disks, boxes cut by
//!   the border) with exact integrals over the square;
//! - [`family`]: the families and their documented distributions;
//! - [`mse`]: the family MSE by brute force, the yardstick;
//! - [`halfplanes`]: the half-plane family's MSE in closed form per
//!   direction (a Cramér–von Mises statistic), O(N log N);
//! - [`sampled`]: any smooth family's MSE and gradient on a sample of
//!   members.

pub mod design;
pub mod family;
pub mod halfplanes;
pub mod integrands;
pub mod mse;
pub mod sampled;

pub use family::{Family, FamilyError};
pub use mse::{SquareMse, family_mse};
