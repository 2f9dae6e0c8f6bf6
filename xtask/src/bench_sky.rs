//! `cargo xtask bench sky`: the sky's table sizes against the error of its background, on
//! `data/scenes/sunset.ron`'s sky (its model, haze and sun 2.3° above the horizon, the camera's
//! eye) — the hard case: the glow round a low sun, the horizon, the Earth's shadow.
//!
//! - Settings, one knob at a time from the defaults (`SkyTables::default()`): the sky-view
//!   table's size ([`SKY_VIEW_SIZES`]), its march's steps per texel ([`SKY_VIEW_STEPS`]), the
//!   transmittance table's size ([`TRANSMITTANCE_SIZES`]); and every knob finer at once
//!   (512 × 128, 384 × 216, 80 steps).
//! - Time: building the tables — the transmittance table (`Sky::new`, once per sky) and the
//!   sky-view table (`Sky::view`, once per frame) — on all cores, the median of the repeats
//!   (once where they take over `sweep_frame::SLOW_MS`).
//! - The reference: `fray_atmosphere::sky::reference::single_scattering`, the single-scattering
//!   integral by nested Gauss–Kronrod quadrature with its optical depths integrated too (no
//!   table), along each direction.
//! - Error: over the camera's pixel directions of a [`VIEW`] frame (every direction, objects
//!   ignored: the sky the frame would show behind them), the largest channel's `|Δ|` of the
//!   table's radiance (`SkyView::lookup`, the sun's disc apart) against the reference, its max
//!   (plotted) and RMS, in units of the reference's brightest direction.
//!
//! Written as `target/bench/sky.md` and the sweep `sky_tables.{csv,svg,png}` (`sweep_plot`), the
//! defaults marked.

use crate::sweep_frame::{SLOW_MS, median};
use crate::sweep_plot::{Setting, Sweep};
use crate::workspace;
use fray_atmosphere::sky::{Sky, SkyTables, reference};
use fray_core::MemoryBudget;
use glam::DVec3;
use std::fmt::Write as _;
use std::time::Instant;

/// The scene whose sky is swept.
const SCENE: &str = "data/scenes/sunset.ron";
/// The frame whose pixel directions are checked.
const VIEW: (u32, u32) = (128, 72);
/// Sky-view table sizes (width × height; the default 192 × 108 among them).
const SKY_VIEW_SIZES: [(u32, u32); 4] = [(48, 28), (96, 54), (192, 108), (384, 216)];
/// Sky-view march steps per texel (the default 40 among them).
const SKY_VIEW_STEPS: [u32; 5] = [10, 20, 40, 80, 160];
/// Transmittance table sizes (the default 256 × 64 among them).
const TRANSMITTANCE_SIZES: [(u32, u32); 4] = [(64, 16), (128, 32), (256, 64), (512, 128)];

/// The brightest channel over the directions, and the error of `got` against `reference`
/// (per direction the largest channel's `|Δ|`): max and RMS.
fn radiance_error(reference: &[DVec3], got: &[DVec3]) -> (f64, f64) {
    let (mut max, mut sum) = (0.0f64, 0.0f64);
    for (a, b) in reference.iter().zip(got) {
        let d = (*a - *b).abs().max_element();
        max = max.max(d);
        sum += d * d;
    }
    (max, (sum / reference.len().max(1) as f64).sqrt())
}

