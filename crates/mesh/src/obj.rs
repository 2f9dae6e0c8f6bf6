//! OBJ files through `tobj` (triangulated, one index per vertex: positions, normals and UVs
//! unified), with the errors a user can act on: a missing file, and a malformed line named by
//! its number and what is wrong with it (a pre-pass over the lines `tobj` reads — `v`, `vn`,
//! `vt`, `f` — since `tobj` reports no line). Several objects in a file become one mesh.

use crate::{MeshError, TriangleMesh};
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
        let (vertices, faces) = check_lines(path, &text)?;
        // Positions, normals and UVs in f64 and the triangles, per vertex of the unified
        // indexing (at most 3 per face corner): a generous bound, checked before tobj allocates.
        budget.check_elements(
            format!("the mesh {}", path.display()),
            (vertices + 3 * faces).saturating_mul(4),
            8 * 3,
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
        TriangleMesh::with_attributes(
            positions,
            triangles,
            all_normals.then_some(normals),
            all_uvs.then_some(uvs),
        )
        .map_err(|e| invalid(e.to_string()))
    }
}

/// Checks every `v`, `vn`, `vt` and `f` line (numbers finite, face indices naming existing
/// elements, counting negative ones from the end); returns the vertex and face counts.
fn check_lines(path: &Path, text: &str) -> Result<(u64, u64), MeshError> {
    let (mut v, mut vt, mut vn, mut faces) = (0i64, 0i64, 0i64, 0u64);
    for (number, line) in text.lines().enumerate() {
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
            let values: Vec<&str> = words.collect();
            if values.len() < need {
                return Err(fail(format!(
                    "`{keyword}` needs {need} numbers ({what}), got {}",
                    values.len()
                )));
            }
            for value in &values {
                match value.parse::<f64>() {
                    Ok(x) if x.is_finite() => {}
                    _ => return Err(fail(format!("`{value}` is not a finite number"))),
                }
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
            "f" => {
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return Err(fail(format!(
                        "a face needs at least 3 corners, got {}",
                        corners.len()
                    )));
                }
                for corner in corners {
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
                faces += 1;
            }
            _ => {}
        }
    }
    Ok((v as u64, faces))
}
