//! The frame loop casts a tile's camera rays against each mesh instance as packets
//! (`PacketBvh` through `Instance::nearest_hits`), and the frame is the one ray-by-ray casts
//! give, bit for bit: the same scene with instances that have no packet data (every ray through
//! `MeshBvh::nearest_hit`) renders the same colour, depth and normals — culled and not, with
//! and without anti-aliasing samples, shaded and visibility only, tiles of 16 and of 13 pixels
//! (packets cut short at tile edges) — on a scene with rays that miss, a free form in front of
//! part of the bunny (the earlier kind's nearer hit bounds the mesh's range, and a tie keeps
//! it), a mirrored second instance of the same mesh, and meshes cut by tile edges. Shaded, the
//! camera hits' shadow rays go through the packets too (`mesh_shadows`), and the frame is still
//! the ray-by-ray one. The stats say the packets ran.

use fray_core::PixelSamples;
use fray_mesh::Instance;
use fray_scene::Scene;
use fray_trace::{TraceSettings, render};
use std::path::Path;

fn scene() -> Scene {
    let bunny = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes/bunny00.obj");
    let bunny = bunny.display().to_string();
    let source = format!(
        "Scene(image: (width: 72, height: 52), \
         camera: Pinhole(eye: (0, 0.1, -2.2), look_at: (0, 0, 0), fov_y: 30), \
         ambient: (0.1, 0.1, 0.1), \
         lights: [Sun(direction: (0.3, 0.8, -0.5), irradiance: (3, 3, 3)), \
                  Point(position: (-1.2, 0.9, -1.0), intensity: (1.5, 1.2, 1.0))], \
         objects: [ \
           (name: \"bunny\", shape: Mesh(path: {bunny:?}, \
              transform: (scale: (0.7, 0.7, 0.7), rotate: (0, 30, 0), translate: (-0.28, 0, 0)))), \
           (name: \"ball\", shape: Sphere(center: (-0.3, 0.05, -0.5), radius: 0.12)), \
           (name: \"mirrored bunny\", shape: Mesh(path: {bunny:?}, smooth: false, \
              transform: (scale: (-0.5, 0.5, 0.5), translate: (0.36, 0, 0.3)))), \
         ])"
    );
    fray_scene::parse(&source, "mesh_tiles.ron").unwrap_or_else(|e| panic!("{e}"))
}

/// `scene` with every mesh instance stripped of its packet data: its rays go one by one.
fn ray_by_ray(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    for m in &mut s.meshes {
        m.instance = Instance::new(m.instance.mesh.clone(), m.instance.to_world()).unwrap();
        assert!(m.instance.packets().is_none());
    }
    s
}

