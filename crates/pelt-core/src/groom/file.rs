//! The per-vertex groom file (`.groom`): a small binary file, all numbers little-endian.
//!
//! | offset | bytes | content |
//! |---|---|---|
//! | 0 | 8 | magic `PELTGROM` |
//! | 8 | 4 | version, `u32` = 1 |
//! | 12 | 4 | `V`, the mesh's vertex count, `u32` |
//! | 16 | 8 | the mesh's positions hash ([`super::mesh_hash`]), `u64` |
//! | 24 | 4 | the maps present, `u32` bits: 1 length, 2 density, 4 direction, 8 clump, 16 tint |
//! | 28 | ... | each present map in that order, `V * components` `f32` (vertex-major: direction `x y`, tint `r g b`) |
//! | end - 8 | 8 | 64-bit FNV-1a of every byte before it, `u64` |
//!
//! Writing goes to a temporary file beside the target, then renames it, so a failed write never
//! leaves a partial file. Encoding is deterministic: reading a file and writing it again gives
//! the same bytes.

use std::io::Write;
use std::path::{Path, PathBuf};

use super::{Fnv, Groom, GroomError, GroomMap, mesh_hash};
use crate::mesh::Mesh;

/// The first 8 bytes of every groom file.
pub const FILE_MAGIC: [u8; 8] = *b"PELTGROM";
/// The groom file version this Pelt writes and reads.
pub const FILE_VERSION: u32 = 1;

const HEADER_BYTES: usize = 28;
const CHECKSUM_BYTES: usize = 8;

impl Groom {
    /// The groom as groom-file bytes for `mesh`.
    ///
    /// # Errors
    /// [`GroomError::Size`] or [`GroomError::Value`] if the groom does not fit `mesh` (nothing
    /// invalid is ever written).
    pub fn to_file_bytes(&self, mesh: &Mesh) -> Result<Vec<u8>, GroomError> {
        self.validate(mesh.vertex_count(), "the groom to write")?;
        let mut bytes = Vec::with_capacity(HEADER_BYTES + self.bytes() as usize + CHECKSUM_BYTES);
        bytes.extend_from_slice(&FILE_MAGIC);
        bytes.extend_from_slice(&FILE_VERSION.to_le_bytes());
        bytes.extend_from_slice(&(mesh.vertex_count() as u32).to_le_bytes());
        bytes.extend_from_slice(&mesh_hash(mesh).to_le_bytes());
        let mut present = 0u32;
        for (bit, map) in GroomMap::ALL.into_iter().enumerate() {
            if self.has(map) {
                present |= 1 << bit;
            }
        }
        bytes.extend_from_slice(&present.to_le_bytes());
        for map in GroomMap::ALL {
            for value in self.values(map).unwrap_or_default() {
                bytes.extend_from_slice(&value.to_le_bytes());
            }
        }
        let mut checksum = Fnv::new();
        checksum.write(&bytes);
        bytes.extend_from_slice(&checksum.finish().to_le_bytes());
        Ok(bytes)
    }

    /// Reads groom-file bytes for `mesh`; `file` and `mesh_name` name them in messages.
    ///
    /// # Errors
    /// [`GroomError::Format`] for a malformed file, [`GroomError::WrongMesh`] for a groom made
    /// for another mesh, [`GroomError::Value`] for NaN, infinity or values out of range.
    pub fn from_file_bytes(bytes: &[u8], file: &Path, mesh: &Mesh, mesh_name: &str) -> Result<Self, GroomError> {
        let format = |problem: String| GroomError::Format { file: file.to_path_buf(), problem };
        if bytes.len() < HEADER_BYTES + CHECKSUM_BYTES || bytes[..8] != FILE_MAGIC {
            return Err(format("it does not start with PELTGROM".to_owned()));
        }
        let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
        let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"));
        let version = u32_at(8);
        if version != FILE_VERSION {
            return Err(format(format!("version {version}, but this Pelt reads version {FILE_VERSION}")));
        }
        let body_end = bytes.len() - CHECKSUM_BYTES;
        let mut checksum = Fnv::new();
        checksum.write(&bytes[..body_end]);
        if checksum.finish() != u64_at(body_end) {
            return Err(format("its checksum does not match (the file is damaged or truncated)".to_owned()));
        }
        let (file_vertices, file_hash, present) = (u32_at(12) as usize, u64_at(16), u32_at(24));
        let (mesh_vertices, mesh_hash) = (mesh.vertex_count(), mesh_hash(mesh));
        if file_vertices != mesh_vertices || file_hash != mesh_hash {
            return Err(GroomError::WrongMesh {
                file: file.to_path_buf(),
                file_vertices,
                file_hash,
                mesh: mesh_name.to_owned(),
                mesh_vertices,
                mesh_hash,
            });
        }
        if present >> GroomMap::ALL.len() != 0 {
            return Err(format(format!("unknown maps (bits {present:#x})")));
        }
        let maps: Vec<GroomMap> = GroomMap::ALL
            .into_iter()
            .enumerate()
            .filter(|(bit, _)| present & (1 << bit) != 0)
            .map(|(_, m)| m)
            .collect();
        let floats: usize = maps.iter().map(|m| m.components() * file_vertices).sum();
        let expected = HEADER_BYTES + 4 * floats + CHECKSUM_BYTES;
        if bytes.len() != expected {
            return Err(format(format!("{} bytes, but its header says {expected}", bytes.len())));
        }
        let mut groom = Self::default();
        let mut at = HEADER_BYTES;
        for map in maps {
            let count = map.components() * file_vertices;
            let values = bytes[at..at + 4 * count]
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
                .collect();
            groom.set_values(map, values);
            at += 4 * count;
        }
        groom.validate(mesh_vertices, &file.display().to_string())?;
        Ok(groom)
    }

    /// Reads a groom file for `mesh` (`mesh_name` names the mesh in messages).
    ///
    /// # Errors
    /// [`GroomError::Io`] for a file that cannot be read, else as [`Groom::from_file_bytes`].
    pub fn load(file: &Path, mesh: &Mesh, mesh_name: &str) -> Result<Self, GroomError> {
        let bytes = std::fs::read(file).map_err(|error| GroomError::Io { file: file.to_path_buf(), error })?;
        Self::from_file_bytes(&bytes, file, mesh, mesh_name)
    }

    /// Writes the groom for `mesh` to `file`, through a temporary file beside it and a rename,
    /// so a failed write leaves no partial file (and an existing file untouched).
    ///
    /// # Errors
    /// As [`Groom::to_file_bytes`], and [`GroomError::Io`] naming the file.
    pub fn save(&self, file: &Path, mesh: &Mesh) -> Result<(), GroomError> {
        let bytes = self.to_file_bytes(mesh)?;
        let io = |error| GroomError::Io { file: file.to_path_buf(), error };
        let temporary = temporary_beside(file);
        let written = (|| {
            let mut out = std::fs::File::create(&temporary)?;
            out.write_all(&bytes)?;
            out.sync_all()?;
            std::fs::rename(&temporary, file)
        })();
        if let Err(error) = written {
            // Best effort: the temporary may not exist; the error that matters is the write's.
            let _ = std::fs::remove_file(&temporary);
            return Err(io(error));
        }
        Ok(())
    }
}

/// `.<name>.tmp<pid>` in `file`'s folder (a rename within one folder is atomic).
fn temporary_beside(file: &Path) -> PathBuf {
    let name = file.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    file.with_file_name(format!(".{name}.tmp{}", std::process::id()))
}
