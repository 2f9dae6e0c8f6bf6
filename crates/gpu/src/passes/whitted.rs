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

use super::media::MediaPass;
use super::shade::ShadePass;
use super::{Kernel, PassSetup};
use crate::GpuError;
use crate::bindings::{self, FRAME, FREE_FORMS, Group, QUEUE};
use crate::shader::ModuleOptions;

pub use crate::params::MAX_SHADOW_CROSSINGS;

/// Queue slots per camera ray a band starts with (every level's rays at once); doubled, with
/// the band halved, when a frame's queue overflows.
pub const QUEUE_SLOTS_PER_RAY: u32 = 2;

/// Whitted's queue passes.
#[derive(Debug)]
pub struct WhittedPasses {
    forward: Kernel,
    intersect: Kernel,
    select_parents: Kernel,
    gather: Kernel,
    /// Only with media: makes the level being gathered current for the media pass.
    select_level: Option<Kernel>,
    /// Whether the intersection pass binds the terrains-and-meshes group.
    surfaces: bool,
}

/// The bind groups the queue passes take (see [`WhittedPasses::encode`]).
#[derive(Debug)]
pub struct WhittedGroups<'a> {
    pub frame: &'a wgpu::BindGroup,
    pub free_forms: &'a wgpu::BindGroup,
    pub shading: &'a wgpu::BindGroup,
    pub surfaces: Option<&'a wgpu::BindGroup>,
    pub queue: &'a wgpu::BindGroup,
}

impl WhittedPasses {
    /// The groups of the intersection pass for a scene composed with `options`.
    pub fn intersect_groups(options: &ModuleOptions) -> Vec<Group> {
        let mut groups = vec![FRAME, FREE_FORMS];
        groups.extend(bindings::surfaces(
            options.terrain,
            options.meshes,
            options.textures,
        ));
        groups
    }

    /// The groups of the queue passes.
    pub const QUEUE_GROUPS: [Group; 2] = [FRAME, QUEUE];

    /// The groups of the gather pass for a scene composed with `options`.
    pub fn gather_groups(options: &ModuleOptions) -> Vec<Group> {
        vec![
            FRAME,
            bindings::shading(options.fog, options.sky, options.clouds, options.whitted),
        ]
    }

    pub fn new(setup: &PassSetup<'_>) -> Result<Self, GpuError> {
        let options = setup.options;
        Ok(Self {
            forward: Kernel::new(setup, "queue_forward.wgsl", &Self::QUEUE_GROUPS)?,
            intersect: Kernel::new(
                setup,
                "intersect_secondary.wgsl",
                &Self::intersect_groups(options),
            )?,
            select_parents: Kernel::new(setup, "queue_gather.wgsl", &Self::QUEUE_GROUPS)?,
            gather: Kernel::new(setup, "whitted_gather.wgsl", &Self::gather_groups(options))?,
            select_level: (options.fog || options.sky || options.clouds)
                .then(|| Kernel::new(setup, "queue_level.wgsl", &Self::QUEUE_GROUPS))
                .transpose()?,
            surfaces: bindings::surfaces(options.terrain, options.meshes, options.textures)
                .is_some(),
        })
    }

    /// Encodes `max_depth` levels of secondary rays after the band's shade pass, then their
    /// gathers — each level first through `media` where the scene has them: `args` holds the
    /// indirect dispatch the queue passes write (bound in `queue`).
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        (shade, media): (&ShadePass, Option<&MediaPass>),
        groups: &WhittedGroups<'_>,
        args: &wgpu::Buffer,
        max_depth: u32,
    ) {
        let queue = [groups.frame, groups.queue];
        for _ in 0..max_depth {
            self.forward.run_2d(pass, &queue, 1, 1);
            let mut intersect = vec![groups.frame, groups.free_forms];
            if self.surfaces
                && let Some(s) = groups.surfaces
            {
                intersect.push(s);
            }
            self.intersect.run_indirect(pass, &intersect, args);
            shade.encode_indirect(
                pass,
                [groups.frame, groups.free_forms, groups.shading],
                groups.surfaces,
                args,
            );
        }
        for _ in 0..max_depth {
            if let (Some(select_level), Some(media)) = (&self.select_level, media) {
                select_level.run_2d(pass, &queue, 1, 1);
                media.encode_indirect(pass, [groups.frame, groups.shading], args);
            }
            self.select_parents.run_2d(pass, &queue, 1, 1);
            self.gather
                .run_indirect(pass, &[groups.frame, groups.shading], args);
        }
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
