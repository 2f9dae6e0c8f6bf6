//! Includes that fan out: a scene reads at most 64 files through `include`s, all levels together,
//! so a few lines that include a file which includes the next several times over (`k^depth`
//! files; found while writing the scene loader's fuzz target) are refused at once, at the
//! include past the limit, instead of being read and resolved one by one.

use std::time::{Duration, Instant};

fn folder(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("fray-includes-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn list(name: &str, times: usize) -> String {
    vec![format!("{name:?}"); times].join(", ")
}

#[test]
fn sixty_four_included_files_load_and_the_sixty_fifth_is_refused_where_it_is() {
    let dir = folder("flat");
    for k in 0..65 {
        std::fs::write(
            dir.join(format!("part{k}.ron")),
            r#"(materials: { "red": (diffuse: (0.8, 0.1, 0.1)) },
                objects: [(name: "ball", material: "red", shape: Sphere(radius: 1))])"#,
        )
        .unwrap();
    }
    let parts = |n: usize| {
        (0..n)
            .map(|k| format!("\"part{k}.ron\""))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let main = dir.join("main.ron");
    std::fs::write(&main, format!("(include: [{}])", parts(64))).unwrap();
    assert_eq!(fray_scene::load(&main).unwrap().objects.len(), 64);
    // One file included many times is read once.
    std::fs::write(&main, format!("(include: [{}])", list("part0.ron", 200))).unwrap();
    assert_eq!(fray_scene::load(&main).unwrap().objects.len(), 200);
    std::fs::write(&main, format!("(include: [{}])", parts(65))).unwrap();
    let e = fray_scene::load(&main).unwrap_err();
    assert_eq!(e.field(), Some("include[64]"), "{e}");
    assert!(
        e.to_string()
            .contains("file 65 read through includes, past the limit of 64"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Six includes of the next file on each of seven levels would be 6⁷ = 279 936 copies of one
/// object: refused at the object cap, in well under a second (the bound: 1 s).
#[test]
fn includes_fanning_out_are_refused_in_well_under_a_second() {
    let dir = folder("fan");
    let main = dir.join("main.ron");
    std::fs::write(&main, format!("(include: [{}])", list("a1.ron", 6))).unwrap();
    for level in 1..7 {
        let next = format!("a{}.ron", level + 1);
        std::fs::write(
            dir.join(format!("a{level}.ron")),
            format!("(include: [{}])", list(&next, 6)),
        )
        .unwrap();
    }
    std::fs::write(
        dir.join("a7.ron"),
        r#"(materials: { "m": (diffuse: (0.5, 0.5, 0.5)) },
            objects: [(name: "s", material: "m", shape: Sphere(radius: 1))])"#,
    )
    .unwrap();
    let started = Instant::now();
    let e = fray_scene::load(&main).unwrap_err().to_string();
    let took = started.elapsed();
    assert!(
        e.contains(&format!("more than the {}", fray_scene::MAX_OBJECTS)),
        "{e}"
    );
    assert!(took < Duration::from_secs(1), "took {took:?}");
    std::fs::remove_dir_all(&dir).ok();
}
