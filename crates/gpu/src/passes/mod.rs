//! The GPU frame in passes, each a value ([`band::Pass`]): rebase (the resident scene moved to
//! the camera) → ray generation → intersection per primitive kind (free forms, terrains,
//! meshes), each narrowing the rays' nearest hits → surfaces and shading (shadow rays any-hit
//! per kind) → Whitted's levels (with reflecting or transmitting materials) → media (fog, the sky,
//! clouds, only with them) → resolve into the frame's storage textures. A pass that is one
//! kernel is a [`band::PassSpec`] (label, entry module, the roles of the groups it binds,
//! workload) in its own file (a kind's intersection pass in `crate::kinds`); [`frame::frame_passes`]
//! builds the list a scene's features call for, once
//! per resident scene. The frame's shared buffers (paths, counters, parameters) and bind groups
//! belong to `crate::render::GpuScene`; pipelines come from the renderer's cache.

pub mod band;
pub mod frame;
pub mod media;
pub mod raygen;
pub mod rebase;
pub mod resolve;
pub mod shade;
pub mod spec;
pub mod whitted;

use crate::bindings::Group;
use crate::shader::{self, ModuleOptions, Specialisation};
use crate::{GpuContext, GpuError};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// What makes two pipelines the same: the entry module, what it was composed with and its
/// specialisation.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct PipelineKey {
    entry: &'static str,
    options: ModuleOptions,
    specialisation: Specialisation,
}

/// The renderer's pipelines, built once per key and reused by every scene and frame that needs
/// the same one, and the bind-group layouts (one per group, device-wide).
#[derive(Debug, Default)]
pub struct PipelineCache {
    pipelines: Mutex<HashMap<PipelineKey, Arc<wgpu::ComputePipeline>>>,
    layouts: Mutex<HashMap<&'static str, Arc<wgpu::BindGroupLayout>>>,
    built: Mutex<(u32, Duration)>,
}

impl PipelineCache {
    /// The layout of `group` on this device.
    pub fn layout(&self, ctx: &GpuContext, group: &Group) -> Arc<wgpu::BindGroupLayout> {
        let mut layouts = lock(&self.layouts);
        layouts
            .entry(group.name)
            .or_insert_with(|| Arc::new(group.layout(&ctx.device)))
            .clone()
    }

    /// The pipeline of entry module `entry` with bind groups `groups` (group `k` the `k`-th, as
    /// the module's `#bindings` line names them), composed with `options` and specialised by
    /// `specialisation`: from the cache, or built (and counted).
    pub fn pipeline(
        &self,
        ctx: &GpuContext,
        entry: &'static str,
        groups: &[Group],
        options: &ModuleOptions,
        specialisation: &Specialisation,
    ) -> Result<Arc<wgpu::ComputePipeline>, GpuError> {
        let key = PipelineKey {
            entry,
            options: *options,
            specialisation: *specialisation,
        };
        if let Some(p) = lock(&self.pipelines).get(&key) {
            return Ok(p.clone());
        }
        let start = Instant::now();
        let source = shader::compose(entry, options).map_err(|e| GpuError::Pipeline {
            pass: entry,
            reason: e.to_string(),
        })?;
        let device = &ctx.device;
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let internal = device.push_error_scope(wgpu::ErrorFilter::Internal);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(entry),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let module_groups =
            shader::module_groups(entry, options).map_err(|e| GpuError::Pipeline {
                pass: entry,
                reason: e.to_string(),
            })?;
        if module_groups.as_slice() != groups {
            return Err(GpuError::Pipeline {
                pass: entry,
                reason: format!(
                    "the module binds {:?}, its pass {:?}",
                    module_groups.iter().map(|g| g.name).collect::<Vec<_>>(),
                    groups.iter().map(|g| g.name).collect::<Vec<_>>()
                ),
            });
        }
        let owned: Vec<Arc<wgpu::BindGroupLayout>> =
            groups.iter().map(|g| self.layout(ctx, g)).collect();
        let layouts: Vec<Option<&wgpu::BindGroupLayout>> =
            owned.iter().map(|l| Some(l.as_ref())).collect();
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(entry),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        });
        let constants = specialisation.constants(entry);
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
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
                pass: entry,
                reason: e.to_string(),
            });
        }
        let pipeline = Arc::new(pipeline);
        lock(&self.pipelines).insert(key, pipeline.clone());
        let mut built = lock(&self.built);
        built.0 += 1;
        built.1 += start.elapsed();
        Ok(pipeline)
    }

    /// Pipelines built and the time it took, since the last call.
    pub fn take_built(&self) -> (u32, Duration) {
        std::mem::take(&mut *lock(&self.built))
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    match m.lock() {
        Ok(g) => g,
        Err(poisoned) => poisoned.into_inner(),
    }
}

