//! Whitted's secondary-ray budget (`settings.max_secondary_rays`, `fray_trace::ray_budget`) on
//! the reproducer of an exponential tree: two glass plates that both reflect and transmit
//! (`kr = kt = 0.5`, no Fresnel, `min_contribution: 0`), one above the other, seen between them,
//! so that nearly every hit spawns two rays. At depth 64 the budget bounds each camera ray's
//! rays (the frame finishes in a second or two), the image does not depend on the thread
//! count or tile size; and where every tree is full (two concentric glass shells round the
//! camera), a budget that holds the full tree of the depth changes no bit.

use fray_core::Interval;
use fray_scene::Scene;
use fray_trace::{Integrator, TraceContext, TraceSettings, render};

/// At depth 64 (the cap; the full tree would be `2⁶⁵ − 2` rays) no camera ray traces more than
/// the budget — each pixel's camera ray counted alone through the integrator —, and the
/// frame's secondary rays are at most `budget ×` its camera rays; a smaller budget traces
/// fewer (the budget, not the depth, decides). The default (256) is the budget of a scene that
/// names none. Each frame takes about 0.1 s (its depth-20 frame without a budget: 19 s).
#[test]
fn a_tree_of_depth_64_traces_at_most_the_budget_per_camera_ray() {
    let defaults = fray_scene::parse("(settings: (max_depth: 64))", "d.ron").unwrap();
    assert_eq!(
        defaults.settings.max_secondary_rays,
        fray_scene::DEFAULT_MAX_SECONDARY_RAYS
    );
    let mut traced = Vec::new();
    for budget in [fray_scene::DEFAULT_MAX_SECONDARY_RAYS, 40] {
        let scene = two_plates(32, 24, 64, budget);
        let start = std::time::Instant::now();
        let frame = render(&scene, &TraceSettings::for_scene(&scene), None).unwrap();
        let (rays, camera) = (frame.stats.secondary_rays, frame.stats.primary_rays);
        eprintln!(
            "budget {budget}: {rays} secondary rays for {camera} camera rays in {:.2?}",
            start.elapsed()
        );
        assert_eq!(camera, 32 * 24);
        assert!(rays <= u64::from(budget) * camera, "{rays}");
        let integrator = Integrator::new(&scene, &TraceSettings::for_scene(&scene));
        let mut most = 0;
        for y in 0..24 {
            for x in 0..32 {
                let c = scene.camera.pixel_ray(x, y, 32, 24).unwrap();
                let mut ctx = TraceContext::default();
                let range = Interval::new(c.t_near, f64::INFINITY);
                integrator.radiance(&mut ctx, &c.ray, range);
                most = most.max(ctx.counts.secondary_rays);
            }
        }
        eprintln!("budget {budget}: at most {most} secondary rays per camera ray");
        assert!(most <= u64::from(budget), "{most}");
        traced.push(rays);
    }
    assert!(traced[1] < traced[0], "{traced:?}");
}

/// The rays a camera ray traces depend on its path alone: the budget-bound frame is the same,
/// bit for bit, on one thread with 8-pixel tiles as on two with the default tiles.
#[test]
fn the_bound_frame_does_not_depend_on_threads_or_tiles() {
    let scene = two_plates(24, 16, 64, 48);
    let mut one = TraceSettings::for_scene(&scene);
    one.threads = Some(1);
    one.tile_size = 8;
    let mut two = TraceSettings::for_scene(&scene);
    two.threads = Some(2);
    let (a, b) = (
        render(&scene, &one, None).unwrap(),
        render(&scene, &two, None).unwrap(),
    );
    assert_eq!(a.colour.pixels(), b.colour.pixels());
    assert_eq!(a.stats.secondary_rays, b.stats.secondary_rays);
}

/// Inside the shells every tree at depth 4 is full (30 rays). A budget of 30 — the full tree's
/// count — never binds: its frame is the frame of the largest budget bit for bit, with exactly
/// 30 rays per camera ray. A budget of 29 binds on every camera ray, and the rule spends it all
/// (every ray has both children): exactly 29 per camera ray, and another image.
#[test]
fn a_budget_holding_the_full_tree_changes_no_bit() {
    let frame = |budget: u32| {
        let scene = shells(4, budget);
        render(&scene, &TraceSettings::for_scene(&scene), None).unwrap()
    };
    let unbound = frame(fray_scene::MAX_SECONDARY_RAYS);
    let camera = unbound.stats.primary_rays;
    assert_eq!(camera, 16 * 12);
    assert_eq!(unbound.stats.secondary_rays, 30 * camera);
    let whole = frame(30);
    assert_eq!(whole.colour.pixels(), unbound.colour.pixels());
    assert_eq!(whole.depth.pixels(), unbound.depth.pixels());
    assert_eq!(whole.stats.secondary_rays, 30 * camera);
    let short = frame(29);
    assert_eq!(short.stats.secondary_rays, 29 * camera);
    assert_ne!(short.colour.pixels(), whole.colour.pixels());
}

/// The two plates of `fray_test_support::scenes`, parsed.
fn two_plates(width: u32, height: u32, depth: u32, budget: u32) -> Scene {
    let text = fray_test_support::scenes::two_plates(width, height, depth, budget);
    fray_scene::parse(&text, "two_plates.ron").unwrap_or_else(|e| panic!("{e}"))
}

/// The two shells of `fray_test_support::scenes`, parsed.
fn shells(depth: u32, budget: u32) -> Scene {
    let text = fray_test_support::scenes::shells(depth, budget);
    fray_scene::parse(&text, "shells.ron").unwrap_or_else(|e| panic!("{e}"))
}
