//! The overlay (egui): what the last frame cost, pass by pass, and the switches a viewer turns.

use crate::present::DebugView;
use fray_core::RenderStats;

/// The switches the overlay turns; a change re-renders.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controls {
    pub shadows: bool,
    pub culling: bool,
    /// Anti-aliasing samples (the GPU: every frame; the CPU: still frames).
    pub samples: u32,
    pub debug: DebugView,
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

/// Draws the overlay; returns the controls as the user left them.
pub fn show(ctx: &egui::Context, controls: Controls, readout: &Readout) -> Controls {
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
            ui.horizontal(|ui| {
                ui.radio_value(&mut c.debug, DebugView::Colour, "colour");
                ui.radio_value(&mut c.debug, DebugView::Depth, "depth");
                ui.radio_value(&mut c.debug, DebugView::Normals, "normals");
            });
            ui.separator();
            ui.label(format!("speed {:.3} units/s (wheel)", readout.speed));
            ui.label(&readout.camera);
            ui.label("WASD QE fly · right drag look · left drag orbit · 1 scene camera");
            ui.label("F12 / Ctrl+S save · H / F1 hide · Esc quit");
        });
    c
}
