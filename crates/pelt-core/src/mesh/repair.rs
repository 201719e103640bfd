//! Validation and repair of a [`RawMesh`]: welding, dropping degenerate triangles, orienting
//! the winding, normals.

use std::collections::HashMap;
use std::path::Path;

use glam::Vec3;

use super::topology::sorted_half_edges;
use super::vertex_cache::{CACHE_SIZE, tipsify_order};
use super::{ColourSet, ImportOptions, Mesh, MeshError, MeshReport, NormalSource, RawMesh, Topology, bounds};

impl Mesh {
    /// Validates, welds and repairs a raw mesh.
    ///
    /// # Errors
    /// [`MeshError::IndexOutOfRange`], [`MeshError::NonFinite`] or [`MeshError::NoTriangles`]
    /// (also when every triangle was degenerate).
    pub fn from_raw(raw: RawMesh, file: &Path, options: &ImportOptions) -> Result<(Self, MeshReport), MeshError> {
        Self::repair(raw, &[], file, options).map(|(mesh, report, _)| (mesh, report))
    }

    /// [`Mesh::from_raw`], also returning for each base vertex the raw vertex it was taken from,
    /// so per-vertex data kept beside the raw mesh (a game engine's skin weights, for
    /// [`crate::anim::Skin`]) follows welding and repair.
    ///
    /// # Errors
    /// As [`Mesh::from_raw`].
    pub fn from_raw_traced(
        raw: RawMesh,
        file: &Path,
        options: &ImportOptions,
    ) -> Result<(Self, MeshReport, Vec<u32>), MeshError> {
        Self::repair(raw, &[], file, options)
    }

    /// [`Mesh::from_raw`], also returning for each kept vertex the raw vertex it was taken from
    /// (so per-vertex data read beside the mesh, like skin weights, follows welding and repair).
    /// `colour_sets` (one colour per raw vertex each) follow welding too: see [`Mesh::colour_sets`].
    pub(crate) fn repair(
        raw: RawMesh,
        colour_sets: &[ColourSet],
        file: &Path,
        options: &ImportOptions,
    ) -> Result<(Self, MeshReport, Vec<u32>), MeshError> {
        let file_buf = || file.to_path_buf();
        let input_vertices = raw.positions.len();
        let input_triangles = raw.triangles.len();
        if raw.triangles.is_empty() {
            return Err(MeshError::NoTriangles { file: file_buf(), detail: String::new() });
        }
        for (triangle, corners) in raw.triangles.iter().enumerate() {
            if let Some(&index) = corners.iter().find(|&&i| i as usize >= input_vertices) {
                return Err(MeshError::IndexOutOfRange {
                    file: file_buf(),
                    triangle,
                    index,
                    vertex_count: input_vertices,
                });
            }
        }
        if let Some((vertex, p)) = raw.positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(MeshError::NonFinite { file: file_buf(), vertex, position: p.to_array() });
        }
        let raw_normals = raw.normals.filter(|n| n.len() == input_vertices && n.iter().all(|v| v.is_finite()));
        let raw_uvs = raw.uvs.filter(|uv| uv.len() == input_vertices && uv.iter().all(|v| v.is_finite()));

        let (min, max) = bounds(&raw.positions);
        let diagonal = (max - min).length().max(f32::MIN_POSITIVE);

        // Weld: map every input vertex to a canonical one.
        let canonical: Vec<u32> = if options.weld {
            weld_map(&raw.positions, options.weld_tolerance * diagonal)
        } else {
            (0..input_vertices as u32).collect()
        };
        let welded_vertices = canonical.iter().enumerate().filter(|&(i, &c)| c as usize != i).count();

