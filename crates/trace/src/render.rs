//! The CPU frame loop: bands of image rows in parallel (rayon), written in place; in each band
//! its tiles, each in passes — camera rays (one per pixel centre), hits (candidates outer,
//! pixels inner), surfaces, the shadow rays against meshes as packets, shading — and the frame's
//! statistics. The result does not depend
//! on the thread count or the tile size.

use crate::SceneHit;
use crate::hit::{TileShape, complete_surface, interaction, nearest_hits_deferred, shading_normal};
use crate::integrator::Integrator;
use crate::media_grid::MediaGrid;
use crate::mesh_shadows::MeshShadows;
use crate::primitive::{RayCounts, TraceContext};
use crate::shadow_cull;
use crate::{TraceError, TraceSettings};
use fray_core::{CameraRay, Frame, Image, Interval, RenderStats, Rgb};
use fray_geometry::ActiveSet;
use fray_quadtree::{PixelCoverage, QuadtreeConfig, WorkList};
use fray_scene::{PrimitiveId, PrimitiveKind, Scene, work_list_within};
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// Bytes per pixel of a frame's images: colour (3 × f32), depth (f64), normal (3 × f32).
pub const FRAME_BYTES_PER_PIXEL: u64 = 32;

/// Called after each finished tile with (pixels done, pixels in total).
pub type Progress<'a> = &'a (dyn Fn(u64, u64) + Sync);

/// One thread's reusable scratch space (nothing in it outlives a tile) and its counters.
struct Scratch {
    ctx: TraceContext,
    hits_found: u64,
    /// The current tile's candidates, with their active sets (reused: sets keep their buffers).
    candidates: Vec<(PrimitiveId, ActiveSet)>,
    hits: Vec<(Option<CameraRay>, Option<SceneHit>)>,
    /// The tile's surfaces and their shadow rays' mesh answers, where those go as packets.
    mesh_shadows: MeshShadows,
}

/// A band of whole image rows, written in place by one task: its slices of the three images.
struct BandImages<'a> {
    y0: u32,
    width: u32,
    colour: &'a mut [Rgb],
    depth: &'a mut [f64],
    normals: &'a mut [Vec3],
}

/// Renders `scene` on the CPU.
pub fn render(
    scene: &Scene,
    settings: &TraceSettings,
    progress: Option<Progress<'_>>,
) -> Result<Frame, TraceError> {
    let mut frame = Frame {
        colour: Image::filled(0, 0, Rgb::ZERO),
        depth: Image::filled(0, 0, 0.0),
        normals: Image::filled(0, 0, Vec3::ZERO),
        stats: RenderStats::default(),
    };
    render_into(scene, settings, progress, &mut frame)?;
    Ok(frame)
}

