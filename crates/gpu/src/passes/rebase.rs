//! The rebase pass: the resident scene is uploaded once relative to a fixed anchor; every frame
//! this pass moves its positions to the camera — `(x − hi) − lo` with the camera's offset from
//! the anchor as a hi/lo pair of f32 — into camera-relative copies the other passes read, so a
//! moved camera uploads no scene. Box corners move outward by the subtraction's rounding, so
//! boxes stay conservative; with a zero offset the copy is exact. [`rebase_words`] is the CPU
//! twin (the GPU's result is bit-identical: f32 subtraction and multiplication by a power of two
//! are correctly rounded on every backend).

use super::{Kernel, PassSetup, PipelineCache};
use crate::bindings::REBASE;
use crate::shader::{ModuleOptions, Specialisation};
use crate::{GpuContext, GpuError};
use bytemuck::Pod;

pub use crate::params::RebaseParams;

/// Which 16-byte slots of a GPU struct hold positions and box corners (from the structs'
/// `offset_of!`s; `resident/mod.rs` lists the scene's).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RebaseLayout {
    /// Slots per element.
    pub stride: u32,
    pub points: u32,
    pub box_mins: u32,
    pub box_maxs: u32,
}

impl RebaseLayout {
    /// The layout of a struct of `size` bytes with positions, lower and upper box corners at
    /// the given byte offsets (each a multiple of 16: a `[f32; 4]` field).
    pub const fn new(size: usize, points: &[usize], mins: &[usize], maxs: &[usize]) -> Self {
        const fn mask(offsets: &[usize]) -> u32 {
            let mut m = 0u32;
            let mut i = 0;
            while i < offsets.len() {
                assert!(offsets[i].is_multiple_of(16) && offsets[i] / 16 < 32);
                m |= 1 << (offsets[i] / 16);
                i += 1;
            }
            m
        }
        assert!(size.is_multiple_of(16) && size / 16 <= 32);
        Self {
            stride: (size / 16) as u32,
            points: mask(points),
            box_mins: mask(mins),
            box_maxs: mask(maxs),
        }
    }
}

/// The slack that keeps a moved box corner conservative: twice an f32 ulp of `|x| + |hi|`
/// (2⁻²²), zero where the offset is zero.
#[inline]
fn slack(x: f32, hi: f32, moved: bool) -> f32 {
    if moved {
        (x.abs() + hi.abs()) * (1.0 / 4_194_304.0)
    } else {
        0.0
    }
}

/// The CPU twin of the pass: `words` (an array of GPU structs as 16-byte slots) moved by the
/// offset `(hi, lo)` as `layout` says.
pub fn rebase_words(
    words: &[[u32; 4]],
    layout: &RebaseLayout,
    hi: [f32; 4],
    lo: [f32; 4],
) -> Vec<[u32; 4]> {
    let moved: [bool; 3] = std::array::from_fn(|k| hi[k] != 0.0 || lo[k] != 0.0);
    words
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let bit = 1u32 << (i as u32 % layout.stride);
            let x: [f32; 3] = std::array::from_fn(|k| f32::from_bits(v[k]));
            let shifted: [f32; 3] = std::array::from_fn(|k| (x[k] - hi[k]) - lo[k]);
            let out: [f32; 3] = if layout.points & bit != 0 {
                shifted
            } else if layout.box_mins & bit != 0 {
                std::array::from_fn(|k| shifted[k] - slack(x[k], hi[k], moved[k]))
            } else if layout.box_maxs & bit != 0 {
                std::array::from_fn(|k| shifted[k] + slack(x[k], hi[k], moved[k]))
            } else {
                return *v;
            };
            [out[0].to_bits(), out[1].to_bits(), out[2].to_bits(), v[3]]
        })
        .collect()
}

