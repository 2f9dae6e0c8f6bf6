//! Anti-aliasing: `N` stratified samples per pixel, box-filtered. Known answers on an edge whose
//! covered fraction of each pixel is known exactly, and the rules that make it usable: one
//! sample is the unsampled image, depth and normals come from the pixel centre, and the result
//! is deterministic.

use fray_core::PixelSamples;
use fray_trace::{TraceSettings, render};

/// A parallel view of a flat, unlit slab whose left edge is the world plane `x = edge`: the
/// picture is 4 m wide over 16 pixels (0.25 m per pixel; +x is on the left), the slab has
/// radiance 0.5 · 0.8 = 0.4 (ambient only), the background 0.
fn edge_scene(edge: f64) -> fray_scene::Scene {
    fray_scene::parse(
        &format!(
            r#"Scene(
                image: (width: 16, height: 16),
                camera: Parallel(eye: (0, 0, -5), look_at: (0, 0, 0), height: 4),
                background: (0, 0, 0),
                ambient: (0.5, 0.5, 0.5),
                materials: {{ "flat": (ambient: (0.8, 0.8, 0.8), diffuse: (0, 0, 0)) }},
                objects: [(material: "flat", shape: FreeForm(
                    base: HalfSpace(point: (0, 0, 0), normal: (0, 0, -1)),
                    bounds: (min: (-10, -10, 0), max: ({edge}, 10, 1)),
                ))],
            )"#
        ),
        "edge.ron",
    )
    .unwrap()
}

/// The fraction of pixel column `px` (world `x` from `2 − 0.25 px` down to `2 − 0.25 (px+1)`)
/// that lies at `x ≤ edge`.
fn covered(px: u32, edge: f64) -> f64 {
    let left = 2.0 - 0.25 * f64::from(px);
    let right = left - 0.25;
    ((edge - right) / 0.25).clamp(0.0, 1.0)
}

#[test]
fn edge_pixels_get_their_covered_fraction_within_the_stratification_bound() {
    let edge = 0.5 + 0.25 * 0.3; // 30 % into a pixel column
    for n in [4u32, 9, 16, 64, 100] {
        let mut scene = edge_scene(edge);
        scene.settings.samples = PixelSamples::new(n).unwrap();
        let frame = render(&scene, &TraceSettings::for_scene(&scene), None).unwrap();
        let samples = PixelSamples::new(n).unwrap();
        // A vertical edge crosses one stratum per row: each row's estimate is off by less than
        // one stratum's share, so the pixel by less than 1 / (strata per row), at most.
        let strata = f64::from(n.div_ceil(samples.rows()));
        let bound = 1.0 / strata;
        let (mut edge_pixels, mut mean_error) = (0, 0.0);
        for py in 0..16 {
            for px in 0..16 {
                let value = f64::from(frame.colour.get(px, py).x) / 0.4;
                let expect = covered(px, edge);
                assert!(
                    (value - expect).abs() <= bound + 1e-6,
                    "{n} samples, pixel ({px}, {py}): {value} vs {expect} (bound {bound})"
                );
                if expect > 0.0 && expect < 1.0 {
                    edge_pixels += 1;
                    mean_error += (value - expect) / 16.0;
                }
            }
        }
        assert_eq!(edge_pixels, 16, "one column of edge pixels");
        // Unbiased: over the column the errors of the jittered strata mostly cancel.
        assert!(
            mean_error.abs() <= 0.5 * bound,
            "{n} samples: mean error {mean_error} over the edge column (bound {bound})"
        );
    }
}

#[test]
fn one_sample_is_the_pixel_centre_and_depth_and_normals_come_from_the_centre() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes/csg.ron");
    let mut scene = fray_scene::load(&path).unwrap();
    (scene.width, scene.height) = (48, 36);
    let plain = render(&scene, &TraceSettings::for_scene(&scene), None).unwrap();
    scene.settings.samples = PixelSamples::new(1).unwrap();
    let one = render(&scene, &TraceSettings::for_scene(&scene), None).unwrap();
    assert_eq!(plain.colour.pixels(), one.colour.pixels());
    scene.settings.samples = PixelSamples::new(6).unwrap();
    let settings = TraceSettings::for_scene(&scene);
    let six = render(&scene, &settings, None).unwrap();
    let bits = |d: &[f64]| d.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(plain.depth.pixels()), bits(six.depth.pixels()));
    assert_eq!(plain.normals.pixels(), six.normals.pixels());
    assert_ne!(plain.colour.pixels(), six.colour.pixels());
    // Deterministic, whatever the thread count.
    let again = render(
        &scene,
        &TraceSettings {
            threads: Some(1),
            ..settings
        },
        None,
    )
    .unwrap();
    assert_eq!(six.colour.pixels(), again.colour.pixels());
    assert_eq!(six.stats.primary_rays, 48 * 36 * 7);
}
