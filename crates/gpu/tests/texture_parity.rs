//! GPU textures against the CPU reference (`fray_trace::render`, f64):
//! - orientation: a known 2 × 2 image lands the same way round on both backends — on a mesh
//!   quad by its file UVs, on a free form by a planar mapping, draped over a terrain — exact
//!   colours at the quadrants' centres (away from texel boundaries);
//! - frames: nearest, bilinear and trilinear lookups, every wrap mode, each projected mapping, a
//!   mesh's UVs (and a mesh without them: the image's mean), a draped and a ramp-coloured DEM —
//!   per pixel, away from silhouettes and shadow edges, `|Δ| ≤ COLOUR_ABS + COLOUR_REL·|c|` per
//!   channel, the untextured parity bound (`tests/parity.rs`): the f32 texture lookup adds
//!   the uv's f32 error — positions camera-relative, so `2⁻²⁴ · (t + |origin − eye|)` world
//!   units, times the uv per world and the texels per uv: below 10⁻³ of a texel in these scenes
//!   — times the image's contrast between neighbouring texels (≤ 1) for bilinear and
//!   trilinear, and a level-of-detail error of a few f32 ulps of `log₂` (the trilinear blend is
//!   continuous in it). Nearest lookups are discontinuous at texel edges, where that uv error
//!   can pick the neighbouring texel: such **boundary pixels** may differ by the image's
//!   contrast; they are counted and their count bounded (`BOUNDARY_*`);
//! - a receding textured floor (far mip levels): GPU against CPU with the same bounds, and the
//!   trilinear frame reads coarse levels (it differs from the base-level frame far away);
//! - a scene without textures allocates, uploads and compiles none of the texture code; one
//!   past the memory budget is refused before anything is uploaded.

mod common;

use fray_core::{Frame, MemoryBudget};
use fray_gpu::{GpuRenderer, GpuSettings};
use fray_scene::Scene;
use fray_trace::TraceSettings;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// The untextured frame bound (`tests/parity.rs`).
const COLOUR_ABS: f32 = 2e-3;
const COLOUR_REL: f32 = 2e-3;
/// The most pixels (a fraction of those checked) past the bound at texel boundaries: nearest
/// lookups (measured on lavapipe: see the report; bounded with margin), and every other filter
/// (continuous in uv: none measured).
const BOUNDARY_NEAREST: f64 = 0.005;
const BOUNDARY_FILTERED: f64 = 0.001;

