//! The clouds' GPU parameter block: [`GpuClouds`], a `#[repr(C)]` Pod struct declared with its
//! WGSL twin from one field list (`fray_core::gpu_struct!`), filled in f64 from a
//! [`GridVolume`], its [`CloudLight`] and [`MarchSettings`] relative to a reference point (the
//! camera) before rounding to f32 — so a cloud layer kilometres from the world origin keeps f32
//! precision in the camera-relative positions `shaders/clouds.wgsl` marches — and the texels of
//! the grids the GPU reads as 3D textures ([`max_grid_texels`]: one bound per block, x fastest,
//! as the density grid's samples).

use crate::march::{CloudLight, GridVolume, MarchSettings};
use crate::{DensityGrid, MaxGrid};
pub use fray_core::gpu_struct::GpuStruct;

fray_core::gpu_struct! {
    /// A cloud volume as the GPU reads it: [`GridVolume`]'s box (relative to a reference point)
    /// and scale, its grid's and max grid's sizes, [`CloudLight`] and [`MarchSettings`].
    pub struct GpuClouds {
        /// The region's corners minus the reference point (f64, then rounded); `w` unused.
        pub region_min: [f32; 4],
        pub region_max: [f32; 4],
        /// `max − min` per axis from the f64 corners (the difference of the rounded corners
        /// would lose a thin box far from the reference point); `w` unused.
        pub extent: [f32; 4],
        /// Unit vector toward the sun (xyz).
        pub sun_direction: [f32; 4],
        /// The sun's irradiance reaching the volume (rgb).
        pub sun_irradiance: [f32; 4],
        /// The ambient radiance scattered in (rgb).
        pub ambient: [f32; 4],
        /// The density grid's samples per axis (xyz) and 1 when empty-space skipping is on (w).
        pub grid_size: [u32; 4],
        /// The max grid's blocks per axis (xyz) and the block side in cells (w).
        pub blocks: [u32; 4],
        /// The extinction at grid value 1 (1/m).
        pub scale: f32,
        pub albedo: f32,
        /// The dual-lobe phase: `(1 − weight)·HG(g1) + weight·HG(g2)`.
        pub g1: f32,
        pub g2: f32,
        pub weight: f32,
        /// The view ray's step (world units), the sun rays' steps, the early-exit threshold.
        pub step: f32,
        pub sun_steps: u32,
        pub min_transmittance: f32,
        /// 1: camera rays offset their samples by the pixel's interleaved gradient noise; 0:
        /// midpoints.
        pub jitter: u32,
        pub pad: u32,
        pub pad2: [u32; 2],
    }
}

impl GpuClouds {
    /// The block of `volume` lit by `light`, marched with `settings`, relative to `reference`;
    /// `jitter`: camera rays take the pixel's jitter (else `settings.jitter` is irrelevant: the
    /// GPU takes midpoints, as the CPU's 0.5).
    pub fn new(
        volume: &GridVolume,
        light: &CloudLight,
        settings: &MarchSettings,
        jitter: bool,
        reference: [f64; 3],
    ) -> Self {
        let r = &volume.region;
        let v4 = |v: [f64; 3]| [v[0] as f32, v[1] as f32, v[2] as f32, 0.0];
        let size = volume.grid.size();
        let (skip, blocks, block) = match &volume.skip {
            Some(m) => {
                let b = m.blocks();
                (
                    1,
                    [b[0] as u32, b[1] as u32, b[2] as u32],
                    block_side(m, size),
                )
            }
            None => (0, [1, 1, 1], 1),
        };
        Self {
            region_min: v4(std::array::from_fn(|a| r.min[a] - reference[a])),
            region_max: v4(std::array::from_fn(|a| r.max[a] - reference[a])),
            extent: v4(std::array::from_fn(|a| r.max[a] - r.min[a])),
            sun_direction: v4(light.sun_direction),
            sun_irradiance: v4(light.sun_irradiance),
            ambient: v4(light.ambient),
            grid_size: [size[0] as u32, size[1] as u32, size[2] as u32, skip],
            blocks: [blocks[0], blocks[1], blocks[2], block],
            scale: volume.scale as f32,
            albedo: light.albedo as f32,
            g1: light.phase.g1 as f32,
            g2: light.phase.g2 as f32,
            weight: light.phase.weight as f32,
            step: settings.step as f32,
            sun_steps: settings.sun_steps,
            min_transmittance: settings.min_transmittance as f32,
            jitter: u32::from(jitter),
            pad: 0,
            pad2: [0; 2],
        }
    }
}

