//! The scene stays on the GPU: a second frame builds no pipeline and uploads no scene, a moved
//! camera rebases the resident scene on the GPU (bit for bit the CPU twin's), frames repeat bit
//! for bit, several bands agree with one, the display image is the CPU's tone map of the frame,
//! and anti-aliased frames match the CPU's. Ignored without an adapter; a failure under
//! `FRAY_REQUIRE_GPU=1`.

mod common;

use fray_core::PixelSamples;
use fray_gpu::{GpuSettings, View};
use fray_scene::Scene;
use std::path::Path;

fn data_scene(name: &str, width: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/scenes")
        .join(name);
    let mut s = fray_scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    s.height = (u64::from(s.height) * u64::from(width) / u64::from(s.width)).max(1) as u32;
    s.width = width;
    s
}

/// The scene's pinhole camera moved by `offset` (and looking at the same point).
fn moved(scene: &Scene, offset: glam::DVec3) -> fray_core::Projector {
    let fray_core::Projector::Pinhole(p) = scene.camera else {
        panic!("a pinhole scene");
    };
    let target = p.eye + p.basis.forward * 8.0;
    let fov = 2.0 * p.tan_half_fov_y.atan();
    fray_core::Projector::Pinhole(
        fray_core::Pinhole::new(p.eye + offset, target, glam::DVec3::Y, fov, p.near).unwrap(),
    )
}

fn bits(frame: &fray_core::Frame) -> (Vec<u32>, Vec<u64>, Vec<u32>) {
    (
        frame
            .colour
            .pixels()
            .iter()
            .flat_map(|c| c.to_array().map(f32::to_bits))
            .collect(),
        frame.depth.pixels().iter().map(|d| d.to_bits()).collect(),
        frame
            .normals
            .pixels()
            .iter()
            .flat_map(|n| n.to_array().map(f32::to_bits))
            .collect(),
    )
}

