//! A triangle mesh: positions, triangles as vertex index triples, per-vertex shading normals (the
//! file's, or computed — each face's normal weighted by its angle at the vertex, so a vertex's
//! normal does not depend on how the faces around it are split) and optional UVs.

use crate::MeshError;
use fray_core::Aabb;
use glam::{DVec2, DVec3};

/// An indexed triangle mesh in f64.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleMesh {
    pub positions: Vec<DVec3>,
    /// Vertex indices, counter-clockwise seen from the front (outside).
    pub triangles: Vec<[u32; 3]>,
    /// Unit shading normals, one per vertex.
    pub normals: Vec<DVec3>,
    /// Texture coordinates, one per vertex, when the mesh has them.
    pub uvs: Option<Vec<DVec2>>,
}

impl TriangleMesh {
    /// The bytes its arrays hold (positions, triangles, normals and UVs).
    pub fn heap_bytes(&self) -> u64 {
        let size = |n: usize, each: usize| (n as u64).saturating_mul(each as u64);
        size(self.positions.len(), std::mem::size_of::<DVec3>())
            + size(self.triangles.len(), std::mem::size_of::<[u32; 3]>())
            + size(self.normals.len(), std::mem::size_of::<DVec3>())
            + self
                .uvs
                .as_ref()
                .map_or(0, |u| size(u.len(), std::mem::size_of::<DVec2>()))
    }

    /// A mesh of `positions` and `triangles` with computed angle-weighted normals; every index
    /// must name a vertex, every position be finite, and the triangles be at most
    /// [`crate::MAX_TRIANGLES`].
    pub fn new(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        Self::with_attributes(positions, triangles, None, None)
    }

    /// A mesh with the given per-vertex normals (renormalised; computed where absent or zero)
    /// and UVs.
    pub fn with_attributes(
        positions: Vec<DVec3>,
        triangles: Vec<[u32; 3]>,
        normals: Option<Vec<DVec3>>,
        uvs: Option<Vec<DVec2>>,
    ) -> Result<Self, MeshError> {
        let n = positions.len();
        if triangles.len() > crate::MAX_TRIANGLES {
            return Err(MeshError::Mesh(format!(
                "{} triangles, more than the {} a mesh may have",
                triangles.len(),
                crate::MAX_TRIANGLES
            )));
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::Mesh(format!(
                "vertex {i} is not finite: {}",
                positions[i]
            )));
        }
        if let Some((t, tri)) = triangles
            .iter()
            .enumerate()
            .find(|(_, tri)| tri.iter().any(|&v| v as usize >= n))
        {
            return Err(MeshError::Mesh(format!(
                "triangle {t} names vertex {:?} of {n}",
                tri
            )));
        }
        for (what, len) in [
            ("normals", normals.as_ref().map(Vec::len)),
            ("uvs", uvs.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len.filter(|&l| l != n) {
                return Err(MeshError::Mesh(format!("{len} {what} for {n} vertices")));
            }
        }
        let computed = angle_weighted_normals(&positions, &triangles);
        let normals = match normals {
            None => computed,
            Some(given) => given
                .iter()
                .zip(&computed)
                .map(|(g, c)| g.try_normalize().unwrap_or(*c))
                .collect(),
        };
        Ok(Self {
            positions,
            triangles,
            normals,
            uvs,
        })
    }

    /// The three corners of triangle `i`.
    #[inline]
    pub fn corners(&self, i: usize) -> [DVec3; 3] {
        self.triangles[i].map(|v| self.positions[v as usize])
    }

    /// The box around every vertex.
    pub fn bounds(&self) -> Aabb {
        self.positions
            .iter()
            .fold(Aabb::EMPTY, |b, p| b.union(&Aabb::new(*p, *p)))
    }
}

/// Per-vertex normals: the sum over a vertex's faces of the face's unit normal times its angle at
/// the vertex (Thürmer and Wüthrich 1998), normalised; a vertex of only degenerate faces gets +y.
pub fn angle_weighted_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut sums = vec![DVec3::ZERO; positions.len()];
    for tri in triangles {
        let p = tri.map(|v| positions[v as usize]);
        let Some(n) = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize() else {
            continue;
        };
        for k in 0..3 {
            let (a, b) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            let angle = a.angle_between(b);
            if angle.is_finite() {
                sums[tri[k] as usize] += n * angle;
            }
        }
    }
    sums.into_iter()
        .map(|s| s.try_normalize().unwrap_or(DVec3::Y))
        .collect()
}
