//! Worker threads: a render may ask for up to `MAX_THREADS_PER_CORE` (8) per core the machine
//! reports; past that it is refused before any thread starts or any image is allocated, naming
//! the limit — `--threads 10000` spent minutes starting threads before.

use fray_trace::{MAX_THREADS_PER_CORE, TraceError, TraceSettings, max_threads, render};

fn sphere() -> fray_scene::Scene {
    let mut scene = fray_scene::parse(
        "Scene(camera: Pinhole(eye: (0, 0, -4), look_at: (0, 0, 0)), \
         objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))])",
        "sphere.ron",
    )
    .unwrap();
    (scene.width, scene.height) = (16, 12);
    scene
}

#[test]
fn threads_past_the_limit_are_refused_before_the_pool_is_built() {
    let scene = sphere();
    let mut settings = TraceSettings::for_scene(&scene);
    settings.threads = Some(10_000);
    let e = render(&scene, &settings, None).unwrap_err();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let limit = MAX_THREADS_PER_CORE * cores;
    assert_eq!(max_threads(), limit);
    assert_eq!(
        e,
        TraceError::TooManyThreads {
            threads: 10_000,
            limit,
            cores
        }
    );
    assert!(
        e.to_string().contains(&format!(
            "10000 worker threads asked for, over the limit of {limit} (8 per core × {cores} cores)"
        )),
        "{e}"
    );
    // One past the limit is refused; the limit itself and rayon's default (0) render.
    settings.threads = Some(max_threads() + 1);
    assert!(matches!(
        render(&scene, &settings, None),
        Err(TraceError::TooManyThreads { .. })
    ));
    for ok in [max_threads(), 0] {
        settings.threads = Some(ok);
        assert!(render(&scene, &settings, None).is_ok(), "{ok} threads");
    }
}
