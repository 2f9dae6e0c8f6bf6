//! Buffer and bind-group-layout building blocks shared by the passes.

use crate::GpuContext;
use bytemuck::Pod;
use wgpu::util::DeviceExt;

/// A compute-stage buffer binding of type `ty` at `binding`.
pub(crate) fn entry(binding: u32, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A storage buffer holding `data`, or the single element `fill` when `data` is empty (WebGPU
/// has no empty bindings).
pub(crate) fn storage<T: Pod>(ctx: &GpuContext, label: &str, data: &[T], fill: T) -> wgpu::Buffer {
    let data: Vec<T> = if data.is_empty() {
        vec![fill]
    } else {
        data.to_vec()
    };
    ctx.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::cast_slice(&data),
            usage: wgpu::BufferUsages::STORAGE,
        })
}
