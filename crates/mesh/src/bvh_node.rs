//! A BVH node as [`crate::MeshBvh::nodes`] hands it out: read access to the tree for code that
//! flattens it (the GPU layout), without exposing the BVH's own storage.

use glam::DVec3;

/// One node of a [`crate::MeshBvh`]: its f64 box (bounding its triangles' f64 corners exactly);
/// an inner node (`count == 0`) has children `first` and `first + 1`, a leaf's triangles are
/// `leaf_order()[first..first + count]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhNode {
    pub min: DVec3,
    pub max: DVec3,
    pub first: u32,
    /// 0 for an inner node, else the leaf's triangle count.
    pub count: u32,
}

impl BvhNode {
    /// Whether this node is a leaf.
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}
