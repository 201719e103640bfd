//! glTF 2.0 (`.gltf`, `.glb`): every mesh primitive reachable from the default scene (or the
//! first scene, or, with no scene at all, every mesh once), node transforms applied.
//!
//! Triangle strips and fans are unrolled into triangles; points and lines carry no surface and
//! are skipped. A skinned mesh is taken in its bind pose: the glTF spec says the transform of
//! the node holding a skinned mesh is ignored, so it is not applied here either. Images are
//! never decoded: fur colour comes from the preset.

use std::path::Path;

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use gltf::mesh::Mode;

use super::{ColourSet, MeshError, RawMesh};

/// Deeper node hierarchies than this are treated as broken (and cannot blow the stack).
const MAX_NODE_DEPTH: usize = 256;

/// Vertex colour sets `COLOR_0 ..` read (grooms name them; files rarely have more than two).
const MAX_COLOUR_SETS: u32 = 8;

/// A file's raw mesh, its vertex colour sets (one colour per raw vertex) and what a further
/// reader took from the document.
pub(crate) type Parsed<T> = (RawMesh, Vec<ColourSet>, T);

/// One primitive's vertices in the raw mesh and where in the glTF document they came from, for
/// readers of the rest of the document (the rig) to line their data up with the mesh.
#[derive(Clone, Debug)]
pub(crate) struct Span {
    /// The node holding the mesh (none when the file has no scene).
    pub node: Option<usize>,
    /// The node's skin.
    pub skin: Option<usize>,
    pub mesh: usize,
    pub primitive: usize,
    pub first_vertex: u32,
    pub count: u32,
    /// The transform the static import applied (identity for a skinned mesh).
    pub world_from_local: Mat4,
}

/// A further reader of the parsed document: given the document, its buffers, the raw mesh's
/// spans and vertex count, it returns its own result or a message for the file's parse error.
pub(crate) trait DocumentReader<T>:
    FnOnce(&gltf::Document, &[gltf::buffer::Data], &[Span], usize) -> Result<T, String> + std::panic::UnwindSafe
{
}

impl<T, F> DocumentReader<T> for F where
    F: FnOnce(&gltf::Document, &[gltf::buffer::Data], &[Span], usize) -> Result<T, String> + std::panic::UnwindSafe
{
}

pub(super) fn load(path: &Path) -> Result<(RawMesh, Vec<ColourSet>), MeshError> {
    load_with(path, |_, _, _, _| Ok(())).map(|(raw, colour_sets, ())| (raw, colour_sets))
}

/// Parses `.gltf` JSON or `.glb` bytes. External buffers are looked up next to `base`; without
/// a `base` only embedded (GLB or `data:` URI) buffers can be read.
pub(super) fn parse(bytes: &[u8], file: &Path, base: Option<&Path>) -> Result<(RawMesh, Vec<ColourSet>), MeshError> {
    parse_with(bytes, file, base, |_, _, _, _| Ok(())).map(|(raw, colour_sets, ())| (raw, colour_sets))
}

/// Reads the whole file: [`load`] plus what `read` takes from the rest of the document.
pub(crate) fn load_with<T>(path: &Path, read: impl DocumentReader<T>) -> Result<Parsed<T>, MeshError> {
    let bytes = std::fs::read(path).map_err(|error| MeshError::Io { file: path.to_path_buf(), error })?;
    parse_with(&bytes, path, path.parent(), read)
}

/// [`parse`], plus what `read` takes from the rest of the document.
pub(crate) fn parse_with<T>(
    bytes: &[u8],
    file: &Path,
    base: Option<&Path>,
    read: impl DocumentReader<T>,
) -> Result<Parsed<T>, MeshError> {
    // The `gltf` crate's validation indexes unchecked in places (gltf-json 1.4.1 panics on a
    // primitive whose attribute map is emptied, for one); a broken file must stay an error.
    std::panic::catch_unwind(|| parse_unguarded(bytes, file, base, read)).unwrap_or_else(|_| {
        Err(MeshError::Parse {
            file: file.to_path_buf(),
            line: None,
            message: "the glTF reader failed on malformed content".to_owned(),
        })
    })
}

