//! End-to-end tests of the `fray` binary: the default scene, outputs, and clear errors (never a
//! panic) for malformed scenes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;

use common::fray;

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("cli", name)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn default_scene_renders_to_png() {
    let dir = temp_dir("default");
    let out = dir.join("plane.png");
    let o = fray(&[
        "render",
        "--width",
        "64",
        "--quiet",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&out).expect("a readable PNG").to_rgb8();
    assert_eq!(img.width(), 64);
    // The aircraft covers part of the frame: not every pixel is the background.
    let first = *img.get_pixel(0, 0);
    assert!(img.pixels().any(|p| *p != first));
}

#[test]
fn summary_line_reports_time_and_steps() {
    let dir = temp_dir("summary");
    let out = dir.join("csg.exr");
    let o = fray(&[
        "render",
        "data/scenes/csg.ron",
        "--width",
        "48",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("Mrays/s") && stdout.contains("per ray") && stdout.contains("ms"),
        "{stdout}"
    );
    assert!(
        std::fs::metadata(&out)
            .map(|m| m.len() > 0)
            .unwrap_or(false)
    );
}

/// `fray check` prints what the scene charged to its memory account, item by item, and refuses
/// a scene over `--memory-budget` naming what and the limit.
#[test]
fn check_prints_the_memory_ledger() {
    let o = fray(&["check", "data/scenes/terrain_pair.ron"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("charged of the 4.00 GiB budget")
            && stdout.contains("height maps' f32 samples")
            && stdout.contains("terrains' pyramids"),
        "{stdout}"
    );
    let o = fray(&[
        "check",
        "data/scenes/terrain_pair.ron",
        "--memory-budget",
        "1M",
    ]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("memory budget of 1.00 MiB") && err.contains("objects["),
        "{err}"
    );
}

#[test]
fn check_lists_features() {
    let o = fray(&["check", "data/scenes/csg.ron"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("csg") && stdout.contains("free-form"),
        "{stdout}"
    );
}

/// Writes `body` to a scene file and runs `fray render` on it; returns stderr.
fn render_bad(name: &str, body: &str) -> (String, PathBuf) {
    let dir = temp_dir(name);
    let scene = dir.join(format!("{name}.ron"));
    std::fs::write(&scene, body).expect("write scene");
    let o = fray(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        dir.join("x.png").to_str().unwrap(),
    ]);
    assert!(!o.status.success(), "{name}: a malformed scene must fail");
    let err = stderr(&o);
    assert!(!err.contains("panicked"), "{name}: panicked: {err}");
    (err, scene)
}

fn assert_names(err: &str, scene: &Path, line: u32, field: &str) {
    let file = scene.display().to_string();
    assert!(err.contains(&file), "names the file: {err}");
    assert!(
        err.contains(&format!(":{line}:")),
        "names line {line}: {err}"
    );
    assert!(err.contains(field), "names the field `{field}`: {err}");
}

#[test]
fn malformed_scenes_fail_with_file_line_and_field() {
    let (err, path) = render_bad(
        "syntax",
        "Scene(\n  image: (width: 10, height: 10),\n  objects: [ (shape: Sphere(center: (0, 0, 0) radius: 1)) ],\n)\n",
    );
    assert_names(&err, &path, 3, "");

    let (err, path) = render_bad(
        "unknown_field",
        "Scene(\n  camera: Pinhole(eye: (0, 0, -5), look_at: (0, 0, 0)),\n  objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1, colour: 3)) ],\n)\n",
    );
    assert_names(&err, &path, 3, "colour");

    let (err, path) = render_bad(
        "negative_radius",
        "Scene(\n  camera: Pinhole(eye: (0, 0, -5), look_at: (0, 0, 0)),\n  objects: [\n    (shape: Sphere(center: (0, 0, 0), radius: -1)),\n  ],\n)\n",
    );
    assert_names(&err, &path, 4, "radius");

    let (err, path) = render_bad(
        "unbounded",
        "Scene(\n  camera: Pinhole(eye: (0, 0, -5), look_at: (0, 0, 0)),\n  objects: [\n    (shape: FreeForm(base: Cylinder(point: (0, 0, 0), axis: (0, 1, 0), radius: 1))),\n  ],\n)\n",
    );
    assert_names(&err, &path, 4, "shape");
    assert!(err.contains("unbounded") || err.contains("bounds"), "{err}");
}

#[test]
fn missing_scene_file_is_a_clear_error() {
    let o = fray(&["render", "no/such/scene.ron"]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("no/such/scene.ron") && !err.contains("panicked"),
        "{err}"
    );
}

#[test]
fn unsupported_output_extension_is_a_clear_error() {
    let o = fray(&[
        "render",
        "data/scenes/csg.ron",
        "--width",
        "8",
        "-o",
        "out.bmp",
    ]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("out.bmp") && !err.contains("panicked"),
        "{err}"
    );
    // Checked before anything renders: with no GPU adapter, `--backend gpu` would fail to
    // render, but the extension is what is reported (and nothing was rendered or written).
    let o = Command::new(env!("CARGO_BIN_EXE_fray"))
        .args([
            "render",
            "data/scenes/csg.ron",
            "--backend",
            "gpu",
            "-o",
            "out.bmp",
        ])
        .env("WGPU_BACKEND", "none")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the fray binary runs");
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("unsupported image extension") && !err.contains("no GPU adapter"),
        "{err}"
    );
    assert!(
        o.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
}

/// The README's first command, `cargo run --release` without arguments, in an empty folder:
/// the same picture, pixel for pixel, as `fray render` of the default scene file and as the
/// blessed full-size reference (`data/reference/default/turboprop.png`, written by
/// `cargo xtask bless`). The CPU renders it (`WGPU_BACKEND=none`), as it would on a machine
/// without a GPU. (Once the no-argument path built its options by hand with an exposure of 0 and
/// wrote an all-black picture that no test saw.)
#[test]
fn no_arguments_in_an_empty_folder_render_the_default_scene_like_fray_render() {
    let run = |dir: &Path, args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_fray"))
            .args(args)
            .env("WGPU_BACKEND", "none")
            .current_dir(dir)
            .output()
            .expect("the fray binary runs");
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    };
    let empty = temp_dir("no-arguments");
    let _ = std::fs::remove_dir_all(&empty);
    std::fs::create_dir_all(&empty).unwrap();
    run(&empty, &[]);
    let written: Vec<_> = std::fs::read_dir(&empty)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        written,
        ["turboprop.png"],
        "the no-argument run writes one file"
    );
    let explicit = temp_dir("render-default");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/scenes/turboprop.ron");
    let out = explicit.join("turboprop.png");
    run(
        &explicit,
        &[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
    );
    let pixels = |p: &Path| image::open(p).expect("a readable PNG").to_rgb8();
    let no_args = pixels(&empty.join("turboprop.png"));
    assert_eq!((no_args.width(), no_args.height()), (800, 600));
    assert!(
        no_args.pixels().any(|p| p.0.iter().any(|&c| c > 64)),
        "the picture is not dark"
    );
    assert!(no_args == pixels(&out), "no arguments ≠ fray render");
    let reference =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/reference/default/turboprop.png");
    assert!(
        no_args == pixels(&reference),
        "no arguments ≠ {} (re-bless with `cargo xtask bless` after a reviewed change)",
        reference.display()
    );
    let _ = std::fs::remove_dir_all(&empty);
    let _ = std::fs::remove_dir_all(&explicit);
}

#[test]
fn backend_flag_picks_cpu_or_gpu_and_gpu_without_adapter_is_a_clear_error() {
    let dir = temp_dir("backend");
    for backend in ["cpu", "gpu", "auto"] {
        let out = dir.join(format!("csg.{backend}.png"));
        let o = fray(&[
            "render",
            "data/scenes/csg.ron",
            "--width",
            "32",
            "--backend",
            backend,
            "-o",
            out.to_str().unwrap(),
        ]);
        let stdout = String::from_utf8_lossy(&o.stdout);
        if o.status.success() {
            let expect = match backend {
                "cpu" => "(cpu,",
                "gpu" => "(gpu (",
                _ => "",
            };
            assert!(stdout.contains(expect), "{backend}: {stdout}");
            assert!(out.is_file());
        } else {
            // Only the GPU may be missing, and then the message says so.
            assert_eq!(backend, "gpu", "{}", stderr(&o));
            assert!(stderr(&o).contains("no GPU adapter"), "{}", stderr(&o));
            assert!(
                std::env::var("FRAY_REQUIRE_GPU").map_or(true, |v| v != "1"),
                "FRAY_REQUIRE_GPU=1 but: {}",
                stderr(&o)
            );
        }
    }
}

/// Forces "no GPU adapter" on any machine: `WGPU_BACKEND=none` names no wgpu backend, so the
/// instance has none to search (a subprocess, so the rest of the tests keep their adapter).
#[test]
fn without_any_gpu_adapter_auto_warns_and_renders_on_the_cpu_and_gpu_is_a_clear_error() {
    let dir = temp_dir("no-adapter");
    let run = |backend: &str, out: &Path| {
        Command::new(env!("CARGO_BIN_EXE_fray"))
            .args([
                "render",
                "data/scenes/csg.ron",
                "--width",
                "24",
                "--backend",
                backend,
                "-o",
                out.to_str().unwrap(),
            ])
            .env("WGPU_BACKEND", "none")
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .expect("the fray binary runs")
    };
    let out = dir.join("auto.png");
    let o = run("auto", &out);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("warning: no GPU adapter"),
        "{}",
        stderr(&o)
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("(cpu,"), "{stdout}");
    assert!(out.is_file());
    let out = dir.join("gpu.png");
    let o = run("gpu", &out);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("no GPU adapter"), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A size the scene validation accepts but the memory budget does not: a clear error before
/// anything large is allocated (never an abort in the allocator); a larger budget is an option.
#[test]
fn a_frame_over_the_memory_budget_is_a_clear_error() {
    let o = fray(&[
        "render",
        "data/scenes/csg.ron",
        "--width",
        "16384",
        "--height",
        "16384",
        "--backend",
        "cpu",
        "-o",
        "never-written.png",
    ]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("memory budget of 4.00 GiB") && err.contains("--memory-budget"),
        "{err}"
    );
    let o = fray(&[
        "render",
        "data/scenes/csg.ron",
        "--width",
        "64",
        "--memory-budget",
        "1K",
        "-o",
        "never-written.png",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("memory budget of 1.00 KiB"),
        "{}",
        stderr(&o)
    );
    // The budget covers what the scene itself builds: here the CT volume's 1 MiB grid, which
    // with its 1 MiB file does not fit in 1.5 MiB (the file alone does).
    let o = fray(&[
        "render",
        "data/scenes/clouds_ct_skull.ron",
        "--memory-budget",
        "1536K",
        "-o",
        "never-written.png",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("clouds.density.path") && stderr(&o).contains("64 × 64 × 64 volume"),
        "{}",
        stderr(&o)
    );
    let o = fray(&["render", "--memory-budget", "4X", "-o", "never-written.png"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("K, M, G or T suffix"), "{}", stderr(&o));
    assert!(
        !Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("never-written.png")
            .exists()
    );
}

/// The atmosphere from the command line: `--media-grid` alone takes the default spacing and the
/// summary says so; a spacing outside 0, 2..=64 is a clear error; a fog scene says it ran fog.
#[test]
fn media_grid_option_and_fog_in_the_summary() {
    let dir = temp_dir("media");
    let out = dir.join("fog.png");
    let scene = "data/scenes/fog_aircraft_low_sun.ron";
    let o = fray(&[
        "render",
        scene,
        "--backend",
        "cpu",
        "--width",
        "96",
        "--media-grid",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = String::from_utf8_lossy(&o.stdout);
    assert!(
        summary.contains("fog") && summary.contains("media grid every 8 px"),
        "{summary}"
    );
    let o = fray(&[
        "render",
        scene,
        "--media-grid",
        "1",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("0 (every pixel) or a spacing in 2..=64"),
        "{}",
        stderr(&o)
    );
    let o = fray(&["check", scene]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("fog"));
}

/// Writes `body` as `name.ron` into a fresh temp dir and runs `fray check` on it.
fn check_scene(name: &str, body: &str) -> (Output, PathBuf) {
    let scene = temp_dir(name).join(format!("{name}.ron"));
    std::fs::write(&scene, body).expect("write scene");
    (fray(&["check", scene.to_str().unwrap()]), scene)
}

#[test]
fn check_counts_objects_of_every_kind() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data");
    let bunny = data.join("meshes/bunny00.obj").display().to_string();
    let dem = data
        .join("terrain/jacksboro_fault_dem.png")
        .display()
        .to_string();
    let mesh = format!("(name: \"bunny\", shape: Mesh(path: \"{bunny}\"))");
    let terrain = format!("(name: \"land\", shape: Terrain(path: \"{dem}\", spacing: (74, 93)))");
    let sphere = "(shape: Sphere(center: (0, 0, 0), radius: 1))";
    for (name, objects, line) in [
        (
            "mesh-only",
            vec![mesh.as_str()],
            "1 objects (0 free-form with 0 free forms and 0 perturbations, 0 terrain, 1 mesh)",
        ),
        (
            "terrain-only",
            vec![terrain.as_str()],
            "1 objects (0 free-form with 0 free forms and 0 perturbations, 1 terrain, 0 mesh)",
        ),
        (
            "every-kind",
            vec![sphere, terrain.as_str(), mesh.as_str(), mesh.as_str()],
            "4 objects (1 free-form with 1 free forms and 0 perturbations, 1 terrain, 2 mesh)",
        ),
    ] {
        let body = format!("(objects: [{}])", objects.join(", "));
        let (o, _) = check_scene(name, &body);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(stdout.contains(line), "{name}: {stdout}");
    }
}

#[test]
fn threads_past_the_machines_limit_are_refused_before_the_scene_is_loaded() {
    // The bound: 8 threads per core (fray_trace::MAX_THREADS_PER_CORE). The scene named does
    // not exist: the refusal comes before it is read, and before any thread starts.
    let started = std::time::Instant::now();
    let o = fray(&["render", "no/such/scene.ron", "--threads", "10000"]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("10000 worker threads asked for, over the limit of")
            && err.contains("per core")
            && !err.contains("scene.ron"),
        "{err}"
    );
    // Nothing to wait for: the old path started 10 000 threads first (minutes).
    assert!(started.elapsed().as_secs() < 10, "{:?}", started.elapsed());
}

#[test]
fn check_refuses_a_cloud_march_or_bake_past_its_cap_at_once() {
    // The reproducers: a step of 1e-7 in a unit box (1.7e7 steps per ray: hours), and a
    // 1024³ layer (4 GiB, within the default budget: more than ten minutes to bake). Each is
    // refused at load at its field, naming its cost and the cap.
    let (o, scene) = check_scene(
        "cloud-step",
        "(clouds: (region: (min: (0, 0, 0), max: (1, 1, 1)),\n  step: 1e-7,\n  density: Layer((resolution: (8, 8, 8)))))",
    );
    assert!(!o.status.success());
    assert_names(&stderr(&o), &scene, 2, "clouds.step");
    assert!(
        stderr(&o).contains("over the cap of 65536"),
        "{}",
        stderr(&o)
    );
    let started = std::time::Instant::now();
    let (o, scene) = check_scene(
        "cloud-bake",
        "(clouds: (region: (min: (0, 0, 0), max: (1, 1, 1)),\n  density: Layer((\n    resolution: (1024, 1024, 1024)))))",
    );
    assert!(!o.status.success());
    assert_names(&stderr(&o), &scene, 3, "clouds.density.resolution");
    assert!(
        stderr(&o).contains("units of work, over the cap of 1073741824"),
        "{}",
        stderr(&o)
    );
    assert!(started.elapsed().as_secs() < 10, "{:?}", started.elapsed());
}

/// The summary's hit fraction is of pixels: anti-aliasing samples do not divide it (each pixel's
/// depth comes from its centre ray, whatever the samples).
#[test]
fn hit_fraction_is_of_pixels_whatever_the_samples() {
    let dir = temp_dir("hits");
    let out = dir.join("csg.png");
    let hit_percent = |samples: &str| -> f64 {
        let o = fray(&[
            "render",
            "data/scenes/csg.ron",
            "--backend",
            "cpu",
            "--width",
            "80",
            "--samples",
            samples,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
        let at = stdout
            .find("% hit")
            .unwrap_or_else(|| panic!("no hit fraction: {stdout}"));
        let number = stdout[..at].rsplit(' ').next().unwrap();
        number.parse().unwrap_or_else(|e| panic!("{number:?}: {e}"))
    };
    let one = hit_percent("1");
    let four = hit_percent("4");
    assert!(
        one > 30.0,
        "csg.ron's objects cover most of the frame: {one}%"
    );
    assert_eq!(one, four, "the same pixels hit");
}

/// The robustness issue's reproducers, run as a user runs them — the `fray` binary on the CPU —
/// under a 6 GiB address-space limit (`ulimit -v`): each ends by itself within a minute (most in
/// well under a second) with a clear error, or with its image where the work is bounded, and
/// none panics or aborts in the allocator.
#[test]
fn the_robustness_reproducers_end_in_seconds_under_a_6_gib_address_space_limit() {
    use std::io::Write;
    let dir = temp_dir("reproducers");
    let write = |name: &str, body: &str| {
        let path = dir.join(name);
        std::fs::write(&path, body).unwrap();
        path.to_string_lossy().into_owned()
    };
    // An include bomb: each file includes the next ten times, nine levels (10⁹ objects).
    for level in 0..9 {
        let next = format!("\"bomb{}.ron\"", level + 1);
        write(
            &format!("bomb{level}.ron"),
            &format!("(include: [{}])", vec![next; 10].join(", ")),
        );
    }
    write(
        "bomb9.ron",
        "(objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))])",
    );
    // A duplicate-triangle mesh (5·10⁴ copies of one triangle: over 300 s before the BVH build
    // was made O(n log n)), and one face of 3·10⁶ corners under a 64 MiB budget.
    let mut copies = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for _ in 0..50_000 {
        copies.push_str("f 1 2 3\n");
    }
    std::fs::write(dir.join("copies.obj"), copies).unwrap();
    let mut face = std::io::BufWriter::new(std::fs::File::create(dir.join("face.obj")).unwrap());
    face.write_all(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf")
        .unwrap();
    for k in 0..3_000_000 {
        write!(face, " {}", 1 + k % 4).unwrap();
    }
    face.write_all(b"\n").unwrap();
    drop(face);
    let mesh_scene = |obj: &str| {
        format!(
            "(image: (width: 48, height: 32), camera: Pinhole(eye: (0.3, 0.3, 3), look_at: (0.3, 0.3, 0)),
              lights: [Sun(direction: (0, 0, 1), irradiance: (1, 1, 1))],
              objects: [(shape: Mesh(path: \"{obj}\"))])"
        )
    };
    let endless = |shape: &str| format!("(objects: [(shape: {shape})])");
    let cases: Vec<(&str, Vec<String>, Option<&str>)> = vec![
        (
            "an include bomb",
            vec![
                "check".into(),
                write("bomb.ron", "(include: [\"bomb0.ron\"])"),
            ],
            Some("include["),
        ),
        (
            "/dev/zero as a height map",
            vec![
                "check".into(),
                write(
                    "zero_map.ron",
                    &endless("Terrain(path: \"/dev/zero\", spacing: (1, 1))"),
                ),
            ],
            Some("/dev/zero"),
        ),
        (
            "/dev/zero as a mesh",
            vec![
                "check".into(),
                write("zero_mesh.ron", &endless("Mesh(path: \"/dev/zero\")")),
            ],
            Some("/dev/zero"),
        ),
        (
            "/dev/zero as a cloud volume",
            vec![
                "check".into(),
                write(
                    "zero_volume.ron",
                    "(clouds: (region: (min: (0, 0, 0), max: (1, 1, 1)),
                       density: Volume(path: \"/dev/zero\", threshold: 1)))",
                ),
            ],
            Some("/dev/zero"),
        ),
        (
            "a cloud step of 1e-7",
            vec![
                "check".into(),
                write(
                    "cloud_step.ron",
                    "(clouds: (region: (min: (0, 0, 0), max: (1, 1, 1)), step: 1e-7,
                       density: Layer((resolution: (8, 8, 8)))))",
                ),
            ],
            Some("over the cap"),
        ),
        (
            "a face of 3·10⁶ corners under a 64 MiB budget",
            vec![
                "check".into(),
                "--memory-budget".into(),
                "64M".into(),
                write("face.ron", &mesh_scene("face.obj")),
            ],
            Some("memory budget"),
        ),
        (
            "5·10⁴ copies of one triangle",
            vec![
                "render".into(),
                "--backend".into(),
                "cpu".into(),
                write("copies.ron", &mesh_scene("copies.obj")),
                "-o".into(),
                dir.join("copies.png").to_string_lossy().into_owned(),
            ],
            None,
        ),
        (
            "two plates that reflect and transmit, depth 64",
            vec![
                "render".into(),
                "--backend".into(),
                "cpu".into(),
                write(
                    "plates.ron",
                    &fray_test_support::scenes::two_plates(64, 48, 64, 256),
                ),
                "-o".into(),
                dir.join("plates.png").to_string_lossy().into_owned(),
            ],
            None,
        ),
    ];
    for (what, args, refusal) in cases {
        let started = std::time::Instant::now();
        let mut child = Command::new("sh")
            .arg("-c")
            .arg("ulimit -v 6291456 && exec \"$0\" \"$@\"")
            .arg(env!("CARGO_BIN_EXE_fray"))
            .args(&args)
            .env_remove("FRAY_MEMORY_BUDGET")
            .env("WGPU_BACKEND", "none")
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // A hang is a failure, not a stuck test run.
        while child.try_wait().unwrap().is_none() {
            if started.elapsed().as_secs() > 60 {
                child.kill().unwrap();
                panic!("{what}: still running after 60 s");
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let o = child.wait_with_output().unwrap();
        let err = stderr(&o);
        eprintln!("{what}: {:.2?}", started.elapsed());
        assert!(
            o.status.code().is_some(),
            "{what}: killed by a signal ({:?}): {err}",
            o.status
        );
        assert!(
            !err.contains("panicked") && !err.contains("memory allocation of"),
            "{what}: {err}"
        );
        match refusal {
            Some(words) => assert!(
                !o.status.success() && err.contains(words),
                "{what}: expected a refusal naming {words:?}: {err}"
            ),
            None => assert!(o.status.success(), "{what}: {err}"),
        }
    }
}