/// The second frame of a resident scene builds no pipeline and uploads no scene (only its
/// parameters and work list), from the same camera or a moved one, and is faster than the
/// first; the same view renders the same bits again.
fn a_second_frame_builds_no_pipeline_and_uploads_no_scene() {
    let gpu = common::gpu("a_second_frame_builds_no_pipeline_and_uploads_no_scene");
    for name in ["csg.ron", "terrain_low.ron"] {
        let scene = data_scene(name, 96);
        let settings = GpuSettings::for_scene(&scene);
        let mut resident = gpu.upload(&scene, &settings).unwrap();
        let view = View::of_scene(&scene, settings.samples);
        let first = resident.render(&view).unwrap();
        assert!(first.stats.scene_uploaded_bytes > 0, "{name}");
        assert!(
            first.stats.uploaded_bytes > first.stats.scene_uploaded_bytes,
            "{name}"
        );
        let again = resident.render(&view).unwrap();
        assert_eq!(
            bits(&first),
            bits(&again),
            "{name}: the same view, other bits"
        );
        assert_eq!(
            (
                first.stats.hits,
                first.stats.bound_evaluations,
                first.stats.point_evaluations
            ),
            (
                again.stats.hits,
                again.stats.bound_evaluations,
                again.stats.point_evaluations
            ),
            "{name}: stale counters"
        );
        // The passes' GPU time exists exactly when the device has timestamp queries (or is a
        // software adapter, timed by the host's clock), lies within the frame's wall time, and
        // is the sum of the per-pass table, which names every pass the frame ran, in order.
        let ctx = gpu.context();
        let timed = ctx.timestamp_period_ns.is_some() || ctx.software;
        assert_eq!(again.stats.kernel_time.is_some(), timed, "{name}");
        if let Some(k) = again.stats.kernel_time {
            assert!(
                k > std::time::Duration::ZERO && k <= again.stats.elapsed,
                "{name}: {k:?}"
            );
            let sum: std::time::Duration = again.stats.pass_times.iter().map(|(_, d)| *d).sum();
            assert_eq!(sum, k, "{name}: the passes' sum");
            let labels: Vec<&str> = again
                .stats
                .pass_times
                .iter()
                .map(|(l, _)| l.as_str())
                .collect();
            assert_eq!(labels.first(), Some(&"raygen"), "{name}: {labels:?}");
            assert_eq!(labels.last(), Some(&"resolve"), "{name}: {labels:?}");
            assert!(labels.contains(&"shade"), "{name}: {labels:?}");
            let kinds = [
                ("free forms", !scene.objects.is_empty()),
                ("terrains", !scene.terrains.is_empty()),
            ];
            for (label, present) in kinds {
                assert_eq!(labels.contains(&label), present, "{name}: {labels:?}");
            }
        } else {
            assert!(again.stats.pass_times.is_empty(), "{name}");
        }
        // The host's part (work list, writes, encoding, submissions) is measured and leaves out
        // at least the readback that follows the last submission.
        let encode = again.stats.encode_time;
        assert!(
            encode > std::time::Duration::ZERO && encode < again.stats.elapsed,
            "{name}: encode {encode:?} of {:?}",
            again.stats.elapsed
        );
        if let (true, Some(k)) = (ctx.software, again.stats.kernel_time) {
            // The host clock's passes (submission and wait) are counted once, in the passes.
            assert!(
                encode + k <= again.stats.elapsed,
                "{name}: encode {encode:?} + kernels {k:?} > frame {:?}",
                again.stats.elapsed
            );
        }
        let mut view2 = view;
        view2.camera = moved(&scene, glam::DVec3::new(0.4, 0.2, -0.3));
        let second = resident.render(&view2).unwrap();
        assert_eq!(second.stats.pipelines_built, 0, "{name}");
        assert_eq!(second.stats.scene_uploaded_bytes, 0, "{name}");
        assert!(
            second.stats.uploaded_bytes > 0,
            "{name}: the camera and the work list"
        );
        assert!(
            second.stats.uploaded_bytes < first.stats.scene_uploaded_bytes / 2 || name == "csg.ron",
            "{name}: {} bytes per frame vs {} for the scene",
            second.stats.uploaded_bytes,
            first.stats.scene_uploaded_bytes
        );
        assert_ne!(bits(&first).1, bits(&second).1, "{name}: the camera moved");
        assert!(second.stats.hits > 0, "{name}");
        eprintln!(
            "{name}: first frame {:.1} ms ({} pipelines, {:.1} ms to build; {} bytes uploaded, {} of them the scene), moved camera {:.1} ms ({} bytes uploaded)",
            first.stats.elapsed.as_secs_f64() * 1e3,
            first.stats.pipelines_built,
            first.stats.pipeline_build_time.as_secs_f64() * 1e3,
            first.stats.uploaded_bytes,
            first.stats.scene_uploaded_bytes,
            second.stats.elapsed.as_secs_f64() * 1e3,
            second.stats.uploaded_bytes
        );
        // A moved camera's frame equals a fresh upload anchored at the moved camera, up to the
        // rebase's f32 rounding: the same hits, depth within the parity bound.
        let mut at_moved = scene.clone();
        at_moved.camera = view2.camera;
        let fresh = gpu.render(&at_moved, &settings).unwrap();
        let (flips, worst) = depth_differences(&second, &fresh);
        let pixels = second.depth.pixels().len();
        assert!(flips * 200 <= pixels, "{name}: {flips} hit/miss flips");
        assert!(worst < 1e-4, "{name}: relative depth difference {worst:e}");
    }
}

/// A frame taller than one band (1024 × 2100 rays exceed the 64 MiB band limit) equals, bit for
/// bit, the frame in a single band of a device with a higher limit would — checked here as: the
/// top and the bottom bands both hold hits, culling on and off agree, and a second frame is the
/// same.
fn several_bands_render_like_one() {
    let gpu = common::gpu("several_bands_render_like_one");
    let scene = fray_scene::parse(
        r#"Scene(
            image: (width: 1024, height: 2100),
            camera: Pinhole(eye: (0, 0, -6), look_at: (0, 0, 0), fov_y: 40),
            lights: [Sun(direction: (1, 2, -1), irradiance: (3, 3, 3))],
            objects: [(shape: Ellipsoid(center: (0, 0, 0), radii: (0.6, 3.0, 0.6)))],
        )"#,
        "two_bands.ron",
    )
    .unwrap();
    let on = gpu.render(&scene, &GpuSettings::for_scene(&scene)).unwrap();
    let settings = GpuSettings {
        culling: false,
        ..GpuSettings::for_scene(&scene)
    };
    let mut resident = gpu.upload(&scene, &settings).unwrap();
    let view = View::of_scene(&scene, settings.samples);
    let off = resident.render(&view).unwrap();
    let again = resident.render(&view).unwrap();
    assert_eq!(bits(&on), bits(&off));
    assert_eq!(bits(&off), bits(&again));
    let row_hits = |y: u32| (0..scene.width).any(|x| on.depth.get(x, y).is_finite());
    assert!(
        row_hits(20) && row_hits(2080),
        "hits in the first and the last band"
    );
    assert_eq!(on.stats.hits, off.stats.hits);
}

