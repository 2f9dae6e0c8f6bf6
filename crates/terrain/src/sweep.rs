//! The terrain sweep setup shared by the criterion bench (`cargo bench -p fray-terrain`) and
//! `cargo xtask bench`: a DEM upsampled to any map size over the same ground, one fixed oblique
//! screen of rays over it, and depth errors against a reference. Public so that both measure the
//! same thing; not needed to render terrain.

use crate::{Heightmap, Placement, Terrain, TerrainError, TerrainOptions};
use fray_core::Ray;
use glam::{DVec2, DVec3};

/// Side of the square of ground every sweep map covers, in world units (metres).
pub const EXTENT: f64 = 30_000.0;

/// The fixed screen's eye: a corner of the square, 14 km up.
pub const EYE: DVec3 = DVec3::new(-4_000.0, 14_000.0, -4_000.0);

/// The fixed screen's target: the square's centre (≈ 35° down from the eye).
pub const TARGET: DVec3 = DVec3::new(0.5 * EXTENT, 600.0, 0.5 * EXTENT);

/// The fixed screen's vertical (and horizontal) field of view, in degrees.
pub const FOV_DEGREES: f64 = 50.0;

fn hash(i: i64, j: i64, octave: u32) -> f64 {
    let mut z = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (j as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ u64::from(octave).wrapping_mul(0x1656_67B1_9E37_79F9);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}

/// Bilinearly interpolated hashed lattice noise with lattice period `period` samples.
fn value_noise(x: f64, y: f64, period: f64, octave: u32) -> f64 {
    let (fx, fy) = (x / period, y / period);
    let (i, j) = (fx.floor(), fy.floor());
    let (s, t) = (fx - i, fy - j);
    let (i, j) = (i as i64, j as i64);
    let a = hash(i, j, octave) * (1.0 - s) + hash(i + 1, j, octave) * s;
    let b = hash(i, j + 1, octave) * (1.0 - s) + hash(i + 1, j + 1, octave) * s;
    a * (1.0 - t) + b * t
}

/// `base`'s surface resampled to `n × n` samples (`n ≥ 2`) with deterministic fractal detail
/// below `base`'s resolution (4 octaves of hashed value noise, periods 16 … 2 samples, 12 m
/// halving), placed over the same [`EXTENT`]² square for every `n` (spacing `EXTENT / (n − 1)`).
pub fn upsampled(
    base: &Terrain,
    n: usize,
    options: TerrainOptions,
) -> Result<Terrain, TerrainError> {
    let (cw, ch) = base.map().cells();
    let scale = (n.max(2) - 1) as f64;
    let samples = (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f64, (k / n) as f64);
            let (u, v) = (i / scale * cw as f64, j / scale * ch as f64);
            let mut h = base.surface(u, v).unwrap_or(0.0);
            for octave in 0..4u32 {
                let period = f64::from(16 >> octave);
                if period * 0.5 > n as f64 / 403.0 {
                    continue; // only below the DEM's own resolution
                }
                h += 12.0 * 0.5f64.powi(octave as i32) * value_noise(i, j, period, octave);
            }
            h as f32
        })
        .collect();
    let map = Heightmap::from_samples(n, n, samples)?;
    let placement = Placement::new(DVec3::ZERO, DVec2::splat(EXTENT / scale), 1.0)?;
    Terrain::new(map, placement, options)
}

/// The world width of one sweep-map cell for an `n × n` map.
pub fn cell_size(n: usize) -> f64 {
    EXTENT / (n.max(2) - 1) as f64
}

/// The fixed screen: `side × side` pinhole rays from [`EYE`] toward [`TARGET`] over a
/// [`FOV_DEGREES`] square field (pixel centres, row 0 at the top).
pub fn screen_rays(side: usize) -> Vec<Ray> {
    let fwd = (TARGET - EYE).normalize();
    let right = fwd.cross(DVec3::Y).normalize();
    let up = right.cross(fwd);
    let half = (0.5 * FOV_DEGREES).to_radians().tan();
    let s = side.max(1) as f64;
    (0..side * side)
        .filter_map(|k| {
            let (x, y) = ((k % side) as f64, (k / side) as f64);
            let sx = ((x + 0.5) / s * 2.0 - 1.0) * half;
            let sy = (1.0 - (y + 0.5) / s * 2.0) * half;
            Ray::new(EYE, fwd + right * sx + up * sy)
        })
        .collect()
}

/// World size of a pixel per unit distance on a `side × side` fixed screen.
pub fn screen_footprint(side: usize) -> f64 {
    2.0 * (0.5 * FOV_DEGREES).to_radians().tan() / side.max(1) as f64
}

/// Depth differences of `got` against `reference` (hits per ray), in units of `cell`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DepthError {
    /// Mean `|Δt| / cell` over rays both hit.
    pub mean: f64,
    /// Largest `|Δt| / cell` over rays both hit.
    pub max: f64,
    /// Rays one hits and the other misses.
    pub flips: usize,
}

impl DepthError {
    /// Compares two lists of hits ray by ray.
    pub fn of(reference: &[Option<f64>], got: &[Option<f64>], cell: f64) -> Self {
        let (mut sum, mut max, mut n, mut flips) = (0.0, 0.0f64, 0usize, 0usize);
        for (a, b) in reference.iter().zip(got) {
            match (a, b) {
                (Some(a), Some(b)) => {
                    let e = (a - b).abs() / cell;
                    sum += e;
                    max = max.max(e);
                    n += 1;
                }
                (None, None) => {}
                _ => flips += 1,
            }
        }
        Self {
            mean: sum / n.max(1) as f64,
            max,
            flips,
        }
    }
}
