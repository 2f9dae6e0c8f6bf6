//! Test support (the `testing` feature, and this crate's own tests): the GPU's kernels run ray by
//! ray. One generic [`BatchPass`] runs a batch kernel — a module built on `shaders/batch.wgsl` —
//! over queries given by the caller; each kind and medium has its kernel here ([`FreeFormBatch`],
//! [`TerrainBatch`],
//! [`MeshBatch`], [`FogBatch`], [`SkyBatch`], [`CloudsBatch`]), the f32 twins of their CPU
//! functions that the parity tests compare ray by ray. Nothing of it is part of a frame.

mod batch;
pub mod clouds;
pub mod fog;
pub mod freeform;
pub mod mesh;
pub mod sky;
pub mod terrain;

pub use batch::{BatchPass, Kernel, floats};
pub use clouds::{CloudsBatch, GpuCloudRay, GpuCloudTerms};
pub use fog::{FogBatch, GpuFogRay, GpuFogTerms};
pub use freeform::{FreeFormBatch, GpuFreeFormHit};
pub use mesh::{GpuMeshHit, MeshBatch};
pub use sky::{GpuSkyAnswer, GpuSkyQuery, SkyBatch, SkySeen, sky_query};
pub use terrain::{GpuRay, GpuTerrainHit, TerrainBatch};

/// Every batch kernel.
pub const KERNELS: [Kernel; 6] = [
    freeform::KERNEL,
    terrain::KERNEL,
    mesh::KERNEL,
    fog::KERNEL,
    sky::KERNEL,
    clouds::KERNEL,
];
