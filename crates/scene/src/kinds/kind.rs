//! What a primitive kind is to a scene, in one trait: how an object of the kind is resolved
//! from its description into the scene's storage, how many the scene holds, their boxes and
//! materials, its feature flag, and its share of the quadtree's cell test. Each kind implements
//! it once, in its own file; `kinds/mod.rs` dispatches over [`crate::PrimitiveKind`].

use crate::FeatureSet;
use crate::assets::LoadedAssets;
use crate::checks::Result;
use crate::description;
use crate::path::FieldPath;
use crate::scene::Scene;
use fray_core::{Aabb, MemoryBudget};
use fray_quadtree::{Candidate, Candidates, RayBundle};
use std::collections::BTreeMap;
use std::path::Path;

/// What resolving an object needs besides the object: the scene's materials by name, the
/// scene file's folder (assets are relative to it), the memory account and the load's assets.
pub(crate) struct ObjectContext<'a> {
    pub(crate) materials: &'a BTreeMap<&'a str, u32>,
    pub(crate) base: &'a Path,
    pub(crate) budget: &'a MemoryBudget,
    pub(crate) assets: &'a mut LoadedAssets,
}

impl ObjectContext<'_> {
    /// The object's own material (its `material` field; the default material if it names none).
    pub(crate) fn object_material(
        &self,
        path: &FieldPath,
        object: &description::Object,
    ) -> Result<u32> {
        match &object.material {
            Some(name) => crate::checks::material(self.materials, &path.field("material"), name),
            None => Ok(0),
        }
    }
}

/// One primitive kind of a scene. Implemented by a zero-sized type per kind.
pub(crate) trait SceneKind: Sync {
    /// Resolves `object` (at `path`, named `name`), whose shape is of this kind, and adds it to
    /// the scene's storage of the kind.
    fn resolve(
        &self,
        cx: &mut ObjectContext<'_>,
        scene: &mut Scene,
        path: &FieldPath,
        object: &description::Object,
        name: String,
    ) -> Result<()>;

    /// How many primitives of the kind `scene` holds.
    fn count(&self, scene: &Scene) -> usize;

    /// The box of primitive `index` of the kind (`None`: no such primitive).
    fn bounds(&self, scene: &Scene, index: usize) -> Option<Aabb>;

    /// The material of `part` of primitive `index` (`None`: no such primitive or part).
    fn material_of(&self, scene: &Scene, index: usize, part: u32) -> Option<u32>;

    /// Every material index the kind's primitives use.
    fn materials<'s>(&self, scene: &'s Scene) -> Box<dyn Iterator<Item = u32> + 's>;

    /// Marks the kind as used in `features` (the scene holds at least one of it).
    fn mark(&self, features: &mut FeatureSet);

    /// The kind's share of the quadtree's cell test over `scene`, its boxes gathered once.
    fn culling<'s>(&self, scene: &'s Scene) -> Box<dyn Culling + 's>;
}

/// A kind's part of the cell test for one work list. Each test is conservative against the
/// kind's per-ray tests, so that culling stays lossless.
pub(crate) trait Culling: Sync {
    /// Adds the kind's primitives to the root cell's candidates (scene order).
    fn roots(&self, root: &mut Candidates);

    /// The test of one worker (with its own scratch).
    fn cell_test(&self) -> CellTest<'_>;
}

/// A kind's cell test for one worker: `c`, a candidate of the kind from `parent`, goes to `out`
/// — narrowed to what `bundle` may meet — if the bundle may meet it.
pub(crate) type CellTest<'a> =
    Box<dyn FnMut(&RayBundle, &Candidate, &Candidates, &mut Candidates) + 'a>;
