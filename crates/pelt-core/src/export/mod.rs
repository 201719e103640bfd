//! Pelt's fur as a standard glTF 2.0 file that any glTF viewer or engine draws without custom
//! shaders: the shells as one primitive per exported layer (its own slice image, alpha as MASK or
//! BLEND), the fins as strips on every edge with the fin image, all at one settled pose. A
//! source glTF is carried over whole (meshes, materials, nodes, skins, morph targets,
//! animations), and on a skinned source every fur vertex is bound to its root's joints, so the
//! fur follows the skeleton. Morph targets on the fur ([`FurMorphs`]) follow the source's or
//! loop a baked sway.
//!
//! What the renderer computes per fragment and a plain material cannot (Kajiya-Kay lighting, the
//! view-angle fading of shells and fins) is left to the player's lighting; what depends only on
//! the layer or the fin's height (root darkening, the fins' thinning) is baked into the material
//! factors and images, and the surface colour mode's tint into vertex colours.

mod document;
mod geometry;
mod images;
mod morph;
mod strands;

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};
use serde_json::{Value, json};

use self::document::{CLAMP_TO_EDGE, Document, REPEAT};
use self::geometry::{fins, shell_wedges, srgb_to_linear, surface_colours};
pub use self::morph::{FurMorphs, MorphAnimation, carried_up};
pub use self::strands::{
    StrandBasis, StrandExportCounts, StrandExportInput, StrandFrame, kept_strands, write_strands_usda,
};
use crate::fur::FurStructure;
use crate::mesh::Mesh;
use crate::reference::TileMapping;
use crate::texture::FurTextures;

/// Errors from exporting.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The source glTF could not be copied.
    #[error("{file}: cannot copy the source glTF: {problem}")]
    Source {
        /// The source file.
        file: PathBuf,
        /// What went wrong.
        problem: String,
    },
    /// An image could not be encoded.
    #[error("cannot encode an image as PNG: {0}")]
    Image(String),
    /// The output could not be written (no partial file is left).
    #[error("{file}: cannot write: {problem}")]
    Write {
        /// The output file.
        file: PathBuf,
        /// What went wrong.
        problem: String,
    },
    /// The input does not describe an exportable fur.
    #[error("{0}")]
    Input(String),
}

/// How the fur's materials blend.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AlphaMode {
    /// Alpha tested (glTF `MASK`): no sorting needed, hard strand edges.
    Mask,
    /// Alpha blended (glTF `BLEND`): soft strands; players draw the layers in file order.
    Blend,
}

impl AlphaMode {
    fn gltf(self) -> &'static str {
        match self {
            Self::Mask => "MASK",
            Self::Blend => "BLEND",
        }
    }
}

/// The glTF skin the fur is bound to and each base vertex's joints (indices into that skin's
/// joints) and weights.
#[derive(Clone, Debug)]
pub struct FurSkin {
    /// The skin's index in the source file.
    pub skin: usize,
    /// Per base vertex: four joints and weights summing to 1.
    pub influences: Vec<([u16; 4], [f32; 4])>,
}

/// Everything one export writes.
#[derive(Debug)]
pub struct ExportInput<'a> {
    /// The structure: its mesh (bind pose for a skinned source) and layer count.
    pub fur: &'a FurStructure,
    /// The settled shared array `NV`, `(L + 1) * V`, in the mesh's own space (for a skinned mesh,
    /// the bind pose: see [`bind_space_positions`]; with morph targets, where zero weights put it).
    pub positions: &'a [Vec3],
    /// The fur's textures.
    pub textures: &'a FurTextures,
    /// How the renderer lays the shell tile on the mesh (`pelt_render::tile_mapping`).
    pub mapping: TileMapping,
    /// The renderer's brightness at the roots (`FurLook::root_occlusion`).
    pub root_occlusion: f32,
    /// Shells to write, `1..=L`, spread evenly up to the tips.
    pub shells: u32,
    /// The fur materials' alpha mode.
    pub alpha: AlphaMode,
    /// The skin to bind the fur to (a skinned source).
    pub skin: Option<FurSkin>,
    /// The glTF file the mesh came from: copied whole, and it draws the skin. Without one the
    /// base mesh is written as the skin, in the colour of the roots.
    pub source: Option<&'a Path>,
    /// Meshes drawn without fur (a try-on body) and their linear colours.
    pub plain: &'a [(&'a Mesh, Vec3)],
    /// Written as `asset.extras.pelt`: the preset, Pelt's version, how it was made.
    pub extras: Value,
    /// Morph targets on every fur primitive (the source's, or a wind loop) and what drives them.
    pub morphs: Option<FurMorphs>,
}

