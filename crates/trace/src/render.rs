//! The CPU frame loop: tiles in parallel (rayon), one primary ray per pixel centre, shading, and
//! the frame's statistics. The result does not depend on the thread count.

use crate::SceneHit;
use crate::hit::nearest_hit_lod;
use crate::shade::{ShadeContext, SurfacePoint};
use crate::shadow_cull;
use crate::terrain_hit::TerrainCast;
use crate::{TraceError, TraceSettings};
use fray_core::{CameraRay, Frame, Image, Interval, RenderStats, Rgb};
use fray_geometry::{ActiveSet, CastStats, RayCaster};
use fray_scene::{Scene, work_list};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// Called after each finished tile with (pixels done, pixels in total).
pub type Progress<'a> = &'a (dyn Fn(u64, u64) + Sync);

/// One tile's pixels and counters.
struct TileResult {
    x0: u32,
    y0: u32,
    w: u32,
    h: u32,
    colour: Vec<Rgb>,
    depth: Vec<f64>,
    normals: Vec<Vec3>,
    hits: u64,
    shadow_rays: u64,
    cast: CastStats,
    terrain: TerrainCast,
}

/// Renders `scene` on the CPU.
pub fn render(
    scene: &Scene,
    settings: &TraceSettings,
    progress: Option<Progress<'_>>,
) -> Result<Frame, TraceError> {
    if !(settings.epsilon.is_finite() && settings.epsilon > 0.0) {
        return Err(TraceError::BadEpsilon(settings.epsilon));
    }
    if scene.width == 0 || scene.height == 0 {
        return Err(TraceError::EmptyImage(scene.width, scene.height));
    }
    if settings.tile_size == 0 {
        return Err(TraceError::BadTileSize);
    }
    let start = Instant::now();
    let pool = {
        let mut builder = rayon::ThreadPoolBuilder::new();
        if let Some(n) = settings.threads {
            builder = builder.num_threads(n);
        }
        builder.build().map_err(|e| TraceError::ThreadPool {
            threads: settings.threads.unwrap_or(0),
            reason: e.to_string(),
        })?
    };
    let (width, height) = (scene.width, scene.height);
    let ts = settings.tile_size;
    let total = u64::from(width) * u64::from(height);
    let done = AtomicU64::new(0);
    // Tiles `(x0, y0, x1, y1)`, with the index of their work item when culling.
    let (tiles, list): (Vec<Tile>, _) = if settings.culling {
        let list = pool.install(|| work_list(scene, ts))?;
        let tiles = list
            .items
            .iter()
            .enumerate()
            .map(|(k, it)| Tile {
                rect: (it.x0, it.y0, it.x1, it.y1),
                item: Some(k),
            })
            .collect();
        (tiles, Some(list))
    } else {
        let tiles = (0..height.div_ceil(ts))
            .flat_map(|ty| {
                (0..width.div_ceil(ts)).map(move |tx| Tile {
                    rect: (
                        tx * ts,
                        ty * ts,
                        (tx * ts + ts).min(width),
                        (ty * ts + ts).min(height),
                    ),
                    item: None,
                })
            })
            .collect();
        (tiles, None)
    };
    let results: Vec<TileResult> = pool.install(|| {
        tiles
            .par_iter()
            .map_init(RayCaster::new, |caster, t| {
                let candidates: Option<Vec<(u32, ActiveSet)>> = match (t.item, list.as_ref()) {
                    (Some(k), Some(list)) => Some(
                        list.candidates_of(&list.items[k])
                            .iter()
                            .map(|c| {
                                let mut a = ActiveSet::new();
                                // Terrain candidates (ids after the objects) have no solid.
                                if let Some(object) = scene.objects.get(c.object as usize) {
                                    a.set(
                                        &object.solid,
                                        c.leaves(&list.leaves),
                                        c.perturbations(&list.perturbations),
                                    );
                                }
                                (c.object, a)
                            })
                            .collect(),
                    ),
                    _ => None,
                };
                let tile = render_tile(scene, settings, caster, t.rect, candidates.as_deref());
                if let Some(report) = progress {
                    let n = u64::from(tile.w) * u64::from(tile.h);
                    report(done.fetch_add(n, Ordering::Relaxed) + n, total);
                }
                tile
            })
            .collect()
    });

    if let Some(report) = progress {
        // Culled tiles are done too (background).
        report(total, total);
    }
    let (colour, depth, normals) =
        pool.install(|| assemble(width, height, scene.background, &results));
    let mut stats = RenderStats {
        backend: "cpu".into(),
        threads: pool.current_num_threads(),
        primary_rays: total,
        epsilon: settings.epsilon,
        ..RenderStats::default()
    };
    if let Some(list) = &list {
        stats.cells_visited = list.stats.cells_visited;
        stats.cells_culled = list.stats.cells_culled;
        stats.work_items = list.stats.items;
    }
    for t in &results {
        stats.hits += t.hits;
        stats.shadow_rays += t.shadow_rays;
        stats.bound_evaluations += t.cast.bound_evaluations;
        stats.point_evaluations += t.cast.point_evaluations;
        stats.terrain_rays += t.terrain.rays;
        stats.terrain_segments += t.terrain.stats.segments;
        stats.terrain_cells += t.terrain.stats.cells;
        stats.terrain_stops += t.terrain.stats.stops;
        stats.terrain_stop_levels += t.terrain.stats.stop_levels_above_finest;
    }
    if list.is_some() {
        stats.passes.push("quadtree".into());
    }
    stats.passes.push("primary".into());
    stats
        .passes
        .extend(scene.features.names().iter().map(|s| s.to_string()));
    if !(settings.shadows && scene.features.shadows) {
        stats.passes.retain(|p| p != "shadows");
    }
    if !settings.shading {
        // Visibility only: no light was evaluated.
        stats
            .passes
            .retain(|p| !matches!(p.as_str(), "shadows" | "sun" | "point-lights"));
    }
    stats.elapsed = start.elapsed();
    Ok(Frame {
        colour,
        depth,
        normals,
        stats,
    })
}

