//! What stays on the GPU: a scene uploaded once, relative to a fixed anchor (the first view's
//! eye), with the camera-relative copies the rebase pass refreshes from it — so a frame from a
//! moved camera uploads only the camera and its work list. Free forms (solids, leaves,
//! perturbations and their CSG programs, at the head of `indices`), lights, materials, the
//! terrains (parameters, concatenated pyramids and samples), the fog layer's parameters
//! (camera-relative heights, written per frame) and the sky (its transmittance table, uploaded
//! here once; its sky-view table, written when the eye's height changes; its parameters, written
//! per frame), the clouds (their density grid and max grid as 3D textures, uploaded here once;
//! their parameters, camera-relative, written per frame), the meshes (every mesh's BVH, triangles
//! and vertices once, in one texture with the instance blocks, which alone a moved camera
//! rewrites — relative to the camera, from f64 —: `meshes::MeshBuffers`); every buffer and
//! texture checked against the device's limits before it is made.

pub mod clouds;
pub mod meshes;
pub mod sky;
pub mod terrains;

use crate::bindings::Part;
use crate::params::{self, GpuLight, GpuMaterial};
use crate::passes::PipelineCache;
use crate::passes::rebase::{RebaseLayout, Rebased};
use crate::{GpuContext, GpuError};
use fray_atmosphere::gpu_layout::{GpuFog, GpuSky};
use fray_core::MemoryBudget;
use fray_geometry::gpu_layout::{GpuLeaf, GpuPerturbation, GpuQuadric, GpuSolid, GpuSolids};
use fray_mesh::gpu_layout::GpuMeshes;
use fray_scene::Scene;
use fray_terrain::gpu_layout::GpuTerrainParams;
use glam::DVec3;
use meshes::{MeshBuffers, layout_error, mesh_buffers};
use std::mem::{offset_of, size_of};
use terrains::{TerrainUpload, terrain_arrays};
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
pub const TERRAIN_LAYOUT: RebaseLayout = RebaseLayout::new(
    size_of::<GpuTerrainParams>(),
    &[offset_of!(GpuTerrainParams, origin)],
    &[],
    &[],
);

/// The terrains on the GPU.
#[derive(Debug)]
pub struct ResidentTerrains {
    /// The parameters (anchor-relative source, camera-relative copy).
    pub params: Rebased,
    /// The camera-relative parameters as the uniform table the passes read (copied from
    /// `params.target` each frame the camera moves).
    pub table: wgpu::Buffer,
    /// This view's level-of-detail parameters, one vec4 per terrain (camera data, written per
    /// frame).
    pub lods: wgpu::Buffer,
    pub pyramid: wgpu::Buffer,
    pub samples: wgpu::Buffer,
}

/// The sky on the GPU.
#[derive(Debug)]
pub struct ResidentSky {
    /// Its parameters (`GpuSky`, a uniform written per frame from f64).
    pub params: wgpu::Buffer,
    /// The transmittance table (optical depth), uploaded once: it depends on the model only.
    pub transmittance: wgpu::Texture,
    /// The sky-view table of the eye's height (`Sky::view`), written when that height changes:
    /// it depends neither on the eye's horizontal position nor on where the camera looks.
    pub view: wgpu::Texture,
}

/// The texture views of the resident scene's parts, where it has them.
#[derive(Debug)]
pub struct PartViews {
    sky: Option<(wgpu::TextureView, wgpu::TextureView)>,
    clouds: Option<(wgpu::TextureView, wgpu::TextureView)>,
    meshes: Option<wgpu::TextureView>,
    textures: Option<wgpu::TextureView>,
}

/// The clouds on the GPU.
#[derive(Debug)]
pub struct ResidentClouds {
    /// Their parameters (`GpuClouds`, a uniform written per frame from f64: the box relative to
    /// the camera, the sun's light through the sky).
    pub params: wgpu::Buffer,
    /// The density grid and the max grid, uploaded once.
    pub textures: clouds::CloudTextures,
}

/// The meshes on the GPU.
#[derive(Debug)]
pub struct ResidentMeshes {
    /// The layout uploaded (each distinct mesh once, one instance per mesh object in scene
    /// order, with its material and smooth flag), kept for the instance blocks of a moved
    /// camera.
    pub layout: GpuMeshes,
    pub buffers: MeshBuffers,
    /// The point (world, f64) the instance blocks on the GPU are relative to.
    pub reference: DVec3,
}

