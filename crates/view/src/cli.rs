//! `fray view`'s command-line arguments (the CLI parses them; the viewer runs them).

use crate::overlay::Look;
use crate::{ViewBackend, ViewError, ViewOptions};
use fray_core::{MemoryBudget, PixelSamples};
use fray_scene::{BuildOptions, Scene};
use std::path::PathBuf;

/// `fray view [SCENE]`: fly through a scene in a window.
#[derive(clap::Args, Clone, Debug)]
pub struct ViewArgs {
    /// The scene file (.ron); if omitted, data/scenes/showcase.ron where it is found, else the
    /// built-in default scene.
    pub scene: Option<PathBuf>,
    /// The window's size in pixels, e.g. 1280x720 [default: the scene's image size].
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Which backend renders: the GPU draws every frame; the CPU renders progressively (coarse
    /// while moving, full and anti-aliased when still). Auto: the GPU unless its only adapter is
    /// a software one.
    #[arg(long, value_enum, default_value_t = BackendArg::Auto)]
    pub backend: BackendArg,
    /// CPU worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Anti-aliasing samples per pixel in 1..=64 [default: the scene's `settings.samples`]: every
    /// GPU frame, the CPU's still frames.
    #[arg(long, value_name = "N", value_parser = parse_samples)]
    pub samples: Option<PixelSamples>,
    /// Where the save key (F12, Ctrl+S) writes: .png or .exr [default: <scene>-view-<n>.png].
    #[arg(long, value_name = "PATH")]
    pub save_as: Option<PathBuf>,
    /// Exit after this many frames have been shown, printing the frame rate (measurements, tests).
    #[arg(long, value_name = "N")]
    pub exit_after_frames: Option<u64>,
    /// Exit after the first save (tests).
    #[arg(long)]
    pub exit_after_save: bool,
    /// Turn the camera a little every frame, without waiting for the display's refresh: every
    /// frame a moving camera's (measuring frames per second).
    #[arg(long)]
    pub turntable: bool,
    /// Start with the overlay hidden (H or F1 shows it).
    #[arg(long)]
    pub no_overlay: bool,
    /// Start playing the scene's animation (space plays and pauses it).
    #[arg(long)]
    pub play: bool,
    /// What the window shows at first: the picture, the frame's depth or normals, or a view the
    /// CPU probes — the quadtree's cells, search steps per pixel, the terrain's level of detail.
    #[arg(long, value_enum, default_value_t = Look::Colour)]
    pub look: Look,
    /// The memory budget to build the scene and render within [default: FRAY_MEMORY_BUDGET or 4G].
    #[arg(long, value_name = "BYTES")]
    pub memory_budget: Option<MemoryBudget>,
}

/// `--backend`'s values.
#[derive(Clone, Copy, Debug, Default, clap::ValueEnum)]
pub enum BackendArg {
    Cpu,
    Gpu,
    #[default]
    Auto,
}

impl ViewArgs {
    /// How the scene is built.
    pub fn build_options(&self) -> BuildOptions<'static> {
        BuildOptions::within(self.memory_budget.clone().unwrap_or_default())
    }

    /// Runs the viewer on `scene` (named `name`) with these arguments.
    pub fn run(&self, scene: Scene, name: String) -> Result<(), String> {
        self.options(scene, name)
            .and_then(crate::run)
            .map_err(|e| e.to_string())
    }

    fn options(&self, scene: Scene, name: String) -> Result<ViewOptions, ViewError> {
        let options = |e: String| ViewError::Options(e);
        fray_render::RenderOptions {
            threads: self.threads,
            ..Default::default()
        }
        .check()
        .map_err(|e| options(e.to_string()))?;
        if let Some(path) = &self.save_as {
            fray_render::output::check_extension(path).map_err(|e| options(e.to_string()))?;
        }
        if self.exit_after_frames == Some(0) {
            return Err(options("--exit-after-frames needs at least 1 frame".into()));
        }
        Ok(ViewOptions {
            size: self.size,
            backend: match self.backend {
                BackendArg::Cpu => ViewBackend::Cpu,
                BackendArg::Gpu => ViewBackend::Gpu,
                BackendArg::Auto => ViewBackend::Auto,
            },
            threads: self.threads,
            samples: self.samples,
            save_as: self.save_as.clone(),
            exit_after_frames: self.exit_after_frames,
            exit_after_save: self.exit_after_save,
            overlay: !self.no_overlay,
            turntable: self.turntable,
            play: self.play,
            look: self.look,
            ..ViewOptions::new(scene, name)
        })
    }
}

/// `WxH` with both sides in 1..=16384.
fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let bad = || format!("a size WIDTHxHEIGHT in pixels is needed (e.g. 1280x720), got {text:?}");
    let (w, h) = text.split_once(['x', 'X', '×']).ok_or_else(bad)?;
    let side = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|v| (1..=16384).contains(v))
    };
    Ok((side(w).ok_or_else(bad)?, side(h).ok_or_else(bad)?))
}

/// Samples in 1..=64 (the overlay's range).
fn parse_samples(text: &str) -> Result<PixelSamples, String> {
    let n: u32 = text
        .parse()
        .ok()
        .filter(|n| (1..=64).contains(n))
        .ok_or_else(|| format!("a whole number of samples in 1..=64 is needed, got {text:?}"))?;
    PixelSamples::new(n).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_samples_parse_and_bad_ones_are_refused() {
        assert_eq!(parse_size("1280x720"), Ok((1280, 720)));
        assert_eq!(parse_size("320×240"), Ok((320, 240)));
        for bad in ["1280", "0x10", "10x", "x10", "20000x10", "axb"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_samples("4").map(|s| s.count()), Ok(4));
        for bad in ["0", "65", "two"] {
            assert!(parse_samples(bad).is_err(), "{bad}");
        }
    }
}
