//! `cargo xtask bench terrain-scaling`: how a terrain frame's cost grows with the screen and
//! with the camera's distance, on the DEM upsampled to [`MAP`]² (`fray_terrain::sweep`, the
//! same map and camera as `cargo xtask bench terrain`'s map-size sweep), CPU, [`THREADS`]
//! threads, the default LOD (`Pixel`) and `Exact`, each frame the median of the repeats (once
//! for a frame over `sweep_frame::SLOW_MS`).
//!
//! - Screen size: the fixed camera at [`SCREENS`]² pixels; time per frame and per pixel.
//! - Distance: the eye moved along its line of sight to [`DISTANCES`] × its distance to the
//!   target, the field of view narrowed (`tan(fov/2) / k`) so that the screen frames the same
//!   ground, at [`DISTANCE_SCREEN`]²: the same pixels see the same ground, each ray k times as
//!   long, its pixel footprint k times as wide.
//!
//! Time plots (`sweep_plot::LinePlot`): `terrain_screen.{csv,svg,png}`,
//! `terrain_distance.{csv,svg,png}`; the map-size plot is `cargo xtask bench terrain`'s
//! `terrain_map_size`. The markdown is `target/bench/terrain_scaling.md`.

use crate::sweep_frame::{SLOW_MS, timed_unless_slow};
use crate::sweep_plot::{LinePlot, Series};
use crate::workspace;
use fray_core::{Pinhole, Projector, glam::DVec3};
use fray_scene::{Scene, TerrainLod};
use fray_terrain::{TerrainOptions, sweep};
use std::fmt::Write as _;
use std::sync::Arc;

/// The map's side.
const MAP: usize = 1024;
/// Worker threads of the frames.
const THREADS: usize = 2;
/// Screen sides of the screen-size sweep.
const SCREENS: [u32; 4] = [128, 256, 512, 1024];
/// Factors on the eye's distance to the target.
const DISTANCES: [f64; 5] = [0.25, 0.5, 1.0, 2.0, 4.0];
/// Screen side of the distance sweep.
const DISTANCE_SCREEN: u32 = 256;
/// The LOD rules compared.
const LODS: [(TerrainLod, &str); 2] = [
    (TerrainLod::Pixel, "pixel LOD"),
    (TerrainLod::Exact, "exact"),
];

/// The sweep's camera: the eye at `k` × its distance from the target on the same line, the
/// field narrowed by `k`.
fn camera(k: f64) -> Result<Projector, String> {
    let eye = sweep::TARGET + (sweep::EYE - sweep::TARGET) * k;
    let half = (0.5 * sweep::FOV_DEGREES).to_radians().tan() / k;
    Ok(Projector::Pinhole(
        Pinhole::new(eye, sweep::TARGET, DVec3::Y, 2.0 * half.atan(), 1.0)
            .map_err(|e| e.to_string())?,
    ))
}

fn with_lod(scene: &Scene, lod: TerrainLod) -> Scene {
    let mut s = scene.clone();
    for t in &mut s.terrains {
        t.lod = lod;
    }
    s
}

/// Runs both sweeps; returns the markdown and the plots.
pub fn run(repeats: usize) -> Result<(String, Vec<LinePlot>), String> {
    let root = workspace::root();
    let base = crate::bench::dem(&root)?;
    let map = Arc::new(
        sweep::upsampled(&base, MAP, TerrainOptions::default()).map_err(|e| e.to_string())?,
    );
    // terrain_high's lights and material, the sweep's map in place of its terrain.
    let mut scene = crate::render::load(&root.join("data/scenes/terrain_high.ron"))?;
    let Some(obj) = scene.terrains.first_mut() else {
        return Err("terrain_high.ron has no terrain".into());
    };
    obj.terrain = map;
    let mut md = format!(
        "# Terrain: cost against screen size and distance (`cargo xtask bench terrain-scaling`)\n\n\
         The DEM upsampled to {MAP}² over 30 km (`fray_terrain::sweep`), terrain_high's lights \
         and material, CPU, {THREADS} threads, shaded with shadow rays, medians of {repeats} \
         (a frame over {SLOW_MS} ms: once).\n\n\
         ## Screen size\n\nThe fixed camera (`sweep::EYE` toward `sweep::TARGET`, \
         {}° field).\n\n\
         | side | pixel LOD ms | exact ms | pixel LOD µs / pixel | exact µs / pixel |\n\
         |---:|---:|---:|---:|---:|\n",
        sweep::FOV_DEGREES
    );
    scene.camera = camera(1.0)?;
    let mut screen_series = empty_series();
    for side in SCREENS {
        eprintln!("terrain-scaling: screen {side}²");
        (scene.width, scene.height) = (side, side);
        let mut ms = Vec::new();
        for (i, (lod, _)) in LODS.iter().enumerate() {
            let (t, _) = timed_unless_slow(&with_lod(&scene, *lod), THREADS, repeats)?;
            screen_series[i].points.push((f64::from(side), t));
            ms.push(t);
        }
        let pixels = f64::from(side * side);
        let _ = writeln!(
            md,
            "| {side} | {:.1} | {:.1} | {:.2} | {:.2} |",
            ms[0],
            ms[1],
            ms[0] * 1e3 / pixels,
            ms[1] * 1e3 / pixels
        );
    }

    let _ = write!(
        md,
        "\n## Distance\n\n{DISTANCE_SCREEN}² frames; the eye at k × its distance to the target \
         ({:.0} m) on the same line, the field narrowed to frame the same ground.\n\n\
         | k | distance km | pixel LOD ms | exact ms | exact / pixel LOD |\n\
         |---:|---:|---:|---:|---:|\n",
        (sweep::EYE - sweep::TARGET).length()
    );
    (scene.width, scene.height) = (DISTANCE_SCREEN, DISTANCE_SCREEN);
    let mut distance_series = empty_series();
    for k in DISTANCES {
        eprintln!("terrain-scaling: distance × {k}");
        scene.camera = camera(k)?;
        let distance = (sweep::EYE - sweep::TARGET).length() * k / 1e3;
        let mut ms = Vec::new();
        for (i, (lod, _)) in LODS.iter().enumerate() {
            let (t, _) = timed_unless_slow(&with_lod(&scene, *lod), THREADS, repeats)?;
            // Kilometres to 0.1 (the plot's ticks).
            distance_series[i]
                .points
                .push(((distance * 10.0).round() / 10.0, t));
            ms.push(t);
        }
        let _ = writeln!(
            md,
            "| {k} | {distance:.1} | {:.1} | {:.1} | {:.2} |",
            ms[0],
            ms[1],
            ms[1] / ms[0]
        );
    }
    let plots = vec![
        LinePlot {
            name: "terrain_screen".into(),
            title: format!("terrain {MAP}²: frame time against screen size"),
            x_desc: "screen side (pixels)".into(),
            y_desc: format!("frame ms ({THREADS} threads)"),
            series: screen_series,
        },
        LinePlot {
            name: "terrain_distance".into(),
            title: format!("terrain {MAP}²: frame time against distance (same ground framed)"),
            x_desc: "camera distance to the target (km)".into(),
            y_desc: format!("frame ms ({DISTANCE_SCREEN}², {THREADS} threads)"),
            series: distance_series,
        },
    ];
    Ok((md, plots))
}

/// One empty series per level-of-detail setting, in `LODS` order.
fn empty_series() -> Vec<Series> {
    LODS.iter()
        .map(|(_, name)| Series {
            label: (*name).into(),
            points: Vec::new(),
            point_labels: Vec::new(),
        })
        .collect()
}
