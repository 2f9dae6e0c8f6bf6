//! Textures (docs/methods.md §7): linear `f32` images with their mip chains, loaded from PNG or
//! OpenEXR under a memory budget; nearest, bilinear and trilinear lookups with a wrap mode per
//! axis; the footprint rule that picks the level from a pixel's footprint; projected mappings
//! for surfaces without UVs; colour ramps and drapes for terrain. No GPU, no scene files.
//!
//! **The uv convention.** `uv = (0, 0)` is the image's **bottom-left** corner and `v` grows
//! **up** (the OBJ and OpenGL convention); `(1, 1)` is the top-right. The image's row 0 is its
//! top row (as PNG and EXR store it, and as [`Texture::from_rgb`] takes it), so at a level of
//! `w × h` texels uv `(u, v)` is the point `x = u·w` (columns, right) and `y = (1 − v)·h` (rows,
//! down) of the image, and texel `(i, j)` — column `i`, row `j` from the top — has its centre at
//! `x = i + ½, y = j + ½`, i.e. `uv = ((i + ½)/w, 1 − (j + ½)/h)`. In a 2 × 2 image, uv
//! `(0.25, 0.75)` is the top-left texel's centre.
//!
//! **The footprint rule** ([`Footprint`]): a hit at distance `t` sees the texture through a
//! pixel `w = PixelFootprint::at(t)` wide; its cone meets the surface in an ellipse whose longer
//! axis is `w / |cos θ|`; the lookup's uv width is that axis times the mapping's uv per world
//! unit, with the stretch `1/|cos θ|` capped at [`Footprint::max_anisotropy`]; the level is
//! `log₂` of the width in base texels, clamped to the chain.
//!
//! ```
//! use fray_mesh::texture::{Footprint, Mapping, Planar, Texture, Wrap};
//! use glam::{DVec2, DVec3};
//!
//! // A 2 × 2 texture: red top-left, green top-right, blue bottom-left, white bottom-right.
//! let t = Texture::from_rgb(2, 2, vec![
//!     1.0, 0.0, 0.0,  0.0, 1.0, 0.0,
//!     0.0, 0.0, 1.0,  1.0, 1.0, 1.0,
//! ])?;
//! assert_eq!(t.bilinear(0, DVec2::new(0.25, 0.75), Wrap::REPEAT).truncate(), glam::Vec3::X);
//! assert_eq!(t.level_count(), 2); // 2 × 2, 1 × 1
//!
//! // The ground plane y = 0 mapped with one texture per 2 m, seen at t = 10 through a pixel of
//! // 1 mrad, 60° from the normal.
//! let ground = Mapping::Planar(Planar::new(DVec3::ZERO, DVec3::X, -DVec3::Z, DVec2::splat(0.5))?);
//! let p = ground.project(DVec3::new(3.0, 0.0, -1.0), DVec3::Y);
//! assert_eq!(p.main_uv(), DVec2::new(1.5, 0.5));
//! let width = Footprint::default().uv_width(1e-3 * 10.0, 0.5, p.uv_per_world);
//! assert!((width - 0.01).abs() < 1e-15); // 10 mm · 2 (stretch) · 0.5 uv/m
//! let colour = p.sample(&t, width, Wrap::REPEAT);
//! assert!(colour.is_finite());
//! # Ok::<(), fray_mesh::texture::TextureError>(())
//! ```

mod error;
mod footprint;
pub mod gpu_layout;
mod load;
mod mapping;
mod mip;
mod ramp;
mod sample;
mod texels;
mod wrap;

pub use error::TextureError;
pub use footprint::{Footprint, triangle_uv_per_world};
pub use load::{Encoding, srgb_to_linear};
pub use mapping::{Cylindrical, Mapping, Planar, Projected, Spherical, Triplanar};
pub use mip::{MipLevel, chain_texels, level_count, level_sizes};
pub use ramp::{Drape, Ramp, TerrainRamp};
pub use sample::Filter;
pub use texels::{Channels, MAX_SIDE, Texture};
pub use wrap::{Wrap, WrapMode};
