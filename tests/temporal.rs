//! Temporal stability: a slow fly-by over the DEM and into the cloud layer changes from frame to
//! frame only as much as the motion does. The reference for "the motion" is the same fly-by
//! rendered without the approximation under test — the terrain at its exact finest level (no LOD
//! to pop), the clouds marched in steps four times finer (jitter and banding four times smaller)
//! —, the brick floor with 16 samples per pixel (its aliasing four times smaller) — so a pop, a
//! crawling pattern or a shimmer shows as change the reference does not have.

use fray_render::output::{PngOptions, srgb8};
use fray_render::{Backend, RenderOptions, Renderer};
use std::path::Path;

const FRAMES: u32 = 10;
const WIDTH: u32 = 160;

/// The frames of `scene` (an animated scene text), as 8-bit sRGB.
fn frames(scene: &str) -> Vec<Vec<[u8; 3]>> {
    let scene = fray_scene::parse_with(
        scene,
        "flyby.ron",
        &fray_scene::BuildOptions::within(fray_core::MemoryBudget::default()),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let renderer = Renderer::new(RenderOptions {
        backend: Backend::Cpu,
        width: Some(WIDTH),
        ..RenderOptions::default()
    });
    (0..FRAMES)
        .map(|n| {
            let frame = renderer.render(&scene.at_frame(n).unwrap()).unwrap();
            srgb8(&frame, &PngOptions::default()).into_pixels()
        })
        .collect()
}

/// Per pair of consecutive frames: the mean absolute change of a channel (of 255), and the
/// fraction of pixels where some channel changed by more than 24/255 (a visible jump).
fn changes(frames: &[Vec<[u8; 3]>]) -> Vec<(f64, f64)> {
    frames
        .windows(2)
        .map(|w| {
            let (mut sum, mut jumps) = (0u64, 0usize);
            for (a, b) in w[0].iter().zip(&w[1]) {
                let d: Vec<u8> = (0..3).map(|c| a[c].abs_diff(b[c])).collect();
                sum += d.iter().map(|&x| u64::from(x)).sum::<u64>();
                jumps += usize::from(d.iter().any(|&x| x > 24));
            }
            let n = w[0].len();
            (sum as f64 / (3 * n) as f64, jumps as f64 / n as f64)
        })
        .collect()
}

/// Asserts that `tested`'s frame-to-frame changes stay within the reference's: the mean change
/// at most `1.5 ×` the reference's plus `margin` (of 255), the share of pixels that jump at most
/// `1.5 ×` plus 0.2 %, and no pair above twice the reference's largest plus `margin` (a spike).
/// Prints every pair's figures (`--nocapture`).
#[track_caller]
fn assert_stable(what: &str, tested: &[(f64, f64)], reference: &[(f64, f64)], margin: f64) {
    for (k, (t, r)) in tested.iter().zip(reference).enumerate() {
        eprintln!(
            "{what}, frames {k}→{}: mean change {:.3} (reference {:.3}); jumps {:.4} ({:.4})",
            k + 1,
            t.0,
            r.0,
            t.1,
            r.1
        );
    }
    let mean = |v: &[(f64, f64)], pick: fn(&(f64, f64)) -> f64| {
        v.iter().map(pick).sum::<f64>() / v.len() as f64
    };
    let (tm, rm) = (mean(tested, |x| x.0), mean(reference, |x| x.0));
    assert!(
        tm <= 1.5 * rm + margin,
        "{what}: mean change {tm:.3} against {rm:.3}"
    );
    let (tj, rj) = (mean(tested, |x| x.1), mean(reference, |x| x.1));
    assert!(
        tj <= 1.5 * rj + 0.002,
        "{what}: visible jumps {tj:.4} against {rj:.4}"
    );
    let worst = reference.iter().map(|x| x.0).fold(0.0, f64::max);
    for (k, t) in tested.iter().enumerate() {
        assert!(
            t.0 <= 2.0 * worst + margin,
            "{what}, frames {k}→{}: a spike of {:.3} (the reference at most {worst:.3})",
            k + 1,
            t.0
        );
    }
}

fn dem() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/terrain/jacksboro_fault_dem.png")
        .display()
        .to_string()
}

/// The fly-by over the DEM (terrain_low's view, the camera gliding 30 m a frame toward the
/// ridges 2–17 km away): `lod` is `Pixel` or `Exact`.
fn terrain_flyby(lod: &str) -> String {
    format!(
        r#"Scene(
  image: (width: 640, height: 360),
  camera: Pinhole(eye: (17000, 1250, 30500), look_at: (12000, 650, 14000), fov_y: 45, near: 1),
  background: (0.45, 0.55, 0.75),
  ambient: (0.10, 0.11, 0.13),
  lights: [Sun(direction: (-0.8, 0.45, 0.6), irradiance: (3.2, 3.0, 2.7))],
  materials: {{"land": (diffuse: (0.42, 0.40, 0.30))}},
  objects: [(name: "dem", material: "land", shape: Terrain(path: "{}", spacing: (74, 93), lod: {lod}))],
  animation: Some((fps: 10, camera: Some((interpolation: Linear, keys: [
    (time: 0, eye: (17000, 1250, 30500), look_at: (12000, 650, 14000)),
    (time: 1, eye: (16910, 1240, 30200), look_at: (11910, 640, 13700)),
  ])))),
)"#,
        dem()
    )
}

