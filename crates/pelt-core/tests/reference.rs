//! The explicit strand reference agrees with itself and with the fur it stands for: roots on the
//! surface, lengths of the fur length times each strand's factor, strands along the growth
//! directions, and as many strands as the tile holds over the surface.
//!
//! The oracles here (closest point on a triangle, arc lengths, the growth cone) share no code with
//! the placement.

use glam::Vec3;
use pelt_core::reference::{StrandReference, TileMapping};
use pelt_core::texture::{ColourParams, StrandField, Style, TextureInputs, TextureParams};
use pelt_core::{Builtin, FurStructure, Mesh, Preset};

const TILES_PER_RADIUS: f32 = 0.4;

fn mapping(mesh: &Mesh) -> TileMapping {
    // The renderer's mapping (pelt-render's `ObjectShape`), written out here.
    let radius = mesh.bounding_sphere().1;
    let tiles_per_world = TILES_PER_RADIUS / radius;
    let world_per_uv = mesh.corner_uvs.as_ref().map_or(1.0, |uvs| {
        let uv_area: f32 = uvs.iter().map(|[a, b, c]| (*b - *a).perp_dot(*c - *a).abs() * 0.5).sum();
        (mesh.surface_area() / uv_area).sqrt()
    });
    TileMapping { tiles_per_uv: tiles_per_world * world_per_uv, tiles_per_world }
}

fn straight_params() -> TextureParams {
    TextureParams { size: 128, style: Style::Straight, clump: 0.0, ..TextureParams::default() }
}

fn place(mesh: Mesh, preset: &Preset, texture: &TextureParams) -> (FurStructure, StrandReference) {
    let fur = FurStructure::new(mesh.clone(), &fur_params(preset, &mesh)).unwrap();
    let field = StrandField::new(texture, &ColourParams::default(), &TextureInputs::default()).unwrap();
    let mapping = mapping(&fur.mesh);
    let reference = StrandReference::new(&fur, field, mapping).unwrap();
    (fur, reference)
}

/// The preset's fur on `mesh` (length relative to its radius), growing along the normals.
fn fur_params(preset: &Preset, mesh: &Mesh) -> pelt_core::FurParams {
    pelt_core::FurParams { direction: pelt_core::GrowthDirection::default(), ..preset.fur_params(mesh) }
}

/// Closest point to `p` on triangle `abc` (Ericson, Real-Time Collision Detection 5.1.5).
fn closest_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

fn distance_to_mesh(mesh: &Mesh, p: Vec3) -> f32 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|j| mesh.positions[j as usize]);
            closest_on_triangle(p, a, b, c).distance(p)
        })
        .fold(f32::INFINITY, f32::min)
}

fn without_uvs(mut mesh: Mesh) -> Mesh {
    mesh.corner_uvs = None;
    mesh
}

#[test]
fn roots_land_on_the_surface() {
    let preset = Preset::default();
    for (name, mesh) in [
        ("bunny", Builtin::Bunny.mesh().0),
        ("sphere (uvs)", Builtin::Sphere.mesh().0),
        ("sphere (triplanar)", without_uvs(Builtin::Sphere.mesh().0)),
    ] {
        let radius = mesh.bounding_sphere().1;
        let (fur, reference) = place(mesh, &preset, &TextureParams { size: 128, ..TextureParams::default() });
        assert!(reference.strands.len() > 1000, "{name}: {} strands", reference.strands.len());
        let nodes = reference.node_positions(&fur.positions).unwrap();
        // Every 50th strand against every triangle: the oracle is brute force.
        for strand in reference.strands.iter().step_by(50) {
            let root = nodes[strand.first_node as usize];
            let distance = distance_to_mesh(&fur.mesh, root);
            assert!(distance <= 1e-4 * radius, "{name}: a root {distance} from the surface (radius {radius})");
        }
    }
}

