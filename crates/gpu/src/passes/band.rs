//! A frame's passes as values: the [`Pass`] trait (a label, the bind groups it reads and writes
//! by [`Role`], how it encodes one band), [`BandPass`] — one kernel dispatched over the band's
//! rays, its work items or its 8 × 8 pixel tiles, as its [`PassSpec`] says — and the [`Band`]
//! every pass encodes against. A scene's frame is the ordered list of passes its features call
//! for ([`super::frame_passes`]), built once when the scene is uploaded.

use super::{Kernel, PassSetup};
use crate::bindings::{self, FRAME, FREE_FORMS, Group, QUEUE, TARGETS, TERRAINS, WORK};
use crate::shader::ModuleOptions;
use crate::{GpuContext, GpuError};

/// Which of the frame's bind groups a pass binds at an index: the group's layout follows from
/// the role and the scene's composition ([`Role::group`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Role {
    /// The frame's parameters, paths and counters.
    Frame,
    /// The free forms' solids, leaves, perturbations and programs.
    FreeForms,
    /// The band's work list.
    Work,
    /// Lights and materials, with the scene's media (`bindings::shading`).
    Shading,
    /// Terrains, meshes and textures as the shade pass reads them (`bindings::surfaces`).
    Surfaces,
    /// The terrains' pyramids and samples (their intersection pass).
    Terrains,
    /// The meshes' arrays (their intersection pass).
    Meshes,
    /// Whitted's queue of secondary rays.
    Queue,
    /// The frame's storage textures.
    Targets,
}

impl Role {
    /// The group this role binds in a scene composed with `options`; `None` where the scene has
    /// nothing for it (no terrains, meshes or textures: no surfaces group).
    pub fn group(self, options: &ModuleOptions) -> Option<Group> {
        let o = options;
        Some(match self {
            Role::Frame => FRAME,
            Role::FreeForms => FREE_FORMS,
            Role::Work => WORK,
            Role::Shading => bindings::shading(o.fog, o.sky, o.clouds, o.whitted),
            Role::Surfaces => return bindings::surfaces(o.terrain, o.meshes, o.textures),
            Role::Terrains => TERRAINS,
            Role::Meshes => bindings::MESHES,
            Role::Queue => QUEUE,
            Role::Targets => TARGETS,
        })
    }
}

/// How many workgroups a [`BandPass`] dispatches over a band.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Workload {
    /// One invocation per camera ray, 64 per workgroup.
    Rays,
    /// One workgroup per work item (its tile's pixels).
    Items,
    /// One workgroup per 8 × 8 pixels of the band.
    Tiles,
    /// One workgroup (a queue's bookkeeping).
    Single,
}

/// What a pass is: its label (in timings), its entry module, the roles of the groups it binds
/// in the module's order (a role with no group in the scene is left out), and its workload.
#[derive(Clone, Copy, Debug)]
pub struct PassSpec {
    pub label: &'static str,
    pub entry: &'static str,
    pub roles: &'static [Role],
    pub workload: Workload,
}

impl PassSpec {
    /// The roles and groups it binds in a scene composed with `options`.
    pub fn groups(&self, options: &ModuleOptions) -> Vec<(Role, Group)> {
        self.roles
            .iter()
            .filter_map(|r| r.group(options).map(|g| (*r, g)))
            .collect()
    }
}

/// The frame's bind groups by role.
pub trait BindGroups {
    fn group(&self, role: Role) -> Option<&wgpu::BindGroup>;
}

/// One band of rows as the passes encode it.
#[derive(Clone, Copy)]
pub struct Band<'a> {
    pub ctx: &'a GpuContext,
    pub groups: &'a dyn BindGroups,
    /// The band's width and rows in pixels, its camera rays and its work items.
    pub width: u32,
    pub rows: u32,
    pub rays: u32,
    pub items: u32,
    /// Whitted's indirect dispatch arguments (written by its queue passes).
    pub queue_args: &'a wgpu::Buffer,
    /// Whitted's levels of secondary rays.
    pub max_depth: u32,
}

impl std::fmt::Debug for Band<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Band")
            .field("width", &self.width)
            .field("rows", &self.rows)
            .field("rays", &self.rays)
            .field("items", &self.items)
            .finish_non_exhaustive()
    }
}

/// One pass of a frame.
pub trait Pass: std::fmt::Debug + Send + Sync {
    /// Its name in the frame's timings (`RenderStats::pass_times`).
    fn label(&self) -> &'static str;
    /// The roles of the bind groups it reads and writes.
    fn roles(&self) -> Vec<Role>;
    /// Encodes its work for `band` into `pass`.
    fn encode(&self, pass: &mut wgpu::ComputePass<'_>, band: &Band<'_>) -> Result<(), GpuError>;
}

/// A pass that is one kernel: its pipeline, the roles it binds and its workload.
#[derive(Clone, Debug)]
pub struct BandPass {
    spec: PassSpec,
    kernel: Kernel,
    roles: Vec<Role>,
}

impl BandPass {
    /// The pass `spec` for the scene `setup` composes (its pipeline from the cache, or built).
    pub fn new(setup: &PassSetup<'_>, spec: PassSpec) -> Result<Self, GpuError> {
        let (roles, groups): (Vec<Role>, Vec<Group>) =
            spec.groups(setup.options).into_iter().unzip();
        let kernel = Kernel::new(setup, spec.entry, &groups)?;
        Ok(Self {
            spec,
            kernel,
            roles,
        })
    }

    /// The band's bind groups in this pass's order.
    fn bind<'b>(&self, band: &Band<'b>) -> Result<Vec<&'b wgpu::BindGroup>, GpuError> {
        self.roles
            .iter()
            .map(|role| {
                band.groups.group(*role).ok_or_else(|| GpuError::Dispatch {
                    pass: self.spec.label,
                    reason: format!("the frame has no {role:?} bind group"),
                })
            })
            .collect()
    }

    /// Binds its groups and dispatches the workgroups the band's `queue_args` say (written on
    /// the GPU by an earlier pass).
    pub fn encode_indirect(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        band: &Band<'_>,
    ) -> Result<(), GpuError> {
        let groups = self.bind(band)?;
        self.kernel.run_indirect(pass, &groups, band.queue_args);
        Ok(())
    }
}

impl Pass for BandPass {
    fn label(&self) -> &'static str {
        self.spec.label
    }

    fn roles(&self) -> Vec<Role> {
        self.roles.clone()
    }

    fn encode(&self, pass: &mut wgpu::ComputePass<'_>, band: &Band<'_>) -> Result<(), GpuError> {
        let groups = self.bind(band)?;
        match self.spec.workload {
            Workload::Rays => self
                .kernel
                .run(pass, band.ctx, &groups, band.rays.div_ceil(64)),
            Workload::Items => self.kernel.run(pass, band.ctx, &groups, band.items),
            Workload::Tiles => {
                let (x, y) = (band.width.div_ceil(8), band.rows.div_ceil(8));
                self.kernel.run_2d(pass, &groups, x, y);
            }
            Workload::Single => self.kernel.run_2d(pass, &groups, 1, 1),
        }
        Ok(())
    }
}