/// [`render`] into `frame`, reusing its image buffers when they already have the scene's size:
/// a loop that renders frame after frame (an animation, a flight) then allocates no images.
/// A fresh 1024² frame spends about a tenth of its time having the kernel supply and zero the
/// 32 MB of new pages. Every pixel and the stats are overwritten; on an error `frame` is left
/// as it was.
pub fn render_into(
    scene: &Scene,
    settings: &TraceSettings,
    progress: Option<Progress<'_>>,
    frame: &mut Frame,
) -> Result<(), TraceError> {
    check_frame(scene, settings)?;
    let start = Instant::now();
    let (width, height) = (scene.width, scene.height);
    let ts = settings.tile_size;
    // The rows rendered: the whole image, or a band of it that starts where a band of the whole
    // image's loop starts, so every pixel is computed exactly as in the whole image.
    let (row0, row1) = settings.rows.unwrap_or((0, height));
    if !(row0 < row1 && row1 <= height && row0 % ts == 0) {
        return Err(TraceError::BadRows {
            start: row0,
            end: row1,
            height,
            tile: ts,
        });
    }
    let rows = row1 - row0;
    let n = width as usize * rows as usize;
    let sized = |w: u32, h: u32| w == width && h == rows;
    let resized = !(sized(frame.colour.width(), frame.colour.height())
        && sized(frame.depth.width(), frame.depth.height())
        && sized(frame.normals.width(), frame.normals.height()));
    // New images are charged to the render's account while it renders, so the work list and
    // the media grid are checked against what the scene and the frame leave.
    let _frame_images = if resized {
        Some(scene.budget.reserve_elements(
            format!("the frame's colour, depth and normal images ({width} × {rows} pixels, 32 bytes each)"),
            n as u64,
            FRAME_BYTES_PER_PIXEL,
        )?)
    } else {
        None
    };
    let pool = crate::settings::thread_pool(settings.threads)?;
    let total = u64::from(width) * u64::from(rows);
    let done = AtomicU64::new(0);
    // Samples anywhere in a pixel need bundles over the whole pixel.
    let coverage = if settings.samples.count() > 1 {
        PixelCoverage::Area
    } else {
        PixelCoverage::Centres
    };
    let (tiles, list) = frame_tiles(scene, settings, coverage, &pool)?;
    // The images are written in place, a band of `tile_size` rows per task (a tile that
    // straddles bands is rendered in parts): no per-tile buffers to allocate, fill and copy,
    // which cost a 1024² frame as much as a fifth of its tracing in page faults and copies.
    let band_rows = ts as usize;
    let bands = tiles_by_band(&tiles, height, ts);
    let bands = &bands[(row0 / ts) as usize..row1.div_ceil(ts) as usize];
    if resized {
        // New buffers from zeroed allocations: the kernel maps their pages when a band task
        // first writes its rows (in parallel, once), instead of in a fill pass before that.
        let zeroed = || {
            bytemuck::allocation::try_zeroed_vec::<Vec3>(n).unwrap_or_else(|_| vec![Vec3::ZERO; n])
        };
        let (colour, depth, normals) = (zeroed(), vec![0.0; n], zeroed());
        // The lengths are width × height by construction, so the fallbacks are never taken.
        frame.colour = Image::from_pixels(width, rows, colour)
            .unwrap_or_else(|| Image::filled(width, rows, Rgb::ZERO));
        frame.depth = Image::from_pixels(width, rows, depth)
            .unwrap_or_else(|| Image::filled(width, rows, 0.0));
        frame.normals = Image::from_pixels(width, rows, normals)
            .unwrap_or_else(|| Image::filled(width, rows, Vec3::ZERO));
    }
    let w = width as usize;
    let mut integrator = Integrator::new(scene, settings);
    // Clouds change from pixel to pixel: with them every camera ray takes its own terms.
    let grid_spacing = settings
        .media_grid
        .filter(|_| integrator.media().is_some_and(|m| !m.has_clouds()));
    if let (Some(media), Some(spacing)) = (integrator.media(), grid_spacing) {
        let grid = pool
            .install(|| MediaGrid::build(scene, media, spacing, settings.epsilon, &scene.budget))?;
        integrator.set_media_grid(grid);
    }
    let counters: Vec<(RayCounts, u64)> = pool.install(|| {
        frame
            .colour
            .pixels_mut()
            .par_chunks_mut(w * band_rows)
            .zip(frame.depth.pixels_mut().par_chunks_mut(w * band_rows))
            .zip(frame.normals.pixels_mut().par_chunks_mut(w * band_rows))
            .zip(bands.par_iter())
            .enumerate()
            .map_init(
                || Scratch {
                    ctx: TraceContext::new(settings.method),
                    hits_found: 0,
                    candidates: Vec::new(),
                    hits: Vec::new(),
                    mesh_shadows: MeshShadows::default(),
                },
                |scratch, (k, (((colour, depth), normals), band))| {
                    // Background where no tile (or no surface) is.
                    let y0 = row0 + k as u32 * ts;
                    let media = integrator.media().is_some();
                    if media {
                        // Marked unwritten: what no tile writes gets its miss after the tiles.
                        colour.fill(Rgb::NAN);
                    } else {
                        colour.fill(scene.background);
                    }
                    depth.fill(f64::INFINITY);
                    normals.fill(Vec3::ZERO);
                    let mut out = BandImages {
                        y0,
                        width,
                        colour,
                        depth,
                        normals,
                    };
                    let y1 = (y0 + ts).min(row1);
                    for &ti in band {
                        let t = &tiles[ti as usize];
                        let (x0, ty0, x1, ty1) = t.rect;
                        let rect = (x0, ty0.max(y0), x1, ty1.min(y1));
                        let listed = match (t.item, list.as_ref()) {
                            (Some(k), Some(list)) => {
                                Some(active_sets(scene, list, k, &mut scratch.candidates))
                            }
                            _ => None,
                        };
                        render_tile(
                            scene,
                            settings,
                            &integrator,
                            scratch,
                            rect,
                            listed,
                            &mut out,
                        );
                        if let Some(report) = progress {
                            let n = u64::from(rect.2 - rect.0) * u64::from(rect.3 - rect.1);
                            report(done.fetch_add(n, Ordering::Relaxed) + n, total);
                        }
                    }
                    if media {
                        // Seen through the media: every pixel's own, computed as a tile's miss
                        // would be, so culling stays lossless.
                        fill_misses(
                            scene,
                            settings,
                            &integrator,
                            &mut scratch.ctx,
                            y0,
                            out.colour,
                        );
                    }
                    // The band's counters; the scratch space goes on to the thread's next band.
                    (
                        scratch.ctx.take_counts(),
                        std::mem::take(&mut scratch.hits_found),
                    )
                },
            )
            .collect()
    });

    if let Some(report) = progress {
        // Culled tiles are done too (background).
        report(total, total);
    }
    let mut stats = RenderStats {
        backend: "cpu".into(),
        threads: pool.current_num_threads(),
        primary_rays: total * rays_per_pixel(settings.samples) as u64,
        epsilon: settings.epsilon,
        ..RenderStats::default()
    };
    if let Some(list) = &list {
        stats.cells_visited = list.stats.cells_visited;
        stats.cells_culled = list.stats.cells_culled;
        stats.work_items = list.stats.items;
    }
    for (t, hits) in &counters {
        stats.hits += hits;
        stats.shadow_rays += t.shadow_rays;
        stats.bound_evaluations += t.cast.bound_evaluations;
        stats.point_evaluations += t.cast.point_evaluations;
        stats.closed_form_casts += t.cast.closed_form_casts;
        stats.terrain_rays += t.terrain_rays;
        stats.terrain_segments += t.terrain.segments;
        stats.terrain_cells += t.terrain.cells;
        stats.terrain_stops += t.terrain.stops;
        stats.terrain_stop_levels += t.terrain.stop_levels_above_finest;
        stats.media_interpolated += t.media_interpolated;
        stats.media_exact += t.media_exact;
        stats.cloud_samples += t.cloud_samples;
        stats.mesh_rays += t.mesh_rays;
        stats.mesh_tile_rays += t.mesh_tile_rays;
        stats.mesh_shadow_tile_rays += t.mesh_shadow_tile_rays;
        stats.secondary_rays += t.secondary_rays;
    }
    if list.is_some() {
        stats.passes.push("quadtree".into());
    }
    stats.passes.push("primary".into());
    if settings.samples.count() > 1 {
        stats
            .passes
            .push(format!("{} samples per pixel", settings.samples.count()));
    }
    if stats.closed_form_casts > 0 {
        stats.passes.push("closed-form".into());
    }
    stats
        .passes
        .extend(scene.features.names().iter().map(|s| s.to_string()));
    if !(settings.shadows && scene.features.shadows) {
        stats.passes.retain(|p| p != "shadows");
    }
    if let Some(grid) = integrator.media_grid() {
        stats.passes.push(format!(
            "media grid every {} px ({} nodes)",
            grid.spacing(),
            grid.len()
        ));
    }
    if !settings.shading {
        // Visibility only: no light was evaluated.
        stats.passes.retain(|p| {
            !matches!(
                p.as_str(),
                "shadows" | "sun" | "point-lights" | "fog" | "sky" | "clouds"
            )
        });
    }
    stats.elapsed = start.elapsed();
    frame.stats = stats;
    Ok(())
}