/// The display image the resolve pass tone maps on the GPU is the CPU's tone map and sRGB
/// encoding of the frame's linear colour, to one code value.
fn the_display_image_is_the_frames_tone_map() {
    let gpu = common::gpu("the_display_image_is_the_frames_tone_map");
    let scene = data_scene("turboprop.ron", 96);
    let settings = GpuSettings::for_scene(&scene);
    let mut resident = gpu.upload(&scene, &settings).unwrap();
    for (tone_map, exposure) in [
        (fray_core::ToneMap::Clamp, 1.0),
        (fray_core::ToneMap::Reinhard, 2.5),
    ] {
        let view = View {
            tone_map,
            exposure,
            ..View::of_scene(&scene, settings.samples)
        };
        let frame = resident.render(&view).unwrap();
        let display = resident.display_image().unwrap();
        let cpu = fray_render_like_srgb8(&frame, tone_map, exposure);
        let worst = display
            .pixels()
            .iter()
            .zip(cpu.pixels())
            .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)))
            .max()
            .unwrap_or(0);
        assert!(worst <= 1, "{tone_map:?}: {worst} code values apart");
    }
}

/// A frame left on the device (`render_display`, a viewer's loop) is the frame `render` reads
/// back: the same display texture and the same counters, from a camera that moved in between.
fn a_frame_left_on_the_device_is_the_rendered_frame() {
    let gpu = common::gpu("a_frame_left_on_the_device_is_the_rendered_frame");
    let scene = data_scene("turboprop.ron", 96);
    let settings = GpuSettings::for_scene(&scene);
    let mut resident = gpu.upload(&scene, &settings).unwrap();
    let first = View::of_scene(&scene, settings.samples);
    resident.render(&first).unwrap();
    let before = resident.display_image().unwrap();
    let mut view = first;
    view.camera = moved(&scene, glam::DVec3::new(0.5, 0.25, -0.75));
    let (stats, textures) = resident.render_display(&view).unwrap();
    assert_eq!(
        (textures.display.width(), textures.display.height()),
        (view.width, view.height)
    );
    let left = resident.display_image().unwrap();
    let frame = resident.render(&view).unwrap();
    let read = resident.display_image().unwrap();
    assert_ne!(before.pixels(), left.pixels(), "the moved camera's frame");
    assert_eq!(left.pixels(), read.pixels());
    assert_eq!(stats.hits, frame.stats.hits);
    assert_eq!(stats.primary_rays, frame.stats.primary_rays);
    assert!(stats.hits > 0);
}

/// `fray_render::output::srgb8` without depending on fray-render: tone map, sRGB, round.
fn fray_render_like_srgb8(
    frame: &fray_core::Frame,
    tone_map: fray_core::ToneMap,
    exposure: f32,
) -> fray_core::Image<[u8; 3]> {
    frame.colour.map(|c| {
        c.to_array()
            .map(|v| (fray_core::linear_to_srgb(tone_map.apply(v, exposure)) * 255.0).round() as u8)
    })
}

/// The rebase pass moves the resident scene bit for bit as its CPU twin does.
fn the_rebase_pass_is_its_cpu_twin() {
    let gpu = common::gpu("the_rebase_pass_is_its_cpu_twin");
    let scene = data_scene("turboprop.ron", 32);
    let settings = GpuSettings::for_scene(&scene);
    let mut resident = gpu.upload(&scene, &settings).unwrap();
    let mut view = View::of_scene(&scene, settings.samples);
    view.camera = moved(&scene, glam::DVec3::new(123.456, -7.25, 1.0e3 / 3.0));
    resident.render(&view).unwrap();
    let checked = resident.check_rebase_against_cpu().unwrap();
    assert!(checked > 100, "{checked} slots");
}

