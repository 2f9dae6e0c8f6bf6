//! The bind groups, one per subsystem, declared once: each [`Group`] lists its bindings with
//! their WGSL names and types, from which both the WGSL declarations (`shader::compose` inserts
//! them where a module says `// #bindings …`) and the wgpu bind-group layouts are made — the two
//! sides cannot disagree. A module's groups are numbered in the order its `#bindings` line names
//! them, which is the order its pass binds them in (a test checks every pass): pipeline layouts
//! have no gaps. Every pipeline stays within wgpu's default limits — at most 4 groups and 8 storage
//! buffers per stage (uniform arrays hold the small per-scene tables; the sky's tables, too
//! large for a uniform, are sampled textures, which have a limit of their own) — except the
//! shade pass of a Whitted scene (reflecting or transmitting materials: [`shading`]`(…, true)`),
//! which binds one more storage buffer, its secondary rays' records: a device that cannot bind
//! nine is refused before upload (`crate::render`), and the CPU renders the scene.
//!
//! The lights and materials travel with the scene's media in one group — [`SHADING`],
//! [`SHADING_FOG`], [`SHADING_SKY`] or [`SHADING_FOG_SKY`], picked by [`shading`] — since the
//! shade pass of a scene with free forms and terrains already binds four groups. A module names
//! that group `shading` in its `#bindings` line and `shader::compose` substitutes the scene's.
//! Likewise the shade pass's fourth group holds the terrains, the meshes, the textures or any
//! of them together ([`TERRAINS`], [`MESHES`], [`TERRAINS_MESHES`], [`TEXTURES`] and the
//! `…_TEXTURES` groups, picked by [`surfaces`]; a module names it `surfaces`). The meshes and
//! the textures bind no storage buffer — the shade pass's eight are the frame's two, the free
//! forms' four and the terrains' two —: their arrays are packed into `Rgba32Uint` textures read
//! with `textureLoad`, with the sections' first texels in a uniform
//! (`crate::resident::meshes::MeshBuffers`, `crate::textures::ResidentTextures`).

use crate::GpuContext;
use bytemuck::Pod;
use wgpu::util::DeviceExt;

/// What a binding is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    Uniform,
    StorageRead,
    StorageReadWrite,
    /// A write-only 2D storage texture of this format.
    Texture(wgpu::TextureFormat),
    /// A 2D texture of unfilterable floats (`texture_2d<f32>`), read with `textureLoad`.
    Sampled,
    /// A 3D texture of unfilterable floats (`texture_3d<f32>`), read with `textureLoad`.
    Sampled3d,
    /// A 2D texture of unsigned integers (`texture_2d<u32>`), read with `textureLoad`.
    SampledUint,
}

/// One binding of a group.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Binding {
    pub binding: u32,
    pub name: &'static str,
    /// The WGSL type (for textures, the texel format's WGSL name).
    pub wgsl: &'static str,
    pub access: Access,
}

/// A bind group: its bindings (its index is its position in a module's `#bindings` line).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Group {
    /// The name modules use in `// #bindings …`.
    pub name: &'static str,
    pub bindings: &'static [Binding],
}

const fn binding(binding: u32, name: &'static str, wgsl: &'static str, access: Access) -> Binding {
    Binding {
        binding,
        name,
        wgsl,
        access,
    }
}

use Access::{StorageRead, StorageReadWrite, Uniform};

/// The frame: its parameters, the rays in flight, the work counters.
pub const FRAME: Group = Group {
    name: "frame",
    bindings: &[
        binding(0, "frame", "FrameParams", Uniform),
        binding(1, "paths", "array<GpuPath>", StorageReadWrite),
        binding(
            2,
            "counters",
            "array<atomic<u32>, COUNTER_WORDS>",
            StorageReadWrite,
        ),
    ],
};

/// The free forms (camera-relative) and `indices`: the CSG programs, then the frame's work-list
/// index arrays (active leaves, active perturbations, candidates' program pairs).
pub const FREE_FORMS: Group = Group {
    name: "free_forms",
    bindings: &[
        binding(0, "solids", "array<GpuSolid>", StorageRead),
        binding(1, "leaves", "array<GpuLeaf>", StorageRead),
        binding(2, "perturbations", "array<GpuPerturbation>", StorageRead),
        binding(3, "indices", "array<u32>", StorageRead),
    ],
};

