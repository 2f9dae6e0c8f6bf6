//! OBJ files through `tobj` (triangulated, one index per vertex: positions, normals and UVs
//! unified), with the errors a user can act on: a missing file, and a malformed line named by
//! its number and what is wrong with it (a pre-pass over the lines `tobj` reads — `v`, `vn`,
//! `vt`, `f`, `l` — since `tobj` reports no line), and a memory bound from the pre-pass's counts
//! (`obj_size`) checked before `tobj` allocates. Several objects in a file become one mesh.

use crate::obj_size::ObjCounts;
use crate::{MAX_TRIANGLES, MeshError, TriangleMesh};
use fray_core::MemoryBudget;
use glam::{DVec2, DVec3};
use std::path::Path;

impl TriangleMesh {
    /// Loads the OBJ file at `path`: its normals and UVs when every object has them (normals
    /// computed, angle-weighted, otherwise); its size checked against `budget` first.
    pub fn load_obj(path: &Path, budget: &MemoryBudget) -> Result<Self, MeshError> {
        // Only a regular file, no larger than what is left of the budget.
        let text = fray_core::input::read_text(path, budget).map_err(|e| match e {
            fray_core::input::InputError::Budget(source) => MeshError::Budget(source),
            other => MeshError::Io {
                path: path.to_owned(),
                reason: other.to_string(),
            },
        })?;
        let counts = check_lines(path, &text)?;
        if counts.too_many_triangles() {
            return Err(MeshError::TooManyTriangles {
                path: path.to_owned(),
                triangles: counts.triangles,
                limit: MAX_TRIANGLES as u64,
            });
        }
        // tobj's buffers and the mesh made from them, checked before tobj allocates.
        budget.check(
            format!(
                "loading the mesh {} ({} triangles from {} face corners)",
                path.display(),
                counts.triangles,
                counts.corners
            ),
            counts.load_bytes(text.len() as u64),
        )?;
        let options = tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ignore_points: true,
            ignore_lines: true,
        };
        let invalid = |reason: String| MeshError::Invalid {
            path: path.to_owned(),
            reason,
        };
        let (models, _materials) = tobj::load_obj_buf(
            &mut std::io::BufReader::new(text.as_bytes()),
            &options,
            // Materials are not read yet: an `mtllib` line loads nothing.
            |_| Ok(Default::default()),
        )
        .map_err(|e| invalid(format!("not a valid OBJ file: {e}")))?;
        let mut positions = Vec::new();
        let mut normals = Vec::new();
        let mut uvs = Vec::new();
        let mut triangles = Vec::new();
        let (mut all_normals, mut all_uvs) = (true, true);
        for model in &models {
            let m = &model.mesh;
            let base = positions.len() as u32;
            let count = m.positions.len() / 3;
            positions.extend(
                m.positions
                    .chunks_exact(3)
                    .map(|p| DVec3::new(p[0].into(), p[1].into(), p[2].into())),
            );
            all_normals &= m.normals.len() == 3 * count;
            all_uvs &= m.texcoords.len() == 2 * count;
            normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|n| DVec3::new(n[0].into(), n[1].into(), n[2].into())),
            );
            uvs.extend(
                m.texcoords
                    .chunks_exact(2)
                    .map(|t| DVec2::new(t[0].into(), t[1].into())),
            );
            triangles.extend(
                m.indices
                    .chunks_exact(3)
                    .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
            );
        }
        if triangles.is_empty() {
            return Err(invalid("the file holds no faces".into()));
        }
        let mesh = TriangleMesh::with_attributes(
            positions,
            triangles,
            all_normals.then_some(normals),
            all_uvs.then_some(uvs),
        )
        .map_err(|e| invalid(e.to_string()))?;
        // The mesh lives as long as the scene: charged to the render's account.
        budget.charge(format!("the mesh {}", path.display()), mesh.heap_bytes())?;
        Ok(mesh)
    }
}

/// Checks every `v`, `vn`, `vt`, `f` and `l` line (numbers finite, face indices naming existing
/// elements, counting negative ones from the end) without allocating per line; returns what it
/// counted, for the memory bound (`obj_size`).
fn check_lines(path: &Path, text: &str) -> Result<ObjCounts, MeshError> {
    let (mut v, mut vt, mut vn) = (0i64, 0i64, 0i64);
    let mut counts = ObjCounts::default();
    for (number, line) in text.lines().enumerate() {
        counts.longest_line = counts.longest_line.max(line.len() as u64);
        let fail = |reason: String| MeshError::Obj {
            path: path.to_owned(),
            line: number + 1,
            reason,
        };
        let line = line.split('#').next().unwrap_or_default();
        let mut words = line.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let numbers = |words: std::str::SplitWhitespace, need: usize, what: &str| {
            let mut got = 0;
            for value in words {
                match value.parse::<f64>() {
                    Ok(x) if x.is_finite() => got += 1,
                    _ => return Err(fail(format!("`{value}` is not a finite number"))),
                }
            }
            if got < need {
                return Err(fail(format!(
                    "`{keyword}` needs {need} numbers ({what}), got {got}"
                )));
            }
            Ok(())
        };
        match keyword {
            "v" => {
                numbers(words, 3, "x y z")?;
                v += 1;
            }
            "vn" => {
                numbers(words, 3, "x y z")?;
                vn += 1;
            }
            "vt" => {
                numbers(words, 1, "u [v]")?;
                vt += 1;
            }
            // `tobj` reads a line element (`l`) as it reads a face, and makes triangles of one
            // with 3 corners or more.
            "f" | "l" => {
                let mut corners = 0u64;
                for corner in words {
                    corners += 1;
                    for (k, (index, count, what)) in corner
                        .split('/')
                        .zip([(v, "vertex"), (vt, "texture coordinate"), (vn, "normal")])
                        .map(|(i, (c, w))| (i, c, w))
                        .enumerate()
                    {
                        if index.is_empty() && k > 0 {
                            continue; // `v//vn`
                        }
                        let i: i64 = index
                            .parse()
                            .map_err(|_| fail(format!("`{corner}`: `{index}` is not an index")))?;
                        let resolved = if i < 0 { count + i + 1 } else { i };
                        if i == 0 || resolved < 1 || resolved > count {
                            return Err(fail(format!(
                                "`{corner}` names {what} {i}, but only {count} are defined above it"
                            )));
                        }
                    }
                }
                if keyword == "f" && corners < 3 {
                    return Err(fail(format!(
                        "a face needs at least 3 corners, got {corners}"
                    )));
                }
                counts.faces += 1;
                if corners >= 5 {
                    counts.polygon_corners += corners;
                }
                if corners >= 3 {
                    counts.corners += corners;
                    counts.triangles += corners - 2;
                }
            }
            _ => {}
        }
    }
    (counts.vertices, counts.texcoords, counts.normals) = (v as u64, vt as u64, vn as u64);
    Ok(counts)
}
