//! The free-form pass: one compute dispatch per band of rows over the band's quadtree work items
//! (one workgroup per item) that casts, shades and writes each pixel of the items' tiles (colour +
//! depth, normal), then reads the band back. Owns its pipeline, scene and work-list buffers, and
//! the per-frame buffers and bind group, allocated once (a prepared pass has a fixed work list
//! and image size): a run writes the parameters, dispatches, copies and maps. Where the device
//! has timestamp queries, each band's compute pass is timed on the GPU.

use crate::bindings::{entry, storage};
use crate::counters::{self, Counter};
use crate::params::{self, FrameParams};
use crate::readback::{map_read, read_back, readback_buffer};
use crate::shader::{self, ArraySizes, Specialisation};
use crate::terrain_pass::{TerrainUpload, terrain_buffers};
use crate::timestamps::Timestamps;
use crate::work::{GpuWork, TILE};
use crate::{GpuContext, GpuError};
use fray_geometry::gpu_layout::GpuSolids;
use fray_quadtree::{QuadtreeStats, WorkItem};
use fray_scene::Scene;
use std::sync::Mutex;
use std::time::Duration;

const PASS: &str = "free-form";
/// Bytes written per pixel: two `vec4<f32>` (colour + depth, normal + hit flag).
const BYTES_PER_PIXEL: u64 = 32;
/// Words of the frame's counter buffer (the layout: [`crate::counters`]).
const COUNTERS: usize = counters::WORDS;
/// Storage buffers the pass binds (scene 6, output, counters, work list 5).
const STORAGE_BUFFERS: u32 = 13;
/// Upper bound of one band's output buffer (smaller bands keep readback memory modest).
const BAND_BYTES: u64 = 64 << 20;

/// What one run of the pass produced, in f32 as the GPU wrote it.
#[derive(Clone, Debug, Default)]
pub struct PassOutput {
    /// Per pixel (row-major): `[r, g, b, depth]`; for a miss the background and depth `< 0`,
    /// and all zeros where no work item covered the pixel (culled: a miss too).
    pub colour_depth: Vec<[f32; 4]>,
    /// Per pixel: `[nx, ny, nz, hit]` (`hit` is 1 for a hit, 0 otherwise).
    pub normal: Vec<[f32; 4]>,
    pub hits: u64,
    pub shadow_rays: u64,
    pub bound_evaluations: u64,
    pub point_evaluations: u64,
    /// The terrain's work on camera rays, counted as `fray_terrain::TerrainStats` counts it
    /// (zero without a terrain).
    pub terrain_rays: u64,
    pub terrain: fray_terrain::TerrainStats,
    /// GPU time of the compute passes (timestamps at the start and end of each band's pass,
    /// summed), when the device has timestamp queries; `None` without them. The rest of a run
    /// (uploads, clearing, copies, mapping, repacking) is host and transfer time.
    pub kernel_time: Option<Duration>,
}

/// The free-form pass for one scene: pipeline specialised for it, scene buffers uploaded.
#[derive(Debug)]
pub struct FreeFormPass {
    pipeline: wgpu::ComputePipeline,
    params: FrameParams,
    params_buffer: wgpu::Buffer,
    work: GpuWork,
    counters: wgpu::Buffer,
    specialisation: Specialisation,
    /// The per-frame buffers and the bind group (locked by a run: one run at a time uses
    /// them). The bind group keeps the scene buffers (bindings 1–6), the work list's
    /// (candidates, active leaves, active perturbations, candidate programs: 10–13) and the
    /// terrains' (parameter blocks, max pyramids, samples: 14–16) alive.
    frame: Mutex<FrameResources>,
}

/// What a run needs beyond the scene: allocated once per pass.
#[derive(Debug)]
struct FrameResources {
    /// `(first row, rows)` of each dispatch.
    bands: Vec<(u32, u32)>,
    /// The band's work items (binding 9), sized for the band with the most.
    items: wgpu::Buffer,
    /// The items were uploaded at construction (one band): a run does not write them.
    items_resident: bool,
    /// The band's pixels (binding 7) and their host-mappable copy.
    output: wgpu::Buffer,
    readback: wgpu::Buffer,
    counters_readback: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    timestamps: Option<Timestamps>,
}

