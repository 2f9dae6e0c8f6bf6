//! What stays on the GPU: a scene uploaded once, relative to a fixed anchor (the first view's
//! eye), with the camera-relative copies the rebase pass refreshes from it — so a frame from a
//! moved camera uploads only the camera and its work list. Free forms (solids, leaves,
//! perturbations and their CSG programs, at the head of `indices`), lights, materials, what each
//! other kind keeps (`crate::kinds`: the terrains' parameters, pyramids and samples; the meshes'
//! BVHs, triangles and instance blocks), what each medium keeps (`crate::media`: the fog layer's
//! parameters; the sky's tables; the clouds' grids, each with parameters written per view), the
//! materials' textures; every buffer and texture checked against the device's limits and
//! charged to the render's budget before it is made.

use crate::bindings::Part;
use crate::kinds::{ResidentKind, Upload};
use crate::media::ResidentMedium;
use crate::params::{self, GpuLight, GpuMaterial};
use crate::passes::PipelineCache;
use crate::passes::rebase::{RebaseLayout, Rebased};
use crate::{GpuContext, GpuError};
use fray_core::MemoryBudget;
use fray_geometry::gpu_layout::{GpuLeaf, GpuPerturbation, GpuQuadric, GpuSolid, GpuSolids};
use fray_scene::{PrimitiveKind, Scene};
use glam::DVec3;
use std::mem::{offset_of, size_of};
use wgpu::BufferUsages as U;

/// Where the positions and box corners of the scene's GPU structs are.
pub const SOLID_LAYOUT: RebaseLayout = RebaseLayout::new(
    size_of::<GpuSolid>(),
    &[],
    &[offset_of!(GpuSolid, box_min)],
    &[offset_of!(GpuSolid, box_max)],
);
pub const LEAF_LAYOUT: RebaseLayout = RebaseLayout::new(
    size_of::<GpuLeaf>(),
    &[offset_of!(GpuLeaf, base) + offset_of!(GpuQuadric, origin)],
    &[offset_of!(GpuLeaf, box_min)],
    &[offset_of!(GpuLeaf, box_max)],
);
pub const PERTURBATION_LAYOUT: RebaseLayout = RebaseLayout::new(
    size_of::<GpuPerturbation>(),
    &[offset_of!(GpuPerturbation, quadric) + offset_of!(GpuQuadric, origin)],
    &[],
    &[],
);
pub const LIGHT_LAYOUT: RebaseLayout = RebaseLayout::new(
    size_of::<GpuLight>(),
    &[offset_of!(GpuLight, position)],
    &[],
    &[],
);

/// The texture views of the resident scene's textures part, where it has one (made for each set
/// of bind groups; the kinds and media keep their own).
#[derive(Debug)]
pub struct PartViews {
    textures: Option<wgpu::TextureView>,
}

/// A scene on the GPU.
#[derive(Debug)]
pub struct ResidentScene {
    /// The point every resident position is relative to.
    pub anchor: DVec3,
    /// The solids flattened (for the work list: programs, first leaves).
    pub flat: GpuSolids,
    pub solids: Rebased,
    pub leaves: Rebased,
    pub perturbations: Rebased,
    /// The scene's CSG programs, the head of every frame's `indices` (copied on the GPU).
    pub programs: wgpu::Buffer,
    pub lights: Rebased,
    /// The camera-relative lights as the uniform table the shade pass reads.
    pub lights_table: wgpu::Buffer,
    pub materials: wgpu::Buffer,
    /// What each kind the scene has keeps of its own (`crate::kinds::GpuKind::upload`), in
    /// kind order; nothing for a kind it lacks.
    pub kinds: Vec<(PrimitiveKind, Box<dyn ResidentKind>)>,
    /// What each medium the scene has keeps (`crate::media::GpuMedium::upload`: the fog's
    /// parameters, the sky's and its tables, the clouds' and their grids), in `MEDIA` order;
    /// nothing for a medium it lacks.
    pub media: Vec<(Part, Box<dyn ResidentMedium>)>,
    /// The materials' image textures and colour ramps; `None` without them (nothing of them is
    /// allocated).
    pub textures: Option<crate::textures::ResidentTextures>,
    /// Bytes uploaded.
    pub bytes: u64,
    /// The resident buffers' and textures' bytes on the render's memory account, each charged
    /// before it was allocated, for as long as they live.
    charges: crate::DeviceCharges,
}

