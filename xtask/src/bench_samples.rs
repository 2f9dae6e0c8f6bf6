//! `cargo xtask bench samples`: anti-aliasing's samples per pixel against the error of the
//! box-filtered pixel, on `data/scenes/mesh_bunny_freeform.ron` (the bunny mesh, a perturbed
//! free form and a mirror ball on a floor: mesh silhouettes, a reflected one and shadow edges to
//! resolve) at [`SIZE`] on the CPU with [`THREADS`] worker threads.
//!
//! - Settings: `samples` ∈ [`SAMPLES`] (whole strata grids: 1 is the pixel centre), each frame the
//!   median of the repeats.
//! - The reference: the same frame at [`REFERENCE_SAMPLES`] samples per pixel (a 32 × 32 strata
//!   grid: its own error on an edge pixel is about a stratum's share of the edge's contrast,
//!   ~1/32 of what one sample's is).
//! - Error: per pixel the largest channel's `|Δ|` of the linear colour against the reference,
//!   its RMS (plotted) and max over the frame, in units of the reference's brightest pixel.
//!
//! Written as `target/bench/samples.md` and the sweep `samples.{csv,svg,png}` (`sweep_plot`), the
//! scene's own count (1) the default.

use crate::sweep_frame::{ImageError, brightest, render_once, timed_unless_slow};
use crate::sweep_plot::{Setting, Sweep};
use crate::workspace;
use fray_core::PixelSamples;
use std::fmt::Write as _;

/// The scene the sweep renders.
const SCENE: &str = "data/scenes/mesh_bunny_freeform.ron";
/// The frame size (the scene's 16:10 kept).
const SIZE: (u32, u32) = (128, 80);
/// Worker threads of the renders.
const THREADS: usize = 2;
/// The counts swept.
const SAMPLES: [u32; 4] = [1, 4, 16, 64];
/// The reference's count.
const REFERENCE_SAMPLES: u32 = 1024;

/// Runs the sweep; returns its markdown and the count's time against error.
pub fn run(repeats: usize) -> Result<(String, Sweep), String> {
    let path = workspace::root().join(SCENE);
    let mut scene = fray_scene::load(&path).map_err(|e| e.to_string())?;
    (scene.width, scene.height) = SIZE;
    let default = scene.settings.samples.count();
    let with_samples = |n: u32| -> Result<fray_scene::Scene, String> {
        let mut s = scene.clone();
        s.settings.samples = PixelSamples::new(n).map_err(|e| e.to_string())?;
        Ok(s)
    };
    eprintln!("samples: reference ({REFERENCE_SAMPLES} per pixel)");
    let (reference_ms, reference) = render_once(&with_samples(REFERENCE_SAMPLES)?, THREADS)?;
    let bright = brightest(&reference);

    let mut rows = Vec::new();
    for n in SAMPLES {
        eprintln!("samples: {n} per pixel");
        let (ms, frame) = timed_unless_slow(&with_samples(n)?, THREADS, repeats)?;
        rows.push((n, ms, ImageError::of(&reference, &frame)?.relative(bright)));
    }
    let sweep = Sweep {
        name: "samples".into(),
        method: format!(
            "samples per pixel ({})",
            SCENE.trim_start_matches("data/scenes/")
        ),
        error_desc: "RMS |Δ| / brightest pixel".into(),
        time_desc: format!("frame ms ({}×{}, {THREADS} threads)", SIZE.0, SIZE.1),
        settings: rows
            .iter()
            .map(|&(n, ms, e)| Setting::new(format!("{n} spp"), ms, e.rms))
            .collect(),
        default: rows.iter().position(|r| r.0 == default),
    };

    let mut md = format!(
        "# Samples per pixel against error (`cargo xtask bench samples`)\n\n\
         `{SCENE}` at {}×{}, CPU, {THREADS} threads, medians of {repeats}. Reference: \
         {REFERENCE_SAMPLES} samples per pixel (one render, {:.1} s). Error per pixel: the \
         largest channel's |Δ| of the linear colour, in units of the reference's brightest pixel \
         ({bright:.3}); the RMS is plotted.\n\n\
         | samples | frame ms | ms / sample | RMS \\|Δ\\| | mean \\|Δ\\| | max \\|Δ\\| |\n\
         |---:|---:|---:|---:|---:|---:|\n",
        SIZE.0,
        SIZE.1,
        reference_ms / 1e3,
    );
    for &(n, ms, e) in &rows {
        let _ = writeln!(
            md,
            "| {n} | {ms:.1} | {:.2} | {:.2e} | {:.2e} | {:.2e} |",
            ms / f64::from(n),
            e.rms,
            e.mean,
            e.max
        );
    }
    // The RMS's order of convergence between neighbouring counts: stratified sampling of an
    // edge converges as N^-3/4, of a smooth pixel faster.
    md.push_str("\nRMS order between neighbouring counts (log ratio per log count): ");
    let orders: Vec<String> = rows
        .windows(2)
        .map(|w| {
            let order =
                (w[0].2.rms / w[1].2.rms).ln() / (f64::from(w[1].0) / f64::from(w[0].0)).ln();
            format!("{}→{}: {order:.2}", w[0].0, w[1].0)
        })
        .collect();
    md.push_str(&orders.join(", "));
    md.push('\n');
    Ok((md, sweep))
}