/// No terrain LOD popping: with the pixel level of detail the frames change no more than the
/// exact surface's frames do under the same motion — on average per frame (1.5× the exact
/// change, plus 0.5/255 for the levels' own coarser shading), with no frame pair spiking, and
/// with visible jumps on at most 1.5× as many pixels plus 0.2 % of the frame.
#[test]
fn terrain_lod_does_not_pop_in_a_slow_flyby() {
    let exact = changes(&frames(&terrain_flyby("Exact")));
    let pixel = changes(&frames(&terrain_flyby("Pixel")));
    assert_stable("pixel LOD against the exact surface", &pixel, &exact, 0.5);
}

/// Into the cloud layer: the camera flies 6 m a frame along the turboprop's course into the
/// layer's base. `step` is the march's step in metres.
fn cloud_flyby(step: f64) -> String {
    format!(
        r#"Scene(
  image: (width: 640, height: 360),
  camera: Pinhole(eye: (-60, 10, -40), look_at: (200, 60, 0), fov_y: 45, near: 0.1),
  ambient: (0.22, 0.25, 0.31),
  lights: [Sun(direction: (0.5, 0.62, -0.6), irradiance: (3.4, 3.3, 3.1))],
  materials: {{"land": (diffuse: (0.40, 0.38, 0.29))}},
  atmosphere: (sky: (haze: 2, steps: 12)),
  clouds: (
    region: (min: (-3000, -20, -3000), max: (3000, 320, 3000)),
    density: Layer((resolution: (192, 16, 192), feature_size: 700, octaves: 5, seed: 11,
                    coverage: 0.5, threshold: 0.08, profile: Cumulus)),
    scattering: 0.12, absorption: 0.0002, step: {step}, sun_steps: 6, ambient: 2.0,
  ),
  objects: [(name: "dem", material: "land", shape: Terrain(path: "{}", spacing: (74, 93),
             origin: (-15000, -1500, -16000), lod: Pixel))],
  animation: Some((fps: 10, camera: Some((interpolation: Linear, keys: [
    (time: 0, eye: (-60, 10, -40), look_at: (200, 60, 0)),
    (time: 1, eye: (0, 20, -35), look_at: (260, 70, 5)),
  ])))),
)"#,
        dem()
    )
}

/// The cloud march's jitter does not crawl: it is fixed to the pixel, so flying through the layer
/// the frames change no more than with steps four times finer (where the jitter's pattern is four
/// times weaker) — 1.5× on average plus 0.5/255 — and no pair spikes.
#[test]
fn cloud_jitter_does_not_crawl_when_flying_into_the_layer() {
    let fine = changes(&frames(&cloud_flyby(4.0)));
    let coarse = changes(&frames(&cloud_flyby(16.0)));
    assert_stable("16 m steps against 4 m", &coarse, &fine, 0.5);
}

/// Low over a brick floor that runs to the horizon (the texture minified 100× and more), the
/// camera gliding 3 cm a frame: `samples` per pixel.
fn texture_flyby(samples: u32) -> String {
    let bricks = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/textures/brick.png")
        .display()
        .to_string();
    format!(
        r#"Scene(
  image: (width: 640, height: 360),
  camera: Pinhole(eye: (0, 1.2, -6), look_at: (0, 0.4, 10), fov_y: 50, near: 0.05),
  background: (0.45, 0.55, 0.75),
  ambient: (0.2, 0.2, 0.2),
  lights: [Sun(direction: (0.3, 0.8, -0.5), irradiance: (3, 3, 3))],
  materials: {{"bricks": (diffuse: (0.85, 0.55, 0.42),
    texture: (path: "{bricks}", mapping: Planar(u_axis: (1, 0, 0), v_axis: (0, 0, 1), scale: (0.8, 0.8))))}},
  objects: [(name: "floor", material: "bricks", shape: FreeForm(
    base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
    bounds: (min: (-400, -1, -20), max: (400, 0, 800))))],
  settings: (samples: {samples}, shadows: false),
  animation: Some((fps: 10, camera: Some((interpolation: Linear, keys: [
    (time: 0, eye: (0, 1.2, -6), look_at: (0, 0.4, 10)),
    (time: 1, eye: (0.1, 1.2, -5.7), look_at: (0.1, 0.4, 10.3)),
  ])))),
)"#
    )
}

/// Textures do not shimmer: the mipmapped bricks seen to the horizon change from frame to frame
/// no more than with 16 samples per pixel — 1.5× on average plus 0.1/255 (the motion changes
/// this frame by only ~0.2/255 on average, so the margin is tighter than the others') — and no
/// pair spikes.
#[test]
fn textures_do_not_shimmer_in_a_slow_flyby() {
    let reference = changes(&frames(&texture_flyby(16)));
    let one = changes(&frames(&texture_flyby(1)));
    assert_stable("1 sample against 16", &one, &reference, 0.1);
}