/// The frame's work list: tiles and their candidates.
pub const WORK: Group = Group {
    name: "work",
    bindings: &[
        binding(0, "items", "array<WorkItem>", StorageRead),
        binding(1, "candidates", "array<Candidate>", StorageRead),
    ],
};

/// What lights a scene: its lights (camera-relative) and materials.
const LIGHTS: Binding = binding(0, "lights", "array<GpuLight, MAX_LIGHTS>", Uniform);
const MATERIALS: Binding = binding(1, "materials", "array<GpuMaterial, MAX_MATERIALS>", Uniform);
/// The fog layer (camera-relative heights, written per frame).
const FOG: Binding = binding(2, "fog", "GpuFog", Uniform);
/// The sky: its parameters (written per frame), its transmittance table (resident) and its
/// sky-view table (written when the eye's height changes).
const SKY: Binding = binding(3, "sky", "GpuSky", Uniform);
const SKY_TRANSMITTANCE: Binding = binding(
    4,
    "sky_transmittance_table",
    "texture_2d<f32>",
    Access::Sampled,
);
const SKY_VIEW: Binding = binding(5, "sky_view_table", "texture_2d<f32>", Access::Sampled);
/// The clouds: their parameters (camera-relative, written per frame), the density grid and the
/// max grid of its blocks (resident; a single zero texel when skipping is off).
const CLOUDS: Binding = binding(6, "clouds", "GpuClouds", Uniform);
const CLOUD_DENSITY: Binding = binding(7, "cloud_density", "texture_3d<f32>", Access::Sampled3d);
const CLOUD_MAX: Binding = binding(8, "cloud_max", "texture_3d<f32>", Access::Sampled3d);

/// Lights and materials, for a scene without media.
pub const SHADING: Group = Group {
    name: "shading",
    bindings: &[LIGHTS, MATERIALS],
};

/// [`SHADING`] and the fog layer, for the shade and media passes of a scene with fog.
pub const SHADING_FOG: Group = Group {
    name: "shading_fog",
    bindings: &[LIGHTS, MATERIALS, FOG],
};

/// [`SHADING`] and the sky, for the shade and media passes of a scene with a sky.
pub const SHADING_SKY: Group = Group {
    name: "shading_sky",
    bindings: &[LIGHTS, MATERIALS, SKY, SKY_TRANSMITTANCE, SKY_VIEW],
};

/// [`SHADING`], the fog layer and the sky.
pub const SHADING_FOG_SKY: Group = Group {
    name: "shading_fog_sky",
    bindings: &[LIGHTS, MATERIALS, FOG, SKY, SKY_TRANSMITTANCE, SKY_VIEW],
};

/// [`SHADING`] and the clouds, for a scene with a cloud volume.
pub const SHADING_CLOUDS: Group = Group {
    name: "shading_clouds",
    bindings: &[LIGHTS, MATERIALS, CLOUDS, CLOUD_DENSITY, CLOUD_MAX],
};

/// [`SHADING_FOG`] and the clouds.
pub const SHADING_FOG_CLOUDS: Group = Group {
    name: "shading_fog_clouds",
    bindings: &[LIGHTS, MATERIALS, FOG, CLOUDS, CLOUD_DENSITY, CLOUD_MAX],
};

/// [`SHADING_SKY`] and the clouds.
pub const SHADING_SKY_CLOUDS: Group = Group {
    name: "shading_sky_clouds",
    bindings: &[
        LIGHTS,
        MATERIALS,
        SKY,
        SKY_TRANSMITTANCE,
        SKY_VIEW,
        CLOUDS,
        CLOUD_DENSITY,
        CLOUD_MAX,
    ],
};

/// [`SHADING_FOG_SKY`] and the clouds.
pub const SHADING_FOG_SKY_CLOUDS: Group = Group {
    name: "shading_fog_sky_clouds",
    bindings: &[
        LIGHTS,
        MATERIALS,
        FOG,
        SKY,
        SKY_TRANSMITTANCE,
        SKY_VIEW,
        CLOUDS,
        CLOUD_DENSITY,
        CLOUD_MAX,
    ],
};

