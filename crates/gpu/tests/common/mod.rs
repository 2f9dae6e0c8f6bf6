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

/// Runs `gpu_tests` (reported as ignored when [`gpu_tests_ignored`]) and `host_tests` (which need
/// no adapter and always run) under libtest-mimic, then exits with the result.
pub fn run(gpu_tests: &[(&'static str, fn())], host_tests: &[(&'static str, fn())]) -> ! {
    let args = libtest_mimic::Arguments::from_args();
    let ignored = gpu_tests_ignored();
    let trial = |&(name, test): &(&'static str, fn())| {
        libtest_mimic::Trial::test(name, move || {
            test();
            Ok(())
        })
    };
    let trials = gpu_tests
        .iter()
        .map(|t| trial(t).with_ignored_flag(ignored))
        .chain(host_tests.iter().map(trial))
        .collect();
    libtest_mimic::run(&args, trials).exit()
}
