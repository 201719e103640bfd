//! A plain mesh as a signed distance field: a grid of distances baked once from a closed mesh,
//! queried with trilinear interpolation (distance and gradient) wherever a rigid transform puts
//! it. Baking costs one closest-point and one winding-number sum over every triangle per grid
//! node; a query costs eight grid reads, whatever the mesh.

use glam::{Mat4, Vec3};
use rayon::prelude::*;

use super::transfer::closest_on_mesh;
use crate::mesh::{Mesh, NO_FACE};

/// Grid nodes of padding around the mesh's bounds, so the field is exact a little outside it.
const PADDING_NODES: usize = 2;

/// Why a mesh cannot become a distance field.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SdfError {
    /// Inside and outside need a closed surface.
    #[error(
        "the mesh is not closed ({boundary_edges} edges have one triangle): a signed distance field needs a \
         closed surface (fill its holes, or use a collider shape)"
    )]
    NotClosed {
        /// Edges with only one triangle.
        boundary_edges: usize,
    },
    /// The mesh has no triangles.
    #[error("the mesh has no triangles")]
    Empty,
    /// Too few grid cells to resolve anything.
    #[error("a distance field needs at least 2 cells along its longest side, got {0}")]
    Resolution(usize),
    /// A position or transform entry is NaN or infinite.
    #[error("{0} is not finite")]
    NonFinite(&'static str),
    /// The transform shears or scales unevenly (distances would not be distances).
    #[error("world_from_local must be a rotation, a translation and one uniform scale")]
    NotRigid,
}

/// Signed distances to a closed mesh on a regular grid (negative inside), placed in the world
/// by a rigid transform with uniform scale.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshSdf {
    origin: Vec3,
    cell: f32,
    dims: [usize; 3],
    values: Vec<f32>,
    world_from_local: Mat4,
    local_from_world: Mat4,
    scale: f32,
}

impl MeshSdf {
    /// Bakes `mesh` (in its own, local space) with `resolution` cells along its longest side.
    ///
    /// # Errors
    /// [`SdfError::NotClosed`] for a mesh with boundary edges, [`SdfError::Empty`],
    /// [`SdfError::Resolution`] below 2, [`SdfError::NonFinite`] for NaN positions.
    pub fn bake(mesh: &Mesh, resolution: usize) -> Result<Self, SdfError> {
        if mesh.triangles.is_empty() {
            return Err(SdfError::Empty);
        }
        if resolution < 2 {
            return Err(SdfError::Resolution(resolution));
        }
        if mesh.positions.iter().any(|p| !p.is_finite()) {
            return Err(SdfError::NonFinite("a mesh position"));
        }
        let boundary_edges = mesh.edge_faces.iter().filter(|f| f[1] == NO_FACE).count();
        if boundary_edges > 0 {
            return Err(SdfError::NotClosed { boundary_edges });
        }
        let (lo, hi) = mesh.bounds();
        let cell = (hi - lo).max_element().max(f32::MIN_POSITIVE) / resolution as f32;
        let padding = cell * PADDING_NODES as f32;
        let origin = lo - Vec3::splat(padding);
        let dims = ((hi - lo + Vec3::splat(2.0 * padding)) / cell).ceil().as_uvec3().to_array().map(|n| n as usize + 1);
        let values = (0..dims[0] * dims[1] * dims[2])
            .into_par_iter()
            .map(|index| {
                let (x, y, z) = (index % dims[0], (index / dims[0]) % dims[1], index / (dims[0] * dims[1]));
                let p = origin + Vec3::new(x as f32, y as f32, z as f32) * cell;
                let distance = closest_on_mesh(mesh, p).map_or(f32::INFINITY, |(_, _, d)| d);
                if winding_number(mesh, p) > 0.5 { -distance } else { distance }
            })
            .collect();
        Ok(Self {
            origin,
            cell,
            dims,
            values,
            world_from_local: Mat4::IDENTITY,
            local_from_world: Mat4::IDENTITY,
            scale: 1.0,
        })
    }

    /// Grid nodes along x, y and z.
    #[must_use]
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The grid's spacing in the mesh's space.
    #[must_use]
    pub fn cell(&self) -> f32 {
        self.cell
    }