/// The lights-and-materials group of a scene with (or without) fog, a sky and clouds: what a
/// module's `shading` stands for. A scene without a medium binds none of its buffers or
/// textures. A Whitted scene (`whitted`: its materials reflect or transmit) binds the same and
/// its rays' records (`secondaries`, last), as a group named `<medium's>_whitted`.
pub fn shading(fog: bool, sky: bool, clouds: bool, whitted: bool) -> Group {
    let media = shading_of_media(fog, sky, clouds);
    if whitted {
        with_secondaries(media)
    } else {
        media
    }
}

/// `group` and Whitted's records: made once per group (the layouts are cached by name, so each
/// is its own name) and kept for the process, as the constant groups are.
fn with_secondaries(group: Group) -> Group {
    static MADE: std::sync::Mutex<Vec<Group>> = std::sync::Mutex::new(Vec::new());
    let mut made = MADE.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let name = format!("{}_whitted", group.name);
    if let Some(g) = made.iter().find(|g| g.name == name) {
        return *g;
    }
    let mut bindings = group.bindings.to_vec();
    bindings.push(SECONDARIES);
    let g = Group {
        name: Box::leak(name.into_boxed_str()),
        bindings: Box::leak(bindings.into_boxed_slice()),
    };
    made.push(g);
    g
}

const fn shading_of_media(fog: bool, sky: bool, clouds: bool) -> Group {
    match (fog, sky, clouds) {
        (false, false, false) => SHADING,
        (true, false, false) => SHADING_FOG,
        (false, true, false) => SHADING_SKY,
        (true, true, false) => SHADING_FOG_SKY,
        (false, false, true) => SHADING_CLOUDS,
        (true, false, true) => SHADING_FOG_CLOUDS,
        (false, true, true) => SHADING_SKY_CLOUDS,
        (true, true, true) => SHADING_FOG_SKY_CLOUDS,
    }
}

/// Whitted's per-ray records (`crate::params::GpuSecondary`), slot for slot with `paths` (after
/// every medium's binding).
const SECONDARIES: Binding = binding(9, "secondaries", "array<GpuSecondary>", StorageReadWrite);

/// Whitted's queue passes (`crate::passes::whitted`): the indirect dispatch arguments of the
/// current level (x, y, z workgroups), written on the GPU from the queue's state.
pub const QUEUE: Group = Group {
    name: "queue",
    bindings: &[binding(0, "queue_args", "array<u32, 4>", StorageReadWrite)],
};

const TERRAIN_TABLE: Binding = binding(
    0,
    "terrains",
    "array<GpuTerrainParams, MAX_TERRAINS>",
    Uniform,
);
const TERRAIN_LODS: Binding = binding(1, "terrain_lods", "array<vec4<f32>, MAX_TERRAINS>", Uniform);
const PYRAMID: Binding = binding(2, "pyramid", "array<f32>", StorageRead);
const SAMPLES: Binding = binding(3, "samples", "array<f32>", StorageRead);

/// The terrains (camera-relative parameters, this view's level-of-detail parameters) and their
/// pyramids and samples, concatenated.
pub const TERRAINS: Group = Group {
    name: "terrains",
    bindings: &[TERRAIN_TABLE, TERRAIN_LODS, PYRAMID, SAMPLES],
};

/// `b` as binding `index` of another group.
const fn renumbered(b: Binding, index: u32) -> Binding {
    Binding {
        binding: index,
        ..b
    }
}

/// The meshes' layout: (instance count, first texel of the BVH nodes, of the triangles, of the
/// vertices) in `mesh_data`.
const MESH_INFO: Binding = binding(0, "mesh_info", "vec4<u32>", Uniform);
/// Every mesh array (`fray_mesh::gpu_layout`) packed into one texture of 16-byte texels,
/// `MESH_TEXTURE_WIDTH` per row: the instance blocks first (4 texels each, relative to the
/// reference point — the only part a moved camera rewrites), then the BVH nodes (2), the
/// triangles (4, leaf order, anchor-relative) and the vertex attributes (2).
const MESH_DATA: Binding = binding(1, "mesh_data", "texture_2d<u32>", Access::SampledUint);

