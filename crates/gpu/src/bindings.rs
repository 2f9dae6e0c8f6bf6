//! The bind groups, one per subsystem, declared once: each [`Group`] lists its bindings with their
//! WGSL names and types, from which both the WGSL declarations (`shader::compose` inserts them
//! where a module says `// #bindings …`) and the wgpu bind-group layouts are made — the two sides
//! cannot disagree. A module's groups are numbered in the order its `#bindings` line names them,
//! which is the order its pass binds them in (a test checks every pass): pipeline layouts have no
//! gaps. Every pipeline stays within wgpu's default limits — at most 4 groups and 8 storage buffers
//! per stage (uniform arrays hold the small per-scene tables; the sky's tables, too large for a
//! uniform, are sampled textures, which have a limit of their own) — except the shade pass of a
//! Whitted scene (reflecting or transmitting materials: [`shading`] with `Feature::Whitted`), which
//! binds one more storage buffer, its secondary rays' records: a device that cannot bind nine is
//! refused before upload (`crate::render`), and the CPU renders the scene.
//!
//! The lights and materials travel with the scene's media in one group since the shade pass of a
//! scene with free forms and terrains already binds four groups: the group is made of the
//! [`Part`]s the scene has ([`shading`]: lighting, then fog, sky, clouds and Whitted's records
//! where present). A module names that group `shading` in its `#bindings` line and
//! `shader::compose` substitutes the scene's. Likewise the shade pass's fourth group holds the
//! terrains', the meshes' and the textures' parts, those the scene has ([`surfaces`]; a module
//! names it `surfaces`). Nothing is enumerated per combination: a kind or a medium adds a part.
//! The meshes and
//! the textures bind no storage buffer — the shade pass's eight are the frame's two, the free
//! forms' four and the terrains' two —: their arrays are packed into `Rgba32Uint` textures read
//! with `textureLoad`, with the sections' first texels in a uniform
//! (`crate::kinds::mesh::MeshBuffers`, `crate::textures::ResidentTextures`).

use crate::GpuContext;
use crate::features::{Feature, Features};
use bytemuck::Pod;
use fray_scene::PrimitiveKind;
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

/// What one kind or medium of a scene — or its lights and materials, or Whitted's records —
/// puts in a group that passes share: its bindings, numbered from 0 within the part. The shade
/// and media passes' groups are made of the parts the scene has ([`shading`], [`surfaces`],
/// [`group_of`]), and the resident scene binds each part's resources in the same order
/// (`crate::resident::ResidentScene::part_resources`): adding a kind or a medium adds a part, not
/// a power of two of groups.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Part {
    /// The lights (camera-relative) and materials: every scene's.
    Lighting,
    /// The fog layer (camera-relative heights, written per frame).
    Fog,
    /// The sky: its parameters (written per frame), its transmittance table (resident) and its
    /// sky-view table (written when the eye's height changes).
    Sky,
    /// The clouds: their parameters (camera-relative, written per frame), the density grid and
    /// the max grid of its blocks (resident; a single zero texel when skipping is off).
    Clouds,
    /// Whitted's per-ray records (`crate::params::GpuSecondary`), slot for slot with `paths`.
    Secondaries,
    /// The terrains (camera-relative parameters, this view's level-of-detail parameters) and
    /// their pyramids and samples, concatenated.
    Terrains,
    /// The meshes' layout — (instance count, first texel of the BVH nodes, of the triangles, of
    /// the vertices) — and every mesh array (`fray_mesh::gpu_layout`) packed into one texture of
    /// 16-byte texels, `MESH_TEXTURE_WIDTH` per row: the instance blocks first (4 texels each,
    /// relative to the reference point — the only part a moved camera rewrites), then the BVH
    /// nodes (2), the triangles (4, leaf order, anchor-relative) and the vertex attributes (2).
    Meshes,
    /// The textures' layout (`crate::textures::GpuTextureInfo`, written per frame) and every
    /// image level, material record, mapping block and ramp stop packed into one texture of
    /// 16-byte texels (`crate::textures`; the mapping blocks, camera-relative, are the only part
    /// a moved camera rewrites).
    Textures,
}

