//! Shared helpers of the GPU integration tests: getting an adapter (or saying the test skipped).

use fray_gpu::GpuRenderer;

/// The GPU to test on. Without an adapter: a failure when `FRAY_REQUIRE_GPU=1` (CI, which
/// installs lavapipe), otherwise `None` after printing "skipped: no GPU adapter" — the caller
/// returns at once, so such a run checks nothing and says so.
pub fn gpu_or_skip(test: &str) -> Option<GpuRenderer> {
    match GpuRenderer::new() {
        Ok(r) => {
            eprintln!("{test}: on {}", r.context().adapter_name);
            Some(r)
        }
        Err(e) => {
            if std::env::var("FRAY_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("{test}: FRAY_REQUIRE_GPU=1 but the GPU is unavailable: {e}");
            }
            eprintln!("{test}: skipped: no GPU adapter ({e})");
            None
        }
    }
}
