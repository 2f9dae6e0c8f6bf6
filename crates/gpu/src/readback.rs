//! Reading a GPU buffer back to the host: map, wait, copy out, unmap — with every failure a
//! [`GpuError`] naming the pass.

use crate::GpuError;
use bytemuck::Pod;

/// Maps `buffer[..bytes]`, waits, copies it out as `T`s and unmaps. A failed poll is a lost
/// device; a failed map is an error of `pass`.
pub(crate) fn read_back<T: Pod>(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
    bytes: u64,
    pass: &'static str,
) -> Result<Vec<T>, GpuError> {
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
    let data = {
        let view = slice.get_mapped_range().map_err(|e| GpuError::Dispatch {
            pass,
            reason: e.to_string(),
        })?;
        bytemuck::pod_collect_to_vec::<u8, T>(&view)
    };
    buffer.unmap();
    Ok(data)
}
