//! `fray-geometry`: free-form objects by perturbation functions, and their ray casting.
//!
//! A base quadric `F` (ten coefficients, `F ≥ 0` inside) is deformed by perturbations
//! `F′ = F + Σ fᵢ Rᵢ`, `Rᵢ = Qᵢ³` where `Qᵢ > 0`; objects combine by CSG (union = max,
//! intersection = min, difference = min(a, −b)). Rays find the first point with `F′ ≥ 0` by binary
//! search on the ray segment with exact per-term bounds ([`RayCaster`]), or in closed form where
//! only plain quadrics meet the ray; every leaf is widened by a bound on its rounding, so no span
//! at least ε long is missed, grazing or not (docs/accuracy.md). Usable alone: no GPU, no scene
//! files.
//!
//! ```
//! use fray_core::{Interval, Ray};
//! use fray_geometry::{FreeForm, Perturbation, Quadric, Solid};
//! use glam::DVec3;
//!
//! // An ellipsoid with a bump on its +x side.
//! let body = Quadric::ellipsoid(DVec3::ZERO, DVec3::new(2.0, 1.0, 1.0));
//! let bump = Perturbation::new(0.6, Quadric::sphere(DVec3::new(2.0, 0.0, 0.0), 0.8));
//! let solid = Solid::from_free_form(FreeForm::new(body, vec![bump], None)?);
//!
//! // Cast a ray along −x from far away; the bump pushes the surface out beyond x = 2.
//! let ray = Ray::new(DVec3::new(10.0, 0.0, 0.0), -DVec3::X).unwrap();
//! let t = solid.cast(&ray, Interval::new(0.0, f64::INFINITY), 1e-10).unwrap();
//! let hit = ray.at(t);
//! assert!(hit.x > 2.3);
//! assert!(solid.eval(hit).abs() < 1e-9); // on the surface, up to rounding
//! let (normal, _leaf) = solid.surface_at(hit, -ray.dir);
//! assert!(normal.x > 0.99);
//! # Ok::<(), fray_geometry::GeometryError>(())
//! ```

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