/// For each band of `rows` image rows, the tiles that overlap it.
fn tiles_by_band(tiles: &[Tile], height: u32, rows: u32) -> Vec<Vec<u32>> {
    let mut bands: Vec<Vec<u32>> = vec![Vec::new(); height.div_ceil(rows) as usize];
    for (k, t) in tiles.iter().enumerate() {
        let (_, y0, _, y1) = t.rect;
        if y1 <= y0 {
            continue;
        }
        for band in (y0 / rows)..=((y1 - 1) / rows) {
            if let Some(b) = bands.get_mut(band as usize) {
                b.push(k as u32);
            }
        }
    }
    bands
}

/// Work item `k`'s candidates with their active sets, into the front of `out` (whose sets are
/// reused, so their buffers are too); returns how many.
pub(crate) fn active_sets(
    scene: &Scene,
    list: &WorkList,
    k: usize,
    out: &mut Vec<(PrimitiveId, ActiveSet)>,
) -> usize {
    let mut n = 0;
    for c in list.candidates_of(&list.items[k]) {
        let Some(id) = PrimitiveId::of_candidate(c) else {
            continue;
        };
        if out.len() <= n {
            out.push((id, ActiveSet::new()));
        }
        let (slot, active) = &mut out[n];
        *slot = id;
        // Only free forms have active subsets.
        if id.kind == PrimitiveKind::FreeForm
            && let Some(o) = scene.objects.get(id.index as usize)
        {
            active.set(
                &o.solid,
                c.leaves(&list.leaves),
                c.perturbations(&list.perturbations),
            );
        }
        n += 1;
    }
    n
}

