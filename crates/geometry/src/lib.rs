//! `fray-geometry`: free forms (perturbed quadrics, CSG) and their ray casting, in f64.
//!
#![doc = include_str!("../README.md")]

mod active;
mod cast;
pub mod csg;
mod error;
mod free_form;
pub mod gpu_layout;
mod perturbation;
pub mod polygonise;
mod quadric;
mod ray_quadratic;

pub use active::ActiveSet;
pub use cast::{CastMethod, CastPlan, CastStats, RayCaster};
pub use csg::{CsgOp, Shape, Solid};
pub use error::GeometryError;
pub use free_form::FreeForm;
pub use perturbation::Perturbation;
pub use polygonise::{PolygonMesh, polygonise};
pub use quadric::{OriginTerms, Quadric, Sheets};
pub use ray_quadratic::RayQuadratic;