        // Drop degenerate triangles.
        let area_epsilon = (diagonal * 1e-7).powi(2);
        let mut dropped_repeated = 0;
        let mut dropped_zero_area = 0;
        let mut dropped_duplicate = 0;
        let mut seen = std::collections::HashSet::with_capacity(raw.triangles.len());
        let mut kept: Vec<([u32; 3], usize)> = Vec::with_capacity(raw.triangles.len());
        for (t, tri) in raw.triangles.iter().enumerate() {
            let w = tri.map(|i| canonical[i as usize]);
            if w[0] == w[1] || w[1] == w[2] || w[0] == w[2] {
                dropped_repeated += 1;
                continue;
            }
            let [a, b, c] = w.map(|i| raw.positions[i as usize]);
            if (b - a).cross(c - a).length_squared() * 0.25 <= area_epsilon {
                dropped_zero_area += 1;
                continue;
            }
            let mut corners = w;
            corners.sort_unstable();
            if !seen.insert(corners) {
                dropped_duplicate += 1;
                continue;
            }
            kept.push((w, t));
        }
        if kept.is_empty() {
            return Err(MeshError::NoTriangles {
                file: file_buf(),
                detail: format!(" left after repair (all {input_triangles} were degenerate)"),
            });
        }

        // Compact: keep referenced canonical vertices only, in input order.
        let mut new_index = vec![u32::MAX; input_vertices];
        let mut referenced = vec![false; input_vertices];
        for (tri, _) in &kept {
            for &i in tri {
                referenced[i as usize] = true;
            }
        }
        let mut positions = Vec::new();
        let mut source = Vec::new();
        for (i, &is_used) in referenced.iter().enumerate() {
            if is_used {
                new_index[i] = positions.len() as u32;
                positions.push(raw.positions[i]);
                source.push(i as u32);
            }
        }
        let canonical_count = canonical.iter().enumerate().filter(|&(i, &c)| c as usize == i).count();
        let dropped_unreferenced = canonical_count - positions.len();
        let mut triangles: Vec<[u32; 3]> = kept.iter().map(|(tri, _)| tri.map(|i| new_index[i as usize])).collect();
        let mut corner_uvs = raw_uvs
            .as_ref()
            .map(|uvs| kept.iter().map(|&(_, t)| raw.triangles[t].map(|i| uvs[i as usize])).collect::<Vec<_>>());
        let flips = if options.orient { orientation_flips(&positions, &triangles) } else { Vec::new() };
        for (t, _) in flips.iter().enumerate().filter(|&(_, &flip)| flip) {
            triangles[t].swap(1, 2);
            if let Some(uvs) = &mut corner_uvs {
                uvs[t].swap(1, 2);
            }
        }
        let reoriented_triangles = flips.iter().filter(|&&flip| flip).count();

        let computed = smooth_normals(&positions, &triangles);
        let (normals, normal_source) = match &raw_normals {
            Some(file_normals) => {
                let mut sum = vec![Vec3::ZERO; positions.len()];
                for (i, n) in file_normals.iter().enumerate() {
                    let target = new_index[canonical[i] as usize];
                    if target != u32::MAX {
                        sum[target as usize] += *n;
                    }
                }
                let normals = sum.iter().zip(&computed).map(|(s, c)| s.try_normalize().unwrap_or(*c)).collect();
                (normals, NormalSource::File)
            }
            None => (computed, NormalSource::Computed),
        };
        let colour_sets = colour_sets
            .iter()
            // Non-finite colours are kept: a groom reading the set says which vertex and key.
            .filter(|set| set.colours.len() == input_vertices)
            .map(|set| ColourSet {
                set: set.set,
                colours: welded_mean(&set.colours, &canonical, &new_index, positions.len()),
            })
            .collect();
        // After the normals, which sum the faces in order: the order changes no bit of them.
        if options.vertex_cache_order {
            let order = tipsify_order(&triangles, positions.len(), CACHE_SIZE);
            triangles = order.iter().map(|&t| triangles[t as usize]).collect();
            if let Some(uvs) = &mut corner_uvs {
                *uvs = order.iter().map(|&t| uvs[t as usize]).collect();
            }
        }

