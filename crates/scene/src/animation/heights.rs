//! Terrains whose heights change with time: a terrain's checked `animate:` (waves, or a sequence
//! of maps) and the terrain it is at a time — the base terrain's heights moved, its pyramids
//! updated only above the samples that moved ([`Terrain::with_heights`]), the copy reserved on
//! the scene's budget first.

use crate::checks::{Invalid, Result, finite, invalid, positive};
use crate::description::{self, TerrainAnimate};
use crate::path::FieldPath;
use fray_core::{MemoryBudget, Reservation};
use fray_terrain::{Heightmap, Region, Terrain, Wave, Waves};
use glam::DVec2;
use std::path::Path;
use std::sync::Arc;

/// The most waves one terrain sums (each costs a sine per sample and frame).
pub const MAX_WAVES: usize = 16;

/// How a terrain's heights change with time, checked against its map.
#[derive(Clone, Debug, PartialEq)]
pub enum Heights {
    /// Travelling sine waves over a region ([`Waves`]).
    Waves(Waves),
    /// One height map a frame, each with the samples where it differs from the file's map.
    Sequence(Sequence),
}

/// A sequence of height maps of the terrain's size (with its threshold), `fps` a second.
#[derive(Clone, Debug, PartialEq)]
pub struct Sequence {
    pub fps: f64,
    /// Each frame's map and the samples where it differs from the base map (the bounding
    /// rectangle: what its pyramid update covers).
    pub frames: Vec<(Arc<Heightmap>, Region)>,
}

impl Sequence {
    /// The frame shown at `t`: `⌊t · fps⌋`, held at the ends.
    pub fn frame_at(&self, t: f64) -> usize {
        let k = (t * self.fps).floor();
        if k <= 0.0 {
            0
        } else {
            (k.min((self.frames.len() - 1) as f64)) as usize
        }
    }
}

impl Heights {
    /// Checks a terrain's `animate:` (at `path`) against its base terrain: finite values, a
    /// positive wavelength, a direction that is not zero, a region inside the map, and heights
    /// that stay finite in `f32` whatever the time.
    pub(crate) fn resolve(
        path: &FieldPath,
        a: &TerrainAnimate,
        base: &Terrain,
        folder: &Path,
        budget: &MemoryBudget,
    ) -> Result<Self> {
        match a {
            TerrainAnimate::Sequence { paths, fps } => {
                let fps = positive(&path.field("fps"), *fps)?;
                if paths.is_empty() {
                    return invalid(&path.field("paths"), "give at least one height map");
                }
                let frames = paths
                    .iter()
                    .enumerate()
                    .map(|(k, p)| {
                        frame(&path.field("paths").index(k), &folder.join(p), base, budget)
                    })
                    .collect::<Result<Vec<_>>>()?;
                Ok(Heights::Sequence(Sequence { fps, frames }))
            }
            TerrainAnimate::Waves {
                level,
                waves,
                region,
            } => {
                let waves_path = path.field("waves");
                if waves.is_empty() || waves.len() > MAX_WAVES {
                    return invalid(
                        &waves_path,
                        format!("give 1 to {MAX_WAVES} waves, got {}", waves.len()),
                    );
                }
                let waves = waves
                    .iter()
                    .enumerate()
                    .map(|(k, w)| wave(&waves_path.index(k), w))
                    .collect::<Result<Vec<_>>>()?;
                let level = match level {
                    Some(l) => Some(finite(&path.field("level"), *l)?),
                    None => None,
                };
                let map = base.map();
                let (w, h) = (map.width(), map.height());
                let region = match region {
                    Some(r) => Some(check_region(&path.field("region"), *r, w, h)?),
                    None => None,
                };
                // The highest a sample can reach, in raw units: it must stay a finite f32.
                let scale = base.placement().vertical_scale();
                let reach: f64 = waves.iter().map(|w| w.amplitude.abs()).sum::<f64>()
                    + level.map_or(0.0, f64::abs);
                let highest = map
                    .samples()
                    .iter()
                    .fold(0f64, |m, s| m.max(f64::from(s.abs())));
                if highest + reach / scale > f64::from(f32::MAX) / 2.0 {
                    return invalid(
                        &waves_path,
                        format!(
                            "the amplitudes (and level) reach {reach:e} world units: heights of \
                             {:e} raw units do not fit the map's f32 samples",
                            highest + reach / scale
                        ),
                    );
                }
                Ok(Heights::Waves(Waves {
                    waves,
                    level,
                    region,
                }))
            }
        }
    }

