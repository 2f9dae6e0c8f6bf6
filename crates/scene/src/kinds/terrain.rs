//! Height-map terrains as a primitive kind of the scene ([`crate::Scene::terrains`]).
//!
//! Resolving a `Terrain(...)` shape: the height map is loaded (relative to the scene file),
//! placed and its pyramid built here, once per file and description in a load; a bad file is
//! reported at the `path` field with the file's path and the reason, and so is a map or pyramid
//! over the memory budget (what, how much, the limit). The cell test keeps a terrain where the
//! bundle meets its box and one of its coarse max columns.

use super::kind::{CellTest, Culling, ObjectContext, SceneKind};
use crate::FeatureSet;
use crate::animation::Heights;
use crate::checks::{Invalid, Result, finite, invalid, point, positive};
use crate::description::{self, TerrainInterpolation};
use crate::path::FieldPath;
use crate::scene::{Scene, TerrainObject};
use fray_core::{Aabb, MemoryBudget};
use fray_quadtree::Candidates;
use fray_terrain::{Heightmap, Interpolation, Placement, Terrain, TerrainOptions};
use glam::{DMat3, DVec2};
use std::path::Path;
use std::sync::Arc;

/// The deepest LOD bias accepted (a pyramid has at most 16 levels).
const MAX_LOD_BIAS: u32 = 16;

fn terrain(
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

/// The terrain kind.
pub(crate) struct Terrains;

impl SceneKind for Terrains {
    fn resolve(
        &self,
        cx: &mut ObjectContext<'_>,
        scene: &mut Scene,
        path: &FieldPath,
        object: &description::Object,
        name: String,
    ) -> Result<()> {
        let description::Shape::Terrain(t) = &object.shape else {
            return invalid(&path.field("shape"), "expected a Terrain");
        };
        let material = cx.object_material(path, object)?;
        let file = cx.base.join(&t.path);
        // The base terrain does not depend on how it moves: objects that differ only there
        // share it.
        let still = description::Terrain {
            animate: None,
            ..t.clone()
        };
        let key = (
            std::fs::canonicalize(&file).unwrap_or(file),
            format!("{still:?}"),
        );
        let (base, budget) = (cx.base, cx.budget);
        let terrain = cx.assets.terrains.get_or_build(
            key,
            budget,
            || format!("the terrain {}", t.path),
            || terrain(&path.field("shape"), t, base, budget),
            |e| Invalid {
                path: path.field("shape").field("path"),
                message: e.to_string(),
            },
        )?;
        let heights = match &t.animate {
            Some(a) => Some(Arc::new(Heights::resolve(
                &path.field("shape").field("animate"),
                a,
                &terrain,
                cx.base,
                cx.budget,
            )?)),
            None => None,
        };
        scene.terrains.push(TerrainObject {
            name,
            terrain,
            material,
            lod: t.lod,
            heights,
            frame_memory: None,
        });
        Ok(())
    }

    fn count(&self, scene: &Scene) -> usize {
        scene.terrains.len()
    }

    fn bounds(&self, scene: &Scene, index: usize) -> Option<Aabb> {
        scene.terrains.get(index).map(|t| t.terrain.bounds())
    }

    fn material_of(&self, scene: &Scene, index: usize, _part: u32) -> Option<u32> {
        scene.terrains.get(index).map(|t| t.material)
    }

    fn materials<'s>(&self, scene: &'s Scene) -> Box<dyn Iterator<Item = u32> + 's> {
        Box::new(scene.terrains.iter().map(|t| t.material))
    }

    fn mark(&self, features: &mut FeatureSet) {
        features.terrain = true;
    }

    fn culling<'s>(&self, scene: &'s Scene) -> Box<dyn Culling + 's> {
        Box::new(TerrainCulling(
            scene.terrains.iter().map(|t| boxes(&t.terrain)).collect(),
        ))
    }
}

/// A terrain's box and its coarse max columns (level [`Terrain::coarsest_stop_level`], at most
/// 8 × 8 columns: each column is a cell's map rectangle from the base up to the pyramid's maximum
/// over it). Every hit — the exact surface, and the max-column tops a LOD search (bias or pixel
/// footprint) stops at, which lie in the columns of any coarser level — is in one of the columns,
/// so a bundle that misses all of them misses the terrain.
struct TerrainBoxes {
    bounds: Aabb,
    columns: Vec<Aabb>,
}

fn boxes(t: &Terrain) -> TerrainBoxes {
    let level = t.coarsest_stop_level();
    let side = 1usize << level;
    let columns = (0..side * side)
        .filter_map(|k| t.column_bounds(level, k % side, k / side))
        .collect();
    TerrainBoxes {
        bounds: t.bounds(),
        columns,
    }
}

/// The scene's terrains' boxes for one work list.
struct TerrainCulling(Vec<TerrainBoxes>);

const KIND: u32 = crate::PrimitiveKind::Terrain.code();

impl Culling for TerrainCulling {
    fn roots(&self, root: &mut Candidates) {
        for k in 0..self.0.len() {
            root.begin(KIND, k as u32, 0.0, f64::INFINITY);
        }
    }

    fn cell_test(&self) -> CellTest<'_> {
        Box::new(|bundle, c, _parent, out| {
            let Some(t) = self.0.get(c.object as usize) else {
                return;
            };
            if bundle.box_range(&t.bounds).is_some() {
                let hull = t
                    .columns
                    .iter()
                    .filter_map(|b| bundle.box_range(b))
                    .reduce(|a, b| fray_core::Interval::new(a.lo.min(b.lo), a.hi.max(b.hi)));
                if let Some(range) = hull {
                    out.begin(KIND, c.object, range.lo, range.hi);
                }
            }
        })
    }
}