/// What the export holds of the fur, for reports and checks.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FurCounts {
    /// The exported shell layers, ascending (layer `L` last).
    pub shell_layers: Vec<u32>,
    /// Vertices of one shell (the wedges: a base vertex once per tile coordinate it takes).
    pub shell_vertices: usize,
    /// Triangles of one shell (`F`).
    pub shell_triangles: usize,
    /// Fin vertices (`2E` per strand node).
    pub fin_vertices: usize,
    /// Fin triangles (`2E` per exported layer).
    pub fin_triangles: usize,
}

/// A built glTF document, ready to write.
#[derive(Debug)]
pub struct Export {
    document: Document,
    /// What it holds of the fur.
    pub counts: FurCounts,
}

/// The layers `shells` exported shells sit on, out of `layers`: evenly spaced, the tips last.
#[must_use]
pub fn exported_layers(layers: u32, shells: u32) -> Vec<u32> {
    let shells = shells.clamp(1, layers.max(1));
    (1..=shells)
        .map(|k| ((u64::from(k) * u64::from(layers) + u64::from(shells) / 2) / u64::from(shells)) as u32)
        .collect()
}

/// The posed shared array `posed` (`(L + 1) * V`) taken back to the bind pose through each
/// strand's root skinning matrix (`Rig::vertex_matrices`), so a player's skinning puts it back.
/// A strand whose matrix cannot be inverted keeps `rest` (the structure's rest array).
#[must_use]
pub fn bind_space_positions(posed: &[Vec3], rest: &[Vec3], matrices: &[Mat4]) -> Vec<Vec3> {
    let v = matrices.len().max(1);
    let inverses: Vec<Option<Mat4>> = matrices
        .iter()
        .map(|m| (m.determinant().abs() > 1e-12).then(|| m.inverse()).filter(|i| i.is_finite()))
        .collect();
    posed
        .iter()
        .zip(rest)
        .enumerate()
        .map(|(k, (p, r))| inverses[k % v].map_or(*r, |inverse| inverse.transform_point3(*p)))
        .collect()
}

/// The joints (node indices) of every skin in the glTF file at `path`, in skin order.
///
/// # Errors
/// [`ExportError::Source`] for a file that is not readable glTF.
pub fn source_skin_joints(path: &Path) -> Result<Vec<Vec<usize>>, ExportError> {
    let gltf =
        gltf::Gltf::open(path).map_err(|e| ExportError::Source { file: path.to_path_buf(), problem: e.to_string() })?;
    Ok(gltf.skins().map(|skin| skin.joints().map(|joint| joint.index()).collect()).collect())
}

impl Export {
    /// Builds the document.
    ///
    /// # Errors
    /// [`ExportError::Input`] for arrays of the wrong size or a shell count outside `1..=L`,
    /// [`ExportError::Source`] for a source that cannot be read, [`ExportError::Image`].
    pub fn build(input: &ExportInput<'_>) -> Result<Self, ExportError> {
        let fur = input.fur;
        let v = fur.vertex_count();
        if input.positions.len() != (fur.layers as usize + 1) * v {
            return Err(ExportError::Input(format!(
                "{} positions for {} layers of {v} vertices",
                input.positions.len(),
                fur.layers + 1
            )));
        }
        if input.shells == 0 || input.shells > fur.layers {
            return Err(ExportError::Input(format!(
                "shells must be between 1 and {}, got {}",
                fur.layers, input.shells
            )));
        }
        if let Some(skin) = &input.skin
            && skin.influences.len() != v
        {
            return Err(ExportError::Input(format!("{} skin influences for {v} vertices", skin.influences.len())));
        }
        if let Some(morphs) = &input.morphs {
            morphs.check(input.positions.len())?;
        }
        let mut document = match input.source {
            Some(path) => Document::from_source(path)?,
            None => Document::new(),
        };
        set_asset(&mut document, &input.extras);
        let mut builder = Builder { input, document: &mut document };
        let mut primitives = builder.shells()?;
        let (fin_primitive, fin_counts) = builder.fins()?;
        primitives.push(fin_primitive);
        if input.source.is_none() {
            primitives.insert(0, builder.skin()?);
        }
        let mut mesh = json!({ "name": "pelt fur", "primitives": primitives });
        if let Some(morphs) = input.morphs.as_ref().filter(|m| !m.weights.is_empty()) {
            mesh["weights"] = json!(morphs.weights);
        }
        let mesh = document.push("meshes", mesh);
        let mut node = json!({ "name": "pelt fur", "mesh": mesh });
        if let Some(skin) = &input.skin {
            node["skin"] = json!(skin.skin);
        }
        let fur_node = document.add_root_node(node);
        if let Some(morphs) = &input.morphs {
            morphs.animate(&mut document, fur_node);
        }
        for (k, (mesh, colour)) in input.plain.iter().enumerate() {
            let primitive = plain_primitive(&mut document, mesh, *colour, k);
            let mesh = document.push("meshes", json!({ "name": format!("plain {k}"), "primitives": [primitive] }));
            document.add_root_node(json!({ "name": format!("plain {k}"), "mesh": mesh }));
        }
        let wedges = shell_wedges(fur, input.mapping);
        let counts = FurCounts {
            shell_layers: exported_layers(fur.layers, input.shells),
            shell_vertices: wedges.vertices.len(),
            shell_triangles: wedges.triangles.len(),
            fin_vertices: fin_counts.0,
            fin_triangles: fin_counts.1,
        };
        Ok(Self { document, counts })
    }