        let topology = Topology::build(&triangles);
        let boundary_loops = topology.boundary_loops();
        let mesh = Mesh {
            positions,
            normals,
            corner_uvs,
            triangles,
            edges: topology.edges,
            edge_faces: topology.edge_faces,
            colour_sets,
        };
        let report = MeshReport {
            source: file.display().to_string(),
            input_vertices,
            input_triangles,
            welded_vertices,
            dropped_zero_area_triangles: dropped_zero_area,
            dropped_repeated_index_triangles: dropped_repeated,
            dropped_duplicate_triangles: dropped_duplicate,
            dropped_unreferenced_vertices: dropped_unreferenced,
            reoriented_triangles,
            normals: normal_source,
            has_uvs: mesh.corner_uvs.is_some(),
            boundary_edges: topology.boundary_edges,
            boundary_loops,
            non_manifold_edges: topology.non_manifold_edges,
            inconsistent_winding_edges: topology.inconsistent_winding_edges,
            vertices: mesh.positions.len(),
            triangles: mesh.triangles.len(),
            edges: mesh.edges.len(),
        };
        Ok((mesh, report, source))
    }
}

/// Per kept vertex, the mean of the raw vertices' `values` welded into it.
fn welded_mean(values: &[glam::Vec4], canonical: &[u32], new_index: &[u32], kept: usize) -> Vec<glam::Vec4> {
    let mut sums = vec![(glam::Vec4::ZERO, 0u32); kept];
    for (value, &c) in values.iter().zip(canonical) {
        if let Some((sum, count)) = sums.get_mut(new_index[c as usize] as usize) {
            *sum += *value;
            *count += 1;
        }
    }
    sums.into_iter().map(|(sum, count)| sum / count.max(1) as f32).collect()
}

/// Which triangles to flip so that every manifold edge is traversed in opposite directions by
/// its two faces. Each connected part (through manifold edges) is oriented from its first
/// triangle, then as a whole: a closed part to enclose positive volume (outward), an open part
/// to flip as few triangles as possible. A non-orientable part (a Moebius strip) keeps the
/// conflicts it cannot avoid; they stay counted as inconsistent winding.
fn orientation_flips(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<bool> {
    let half_edges = sorted_half_edges(triangles);
    // (neighbour, whether the two traverse the edge the same way, i.e. one must flip).
    let mut neighbours: Vec<Vec<(u32, bool)>> = vec![Vec::new(); triangles.len()];
    let mut is_open = vec![false; triangles.len()];
    for group in half_edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        if let [first, second] = group {
            let same_way = first.3 == second.3;
            neighbours[first.2 as usize].push((second.2, same_way));
            neighbours[second.2 as usize].push((first.2, same_way));
        } else {
            for use_ in group {
                is_open[use_.2 as usize] = true;
            }
        }
    }

    let mut flip = vec![false; triangles.len()];
    let mut visited = vec![false; triangles.len()];
    let mut part = Vec::new();
    for seed in 0..triangles.len() {
        if visited[seed] {
            continue;
        }
        visited[seed] = true;
        part.clear();
        part.push(seed as u32);
        let mut next = 0;
        while next < part.len() {
            let face = part[next] as usize;
            next += 1;
            for &(other, same_way) in &neighbours[face] {
                if !visited[other as usize] {
                    visited[other as usize] = true;
                    flip[other as usize] = flip[face] ^ same_way;
                    part.push(other);
                }
            }
        }
        let is_closed = part.iter().all(|&f| !is_open[f as usize]);
        let turn_around = if is_closed {
            let volume: f64 = part
                .iter()
                .map(|&f| {
                    let [a, b, c] = triangles[f as usize].map(|i| positions[i as usize].as_dvec3());
                    let v = a.dot(b.cross(c));
                    if flip[f as usize] { -v } else { v }
                })
                .sum();
            volume < 0.0
        } else {
            2 * part.iter().filter(|&&f| flip[f as usize]).count() > part.len()
        };
        if turn_around {
            for &f in &part {
                flip[f as usize] = !flip[f as usize];
            }
        }
    }
    flip
}