/// The block side (in cells) of `max`, a max grid of a grid of `size`: from the first block's
/// box where an axis has several blocks; any side covering the grid where none has.
fn block_side(max: &MaxGrid, size: [usize; 3]) -> u32 {
    let blocks = max.blocks();
    let first = size.map(|n| 0.5 / n as f64);
    let (_, _, hi) = max.block_at(first);
    (0..3)
        .find(|&a| blocks[a] > 1)
        .map(|a| (hi[a] * size[a] as f64).round() as u32)
        .unwrap_or_else(|| size.into_iter().max().unwrap_or(1) as u32)
        .max(1)
}

/// The bounds of `max` (a max grid of `grid`), one per block, x fastest, then y, then z: the
/// texels of the GPU's max-grid texture.
pub fn max_grid_texels(max: &MaxGrid, grid: &DensityGrid) -> Vec<f32> {
    let size = grid.size();
    let blocks = max.blocks();
    let block = block_side(max, size) as usize;
    let mut texels = Vec::with_capacity(blocks.iter().product());
    for bk in 0..blocks[2] {
        for bj in 0..blocks[1] {
            for bi in 0..blocks[0] {
                // The centre of the block's first cell lies in the block.
                let at = [bi, bj, bk];
                let p = std::array::from_fn(|a| ((at[a] * block) as f64 + 0.5) / size[a] as f64);
                texels.push(max.bound_at(p));
            }
        }
    }
    texels
}

/// The WGSL declaration of [`GpuClouds`] (for the shader prelude).
pub fn wgsl_declaration() -> String {
    format!(
        "// Generated by fray_clouds::gpu_layout — do not edit.\n{}",
        GpuClouds::declaration()
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bake::Region;
    use crate::march::DualLobe;
    use fray_core::MemoryBudget;

    #[test]
    fn the_block_is_relative_to_the_reference_and_its_layout_is_wgsl_s() {
        GpuClouds::check_layout().unwrap();
        let grid = DensityGrid::from_fn([10, 4, 7], &MemoryBudget::default(), |i, j, k| {
            if i > 6 && j > 1 && k < 3 {
                (i + j + k) as f32
            } else {
                0.0
            }
        })
        .unwrap();
        let skip = grid.max_grid(3);
        let volume = GridVolume {
            region: Region {
                min: [1e5, 10.0, -3.0],
                max: [1e5 + 50.0, 12.5, 4.0],
            },
            scale: 0.25,
            skip: Some(skip.clone()),
            grid: grid.clone(),
        };
        let light = CloudLight {
            sun_direction: [0.0, 1.0, 0.0],
            sun_irradiance: [1.0, 2.0, 3.0],
            ambient: [0.1, 0.2, 0.3],
            albedo: 0.9,
            phase: DualLobe {
                g1: 0.8,
                g2: -0.3,
                weight: 0.2,
            },
        };
        let g = GpuClouds::new(
            &volume,
            &light,
            &MarchSettings::default(),
            true,
            [1e5 + 1.0, 0.0, 0.0],
        );
        assert_eq!(g.region_min, [-1.0, 10.0, -3.0, 0.0]);
        assert_eq!(g.region_max, [49.0, 12.5, 4.0, 0.0]);
        assert_eq!(g.extent, [50.0, 2.5, 7.0, 0.0]);
        assert_eq!(g.grid_size, [10, 4, 7, 1]);
        assert_eq!(g.blocks, [4, 2, 3, 3]);
        assert_eq!((g.g2, g.weight, g.jitter, g.sun_steps), (-0.3, 0.2, 1, 6));
        // The texels are the max grid's bounds, block by block.
        let texels = max_grid_texels(&skip, &grid);
        assert_eq!(texels.len(), 24);
        for (k, &t) in texels.iter().enumerate() {
            let (bi, bj, bk) = (k % 4, (k / 4) % 2, k / 8);
            let p = [
                (bi as f64 * 3.0 + 1.0) / 10.0,
                (bj as f64 * 3.0 + 1.0) / 4.0,
                (bk as f64 * 3.0 + 1.0) / 7.0,
            ];
            assert_eq!(t, skip.bound_at(p), "block {k}");
        }
        assert!(texels.contains(&0.0) && texels.iter().any(|&t| t > 0.0));
        // A single block per axis: any side covering the grid.
        let one = grid.max_grid(16);
        assert_eq!(block_side(&one, [10, 4, 7]), 10);
        assert_eq!(max_grid_texels(&one, &grid).len(), 1);
        let plain = GpuClouds::new(
            &GridVolume {
                skip: None,
                ..volume
            },
            &light,
            &MarchSettings::default(),
            false,
            [0.0; 3],
        );
        assert_eq!((plain.grid_size[3], plain.jitter), (0, 0));
    }
}