    /// The export as GLB bytes.
    #[must_use]
    pub fn glb(&self) -> Vec<u8> {
        self.document.glb()
    }

    /// Writes `path`: a `.glb`, or a `.gltf` with its buffer beside it as `<stem>.bin`. Each file
    /// is written to a temporary name and renamed, so a failure leaves no partial file.
    ///
    /// # Errors
    /// [`ExportError::Write`] naming the file, for an unknown extension or a failed write.
    pub fn write(&self, path: &Path) -> Result<(), ExportError> {
        let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("glb") => write_atomic(path, &self.glb()),
            Some("gltf") => {
                let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("fur");
                let bin_name = format!("{stem}.bin");
                let bin_path = path.with_file_name(&bin_name);
                write_atomic(&bin_path, &self.document.bin)?;
                write_atomic(path, &self.document.json_text(Some(&bin_name))).inspect_err(|_| {
                    let _ = std::fs::remove_file(&bin_path);
                })
            }
            _ => Err(ExportError::Write {
                file: path.to_path_buf(),
                problem: "the output must end in .glb or .gltf".to_owned(),
            }),
        }
    }
}

/// Writes `bytes` to a temporary file beside `path`, then renames it over `path`.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), ExportError> {
    let error = |problem: String| ExportError::Write { file: path.to_path_buf(), problem };
    let name = path.file_name().ok_or_else(|| error("not a file name".to_owned()))?;
    let temporary = path.with_file_name(format!(".{}.{}.partial", name.to_string_lossy(), std::process::id()));
    let result = std::fs::write(&temporary, bytes).and_then(|()| std::fs::rename(&temporary, path));
    result.map_err(|e| {
        let _ = std::fs::remove_file(&temporary);
        error(e.to_string())
    })
}

fn set_asset(document: &mut Document, extras: &Value) {
    let asset = &mut document.root["asset"];
    asset["generator"] = json!(format!("Pelt {}", env!("CARGO_PKG_VERSION")));
    if !asset.get("extras").is_some_and(Value::is_object) {
        asset["extras"] = json!({});
    }
    asset["extras"]["pelt"] = extras.clone();
}

/// Writes the fur's primitives into one document.
struct Builder<'a, 'b> {
    input: &'a ExportInput<'b>,
    document: &'a mut Document,
}

impl Builder<'_, '_> {
    /// JOINTS_0 and WEIGHTS_0 of the vertices `roots` (base vertices), when the fur is skinned.
    fn skin_attributes(&mut self, roots: &[u32], attributes: &mut Value) {
        if let Some(skin) = &self.input.skin {
            let (joints, weights): (Vec<[u16; 4]>, Vec<[f32; 4]>) =
                roots.iter().map(|&j| skin.influences[j as usize]).unzip();
            attributes["JOINTS_0"] = json!(self.document.joints(&joints));
            attributes["WEIGHTS_0"] = json!(self.document.vec4(&weights));
        }
    }

    /// The morph targets of a primitive whose vertices are the shared array's `nodes` (every
    /// primitive of a mesh carries the same targets).
    fn morph_targets(&mut self, nodes: &[usize], primitive: &mut Value) {
        if let Some(morphs) = &self.input.morphs {
            primitive["targets"] = morphs.primitive_targets(self.document, nodes);
        }
    }

    /// The surface colour mode's tint at each uv, as COLOR_0.
    fn tint(&mut self, uvs: Option<&Vec<glam::Vec2>>, attributes: &mut Value) {
        if let (Some(surface), Some(uvs)) = (&self.input.textures.surface, uvs) {
            let colours = surface_colours(surface, uvs);
            attributes["COLOR_0"] = json!(self.document.vec3(&colours, false));
        }
    }

