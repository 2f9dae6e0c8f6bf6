//! Textures on the GPU: each material's image (every level of the mip chain the CPU samples,
//! `fray_mesh::texture::Texture::levels`: one source of truth), its wrap, filter and projected
//! mapping, and its colour ramp, packed into one `Rgba32Uint` texture of 16-byte texels read
//! with `textureLoad` — [`TEXTURE_DATA_WIDTH`] texels a row, as the meshes' arrays — and a small
//! uniform ([`GpuTextureInfo`]) saying where each section starts. No storage buffer: the shade
//! pass already binds the eight WebGPU allows (`bindings`). The filtering is written by hand in
//! `shaders/texture.wgsl`, the f32 twin of `fray_mesh::texture`'s nearest, bilinear and
//! trilinear lookups, wrap modes and footprint rule.
//!
//! The texture's sections, in texels:
//! 1. the mapping blocks, one [`GpuMapping`] (5 texels) per material (the scene's materials and
//!    then the default one, as `params::materials`), their origins **relative to the camera**
//!    from f64: rewritten, alone, for a moved camera ([`ResidentTextures::move_to`]);
//! 2. the material records, one [`GpuTextureMaterial`] (3 texels) per material;
//! 3. the level records, one [`GpuTextureLevel`] per level of every distinct image (a file
//!    named by several materials is uploaded once);
//! 4. the texels of every level, row-major from the top row, as RGBA `f32` bits (grey
//!    replicated, a missing alpha 1: what `MipLevel::texel` returns);
//! 5. the ramps' stops, two texels each: `(key, 0, 0, 0)` and the RGBA colour.
//!
//! A scene without textures or ramps allocates, binds and compiles none of this
//! (`ModuleOptions::textures`, `if textures` includes). The bytes are checked against the
//! memory budget before the host copy is built and the rows against the device's 2D texture
//! limit before the texture is made.

use crate::bindings;
use crate::bindings::write_texels;
pub use crate::texture_layout::*;
use crate::{GpuContext, GpuError};
use fray_core::MemoryBudget;
use fray_mesh::Texture;
use fray_mesh::texture::gpu_layout::{GpuMapping, MAPPING_NONE};
use fray_mesh::texture::{Filter, Mapping, Ramp, WrapMode};
use fray_scene::{Material, Scene};
use glam::DVec3;
use std::sync::Arc;

fn wrap_code(m: WrapMode) -> u32 {
    match m {
        WrapMode::Repeat => TEXTURE_WRAP_REPEAT,
        WrapMode::Clamp => TEXTURE_WRAP_CLAMP,
        WrapMode::Mirror => TEXTURE_WRAP_MIRROR,
    }
}

fn filter_code(f: Filter) -> u32 {
    match f {
        Filter::Nearest => TEXTURE_FILTER_NEAREST,
        Filter::Bilinear => TEXTURE_FILTER_BILINEAR,
        Filter::Trilinear => TEXTURE_FILTER_TRILINEAR,
    }
}

/// A scene's textures laid out for the GPU (host side).
#[derive(Clone, Debug)]
pub struct TextureLayout {
    /// Each material's mapping (the default material last), for the camera-relative blocks.
    pub mappings: Vec<Option<Mapping>>,
    pub materials: Vec<GpuTextureMaterial>,
    pub levels: Vec<GpuTextureLevel>,
    /// Every level's texels, then the ramps' stops (16-byte texels).
    pub data: Vec<[u32; 4]>,
    /// [`GpuTextureInfo::sections`].
    pub sections: [u32; 4],
}

