//! Scene files end to end: defaults, every variant, the feature set, located errors, and that
//! no input makes the loader panic.

use fray_core::Projector;
use fray_scene::{FeatureSet, Light, Material, SceneError, load, parse};
use glam::DVec3;
use std::f64::consts::PI;

fn ok(src: &str) -> fray_scene::Scene {
    match parse(src, "test.ron") {
        Ok(s) => s,
        Err(e) => panic!("expected the scene to parse, got: {e}"),
    }
}

fn err(src: &str) -> SceneError {
    match parse(src, "test.ron") {
        Ok(_) => panic!("expected an error for:\n{src}"),
        Err(e) => e,
    }
}

/// Asserts an `Invalid` error at `line` about `field`, and returns its message.
#[track_caller]
fn invalid(src: &str, line: usize, field: &str) -> String {
    let e = err(src);
    match &e {
        SceneError::Invalid {
            file,
            line: l,
            field: f,
            message,
            ..
        } => {
            assert_eq!(
                (file.as_str(), *l, f.as_str()),
                ("test.ron", line, field),
                "{e}"
            );
            assert!(
                e.to_string().starts_with(&format!("test.ron:{line}:")),
                "{e}"
            );
            message.clone()
        }
        other => panic!("expected an Invalid error, got {other:?}"),
    }
}

#[test]
fn minimal_scene_takes_every_default() {
    let s = ok("(objects: [(shape: Sphere(radius: 1))])");
    assert_eq!((s.width, s.height), (640, 480));
    let Projector::Pinhole(p) = s.camera else {
        panic!("default camera is a pinhole")
    };
    assert_eq!(p.eye, DVec3::new(0.0, 1.0, -5.0));
    assert!((p.tan_half_fov_y - (22.5f64).to_radians().tan()).abs() < 1e-15);
    assert_eq!(p.near, 0.01);
    assert_eq!(s.background, glam::Vec3::new(0.05, 0.05, 0.08));
    assert_eq!(s.ambient, glam::Vec3::splat(0.03));
    assert!(s.lights.is_empty());
    assert_eq!(s.materials, vec![Material::default()]);
    assert_eq!(s.objects.len(), 1);
    assert_eq!(s.objects[0].name, "object0");
    assert_eq!(s.objects[0].leaf_materials, vec![0]);
    assert_eq!(s.settings, fray_scene::Settings::default());
    assert_eq!(
        s.features,
        FeatureSet {
            free_forms: true,
            ..FeatureSet::default()
        }
    );
    let b = s.objects[0].solid.bounds();
    assert!(
        b.contains(DVec3::splat(-1.0)) && b.contains(DVec3::ONE),
        "{b:?}"
    );
    assert!(
        !b.contains(DVec3::splat(-1.01)) && !b.contains(DVec3::splat(1.01)),
        "{b:?}"
    );
}

#[test]
fn empty_scene_and_named_struct_and_extension_attribute() {
    let s = ok("Scene()");
    assert!(s.objects.is_empty());
    assert_eq!(s.features, FeatureSet::default());
    let s = ok("#![enable(implicit_some)]\nScene(settings: (epsilon: Some(1e-6)), objects: [])");
    assert_eq!(s.settings.epsilon, Some(1e-6));
    let s = ok("(settings: (epsilon: 1e-6, shadows: false))");
    assert_eq!(
        s.settings,
        fray_scene::Settings {
            epsilon: Some(1e-6),
            shadows: false,
            samples: fray_core::PixelSamples::ONE,
            max_depth: 5,
            min_contribution: 1e-3,
            max_secondary_rays: 256,
        }
    );
    assert_eq!(s.epsilon(), 1e-6);
    let s = ok("(settings: (samples: 16))");
    assert_eq!(s.settings.samples.count(), 16);
}

