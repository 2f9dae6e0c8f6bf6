//! Memory budgets of the CPU frame: what grows with the image is checked before it is made.

use fray_core::MemoryBudget;
use fray_trace::{TraceError, TraceSettings, render};

fn sphere(width: u32, height: u32) -> fray_scene::Scene {
    let mut scene = fray_scene::parse(
        "Scene(camera: Pinhole(eye: (0, 0, -4), look_at: (0, 0, 0)), \
         objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))])",
        "sphere.ron",
    )
    .unwrap();
    (scene.width, scene.height) = (width, height);
    scene
}

/// A 16384² frame, which scene validation accepts, needs 8 GiB of images: refused over the
/// default 4 GiB budget before anything is allocated, with what, how much and the limit.
#[test]
fn a_frame_over_the_budget_is_refused_before_it_is_allocated() {
    let mut scene = sphere(16384, 16384);
    scene.budget = MemoryBudget::new(MemoryBudget::DEFAULT_BYTES);
    let settings = TraceSettings::for_scene(&scene);
    let e = render(&scene, &settings, None).unwrap_err();
    let TraceError::Budget(b) = &e else {
        panic!("expected a budget error, got {e}");
    };
    assert_eq!(b.needed, 16384 * 16384 * 32);
    assert_eq!(b.limit, 4 << 30);
    let text = e.to_string();
    assert!(
        text.contains("frame's colour, depth and normal images")
            && text.contains("16384 × 16384")
            && text.contains("8.00 GiB")
            && text.contains("4.00 GiB"),
        "{text}"
    );
}

/// Within the frame's budget but not the work list's: the quadtree refuses, naming itself.
#[test]
fn a_work_list_over_the_budget_is_refused() {
    let mut scene = sphere(64, 64);
    let frame_bytes = 64 * 64 * 32;
    scene.budget = MemoryBudget::new(frame_bytes);
    let settings = TraceSettings {
        tile_size: 1,
        ..TraceSettings::for_scene(&scene)
    };
    let e = render(&scene, &settings, None).unwrap_err();
    assert!(e.to_string().contains("quadtree work list"), "{e}");
    // A budget that holds both renders.
    scene.budget = MemoryBudget::new(1 << 20);
    let settings = TraceSettings::for_scene(&scene);
    let frame = render(&scene, &settings, None).unwrap();
    assert!(frame.stats.hits > 0);
}

/// Every render of one scene charges the same account: what the scene built stays charged, and
/// a frame's images are released when it returns, so frame after frame fits a budget that
/// holds one.
#[test]
fn frames_are_released_and_the_scene_stays_charged() {
    let mut scene = sphere(64, 64);
    scene.budget = MemoryBudget::new(1 << 20);
    scene
        .budget
        .charge("what the scene built", 900_000)
        .unwrap();
    let settings = TraceSettings::for_scene(&scene);
    for _ in 0..3 {
        render(&scene, &settings, None).unwrap();
        assert_eq!(scene.budget.charged(), 900_000);
    }
    scene.budget.charge("more of the scene", 120_000).unwrap();
    let e = render(&scene, &settings, None).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("frame's colour") && text.contains("1020000 bytes"),
        "{text}"
    );
}
