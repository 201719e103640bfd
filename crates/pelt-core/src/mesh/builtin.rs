//! Meshes built into Pelt, so every command works with no files at all.

use std::f32::consts::{PI, TAU};
use std::fmt;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::{ImportOptions, Mesh, MeshReport, RawMesh};

/// The Stanford bunny (low resolution), embedded. Credits in `assets/CREDITS.md`.
const BUNNY_OBJ: &str = include_str!("../../assets/meshes/bunny.obj");

/// The `--builtin` name of the paper's virtual try-on scene ([`try_on_scene`]).
pub const TRY_ON_NAME: &str = "tryon";
pub(crate) const TRY_ON_GARMENT_OBJ: &str = include_str!("../../assets/meshes/skirthelper.obj");
pub(crate) const TRY_ON_BODY_OBJ: &str = include_str!("../../assets/meshes/female_generic.obj");

/// The paper's virtual try-on: a garment to grow fur on, worn by a body drawn plain.
#[derive(Clone, Debug)]
pub struct TryOnScene {
    /// `skirthelper.obj`: an open cloth tube around the hips (MakeHuman, CC0).
    pub garment: Mesh,
    /// What import did to the garment.
    pub garment_report: super::MeshReport,
    /// `female_generic.obj`: the body, in the same space (MakeHuman, CC0), with the vertices
    /// that poked through the garment tucked under it ([`super::tuck_under`]).
    pub body: Mesh,
}

/// Loads the embedded try-on scene (one copy of its meshes in any binary that uses it).
///
/// # Errors
/// Only if `options` make the shipped meshes unusable (e.g. a weld tolerance that collapses them).
pub fn try_on_scene(options: &ImportOptions) -> Result<TryOnScene, super::MeshError> {
    let (garment, garment_report) =
        Mesh::from_obj_str(TRY_ON_GARMENT_OBJ, Path::new("builtin:tryon/skirthelper.obj"), options)?;
    let mut body = Mesh::from_obj_str(TRY_ON_BODY_OBJ, Path::new("builtin:tryon/female_generic.obj"), options)?.0;
    // The thighs press through the skirt's front; tucked under it they do not show through
    // the fur as pale specks.
    let radius = garment.bounding_sphere().1;
    super::tuck_under(&mut body, &garment, 0.01 * radius, 0.1 * radius);
    Ok(TryOnScene { garment, garment_report, body })
}

/// A mesh Pelt can build without a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Builtin {
    /// The paper's Box: a cube with an 8 x 8 vertex grid per face (296 vertices, 588 triangles).
    Box,
    /// The Stanford bunny (1,839 vertices, 3,674 triangles).
    Bunny,
    /// A UV sphere of radius 1.
    Sphere,
    /// A 2 x 2 plane facing +Y (open: it has a boundary).
    Plane,
    /// A torus around +Y.
    Torus,
}

impl Builtin {
    /// Every built-in mesh.
    pub const ALL: [Self; 5] = [Self::Box, Self::Bunny, Self::Sphere, Self::Plane, Self::Torus];

    /// The name used on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Box => "box",
            Self::Bunny => "bunny",
            Self::Sphere => "sphere",
            Self::Plane => "plane",
            Self::Torus => "torus",
        }
    }

    /// Looks a built-in up by its name.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|b| b.name() == name)
    }

    /// Builds the mesh.
    ///
    /// # Panics
    /// Never for the shipped built-ins: their data is fixed and tested.
    #[must_use]
    pub fn mesh(self) -> (Mesh, MeshReport) {
        let source = format!("builtin:{}", self.name());
        let source = Path::new(&source);
        let options = ImportOptions::default();
        let result = match self {
            Self::Bunny => Mesh::from_obj_str(BUNNY_OBJ, source, &options),
            Self::Box => Mesh::from_raw(grid_box(8), source, &options),
            Self::Sphere => Mesh::from_raw(uv_sphere(48, 24), source, &options),
            Self::Plane => Mesh::from_raw(plane(16), source, &options),
            Self::Torus => Mesh::from_raw(torus(64, 24, 1.0, 0.4), source, &options),
        };
        result.expect("built-in meshes are valid")
    }
}

