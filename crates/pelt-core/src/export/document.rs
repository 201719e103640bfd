//! A glTF document under construction: the JSON as a `serde_json` value (so a source file's own
//! objects, extensions and extras are carried over untouched) and one binary buffer.

use std::path::Path;

use glam::{Vec2, Vec3};
use serde_json::{Value, json};

use super::ExportError;

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;

/// glTF's REPEAT and CLAMP_TO_EDGE wrap modes, and its trilinear filters.
pub(super) const REPEAT: u32 = 10497;
pub(super) const CLAMP_TO_EDGE: u32 = 33071;
const LINEAR: u32 = 9729;
const LINEAR_MIPMAP_LINEAR: u32 = 9987;

/// The JSON and the one buffer of a glTF file being written.
#[derive(Debug)]
pub(super) struct Document {
    pub root: Value,
    pub bin: Vec<u8>,
}

impl Document {
    /// An empty document.
    pub fn new() -> Self {
        Self {
            root: json!({ "asset": { "version": "2.0" }, "scene": 0, "scenes": [{ "nodes": [] }] }),
            bin: Vec::new(),
        }
    }

    /// Everything in the glTF file at `path`, its buffers joined into one and its images moved
    /// into that buffer (so the export stands alone wherever it is written).
    pub fn from_source(path: &Path) -> Result<Self, ExportError> {
        let error = |problem: String| ExportError::Source { file: path.to_path_buf(), problem };
        let bytes = std::fs::read(path).map_err(|e| error(e.to_string()))?;
        let json_bytes = if bytes.starts_with(b"glTF") {
            gltf::binary::Glb::from_slice(&bytes).map_err(|e| error(e.to_string()))?.json.into_owned()
        } else {
            bytes.clone()
        };
        let mut root: Value = serde_json::from_slice(&json_bytes).map_err(|e| error(e.to_string()))?;
        let gltf::Gltf { document, blob } = gltf::Gltf::from_slice(&bytes).map_err(|e| error(e.to_string()))?;
        let buffers =
            gltf::import_buffers(&document, path.parent(), blob).map_err(|e| error(format!("a buffer: {e}")))?;
        let mut out = Self { root: Value::Null, bin: Vec::new() };
        let mut starts = Vec::with_capacity(buffers.len());
        for data in &buffers {
            out.align(16);
            starts.push(out.bin.len() as u64);
            out.bin.extend_from_slice(&data.0);
        }
        for view in root.get_mut("bufferViews").and_then(Value::as_array_mut).into_iter().flatten() {
            let buffer = view["buffer"].as_u64().unwrap_or(0) as usize;
            let start = starts.get(buffer).copied().ok_or_else(|| error(format!("no buffer {buffer}")))?;
            view["buffer"] = json!(0);
            view["byteOffset"] = json!(start + view["byteOffset"].as_u64().unwrap_or(0));
        }
        let images = root.get_mut("images").and_then(Value::as_array_mut).map(std::mem::take).unwrap_or_default();
        let mut moved = Vec::with_capacity(images.len());
        for mut image in images {
            if let Some(uri) = image.get("uri").and_then(Value::as_str).map(str::to_owned) {
                let (data, mime) =
                    image_bytes(path, &uri).map_err(|problem| error(format!("image {uri:?}: {problem}")))?;
                let view = out.view(&data, None);
                let object = image.as_object_mut().ok_or_else(|| error("an image is not an object".to_owned()))?;
                object.remove("uri");
                object.insert("bufferView".to_owned(), json!(view));
                object.entry("mimeType").or_insert(json!(mime));
            }
            moved.push(image);
        }
        if !moved.is_empty() {
            root["images"] = Value::Array(moved);
        }
        root.as_object_mut().ok_or_else(|| error("the JSON is not an object".to_owned()))?.remove("buffers");
        if root.get("scenes").and_then(Value::as_array).is_none_or(Vec::is_empty) {
            root["scenes"] = json!([{ "nodes": [] }]);
        }
        if root.get("scene").is_none() {
            root["scene"] = json!(0);
        }
        out.root = root;
        Ok(out)
    }

    fn align(&mut self, to: usize) {
        self.bin.resize(self.bin.len().next_multiple_of(to), 0);
    }

    /// Appends `value` to the top-level array `key`; its index.
    pub fn push(&mut self, key: &str, value: Value) -> usize {
        let array = self.root.as_object_mut().expect("the document root is an object").entry(key).or_insert(json!([]));
        let array = array.as_array_mut().expect("top-level glTF collections are arrays");
        array.push(value);
        array.len() - 1
    }

