//! Resolving a `Terrain(...)` shape: the height map is loaded (relative to the scene file),
//! placed and its pyramid built here, once; a bad file is reported at the `path` field with the
//! file's path and the reason, and so is a map or pyramid over the memory budget (what, how
//! much, the limit).

use crate::description::{self, TerrainInterpolation};
use crate::path::FieldPath;
use crate::resolve::{Result, finite, invalid, point, positive};
use fray_core::MemoryBudget;
use fray_terrain::{Heightmap, Interpolation, Placement, Terrain, TerrainOptions};
use glam::{DMat3, DVec2};
use std::path::Path;

/// The deepest LOD bias accepted (a pyramid has at most 16 levels).
const MAX_LOD_BIAS: u32 = 16;

pub(crate) fn terrain(
    path: &FieldPath,
    t: &description::Terrain,
    base: &Path,
    budget: &MemoryBudget,
) -> Result<Terrain> {
    let spacing_path = path.field("spacing");
    let spacing = DVec2::new(
        positive(&spacing_path.index(0), t.spacing[0])?,
        positive(&spacing_path.index(1), t.spacing[1])?,
    );
    let vertical_scale = positive(&path.field("vertical_scale"), t.vertical_scale)?;
    let origin = point(&path.field("origin"), t.origin)?;
    let rotate = point(&path.field("rotate"), t.rotate)?;
    if t.lod_bias > MAX_LOD_BIAS {
        return invalid(
            &path.field("lod_bias"),
            format!("must be in 0..={MAX_LOD_BIAS}, got {}", t.lod_bias),
        );
    }
    let threshold = match t.threshold {
        Some(v) => Some(finite(&path.field("threshold"), v)? as f32),
        None => None,
    };
    let file = base.join(&t.path);
    let map = Heightmap::load_within(&file, budget)
        .or_else(|e| invalid(&path.field("path"), e.to_string()))?;
    let map = match threshold {
        Some(v) => map
            .with_threshold(v)
            .or_else(|e| invalid(&path.field("threshold"), e.to_string()))?,
        None => map,
    };
    let rotation = DMat3::from_rotation_z(rotate.z.to_radians())
        * DMat3::from_rotation_y(rotate.y.to_radians())
        * DMat3::from_rotation_x(rotate.x.to_radians());
    let placement = Placement::new(origin, spacing, vertical_scale)
        .and_then(|p| p.with_rotation(rotation))
        .or_else(|e| invalid(path, e.to_string()))?;
    let options = TerrainOptions {
        interpolation: match t.interpolation {
            TerrainInterpolation::Bilinear => Interpolation::Bilinear,
            TerrainInterpolation::Bicubic => Interpolation::Bicubic,
        },
        lod_bias: t.lod_bias,
        min_pyramid: false,
    };
    Terrain::new_within(map, placement, options, budget).or_else(|e| {
        let at = if t.threshold.is_some() {
            path.field("threshold")
        } else {
            path.field("path")
        };
        invalid(&at, format!("{}: {e}", file.display()))
    })
}