/// The scene's free forms as the GPU holds them, relative to `anchor`: every object with its
/// leaves' materials (the default where one is out of range), then the complement of each object
/// with a transmitting leaf — rays travel inside transmissive solids and look for where they end,
/// the first point of their complement (fray-trace's Interiors).
pub fn scene_solids(scene: &Scene, anchor: DVec3) -> GpuSolids {
    let mut flat = GpuSolids::new(anchor);
    let material_count = scene.materials.len() as u32;
    for object in &scene.objects {
        flat.push(&object.solid, |leaf| {
            object
                .leaf_materials
                .get(leaf)
                .copied()
                .filter(|&m| m < material_count)
                .unwrap_or(material_count)
        });
    }
    let transmits = |m: &u32| {
        scene
            .materials
            .get(*m as usize)
            .is_some_and(|m| m.transmits())
    };
    for (index, object) in scene.objects.iter().enumerate() {
        if object.leaf_materials.iter().any(transmits) {
            flat.push_complement(index);
        }
    }
    flat
}

impl ResidentScene {
    /// Uploads `scene` relative to `anchor`. Every buffer and texture is charged to `budget`
    /// before it is allocated (a scene past the budget is refused with nothing allocated beyond
    /// it), as is what it lays out on the host for the device (the meshes' arrays); the charges
    /// stay on the account while the scene lives.
    pub fn upload(
        ctx: &GpuContext,
        cache: &PipelineCache,
        scene: &Scene,
        anchor: DVec3,
        budget: &MemoryBudget,
    ) -> Result<Self, GpuError> {
        let flat = scene_solids(scene, anchor);
        let mut charges = crate::DeviceCharges::new(budget);
        let mut bytes = 0;
        let (solids, b) = Rebased::new(
            ctx,
            &mut charges,
            cache,
            "solids",
            &flat.solids,
            SOLID_LAYOUT,
        )?;
        bytes += b;
        let (leaves, b) = Rebased::new(
            ctx,
            &mut charges,
            cache,
            "leaves",
            &flat.leaves,
            LEAF_LAYOUT,
        )?;
        bytes += b;
        let (perturbations, b) = Rebased::new(
            ctx,
            &mut charges,
            cache,
            "perturbations",
            &flat.perturbations,
            PERTURBATION_LAYOUT,
        )?;
        bytes += b;
        let lights = params::lights(scene, anchor);
        let (lights_rebased, b) =
            Rebased::new(ctx, &mut charges, cache, "lights", &lights, LIGHT_LAYOUT)?;
        bytes += b;
        let programs = charges.upload(ctx, "programs", &flat.program, 0u32, U::COPY_SRC)?;
        let lights_table = charges.empty(
            ctx,
            "lights table",
            (lights.len() * size_of::<GpuLight>()) as u64,
            U::UNIFORM | U::COPY_DST,
        )?;
        let materials = params::materials(scene);
        let materials_buffer = charges.upload(
            ctx,
            "materials",
            &materials,
            GpuMaterial::default(),
            U::UNIFORM,
        )?;
        bytes += programs.size() + materials_buffer.size();
        let at = Upload {
            ctx,
            cache,
            scene,
            anchor,
            budget,
        };
        let mut kinds = Vec::new();
        for kind in crate::kinds::KINDS {
            if scene.count(kind.kind()) == 0 {
                continue;
            }
            if let Some(resident) = kind.upload(at, &mut charges)? {
                bytes += resident.bytes();
                kinds.push((kind.kind(), resident));
            }
        }
        let mut media = Vec::new();
        for medium in crate::media::MEDIA {
            if let Some(resident) = medium.upload(at, &mut charges)? {
                bytes += resident.bytes();
                media.push((medium.part(), resident));
            }
        }
        let textures = if scene.features.textures {
            let layout = crate::textures::TextureLayout::build(scene, budget)?;
            let t = crate::textures::ResidentTextures::upload(ctx, &mut charges, layout, anchor)?;
            bytes += t.bytes;
            Some(t)
        } else {
            None
        };
        charges.finish_uploads(ctx)?;
        Ok(Self {
            anchor,
            flat,
            solids,
            leaves,
            perturbations,
            programs,
            lights: lights_rebased,
            lights_table,
            materials: materials_buffer,
            kinds,
            media,
            textures,
            bytes,
            charges,
        })
    }

