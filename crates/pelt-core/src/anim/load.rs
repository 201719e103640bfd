//! Mesh and rig from one glTF file: the mesh reader's parse, with [`read_rig`] reading the rest
//! of the same document. It lives here, above `mesh`, so the mesh module never needs the rig.

use std::path::Path;

use super::Rig;
use super::gltf_rig::read_rig;
use crate::mesh::{ImportOptions, Mesh, MeshError, MeshReport, gltf};

impl Mesh {
    /// Loads a mesh file like [`Mesh::load`], with its [`Rig`] when it is a glTF file with skins,
    /// animations or morph targets (`None` otherwise). The mesh is the static import (the bind
    /// pose); the rig poses it. Problems with skins and animations the loader could handle are
    /// lines in [`Rig::report`].
    ///
    /// # Errors
    /// As [`Mesh::load`], and [`MeshError::Parse`] for skin or animation data that cannot be read.
    pub fn load_animated(path: &Path, options: &ImportOptions) -> Result<(Self, MeshReport, Option<Rig>), MeshError> {
        let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
        if !matches!(extension.as_str(), "gltf" | "glb") || !path.exists() {
            return Self::load(path, options).map(|(mesh, report)| (mesh, report, None));
        }
        let (raw, colour_sets, rig) = gltf::load_with(path, read_rig)?;
        let (mesh, report, source) = Self::repair(raw, &colour_sets, path, options)?;
        Ok((mesh, report, rig.map(|rig| rig.finish(&source))))
    }

    /// [`Mesh::from_gltf_slice`] with the [`Rig`], as [`Mesh::load_animated`].
    ///
    /// # Errors
    /// As [`Mesh::load_animated`].
    pub fn from_gltf_slice_animated(
        bytes: &[u8],
        name: &Path,
        options: &ImportOptions,
    ) -> Result<(Self, MeshReport, Option<Rig>), MeshError> {
        let (raw, colour_sets, rig) = gltf::parse_with(bytes, name, None, read_rig)?;
        let (mesh, report, source) = Self::repair(raw, &colour_sets, name, options)?;
        Ok((mesh, report, rig.map(|rig| rig.finish(&source))))
    }
}
