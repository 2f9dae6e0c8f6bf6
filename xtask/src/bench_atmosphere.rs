//! `cargo xtask bench atmosphere`: the media's time/error knob, written to
//! `target/bench/atmosphere.md`, on two scenes: fog (`fog_aircraft_low_sun.ron`, the closed form
//! per pixel) and the sky's air seen from 66 km (`haze_dem_high.ron`, a 16-step aerial-perspective
//! march per pixel).
//!
//! - Frame times (CPU, 2 threads, medians): the scene without its media, with them per pixel (for
//!   fog by the exact formula and by the method's), and on media grids of 4, 8 and 16 pixels.
//! - Errors of the media's terms against the numerical reference (fog:
//!   `fray_atmosphere::reference::single_scattering`, nested Gauss–Kronrod; sky:
//!   `fray_atmosphere::sky::reference::single_scattering`) on every pixel of the same frame,
//!   along each pixel's centre ray to its depth: the in-scattered radiance's error (max, RMS over
//!   pixels; the largest channel) relative to the frame's brightest in-scatter, and the
//!   transmittance's absolute error, per mode; for the grids also the share of pixels
//!   interpolated.
//! - Each scene's modes as time against the in-scatter's max relative error, plotted
//!   (`sweep_plot`) as `atmosphere_{fog,sky}.{csv,svg,png}`, the scene's own mode the default.

use crate::sweep_plot::{Setting, Sweep};
use crate::workspace;
use fray_atmosphere::reference::single_scattering;
use fray_atmosphere::{FogLighting, FogModel, Sunlight};
use fray_core::Interval;
use fray_render::{Backend, RenderOptions, Renderer};
use fray_scene::{Light, Scene};
use fray_trace::{Media, MediaGrid, MediaTerms};
use std::fmt::Write as _;
use std::time::Instant;

/// The scenes the sweep renders: fog, and the sky's air.
const SCENES: [&str; 2] = [
    "data/scenes/fog_aircraft_low_sun.ron",
    "data/scenes/haze_dem_high.ron",
];
/// Frame sizes: timed frames, and the frame whose every pixel is checked against the reference.
const TIMED: (u32, u32) = (640, 360);
const CHECKED: (u32, u32) = TIMED;
const GRIDS: [u32; 3] = [4, 8, 16];

