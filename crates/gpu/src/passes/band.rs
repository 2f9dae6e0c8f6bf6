//! A frame's passes as values: the [`Pass`] trait (a label, the bind groups it reads and writes
//! by [`Role`], how it encodes one band), [`BandPass`] — one kernel dispatched over the band's
//! rays, its work items or its 8 × 8 pixel tiles, as its [`PassSpec`] says — and the [`Band`]
//! every pass encodes against. A scene's frame is the ordered list of passes its features call
//! for ([`super::frame_passes`]), built once when the scene is uploaded.

pub use super::spec::{PassSpec, Role, Workload};
use super::{Kernel, PassSetup};
use crate::bindings::Group;
use crate::{GpuContext, GpuError};

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
