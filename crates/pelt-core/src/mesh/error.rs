//! Errors from reading and validating meshes.

use std::path::PathBuf;

/// Errors from reading or validating a mesh. Each names the file (or built-in) it came from.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    // The cause is part of the message (not a `source`) so it is printed exactly once.
    /// A built-in mesh name Pelt does not have.
    #[error("unknown built-in mesh {name:?}; choose one of {choices}")]
    UnknownBuiltin {
        /// The name asked for.
        name: String,
        /// Every name there is.
        choices: String,
    },
    /// The file could not be read.
    #[error("{}: cannot read the file: {error}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// Why it could not be read.
        error: std::io::Error,
    },
    /// The file's extension is no mesh format Pelt reads.
    #[error("{}: unknown mesh format {extension:?} (Pelt reads .obj, .gltf and .glb)", file.display())]
    UnknownFormat {
        /// The file.
        file: PathBuf,
        /// Its extension.
        extension: String,
    },
    /// The file is malformed.
    #[error("{}{}: {message}", file.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Parse {
        /// The file.
        file: PathBuf,
        /// The line, where the format has lines.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// No usable triangle is left.
    #[error("{}: the mesh has no triangles{detail}", file.display())]
    NoTriangles {
        /// The file.
        file: PathBuf,
        /// What was dropped, if anything.
        detail: String,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("{}: triangle {triangle} uses vertex index {index}, but the mesh has only {vertex_count} vertices", file.display())]
    IndexOutOfRange {
        /// The file.
        file: PathBuf,
        /// The triangle.
        triangle: usize,
        /// The vertex index it uses.
        index: u32,
        /// Vertices in the mesh.
        vertex_count: usize,
    },
    /// A vertex has a NaN or infinite coordinate.
    #[error("{}: vertex {vertex} has a non-finite coordinate {position:?} (NaN or infinity)", file.display())]
    NonFinite {
        /// The file.
        file: PathBuf,
        /// The vertex.
        vertex: usize,
        /// Its coordinates.
        position: [f32; 3],
    },
}
