//! Resolving a material's `texture` and `ramp`: the image is loaded once per file (relative to
//! the scene file, budget-checked from its header before decoding), the mapping built and
//! checked; a bad file is reported at `texture.path` with its path and the reason, a bad mapping
//! parameter at its field.

use crate::assets::LoadedAssets;
use crate::checks::{Invalid, Result, invalid, point};
use crate::description::{self, TextureFilter, TextureMapping, TextureWrap};
use crate::path::FieldPath;
use fray_core::MemoryBudget;
use fray_mesh::Texture;
use fray_mesh::texture::{
    Cylindrical, Encoding, Filter, Mapping, Planar, Ramp, Spherical, TerrainRamp, TextureError,
    Triplanar, Wrap, WrapMode,
};
use glam::{DVec2, Vec4};
use std::path::Path;
use std::sync::Arc;

/// A material's texture, ready to sample.
#[derive(Clone, Debug)]
pub struct TextureSlot {
    /// The image and its mip chain (shared by every material naming the file).
    pub texture: Arc<Texture>,
    /// How surfaces map to it; `None`: the surface's own uv (meshes' UVs, terrains' drape).
    pub mapping: Option<Mapping>,
    pub wrap: Wrap,
    pub filter: Filter,
}

impl PartialEq for TextureSlot {
    fn eq(&self, o: &Self) -> bool {
        Arc::ptr_eq(&self.texture, &o.texture)
            && self.mapping == o.mapping
            && self.wrap == o.wrap
            && self.filter == o.filter
    }
}

/// The texture slot `t` describes (`path` is its field path): its image loaded once per file
/// and encoding in a load (`assets`), however many materials — or resolves — use it.
pub(crate) fn slot(
    path: &FieldPath,
    t: &description::MaterialTexture,
    base: &Path,
    budget: &MemoryBudget,
    assets: &mut LoadedAssets,
) -> Result<TextureSlot> {
    let mapping = mapping(&path.field("mapping"), &t.mapping)?;
    let file = base.join(&t.path);
    let key = (
        std::fs::canonicalize(&file).unwrap_or_else(|_| file.clone()),
        t.linear,
    );
    let texture = assets.textures.get_or_build(
        key,
        budget,
        || format!("the texture {}", file.display()),
        || {
            let encoding = if t.linear {
                Encoding::Linear
            } else {
                Encoding::Srgb
            };
            Texture::load(&file, encoding, budget)
                .or_else(|e| invalid(&path.field("path"), e.to_string()))
        },
        |e| Invalid {
            path: path.field("path"),
            message: e.to_string(),
        },
    )?;
    Ok(TextureSlot {
        texture,
        mapping,
        wrap: Wrap::both(match t.wrap {
            TextureWrap::Repeat => WrapMode::Repeat,
            TextureWrap::Clamp => WrapMode::Clamp,
            TextureWrap::Mirror => WrapMode::Mirror,
        }),
        filter: match t.filter {
            TextureFilter::Trilinear => Filter::Trilinear,
            TextureFilter::Bilinear => Filter::Bilinear,
            TextureFilter::Nearest => Filter::Nearest,
        },
    })
}

/// A mapping's parameter error at its field (`scale.y` → `…mapping.scale[1]`-style names are
/// the texture crate's own: reported as given).
fn parameter<T>(path: &FieldPath, e: TextureError) -> Result<T> {
    match e {
        TextureError::Parameter { name, message } => invalid(&path.field(name), message),
        other => invalid(path, other.to_string()),
    }
}

fn mapping(path: &FieldPath, m: &TextureMapping) -> Result<Option<Mapping>> {
    let p = |name: &str, v| point(&path.field(name), v);
    Ok(Some(match m {
        TextureMapping::Uv => return Ok(None),
        TextureMapping::Planar {
            origin,
            u_axis,
            v_axis,
            scale,
        } => Mapping::Planar(
            Planar::new(
                p("origin", *origin)?,
                p("u_axis", *u_axis)?,
                p("v_axis", *v_axis)?,
                DVec2::from(*scale),
            )
            .or_else(|e| parameter(path, e))?,
        ),
        TextureMapping::Spherical {
            centre,
            pole,
            seam,
            repeat,
        } => Mapping::Spherical(
            Spherical::new(
                p("centre", *centre)?,
                p("pole", *pole)?,
                p("seam", *seam)?,
                DVec2::from(*repeat),
            )
            .or_else(|e| parameter(path, e))?,
        ),
        TextureMapping::Cylindrical {
            origin,
            axis,
            seam,
            repeat,
            scale,
        } => Mapping::Cylindrical(
            Cylindrical::new(
                p("origin", *origin)?,
                p("axis", *axis)?,
                p("seam", *seam)?,
                *repeat,
                *scale,
            )
            .or_else(|e| parameter(path, e))?,
        ),
        TextureMapping::Triplanar {
            origin,
            scale,
            sharpness,
        } => Mapping::Triplanar(
            Triplanar::new(p("origin", *origin)?, *scale, *sharpness)
                .or_else(|e| parameter(path, e))?,
        ),
    }))
}

/// A terrain colour ramp: heights in world units, slopes given in degrees (radians here).
pub(crate) fn ramp(path: &FieldPath, r: &description::ColourRamp) -> Result<TerrainRamp> {
    let colour = |c: [f64; 4]| Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32);
    let height = Ramp::new(
        r.height
            .iter()
            .map(|&(h, c)| (h, colour([c[0], c[1], c[2], 1.0])))
            .collect(),
    )
    .or_else(|e| invalid(&path.field("height"), e.to_string()))?;
    let slope = if r.slope.is_empty() {
        None
    } else {
        if let Some(&(deg, _)) = r.slope.iter().find(|(d, _)| !(0.0..=90.0).contains(d)) {
            return invalid(
                &path.field("slope"),
                format!("slopes are degrees in [0, 90], got {deg}"),
            );
        }
        Some(
            Ramp::new(
                r.slope
                    .iter()
                    .map(|&(d, c)| (d.to_radians(), colour(c)))
                    .collect(),
            )
            .or_else(|e| invalid(&path.field("slope"), e.to_string()))?,
        )
    };
    Ok(TerrainRamp { height, slope })
}
