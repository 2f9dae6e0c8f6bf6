//! What loading an OBJ file costs in memory, bounded from the pre-pass's counts before `tobj`
//! allocates anything: `tobj`'s parse (its faces, a polygon's corners, the fan triangulation of
//! `corners − 2` triangles a face, its vertex map) and the [`crate::TriangleMesh`] made from it.

use crate::MAX_TRIANGLES;

/// What the pre-pass counted in an OBJ file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct ObjCounts {
    /// `v` lines.
    pub vertices: u64,
    /// `vt` lines.
    pub texcoords: u64,
    /// `vn` lines.
    pub normals: u64,
    /// `f` and `l` lines (`tobj` keeps both until it exports them).
    pub faces: u64,
    /// Corners of the faces `tobj` stores as polygons (5 corners or more), each in a vector of
    /// its own.
    pub polygon_corners: u64,
    /// Corners of the faces that become triangles (3 corners or more).
    pub corners: u64,
    /// Triangles after the fan triangulation: `corners − 2` a face.
    pub triangles: u64,
    /// The longest line in bytes (`tobj` copies each line into a string of its own).
    pub longest_line: u64,
}

/// How much larger than its contents a vector that grew by pushing may be: `tobj` pushes, and
/// `Vec` doubles its capacity when full.
const GROWTH: u64 = 2;

/// `tobj` 4's `Face` (private): its largest variant, a quad, holds four `VertexIndices` of three
/// `usize` each, plus the tag — 104 bytes on a 64-bit target.
const TOBJ_FACE: u64 = 4 * 3 * 8 + 8;

/// One corner of a `tobj` polygon: a `VertexIndices`, three `usize`.
const TOBJ_CORNER: u64 = 3 * 8;

/// Per vertex line: `tobj`'s position and, for `v x y z r g b`, colour (three `f32` each).
const TOBJ_VERTEX: u64 = 2 * 3 * 4;

/// Per vertex of the unified indexing, `tobj`'s exported position, texture coordinate, normal
/// and colour (11 `f32`), grown by pushing.
const TOBJ_UNIFIED_VERTEX: u64 = GROWTH * 11 * 4;

/// Per vertex of the unified indexing, `tobj`'s map from `(v, vt, vn)` to it: a bucket of 33
/// bytes (a 24-byte key, a 4-byte value, padding, a control byte), at most `16/7` buckets a
/// vertex (a power of two above `8/7` of the entries), the old and the new table together while
/// it grows (× 1.5): ≈ 113 bytes, rounded up.
const TOBJ_INDEX_MAP: u64 = 128;

/// Per vertex of the unified indexing, the [`crate::TriangleMesh`]: f64 position, normal (given
/// and computed) and UV, extended model by model (`GROWTH`), plus the computed normals' sums and
/// the renormalised copy of the given ones.
const MESH_VERTEX: u64 = GROWTH * (24 + 24 + 16) + 24 + 24;

/// Per triangle: `tobj`'s three `u32` indices (grown by pushing) and the mesh's (extended).
const TRIANGLE: u64 = GROWTH * 12 + GROWTH * 12;

impl ObjCounts {
    /// The vertices the unified indexing (one per distinct `(v, vt, vn)` a face names) can make,
    /// at most: no more than the corners, nor than the combinations of the elements defined.
    pub(crate) fn unified_vertices(&self) -> u64 {
        let combinations = self
            .vertices
            .saturating_mul(self.texcoords.saturating_add(1))
            .saturating_mul(self.normals.saturating_add(1));
        self.corners.min(combinations)
    }

    /// The most the load of a file of `text` bytes holds at once: the text, a line's copy,
    /// `tobj`'s buffers while it exports the faces, and the mesh being made from them.
    pub(crate) fn load_bytes(&self, text: u64) -> u64 {
        let terms = [
            text,
            self.longest_line.saturating_mul(GROWTH),
            self.vertices.saturating_mul(GROWTH * TOBJ_VERTEX),
            self.texcoords.saturating_mul(GROWTH * 2 * 4),
            self.normals.saturating_mul(GROWTH * 3 * 4),
            self.faces.saturating_mul(GROWTH * TOBJ_FACE),
            self.polygon_corners.saturating_mul(GROWTH * TOBJ_CORNER),
            self.unified_vertices()
                .saturating_mul(TOBJ_UNIFIED_VERTEX + TOBJ_INDEX_MAP + MESH_VERTEX),
            self.triangles.saturating_mul(TRIANGLE),
        ];
        terms.into_iter().fold(0, u64::saturating_add)
    }

    /// Whether the triangles fit a mesh ([`MAX_TRIANGLES`]).
    pub(crate) fn too_many_triangles(&self) -> bool {
        self.triangles > MAX_TRIANGLES as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The face of 3·10⁷ corners over 4 vertices: the triangles and the polygon's
    /// corners dominate (≈ 3 GB), not its 4 distinct vertices.
    #[test]
    fn a_huge_face_costs_its_triangles_and_corners() {
        let c = ObjCounts {
            vertices: 4,
            faces: 1,
            polygon_corners: 30_000_000,
            corners: 30_000_000,
            triangles: 29_999_998,
            longest_line: 60_000_000,
            ..Default::default()
        };
        assert_eq!(c.unified_vertices(), 4);
        let bytes = c.load_bytes(60_000_000);
        assert!(
            bytes > 30_000_000 * (GROWTH * TOBJ_CORNER + TRIANGLE),
            "{bytes}"
        );
        // Counts past u64 saturate instead of wrapping.
        let huge = ObjCounts {
            vertices: u64::MAX,
            texcoords: u64::MAX,
            corners: u64::MAX,
            ..Default::default()
        };
        assert_eq!(huge.load_bytes(1), u64::MAX);
    }
}