/// Anti-aliasing on the GPU: the same strata and jitter as the CPU, so the frames agree within
/// the parity bounds: depth and normals from the centre (equal to the unsampled frame's), colour
/// close to the CPU's.
fn anti_aliased_frames_match_the_cpu() {
    let gpu = common::gpu("anti_aliased_frames_match_the_cpu");
    let mut scene = data_scene("csg.ron", 80);
    scene.settings.samples = PixelSamples::new(4).unwrap();
    let settings = GpuSettings::for_scene(&scene);
    let frame = gpu.render(&scene, &settings).unwrap();
    assert_eq!(
        frame.stats.primary_rays,
        u64::from(scene.width * scene.height) * 5
    );
    let plain = gpu
        .render(
            &scene,
            &GpuSettings {
                samples: PixelSamples::ONE,
                ..settings
            },
        )
        .unwrap();
    assert_eq!(bits(&frame).1, bits(&plain).1, "depth from the centre ray");
    assert_eq!(
        bits(&frame).2,
        bits(&plain).2,
        "normals from the centre ray"
    );
    let cpu =
        fray_trace::render(&scene, &fray_trace::TraceSettings::for_scene(&scene), None).unwrap();
    let (mut far, mut total) = (0usize, 0usize);
    for (g, c) in frame.colour.pixels().iter().zip(cpu.colour.pixels()) {
        total += 1;
        if (*g - *c).abs().max_element() > 0.02 + 0.02 * c.max_element() {
            far += 1;
        }
    }
    // Silhouette and shadow-terminator samples may flip in f32; at most 2 % of pixels.
    assert!(
        far * 50 <= total,
        "{far} of {total} pixels differ from the CPU's"
    );
}

/// What grows with the input is refused before it is made: a frame whose host images exceed the
/// memory budget (16384² needs 16 GiB through the GPU path), a scene whose largest solid needs
/// more per-invocation private memory than the GPU backend allows, an image side past the
/// device's texture limit — each a clear error (`auto` renders such scenes on the CPU).
fn oversized_frames_and_scenes_are_refused_with_clear_errors() {
    let gpu = common::gpu("oversized_frames_and_scenes_are_refused_with_clear_errors");
    let mut scene = data_scene("csg.ron", 64);
    scene.budget = fray_core::MemoryBudget::new(4 << 30);
    let settings = GpuSettings::for_scene(&scene);
    let mut resident = gpu.upload(&scene, &settings).unwrap();
    let mut view = View::of_scene(&scene, settings.samples);
    (view.width, view.height) = (16384, 16384);
    let e = resident.render(&view).unwrap_err();
    let fray_gpu::GpuError::Budget(b) = &e else {
        panic!("expected a budget error, got {e}");
    };
    assert_eq!(b.needed, 16384 * 16384 * fray_gpu::HOST_BYTES_PER_PIXEL);
    assert!(
        e.to_string().contains("GPU frame's readback and images"),
        "{e}"
    );
    // Past the texture limit (within the budget): refused, naming the limit.
    let side = gpu.context().limits.max_texture_dimension_2d + 1;
    let mut wide = View::of_scene(&scene, settings.samples);
    (wide.width, wide.height) = (side, 1);
    let e = resident.render(&wide).unwrap_err();
    assert!(matches!(e, fray_gpu::GpuError::TooLarge { .. }), "{e}");
    // A solid of 2000 perturbations needs 32 KiB of private memory per invocation.
    let mut perturbations = String::new();
    for k in 0..2000 {
        let x = -1.0 + 2.0 * f64::from(k) / 2000.0;
        perturbations.push_str(&format!(
            "(form_factor: 0.1, quadric: Sphere(center: ({x}, 1, 0), radius: 0.05)),"
        ));
    }
    let big = fray_scene::parse(
        &format!(
            "Scene(camera: Pinhole(eye: (0, 0, -5), look_at: (0, 0, 0)), \
             objects: [(shape: FreeForm(base: Sphere(center: (0, 0, 0), radius: 1), \
                                        perturbations: [{perturbations}]))])"
        ),
        "big.ron",
    )
    .unwrap();
    let e = gpu.upload(&big, &GpuSettings::for_scene(&big)).unwrap_err();
    match &e {
        fray_gpu::GpuError::TooLarge {
            what,
            needed,
            limit,
        } => {
            assert!(what.contains("private memory") && needed > limit, "{e}");
        }
        other => panic!("expected TooLarge, got {other}"),
    }
}