/// The meshes (read by `mesh.wgsl`), for the mesh intersection pass and the batch mesh pass.
/// The vertices are read only for surfaces (`mesh_surface`).
pub const MESHES: Group = Group {
    name: "meshes",
    bindings: &[MESH_INFO, MESH_DATA],
};

/// [`TERRAINS`] and [`MESHES`] in one group: the shade pass's fourth of a scene with both.
pub const TERRAINS_MESHES: Group = Group {
    name: "terrains_meshes",
    bindings: &[
        TERRAIN_TABLE,
        TERRAIN_LODS,
        PYRAMID,
        SAMPLES,
        renumbered(MESH_INFO, 4),
        renumbered(MESH_DATA, 5),
    ],
};

/// The textures' layout (`crate::textures::GpuTextureInfo`, written per frame) and every
/// image level, material record, mapping block and ramp stop packed into one texture of 16-byte
/// texels, `TEXTURE_DATA_WIDTH` per row (`crate::textures`; the mapping blocks, camera-relative,
/// are the only part a moved camera rewrites).
const TEXTURE_INFO: Binding = binding(0, "texture_info", "GpuTextureInfo", Uniform);
const TEXTURE_DATA: Binding = binding(1, "texture_data", "texture_2d<u32>", Access::SampledUint);

/// The textures alone (a scene whose only kind is free forms).
pub const TEXTURES: Group = Group {
    name: "textures",
    bindings: &[TEXTURE_INFO, TEXTURE_DATA],
};

/// [`TERRAINS`] and the textures.
pub const TERRAINS_TEXTURES: Group = Group {
    name: "terrains_textures",
    bindings: &[
        TERRAIN_TABLE,
        TERRAIN_LODS,
        PYRAMID,
        SAMPLES,
        renumbered(TEXTURE_INFO, 4),
        renumbered(TEXTURE_DATA, 5),
    ],
};

/// [`MESHES`] and the textures.
pub const MESHES_TEXTURES: Group = Group {
    name: "meshes_textures",
    bindings: &[
        MESH_INFO,
        MESH_DATA,
        renumbered(TEXTURE_INFO, 2),
        renumbered(TEXTURE_DATA, 3),
    ],
};

/// [`TERRAINS_MESHES`] and the textures.
pub const TERRAINS_MESHES_TEXTURES: Group = Group {
    name: "terrains_meshes_textures",
    bindings: &[
        TERRAIN_TABLE,
        TERRAIN_LODS,
        PYRAMID,
        SAMPLES,
        renumbered(MESH_INFO, 4),
        renumbered(MESH_DATA, 5),
        renumbered(TEXTURE_INFO, 6),
        renumbered(TEXTURE_DATA, 7),
    ],
};

/// The shade pass's group of what a scene has beyond free forms (what a module's `surfaces`
/// stands for): its terrains', its meshes' and its textures' bindings, in that order, in one
/// group — or none without any of them.
pub const fn surfaces(terrain: bool, meshes: bool, textures: bool) -> Option<Group> {
    match (terrain, meshes, textures) {
        (false, false, false) => None,
        (true, false, false) => Some(TERRAINS),
        (false, true, false) => Some(MESHES),
        (true, true, false) => Some(TERRAINS_MESHES),
        (false, false, true) => Some(TEXTURES),
        (true, false, true) => Some(TERRAINS_TEXTURES),
        (false, true, true) => Some(MESHES_TEXTURES),
        (true, true, true) => Some(TERRAINS_MESHES_TEXTURES),
    }
}

/// The frame's images (the resolve pass).
pub const TARGETS: Group = Group {
    name: "targets",
    bindings: &[
        binding(
            0,
            "colour_depth",
            "rgba32float",
            Access::Texture(wgpu::TextureFormat::Rgba32Float),
        ),
        binding(
            1,
            "normals",
            "rgba32float",
            Access::Texture(wgpu::TextureFormat::Rgba32Float),
        ),
        binding(
            2,
            "display_image",
            "rgba8unorm",
            Access::Texture(wgpu::TextureFormat::Rgba8Unorm),
        ),
    ],
};

