//! The media pass, between shade and resolve: one invocation per ray of the band, the radiance
//! reaching the camera through the scene's media — `T · L_surface + L_in` over `[t_near, t_hit]`
//! for a hit (the fog's terms, the sky's air and the cloud volume's march composed in the CPU's
//! order), `T · background + L_in` over `[t_near, ∞)` for a miss (the sky's background, or the
//! scene's colour, through the fog and the clouds) — `shaders/media.wgsl` over
//! `shaders/fog.wgsl`, `shaders/sky.wgsl` and `shaders/clouds.wgsl`, the f32 twins of
//! fray-trace's `Media`, fray-atmosphere's `FogLayer` and `Sky` and fray-clouds' `march`. Built
//! only for scenes with fog, a sky or clouds; resolve is then specialised to take every ray's
//! radiance.

use super::band::{PassSpec, Role, Workload};

/// The media pass: the frame (paths) and the lights (suns, ambient in the frame) with the fog
/// layer, the sky and the clouds (`bindings::shading`). One invocation per ray of the band;
/// Whitted's levels dispatch it indirectly.
pub const MEDIA: PassSpec = PassSpec {
    label: "media",
    entry: "media.wgsl",
    roles: &[Role::Frame, Role::Shading],
    workload: Workload::Rays,
};
