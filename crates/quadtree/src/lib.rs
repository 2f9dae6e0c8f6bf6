//! `fray-quadtree`: the CPU quadtree scheduler. It splits the image rectangle into a quadtree,
//! describes each cell's rays by a conservative [`RayBundle`] (for every projector kind: pinhole,
//! parallel, sphere picture surface), asks a caller-supplied test which candidates the bundle may
//! meet, drops cells where nothing can be hit, and returns a flat [`WorkList`] of tiles with their
//! candidate objects, active leaves and perturbations and depth ranges — plain `#[repr(C)]` Pod
//! arrays that a GPU can upload as they are. It knows only `fray-core`: what a candidate is and
//! how it is tested belong to the caller.
//!
//! ```
//! use fray_core::{Aabb, Pinhole, Projector};
//! use fray_quadtree::{Candidates, QuadtreeConfig, build};
//! use glam::DVec3;
//!
//! let camera = Projector::Pinhole(Pinhole::new(
//!     DVec3::new(0.0, 0.0, -10.0), DVec3::ZERO, DVec3::Y, 40f64.to_radians(), 0.1,
//! )?);
//! // One object: a small box at the centre of the view.
//! let object = Aabb::new(DVec3::splat(-0.5), DVec3::splat(0.5));
//! let mut root = Candidates::new();
//! root.begin(0, 0, 0.0, f64::INFINITY);
//! let list = build(&camera, (256, 256), &QuadtreeConfig::new(16), &root,
//!     |bundle, parent, out| {
//!         for c in &parent.candidates {
//!             if let Some(t) = bundle.box_range(&object) {
//!                 out.begin(c.kind, c.object, t.lo, t.hi);
//!             }
//!         }
//!     })?;
//! assert!(list.items.len() < 256 / 4); // most of the 16 × 16 tiles are empty space
//! assert!(list.stats.cells_culled > 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod build;
mod bundle;
mod error;
mod trig;
mod work;

pub use build::{QuadtreeConfig, build, build_parallel};
pub use bundle::{PixelCoverage, RayBundle};
pub use error::QuadtreeError;
pub use work::{Candidate, Candidates, QuadtreeStats, WorkItem, WorkList};