/// The frame's images from the tiles' pixels: background where no tile is. Row by row in
/// parallel (a serial copy of a 1024² frame's 32 MB costs as much as a tenth of its tracing).
fn assemble(
    width: u32,
    height: u32,
    background: Rgb,
    tiles: &[TileResult],
) -> (Image<Rgb>, Image<f64>, Image<Vec3>) {
    let (w, n) = (width as usize, width as usize * height as usize);
    // Which tiles cover each row.
    let mut rows: Vec<Vec<u32>> = vec![Vec::new(); height as usize];
    for (k, t) in tiles.iter().enumerate() {
        for y in t.y0..t.y0 + t.h {
            if let Some(row) = rows.get_mut(y as usize) {
                row.push(k as u32);
            }
        }
    }
    let mut colour: Vec<Rgb> = (0..n).into_par_iter().map(|_| background).collect();
    let mut depth: Vec<f64> = (0..n).into_par_iter().map(|_| f64::INFINITY).collect();
    let mut normals: Vec<Vec3> = (0..n).into_par_iter().map(|_| Vec3::ZERO).collect();
    colour
        .par_chunks_mut(w)
        .zip(depth.par_chunks_mut(w))
        .zip(normals.par_chunks_mut(w))
        .zip(rows.par_iter())
        .enumerate()
        .for_each(|(y, (((c, d), nrm), covering))| {
            for &k in covering {
                let t = &tiles[k as usize];
                let (x0, x1) = (t.x0 as usize, (t.x0 + t.w) as usize);
                let from = (y - t.y0 as usize) * t.w as usize;
                let to = from + t.w as usize;
                c[x0..x1].copy_from_slice(&t.colour[from..to]);
                d[x0..x1].copy_from_slice(&t.depth[from..to]);
                nrm[x0..x1].copy_from_slice(&t.normals[from..to]);
            }
        });
    // The lengths are width × height by construction, so the fallback is never taken.
    match (
        Image::from_pixels(width, height, colour),
        Image::from_pixels(width, height, depth),
        Image::from_pixels(width, height, normals),
    ) {
        (Some(c), Some(d), Some(nrm)) => (c, d, nrm),
        _ => (
            Image::filled(width, height, background),
            Image::filled(width, height, f64::INFINITY),
            Image::filled(width, height, Vec3::ZERO),
        ),
    }
}

/// A rectangle of pixels `[x0, x1) × [y0, y1)` and its work item, if culled.
struct Tile {
    rect: (u32, u32, u32, u32),
    item: Option<usize>,
}