const FULL: &str = r#"Scene(
    image: (width: 320, height: 200),
    camera: Pinhole(eye: (0, 2, -10), look_at: (0, 0, 0), up: (0, 1, 0), fov_y: 60, near: 0.5),
    background: (0, 0, 0),
    ambient: (0.1, 0.1, 0.1),
    lights: [
        Sun(direction: (0, 3, 4), irradiance: (2, 2, 2)),
        Point(position: (0, 5, 0), intensity: (10, 20, 30)),
    ],
    materials: {
        "red": (diffuse: (0.8, 0.1, 0.1), specular: (0.2, 0.2, 0.2), shininess: 40),
        "blue": (diffuse: (0.1, 0.1, 0.8), ambient: (0, 0, 0.5)),
        "plain": (),
    },
    objects: [
        (name: "ball", material: "red", shape: Sphere(center: (0, 1, 0), radius: 1)),
        (shape: Ellipsoid(center: (3, 0, 0), radii: (1, 2, 3))),
        (material: "blue", shape: FreeForm(
            base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
            bounds: (min: (-10, -1, -10), max: (10, 0, 10)),
        )),
        (shape: FreeForm(base: Cylinder(point: (0, 0, 0), axis: (0, 1, 0), radius: 0.5),
                         bounds: (min: (-1, 0, -1), max: (1, 2, 1)))),
        (shape: FreeForm(base: Cone(apex: (0, 0, 0), axis: (0, 1, 0), half_angle: 30),
                         bounds: (min: (-2, 0, -2), max: (2, 2, 2)))),
        (shape: FreeForm(base: Paraboloid(vertex: (0, 0, 0), axis: (0, 1, 0), focal_length: 0.25),
                         bounds: (min: (-2, 0, -2), max: (2, 2, 2)))),
        (shape: FreeForm(base: Hyperboloid(center: (0, 0, 0), axis: (0, 1, 0), radius: 1, height: 2, sheets: Two),
                         bounds: (min: (-2, -2, -2), max: (2, 2, 2)))),
        (shape: FreeForm(base: Hyperboloid(radius: 1, height: 2), bounds: (min: (-2, -2, -2), max: (2, 2, 2)))),
        (shape: General(origin: (1, 0, 0), coefficients: (-1, -1, -1, 0, 0, 0, 0, 0, 0, 1))),
        (name: "blob", material: "red", shape: FreeForm(
            base: Sphere(radius: 1),
            perturbations: [
                (form_factor: 0.5, quadric: Sphere(center: (1, 0, 0), radius: 0.5)),
                (form_factor: 0, quadric: Sphere(center: (-1, 0, 0), radius: 0.5)),
            ],
            material: "blue",
            transform: (translate: (0, 0, 5), rotate: (0, 90, 0), scale: (2, 2, 2)),
        )),
        (material: "plain", shape: Difference(
            Union([Sphere(radius: 1), FreeForm(base: Sphere(center: (1, 0, 0), radius: 1), material: "red")]),
            Transformed(
                shape: Intersection([Sphere(radius: 1), FreeForm(base: Sphere(radius: 2), material: "blue")]),
                transform: (translate: (0, 1, 0)),
            ),
        )),
    ],
    settings: (epsilon: 1e-8, shadows: true),
)"#;

