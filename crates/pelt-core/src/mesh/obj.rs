//! Wavefront OBJ through `tobj`: quads and n-gons triangulated; `g`/`o` groups are merged back
//! into one mesh so welding restores the adjacency across group borders.

use std::io::BufReader;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::{MeshError, RawMesh};

pub(super) fn load(path: &Path) -> Result<RawMesh, MeshError> {
    let text = std::fs::read(path).map_err(|error| MeshError::Io { file: path.to_path_buf(), error })?;
    let text = String::from_utf8_lossy(&text);
    parse(&text, path)
}

pub(super) fn parse(text: &str, file: &Path) -> Result<RawMesh, MeshError> {
    let options = tobj::LoadOptions { single_index: true, triangulate: true, ignore_points: true, ignore_lines: true };
    let error = |line, message| MeshError::Parse { file: file.to_path_buf(), line, message };
    // Checked here first: tobj reports no line numbers, and panics (index arithmetic overflow)
    // on some malformed relative indices.
    if let Some((line, message)) = diagnose(text) {
        return Err(error(Some(line), message));
    }
    // tobj takes an inline comment (`v 0 0 0 # origin`) for more numbers; cut them, keeping the
    // line count so line numbers in messages stay right.
    let uncommented: String;
    let text = if text.lines().any(|line| line.trim_start().find('#').is_some_and(|at| at > 0)) {
        uncommented =
            text.lines().map(|line| line.split('#').next().unwrap_or_default()).collect::<Vec<_>>().join("\n");
        &uncommented
    } else {
        text
    };
    let mut reader = BufReader::new(text.as_bytes());
    // Materials are not needed: colour comes from the fur preset.
    let load = || tobj::load_obj_buf(&mut reader, &options, |_| Ok(Default::default()));
    // Should tobj still panic on something `diagnose` let through, the file is bad, not Pelt.
    let (models, _materials) = std::panic::catch_unwind(std::panic::AssertUnwindSafe(load))
        .map_err(|_| error(None, "the OBJ parser (tobj) failed on this file".to_owned()))?
        .map_err(|e| error(None, e.to_string()))?;

    let mut raw = RawMesh::default();
    let every_model_has_normals = models.iter().all(|m| !m.mesh.normals.is_empty());
    let every_model_has_uvs = models.iter().all(|m| !m.mesh.texcoords.is_empty());
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let base = raw.positions.len() as u32;
        raw.positions.extend(mesh.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
        if every_model_has_normals {
            normals.extend(mesh.normals.chunks_exact(3).map(|n| Vec3::new(n[0], n[1], n[2])));
        }
        if every_model_has_uvs {
            uvs.extend(mesh.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], t[1])));
        }
        raw.triangles.extend(mesh.indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
    }
    if every_model_has_normals && normals.len() == raw.positions.len() {
        raw.normals = Some(normals);
    }
    if every_model_has_uvs && uvs.len() == raw.positions.len() {
        raw.uvs = Some(uvs);
    }
    Ok(raw)
}

/// Finds the first malformed `v`, `vt`, `vn` or `f` line (numbers that do not parse, too few
/// of them, face indices outside what is defined above) and says what is wrong with it.
fn diagnose(text: &str) -> Option<(usize, String)> {
    // Elements defined so far, for checking (and resolving relative) face indices.
    let (mut positions, mut uvs, mut normals) = (0_i64, 0_i64, 0_i64);
    for (n, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or_default();
        let mut words = content.split_whitespace();
        let Some(keyword) = words.next() else { continue };
        let values: Vec<&str> = words.collect();
        let bad = |message: String| Some((n + 1, message));
        match keyword {
            "v" | "vn" | "vt" => {
                let expected = if keyword == "vt" { 1 } else { 3 };
                if values.len() < expected {
                    return bad(format!("`{keyword}` needs {expected} numbers, found {}", values.len()));
                }
                if let Some(word) = values.iter().find(|w| w.parse::<f32>().is_err()) {
                    return bad(format!("`{keyword}`: {word:?} is not a number"));
                }
                match keyword {
                    "v" => positions += 1,
                    "vt" => uvs += 1,
                    _ => normals += 1,
                }
            }
            "f" => {
                if values.len() < 3 {
                    return bad(format!("a face needs at least 3 corners, found {}", values.len()));
                }
                for corner in &values {
                    for (k, (part, count, what)) in corner
                        .split('/')
                        .zip([(positions, "vertex"), (uvs, "texture coordinate"), (normals, "normal")])
                        .map(|(part, (count, what))| (part, count, what))
                        .enumerate()
                    {
                        if part.is_empty() && k > 0 {
                            continue;
                        }
                        let Ok(index) = part.parse::<i64>() else {
                            return bad(format!("face corner {corner:?}: {part:?} is not an index"));
                        };
                        // 1-based, or negative: relative to the end of the list so far.
                        let resolved = if index < 0 { count + index + 1 } else { index };
                        if index == 0 || resolved < 1 || resolved > count {
                            return bad(format!(
                                "face corner {corner:?} uses {what} {index}, but only {count} are defined above it"
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}