impl ResidentMeshes {
    /// Rewrites the instance blocks relative to `reference` (a camera's eye, f64), unless they
    /// already are; nothing else of the meshes moves. Returns the bytes written.
    pub fn move_to(&mut self, ctx: &GpuContext, reference: DVec3) -> Result<u64, GpuError> {
        if reference == self.reference {
            return Ok(0);
        }
        let blocks = self.layout.instances_at(reference).map_err(layout_error)?;
        let bytes = self.buffers.write_instances(ctx, &blocks);
        self.layout.instances = blocks;
        self.reference = reference;
        Ok(bytes)
    }
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
    pub terrains: Option<ResidentTerrains>,
    /// The fog layer's parameters (`GpuFog`, a uniform written per frame: its heights are
    /// relative to the camera's); `None` without fog.
    pub fog: Option<wgpu::Buffer>,
    /// The sky's parameters and tables; `None` without a sky (nothing of it is allocated).
    pub sky: Option<ResidentSky>,
    /// The clouds' parameters and grids; `None` without clouds (nothing of them is allocated).
    pub clouds: Option<ResidentClouds>,
    /// The meshes; `None` without meshes (nothing of them is allocated).
    pub meshes: Option<ResidentMeshes>,
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
        let terrains = if scene.terrains.is_empty() {
            None
        } else {
            let (t, b) = upload_terrains(ctx, &mut charges, cache, scene, anchor)?;
            bytes += b;
            Some(t)
        };
        let fog = match scene.atmosphere.fog {
            Some(_) => Some(charges.empty(
                ctx,
                "fog",
                size_of::<GpuFog>() as u64,
                U::UNIFORM | U::COPY_DST,
            )?),
            None => None,
        };
        let sky = match &scene.atmosphere.sky {
            Some(s) => {
                let (sky, b) = upload_sky(ctx, &mut charges, &s.sky)?;
                bytes += b;
                Some(sky)
            }
            None => None,
        };
        let clouds = match &scene.clouds {
            Some(c) => {
                let (textures, b) = clouds::CloudTextures::upload(ctx, &mut charges, &c.volume)?;
                bytes += b;
                let params = charges.empty(
                    ctx,
                    "clouds",
                    size_of::<fray_clouds::gpu_layout::GpuClouds>() as u64,
                    U::UNIFORM | U::COPY_DST,
                )?;
                Some(ResidentClouds { params, textures })
            }
            None => None,
        };
        let meshes = if scene.meshes.is_empty() {
            None
        } else {
            let m = upload_meshes(ctx, &mut charges, scene, anchor, budget)?;
            bytes += m.buffers.bytes;
            Some(m)
        };
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
            terrains,
            fog,
            sky,
            clouds,
            meshes,
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
            sky: self
                .sky
                .as_ref()
                .map(|s| (sky::view(&s.transmittance), sky::view(&s.view))),
            clouds: self.clouds.as_ref().map(|c| c.textures.views()),
            meshes: self.meshes.as_ref().map(|m| m.buffers.view()),
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
            Part::Fog => self.fog.iter().map(|f| f.as_entire_binding()).collect(),
            Part::Sky => match (&self.sky, &views.sky) {
                (Some(s), Some((transmittance, view))) => vec![
                    s.params.as_entire_binding(),
                    TextureView(transmittance),
                    TextureView(view),
                ],
                _ => Vec::new(),
            },
            Part::Clouds => match (&self.clouds, &views.clouds) {
                (Some(c), Some((density, max))) => vec![
                    c.params.as_entire_binding(),
                    TextureView(density),
                    TextureView(max),
                ],
                _ => Vec::new(),
            },
            Part::Secondaries => vec![secondaries.as_entire_binding()],
            Part::Terrains => match &self.terrains {
                Some(t) => vec![
                    t.table.as_entire_binding(),
                    t.lods.as_entire_binding(),
                    t.pyramid.as_entire_binding(),
                    t.samples.as_entire_binding(),
                ],
                None => Vec::new(),
            },
            Part::Meshes => match (&self.meshes, &views.meshes) {
                (Some(m), Some(view)) => {
                    vec![m.buffers.info.as_entire_binding(), TextureView(view)]
                }
                _ => Vec::new(),
            },
            Part::Textures => match (&self.textures, &views.textures) {
                (Some(t), Some(view)) => vec![t.info.as_entire_binding(), TextureView(view)],
                _ => Vec::new(),
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
        if let Some(t) = &self.terrains {
            v.push(&t.params);
        }
        v
    }

    /// Copies the moved uniform tables (lights, terrain parameters) into their uniform buffers.
    pub fn copy_tables(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_buffer_to_buffer(
            &self.lights.target,
            0,
            &self.lights_table,
            0,
            self.lights_table.size(),
        );
        if let Some(t) = &self.terrains {
            encoder.copy_buffer_to_buffer(&t.params.target, 0, &t.table, 0, t.table.size());
        }
    }
}

