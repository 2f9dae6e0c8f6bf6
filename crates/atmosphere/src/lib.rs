//! `fray-atmosphere`: Klassen's fog layer, phase functions and the physically based sky, in f64.
//!
#![doc = include_str!("../README.md")]
//!
//! ## In detail
//!
//! - [`FogLayer`]: Klassen's horizontal fog layer — a slab of extinction `B` (optionally falling
//!   off exponentially with height) — with the method's two terms (eq. 14, object light; eq. 15,
//!   fog in-scatter) in radiometric units, exact single scattering (the sun's path in the fog
//!   varies with the height of each point; one closed form for the homogeneous slab and the
//!   falloff) and an independent f64 numerical reference ([`reference`](mod@reference)).
//! - [`Phase`]: the normalised Henyey–Greenstein phase function and the source's printed form.
//! - [`sky`]: a physically based sky beyond the fog.

mod error;
mod fog;
pub mod gpu_layout;
mod method;
mod phase;
pub mod quadrature;
pub mod reference;
mod single_scattering;
pub mod sky;

pub use error::AtmosphereError;
pub use fog::{FogLayer, FogLighting, FogModel, FogTerms, Sunlight};
pub use phase::Phase;