#[test]
fn mesh_packets_give_the_frame_of_ray_by_ray_casts() {
    let packets = scene();
    assert!(
        packets
            .meshes
            .iter()
            .all(|m| m.instance.packets().is_some())
    );
    let single = ray_by_ray(&packets);
    for samples in [1, 4] {
        for culling in [true, false] {
            for (shading, tile_size) in [(true, 16), (false, 16), (true, 13)] {
                let what = format!(
                    "{samples} samples, culling {culling}, shading {shading}, tiles {tile_size}"
                );
                let frame = |s: &Scene| {
                    let mut s = s.clone();
                    s.settings.samples = PixelSamples::new(samples).unwrap();
                    let settings = TraceSettings {
                        culling,
                        shading,
                        tile_size,
                        ..TraceSettings::for_scene(&s)
                    };
                    render(&s, &settings, None).unwrap_or_else(|e| panic!("{what}: {e}"))
                };
                let (a, b) = (frame(&packets), frame(&single));
                let bits = |f: &fray_core::Frame| {
                    let colour: Vec<_> = f.colour.pixels().iter().map(|c| c.to_array()).collect();
                    let normals: Vec<_> = f.normals.pixels().iter().map(|n| n.to_array()).collect();
                    let depth: Vec<_> = f.depth.pixels().iter().map(|d| d.to_bits()).collect();
                    (
                        colour
                            .into_iter()
                            .flatten()
                            .map(f32::to_bits)
                            .collect::<Vec<_>>(),
                        normals
                            .into_iter()
                            .flatten()
                            .map(f32::to_bits)
                            .collect::<Vec<_>>(),
                        depth,
                    )
                };
                assert!(bits(&a) == bits(&b), "{what}: the frames differ");
                // Every camera ray searched against a mesh went through a tile's packets (no
                // secondary rays here); the same casts as ray by ray.
                let s = &a.stats;
                assert!(
                    s.mesh_tile_rays > 0 && s.mesh_tile_rays == s.mesh_rays,
                    "{what}: {} of {} mesh rays in tiles",
                    s.mesh_tile_rays,
                    s.mesh_rays
                );
                assert_eq!(s.mesh_rays, b.stats.mesh_rays, "{what}");
                // Shaded, the camera hits' shadow rays went through the packets too (two
                // instances: two casts per shadow ray); ray by ray, none did. The same shadow
                // rays either way.
                assert_eq!(s.shadow_rays, b.stats.shadow_rays, "{what}");
                assert_eq!(b.stats.mesh_shadow_tile_rays, 0, "{what}");
                if shading {
                    assert!(
                        s.shadow_rays > 1000 && s.mesh_shadow_tile_rays == 2 * s.shadow_rays,
                        "{what}: {} of {} shadow rays in packets",
                        s.mesh_shadow_tile_rays,
                        s.shadow_rays
                    );
                } else {
                    assert_eq!(s.mesh_shadow_tile_rays, 0, "{what}");
                }
                // The picture has all of it: misses, both bunnies, the ball.
                let depth = a.depth.pixels();
                let missed = depth.iter().filter(|d| d.is_infinite()).count();
                assert!(
                    missed > 300 && depth.len() - missed > 500,
                    "{what}: {missed} misses"
                );
            }
        }
    }
}

/// The scene's shadows matter: 84 of its 3744 pixels are darker with shadows (so the frame test above
/// compares shadow answers, not only unshadowed light).
#[test]
fn the_meshes_cast_shadows_in_the_test_scene() {
    let s = scene();
    let lit = |shadows: bool| {
        let settings = TraceSettings {
            shadows,
            ..TraceSettings::for_scene(&s)
        };
        render(&s, &settings, None).unwrap_or_else(|e| panic!("{e}"))
    };
    let (with, without) = (lit(true), lit(false));
    let darker = with
        .colour
        .pixels()
        .iter()
        .zip(without.colour.pixels())
        .filter(|(a, b)| a.element_sum() < b.element_sum() - 1e-3)
        .count();
    assert!(darker > 40, "{darker} pixels in shadow");
}

/// A tile batches at most `2¹⁶` shadow rays (its scratch space is bounded, whatever the number
/// of lights): with 600 lights 16-pixel tiles (up to 256 rays × 600) cast them one by one, 4-pixel
/// tiles (16 × 600) as packets, and the two frames are the same bit for bit.
#[test]
fn many_lights_keep_a_tiles_batch_bounded() {
    let mut s = scene();
    s.width = 24;
    s.height = 16;
    let light = s.lights[1];
    s.lights = vec![light; 600];
    let frame = |tile_size| {
        let settings = TraceSettings {
            tile_size,
            ..TraceSettings::for_scene(&s)
        };
        render(&s, &settings, None).unwrap_or_else(|e| panic!("{e}"))
    };
    let (whole, small) = (frame(16), frame(4));
    assert!(
        whole.stats.shadow_rays > 10_000,
        "{}",
        whole.stats.shadow_rays
    );
    assert_eq!(whole.stats.mesh_shadow_tile_rays, 0);
    assert_eq!(
        small.stats.mesh_shadow_tile_rays,
        2 * small.stats.shadow_rays
    );
    let bits = |f: &fray_core::Frame| {
        let c = f.colour.pixels().iter().flat_map(|c| c.to_array());
        c.map(f32::to_bits).collect::<Vec<_>>()
    };
    assert!(bits(&whole) == bits(&small), "the frames differ");
}