    /// The samples that move, on the base terrain's map.
    pub fn region(&self, base: &Terrain, t: f64) -> Region {
        match self {
            Heights::Waves(w) => w.region(base.map().width(), base.map().height()),
            Heights::Sequence(s) => s.frames[s.frame_at(t)].1,
        }
    }

    /// The terrain at time `t`: `base` with its heights at `t`, and what the copy holds on
    /// `budget` (reserved before it is made; released when the last still holding it drops).
    pub fn terrain_at(
        &self,
        base: &Terrain,
        t: f64,
        budget: &MemoryBudget,
        name: &str,
    ) -> std::result::Result<(Arc<Terrain>, Arc<Reservation>), String> {
        let held = budget
            .reserve(
                format!("the terrain {name}'s heights and pyramids at {t} s"),
                base.heap_bytes(),
            )
            .map_err(|e| e.to_string())?;
        let map = match self {
            Heights::Waves(w) => w
                .heights_at(base.map(), base.placement(), t)
                .map_err(|e| e.to_string())?,
            Heights::Sequence(s) => (*s.frames[s.frame_at(t)].0).clone(),
        };
        let terrain = base
            .with_heights(map, self.region(base, t))
            .map_err(|e| e.to_string())?;
        Ok((Arc::new(terrain), Arc::new(held)))
    }
}

/// One map of a sequence at `file` (the error at `path`): loaded within the budget (charged for
/// the scene's life), the terrain's size, given its threshold; and where it differs from the
/// terrain's map.
fn frame(
    path: &FieldPath,
    file: &Path,
    base: &Terrain,
    budget: &MemoryBudget,
) -> Result<(Arc<Heightmap>, Region)> {
    let fail = |m: String| Invalid {
        path: path.clone(),
        message: m,
    };
    let map = Heightmap::load_within(file, budget).map_err(|e| fail(e.to_string()))?;
    let own = base.map();
    if (map.width(), map.height()) != (own.width(), own.height()) {
        return Err(fail(format!(
            "{}: a {} × {} map, the terrain's is {} × {}",
            file.display(),
            map.width(),
            map.height(),
            own.width(),
            own.height()
        )));
    }
    let map = map
        .with_threshold(own.threshold())
        .map_err(|e| fail(e.to_string()))?;
    // The bounding rectangle of the samples that differ (bit for bit) from the terrain's.
    let mut changed = Region::default();
    for j in 0..map.height() {
        for i in 0..map.width() {
            if map.at(i, j).to_bits() != own.at(i, j).to_bits() {
                changed = changed.union(&Region::new(i, j, i + 1, j + 1));
            }
        }
    }
    Ok((Arc::new(map), changed))
}

fn wave(path: &FieldPath, w: &description::TerrainWave) -> Result<Wave> {
    let d = DVec2::from_array(w.direction);
    let direction = d.normalize_or_zero();
    if !d.is_finite() || direction == DVec2::ZERO {
        return invalid(
            &path.field("direction"),
            format!(
                "must be a finite vector that is not zero, got {:?}",
                w.direction
            ),
        );
    }
    Ok(Wave {
        amplitude: finite(&path.field("amplitude"), w.amplitude)?,
        wavelength: positive(&path.field("wavelength"), w.wavelength)?,
        direction,
        speed: finite(&path.field("speed"), w.speed)?,
    })
}

fn check_region(path: &FieldPath, r: [u64; 4], width: usize, height: usize) -> Result<Region> {
    let [x, y, columns, rows] = r;
    let fits = |start: u64, n: u64, side: usize| {
        n > 0 && start.checked_add(n).is_some_and(|end| end <= side as u64)
    };
    if !fits(x, columns, width) || !fits(y, rows, height) {
        return Err(Invalid {
            path: path.clone(),
            message: format!(
                "(first column, first row, columns, rows) = ({x}, {y}, {columns}, {rows}) must \
                 be a rectangle of at least one sample inside the {width} × {height} map"
            ),
        });
    }
    let (x, y) = (x as usize, y as usize);
    Ok(Region::new(x, y, x + columns as usize, y + rows as usize))
}
