//! `cargo xtask bench atmosphere`: the media's time/error knob on the fog scene
//! (`data/scenes/fog_aircraft_low_sun.ron`), written to `target/bench/atmosphere.md`.
//!
//! - Frame times (CPU, 2 threads, medians): the scene without its fog, with fog per pixel by the
//!   exact formula and by the method's, and on media grids of 4, 8 and 16 pixels.
//! - Errors of the media's terms against the numerical reference
//!   (`fray_atmosphere::reference::single_scattering`, nested Gauss–Kronrod) on every pixel of a
//!   smaller frame, along each pixel's centre ray to its depth: the in-scattered radiance's
//!   relative error (max, RMS over pixels; the largest channel) and the transmittance's absolute
//!   error, per mode; for the grids also the share of pixels interpolated.

use crate::workspace;
use fray_atmosphere::reference::single_scattering;
use fray_atmosphere::{FogLighting, FogModel, Sunlight};
use fray_core::Interval;
use fray_render::{Backend, RenderOptions, Renderer};
use fray_scene::{Light, Scene};
use fray_trace::{Media, MediaGrid, MediaTerms};
use std::fmt::Write as _;
use std::time::Instant;

/// The scene the sweep renders.
const SCENE: &str = "data/scenes/fog_aircraft_low_sun.ron";
/// Frame sizes: timed frames, and the frame whose every pixel is checked against the reference.
const TIMED: (u32, u32) = (640, 360);
const CHECKED: (u32, u32) = (160, 90);
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

/// Errors of one mode's terms against the reference's.
#[derive(Default)]
struct Errors {
    max_rel: f64,
    sum_sq_rel: f64,
    max_transmittance: f64,
    pixels: usize,
    interpolated: usize,
}

impl Errors {
    fn add(&mut self, got: &MediaTerms, reference: &MediaTerms) {
        let rel = ((got.in_scatter - reference.in_scatter).abs()
            / reference.in_scatter.max(glam::DVec3::splat(1e-300)))
        .max_element();
        self.max_rel = self.max_rel.max(rel);
        self.sum_sq_rel += rel * rel;
        let dt = (got.transmittance - reference.transmittance)
            .abs()
            .max_element();
        self.max_transmittance = self.max_transmittance.max(dt);
        self.pixels += 1;
    }

    fn rms(&self) -> f64 {
        (self.sum_sq_rel / self.pixels.max(1) as f64).sqrt()
    }
}

use fray_core::glam;

/// Runs the sweep; returns its markdown.
pub fn run(repeats: usize) -> Result<String, String> {
    let path = workspace::root().join(SCENE);
    let mut scene = fray_scene::load(&path).map_err(|e| e.to_string())?;
    let Some(fog) = scene.atmosphere.fog else {
        return Err(format!(
            "{}: the sweep needs a scene with fog",
            path.display()
        ));
    };
    let mut out = format!(
        "# Atmosphere: fog evaluation modes (`cargo xtask bench atmosphere`; {SCENE})\n\n\
         Frames {}×{}, CPU, 2 threads, medians of {repeats}:\n\n\
         | mode | frame ms | × per pixel exact |\n|---|---:|---:|\n",
        TIMED.0, TIMED.1
    );
    (scene.width, scene.height) = TIMED;
    let mut clear = scene.clone();
    clear.atmosphere = fray_scene::Atmosphere::default();
    clear.features.fog = false;
    let mut method = scene.clone();
    if let Some(f) = method.atmosphere.fog.as_mut() {
        f.model = FogModel::Method;
    }
    let exact_ms = frame_ms(&scene, 0, repeats)?;
    let mut rows = vec![
        ("no fog".to_owned(), frame_ms(&clear, 0, repeats)?),
        ("per pixel, exact".to_owned(), exact_ms),
        (
            "per pixel, method".to_owned(),
            frame_ms(&method, 0, repeats)?,
        ),
    ];
    for g in GRIDS {
        rows.push((format!("grid {g} px, exact"), frame_ms(&scene, g, repeats)?));
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
    let lighting = FogLighting {
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
    let start = Instant::now();
    for y in 0..scene.height {
        for x in 0..scene.width {
            let Some(c) = scene.camera.pixel_ray(x, y, scene.width, scene.height) else {
                continue;
            };
            let range = Interval::new(c.t_near, *frame.depth.get(x, y));
            let r = single_scattering(&fog.layer, &c.ray, range, &lighting);
            let reference = MediaTerms {
                transmittance: glam::DVec3::splat(r.transmittance),
                in_scatter: r.in_scatter,
            };
            let exact = exact_media.terms(&c.ray, range);
            errors[0].add(&exact, &reference);
            errors[1].add(&method_media.terms(&c.ray, range), &reference);
            for (k, grid) in grids.iter().enumerate() {
                let at = (f64::from(x) + 0.5, f64::from(y) + 0.5);
                let e = &mut errors[2 + k];
                match grid.interpolate(at.0, at.1, range) {
                    Some(t) => {
                        e.interpolated += 1;
                        e.add(&t, &reference);
                    }
                    None => e.add(&exact, &reference),
                }
            }
        }
    }
    let _ = write!(
        out,
        "\nErrors of the media terms against the quadrature reference, every pixel of a {}×{} \
         frame along its centre ray to its depth ({:.1} s of reference):\n\n\
         | mode | in-scatter max rel | in-scatter RMS rel | transmittance max abs | interpolated |\n\
         |---|---:|---:|---:|---:|\n",
        CHECKED.0,
        CHECKED.1,
        start.elapsed().as_secs_f64()
    );
    let names = ["per pixel, exact", "per pixel, method"]
        .into_iter()
        .map(String::from)
        .chain(GRIDS.iter().map(|g| format!("grid {g} px")));
    for (name, e) in names.zip(&errors) {
        let share = if name.starts_with("grid") {
            format!(
                "{:.1} %",
                100.0 * e.interpolated as f64 / e.pixels.max(1) as f64
            )
        } else {
            String::new()
        };
        let _ = writeln!(
            out,
            "| {name} | {:.2e} | {:.2e} | {:.2e} | {share} |",
            e.max_rel,
            e.rms(),
            e.max_transmittance
        );
    }
    Ok(out)
}
