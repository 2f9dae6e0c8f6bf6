//! Named cameras and animation in scene files: paths, tracks, the sun over time, loops, frames
//! computed from the file's placement, and located errors.

use fray_core::Projector;
use fray_scene::{Light, Scene, SceneError, parse};
use glam::DVec3;

fn ok(src: &str) -> Scene {
    parse(src, "anim.ron").unwrap_or_else(|e| panic!("expected the scene to parse, got: {e}"))
}

/// The error's field and line, and its message.
#[track_caller]
fn invalid(src: &str) -> (String, usize, String) {
    match parse(src, "anim.ron") {
        Ok(_) => panic!("expected an error for:\n{src}"),
        Err(SceneError::Invalid {
            field,
            line,
            message,
            ..
        }) => (field, line, message),
        Err(e) => panic!("expected a located error, got {e}"),
    }
}

const HEAD: &str = "Scene(image: (width: 32, height: 24),
  camera: Pinhole(eye: (0, 1, -10), look_at: (0, 0, 0), fov_y: 40),
  lights: [Sun(direction: (0, 1, 0), irradiance: (3, 3, 3))],
  objects: [
    (name: \"ball\", shape: Sphere(center: (0, 0, 0), radius: 1)),
    (name: \"slab\", shape: FreeForm(base: HalfSpace(point: (0, -1, 0), normal: (0, 1, 0)),
                                     bounds: (min: (-5, -2, -5), max: (5, -1, 5)))),
  ],";

fn eye(scene: &Scene) -> DVec3 {
    match scene.camera {
        Projector::Pinhole(p) => p.eye,
        other => panic!("not a pinhole: {other:?}"),
    }
}

#[test]
fn named_cameras_are_chosen_by_name_and_unknown_names_list_the_known_ones() {
    let scene = ok(&format!(
        "{HEAD}
  cameras: {{
    \"top\": Pinhole(eye: (0, 20, 0.01), look_at: (0, 0, 0)),
    \"side\": Parallel(eye: (-10, 0, 0), look_at: (0, 0, 0), height: 4),
  }},
)"
    ));
    let names: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["side", "top"], "name order");
    let top = scene.with_camera("top").unwrap();
    assert_eq!(eye(&top), DVec3::new(0.0, 20.0, 0.01));
    assert!(matches!(
        scene.with_camera("side").unwrap().camera,
        Projector::Parallel(_)
    ));
    let e = scene.with_camera("front").unwrap_err().to_string();
    assert!(e.contains("\"front\"") && e.contains("side, top"), "{e}");
    let (field, line, _) = invalid(&format!(
        "{HEAD}\n  cameras: {{\"bad\": Pinhole(eye: (0, 0, 0), look_at: (0, 0, 0))}},\n)"
    ));
    assert_eq!((field.as_str(), line), ("cameras.bad.look_at", 9));
}

/// A camera path at its keys is the keys' camera; between them it moves smoothly; frames are
/// `n / fps`; the default length reaches the last key.
#[test]
fn a_camera_path_passes_its_keys_at_their_frames() {
    let scene = ok(&format!(
        "{HEAD}
  animation: Some((fps: 10, camera: Some((keys: [
    (time: 0, eye: (0, 1, -10), look_at: (0, 0, 0)),
    (time: 1, eye: (10, 1, 0), look_at: (0, 0, 0)),
    (time: 2, eye: (0, 1, 10), look_at: (0, 0, 0), fov_y: 20),
  ])))),
)"
    ));
    let a = scene.animation.as_ref().unwrap();
    assert_eq!(a.frames, 21);
    for (n, want) in [
        (0, [0.0, 1.0, -10.0]),
        (10, [10.0, 1.0, 0.0]),
        (20, [0.0, 1.0, 10.0]),
    ] {
        let frame = scene.at_frame(n).unwrap();
        assert!(frame.animation.is_none(), "a frame is a still");
        assert!(
            (eye(&frame) - DVec3::from_array(want)).length() < 1e-12,
            "frame {n}"
        );
    }
    // Between keys the eye bows out from the chord toward the circle the keys lie on
    // (Catmull–Rom: the chord's midpoint is 7.07 from the axis, the circle 10; the end segment's
    // one-sided tangent gives 8.0).
    let mid = eye(&scene.at_time(0.5).unwrap());
    let radius = DVec3::new(mid.x, 0.0, mid.z).length();
    assert!(radius > 7.5 && radius < 10.5, "{mid}");
    // The last key's field of view is reached.
    match scene.at_frame(20).unwrap().camera {
        Projector::Pinhole(p) => {
            assert!((p.tan_half_fov_y - 10f64.to_radians().tan()).abs() < 1e-12)
        }
        _ => unreachable!(),
    }
}

