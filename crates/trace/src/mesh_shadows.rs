//! A tile's shadow rays against the meshes as packets: before the tile is shaded, the shadow
//! ray of every shaded camera hit toward every light ([`Integrator::shadow_rays`], exactly the
//! rays shading casts) goes through each mesh instance's packet path at once; shading then takes
//! "a mesh blocks it" from here and asks only the other kinds, ray by ray. The frame is the one
//! per-ray casts give, bit for bit: without transmission a shadow ray's transmittance is 0 or
//! 1, "some kind blocks it" does not depend on the order the kinds are asked in, and the packet
//! path answers as [`fray_mesh::MeshBvh::any_hit`] does.
//!
//! Only camera hits are batched: Whitted's secondary surfaces are found one ray at a time, and
//! their shadow rays go with them.

use crate::SceneHit;
use crate::hit::interaction;
use crate::integrator::Integrator;
use crate::interaction::SurfaceInteraction;
use crate::primitive::RayCounts;
use fray_core::{CameraRay, Interval, Ray};
use fray_scene::Scene;

/// The most shadow rays (tile rays × lights) one tile batches: its scratch space is then at most
/// ≈ 8 MB per thread (per ray a world ray, a local ray, a range, an entry, a result and its
/// `blocked` byte: 118 bytes). A tile with more (many lights, many samples) casts its shadow rays
/// one by one, with the same answers.
pub(crate) const MAX_BATCHED_SHADOW_RAYS: usize = 1 << 16;

/// A tile's shaded surfaces and, per shaded ray and light, whether a mesh blocks its shadow
/// ray (reused from tile to tile).
#[derive(Debug, Default)]
pub(crate) struct MeshShadows {
    /// Per tile ray slot: its surface, where the slot is shaded (a camera ray that hit, and with
    /// anti-aliasing a sample rather than the centre).
    surfaces: Vec<Option<SurfaceInteraction>>,
    /// Per slot × light: whether a mesh blocks that shadow ray (false where none is cast).
    blocked: Vec<bool>,
    lights: usize,
    /// The shadow rays in packet order, the `blocked` entry each answers, and the packets'
    /// scratch space.
    rays: Vec<Ray>,
    ranges: Vec<Interval>,
    entries: Vec<u32>,
    occluded: Vec<bool>,
    local: Vec<Ray>,
}

impl MeshShadows {
    /// Whether a shaded tile of `scene` with `rays` camera rays batches its shadow rays against
    /// the meshes: shadows are cast, nothing transmits (a glass surface's shadow ray keeps `kt`
    /// per crossing, which needs every crossing in order), some instance has a packet path, and
    /// the batch is within [`MAX_BATCHED_SHADOW_RAYS`].
    pub(crate) fn applies(scene: &Scene, integrator: &Integrator<'_>, rays: usize) -> bool {
        integrator.shadows()
            && !scene.features.transmission
            && rays.saturating_mul(scene.lights.len()) <= MAX_BATCHED_SHADOW_RAYS
            && scene.meshes.iter().any(|m| m.instance.packets().is_some())
    }

    /// The surfaces of the tile's shaded rays (`hits`, `per_pixel` rays per pixel), then their
    /// shadow rays, listed in `order` (the tile's packet order: nearby pixels consecutive), cast
    /// against every mesh instance.
    pub(crate) fn cast(
        &mut self,
        scene: &Scene,
        integrator: &Integrator<'_>,
        hits: &[(Option<CameraRay>, Option<SceneHit>)],
        per_pixel: usize,
        order: &[u32],
        counts: &mut RayCounts,
    ) {
        self.surfaces.clear();
        self.surfaces
            .extend(hits.iter().enumerate().map(|(k, (c, hit))| {
                let shaded = per_pixel == 1 || k % per_pixel != 0;
                match (c, hit) {
                    (Some(c), Some(hit)) if shaded => {
                        Some(interaction(scene, &c.ray, c.t_near, hit, None))
                    }
                    _ => None,
                }
            }));
        self.lights = scene.lights.len();
        self.blocked.clear();
        self.blocked.resize(hits.len() * self.lights, false);
        self.rays.clear();
        self.ranges.clear();
        self.entries.clear();
        for &k in order {
            let (Some(si), (Some(c), _)) = (&self.surfaces[k as usize], &hits[k as usize]) else {
                continue;
            };
            let first = k as usize * self.lights;
            integrator.shadow_rays(si, -c.ray.dir, |light, ray, range| {
                self.rays.push(ray);
                self.ranges.push(range);
                self.entries.push((first + light) as u32);
            });
        }
        let n = self.rays.len();
        if n == 0 {
            return;
        }
        self.occluded.resize(n, false);
        for object in &scene.meshes {
            object.instance.any_hits(
                &self.rays,
                &self.ranges,
                &mut self.occluded,
                &mut self.local,
            );
            for (&entry, &o) in self.entries.iter().zip(&self.occluded) {
                self.blocked[entry as usize] |= o;
            }
            counts.mesh_shadow_tile_rays += n as u64;
        }
    }

    /// Slot `k`'s surface, where it is shaded.
    pub(crate) fn surface(&self, k: usize) -> Option<&SurfaceInteraction> {
        self.surfaces.get(k)?.as_ref()
    }

    /// Per light, whether a mesh blocks slot `k`'s shadow ray.
    pub(crate) fn blocked(&self, k: usize) -> &[bool] {
        &self.blocked[k * self.lights..(k + 1) * self.lights]
    }
}
