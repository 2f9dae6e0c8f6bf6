//! `fray-core`: the bottom of fray — f64 rays, conservative interval arithmetic, boxes, the
//! parametric projector (cameras as pixel → (origin, picture point) pairs), image buffers,
//! linear colour and the [`Frame`] every backend returns. It knows nothing about any rendering
//! method.
//!
//! ```
//! use fray_core::{Interval, Pinhole, Projector};
//! use glam::DVec3;
//!
//! // Bound x² − 2x over x ∈ [0, 3] conservatively.
//! let x = Interval::new(0.0, 3.0);
//! let f = x.square() - x.scale(2.0);
//! assert!(f.contains(-1.0) && f.contains(3.0));
//!
//! // A pinhole camera and the ray through the centre of a 64 × 64 image.
//! let camera = Projector::Pinhole(
//!     Pinhole::new(DVec3::new(0.0, 1.0, -4.0), DVec3::ZERO, DVec3::Y, 45f64.to_radians(), 0.1)?,
//! );
//! let r = camera.ray(32.0, 32.0, 64, 64).unwrap();
//! assert!(r.ray.dir.dot(DVec3::new(0.0, -1.0, 4.0).normalize()) > 0.999_999);
//! assert!((r.t_near - 0.1).abs() < 1e-12); // hits nearer than the picture plane are not shown
//! # Ok::<(), fray_core::ProjectorError>(())
//! ```

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
