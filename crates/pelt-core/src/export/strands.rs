//! The strands the shells stand for as USD hair: one `UsdGeomBasisCurves` with every kept strand
//! of a [`StrandReference`] (where `pelt fidelity` places them: groom, wet clumps, the simulated
//! pose), beside the base mesh as a `UsdGeomMesh`, both under one `Xform` that is the layer's
//! default prim.
//!
//! - A strand has one point per layer it reaches and one at its end (the reference's nodes), as
//!   linear segments or a pinned Catmull-Rom curve through the same points.
//! - `widths` per point: twice the cross-section's radius as the textures taper it, in model
//!   units on the strand's triangle.
//! - `primvars:displayColor` per strand, linear RGB: the strand's colour from the textures
//!   (averaged root to tip), times the surface texture at its root in surface mode, times the
//!   groom's tint.
//! - Strands on bald triangles are left out; a groom's density keeps a strand where its seeded
//!   keep value lies below the density at its root (as the shells keep it); `fraction` keeps a
//!   seeded share of the rest.
//! - `primvars:pelt:lengthFactor` per strand: its seeded length over its column's (strands end
//!   at seeded heights), so a bake of the file finds the columns' lengths exactly.
//! - `primvars:pelt:textureOffset` per point (`vector3f`, vertex interpolation, model units in
//!   the curves' space): what the shell texture adds to the strand there, its offset from the
//!   strand's straight column at that height (the texture's lean, clumps and curl, a wet coat's
//!   gathering). The groom shapes the column alone, so a bake subtracts the offsets and measures
//!   the groom without counting the texture's lean twice when the same preset grows it again;
//!   a tool that moves the points but keeps the primvar (Houdini) still has its edit baked.
//! - Several frames become time samples on the points and extents (the mesh's too).
//!
//! The file is written through a temporary file and a rename: a failed write leaves nothing.

use std::io::{BufWriter, Write};
use std::path::Path;

use glam::{Vec2, Vec3};

use super::ExportError;
use super::geometry::srgb_to_linear;
use crate::fur::FurStructure;
use crate::reference::{PlacedStrand, StrandReference};
use crate::rng;
use crate::usd::{StageMetadata, UpAxis, UsdaWriter, format_f32};

/// How the curves are drawn between their points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StrandBasis {
    /// Straight segments (`type = "linear"`): exactly the shells' piecewise-linear strands.
    Linear,
    /// A pinned Catmull-Rom spline through the same points (`type = "cubic"`).
    CatmullRom,
}

/// One pose to write.
#[derive(Clone, Debug)]
pub struct StrandFrame {
    /// The USD time code (`None`: a single, untimed pose).
    pub time_code: Option<f64>,
    /// The shared array, `(L + 1) * V` positions (layer 0 is the posed base mesh).
    pub positions: Vec<Vec3>,
    /// The posed base normals, one per vertex.
    pub normals: Vec<Vec3>,
}

/// What to write.
#[derive(Debug)]
pub struct StrandExportInput<'a> {
    /// The fur (base mesh, groom).
    pub fur: &'a FurStructure,
    /// The strands, placed on `fur`.
    pub reference: &'a StrandReference,
    /// One pose, or one per time sample.
    pub frames: &'a [StrandFrame],
    /// Share of the strands kept, `0 < fraction <= 1` (seeded per strand).
    pub fraction: f32,
    /// Linear or Catmull-Rom curves.
    pub basis: StrandBasis,
    /// Metres per model unit (`metersPerUnit`).
    pub meters_per_unit: f64,
    /// Time codes per second, for several frames.
    pub frames_per_second: f64,
    /// What wrote it and from what (the layer's `doc`).
    pub doc: String,
}

/// What was written: counts and extents (the first frame's), as a USD reader reports them.
#[derive(Clone, Debug, PartialEq)]
pub struct StrandExportCounts {
    /// Curves.
    pub curves: usize,
    /// Curve points.
    pub points: usize,
    /// Base mesh vertices.
    pub mesh_vertices: usize,
    /// Base mesh triangles.
    pub mesh_triangles: usize,
    /// Time samples (0 for an untimed pose).
    pub time_samples: usize,
    /// The curves' bounds, `[min, max]`, widths included.
    pub curves_extent: [Vec3; 2],
    /// The mesh's bounds.
    pub mesh_extent: [Vec3; 2],
}