/// The rebase pass: its parameters, one array of GPU structs in and out.
pub const REBASE: Group = Group {
    name: "rebase",
    bindings: &[
        binding(0, "rebase", "RebaseParams", Uniform),
        binding(1, "source", "array<vec4<u32>>", StorageRead),
        binding(2, "moved", "array<vec4<u32>>", StorageReadWrite),
    ],
};

/// Every batch kernel's queries and answers (`crate::testing::BatchPass`): the query count and
/// three parameters of the kernel's own, its queries' rows in, its answers' rows out (floats as
/// their bits where a kernel answers floats).
pub const BATCH: Group = Group {
    name: "batch",
    bindings: &[
        binding(0, "batch", "vec4<u32>", Uniform),
        binding(1, "queries", "array<vec4<f32>>", StorageRead),
        binding(2, "answers", "array<vec4<u32>>", StorageReadWrite),
    ],
};

/// The fog layer alone (the fog's batch kernel).
pub const FOG_LAYER: Group = Group {
    name: "fog_layer",
    bindings: &[renumbered(FOG, 0)],
};

/// The sky's parameters and tables alone (the sky's batch kernel).
pub const SKY_TABLES: Group = Group {
    name: "sky_tables",
    bindings: &[
        renumbered(SKY, 0),
        renumbered(SKY_TRANSMITTANCE, 1),
        renumbered(SKY_VIEW, 2),
    ],
};

/// The cloud volume's parameters and grids alone (the clouds' batch kernel).
pub const CLOUD_VOLUME: Group = Group {
    name: "cloud_volume",
    bindings: &[
        renumbered(CLOUDS, 0),
        renumbered(CLOUD_DENSITY, 1),
        renumbered(CLOUD_MAX, 2),
    ],
};

/// Every group, for the include step.
pub const GROUPS: [Group; 25] = [
    FRAME,
    QUEUE,
    FREE_FORMS,
    WORK,
    SHADING,
    SHADING_FOG,
    SHADING_SKY,
    SHADING_FOG_SKY,
    SHADING_CLOUDS,
    SHADING_FOG_CLOUDS,
    SHADING_SKY_CLOUDS,
    SHADING_FOG_SKY_CLOUDS,
    CLOUD_VOLUME,
    TERRAINS,
    TERRAINS_MESHES,
    TARGETS,
    REBASE,
    BATCH,
    FOG_LAYER,
    SKY_TABLES,
    MESHES,
    TEXTURES,
    TERRAINS_TEXTURES,
    MESHES_TEXTURES,
    TERRAINS_MESHES_TEXTURES,
];

/// The rows of a data texture (an `Rgba32Uint` texture read with `textureLoad`, how the meshes'
/// and the textures' arrays reach the shade pass without storage buffers) of `texels` texels,
/// `width` a row — or [`GpuError::TooLarge`], named `what` (the row, the rows), where either
/// exceeds the device's 2D texture side.
pub fn data_texture_rows(
    texels: u64,
    width: u32,
    what: [&'static str; 2],
    limits: &wgpu::Limits,
) -> Result<u32, crate::GpuError> {
    let w = u64::from(width);
    let rows = texels.div_ceil(w).max(1);
    let limit = u64::from(limits.max_texture_dimension_2d);
    for (what, needed) in what.into_iter().zip([w, rows]) {
        if needed > limit {
            return Err(crate::GpuError::TooLarge {
                what,
                needed,
                limit,
            });
        }
    }
    Ok(rows as u32)
}

/// An empty data texture of `width × rows` texels (its rows from [`data_texture_rows`]), for
/// `textureLoad` and written by copies; charged to `charges` first.
pub fn data_texture(
    ctx: &GpuContext,
    charges: &mut crate::DeviceCharges,
    label: &'static str,
    width: u32,
    rows: u32,
) -> Result<wgpu::Texture, crate::GpuError> {
    // Rgba32Uint: 16 bytes a texel.
    charges.charge_uploaded(label, u64::from(width) * u64::from(rows) * 16)?;
    Ok(ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height: rows,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Uint,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    }))
}