/// Every resident buffer and texture is charged to the render's budget before it is allocated:
/// what the device's allocator reports for an upload is what was charged (within its alignment
/// padding), and a scene one byte past its budget is refused — naming the array that did not fit —
/// with its earlier charges released.
fn resident_buffers_are_charged_before_they_are_allocated() {
    let gpu = common::gpu("resident_buffers_are_charged_before_they_are_allocated");
    let device = &gpu.context().device;
    let allocated = || {
        device
            .generate_allocator_report()
            .map(|r| r.total_allocated_bytes)
    };
    // Free forms, a terrain and fog; clouds; meshes with textures; the sky.
    for name in [
        "terrain_low.ron",
        "clouds_aircraft_inside.ron",
        "whitted_glass_mirror.ron",
        "sunset.ron",
    ] {
        let mut scene = data_scene(name, 32);
        let settings = GpuSettings::for_scene(&scene);
        // The scene's host arrays stay charged as they were.
        let host = scene.budget.charged();
        let before = allocated();
        let resident = gpu.upload(&scene, &settings).unwrap();
        let charged = resident.resident_device_bytes();
        assert_eq!(scene.budget.charged() - host, charged, "{name}");
        if let (Some(before), Some(after)) = (before, allocated()) {
            // The frame's own buffers (16-byte placeholders until a frame sizes them) and
            // alignment padding come on top of the resident ones; nothing large may.
            let grew = after.saturating_sub(before);
            eprintln!("{name}: charged {charged} bytes, the allocator grew by {grew}");
            assert!(
                grew <= charged + charged / 8 + (1 << 20),
                "{name}: {grew} bytes allocated for {charged} charged"
            );
        }
        drop(resident);
        assert_eq!(scene.budget.charged(), host, "{name}");
        // A fresh account (the host arrays are not on it) one byte short, half, and nothing.
        for limit in [charged - 1, charged / 2, 1] {
            scene.budget = fray_core::MemoryBudget::new(limit);
            let e = gpu.upload(&scene, &settings).map(|_| ()).unwrap_err();
            assert!(
                matches!(&e, fray_gpu::GpuError::Budget(_)),
                "{name} at {limit} bytes: {e}"
            );
            assert_eq!(scene.budget.charged(), 0, "{name} at {limit} bytes");
            if limit == charged - 1 {
                eprintln!("{name}, {limit} bytes: {e}");
            }
        }
    }
}