    fn material(&mut self, name: String, texture: usize, brightness: f32) -> usize {
        let mut material = json!({
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorTexture": { "index": texture },
                "baseColorFactor": [brightness, brightness, brightness, 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 0.8,
            },
            "alphaMode": self.input.alpha.gltf(),
            "doubleSided": true,
        });
        if self.input.alpha == AlphaMode::Mask {
            material["alphaCutoff"] = json!(0.3);
        }
        self.document.push("materials", material)
    }

    fn shells(&mut self) -> Result<Vec<Value>, ExportError> {
        let input = self.input;
        let fur = input.fur;
        let v = fur.vertex_count();
        let wedges = shell_wedges(fur, input.mapping);
        let mut shared = json!({});
        shared["TEXCOORD_0"] = json!(self.document.vec2(&wedges.tile_uvs));
        let normals: Vec<Vec3> = wedges.vertices.iter().map(|&j| unit(fur.mesh.normals[j as usize])).collect();
        shared["NORMAL"] = json!(self.document.vec3(&normals, false));
        self.skin_attributes(&wedges.vertices, &mut shared);
        self.tint(wedges.mesh_uvs.as_ref(), &mut shared);
        let indices = self.document.indices(&wedges.triangles, wedges.vertices.len());
        let sampler = self.document.sampler(REPEAT, REPEAT);
        let layers = exported_layers(fur.layers, input.shells);
        let stride = fur.layers as f32 / layers.len() as f32;
        let textures = input.textures;
        let mut primitives = Vec::with_capacity(layers.len());
        for &layer in &layers {
            let slice = (layer - 1) * textures.layers / fur.layers;
            let png = images::slice_png(textures, slice, stride)?;
            let texture = self.document.png_texture(&png, sampler, &format!("pelt shell {layer}"));
            let brightness = images::occlusion(input.root_occlusion, layer as f32 / fur.layers as f32);
            let material = self.material(format!("pelt shell {layer}/{}", fur.layers), texture, brightness);
            let base = layer as usize * v;
            let positions: Vec<Vec3> = wedges.vertices.iter().map(|&j| input.positions[base + j as usize]).collect();
            let mut attributes = shared.clone();
            attributes["POSITION"] = json!(self.document.vec3(&positions, true));
            let mut primitive = json!({ "attributes": attributes, "indices": indices, "material": material });
            let nodes: Vec<usize> = wedges.vertices.iter().map(|&j| base + j as usize).collect();
            self.morph_targets(&nodes, &mut primitive);
            primitives.push(primitive);
        }
        Ok(primitives)
    }

    /// The fin primitive, and its vertex and triangle counts.
    fn fins(&mut self) -> Result<(Value, (usize, usize)), ExportError> {
        let input = self.input;
        let fur = input.fur;
        let v = fur.vertex_count();
        let mut nodes = vec![0];
        nodes.extend(exported_layers(fur.layers, input.shells));
        let fins = fins(fur, &nodes, input.mapping);
        let positions: Vec<Vec3> = fins
            .vertices
            .iter()
            .zip(&fins.layers)
            .map(|(&j, &i)| input.positions[i as usize * v + j as usize])
            .collect();
        let mut attributes = json!({});
        attributes["POSITION"] = json!(self.document.vec3(&positions, true));
        attributes["NORMAL"] = json!(self.document.vec3(&fins.normals, false));
        attributes["TEXCOORD_0"] = json!(self.document.vec2(&fins.uvs));
        self.skin_attributes(&fins.vertices, &mut attributes);
        self.tint(fins.mesh_uvs.as_ref(), &mut attributes);
        let indices = self.document.indices(&fins.triangles, fins.vertices.len());
        let sampler = self.document.sampler(REPEAT, CLAMP_TO_EDGE);
        let png = images::fin_png(input.textures, input.root_occlusion)?;
        let texture = self.document.png_texture(&png, sampler, "pelt fins");
        let material = self.material("pelt fins".to_owned(), texture, 1.0);
        let mut primitive = json!({ "attributes": attributes, "indices": indices, "material": material });
        let nodes: Vec<usize> =
            fins.vertices.iter().zip(&fins.layers).map(|(&j, &i)| i as usize * v + j as usize).collect();
        self.morph_targets(&nodes, &mut primitive);
        Ok((primitive, (fins.vertices.len(), fins.triangles.len())))
    }