impl FreeFormPass {
    /// Builds the specialised pipeline, uploads `scene` (positions relative to the eye) and its
    /// work list: the quadtree's when `culling`, else every tile with every object.
    pub fn new(
        ctx: &GpuContext,
        scene: &Scene,
        epsilon: f64,
        shadow_offset: f64,
        specialisation: Specialisation,
        culling: bool,
    ) -> Result<Self, GpuError> {
        let reference = params::reference_point(&scene.camera);
        let mut solids = GpuSolids::new(reference);
        let material_count = scene.materials.len() as u32;
        for object in &scene.objects {
            solids.push(&object.solid, |leaf| {
                object
                    .leaf_materials
                    .get(leaf)
                    .copied()
                    .filter(|&m| m < material_count)
                    .unwrap_or(material_count)
            });
        }
        let work = if culling {
            GpuWork::culled(scene, &solids).map_err(|e| GpuError::WorkList(e.to_string()))?
        } else {
            GpuWork::everything(scene, &solids)
        };
        let storage_limit = ctx.limits.max_storage_buffers_per_shader_stage;
        // The terrains add their parameter blocks, pyramids and samples.
        let needed = STORAGE_BUFFERS + if scene.terrains.is_empty() { 0 } else { 3 };
        if storage_limit < needed {
            return Err(GpuError::TooLarge {
                what: "storage buffers per shader stage",
                needed: u64::from(needed),
                limit: u64::from(storage_limit),
            });
        }
        let sizes = ArraySizes {
            max_leaves: solids.max_leaves,
            max_perturbations: solids.max_perturbations,
            max_stack: solids.max_stack,
        };
        let device = &ctx.device;
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let internal = device.push_error_scope(wgpu::ErrorFilter::Internal);
        // Every terrain's buffers (checked against the device limits first): camera rays cast
        // at each terrain's level of detail and shaded with its material, as on the CPU.
        let terrain = if scene.terrains.is_empty() {
            None
        } else {
            let uploads: Vec<TerrainUpload> = scene
                .terrains
                .iter()
                .map(|t| TerrainUpload {
                    terrain: &t.terrain,
                    material: t.material.min(material_count),
                    footprint: match t.lod {
                        fray_scene::TerrainLod::Pixel => scene
                            .camera
                            .pixel_footprint(scene.width, scene.height)
                            .coarser(t.terrain.options().lod_bias),
                        fray_scene::TerrainLod::Exact => fray_core::PixelFootprint::ZERO,
                    },
                })
                .collect();
            Some(terrain_buffers(ctx, &uploads, reference)?)
        };
        let source = shader::freeform_source(sizes, terrain.is_some());
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("freeform.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        use wgpu::BufferBindingType as B;
        let read = B::Storage { read_only: true };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("free-form"),
            entries: &[
                entry(0, B::Uniform),
                entry(1, read),
                entry(2, read),
                entry(3, read),
                entry(4, read),
                entry(5, read),
                entry(6, read),
                entry(7, B::Storage { read_only: false }),
                entry(8, B::Storage { read_only: false }),
                entry(9, read),
                entry(10, read),
                entry(11, read),
                entry(12, read),
                entry(13, read),
                entry(shader::FREEFORM_TERRAIN_BINDING, read),
                entry(shader::FREEFORM_TERRAIN_BINDING + 1, read),
                entry(shader::FREEFORM_TERRAIN_BINDING + 2, read),
            ][..if terrain.is_some() { 17 } else { 14 }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("free-form"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let constants = specialisation.constants();
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("free-form"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("main"),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &constants,
                zero_initialize_workgroup_memory: false,
            },
            cache: None,
        });
        let internal = pollster::block_on(internal.pop());
        let validation = pollster::block_on(validation.pop());
        if let Some(e) = validation.or(internal) {
            return Err(GpuError::Pipeline {
                pass: PASS,
                reason: e.to_string(),
            });
        }
        let params = params::frame_params(scene, epsilon, shadow_offset);
        let params_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame params"),
            size: std::mem::size_of::<FrameParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let scene_buffers = [
            storage(ctx, "solids", &solids.solids, Default::default()),
            storage(ctx, "leaves", &solids.leaves, Default::default()),
            storage(
                ctx,
                "perturbations",
                &solids.perturbations,
                Default::default(),
            ),
            storage(ctx, "program", &work.program, 0u32),
            storage(ctx, "lights", &params::lights(scene), Default::default()),
            storage(
                ctx,
                "materials",
                &params::materials(scene),
                Default::default(),
            ),
        ];
        let work_buffers = [
            storage(ctx, "candidates", &work.candidates, Default::default()),
            storage(ctx, "active leaves", &work.leaves, 0u32),
            storage(ctx, "active perturbations", &work.perturbations, 0u32),
            storage(ctx, "candidate programs", &work.programs, [0u32; 2]),
        ];
        let counters = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("counters"),
            size: (COUNTERS * 4) as u64,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let frame = FrameResources::new(
            ctx,
            &work,
            (params.size[0], params.size[1]),
            &layout,
            &bind_group_buffers(
                &params_buffer,
                &scene_buffers,
                &counters,
                &work_buffers,
                terrain.as_ref(),
            ),
        )?;
        Ok(Self {
            pipeline,
            params,
            params_buffer,
            work,
            counters,
            specialisation,
            frame: Mutex::new(frame),
        })
    }

    /// The specialisation this pass was built with.
    pub fn specialisation(&self) -> Specialisation {
        self.specialisation
    }

    /// The quadtree's counts when this pass culls (`None`: every tile is rendered).
    pub fn work_stats(&self) -> Option<QuadtreeStats> {
        self.work.stats
    }

    /// Rows per dispatch for an image `width` wide on this device: a multiple of the tile side
    /// (tiles are aligned to it, so every item lies in one band).
    fn band_rows(ctx: &GpuContext, width: u32, height: u32) -> u32 {
        let limit = ctx
            .limits
            .max_storage_buffer_binding_size
            .min(ctx.limits.max_buffer_size)
            .min(BAND_BYTES);
        let per_row = BYTES_PER_PIXEL * u64::from(width.max(1));
        let tile = u64::from(TILE);
        let rows = (limit / per_row / tile).max(1) * tile;
        rows.min(u64::from(height.max(1)).next_multiple_of(tile)) as u32
    }

    /// Renders every pixel and reads the results back.
    pub fn run(&self, ctx: &GpuContext) -> Result<PassOutput, GpuError> {
        let frame = match self.frame.lock() {
            Ok(f) => f,
            Err(poisoned) => poisoned.into_inner(),
        };
        let width = self.params.size[0];
        let device = &ctx.device;
        ctx.queue
            .write_buffer(&self.counters, 0, &[0u8; COUNTERS * 4]);
        let pixels = (u64::from(width) * u64::from(self.params.size[1])) as usize;
        let mut out = PassOutput {
            colour_depth: Vec::with_capacity(pixels),
            normal: Vec::with_capacity(pixels),
            kernel_time: frame.timestamps.as_ref().map(|_| Duration::ZERO),
            ..PassOutput::default()
        };
        let max_groups = ctx.limits.max_compute_workgroups_per_dimension.max(1);
        for (i, &(y0, rows)) in frame.bands.iter().enumerate() {
            let band_items = self.work.band(y0, y0 + rows);
            let n = band_items.len() as u32;
            let bytes = u64::from(rows) * u64::from(width) * BYTES_PER_PIXEL;
            let last = i + 1 == frame.bands.len();
            if n == 0 && !last {
                // Every tile of the band was culled: nothing to run, nothing hit.
                let pixels = (u64::from(rows) * u64::from(width)) as usize;
                out.colour_depth
                    .extend(std::iter::repeat_n([0.0; 4], pixels));
                out.normal.extend(std::iter::repeat_n([0.0; 4], pixels));
                continue;
            }
            let mut params = self.params;
            params.size[2] = y0;
            params.mode[2] = rows;
            params.mode[3] = n;
            ctx.queue
                .write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
            if n > 0 && !frame.items_resident {
                ctx.queue
                    .write_buffer(&frame.items, 0, bytemuck::cast_slice(band_items));
            }
            let mut encoder =
                device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
            // Pixels no item covers stay zero (a miss).
            encoder.clear_buffer(&frame.output, 0, Some(bytes));
            let timed = frame.timestamps.as_ref().filter(|_| n > 0);
            if n > 0 {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("free-form"),
                    timestamp_writes: timed.map(Timestamps::writes),
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &frame.bind_group, &[]);
                let x = n.min(max_groups);
                pass.dispatch_workgroups(x, n.div_ceil(x), 1);
            }
            if let Some(t) = timed {
                t.resolve(&mut encoder);
            }
            encoder.copy_buffer_to_buffer(&frame.output, 0, &frame.readback, 0, bytes);
            if last {
                encoder.copy_buffer_to_buffer(
                    &self.counters,
                    0,
                    &frame.counters_readback,
                    0,
                    (COUNTERS * 4) as u64,
                );
            }
            ctx.queue.submit([encoder.finish()]);
            map_read(device, &frame.readback, bytes, PASS, |data| {
                unpack(data, &mut out.colour_depth, &mut out.normal)
            })?;
            if let (Some(t), Some(total)) = (timed, out.kernel_time.as_mut()) {
                *total += t.read(device)?;
            }
            if last {
                let c: Vec<u32> = read_back(
                    device,
                    &frame.counters_readback,
                    (COUNTERS * 4) as u64,
                    PASS,
                )?;
                out.hits = Counter::Hits.read(&c);
                out.shadow_rays = Counter::ShadowRays.read(&c);
                out.bound_evaluations = Counter::BoundEvaluations.read(&c);
                out.point_evaluations = Counter::PointEvaluations.read(&c);
                out.terrain_rays = Counter::TerrainRays.read(&c);
                out.terrain = fray_terrain::TerrainStats {
                    segments: Counter::TerrainSegments.read(&c),
                    cells: Counter::TerrainCells.read(&c),
                    stops: Counter::TerrainStops.read(&c),
                    stop_levels_above_finest: Counter::TerrainStopLevels.read(&c),
                };
            }
        }
        Ok(out)
    }
}