/// The fog's heights are camera-relative and sent every frame: a resident fog scene seen from a
/// camera moved up out of the layer (and one moved back in) looks as a fresh upload at that
/// camera does — within the rebase's f32 rounding; a stale layer 25 m off would change almost
/// every pixel — builds no pipeline and uploads no scene.
fn a_moved_camera_sees_the_fog_from_where_it_is() {
    let gpu = common::gpu("a_moved_camera_sees_the_fog_from_where_it_is");
    let scene = fray_scene::parse(
        r#"Scene(
            image: (width: 64, height: 48),
            camera: Pinhole(eye: (0, 4, -60), look_at: (0, 3.5, 0), fov_y: 40, near: 0.1),
            background: (0.4, 0.5, 0.7),
            ambient: (0.1, 0.1, 0.12),
            lights: [Sun(direction: (0.3, 2.0, -0.6), irradiance: (3, 2.9, 2.7))],
            atmosphere: (fog: (base: -1, top: 20, extinction: 0.02, falloff: 12)),
            objects: [
                (shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                    bounds: (min: (-300, -1, -300), max: (300, 0, 300)))),
                (shape: Sphere(center: (5, 6, 10), radius: 5)),
            ],
        )"#,
        "fog.ron",
    )
    .unwrap();
    let settings = GpuSettings::for_scene(&scene);
    let mut resident = gpu.upload(&scene, &settings).unwrap();
    let view = View::of_scene(&scene, settings.samples);
    let first = resident.render(&view).unwrap();
    for offset in [
        glam::DVec3::new(0.0, 25.0, -10.0),
        glam::DVec3::new(3.0, 2.0, 5.0),
    ] {
        let moved_view = View {
            camera: moved(&scene, offset),
            ..view
        };
        let frame = resident.render(&moved_view).unwrap();
        assert_eq!(
            (
                frame.stats.pipelines_built,
                frame.stats.scene_uploaded_bytes
            ),
            (0, 0)
        );
        let mut at_moved = scene.clone();
        at_moved.camera = moved_view.camera;
        let fresh = gpu.render(&at_moved, &settings).unwrap();
        let (mut off, mut changed) = (0usize, 0usize);
        for ((a, b), c) in frame
            .colour
            .pixels()
            .iter()
            .zip(fresh.colour.pixels())
            .zip(first.colour.pixels())
        {
            off += usize::from((*a - *b).abs().max_element() > 1e-4);
            changed += usize::from((*a - *c).abs().max_element() > 1e-3);
        }
        let pixels = frame.colour.pixels().len();
        eprintln!("{offset}: {off} of {pixels} pixels off a fresh upload, {changed} changed");
        // Silhouette pixels may flip under the rebase's rounding.
        assert!(off * 50 <= pixels, "{offset}: {off} of {pixels} pixels");
        assert!(changed * 2 > pixels, "{offset}: the view barely changed");
    }
}

/// The sky stays resident too: its transmittance table is scene data (uploaded once), its
/// sky-view table depends only on the eye's height (written again only when that changes) and
/// its parameters are written per frame. A camera moved level (here 80 m sideways) uploads its
/// parameters and work list but no table; one moved up 300 m uploads the sky-view table of its
/// new height (192 × 108 texels of 16 bytes) and sees the sky as a fresh upload there does.
fn a_moved_camera_uploads_the_sky_view_table_only_for_a_new_height() {
    let gpu = common::gpu("a_moved_camera_uploads_the_sky_view_table_only_for_a_new_height");
    let scene = fray_scene::parse(
        r#"Scene(
            image: (width: 64, height: 48),
            camera: Pinhole(eye: (0, 20, 0), look_at: (1000, 60, 300), fov_y: 40, near: 0.1),
            lights: [Sun(direction: (0.93, 0.17, 0.3), irradiance: (20, 20, 20))],
            atmosphere: (sky: (haze: 2)),
            objects: [
                (shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                    bounds: (min: (-20000, -1, -20000), max: (20000, 0, 20000)))),
                (shape: Sphere(center: (3000, 300, 800), radius: 300)),
            ],
        )"#,
        "sky.ron",
    )
    .unwrap();
    let sky = scene.atmosphere.sky.as_ref().unwrap();
    let sizes = sky.sky.tables();
    let view_table = u64::from(sizes.sky_view_width) * u64::from(sizes.sky_view_height) * 16;
    let transmittance =
        u64::from(sizes.transmittance_width) * u64::from(sizes.transmittance_height) * 16;
    let settings = GpuSettings::for_scene(&scene);
    let mut resident = gpu.upload(&scene, &settings).unwrap();
    let view = View::of_scene(&scene, settings.samples);
    let first = resident.render(&view).unwrap();
    assert!(first.stats.scene_uploaded_bytes >= transmittance);
    assert!(first.stats.uploaded_bytes >= first.stats.scene_uploaded_bytes + view_table);
    let again = resident.render(&view).unwrap();
    assert_eq!(bits(&first), bits(&again), "the same view, other bits");
    // The camera moved by `offset`, looking the same way.
    let shifted = |offset: glam::DVec3| {
        let fray_core::Projector::Pinhole(p) = scene.camera else {
            panic!("a pinhole scene");
        };
        let fov = 2.0 * p.tan_half_fov_y.atan();
        let (eye, target) = (p.eye + offset, p.eye + offset + p.basis.forward * 8.0);
        let camera = fray_core::Pinhole::new(eye, target, glam::DVec3::Y, fov, p.near).unwrap();
        View {
            camera: fray_core::Projector::Pinhole(camera),
            ..view
        }
    };
    let level = shifted(glam::DVec3::new(60.0, 0.0, -50.0));
    let up = shifted(glam::DVec3::new(0.0, 300.0, 0.0));
    for (what, v, table) in [("level", level, false), ("up", up, true)] {
        let frame = resident.render(&v).unwrap();
        let stats = &frame.stats;
        eprintln!(
            "moved {what}: {} bytes uploaded (sky-view table {view_table}, transmittance {transmittance})",
            stats.uploaded_bytes
        );
        assert_eq!(
            (stats.pipelines_built, stats.scene_uploaded_bytes),
            (0, 0),
            "{what}"
        );
        assert_eq!(
            stats.uploaded_bytes >= view_table,
            table,
            "{what}: {stats:?}"
        );
        let mut at_moved = scene.clone();
        at_moved.camera = v.camera;
        let fresh = gpu.render(&at_moved, &settings).unwrap();
        let (mut off, mut misses) = (0usize, 0usize);
        for ((a, b), d) in frame
            .colour
            .pixels()
            .iter()
            .zip(fresh.colour.pixels())
            .zip(frame.depth.pixels())
        {
            off += usize::from((*a - *b).abs().max_element() > 1e-4 * a.max_element().max(1.0));
            misses += usize::from(!d.is_finite());
        }
        let pixels = frame.colour.pixels().len();
        eprintln!("moved {what}: {off} of {pixels} pixels off a fresh upload ({misses} sky)");
        assert!(misses > 0, "{what}: no sky in view");
        // Silhouette pixels may flip under the rebase's rounding.
        assert!(off * 50 <= pixels, "{what}: {off} of {pixels} pixels");
    }
}

