//! A rendered frame (colour, depth, normals) and the statistics of how it was made.

use crate::{Image, Rgb};
use glam::Vec3;
use std::time::Duration;

/// The result of rendering: linear colour, depth (distance along the ray from its origin, in
/// world units; `f64::INFINITY` where nothing was hit) and unit world-space normals (zero where
/// nothing was hit).
#[derive(Clone, Debug)]
pub struct Frame {
    pub colour: Image<Rgb>,
    pub depth: Image<f64>,
    pub normals: Image<Vec3>,
    pub stats: RenderStats,
}

/// What a backend did to produce a frame. Counters are totals over the frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// The backend that ran, e.g. `"cpu"`.
    pub backend: String,
    /// Worker threads used.
    pub threads: usize,
    /// Camera rays cast (one per pixel).
    pub primary_rays: u64,
    /// Rays toward lights.
    pub shadow_rays: u64,
    /// Pixels whose centre ray hit a surface (one per pixel whatever the samples per pixel:
    /// depth and normals come from the centre); [`Frame::hit_fraction`] divides by the pixels.
    pub hits: u64,
    /// Interval bounds evaluated over ray segments (halving steps).
    pub bound_evaluations: u64,
    /// Point evaluations of a function (root refinement, sign checks).
    pub point_evaluations: u64,
    /// Free-form casts answered in closed form (every leaf on the ray a plain quadric) instead
    /// of by the halving search; 0 on the GPU, which always searches.
    pub closed_form_casts: u64,
    /// The ray-casting tolerance ε that was used, in world units.
    pub epsilon: f64,
    /// Quadtree cells whose ray bundle was tested (0 when no culling ran).
    pub cells_visited: u64,
    /// Quadtree cells dropped because nothing could be hit in them.
    pub cells_culled: u64,
    /// Work items (tiles with candidates) that were rendered per pixel.
    pub work_items: u64,
    /// Terrain casts of camera rays (one per ray and terrain searched; 0 without terrain).
    pub terrain_rays: u64,
    /// Pyramid segments the terrain searches tested (halving steps).
    pub terrain_segments: u64,
    /// Finest cells (or LOD max columns) the terrain searches intersected.
    pub terrain_cells: u64,
    /// Terrain segments that reached their stop level (level of detail) and were intersected.
    pub terrain_stops: u64,
    /// Sum over those stops of their level's distance above the finest level.
    pub terrain_stop_levels: u64,
    /// Media on a grid: camera rays whose terms were interpolated, and those evaluated exactly
    /// because their depth disagreed with a node's (both 0 when the media run per pixel).
    pub media_interpolated: u64,
    pub media_exact: u64,
    /// Density samples the cloud marches of camera rays took, empty-space skipping leaving out
    /// what it proved empty (0 without clouds).
    pub cloud_samples: u64,
    /// Rays cast against mesh instances (one per ray and instance searched; 0 without meshes).
    pub mesh_rays: u64,
    /// Those of them cast a tile at a time as packets (the CPU frame loop's camera rays; 0 on
    /// the GPU).
    pub mesh_tile_rays: u64,
    /// Shadow rays cast against mesh instances a tile at a time as packets (the CPU frame
    /// loop's camera hits' shadow rays, one per ray and instance; 0 on the GPU).
    pub mesh_shadow_tile_rays: u64,
    /// Whitted secondary rays traced: reflections and refractions (0 without such materials).
    pub secondary_rays: u64,
    /// Which stages and features ran, in order (e.g. `"free-form"`, `"shadows"`).
    pub passes: Vec<String>,
    /// Wall time of the render call.
    pub elapsed: Duration,
    /// GPU time of the kernels alone (timestamp queries around the compute passes), when the
    /// backend measured it: `None` on the CPU and on devices without timestamp queries.
    pub kernel_time: Option<Duration>,
    /// GPU time per pass (`raygen`, `free forms`, `shade`, …) summed over the frame's bands, in the
    /// order the passes ran; their sum is `kernel_time`. Empty where `kernel_time` is `None`.
    pub pass_times: Vec<(String, Duration)>,
    /// The host's time to make the frame's work and hand it to the device (GPU backends; zero
    /// on the CPU): from the start of the frame to its last submission — the work list, buffer
    /// writes, encoding and submitting — less the time spent waiting for the device in between
    /// (timestamp readbacks; on a software adapter, whose passes are each submitted and waited
    /// for alone, each pass's submission and wait, which `pass_times` hold). The readback after
    /// the last submission is not in it. Of the frame's last try, like `pass_times`.
    pub encode_time: Duration,
    /// Bytes the frame sent from the host to the device (GPU backends; 0 on the CPU): the
    /// camera, the work list and, when the scene was uploaded for this frame, the scene.
    pub uploaded_bytes: u64,
    /// Of those, the scene's own data (geometry, terrains, materials, lights): 0 for a frame
    /// of a scene that stays resident on the device.
    pub scene_uploaded_bytes: u64,
    /// Pipelines (compiled shaders) built for this frame; 0 when all came from the cache.
    pub pipelines_built: u32,
    /// Time spent building them.
    pub pipeline_build_time: Duration,
}

impl Frame {
    /// The fraction of pixels whose centre ray hit a surface.
    pub fn hit_fraction(&self) -> f64 {
        let pixels = self.colour.width() as u64 * self.colour.height() as u64;
        self.stats.hits as f64 / pixels.max(1) as f64
    }
}

impl RenderStats {
    /// All rays cast, primary and secondary.
    pub fn rays(&self) -> u64 {
        self.primary_rays + self.shadow_rays
    }

    /// Rays per second of wall time.
    pub fn rays_per_second(&self) -> f64 {
        self.rays() as f64 / self.elapsed.as_secs_f64().max(1e-12)
    }

    /// Bound evaluations per ray: the "steps per ray" of the binary search.
    pub fn steps_per_ray(&self) -> f64 {
        self.bound_evaluations as f64 / self.rays().max(1) as f64
    }

    /// Mean level of detail of the terrain searches: levels above the finest where they stopped
    /// (0 = exact everywhere).
    pub fn terrain_mean_lod(&self) -> f64 {
        self.terrain_stop_levels as f64 / self.terrain_stops.max(1) as f64
    }
}
