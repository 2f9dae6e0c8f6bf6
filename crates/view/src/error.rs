//! Why the viewer could not run.

/// A viewer failure, with the reason in words.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    #[error("cannot open a window: {0}")]
    Window(String),
    #[error("no GPU adapter can present to the window: {0}")]
    NoAdapter(String),
    #[error("gpu backend: {0}")]
    Gpu(#[from] fray_gpu::GpuError),
    #[error("{0}")]
    Options(String),
    #[error("{0}")]
    Scene(#[from] fray_scene::SceneError),
}