    /// The device memory its buffers and textures were charged to the render's budget for.
    pub fn device_bytes(&self) -> u64 {
        self.charges.bytes()
    }

    /// The texture views its parts bind (made for each set of bind groups).
    pub fn part_views(&self) -> PartViews {
        PartViews {
            textures: self.textures.as_ref().map(|t| t.view()),
        }
    }

    /// The resources of `part`, in the order of its bindings (`bindings::Part::bindings`);
    /// `secondaries` is Whitted's records (a frame buffer). A part the scene lacks has none —
    /// the groups are made of the parts it has.
    pub fn part_resources<'a>(
        &'a self,
        part: Part,
        views: &'a PartViews,
        secondaries: &'a wgpu::Buffer,
    ) -> Vec<wgpu::BindingResource<'a>> {
        use wgpu::BindingResource::TextureView;
        match part {
            Part::Lighting => vec![
                self.lights_table.as_entire_binding(),
                self.materials.as_entire_binding(),
            ],
            Part::Secondaries => vec![secondaries.as_entire_binding()],
            Part::Textures => match (&self.textures, &views.textures) {
                (Some(t), Some(view)) => vec![t.info.as_entire_binding(), TextureView(view)],
                _ => Vec::new(),
            },
            // A medium's part, or a kind's.
            part => match self.media.iter().find(|(p, _)| *p == part) {
                Some((_, medium)) => medium.resources(),
                None => self
                    .kinds
                    .iter()
                    .find(|(kind, _)| Part::of_kind(*kind) == Some(part))
                    .map(|(_, resident)| resident.resources())
                    .unwrap_or_default(),
            },
        }
    }

    /// Every array the rebase pass moves.
    pub fn rebased(&self) -> Vec<&Rebased> {
        let mut v = vec![
            &self.solids,
            &self.leaves,
            &self.perturbations,
            &self.lights,
        ];
        for (_, resident) in &self.kinds {
            v.extend(resident.rebased());
        }
        v
    }

    /// Copies the moved uniform tables (lights, the kinds' tables) into their uniform buffers.
    pub fn copy_tables(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_buffer_to_buffer(
            &self.lights.target,
            0,
            &self.lights_table,
            0,
            self.lights_table.size(),
        );
        for (_, resident) in &self.kinds {
            resident.copy_tables(encoder);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rebase_layouts_name_the_positions_and_boxes() {
        assert_eq!(LEAF_LAYOUT.stride as usize, size_of::<GpuLeaf>() / 16);
        assert_eq!(LEAF_LAYOUT.points, 1);
        assert_eq!(
            LEAF_LAYOUT.box_mins,
            1 << (offset_of!(GpuLeaf, box_min) / 16)
        );
        assert_eq!(SOLID_LAYOUT.points, 0);
        assert_eq!(
            LIGHT_LAYOUT.points,
            1 << (offset_of!(GpuLight, position) / 16)
        );
        // Directions are never moved: a sun's direction slot is not a position.
        assert_eq!(LIGHT_LAYOUT.points & 1, 0);
        assert_eq!(PERTURBATION_LAYOUT.points, 1);
    }
}