impl TextureLayout {
    /// The textures and ramps of `scene`'s materials (every material that has one, used or
    /// not; each distinct image once), their bytes checked against `budget` before the host
    /// copy is built.
    pub fn build(scene: &Scene, budget: &MemoryBudget) -> Result<Self, GpuError> {
        let default = Material::default();
        let all: Vec<&Material> = scene
            .materials
            .iter()
            .chain(std::iter::once(&default))
            .collect();
        // The distinct images, in first-use order.
        let mut images: Vec<&Arc<Texture>> = Vec::new();
        for m in &all {
            if let Some(slot) = &m.texture
                && !images.iter().any(|t| Arc::ptr_eq(t, &slot.texture))
            {
                images.push(&slot.texture);
            }
        }
        let level_count: u64 = images.iter().map(|t| t.level_count() as u64).sum();
        let image_texels: u64 = images
            .iter()
            .flat_map(|t| t.levels())
            .map(|l| u64::from(l.width()) * u64::from(l.height()))
            .sum();
        let stops: u64 = all
            .iter()
            .filter_map(|m| m.ramp.as_ref())
            .map(|r| {
                (r.height.stops().count() + r.slope.as_ref().map_or(0, |s| s.stops().count()))
                    as u64
            })
            .sum();
        let n = all.len() as u64;
        let materials_at = n * MAPPING_TEXELS;
        let levels_at = materials_at + n * MATERIAL_TEXELS;
        let texels_at = levels_at + level_count;
        let ramps_at = texels_at + image_texels;
        let total = ramps_at + 2 * stops;
        budget
            .check(
                format!("the GPU texture data ({total} texels of 16 bytes)"),
                total.saturating_mul(16),
            )
            .map_err(GpuError::Budget)?;
        let index = |v: u64| {
            u32::try_from(v).map_err(|_| GpuError::TooLarge {
                what: "texels of the texture data",
                needed: total,
                limit: u32::MAX.into(),
            })
        };
        index(total)?;
        let mut levels = Vec::with_capacity(level_count as usize);
        let mut data: Vec<[u32; 4]> = Vec::with_capacity((image_texels + 2 * stops) as usize);
        let mut first_level = Vec::with_capacity(images.len());
        for t in &images {
            first_level.push(levels.len() as u32);
            for l in t.levels() {
                levels.push(GpuTextureLevel {
                    first: index(texels_at + data.len() as u64)?,
                    width: l.width(),
                    height: l.height(),
                    pad: 0,
                });
                for y in 0..l.height() {
                    for x in 0..l.width() {
                        data.push(l.texel(x, y).to_array().map(f32::to_bits));
                    }
                }
            }
        }
        let push_ramp = |r: &Ramp, data: &mut Vec<[u32; 4]>| -> Result<(u32, u32), GpuError> {
            let first = index(texels_at + data.len() as u64)?;
            let mut count = 0;
            for (key, colour) in r.stops() {
                data.push([(key as f32).to_bits(), 0, 0, 0]);
                data.push(colour.to_array().map(f32::to_bits));
                count += 1;
            }
            Ok((first, count))
        };
        let mut materials = Vec::with_capacity(all.len());
        let mut mappings = Vec::with_capacity(all.len());
        for m in &all {
            let mut record = GpuTextureMaterial::default();
            let mut mapping = None;
            if let Some(slot) = &m.texture {
                let k = images
                    .iter()
                    .position(|t| Arc::ptr_eq(t, &slot.texture))
                    .unwrap_or(0);
                record.flags |= TEXTURE_FLAG_IMAGE;
                record.mapping = slot.mapping.map_or(MAPPING_NONE, |m| m.gpu_kind());
                record.filter_mode = filter_code(slot.filter);
                record.first_level = first_level[k];
                record.level_count = slot.texture.level_count() as u32;
                record.wrap_u = wrap_code(slot.wrap.u);
                record.wrap_v = wrap_code(slot.wrap.v);
                record.texels_per_uv = slot.texture.texels_per_uv() as f32;
                mapping = slot.mapping;
            }
            if let Some(ramp) = &m.ramp {
                record.flags |= TEXTURE_FLAG_RAMP;
                (record.height_first, record.height_count) = push_ramp(&ramp.height, &mut data)?;
                if let Some(s) = &ramp.slope {
                    (record.slope_first, record.slope_count) = push_ramp(s, &mut data)?;
                }
            }
            materials.push(record);
            mappings.push(mapping);
        }
        Ok(Self {
            mappings,
            materials,
            levels,
            data,
            sections: [
                index(materials_at)?,
                index(levels_at)?,
                index(texels_at)?,
                index(ramps_at)?,
            ],
        })
    }

    /// Every texel of the texture data.
    pub fn texels(&self) -> u64 {
        u64::from(self.sections[2]) + self.data.len() as u64
    }

    /// The mapping blocks relative to `reference` (the camera's point, f64), one per material
    /// (zeros where it has none).
    pub fn mappings_at(&self, reference: DVec3) -> Vec<GpuMapping> {
        self.mappings
            .iter()
            .map(|m| m.map_or(GpuMapping::default(), |m| m.gpu(reference)))
            .collect()
    }

    /// The uniform for a view from `reference`.
    pub fn info(&self, reference: DVec3) -> GpuTextureInfo {
        let hi = reference.y as f32;
        let lo = (reference.y - f64::from(hi)) as f32;
        GpuTextureInfo {
            sections: self.sections,
            reference: [hi, lo, 0.0, 0.0],
        }
    }
}