/// Runs the sweep; returns its markdown and the tables' time against error.
pub fn run(repeats: usize) -> Result<(String, Sweep), String> {
    let path = workspace::root().join(SCENE);
    let scene = fray_scene::load(&path).map_err(|e| e.to_string())?;
    let sky = scene
        .atmosphere
        .sky
        .as_ref()
        .ok_or_else(|| format!("{SCENE}: the scene has no sky"))?;
    let (model, sun) = (*sky.sky.model(), *sky.sky.sun());
    let defaults = SkyTables::default();
    let directions: Vec<(DVec3, DVec3)> = (0..VIEW.0 * VIEW.1)
        .filter_map(|i| {
            let c = scene
                .camera
                .pixel_ray(i % VIEW.0, i / VIEW.0, VIEW.0, VIEW.1)?;
            Some((c.ray.origin, c.ray.dir))
        })
        .collect();
    let eye = directions.first().map_or(DVec3::ZERO, |d| d.0);
    eprintln!("sky: reference over {} directions", directions.len());
    let start = Instant::now();
    let truth: Vec<DVec3> = directions
        .iter()
        .map(|&(o, d)| reference::single_scattering(&model, &sun, o, d, f64::INFINITY).in_scatter)
        .collect();
    let reference_s = start.elapsed().as_secs_f64();
    let bright = truth
        .iter()
        .map(|c| c.max_element())
        .fold(0.0, f64::max)
        .max(1e-30);

    let mut settings_list: Vec<(String, SkyTables)> = Vec::new();
    for (w, h) in SKY_VIEW_SIZES {
        settings_list.push((
            format!("sky view {w}×{h}"),
            SkyTables {
                sky_view_width: w,
                sky_view_height: h,
                ..defaults
            },
        ));
    }
    for steps in SKY_VIEW_STEPS {
        if steps != defaults.sky_view_steps {
            settings_list.push((
                format!("{steps} steps"),
                SkyTables {
                    sky_view_steps: steps,
                    ..defaults
                },
            ));
        }
    }
    for (w, h) in TRANSMITTANCE_SIZES {
        if (w, h) != (defaults.transmittance_width, defaults.transmittance_height) {
            settings_list.push((
                format!("transmittance {w}×{h}"),
                SkyTables {
                    transmittance_width: w,
                    transmittance_height: h,
                    ..defaults
                },
            ));
        }
    }

    // Every knob finer at once: where the one-knob rows' floor comes from.
    settings_list.push((
        "all finer".into(),
        SkyTables {
            transmittance_width: 512,
            transmittance_height: 128,
            sky_view_width: 384,
            sky_view_height: 216,
            sky_view_steps: 80,
        },
    ));

    let mut md = format!(
        "# Sky tables: size against error (`cargo xtask bench sky`)\n\n\
         `{SCENE}`'s sky (sun {:.1}° up), the eye at the camera; one knob at a time from the \
         defaults (transmittance {}×{}, sky view {}×{}, {} steps per texel). Time: the \
         transmittance table (`Sky::new`, once per sky) and the sky-view table (`Sky::view`, once \
         per frame), on all cores, medians of {repeats} (once where they take over {SLOW_MS} \
         ms). Error over the {}×{} camera's {} pixel \
         directions (objects ignored): the largest channel's |Δ| of `SkyView::lookup` against the \
         quadrature reference ({reference_s:.1} s), in units of the brightest direction's \
         ({bright:.3e}).\n\n\
         | setting | transmittance ms | sky view ms | total ms | max \\|Δ\\| | RMS \\|Δ\\| |\n\
         |---|---:|---:|---:|---:|---:|\n",
        sun.unit_direction().y.asin().to_degrees(),
        defaults.transmittance_width,
        defaults.transmittance_height,
        defaults.sky_view_width,
        defaults.sky_view_height,
        defaults.sky_view_steps,
        VIEW.0,
        VIEW.1,
        directions.len(),
    );
    let mut sweep = Sweep {
        name: "sky_tables".into(),
        method: format!("sky tables ({})", SCENE.trim_start_matches("data/scenes/")),
        error_desc: "max |Δ| / brightest direction".into(),
        time_desc: "table builds, ms (all cores)".into(),
        settings: Vec::new(),
        default: None,
    };
    let budget = MemoryBudget::default();
    for (label, tables) in settings_list {
        eprintln!("sky: {label}");
        let (mut t_ms, mut v_ms) = (Vec::new(), Vec::new());
        let mut last = None;
        for _ in 0..repeats.max(1) {
            let start = Instant::now();
            let s = Sky::new(model, sun, tables, &budget).map_err(|e| e.to_string())?;
            t_ms.push(start.elapsed().as_secs_f64() * 1e3);
            let start = Instant::now();
            let view = s.view(eye);
            v_ms.push(start.elapsed().as_secs_f64() * 1e3);
            last = Some(view);
            // The largest tables are timed once (`sweep_frame::SLOW_MS`).
            if t_ms[0] + v_ms[0] > SLOW_MS {
                break;
            }
        }
        let view = last.ok_or("no sky built")?;
        let got: Vec<DVec3> = directions.iter().map(|&(_, d)| view.lookup(d)).collect();
        let (max, rms) = radiance_error(&truth, &got);
        let (t_ms, v_ms) = (median(t_ms), median(v_ms));
        if tables == defaults && sweep.default.is_none() {
            sweep.default = Some(sweep.settings.len());
        }
        sweep
            .settings
            .push(Setting::new(label.clone(), t_ms + v_ms, max / bright));
        let _ = writeln!(
            md,
            "| {label} | {t_ms:.1} | {v_ms:.1} | {:.1} | {:.2e} | {:.2e} |",
            t_ms + v_ms,
            max / bright,
            rms / bright
        );
    }
    Ok((md, sweep))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Per direction the largest channel's difference, whatever its sign: max 0.5, RMS over the
    /// three directions √((0.25 + 0 + 0.04) / 3).
    #[test]
    fn the_error_is_the_largest_channel_per_direction() {
        let reference = [DVec3::new(1.0, 0.0, 0.0), DVec3::ONE, DVec3::ZERO];
        let got = [
            DVec3::new(0.5, 0.1, 0.0),
            DVec3::ONE,
            DVec3::new(0.0, -0.2, 0.1),
        ];
        let (max, rms) = radiance_error(&reference, &got);
        assert_eq!(max, 0.5);
        assert!((rms - (0.29f64 / 3.0).sqrt()).abs() < 1e-15, "{rms}");
    }
}