#[test]
fn every_variant_parses_and_resolves() {
    let s = ok(FULL);
    assert_eq!((s.width, s.height), (320, 200));
    let Projector::Pinhole(p) = s.camera else {
        panic!("a pinhole")
    };
    assert!((p.tan_half_fov_y - (PI / 6.0).tan()).abs() < 1e-15);
    assert_eq!(p.near, 0.5);
    assert_eq!(s.lights.len(), 2);
    let Light::Sun {
        direction,
        irradiance,
    } = s.lights[0]
    else {
        panic!("a sun")
    };
    assert!((direction - DVec3::new(0.0, 0.6, 0.8)).length() < 1e-15);
    assert_eq!(irradiance, glam::Vec3::splat(2.0));
    assert_eq!(
        s.lights[1],
        Light::Point {
            position: DVec3::new(0.0, 5.0, 0.0),
            intensity: glam::Vec3::new(10.0, 20.0, 30.0)
        }
    );

    // Index 0 is the built-in default; named materials follow in sorted-name order.
    let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["default", "blue", "plain", "red"]);
    let (blue, plain, red) = (1, 2, 3);
    assert_eq!(s.materials[red].shininess, 40.0);
    assert_eq!(s.materials[red].ambient, s.materials[red].diffuse);
    assert_eq!(s.materials[blue].ambient, glam::Vec3::new(0.0, 0.0, 0.5));
    assert_eq!(
        s.materials[plain],
        Material {
            name: "plain".into(),
            ..Material::default()
        }
    );

    let o = &s.objects;
    assert_eq!(o.len(), 11);
    assert_eq!(o[0].name, "ball");
    assert_eq!(o[1].name, "object1");
    assert_eq!(o[0].leaf_materials, [red as u32]);
    assert_eq!(o[1].leaf_materials, [0]);
    assert_eq!(o[2].leaf_materials, [blue as u32]);
    assert!(o[2].solid.leaves()[0].clips());
    // The leaf's material overrides the object's.
    assert_eq!(o[9].name, "blob");
    assert_eq!(o[9].leaf_materials, [blue as u32]);
    // Leaf order is depth first, left to right; leaves inherit the object's material.
    assert_eq!(
        o[10].leaf_materials,
        [plain as u32, red as u32, plain as u32, blue as u32]
    );
    assert_eq!(o[10].solid.leaves().len(), 4);

    // The transform: scale 2, rotate 90° about y (x → −z), then move to z = 5.
    let blob = &o[9].solid;
    let bump_tip = DVec3::new(0.0, 0.0, 5.0 - 2.0 * 1.1);
    assert!(
        blob.eval(bump_tip) > 0.0,
        "the bump moved with the transform"
    );
    assert!(blob.eval(DVec3::new(0.0, 0.0, 5.0 + 2.0 * 1.1)) < 0.0);
    assert!(blob.eval(DVec3::new(0.0, 0.0, 5.0)) > 0.0);
    // `Transformed` moves every quadric below it.
    let moved = &o[10].solid.leaves()[2];
    assert!((moved.base().eval(DVec3::new(0.0, 1.0, 0.0)) - 1.0).abs() < 1e-12);
    // General quadrics keep their coefficients and origin.
    assert_eq!(o[8].solid.leaves()[0].base().origin, DVec3::X);

    assert_eq!(s.settings.epsilon, Some(1e-8));
    assert_eq!(
        s.features,
        FeatureSet {
            free_forms: true,
            perturbations: true,
            csg: true,
            terrain: false,
            shadows: true,
            sun: true,
            point_lights: true,
            fog: false,
            sky: false,
            clouds: false,
            meshes: false,
            reflection: false,
            transmission: false,
            textures: false,
        }
    );
}

#[test]
fn parallel_and_sphere_cameras() {
    let s = ok("(camera: Parallel(eye: (0, 0, -5), look_at: (0, 0, 0), height: 4))");
    let Projector::Parallel(p) = s.camera else {
        panic!("parallel")
    };
    assert_eq!((p.height, p.near), (4.0, 0.0));

    let s = ok("(camera: Sphere(eye: (0, 0, 0), look_at: (0, 0, 1)))");
    let Projector::Sphere(c) = s.camera else {
        panic!("sphere")
    };
    assert_eq!(c.centre, DVec3::ZERO);
    assert!((c.fov_x - 2.0 * PI).abs() < 1e-15 && (c.fov_y - PI).abs() < 1e-15);
    assert_eq!((c.radius, c.amplitude, c.frequency), (1.0, 0.0, 0.0));

    let s = ok(
        r"(camera: Sphere(eye: (0.1, 0, 0), centre: (0, 0, 0), look_at: (0, 0, 1), up: (0, 1, 0),
        fov_x: 90, fov_y: 60, radius: 2, ripple_amplitude: 0.1, ripple_frequency: 3))",
    );
    let Projector::Sphere(c) = s.camera else {
        panic!("sphere")
    };
    assert!((c.fov_x - PI / 2.0).abs() < 1e-15 && (c.fov_y - PI / 3.0).abs() < 1e-15);
    assert_eq!(
        (c.eye.x, c.radius, c.amplitude, c.frequency),
        (0.1, 2.0, 0.1, 3.0)
    );
}