    /// The grid's first node in the mesh's space.
    #[must_use]
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// The signed distances at the grid nodes, x fastest, then y, then z (the GPU's copy).
    #[must_use]
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// Where the mesh is: its rigid motion (rotation, translation, one uniform scale).
    ///
    /// # Errors
    /// [`SdfError::NonFinite`] or [`SdfError::NotRigid`]; the old transform stays.
    pub fn set_world_from_local(&mut self, world_from_local: Mat4) -> Result<(), SdfError> {
        if !world_from_local.is_finite() {
            return Err(SdfError::NonFinite("world_from_local"));
        }
        let axes = [world_from_local.x_axis, world_from_local.y_axis, world_from_local.z_axis].map(|a| a.truncate());
        let scale = axes[0].length();
        let tolerance = 1e-4 * scale;
        let similar = scale > f32::MIN_POSITIVE
            && axes.iter().all(|a| (a.length() - scale).abs() <= tolerance)
            && axes[0].dot(axes[1]).abs() <= tolerance * scale
            && axes[1].dot(axes[2]).abs() <= tolerance * scale
            && axes[0].dot(axes[2]).abs() <= tolerance * scale
            && world_from_local.row(3) == glam::Vec4::W;
        if !similar {
            return Err(SdfError::NotRigid);
        }
        self.world_from_local = world_from_local;
        self.local_from_world = world_from_local.inverse();
        self.scale = scale;
        Ok(())
    }

    /// The transform [`MeshSdf::set_world_from_local`] set.
    #[must_use]
    pub fn world_from_local(&self) -> Mat4 {
        self.world_from_local
    }

    /// Signed distance from world point `p` to the mesh (negative inside).
    #[must_use]
    pub fn distance(&self, p: Vec3) -> f32 {
        self.distance_gradient(p).0
    }

    /// Signed distance and its gradient (unit length away from the surface where the field is
    /// smooth) at world point `p`. Beyond the grid, the distance to the grid is added and the
    /// gradient points away from it.
    #[must_use]
    pub fn distance_gradient(&self, p: Vec3) -> (f32, Vec3) {
        let (distance, gradient) = self.local_distance_gradient(self.local_from_world.transform_point3(p));
        let world_gradient = (self.world_from_local.transform_vector3(gradient) / self.scale).normalize_or_zero();
        (distance * self.scale, world_gradient)
    }

    /// Signed distance and gradient at `local`, a point in the mesh's own space (the transform
    /// ignored; the gradient not normalised). `simulation_contact.wgsl`'s `sdf_closest` repeats
    /// it operation for operation.
    #[must_use]
    pub fn local_distance_gradient(&self, local: Vec3) -> (f32, Vec3) {
        let g = (local - self.origin) / self.cell;
        let top = Vec3::new(self.dims[0] as f32, self.dims[1] as f32, self.dims[2] as f32) - 1.0;
        let inside = g.clamp(Vec3::ZERO, top);
        let base = inside.floor().min(top - 1.0).max(Vec3::ZERO);
        let f = inside - base;
        let [x, y, z] = base.as_uvec3().to_array().map(|n| n as usize);
        let v = |dx: usize, dy: usize, dz: usize| {
            self.values[(x + dx) + self.dims[0] * ((y + dy) + self.dims[1] * (z + dz))]
        };
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let (c00, c10) = (lerp(v(0, 0, 0), v(1, 0, 0), f.x), lerp(v(0, 1, 0), v(1, 1, 0), f.x));
        let (c01, c11) = (lerp(v(0, 0, 1), v(1, 0, 1), f.x), lerp(v(0, 1, 1), v(1, 1, 1), f.x));
        let (c0, c1) = (lerp(c00, c10, f.y), lerp(c01, c11, f.y));
        let mut distance = lerp(c0, c1, f.z);
        // The trilinear gradient, per cell of the grid.
        let dx = lerp(
            lerp(v(1, 0, 0) - v(0, 0, 0), v(1, 1, 0) - v(0, 1, 0), f.y),
            lerp(v(1, 0, 1) - v(0, 0, 1), v(1, 1, 1) - v(0, 1, 1), f.y),
            f.z,
        );
        let dy = lerp(
            lerp(v(0, 1, 0) - v(0, 0, 0), v(1, 1, 0) - v(1, 0, 0), f.x),
            lerp(v(0, 1, 1) - v(0, 0, 1), v(1, 1, 1) - v(1, 0, 1), f.x),
            f.z,
        );
        let dz = c1 - c0;
        let mut gradient = Vec3::new(dx, dy, dz) / self.cell;
        let outside = (g - inside) * self.cell;
        if outside != Vec3::ZERO {
            distance += outside.length();
            gradient = outside.normalize();
        }
        (distance, gradient)
    }
}

