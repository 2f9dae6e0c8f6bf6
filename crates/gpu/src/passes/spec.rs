//! What a pass is, as data: its [`PassSpec`] — a label, an entry module, the [`Role`]s of the
//! bind groups it binds (whose layouts follow from the scene's features) and its [`Workload`].

use crate::bindings::{self, FRAME, FREE_FORMS, Group, Part, QUEUE, TARGETS, WORK};
use crate::shader::ModuleOptions;
use fray_scene::PrimitiveKind;

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
    /// A primitive kind's own arrays (its intersection pass): its `Part` alone.
    Kind(PrimitiveKind),
    /// Whitted's queue of secondary rays.
    Queue,
    /// The frame's storage textures.
    Targets,
}

impl Role {
    /// The group this role binds in a scene composed with `options`; `None` where the scene has
    /// nothing for it (no terrains, meshes or textures: no surfaces group; free forms: no part of
    /// their own, their arrays are `Role::FreeForms`).
    pub fn group(self, options: &ModuleOptions) -> Option<Group> {
        let o = options;
        Some(match self {
            Role::Frame => FRAME,
            Role::FreeForms => FREE_FORMS,
            Role::Work => WORK,
            Role::Shading => bindings::shading(o.features),
            Role::Surfaces => return bindings::surfaces(o.features),
            Role::Kind(kind) => bindings::group_of(&[Part::of_kind(kind)?]),
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