/// What every pass is built from: the renderer's cache and device, the scene's composition
/// options and its specialisation (the same for all passes of one scene).
#[derive(Clone, Copy, Debug)]
pub struct PassSetup<'a> {
    pub cache: &'a PipelineCache,
    pub ctx: &'a GpuContext,
    pub options: &'a ModuleOptions,
    pub specialisation: &'a Specialisation,
}

/// A pass's compute pipeline and the bind groups it takes (in its module's order): what every
/// pass struct holds, so that each pass is only its module, its groups and its dispatch size.
#[derive(Clone, Debug)]
pub(crate) struct Kernel {
    pipeline: Arc<wgpu::ComputePipeline>,
}

impl Kernel {
    /// The pipeline of `entry` binding `groups` (from the cache, or built).
    pub(crate) fn new(
        setup: &PassSetup<'_>,
        entry: &'static str,
        groups: &[Group],
    ) -> Result<Self, GpuError> {
        let PassSetup {
            cache,
            ctx,
            options,
            specialisation,
        } = *setup;
        Ok(Self {
            pipeline: cache.pipeline(ctx, entry, groups, options, specialisation)?,
        })
    }

    /// Binds `groups` (group `k` the `k`-th) and dispatches `workgroups` workgroups.
    pub(crate) fn run(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        ctx: &GpuContext,
        groups: &[&wgpu::BindGroup],
        workgroups: u32,
    ) {
        pass.set_pipeline(&self.pipeline);
        for (k, g) in groups.iter().enumerate() {
            pass.set_bind_group(k as u32, *g, &[]);
        }
        dispatch(pass, ctx, workgroups);
    }

    /// Binds `groups` and dispatches the workgroups `args` (x, y, z at offset 0) says — written
    /// on the GPU by an earlier pass.
    pub(crate) fn run_indirect(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        groups: &[&wgpu::BindGroup],
        args: &wgpu::Buffer,
    ) {
        pass.set_pipeline(&self.pipeline);
        for (k, g) in groups.iter().enumerate() {
            pass.set_bind_group(k as u32, *g, &[]);
        }
        pass.dispatch_workgroups_indirect(args, 0);
    }

    /// Binds `groups` and dispatches a 2D grid of `x × y` workgroups.
    pub(crate) fn run_2d(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        groups: &[&wgpu::BindGroup],
        x: u32,
        y: u32,
    ) {
        pass.set_pipeline(&self.pipeline);
        for (k, g) in groups.iter().enumerate() {
            pass.set_bind_group(k as u32, *g, &[]);
        }
        pass.dispatch_workgroups(x, y, 1);
    }
}

/// Dispatches `groups` workgroups as a 2D grid when there are more than one dimension holds
/// (the shaders fold `group.y * groups.x + group.x` or `id.y * groups.x * 64 + id.x` back).
pub(crate) fn dispatch(pass: &mut wgpu::ComputePass<'_>, ctx: &GpuContext, groups: u32) {
    if groups == 0 {
        return;
    }
    let max = ctx.limits.max_compute_workgroups_per_dimension.max(1);
    let x = groups.min(max);
    pass.dispatch_workgroups(x, groups.div_ceil(x), 1);
}
