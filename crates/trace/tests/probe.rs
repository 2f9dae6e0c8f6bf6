//! `pixel_work` (the viewer's heat map and terrain-level views) counts the work the frame loop
//! does: summed over the pixels, its steps are the visibility frame's counters exactly, with
//! culling on and off, and its levels are the frame's mean stop level.

mod common;

use fray_core::RenderStats;
use fray_trace::{TraceSettings, pixel_work, render};
use std::path::Path;

fn frame_steps(s: &RenderStats) -> u64 {
    s.bound_evaluations + s.point_evaluations + s.terrain_segments + s.terrain_cells + s.mesh_rays
}

#[test]
fn the_steps_per_pixel_sum_to_the_frames_counters_and_levels_to_its_mean_level() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes");
    for name in ["csg.ron", "terrain_low.ron", "mesh_bunny_freeform.ron"] {
        let scene = common::load_at_height(&dir.join(name), 54);
        for culling in [true, false] {
            let settings = TraceSettings {
                shading: false,
                culling,
                threads: Some(2),
                ..TraceSettings::for_scene(&scene)
            };
            let frame = render(&scene, &settings, None).unwrap();
            let work = pixel_work(&scene, &settings).unwrap();
            assert_eq!((work.width, work.height), (scene.width, scene.height));
            let summed: u64 = work.steps.iter().map(|&s| u64::from(s)).sum();
            assert_eq!(
                summed,
                frame_steps(&frame.stats),
                "{name}, culling {culling}: the pixels' steps against the frame's"
            );
            assert!(work.most_steps() > 0, "{name}");
            // Every pixel that hit a surface took a step; a culled pixel none.
            for (k, d) in frame.depth.pixels().iter().enumerate() {
                if d.is_finite() {
                    assert!(work.steps[k] > 0, "{name}: pixel {k} hit with no step");
                }
            }
            // Each pixel's level weighted by its stops gives back the frame's sums.
            let stops: u64 = work.terrain_stops.iter().map(|&s| u64::from(s)).sum();
            let levels: f64 = work
                .terrain_level
                .iter()
                .zip(&work.terrain_stops)
                .filter(|(_, s)| **s > 0)
                .map(|(l, s)| (f64::from(*l) * f64::from(*s)).round())
                .sum();
            assert_eq!(stops, frame.stats.terrain_stops, "{name}");
            assert_eq!(levels as u64, frame.stats.terrain_stop_levels, "{name}");
            if name.starts_with("terrain") {
                assert!(
                    stops > 0 && work.highest_level() > 0.0,
                    "{name}: no level of detail"
                );
            }
        }
    }
}

#[test]
fn the_probe_refuses_what_a_frame_refuses() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes");
    let mut scene = common::load_at_height(&dir.join("csg.ron"), 16);
    let settings = TraceSettings {
        epsilon: f64::NAN,
        ..TraceSettings::for_scene(&scene)
    };
    assert!(pixel_work(&scene, &settings).is_err());
    scene.width = 0;
    assert!(pixel_work(&scene, &TraceSettings::for_scene(&scene)).is_err());
}
