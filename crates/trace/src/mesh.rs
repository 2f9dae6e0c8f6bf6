//! Triangle meshes as a primitive kind: a scene's mesh instance, cast by `fray-mesh`'s BVH (the
//! watertight f64 triangle test; any hit for shadow rays); the surface from the hit triangle —
//! its own normal (geometric), the vertex normals interpolated by the barycentrics (shading,
//! unless the object is faceted) and the interpolated UVs. A tile's camera rays go through the
//! instance's packet path at once ([`MeshPrimitive::narrow_tile`]), with the same answers.

use crate::hit::TileShape;
use crate::primitive::{KindHit, Primitive, Surface, TraceContext};
use fray_core::{Aabb, CameraRay, Interval, Ray, Rgb};
use fray_mesh::texture::triangle_uv_per_world;
use fray_scene::MeshObject;
use glam::{DVec2, DVec3};

/// One mesh instance of the scene.
#[derive(Clone, Copy, Debug)]
pub struct MeshPrimitive<'a> {
    pub object: &'a MeshObject,
}

impl Primitive for MeshPrimitive<'_> {
    fn bounds(&self) -> Aabb {
        self.object.instance.bounds()
    }

    /// The nearest triangle hit strictly inside `range` (a mesh is a surface, not a solid: a ray
    /// that starts inside a closed mesh hits its far side). `part` is the triangle, `detail` its
    /// barycentric weights.
    #[inline]
    fn nearest_hit(
        &self,
        ray: &Ray,
        range: Interval,
        _eps: f64,
        ctx: &mut TraceContext,
    ) -> Option<KindHit> {
        ctx.counts.mesh_rays += 1;
        let hit = self.object.instance.nearest_hit(ray, range)?;
        Some(kind_hit(hit))
    }

    fn transmittance(&self, ray: &Ray, range: Interval, _eps: f64, _: &mut TraceContext) -> Rgb {
        if self.object.instance.any_hit(ray, range) {
            Rgb::ZERO
        } else {
            Rgb::ONE
        }
    }

    fn uv_per_world(&self, part: u32) -> f64 {
        let instance = &self.object.instance;
        let mesh = instance.mesh.mesh();
        let (Some(uvs), Some(&[a, b, c])) = (&mesh.uvs, mesh.triangles.get(part as usize)) else {
            return 0.0;
        };
        let corners = instance.world_corners(part as usize);
        triangle_uv_per_world(corners, [a, b, c].map(|v| uvs[v as usize]))
    }

    fn surface(&self, ray: &Ray, hit: &KindHit) -> Surface {
        let instance = &self.object.instance;
        let triangle = hit.part as usize;
        let mesh = instance.mesh.mesh();
        let Some(&[i, j, k]) = mesh.triangles.get(triangle) else {
            return Surface {
                geometric_normal: -ray.dir,
                shading_normal: -ray.dir,
                part: hit.part,
                uv: None,
            };
        };
        let [a, b, c] = instance.world_corners(triangle);
        // Counter-clockwise seen from outside: the face normal points out (a mirroring
        // transform reverses the winding). A triangle the watertight test hit has a non-zero
        // area, but a sliver may round to zero here.
        let winding = if instance.mirrored() { -1.0 } else { 1.0 };
        let geometric_normal = ((b - a).cross(c - a) * winding)
            .try_normalize()
            .unwrap_or(-ray.dir);
        let w = hit.detail;
        let shading_normal = if self.object.smooth {
            let [ni, nj, nk] = [i, j, k].map(|v| mesh.normals[v as usize]);
            let n = instance.world_normal(ni * w.x + nj * w.y + nk * w.z);
            // An interpolated normal that turned away from its face (a folded mesh) would light
            // the wrong side: keep the face's then.
            if n.dot(geometric_normal) > 0.0 {
                n
            } else {
                geometric_normal
            }
        } else {
            geometric_normal
        };
        let uv = mesh.uvs.as_ref().map(|uvs| {
            let [ti, tj, tk] = [i, j, k].map(|v| uvs[v as usize]);
            ti * w.x + tj * w.y + tk * w.z
        });
        Surface {
            geometric_normal,
            shading_normal,
            part: hit.part,
            uv: uv.map(|uv: DVec2| uv),
        }
    }
}