#[test]
fn lengths_are_the_fur_length_times_the_factor() {
    let preset = Preset::default();
    // A flat plane: every column is parallel, so strands are exact straight lines.
    let (fur, reference) = place(Builtin::Plane.mesh().0, &preset, &straight_params());
    let nodes = reference.node_positions(&fur.positions).unwrap();
    let arc =
        |first: usize, count: usize| nodes[first..first + count].windows(2).map(|w| w[0].distance(w[1])).sum::<f32>();
    let mut factors = (f32::INFINITY, 0.0_f32);
    for strand in &reference.strands {
        let factor = reference.field_strand(strand).length_factor();
        factors = (factors.0.min(factor), factors.1.max(factor));
        let length = arc(strand.first_node as usize, strand.node_count as usize);
        let expected = fur.lengths[0] * factor;
        assert!((length - expected).abs() <= 1e-5 * expected.max(1e-3), "length {length}, expected {expected}");
    }
    // The factors spread as the preset says, past the tips included.
    assert!(factors.0 < 0.8 && factors.1 > 1.05, "length factors {factors:?}");

    // A sphere: neighbouring columns splay, so interpolated columns are a little shorter.
    let (fur, reference) = place(Builtin::Sphere.mesh().0, &preset, &straight_params());
    let nodes = reference.node_positions(&fur.positions).unwrap();
    for strand in &reference.strands {
        let expected = fur.lengths[0] * reference.field_strand(strand).length_factor();
        let first = strand.first_node as usize;
        let length: f32 =
            nodes[first..first + strand.node_count as usize].windows(2).map(|w| w[0].distance(w[1])).sum();
        assert!((length - expected).abs() <= 5e-3 * expected, "sphere: length {length}, expected {expected}");
    }
}

#[test]
fn calm_bunny_strands_follow_the_growth_directions() {
    let preset = Preset::default();
    let (mesh, _) = Builtin::Bunny.mesh();
    let (fur, reference) = place(mesh, &preset, &straight_params());
    let nodes = reference.node_positions(&fur.positions).unwrap();
    for strand in &reference.strands {
        let first = strand.first_node as usize;
        let last = first + strand.node_count as usize - 1;
        let direction = (nodes[last] - nodes[first]).normalize();
        let corners = fur.mesh.triangles[strand.triangle as usize].map(|j| fur.directions[j as usize]);
        // Inside the cone the triangle's three growth directions span (up to rounding).
        let spread = corners[0].dot(corners[1]).min(corners[1].dot(corners[2])).min(corners[0].dot(corners[2]));
        for g in corners {
            assert!(direction.dot(g) >= spread - 1e-4, "strand {direction} leaves the growth cone of {corners:?}");
        }
    }

    // The default (leaning, clumping) field still grows along the fur: the mean cosine to the
    // growth direction stays high (leans are in texels, so at the default tile size).
    let textures = TextureParams::default();
    let (fur, reference) = reference_of(&fur, &textures);
    let nodes = reference.node_positions(&fur.positions).unwrap();
    let mut sum = 0.0;
    for strand in &reference.strands {
        let first = strand.first_node as usize;
        let last = first + strand.node_count as usize - 1;
        let direction = (nodes[last] - nodes[first]).normalize();
        let growth: Vec3 =
            fur.mesh.triangles[strand.triangle as usize].iter().map(|j| fur.directions[*j as usize]).sum();
        sum += direction.dot(growth.normalize());
    }
    let mean = sum / reference.strands.len() as f32;
    assert!(mean > 0.9, "mean cosine to the growth direction {mean}");
}

fn reference_of<'a>(fur: &'a FurStructure, texture: &TextureParams) -> (&'a FurStructure, StrandReference) {
    let field = StrandField::new(texture, &ColourParams::default(), &TextureInputs::default()).unwrap();
    (fur, StrandReference::new(fur, field, mapping(&fur.mesh)).unwrap())
}

#[test]
fn strand_count_matches_the_tile_over_the_surface() {
    let preset = Preset::default();
    for (name, mesh) in
        [("plane (uvs)", Builtin::Plane.mesh().0), ("plane (triplanar)", without_uvs(Builtin::Plane.mesh().0))]
    {
        let area = mesh.surface_area();
        let mapping = mapping(&mesh);
        let (_, reference) = place(mesh, &preset, &straight_params());
        let tiles = area * mapping.tiles_per_world * mapping.tiles_per_world;
        let expected = tiles * reference.field.strands.len() as f32;
        let got = reference.strands.len() as f32;
        assert!((got / expected - 1.0).abs() < 0.05, "{name}: {got} strands placed, {expected} expected");
    }
}

#[test]
fn bad_inputs_are_errors() {
    let preset = Preset::default();
    let (fur, reference) = place(Builtin::Box.mesh().0, &preset, &straight_params());
    assert!(reference.node_positions(&fur.positions[1..]).is_err());
    let field = reference.field.clone();
    let bad = TileMapping { tiles_per_uv: f32::NAN, tiles_per_world: 1.0 };
    assert!(StrandReference::new(&fur, field, bad).is_err());
}