/// The generalised winding number of `mesh` around `p`: the solid angle its triangles subtend,
/// over 4 pi (1 inside a closed outward-wound mesh, 0 outside; Van Oosterom and Strackee).
fn winding_number(mesh: &Mesh, p: Vec3) -> f32 {
    let total: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| (mesh.positions[i as usize] - p).as_dvec3());
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let numerator = a.dot(b.cross(c));
            let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            2.0 * numerator.atan2(denominator)
        })
        .sum();
    (total / (4.0 * std::f64::consts::PI)) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::builtin::Builtin;

    /// Inside by ray parity: crossings of a ray in a fixed, unaligned direction (Moller-Trumbore);
    /// independent of the winding number the bake uses.
    fn inside_by_parity(mesh: &Mesh, p: Vec3) -> bool {
        let direction = Vec3::new(0.5377, 0.8031, 0.2566).normalize();
        let crossings = mesh
            .triangles
            .iter()
            .filter(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                let (e1, e2) = (b - a, c - a);
                let q = direction.cross(e2);
                let det = e1.dot(q);
                if det.abs() < 1e-12 {
                    return false;
                }
                let s = p - a;
                let u = s.dot(q) / det;
                let r = s.cross(e1);
                let v = direction.dot(r) / det;
                u >= 0.0 && v >= 0.0 && u + v <= 1.0 && e2.dot(r) / det > 0.0
            })
            .count();
        crossings % 2 == 1
    }

    fn random_points(n: usize, half: f32) -> Vec<Vec3> {
        let mut state = 0x9e37_79b9_u32;
        let mut next = move || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            ((state >> 8) as f32 / (1 << 24) as f32 * 2.0 - 1.0) * half
        };
        (0..n).map(|_| Vec3::new(next(), next(), next())).collect()
    }

    #[test]
    fn the_bunny_s_field_agrees_with_ray_parity_on_inside_and_outside() {
        let (bunny, _) = Builtin::Bunny.mesh();
        let sdf = MeshSdf::bake(&bunny, 24).unwrap();
        let (lo, hi) = bunny.bounds();
        let (centre, half) = ((lo + hi) * 0.5, (hi - lo).max_element() * 0.6);
        let (mut inside, mut checked) = (0, 0);
        for p in random_points(3000, half).into_iter().map(|p| p + centre) {
            let d = sdf.distance(p);
            // Within a cell of the surface the interpolated sign may lag the true one.
            if d.abs() < 1.5 * sdf.cell() {
                continue;
            }
            let parity = inside_by_parity(&bunny, p);
            assert_eq!(d < 0.0, parity, "{p}: distance {d}, parity says inside = {parity}");
            inside += usize::from(parity);
            checked += 1;
        }
        assert!(inside > 100 && checked > 1000, "{inside} inside of {checked}");
    }

    #[test]
    fn the_box_s_field_is_the_box_s_distance_and_moves_with_it() {
        let (cube, _) = Builtin::Box.mesh();
        let mut sdf = MeshSdf::bake(&cube, 16).unwrap();
        let exact = |p: Vec3| {
            let q = p.abs() - Vec3::ONE;
            q.max(Vec3::ZERO).length() + q.max_element().min(0.0)
        };
        for p in random_points(2000, 1.6) {
            let (d, g) = sdf.distance_gradient(p);
            assert!((d - exact(p)).abs() <= sdf.cell(), "{p}: {d} vs {}", exact(p));
            if exact(p).abs() > 2.0 * sdf.cell() && exact(p) > 0.0 {
                assert!(exact(p + 0.05 * g) > exact(p), "{p}: the gradient {g} points into the box");
            }
        }
        // Beyond the grid: still the distance, to within the padding's error.
        assert!((sdf.distance(Vec3::new(5.0, 0.0, 0.0)) - 4.0).abs() < sdf.cell());
        // Moved, turned and doubled: distances double and follow the box.
        let world = Mat4::from_translation(Vec3::new(3.0, -1.0, 2.0))
            * Mat4::from_rotation_y(0.6)
            * Mat4::from_scale(Vec3::splat(2.0));
        let before: Vec<f32> = random_points(50, 1.5).into_iter().map(|p| sdf.distance(p)).collect();
        sdf.set_world_from_local(world).unwrap();
        for (p, d) in random_points(50, 1.5).into_iter().zip(before) {
            assert!((sdf.distance(world.transform_point3(p)) - 2.0 * d).abs() < 1e-4);
        }
    }

    #[test]
    fn open_meshes_and_bad_transforms_are_refused() {
        let (plane, _) = Builtin::Plane.mesh();
        let error = MeshSdf::bake(&plane, 8).unwrap_err();
        assert!(matches!(error, SdfError::NotClosed { boundary_edges } if boundary_edges > 0), "{error}");
        assert!(error.to_string().contains("not closed"));
        let (cube, _) = Builtin::Box.mesh();
        assert_eq!(MeshSdf::bake(&cube, 1).unwrap_err(), SdfError::Resolution(1));
        let mut sdf = MeshSdf::bake(&cube, 4).unwrap();
        assert_eq!(sdf.set_world_from_local(Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0))), Err(SdfError::NotRigid));
        assert_eq!(
            sdf.set_world_from_local(Mat4::from_translation(Vec3::NAN)),
            Err(SdfError::NonFinite("world_from_local"))
        );
        assert_eq!(sdf.world_from_local(), Mat4::IDENTITY);
        assert!(sdf.distance(Vec3::ZERO) < 0.0 && sdf.distance(Vec3::ZERO).is_finite());
    }
}
