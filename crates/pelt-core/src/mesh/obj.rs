//! Wavefront OBJ through `tobj`: quads and n-gons triangulated; `g`/`o` groups are merged back
//! into one mesh so welding restores the adjacency across group borders.

use std::io::BufReader;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::{MeshError, RawMesh};

pub(super) fn load(path: &Path) -> Result<RawMesh, MeshError> {
    let text = std::fs::read(path).map_err(|source| MeshError::Io { file: path.to_path_buf(), source })?;
    let text = String::from_utf8_lossy(&text);
    parse(&text, path)
}

pub(super) fn parse(text: &str, file: &Path) -> Result<RawMesh, MeshError> {
    let options = tobj::LoadOptions { single_index: true, triangulate: true, ignore_points: true, ignore_lines: true };
    let mut reader = BufReader::new(text.as_bytes());
    // Materials are not needed: colour comes from the fur preset.
    let (models, _materials) = tobj::load_obj_buf(&mut reader, &options, |_| Ok(Default::default())).map_err(|e| {
        MeshError::Parse { file: file.to_path_buf(), line: find_bad_line(text), message: e.to_string() }
    })?;

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

/// tobj reports no line numbers; find the first line whose numbers do not parse, for the message.
fn find_bad_line(text: &str) -> Option<usize> {
    text.lines().enumerate().find_map(|(n, line)| {
        let mut words = line.split_whitespace();
        let expected = match words.next()? {
            "v" | "vn" => 3,
            "vt" => 1,
            "f" => 3,
            _ => return None,
        };
        let values: Vec<&str> = words.collect();
        let is_bad = values.len() < expected
            || values.iter().any(|w| {
                w.split('/').next().is_none_or(|first| first.parse::<f64>().is_err() && first.parse::<i64>().is_err())
            });
        is_bad.then_some(n + 1)
    })
}