/// The rows of a data texture of `texels` texels, [`TEXTURE_DATA_WIDTH`] a row, or
/// [`GpuError::TooLarge`] where the row or the rows exceed the device's 2D texture side.
pub fn data_rows(texels: u64, limits: &wgpu::Limits) -> Result<u32, GpuError> {
    crate::bindings::data_texture_rows(
        texels,
        TEXTURE_DATA_WIDTH,
        [
            "texels per row of the texture data",
            "rows of the texture data (4096 texels of 16 bytes each)",
        ],
        limits,
    )
}

/// A scene's textures on the GPU: the layout uniform and the data texture.
#[derive(Debug)]
pub struct ResidentTextures {
    pub layout: TextureLayout,
    pub info: wgpu::Buffer,
    pub texture: wgpu::Texture,
    /// The point (world, f64) the mapping blocks and the uniform are written for.
    pub reference: DVec3,
    /// Bytes uploaded.
    pub bytes: u64,
}

impl ResidentTextures {
    /// Uploads `layout` for a view from `reference`, its rows checked against the device's 2D
    /// texture limit first.
    pub fn upload(
        ctx: &GpuContext,
        charges: &mut crate::DeviceCharges,
        layout: TextureLayout,
        reference: DVec3,
    ) -> Result<Self, GpuError> {
        use wgpu::BufferUsages as U;
        let rows = data_rows(layout.texels(), &ctx.limits)?;
        let info = charges.upload(
            ctx,
            "texture layout",
            &[layout.info(reference)],
            GpuTextureInfo::default(),
            U::UNIFORM | U::COPY_DST,
        )?;
        let texture = bindings::data_texture(ctx, charges, "textures", TEXTURE_DATA_WIDTH, rows)?;
        let mut bytes = std::mem::size_of::<GpuTextureInfo>() as u64;
        let mappings = layout.mappings_at(reference);
        bytes += write_texels(ctx, &texture, 0, bytemuck::cast_slice(&mappings));
        let [materials_at, levels_at, texels_at, _] = layout.sections.map(u64::from);
        bytes += write_texels(
            ctx,
            &texture,
            materials_at,
            bytemuck::cast_slice(&layout.materials),
        );
        bytes += write_texels(
            ctx,
            &texture,
            levels_at,
            bytemuck::cast_slice(&layout.levels),
        );
        bytes += write_texels(ctx, &texture, texels_at, &layout.data);
        Ok(Self {
            layout,
            info,
            texture,
            reference,
            bytes,
        })
    }

    /// A view of the data texture.
    pub fn view(&self) -> wgpu::TextureView {
        self.texture
            .create_view(&wgpu::TextureViewDescriptor::default())
    }