// The parts' bindings (`Part::bindings`).
const LIGHTING_BINDINGS: [Binding; 2] = [
    binding(0, "lights", "array<GpuLight, MAX_LIGHTS>", Uniform),
    binding(1, "materials", "array<GpuMaterial, MAX_MATERIALS>", Uniform),
];
const FOG_BINDINGS: [Binding; 1] = [binding(0, "fog", "GpuFog", Uniform)];
const SKY_BINDINGS: [Binding; 3] = [
    binding(0, "sky", "GpuSky", Uniform),
    binding(
        1,
        "sky_transmittance_table",
        "texture_2d<f32>",
        Access::Sampled,
    ),
    binding(2, "sky_view_table", "texture_2d<f32>", Access::Sampled),
];
const CLOUDS_BINDINGS: [Binding; 3] = [
    binding(0, "clouds", "GpuClouds", Uniform),
    binding(1, "cloud_density", "texture_3d<f32>", Access::Sampled3d),
    binding(2, "cloud_max", "texture_3d<f32>", Access::Sampled3d),
];
const SECONDARIES_BINDINGS: [Binding; 1] = [binding(
    0,
    "secondaries",
    "array<GpuSecondary>",
    StorageReadWrite,
)];
const TERRAINS_BINDINGS: [Binding; 4] = [
    binding(
        0,
        "terrains",
        "array<GpuTerrainParams, MAX_TERRAINS>",
        Uniform,
    ),
    binding(1, "terrain_lods", "array<vec4<f32>, MAX_TERRAINS>", Uniform),
    binding(2, "pyramid", "array<f32>", StorageRead),
    binding(3, "samples", "array<f32>", StorageRead),
];
const MESHES_BINDINGS: [Binding; 2] = [
    binding(0, "mesh_info", "vec4<u32>", Uniform),
    binding(1, "mesh_data", "texture_2d<u32>", Access::SampledUint),
];
const TEXTURES_BINDINGS: [Binding; 2] = [
    binding(0, "texture_info", "GpuTextureInfo", Uniform),
    binding(1, "texture_data", "texture_2d<u32>", Access::SampledUint),
];

impl Part {
    /// Its name (in a composed group's name).
    pub const fn name(self) -> &'static str {
        match self {
            Part::Lighting => "lighting",
            Part::Fog => "fog",
            Part::Sky => "sky",
            Part::Clouds => "clouds",
            Part::Secondaries => "secondaries",
            Part::Terrains => "terrains",
            Part::Meshes => "meshes",
            Part::Textures => "textures",
        }
    }

    /// Its bindings, numbered from 0.
    pub const fn bindings(self) -> &'static [Binding] {
        match self {
            Part::Lighting => &LIGHTING_BINDINGS,
            Part::Fog => &FOG_BINDINGS,
            Part::Sky => &SKY_BINDINGS,
            Part::Clouds => &CLOUDS_BINDINGS,
            Part::Secondaries => &SECONDARIES_BINDINGS,
            Part::Terrains => &TERRAINS_BINDINGS,
            Part::Meshes => &MESHES_BINDINGS,
            Part::Textures => &TEXTURES_BINDINGS,
        }
    }

    /// The part of a primitive kind's own arrays (its intersection pass's group, and its share
    /// of the shade pass's surfaces group); `None` for free forms, whose arrays are the fixed
    /// [`FREE_FORMS`] group every shading module binds.
    pub const fn of_kind(kind: PrimitiveKind) -> Option<Part> {
        match kind {
            PrimitiveKind::FreeForm => None,
            PrimitiveKind::Terrain => Some(Part::Terrains),
            PrimitiveKind::Mesh => Some(Part::Meshes),
        }
    }

    /// The group of this part alone, named `name`.
    pub const fn alone(self, name: &'static str) -> Group {
        Group {
            name,
            bindings: self.bindings(),
        }
    }
}

/// The group of `parts` in order, their bindings numbered on from one part to the next; named by
/// its parts (`lighting+fog+sky`), made once per distinct list and kept for the process, as the
/// constant groups are (pipeline layouts are cached by a group's name).
pub fn group_of(parts: &[Part]) -> Group {
    static MADE: std::sync::Mutex<Vec<Group>> = std::sync::Mutex::new(Vec::new());
    let name = parts.iter().map(|p| p.name()).collect::<Vec<_>>().join("+");
    let mut made = MADE.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some(g) = made.iter().find(|g| g.name == name) {
        return *g;
    }
    let bindings: Vec<Binding> = parts
        .iter()
        .flat_map(|p| p.bindings())
        .enumerate()
        .map(|(index, b)| Binding {
            binding: index as u32,
            ..*b
        })
        .collect();
    let g = Group {
        name: Box::leak(name.into_boxed_str()),
        bindings: Box::leak(bindings.into_boxed_slice()),
    };
    made.push(g);
    g
}