    /// Adds `node` to the default scene's root nodes.
    pub fn add_root_node(&mut self, node: Value) -> usize {
        let index = self.push("nodes", node);
        let scene = self.root["scene"].as_u64().unwrap_or(0) as usize;
        if let Some(nodes) = self.root["scenes"][scene].as_object_mut().map(|s| s.entry("nodes").or_insert(json!([]))) {
            nodes.as_array_mut().expect("a scene's nodes are an array").push(json!(index));
        }
        index
    }

    /// A buffer view over `bytes` (4-aligned); its index.
    pub fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        self.align(4);
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let mut view = json!({ "buffer": 0, "byteOffset": offset, "byteLength": bytes.len() });
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        self.push("bufferViews", view)
    }

    fn accessor(&mut self, bytes: &[u8], target: u32, accessor: Value) -> usize {
        let view = self.view(bytes, Some(target));
        let mut accessor = accessor;
        accessor["bufferView"] = json!(view);
        self.push("accessors", accessor)
    }

    /// A VEC3 float accessor (with its bounds, which POSITION needs).
    pub fn vec3(&mut self, values: &[Vec3], bounds: bool) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_array()).flat_map(f32::to_le_bytes).collect();
        let mut accessor = json!({ "componentType": FLOAT, "count": values.len(), "type": "VEC3" });
        if bounds {
            let low = values.iter().fold(Vec3::splat(f32::INFINITY), |a, b| a.min(*b));
            let high = values.iter().fold(Vec3::splat(f32::NEG_INFINITY), |a, b| a.max(*b));
            accessor["min"] = json!(low.to_array());
            accessor["max"] = json!(high.to_array());
        }
        self.accessor(&bytes, ARRAY_BUFFER, accessor)
    }

    /// A SCALAR float accessor of animation keys (a buffer view with no target), with its bounds
    /// where asked (a sampler's input needs them).
    pub fn animation_floats(&mut self, values: &[f32], bounds: bool) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, None);
        let mut accessor =
            json!({ "bufferView": view, "componentType": FLOAT, "count": values.len(), "type": "SCALAR" });
        if bounds {
            accessor["min"] = json!([values.iter().copied().fold(f32::INFINITY, f32::min)]);
            accessor["max"] = json!([values.iter().copied().fold(f32::NEG_INFINITY, f32::max)]);
        }
        self.push("accessors", accessor)
    }

    /// A VEC2 float accessor.
    pub fn vec2(&mut self, values: &[Vec2]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_array()).flat_map(f32::to_le_bytes).collect();
        self.accessor(&bytes, ARRAY_BUFFER, json!({ "componentType": FLOAT, "count": values.len(), "type": "VEC2" }))
    }

    /// A VEC4 unsigned short accessor (JOINTS_0).
    pub fn joints(&mut self, values: &[[u16; 4]]) -> usize {
        let bytes: Vec<u8> = values.iter().flatten().flat_map(|j| j.to_le_bytes()).collect();
        let accessor = json!({ "componentType": UNSIGNED_SHORT, "count": values.len(), "type": "VEC4" });
        self.accessor(&bytes, ARRAY_BUFFER, accessor)
    }

    /// A VEC4 float accessor (WEIGHTS_0).
    pub fn vec4(&mut self, values: &[[f32; 4]]) -> usize {
        let bytes: Vec<u8> = values.iter().flatten().flat_map(|w| w.to_le_bytes()).collect();
        self.accessor(&bytes, ARRAY_BUFFER, json!({ "componentType": FLOAT, "count": values.len(), "type": "VEC4" }))
    }

    /// A triangle index accessor: 16-bit where the vertices allow it.
    pub fn indices(&mut self, triangles: &[[u32; 3]], vertex_count: usize) -> usize {
        let count = triangles.len() * 3;
        if vertex_count <= usize::from(u16::MAX) {
            let bytes: Vec<u8> = triangles.iter().flatten().flat_map(|&i| (i as u16).to_le_bytes()).collect();
            let accessor = json!({ "componentType": UNSIGNED_SHORT, "count": count, "type": "SCALAR" });
            self.accessor(&bytes, ELEMENT_ARRAY_BUFFER, accessor)
        } else {
            let bytes: Vec<u8> = triangles.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
            let accessor = json!({ "componentType": UNSIGNED_INT, "count": count, "type": "SCALAR" });
            self.accessor(&bytes, ELEMENT_ARRAY_BUFFER, accessor)
        }
    }

    /// A sampler with trilinear filtering and the given wrap modes; its index.
    pub fn sampler(&mut self, wrap_s: u32, wrap_t: u32) -> usize {
        self.push(
            "samplers",
            json!({ "magFilter": LINEAR, "minFilter": LINEAR_MIPMAP_LINEAR, "wrapS": wrap_s, "wrapT": wrap_t }),
        )
    }

    /// A PNG image stored in the buffer and a texture sampling it; the texture's index.
    pub fn png_texture(&mut self, png: &[u8], sampler: usize, name: &str) -> usize {
        let view = self.view(png, None);
        let image = self.push("images", json!({ "name": name, "bufferView": view, "mimeType": "image/png" }));
        self.push("textures", json!({ "sampler": sampler, "source": image }))
    }

    /// The JSON text, with the buffer given `uri` (a `.gltf` beside its `.bin`) or none (GLB).
    pub fn json_text(&self, uri: Option<&str>) -> Vec<u8> {
        let mut root = self.root.clone();
        let mut buffer = json!({ "byteLength": self.bin.len() });
        if let Some(uri) = uri {
            buffer["uri"] = json!(uri);
        }
        if !self.bin.is_empty() {
            root["buffers"] = json!([buffer]);
        }
        serde_json::to_vec(&root).expect("a JSON value always serialises")
    }

    /// The GLB container: header, JSON chunk (space-padded), BIN chunk (zero-padded).
    pub fn glb(&self) -> Vec<u8> {
        let mut json = self.json_text(None);
        json.resize(json.len().next_multiple_of(4), b' ');
        let mut bin = self.bin.clone();
        bin.resize(bin.len().next_multiple_of(4), 0);
        let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2_u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        if !bin.is_empty() {
            out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
            out.extend_from_slice(b"BIN\0");
            out.extend_from_slice(&bin);
        }
        out
    }
}