/// A mesh hit as its kind's hit: the triangle is the part, the barycentrics the detail.
#[inline]
fn kind_hit(hit: fray_mesh::MeshHit) -> KindHit {
    let [a, b, c] = hit.barycentric;
    KindHit {
        t: hit.t,
        part: hit.triangle,
        detail: DVec3::new(a, b, c),
    }
}

impl MeshPrimitive<'_> {
    /// Narrows each pixel's hit (`pixels`: camera ray and best hit so far; `id` the object's)
    /// with this instance: the casts [`Primitive::nearest_hit`] makes, each over
    /// `[t_near, best so far]` and kept only if nearer, made for all the tile's rays at once
    /// through the instance's packet path ([`fray_mesh::Instance::nearest_hits`]: the same
    /// answers bit for bit), so the frame is the one per-ray casts give.
    pub(crate) fn narrow_tile(
        &self,
        id: fray_scene::PrimitiveId,
        pixels: &mut [(Option<CameraRay>, Option<crate::SceneHit>)],
        shape: TileShape,
        ctx: &mut TraceContext,
    ) {
        let s = &mut ctx.mesh;
        s.packet_order(shape, pixels.len());
        s.rays.clear();
        s.ranges.clear();
        s.slots.clear();
        for &k in &s.order {
            let Some(c) = &pixels[k as usize].0 else {
                continue;
            };
            let best = &pixels[k as usize].1;
            let hi = best.map_or(f64::INFINITY, |b| b.hit.t);
            s.rays.push(c.ray);
            s.ranges.push(Interval { lo: c.t_near, hi });
            s.slots.push(k);
        }
        let n = s.rays.len();
        s.hits.clear();
        s.hits.resize(n, None);
        self.object
            .instance
            .nearest_hits(&s.rays, &s.ranges, &mut s.hits, &mut s.local);
        ctx.counts.mesh_rays += n as u64;
        ctx.counts.mesh_tile_rays += n as u64;
        for (&k, hit) in s.slots.iter().zip(&s.hits) {
            let Some(hit) = hit else {
                continue;
            };
            let best = &mut pixels[k as usize].1;
            if best.is_none_or(|b| hit.t < b.hit.t) {
                *best = Some(crate::SceneHit {
                    primitive: id,
                    hit: kind_hit(*hit),
                });
            }
        }
    }
}

impl crate::primitive::MeshScratch {
    /// Makes `order` the tile's ray slots in packet order, for `len` rays listed as `shape`
    /// says (kept while the shape and count stay). Packets are runs of consecutive rays: in
    /// Morton order of the pixels, 64 rays are an 8 × 8 block (or a few pixels' samples), not
    /// four rows.
    pub(crate) fn packet_order(&mut self, shape: TileShape, len: usize) {
        let key = (shape.width, shape.rays_per_pixel, len);
        if self.order_for != Some(key) {
            morton_order(shape, len, &mut self.order);
            self.order_for = Some(key);
        }
    }
}

/// The slots of a tile's `len` rays (listed as `shape` says) with the pixels in Morton order
/// (the bits of x and y interleaved), each pixel's rays together: nearby rays are consecutive at
/// every scale.
fn morton_order(shape: TileShape, len: usize, order: &mut Vec<u32>) {
    let per_pixel = shape.rays_per_pixel.max(1) as usize;
    let width = shape.width.max(1) as usize;
    let spread = |v: u32| {
        let mut v = u64::from(v);
        let mut out = 0u64;
        for bit in 0..32 {
            out |= (v & 1) << (2 * bit);
            v >>= 1;
        }
        out
    };
    let pixels = len.div_ceil(per_pixel);
    let mut keyed: Vec<(u64, u32)> = (0..pixels)
        .map(|p| {
            let (x, y) = ((p % width) as u32, (p / width) as u32);
            (spread(x) | (spread(y) << 1), p as u32)
        })
        .collect();
    keyed.sort_unstable();
    order.clear();
    for (_, p) in keyed {
        let first = p as usize * per_pixel;
        order.extend((first..(first + per_pixel).min(len)).map(|k| k as u32));
    }
}