/// A camera without look-at points looks along its path.
#[test]
fn a_path_without_look_at_looks_where_it_goes() {
    let scene = ok(&format!(
        "{HEAD}
  animation: Some((fps: 4, camera: Some((interpolation: Linear, keys: [
    (time: 0, eye: (0, 5, -50)),
    (time: 2, eye: (0, 5, 50)),
  ])))),
)"
    ));
    match scene.at_time(1.0).unwrap().camera {
        Projector::Pinhole(p) => {
            assert!(
                (p.basis.forward - DVec3::Z).length() < 1e-12,
                "{:?}",
                p.basis
            )
        }
        _ => unreachable!(),
    }
}

/// An object track moves the object from where the file puts it: the sphere translated by the
/// track at a time equals a sphere written there (the same values at every probe point); the
/// unanimated slab stays; every frame starts from the file, so frame 3 alone equals frame 3
/// after frames 0–2.
#[test]
fn an_object_track_moves_the_object_and_frames_do_not_accumulate() {
    let scene = ok(&format!(
        "{HEAD}
  animation: Some((fps: 1, objects: {{\"ball\": (interpolation: Linear, keys: [
    (time: 0, translate: (0, 0, 0)),
    (time: 4, translate: (8, 0, 0), rotate: (0, 90, 0)),
  ])}})),
)"
    ));
    // At 3 s: translated by (6, 0, 0) after three quarters of a quarter turn about y — about the
    // world origin, where the ball sits, so the ball is the one written at (6, 0, 0).
    let at3 = scene.at_frame(3).unwrap();
    let want = ok(&format!("{HEAD}\n)").replace(
        "Sphere(center: (0, 0, 0), radius: 1)",
        "Sphere(center: (6, 0, 0), radius: 1)",
    ));
    for p in [
        DVec3::new(6.0, 0.0, 0.0),
        DVec3::new(6.5, 0.3, -0.2),
        DVec3::new(7.2, 0.0, 0.0),
    ] {
        let (a, b) = (at3.objects[0].solid.eval(p), want.objects[0].solid.eval(p));
        assert!((a - b).abs() < 1e-12, "at {p}: {a} vs {b}");
    }
    assert_eq!(
        at3.objects[1].solid.bounds(),
        scene.objects[1].solid.bounds()
    );
    for n in 0..3 {
        scene.at_frame(n).unwrap();
    }
    let again = scene.at_frame(3).unwrap();
    assert_eq!(
        again.objects[0].solid.bounds(),
        at3.objects[0].solid.bounds()
    );
}

/// The sun track turns the first sun, and with a sky the sky's sun.
#[test]
fn the_sun_track_turns_the_first_sun_and_the_skys() {
    let scene = ok(&format!(
        "{HEAD}
  atmosphere: (sky: Some(())),
  animation: Some((fps: 2, sun: Some((interpolation: Linear, keys: [
    (time: 0, direction: (1, 0.2, 0)),
    (time: 1, direction: (1, 1, 0)),
  ])))),
)"
    ));
    let end = scene.at_time(1.0).unwrap();
    let want = DVec3::new(1.0, 1.0, 0.0).normalize();
    match end.lights[0] {
        Light::Sun { direction, .. } => assert!((direction - want).length() < 1e-12),
        _ => unreachable!(),
    }
    let sky = end.atmosphere.sky.as_ref().unwrap();
    assert!((sky.sky.sun().direction - want).length() < 1e-12);
}

/// A loop wraps time at its length and closes every track.
#[test]
fn a_loop_wraps_and_closes() {
    let scene = ok(&format!(
        "{HEAD}
  animation: Some((fps: 10, frames: 40, loop: true, camera: Some((keys: [
    (time: 0, eye: (0, 1, -10), look_at: (0, 0, 0)),
    (time: 1, eye: (10, 1, 0), look_at: (0, 0, 0)),
    (time: 2, eye: (0, 1, 10), look_at: (0, 0, 0)),
    (time: 3, eye: (-10, 1, 0), look_at: (0, 0, 0)),
  ])))),
)"
    ));
    let (a, b) = (
        eye(&scene.at_time(0.0).unwrap()),
        eye(&scene.at_time(4.0).unwrap()),
    );
    assert!((a - b).length() < 1e-12);
    let (c, d) = (
        eye(&scene.at_time(3.9).unwrap()),
        eye(&scene.at_time(-0.1).unwrap()),
    );
    assert!((c - d).length() < 1e-9);
    // 0.1 s before the first key at about 15 m/s.
    assert!(
        (d - a).length() < 2.0,
        "smooth into the first key: {d} vs {a}"
    );
}

