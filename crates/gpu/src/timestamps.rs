//! GPU time pass by pass: each pass of a band is its own compute pass, timed by a timestamp at its
//! start and its end (resolved and read back after the band, converted with the queue's period)
//! or, on a software adapter, by the host's clock around the pass submitted alone; the times are
//! summed per pass label over the frame, and the host's waits for them kept apart (so that the
//! frame's encode time can leave them out).

use crate::GpuContext;
use crate::GpuError;
use crate::readback::{read_back, readback_buffer};
use std::time::Duration;

/// The pass name in errors.
const PASS: &str = "timestamps";

/// The most passes one submission can time (a band has at most raygen, three kinds, shade,
/// Whitted, media and resolve: 8).
pub(crate) const MAX_TIMED_PASSES: u32 = 16;

const QUERIES: u32 = 2 * MAX_TIMED_PASSES;
const TIMESTAMP_BYTES: u64 = QUERIES as u64 * wgpu::QUERY_SIZE as u64;

/// Timestamp pairs around up to [`MAX_TIMED_PASSES`] compute passes of one submission.
#[derive(Debug)]
pub(crate) struct Timestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    period_ns: f64,
}

impl Timestamps {
    /// `None` on a device without timestamp queries.
    pub(crate) fn new(ctx: &GpuContext) -> Option<Self> {
        let period_ns = ctx.timestamp_period_ns?;
        let device = &ctx.device;
        Some(Self {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: QUERIES,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass timestamps resolve"),
                size: TIMESTAMP_BYTES,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: readback_buffer(device, "pass timestamps readback", TIMESTAMP_BYTES),
            period_ns,
        })
    }

    /// The timestamp writes of the `slot`-th timed pass (start → 2·slot, end → 2·slot + 1).
    fn writes(&self, slot: u32) -> wgpu::ComputePassTimestampWrites<'_> {
        wgpu::ComputePassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: Some(2 * slot),
            end_of_pass_write_index: Some(2 * slot + 1),
        }
    }

    /// Resolves the first `passes` pairs and copies them to the readback buffer.
    fn resolve(&self, encoder: &mut wgpu::CommandEncoder, passes: u32) {
        let bytes = u64::from(2 * passes) * wgpu::QUERY_SIZE as u64;
        encoder.resolve_query_set(&self.set, 0..2 * passes, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, bytes);
    }

    /// The times of the first `passes` passes of the last submission, in order.
    fn read(&self, device: &wgpu::Device, passes: u32) -> Result<Vec<Duration>, GpuError> {
        let bytes = u64::from(2 * passes) * wgpu::QUERY_SIZE as u64;
        let t: Vec<u64> = read_back(device, &self.readback, bytes, PASS)?;
        Ok(t.chunks_exact(2)
            .map(|pair| {
                let ticks = pair[1].saturating_sub(pair[0]);
                Duration::from_secs_f64(ticks as f64 * self.period_ns * 1e-9)
            })
            .collect())
    }
}

/// How a [`TimedEncoder`]'s passes are timed.
#[derive(Clone, Copy, Debug)]
pub(crate) enum PassClock<'t> {
    /// Timestamp pairs written by the device around each pass (one submission).
    Device(&'t Timestamps),
    /// The host's clock around each pass submitted alone and waited for: a software adapter's
    /// passes run on the host, and its timestamps are not taken when they run (on lavapipe
    /// every pass but the last of a submission read 0).
    Host,
    /// Not timed (no timestamp queries on this device).
    Off,
}

impl<'t> PassClock<'t> {
    /// The clock for `ctx`, whose timestamp queries (if any) are `timestamps`.
    pub(crate) fn of(ctx: &GpuContext, timestamps: Option<&'t Timestamps>) -> Self {
        match timestamps {
            _ if ctx.software => PassClock::Host,
            Some(t) => PassClock::Device(t),
            None => PassClock::Off,
        }
    }

    /// Whether passes are timed at all.
    pub(crate) fn times(self) -> bool {
        !matches!(self, PassClock::Off)
    }
}

/// One submission's passes, begun by label and timed by a [`PassClock`]; under the host clock
/// each pass is submitted on its own when the next begins.
#[derive(Debug)]
pub(crate) struct TimedEncoder<'t> {
    ctx: &'t GpuContext,
    encoder: wgpu::CommandEncoder,
    clock: PassClock<'t>,
    /// The passes timed on the device, in order.
    labels: Vec<&'static str>,
    /// Under the host clock: the pass being encoded.
    host_pass: Option<&'static str>,
    times: PassTimes,
}

