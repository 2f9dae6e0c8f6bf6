//! Whitted's secondary rays on the GPU (`fray_gpu::passes::whitted`: queues of reflected and
//! refracted rays through the pass pipeline) vs the f64 reference (`fray_trace::render`):
//!
//! - frames of synthetic scenes — mirror and glass free forms (rays inside a glass solid leave
//!   it through its complement), Fresnel, total internal reflection in a dense ball, a glass
//!   mesh (the bunny) and a mirror beside it, shadows through glass; secondary rays through fog,
//!   under a sky (misses see the sky, hits its air) and through clouds — and the data scenes whose
//!   materials reflect or transmit (`mesh_bunny_freeform`, `mesh_aircraft_pair`,
//!   `whitted_glass_mirror` with its brick floor textured along reflected and refracted paths), at
//!   a small width;
//! - a scene whose secondary rays overflow the first queue (two glass balls at depth 8): the
//!   frame is rendered again with a larger queue and still matches;
//! - the secondary rays traced are counted, within a small share of the CPU's count (a ray
//!   whose weight sits at the cut-off, or whose refraction sits at the critical angle, can be
//!   decided the other way in f32);
//! - `max_depth: 0` traces no secondary ray and is the frame of the same scene without `kr`/`kt`
//!   in its local terms;
//! - the secondary-ray budget (`settings.max_secondary_rays`, fray-trace's `ray_budget` rule):
//!   two glass plates that reflect and transmit at depth 64 trace at most the budget per camera
//!   ray, in a queue no larger, and match the CPU where the budget binds; where every tree is
//!   full (two glass shells round the camera) a budget holding the full tree changes no bit.
//!
//! Uses the libtest-mimic harness: ignored without an adapter, a failure under
//! `FRAY_REQUIRE_GPU=1`.

mod common;

use fray_core::Frame;
use fray_gpu::{GpuRenderer, GpuSettings};
use fray_scene::Scene;
use fray_trace::TraceSettings;

const WIDTH: u32 = 96;
/// The colour bound per pixel: `COLOUR_ABS + COLOUR_REL · |c|` (the camera rays' frame bound of
/// `parity.rs`).
const COLOUR_ABS: f32 = 2e-3;
const COLOUR_REL: f32 = 2e-3;
/// The share of compared pixels that may be past the colour bound: a secondary ray crosses
/// silhouettes and shadow edges the camera rays' masks do not know of (a reflected or refracted
/// edge), and f32 moves such a crossing by a pixel's worth after a refraction or two.
const WHITTED_COLOUR_OFF: f64 = 0.03;
/// The secondary rays' count may differ from the CPU's by this share.
const SECONDARY_COUNT_OFF: f64 = 0.02;