/// The parts of the lights-and-media group of a scene with `features`: the lights, then its
/// media's parts (fog, sky, clouds), then Whitted's records where its materials reflect or
/// transmit (last).
pub fn shading_parts(features: Features) -> Vec<Part> {
    let mut parts = vec![Part::Lighting];
    for (feature, part) in [
        (Feature::Fog, Part::Fog),
        (Feature::Sky, Part::Sky),
        (Feature::Clouds, Part::Clouds),
        (Feature::Whitted, Part::Secondaries),
    ] {
        if features.has(feature) {
            parts.push(part);
        }
    }
    parts
}

/// The lights-and-media group: what a module's `shading` stands for ([`shading_parts`]). A scene
/// without a medium binds none of its buffers or textures.
pub fn shading(features: Features) -> Group {
    group_of(&shading_parts(features))
}

/// The parts of the shade pass's group of what a scene has beyond free forms: each kind's own
/// part (`Part::of_kind`) in kind order, then its textures' (empty without any of them).
pub fn surface_parts(features: Features) -> Vec<Part> {
    let kinds = PrimitiveKind::ALL
        .into_iter()
        .filter(|k| features.has_kind(*k))
        .filter_map(Part::of_kind);
    let textures = features.has(Feature::Textures).then_some(Part::Textures);
    kinds.chain(textures).collect()
}

/// The shade pass's group of what a scene has beyond free forms (what a module's `surfaces`
/// stands for, [`surface_parts`]), or none without any of it.
pub fn surfaces(features: Features) -> Option<Group> {
    let parts = surface_parts(features);
    (!parts.is_empty()).then(|| group_of(&parts))
}

/// Whitted's queue passes (`crate::passes::whitted`): the indirect dispatch arguments of the
/// current level (x, y, z workgroups), written on the GPU from the queue's state.
pub const QUEUE: Group = Group {
    name: "queue",
    bindings: &[binding(0, "queue_args", "array<u32, 4>", StorageReadWrite)],
};

/// The terrains alone: the terrain intersection pass's and the terrain batch kernel's.
pub const TERRAINS: Group = Part::Terrains.alone("terrains");

/// The meshes alone (read by `mesh.wgsl`): the mesh intersection pass's and the mesh batch
/// kernel's. The vertices are read only for surfaces (`mesh_surface`).
pub const MESHES: Group = Part::Meshes.alone("meshes");

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
pub const FOG_LAYER: Group = Part::Fog.alone("fog_layer");

/// The sky's parameters and tables alone (the sky's batch kernel).
pub const SKY_TABLES: Group = Part::Sky.alone("sky_tables");

/// The cloud volume's parameters and grids alone (the clouds' batch kernel).
pub const CLOUD_VOLUME: Group = Part::Clouds.alone("cloud_volume");