/// Meshes stay resident too: a frame from a moved camera builds no pipeline, uploads no scene
/// bytes and, of the meshes, rewrites only their 64-byte instance blocks (the frame uploads
/// exactly `64 · (rebased arrays + instances)` bytes more than the same view again: the rebase
/// parameters and the blocks). With meshes and a sun alone — nothing rebased in f32 that the
/// image depends on — the moved frame equals a fresh upload at the moved camera bit for bit (the
/// blocks come from f64 relative to the camera either way); with a free form beside them, within
/// the rebase's rounding as above.
fn a_moved_camera_rewrites_only_the_mesh_instance_blocks() {
    let gpu = common::gpu("a_moved_camera_rewrites_only_the_mesh_instance_blocks");
    let meshes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes");
    let text = format!(
        r#"Scene(
            image: (width: 80, height: 56),
            camera: Pinhole(eye: (0.5, 1.4, -3.2), look_at: (0, 0.3, 0), fov_y: 40, near: 0.05),
            lights: [Sun(direction: (0.4, 1.0, -0.6), irradiance: (3, 3, 3))],
            objects: [
                (shape: Mesh(path: "{bunny}", transform: (translate: (-0.6, 0.5, 0)))),
                (shape: Mesh(path: "{bunny}", transform: (rotate: (0, 90, 0), translate: (0.6, 0.5, 0.3)),
                    smooth: false)),
                (shape: Mesh(path: "{boeing}", transform: (scale: (0.06, 0.06, 0.06), rotate: (-90, 0, 0)))),
            ],
        )"#,
        bunny = meshes.join("bunny00.obj").display(),
        boeing = meshes.join("boeing.obj").display(),
    );
    let meshes_alone = fray_scene::parse(&text, "meshes.ron").unwrap();
    let with_free_form = fray_scene::parse(
        &text.replace(
            "objects: [",
            "objects: [(shape: Sphere(center: (0, 1.2, -0.4), radius: 0.2)),",
        ),
        "meshes_and_a_sphere.ron",
    )
    .unwrap();
    let rebase_params = std::mem::size_of::<fray_gpu::passes::rebase::RebaseParams>() as u64;
    for (name, scene) in [
        ("meshes", meshes_alone),
        ("meshes and a sphere", with_free_form),
    ] {
        let settings = GpuSettings::for_scene(&scene);
        let mut resident = gpu.upload(&scene, &settings).unwrap();
        let view = View::of_scene(&scene, settings.samples);
        let first = resident.render(&view).unwrap();
        assert!(
            first.stats.scene_uploaded_bytes > 1 << 20,
            "{name}: the meshes"
        );
        let mut moved_view = view;
        moved_view.camera = moved(&scene, glam::DVec3::new(0.3, 0.15, -0.2));
        let second = resident.render(&moved_view).unwrap();
        let again = resident.render(&moved_view).unwrap();
        assert_eq!(
            (
                second.stats.pipelines_built,
                second.stats.scene_uploaded_bytes
            ),
            (0, 0),
            "{name}"
        );
        assert_eq!(bits(&second), bits(&again), "{name}");
        // Solids, leaves, perturbations and lights are rebased; the three instance blocks
        // rewritten.
        let instances = scene.meshes.len() as u64;
        assert_eq!(
            second.stats.uploaded_bytes - again.stats.uploaded_bytes,
            4 * rebase_params + 64 * instances,
            "{name}"
        );
        assert_ne!(bits(&first).1, bits(&second).1, "{name}: the camera moved");
        let mut at_moved = scene.clone();
        at_moved.camera = moved_view.camera;
        let fresh = gpu.render(&at_moved, &settings).unwrap();
        if scene.objects.is_empty() {
            assert_eq!(bits(&second), bits(&fresh), "{name}: a fresh upload");
        } else {
            let (flips, worst) = depth_differences(&second, &fresh);
            let pixels = second.depth.pixels().len();
            eprintln!("{name}: moved vs fresh: {flips} flips, depth within {worst:e}");
            assert!(flips * 200 <= pixels && worst < 1e-4, "{name}");
        }
        eprintln!(
            "{name}: scene {} bytes; moved camera {} bytes uploaded, {} mesh rays",
            first.stats.scene_uploaded_bytes, second.stats.uploaded_bytes, second.stats.mesh_rays
        );
    }
}