impl Group {
    /// The WGSL declarations of the group's bindings as group `index`.
    pub fn declarations(&self, index: u32) -> String {
        let mut s = format!(
            "// Bind group {index} ({}), generated by fray_gpu::bindings.\n",
            self.name
        );
        for b in self.bindings {
            let at = format!("@group({index}) @binding({})", b.binding);
            let line = match b.access {
                Access::Uniform => format!("{at} var<uniform> {}: {};\n", b.name, b.wgsl),
                StorageRead => format!("{at} var<storage, read> {}: {};\n", b.name, b.wgsl),
                StorageReadWrite => {
                    format!("{at} var<storage, read_write> {}: {};\n", b.name, b.wgsl)
                }
                Access::Texture(_) => format!(
                    "{at} var {}: texture_storage_2d<{}, write>;\n",
                    b.name, b.wgsl
                ),
                Access::Sampled | Access::Sampled3d | Access::SampledUint => {
                    format!("{at} var {}: {};\n", b.name, b.wgsl)
                }
            };
            s.push_str(&line);
        }
        s
    }

    /// The wgpu layout entries of the group (compute stage).
    pub fn layout_entries(&self) -> Vec<wgpu::BindGroupLayoutEntry> {
        self.bindings
            .iter()
            .map(|b| wgpu::BindGroupLayoutEntry {
                binding: b.binding,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: match b.access {
                    Access::Uniform => buffer(wgpu::BufferBindingType::Uniform),
                    StorageRead => buffer(wgpu::BufferBindingType::Storage { read_only: true }),
                    StorageReadWrite => {
                        buffer(wgpu::BufferBindingType::Storage { read_only: false })
                    }
                    Access::Texture(format) => wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    Access::Sampled => wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    Access::Sampled3d => wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D3,
                        multisampled: false,
                    },
                    Access::SampledUint => wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Uint,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                },
                count: None,
            })
            .collect()
    }

    /// Storage buffers the group binds.
    pub fn storage_buffers(&self) -> u32 {
        self.bindings
            .iter()
            .filter(|b| matches!(b.access, StorageRead | StorageReadWrite))
            .count() as u32
    }

    /// Sampled textures the group binds.
    pub fn sampled_textures(&self) -> u32 {
        self.bindings
            .iter()
            .filter(|b| {
                matches!(
                    b.access,
                    Access::Sampled | Access::Sampled3d | Access::SampledUint
                )
            })
            .count() as u32
    }

    /// Uniform buffers the group binds.
    pub fn uniform_buffers(&self) -> u32 {
        self.bindings.iter().filter(|b| b.access == Uniform).count() as u32
    }

    /// The bind-group layout on `device`.
    pub fn layout(&self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(self.name),
            entries: &self.layout_entries(),
        })
    }

    /// A bind group of `resources`, in the group's binding order.
    pub fn bind(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        resources: &[wgpu::BindingResource<'_>],
    ) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry> = self
            .bindings
            .iter()
            .zip(resources)
            .map(|(b, r)| wgpu::BindGroupEntry {
                binding: b.binding,
                resource: r.clone(),
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.name),
            layout,
            entries: &entries,
        })
    }
}

fn buffer(ty: wgpu::BufferBindingType) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty,
        has_dynamic_offset: false,
        min_binding_size: None,
    }
}

/// A buffer holding `data` (or the single element `fill` when `data` is empty: WebGPU has no
/// empty bindings) with `usage`, checked against the device's limits first.
pub(crate) fn upload<T: Pod>(
    ctx: &GpuContext,
    label: &'static str,
    data: &[T],
    fill: T,
    usage: wgpu::BufferUsages,
) -> Result<wgpu::Buffer, crate::GpuError> {
    let data: std::borrow::Cow<[T]> = if data.is_empty() {
        std::borrow::Cow::Owned(vec![fill])
    } else {
        std::borrow::Cow::Borrowed(data)
    };
    let bytes = std::mem::size_of_val(data.as_ref()) as u64;
    check_buffer(ctx, label, bytes, usage)?;
    Ok(ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::cast_slice(&data),
            usage,
        }))
}