/// Every group, for the include step.
pub const GROUPS: [Group; 12] = [
    FRAME,
    QUEUE,
    FREE_FORMS,
    WORK,
    TERRAINS,
    MESHES,
    TARGETS,
    REBASE,
    BATCH,
    FOG_LAYER,
    SKY_TABLES,
    CLOUD_VOLUME,
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

/// Writes `data` (16-byte texels) into `texture` from texel `first` on, row-major with
/// [`crate::params::DATA_TEXTURE_WIDTH`] per row: a partial first row, whole rows, a partial last
/// row — no texel outside the range is touched. Returns the bytes written.
pub(crate) fn write_texels(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    first: u64,
    data: &[[u32; 4]],
) -> u64 {
    let w = u64::from(crate::params::DATA_TEXTURE_WIDTH);
    let mut at = first;
    let mut rest = data;
    let write = |x: u64, y: u64, width: u64, rows: u64, texels: &[[u32; 4]]| {
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: x as u32,
                    y: y as u32,
                    z: 0,
                },
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(texels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some((width * 16) as u32),
                rows_per_image: Some(rows as u32),
            },
            wgpu::Extent3d {
                width: width as u32,
                height: rows as u32,
                depth_or_array_layers: 1,
            },
        );
    };
    let x = at % w;
    if x != 0 && !rest.is_empty() {
        let n = (w - x).min(rest.len() as u64);
        write(x, at / w, n, 1, &rest[..n as usize]);
        at += n;
        rest = &rest[n as usize..];
    }
    let rows = rest.len() as u64 / w;
    if rows > 0 {
        let n = (rows * w) as usize;
        write(0, at / w, w, rows, &rest[..n]);
        at += rows * w;
        rest = &rest[n..];
    }
    if !rest.is_empty() {
        write(0, at / w, rest.len() as u64, 1, rest);
    }
    std::mem::size_of_val(data) as u64
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

    /// The lights-and-media group with (or without) each medium and Whitted's records.
    fn shading(fog: bool, sky: bool, clouds: bool, whitted: bool) -> Group {
        let features = Features::NONE
            .with_if(Feature::Fog, fog)
            .with_if(Feature::Sky, sky)
            .with_if(Feature::Clouds, clouds)
            .with_if(Feature::Whitted, whitted);
        super::shading(features)
    }

    /// The surfaces group with (or without) terrains, meshes and textures.
    fn surfaces(terrain: bool, meshes: bool, textures: bool) -> Option<Group> {
        let features = Features::NONE
            .with_if(Feature::Kind(PrimitiveKind::Terrain), terrain)
            .with_if(Feature::Kind(PrimitiveKind::Mesh), meshes)
            .with_if(Feature::Textures, textures);
        super::surfaces(features)
    }

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
                format!("{}+secondaries", shading(fog, sky, clouds, false).name)
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
        let every_surface = surfaces(true, true, true).unwrap();
        let full = [
            FRAME,
            FREE_FORMS,
            shading(true, true, true, false),
            every_surface,
        ];
        assert_eq!(
            full.iter().map(Group::storage_buffers).sum::<u32>(),
            defaults.max_storage_buffers_per_shader_stage
        );
        // A composed group declares its parts' bindings under their names, in order, numbered on
        // from one part to the next.
        let names = |g: Group| g.bindings.iter().map(|b| b.name).collect::<Vec<_>>();
        let mut all = names(TERRAINS);
        all.extend(names(MESHES));
        assert_eq!(names(surfaces(true, true, false).unwrap()), all);
        all.extend(Part::Textures.bindings().iter().map(|b| b.name));
        assert_eq!(names(every_surface), all);
        assert!(
            every_surface
                .bindings
                .iter()
                .enumerate()
                .all(|(k, b)| b.binding == k as u32)
        );
        assert_eq!(surfaces(false, false, false), None);
        assert_eq!(
            surfaces(true, false, false).unwrap().bindings,
            TERRAINS.bindings
        );
        // The textures bind no storage buffer, and a scene without them none of their
        // bindings.
        assert_eq!(every_surface.storage_buffers(), 2);
        for k in 0..4 {
            let g = surfaces(k & 1 != 0, k & 2 != 0, false);
            assert!(g.is_none_or(|g| g.bindings.iter().all(|b| !b.name.starts_with("texture"))));
            let t = surfaces(k & 1 != 0, k & 2 != 0, true).unwrap();
            let names = names(t);
            assert_eq!(&names[names.len() - 2..], ["texture_info", "texture_data"]);
        }
        // A scene without a medium binds none of its parameters or tables: lights and materials.
        assert_eq!(
            names(shading(false, false, false, false)),
            ["lights", "materials"]
        );
        // Every combination is its own group (layouts are cached by name), made once.
        let names: std::collections::HashSet<&str> = (0..8)
            .map(|k| shading(k & 1 != 0, k & 2 != 0, k & 4 != 0, false).name)
            .collect();
        assert_eq!(names.len(), 8);
        for k in 0..8 {
            let g = shading(k & 1 != 0, k & 2 != 0, k & 4 != 0, false);
            assert_eq!(shading(k & 1 != 0, k & 2 != 0, k & 4 != 0, false), g);
            let has = |name: &str| g.bindings.iter().any(|b| b.name == name);
            assert_eq!(has("fog"), k & 1 != 0, "{}", g.name);
            assert_eq!(
                has("sky") && has("sky_transmittance_table") && has("sky_view_table"),
                k & 2 != 0,
                "{}",
                g.name
            );
            assert_eq!(
                has("clouds") && has("cloud_density") && has("cloud_max"),
                k & 4 != 0,
                "{}",
                g.name
            );
            assert_eq!(has("cloud_density"), k & 4 != 0, "{}", g.name);
        }
    }
}