    /// The base mesh drawn opaque in the colour of the roots, darkened as the renderer's skin
    /// (with the surface texture in the surface colour mode).
    fn skin(&mut self) -> Result<Value, ExportError> {
        let input = self.input;
        let mesh = &input.fur.mesh;
        let colour = root_colour(input.textures) * input.root_occlusion;
        let mut material = json!({
            "name": "pelt skin",
            "pbrMetallicRoughness": {
                "baseColorFactor": [colour.x, colour.y, colour.z, 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 0.9,
            },
        });
        let mut attributes = json!({});
        let (roots, triangles) = match mesh.wedges() {
            Some(wedges) => {
                attributes["TEXCOORD_0"] = json!(self.document.vec2(&wedges.uvs));
                if let Some(surface) = &input.textures.surface {
                    let png = images::png(&surface.pixels, surface.width, surface.height)?;
                    let sampler = self.document.sampler(REPEAT, REPEAT);
                    let texture = self.document.png_texture(&png, sampler, "pelt surface");
                    material["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": texture });
                }
                let triangles: Vec<[u32; 3]> = wedges.corners.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
                (wedges.vertices, triangles)
            }
            None => ((0..mesh.vertex_count() as u32).collect(), mesh.triangles.clone()),
        };
        let positions: Vec<Vec3> = roots.iter().map(|&j| input.positions[j as usize]).collect();
        let normals: Vec<Vec3> = roots.iter().map(|&j| unit(mesh.normals[j as usize])).collect();
        attributes["POSITION"] = json!(self.document.vec3(&positions, true));
        attributes["NORMAL"] = json!(self.document.vec3(&normals, false));
        self.skin_attributes(&roots, &mut attributes);
        let indices = self.document.indices(&triangles, roots.len());
        let material = self.document.push("materials", material);
        let mut primitive = json!({ "attributes": attributes, "indices": indices, "material": material });
        let nodes: Vec<usize> = roots.iter().map(|&j| j as usize).collect();
        self.morph_targets(&nodes, &mut primitive);
        Ok(primitive)
    }
}

/// A plain mesh's primitive, lit in `colour`.
fn plain_primitive(document: &mut Document, mesh: &Mesh, colour: Vec3, k: usize) -> Value {
    let normals: Vec<Vec3> = mesh.normals.iter().map(|n| unit(*n)).collect();
    let attributes = json!({
        "POSITION": document.vec3(&mesh.positions, true),
        "NORMAL": document.vec3(&normals, false),
    });
    let indices = document.indices(&mesh.triangles, mesh.vertex_count());
    let material = document.push(
        "materials",
        json!({
            "name": format!("plain {k}"),
            "pbrMetallicRoughness": { "baseColorFactor": [colour.x, colour.y, colour.z, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.9 },
        }),
    );
    json!({ "attributes": attributes, "indices": indices, "material": material })
}

/// A unit normal (glTF requires them), up for a degenerate one.
fn unit(n: Vec3) -> Vec3 {
    n.try_normalize().unwrap_or(Vec3::Y)
}

/// The colour of the fur at the roots, linear: the first slice with strands, weighted by
/// coverage (the renderer's skin colour).
fn root_colour(textures: &FurTextures) -> Vec3 {
    for k in 0..textures.layers {
        let (mut sum, mut weight) = (Vec3::ZERO, 0.0);
        for texel in textures.slice(k).chunks_exact(4) {
            let alpha = f32::from(texel[3]) / 255.0;
            let rgb = Vec3::new(texel[0].into(), texel[1].into(), texel[2].into()) / 255.0;
            sum += rgb.map(srgb_to_linear) * alpha;
            weight += alpha;
        }
        if weight > 0.0 {
            return sum / weight;
        }
    }
    Vec3::splat(0.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exported_layers_spread_to_the_tips() {
        assert_eq!(exported_layers(16, 16), (1..=16).collect::<Vec<_>>());
        assert_eq!(exported_layers(16, 4), [4, 8, 12, 16]);
        assert_eq!(exported_layers(16, 1), [16]);
        assert_eq!(exported_layers(5, 2), [3, 5]);
    }

    #[test]
    fn bind_space_undoes_the_pose() {
        let matrix = Mat4::from_rotation_y(0.7) * Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0));
        let rest = [Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.5, 1.0, 0.0)];
        let posed: Vec<Vec3> = rest.iter().map(|p| matrix.transform_point3(*p)).collect();
        let back = bind_space_positions(&posed, &rest, &[matrix]);
        for (b, r) in back.iter().zip(rest) {
            assert!(b.distance(r) < 1e-5, "{b} vs {r}");
        }
        let flat = bind_space_positions(&posed, &rest, &[Mat4::ZERO]);
        assert_eq!(flat, rest);
    }
}