#[test]
fn feature_sets() {
    let f = |src: &str| ok(src).features;
    assert_eq!(f("()"), FeatureSet::default());
    assert_eq!(
        f("(lights: [Point(position: (0, 5, 0))], objects: [(shape: Sphere(radius: 1))])"),
        FeatureSet {
            free_forms: true,
            shadows: true,
            point_lights: true,
            ..FeatureSet::default()
        }
    );
    assert_eq!(
        f("(lights: [Sun(direction: (0, 1, 0))], settings: (shadows: false))"),
        FeatureSet {
            sun: true,
            ..FeatureSet::default()
        }
    );
    // A zero form factor is no perturbation.
    let zero = "(objects: [(shape: FreeForm(base: Sphere(radius: 1),
        perturbations: [(form_factor: 0, quadric: Sphere(radius: 1))]))])";
    assert_eq!(
        f(zero),
        FeatureSet {
            free_forms: true,
            ..FeatureSet::default()
        }
    );
    let csg = "(objects: [(shape: Intersection([Sphere(radius: 1), Sphere(center: (1, 0, 0), radius: 1)]))])";
    assert_eq!(
        f(csg),
        FeatureSet {
            free_forms: true,
            csg: true,
            ..FeatureSet::default()
        }
    );
}

#[test]
fn integers_are_accepted_for_floats() {
    let s =
        ok("(objects: [(shape: Sphere(center: (1, 2, 3), radius: 2))], settings: (epsilon: 1))");
    assert_eq!(
        s.objects[0].solid.leaves()[0].base().origin,
        DVec3::new(1.0, 2.0, 3.0)
    );
    assert_eq!(s.settings.epsilon, Some(1.0));
}

#[test]
fn syntax_error_names_the_line() {
    let e = err(
        "(\n  image: (width: 10, height: 10),\n  objects: [\n    (shape: Sphere(radius: 1)\n  ],\n)",
    );
    let SceneError::Syntax { file, line, .. } = &e else {
        panic!("expected a syntax error, got {e:?}")
    };
    assert_eq!((file.as_str(), *line), ("test.ron", 5), "{e}");
    assert!(e.to_string().starts_with("test.ron:5:"), "{e}");

    let e = err("(objects: [])\ntrailing");
    assert!(matches!(e, SceneError::Syntax { line: 2, .. }), "{e}");
}

#[test]
fn unknown_field() {
    let m = invalid(
        "(\n  objects: [\n    (shape: Sphere(radius: 1, colour: 3)),\n  ],\n)",
        3,
        "objects[0].shape.colour",
    );
    assert!(
        m.contains("unknown field `colour`") && m.contains("`radius`"),
        "{m}"
    );
    let m = invalid("(\n  image: (width: 10, heigth: 10),\n)", 2, "image.heigth");
    assert!(m.contains("`height`"), "{m}");
}

#[test]
fn wrong_type() {
    let m = invalid(
        "(\n  objects: [\n    (shape: Sphere(\n      radius: \"one\",\n    )),\n  ],\n)",
        4,
        "objects[0].shape.radius",
    );
    assert!(m.contains("number") || m.contains("float"), "{m}");
    invalid("(\n  image: (width: 1.5),\n)", 2, "image.width");
    invalid("(\n  settings: (shadows: 1),\n)", 2, "settings.shadows");
    invalid("(\n  image: (width: -3),\n)", 2, "image.width");
}

#[test]
fn unknown_variant_and_missing_field() {
    let m = invalid(
        "(\n  objects: [\n    (shape: Torus(radius: 1)),\n  ],\n)",
        3,
        "objects[0].shape",
    );
    assert!(
        m.contains("unknown variant `Torus`") && m.contains("`Sphere`"),
        "{m}"
    );
    let m = invalid(
        "(\n  objects: [\n    (shape: Sphere(center: (0, 0, 0))),\n  ],\n)",
        3,
        "objects[0].shape.radius",
    );
    assert!(m.contains("missing"), "{m}");
}

#[test]
fn negative_radius_names_line_and_field() {
    let src = "(
  objects: [
    (shape: Sphere(radius: 1)),
    (shape: FreeForm(
      base: Sphere(radius: 1),
      perturbations: [
        (form_factor: 0.5, quadric: Sphere(radius: -1)),
      ],
    )),
  ],
)";
    let e = err(src);
    assert_eq!(
        e.to_string(),
        "test.ron:7:44: objects[1].shape.perturbations[0].quadric.radius: must be > 0, got -1"
    );
    let src = "(objects: [\n  (shape: FreeForm(\n    base: Sphere(\n      center: (0, 0, 0),\n      radius: -1)))])";
    let m = invalid(src, 5, "objects[0].shape.base.radius");
    assert_eq!(m, "must be > 0, got -1");
}