/// One resident array and its camera-relative copy.
#[derive(Debug)]
pub struct Rebased {
    /// The anchor-relative data, uploaded once.
    pub source: wgpu::Buffer,
    /// The camera-relative copy the passes read (its usage includes `COPY_SRC` so that a
    /// uniform table can be filled from it).
    pub target: wgpu::Buffer,
    pub layout: RebaseLayout,
    words: u32,
    params: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

impl Rebased {
    /// Uploads `data` (a `gpu_struct!` array laid out as `layout`) and allocates its copy;
    /// returns it and the bytes uploaded.
    pub fn new<T: Pod + Default>(
        ctx: &GpuContext,
        charges: &mut crate::DeviceCharges,
        cache: &PipelineCache,
        label: &'static str,
        data: &[T],
        layout: RebaseLayout,
    ) -> Result<(Self, u64), GpuError> {
        use wgpu::BufferUsages as U;
        let source = charges.upload(ctx, label, data, T::default(), U::STORAGE | U::COPY_SRC)?;
        let bytes = source.size();
        let target = charges.empty(ctx, label, bytes, U::STORAGE | U::COPY_SRC)?;
        let params = charges.empty(
            ctx,
            "rebase params",
            std::mem::size_of::<RebaseParams>() as u64,
            U::UNIFORM | U::COPY_DST,
        )?;
        let group_layout = cache.layout(ctx, &REBASE);
        let bind_group = REBASE.bind(
            &ctx.device,
            &group_layout,
            &[
                params.as_entire_binding(),
                source.as_entire_binding(),
                target.as_entire_binding(),
            ],
        );
        let rebased = Self {
            source,
            target,
            layout,
            words: (bytes / 16) as u32,
            params,
            bind_group,
        };
        Ok((rebased, bytes))
    }
}

/// The rebase pass.
#[derive(Debug)]
pub struct RebasePass {
    kernel: Kernel,
}

impl RebasePass {
    pub fn new(cache: &PipelineCache, ctx: &GpuContext) -> Result<Self, GpuError> {
        // The same module for every scene: no composition options, no specialisation.
        let setup = PassSetup {
            cache,
            ctx,
            options: &ModuleOptions::default(),
            specialisation: &Specialisation::default(),
        };
        let kernel = Kernel::new(&setup, "rebase.wgsl", &[REBASE])?;
        Ok(Self { kernel })
    }

    /// Writes each array's parameters for the offset `(hi, lo)` (returns the bytes written) and
    /// encodes the moves; the parameters must reach the queue before the encoder is submitted.
    pub fn encode(
        &self,
        ctx: &GpuContext,
        pass: &mut wgpu::ComputePass<'_>,
        arrays: &[&Rebased],
        hi: [f32; 4],
        lo: [f32; 4],
    ) -> u64 {
        let mut bytes = 0;
        for a in arrays {
            let params = RebaseParams {
                hi,
                lo,
                words: a.words,
                stride: a.layout.stride,
                points: a.layout.points,
                box_mins: a.layout.box_mins,
                box_maxs: a.layout.box_maxs,
                ..RebaseParams::default()
            };
            ctx.queue
                .write_buffer(&a.params, 0, bytemuck::bytes_of(&params));
            bytes += std::mem::size_of::<RebaseParams>() as u64;
        }
        for a in arrays {
            self.kernel
                .run(pass, ctx, &[&a.bind_group], a.words.div_ceil(64));
        }
        bytes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cpu_twin_moves_positions_widens_boxes_and_copies_the_rest() {
        let layout = RebaseLayout::new(48, &[0], &[16], &[32]);
        assert_eq!(
            (
                layout.stride,
                layout.points,
                layout.box_mins,
                layout.box_maxs
            ),
            (3, 1, 2, 4)
        );
        let f = |v: [f32; 3], w: u32| [v[0].to_bits(), v[1].to_bits(), v[2].to_bits(), w];
        let words = [
            f([1.0, 2.0, 3.0], 7),
            f([-1.0, -1.0, -1.0], 8),
            f([1.0, 1.0, 1.0], 9),
        ];
        // A zero offset copies exactly.
        assert_eq!(rebase_words(&words, &layout, [0.0; 4], [0.0; 4]), words);
        let (hi, lo) = crate::params::hi_lo(glam::DVec3::new(1.0e5 + 0.25, 0.0, -3.0));
        let out = rebase_words(&words, &layout, hi, lo);
        let get = |w: [u32; 4], k: usize| f64::from(f32::from_bits(w[k]));
        // Positions: (x − hi) − lo, within an f32 ulp of the exact difference.
        assert!((get(out[0], 0) - (1.0 - 1.0e5 - 0.25)).abs() <= 1e5 * 1.2e-7);
        assert_eq!(get(out[0], 1), 2.0);
        assert_eq!(out[0][3], 7, "the w word is copied bit for bit");
        // Boxes grow outward on moved axes and stay where they were on the others.
        assert!(get(out[1], 0) <= -1.0 - 1.0e5 - 0.25);
        assert!(get(out[2], 0) >= 1.0 - 1.0e5 - 0.25);
        assert_eq!((get(out[1], 1), get(out[2], 1)), (-1.0, 1.0));
        assert!(get(out[1], 2) <= -1.0 + 3.0 && get(out[2], 2) >= 1.0 + 3.0);
    }
}
