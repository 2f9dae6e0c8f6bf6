//! `cargo xtask regress`: render every scene on every available backend at test size, compare
//! with the blessed references (and the backends with each other), write the HTML report.

use crate::compare::{compare, diff_image};
use crate::render::{Rendered, backend_name, load, render, save_rgb8};
use crate::report::{self, Row, console_line};
use crate::thresholds::{SceneThresholds, ThresholdTable};
use crate::workspace::{SceneFile, list_scenes};
use fray_core::Image;
use fray_render::available_backends;
use fray_render::output::read_png_rgb8;
use std::path::{Path, PathBuf};

/// Where regress reads and writes, and the test size.
#[derive(Clone, Debug)]
pub struct RegressOptions {
    pub scenes: PathBuf,
    pub reference: PathBuf,
    pub out: PathBuf,
    /// Image width; the height keeps the scene's aspect ratio.
    pub width: u32,
}

/// Runs the regression; `Ok(true)` when every row passed. `Err` is a setup failure (no scene
/// directory, unreadable thresholds, unwritable output directory).
pub fn run(options: &RegressOptions) -> Result<bool, String> {
    let scenes = list_scenes(&options.scenes)?;
    let thresholds = ThresholdTable::load(&options.reference)?;
    let backends = available_backends();
    if backends.is_empty() {
        return Err("no backend is available".to_owned());
    }
    std::fs::create_dir_all(&options.out)
        .map_err(|e| format!("cannot create {}: {e}", options.out.display()))?;
    if scenes.is_empty() {
        println!("regress: no *.ron scenes in {}", options.scenes.display());
    }

    let mut rows = Vec::new();
    for scene in &scenes {
        for row in regress_scene(scene, options, thresholds.get(&scene.stem), &backends) {
            println!("{}", console_line(&row));
            rows.push(row);
        }
    }

    let title = format!(
        "fray regress — {} scenes, width {}",
        scenes.len(),
        options.width
    );
    report::write(&options.out, &rows, &title)?;
    let failed = rows.iter().filter(|r| !r.pass).count();
    println!(
        "regress: {} passed, {failed} failed; report: {}",
        rows.len() - failed,
        options.out.join("index.html").display()
    );
    Ok(failed == 0)
}

/// The reference image of `stem`, copied into the report directory. `Err` is the row message.
fn reference(stem: &str, options: &RegressOptions) -> Result<(Image<[u8; 3]>, String), String> {
    let path = options.reference.join(format!("{stem}.png"));
    if !path.exists() {
        return Err(format!(
            "no reference {}: run `cargo xtask bless {stem}`",
            path.display()
        ));
    }
    let image = read_png_rgb8(&path).map_err(|e| e.to_string())?;
    let copy = format!("{stem}.reference.png");
    save_rgb8(&image, &options.out.join(&copy))?;
    Ok((image, copy))
}

/// Compares `actual` with `expected` into `row`, writing the diff image as `diff_name`.
fn judge(
    row: &mut Row,
    expected: &Image<[u8; 3]>,
    actual: &Image<[u8; 3]>,
    out: &Path,
    diff_name: String,
) {
    let result = compare(expected, actual).and_then(|m| Ok((m, diff_image(expected, actual)?)));
    match result {
        Ok((metrics, diff)) => {
            row.metrics = Some(metrics);
            row.pass = row.thresholds.pass(&metrics);
            match save_rgb8(&diff, &out.join(&diff_name)) {
                Ok(()) => row.diff = Some(diff_name),
                Err(e) => row.message = Some(e),
            }
        }
        Err(mismatch) => {
            row.pass = false;
            row.message = Some(format!("{mismatch} (blessed at another --size?)"));
        }
    }
}

