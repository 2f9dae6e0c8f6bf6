//! The work a frame does per pixel, for debug views (a heat map of search steps, the terrain's
//! level of detail): each pixel's centre ray cast alone, as the frame loop casts it — the same
//! tiles and candidates with culling, the same pixel footprint — with its work counted.

use crate::hit::nearest_pending;
use crate::primitive::{RayCounts, TraceContext};
use crate::render::{active_sets, check_frame, frame_tiles};
use crate::{TraceError, TraceSettings};
use fray_core::Interval;
use fray_quadtree::PixelCoverage;
use fray_scene::Scene;
use rayon::prelude::*;

/// Bytes the probe holds per pixel: its steps (u32), its level (f32) and its stops (u32).
const BYTES_PER_PIXEL: u64 = 12;

/// The work of each pixel's centre ray, row by row.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelWork {
    pub width: u32,
    pub height: u32,
    /// Search steps: the free forms' interval bounds and point evaluations, the terrains'
    /// pyramid segments and cells, and one per mesh instance searched (a BVH's node visits are
    /// not counted). 0 where the quadtree culled the pixel's tile.
    pub steps: Vec<u32>,
    /// The terrain's level of detail where the ray stopped: the mean over its stops of the
    /// stop level's distance above the finest level (0 = the finest cells); NaN where the ray
    /// stopped on no terrain column.
    pub terrain_level: Vec<f32>,
    /// The terrain segments the ray intersected at their stop level (the level's weight).
    pub terrain_stops: Vec<u32>,
}

impl PixelWork {
    /// The most steps any pixel took (the heat map's scale).
    pub fn most_steps(&self) -> u32 {
        self.steps.iter().copied().max().unwrap_or(0)
    }

    /// The highest level any pixel stopped at (the level view's scale); 0 without terrain.
    pub fn highest_level(&self) -> f32 {
        self.terrain_level
            .iter()
            .copied()
            .filter(|l| l.is_finite())
            .fold(0.0, f32::max)
    }
}

/// The steps of `counts`, as [`PixelWork::steps`] counts them.
fn steps(c: &RayCounts) -> u64 {
    c.cast.bound_evaluations
        + c.cast.point_evaluations
        + c.terrain.segments
        + c.terrain.cells
        + c.mesh_rays
}

/// Casts every pixel's centre ray of `scene` (its camera and size) with `settings`' epsilon,
/// culling, tile size and threads, and counts each one's work. No shading: the work of finding
/// the surfaces, which is most of a frame's.
pub fn pixel_work(scene: &Scene, settings: &TraceSettings) -> Result<PixelWork, TraceError> {
    check_frame(scene, settings)?;
    let (width, height) = (scene.width, scene.height);
    let pixels = u64::from(width) * u64::from(height);
    let _images = scene.budget.reserve_elements(
        format!(
            "the per-pixel work images ({width} × {height} pixels, {BYTES_PER_PIXEL} bytes each)"
        ),
        pixels,
        BYTES_PER_PIXEL,
    )?;
    let pool = crate::settings::thread_pool(settings.threads)?;
    // The frame loop's tiles, for centre rays only.
    let (tiles, list) = frame_tiles(scene, settings, PixelCoverage::Centres, &pool)?;
    let footprint = scene.camera.pixel_footprint(width, height);
    let per_tile: Vec<Vec<(u32, f32, u32)>> = pool.install(|| {
        tiles
            .par_iter()
            .map_init(
                || (TraceContext::new(settings.method), Vec::new()),
                |(ctx, candidates), tile| {
                    let ((x0, y0, x1, y1), item) = (tile.rect, tile.item);
                    let listed = match (item, &list) {
                        (Some(k), Some(list)) => Some(active_sets(scene, list, k, candidates)),
                        _ => None,
                    };
                    let candidates = listed.map(|n| &candidates[..n]);
                    let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
                    for py in y0..y1 {
                        for px in x0..x1 {
                            let Some(c) = scene.camera.pixel_ray(px, py, width, height) else {
                                out.push((0, f32::NAN, 0));
                                continue;
                            };
                            let before = ctx.counts;
                            let range = Interval {
                                lo: c.t_near,
                                hi: f64::INFINITY,
                            };
                            let _ = nearest_pending(
                                scene,
                                ctx,
                                &c.ray,
                                range,
                                settings.epsilon,
                                candidates,
                                footprint,
                                None,
                            );
                            let after = ctx.counts;
                            let n = steps(&after) - steps(&before);
                            let stops = after.terrain.stops - before.terrain.stops;
                            let levels = after.terrain.stop_levels_above_finest
                                - before.terrain.stop_levels_above_finest;
                            let level = if stops > 0 {
                                levels as f32 / stops as f32
                            } else {
                                f32::NAN
                            };
                            out.push((
                                u32::try_from(n).unwrap_or(u32::MAX),
                                level,
                                u32::try_from(stops).unwrap_or(u32::MAX),
                            ));
                        }
                    }
                    out
                },
            )
            .collect()
    });
    let n = pixels as usize;
    let mut work = PixelWork {
        width,
        height,
        steps: vec![0; n],
        terrain_level: vec![f32::NAN; n],
        terrain_stops: vec![0; n],
    };
    for (tile, values) in tiles.iter().zip(&per_tile) {
        let (x0, y0, x1, _) = tile.rect;
        let w = (x1 - x0) as usize;
        for (k, &(s, l, stops)) in values.iter().enumerate() {
            let (px, py) = (x0 as usize + k % w, y0 as usize + k / w);
            let at = py * width as usize + px;
            work.steps[at] = s;
            work.terrain_level[at] = l;
            work.terrain_stops[at] = stops;
        }
    }
    Ok(work)
}
