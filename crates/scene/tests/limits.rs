//! No input stops a scene load: one memory account for everything a scene builds, files read
//! only when they are regular files that fit, invalid UTF-8 located, and includes that cannot
//! multiply past a cap. Each case ends in well under a second with an error naming what and the
//! limit.

use fray_core::MemoryBudget;
use fray_scene::{BuildOptions, SceneError, load_with, parse_with};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fray-limits-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A `rows × columns` `.npy` height map of `<f4` values (a gentle ramp).
fn write_npy(path: &Path, rows: usize, columns: usize) {
    let mut header =
        format!("{{'descr': '<f4', 'fortran_order': False, 'shape': ({rows}, {columns}), }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    for k in 0..rows * columns {
        bytes.extend_from_slice(&((k % columns) as f32 * 0.01).to_le_bytes());
    }
    std::fs::write(path, bytes).unwrap();
}

fn write_png(path: &Path, side: u32, shade: u8) {
    image::RgbImage::from_pixel(side, side, image::Rgb([shade, 128, 200]))
        .save(path)
        .unwrap();
}

fn load_within(path: &Path, budget: &MemoryBudget) -> Result<fray_scene::Scene, SceneError> {
    load_with(path, &BuildOptions::within(budget.clone()))
}

/// Each height map fits the budget alone; together they do not. The refusal names the map
/// that passed the limit, the total charged before it and the limit.
#[test]
fn terrains_are_charged_to_one_account() {
    let dir = temp_dir("terrains");
    let side = 512;
    let mut objects = String::new();
    for k in 0..4 {
        write_npy(&dir.join(format!("map{k}.npy")), side, side);
        objects.push_str(&format!(
            "(shape: Terrain(path: \"map{k}.npy\", origin: ({}, 0, 0))),",
            k * 600
        ));
    }
    let scene = dir.join("scene.ron");
    std::fs::write(
        &scene,
        format!("(camera: Pinhole(eye: (0, 50, -100), look_at: (0, 0, 0)), objects: [{objects}])"),
    )
    .unwrap();
    // A map's samples and its max pyramid: 4·512² + 4·(4/3)·511² ≈ 2.4 MB; a map loads at a
    // peak of about 3 MB (the file and the samples together).
    let roomy = MemoryBudget::new(64 << 20);
    let s = load_within(&scene, &roomy).unwrap();
    let charged = s.budget.charged();
    assert!(
        charged > 4 * 2_000_000,
        "four terrains charged only {charged} bytes"
    );
    let ledger = s.budget.ledger();
    assert!(
        ledger.iter().any(|(w, _)| w.contains("height maps")),
        "{ledger:?}"
    );
    assert!(
        ledger.iter().any(|(w, _)| w.contains("pyramids")),
        "{ledger:?}"
    );
    let tight = MemoryBudget::new(charged / 2);
    let e = load_within(&scene, &tight).unwrap_err().to_string();
    assert!(
        e.contains("already charged") && e.contains("memory budget") && e.contains("objects["),
        "{e}"
    );
}

/// Textures likewise: each mip chain fits, four do not.
#[test]
fn textures_are_charged_to_one_account() {
    let dir = temp_dir("textures");
    let mut materials = String::new();
    let mut objects = String::new();
    for k in 0..4 {
        write_png(&dir.join(format!("t{k}.png")), 512, 40 * k as u8);
        materials.push_str(&format!("\"m{k}\": (texture: (path: \"t{k}.png\")),"));
        objects.push_str(&format!(
            "(shape: Sphere(center: ({}, 0, 0), radius: 1), material: \"m{k}\"),",
            3 * k
        ));
    }
    let scene = dir.join("scene.ron");
    std::fs::write(
        &scene,
        format!(
            "(camera: Pinhole(eye: (0, 0, -10), look_at: (0, 0, 0)), materials: {{{materials}}}, \
             objects: [{objects}])"
        ),
    )
    .unwrap();
    // A 512² RGB chain is 4·3·512²·4/3 ≈ 4.2 MB.
    let s = load_within(&scene, &MemoryBudget::new(64 << 20)).unwrap();
    let chains: u64 = s
        .budget
        .ledger()
        .iter()
        .filter(|(w, _)| w.contains("mip chain"))
        .map(|(_, b)| b)
        .sum();
    assert!(chains >= 4 * 4_194_300, "{:?}", s.budget.ledger());
    let e = load_within(&scene, &MemoryBudget::new(10 << 20))
        .unwrap_err()
        .to_string();
    assert!(e.contains("already charged") && e.contains("t2.png"), "{e}");
}

