//! Worley's cellular noise (SIGGRAPH 1996): one feature point in each unit lattice cell, at an
//! offset hashed from the cell by Perlin's permutation (so it tiles with Perlin's period, 256),
//! and `F1(p)`, the distance from `p` to the nearest feature point — exactly: the 3 × 3 × 3 cells
//! around `p` are searched, and the 5 × 5 × 5 ones when what they found could be beaten from a
//! cell farther out. Summed over octaves as `1 − F1` ("billows"), it gives clouds their puffy,
//! cauliflower tops when mixed into the Perlin sum (`CloudField::worley`).

use crate::perlin::PERMUTATION;

#[inline]
fn hash(i: i64) -> usize {
    usize::from(PERMUTATION[i.rem_euclid(256) as usize])
}

/// The feature point of lattice cell `(i, j, k)`: the cell's corner plus an offset in `[0, 1)³`.
pub fn feature_point(i: i64, j: i64, k: i64) -> [f64; 3] {
    let h = hash(hash(hash(i) as i64 + j) as i64 + k);
    // Three more hashes of the cell's hash, each in 1/256 steps (centred in its step).
    let offset = |n: usize| (hash((h + n) as i64) as f64 + 0.5) / 256.0;
    [
        i as f64 + offset(0),
        j as f64 + offset(101),
        k as f64 + offset(211),
    ]
}

/// `F1(p)`: the distance from `(x, y, z)` to the nearest feature point.
pub fn f1(x: f64, y: f64, z: f64) -> f64 {
    let cell = [x.floor() as i64, y.floor() as i64, z.floor() as i64];
    let nearest = |reach: i64| {
        let mut best = f64::INFINITY;
        for dk in -reach..=reach {
            for dj in -reach..=reach {
                for di in -reach..=reach {
                    let q = feature_point(cell[0] + di, cell[1] + dj, cell[2] + dk);
                    let d2 = (q[0] - x).powi(2) + (q[1] - y).powi(2) + (q[2] - z).powi(2);
                    best = best.min(d2);
                }
            }
        }
        best.sqrt()
    };
    let near = nearest(1);
    // A feature point two or more cells away along some axis is at least the distance from `p`
    // to the 3³ block's faces away: only then can it be nearer.
    let to_faces = [x, y, z]
        .iter()
        .zip(cell)
        .map(|(v, c)| {
            let f = v - c as f64;
            (1.0 + f).min(2.0 - f)
        })
        .fold(f64::INFINITY, f64::min);
    if near <= to_faces { near } else { nearest(2) }
}

/// The octave sum of billows `Σᵢ gainⁱ (1 − F1(lacunarityⁱ p)) / Σᵢ gainⁱ`, clamped to `[0, 1]`.
pub fn billows(x: f64, y: f64, z: f64, octaves: u32, lacunarity: f64, gain: f64) -> f64 {
    let (mut sum, mut norm, mut frequency, mut amplitude) = (0.0, 0.0, 1.0, 1.0);
    for _ in 0..octaves {
        sum += amplitude * (1.0 - f1(x * frequency, y * frequency, z * frequency));
        norm += amplitude;
        frequency *= lacunarity;
        amplitude *= gain;
    }
    if norm > 0.0 {
        (sum / norm).clamp(0.0, 1.0)
    } else {
        0.0
    }
}