fn render_tile(
    scene: &Scene,
    settings: &TraceSettings,
    caster: &mut RayCaster,
    (x0, y0, x1, y1): (u32, u32, u32, u32),
    candidates: Option<&[(u32, ActiveSet)]>,
) -> TileResult {
    let (w, h) = (x1 - x0, y1 - y0);
    let n = (w * h) as usize;
    let mut tile = TileResult {
        x0,
        y0,
        w,
        h,
        colour: Vec::with_capacity(n),
        depth: Vec::with_capacity(n),
        normals: Vec::with_capacity(n),
        hits: 0,
        shadow_rays: 0,
        cast: CastStats::default(),
        terrain: TerrainCast::with_footprint(
            scene.camera.pixel_footprint(scene.width, scene.height),
        ),
    };
    let mut shade = ShadeContext {
        scene,
        shadows: settings.shading && settings.shadows && scene.features.shadows,
        epsilon: settings.epsilon,
        shadow_rays: 0,
        cast: CastStats::default(),
        occluders: None,
    };
    // First every pixel's camera ray and nearest hit, then (with culling) the objects the
    // tile's shadow rays can meet, then the shading.
    let mut hits: Vec<(Option<CameraRay>, Option<SceneHit>)> = Vec::with_capacity(n);
    for py in y0..y0 + h {
        for px in x0..x0 + w {
            let camera_ray = scene.camera.pixel_ray(px, py, scene.width, scene.height);
            let hit = camera_ray.as_ref().and_then(|c| {
                let range = Interval::new(c.t_near, f64::INFINITY);
                let (stats, terrain) = (&mut tile.cast, &mut tile.terrain);
                let eps = settings.epsilon;
                nearest_hit_lod(
                    scene, caster, &c.ray, range, eps, candidates, stats, terrain,
                )
            });
            hits.push((camera_ray, hit));
        }
    }
    if shade.shadows && settings.culling && !scene.lights.is_empty() {
        // The surface points again (cheap, and only here): storing them for every pixel would
        // cost the visibility-only frame more than recomputing costs the shaded one.
        let mut reach = 0.0f64;
        let origins = shadow_cull::bounding_box(hits.iter().filter_map(|(c, hit)| {
            let (point, _) = surface_point(c.as_ref()?, hit.as_ref()?);
            reach = reach.max(shade.shadow_offset(&point));
            Some(shade.shadow_origin(&point))
        }));
        shade.occluders = Some(shadow_cull::occluders(scene, origins, reach));
    }
    for (camera_ray, hit) in &hits {
        let (c, d, nrm) = match (camera_ray, hit) {
            (Some(camera_ray), Some(hit)) => {
                shade_hit(scene, settings, caster, &mut shade, camera_ray, hit)
            }
            _ => (scene.background, f64::INFINITY, Vec3::ZERO),
        };
        if d.is_finite() {
            tile.hits += 1;
        }
        tile.colour.push(c);
        tile.depth.push(d);
        tile.normals.push(nrm);
    }
    tile.shadow_rays = shade.shadow_rays;
    tile.cast += shade.cast;
    tile
}

/// The shading frame of a camera ray's hit: the surface point (normal facing the viewer) and
/// the outward normal the frame stores.
fn surface_point(camera_ray: &CameraRay, hit: &SceneHit) -> (SurfacePoint, DVec3) {
    let ray = camera_ray.ray;
    let position = ray.at(hit.t);
    let to_viewer = -ray.dir;
    let normal = if hit.t <= camera_ray.t_near {
        // The picture surface cuts the object: show the cut face, facing the viewer.
        to_viewer
    } else {
        hit.normal
    };
    let shading_normal = if normal.dot(to_viewer) < 0.0 {
        -normal
    } else {
        normal
    };
    let point = SurfacePoint {
        position,
        normal: shading_normal,
        to_viewer,
    };
    (point, normal)
}

/// The colour, depth and normal of a pixel whose camera ray hit `hit`.
fn shade_hit(
    scene: &Scene,
    settings: &TraceSettings,
    caster: &mut RayCaster,
    shade: &mut ShadeContext<'_>,
    camera_ray: &CameraRay,
    hit: &SceneHit,
) -> (Rgb, f64, Vec3) {
    let (point, normal) = surface_point(camera_ray, hit);
    if !settings.shading {
        let n = normal.as_vec3();
        return (Vec3::splat(0.5) + 0.5 * n, hit.t, n);
    }
    // Borrowed, not cloned: a clone allocates the material's name for every hit pixel.
    let material = crate::terrain_hit::material_of(scene, hit.object, hit.leaf)
        .and_then(|m| scene.materials.get(m as usize));
    let fallback;
    let material = match material {
        Some(m) => m,
        None => {
            fallback = fray_scene::Material::default();
            &fallback
        }
    };
    let radiance: DVec3 = shade.radiance(caster, &point, material);
    (radiance.as_vec3(), hit.t, normal.as_vec3())
}