/// A rectangle of pixels `[x0, x1) × [y0, y1)` and its work item, if culled.
pub(crate) struct Tile {
    pub(crate) rect: (u32, u32, u32, u32),
    pub(crate) item: Option<usize>,
}

/// Refuses what no frame can be made of: a bad epsilon, an empty image, tiles of no size, more
/// threads than the machine allows.
pub(crate) fn check_frame(scene: &Scene, settings: &TraceSettings) -> Result<(), TraceError> {
    if !(settings.epsilon.is_finite() && settings.epsilon > 0.0) {
        return Err(TraceError::BadEpsilon(settings.epsilon));
    }
    if scene.width == 0 || scene.height == 0 {
        return Err(TraceError::EmptyImage(scene.width, scene.height));
    }
    if settings.tile_size == 0 {
        return Err(TraceError::BadTileSize);
    }
    crate::settings::check_threads(settings.threads)
}

/// The frame loop's tiles: with culling the quadtree's work items (bundles over `coverage` of
/// each pixel) and the list they index, else a plain grid of `tile_size` squares.
pub(crate) fn frame_tiles(
    scene: &Scene,
    settings: &TraceSettings,
    coverage: PixelCoverage,
    pool: &rayon::ThreadPool,
) -> Result<(Vec<Tile>, Option<WorkList>), TraceError> {
    let (width, height, ts) = (scene.width, scene.height, settings.tile_size);
    let (tiles, list): (Vec<Tile>, _) = if settings.culling {
        let config = QuadtreeConfig {
            cell_size: ts,
            memory_budget: scene.budget.clone(),
            coverage,
        };
        let list = pool.install(|| work_list_within(scene, &config))?;
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
    Ok((tiles, list))
}

/// Renders the pixels of `rect` into `out`: with culling, `listed` is how many of
/// `scratch.candidates` are the tile's candidates; `None` tests every primitive.
fn render_tile(
    scene: &Scene,
    settings: &TraceSettings,
    integrator: &Integrator<'_>,
    scratch: &mut Scratch,
    (x0, y0, x1, y1): (u32, u32, u32, u32),
    listed: Option<usize>,
    out: &mut BandImages<'_>,
) {
    let Scratch {
        ctx,
        hits_found,
        candidates,
        hits,
        mesh_shadows,
    } = scratch;
    let candidates = listed.map(|n| &candidates[..n]);
    let footprint = scene.camera.pixel_footprint(scene.width, scene.height);
    // In passes: every pixel's camera ray, the hits, their surfaces, then (with culling) the
    // free forms the tile's shadow rays can meet, then (with meshes) the shadow rays against the
    // meshes as packets, then the shading. The camera rays get a pass
    // of their own so that the casts read them from the cache, not from stores still in flight
    // (3-float vectors stored and reloaded in other widths stall store forwarding).
    // With anti-aliasing each pixel casts its centre (depth and normal) and then its samples
    // (colour): `per_pixel` rays in a row.
    let samples = settings.samples;
    let per_pixel = rays_per_pixel(samples);
    hits.clear();
    if per_pixel == 1 {
        for py in y0..y1 {
            for px in x0..x1 {
                let camera_ray = scene.camera.pixel_ray(px, py, scene.width, scene.height);
                hits.push((camera_ray, None));
            }
        }
    } else {
        push_sampled_rays(scene, samples, (x0, y0, x1, y1), hits);
    }
    let shape = TileShape {
        width: x1 - x0,
        rays_per_pixel: per_pixel as u32,
    };
    nearest_hits_deferred(
        scene,
        ctx,
        hits,
        shape,
        settings.epsilon,
        candidates,
        footprint,
    );
    for (camera_ray, hit) in hits.iter_mut() {
        if let (Some(c), Some(h)) = (camera_ray, hit) {
            complete_surface(scene, &c.ray, candidates, h);
        }
    }
    let shading = settings.shading;
    let occluders = if integrator.shadows() && settings.culling && !scene.lights.is_empty() {
        // The interactions again (cheap, and only here): storing them for every pixel would
        // cost the visibility-only frame more than recomputing costs the shaded one.
        let mut reach = 0.0f64;
        // The rays that are shaded: every one without anti-aliasing, else the samples.
        let shaded = hits
            .iter()
            .enumerate()
            .filter(|(k, _)| per_pixel == 1 || k % per_pixel != 0);
        let origins = shadow_cull::bounding_box(shaded.filter_map(|(_, (c, hit))| {
            let (c, hit) = (c.as_ref()?, hit.as_ref()?);
            let p = c.ray.at(hit.hit.t);
            let n = shading_normal(scene, &c.ray, c.t_near, hit);
            let n = if n.dot(-c.ray.dir) < 0.0 { -n } else { n };
            let offset = integrator.shadow_offset_at(p);
            reach = reach.max(offset);
            Some(p + n * offset)
        }));
        Some(shadow_cull::occluders(scene, origins, reach))
    } else {
        None
    };
    // The shadow rays against the meshes as packets, where they go so (`None`: ray by ray).
    let batched = if shading && MeshShadows::applies(scene, integrator, hits.len()) {
        ctx.mesh.packet_order(shape, hits.len());
        let (order, counts) = (&ctx.mesh.order, &mut ctx.counts);
        mesh_shadows.cast(scene, integrator, hits, per_pixel, order, counts);
        Some(&*mesh_shadows)
    } else {
        None
    };
    if per_pixel > 1 {
        write_sampled_pixels(
            scene,
            settings,
            integrator,
            ctx,
            hits,
            occluders.as_deref(),
            batched,
            (x0, y0, x1, y1),
            out,
            hits_found,
        );
        return;
    }
    let w = (x1 - x0) as usize;
    for (row, py) in (y0..y1).enumerate() {
        let at = (py - out.y0) as usize * out.width as usize + x0 as usize;
        let pixels = hits[row * w..(row + 1) * w].iter();
        let colour = out.colour[at..at + w].iter_mut();
        let depth = out.depth[at..at + w].iter_mut();
        let normals = out.normals[at..at + w].iter_mut();
        let columns = x0..x1;
        for (column, (((((camera_ray, hit), c), d), nrm), px)) in pixels
            .zip(colour)
            .zip(depth)
            .zip(normals)
            .zip(columns)
            .enumerate()
        {
            let (Some(camera_ray), Some(hit)) = (camera_ray, hit) else {
                continue;
            };
            // The surfaces are complete: no active subsets needed.
            let (t, n) = if shading {
                let ray = &camera_ray.ray;
                let k = row * w + column;
                let (si, surface) = shade_camera_hit(
                    scene,
                    integrator,
                    ctx,
                    camera_ray,
                    hit,
                    occluders.as_deref(),
                    batched.map(|b| (b, k)),
                );
                let range = Interval::new(camera_ray.t_near, si.t);
                let at = (f64::from(px) + 0.5, f64::from(py) + 0.5);
                *c = integrator
                    .camera_through_media(ctx, at, ray, range, surface)
                    .as_vec3();
                (si.t, si.shading_normal.as_vec3())
            } else {
                // Visibility only: the normal as a colour.
                let n = shading_normal(scene, &camera_ray.ray, camera_ray.t_near, hit).as_vec3();
                *c = Vec3::splat(0.5) + 0.5 * n;
                (hit.hit.t, n)
            };
            (*d, *nrm) = (t, n);
            if t.is_finite() {
                *hits_found += 1;
            }
        }
    }
}

/// The colour of every pixel of the band from row `y0` that no tile wrote (still NaN: culled, or
/// a centre ray that missed), as its rays hitting nothing give it: the background through the
/// media — the centre ray's, or the samples' box-filtered, in the same order and arithmetic as a
/// tile's misses.
#[cold]
fn fill_misses(
    scene: &Scene,
    settings: &TraceSettings,
    integrator: &Integrator<'_>,
    ctx: &mut TraceContext,
    y0: u32,
    colour: &mut [Rgb],
) {
    let (width, height) = (scene.width, scene.height);
    let background = scene.background.as_dvec3();
    let mut miss = |ray: Option<CameraRay>, at: (f64, f64)| match ray {
        Some(c) => integrator.camera_miss(ctx, at, &c.ray, c.t_near),
        None => background,
    };
    for (k, c) in colour.iter_mut().enumerate() {
        let (px, py) = ((k as u32) % width, y0 + (k as u32) / width);
        if py >= height {
            break;
        }
        if !c.x.is_nan() {
            continue;
        }
        let samples = settings.samples;
        *c = if samples.count() == 1 {
            let centre = (f64::from(px) + 0.5, f64::from(py) + 0.5);
            miss(scene.camera.pixel_ray(px, py, width, height), centre).as_vec3()
        } else {
            let mut sum = glam::DVec3::ZERO;
            for s in 0..samples.count() {
                let q = samples.sample(px, py, s);
                let (x, y) = (f64::from(px) + q.dx, f64::from(py) + q.dy);
                sum += q.weight * miss(scene.camera.ray(x, y, width, height), (x, y));
            }
            sum.as_vec3()
        };
    }
}

/// Camera rays per pixel: the centre alone, or the centre and `N` samples.
fn rays_per_pixel(samples: fray_core::PixelSamples) -> usize {
    if samples.count() == 1 {
        1
    } else {
        1 + samples.count() as usize
    }
}

/// Each pixel's camera rays with anti-aliasing: its centre, then its samples.
#[cold]
fn push_sampled_rays(
    scene: &Scene,
    samples: fray_core::PixelSamples,
    (x0, y0, x1, y1): (u32, u32, u32, u32),
    hits: &mut Vec<(Option<CameraRay>, Option<SceneHit>)>,
) {
    for py in y0..y1 {
        for px in x0..x1 {
            hits.push((
                scene.camera.pixel_ray(px, py, scene.width, scene.height),
                None,
            ));
            for k in 0..samples.count() {
                let q = samples.sample(px, py, k);
                let (x, y) = (f64::from(px) + q.dx, f64::from(py) + q.dy);
                hits.push((scene.camera.ray(x, y, scene.width, scene.height), None));
            }
        }
    }
}

/// The pixels of an anti-aliased tile (`hits`: per pixel the centre ray, then its samples):
/// depth and normal from the centre, colour the samples' box-filtered radiance (the background
/// where a sample hits nothing).
#[allow(clippy::too_many_arguments)]
fn write_sampled_pixels(
    scene: &Scene,
    settings: &TraceSettings,
    integrator: &Integrator<'_>,
    ctx: &mut TraceContext,
    hits: &[(Option<CameraRay>, Option<SceneHit>)],
    occluders: Option<&[Vec<u32>]>,
    batched: Option<&MeshShadows>,
    (x0, y0, x1, y1): (u32, u32, u32, u32),
    out: &mut BandImages<'_>,
    hits_found: &mut u64,
) {
    let samples = settings.samples;
    let per_pixel = rays_per_pixel(samples);
    let background = scene.background.as_dvec3();
    let w = (x1 - x0) as usize;
    for (row, py) in (y0..y1).enumerate() {
        for (column, px) in (x0..x1).enumerate() {
            let rays = &hits[(row * w + column) * per_pixel..][..per_pixel];
            let at = (py - out.y0) as usize * out.width as usize + px as usize;
            let mut colour = glam::DVec3::ZERO;
            let first = (row * w + column) * per_pixel;
            for (k, (camera_ray, hit)) in rays[1..].iter().enumerate() {
                let q = samples.sample(px, py, k as u32);
                let (weight, point) = (q.weight, (f64::from(px) + q.dx, f64::from(py) + q.dy));
                let radiance = match (camera_ray, hit) {
                    (Some(c), Some(hit)) if settings.shading => {
                        let slot = batched.map(|b| (b, first + 1 + k));
                        let (si, surface) =
                            shade_camera_hit(scene, integrator, ctx, c, hit, occluders, slot);
                        let range = Interval::new(c.t_near, si.t);
                        integrator.camera_through_media(ctx, point, &c.ray, range, surface)
                    }
                    (Some(c), Some(hit)) => {
                        let si = interaction(scene, &c.ray, c.t_near, hit, None);
                        glam::DVec3::splat(0.5) + 0.5 * si.shading_normal
                    }
                    (Some(c), None) => integrator.camera_miss(ctx, point, &c.ray, c.t_near),
                    (None, _) => background,
                };
                colour += weight * radiance;
            }
            out.colour[at] = colour.as_vec3();
            if let (Some(c), Some(hit)) = &rays[0] {
                let si = interaction(scene, &c.ray, c.t_near, hit, None);
                out.depth[at] = si.t;
                out.normals[at] = si.shading_normal.as_vec3();
                *hits_found += 1;
            }
        }
    }
}

/// A camera hit's surface and the radiance leaving it toward the camera: from the tile's
/// batch (its surface, its shadow rays' mesh answers) where `batched` gives its slot in it.
fn shade_camera_hit(
    scene: &Scene,
    integrator: &Integrator<'_>,
    ctx: &mut TraceContext,
    camera_ray: &CameraRay,
    hit: &SceneHit,
    occluders: Option<&[Vec<u32>]>,
    batched: Option<(&MeshShadows, usize)>,
) -> (crate::SurfaceInteraction, glam::DVec3) {
    let wo = -camera_ray.ray.dir;
    if let Some((b, k)) = batched
        && let Some(si) = b.surface(k)
    {
        let surface =
            integrator.surface_radiance_mesh_shadowed(ctx, si, wo, occluders, b.blocked(k));
        return (*si, surface);
    }
    let si = interaction(scene, &camera_ray.ray, camera_ray.t_near, hit, None);
    let surface = integrator.surface_radiance(ctx, &si, wo, occluders);
    (si, surface)
}