fn data(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(path)
        .canonicalize()
        .unwrap()
        .display()
        .to_string()
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fray-gpu-textures-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A quad facing −z at z = 0, 2 × 2, uv `(0, 0)` at its `(+x, −y)` corner and `(k, k)` at the
/// opposite one.
fn quad_obj(dir: &Path, k: f64) -> String {
    let path = dir.join(format!("quad{k}.obj"));
    std::fs::write(
        &path,
        format!(
            "v 1 -1 0\nv -1 -1 0\nv -1 1 0\nv 1 1 0\nvt 0 0\nvt {k} 0\nvt {k} {k}\nvt 0 {k}\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n"
        ),
    )
    .unwrap();
    path.display().to_string()
}

fn parse(text: &str) -> Scene {
    fray_scene::parse(text, "textures.ron").unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn gpu_frame(gpu: &GpuRenderer, scene: &Scene) -> Frame {
    gpu.render(scene, &GpuSettings::for_scene(scene))
        .unwrap_or_else(|e| panic!("{e}"))
}

const EXPECTED: [Vec3; 4] = [Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE];

/// Looking along +z (screen right is −x), no lights, ambient 1: the image's top left shows at
/// the screen's top left on both backends, whichever way the surface gets its coordinates, and
/// the colours at the quadrants' centres are the texels' exactly (1e-6).
fn a_known_image_lands_the_same_way_round() {
    let gpu = common::gpu("a_known_image_lands_the_same_way_round");
    let dir = temp_dir("orientation");
    let png = fray_test_support::images::quadrants_png(&dir, 2);
    let png4 = fray_test_support::images::quadrants_png(&dir, 4);
    let quad = quad_obj(&dir, 1.0);
    let map = dir.join("flat.png");
    image::save_buffer(&map, &[0u8; 16], 4, 4, image::ColorType::L8).unwrap();
    let camera = "Pinhole(eye: (0, 0, -3), look_at: (0, 0, 0), fov_y: 30)";
    let scene = |camera: &str, material: String, shape: String| {
        parse(&format!(
            "Scene(image: (width: 64, height: 64), camera: {camera}, \
             ambient: (1, 1, 1), materials: {{ \"t\": ({material}) }}, \
             objects: [(material: \"t\", shape: {shape})])"
        ))
    };
    let texture = |png: &str, filter: &str, extra: &str| {
        format!("diffuse: (1, 1, 1), texture: (path: {png:?}, filter: {filter}{extra})")
    };
    let mut cases = Vec::new();
    for filter in ["Nearest", "Bilinear"] {
        cases.push((
            format!("mesh uv, {filter}"),
            scene(
                camera,
                texture(&png, filter, ""),
                format!("Mesh(path: {quad:?})"),
            ),
        ));
        cases.push((
            format!("free form, planar, {filter}"),
            scene(
                camera,
                texture(
                    &png,
                    filter,
                    ", mapping: Planar(origin: (1, -1, 0), u_axis: (-1, 0, 0), v_axis: (0, 1, 0), scale: (0.5, 0.5))",
                ),
                "FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 0, -1)), bounds: (min: (-1, -1, 0), max: (1, 1, 0.1)))".into(),
            ),
        ));
    }
    // A 4 × 4 flat map seen from above, north (−z, the map's row 0) up.
    cases.push((
        "terrain drape".into(),
        scene(
            "Parallel(eye: (1.5, 10, 1.5), look_at: (1.5, 0, 1.5), up: (0, 0, -1), height: 3)",
            texture(&png4, "Nearest", ", wrap: Clamp"),
            format!(
                "Terrain(path: {:?}, origin: (0, 5, 0))",
                map.display().to_string()
            ),
        ),
    ));
    for (what, scene) in &cases {
        assert!(fray_gpu::unsupported_feature(scene).is_none());
        let cpu = fray_trace::render(scene, &TraceSettings::for_scene(scene), None).unwrap();
        let g = gpu_frame(&gpu, scene);
        for (k, (x, y)) in [(16, 16), (48, 16), (16, 48), (48, 48)]
            .into_iter()
            .enumerate()
        {
            let (c, gc) = (*cpu.colour.get(x, y), *g.colour.get(x, y));
            if what.contains("Nearest") || what.contains("drape") {
                // Point samples: the texel itself.
                assert!(
                    (c - EXPECTED[k]).abs().max_element() < 1e-6,
                    "{what}: the CPU at ({x}, {y}): {c}"
                );
                assert!(
                    (gc - EXPECTED[k]).abs().max_element() < 1e-6,
                    "{what}: the GPU at ({x}, {y}): {gc}, the CPU {c}"
                );
            } else {
                // Bilinear (the quadrant's centre is not a texel centre in perspective): the
                // CPU's blend, nearest to the quadrant's own texel.
                assert!(
                    (gc - c).abs().max_element() < 1e-4,
                    "{what}: at ({x}, {y}) the GPU {gc}, the CPU {c}"
                );
                let nearest = (0..4)
                    .min_by(|&a, &b| {
                        (gc - EXPECTED[a])
                            .length()
                            .total_cmp(&(gc - EXPECTED[b]).length())
                    })
                    .unwrap();
                assert_eq!(nearest, k, "{what}: at ({x}, {y}) the GPU {gc}");
            }
        }
        assert!(
            g.stats.passes.iter().any(|p| p == "textures")
                && g.stats.passes[0].contains("textures"),
            "{what}: {:?}",
            g.stats.passes
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// What a frame comparison found.
#[derive(Debug, Default)]
struct Report {
    checked: usize,
    /// The largest per-channel difference within the bound.
    max_abs: f32,
    /// Pixels past the bound (texel-boundary pixels) and the largest difference among them.
    boundary: usize,
    max_boundary: f32,
    worst: String,
    /// Pixels left out where the untextured frames already differ past the bound.
    geometry: usize,
}

/// Silhouettes: the hit/miss state changes, or the depth jumps by 5 %, between neighbours.
fn depth_edges(frame: &Frame, w: u32, h: u32) -> Vec<bool> {
    let depth = frame.depth.pixels();
    let mut edges = vec![false; depth.len()];
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let k = (y * i64::from(w) + x) as usize;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= i64::from(w) || ny >= i64::from(h) {
                        continue;
                    }
                    let (a, b) = (depth[k], depth[(ny * i64::from(w) + nx) as usize]);
                    if a.is_finite() != b.is_finite()
                        || (a.is_finite() && (a / b).ln().abs() > 0.05)
                    {
                        edges[k] = true;
                    }
                }
            }
        }
    }
    edges
}

/// `scene` with every texture and ramp taken away.
fn untextured(scene: &Scene) -> Scene {
    let mut plain = scene.clone();
    for m in &mut plain.materials {
        m.texture = None;
        m.ramp = None;
    }
    plain.features.textures = false;
    plain
}

/// Where the backends' frames differ past the bound without textures (f32 geometry: a terrain
/// hit a cell away, a grazing normal): not the textures' to answer for.
fn untextured_mismatch(scene: &Scene, gpu: &GpuRenderer) -> Vec<bool> {
    let plain = untextured(scene);
    let cpu = fray_trace::render(&plain, &TraceSettings::for_scene(&plain), None).unwrap();
    let g = gpu_frame(gpu, &plain);
    cpu.colour
        .pixels()
        .iter()
        .zip(g.colour.pixels())
        .map(|(c, g)| {
            (*g - *c).abs().max_element() > COLOUR_ABS + COLOUR_REL * c.abs().max_element()
        })
        .collect()
}

/// The GPU frame of `scene` against the CPU's: every pixel away from silhouettes and shadow
/// edges (and from where the untextured frames already differ) within the bound, but for at
/// most `boundary` of them (texel boundaries).
fn compare(name: &str, scene: &Scene, gpu: &GpuRenderer, boundary: f64) -> Report {
    compare_frame(name, scene, &gpu_frame(gpu, scene), gpu, boundary)
}

/// [`compare`] for the GPU frame `g` of `scene` (rendered however: a resident scene's view).
fn compare_frame(name: &str, scene: &Scene, g: &Frame, gpu: &GpuRenderer, boundary: f64) -> Report {
    let settings = TraceSettings::for_scene(scene);
    let cpu = fray_trace::render(scene, &settings, None).unwrap();
    let geometry = untextured_mismatch(scene, gpu);
    assert!(
        g.stats.passes.iter().any(|p| p == "textures"),
        "{name}: {:?}",
        g.stats.passes
    );
    let (w, h) = (scene.width, scene.height);
    let edges = depth_edges(&cpu, w, h);
    let shadows = common::shadow_edges(scene, &settings, &cpu);
    let mut r = Report::default();
    for k in 0..(w * h) as usize {
        let (cc, cg) = (cpu.colour.pixels()[k], g.colour.pixels()[k]);
        assert!(cg.is_finite(), "{name}: pixel {k} is {cg}");
        if edges[k] || shadows[k] {
            continue;
        }
        if geometry[k] {
            r.geometry += 1;
            continue;
        }
        r.checked += 1;
        let d = (cg - cc).abs().max_element();
        if d > COLOUR_ABS + COLOUR_REL * cc.abs().max_element() {
            r.boundary += 1;
            if d > r.max_boundary {
                r.max_boundary = d;
                r.worst = format!(
                    "({}, {}) depth {:.3}: cpu {cc} gpu {cg}",
                    k as u32 % w,
                    k as u32 / w,
                    cpu.depth.pixels()[k]
                );
            }
        } else {
            r.max_abs = r.max_abs.max(d);
        }
    }
    eprintln!("{name}: {w}×{h}: {r:?}");
    assert!(
        r.checked * 2 > (w * h) as usize,
        "{name}: too few pixels checked ({})",
        r.checked
    );
    assert!(
        r.boundary as f64 <= boundary * r.checked as f64,
        "{name}: {} of {} pixels past the bound (at most {boundary} of them): worst {}",
        r.boundary,
        r.checked,
        r.worst
    );
    r
}

/// A scene of `objects` with material "t" = `material`, a sun (shadows on) and ambient light,
/// 96 × 64.
fn lit(camera: &str, material: &str, objects: &str) -> Scene {
    parse(&format!(
        "Scene(image: (width: 96, height: 64), camera: {camera}, background: (0.2, 0.3, 0.5), \
         ambient: (0.3, 0.3, 0.3), lights: [Sun(direction: (0.4, 0.8, -0.45), irradiance: (2.5, 2.4, 2.2))], \
         materials: {{ \"t\": ({material}), \"grey\": (diffuse: (0.6, 0.6, 0.6)) }}, objects: [{objects}])"
    ))
}

fn texture(png: &str, filter: &str, wrap: &str, mapping: &str) -> String {
    format!(
        "diffuse: (0.9, 0.9, 0.9), specular: (0.2, 0.2, 0.2), shininess: 20, \
         texture: (path: {png:?}, filter: {filter}, wrap: {wrap}{mapping})"
    )
}

const FLOOR: &str = "(material: \"t\", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)), bounds: (min: (-8, -1, -4), max: (8, 0, 24))))";
const BALL: &str = "(material: \"grey\", shape: Sphere(center: (0.8, 0.6, 1.5), radius: 0.6))";
const FLOOR_CAMERA: &str = "Pinhole(eye: (0.3, 1.6, -2.5), look_at: (0, 0, 2.5), fov_y: 50)";

/// A planar-mapped floor with a ball's shadow on it in every filter and wrap mode (the mapping's
/// origin off the image so that clamp and mirror are read); each projected mapping on free
/// forms; a mesh quad's UVs tiled 3 times, and the bunny without UVs (the image's mean); a DEM
/// draped with a photograph and coloured by a height-and-slope ramp.
fn textured_frames_match_the_cpu() {
    let gpu = common::gpu("textured_frames_match_the_cpu");
    let chelsea = data("textures/chelsea.png");
    let brick = data("textures/brick.png");
    let dir = temp_dir("frames");
    let quad = quad_obj(&dir, 3.0);
    let planar = ", mapping: Planar(origin: (-1.3, 0, -0.7), u_axis: (1, 0, 0), v_axis: (0, 0, 1), scale: (0.45, 0.6))";
    let mut report = Vec::new();
    for filter in ["Nearest", "Bilinear", "Trilinear"] {
        for wrap in ["Repeat", "Clamp", "Mirror"] {
            let name = format!("floor, planar, {filter}, {wrap}");
            let scene = lit(
                FLOOR_CAMERA,
                &texture(&chelsea, filter, wrap, planar),
                &format!("{FLOOR}, {BALL}"),
            );
            let bound = if filter == "Nearest" {
                BOUNDARY_NEAREST
            } else {
                BOUNDARY_FILTERED
            };
            report.push((name.clone(), compare(&name, &scene, &gpu, bound)));
        }
    }
    let object_camera = "Pinhole(eye: (0.4, 1.4, -3.4), look_at: (0, 0.2, 0), fov_y: 45)";
    let mappings = [
        (
            "sphere, spherical, Trilinear, Repeat",
            texture(
                &chelsea,
                "Trilinear",
                "Repeat",
                ", mapping: Spherical(centre: (0, 0.2, 0), pole: (0, 1, 0), seam: (0, 0, -1), repeat: (2, 1))",
            ),
            "(material: \"t\", shape: Sphere(center: (0, 0.2, 0), radius: 1))",
        ),
        (
            "barrel, cylindrical, Bilinear, Mirror",
            texture(
                &chelsea,
                "Bilinear",
                "Mirror",
                ", mapping: Cylindrical(origin: (0, -0.8, 0), axis: (0, 1, 0), seam: (1, 0, 0), repeat: 3, scale: 0.7)",
            ),
            "(material: \"t\", shape: Intersection([FreeForm(base: Cylinder(point: (0, 0, 0), axis: (0, 1, 0), radius: 0.85), bounds: (min: (-1, -0.8, -1), max: (1, 1.1, 1))), Sphere(center: (0, 0.15, 0), radius: 1.12)]))",
        ),
        (
            "rounded box, triplanar, Trilinear, Repeat",
            texture(
                &brick,
                "Trilinear",
                "Repeat",
                ", mapping: Triplanar(origin: (0.1, 0, 0.2), scale: 0.8, sharpness: 4)",
            ),
            "(material: \"t\", shape: Intersection([Sphere(center: (0, 0.2, 0), radius: 1.25), FreeForm(base: Sphere(center: (0, 0.2, 0), radius: 2), bounds: (min: (-0.9, -0.7, -0.9), max: (0.9, 1.1, 0.9)))]))",
        ),
        (
            "mesh quad, uv × 3, Trilinear, Repeat",
            texture(&chelsea, "Trilinear", "Repeat", ""),
            &*format!(
                "(material: \"t\", shape: Mesh(path: {quad:?}, transform: (rotate: (20, 30, 0))))"
            ),
        ),
        (
            "bunny without uvs (the mean), Trilinear",
            texture(&chelsea, "Trilinear", "Repeat", ""),
            &*format!(
                "(material: \"t\", shape: Mesh(path: {:?}, transform: (scale: (8, 8, 8), translate: (0.2, -0.6, 0))))",
                data("meshes/bunny00.obj")
            ),
        ),
    ];
    for (name, material, object) in &mappings {
        let scene = lit(object_camera, material, object);
        report.push((
            name.to_string(),
            compare(name, &scene, &gpu, BOUNDARY_FILTERED),
        ));
    }
    // The DEM (403 × 344 samples, 74 m × 93 m apart), exact level of detail for the drape (the
    // footprint's cosine on a LOD hit's column face is not the CPU's: see ARCHITECTURE), the
    // pixel LOD for the ramp (which reads the shading normal, as the CPU does).
    let dem = data("terrain/jacksboro_fault_dem.png");
    let terrain = |material: &str, lod: &str| {
        parse(&format!(
            "Scene(image: (width: 96, height: 64), \
             camera: Pinhole(eye: (17000, 1250, 30500), look_at: (12000, 650, 14000), fov_y: 45, near: 1), \
             background: (0.45, 0.55, 0.75), ambient: (0.2, 0.2, 0.2), \
             lights: [Sun(direction: (-0.8, 0.45, 0.6), irradiance: (3.2, 3.0, 2.7))], \
             materials: {{ \"land\": ({material}) }}, \
             objects: [(material: \"land\", shape: Terrain(path: {dem:?}, spacing: (74, 93), lod: {lod}))])"
        ))
    };
    let drape = terrain(
        &format!(
            "diffuse: (1, 1, 1), texture: (path: {chelsea:?}, filter: Trilinear, wrap: Clamp)"
        ),
        "Exact",
    );
    report.push((
        "DEM, draped, Trilinear".into(),
        compare("DEM, draped, Trilinear", &drape, &gpu, BOUNDARY_FILTERED),
    ));
    let ramp = terrain(
        "diffuse: (1, 1, 1), ramp: (height: [(250, (0.2, 0.45, 0.15)), (500, (0.55, 0.5, 0.3)), (750, (0.9, 0.9, 0.9))], \
         slope: [(12, (0.35, 0.3, 0.3, 0)), (25, (0.35, 0.3, 0.3, 1))])",
        "Pixel",
    );
    report.push((
        "DEM, height and slope ramp".into(),
        compare("DEM, height and slope ramp", &ramp, &gpu, BOUNDARY_FILTERED),
    ));
    eprintln!(
        "summary (name: max |Δ| within the bound, boundary pixels / checked, their max |Δ|, \
         pixels where the untextured frames differ)"
    );
    for (name, r) in &report {
        eprintln!(
            "  {name}: {:.2e}, {}/{}, {:.3}, {}",
            r.max_abs, r.boundary, r.checked, r.max_boundary, r.geometry
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A brick floor receding to the horizon from 1.2 m up (trilinear: the footprint reaches the
/// coarse levels far away), GPU against CPU with the frame bound; and the GPU's trilinear frame
/// differs from its base-level (bilinear) frame in the far half by far more than the bound —
/// the coarse levels are read.
fn a_receding_floor_reads_the_far_levels_as_the_cpu_does() {
    let gpu = common::gpu("a_receding_floor_reads_the_far_levels_as_the_cpu_does");
    let brick = data("textures/brick.png");
    let scene = |filter: &str| {
        parse(&format!(
            "Scene(image: (width: 128, height: 80), \
             camera: Pinhole(eye: (0, 1.2, 0), look_at: (0, 0.9, 10), fov_y: 40), \
             background: (0, 0, 0), ambient: (1, 1, 1), \
             materials: {{ \"b\": (diffuse: (1, 1, 1), texture: (path: {brick:?}, filter: {filter}, \
             mapping: Planar(u_axis: (1, 0, 0), v_axis: (0, 0, 1), scale: (2, 2)))) }}, \
             objects: [(material: \"b\", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)), \
             bounds: (min: (-400, -1, 0.5), max: (400, 0, 800))))])"
        ))
    };
    let trilinear = scene("Trilinear");
    let r = compare(
        "receding floor, Trilinear",
        &trilinear,
        &gpu,
        BOUNDARY_FILTERED,
    );
    assert!(r.checked > 2000);
    let a = gpu_frame(&gpu, &trilinear);
    let b = gpu_frame(&gpu, &scene("Bilinear"));
    // The far half of the floor: the rows just below the horizon.
    let (w, h) = (trilinear.width, trilinear.height);
    let (mut sum, mut n) = (0.0f64, 0usize);
    for y in 0..h {
        for x in 0..w {
            let t = *a.depth.get(x, y);
            if t.is_finite() && t > 20.0 {
                let d = a.colour.get(x, y) - b.colour.get(x, y);
                sum += f64::from(d.length_squared());
                n += 1;
            }
        }
    }
    let rms = (sum / n.max(1) as f64).sqrt();
    eprintln!("receding floor: {n} far pixels, trilinear vs bilinear RMS {rms:.3}");
    assert!(n > 200 && rms > 0.02, "{n} pixels, RMS {rms}");
}

/// A resident textured scene seen from a moved (and raised) camera: the mapping blocks and the
/// ramp's reference height are rewritten from f64 for it, nothing else of the textures is
/// uploaded, and the frame matches the CPU's from that camera (a planar-mapped floor, trilinear,
/// coloured also by a height ramp about its own height, so a wrong reference shifts it).
fn a_moved_camera_rewrites_the_mappings() {
    let gpu = common::gpu("a_moved_camera_rewrites_the_mappings");
    let chelsea = data("textures/chelsea.png");
    let material = format!(
        "{}, ramp: (height: [(-1, (1, 0.3, 0.3)), (1, (0.3, 1, 0.3))])",
        texture(
            &chelsea,
            "Trilinear",
            "Repeat",
            ", mapping: Planar(origin: (0.4, 0, 0.3), u_axis: (1, 0, 0), v_axis: (0, 0, 1), scale: (0.5, 0.5))",
        )
    );
    let objects = format!("{FLOOR}, {BALL}");
    let scene = lit(FLOOR_CAMERA, &material, &objects);
    let moved = lit(
        "Pinhole(eye: (1.7, 2.6, -1.2), look_at: (0.2, 0, 3.5), fov_y: 50)",
        &material,
        &objects,
    );
    let settings = GpuSettings::for_scene(&scene);
    let mut resident = gpu.upload(&scene, &settings).unwrap();
    let view = fray_gpu::View::of_scene(&scene, settings.samples);
    let first = resident.render(&view).unwrap();
    let r = compare_frame("floor, first view", &scene, &first, &gpu, BOUNDARY_FILTERED);
    assert_eq!(r.boundary, 0);
    let second = resident
        .render(&fray_gpu::View {
            camera: moved.camera,
            ..view
        })
        .unwrap();
    assert_eq!(
        (
            second.stats.scene_uploaded_bytes,
            second.stats.pipelines_built
        ),
        (0, 0)
    );
    let r = compare_frame(
        "floor, moved camera",
        &moved,
        &second,
        &gpu,
        BOUNDARY_FILTERED,
    );
    assert_eq!(r.boundary, 0);
}

/// A scene without textures or ramps allocates, uploads and compiles none of them: the same
/// scene with a texture uploads exactly the texture data's bytes more (every texel of its
/// chain, records and mapping blocks, 16 bytes each, and the layout uniform), and only the
/// textured one is specialised for and names them. A texture past the memory budget is refused
/// (`Budget`, naming the texture data) before anything is uploaded.
fn a_scene_without_textures_builds_none_of_them() {
    let gpu = common::gpu("a_scene_without_textures_builds_none_of_them");
    let chelsea = data("textures/chelsea.png");
    let scene = lit(
        FLOOR_CAMERA,
        &texture(
            &chelsea,
            "Trilinear",
            "Repeat",
            ", mapping: Planar(u_axis: (1, 0, 0), v_axis: (0, 0, 1), scale: (0.5, 0.5))",
        ),
        &format!("{FLOOR}, {BALL}"),
    );
    let mut plain = scene.clone();
    for m in &mut plain.materials {
        m.texture = None;
    }
    plain.features.textures = false;
    let settings = GpuSettings::for_scene(&scene);
    {
        let textured = gpu.upload(&scene, &settings).unwrap();
        let untextured = gpu.upload(&plain, &settings).unwrap();
        let textures = fray_gpu::Feature::Textures;
        assert!(
            textured.specialisation().has(textures) && !untextured.specialisation().has(textures)
        );
    }
    let a = gpu.render(&scene, &settings).unwrap();
    let b = gpu.render(&plain, &settings).unwrap();
    let layout =
        fray_gpu::textures::TextureLayout::build(&scene, &MemoryBudget::default()).unwrap();
    // Chelsea's chain: 451 × 300 down to 1 × 1.
    let chain: u64 = fray_mesh::texture::level_sizes(451, 300)
        .iter()
        .map(|&(w, h)| u64::from(w) * u64::from(h))
        .sum();
    // Each material's mapping block and record (the default one too) and 10 level records.
    let materials = scene.materials.len() as u64 + 1;
    assert_eq!(layout.texels(), chain + materials * (5 + 3) + 10);
    assert_eq!(
        a.stats.scene_uploaded_bytes - b.stats.scene_uploaded_bytes,
        16 * layout.texels() + 32
    );
    assert!(
        !b.stats.passes[0].contains("textures") && !b.stats.passes.iter().any(|p| p == "textures")
    );
    assert!(a.stats.passes[0].contains("textures"));
    // A budget below the texture data: refused before any upload.
    let mut tight = scene.clone();
    tight.budget = MemoryBudget::new(16 * chain / 2);
    match gpu.upload(&tight, &settings) {
        Err(fray_gpu::GpuError::Budget(e)) => {
            assert!(e.to_string().contains("texture data"), "{e}")
        }
        other => panic!("expected Budget, got {:?}", other.err()),
    }
}

fn main() {
    common::run(
        &[
            (
                "a_known_image_lands_the_same_way_round",
                a_known_image_lands_the_same_way_round,
            ),
            (
                "textured_frames_match_the_cpu",
                textured_frames_match_the_cpu,
            ),
            (
                "a_receding_floor_reads_the_far_levels_as_the_cpu_does",
                a_receding_floor_reads_the_far_levels_as_the_cpu_does,
            ),
            (
                "a_moved_camera_rewrites_the_mappings",
                a_moved_camera_rewrites_the_mappings,
            ),
            (
                "a_scene_without_textures_builds_none_of_them",
                a_scene_without_textures_builds_none_of_them,
            ),
        ],
        &[],
    )
}
