//! Free-form CSG solids as a primitive kind of the scene ([`crate::Scene::objects`]): an object
//! whose shape is a CSG tree of free forms (`crate::solid` resolves the tree), and its cell test
//! — the solid's box, then which of its leaves and perturbations the bundle may meet, the
//! candidate dropped where the active set is empty.

use super::kind::{CellTest, Culling, ObjectContext, SceneKind};
use crate::FeatureSet;
use crate::checks::Result;
use crate::description;
use crate::path::FieldPath;
use crate::scene::{Object, Scene};
use fray_core::Aabb;
use fray_geometry::ActiveSet;
use fray_quadtree::Candidates;

/// The free-form kind.
pub(crate) struct FreeForms;

impl SceneKind for FreeForms {
    fn resolve(
        &self,
        cx: &mut ObjectContext<'_>,
        scene: &mut Scene,
        path: &FieldPath,
        object: &description::Object,
        name: String,
    ) -> Result<()> {
        let material = cx.object_material(path, object)?;
        let (solid, leaf_materials) = crate::solid::object_solid(
            &path.field("shape"),
            &object.shape,
            material,
            cx.materials,
            &mut scene.features,
        )?;
        scene.objects.push(Object {
            name,
            solid,
            leaf_materials,
        });
        Ok(())
    }

    fn count(&self, scene: &Scene) -> usize {
        scene.objects.len()
    }

    fn bounds(&self, scene: &Scene, index: usize) -> Option<Aabb> {
        scene.objects.get(index).map(|o| o.solid.bounds())
    }

    fn material_of(&self, scene: &Scene, index: usize, part: u32) -> Option<u32> {
        scene
            .objects
            .get(index)
            .and_then(|o| o.leaf_materials.get(part as usize).copied())
    }

    fn materials<'s>(&self, scene: &'s Scene) -> Box<dyn Iterator<Item = u32> + 's> {
        Box::new(
            scene
                .objects
                .iter()
                .flat_map(|o| o.leaf_materials.iter().copied()),
        )
    }

    fn mark(&self, features: &mut FeatureSet) {
        features.free_forms = true;
    }

    fn culling<'s>(&self, scene: &'s Scene) -> Box<dyn Culling + 's> {
        Box::new(FreeFormCulling {
            scene,
            boxes: scene.objects.iter().map(object_boxes).collect(),
        })
    }
}

/// The boxes the cell test needs, gathered once per work list.
struct ObjectBoxes {
    solid: Aabb,
    leaves: Vec<Aabb>,
    /// Per object-wide perturbation: its support box (`None`: unbounded, always kept). The whole
    /// box, not its part inside the leaf's box: a perturbation is dropped only where it is zero
    /// all along the tile's rays, so normals evaluated with the subset are exact too.
    perturbations: Vec<Option<Aabb>>,
}

fn object_boxes(o: &Object) -> ObjectBoxes {
    let mut perturbations = Vec::new();
    for leaf in o.solid.leaves() {
        for p in leaf.perturbations() {
            perturbations.push(p.support_bounds());
        }
    }
    ObjectBoxes {
        solid: o.solid.bounds(),
        leaves: o.solid.leaves().iter().map(|l| l.bounds()).collect(),
        perturbations,
    }
}

struct FreeFormCulling<'s> {
    scene: &'s Scene,
    boxes: Vec<ObjectBoxes>,
}

const KIND: u32 = crate::PrimitiveKind::FreeForm.code();

impl Culling for FreeFormCulling<'_> {
    fn roots(&self, root: &mut Candidates) {
        for (i, (object, b)) in self.scene.objects.iter().zip(&self.boxes).enumerate() {
            root.begin(KIND, i as u32, 0.0, f64::INFINITY);
            for l in 0..b.leaves.len() as u32 {
                root.push_leaf(l);
            }
            // Every perturbation, zero form factors included (the caster skips those per ray;
            // the normals sum them like the full evaluation does).
            for k in 0..object.solid.perturbation_count() as u32 {
                root.push_perturbation(k);
            }
        }
    }

    fn cell_test(&self) -> CellTest<'_> {
        let mut active = ActiveSet::new();
        Box::new(move |bundle, c, parent, out| {
            let Some(b) = self.boxes.get(c.object as usize) else {
                return;
            };
            let Some(t) = bundle.box_range(&b.solid) else {
                return;
            };
            out.begin(KIND, c.object, t.lo, t.hi);
            for &l in c.leaves(&parent.leaves) {
                if bundle.box_range(&b.leaves[l as usize]).is_some() {
                    out.push_leaf(l);
                }
            }
            for &p in c.perturbations(&parent.perturbations) {
                if b.perturbations[p as usize].is_none_or(|pb| bundle.box_range(&pb).is_some()) {
                    out.push_perturbation(p);
                }
            }
            let solid = &self.scene.objects[c.object as usize].solid;
            let (leaves, perts) = out
                .candidates
                .last()
                .map(|last| {
                    (
                        last.leaves(&out.leaves),
                        last.perturbations(&out.perturbations),
                    )
                })
                .unwrap_or((&[], &[]));
            if !active.set(solid, leaves, perts) {
                out.cancel();
            }
        })
    }
}
