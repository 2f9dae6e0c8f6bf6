//! Shared helpers of the GPU integration tests: whether they can run here, and the adapter.

use fray_gpu::GpuRenderer;

/// Whether the GPU tests are reported as *ignored*: no adapter on this machine and
/// `FRAY_REQUIRE_GPU` is not `1`. Under `FRAY_REQUIRE_GPU=1` (CI, which installs lavapipe) they
/// always run, so a missing adapter is a failure there, never a silent pass.
pub fn gpu_tests_ignored() -> bool {
    let required = std::env::var("FRAY_REQUIRE_GPU").is_ok_and(|v| v == "1");
    match fray_gpu::probe_adapter() {
        Ok(_) => false,
        Err(e) => {
            if !required {
                eprintln!("GPU tests ignored: no GPU adapter ({e})");
            }
            !required
        }
    }
}

/// The GPU to test on; panics (the test fails) when it cannot be opened.
pub fn gpu(test: &str) -> GpuRenderer {
    match GpuRenderer::new() {
        Ok(r) => {
            eprintln!("{test}: on {}", r.context().adapter_name);
            r
        }
        Err(e) => panic!("{test}: the GPU is unavailable: {e}"),
    }
}

/// A named test: a closure over what it checks.
pub type Test = (String, Box<dyn FnOnce() + Send>);

/// Runs `gpu_tests` (reported as ignored when [`gpu_tests_ignored`]) and `host_tests` (which need
/// no adapter and always run) under libtest-mimic, then exits with the result.
#[allow(dead_code)] // the ray suite names closures ([`run_tests`])
pub fn run(gpu_tests: &[(&'static str, fn())], host_tests: &[(&'static str, fn())]) -> ! {
    let boxed = |tests: &[(&'static str, fn())]| -> Vec<Test> {
        tests
            .iter()
            .map(|&(name, test)| (name.to_owned(), Box::new(test) as Box<dyn FnOnce() + Send>))
            .collect()
    };
    run_tests(boxed(gpu_tests), boxed(host_tests))
}

/// [`run`] with closures.
pub fn run_tests(gpu_tests: Vec<Test>, host_tests: Vec<Test>) -> ! {
    let args = libtest_mimic::Arguments::from_args();
    let ignored = gpu_tests_ignored();
    let trial = |(name, test): Test| {
        libtest_mimic::Trial::test(name, move || {
            test();
            Ok(())
        })
    };
    let trials = gpu_tests
        .into_iter()
        .map(|t| trial(t).with_ignored_flag(ignored))
        .chain(host_tests.into_iter().map(trial))
        .collect();
    libtest_mimic::run(&args, trials).exit()
}

/// Pixels whose 3×3 neighbourhood in `labels` (row-major, `w × h`) is not uniform: where the
/// frame comparisons do not hold the backends to the colour bound (silhouettes, shadow edges).
#[allow(dead_code)] // not every test file compares frames
pub fn boundary<T: PartialEq + Copy>(labels: &[T], w: u32, h: u32) -> Vec<bool> {
    let at = |x: i64, y: i64| labels[(y as usize) * (w as usize) + x as usize];
    let mut out = vec![false; labels.len()];
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let c = at(x, y);
            let mut edge = false;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx >= 0 && ny >= 0 && nx < w as i64 && ny < h as i64 && at(nx, ny) != c {
                        edge = true;
                    }
                }
            }
            out[(y as usize) * (w as usize) + x as usize] = edge;
        }
    }
    out
}

/// The CPU frame's shadow boundaries: [`boundary`] of where `cpu` (rendered with `settings`)
/// differs from the same scene rendered without shadows, by more than 1e-6 in any channel.
#[allow(dead_code)] // not every test file compares frames
pub fn shadow_edges(
    scene: &fray_scene::Scene,
    settings: &fray_trace::TraceSettings,
    cpu: &fray_core::Frame,
) -> Vec<bool> {
    let unshadowed = fray_trace::render(
        scene,
        &fray_trace::TraceSettings {
            shadows: false,
            ..*settings
        },
        None,
    )
    .unwrap_or_else(|e| panic!("the unshadowed CPU frame: {e}"));
    let shadow: Vec<bool> = cpu
        .colour
        .pixels()
        .iter()
        .zip(unshadowed.colour.pixels())
        .map(|(a, b)| (*a - *b).abs().max_element() > 1e-6)
        .collect();
    boundary(&shadow, scene.width, scene.height)
}
