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

/// A scene with a reflecting or transmitting material is refused before anything is uploaded —
/// `Unsupported`, naming what — until the GPU traces Whitted's secondary rays, so that `Auto`
/// renders it on the CPU; a scene with a mesh or a textured material is not (the GPU draws
/// meshes and samples textures and ramps).
fn secondary_rays_are_refused_as_unsupported_meshes_are_not() {
    let renderer = common::gpu("secondary_rays_are_refused_as_unsupported_meshes_are_not");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes");
    let mesh = format!(
        "Scene(camera: Pinhole(eye: (0, 0, -3), look_at: (0, 0, 0)), \
         objects: [(shape: Mesh(path: {:?}))])",
        dir.join("bunny00.obj").display().to_string()
    );
    let scene = fray_scene::parse(&mesh, "inline.ron").unwrap();
    assert!(fray_gpu::unsupported_feature(&scene).is_none());
    let settings = fray_gpu::GpuSettings::for_scene(&scene);
    if let Err(e) = renderer.upload(&scene, &settings) {
        panic!("a mesh scene: {e}");
    }
    let mirror = "Scene(camera: Pinhole(eye: (0, 0, -3), look_at: (0, 0, 0)), \
         materials: { \"m\": (reflect: (1, 1, 1)) }, \
         objects: [(material: \"m\", shape: Sphere(radius: 1))])";
    let glass_bunny = format!(
        "Scene(camera: Pinhole(eye: (0, 0, -3), look_at: (0, 0, 0)), \
         materials: {{ \"g\": (transmit: (1, 1, 1), ior: 1.5) }}, \
         objects: [(material: \"g\", shape: Mesh(path: {:?}))])",
        dir.join("bunny00.obj").display().to_string()
    );
    // A textured material is not (the GPU samples textures and ramps).
    let ramp = "Scene(camera: Pinhole(eye: (0, 0, -3), look_at: (0, 0, 0)), \
         materials: { \"r\": (ramp: (height: [(0, (0, 0, 1)), (1, (1, 1, 1))])) }, \
         objects: [(material: \"r\", shape: Sphere(radius: 1))])";
    let scene = fray_scene::parse(ramp, "inline.ron").unwrap();
    assert!(scene.features.textures && fray_gpu::unsupported_feature(&scene).is_none());
    let settings = fray_gpu::GpuSettings::for_scene(&scene);
    match renderer.upload(&scene, &settings) {
        Ok(resident) => assert!(resident.specialisation().textures),
        Err(e) => panic!("a ramp scene: {e}"),
    }
    for (text, feature) in [(mirror, "reflection"), (glass_bunny.as_str(), "refraction")] {
        let scene = fray_scene::parse(text, "inline.ron").unwrap();
        let settings = fray_gpu::GpuSettings::for_scene(&scene);
        match renderer.upload(&scene, &settings) {
            Err(fray_gpu::GpuError::Unsupported { feature: f }) => {
                assert!(f.contains(feature), "{f}")
            }
            other => panic!("{feature}: expected Unsupported, got {:?}", other.err()),
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
                "secondary_rays_are_refused_as_unsupported_meshes_are_not",
                secondary_rays_are_refused_as_unsupported_meshes_are_not,
            ),
        ],
        &[],
    );
}