#[test]
fn strands_are_as_wide_as_the_texels_that_draw_them() {
    // The plane (2 x 2 units, uvs 0..1) with the uvs of its left half squeezed to half their
    // width: there the tile's texels are twice as wide on the surface (sqrt 2 in area terms).
    let mut mesh = Builtin::Plane.mesh().0;
    let left: Vec<bool> =
        mesh.triangles.iter().map(|t| t.iter().map(|&j| mesh.positions[j as usize].x).sum::<f32>() < 0.0).collect();
    for (uvs, squeezed) in mesh.corner_uvs.as_mut().unwrap().iter_mut().zip(&left) {
        if *squeezed {
            for uv in uvs {
                uv.x *= 0.5;
            }
        }
    }
    let texture = straight_params();
    let mapping = mapping(&mesh);
    let (_, reference) = place(mesh, &Preset::default(), &texture);
    // Written out: 2 units of surface over 1 uv unit, times the tile's texels per uv unit.
    let usual = 2.0 / (mapping.tiles_per_uv * texture.size as f32);
    let mut seen = [0usize; 2];
    for strand in &reference.strands {
        let squeezed = left[strand.triangle as usize];
        let expected = if squeezed { usual * 2f32.sqrt() } else { usual };
        let got = strand.world_per_texel;
        assert!(
            (got / expected - 1.0).abs() < 1e-3,
            "squeezed {squeezed}: {got} model units per texel, expected {expected}"
        );
        let radius = reference.field_strand(strand).radius_at(0.0, 0.0) * expected;
        assert!(
            (strand.root_radius / radius - 1.0).abs() < 1e-3,
            "root radius {} expected {radius}",
            strand.root_radius
        );
        seen[usize::from(squeezed)] += 1;
    }
    assert!(seen[0] > 100 && seen[1] > 100, "strands on each half: {seen:?}");
}

/// Mean distance from each point to its nearest other point (brute force: the oracle).
fn mean_nearest_distance(points: &[Vec3]) -> f32 {
    let total: f32 = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            points
                .iter()
                .enumerate()
                .filter(|(k, _)| *k != i)
                .map(|(_, q)| p.distance(*q))
                .fold(f32::INFINITY, f32::min)
        })
        .sum();
    total / points.len() as f32
}

#[test]
fn wet_strands_gather_into_clumps_and_dry_ones_stay_put() {
    use pelt_core::reference::WetClumps;
    let preset = Preset::default();
    let (fur, dry) = place(Builtin::Sphere.mesh().0, &preset, &straight_params());
    let v = fur.vertex_count();
    let wet_with = |wetness: f32| {
        let clumps = WetClumps { wetness: vec![wetness; v], clump_size: 12.0, clump_strength: 0.8, groom_clump: None };
        StrandReference::wet(&fur, dry.field.clone(), mapping(&fur.mesh), &clumps).unwrap()
    };
    // Wetness 0 gathers nothing: the dry reference, node for node.
    let zero = wet_with(0.0);
    assert_eq!(zero.nodes, dry.nodes);
    let wet = wet_with(0.8);
    assert_eq!(wet.strands.len(), dry.strands.len(), "the same strands, moved");
    assert!(wet.strands.iter().all(|s| (s.wetness - 0.8).abs() < 1e-6));
    let tips = |reference: &StrandReference| {
        let nodes = reference.node_positions(&fur.positions).unwrap();
        reference.strands.iter().map(|s| nodes[(s.first_node + s.node_count - 1) as usize]).collect::<Vec<_>>()
    };
    // A soaked tip moves 0.6 * 0.8 * 0.8 = 0.38 of the way to its clump's centre, so tips of
    // one clump stand closer: their nearest neighbours at most 0.8 of the dry distance.
    let (dry_spacing, wet_spacing) = (mean_nearest_distance(&tips(&dry)), mean_nearest_distance(&tips(&wet)));
    assert!(wet_spacing < 0.8 * dry_spacing, "tip spacing wet {wet_spacing} against dry {dry_spacing}");
    let bad = WetClumps { wetness: vec![0.5; 3], clump_size: 12.0, clump_strength: 0.8, groom_clump: None };
    assert!(StrandReference::wet(&fur, dry.field.clone(), mapping(&fur.mesh), &bad).is_err());
}
