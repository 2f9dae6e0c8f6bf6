//! The debug views the CPU computes from the view's camera, whichever backend draws the picture:
//! the quadtree's cells (the work items both backends render from, coloured by how much each
//! may meet), the search steps per pixel as a heat map, and the terrain's level of detail.

use fray_quadtree::{PixelCoverage, QuadtreeConfig};
use fray_scene::{Scene, work_list_within};
use fray_trace::{TraceSettings, pixel_work};
use std::time::{Duration, Instant};

/// A debug view computed by probing the scene on the CPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProbeView {
    /// The quadtree's work items (tiles), filled by their candidates' leaf count; culled tiles
    /// black.
    Cells,
    /// The search steps of each pixel's centre ray (`fray_trace::pixel_work`), on a log scale.
    Steps,
    /// The terrain level of detail each pixel's ray stopped at (0: the finest cells).
    TerrainLevel,
}

/// A probe's picture, ready to upload: RGBA8 texels, what its colours mean, what it cost.
#[derive(Clone, Debug)]
pub struct ProbeImage {
    pub size: (u32, u32),
    pub rgba: Vec<u8>,
    pub legend: String,
    pub elapsed: Duration,
}

/// The colour ramp of every probe view (dark blue, teal, green, yellow), `v` in `[0, 1]`.
pub fn ramp(v: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let v = if v.is_finite() {
        v.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = v * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let s = x - i as f64;
    let c = |k: usize| (STOPS[i][k] + s * (STOPS[i + 1][k] - STOPS[i][k])).round() as u8;
    [c(0), c(1), c(2)]
}

/// `count` on a log scale against `most` (0 for 0, 1 for `most`).
fn log_scale(count: u64, most: u64) -> f64 {
    if most == 0 {
        0.0
    } else {
        (count as f64).ln_1p() / (most as f64).ln_1p()
    }
}

/// Probes `scene` (its camera and size are the view's) for `view`, with the frame loop's tiles,
/// culling as asked and `threads` worker threads.
pub fn probe(
    view: ProbeView,
    scene: &Scene,
    culling: bool,
    threads: Option<usize>,
) -> Result<ProbeImage, String> {
    let start = Instant::now();
    let settings = TraceSettings {
        culling,
        threads,
        shading: false,
        ..TraceSettings::for_scene(scene)
    };
    let (w, h) = (scene.width, scene.height);
    // Opaque black where nothing is counted.
    let mut rgba = [0u8, 0, 0, 255].repeat(w as usize * h as usize);
    let mut put = |at: usize, [r, g, b]: [u8; 3]| {
        rgba[4 * at..4 * at + 4].copy_from_slice(&[r, g, b, 255]);
    };
    let legend = match view {
        ProbeView::Cells => {
            let config = QuadtreeConfig {
                cell_size: settings.tile_size,
                memory_budget: scene.budget.clone(),
                coverage: PixelCoverage::Centres,
            };
            let list = work_list_within(scene, &config).map_err(|e| e.to_string())?;
            // A candidate weighs its active leaves (a free form) or 1 (a terrain, a mesh).
            let weight = |item: &fray_quadtree::WorkItem| -> u64 {
                list.candidates_of(item)
                    .iter()
                    .map(|c| u64::from(c.leaf_count.max(1)))
                    .sum()
            };
            let most = list.items.iter().map(weight).max().unwrap_or(0);
            for item in &list.items {
                let [r, g, b] = ramp(log_scale(weight(item), most));
                for y in item.y0..item.y1 {
                    for x in item.x0..item.x1 {
                        let edge = x == item.x0 || y == item.y0;
                        // The cell's top and left edges at half brightness: the grid shows.
                        let c = if edge {
                            [r / 2, g / 2, b / 2]
                        } else {
                            [r, g, b]
                        };
                        put((y * w + x) as usize, c);
                    }
                }
            }
            let s = list.stats;
            format!(
                "cells: {} work items of {} visited ({} culled: black); colour: leaves and objects a cell may meet, 1…{most} (log)",
                s.items, s.cells_visited, s.cells_culled
            )
        }
        ProbeView::Steps => {
            let work = pixel_work(scene, &settings).map_err(|e| e.to_string())?;
            let most = work.most_steps();
            for (at, &s) in work.steps.iter().enumerate() {
                if s > 0 {
                    put(at, ramp(log_scale(u64::from(s), u64::from(most))));
                }
            }
            let total: u64 = work.steps.iter().map(|&s| u64::from(s)).sum();
            format!(
                "search steps per pixel: 1…{most} (log; none: black), {:.1} a pixel",
                total as f64 / work.steps.len().max(1) as f64
            )
        }
        ProbeView::TerrainLevel => {
            let work = pixel_work(scene, &settings).map_err(|e| e.to_string())?;
            let highest = work.highest_level();
            for (at, &l) in work.terrain_level.iter().enumerate() {
                if l.is_finite() {
                    put(at, ramp(f64::from(l) / f64::from(highest.max(1.0))));
                }
            }
            format!(
                "terrain level of detail: 0 (finest cells) … {highest:.1} levels above (no terrain stop: black)"
            )
        }
    };
    Ok(ProbeImage {
        size: (w, h),
        rgba,
        legend,
        elapsed: start.elapsed(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(name: &str, height: u32) -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../data/scenes")
            .join(name);
        let mut s = fray_scene::load(&path).unwrap();
        s.width = s.width * height / s.height;
        s.height = height;
        s
    }

    fn pixel(image: &ProbeImage, x: u32, y: u32) -> [u8; 4] {
        let at = 4 * (y * image.size.0 + x) as usize;
        image.rgba[at..at + 4].try_into().unwrap()
    }

    #[test]
    fn the_ramp_runs_from_dark_blue_to_yellow_and_takes_anything() {
        assert_eq!(ramp(0.0), [68, 1, 84]);
        assert_eq!(ramp(1.0), [253, 231, 37]);
        assert_eq!(ramp(f64::NAN), ramp(0.0));
        assert_eq!(ramp(7.0), ramp(1.0));
        // Brighter all the way up (the sum of the channels grows).
        let sum = |c: [u8; 3]| c.iter().map(|&v| u32::from(v)).sum::<u32>();
        assert!(
            (1..=20).all(|k| sum(ramp(f64::from(k) / 20.0)) >= sum(ramp(f64::from(k - 1) / 20.0)))
        );
    }

    #[test]
    fn each_view_colours_exactly_what_it_counts() {
        let s = scene("terrain_low.ron", 36);
        let work = pixel_work(
            &s,
            &TraceSettings {
                shading: false,
                ..TraceSettings::for_scene(&s)
            },
        )
        .unwrap();
        let steps = probe(ProbeView::Steps, &s, true, Some(2)).unwrap();
        let levels = probe(ProbeView::TerrainLevel, &s, true, Some(2)).unwrap();
        for y in 0..s.height {
            for x in 0..s.width {
                let at = (y * s.width + x) as usize;
                let black = |p: [u8; 4]| p == [0, 0, 0, 255];
                assert_eq!(
                    black(pixel(&steps, x, y)),
                    work.steps[at] == 0,
                    "({x}, {y})"
                );
                assert_eq!(
                    black(pixel(&levels, x, y)),
                    !work.terrain_level[at].is_finite(),
                    "({x}, {y})"
                );
            }
        }
        assert!(steps.legend.contains("search steps"), "{}", steps.legend);
    }

    #[test]
    fn the_cells_view_leaves_culled_tiles_black_and_fills_the_others() {
        // The csg scene leaves sky around its objects: some tiles are culled.
        let s = scene("csg.ron", 72);
        let cells = probe(ProbeView::Cells, &s, true, Some(2)).unwrap();
        let config = QuadtreeConfig {
            cell_size: TraceSettings::for_scene(&s).tile_size,
            memory_budget: s.budget.clone(),
            coverage: PixelCoverage::Centres,
        };
        let list = work_list_within(&s, &config).unwrap();
        assert!(list.stats.cells_culled > 0);
        let mut covered = vec![false; (s.width * s.height) as usize];
        for item in &list.items {
            for y in item.y0..item.y1 {
                for x in item.x0..item.x1 {
                    covered[(y * s.width + x) as usize] = true;
                }
            }
        }
        for y in 0..s.height {
            for x in 0..s.width {
                let p = pixel(&cells, x, y);
                assert_eq!(
                    p != [0, 0, 0, 255],
                    covered[(y * s.width + x) as usize],
                    "({x}, {y})"
                );
            }
        }
    }
}
