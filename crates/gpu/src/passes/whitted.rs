//! Whitted's secondary rays on the GPU as queues through the pass pipeline, not recursion
//! (fray-trace's `Integrator::whitted`): after a band's camera rays are shaded, each level of
//! reflected and refracted rays the level before spawned is made current (`queue_forward.wgsl`),
//! intersected with every primitive kind (`intersect_secondary.wgsl`) and shaded — spawning the
//! next level — by the shade pass; then, deepest level first, each level's parents add their
//! children's radiance weighted by `kr` or `kt` (`queue_gather.wgsl`, `whitted_gather.wgsl`) —
//! in a scene with media after the level's rays have been taken through them
//! (`queue_level.wgsl`, then the media pass over the level).
//! The levels' sizes are known only on the GPU: their passes are dispatched indirectly from
//! arguments the queue passes write, so a band is one submission with no readback. A band's
//! queue holds every level's rays at once (the gather needs them); a frame whose queue overflows
//! is rendered again in smaller bands (`crate::render`). Built only for scenes whose materials
//! reflect or transmit.

use super::PassSetup;
use super::band::{Band, BandPass, Pass, PassSpec, Role, Workload};
use super::media::MEDIA;
use super::shade::SHADE;
use crate::GpuError;

pub use crate::params::MAX_SHADOW_CROSSINGS;

/// Queue slots per camera ray a band starts with (every level's rays at once); doubled, with
/// the band halved, when a frame's queue overflows.
pub const QUEUE_SLOTS_PER_RAY: u32 = 2;

/// A step of the queue between levels: one invocation that reads and moves the queue's
/// counters and writes the next pass's indirect dispatch.
const fn queue_step(label: &'static str, entry: &'static str) -> PassSpec {
    PassSpec {
        label,
        entry,
        roles: &[Role::Frame, Role::Queue],
        workload: Workload::Single,
    }
}

/// Makes the level the level before spawned current, and writes its indirect dispatch.
pub const FORWARD: PassSpec = queue_step("whitted forward", "queue_forward.wgsl");
/// Intersects the current level with every primitive kind (dispatched indirectly).
pub const INTERSECT: PassSpec = PassSpec {
    label: "whitted intersect",
    entry: "intersect_secondary.wgsl",
    roles: &[Role::Frame, Role::FreeForms, Role::Surfaces],
    workload: Workload::Rays,
};
/// Makes a level's parents current for the gather.
pub const SELECT_PARENTS: PassSpec = queue_step("whitted parents", "queue_gather.wgsl");
/// Adds each level's radiance to its parents, weighted by `kr` or `kt` (dispatched indirectly).
pub const GATHER: PassSpec = PassSpec {
    label: "whitted gather",
    entry: "whitted_gather.wgsl",
    roles: &[Role::Frame, Role::Shading],
    workload: Workload::Rays,
};
/// Only with media: makes the level being gathered current for the media pass.
pub const SELECT_LEVEL: PassSpec = queue_step("whitted level", "queue_level.wgsl");

/// Whitted's queue passes, with the shade and media passes they run again per level.
#[derive(Debug)]
pub struct WhittedPasses {
    forward: BandPass,
    intersect: BandPass,
    select_parents: BandPass,
    gather: BandPass,
    shade: BandPass,
    /// Only with media: the level's selection and the media pass.
    media: Option<(BandPass, BandPass)>,
}

impl WhittedPasses {
    /// The queue passes of the scene `setup` composes (`media`: whether it has fog, a sky or
    /// clouds).
    pub fn new(setup: &PassSetup<'_>, media: bool) -> Result<Self, GpuError> {
        Ok(Self {
            forward: BandPass::new(setup, FORWARD)?,
            intersect: BandPass::new(setup, INTERSECT)?,
            select_parents: BandPass::new(setup, SELECT_PARENTS)?,
            gather: BandPass::new(setup, GATHER)?,
            shade: BandPass::new(setup, SHADE)?,
            media: media
                .then(|| {
                    Ok((
                        BandPass::new(setup, SELECT_LEVEL)?,
                        BandPass::new(setup, MEDIA)?,
                    ))
                })
                .transpose()?,
        })
    }
}

impl Pass for WhittedPasses {
    fn label(&self) -> &'static str {
        "whitted"
    }

    fn roles(&self) -> Vec<Role> {
        let mut roles = vec![Role::Frame, Role::FreeForms, Role::Shading, Role::Queue];
        roles.extend(
            self.intersect
                .roles()
                .into_iter()
                .filter(|r| *r == Role::Surfaces),
        );
        roles
    }

    /// Encodes the band's `max_depth` levels of secondary rays after its shade pass, then their
    /// gathers — each level first through the media where the scene has them.
    fn encode(&self, pass: &mut wgpu::ComputePass<'_>, band: &Band<'_>) -> Result<(), GpuError> {
        for _ in 0..band.max_depth {
            self.forward.encode(pass, band)?;
            self.intersect.encode_indirect(pass, band)?;
            self.shade.encode_indirect(pass, band)?;
        }
        for _ in 0..band.max_depth {
            if let Some((select_level, media)) = &self.media {
                select_level.encode(pass, band)?;
                media.encode_indirect(pass, band)?;
            }
            self.select_parents.encode(pass, band)?;
            self.gather.encode_indirect(pass, band)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn shadow_crossings_match_the_cpu() {
        assert_eq!(
            super::MAX_SHADOW_CROSSINGS as usize,
            fray_trace::MAX_SHADOW_CROSSINGS
        );
    }
}
