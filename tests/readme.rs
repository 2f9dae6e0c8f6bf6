//! The README a user meets stays true: its gallery shows every data scene (through the regression
//! references, which `cargo xtask regress` keeps current), and its first picture is what the
//! first command renders today.

use std::path::Path;
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_gallery_shows_every_data_scene_through_its_reference_image() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let mut scenes: Vec<String> = std::fs::read_dir(root().join("data/scenes"))
        .unwrap()
        .filter_map(|e| {
            let name = e.ok()?.file_name().to_string_lossy().into_owned();
            name.strip_suffix(".ron").map(str::to_owned)
        })
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 20, "{scenes:?}");
    for scene in &scenes {
        let image = format!("data/reference/{scene}.png");
        assert!(
            readme.contains(&format!("({image})")),
            "README's gallery lacks {scene} ({image})"
        );
        assert!(root().join(&image).is_file(), "{image} is missing");
    }
}

/// The first command (`cargo run --release -- render data/scenes/showcase.ron`) on the CPU
/// backend at the picture's size gives the picture: no channel of any pixel off by more than
/// 1/255, the regression's bound for CPU renders (the CPU backend is deterministic).
#[test]
fn the_first_picture_is_what_the_first_command_renders() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    assert!(readme.contains("cargo run --release -- render data/scenes/showcase.ron\n"));
    assert!(readme.contains("](docs/showcase.png)"));
    let picture = image::open(root().join("docs/showcase.png"))
        .unwrap()
        .to_rgb8();
    let out = std::env::temp_dir().join(format!("fray-readme-{}.png", std::process::id()));
    let o = Command::new(env!("CARGO_BIN_EXE_fray"))
        .args([
            "render",
            "data/scenes/showcase.ron",
            "--backend",
            "cpu",
            "--quiet",
        ])
        .args(["--width", &picture.width().to_string(), "-o"])
        .arg(&out)
        .current_dir(root())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rendered = image::open(&out).unwrap().to_rgb8();
    assert_eq!(rendered.dimensions(), picture.dimensions());
    let worst = rendered
        .as_raw()
        .iter()
        .zip(picture.as_raw())
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap_or(0);
    assert!(
        worst <= 1,
        "docs/showcase.png is out of date (a channel differs by {worst}/255): render it again with \
         `cargo run --release -- render data/scenes/showcase.ron --backend cpu --width {} -o docs/showcase.png`",
        picture.width()
    );
}
