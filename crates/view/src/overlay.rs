//! The overlay (egui): what the last frame cost, pass by pass, and the switches a viewer turns.

use crate::present::DebugView;
use crate::probe_view::ProbeView;
use fray_core::RenderStats;
use fray_scene::Switches;

/// What the window shows: the picture, one of the frame's own debug images, or a view the CPU
/// probes from the camera.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Look {
    /// The picture.
    #[default]
    Colour,
    /// Depth as grey.
    Depth,
    /// Normals as colours.
    Normals,
    /// The quadtree's cells.
    Cells,
    /// Search steps per pixel (heat map).
    Steps,
    /// The terrain's level of detail.
    TerrainLod,
}

impl Look {
    /// The frame's image this look shows (the picture for a probed look, which replaces it).
    pub fn frame_view(self) -> DebugView {
        match self {
            Look::Depth => DebugView::Depth,
            Look::Normals => DebugView::Normals,
            Look::Colour | Look::Cells | Look::Steps | Look::TerrainLod => DebugView::Colour,
        }
    }

    /// The probed view this look is, if it is one.
    pub fn probe(self) -> Option<ProbeView> {
        match self {
            Look::Cells => Some(ProbeView::Cells),
            Look::Steps => Some(ProbeView::Steps),
            Look::TerrainLod => Some(ProbeView::TerrainLevel),
            Look::Colour | Look::Depth | Look::Normals => None,
        }
    }
}

/// The switches the overlay turns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controls {
    pub shadows: bool,
    pub culling: bool,
    /// Anti-aliasing samples (the GPU: every frame; the CPU: still frames).
    pub samples: u32,
    pub look: Look,
    /// The scene's optional parts left on (a change rebuilds the scene the backend renders).
    pub switches: Switches,
    /// The animation plays; `time` is where it is, in seconds.
    pub playing: bool,
    pub time: f64,
    /// The camera rides the animation's camera path (until the user flies it).
    pub follow: bool,
}

impl Controls {
    /// What a frame depends on of the controls (the rest picks what is shown of it, or the
    /// scene, which is compared on its own).
    pub fn frame_key(&self) -> (bool, bool, u32) {
        (self.shadows, self.culling, self.samples)
    }
}

/// What the scene has that the overlay can offer.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Offers {
    /// The optional parts the scene has (a part it lacks gets no switch).
    pub parts: Switches,
    /// The animation's length in seconds, if anything moves (infinite: moving terrain heights
    /// without an animation block).
    pub duration: Option<f64>,
    /// The animation has a camera path.
    pub camera_path: bool,
}

/// What the overlay reports.
#[derive(Clone, Debug, Default)]
pub struct Readout {
    /// Which backend renders, e.g. `"gpu (NVIDIA H200, Vulkan)"` or `"cpu (2 threads)"`.
    pub backend: String,
    /// The last frame's size and, on the CPU, its level.
    pub frame: String,
    pub stats: RenderStats,
    /// Frames shown per second over the last second.
    pub frames_per_second: f64,
    pub camera: String,
    pub speed: f64,
}

/// The most samples the overlay offers (the scene format allows 1024; a viewer wants a frame).
const MOST_SAMPLES: u32 = 64;

/// The longest time the slider offers for moving heights without an animation's length.
const OPEN_ENDED_SECONDS: f64 = 60.0;

/// Draws the overlay; returns the controls as the user left them.
pub fn show(
    ctx: &egui::Context,
    controls: Controls,
    readout: &Readout,
    offers: &Offers,
) -> Controls {
    let mut c = controls;
    egui::Window::new("fray view")
        .default_pos([8.0, 8.0])
        .resizable(false)
        .show(ctx, |ui| {
            ui.label(format!("backend: {}", readout.backend));
            ui.label(format!("frame: {}", readout.frame));
            let s = &readout.stats;
            ui.label(format!(
                "frame time {:.1} ms · {:.1} frames/s · {:.2} Mrays/s",
                s.elapsed.as_secs_f64() * 1e3,
                readout.frames_per_second,
                s.rays_per_second() / 1e6
            ));
            if !s.pass_times.is_empty() {
                egui::CollapsingHeader::new("passes")
                    .default_open(true)
                    .show(ui, |ui| {
                        for (label, d) in &s.pass_times {
                            ui.label(format!("{label}: {:.2} ms", d.as_secs_f64() * 1e3));
                        }
                    });
            }
            ui.separator();
            ui.checkbox(&mut c.shadows, "shadows");
            ui.checkbox(&mut c.culling, "culling");
            ui.add(egui::Slider::new(&mut c.samples, 1..=MOST_SAMPLES).text("samples"));
            let parts = offers.parts;
            if parts.fog || parts.sky || parts.clouds || parts.reflections {
                ui.horizontal(|ui| {
                    let mut offer = |on: bool, value: &mut bool, label: &str| {
                        if on {
                            ui.checkbox(value, label);
                        }
                    };
                    offer(parts.fog, &mut c.switches.fog, "fog");
                    offer(parts.sky, &mut c.switches.sky, "sky");
                    offer(parts.clouds, &mut c.switches.clouds, "clouds");
                    offer(
                        parts.reflections,
                        &mut c.switches.reflections,
                        "reflections",
                    );
                });
            }
            ui.horizontal(|ui| {
                ui.radio_value(&mut c.look, Look::Colour, "colour");
                ui.radio_value(&mut c.look, Look::Depth, "depth");
                ui.radio_value(&mut c.look, Look::Normals, "normals");
            });
            ui.horizontal(|ui| {
                ui.radio_value(&mut c.look, Look::Cells, "cells");
                ui.radio_value(&mut c.look, Look::Steps, "steps");
                ui.radio_value(&mut c.look, Look::TerrainLod, "terrain LOD");
            });
            if let Some(duration) = offers.duration {
                ui.separator();
                let end = if duration.is_finite() {
                    duration
                } else {
                    OPEN_ENDED_SECONDS
                };
                ui.horizontal(|ui| {
                    ui.checkbox(&mut c.playing, "play (space)");
                    if offers.camera_path {
                        ui.checkbox(&mut c.follow, "ride the camera path");
                    }
                });
                ui.add(egui::Slider::new(&mut c.time, 0.0..=end).text("time (s)"));
            }
            ui.separator();
            ui.label(format!("speed {:.3} units/s (wheel)", readout.speed));
            ui.label(&readout.camera);
            ui.label("WASD QE fly · right drag look · left drag orbit · 1 scene camera");
            ui.label("space play / pause the animation");
            ui.label("F12 / Ctrl+S save · H / F1 hide · Esc quit");
        });
    c
}
