//! An instance: one mesh's BVH placed in the world by an affine transform. Rays are taken into
//! the mesh's space (not renormalised, so `t` stays the world ray's), normals back out by the
//! inverse transpose. An instance made [`Instance::with_packets`] also casts many rays at once
//! ([`Instance::nearest_hits`]: the same answers, through the shared [`PacketBvh`]).

use crate::{MeshBvh, MeshError, MeshHit, PacketBvh};
use fray_core::{Interval, Ray};
use glam::{DAffine3, DMat3, DVec3};
use std::sync::Arc;

/// One placement of a shared mesh.
#[derive(Clone, Debug)]
pub struct Instance {
    pub mesh: Arc<MeshBvh>,
    /// The mesh's packet data (its reference is `mesh`), shared like it; `None`: rays go one
    /// by one.
    packets: Option<Arc<PacketBvh>>,
    to_world: DAffine3,
    to_mesh: DAffine3,
    normal_matrix: DMat3,
    /// The transform's determinant is negative: world corners wind the other way round.
    mirrored: bool,
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
            packets: None,
            to_world,
            to_mesh,
            normal_matrix: to_mesh.matrix3.transpose(),
            mirrored: det < 0.0,
        })
    }

    /// `packets`' mesh (its reference) placed by `to_world`, casting many rays at once through
    /// `packets` ([`Instance::nearest_hits`]).
    pub fn with_packets(packets: Arc<PacketBvh>, to_world: DAffine3) -> Result<Self, MeshError> {
        let mut instance = Self::new(packets.shared_reference().clone(), to_world)?;
        instance.packets = Some(packets);
        Ok(instance)
    }

    /// The same mesh (and packet data) placed by `t` after this instance's own placement: what an
    /// animated object is at a time. Nothing is rebuilt.
    pub fn moved(&self, t: &DAffine3) -> Result<Self, MeshError> {
        let mut instance = Self::new(self.mesh.clone(), *t * self.to_world)?;
        instance.packets = self.packets.clone();
        Ok(instance)
    }

    /// The packet data, if the instance has it.
    pub fn packets(&self) -> Option<&PacketBvh> {
        self.packets.as_deref()
    }

    /// Whether the transform mirrors (negative determinant): a triangle's world corners then
    /// wind clockwise seen from outside, so a normal from their winding must be turned round.
    pub fn mirrored(&self) -> bool {
        self.mirrored
    }

    /// The transform from the mesh's space to the world.
    pub fn to_world(&self) -> DAffine3 {
        self.to_world
    }

    /// `ray` in the mesh's space, its parameter the world ray's: what [`Instance::nearest_hit`]
    /// and [`Instance::any_hit`] cast.
    pub fn local(&self, ray: &Ray) -> Ray {
        Ray {
            origin: self.to_mesh.transform_point3(ray.origin),
            dir: self.to_mesh.transform_vector3(ray.dir),
        }
    }

    /// The nearest hit of the world `ray` over `range`.
    pub fn nearest_hit(&self, ray: &Ray, range: Interval) -> Option<MeshHit> {
        self.mesh.nearest_hit(&self.local(ray), range)
    }

    /// `hits[i]` = [`Instance::nearest_hit`]`(rays[i], ranges[i])` bit for bit, for world
    /// `rays` (taken into the mesh's space in `local`, whose contents are replaced): through the
    /// packet path when the instance has it (fastest for coherent rays, see [`crate::LANES`]),
    /// else ray by ray.
    ///
    /// # Panics
    /// If `rays`, `ranges` and `hits` differ in length.
    pub fn nearest_hits(
        &self,
        rays: &[Ray],
        ranges: &[Interval],
        hits: &mut [Option<MeshHit>],
        local: &mut Vec<Ray>,
    ) {
        assert!(
            rays.len() == ranges.len() && rays.len() == hits.len(),
            "Instance::nearest_hits: {} rays, {} ranges, {} hits",
            rays.len(),
            ranges.len(),
            hits.len()
        );
        local.clear();
        local.extend(rays.iter().map(|r| self.local(r)));
        match &self.packets {
            Some(p) => p.nearest_hits(local, ranges, hits),
            None => {
                for ((ray, range), hit) in local.iter().zip(ranges).zip(hits) {
                    *hit = self.mesh.nearest_hit(ray, *range);
                }
            }
        }
    }

    /// Whether the world `ray` hits the instance over `range`.
    pub fn any_hit(&self, ray: &Ray, range: Interval) -> bool {
        self.mesh.any_hit(&self.local(ray), range)
    }

    /// `occluded[i]` = [`Instance::any_hit`]`(rays[i], ranges[i])` for world `rays` (shadow
    /// rays; taken into the mesh's space in `local`, whose contents are replaced): through the
    /// packet path when the instance has it, else ray by ray.
    ///
    /// # Panics
    /// If `rays`, `ranges` and `occluded` differ in length.
    pub fn any_hits(
        &self,
        rays: &[Ray],
        ranges: &[Interval],
        occluded: &mut [bool],
        local: &mut Vec<Ray>,
    ) {
        assert!(
            rays.len() == ranges.len() && rays.len() == occluded.len(),
            "Instance::any_hits: {} rays, {} ranges, {} results",
            rays.len(),
            ranges.len(),
            occluded.len()
        );
        local.clear();
        local.extend(rays.iter().map(|r| self.local(r)));
        match &self.packets {
            Some(p) => p.any_hits(local, ranges, occluded),
            None => {
                for ((ray, range), o) in local.iter().zip(ranges).zip(occluded) {
                    *o = self.mesh.any_hit(ray, *range);
                }
            }
        }
    }

    /// The world box around the instance: the mesh's box's eight corners mapped to the world
    /// (their rounding covered by a relative margin of `1e-12`).
    pub fn bounds(&self) -> fray_core::Aabb {
        let b = self.mesh.bounds();
        if b.is_empty() {
            return b;
        }
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for k in 0..8 {
            let corner = DVec3::new(
                if k & 1 == 0 { b.min.x } else { b.max.x },
                if k & 2 == 0 { b.min.y } else { b.max.y },
                if k & 4 == 0 { b.min.z } else { b.max.z },
            );
            let p = self.to_world.transform_point3(corner);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let margin = 1e-12 * lo.abs().max(hi.abs()).max_element().max(f64::MIN_POSITIVE);
        fray_core::Aabb::new(lo - margin, hi + margin)
    }

    /// Triangle `i`'s corners in the world.
    pub fn world_corners(&self, i: usize) -> [DVec3; 3] {
        self.mesh
            .mesh()
            .corners(i)
            .map(|p| self.to_world.transform_point3(p))
    }

    /// A mesh-space normal in the world (unit).
    pub fn world_normal(&self, n: DVec3) -> DVec3 {
        (self.normal_matrix * n).try_normalize().unwrap_or(n)
    }
}