/// The strands `input` keeps, in reference order.
#[must_use]
pub fn kept_strands(input: &StrandExportInput<'_>) -> Vec<usize> {
    let fur = input.fur;
    let mesh = &fur.mesh;
    let density = fur.groom.as_ref().and_then(|g| g.density.as_ref());
    (input.reference.strands.iter().enumerate())
        .filter(|(_, placed)| fur.triangle_has_fur(placed.triangle as usize))
        .filter(|(_, placed)| {
            let Some(density) = density else { return true };
            let corners = mesh.triangles[placed.triangle as usize];
            let root = input.reference.strand_nodes(placed)[0].barycentric;
            let at_root: f32 = corners.iter().zip(root.to_array()).map(|(&j, w)| density[j as usize] * w).sum();
            input.reference.field_strand(placed).keep_value() < at_root
        })
        .filter(|(_, placed)| {
            input.fraction >= 1.0
                || rng::unit_f32(rng::hash(0x7374_7261, u64::from(placed.field_index), u64::from(placed.triangle), 0))
                    < input.fraction
        })
        .map(|(k, _)| k)
        .collect()
}

/// Writes `input` to `path` as a USDA layer.
///
/// # Errors
/// [`ExportError::Input`] for frames that do not fit the fur, a fraction outside `0..=1` or
/// non-finite positions; [`ExportError::Write`] naming the file for a failed write.
pub fn write_strands_usda(path: &Path, input: &StrandExportInput<'_>) -> Result<StrandExportCounts, ExportError> {
    let fur = input.fur;
    let v = fur.vertex_count();
    if input.frames.is_empty() {
        return Err(ExportError::Input("no pose to export".to_owned()));
    }
    if !(input.fraction > 0.0 && input.fraction <= 1.0) {
        return Err(ExportError::Input(format!(
            "the strand fraction must be above 0 and at most 1, got {}",
            input.fraction
        )));
    }
    for frame in input.frames {
        if frame.positions.len() != (fur.layers as usize + 1) * v || frame.normals.len() != v {
            return Err(ExportError::Input(format!(
                "a pose has {} positions and {} normals; the fur needs {} and {v}",
                frame.positions.len(),
                frame.normals.len(),
                (fur.layers as usize + 1) * v
            )));
        }
        if frame.positions.iter().any(|p| !p.is_finite()) {
            return Err(ExportError::Input("a pose has positions that are not finite".to_owned()));
        }
    }
    let kept = kept_strands(input);
    let error = |e: std::io::Error| ExportError::Write { file: path.to_path_buf(), problem: e.to_string() };
    let name = path
        .file_name()
        .ok_or_else(|| ExportError::Write { file: path.to_path_buf(), problem: "not a file name".to_owned() })?;
    let temporary = path.with_file_name(format!(".{}.{}.partial", name.to_string_lossy(), std::process::id()));
    let result = std::fs::File::create(&temporary)
        .and_then(|file| write_layer(BufWriter::with_capacity(1 << 20, file), input, &kept))
        .and_then(|counts| std::fs::rename(&temporary, path).map(|()| counts));
    result.map_err(|e| {
        let _ = std::fs::remove_file(&temporary);
        error(e)
    })
}

