//! Each vertex's tangent frame: the two directions in its tangent plane a groom's flow is
//! written in.

use glam::{Vec2, Vec3};

use crate::mesh::Mesh;

/// Two unit vectors in a vertex's tangent plane (both perpendicular to its normal, and to each
/// other): a flow `(x, y)` points along `tangent * x + up * y`.
///
/// - With UVs: `tangent` is the direction in which `u` grows and `up` the direction toward the
///   image's top row (in which `v` shrinks, `v = 0` being the top row as glTF and the renderer
///   sample), each the area-weighted sum over the vertex's triangles, made perpendicular to the
///   normal. So a flow map's red/green are right/up in the image, as painted. On a mirrored UV
///   island `tangent x up` is minus the normal.
/// - Without UVs (or where the UVs are degenerate): `up` is world +Y along the surface (world -Z
///   where the normal is within about 2.6 degrees of +-Y), `tangent = up x normal`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentFrame {
    /// The flow's `x` direction.
    pub tangent: Vec3,
    /// The flow's `y` direction.
    pub up: Vec3,
}

impl TangentFrame {
    /// The flow `(x, y)` as a vector in the surface.
    #[must_use]
    pub fn to_surface(&self, flow: Vec2) -> Vec3 {
        self.tangent * flow.x + self.up * flow.y
    }

    /// The frame without UVs, for a unit `normal`.
    #[must_use]
    pub fn stable(normal: Vec3) -> Self {
        let reference = if normal.y.abs() > 0.999 { Vec3::NEG_Z } else { Vec3::Y };
        let up = (reference - normal * reference.dot(normal)).normalize_or(reference);
        Self { tangent: up.cross(normal).normalize_or_zero(), up }
    }
}

/// The [`TangentFrame`] of every vertex of `mesh`.
#[must_use]
pub fn tangent_frames(mesh: &Mesh) -> Vec<TangentFrame> {
    let v = mesh.vertex_count();
    let mut along_u = vec![Vec3::ZERO; v];
    let mut along_v = vec![Vec3::ZERO; v];
    if let Some(corner_uvs) = &mesh.corner_uvs {
        for (triangle, uvs) in mesh.triangles.iter().zip(corner_uvs) {
            let [p0, p1, p2] = triangle.map(|j| mesh.positions[j as usize]);
            let (e1, e2) = (p1 - p0, p2 - p0);
            let (d1, d2) = (uvs[1] - uvs[0], uvs[2] - uvs[0]);
            let determinant = d1.x * d2.y - d2.x * d1.y;
            if !determinant.is_finite() || determinant == 0.0 {
                continue;
            }
            // dP/du and dP/dv times |determinant|: weighted by the triangle's area in uv space.
            let sign = determinant.signum();
            let du = (e1 * d2.y - e2 * d1.y) * sign;
            let dv = (e2 * d1.x - e1 * d2.x) * sign;
            for &j in triangle {
                along_u[j as usize] += du;
                along_v[j as usize] += dv;
            }
        }
    }
    mesh.normals
        .iter()
        .zip(along_u.iter().zip(&along_v))
        .map(|(&normal, (&du, &dv))| {
            let Some(tangent) = (du - normal * du.dot(normal)).try_normalize() else {
                return TangentFrame::stable(normal);
            };
            let up = normal.cross(tangent).normalize();
            // The image's top is where v shrinks; a mirrored island flips `up`.
            let up = if up.dot(-dv) < 0.0 { -up } else { up };
            TangentFrame { tangent, up }
        })
        .collect()
}
