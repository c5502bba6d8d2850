//! Dual numbers and the [`Real`] scalar trait, defined in the neutral [`crate::scalar`] module
//! (the CR3BP builds on them too); re-exported here for existing paths.

pub use crate::scalar::{Dual, Real};