fn write_layer<W: Write>(out: W, input: &StrandExportInput<'_>, kept: &[usize]) -> std::io::Result<StrandExportCounts> {
    let fur = input.fur;
    let mesh = &fur.mesh;
    let reference = input.reference;
    let v = fur.vertex_count();
    let timed = input.frames.len() > 1 || input.frames[0].time_code.is_some();
    let time_range = timed.then(|| {
        let times: Vec<f64> = input.frames.iter().map(|f| f.time_code.unwrap_or(0.0)).collect();
        (times[0], times[times.len() - 1], input.frames_per_second)
    });
    let metadata = StageMetadata {
        default_prim: "Fur".to_owned(),
        up_axis: UpAxis::Y,
        meters_per_unit: input.meters_per_unit,
        doc: input.doc.clone(),
        time: time_range,
    };
    let mut usd = UsdaWriter::new(out, &metadata)?;
    usd.begin_prim("Xform", "Fur", Some("component"))?;

    // The base mesh.
    usd.begin_prim("Mesh", "Body", None)?;
    usd.attribute("uniform token", "subdivisionScheme", "\"none\"")?;
    usd.array("int[]", "faceVertexCounts", mesh.triangles.iter(), None, |w, _| w.write_all(b"3"))?;
    usd.array("int[]", "faceVertexIndices", mesh.triangles.iter().flatten(), None, |w, j| write!(w, "{j}"))?;
    let vec3 = |w: &mut W, p: Vec3| write!(w, "({}, {}, {})", format_f32(p.x), format_f32(p.y), format_f32(p.z));
    let roots = |frame: &StrandFrame| frame.positions[..v].to_vec();
    let mesh_extent = bounds(input.frames[0].positions[..v].iter().copied(), 0.0);
    if timed {
        usd.time_sampled_array(
            "point3f[]",
            "points",
            input.frames.iter().map(|f| Ok((f.time_code.unwrap_or(0.0), roots(f)))),
            vec3,
        )?;
        usd.declare("normal3f[]", "normals", Some("vertex"))?;
        usd.time_sampled_array(
            "normal3f[]",
            "normals",
            input.frames.iter().map(|f| Ok((f.time_code.unwrap_or(0.0), f.normals.clone()))),
            vec3,
        )?;
        usd.time_sampled_array(
            "float3[]",
            "extent",
            input.frames.iter().map(|f| {
                let [low, high] = bounds(f.positions[..v].iter().copied(), 0.0);
                Ok((f.time_code.unwrap_or(0.0), vec![low, high]))
            }),
            vec3,
        )?;
    } else {
        usd.array("point3f[]", "points", roots(&input.frames[0]), None, vec3)?;
        usd.array("normal3f[]", "normals", input.frames[0].normals.iter().copied(), Some("vertex"), vec3)?;
        usd.array("float3[]", "extent", mesh_extent, None, vec3)?;
    }
    if let Some(uvs) = &mesh.corner_uvs {
        // USD's st has t up; the mesh's v runs down from the image's top row.
        usd.array("texCoord2f[]", "primvars:st", uvs.iter().flatten(), Some("faceVarying"), |w, uv: &Vec2| {
            write!(w, "({}, {})", format_f32(uv.x), format_f32(1.0 - uv.y))
        })?;
    }
    usd.end_prim()?;

    // The strands.
    usd.begin_prim("BasisCurves", "Strands", None)?;
    match input.basis {
        StrandBasis::Linear => usd.attribute("uniform token", "type", "\"linear\"")?,
        StrandBasis::CatmullRom => {
            usd.attribute("uniform token", "type", "\"cubic\"")?;
            usd.attribute("uniform token", "basis", "\"catmullRom\"")?;
            usd.attribute("uniform token", "wrap", "\"pinned\"")?;
        }
    }
    let strands: Vec<&PlacedStrand> = kept.iter().map(|&k| &reference.strands[k]).collect();
    usd.array("int[]", "curveVertexCounts", strands.iter(), None, |w, s| write!(w, "{}", s.node_count))?;
    let taper = reference.field.params.taper;
    let widths: Vec<f32> = strands
        .iter()
        .flat_map(|placed| {
            let strand = reference.field_strand(placed);
            reference
                .strand_nodes(placed)
                .iter()
                .map(move |node| 2.0 * strand.radius_at(node.height, taper) * placed.world_per_texel)
        })
        .collect();
    let widest = widths.iter().copied().fold(0.0, f32::max);
    usd.array("float[]", "widths", widths.iter().copied(), Some("vertex"), |w, x| {
        w.write_all(format_f32(x).as_bytes())
    })?;
    drop(widths);
    let colours: Vec<Vec3> = strands.iter().map(|placed| strand_colour(input, placed)).collect();
    usd.array("color3f[]", "primvars:displayColor", colours.iter().copied(), Some("uniform"), vec3)?;
    drop(colours);
    usd.array(
        "float[]",
        "primvars:pelt:lengthFactor",
        strands.iter().map(|placed| reference.field_strand(placed).length_factor()),
        Some("uniform"),
        |w, x| w.write_all(format_f32(x).as_bytes()),
    )?;
    // Each frame's points and their texture offsets (see the module docs), curve after curve.
    let points = |frame: &StrandFrame| -> std::io::Result<(Vec<Vec3>, Vec<Vec3>)> {
        let (nodes, offsets) = reference
            .node_positions_and_offsets(&frame.positions)
            .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e.to_string()))?;
        let gather = |all: &[Vec3]| -> Vec<Vec3> {
            strands
                .iter()
                .flat_map(|placed| {
                    let first = placed.first_node as usize;
                    all[first..first + placed.node_count as usize].iter().copied()
                })
                .collect()
        };
        Ok((gather(&nodes), gather(&offsets)))
    };
    let (first, first_offsets) = points(&input.frames[0])?;
    let point_count = first.len();
    let curves_extent = bounds(first.iter().copied(), widest * 0.5);
    if timed {
        // The offsets follow the pose (the columns bend with it): one sample per frame, computed
        // again rather than held for every frame.
        usd.declare("vector3f[]", "primvars:pelt:textureOffset", Some("vertex"))?;
        usd.time_sampled_array(
            "vector3f[]",
            "primvars:pelt:textureOffset",
            input.frames.iter().enumerate().map(|(k, f)| {
                let offsets = if k == 0 { first_offsets.clone() } else { points(f)?.1 };
                Ok((f.time_code.unwrap_or(0.0), offsets))
            }),
            vec3,
        )?;
        drop(first_offsets);
        let mut extents = Vec::with_capacity(input.frames.len());
        usd.time_sampled_array(
            "point3f[]",
            "points",
            input.frames.iter().enumerate().map(|(k, f)| {
                let frame_points = if k == 0 { first.clone() } else { points(f)?.0 };
                extents.push((f.time_code.unwrap_or(0.0), bounds(frame_points.iter().copied(), widest * 0.5)));
                Ok((f.time_code.unwrap_or(0.0), frame_points))
            }),
            vec3,
        )?;
        usd.time_sampled_array("float3[]", "extent", extents.into_iter().map(|(t, e)| Ok((t, e))), vec3)?;
    } else {
        usd.array("vector3f[]", "primvars:pelt:textureOffset", first_offsets, Some("vertex"), vec3)?;
        usd.array("point3f[]", "points", first.iter().copied(), None, vec3)?;
        usd.array("float3[]", "extent", curves_extent, None, vec3)?;
    }
    usd.end_prim()?;
    usd.end_prim()?;
    usd.finish()?;
    Ok(StrandExportCounts {
        curves: strands.len(),
        points: point_count,
        mesh_vertices: v,
        mesh_triangles: mesh.triangles.len(),
        time_samples: if timed { input.frames.len() } else { 0 },
        curves_extent,
        mesh_extent,
    })
}

