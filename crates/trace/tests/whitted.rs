//! Whitted ray tracing, known answers: a mirror sphere reflects the analytic direction, a glass
//! slab shifts a ray by the analytic offset `h sin(θ − θₜ)/cos θₜ`, shadow rays through glass keep
//! `kt` per surface; and offsets that leave no acne or gaps: on mirror and glass spheres (free
//! form and mesh) and thin slabs against a uniform background every hit pixel is exactly the
//! background times the weights of its path. Depth and contribution limits cut where they say.

mod common;

use fray_core::{Interval, Ray};
use fray_scene::Scene;
use fray_trace::{Integrator, TraceContext, TraceSettings, render};
use glam::DVec3;
use std::fmt::Write as _;

fn parse(text: &str) -> Scene {
    fray_scene::parse(text, "whitted.ron").unwrap_or_else(|e| panic!("{e}"))
}

/// An axis-aligned box as an OBJ file (12 triangles, counter-clockwise from outside).
fn box_obj(dir: &std::path::Path, name: &str, min: DVec3, max: DVec3) -> String {
    let mut text = String::new();
    for k in 0..8 {
        let p = DVec3::new(
            if k & 1 == 0 { min.x } else { max.x },
            if k & 2 == 0 { min.y } else { max.y },
            if k & 4 == 0 { min.z } else { max.z },
        );
        writeln!(text, "v {} {} {}", p.x, p.y, p.z).unwrap();
    }
    // Faces as quads (1-based), outward: −x, +x, −y, +y, −z, +z.
    for [a, b, c, d] in [
        [1, 5, 7, 3],
        [2, 4, 8, 6],
        [1, 2, 6, 5],
        [3, 7, 8, 4],
        [1, 3, 4, 2],
        [5, 6, 8, 7],
    ] {
        writeln!(text, "f {a} {b} {c}\nf {a} {c} {d}").unwrap();
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// A unit icosphere subdivided `levels` times, as an OBJ file (closed, outward).
fn icosphere_obj(dir: &std::path::Path, name: &str, levels: u32) -> String {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut midpoint = |a: usize, b: usize, v: &mut Vec<DVec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push(((v[a] + v[b]) * 0.5).normalize());
                v.len() - 1
            })
        };
        let mut next = Vec::with_capacity(f.len() * 4);
        for [a, b, c] in f {
            let (ab, bc, ca) = (
                midpoint(a, b, &mut v),
                midpoint(b, c, &mut v),
                midpoint(c, a, &mut v),
            );
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    let mut text = String::new();
    for p in &v {
        writeln!(text, "v {} {} {}", p.x, p.y, p.z).unwrap();
    }
    for [a, b, c] in &f {
        writeln!(text, "f {} {} {}", a + 1, b + 1, c + 1).unwrap();
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

const BLACK: &str = "diffuse: (0, 0, 0), ambient: (0, 0, 0), specular: (0, 0, 0)";

/// A lit, shadowless backdrop whose radiance varies across it: a diffuse floor and a big
/// diffuse ball under a point light. `extra` adds objects.
fn backdrop(extra: &str, materials: &str) -> String {
    format!(
        "Scene(image: (width: 16, height: 16), \
         camera: Pinhole(eye: (0, 0, -5), look_at: (0, 0, 0)), \
         background: (0.2, 0.3, 0.4), ambient: (0.05, 0.05, 0.05), \
         lights: [Point(position: (3, 6, -4), intensity: (40, 35, 30))], \
         materials: {{ \"floor\": (diffuse: (0.7, 0.6, 0.5)), \"ball\": (diffuse: (0.2, 0.5, 0.8)) {materials} }}, \
         objects: [ \
           (material: \"floor\", shape: FreeForm(base: HalfSpace(point: (0, -2, 0), normal: (0, 1, 0)), \
              bounds: (min: (-40, -3, -40), max: (40, -2, 40)))), \
           (material: \"ball\", shape: Sphere(center: (0, 1, 9), radius: 3)) {extra} ], \
         settings: (shadows: false, max_depth: 8, epsilon: 1e-10))"
    )
}

fn radiance(scene: &Scene, ray: &Ray) -> DVec3 {
    let integrator = Integrator::new(scene, &TraceSettings::for_scene(scene));
    let mut ctx = TraceContext::default();
    integrator.radiance(&mut ctx, ray, Interval::new(0.0, f64::INFINITY))
}

fn close(a: DVec3, b: DVec3, rel: f64) -> bool {
    (a - b).abs().max_element() <= rel * b.abs().max_element().max(1e-3)
}

/// A mirror ball (kr = 0.8, no local terms) sends each camera ray along `d − 2(d·n)n` from the
/// analytic hit point: its radiance is `0.8 ×` the radiance of that ray in the scene without the
/// ball, to 1e-6 (ε = 1e-10: the secondary ray starts `10³ ε` off the surface, which moves what
/// it sees by ~1e-7 of the scene).
#[test]
fn a_mirror_sphere_reflects_the_analytic_direction() {
    let with = parse(&backdrop(
        ", (material: \"mirror\", shape: Sphere(center: (0, 0, 0), radius: 1))",
        &format!(", \"mirror\": ({BLACK}, reflect: (0.8, 0.8, 0.8))"),
    ));
    let without = parse(&backdrop("", ""));
    let mut checked = 0;
    for i in 0..9 {
        for j in 0..9 {
            let (x, y) = (-0.8 + 0.2 * f64::from(i), -0.8 + 0.2 * f64::from(j));
            if x * x + y * y > 0.81 {
                continue;
            }
            let ray = Ray::new(DVec3::new(x, y, -5.0), DVec3::Z).unwrap();
            let p = DVec3::new(x, y, -(1.0 - x * x - y * y).sqrt());
            let n = p;
            let r = ray.dir - n * (2.0 * ray.dir.dot(n));
            // Materials hold f32 reflectances.
            let expected = radiance(&without, &Ray::new(p, r).unwrap()) * f64::from(0.8f32);
            let got = radiance(&with, &ray);
            assert!(
                close(got, expected, 1e-6),
                "({x}, {y}): {got} vs {expected}"
            );
            checked += 1;
        }
    }
    assert!(checked > 40);
}

/// A glass slab (index 1.5, kt = 1, no Fresnel) of thickness `h` shifts a ray at incidence θ
/// sideways by `h sin(θ − θₜ)/cos θₜ` and leaves its direction unchanged: the radiance through
/// it equals, to 1e-6, the radiance of the shifted ray in the scene without the slab — for a
/// free-form slab of two half-spaces, one cut by its box (the exit through the box face), and a
/// mesh box.
#[test]
fn a_glass_slab_shifts_a_ray_by_the_analytic_offset() {
    let h = 0.5;
    let dir = common::temp_dir("whitted", "slab");
    let mesh = box_obj(
        &dir,
        "slab.obj",
        DVec3::new(-20.0, -20.0, 0.0),
        DVec3::new(20.0, 20.0, h),
    );
    let slabs = [
        (
            "two half-spaces",
            format!(
                ", (material: \"glass\", shape: Intersection([ \
                   FreeForm(base: HalfSpace(point: (0, 0, {h}), normal: (0, 0, 1)), bounds: (min: (-20, -20, -1), max: (20, 20, 2))), \
                   FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 0, -1)), bounds: (min: (-20, -20, -1), max: (20, 20, 2)))]))"
            ),
        ),
        (
            "a half-space cut by its box",
            format!(
                ", (material: \"glass\", shape: FreeForm(base: HalfSpace(point: (0, 0, {h}), normal: (0, 0, 1)), \
                   bounds: (min: (-20, -20, 0), max: (20, 20, {h}))))"
            ),
        ),
        (
            "a mesh box",
            format!(", (material: \"glass\", shape: Mesh(path: {mesh:?}, smooth: false))"),
        ),
    ];
    let without = parse(&backdrop("", ""));
    let glass = format!(", \"glass\": ({BLACK}, transmit: (1, 1, 1), ior: 1.5)");
    for (what, slab) in &slabs {
        let with = parse(&backdrop(slab, &glass));
        for deg in [0.0f64, 10.0, 25.0, 40.0] {
            for phi in [0.0f64, 90.0, 200.0] {
                let (theta, phi) = (deg.to_radians(), phi.to_radians());
                let d = DVec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                );
                let o = DVec3::new(0.1, 0.2, -2.0);
                let ray = Ray::new(o, d).unwrap();
                // Entry, the refracted ray's angle, the exit.
                let p1 = o + d * (-o.z / d.z);
                let theta_t = (theta.sin() / 1.5).asin();
                let across = DVec3::new(phi.cos(), phi.sin(), 0.0);
                let p2 = p1 + across * (h * theta_t.tan()) + DVec3::Z * h;
                // The exit lies off the undeviated line by the analytic offset.
                let off_line = (p2 - o).cross(d).length();
                let shift = h * (theta - theta_t).sin() / theta_t.cos();
                assert!((off_line - shift).abs() < 1e-12, "{off_line} vs {shift}");
                let expected = radiance(&without, &Ray::new(p2, d).unwrap());
                let got = radiance(&with, &ray);
                assert!(
                    close(got, expected, 1e-6),
                    "{what}, θ = {deg}°: {got} vs {expected}"
                );
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A uniform background `B`, no lights, no ambient: a pixel that sees a mirror shows `kr·B` after
/// exactly one secondary ray, a glass object `kt²·B` after exactly two (in and out), to the f32
/// frame's rounding (1e-6) — a self-intersection (acne) would add a bounce (another factor and
/// another ray), a gap would let the ray through unweighted. Curved (spheres: free form, and a
/// faceted mesh) and thin (slabs 1e-4 thick, free form and mesh) geometry, every pixel of a
/// 64 × 64 frame. The mesh balls are clear (index 1): a mesh sphere's facets are not a sphere, so
/// in glass a ray entering near the silhouette meets the inside past the critical angle and may
/// run round it by total internal reflection (a whispering gallery of more than 64 bounces was
/// seen), which no count would predict; at index 1 every ray crosses exactly twice.
#[test]
fn offsets_leave_no_acne_or_gaps_on_thin_and_curved_geometry() {
    let dir = common::temp_dir("whitted", "acne");
    let sphere = icosphere_obj(&dir, "sphere.obj", 3);
    let thin = box_obj(
        &dir,
        "thin.obj",
        DVec3::new(-1.5, -1.5, 0.0),
        DVec3::new(1.5, 1.5, 1e-4),
    );
    let free_thin = "Intersection([ \
        FreeForm(base: HalfSpace(point: (0, 0, 0.0001), normal: (0, 0, 1)), bounds: (min: (-1.5, -1.5, -1), max: (1.5, 1.5, 1))), \
        FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 0, -1)), bounds: (min: (-1.5, -1.5, -1), max: (1.5, 1.5, 1)))])";
    // The weights as the f32 materials hold them.
    let kr = f64::from(0.7f32);
    let kt = f64::from(0.9f32);
    // (what, material, shape, secondary rays per hit pixel).
    let cases = [
        ("mirror ball", "mirror", "Sphere(radius: 1)".to_owned(), 1),
        ("glass ball", "glass", "Sphere(radius: 1)".to_owned(), 2),
        (
            "mirror mesh ball",
            "mirror",
            format!("Mesh(path: {sphere:?})"),
            1,
        ),
        (
            "clear faceted mesh ball",
            "clear",
            format!("Mesh(path: {sphere:?}, smooth: false)"),
            2,
        ),
        (
            "clear smooth mesh ball",
            "clear",
            format!("Mesh(path: {sphere:?})"),
            2,
        ),
        ("thin glass slab", "glass", free_thin.to_owned(), 2),
        (
            "thin glass mesh slab",
            "glass",
            format!("Mesh(path: {thin:?}, smooth: false)"),
            2,
        ),
        (
            "thin mirror mesh slab",
            "mirror",
            format!("Mesh(path: {thin:?}, smooth: false)"),
            1,
        ),
    ];
    for (what, material, shape, rays) in cases {
        let scene = parse(&format!(
            "Scene(image: (width: 64, height: 64), \
             camera: Pinhole(eye: (0.3, 0.4, -3), look_at: (0, 0, 0), fov_y: 50), \
             background: (0.25, 0.5, 1.0), ambient: (0, 0, 0), \
             materials: {{ \"mirror\": ({BLACK}, reflect: (0.7, 0.7, 0.7)), \
                           \"glass\": ({BLACK}, transmit: (0.9, 0.9, 0.9), ior: 1.5), \
                           \"clear\": ({BLACK}, transmit: (0.9, 0.9, 0.9), ior: 1.0) }}, \
             objects: [(material: \"{material}\", shape: {shape})], \
             settings: (max_depth: 64, min_contribution: 0))"
        ));
        let frame = render(&scene, &TraceSettings::for_scene(&scene), None).unwrap();
        let background = fray_core::Rgb::new(0.25, 0.5, 1.0).as_dvec3();
        let mut hits = 0;
        for y in 0..64 {
            for x in 0..64 {
                let c = frame.colour.get(x, y).as_dvec3();
                if !frame.depth.get(x, y).is_finite() {
                    assert!(
                        (c - background).abs().max_element() < 1e-6,
                        "{what}: ({x}, {y})"
                    );
                    continue;
                }
                hits += 1;
                let matches = |w: f64| (c - background * w).abs().max_element() < 1e-6;
                let ok = if material == "mirror" {
                    matches(kr)
                } else {
                    matches(kt * kt)
                };
                assert!(ok, "{what}: pixel ({x}, {y}) is {c}");
            }
        }
        assert!(hits > 400, "{what}: {hits} hits");
        assert_eq!(frame.stats.secondary_rays, rays * hits, "{what}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A sun straight above a glass ball (kt = 0.6 per channel, red 0.5) over a diffuse floor: the
/// floor point under the ball's centre gets the sun's irradiance times `kt²` (two surfaces
/// crossed), to the f32 rounding of the product (1e-7); a glass mesh box likewise; an opaque ball blocks it all.
#[test]
fn shadow_rays_through_glass_keep_kt_per_surface() {
    let dir = common::temp_dir("whitted", "shadow");
    let cube = box_obj(
        &dir,
        "cube.obj",
        DVec3::new(-0.5, 0.5, -0.5),
        DVec3::new(0.5, 1.5, 0.5),
    );
    let kt = fray_core::Rgb::new(0.5, 0.6, 0.6).as_dvec3();
    for (shape, material, factor) in [
        ("Sphere(center: (0, 1, 0), radius: 0.5)", "glass", kt * kt),
        (
            &format!("Mesh(path: {cube:?}, smooth: false)") as &str,
            "glass",
            kt * kt,
        ),
        (
            "Sphere(center: (0, 1, 0), radius: 0.5)",
            "stone",
            DVec3::ZERO,
        ),
    ] {
        let scene = parse(&format!(
            "Scene(camera: Pinhole(eye: (0, 3, -3), look_at: (0, 0, 0)), ambient: (0, 0, 0), \
             lights: [Sun(direction: (0, 1, 0), irradiance: (3, 3, 3))], \
             materials: {{ \"floor\": (diffuse: (0.5, 0.5, 0.5)), \
                           \"glass\": ({BLACK}, transmit: (0.5, 0.6, 0.6), ior: 1.5), \
                           \"stone\": (diffuse: (0.5, 0.5, 0.5)) }}, \
             objects: [ \
               (material: \"floor\", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)), \
                  bounds: (min: (-5, -1, -5), max: (5, 0, 5)))), \
               (material: \"{material}\", shape: {shape})])"
        ));
        // Straight down onto the floor from under the ball: the camera ray sees only the floor.
        let ray = Ray::new(DVec3::new(0.0, 0.2, 0.0), -DVec3::Y).unwrap();
        let got = radiance(&scene, &ray);
        let lit = DVec3::splat(f64::from(0.5f32) / std::f64::consts::PI * 3.0);
        let expected = lit * factor;
        // The product of f32 transmittances: to f32 rounding.
        assert!(
            (got - expected).abs().max_element() < 1e-7,
            "{shape}: {got} vs {expected}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `max_depth: 0` traces no secondary ray (a black mirror), 1 one bounce; a weight below
/// `min_contribution` is not traced, above it is.
#[test]
fn depth_and_contribution_limits_cut_where_they_say() {
    let scene = |kr: f64, depth: u32, cut: f64| {
        parse(&format!(
            "Scene(image: (width: 8, height: 8), camera: Pinhole(eye: (0, 0, -3), look_at: (0, 0, 0)), \
             background: (1, 1, 1), ambient: (0, 0, 0), \
             materials: {{ \"m\": ({BLACK}, reflect: ({kr}, {kr}, {kr})) }}, \
             objects: [(material: \"m\", shape: Sphere(radius: 1))], \
             settings: (max_depth: {depth}, min_contribution: {cut}))"
        ))
    };
    let ray = Ray::new(DVec3::new(0.1, 0.2, -3.0), DVec3::Z).unwrap();
    assert_eq!(radiance(&scene(0.5, 0, 0.0), &ray), DVec3::ZERO);
    assert_eq!(radiance(&scene(0.5, 1, 0.0), &ray), DVec3::splat(0.5));
    assert_eq!(radiance(&scene(0.01, 5, 0.02), &ray), DVec3::ZERO);
    assert_eq!(
        radiance(&scene(0.01, 5, 0.005), &ray),
        DVec3::splat(f64::from(0.01f32))
    );
    let frame = render(
        &scene(0.5, 1, 0.0),
        &TraceSettings::for_scene(&scene(0.5, 1, 0.0)),
        None,
    )
    .unwrap();
    let hits = (0..8)
        .flat_map(|y| (0..8).map(move |x| (x, y)))
        .filter(|&(x, y)| frame.depth.get(x, y).is_finite())
        .count() as u64;
    assert_eq!(
        frame.stats.secondary_rays, hits,
        "one reflection per hit pixel"
    );
}

/// Total internal reflection occurs exactly past the critical angle, end to end: a right-angle
/// glass prism (black, `kt = 0.9`, no Fresnel) under a uniform background; a ray entering its
/// long face square-on meets a short face at 45°. With `n = 1.4143` (critical angle 44.9985°) it
/// reflects totally twice and leaves back through the long face: `kt⁴·B` (four weighted events);
/// with `n = 1.4142` (critical 45.0003°) it refracts out, grazing: `kt²·B`.
#[test]
fn a_prism_reflects_totally_exactly_past_the_critical_angle() {
    let b = fray_core::Rgb::new(0.25, 0.5, 1.0).as_dvec3();
    let kt = f64::from(0.9f32);
    // The indices as the scene text gives them (1.4142 is √2 rounded down: just below TIR).
    for (ior, expected) in [("1.4143", b * kt.powi(4)), ("1.4142", b * kt * kt)] {
        let scene = parse(&format!(
            "Scene(camera: Pinhole(eye: (0, -3, -3), look_at: (0, 0, 0)), \
             background: (0.25, 0.5, 1.0), ambient: (0, 0, 0), \
             materials: {{ \"glass\": ({BLACK}, transmit: (0.9, 0.9, 0.9), ior: {ior}) }}, \
             objects: [(material: \"glass\", shape: Intersection([ \
               FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, -1, 0)), bounds: (min: (-1.5, -0.5, -1), max: (1.5, 1.5, 1))), \
               FreeForm(base: HalfSpace(point: (-1, 0, 0), normal: (-1, 1, 0)), bounds: (min: (-1.5, -0.5, -1), max: (1.5, 1.5, 1))), \
               FreeForm(base: HalfSpace(point: (1, 0, 0), normal: (1, 1, 0)), bounds: (min: (-1.5, -0.5, -1), max: (1.5, 1.5, 1)))]))], \
             settings: (max_depth: 8, min_contribution: 0))"
        ));
        let ray = Ray::new(DVec3::new(0.5, -2.0, 0.0), DVec3::Y).unwrap();
        let got = radiance(&scene, &ray);
        assert!(
            (got - expected).abs().max_element() < 1e-6,
            "n = {ior}: {got} vs {expected}"
        );
    }
}

/// A mirroring instance (scale −1 on x) reverses its triangles' winding; its normals must still
/// point out: the icosphere is symmetric under x → −x, so mirrored and plain instances shade the
/// same (smooth and faceted), to 1e-5 — a normal turned inward would shade it black or faceted.
#[test]
fn mirrored_instances_keep_outward_normals() {
    let dir = common::temp_dir("whitted", "mirrored");
    let sphere = icosphere_obj(&dir, "sphere.obj", 2);
    for smooth in [true, false] {
        let frame = |scale: &str| {
            let s = parse(&format!(
                "Scene(image: (width: 48, height: 48), camera: Pinhole(eye: (0, 0, -3), look_at: (0, 0, 0)), \
                 ambient: (0.1, 0.1, 0.1), lights: [Sun(direction: (0.3, 0.8, -0.5), irradiance: (3, 3, 3))], \
                 objects: [(shape: Mesh(path: {sphere:?}, smooth: {smooth}, transform: (scale: {scale})))])"
            ));
            render(&s, &TraceSettings::for_scene(&s), None).unwrap()
        };
        let (plain, mirrored) = (frame("(1, 1, 1)"), frame("(-1, 1, 1)"));
        let mut lit = 0;
        for (a, b) in plain.colour.pixels().iter().zip(mirrored.colour.pixels()) {
            assert!(
                (*a - *b).abs().max_element() < 1e-5,
                "smooth {smooth}: {a} vs {b}"
            );
            lit += usize::from(a.max_element() > 0.2);
        }
        assert!(lit > 200, "smooth {smooth}: {lit} lit pixels");
    }
    std::fs::remove_dir_all(&dir).ok();
}
