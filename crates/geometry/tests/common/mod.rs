//! Helpers shared by the integration tests.

pub mod dd;
pub mod reference;
pub mod rng;
