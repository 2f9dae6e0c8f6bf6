//! What `fray view` is asked to do: the scene, the window size, the backend and the test hooks.

use crate::overlay::Look;
use fray_core::PixelSamples;
use fray_scene::Scene;
use std::path::PathBuf;

/// Which backend renders the viewer's frames.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ViewBackend {
    /// The GPU when the window's adapter is a hardware one, else the CPU (a software adapter
    /// such as lavapipe is slower than the CPU backend).
    #[default]
    Auto,
    /// The CPU reference, progressively (coarse while moving, refined when still).
    Cpu,
    /// The GPU, on whatever adapter presents (lavapipe included).
    Gpu,
}

/// The viewer's options.
#[derive(Clone, Debug)]
pub struct ViewOptions {
    /// The scene as loaded: an animated one with its animation (the viewer starts at time 0).
    pub scene: Scene,
    /// The scene's name, for the window title and messages.
    pub name: String,
    /// The window's inner size in physical pixels (default: the scene's image size).
    pub size: Option<(u32, u32)>,
    pub backend: ViewBackend,
    /// CPU worker threads (default: all cores).
    pub threads: Option<usize>,
    /// Anti-aliasing samples of a still frame (default: the scene's `settings.samples`).
    pub samples: Option<PixelSamples>,
    /// Where the save key writes (.png or .exr; default `<scene>-view-<n>.png`).
    pub save_as: Option<PathBuf>,
    /// Exit after this many frames have been shown (tests, measurements).
    pub exit_after_frames: Option<u64>,
    /// Exit once a save has been written (tests).
    pub exit_after_save: bool,
    /// Show the overlay from the start (H or F1 toggles it).
    pub overlay: bool,
    /// Turn the camera a little every frame, so each frame is a moving camera's (measuring
    /// frames per second).
    pub turntable: bool,
    /// Start playing the scene's animation (space toggles it).
    pub play: bool,
    /// What the window shows at first (the overlay switches it).
    pub look: Look,
}

impl ViewOptions {
    /// The options for `scene` with everything else at its default.
    pub fn new(scene: Scene, name: impl Into<String>) -> Self {
        Self {
            scene,
            name: name.into(),
            size: None,
            backend: ViewBackend::Auto,
            threads: None,
            samples: None,
            save_as: None,
            exit_after_frames: None,
            exit_after_save: false,
            overlay: true,
            turntable: false,
            play: false,
            look: Look::Colour,
        }
    }
}