const SCENES: [(&str, &str); 7] = [
    (
        "mirror and diffuse free forms",
        "Scene(image: (width: 160, height: 100),
           camera: Pinhole(eye: (0, 1.2, -4), look_at: (0, 0.5, 0), fov_y: 45),
           background: (0.3, 0.4, 0.6), ambient: (0.1, 0.1, 0.1),
           lights: [Sun(direction: (0.3, 1, -0.4), irradiance: (2.5, 2.4, 2.2)),
                    Point(position: (-2, 3, -2), intensity: (4, 4, 4))],
           materials: {
             \"mirror\": (diffuse: (0.05, 0.05, 0.05), reflect: (0.8, 0.8, 0.8)),
             \"red\": (diffuse: (0.8, 0.15, 0.1), specular: (0.3, 0.3, 0.3), shininess: 40),
             \"floor\": (diffuse: (0.5, 0.5, 0.5), reflect: (0.2, 0.2, 0.2)),
           },
           objects: [
             (material: \"mirror\", shape: Sphere(center: (-0.6, 0.6, 0.3), radius: 0.6)),
             (material: \"red\", shape: FreeForm(base: Ellipsoid(center: (0.9, 0.5, 0), radii: (0.4, 0.5, 0.4)),
                perturbations: [(form_factor: 2, quadric: Sphere(center: (0.9, 1.0, 0), radius: 0.2))])),
             (material: \"floor\", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                bounds: (min: (-6, -0.1, -6), max: (6, 0, 6)))),
           ],
           settings: (max_depth: 4))",
    ),
    (
        "glass free forms with Fresnel and total internal reflection",
        "Scene(image: (width: 160, height: 100),
           camera: Pinhole(eye: (0, 1.0, -4), look_at: (0, 0.5, 0), fov_y: 45),
           background: (0.5, 0.6, 0.8), ambient: (0.1, 0.1, 0.1),
           lights: [Sun(direction: (0.2, 1, -0.5), irradiance: (2.5, 2.4, 2.2))],
           materials: {
             \"glass\": (diffuse: (0, 0, 0), transmit: (0.95, 0.95, 0.95), ior: 1.5, fresnel: true),
             \"dense\": (diffuse: (0, 0, 0), transmit: (0.9, 0.95, 0.9), ior: 2.4),
             \"blue\": (diffuse: (0.1, 0.2, 0.8)),
             \"floor\": (diffuse: (0.6, 0.55, 0.5)),
           },
           objects: [
             (material: \"glass\", shape: Sphere(center: (-0.7, 0.6, 0), radius: 0.6)),
             (material: \"dense\", shape: Sphere(center: (0.8, 0.45, -0.3), radius: 0.45)),
             (material: \"blue\", shape: Sphere(center: (0.1, 0.5, 2), radius: 0.5)),
             (material: \"floor\", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                bounds: (min: (-6, -0.1, -6), max: (6, 0, 6)))),
           ],
           settings: (max_depth: 5))",
    ),
    (
        "glass bunny beside a mirror ball",
        "Scene(image: (width: 160, height: 100),
           camera: Pinhole(eye: (0.3, 0.9, -3.3), look_at: (0.0, 0.35, 0.0), fov_y: 36),
           background: (0.46, 0.58, 0.76), ambient: (0.1, 0.11, 0.13),
           lights: [Sun(direction: (0.4, 1.0, -0.6), irradiance: (2.8, 2.7, 2.5))],
           materials: {
             \"glass\": (diffuse: (0, 0, 0), transmit: (0.9, 0.95, 0.9), ior: 1.45, fresnel: true),
             \"mirror\": (diffuse: (0.02, 0.02, 0.02), reflect: (0.85, 0.85, 0.85)),
             \"floor\": (diffuse: (0.55, 0.55, 0.58)),
           },
           objects: [
             (material: \"glass\", shape: Mesh(path: \"MESHES/bunny00.obj\",
                transform: (rotate: (0, 200, 0), translate: (-0.62, 0.49, 0.1)))),
             (material: \"mirror\", shape: Sphere(center: (0.5, 0.3, 0.5), radius: 0.3)),
             (material: \"floor\", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                bounds: (min: (-8, -0.1, -8), max: (8, 0, 8)))),
           ],
           settings: (max_depth: 5))",
    ),
    (
        "two glass balls at depth 8 (the first queue overflows)",
        "Scene(image: (width: 160, height: 100),
           camera: Pinhole(eye: (0, 0.6, -3), look_at: (0, 0.5, 0), fov_y: 40),
           background: (0.4, 0.5, 0.7), ambient: (0.1, 0.1, 0.1),
           lights: [Sun(direction: (0.2, 1, -0.5), irradiance: (2.5, 2.4, 2.2))],
           materials: {
             \"glass\": (diffuse: (0, 0, 0), transmit: (0.97, 0.97, 0.97), ior: 1.5, fresnel: true),
             \"floor\": (diffuse: (0.6, 0.55, 0.5), reflect: (0.3, 0.3, 0.3)),
           },
           objects: [
             (material: \"glass\", shape: Sphere(center: (-0.45, 0.5, 0), radius: 0.5)),
             (material: \"glass\", shape: Sphere(center: (0.55, 0.5, 0.2), radius: 0.5)),
             (material: \"floor\", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                bounds: (min: (-6, -0.1, -6), max: (6, 0, 6)))),
           ],
           settings: (max_depth: 8, min_contribution: 1e-4))",
    ),
    (
        "a mirror and a glass ball in fog",
        "Scene(image: (width: 160, height: 100),
           camera: Pinhole(eye: (0, 1.2, -5), look_at: (0, 0.6, 0), fov_y: 45),
           background: (0.5, 0.6, 0.7), ambient: (0.1, 0.1, 0.1),
           lights: [Sun(direction: (0.3, 1, -0.4), irradiance: (2.5, 2.4, 2.2)),
                    Point(position: (-2, 3, -2), intensity: (4, 4, 4))],
           atmosphere: (fog: (base: -1, top: 1.2, extinction: 0.15, phase: HenyeyGreenstein(g: 0.5))),
           materials: {
             \"mirror\": (diffuse: (0.05, 0.05, 0.05), reflect: (0.8, 0.8, 0.8)),
             \"glass\": (diffuse: (0, 0, 0), transmit: (0.95, 0.95, 0.95), ior: 1.5, fresnel: true),
             \"red\": (diffuse: (0.8, 0.15, 0.1)),
             \"floor\": (diffuse: (0.5, 0.5, 0.5)),
           },
           objects: [
             (material: \"mirror\", shape: Sphere(center: (-0.8, 0.7, 0.5), radius: 0.7)),
             (material: \"glass\", shape: Sphere(center: (0.9, 0.5, -0.2), radius: 0.5)),
             (material: \"red\", shape: Sphere(center: (0.4, 0.5, 2.5), radius: 0.5)),
             (material: \"floor\", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                bounds: (min: (-20, -0.1, -20), max: (20, 0, 20)))),
           ],
           settings: (max_depth: 4))",
    ),
    (
        "a mirror under the sky: reflected rays see the sky and its air",
        "Scene(image: (width: 96, height: 64),
           camera: Pinhole(eye: (0, 2, 0), look_at: (930, 172, 300), fov_y: 40, near: 0.1),
           ambient: (0.02, 0.02, 0.03),
           lights: [Sun(direction: (0.93, 0.17, 0.3), irradiance: (20, 20, 20))],
           materials: {
             \"ground\": (diffuse: (0.3, 0.3, 0.25), reflect: (0.3, 0.3, 0.3)),
             \"mirror\": (diffuse: (0.05, 0.05, 0.05), reflect: (0.9, 0.9, 0.9)),
           },
           atmosphere: (sky: (haze: 2)),
           objects: [
             (material: \"ground\", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                bounds: (min: (-20000, -1, -20000), max: (20000, 0, 20000)))),
             (material: \"mirror\", shape: Sphere(center: (3000, 300, -400), radius: 300)),
             (shape: Sphere(center: (1200, 50, -200), radius: 60)),
           ],
           settings: (max_depth: 3))",
    ),
    (
        "a mirror ball under clouds",
        "Scene(image: (width: 64, height: 40),
           camera: Pinhole(eye: (0, 7, -48), look_at: (0, 4, 0), fov_y: 50, near: 0.1),
           background: (0.4, 0.55, 0.8), ambient: (0.15, 0.17, 0.2),
           lights: [Sun(direction: (0.5, 0.45, 0.3), irradiance: (3, 2.9, 2.7))],
           materials: { \"ground\": (diffuse: (0.4, 0.38, 0.3)),
                        \"mirror\": (diffuse: (0.02, 0.02, 0.02), reflect: (0.85, 0.85, 0.85)) },
           clouds: (
             region: (min: (-20, 2, -20), max: (20, 12, 20)),
             density: Layer((resolution: (32, 10, 32), feature_size: 14, octaves: 3, seed: 5, coverage: 0.6)),
             scattering: 0.4, step: 0.6,
           ),
           objects: [
             (material: \"ground\", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                bounds: (min: (-80, -1, -80), max: (80, 0, 80)))),
             (material: \"mirror\", shape: Sphere(center: (-2, 5, -10), radius: 5)),
           ],
           settings: (max_depth: 3))",
    ),
];

fn scene_of(name: &str, text: &str) -> Scene {
    let meshes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes");
    let text = text.replace("MESHES/", &format!("{}/", meshes.display()));
    let mut scene = fray_scene::parse(&text, name).unwrap_or_else(|e| panic!("{name}: {e}"));
    sized(&mut scene);
    scene
}

fn sized(scene: &mut Scene) {
    let h = ((u64::from(WIDTH) * u64::from(scene.height)) / u64::from(scene.width)).max(1);
    scene.width = WIDTH;
    scene.height = h as u32;
}

/// What a comparison found.
#[derive(Debug, Default)]
struct Report {
    compared: usize,
    hit_miss: usize,
    max_depth_rel: f64,
    colour_off: usize,
    max_colour: f32,
    mean_colour: f64,
    secondary_cpu: u64,
    secondary_gpu: u64,
}

/// The GPU frame of `scene` against the CPU's: the camera rays' depths where both hit (the
/// primary passes are unchanged by Whitted), and every pixel's colour.
fn compare(name: &str, scene: &Scene, gpu: &GpuRenderer) -> (Report, Frame) {
    let cpu = fray_trace::render(scene, &TraceSettings::for_scene(scene), None).unwrap();
    let g = gpu
        .render(scene, &GpuSettings::for_scene(scene))
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    assert!(g.stats.backend.starts_with("gpu ("), "{}", g.stats.backend);
    let mut r = Report {
        secondary_cpu: cpu.stats.secondary_rays,
        secondary_gpu: g.stats.secondary_rays,
        ..Report::default()
    };
    let (cd, gd) = (cpu.depth.pixels(), g.depth.pixels());
    let (cc, gc) = (cpu.colour.pixels(), g.colour.pixels());
    let mut sum = 0.0;
    for k in 0..cd.len() {
        if cd[k].is_finite() != gd[k].is_finite() {
            r.hit_miss += 1;
            continue;
        }
        if cd[k].is_finite() {
            r.max_depth_rel = r.max_depth_rel.max((gd[k] - cd[k]).abs() / cd[k]);
        }
        r.compared += 1;
        let d = (gc[k] - cc[k]).abs().max_element();
        assert!(
            gc[k].is_finite(),
            "{name}: a non-finite colour at pixel {k}"
        );
        r.max_colour = r.max_colour.max(d);
        // In the display's range: a glint of the sun seen through glass (radiance up to ~50,
        // white on screen) that f32 moves onto the next pixel counts as the white it shows.
        let shown = |c: glam::Vec3| c.clamp(glam::Vec3::ZERO, glam::Vec3::ONE);
        sum += f64::from((shown(gc[k]) - shown(cc[k])).abs().max_element());
        if d > COLOUR_ABS + COLOUR_REL * cc[k].abs().max_element() {
            r.colour_off += 1;
        }
    }
    r.mean_colour = sum / r.compared.max(1) as f64;
    // The worst pixels, for the log.
    let mut worst: Vec<(f32, usize)> = (0..cd.len())
        .map(|k| ((gc[k] - cc[k]).abs().max_element(), k))
        .collect();
    worst.sort_by(|a, b| b.0.total_cmp(&a.0));
    for &(d, k) in worst.iter().take(8) {
        let (x, y) = (k as u32 % scene.width, k as u32 / scene.width);
        eprintln!(
            "{name}: ({x}, {y}) |Δ| {d:.4}: cpu {} gpu {} depth {:.3}",
            cc[k], gc[k], cd[k]
        );
    }
    eprintln!("{name}: {r:?} | gpu {:?}", g.stats.passes);
    (r, g)
}

/// The frame bounds of a Whitted scene: hit/miss of camera rays on at most 0.5 % of the
/// pixels (silhouettes: the f32 casts of `parity.rs`), colour within the bound on all but
/// [`WHITTED_COLOUR_OFF`] of them, mean colour difference (in the display's range, [0, 1])
/// below 3e-3 (measured at most 1.73e-3, on `whitted_glass_mirror`), and the secondary rays' count within [`SECONDARY_COUNT_OFF`] of the CPU's.
fn check(name: &str, scene: &Scene, gpu: &GpuRenderer) -> Frame {
    let (r, frame) = compare(name, scene, gpu);
    let pixels = (scene.width * scene.height) as f64;
    assert!(
        r.hit_miss as f64 <= 0.005 * pixels,
        "{name}: camera hit/miss: {r:?}"
    );
    assert!(
        r.colour_off as f64 <= WHITTED_COLOUR_OFF * r.compared as f64,
        "{name}: colour off the bound: {r:?}"
    );
    assert!(r.mean_colour < 3e-3, "{name}: mean colour: {r:?}");
    assert!(r.secondary_cpu > 0, "{name}: no secondary rays on the CPU");
    let off = (r.secondary_gpu as f64 - r.secondary_cpu as f64).abs() / r.secondary_cpu as f64;
    assert!(
        off <= SECONDARY_COUNT_OFF,
        "{name}: secondary rays gpu {} cpu {}",
        r.secondary_gpu,
        r.secondary_cpu
    );
    frame
}

fn synthetic_whitted_scenes_match_the_cpu_reference() {
    let gpu = common::gpu("synthetic_whitted_scenes_match_the_cpu_reference");
    for (name, text) in SCENES {
        let scene = scene_of(name, text);
        assert!(fray_gpu::unsupported_feature(&scene).is_none(), "{name}");
        let frame = check(name, &scene, &gpu);
        assert!(
            frame.stats.passes[0].contains("whitted"),
            "{name}: {:?}",
            frame.stats.passes
        );
        let queue = frame
            .stats
            .passes
            .iter()
            .find(|p| p.starts_with("whitted queue"))
            .unwrap_or_else(|| panic!("{name}: {:?}", frame.stats.passes));
        if name.contains("overflows") {
            assert!(!queue.contains(" 2 slots"), "{name}: {queue}");
        }
    }
}

fn whitted_data_scenes_match_the_cpu_reference() {
    let gpu = common::gpu("whitted_data_scenes_match_the_cpu_reference");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes");
    let mut drawn = 0;
    for file in [
        "mesh_bunny_freeform.ron",
        "mesh_aircraft_pair.ron",
        "whitted_glass_mirror.ron",
    ] {
        let mut scene = fray_scene::load(&dir.join(file)).unwrap();
        sized(&mut scene);
        assert!(scene.features.reflection || scene.features.transmission);
        assert!(fray_gpu::unsupported_feature(&scene).is_none(), "{file}");
        check(file, &scene, &gpu);
        drawn += 1;
    }
    assert_eq!(drawn, 3);
}

/// At `max_depth: 0` no secondary ray is traced on either backend, and the frame is the local
/// terms alone: the same as the scene with `kr` and `kt` cleared (bit for bit on the GPU, as
/// the shade pass is then the same arithmetic).
fn depth_zero_traces_nothing_and_is_the_local_frame() {
    let gpu = common::gpu("depth_zero_traces_nothing_and_is_the_local_frame");
    let (name, text) = SCENES[0];
    let mut scene = scene_of(name, text);
    scene.settings.max_depth = 0;
    let settings = GpuSettings::for_scene(&scene);
    let zero = gpu.render(&scene, &settings).unwrap();
    assert_eq!(zero.stats.secondary_rays, 0);
    let mut plain = scene.clone();
    for m in &mut plain.materials {
        m.reflect = fray_core::Rgb::ZERO;
        m.transmit = fray_core::Rgb::ZERO;
    }
    plain.features.reflection = false;
    plain.features.transmission = false;
    let local = gpu.render(&plain, &settings).unwrap();
    assert!(!local.stats.passes[0].contains("whitted"));
    assert_eq!(zero.colour.pixels(), local.colour.pixels());
    assert_eq!(zero.depth.pixels(), local.depth.pixels());
}

/// The queue's slots per camera ray a frame was rendered with (its pass list says).
fn queue_slots(frame: &Frame) -> u32 {
    let line = frame
        .stats
        .passes
        .iter()
        .find(|p| p.starts_with("whitted queue: "))
        .unwrap_or_else(|| panic!("{:?}", frame.stats.passes));
    line["whitted queue: ".len()..]
        .split(' ')
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{line}"))
}

/// The two plates at depth 64 (the full tree would be `2⁶⁵ − 2` rays per camera ray; without a
/// budget the CPU took 19 s at depth 20 on 32 × 24 pixels, and the GPU refused depth 12 after
/// 17 s of growing its queue): with the default budget (256) and with 40, the GPU frame traces
/// at most `budget ×` its camera rays, its queue never holds more than the budget per camera
/// ray, and it is the CPU's frame within the Whitted bounds ([`check`]: the budget binds on
/// both backends by the same rule; measured: the same rays, colour within 6e-8). A smaller
/// budget traces fewer rays. The default's frame takes about 6 s on lavapipe (six queue
/// doublings), 40's about 1 s.
fn a_tree_of_depth_64_is_bounded_by_the_budget_and_matches_the_cpu() {
    let gpu = common::gpu("a_tree_of_depth_64_is_bounded_by_the_budget_and_matches_the_cpu");
    let mut traced = Vec::new();
    for budget in [fray_scene::DEFAULT_MAX_SECONDARY_RAYS, 40] {
        let scene = two_plates(48, 32, 64, budget);
        let name = format!("two plates, depth 64, budget {budget}");
        let frame = check(&name, &scene, &gpu);
        let (rays, camera) = (frame.stats.secondary_rays, frame.stats.primary_rays);
        let slots = queue_slots(&frame);
        eprintln!(
            "{name}: {rays} secondary rays for {camera} camera rays, {slots} queue slots per \
             camera ray, {:.2?}",
            frame.stats.elapsed
        );
        assert_eq!(camera, 48 * 32);
        assert!(rays <= u64::from(budget) * camera, "{name}: {rays}");
        assert!(slots <= budget, "{name}: {slots} slots");
        traced.push(rays);
    }
    assert!(traced[1] < traced[0], "{traced:?}");
}

/// Inside the two shells every tree at depth 4 is full, `2⁵ − 2 = 30` rays. On the GPU too, a
/// budget of 30 never binds — its frame is the largest budget's bit for bit, 30 rays per camera
/// ray — and 29 binds on every camera ray and is spent whole, 29 per camera ray.
fn a_budget_holding_the_full_tree_changes_no_bit() {
    let gpu = common::gpu("a_budget_holding_the_full_tree_changes_no_bit");
    let frame = |budget: u32| {
        let scene = shells(4, budget);
        gpu.render(&scene, &GpuSettings::for_scene(&scene))
            .unwrap_or_else(|e| panic!("budget {budget}: {e}"))
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

fn main() {
    common::run(
        &[
            (
                "synthetic_whitted_scenes_match_the_cpu_reference",
                synthetic_whitted_scenes_match_the_cpu_reference,
            ),
            (
                "whitted_data_scenes_match_the_cpu_reference",
                whitted_data_scenes_match_the_cpu_reference,
            ),
            (
                "depth_zero_traces_nothing_and_is_the_local_frame",
                depth_zero_traces_nothing_and_is_the_local_frame,
            ),
            (
                "a_tree_of_depth_64_is_bounded_by_the_budget_and_matches_the_cpu",
                a_tree_of_depth_64_is_bounded_by_the_budget_and_matches_the_cpu,
            ),
            (
                "a_budget_holding_the_full_tree_changes_no_bit",
                a_budget_holding_the_full_tree_changes_no_bit,
            ),
        ],
        &[],
    );
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