#[test]
fn bad_animations_are_located() {
    let cases = [
        // A key out of order.
        (
            "camera: Some((keys: [(time: 1, eye: (0, 1, -9), look_at: (0, 0, 0)), (time: 0.5, eye: (0, 1, -8), look_at: (0, 0, 0))]))",
            "animation.camera.keys[1].time",
            "increasing",
        ),
        // A path that runs the eye into its look-at point.
        (
            "camera: Some((interpolation: Linear, keys: [(time: 0, eye: (0, 0, -2), look_at: (0, 0, 0)), (time: 1, eye: (0, 0, 2), look_at: (0, 0, 0))]))",
            "animation.camera",
            "frame",
        ),
        // Some keys with look_at, some without.
        (
            "camera: Some((keys: [(time: 0, eye: (0, 1, -9), look_at: (0, 0, 0)), (time: 1, eye: (0, 1, -8))]))",
            "animation.camera.keys[1].look_at",
            "every key",
        ),
        // A track for nothing.
        (
            "objects: {\"plane\": (keys: [(time: 0)])}",
            "animation.objects.plane",
            "no free-form or mesh object",
        ),
        // A loop without its length.
        ("loop: true", "animation.frames", "needs its length"),
        // A loop key past the end.
        (
            "frames: 10, loop: true, sun: Some((keys: [(time: 0, direction: (0, 1, 0)), (time: 2, direction: (1, 1, 0))]))",
            "animation.sun.keys[1].time",
            "before its end",
        ),
        ("fps: 0", "animation.fps", "> 0"),
    ];
    for (body, field, says) in cases {
        let src = format!("{HEAD}\n  animation: Some(({body})),\n)");
        let (f, line, message) = invalid(&src);
        assert_eq!(f, field, "{body}: {message}");
        assert_eq!(line, 9, "{body}");
        assert!(message.contains(says), "{body}: {message}");
    }
    // A camera path needs a pinhole.
    let src = format!(
        "{}\n  animation: Some((camera: Some((keys: [(time: 0, eye: (0, 1, -9), look_at: (0, 0, 0))])))),\n)",
        HEAD.replace(
            "Pinhole(eye: (0, 1, -10), look_at: (0, 0, 0), fov_y: 40)",
            "Parallel(eye: (0, 1, -10), look_at: (0, 0, 0), height: 3)"
        )
    );
    let (f, _, message) = invalid(&src);
    assert_eq!(f, "animation.camera");
    assert!(message.contains("Pinhole"), "{message}");
}

/// A clipped object turns with its box: the slab's clipping box becomes its six moved faces
/// (seven leaves, each with the slab's material), and the turned slab holds the slab's turned
/// points.
#[test]
fn a_clipped_object_turns_with_its_box() {
    let scene = ok(&format!(
        "{HEAD}
  materials: {{\"stone\": (diffuse: (0.5, 0.5, 0.5))}},
  animation: Some((fps: 1, objects: {{\"slab\": (interpolation: Linear, keys: [
    (time: 0), (time: 1, rotate: (0, 0, 30))])}})),
)"
    )
    .replace(
        "(name: \"slab\", shape:",
        "(name: \"slab\", material: \"stone\", shape:",
    ));
    let turned = scene.at_time(1.0).unwrap();
    let slab = &turned.objects[1];
    assert_eq!(slab.solid.leaves().len(), 7);
    assert_eq!(
        slab.leaf_materials,
        vec![scene.objects[1].leaf_materials[0]; 7]
    );
    let r = glam::DQuat::from_rotation_z(30f64.to_radians());
    for p in [
        DVec3::new(0.0, -1.5, 0.0),
        DVec3::new(4.0, -1.2, -3.0),
        DVec3::new(-2.0, -1.9, 4.5),
    ] {
        assert!(scene.objects[1].solid.eval(p) > 0.0);
        assert!(slab.solid.eval(r * p) > 0.0, "{p} turned is outside");
    }
}
