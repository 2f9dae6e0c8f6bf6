//! `cargo xtask bench whitted`: Whitted recursion's depth against its error, on
//! `data/scenes/whitted_glass_mirror.ron` (a mirror ball, a glass ball and the glass bunny mesh
//! on a textured floor) at [`SIZE`] on the CPU with [`THREADS`] worker threads.
//!
//! - Settings: `max_depth` ∈ [`DEPTHS`], each frame the median of the repeats. The scene's
//!   secondary-ray budget is raised to its largest (`MAX_SECONDARY_RAYS`) in every frame, so the
//!   depth alone cuts the tree (at the default 256 a depth-8 tree could be cut by the budget);
//!   the minimum contribution stays the scene's, in every frame and the reference alike.
//! - The reference: the same frame at depth [`REFERENCE_DEPTH`] (64, the largest a scene may
//!   ask for; every chain on this frame has ended by depth 48).
//! - Error: per pixel the largest channel's `|Δ|` of the linear colour against the reference,
//!   its max (plotted) and mean over the frame, in units of the reference's brightest pixel.
//!
//! Written as `target/bench/whitted.md` and the sweep `whitted_depth.{csv,svg,png}`
//! (`sweep_plot`), the scene's own depth the default.

use crate::sweep_frame::{ImageError, brightest, render_once, timed};
use crate::sweep_plot::{Setting, Sweep};
use crate::workspace;
use std::fmt::Write as _;

/// The scene the sweep renders.
const SCENE: &str = "data/scenes/whitted_glass_mirror.ron";
/// The frame size (the scene's 16:10 kept).
const SIZE: (u32, u32) = (256, 160);
/// Worker threads of the renders.
const THREADS: usize = 2;
/// The depths swept.
const DEPTHS: [u32; 8] = [0, 1, 2, 3, 4, 6, 8, 16];
/// The reference's depth: the deepest a scene may ask for. A depth-16 reference was not enough
/// (depth 16 against 64: max 2.0e-2 of the brightest pixel — chains the minimum contribution
/// does not cut, presumably total internal reflection in the glass); depth 48 already gives the
/// same bits as 64 on this frame.
const REFERENCE_DEPTH: u32 = fray_scene::MAX_DEPTH;

/// Runs the sweep; returns its markdown and the depth's time against error.
pub fn run(repeats: usize) -> Result<(String, Sweep), String> {
    let path = workspace::root().join(SCENE);
    let mut scene = fray_scene::load(&path).map_err(|e| e.to_string())?;
    (scene.width, scene.height) = SIZE;
    let default_depth = scene.settings.max_depth;
    scene.settings.max_secondary_rays = fray_scene::MAX_SECONDARY_RAYS;
    let with_depth = |depth: u32| {
        let mut s = scene.clone();
        s.settings.max_depth = depth;
        s
    };
    eprintln!("whitted: reference (depth {REFERENCE_DEPTH})");
    let (reference_ms, reference) = render_once(&with_depth(REFERENCE_DEPTH), THREADS)?;
    let bright = brightest(&reference);
    let pixels = f64::from(SIZE.0 * SIZE.1);

    struct Row {
        depth: u32,
        ms: f64,
        secondary: f64,
        error: ImageError,
    }
    let mut rows = Vec::new();
    for depth in DEPTHS {
        eprintln!("whitted: depth {depth}");
        let (ms, frame) = timed(&with_depth(depth), THREADS, repeats)?;
        rows.push(Row {
            depth,
            ms,
            secondary: frame.stats.secondary_rays as f64 / pixels,
            error: ImageError::of(&reference, &frame)?.relative(bright),
        });
    }
    let default_ms = rows
        .iter()
        .find(|r| r.depth == default_depth)
        .map_or(f64::NAN, |r| r.ms);
    let sweep = Sweep {
        name: "whitted_depth".into(),
        method: format!(
            "Whitted depth ({})",
            SCENE.trim_start_matches("data/scenes/")
        ),
        error_desc: "max |Δ| / brightest pixel".into(),
        time_desc: format!("frame ms ({}×{}, {THREADS} threads)", SIZE.0, SIZE.1),
        settings: rows
            .iter()
            .map(|r| Setting::new(format!("depth {}", r.depth), r.ms, r.error.max))
            .collect(),
        default: rows.iter().position(|r| r.depth == default_depth),
    };

    let mut md = format!(
        "# Whitted recursion: depth against error (`cargo xtask bench whitted`)\n\n\
         `{SCENE}` at {}×{}, CPU, {THREADS} threads, medians of {repeats}; the scene's depth is \
         {default_depth}. Every frame with the secondary-ray budget at its largest ({}), so the \
         depth alone cuts; the minimum contribution is the scene's ({}). Reference: depth \
         {REFERENCE_DEPTH} (one render, {reference_ms:.0} ms, {:.2} secondary rays per pixel). \
         Error per pixel: the largest channel's |Δ| of the linear colour, in units of the \
         reference's brightest pixel ({bright:.3}).\n\n\
         | depth | frame ms | × scene's | secondary rays / pixel | max \\|Δ\\| | mean \\|Δ\\| | RMS \\|Δ\\| |\n\
         |---:|---:|---:|---:|---:|---:|---:|\n",
        SIZE.0,
        SIZE.1,
        fray_scene::MAX_SECONDARY_RAYS,
        scene.settings.min_contribution,
        reference.stats.secondary_rays as f64 / pixels,
    );
    for r in &rows {
        let _ = writeln!(
            md,
            "| {} | {:.1} | {:.2} | {:.2} | {:.2e} | {:.2e} | {:.2e} |",
            r.depth,
            r.ms,
            r.ms / default_ms,
            r.secondary,
            r.error.max,
            r.error.mean,
            r.error.rms
        );
    }
    Ok((md, sweep))
}