#[test]
fn non_finite_numbers_are_rejected() {
    invalid(
        "(\n  objects: [(shape: Sphere(radius: inf))],\n)",
        2,
        "objects[0].shape.radius",
    );
    invalid(
        "(\n  objects: [(shape: Sphere(radius: NaN))],\n)",
        2,
        "objects[0].shape.radius",
    );
    invalid(
        "(\n  objects: [\n    (shape: Sphere(center: (0, NaN, 0), radius: 1)),\n  ],\n)",
        3,
        "objects[0].shape.center",
    );
    invalid("(\n  background: (0, -inf, 0),\n)", 2, "background");
    invalid(
        "(\n  camera: Pinhole(eye: (0, 0, -5), look_at: (0, 0, 0), fov_y: NaN),\n)",
        2,
        "camera.fov_y",
    );
    invalid("(\n  settings: (epsilon: inf),\n)", 2, "settings.epsilon");
    for bad in ["0", "2.5", "-4", "1025"] {
        invalid(
            &format!("(\n  settings: (samples: {bad}),\n)"),
            2,
            "settings.samples",
        );
    }
}

#[test]
fn unbounded_object() {
    let src = "(\n  objects: [\n    (shape: Sphere(radius: 1)),\n    (shape: Cylinder(radius: 1)),\n  ],\n)";
    let m = invalid(src, 4, "objects[1].shape");
    assert!(m.contains("unbounded"), "{m}");
    // Inside a CSG tree, the path names the leaf.
    let src =
        "(objects: [(shape: Union([\n  Sphere(radius: 1),\n  HalfSpace(normal: (0, 1, 0)),\n]))])";
    invalid(src, 3, "objects[0].shape[1]");
    // With bounds it is fine.
    ok(
        "(objects: [(shape: FreeForm(base: Cylinder(radius: 1), bounds: (min: (-1, -1, -1), max: (1, 1, 1))))])",
    );
}

#[test]
fn unknown_material() {
    let src = "(\n  materials: { \"red\": () },\n  objects: [\n    (material: \"green\", shape: Sphere(radius: 1)),\n  ],\n)";
    let m = invalid(src, 4, "objects[0].material");
    assert!(m.contains("`green`") && m.contains("`red`"), "{m}");
    let src = "(objects: [(shape: Union([\n  Sphere(radius: 1),\n  FreeForm(base: Sphere(radius: 1),\n    material: \"nope\"),\n]))])";
    invalid(src, 4, "objects[0].shape[1].material");
    invalid(
        "(\n  materials: { \"default\": () },\n)",
        2,
        "materials.default",
    );
    invalid(
        "(\n  materials: {\n    \"m\": (diffuse: (2, 0, 0)),\n  },\n)",
        3,
        "materials.m.diffuse",
    );
}

#[test]
fn bad_camera() {
    let m = invalid(
        "(\n  camera: Pinhole(\n    eye: (1, 2, 3),\n    look_at: (1, 2, 3),\n  ),\n)",
        4,
        "camera.look_at",
    );
    assert!(m.contains("eye"), "{m}");
    invalid(
        "(\n  camera: Pinhole(eye: (0, 0, -5), look_at: (0, 0, 0),\n    up: (0, 0, 1)),\n)",
        3,
        "camera.up",
    );
    let m = invalid(
        "(\n  camera: Pinhole(eye: (0, 0, -5), look_at: (0, 0, 0),\n    fov_y: 180),\n)",
        3,
        "camera.fov_y",
    );
    assert_eq!(m, "must be in (0, 180) degrees, got 180");
    invalid(
        "(\n  camera: Parallel(eye: (0, 0, -5), look_at: (0, 0, 0),\n    height: 0),\n)",
        3,
        "camera.height",
    );
    invalid(
        "(\n  camera: Sphere(eye: (5, 0, 0), centre: (0, 0, 0),\n    look_at: (0, 0, 1)),\n)",
        2,
        "camera.eye",
    );
}