/// The median wall time of `repeats` renders, in milliseconds.
fn frame_ms(scene: &Scene, grid: u32, repeats: usize) -> Result<f64, String> {
    let renderer = Renderer::new(RenderOptions {
        backend: Backend::Cpu,
        threads: Some(2),
        media_grid: Some(grid),
        ..RenderOptions::default()
    });
    let mut times = Vec::new();
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        renderer.render(scene).map_err(|e| e.to_string())?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

/// Errors of one mode's terms against the reference's, per pixel: the in-scattered radiance's
/// difference (largest channel) relative to the frame's brightest reference in-scatter — what
/// shows in the picture, and defined where the in-scatter itself is near 0 — and the
/// transmittance's absolute difference.
#[derive(Default)]
struct Errors {
    in_scatter: Vec<f64>,
    max_transmittance: f64,
    interpolated: usize,
    /// Against the per-pixel evaluation instead of the reference (the grids).
    against_per_pixel: Vec<f64>,
}

impl Errors {
    fn add(&mut self, got: &MediaTerms, reference: &MediaTerms) {
        self.in_scatter
            .push((got.in_scatter - reference.in_scatter).abs().max_element());
        let dt = (got.transmittance - reference.transmittance)
            .abs()
            .max_element();
        self.max_transmittance = self.max_transmittance.max(dt);
    }

    /// (max, RMS) of the in-scatter differences over `scale`.
    fn in_scatter_relative(&self, scale: f64) -> (f64, f64) {
        let n = self.in_scatter.len().max(1) as f64;
        let max = self.in_scatter.iter().copied().fold(0.0, f64::max);
        let rms = (self.in_scatter.iter().map(|e| e * e).sum::<f64>() / n).sqrt();
        (max / scale, rms / scale)
    }
}

use fray_core::glam;

/// Runs the sweeps; returns their markdown and each scene's time against error.
pub fn run(repeats: usize) -> Result<(String, Vec<Sweep>), String> {
    let mut out =
        String::from("# Atmosphere: media evaluation modes (`cargo xtask bench atmosphere`)\n");
    let mut sweeps = Vec::new();
    for scene in SCENES {
        let (md, s) = sweep(scene, repeats)?;
        out.push_str(&md);
        sweeps.push(s);
    }
    Ok((out, sweeps))
}

/// One scene's sweep.
fn sweep(name: &str, repeats: usize) -> Result<(String, Sweep), String> {
    let path = workspace::root().join(name);
    let mut scene = fray_scene::load(&path).map_err(|e| e.to_string())?;
    let fog = scene.atmosphere.fog;
    let sky = scene.atmosphere.sky.clone();
    if fog.is_none() == sky.is_none() {
        return Err(format!(
            "{}: the sweep needs fog or a sky, not both",
            path.display()
        ));
    }
    let mut out = format!(
        "\n## {name}\n\nFrames {}×{}, CPU, 2 threads, medians of {repeats}:\n\n\
         | mode | frame ms | × per pixel |\n|---|---:|---:|\n",
        TIMED.0, TIMED.1
    );
    (scene.width, scene.height) = TIMED;
    let mut clear = scene.clone();
    clear.atmosphere = fray_scene::Atmosphere::default();
    (clear.features.fog, clear.features.sky) = (false, false);
    let mut method = scene.clone();
    if let Some(f) = method.atmosphere.fog.as_mut() {
        f.model = FogModel::Method;
    }
    let exact_ms = frame_ms(&scene, 0, repeats)?;
    let mut rows = vec![
        ("no media".to_owned(), frame_ms(&clear, 0, repeats)?),
        ("per pixel".to_owned(), exact_ms),
    ];
    if fog.is_some() {
        rows.push((
            "per pixel, method".to_owned(),
            frame_ms(&method, 0, repeats)?,
        ));
    }
    for g in GRIDS {
        rows.push((format!("grid {g} px"), frame_ms(&scene, g, repeats)?));
    }
    for (mode, ms) in &rows {
        let _ = writeln!(out, "| {mode} | {ms:.1} | {:.3} |", ms / exact_ms);
    }

    // The checked frame: depths from an exact render, then every mode's terms per pixel.
    (scene.width, scene.height) = CHECKED;
    (method.width, method.height) = CHECKED;
    let frame = Renderer::new(RenderOptions {
        backend: Backend::Cpu,
        ..RenderOptions::default()
    })
    .render(&scene)
    .map_err(|e| e.to_string())?;
    let exact_media = Media::of(&scene).ok_or("no media")?;
    let method_media = Media::of(&method).ok_or("no media")?;
    let eps = scene.epsilon();
    let budget = fray_core::MemoryBudget::default();
    let grids: Vec<MediaGrid> = GRIDS
        .iter()
        .map(|&g| MediaGrid::build(&scene, &exact_media, g, eps, &budget))
        .collect::<Result<_, _>>()
        .map_err(|e| e.to_string())?;
    let lighting = &FogLighting {
        suns: scene
            .lights
            .iter()
            .filter_map(|l| match *l {
                Light::Sun {
                    direction,
                    irradiance,
                } => Some(Sunlight {
                    direction,
                    irradiance: irradiance.as_dvec3(),
                }),
                Light::Point { .. } => None,
            })
            .collect(),
        ambient: scene.ambient.as_dvec3(),
    };
    let mut errors: Vec<Errors> = (0..2 + GRIDS.len()).map(|_| Errors::default()).collect();
    let mut brightest = 0.0f64;
    let start = Instant::now();
    for y in 0..scene.height {
        for x in 0..scene.width {
            let Some(c) = scene.camera.pixel_ray(x, y, scene.width, scene.height) else {
                continue;
            };
            let range = Interval::new(c.t_near, *frame.depth.get(x, y));
            let reference = match (&fog, &sky) {
                (Some(fog), _) => {
                    let r = single_scattering(&fog.layer, &c.ray, range, lighting);
                    MediaTerms {
                        transmittance: glam::DVec3::splat(r.transmittance),
                        in_scatter: r.in_scatter,
                    }
                }
                (None, Some(sky)) if range.hi.is_finite() => {
                    let r = fray_atmosphere::sky::reference::single_scattering(
                        sky.sky.model(),
                        sky.sky.sun(),
                        c.ray.origin,
                        c.ray.dir,
                        range.hi,
                    );
                    MediaTerms {
                        transmittance: r.transmittance,
                        in_scatter: r.in_scatter,
                    }
                }
                // A sky pixel: the background, not media terms.
                _ => continue,
            };
            brightest = brightest.max(reference.in_scatter.max_element());
            let exact = exact_media.terms(&c.ray, range);
            errors[0].add(&exact, &reference);
            if fog.is_some() {
                errors[1].add(&method_media.terms(&c.ray, range), &reference);
            }
            for (k, grid) in grids.iter().enumerate() {
                let at = (f64::from(x) + 0.5, f64::from(y) + 0.5);
                let e = &mut errors[2 + k];
                match grid.interpolate(at.0, at.1, range) {
                    Some(t) => {
                        e.interpolated += 1;
                        e.add(&t, &reference);
                        e.against_per_pixel
                            .push((t.in_scatter - exact.in_scatter).abs().max_element());
                    }
                    None => {
                        e.add(&exact, &reference);
                        e.against_per_pixel.push(0.0);
                    }
                }
            }
        }
    }
    let _ = write!(
        out,
        "\nErrors of the media terms against the quadrature reference, every pixel of a {}×{} \
         frame along its centre ray to its depth ({:.1} s of reference); in-scatter errors relative \
         to the frame's brightest in-scatter ({brightest:.3e} W/(m² sr)):\n\n\
         | mode | in-scatter max | in-scatter RMS | transmittance max abs | interpolated | max / RMS against per pixel |\n\
         |---|---:|---:|---:|---:|---:|\n",
        CHECKED.0,
        CHECKED.1,
        start.elapsed().as_secs_f64()
    );
    let names = ["per pixel", "per pixel, method"]
        .into_iter()
        .map(String::from)
        .chain(GRIDS.iter().map(|g| format!("grid {g} px")));
    let mut plotted = Sweep {
        name: format!("atmosphere_{}", if fog.is_some() { "fog" } else { "sky" }),
        method: format!(
            "{} ({})",
            if fog.is_some() { "fog" } else { "sky's air" },
            name.trim_start_matches("data/scenes/")
        ),
        error_desc: "in-scatter max |Δ| / brightest".into(),
        time_desc: format!("frame ms ({}×{}, 2 threads)", TIMED.0, TIMED.1),
        settings: Vec::new(),
        default: None,
    };
    // The scene's own mode: its media grid, else per pixel (with its own fog model).
    let default_mode = scene
        .atmosphere
        .grid
        .map_or("per pixel".to_owned(), |g| format!("grid {g} px"));
    for (name, e) in names.zip(&errors) {
        if e.in_scatter.is_empty() {
            continue;
        }
        let (max, rms) = e.in_scatter_relative(brightest.max(1e-300));
        if let Some((_, ms)) = rows.iter().find(|(mode, _)| *mode == name) {
            if name == default_mode {
                plotted.default = Some(plotted.settings.len());
            }
            plotted.settings.push(Setting::new(name.clone(), *ms, max));
        }
        let (share, against) = if name.starts_with("grid") {
            let d = &e.against_per_pixel;
            let scale = brightest.max(1e-300);
            let max = d.iter().copied().fold(0.0, f64::max) / scale;
            let rms = (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt() / scale;
            (
                format!(
                    "{:.1} %",
                    100.0 * e.interpolated as f64 / e.in_scatter.len().max(1) as f64
                ),
                format!("{max:.2e} / {rms:.2e}"),
            )
        } else {
            (String::new(), String::new())
        };
        let _ = writeln!(
            out,
            "| {name} | {max:.2e} | {rms:.2e} | {:.2e} | {share} | {against} |",
            e.max_transmittance
        );
    }
    Ok((out, plotted))
}
