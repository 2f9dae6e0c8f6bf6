//! Media on the GPU as values: each medium — the fog layer, the physically based sky, the cloud
//! volume — implements [`GpuMedium`] once: its composition feature, its `bindings::Part` in the
//! lights-and-media group, and what it keeps resident for a scene ([`ResidentMedium`]: its
//! tables and grids, its parameter block written from f64 for each view, the resources it
//! binds). The upload, the bind groups and each view's writes walk [`MEDIA`]. How the media
//! compose along a ray is the media pass's (`shaders/media.wgsl`: the CPU's order), each
//! medium's terms in its `<medium>_media.wgsl` hooks and its light toward surfaces in
//! `<medium>_shading.wgsl`, each with its `// #else` identities. ARCHITECTURE.md's checklist
//! names every file a new medium touches.

pub mod clouds;
pub mod fog;
pub mod sky;

use crate::bindings::Part;
use crate::features::Feature;
use crate::kinds::Upload;
use crate::{DeviceCharges, GpuContext, GpuError, View};
use fray_scene::Scene;

/// A medium on the GPU.
pub trait GpuMedium: Sync {
    /// Its composition feature (`// #if fog`, …): the scene has the medium.
    fn feature(&self) -> Feature;

    /// Its part of the lights-and-media group (`bindings::shading_parts`).
    fn part(&self) -> Part;

    /// Uploads the scene's medium, every buffer and texture charged to `charges` before it is
    /// allocated; `None`, allocating nothing, where the scene does not have it.
    fn upload(
        &self,
        at: Upload<'_>,
        charges: &mut DeviceCharges,
    ) -> Result<Option<Box<dyn ResidentMedium>>, GpuError>;

    /// Reads its counters (`crate::counters`), if it has any, from a frame's read-back `words`
    /// into `stats`.
    fn read_stats(&self, _words: &[u32], _stats: &mut fray_core::RenderStats) {}
}

/// What a medium keeps on the GPU for a scene that has it.
pub trait ResidentMedium: std::fmt::Debug + Send + Sync {
    /// Its part's resources, in the order of the part's bindings.
    fn resources(&self) -> Vec<wgpu::BindingResource<'_>>;

    /// Writes what depends on the view (its parameters relative to the eye, from f64; tables
    /// that depend on the eye) before a frame; returns the bytes written.
    fn write_view(&mut self, ctx: &GpuContext, scene: &Scene, view: &View) -> u64;

    /// The bytes it uploaded.
    fn bytes(&self) -> u64;
}

/// Every medium the GPU draws.
pub const MEDIA: [&dyn GpuMedium; 3] = [&fog::Fog, &sky::Sky, &clouds::Clouds];

#[cfg(test)]
mod tests {
    use super::*;

    /// Each medium has its own feature, a medium's, and its own part.
    #[test]
    fn each_medium_has_its_own_feature_and_part() {
        for (i, a) in MEDIA.iter().enumerate() {
            assert!(a.feature().is_medium(), "{:?}", a.feature());
            for b in &MEDIA[i + 1..] {
                assert_ne!(a.feature(), b.feature());
                assert_ne!(a.part(), b.part());
            }
        }
        let media: Vec<_> = Feature::all().filter(|f| f.is_medium()).collect();
        assert_eq!(
            media.len(),
            MEDIA.len(),
            "every medium feature has its medium"
        );
    }
}
