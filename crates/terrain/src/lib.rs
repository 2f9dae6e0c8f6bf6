//! `fray-terrain`: height-map terrain as a scalar perturbation of a base plane (docs/methods.md §4),
//! the reference implementation of its ray casting. Usable alone: no GPU, no scene files.
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
//!
//! ```
//! use fray_core::{Interval, Ray};
//! use fray_terrain::{Heightmap, Placement, Terrain, TerrainOptions};
//! use glam::{DVec2, DVec3};
//!
//! // A 65 × 65 map of a round hill, 1 m apart, heights in metres.
//! let map = Heightmap::from_fn(65, 65, |i, j| {
//!     let (x, z) = (i as f32 - 32.0, j as f32 - 32.0);
//!     10.0 * (-(x * x + z * z) / 200.0).exp()
//! })?;
//! let placement = Placement::new(DVec3::ZERO, DVec2::ONE, 1.0)?;
//! let terrain = Terrain::new(map, placement, TerrainOptions::default())?;
//!
//! // Straight down onto the top of the hill.
//! let ray = Ray::new(DVec3::new(32.0, 50.0, 32.0), -DVec3::Y).unwrap();
//! let hit = terrain.cast(&ray, Interval::new(0.0, f64::INFINITY), 1e-9).unwrap();
//! assert!((hit.t - 40.0).abs() < 1e-9);
//! assert!(hit.normal.y > 0.99); // bilinear patches meet with a small kink at the summit
//! // The exact brute-force reference agrees.
//! let reference = terrain.cast_brute_force(&ray, Interval::new(0.0, f64::INFINITY), 1e-9);
//! assert_eq!(reference.map(|h| h.t), Some(hit.t));
//! # Ok::<(), fray_terrain::TerrainError>(())
//! ```

mod clip;
mod error;
pub mod gpu_layout;
mod heightmap;
mod interpolation;
mod load;
pub mod npy;
mod placement;
mod pyramid;
pub mod sweep;
mod terrain;

pub use error::TerrainError;
pub use heightmap::{Heightmap, MAX_SAMPLES, MAX_SIDE};
pub use interpolation::{BicubicCell, BilinearCell, Interpolation};
pub use placement::{MapRay, Placement};
pub use pyramid::{MAX_LEVELS, Pyramid, PyramidLevel};
pub use terrain::{
    HitKind, MAX_MARCH_STEPS, PIXEL_LOD_COARSEST_LEVEL, Terrain, TerrainHit, TerrainOptions,
    TerrainStats,
};