/// The terrains' parameters (their pyramids and samples at offsets in the concatenated arrays,
/// their materials) anchor-relative, and the concatenated arrays, written straight into mapped
/// GPU buffers (`terrains::terrain_arrays`); returns them and the bytes uploaded.
fn upload_terrains(
    ctx: &GpuContext,
    charges: &mut crate::DeviceCharges,
    cache: &PipelineCache,
    scene: &Scene,
    anchor: DVec3,
) -> Result<(ResidentTerrains, u64), GpuError> {
    let material_count = scene.materials.len() as u32;
    let uploads: Vec<TerrainUpload<'_>> = scene
        .terrains
        .iter()
        .map(|t| TerrainUpload {
            terrain: &t.terrain,
            material: t.material.min(material_count),
            // The level of detail is the view's: `terrain_lods`, per frame.
            footprint: fray_core::PixelFootprint::ZERO,
        })
        .collect();
    let (params, pyramid, samples) = terrain_arrays(ctx, charges, &uploads, anchor)?;
    let (params_rebased, params_bytes) = Rebased::new(
        ctx,
        charges,
        cache,
        "terrain params",
        &params,
        TERRAIN_LAYOUT,
    )?;
    let table_bytes = (params.len() * size_of::<GpuTerrainParams>()) as u64;
    let table = charges.empty(ctx, "terrain table", table_bytes, U::UNIFORM | U::COPY_DST)?;
    let lods = charges.empty(
        ctx,
        "terrain lods",
        16 * params.len() as u64,
        U::UNIFORM | U::COPY_DST,
    )?;
    let bytes = params_bytes + pyramid.size() + samples.size();
    Ok((
        ResidentTerrains {
            params: params_rebased,
            table,
            lods,
            pyramid,
            samples,
        },
        bytes,
    ))
}

/// The scene's meshes laid out relative to `anchor` (`fray_mesh::gpu_layout::GpuMeshes`: each
/// distinct mesh — objects naming one file share its BVH — once, one instance per mesh object
/// in scene order with its material, the default where it has none, and its smooth flag) and
/// uploaded (`meshes::mesh_buffers`).
fn upload_meshes(
    ctx: &GpuContext,
    charges: &mut crate::DeviceCharges,
    scene: &Scene,
    anchor: DVec3,
    budget: &MemoryBudget,
) -> Result<ResidentMeshes, GpuError> {
    let mut distinct: Vec<&std::sync::Arc<fray_mesh::MeshBvh>> = Vec::new();
    let mut placements = Vec::with_capacity(scene.meshes.len());
    for object in &scene.meshes {
        let mesh = &object.instance.mesh;
        let index = match distinct
            .iter()
            .position(|m| std::sync::Arc::ptr_eq(m, mesh))
        {
            Some(i) => i,
            None => {
                distinct.push(mesh);
                distinct.len() - 1
            }
        };
        placements.push((index as u32, object.instance.to_world()));
    }
    let bvhs: Vec<&fray_mesh::MeshBvh> = distinct.iter().map(|m| m.as_ref()).collect();
    let material_count = scene.materials.len() as u32;
    let materials: Vec<u32> = scene
        .meshes
        .iter()
        .map(|m| m.material.min(material_count))
        .collect();
    let smooth: Vec<bool> = scene.meshes.iter().map(|m| m.smooth).collect();
    let layout = meshes::mesh_layout(&bvhs, &placements, anchor, budget)?
        .with_materials(&materials)
        .with_smooth(&smooth);
    let buffers = mesh_buffers(ctx, charges, &layout)?;
    Ok(ResidentMeshes {
        layout,
        buffers,
        reference: anchor,
    })
}

/// The sky's parameter block (empty: written per frame), its transmittance table (uploaded) and
/// its sky-view table (empty: written per eye height); returns them and the bytes uploaded.
fn upload_sky(
    ctx: &GpuContext,
    charges: &mut crate::DeviceCharges,
    sky: &fray_atmosphere::sky::Sky,
) -> Result<(ResidentSky, u64), GpuError> {
    let table = sky.transmittance_table();
    let transmittance = sky::table_texture(
        ctx,
        charges,
        "the sky's transmittance table (texels per side)",
        table.width(),
        table.height(),
    )?;
    let bytes = sky::write_table(ctx, &transmittance, table.width(), table.texels());
    let sizes = sky.tables();
    let view = sky::table_texture(
        ctx,
        charges,
        "the sky-view table (texels per side)",
        sizes.sky_view_width,
        sizes.sky_view_height,
    )?;
    let params = charges.empty(
        ctx,
        "sky",
        size_of::<GpuSky>() as u64,
        U::UNIFORM | U::COPY_DST,
    )?;
    Ok((
        ResidentSky {
            params,
            transmittance,
            view,
        },
        bytes,
    ))
}

/// This view's level-of-detail parameters of each terrain of `scene` (camera rays at the
/// terrain's `lod`; `GpuTerrainParams::with_pixel_lod`, exactly as the CPU casts them).
pub fn terrain_lods(scene: &Scene, footprint: fray_core::PixelFootprint) -> Vec<[f32; 4]> {
    scene
        .terrains
        .iter()
        .map(|t| {
            let fp = match t.lod {
                fray_scene::TerrainLod::Pixel => footprint.coarser(t.terrain.options().lod_bias),
                fray_scene::TerrainLod::Exact => fray_core::PixelFootprint::ZERO,
            };
            GpuTerrainParams::new(&t.terrain, DVec3::ZERO)
                .with_pixel_lod(&t.terrain, fp)
                .lod
        })
        .collect()
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
        assert_eq!(TERRAIN_LAYOUT.points, 1);
    }
}