impl fmt::Display for Builtin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A cube's faces as (normal, u axis, v axis) with u x v = normal, so faces laid out along u and
/// v wind counter-clockwise from outside.
pub const CUBE_FACES: [(Vec3, Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::NEG_Z, Vec3::Y),
    (Vec3::NEG_X, Vec3::Z, Vec3::Y),
    (Vec3::Y, Vec3::X, Vec3::NEG_Z),
    (Vec3::NEG_Y, Vec3::X, Vec3::Z),
    (Vec3::Z, Vec3::X, Vec3::Y),
    (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
];

/// A cube of side 2 with `n x n` vertices per face (shared along the cube's edges after welding).
fn grid_box(n: u32) -> RawMesh {
    let mut raw = RawMesh { uvs: Some(Vec::new()), ..RawMesh::default() };
    let step = 1.0 / (n - 1) as f32;
    for (normal, u_axis, v_axis) in CUBE_FACES {
        let base = raw.positions.len() as u32;
        for row in 0..n {
            for col in 0..n {
                let (u, v) = (col as f32 * step, row as f32 * step);
                raw.positions.push(normal + u_axis * (2.0 * u - 1.0) + v_axis * (2.0 * v - 1.0));
                if let Some(uvs) = &mut raw.uvs {
                    uvs.push(Vec2::new(u, 1.0 - v));
                }
            }
        }
        push_grid(&mut raw.triangles, base, n, n);
    }
    raw
}

/// Two triangles per cell of a `columns x rows` vertex grid laid out row by row.
fn push_grid(triangles: &mut Vec<[u32; 3]>, base: u32, columns: u32, rows: u32) {
    for row in 0..rows - 1 {
        for col in 0..columns - 1 {
            let i = base + row * columns + col;
            let (right, up) = (i + 1, i + columns);
            triangles.push([i, right, up + 1]);
            triangles.push([i, up + 1, up]);
        }
    }
}

fn uv_sphere(segments: u32, rings: u32) -> RawMesh {
    let mut raw = RawMesh { uvs: Some(Vec::new()), normals: Some(Vec::new()), ..RawMesh::default() };
    for ring in 0..=rings {
        let v = ring as f32 / rings as f32;
        let polar = PI * (1.0 - v);
        for segment in 0..=segments {
            let u = segment as f32 / segments as f32;
            let azimuth = TAU * u;
            let p = Vec3::new(polar.sin() * azimuth.cos(), polar.cos(), -polar.sin() * azimuth.sin());
            raw.positions.push(p);
            raw.normals.as_mut().unwrap().push(p);
            raw.uvs.as_mut().unwrap().push(Vec2::new(u, 1.0 - v));
        }
    }
    // Rows run from the south pole up; triangles that collapse at the poles are dropped (and
    // counted) by the repair step.
    push_grid(&mut raw.triangles, 0, segments + 1, rings + 1);
    raw
}

fn plane(n: u32) -> RawMesh {
    let mut raw = RawMesh { uvs: Some(Vec::new()), ..RawMesh::default() };
    for row in 0..n {
        for col in 0..n {
            let (u, v) = (col as f32 / (n - 1) as f32, row as f32 / (n - 1) as f32);
            raw.positions.push(Vec3::new(2.0 * u - 1.0, 0.0, 1.0 - 2.0 * v));
            raw.uvs.as_mut().unwrap().push(Vec2::new(u, 1.0 - v));
        }
    }
    push_grid(&mut raw.triangles, 0, n, n);
    raw
}

fn torus(segments: u32, sides: u32, major_radius: f32, minor_radius: f32) -> RawMesh {
    let mut raw = RawMesh { uvs: Some(Vec::new()), ..RawMesh::default() };
    for side in 0..=sides {
        let v = side as f32 / sides as f32;
        let phi = TAU * v;
        for segment in 0..=segments {
            let u = segment as f32 / segments as f32;
            let theta = -TAU * u;
            let ring = major_radius + minor_radius * phi.cos();
            raw.positions.push(Vec3::new(ring * theta.cos(), minor_radius * phi.sin(), ring * theta.sin()));
            raw.uvs.as_mut().unwrap().push(Vec2::new(u, v));
        }
    }
    push_grid(&mut raw.triangles, 0, segments + 1, sides + 1);
    raw
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Body vertices that poke through the skirt: cast from the skirt's axis (vertical, through
    /// its centroid) out through the vertex, the ray meets the skirt before it reaches the
    /// vertex, by at most `reach` (farther out are the hands, beside the skirt, not through it).
    /// Rows within `border` of the skirt's top and hem are left out.
    fn poking_through(body: &Mesh, garment: &Mesh, reach: f32, border: f32) -> usize {
        let centroid = garment.positions.iter().sum::<glam::Vec3>() / garment.positions.len() as f32;
        let (bottom, top) =
            garment.positions.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| (lo.min(p.y), hi.max(p.y)));
        let hit = |origin: glam::Vec3, direction: glam::Vec3| -> Option<f32> {
            // Moller-Trumbore, both sides.
            garment
                .triangles
                .iter()
                .filter_map(|t| {
                    let [a, b, c] = t.map(|i| garment.positions[i as usize]);
                    let (e1, e2) = (b - a, c - a);
                    let p = direction.cross(e2);
                    let det = e1.dot(p);
                    if det.abs() < 1e-12 {
                        return None;
                    }
                    let s = origin - a;
                    let u = s.dot(p) / det;
                    let q = s.cross(e1);
                    let v = direction.dot(q) / det;
                    let t = e2.dot(q) / det;
                    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0).then_some(t)
                })
                .min_by(f32::total_cmp)
        };
        body.positions
            .iter()
            .filter(|v| v.y > bottom + border && v.y < top - border)
            .filter(|v| {
                let axis = glam::Vec3::new(centroid.x, v.y, centroid.z);
                let out = **v - axis;
                let Some(direction) = out.try_normalize() else { return false };
                hit(axis, direction).is_some_and(|t| t < out.length() && out.length() - t < reach)
            })
            .count()
    }

    #[test]
    fn the_try_on_body_stays_under_the_skirt() {
        let options = ImportOptions::default();
        let scene = try_on_scene(&options).expect("try-on scene");
        let reach = 0.1 * scene.garment.bounding_sphere().1;
        let raw_body = Mesh::from_obj_str(TRY_ON_BODY_OBJ, Path::new("body"), &options).expect("body").0;
        // The shipped body pokes through (the pale specks this guards against).
        let before = poking_through(&raw_body, &scene.garment, reach, 0.3);
        assert!(before > 20, "the untucked body pokes through at {before} vertices");
        assert_eq!(poking_through(&scene.body, &scene.garment, reach, 0.3), 0);
        assert!(scene.body.positions.iter().chain(&scene.body.normals).all(|p| p.is_finite()));
    }

    #[test]
    fn paper_box_has_the_papers_counts() {
        let (mesh, report) = Builtin::Box.mesh();
        assert_eq!((mesh.vertex_count(), mesh.triangles.len(), mesh.edges.len()), (296, 588, 882));
        assert!(report.is_closed_manifold(), "{report}");
    }

    #[test]
    fn bunny_matches_the_asset_readme() {
        let (mesh, report) = Builtin::Bunny.mesh();
        assert_eq!((mesh.vertex_count(), mesh.triangles.len()), (1839, 3674));
        assert!(report.is_closed_manifold(), "{report}");
    }

    #[test]
    fn try_on_garment_sits_on_the_body() {
        let scene = try_on_scene(&ImportOptions::default()).unwrap();
        assert_eq!((scene.garment.vertex_count(), scene.body.vertex_count()), (720, 13_868));
        let (garment_min, garment_max) = scene.garment.bounds();
        let (body_min, body_max) = scene.body.bounds();
        assert!(garment_min.y > body_min.y && garment_max.y < body_max.y, "the skirt is within the body's height");
    }

    #[test]
    fn every_builtin_is_clean_and_outward_facing() {
        for builtin in Builtin::ALL {
            let (mesh, report) = builtin.mesh();
            assert_eq!(report.inconsistent_winding_edges, 0, "{builtin}");
            assert_eq!(report.non_manifold_edges, 0, "{builtin}");
            assert_eq!(report.boundary_loops, usize::from(builtin == Builtin::Plane), "{builtin}");
            if builtin != Builtin::Plane {
                assert_eq!(report.boundary_edges, 0, "{builtin}: {report}");
                assert_eq!(mesh.edges.len() * 2, mesh.triangles.len() * 3, "E = 3F/2 on {builtin}");
                // Outward winding: a closed mesh wound counter-clockwise has positive volume.
                let volume: f32 = mesh
                    .triangles
                    .iter()
                    .map(|t| {
                        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                        a.dot(b.cross(c)) / 6.0
                    })
                    .sum();
                assert!(volume > 0.0, "{builtin} is wound inside out");
            }
            // Smooth vertex normals agree with the winding.
            let agree = (0..mesh.triangles.len())
                .filter(|&t| {
                    let n = mesh.face_normal(t);
                    mesh.triangles[t].iter().all(|&i| mesh.normals[i as usize].dot(n) > 0.0)
                })
                .count();
            assert!(agree * 10 >= mesh.triangles.len() * 9, "{builtin}: winding and normals disagree");
        }
    }
}