/// `/dev/zero` given as any asset (here through links named as each loader expects) or as the
/// scene, an include or a folder is refused at once, at its field.
#[cfg(unix)]
#[test]
fn endless_and_special_files_are_refused_at_once() {
    let dir = temp_dir("special");
    for name in ["zero.npy", "zero.obj", "zero.png", "zero.inr"] {
        std::os::unix::fs::symlink("/dev/zero", dir.join(name)).unwrap();
    }
    let budget = MemoryBudget::new(256 << 20);
    let sphere = "(shape: Sphere(center: (0, 0, 0), radius: 1), material: \"m\")";
    let cases = [
        (
            "objects[0].shape.path",
            "",
            "(shape: Terrain(path: \"zero.npy\"))",
        ),
        (
            "objects[0].shape.path",
            "",
            "(shape: Mesh(path: \"zero.obj\"))",
        ),
        (
            "materials",
            "materials: { \"m\": (texture: (path: \"zero.png\")) },",
            sphere,
        ),
        (
            "clouds",
            "clouds: (region: (min: (-1, -1, -1), max: (1, 1, 1)), density: Volume(path: \"zero.inr\")),",
            sphere,
        ),
    ];
    for (k, (field, extra, object)) in cases.iter().enumerate() {
        let scene = dir.join(format!("s{k}.ron"));
        let materials = if extra.starts_with("materials") {
            ""
        } else {
            "materials: { \"m\": () },"
        };
        std::fs::write(
            &scene,
            format!(
                "(camera: Pinhole(eye: (0, 0, -10), look_at: (0, 0, 0)), {materials} {extra} \
                 objects: [{object}])"
            ),
        )
        .unwrap();
        let start = Instant::now();
        let e = load_within(&scene, &budget).unwrap_err().to_string();
        assert!(start.elapsed() < Duration::from_secs(2), "{e}");
        assert!(
            e.contains(field) && e.contains("character device"),
            "{field}: {e}"
        );
    }
    let zero = load_within(Path::new("/dev/zero"), &budget)
        .unwrap_err()
        .to_string();
    assert!(zero.contains("character device"), "{zero}");
    let folder = load_within(&dir, &budget).unwrap_err().to_string();
    assert!(folder.contains("directory"), "{folder}");
    let include = dir.join("include.ron");
    std::fs::write(&include, "(include: [\"/dev/zero\"])").unwrap();
    let e = load_within(&include, &budget).unwrap_err().to_string();
    assert!(
        e.contains("include[0]") && e.contains("character device"),
        "{e}"
    );
}

/// A scene file with a byte that is not UTF-8 is a syntax error at its line and column.
#[test]
fn invalid_utf8_is_located() {
    let dir = temp_dir("utf8");
    let scene = dir.join("scene.ron");
    std::fs::write(
        &scene,
        b"(\n  camera: Pinhole(eye: (0, 0, -4), look\xe9_at: (0, 0, 0)),\n)",
    )
    .unwrap();
    let e = load_within(&scene, &MemoryBudget::new(1 << 20)).unwrap_err();
    assert_eq!((e.line(), e.column()), (Some(2), Some(40)), "{e}");
    assert!(e.to_string().contains("invalid UTF-8 at byte 41"), "{e}");
}

/// Nine files, each including the next ten times, would make 10⁸ objects from a few hundred
/// bytes: each file is read and validated once, and the merge stops at the object cap.
#[test]
fn an_include_bomb_stops_at_the_object_cap() {
    let dir = temp_dir("bomb");
    std::fs::write(
        dir.join("f8.ron"),
        "(objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))])",
    )
    .unwrap();
    for k in (0..8).rev() {
        let next = format!("\"f{}.ron\"", k + 1);
        let list = vec![next; 10].join(", ");
        std::fs::write(
            dir.join(format!("f{k}.ron")),
            format!("(include: [{list}])"),
        )
        .unwrap();
    }
    let start = Instant::now();
    let e = load_within(&dir.join("f0.ron"), &MemoryBudget::new(1 << 30))
        .unwrap_err()
        .to_string();
    assert!(
        start.elapsed() < Duration::from_secs(10),
        "{:?}",
        start.elapsed()
    );
    assert!(
        e.contains("include[") && e.contains(&format!("more than the {}", fray_scene::MAX_OBJECTS)),
        "{e}"
    );
    // Below the cap, the included objects are all there and charged.
    let s = parse_with(
        "(include: [\"f6.ron\", \"f6.ron\"])",
        &dir.join("ok.ron").display().to_string(),
        &BuildOptions::within(MemoryBudget::new(1 << 30)),
    )
    .unwrap();
    assert_eq!(s.objects.len(), 200);
    assert!(
        s.budget
            .ledger()
            .iter()
            .any(|(w, b)| w.contains("objects") && *b >= 200 * 64),
        "{:?}",
        s.budget.ledger()
    );
}
