//! `fray-view`: the interactive viewer — a window (winit) with a wgpu surface, the scene
//! rendered by `fray-gpu` straight into the surface's frames or progressively by the CPU
//! reference, fly and orbit cameras, an egui overlay, and a save key that writes what
//! `fray render` would. The renderers know nothing of windows; this crate is their front end,
//! like the command line.

mod app;
mod camera;
mod cameras;
mod cli;
mod error;
mod gpu_path;
mod input;
mod options;
mod overlay;
mod present;
mod probe_view;
mod progressive;
mod save;
mod worker;

pub use camera::FlyCamera;
pub use cli::{BackendArg, ViewArgs};
pub use error::ViewError;
pub use options::{ViewBackend, ViewOptions};
pub use overlay::Look;
pub use probe_view::{ProbeImage, ProbeView, probe};

/// Opens the viewer's window on `options.scene` and runs until the window closes (or a test
/// hook in `options` ends it).
pub fn run(options: ViewOptions) -> Result<(), ViewError> {
    app::run(options)
}
