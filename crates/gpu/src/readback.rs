//! Reading a GPU buffer back to the host: map, wait, read in place (or copy out), unmap — with
//! every failure a [`GpuError`] naming the pass.

use crate::GpuError;
use bytemuck::Pod;

/// A host-readable buffer of `size` bytes that copies land in (`MAP_READ | COPY_DST`).
pub(crate) fn readback_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Maps `buffer[..bytes]`, waits, hands the mapped bytes to `read` and unmaps (also when `read`
/// cannot get the view). A failed poll is a lost device; a failed map is an error of `pass`.
pub(crate) fn map_read<R>(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
    bytes: u64,
    pass: &'static str,
    read: impl FnOnce(&[u8]) -> R,
) -> Result<R, GpuError> {
    let slice = buffer.slice(..bytes);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::DeviceLost(e.to_string()))?;
    match rx.recv() {
        Ok(Ok(())) => {}
        Ok(Err(e)) => {
            return Err(GpuError::Dispatch {
                pass,
                reason: e.to_string(),
            });
        }
        Err(_) => return Err(GpuError::DeviceLost("readback never completed".into())),
    }
    let result = match slice.get_mapped_range() {
        Ok(view) => Ok(read(&view)),
        Err(e) => Err(GpuError::Dispatch {
            pass,
            reason: e.to_string(),
        }),
    };
    buffer.unmap();
    result
}

/// Maps `buffer[..bytes]`, waits, copies it out as `T`s and unmaps (see [`map_read`]).
pub(crate) fn read_back<T: Pod>(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
    bytes: u64,
    pass: &'static str,
) -> Result<Vec<T>, GpuError> {
    map_read(
        device,
        buffer,
        bytes,
        pass,
        bytemuck::pod_collect_to_vec::<u8, T>,
    )
}

/// A batch pass's buffers: `inputs` uploaded as a storage buffer, and a storage buffer of
/// `result_bytes` for the kernel to write and [`run_batch`] to copy back — each checked against
/// the device's limits first under its name (`names`: inputs, results), which labels it too.
pub(crate) fn batch_buffers<T: Pod>(
    ctx: &crate::context::GpuContext,
    (inputs_name, results_name): (&'static str, &'static str),
    inputs: &[T],
    result_bytes: u64,
) -> Result<(wgpu::Buffer, wgpu::Buffer), GpuError> {
    use wgpu::util::DeviceExt;
    let input_bytes = std::mem::size_of_val(inputs) as u64;
    for (what, size) in [(inputs_name, input_bytes), (results_name, result_bytes)] {
        crate::bindings::check_buffer(ctx, what, size, wgpu::BufferUsages::STORAGE)?;
    }
    let input = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(inputs_name),
            contents: bytemuck::cast_slice(inputs),
            usage: wgpu::BufferUsages::STORAGE,
        });
    let output = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(results_name),
        size: result_bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    Ok((input, output))
}

/// Runs a batch test pass: `pipeline` over `items` invocations in workgroups of `workgroup`
/// (spread over two dimensions past the device's per-dimension limit) with `groups` bound in
/// order, then copies `output[..bytes]` to a fresh readback buffer and reads it back as `T`s.
/// The batch passes (terrain, fog, sky) differ only in what they bind and how they decode.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_batch<T: Pod>(
    ctx: &crate::context::GpuContext,
    pipeline: &wgpu::ComputePipeline,
    groups: &[&wgpu::BindGroup],
    items: u32,
    workgroup: u32,
    output: &wgpu::Buffer,
    bytes: u64,
    pass: &'static str,
) -> Result<Vec<T>, GpuError> {
    let device = &ctx.device;
    let readback = readback_buffer(device, pass, bytes);
    let workgroups = items.div_ceil(workgroup);
    let x = workgroups.min(ctx.limits.max_compute_workgroups_per_dimension.max(1));
    let mut encoder =
        device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
    {
        let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(pass),
            timestamp_writes: None,
        });
        compute.set_pipeline(pipeline);
        for (index, group) in groups.iter().enumerate() {
            compute.set_bind_group(index as u32, *group, &[]);
        }
        compute.dispatch_workgroups(x, workgroups.div_ceil(x), 1);
    }
    encoder.copy_buffer_to_buffer(output, 0, &readback, 0, bytes);
    ctx.queue.submit([encoder.finish()]);
    read_back(device, &readback, bytes, pass)
}