#[test]
fn other_invalid_values() {
    invalid("(\n  image: (width: 0),\n)", 2, "image.width");
    invalid("(\n  image: (height: 20000),\n)", 2, "image.height");
    invalid(
        "(\n  lights: [\n    Sun(direction: (0, 0, 0)),\n  ],\n)",
        3,
        "lights[0].direction",
    );
    invalid(
        "(\n  lights: [\n    Point(position: (0, 0, 0), intensity: (-1, 0, 0)),\n  ],\n)",
        3,
        "lights[0].intensity",
    );
    invalid(
        "(objects: [(shape: Union([\n  Sphere(radius: 1),\n]))])",
        1,
        "objects[0].shape",
    );
    invalid(
        "(objects: [(shape: Cone(\n  half_angle: 90))])",
        2,
        "objects[0].shape.half_angle",
    );
    invalid(
        "(objects: [(shape: FreeForm(base: Sphere(radius: 1),\n  bounds: (min: (1, 1, 1), max: (0, 0, 0))))])",
        2,
        "objects[0].shape.bounds",
    );
    invalid(
        "(objects: [(shape: Transformed(shape: Sphere(radius: 1),\n  transform: (scale: (1, 0, 1))))])",
        2,
        "objects[0].shape.transform.scale",
    );
    invalid(
        "(objects: [(shape: General(\n  coefficients: (0, 0, 0, 0, 0, 0, 0, 0, 0, 0)))])",
        2,
        "objects[0].shape.coefficients",
    );
}

#[test]
fn missing_file_names_the_path() {
    let path = std::path::Path::new("/definitely/not/here/scene.ron");
    let e = load(path).unwrap_err();
    assert!(
        matches!(&e, SceneError::Io { path: p, .. } if p == path),
        "{e:?}"
    );
    let text = e.to_string();
    assert!(
        text.contains("/definitely/not/here/scene.ron") && text.contains("No such file"),
        "{text}"
    );
}

