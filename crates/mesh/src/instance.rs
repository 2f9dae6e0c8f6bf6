//! An instance: one mesh's BVH placed in the world by an affine transform. Rays are taken into
//! the mesh's space (not renormalised, so `t` stays the world ray's), normals back out by the
//! inverse transpose.

use crate::{MeshBvh, MeshError, MeshHit};
use fray_core::{Interval, Ray};
use glam::{DAffine3, DMat3, DVec3};
use std::sync::Arc;

/// One placement of a shared mesh.
#[derive(Clone, Debug)]
pub struct Instance {
    pub mesh: Arc<MeshBvh>,
    to_world: DAffine3,
    to_mesh: DAffine3,
    normal_matrix: DMat3,
}

impl Instance {
    /// `mesh` placed by `to_world`, which must be invertible and finite.
    pub fn new(mesh: Arc<MeshBvh>, to_world: DAffine3) -> Result<Self, MeshError> {
        let det = to_world.matrix3.determinant();
        if !(det.is_finite() && det != 0.0 && to_world.translation.is_finite()) {
            return Err(MeshError::Mesh(format!(
                "an instance's transform must be finite and invertible (determinant {det})"
            )));
        }
        let to_mesh = to_world.inverse();
        Ok(Self {
            mesh,
            to_world,
            to_mesh,
            normal_matrix: to_mesh.matrix3.transpose(),
        })
    }

    /// The transform from the mesh's space to the world.
    pub fn to_world(&self) -> DAffine3 {
        self.to_world
    }

    /// `ray` in the mesh's space, its parameter the world ray's.
    fn local(&self, ray: &Ray) -> Ray {
        Ray {
            origin: self.to_mesh.transform_point3(ray.origin),
            dir: self.to_mesh.transform_vector3(ray.dir),
        }
    }

    /// The nearest hit of the world `ray` over `range`.
    pub fn nearest_hit(&self, ray: &Ray, range: Interval) -> Option<MeshHit> {
        self.mesh.nearest_hit(&self.local(ray), range)
    }

    /// Whether the world `ray` hits the instance over `range`.
    pub fn any_hit(&self, ray: &Ray, range: Interval) -> bool {
        self.mesh.any_hit(&self.local(ray), range)
    }

    /// A mesh-space normal in the world (unit).
    pub fn world_normal(&self, n: DVec3) -> DVec3 {
        (self.normal_matrix * n).try_normalize().unwrap_or(n)
    }
}