fn parse_unguarded<T>(
    bytes: &[u8],
    file: &Path,
    base: Option<&Path>,
    read: impl DocumentReader<T>,
) -> Result<Parsed<T>, MeshError> {
    let error = |message: String| MeshError::Parse { file: file.to_path_buf(), line: None, message };
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice(bytes).map_err(|e| error(format!("not valid glTF: {e}")))?;
    let buffers =
        gltf::import_buffers(&document, base, blob).map_err(|e| error(format!("cannot read a buffer: {e}")))?;

    let mut parts = Vec::new();
    match document.default_scene().or_else(|| document.scenes().next()) {
        Some(scene) => {
            for node in scene.nodes() {
                collect(&node, Mat4::IDENTITY, 0, &mut parts).map_err(error)?;
            }
        }
        None => parts.extend(document.meshes().map(|mesh| (mesh, Mat4::IDENTITY, None, None))),
    }

    let mut raw = RawMesh::default();
    let mut normals = Some(Vec::new());
    let mut uvs = Some(Vec::new());
    let mut skipped_primitives = 0;
    let mut spans = Vec::new();
    let mut colours: Vec<Option<Vec<Vec4>>> = (0..MAX_COLOUR_SETS).map(|_| Some(Vec::new())).collect();
    for (mesh, world_from_local, node, skin) in parts {
        for primitive in mesh.primitives() {
            let mode = primitive.mode();
            if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                skipped_primitives += 1;
                continue;
            }
            let name =
                || format!("mesh {} ({:?}) primitive {}", mesh.index(), mesh.name().unwrap_or(""), primitive.index());
            let reader = primitive.reader(|buffer| buffers.get(buffer.index()).map(|data| &data.0[..]));
            let positions: Vec<Vec3> = reader
                .read_positions()
                .ok_or_else(|| error(format!("{} has no readable POSITION attribute", name())))?
                .map(|p| world_from_local.transform_point3(Vec3::from_array(p)))
                .collect();
            let count = positions.len() as u32;
            let indices: Vec<u32> = match reader.read_indices() {
                Some(indices) => indices.into_u32().collect(),
                None => (0..count).collect(),
            };
            if let Some(&bad) = indices.iter().find(|&&i| i >= count) {
                return Err(error(format!("{} uses vertex index {bad}, but it has only {count} vertices", name())));
            }
            let base_index = raw.positions.len() as u32;
            spans.push(Span {
                node,
                skin,
                mesh: mesh.index(),
                primitive: primitive.index(),
                first_vertex: base_index,
                count,
                world_from_local,
            });
            // A mirroring transform turns the winding inside out; swap two corners to undo it.
            let mirrored = world_from_local.determinant() < 0.0;
            for tri in triangles(mode, &indices) {
                let [a, b, c] = tri.map(|i| base_index + i);
                raw.triangles.push(if mirrored { [a, c, b] } else { [a, b, c] });
            }
            raw.positions.extend(positions);

            let normal_from_local = Mat3::from_mat4(world_from_local).inverse().transpose();
            let primitive_normals = reader
                .read_normals()
                .map(|n| n.map(|n| (normal_from_local * Vec3::from_array(n)).normalize_or_zero()).collect::<Vec<_>>());
            keep_if_complete(&mut normals, primitive_normals, count);
            let primitive_uvs =
                reader.read_tex_coords(0).map(|uv| uv.into_f32().map(Vec2::from_array).collect::<Vec<_>>());
            keep_if_complete(&mut uvs, primitive_uvs, count);
            for (set, all) in (0..MAX_COLOUR_SETS).zip(&mut colours) {
                let primitive_colours =
                    reader.read_colors(set).map(|c| c.into_rgba_f32().map(Vec4::from_array).collect::<Vec<_>>());
                keep_if_complete(all, primitive_colours, count);
            }
        }
    }
    if raw.triangles.is_empty() && skipped_primitives > 0 {
        return Err(MeshError::NoTriangles {
            file: file.to_path_buf(),
            detail: format!(" (its {skipped_primitives} primitives are points or lines)"),
        });
    }
    raw.normals = normals;
    raw.uvs = uvs;
    let colour_sets = (0..MAX_COLOUR_SETS)
        .zip(colours)
        .filter_map(|(set, colours)| colours.filter(|c| !c.is_empty()).map(|colours| ColourSet { set, colours }))
        .collect();
    let extra = read(&document, &buffers, &spans, raw.positions.len()).map_err(error)?;
    Ok((raw, colour_sets, extra))
}

/// A mesh to import with its world transform, node and skin.
type Part<'a> = (gltf::Mesh<'a>, Mat4, Option<usize>, Option<usize>);

/// Walks `node` and its children, collecting each mesh with its world transform.
fn collect<'a>(node: &gltf::Node<'a>, parent: Mat4, depth: usize, parts: &mut Vec<Part<'a>>) -> Result<(), String> {
    if depth > MAX_NODE_DEPTH {
        return Err(format!("node {} is nested more than {MAX_NODE_DEPTH} deep (a cycle?)", node.index()));
    }
    let world_from_local = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
    if let Some(mesh) = node.mesh() {
        let skin = node.skin().map(|s| s.index());
        let transform = if skin.is_some() { Mat4::IDENTITY } else { world_from_local };
        parts.push((mesh, transform, Some(node.index()), skin));
    }
    for child in node.children() {
        collect(&child, world_from_local, depth + 1, parts)?;
    }
    Ok(())
}

/// Triangles of a primitive's index list, strips and fans unrolled with their winding kept.
fn triangles(mode: Mode, indices: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
            .map(|k| {
                let [a, b, c] = [indices[k], indices[k + 1], indices[k + 2]];
                if k % 2 == 0 { [a, b, c] } else { [b, a, c] }
            })
            .collect(),
        Mode::TriangleFan => {
            (1..indices.len().saturating_sub(1)).map(|k| [indices[0], indices[k], indices[k + 1]]).collect()
        }
        _ => indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    }
}

/// Appends one primitive's attribute, or gives up on the attribute for the whole mesh when a
/// primitive lacks it (the repair step then computes normals; uvs stay absent).
fn keep_if_complete<T>(all: &mut Option<Vec<T>>, primitive: Option<Vec<T>>, count: u32) {
    match (all.as_mut(), primitive) {
        (Some(all_values), Some(values)) if values.len() == count as usize => all_values.extend(values),
        _ => *all = None,
    }
}
