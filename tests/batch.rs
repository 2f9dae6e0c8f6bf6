//! Batch rendering end to end: numbered frames of an animation (the same bytes alone or in a
//! sequence, on any thread count), tiles rendered by separate processes through the documented
//! job script and stacked back bit for bit.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;

use common::fray;

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("batch", name)
}

#[track_caller]
fn ok(o: &Output) {
    assert!(
        o.status.success(),
        "fray failed:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn bytes(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A small animated scene: a camera path, a moving sphere, the sun turning, fog on a grid.
const ANIMATED: &str = r#"Scene(
  image: (width: 64, height: 40),
  camera: Pinhole(eye: (0, 2, -12), look_at: (0, 0, 0), fov_y: 40),
  lights: [Sun(direction: (0.3, 1, -0.4), irradiance: (3, 3, 3))],
  objects: [
    (name: "ball", shape: Sphere(center: (0, 0.5, 0), radius: 1.2)),
    (name: "ground", shape: FreeForm(base: HalfSpace(point: (0, -1, 0), normal: (0, 1, 0)),
                                     bounds: (min: (-20, -2, -20), max: (20, -1, 20)))),
  ],
  atmosphere: (fog: Some((base: -1, top: 1.5, extinction: 0.05)), grid: 4),
  settings: (samples: 4),
  animation: Some((fps: 8, camera: Some((keys: [
      (time: 0, eye: (0, 2, -12), look_at: (0, 0, 0)),
      (time: 0.5, eye: (6, 3, -10), look_at: (0, 0, 0)),
      (time: 1, eye: (10, 2, -4), look_at: (0, 0, 0), fov_y: 30),
    ])),
    objects: {"ball": (keys: [(time: 0), (time: 1, translate: (2, 1, 0))])},
    sun: Some((keys: [(time: 0, direction: (0.3, 1, -0.4)), (time: 1, direction: (-0.5, 0.6, -0.2))])),
  )),
)"#;

/// Frame 2 rendered in a sequence of four on two threads and alone on one thread is the same
/// file; consecutive frames differ (the animation moves); the numbers follow the pattern.
#[test]
fn frames_are_numbered_and_the_same_bytes_alone_or_in_a_sequence() {
    let dir = temp_dir("frames");
    let scene = dir.join("animated.ron");
    std::fs::write(&scene, ANIMATED).unwrap();
    let (scene, seq, alone) = (
        scene.to_str().unwrap().to_owned(),
        dir.join("seq_%04d.png"),
        dir.join("alone_%d.png"),
    );
    for (frames, threads, out) in [("0..4", "2", &seq), ("2..3", "1", &alone)] {
        ok(&fray(&[
            "render",
            &scene,
            "--backend",
            "cpu",
            "--frames",
            frames,
            "--threads",
            threads,
            "--quiet",
            "-o",
            out.to_str().unwrap(),
        ]));
    }
    let frame = |n: u32| bytes(&dir.join(format!("seq_{n:04}.png")));
    assert_eq!(frame(2), bytes(&dir.join("alone_2.png")));
    for n in 0..3 {
        assert_ne!(frame(n), frame(n + 1), "frames {n} and {} are alike", n + 1);
    }
    assert!(!dir.join("seq_0004.png").exists());
    // `--time` renders a still at any time: frame 2 is 0.25 s at 8 frames per second.
    let at = dir.join("at.png");
    ok(&fray(&[
        "render",
        &scene,
        "--backend",
        "cpu",
        "--time",
        "0.25",
        "--quiet",
        "-o",
        at.to_str().unwrap(),
    ]));
    assert_eq!(bytes(&at), frame(2));
}

#[test]
fn frame_patterns_and_ranges_are_checked() {
    let dir = temp_dir("patterns");
    let out = dir.join("no_pattern.png");
    let o = fray(&["render", "--frames", "0..2", "-o", out.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("frame-number pattern"));
    for bad in ["3..3", "5..2", "a..b", "7"] {
        let o = fray(&["render", "--frames", bad]);
        assert!(!o.status.success(), "{bad}");
        assert!(String::from_utf8_lossy(&o.stderr).contains("A..B"), "{bad}");
    }
    for bad in ["3/3", "1/0", "x/2"] {
        let o = fray(&["render", "--tile", bad]);
        assert!(!o.status.success(), "{bad}");
    }
    // More tiles than blocks of 16 rows.
    let o = fray(&["render", "--height", "40", "--tile", "3/4"]);
    assert!(!o.status.success());
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("3 blocks of 16 rows"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// The job script as a shell loop runs it (and a Kubernetes Indexed Job would: one process per
/// `JOB_COMPLETION_INDEX`): N processes each render a tile, `fray assemble` stacks them, and the
/// result is the whole image's file byte for byte — on scenes whose pixels depend on more than
/// their own ray: the fog's grid, anti-aliasing samples, a terrain's LOD, a mesh's packets.
#[test]
fn tiles_from_separate_processes_reassemble_bit_exactly() {
    let dir = temp_dir("tiles");
    let animated = dir.join("animated.ron");
    std::fs::write(&animated, ANIMATED).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cases: [(&str, PathBuf, &str, &str); 3] = [
        ("fog", animated, "--width 64", "3"),
        (
            "terrain",
            root.join("data/scenes/terrain_low.ron"),
            "--width 96 --samples 2",
            "4",
        ),
        (
            "mesh",
            root.join("data/scenes/mesh_bunny_freeform.ron"),
            "--width 160",
            "5",
        ),
    ];
    for (name, scene, args, jobs) in cases {
        let out = dir.join(name);
        let whole = dir.join(format!("{name}_whole.png"));
        let mut whole_args = vec![
            "render",
            scene.to_str().unwrap(),
            "--backend",
            "cpu",
            "--quiet",
        ];
        whole_args.extend(args.split(' '));
        whole_args.extend(["-o", whole.to_str().unwrap()]);
        ok(&fray(&whole_args));
        let o = Command::new(root.join("deploy/render-loop.sh"))
            .env("FRAY", env!("CARGO_BIN_EXE_fray"))
            .env("FRAY_MODE", "tiles")
            .env("FRAY_JOBS", jobs)
            .env("FRAY_SCENE", &scene)
            .env("FRAY_OUT", &out)
            .env("FRAY_ARGS", format!("{args} --backend cpu --threads 1"))
            .current_dir(root)
            .output()
            .expect("sh runs");
        ok(&o);
        let tiles = std::fs::read_dir(&out)
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .is_ok_and(|e| e.file_name().to_string_lossy().starts_with("tile_"))
            })
            .count();
        assert_eq!(tiles.to_string(), jobs, "{name}: one tile per job");
        assert!(
            bytes(&out.join("image.png")) == bytes(&whole),
            "{name}: the assembled tiles differ from the whole image"
        );
    }
}

/// The frames mode of the same script shares a range out: every frame once, none twice.
#[test]
fn the_job_script_shares_frames_out_without_gaps() {
    let dir = temp_dir("jobframes");
    let scene = dir.join("animated.ron");
    std::fs::write(&scene, ANIMATED).unwrap();
    let out = dir.join("out");
    let o = Command::new(Path::new(env!("CARGO_MANIFEST_DIR")).join("deploy/render-loop.sh"))
        .env("FRAY", env!("CARGO_BIN_EXE_fray"))
        .env("FRAY_MODE", "frames")
        .env("FRAY_FRAMES", "1..6")
        .env("FRAY_JOBS", "3")
        .env("FRAY_SCENE", &scene)
        .env("FRAY_OUT", &out)
        .env("FRAY_ARGS", "--width 32 --backend cpu --threads 1")
        .output()
        .expect("sh runs");
    ok(&o);
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "frame_0001.png",
            "frame_0002.png",
            "frame_0003.png",
            "frame_0004.png",
            "frame_0005.png"
        ]
    );
}

