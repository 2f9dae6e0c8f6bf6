//! `fray-quadtree`: the image quadtree — conservative ray bundles, culling, work lists.
//!
#![doc = include_str!("../README.md")]
//!
//! ## In detail
//!
//! A cell's rays are a [`RayBundle`] (of pixel centres, or of whole pixels with
//! [`PixelCoverage::Area`]); [`build`] and [`build_parallel`] (its subtrees on rayon's threads)
//! return the same [`WorkList`] item for item; [`QuadtreeConfig`] holds the cell size, the
//! coverage and the memory budget the largest possible list is checked against before the build.

mod build;
mod bundle;
mod error;
mod trig;
mod work;

pub use build::{QuadtreeConfig, build, build_parallel};
pub use bundle::{PixelCoverage, RayBundle};
pub use error::QuadtreeError;
pub use work::{Candidate, Candidates, QuadtreeStats, WorkItem, WorkList};
