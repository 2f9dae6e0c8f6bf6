//! `fray-clouds`: volumetric clouds — Perlin's improved noise, density grids, the cloud march.
//!
#![doc = include_str!("../README.md")]
//!
//! ## In detail
//!
//! [`perlin`], Ken Perlin's improved noise ("Improving Noise", SIGGRAPH 2002) exactly —
//! his permutation table, the fade `6t⁵ − 15t⁴ + 10t³` and the 12 gradient directions chosen by
//! the low 4 bits of the hash — in f64 (the reference) and f32, and [`fractal`] sums of it;
//! [`DensityGrid`]s sampled trilinearly, with [`MaxGrid`] bounds for empty-space skipping; and
//! [`inr`], INRIMAGE-4 volumes such as the CT scan in `data/volumes/`; [`shape`], a layer's
//! density — noise cut by coverage and a threshold, a height profile, an [`Envelope`] — and
//! [`bake`] into a grid; [`march`], the cloud march with sun rays (the CPU reference); [`cost`],
//! the caps on a march's samples per ray and a bake's work, checked before either runs.

pub mod bake;
pub mod cost;
mod error;
pub mod fractal;
pub mod gpu_layout;
mod grid;
pub mod inr;
pub mod march;
pub mod perlin;
pub mod shape;
pub mod worley;

pub use error::CloudsError;
pub use grid::{DensityGrid, MaxGrid};
pub use shape::{CloudField, Envelope, HeightProfile, Unbounded};
