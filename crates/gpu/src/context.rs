//! Adapter and device setup on any wgpu backend (`WGPU_BACKEND` is honoured).

use crate::GpuError;
use std::sync::{Arc, Mutex, OnceLock};

/// An open device and its queue, with the adapter's name.
#[derive(Debug)]
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// The adapter's name, e.g. `"llvmpipe (LLVM 15.0.6, 256 bits)"`.
    pub adapter_name: String,
    /// The wgpu backend in use, e.g. `"Vulkan"`.
    pub backend: String,
    pub limits: wgpu::Limits,
    /// Nanoseconds per timestamp tick when the device was opened with
    /// [`wgpu::Features::TIMESTAMP_QUERY`] (requested only where the adapter offers it); `None`
    /// without it, and passes then report no kernel time.
    pub timestamp_period_ns: Option<f64>,
    /// A software adapter running on the host's CPU (wgpu `DeviceType::Cpu`, e.g. Mesa lavapipe):
    /// its timestamps are not taken when its dispatches run, so passes are timed by the host's
    /// clock instead (`crate::timestamps`).
    pub software: bool,
    /// The first GPU error no error scope caught, or a device loss, since it was last taken:
    /// wgpu's default handler would panic on it; fray turns it into a [`GpuError`] instead.
    uncaptured: Arc<Mutex<Option<String>>>,
}

fn instance() -> wgpu::Instance {
    wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
}

async fn adapter(instance: &wgpu::Instance) -> Result<wgpu::Adapter, GpuError> {
    instance
        .request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        })
        .await
        .map_err(|e| GpuError::NoAdapter(e.to_string()))
}

impl GpuContext {
    /// Writes `texels` over the whole of `texture`, `extent` = `[width, height, depth]` texels
    /// (x fastest, then y, then z; one texel a `T`); returns the bytes uploaded.
    pub(crate) fn write_texels<T: bytemuck::Pod>(
        &self,
        texture: &wgpu::Texture,
        [width, height, depth]: [u32; 3],
        texels: &[T],
    ) -> u64 {
        self.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(texels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(width * std::mem::size_of::<T>() as u32),
                rows_per_image: Some(height),
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: depth,
            },
        );
        std::mem::size_of_val(texels) as u64
    }

    /// Opens the first suitable adapter's device (blocking).
    pub fn new() -> Result<Self, GpuError> {
        pollster::block_on(Self::new_async())
    }

    async fn new_async() -> Result<Self, GpuError> {
        let instance = instance();
        let adapter = adapter(&instance).await?;
        Self::open_async(&adapter).await
    }

    /// Opens `adapter`'s device as [`GpuContext::new`] does (blocking): for a caller that chose
    /// the adapter itself, e.g. one compatible with a window's surface (fray-view).
    pub fn from_adapter(adapter: &wgpu::Adapter) -> Result<Self, GpuError> {
        pollster::block_on(Self::open_async(adapter))
    }

    async fn open_async(adapter: &wgpu::Adapter) -> Result<Self, GpuError> {
        let info = adapter.get_info();
        let limits = adapter.limits();
        // Timestamps around the passes' dispatches (their GPU time), where the adapter has them.
        let features = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("fray"),
                required_features: features,
                required_limits: limits.clone(),
                ..Default::default()
            })
            .await
            .map_err(|e| GpuError::Device(e.to_string()))?;
        let uncaptured = Arc::new(Mutex::new(None));
        let sink = Arc::clone(&uncaptured);
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| record(&sink, e.to_string())));
        let sink = Arc::clone(&uncaptured);
        device.set_device_lost_callback(move |reason, message| {
            record(&sink, format!("device lost ({reason:?}): {message}"))
        });
        let period = f64::from(queue.get_timestamp_period());
        let timestamp_period_ns = (features.contains(wgpu::Features::TIMESTAMP_QUERY)
            && period.is_finite()
            && period > 0.0)
            .then_some(period);
        Ok(Self {
            device,
            queue,
            adapter_name: info.name,
            backend: format!("{:?}", info.backend),
            limits,
            timestamp_period_ns,
            software: info.device_type == wgpu::DeviceType::Cpu,
            uncaptured,
        })
    }

    /// Takes the first error since the last call that no error scope caught (a validation or
    /// out-of-memory error in a dispatch, a lost device), if any. Passes call this after their
    /// readback and fail with it, so the facade can fall back to the CPU.
    pub fn take_uncaptured_error(&self) -> Option<String> {
        match self.uncaptured.lock() {
            Ok(mut slot) => slot.take(),
            Err(poisoned) => poisoned.into_inner().take(),
        }
    }
}

/// Keeps the first error (later ones are usually its consequences).
fn record(slot: &Mutex<Option<String>>, message: String) {
    let mut slot = match slot.lock() {
        Ok(slot) => slot,
        Err(poisoned) => poisoned.into_inner(),
    };
    slot.get_or_insert(message);
}

/// What [`probe_adapter`] found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AdapterProbe {
    /// The adapter's name, e.g. `"llvmpipe (LLVM 15.0.6, 256 bits)"`.
    pub name: String,
    /// A software rasteriser running on the CPU (wgpu `DeviceType::Cpu`, e.g. Mesa lavapipe):
    /// correct, but slower than the CPU backend, so automatic backend choice skips it.
    pub software: bool,
}

/// The adapter this machine would use, or why there is none. Probed once per process (an
/// instance and an adapter request, no device).
pub fn probe_adapter() -> Result<AdapterProbe, GpuError> {
    static PROBE: OnceLock<Result<AdapterProbe, GpuError>> = OnceLock::new();
    PROBE
        .get_or_init(|| {
            pollster::block_on(async {
                let instance = instance();
                adapter(&instance).await.map(|a| {
                    let info = a.get_info();
                    AdapterProbe {
                        name: info.name,
                        software: info.device_type == wgpu::DeviceType::Cpu,
                    }
                })
            })
        })
        .clone()
}
