//! `fray-mesh`: triangle meshes (docs/methods.md §7), the reference implementation. Usable alone: no
//! GPU, no scene files.
//!
//! So far: [`TriangleMesh`] from OBJ files ([`TriangleMesh::load_obj`], through `tobj`) with the
//! file's normals and UVs or computed angle-weighted normals; [`triangle::intersect`], a
//! **watertight** ray–triangle test (Woop, Benthin and Wald 2013: shear to the ray's frame, edge
//! functions that agree on a shared edge, so rays through edges and vertices never leak) in f64;
//! [`MeshBvh`], a BVH2 from a binned SAH build whose work is bounded for any triangles,
//! traversed in f64 with a conservative slab test, for the
//! nearest hit and any hit (shadow rays) — an order-independent answer, ties to the smallest
//! triangle index; [`PacketBvh`], the same answers bit for bit for many rays at once (a
//! renderer's tile: f32 packet traversal that only decides what the f64 code looks at);
//! [`Instance`], one mesh under several transforms; [`gpu_layout`], the meshes and instances
//! flattened for the GPU twin (`gpu_struct!`s, f32 boxes rounded outward around anchor-relative
//! f32 triangles, the traversal's stack depth checked); [`texture`]: linear textures with mip
//! chains (PNG, EXR), trilinear lookups from a pixel's footprint, projected mappings for surfaces
//! without UVs, terrain colour ramps.
//!
//! ```
//! use fray_core::{Interval, Ray};
//! use fray_mesh::{MeshBvh, TriangleMesh};
//! use glam::DVec3;
//!
//! // One triangle in the plane z = 2.
//! let mesh = TriangleMesh::new(
//!     vec![DVec3::new(-1.0, -1.0, 2.0), DVec3::new(1.0, -1.0, 2.0), DVec3::new(0.0, 1.0, 2.0)],
//!     vec![[0, 1, 2]],
//! )?;
//! let bvh = MeshBvh::build(mesh);
//! let ray = Ray::new(DVec3::ZERO, DVec3::Z).unwrap();
//! let hit = bvh.nearest_hit(&ray, Interval::new(0.0, f64::INFINITY)).unwrap();
//! assert_eq!(hit.t, 2.0);
//! assert!(bvh.any_hit(&ray, Interval::new(0.0, 10.0)));
//! # Ok::<(), fray_mesh::MeshError>(())
//! ```

mod bvh;
mod bvh_build;
mod bvh_node;
mod error;
pub mod gpu_layout;
mod instance;
mod mesh;
mod obj;
mod obj_size;
mod packet;
pub mod texture;
pub mod triangle;

pub use bvh::{MeshBvh, MeshHit};
pub use bvh_build::{MAX_DEPTH, MAX_LEAF, MAX_TRIANGLES};
pub use bvh_node::BvhNode;
pub use error::MeshError;
pub use instance::Instance;
pub use mesh::TriangleMesh;
pub use packet::{LANES, PacketBvh};
pub use texture::{Texture, TextureError};