fn main() {
    common::run(
        &[
            (
                "oversized_frames_and_scenes_are_refused_with_clear_errors",
                oversized_frames_and_scenes_are_refused_with_clear_errors,
            ),
            (
                "resident_buffers_are_charged_before_they_are_allocated",
                resident_buffers_are_charged_before_they_are_allocated,
            ),
            (
                "a_second_frame_builds_no_pipeline_and_uploads_no_scene",
                a_second_frame_builds_no_pipeline_and_uploads_no_scene,
            ),
            (
                "several_bands_render_like_one",
                several_bands_render_like_one,
            ),
            (
                "the_display_image_is_the_frames_tone_map",
                the_display_image_is_the_frames_tone_map,
            ),
            (
                "a_frame_left_on_the_device_is_the_rendered_frame",
                a_frame_left_on_the_device_is_the_rendered_frame,
            ),
            (
                "the_rebase_pass_is_its_cpu_twin",
                the_rebase_pass_is_its_cpu_twin,
            ),
            (
                "anti_aliased_frames_match_the_cpu",
                anti_aliased_frames_match_the_cpu,
            ),
            (
                "a_moved_camera_sees_the_fog_from_where_it_is",
                a_moved_camera_sees_the_fog_from_where_it_is,
            ),
            (
                "a_moved_camera_uploads_the_sky_view_table_only_for_a_new_height",
                a_moved_camera_uploads_the_sky_view_table_only_for_a_new_height,
            ),
            (
                "a_moved_camera_rewrites_only_the_mesh_instance_blocks",
                a_moved_camera_rewrites_only_the_mesh_instance_blocks,
            ),
        ],
        &[],
    );
}

/// Hit/miss flips between `a` and `b`, and the largest relative depth difference where both
/// hit (relative to `b`).
fn depth_differences(a: &fray_core::Frame, b: &fray_core::Frame) -> (usize, f64) {
    let mut flips = 0;
    let mut worst = 0.0f64;
    for (a, b) in a.depth.pixels().iter().zip(b.depth.pixels()) {
        if a.is_finite() != b.is_finite() {
            flips += 1;
        } else if a.is_finite() {
            worst = worst.max((a - b).abs() / b.max(1e-9));
        }
    }
    (flips, worst)
}