/// Appends the band's pixels, read in place from the mapped `data` (pairs of `vec4<f32>`:
/// colour + depth, normal + hit), to `colour_depth` and `normal` in one pass.
fn unpack(data: &[u8], colour_depth: &mut Vec<[f32; 4]>, normal: &mut Vec<[f32; 4]>) {
    type Pixel = [[f32; 4]; 2];
    let copied: Vec<Pixel>;
    let pixels: &[Pixel] = match bytemuck::try_cast_slice(data) {
        Ok(p) => p,
        // A mapping is at least 8-byte aligned, in practice page aligned; copy if it is not
        // aligned for f32.
        Err(_) => {
            copied = bytemuck::pod_collect_to_vec(data);
            &copied
        }
    };
    let mut both = (std::mem::take(colour_depth), std::mem::take(normal));
    both.extend(pixels.iter().map(|&[c, n]| (c, n)));
    (*colour_depth, *normal) = both;
}

/// The bind group's buffers except the per-frame ones (output, work items): bindings 0–6, 8,
/// 10–13 and, with terrains, 14–16.
fn bind_group_buffers<'a>(
    params: &'a wgpu::Buffer,
    scene: &'a [wgpu::Buffer; 6],
    counters: &'a wgpu::Buffer,
    work: &'a [wgpu::Buffer; 4],
    terrain: Option<&'a [wgpu::Buffer; 3]>,
) -> Vec<(u32, &'a wgpu::Buffer)> {
    let mut buffers = vec![(0, params)];
    buffers.extend((1..).zip(scene));
    buffers.push((8, counters));
    buffers.extend((10..).zip(work));
    buffers.extend((shader::FREEFORM_TERRAIN_BINDING..).zip(terrain.into_iter().flatten()));
    buffers
}