/// Tiles on the GPU (lavapipe in CI) are their rows of the GPU's whole frame, bit for bit, with
/// each tile rendered by its own process; reported as skipped where no adapter exists (a
/// failure under `FRAY_REQUIRE_GPU=1`).
#[test]
fn gpu_tiles_from_separate_processes_reassemble_bit_exactly() {
    let dir = temp_dir("gpu_tiles");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = root.join("data/scenes/terrain_low.ron");
    let whole = dir.join("whole.png");
    let o = fray(&[
        "render",
        scene.to_str().unwrap(),
        "--backend",
        "gpu",
        "--width",
        "96",
        "--quiet",
        "-o",
        whole.to_str().unwrap(),
    ]);
    if !o.status.success() {
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            !std::env::var("FRAY_REQUIRE_GPU").is_ok_and(|v| v == "1"),
            "FRAY_REQUIRE_GPU=1 but the GPU render failed: {err}"
        );
        assert!(err.contains("no GPU adapter"), "{err}");
        eprintln!("skipped: no GPU adapter");
        return;
    }
    let out = dir.join("tiles");
    let o = Command::new(root.join("deploy/render-loop.sh"))
        .env("FRAY", env!("CARGO_BIN_EXE_fray"))
        .env("FRAY_MODE", "tiles")
        .env("FRAY_JOBS", "3")
        .env("FRAY_SCENE", &scene)
        .env("FRAY_OUT", &out)
        .env("FRAY_ARGS", "--width 96 --backend gpu")
        .current_dir(root)
        .output()
        .expect("sh runs");
    ok(&o);
    assert!(
        bytes(&out.join("image.png")) == bytes(&whole),
        "the assembled GPU tiles differ from the whole GPU image"
    );
}
