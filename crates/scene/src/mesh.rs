//! Resolving a `Mesh(...)` shape: the OBJ file is loaded (relative to the scene file) and its BVH
//! built once per file, with the BVH's packet data for the CPU's tiles (`PacketBvh`: about 8 ms
//! and 15 MB for the 75k-triangle bunny) — objects naming the same file become instances of one
//! mesh —, placed by the object's transform. The BVH's build is reserved on the scene's memory
//! account before it starts, and the tree and its packet data are charged to it; a bad file is
//! reported at the `path` field with the file's path, the line and the reason, and so is a mesh
//! over the memory budget. A file is loaded once per load (`crate::assets`).

use crate::assets::LoadedAssets;
use crate::description;
use crate::path::FieldPath;
use crate::resolve::{Invalid, Result, invalid, transform};
use fray_core::MemoryBudget;
use fray_mesh::{Instance, MeshBvh, PacketBvh, TriangleMesh};
use std::path::Path;

/// The instance `m` describes (`path` is the shape's field path): its mesh loaded and its BVH
/// built once per file in a load (`assets`), however many objects — or resolves — use it.
pub(crate) fn instance(
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
