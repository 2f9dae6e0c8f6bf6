//! GPU errors that no error scope catches become values, never panics: wgpu's default handler
//! panics on an uncaptured validation error, so `GpuContext` installs its own and a pass that
//! finds one fails with a `GpuError` (which the facade turns into a CPU fallback under `auto`).
//! Ignored without an adapter; a failure under `FRAY_REQUIRE_GPU=1`.

mod common;

use fray_gpu::GpuContext;

/// A deliberately invalid buffer (mappable for reading *and* a storage buffer, which WebGPU
/// forbids) outside any error scope: the error is recorded, not raised, and taken exactly once.
fn uncaptured_validation_error_is_recorded_not_raised() {
    let renderer = common::gpu("uncaptured_validation_error_is_recorded_not_raised");
    let ctx: &GpuContext = renderer.context();
    assert_eq!(
        ctx.take_uncaptured_error(),
        None,
        "a fresh device has no error"
    );
    let _invalid = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("invalid on purpose"),
        size: 256,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let reason = ctx.take_uncaptured_error();
    assert!(
        reason.as_deref().is_some_and(|r| !r.is_empty()),
        "the validation error was not recorded: {reason:?}"
    );
    eprintln!(
        "recorded: {}",
        reason.unwrap_or_default().lines().next().unwrap_or("")
    );
    assert_eq!(ctx.take_uncaptured_error(), None, "taken once");
}

/// Every feature a scene can use is drawn by the GPU, so none is refused as `Unsupported`:
/// meshes, mirrors and glass (Whitted's queue passes), in fog too, and textured materials
/// (the texture sampling) all upload, specialised for what they use.
fn every_feature_uploads_none_is_refused() {
    let renderer = common::gpu("every_feature_uploads_none_is_refused");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes");
    let bunny = dir.join("bunny00.obj").display().to_string();
    let mesh = format!(
        "Scene(camera: Pinhole(eye: (0, 0, -3), look_at: (0, 0, 0)), \
         objects: [(shape: Mesh(path: {bunny:?}))])"
    );
    let mirror = "Scene(camera: Pinhole(eye: (0, 0, -3), look_at: (0, 0, 0)), \
         materials: { \"m\": (reflect: (1, 1, 1)) }, \
         objects: [(material: \"m\", shape: Sphere(radius: 1))])";
    let glass_bunny = format!(
        "Scene(camera: Pinhole(eye: (0, 0, -3), look_at: (0, 0, 0)), \
         materials: {{ \"g\": (transmit: (1, 1, 1), ior: 1.5) }}, \
         objects: [(material: \"g\", shape: Mesh(path: {bunny:?}))])"
    );
    let foggy_mirror = "Scene(camera: Pinhole(eye: (0, 0, -3), look_at: (0, 0, 0)), \
         materials: { \"m\": (reflect: (1, 1, 1)) }, \
         atmosphere: (fog: (base: -1, top: 2, extinction: 0.1)), \
         objects: [(material: \"m\", shape: Sphere(radius: 1))])";
    let ramp = "Scene(camera: Pinhole(eye: (0, 0, -3), look_at: (0, 0, 0)), \
         materials: { \"r\": (ramp: (height: [(0, (0, 0, 1)), (1, (1, 1, 1))])) }, \
         objects: [(material: \"r\", shape: Sphere(radius: 1))])";
    for (text, whitted, textures) in [
        (mesh.as_str(), false, false),
        (mirror, true, false),
        (glass_bunny.as_str(), true, false),
        (foggy_mirror, true, false),
        (ramp, false, true),
    ] {
        let scene = fray_scene::parse(text, "inline.ron").unwrap_or_else(|e| panic!("{e}"));
        assert!(fray_gpu::unsupported_feature(&scene).is_none(), "{text}");
        let settings = fray_gpu::GpuSettings::for_scene(&scene);
        match renderer.upload(&scene, &settings) {
            Ok(resident) => {
                let s = resident.specialisation();
                let (w, t) = (fray_gpu::Feature::Whitted, fray_gpu::Feature::Textures);
                assert_eq!((s.has(w), s.has(t)), (whitted, textures), "{text}");
            }
            Err(e) => panic!("{text}: {e}"),
        }
    }
}

fn main() {
    common::run(
        &[
            (
                "uncaptured_validation_error_is_recorded_not_raised",
                uncaptured_validation_error_is_recorded_not_raised,
            ),
            (
                "every_feature_uploads_none_is_refused",
                every_feature_uploads_none_is_refused,
            ),
        ],
        &[],
    );
}
