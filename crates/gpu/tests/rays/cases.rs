//! The suite's shared scaffolding: data scenes, camera rays, far views and fans of rays.

use crate::backend::CaseRay;
use fray_core::{Interval, Ray};
use fray_scene::Scene;
use glam::DVec3;
use std::path::Path;

pub use fray_test_support::roots::bisect;

/// The camera rays of `scene` through the pixel centres of a `width × height` grid.
pub fn camera_rays(scene: &Scene, width: u32, height: u32) -> Vec<CaseRay> {
    let mut rays = Vec::new();
    for py in 0..height {
        for px in 0..width {
            if let Some(c) = scene.camera.pixel_ray(px, py, width, height) {
                rays.push(CaseRay {
                    ray: c.ray,
                    range: Interval::new(c.t_near, f64::INFINITY),
                });
            }
        }
    }
    rays
}

/// A camera `back` behind `reference` along the mean of `camera`'s directions, and its rays
/// through the points `at` along each of them (a view of the same things from far away:
/// positions relative to that camera, long `t`).
pub fn far_rays(camera: &[CaseRay], reference: DVec3, back: f64, at: f64) -> (DVec3, Vec<CaseRay>) {
    let forward = camera.iter().map(|r| r.ray.dir).sum::<DVec3>().normalize();
    let eye = reference - forward * back;
    let rays = camera
        .iter()
        .filter_map(|r| {
            Some(CaseRay {
                ray: Ray::new(eye, r.ray.at(at) - eye)?,
                range: Interval::new(0.0, f64::INFINITY),
            })
        })
        .collect();
    (eye, rays)
}

/// Rays from `eye` at every `elevations` × `azimuths` (degrees, Y up) to each of `ends`.
pub fn fan(eye: DVec3, elevations: &[f64], azimuths: &[f64], ends: &[f64]) -> Vec<CaseRay> {
    let mut rays = Vec::new();
    for elevation in elevations {
        for azimuth in azimuths {
            let dir = direction(*elevation, *azimuth);
            for &end in ends {
                rays.push(CaseRay {
                    ray: Ray::new(eye, dir).expect("a unit direction"),
                    range: Interval::new(0.0, end),
                });
            }
        }
    }
    rays
}

/// The data scene `name` (`data/scenes/`), loaded.
pub fn data_scene(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/scenes")
        .join(name);
    fray_scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The unit vector at `elevation` and `azimuth` (degrees), Y up.
pub fn direction(elevation: f64, azimuth: f64) -> DVec3 {
    let (e, a) = (elevation.to_radians(), azimuth.to_radians());
    DVec3::new(e.cos() * a.cos(), e.sin(), e.cos() * a.sin())
}

/// Fails where any of `backend`'s `what` rays are off, with up to four of them.
pub fn assert_none_off<T: std::fmt::Debug>(backend: &str, what: &str, failures: &[T]) {
    assert!(
        failures.is_empty(),
        "{backend}: {} {what} rays off, e.g. {:?}",
        failures.len(),
        &failures[..failures.len().min(4)]
    );
}
