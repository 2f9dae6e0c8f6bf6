//! `fray-mesh`: triangle meshes (OBJ, BVH, watertight hits) and textures.
//!
#![doc = include_str!("../README.md")]
//!
//! ## In detail
//!
//! [`TriangleMesh`] from OBJ files ([`TriangleMesh::load_obj`], through `tobj`) with the
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
pub use bvh_build::{BuildPreset, MAX_DEPTH, MAX_LEAF, MAX_TRIANGLES};
pub use bvh_node::BvhNode;
pub use error::MeshError;
pub use instance::Instance;
pub use mesh::TriangleMesh;
pub use packet::{LANES, PacketBvh};
pub use texture::{Texture, TextureError};
