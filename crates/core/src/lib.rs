//! `fray-core`: the bottom layer — rays, intervals, boxes, cameras, images, colour, the memory budget.
//!
#![doc = include_str!("../README.md")]

mod aabb;
pub mod budget;
mod colour;
mod contain;
mod footprint;
mod frame;
pub mod gpu_struct;
mod image;
pub mod input;
mod interval;
mod projector;
mod ray;
pub mod root;
pub mod samples;

pub use aabb::Aabb;
pub use budget::{BudgetError, MemoryBudget, Reservation};
pub use colour::{Rgb, ToneMap, linear_to_srgb, srgb_to_linear};
pub use contain::contain_panic;
pub use footprint::PixelFootprint;
pub use frame::{Frame, RenderStats};
pub use glam;
pub use image::Image;
pub use interval::Interval;
pub use projector::{
    CameraRay, Parallel, Pinhole, Projector, ProjectorError, SphereSurface, ViewBasis,
};
pub use ray::Ray;
pub use samples::{PixelSample, PixelSamples};
