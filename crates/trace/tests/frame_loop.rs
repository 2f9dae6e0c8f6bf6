//! The frame loop (camera rays, then every tile's hits with candidates outer and pixels inner,
//! then their surfaces) gives each pixel exactly what the per-ray API gives its camera ray:
//! the depth and normal of [`nearest_hit`], bit for bit, on every data scene, culled or not.

mod common;

use fray_trace::{TraceSettings, nearest_hit, render};

#[test]
fn every_pixel_gets_the_hit_of_nearest_hit() {
    let mut ctx = fray_trace::TraceContext::default();
    for path in common::data_scenes() {
        let what = path.display().to_string();
        let mut s = common::load_at_height(&path, 48);
        // Terrains: the frame casts camera rays at the pixel footprint's level of detail, the
        // per-ray API exactly; compare exact terrains.
        for t in &mut s.terrains {
            t.lod = fray_scene::TerrainLod::Exact;
        }
        for culling in [false, true] {
            let settings = TraceSettings {
                shading: false,
                culling,
                ..TraceSettings::for_scene(&s)
            };
            let frame = render(&s, &settings, None).unwrap_or_else(|e| panic!("{what}: {e}"));
            for y in 0..s.height {
                for x in 0..s.width {
                    let Some(c) = s.camera.pixel_ray(x, y, s.width, s.height) else {
                        continue;
                    };
                    let range = fray_core::Interval::new(c.t_near, f64::INFINITY);
                    let hit = nearest_hit(&s, &mut ctx, &c.ray, range, settings.epsilon);
                    let depth = *frame.depth.get(x, y);
                    assert_eq!(
                        depth.to_bits(),
                        hit.map_or(f64::INFINITY, |h| h.t).to_bits(),
                        "{what} (culling {culling}): depth at ({x}, {y})"
                    );
                    if let Some(h) = hit {
                        let n = h.shading_normal.as_vec3().to_array().map(f32::to_bits);
                        assert_eq!(
                            frame.normals.get(x, y).to_array().map(f32::to_bits),
                            n,
                            "{what} (culling {culling}): normal at ({x}, {y})"
                        );
                    }
                }
            }
        }
    }
}

/// The integrator's per-ray entry, `Integrator::camera_radiance` (`radiance` with the camera
/// pixel's media jitter; the one every non-camera ray will take otherwise) — gives each camera ray exactly the colour the frame loop gave its pixel (which found the
/// hits a tile at a time and culled the shadow rays' occluders per tile): one integrator.
#[test]
fn the_integrators_radiance_of_each_camera_ray_is_the_frames_colour() {
    let mut ctx = fray_trace::TraceContext::default();
    for path in common::data_scenes() {
        let what = path.display().to_string();
        let mut s = common::load_at_height(&path, 32);
        for t in &mut s.terrains {
            t.lod = fray_scene::TerrainLod::Exact;
        }
        let settings = TraceSettings::for_scene(&s);
        let frame = render(&s, &settings, None).unwrap_or_else(|e| panic!("{what}: {e}"));
        let integrator = fray_trace::Integrator::new(&s, &settings);
        for y in 0..s.height {
            for x in 0..s.width {
                let Some(c) = s.camera.pixel_ray(x, y, s.width, s.height) else {
                    continue;
                };
                let range = fray_core::Interval::new(c.t_near, f64::INFINITY);
                let at = (f64::from(x) + 0.5, f64::from(y) + 0.5);
                let radiance = integrator
                    .camera_radiance(&mut ctx, at, &c.ray, range)
                    .as_vec3();
                assert_eq!(
                    radiance.to_array().map(f32::to_bits),
                    frame.colour.get(x, y).to_array().map(f32::to_bits),
                    "{what}: colour at ({x}, {y})"
                );
            }
        }
    }
}
