//! Triangle-mesh instances as a primitive kind of the scene ([`crate::Scene::meshes`]).
//!
//! Resolving a `Mesh(...)` shape: the OBJ file is loaded (relative to the scene file) and its BVH
//! built once per file, with the BVH's packet data for the CPU's tiles (`PacketBvh`: about 8 ms
//! and 15 MB for the 75k-triangle bunny) — objects naming the same file become instances of one
//! mesh —, placed by the object's transform. The BVH's build is reserved on the scene's memory
//! account before it starts, and the tree and its packet data are charged to it; a bad file is
//! reported at the `path` field with the file's path, the line and the reason, and so is a mesh
//! over the memory budget. A file is loaded once per load (`crate::assets`). The cell test keeps
//! an instance where the bundle meets its world box.

use super::kind::{CellTest, Culling, ObjectContext, SceneKind};
use crate::FeatureSet;
use crate::assets::LoadedAssets;
use crate::checks::{Invalid, Result, invalid, transform};
use crate::description;
use crate::path::FieldPath;
use crate::scene::{MeshObject, Scene};
use fray_core::{Aabb, MemoryBudget};
use fray_mesh::{Instance, MeshBvh, PacketBvh, TriangleMesh};
use fray_quadtree::Candidates;
use std::path::Path;

/// The instance `m` describes (`path` is the shape's field path): its mesh loaded and its BVH
/// built once per file in a load (`assets`), however many objects — or resolves — use it.
fn instance(
    path: &FieldPath,
    m: &description::Mesh,
    base: &Path,
    budget: &MemoryBudget,
    assets: &mut LoadedAssets,
) -> Result<Instance> {
    let to_world = transform(&path.field("transform"), &m.transform)?;
    let file = base.join(&m.path);
    // The same file by another spelling (`./a.obj`, `../x/a.obj`) is still one mesh.
    let key = std::fs::canonicalize(&file).unwrap_or_else(|_| file.clone());
    let packets = assets.meshes.get_or_build(
        key,
        budget,
        || format!("the mesh {} and its BVH", file.display()),
        || {
            let mesh = TriangleMesh::load_obj(&file, budget)
                .or_else(|e| invalid(&path.field("path"), e.to_string()))?;
            let triangles = mesh.triangles.len();
            let name = |what: &str| {
                format!(
                    "{what} of the mesh {} ({triangles} triangles)",
                    file.display()
                )
            };
            // The build's peak (its boxes and the tree at its largest) is held on the account
            // while it runs; then the tree as built, and the packet data before it is made, are
            // charged for as long as the scene lives.
            let bvh = {
                let _building = budget
                    .reserve(name("building the BVH"), MeshBvh::build_bytes(triangles))
                    .or_else(|e| invalid(&path.field("path"), e.to_string()))?;
                MeshBvh::build(mesh)
            };
            for (what, bytes) in [
                ("the BVH", bvh.bytes()),
                ("the packet data", PacketBvh::bytes_for(&bvh)),
            ] {
                budget
                    .charge(name(what), bytes)
                    .or_else(|e| invalid(&path.field("path"), e.to_string()))?;
            }
            Ok(PacketBvh::new(bvh))
        },
        |e| Invalid {
            path: path.field("path"),
            message: e.to_string(),
        },
    )?;
    Instance::with_packets(packets, to_world)
        .or_else(|e| invalid(&path.field("transform"), e.to_string()))
}

/// The mesh kind.
pub(crate) struct Meshes;

impl SceneKind for Meshes {
    fn resolve(
        &self,
        cx: &mut ObjectContext<'_>,
        scene: &mut Scene,
        path: &FieldPath,
        object: &description::Object,
        name: String,
    ) -> Result<()> {
        let description::Shape::Mesh(m) = &object.shape else {
            return invalid(&path.field("shape"), "expected a Mesh");
        };
        let material = cx.object_material(path, object)?;
        let instance = instance(&path.field("shape"), m, cx.base, cx.budget, cx.assets)?;
        scene.meshes.push(MeshObject {
            name,
            instance,
            material,
            smooth: m.smooth,
        });
        Ok(())
    }

    fn count(&self, scene: &Scene) -> usize {
        scene.meshes.len()
    }

    fn bounds(&self, scene: &Scene, index: usize) -> Option<Aabb> {
        scene.meshes.get(index).map(|m| m.instance.bounds())
    }

    fn material_of(&self, scene: &Scene, index: usize, _part: u32) -> Option<u32> {
        scene.meshes.get(index).map(|m| m.material)
    }

    fn materials<'s>(&self, scene: &'s Scene) -> Box<dyn Iterator<Item = u32> + 's> {
        Box::new(scene.meshes.iter().map(|m| m.material))
    }

    fn mark(&self, features: &mut FeatureSet) {
        features.meshes = true;
    }

    fn culling<'s>(&self, scene: &'s Scene) -> Box<dyn Culling + 's> {
        Box::new(MeshCulling(
            scene.meshes.iter().map(|m| m.instance.bounds()).collect(),
        ))
    }
}

/// The instances' world boxes (each holds every triangle, with a margin) for one work list.
struct MeshCulling(Vec<Aabb>);

const KIND: u32 = crate::PrimitiveKind::Mesh.code();

impl Culling for MeshCulling {
    fn roots(&self, root: &mut Candidates) {
        for k in 0..self.0.len() {
            root.begin(KIND, k as u32, 0.0, f64::INFINITY);
        }
    }

    fn cell_test(&self) -> CellTest<'_> {
        Box::new(|bundle, c, _parent, out| {
            if let Some(range) = self
                .0
                .get(c.object as usize)
                .and_then(|b| bundle.box_range(b))
            {
                out.begin(KIND, c.object, range.lo, range.hi);
            }
        })
    }
}