impl FrameResources {
    /// The bands of a `width × height` image on this device, the buffers for the largest, and
    /// the bind group of `fixed` (binding, buffer) pairs plus the output (7) and items (9).
    fn new(
        ctx: &GpuContext,
        work: &GpuWork,
        (width, height): (u32, u32),
        layout: &wgpu::BindGroupLayout,
        fixed: &[(u32, &wgpu::Buffer)],
    ) -> Result<Self, GpuError> {
        let tile_rows_bytes = u64::from(width) * BYTES_PER_PIXEL * u64::from(TILE);
        let buffer_limit = ctx
            .limits
            .max_storage_buffer_binding_size
            .min(ctx.limits.max_buffer_size);
        if tile_rows_bytes > buffer_limit {
            return Err(GpuError::TooLarge {
                what: "bytes per row of tiles",
                needed: tile_rows_bytes,
                limit: buffer_limit,
            });
        }
        let device = &ctx.device;
        let band = FreeFormPass::band_rows(ctx, width, height);
        let bands: Vec<(u32, u32)> = (0..height)
            .step_by(band as usize)
            .map(|y0| (y0, band.min(height - y0)))
            .collect();
        let most_items = bands
            .iter()
            .map(|&(y0, rows)| work.band(y0, y0 + rows).len())
            .max()
            .unwrap_or(0)
            .max(1);
        let items = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("work items"),
            size: (most_items * std::mem::size_of::<WorkItem>()) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // One band: its items never change, upload them now.
        let items_resident = match bands.as_slice() {
            [(y0, rows)] => {
                let band_items = work.band(*y0, y0 + rows);
                if !band_items.is_empty() {
                    ctx.queue
                        .write_buffer(&items, 0, bytemuck::cast_slice(band_items));
                }
                true
            }
            _ => false,
        };
        let band_bytes = u64::from(band) * u64::from(width) * BYTES_PER_PIXEL;
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("free-form output"),
            size: band_bytes,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let readback = readback_buffer(device, "free-form readback", band_bytes);
        let counters_readback = readback_buffer(device, "counters readback", (COUNTERS * 4) as u64);
        let mut entries: Vec<wgpu::BindGroupEntry> = fixed
            .iter()
            .chain([(7, &output), (9, &items)].iter())
            .map(|&(binding, buffer)| wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            })
            .collect();
        entries.sort_by_key(|e| e.binding);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("free-form"),
            layout,
            entries: &entries,
        });
        Ok(Self {
            bands,
            items,
            items_resident,
            output,
            readback,
            counters_readback,
            bind_group,
            timestamps: Timestamps::new(ctx),
        })
    }
}
