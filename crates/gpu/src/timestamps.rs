//! GPU time of a band's compute pass (all its dispatches) from timestamp queries: two timestamps (start and end of the
//! pass), resolved and read back after it, converted with the queue's timestamp period.

use crate::GpuContext;
use crate::GpuError;
use crate::readback::{read_back, readback_buffer};
use std::time::Duration;

/// The pass name in errors.
const PASS: &str = "timestamps";

/// Two timestamps (start and end of a band's compute pass), resolved and read back per band.
#[derive(Debug)]
pub(crate) struct Timestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    period_ns: f64,
}

const TIMESTAMP_BYTES: u64 = 2 * wgpu::QUERY_SIZE as u64;

impl Timestamps {
    pub(crate) fn new(ctx: &GpuContext) -> Option<Self> {
        let period_ns = ctx.timestamp_period_ns?;
        let device = &ctx.device;
        Some(Self {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("band timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("band timestamps resolve"),
                size: TIMESTAMP_BYTES,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: readback_buffer(device, "band timestamps readback", TIMESTAMP_BYTES),
            period_ns,
        })
    }

    /// The pass's timestamp writes (start → 0, end → 1).
    pub(crate) fn writes(&self) -> wgpu::ComputePassTimestampWrites<'_> {
        wgpu::ComputePassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        }
    }

    /// Resolves both timestamps and copies them to the readback buffer.
    pub(crate) fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.set, 0..2, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, TIMESTAMP_BYTES);
    }

    /// The time between the two timestamps of the last submitted pass.
    pub(crate) fn read(&self, device: &wgpu::Device) -> Result<Duration, GpuError> {
        let t: Vec<u64> = read_back(device, &self.readback, TIMESTAMP_BYTES, PASS)?;
        let ticks = t[1].saturating_sub(t[0]);
        Ok(Duration::from_secs_f64(
            ticks as f64 * self.period_ns * 1e-9,
        ))
    }
}
