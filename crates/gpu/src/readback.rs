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