#[test]
fn load_reads_a_file_and_reports_its_name() {
    let dir = std::env::temp_dir().join(format!("fray-scene-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("good.ron");
    std::fs::write(&good, "(objects: [(shape: Sphere(radius: 1))])").unwrap();
    assert_eq!(load(&good).unwrap().objects.len(), 1);
    let bad = dir.join("bad.ron");
    std::fs::write(&bad, "(\n  objects: [(shape: Sphere(radius: 0))],\n)").unwrap();
    let e = load(&bad).unwrap_err();
    assert!(
        e.to_string().starts_with(&format!("{}:2:", bad.display())),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Every prefix of a valid scene, and many corrupted copies, give an error or a scene — never a
/// panic.
#[test]
fn mangled_scenes_never_panic() {
    for end in 0..=FULL.len() {
        if FULL.is_char_boundary(end) {
            let _ = parse(&FULL[..end], "cut.ron");
        }
    }
    // Deterministic pseudo-random byte substitutions (xorshift), kept to valid UTF-8.
    let alphabet = b"()[]{}:,\"'/*#!-+.0123456789eEaxyzNIf_ \n";
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..3000 {
        let mut bytes = FULL.as_bytes().to_vec();
        for _ in 0..1 + next() % 4 {
            let at = (next() % bytes.len() as u64) as usize;
            bytes[at] = alphabet[(next() % alphabet.len() as u64) as usize];
        }
        if let Ok(text) = std::str::from_utf8(&bytes) {
            let _ = parse(text, "mangled.ron");
        }
    }
}

mod fuzz {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

        #[test]
        fn arbitrary_text_never_panics(text in "\\PC{0,200}") {
            let _ = parse(&text, "any.ron");
        }

        #[test]
        fn spliced_scenes_never_panic(cut in 0usize..2000, insert in "[()\\[\\]{}:,\"a-z0-9 .-]{0,8}") {
            let mut at = cut.min(FULL.len());
            while !FULL.is_char_boundary(at) {
                at -= 1;
            }
            let text = format!("{}{}{}", &FULL[..at], insert, &FULL[at..]);
            let _ = parse(&text, "spliced.ron");
        }
    }
}

/// The complete example in the format reference is a valid scene.
#[test]
fn the_documented_example_resolves() {
    let doc = include_str!("../../../docs/scene-format.md");
    let start = doc
        .find("```ron\n")
        .expect("the reference has a RON example")
        + "```ron\n".len();
    let len = doc[start..].find("```").expect("the example is closed");
    let s = match parse(&doc[start..start + len], "docs/scene-format.md") {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    };
    assert_eq!(s.objects.len(), 4);
    assert_eq!(s.materials.len(), 4);
    assert_eq!(
        s.features,
        FeatureSet {
            free_forms: true,
            perturbations: true,
            csg: true,
            terrain: false,
            shadows: true,
            sun: true,
            point_lights: true,
            fog: false,
            sky: false,
            clouds: false,
            meshes: false,
            reflection: false,
            transmission: false,
            textures: false,
        }
    );
}

/// Comments, strings and names with non-ASCII text do not shift the located position.
#[test]
fn errors_are_located_past_unicode_and_comments() {
    let src = "( // ünïcödé ( [ {\n  materials: { \"rouge é\": (diffuse: (0.5, 0, 0)) },\n  /* a (nested /* é */) comment */\n  objects: [\n    (name: \"ballon (é)\", material: \"rouge é\", shape: Sphere(radius: 1)),\n    (name: \"x\", shape: FreeForm(base: Sphere(radius: 1), perturbations: [\n      (form_factor: 1, quadric: Ellipsoid(radii: (1, -2, 1))),\n    ])),\n  ],\n)";
    let e = err(src);
    assert_eq!(
        e.to_string(),
        "test.ron:7:43: objects[1].shape.perturbations[0].quadric.radii: must be > 0 on every axis, got (1, -2, 1)"
    );
    let s = ok(&src.replace("-2", "2"));
    assert_eq!(s.materials[1].name, "rouge é");
    assert_eq!(s.objects[0].leaf_materials, [1]);
}

/// Absurdly deep nesting is an error, not a stack overflow.
#[test]
fn deep_nesting_is_an_error() {
    let deep = format!(
        "(objects: [(shape: {}Sphere(radius: 1){})])",
        "Union([".repeat(5000),
        "])".repeat(5000)
    );
    assert!(parse(&deep, "deep.ron").is_err());
    assert!(parse(&"(".repeat(100_000), "deep.ron").is_err());
    assert!(parse(&"[".repeat(100_000), "deep.ron").is_err());
}

/// A perturbation's own `transform` moves its quadric alone: a long bump rotated 90° about z
/// equals the bump written with swapped radii.
#[test]
fn perturbation_transform_rotates_its_quadric_only() {
    let rotated = fray_scene::parse(
        r#"Scene(objects: [(shape: FreeForm(
            base: Sphere(center: (0, 0, 0), radius: 1),
            perturbations: [(form_factor: 0.5, quadric: Ellipsoid(center: (0, 0, 0), radii: (2, 0.5, 0.5)), transform: (rotate: (0, 0, 90), translate: (0, 1, 0)))],
        ))])"#,
        "rotated.ron",
    )
    .expect("parses");
    let written = fray_scene::parse(
        r#"Scene(objects: [(shape: FreeForm(
            base: Sphere(center: (0, 0, 0), radius: 1),
            perturbations: [(form_factor: 0.5, quadric: Ellipsoid(center: (0, 1, 0), radii: (0.5, 2, 0.5)))],
        ))])"#,
        "written.ron",
    )
    .expect("parses");
    let a = rotated.objects[0].solid.leaves()[0].clone();
    let b = written.objects[0].solid.leaves()[0].clone();
    // The base is untouched.
    assert_eq!(a.base(), b.base());
    for p in [
        glam::DVec3::new(0.0, 2.5, 0.0),
        glam::DVec3::new(0.3, 1.2, -0.1),
        glam::DVec3::new(1.0, 1.0, 0.0),
    ] {
        assert!(
            (a.eval(p) - b.eval(p)).abs() < 1e-12,
            "at {p}: {} vs {}",
            a.eval(p),
            b.eval(p)
        );
    }
    // A bad perturbation transform names its field.
    let err = fray_scene::parse(
        "Scene(objects: [(shape: FreeForm(base: Sphere(center: (0, 0, 0), radius: 1),\n  perturbations: [(form_factor: 1, quadric: Sphere(center: (0, 0, 0), radius: 1), transform: (scale: (0, 1, 1)))]))])",
        "bad.ron",
    )
    .expect_err("zero scale is rejected");
    let text = err.to_string();
    assert!(
        text.contains("perturbations[0].transform.scale") && text.contains("bad.ron:2:"),
        "{text}"
    );
}