/// `[min, max]` of `points`, grown by `margin`; zeros for no points.
fn bounds(points: impl Iterator<Item = Vec3>, margin: f32) -> [Vec3; 2] {
    let (low, high) =
        points.fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(l, h), p| (l.min(p), h.max(p)));
    if low.is_finite() { [low - margin, high + margin] } else { [Vec3::ZERO; 2] }
}

/// A strand's linear colour: the textures' colour averaged over its nodes (8-bit sRGB, as the
/// shells sample it), times the surface texture at its root and the groom's tint there.
fn strand_colour(input: &StrandExportInput<'_>, placed: &PlacedStrand) -> Vec3 {
    let reference = input.reference;
    let strand = reference.field_strand(placed);
    let nodes = reference.strand_nodes(placed);
    let mut sum = Vec3::ZERO;
    for node in nodes {
        sum += reference
            .field
            .colour(strand, node.height)
            .map(|c| srgb_to_linear((c.clamp(0.0, 1.0) * 255.0).round() / 255.0));
    }
    let mut colour = sum / nodes.len().max(1) as f32;
    if let (Some(image), Some(uv)) = (reference.field.surface(), placed.surface_uv) {
        colour *= image.sample_wrapped(uv.x, uv.y).truncate().map(srgb_to_linear);
    }
    if let Some(tint) = input.fur.groom.as_ref().and_then(|g| g.tint.as_ref()) {
        let corners = input.fur.mesh.triangles[placed.triangle as usize];
        let root = nodes[0].barycentric;
        colour *=
            corners.iter().zip(root.to_array()).map(|(&j, w)| tint[j as usize] * w).fold(Vec3::ZERO, |a, b| a + b);
    }
    colour.clamp(Vec3::ZERO, Vec3::ONE)
}