/// An empty buffer of `bytes` with `usage`, checked against the device's limits first.
pub(crate) fn empty(
    ctx: &GpuContext,
    label: &'static str,
    bytes: u64,
    usage: wgpu::BufferUsages,
) -> Result<wgpu::Buffer, crate::GpuError> {
    check_buffer(ctx, label, bytes, usage)?;
    Ok(ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: empty_buffer_size(bytes),
        usage,
        mapped_at_creation: false,
    }))
}

/// The size [`empty`] allocates for `bytes`: at least 16, so that an empty array still binds.
pub(crate) fn empty_buffer_size(bytes: u64) -> u64 {
    bytes.max(16)
}

/// Refuses a buffer the device cannot hold or bind: larger than `max_buffer_size`, a storage
/// buffer larger than `max_storage_buffer_binding_size`, a uniform larger than
/// `max_uniform_buffer_binding_size`.
pub(crate) fn check_buffer(
    ctx: &GpuContext,
    what: &'static str,
    bytes: u64,
    usage: wgpu::BufferUsages,
) -> Result<(), crate::GpuError> {
    let limits = &ctx.limits;
    let mut limit = limits.max_buffer_size;
    if usage.contains(wgpu::BufferUsages::STORAGE) {
        limit = limit.min(limits.max_storage_buffer_binding_size);
    }
    if usage.contains(wgpu::BufferUsages::UNIFORM) {
        limit = limit.min(limits.max_uniform_buffer_binding_size);
    }
    if bytes > limit {
        return Err(crate::GpuError::TooLarge {
            what,
            needed: bytes,
            limit,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_have_unique_bindings_and_fit_the_default_limits() {
        let defaults = wgpu::Limits::default();
        for g in GROUPS {
            let mut seen = std::collections::HashSet::new();
            for b in g.bindings {
                assert!(
                    seen.insert(b.binding),
                    "{}: binding {} twice",
                    g.name,
                    b.binding
                );
            }
            assert_eq!(g.layout_entries().len(), g.bindings.len());
            assert!(g.declarations(2).contains("@group(2)"));
        }
        // The passes' group sets (see `passes`): storage buffers per stage within the default.
        let mut sets = vec![
            vec![FRAME, FREE_FORMS, WORK],
            vec![FRAME, WORK, TERRAINS],
            vec![FRAME, TARGETS],
            vec![REBASE],
            vec![BATCH, TERRAINS],
            vec![BATCH, FOG_LAYER],
            vec![BATCH, SKY_TABLES],
            vec![BATCH, CLOUD_VOLUME],
            vec![BATCH, MESHES],
            vec![FRAME, WORK, MESHES],
        ];
        for k in 0..64 {
            let (fog, sky, clouds) = (k & 1 != 0, k & 2 != 0, k & 4 != 0);
            let (terrain, meshes, textures) = (k & 8 != 0, k & 16 != 0, k & 32 != 0);
            let mut shade = vec![FRAME, FREE_FORMS, shading(fog, sky, clouds, false)];
            shade.extend(surfaces(terrain, meshes, textures));
            sets.push(shade);
            sets.push(vec![FRAME, shading(fog, sky, clouds, false)]);
        }
        // Whitted's passes; its shade pass is the one past the defaults, by its records
        // (checked against the device before upload, render.rs).
        for k in 0..64 {
            let (terrain, meshes, textures) = (k & 1 != 0, k & 2 != 0, k & 32 != 0);
            let (fog, sky, clouds) = (k & 4 != 0, k & 8 != 0, k & 16 != 0);
            let whitted = shading(fog, sky, clouds, true);
            assert_eq!(
                whitted.name,
                format!("{}_whitted", shading(fog, sky, clouds, false).name)
            );
            assert_eq!(whitted.bindings.last().map(|b| b.name), Some("secondaries"));
            assert_eq!(shading(fog, sky, clouds, true), whitted, "made once");
            let mut shade = vec![FRAME, FREE_FORMS, whitted];
            shade.extend(surfaces(terrain, meshes, textures));
            let storage: u32 = shade.iter().map(Group::storage_buffers).sum();
            assert_eq!(storage, 7 + if terrain { 2 } else { 0 });
            assert!(shade.len() as u32 <= defaults.max_bind_groups);
            let mut intersect = vec![FRAME, FREE_FORMS];
            intersect.extend(surfaces(terrain, meshes, textures));
            sets.push(intersect);
            sets.push(vec![FRAME, QUEUE]);
            sets.push(vec![FRAME, whitted]);
        }
        for set in sets {
            let storage: u32 = set.iter().map(Group::storage_buffers).sum();
            assert!(
                storage <= defaults.max_storage_buffers_per_shader_stage,
                "{storage}"
            );
            let textures: u32 = set.iter().map(Group::sampled_textures).sum();
            assert!(textures <= defaults.max_sampled_textures_per_shader_stage);
            let uniforms: u32 = set.iter().map(Group::uniform_buffers).sum();
            assert!(uniforms <= defaults.max_uniform_buffers_per_shader_stage);
            assert!(set.len() as u32 <= defaults.max_bind_groups);
        }
        // The shade pass of a scene with every kind and every medium is at the limits: four
        // groups and eight storage buffers (the meshes' arrays are a texture).
        assert_eq!(MESHES.storage_buffers(), 0);
        let full = [
            FRAME,
            FREE_FORMS,
            shading(true, true, true, false),
            TERRAINS_MESHES_TEXTURES,
        ];
        assert_eq!(
            full.iter().map(Group::storage_buffers).sum::<u32>(),
            defaults.max_storage_buffers_per_shader_stage
        );
        // The combined group declares the terrains' and the meshes' bindings under their names.
        let names = |g: Group| g.bindings.iter().map(|b| b.name).collect::<Vec<_>>();
        let mut both = names(TERRAINS);
        both.extend(names(MESHES));
        assert_eq!(names(TERRAINS_MESHES), both);
        both.extend(names(TEXTURES));
        assert_eq!(names(TERRAINS_MESHES_TEXTURES), both);
        assert_eq!(surfaces(false, false, false), None);
        assert_eq!(surfaces(true, false, false), Some(TERRAINS));
        // The textures bind no storage buffer, and a scene without them none of their
        // bindings.
        assert_eq!(TERRAINS_MESHES_TEXTURES.storage_buffers(), 2);
        for k in 0..4 {
            let g = surfaces(k & 1 != 0, k & 2 != 0, false);
            assert!(g.is_none_or(|g| g.bindings.iter().all(|b| !b.name.starts_with("texture"))));
            let t = surfaces(k & 1 != 0, k & 2 != 0, true).unwrap();
            let names = names(t);
            assert_eq!(&names[names.len() - 2..], ["texture_info", "texture_data"]);
        }
        // A scene without a medium binds none of its parameters or tables.
        assert_eq!(shading(false, false, false, false), SHADING);
        // Every combination is its own group (layouts are cached by name).
        let names: std::collections::HashSet<&str> = (0..8)
            .map(|k| shading(k & 1 != 0, k & 2 != 0, k & 4 != 0, false).name)
            .collect();
        assert_eq!(names.len(), 8);
        for k in 0..8 {
            let g = shading(k & 1 != 0, k & 2 != 0, k & 4 != 0, false);
            let has = |name: &str| g.bindings.iter().any(|b| b.name == name);
            assert_eq!(has("fog"), k & 1 != 0, "{}", g.name);
            assert_eq!(has("sky_view_table"), k & 2 != 0, "{}", g.name);
            assert_eq!(
                has("clouds") && has("cloud_density") && has("cloud_max"),
                k & 4 != 0,
                "{}",
                g.name
            );
            assert_eq!(has("cloud_density"), k & 4 != 0, "{}", g.name);
        }
        assert!(
            SHADING
                .bindings
                .iter()
                .all(|b| b.name != "fog" && !b.name.starts_with("sky"))
        );
        assert!(
            !SHADING_FOG
                .bindings
                .iter()
                .any(|b| b.name.starts_with("sky"))
        );
        assert!(!SHADING_SKY.bindings.iter().any(|b| b.name == "fog"));
    }
}
