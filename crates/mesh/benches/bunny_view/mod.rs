//! The mesh benchmark's view, shared by `benches/packet.rs` and the Embree comparison
//! (`examples/embree_rays.rs` writes these rays for `benches/embree/embree_bench.c`): the bunny
//! (75 408 triangles) in a 1024² pinhole view that it mostly fills, rays in 16×16 tiles with
//! Morton order inside each, and shadow rays from the primary hits toward one point light.

// Each target that includes this uses part of it.
#![allow(dead_code)]

use fray_core::{Interval, MemoryBudget, Pinhole, Projector, Ray};
use fray_mesh::{MeshBvh, MeshHit, TriangleMesh};
use glam::DVec3;

pub const SIDE: u32 = 1024;
pub const TILE: u32 = 16;
pub const TILE_RAYS: usize = (TILE * TILE) as usize;

pub fn bunny_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes/bunny00.obj")
}

pub fn bunny() -> TriangleMesh {
    TriangleMesh::load_obj(&bunny_path(), &MemoryBudget::default()).expect("the bunny loads")
}

/// The view's rays tile by tile, Morton order inside each tile.
pub fn primary_rays(bvh: &MeshBvh) -> Vec<Ray> {
    let b = bvh.bounds();
    let eye = b.center() + DVec3::new(0.0, 0.0, -1.2 * b.diagonal());
    let camera = Pinhole::new(eye, b.center(), DVec3::Y, 25f64.to_radians(), 0.01).expect("camera");
    let projector = Projector::Pinhole(camera);
    let mut rays = Vec::with_capacity((SIDE * SIDE) as usize);
    for ty in (0..SIDE).step_by(TILE as usize) {
        for tx in (0..SIDE).step_by(TILE as usize) {
            for i in 0..TILE * TILE {
                let (mut x, mut y) = (0, 0);
                for bit in 0..8 {
                    x |= ((i >> (2 * bit)) & 1) << bit;
                    y |= ((i >> (2 * bit + 1)) & 1) << bit;
                }
                let ray = projector.pixel_ray(tx + x, ty + y, SIDE, SIDE);
                rays.push(ray.expect("a pixel ray").ray);
            }
        }
    }
    rays
}

/// From every primary hit toward a point light at `centre + (1, 2, −1.5)·diagonal`, over
/// `(10⁻⁶·diagonal, distance to the light)`.
pub fn shadow_rays(
    bvh: &MeshBvh,
    rays: &[Ray],
    hits: &[Option<MeshHit>],
) -> (Vec<Ray>, Vec<Interval>) {
    let b = bvh.bounds();
    let light = b.center() + DVec3::new(1.0, 2.0, -1.5) * b.diagonal();
    let (mut shadow, mut ranges) = (Vec::new(), Vec::new());
    for (ray, hit) in rays.iter().zip(hits) {
        if let Some(h) = hit {
            let p = ray.at(h.t);
            let to = light - p;
            shadow.push(Ray::new(p, to).expect("a shadow ray"));
            ranges.push(Interval::new(1e-6 * b.diagonal(), to.length()));
        }
    }
    (shadow, ranges)
}