impl<'t> TimedEncoder<'t> {
    pub(crate) fn new(ctx: &'t GpuContext, clock: PassClock<'t>) -> Self {
        Self {
            ctx,
            encoder: Self::encoder_of(ctx),
            clock,
            labels: Vec::new(),
            host_pass: None,
            times: PassTimes::default(),
        }
    }

    fn encoder_of(ctx: &GpuContext) -> wgpu::CommandEncoder {
        ctx.device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("passes"),
            })
    }

    /// Begins the compute pass `label` (passes beyond [`MAX_TIMED_PASSES`] of a submission run
    /// untimed under the device clock).
    pub(crate) fn pass(&mut self, label: &'static str) -> Result<wgpu::ComputePass<'_>, GpuError> {
        let mut writes = None;
        match self.clock {
            PassClock::Device(t) => {
                let slot = self.labels.len() as u32;
                if slot < MAX_TIMED_PASSES {
                    writes = Some(t.writes(slot));
                    self.labels.push(label);
                }
            }
            PassClock::Host => {
                self.finish_host_pass()?;
                self.host_pass = Some(label);
            }
            PassClock::Off => {}
        }
        Ok(self
            .encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(label),
                timestamp_writes: writes,
            }))
    }

    /// Under the host clock: submits the pass encoded since the last, waits for it and adds
    /// the time to its label.
    fn finish_host_pass(&mut self) -> Result<(), GpuError> {
        if let Some(label) = self.host_pass.take() {
            let start = std::time::Instant::now();
            let encoder = std::mem::replace(&mut self.encoder, Self::encoder_of(self.ctx));
            self.ctx.queue.submit([encoder.finish()]);
            self.ctx
                .device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| GpuError::DeviceLost(e.to_string()))?;
            // The pass's time, its submission included, counts as waiting: the host's own
            // part of the frame leaves out what the pass times hold.
            let elapsed = start.elapsed();
            self.times.waited += elapsed;
            self.times.add(label, elapsed);
        }
        Ok(())
    }

    /// The encoder, for copies between passes.
    pub(crate) fn encoder(&mut self) -> &mut wgpu::CommandEncoder {
        &mut self.encoder
    }

    /// Submits what is left, waits for the timings and adds each pass's time to `times`.
    pub(crate) fn submit(mut self, times: &mut PassTimes) -> Result<(), GpuError> {
        let timed = self.labels.len() as u32;
        match self.clock {
            PassClock::Device(t) if timed > 0 => {
                t.resolve(&mut self.encoder, timed);
                self.ctx.queue.submit([self.encoder.finish()]);
                let wait = std::time::Instant::now();
                let read = t.read(&self.ctx.device, timed)?;
                times.waited += wait.elapsed();
                for (label, d) in self.labels.iter().zip(read) {
                    times.add(label, d);
                }
            }
            PassClock::Host => {
                self.finish_host_pass()?;
                self.ctx.queue.submit([self.encoder.finish()]);
            }
            _ => {
                self.ctx.queue.submit([self.encoder.finish()]);
            }
        }
        for (label, d) in self.times.passes {
            times.add(label, d);
        }
        times.waited += self.times.waited;
        Ok(())
    }
}

/// GPU time per pass label over a frame, in the order the passes first ran, and the host's time
/// spent waiting for those times.
#[derive(Debug, Default)]
pub(crate) struct PassTimes {
    passes: Vec<(&'static str, Duration)>,
    /// The host blocked on the device: reading timestamps back, or (host clock) each pass
    /// submitted alone and waited for — its submission too, which its time holds.
    waited: Duration,
}

impl PassTimes {
    fn add(&mut self, label: &'static str, d: Duration) {
        match self.passes.iter_mut().find(|(l, _)| *l == label) {
            Some((_, total)) => *total += d,
            None => self.passes.push((label, d)),
        }
    }

    /// The frame's GPU time over all passes.
    pub(crate) fn total(&self) -> Duration {
        self.passes.iter().map(|(_, d)| *d).sum()
    }

    /// How long the host waited for the device while timing the passes.
    pub(crate) fn waited(&self) -> Duration {
        self.waited
    }

    /// The table, for `RenderStats::pass_times`.
    pub(crate) fn into_stats(self) -> Vec<(String, Duration)> {
        self.passes
            .into_iter()
            .map(|(l, d)| (l.to_owned(), d))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_add_up_by_label_in_first_seen_order() {
        let mut t = PassTimes::default();
        let ms = Duration::from_millis;
        t.add("raygen", ms(1));
        t.add("shade", ms(5));
        t.add("raygen", ms(2));
        assert_eq!(
            t.into_stats(),
            vec![("raygen".to_owned(), ms(3)), ("shade".to_owned(), ms(5))]
        );
    }
}