/// The bytes and MIME type of an image given by `uri`: a `data:` URI or a file beside `source`.
fn image_bytes(source: &Path, uri: &str) -> Result<(Vec<u8>, String), String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, payload) = rest.split_once(',').ok_or("a data URI without a comma")?;
        let mime = header.split(';').next().unwrap_or("image/png").to_owned();
        if !header.ends_with(";base64") {
            return Err("a data URI that is not base64".to_owned());
        }
        return Ok((base64_decode(payload)?, mime));
    }
    let path = source.parent().unwrap_or(Path::new(".")).join(percent_decode(uri));
    let data = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mime = if data.starts_with(&[0xff, 0xd8]) { "image/jpeg" } else { "image/png" };
    Ok((data, mime.to_owned()))
}

fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut k = 0;
    while k < bytes.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if bytes[k] == b'%'
            && let (Some(h), Some(l)) = (bytes.get(k + 1).and_then(|&c| hex(c)), bytes.get(k + 2).and_then(|&c| hex(c)))
        {
            out.push((h * 16 + l) as u8);
            k += 3;
        } else {
            out.push(bytes[k]);
            k += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn base64_decode(text: &str) -> Result<Vec<u8>, String> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => Some(c - b'A'),
        b'a'..=b'z' => Some(c - b'a' + 26),
        b'0'..=b'9' => Some(c - b'0' + 52),
        b'+' | b'-' => Some(62),
        b'/' | b'_' => Some(63),
        _ => None,
    };
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let (mut bits, mut held) = (0_u32, 0);
    for c in text.bytes().filter(|c| !c.is_ascii_whitespace() && *c != b'=') {
        bits = (bits << 6) | u32::from(value(c).ok_or("a character outside base64")?);
        held += 6;
        if held >= 8 {
            held -= 8;
            out.push((bits >> held) as u8);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_and_percent_decode() {
        assert_eq!(base64_decode("aGVsbG8gd29ybGQ=").unwrap(), b"hello world");
        assert_eq!(base64_decode("AAEC").unwrap(), [0, 1, 2]);
        assert!(base64_decode("a*b").is_err());
        assert_eq!(percent_decode("fox%20tex.png"), "fox tex.png");
    }

    #[test]
    fn glb_chunks_are_aligned() {
        let mut document = Document::new();
        document.vec3(&[Vec3::ONE, Vec3::ZERO], true);
        let glb = document.glb();
        assert_eq!(&glb[..4], b"glTF");
        assert_eq!(u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize, glb.len());
        let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
        assert_eq!(json_len % 4, 0);
        let gltf = gltf::Gltf::from_slice(&glb).expect("the GLB parses");
        assert_eq!(gltf.accessors().count(), 1);
    }
}
