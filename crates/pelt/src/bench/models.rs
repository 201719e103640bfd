//! The paper's kinds of model and where Pelt gets a stand-in for each.

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use glam::{Vec2, Vec3};
use pelt_core::anim::Rig;
use pelt_core::mesh::RawMesh;
use pelt_core::{Builtin, ImportOptions, Mesh};

/// Where a mesh comes from.
#[derive(Clone, Copy, Debug)]
pub enum MeshSource {
    Builtin(Builtin),
    /// A file name under the assets' `meshes/` folder.
    Asset(&'static str),
}

impl MeshSource {
    pub fn describe(self) -> String {
        match self {
            Self::Builtin(builtin) => format!("builtin:{builtin}"),
            Self::Asset(file) => format!("assets/meshes/{file}"),
        }
    }

    /// The mesh, and its rig where the file is an animated glTF.
    fn load(self, meshes_dir: &Path) -> anyhow::Result<(Mesh, Option<Rig>)> {
        match self {
            Self::Builtin(builtin) => Ok((builtin.mesh().0, None)),
            Self::Asset(file) => {
                let path = meshes_dir.join(file);
                let (mesh, _, rig) = Mesh::load_animated(&path, &ImportOptions::default())
                    .with_context(|| format!("cannot load {}", path.display()))?;
                Ok((mesh, rig))
            }
        }
    }
}

/// One row kind of the paper's Table 2 and the mesh(es) standing in for it.
#[derive(Clone, Copy, Debug)]
pub struct ModelSpec {
    /// Stable key in the JSON report.
    pub key: &'static str,
    /// The paper's name for the model this stands in for.
    pub paper_model: &'static str,
    /// The mesh the fur grows on.
    pub fur: MeshSource,
    /// A mesh drawn without fur under the furred one (the paper's "Women (with shawl)").
    pub body: Option<MeshSource>,
    /// The animation posed every frame (skinning figures), for an animated file.
    pub animation: Option<&'static str>,
}

/// The paper's five models, in its Table 2 order, then the walking Fox.
pub const MODELS: [ModelSpec; 6] = [
    ModelSpec { key: "box", paper_model: "Box", fur: MeshSource::Builtin(Builtin::Box), body: None, animation: None },
    ModelSpec {
        key: "bunny",
        paper_model: "Bunny",
        fur: MeshSource::Builtin(Builtin::Bunny),
        body: None,
        animation: None,
    },
    ModelSpec { key: "spot", paper_model: "Boar", fur: MeshSource::Asset("spot.obj"), body: None, animation: None },
    ModelSpec {
        key: "skirt",
        paper_model: "Shawl",
        fur: MeshSource::Asset("skirthelper.obj"),
        body: None,
        animation: None,
    },
    ModelSpec {
        key: "women",
        paper_model: "Women (with shawl)",
        fur: MeshSource::Asset("skirthelper.obj"),
        body: Some(MeshSource::Asset("female_generic.obj")),
        animation: None,
    },
    // Not in the paper: a skinned character, posed every frame.
    ModelSpec {
        key: "fox",
        paper_model: "none (animated Fox)",
        fur: MeshSource::Asset("Fox.glb"),
        body: None,
        animation: Some("Walk"),
    },
];

/// A model's meshes, loaded.
#[derive(Debug)]
pub struct Model {
    pub spec: ModelSpec,
    /// The furred mesh.
    pub fur: Mesh,
    /// The un-furred body, if any.
    pub body: Option<Mesh>,
    /// The furred mesh's rig, for an animated file.
    pub rig: Option<Rig>,
}

impl Model {
    pub fn load(spec: ModelSpec, meshes_dir: &Path) -> anyhow::Result<Self> {
        let (fur, rig) = spec.fur.load(meshes_dir)?;
        let body = spec.body.map(|body| body.load(meshes_dir).map(|(mesh, _)| mesh)).transpose()?;
        Ok(Self { spec, fur, body, rig })
    }

    /// The mesh sources, as the report names them (`fur` or `body + fur`).
    pub fn source(&self) -> String {
        match self.spec.body {
            Some(body) => format!("{} + {}", body.describe(), self.spec.fur.describe()),
            None => self.spec.fur.describe(),
        }
    }
}

/// The folder holding the meshes: `explicit`, else `assets/meshes` under the working directory,
/// else the workspace's own (so `cargo run` and the tests work from any crate folder).
pub fn meshes_dir(explicit: Option<&Path>) -> PathBuf {
    if let Some(dir) = explicit {
        return dir.to_path_buf();
    }
    let local = PathBuf::from("assets/meshes");
    if local.is_dir() {
        return local;
    }
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/meshes"))
}

/// Vertices of the large mesh the simulation's throughput is also measured on.
pub const LARGE_MESH_VERTICES: u32 = LARGE_MESH_SEGMENTS * LARGE_MESH_SIDES;
const LARGE_MESH_SEGMENTS: u32 = 250;
const LARGE_MESH_SIDES: u32 = 140;
/// How the report names it.
pub const LARGE_MESH: &str = "generated torus, 250 x 140 vertices";

/// A closed torus of 35,000 vertices (major radius 1, minor 0.4): a mesh at the scale of an
/// animated character, generated so the bench needs no large file.
pub fn large_mesh() -> anyhow::Result<Mesh> {
    let (n, m) = (LARGE_MESH_SEGMENTS, LARGE_MESH_SIDES);
    let mut raw = RawMesh { uvs: Some(Vec::new()), ..RawMesh::default() };
    for i in 0..n {
        let around = std::f32::consts::TAU * i as f32 / n as f32;
        for k in 0..m {
            let tube = std::f32::consts::TAU * k as f32 / m as f32;
            let radial = Vec3::new(around.cos(), 0.0, -around.sin());
            raw.positions.push(radial * (1.0 + 0.4 * tube.cos()) + Vec3::Y * (0.4 * tube.sin()));
            if let Some(uvs) = &mut raw.uvs {
                uvs.push(Vec2::new(i as f32 / n as f32, k as f32 / m as f32));
            }
        }
    }
    let index = |i: u32, k: u32| (i % n) * m + (k % m);
    for i in 0..n {
        for k in 0..m {
            let (a, b, c, d) = (index(i, k), index(i + 1, k), index(i + 1, k + 1), index(i, k + 1));
            raw.triangles.push([a, b, c]);
            raw.triangles.push([a, c, d]);
        }
    }
    let (mesh, _) = Mesh::from_raw(raw, Path::new("generated:torus"), &ImportOptions::default())?;
    Ok(mesh)
}
