//! `fray-terrain`: height-map terrain — the max pyramid and ray casting by halving, in f64.
//!
#![doc = include_str!("../README.md")]
//!
//! ## In detail
//!
//! A [`Heightmap`] (from a 16-bit PNG, an EXR, a `.npy` array or memory; any size, never
//! resampled; a pyramid of rectangular levels over it) is [placed](Placement) in the world; a
//! [`Terrain`] holds its max [`Pyramid`] and finds the first hit of a ray by halving the ray segment in
//! height-map space, nearer half first, dropping halves that stay above the pyramid level their
//! footprint selects, and intersecting the bilinear patch (exactly: a quadratic per cell) or
//! the bicubic B-spline surface at the finest level. A threshold cuts out cells, giving any
//! outline, holes included. [`gpu_layout`] holds the `#[repr(C)]` parameter block (and its
//! generated WGSL) and the flat pyramid the GPU uploads. Everything that grows with the input
//! (the file, the decoded image, the samples, the pyramids) is checked against a
//! [`fray_core::MemoryBudget`] before it is allocated (`*_within` variants; the plain ones use
//! the default budget) and refused with [`TerrainError::Budget`].

mod clip;
mod error;
pub mod gpu_layout;
mod heightmap;
mod interpolation;
mod load;
pub mod npy;
mod placement;
mod pyramid;
mod region;
pub mod sweep;
mod terrain;
mod waves;

pub use error::TerrainError;
pub use heightmap::{Heightmap, MAX_SAMPLES, MAX_SIDE};
pub use interpolation::{BicubicCell, BilinearCell, Interpolation};
pub use placement::{MapRay, Placement};
pub use pyramid::{MAX_LEVELS, Pyramid, PyramidLevel};
pub use region::Region;
pub use terrain::{
    HitKind, MAX_MARCH_STEPS, PIXEL_LOD_COARSEST_LEVEL, Terrain, TerrainHit, TerrainOptions,
    TerrainStats,
};
pub use waves::{Wave, Waves};