/// Maps each vertex to the first vertex within `tolerance` of it (a uniform grid, so near-linear).
fn weld_map(positions: &[Vec3], tolerance: f32) -> Vec<u32> {
    let cell = tolerance.max(f32::MIN_POSITIVE) * 2.0;
    let key = |p: Vec3| {
        let q = (p / cell).floor();
        (q.x as i64, q.y as i64, q.z as i64)
    };
    let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::with_capacity(positions.len());
    let mut canonical = Vec::with_capacity(positions.len());
    for (i, &p) in positions.iter().enumerate() {
        let (x, y, z) = key(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(bucket) = grid.get(&(x + dx, y + dy, z + dz))
                        && let Some(&j) = bucket.iter().find(|&&j| positions[j as usize].distance(p) <= tolerance)
                    {
                        found = Some(j);
                        break 'search;
                    }
                }
            }
        }
        match found {
            Some(j) => canonical.push(j),
            None => {
                grid.entry((x, y, z)).or_default().push(i as u32);
                canonical.push(i as u32);
            }
        }
    }
    canonical
}

/// Angle-weighted smooth vertex normals. A vertex whose faces cancel out gets its first face's
/// normal, and an isolated one +Y, so every normal is a unit vector.
#[must_use]
pub fn smooth_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sum = vec![Vec3::ZERO; positions.len()];
    let mut first_face = vec![Vec3::ZERO; positions.len()];
    for tri in triangles {
        let p = tri.map(|i| positions[i as usize]);
        let face = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        for k in 0..3 {
            let e1 = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
            let e2 = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
            let angle = e1.dot(e2).clamp(-1.0, 1.0).acos();
            let v = tri[k] as usize;
            sum[v] += face * angle;
            if first_face[v] == Vec3::ZERO {
                first_face[v] = face;
            }
        }
    }
    sum.iter()
        .zip(&first_face)
        .map(|(s, f)| s.try_normalize().or_else(|| f.try_normalize()).unwrap_or(Vec3::Y))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> RawMesh {
        RawMesh {
            positions: positions.iter().map(|p| Vec3::from_array(*p)).collect(),
            triangles: triangles.to_vec(),
            ..RawMesh::default()
        }
    }

    fn tetrahedron() -> RawMesh {
        raw(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
    }

    #[test]
    fn tetrahedron_is_closed_manifold() {
        let (mesh, report) = Mesh::from_raw(tetrahedron(), Path::new("tet"), &ImportOptions::default()).unwrap();
        assert_eq!(mesh.edges.len(), 6);
        assert_eq!(mesh.edges.len() * 2, mesh.triangles.len() * 3);
        assert!(report.is_closed_manifold(), "{report}");
        assert_eq!(report.normals, NormalSource::Computed);
        for n in &mesh.normals {
            assert!((n.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn welding_joins_a_triangle_soup() {
        let mut soup = RawMesh::default();
        let tet = tetrahedron();
        for tri in &tet.triangles {
            let base = soup.positions.len() as u32;
            soup.positions.extend(tri.map(|i| tet.positions[i as usize]));
            soup.triangles.push([base, base + 1, base + 2]);
        }
        let (mesh, report) = Mesh::from_raw(soup.clone(), Path::new("soup"), &ImportOptions::default()).unwrap();
        assert_eq!(mesh.vertex_count(), 4);
        assert_eq!(report.welded_vertices, 8);
        assert!(report.is_closed_manifold());
        let unwelded = ImportOptions { weld: false, ..ImportOptions::default() };
        let (mesh, report) = Mesh::from_raw(soup, Path::new("soup"), &unwelded).unwrap();
        assert_eq!(mesh.vertex_count(), 12);
        assert_eq!(report.boundary_edges, 12);
    }

    #[test]
    fn degenerate_triangles_and_unused_vertices_are_dropped_and_counted() {
        let mut m = tetrahedron();
        m.positions.push(Vec3::new(5.0, 5.0, 5.0)); // unreferenced
        m.positions.push(Vec3::new(0.5, 0.0, 0.0)); // on edge 0-1: zero-area triangle below
        m.triangles.push([0, 0, 1]);
        m.triangles.push([0, 1, 5]);
        let (mesh, report) = Mesh::from_raw(m, Path::new("t"), &ImportOptions::default()).unwrap();
        assert_eq!(report.dropped_repeated_index_triangles, 1);
        assert_eq!(report.dropped_zero_area_triangles, 1);
        assert_eq!(report.dropped_unreferenced_vertices, 2);
        assert_eq!(mesh.vertex_count(), 4);
        assert_eq!(mesh.triangles.len(), 4);
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let file = Path::new("bad.obj");
        let mut m = tetrahedron();
        m.triangles.push([0, 1, 9]);
        let err = Mesh::from_raw(m, file, &ImportOptions::default()).unwrap_err();
        assert!(matches!(err, MeshError::IndexOutOfRange { index: 9, .. }), "{err}");
        assert!(err.to_string().contains("bad.obj"));

        let mut m = tetrahedron();
        m.positions[2].y = f32::NAN;
        let err = Mesh::from_raw(m, file, &ImportOptions::default()).unwrap_err();
        assert!(matches!(err, MeshError::NonFinite { vertex: 2, .. }), "{err}");

        let err = Mesh::from_raw(raw(&[[0.0; 3]], &[]), file, &ImportOptions::default()).unwrap_err();
        assert!(matches!(err, MeshError::NoTriangles { .. }));

        let all_degenerate = raw(&[[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], &[[0, 1, 2]]);
        let err = Mesh::from_raw(all_degenerate, file, &ImportOptions::default()).unwrap_err();
        assert!(err.to_string().contains("degenerate"), "{err}");
    }

    #[test]
    fn flipped_and_non_manifold_edges_are_reported() {
        let mut m = tetrahedron();
        m.triangles[3] = [1, 3, 2]; // flip one face
        let as_read = ImportOptions { orient: false, ..ImportOptions::default() };
        let (_, report) = Mesh::from_raw(m, Path::new("t"), &as_read).unwrap();
        assert_eq!(report.inconsistent_winding_edges, 3);
        assert_eq!(report.reoriented_triangles, 0);

        // Three triangles sharing edge 0-1.
        let fan = raw(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]],
            &[[0, 1, 2], [1, 0, 3], [0, 1, 4]],
        );
        let (mesh, report) = Mesh::from_raw(fan, Path::new("fan"), &ImportOptions::default()).unwrap();
        assert_eq!(report.non_manifold_edges, 1);
        assert_eq!(report.boundary_edges, 6);
        assert_eq!(report.boundary_loops, 1, "the fan's rim is one chain through vertices 0 and 1");
        assert_eq!(mesh.edges.len(), 7, "fins are still built for every edge");
    }

    fn volume(mesh: &Mesh) -> f32 {
        mesh.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn flipped_faces_are_turned_back_and_uvs_follow_their_corners() {
        let mut m = tetrahedron();
        m.triangles[3] = [1, 3, 2];
        m.uvs = Some(m.positions.iter().map(|p| p.truncate()).collect());
        let (mesh, report) = Mesh::from_raw(m, Path::new("t"), &ImportOptions::default()).unwrap();
        assert_eq!(report.reoriented_triangles, 1);
        assert!(report.is_closed_manifold(), "{report}");
        assert!((volume(&mesh) - 1.0 / 6.0).abs() < 1e-6);
        let uvs = mesh.corner_uvs.as_ref().unwrap();
        for (tri, corners) in mesh.triangles.iter().zip(uvs) {
            for k in 0..3 {
                assert_eq!(corners[k], mesh.positions[tri[k] as usize].truncate(), "uv stays with its vertex");
            }
        }
    }

    #[test]
    fn a_closed_mesh_inside_out_is_turned_outward() {
        let mut m = tetrahedron();
        for t in &mut m.triangles {
            t.swap(0, 1);
        }
        let (mesh, report) = Mesh::from_raw(m, Path::new("t"), &ImportOptions::default()).unwrap();
        assert_eq!(report.reoriented_triangles, 4);
        assert!(volume(&mesh) > 0.0);
        let centre = Vec3::splat(0.25);
        assert!(mesh.positions.iter().zip(&mesh.normals).all(|(p, n)| n.dot(*p - centre) > 0.0));
    }

    #[test]
    fn an_open_mesh_keeps_its_majority_winding() {
        // A 4 x 4 grid of quads facing -Z as read; three triangles flipped.
        let mut grid = RawMesh::default();
        for row in 0..5 {
            for col in 0..5 {
                grid.positions.push(Vec3::new(col as f32, row as f32, 0.0));
            }
        }
        for row in 0..4 {
            for col in 0..4 {
                let i = row * 5 + col;
                grid.triangles.push([i, i + 6, i + 1]);
                grid.triangles.push([i, i + 5, i + 6]);
            }
        }
        for t in [3, 10, 17] {
            grid.triangles[t].swap(0, 1);
        }
        let (mesh, report) = Mesh::from_raw(grid, Path::new("grid"), &ImportOptions::default()).unwrap();
        assert_eq!(report.reoriented_triangles, 3);
        assert_eq!(report.inconsistent_winding_edges, 0);
        assert!((0..mesh.triangles.len()).all(|t| mesh.face_normal(t).z < -0.99), "the majority (-Z) wins");
    }

    #[test]
    fn a_moebius_strip_keeps_the_conflict_it_cannot_avoid() {
        let segments = 12;
        let mut strip = RawMesh::default();
        for k in 0..segments {
            let angle = std::f32::consts::TAU * k as f32 / segments as f32;
            let twist = angle / 2.0;
            let centre = Vec3::new(angle.cos(), angle.sin(), 0.0) * 2.0;
            let across = Vec3::new(angle.cos() * twist.cos(), angle.sin() * twist.cos(), twist.sin()) * 0.5;
            strip.positions.push(centre - across);
            strip.positions.push(centre + across);
        }
        for k in 0..segments {
            let (a, b) = (2 * k, 2 * k + 1);
            // The last segment joins the first one upside down.
            let (c, d) = if k + 1 == segments { (1, 0) } else { (2 * k + 2, 2 * k + 3) };
            strip.triangles.push([a, c, d]);
            strip.triangles.push([a, d, b]);
        }
        let (mesh, report) = Mesh::from_raw(strip, Path::new("moebius"), &ImportOptions::default()).unwrap();
        assert_eq!(mesh.triangles.len(), 2 * segments as usize);
        assert_eq!(report.inconsistent_winding_edges, 1, "{report}");
        assert_eq!(report.boundary_loops, 1, "a Moebius strip has a single rim");
    }

    #[test]
    fn duplicate_and_double_sided_triangles_are_dropped() {
        let mut m = tetrahedron();
        m.triangles.push([2, 1, 0]); // the back side of triangle 0
        m.triangles.push([1, 3, 0]); // triangle 1 again, rotated
        let (mesh, report) = Mesh::from_raw(m, Path::new("t"), &ImportOptions::default()).unwrap();
        assert_eq!(report.dropped_duplicate_triangles, 2);
        assert_eq!(mesh.triangles.len(), 4);
        assert!(report.is_closed_manifold(), "{report}");
    }
}