fn regress_scene(
    scene: &SceneFile,
    options: &RegressOptions,
    thresholds: SceneThresholds,
    backends: &[fray_render::Backend],
) -> Vec<Row> {
    let stem = scene.stem.as_str();
    let loaded = match load(&scene.path) {
        Ok(s) => s,
        Err(e) => {
            let path = scene.path.display().to_string();
            // The loader's messages usually name the file already.
            let msg = if e.contains(&path) {
                e
            } else {
                format!("cannot load {path}: {e}")
            };
            return vec![Row::failure(stem, "-", msg)];
        }
    };
    let reference = reference(stem, options);

    let mut rows = Vec::new();
    let mut first: Option<(String, Rendered)> = None;
    for &backend in backends {
        let name = backend_name(backend);
        let mut row = Row::failure(stem, &name, String::new());
        row.thresholds = thresholds.for_row(&name);
        row.message = None;
        if backend == fray_render::Backend::Gpu
            && let Some(feature) = fray_render::gpu_unsupported_feature(&loaded)
        {
            // Not a regression: the GPU refuses the scene by design until it draws this.
            row.pass = true;
            row.message = Some(format!(
                "skipped: the GPU backend does not draw {feature} yet"
            ));
            rows.push(row);
            continue;
        }
        let rendered = match render(&loaded, backend, options.width) {
            Ok(r) => r,
            Err(e) => {
                rows.push(Row::failure(stem, &name, format!("render failed: {e}")));
                continue;
            }
        };
        row.render = Some((rendered.wall, rendered.frame.stats.clone()));
        let actual_name = format!("{stem}.{name}.png");
        match save_rgb8(&rendered.image, &options.out.join(&actual_name)) {
            Ok(()) => row.actual = Some(actual_name),
            Err(e) => row.message = Some(e),
        }
        match &reference {
            Ok((expected, copy)) => {
                row.reference = Some(copy.clone());
                let diff_name = format!("{stem}.{name}.diff.png");
                judge(&mut row, expected, &rendered.image, &options.out, diff_name);
            }
            Err(e) => {
                row.pass = false;
                row.message = Some(e.clone());
            }
        }
        rows.push(row);

        // Backends beyond the first (the reference backend) are also held to the first.
        match &first {
            None => first = Some((name, rendered)),
            Some((first_name, first_rendered)) => {
                let pair = format!("{name} vs {first_name}");
                let mut row = Row::failure(stem, &pair, String::new());
                row.message = None;
                row.thresholds = thresholds.for_row(&pair);
                row.reference = Some(format!("{stem}.{first_name}.png"));
                row.actual = Some(format!("{stem}.{name}.png"));
                let diff_name = format!("{stem}.{name}-vs-{first_name}.diff.png");
                judge(
                    &mut row,
                    &first_rendered.image,
                    &rendered.image,
                    &options.out,
                    diff_name,
                );
                rows.push(row);
            }
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bless::{self, BlessOptions};
    use fray_render::Backend;

    const SPHERE: &str = "Scene(camera: Pinhole(eye: (0, 0, -4), look_at: (0, 0, 0)), \
                          objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))])";

    #[test]
    fn blessed_scenes_pass_on_every_backend_and_against_each_other() {
        let dir = std::env::temp_dir().join(format!("xtask-regress-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let scenes = dir.join("scenes");
        std::fs::create_dir_all(&scenes).unwrap();
        std::fs::write(scenes.join("sphere.ron"), SPHERE).unwrap();
        std::fs::write(scenes.join("broken.ron"), "Scene(").unwrap();
        let options = RegressOptions {
            scenes: scenes.clone(),
            reference: dir.join("reference"),
            out: dir.join("out"),
            width: 24,
        };
        std::fs::create_dir_all(&options.out).unwrap();
        let list = list_scenes(&scenes).unwrap();
        let (broken, sphere) = (&list[0], &list[1]);
        // Two CPU runs: "backends" that must agree exactly. (`Auto` may resolve to the GPU, whose
        // f32 image is close to the CPU's but not bit-identical.)
        let backends = [Backend::Cpu, Backend::Cpu];

        let rows = regress_scene(sphere, &options, SceneThresholds::default(), &backends);
        // Without a reference each backend fails; they still agree with each other.
        assert_eq!(
            rows.iter().map(|r| r.pass).collect::<Vec<_>>(),
            [false, false, true]
        );
        assert!(
            rows[0]
                .message
                .as_deref()
                .unwrap()
                .contains("cargo xtask bless sphere")
        );

        let bless = BlessOptions {
            scenes: scenes.clone(),
            reference: options.reference.clone(),
            width: 24,
            stems: vec!["sphere".into()],
        };
        bless::run(&bless).unwrap();
        let rows = regress_scene(sphere, &options, SceneThresholds::default(), &backends);
        let names: Vec<&str> = rows.iter().map(|r| r.backend.as_str()).collect();
        assert_eq!(names, ["cpu", "cpu", "cpu vs cpu"]);
        for row in &rows {
            assert!(row.pass, "{row:?}");
            assert_eq!(row.metrics.unwrap().rmse, 0.0);
            assert!(options.out.join(row.diff.as_ref().unwrap()).is_file());
        }
        assert!(options.out.join("sphere.cpu.png").is_file());
        assert!(options.out.join("sphere.reference.png").is_file());

        let rows = regress_scene(broken, &options, SceneThresholds::default(), &backends);
        assert_eq!(rows.len(), 1);
        assert!(!rows[0].pass);
        assert!(rows[0].message.as_deref().unwrap().contains("broken.ron"));

        // The whole run fails because of the broken scene, and writes the report.
        assert!(!run(&options).unwrap());
        assert!(options.out.join("index.html").is_file());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
