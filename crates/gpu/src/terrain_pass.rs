//! The terrain pass (one struct, its pipeline and buffers): `shaders/terrain.wgsl` casts a batch
//! of camera-relative rays against one terrain — the max pyramid as a storage buffer (levels at
//! offsets `(4ᵏ − 1) / 3`), the samples as another — and reads back `(t, normal)` per ray. It is
//! the f32 twin of `fray_terrain::Terrain::cast` (bilinear and B-spline bicubic); a parity test
//! bounds the difference. The GPU frame casts terrain with the same `cast_terrain`, from the
//! free-form module (see `shader::freeform_source`).

use crate::bindings::{entry, storage};
use crate::readback::{read_back, readback_buffer};
use crate::{GpuContext, GpuError};
use fray_terrain::Terrain;
use fray_terrain::gpu_layout::{self, GpuTerrainParams};
use glam::DVec3;
use wgpu::util::DeviceExt;

const PASS: &str = "terrain";
const WORKGROUP: u32 = 64;

pub use crate::shader::TERRAIN_WGSL;

/// The complete terrain batch module: the generated prelude (which holds the terrain's parameter
/// struct, from `fray_terrain::gpu_layout`), the terrain bindings, terrain.wgsl and
/// terrain_batch.wgsl.
pub fn terrain_source() -> String {
    crate::shader::terrain_batch_source()
}

/// One ray of a batch, relative to the pass's reference point: `(origin, t_lo)`,
/// `(unit direction, t_hi)`.
pub type GpuRay = [[f32; 4]; 2];

/// The terrain pass of one terrain.
#[derive(Debug)]
pub struct TerrainPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: GpuTerrainParams,
    pyramid: wgpu::Buffer,
    samples: wgpu::Buffer,
}

impl TerrainPass {
    /// Builds the pipeline and uploads `terrain` relative to `reference` (the camera).
    pub fn new(ctx: &GpuContext, terrain: &Terrain, reference: DVec3) -> Result<Self, GpuError> {
        let pyramid = gpu_layout::pyramid_values(terrain);
        let samples = terrain.map().samples();
        let limit = ctx.limits.max_storage_buffer_binding_size;
        let bytes = (pyramid.len().max(samples.len()) * 4) as u64;
        if bytes > limit {
            return Err(GpuError::TooLarge {
                what: "terrain buffer bytes",
                needed: bytes,
                limit,
            });
        }
        let device = &ctx.device;
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("terrain.wgsl"),
            source: wgpu::ShaderSource::Wgsl(terrain_source().into()),
        });
        use wgpu::BufferBindingType as B;
        let read = B::Storage { read_only: true };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(PASS),
            entries: &[
                entry(0, B::Uniform),
                entry(1, read),
                entry(2, read),
                entry(3, read),
                entry(4, B::Storage { read_only: false }),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(PASS),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(PASS),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("main"),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            cache: None,
        });
        if let Some(e) = pollster::block_on(validation.pop()) {
            return Err(GpuError::Pipeline {
                pass: PASS,
                reason: e.to_string(),
            });
        }
        Ok(Self {
            pipeline,
            layout,
            params: GpuTerrainParams::new(terrain, reference, 0),
            pyramid: storage(ctx, "terrain pyramid", &pyramid, 0.0),
            samples: storage(ctx, "terrain samples", samples, 0.0),
        })
    }

    /// Casts `rays` (relative to the reference point); per ray `(t, normal)`, `t < 0` for a miss.
    pub fn cast(&self, ctx: &GpuContext, rays: &[GpuRay]) -> Result<Vec<[f32; 4]>, GpuError> {
        if rays.is_empty() {
            return Ok(Vec::new());
        }
        let device = &ctx.device;
        let mut params = self.params;
        params.sizes[2] = rays.len() as u32;
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("terrain params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let ray_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("terrain rays"),
            contents: bytemuck::cast_slice(rays),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let bytes = (rays.len() * 16) as u64;
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("terrain hits"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = readback_buffer(device, "terrain readback", bytes);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(PASS),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: self.pyramid.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.samples.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: ray_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: output.as_entire_binding(),
                },
            ],
        });
        let groups = (rays.len() as u32).div_ceil(WORKGROUP);
        let x = groups.min(ctx.limits.max_compute_workgroups_per_dimension.max(1));
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(PASS),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups(x, groups.div_ceil(x), 1);
        }
        encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, bytes);
        ctx.queue.submit([encoder.finish()]);
        read_back(device, &readback, bytes, PASS)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The terrain module (generated struct + shader) parses and validates with naga, and the
    /// generated struct's layout is the Rust one (every field a 16-byte vector, in order).
    #[test]
    fn terrain_wgsl_validates_and_its_struct_layout_matches_rust() {
        let module = naga::front::wgsl::parse_str(&terrain_source()).expect("terrain.wgsl parses");
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module);
        assert!(info.is_ok(), "{info:?}");
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some("TerrainParams"))
            .expect("TerrainParams declared");
        let naga::TypeInner::Struct { members, span } = &ty.inner else {
            panic!("TerrainParams is not a struct");
        };
        assert_eq!(*span as usize, std::mem::size_of::<GpuTerrainParams>());
        let names: Vec<&str> = members.iter().filter_map(|m| m.name.as_deref()).collect();
        let fields: Vec<&str> = gpu_layout::FIELDS.iter().map(|(n, _)| *n).collect();
        assert_eq!(names, fields);
        for (k, m) in members.iter().enumerate() {
            assert_eq!(m.offset as usize, 16 * k, "{:?}", m.name);
        }
    }
}