    /// Rewrites the mapping blocks and the uniform for a view from `reference` (f64), unless
    /// they already are; nothing else moves. Returns the bytes written.
    pub fn move_to(&mut self, ctx: &GpuContext, reference: DVec3) -> u64 {
        if reference == self.reference {
            return 0;
        }
        let info = self.layout.info(reference);
        ctx.queue
            .write_buffer(&self.info, 0, bytemuck::bytes_of(&info));
        let mappings = self.layout.mappings_at(reference);
        let bytes = if self.layout.mappings.iter().any(Option::is_some) {
            write_texels(ctx, &self.texture, 0, bytemuck::cast_slice(&mappings))
        } else {
            0
        };
        self.reference = reference;
        bytes + std::mem::size_of::<GpuTextureInfo>() as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_core::gpu_struct::GpuStruct;

    #[test]
    fn layouts_match_and_records_are_whole_texels() {
        GpuTextureMaterial::check_layout().unwrap();
        GpuTextureLevel::check_layout().unwrap();
        GpuTextureInfo::check_layout().unwrap();
        for size in [
            std::mem::size_of::<GpuTextureMaterial>(),
            std::mem::size_of::<GpuTextureLevel>(),
            std::mem::size_of::<GpuMapping>(),
        ] {
            assert_eq!(size % 16, 0);
        }
    }

    /// The assignments `{var}.{field} = …` of WGSL function `fn name` in `texture.wgsl`, in
    /// order, with what each reads.
    fn loader(name: &str, var: &str) -> Vec<(String, String)> {
        let text = crate::shader::file("texture.wgsl").unwrap();
        let start = text.find(&format!("fn {name}(")).unwrap();
        let body = &text[start..start + text[start..].find("\n}\n").unwrap()];
        body.lines()
            .filter_map(|l| l.trim().strip_prefix(&format!("{var}.")))
            .filter_map(|l| l.split_once(" = "))
            .map(|(f, r)| (f.to_owned(), r.trim_end_matches(';').to_owned()))
            .collect()
    }

    /// The hand-written WGSL loaders read every field of the records from the word Rust writes
    /// it to (a swapped field, or one read from the wrong texel, fails here).
    #[test]
    fn wgsl_loaders_read_the_fields_where_rust_writes_them() {
        let expect = |fields: Vec<fray_core::gpu_struct::WgslField>, got: Vec<(String, String)>| {
            let names: Vec<&str> = fields.iter().map(|f| f.name).collect();
            let read: Vec<&str> = got.iter().map(|(f, _)| f.as_str()).collect();
            assert_eq!(names, read);
            got.iter()
                .zip(&fields)
                .map(|((_, r), f)| (r.clone(), f.rust_offset))
                .collect::<Vec<_>>()
        };
        for (read, offset) in expect(
            GpuTextureMaterial::fields(),
            loader("load_texture_material", "r"),
        ) {
            let word = offset / 4;
            let lane = ["x", "y", "z", "w"][word % 4];
            assert!(
                read.contains(&format!("w{}.{lane}", word / 4)),
                "{read} at {offset}"
            );
        }
        for (read, offset) in expect(GpuTextureLevel::fields(), loader("load_texture_level", "l")) {
            assert_eq!(read, format!("w0.{}", ["x", "y", "z", "w"][offset / 4]));
        }
        for (read, offset) in expect(GpuMapping::fields(), loader("load_texture_mapping", "g")) {
            let texel = offset / 16;
            let expected = if texel == 0 {
                "texture_vec(at)".to_owned()
            } else {
                format!("texture_vec(at + {texel}u)")
            };
            assert_eq!(read, expected);
        }
        assert!(
            crate::shader::file("texture.wgsl")
                .unwrap()
                .contains("let at = 5u * m;")
        );
        assert_eq!(std::mem::size_of::<GpuMapping>(), 5 * 16);
        assert_eq!(MAPPING_TEXELS, 5);
        assert_eq!(MATERIAL_TEXELS, 3);
    }

    /// Texture data past the device's 2D texture side is refused, naming the rows; at the
    /// limit it is not.
    #[test]
    fn data_past_the_device_limit_is_refused() {
        let limits = wgpu::Limits {
            max_texture_dimension_2d: 8192,
            ..wgpu::Limits::default()
        };
        let w = u64::from(TEXTURE_DATA_WIDTH);
        assert_eq!(data_rows(0, &limits).unwrap(), 1);
        assert_eq!(data_rows(8192 * w, &limits).unwrap(), 8192);
        match data_rows(8192 * w + 1, &limits) {
            Err(GpuError::TooLarge {
                what,
                needed,
                limit,
            }) => {
                assert!(what.contains("rows of the texture data"), "{what}");
                assert_eq!((needed, limit), (8193, 8192));
            }
            other => panic!("expected TooLarge, got {other:?}"),
        }
        let narrow = wgpu::Limits {
            max_texture_dimension_2d: 2048,
            ..limits
        };
        assert!(matches!(
            data_rows(1, &narrow),
            Err(GpuError::TooLarge { what, .. }) if what.contains("per row")
        ));
    }

    /// The WGSL's constants are fray_mesh's.
    #[test]
    fn wgsl_constants_are_the_reference_ones() {
        let text = crate::shader::file("texture.wgsl").unwrap();
        let value = |name: &str| -> f64 {
            let line = text
                .lines()
                .find(|l| l.starts_with(&format!("const {name}: f32 = ")))
                .unwrap();
            line.split(" = ")
                .nth(1)
                .unwrap()
                .trim_end_matches(';')
                .parse()
                .unwrap()
        };
        assert_eq!(
            value("TEXTURE_MAX_ANISOTROPY"),
            fray_mesh::texture::Footprint::DEFAULT_MAX_ANISOTROPY
        );
        assert_eq!(
            value("TEXTURE_SNAP") as f32,
            (1.0f64 / (1u64 << 30) as f64) as f32
        );
        assert_eq!(value("TEXTURE_TAU") as f32, std::f32::consts::TAU);
        assert_eq!(value("TEXTURE_F32_MAX") as f32, f32::MAX);
    }
}
