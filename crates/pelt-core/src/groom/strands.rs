//! A strand groom (USD `BasisCurves`, from Blender, Houdini or `pelt export`) baked into a
//! per-vertex [`Groom`].
//!
//! Each curve's root is placed at the closest point of the mesh's surface (roots farther than
//! the tolerance are counted off the surface and left out); its barycentric weights there say
//! how much it speaks for each corner. The shells draw a strand as the barycentric blend of its
//! triangle's columns, so the bake solves for the per-vertex values whose blend best matches the
//! curves (least squares, lightly pulled toward each vertex's weighted mean where few curves
//! decide it): a vertex whose own curves are short stays short even beside long ones, and bald
//! stays bald.
//!
//! Curves Pelt exported carry `primvars:pelt:textureOffset`, what the shell texture added to
//! each point (its lean, clumps and curl): the bake takes it off first, so it measures the groom
//! alone and the preset's texture, growing the coat again, does not add its lean twice. Curves
//! without it (Blender, other tools) are measured as they are.
//!
//! - **length**: the curves' arc lengths over their strand length factor (Pelt's own
//!   `primvars:pelt:lengthFactor`, else the field's mean: a coat's strands end at seeded heights
//!   below its tip), over the preset's length; a vertex shorter than one layer's height of the
//!   preset's fur, or with no curve near it, is bald (0).
//! - **direction**: the curves' first segments, solved likewise, turned into the flow that makes
//!   the preset grow that direction (its comb blend and random tilt included).
//! - **density**: the curves' weights at a vertex over those of the field's strands at a uniform
//!   density (`expected_strands`), at most 1.
//! - **clump**: how much closer together the tips of a vertex's curves lie than their roots.
//! - **tint**: `primvars:displayColor` over the preset's own strand colour, where the file has
//!   colours; a tint only darkens, so a colour brighter than the preset's is scaled down to
//!   `0..=1` keeping its hue.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use super::sparse::Sparse;
use super::surface_grid::TriangleGrid;
use super::{Groom, GroomError, MAX_LENGTH_FACTOR};
use crate::mesh::Mesh;
use crate::usd::{UpAxis, UsdCurves};

/// Points each cubic segment is sampled at.
const SAMPLES_PER_SEGMENT: usize = 4;
/// How strongly a vertex's value is pulled toward its curves' weighted mean (against the fit).
const PULL_TO_MEAN: f64 = 0.002;

/// What a strand groom bakes against: the preset's fur on one mesh.
pub struct StrandBakeParams<'a> {
    /// The preset's length per vertex, model units (before any groom).
    pub lengths: &'a [f32],
    /// Layers of the fur (a vertex shorter than one layer's height is bald).
    pub layers: u32,
    /// The strand field's mean length factor (its strands' mean length over the fur's).
    pub mean_length_factor: f32,
    /// Strands the field places on each triangle at full density.
    pub expected_strands: &'a [f32],
    /// The most a clumped strand's tip gathers toward its clump (the shells' clump parting).
    pub max_gather: f32,
    /// The preset's own strand colour at each vertex, linear (a tint is the file's over it).
    pub base_colours: &'a [Vec3],
    /// The direction the preset grows vertex `j` with flow `flow` (unit vector).
    pub grow: &'a (dyn Fn(usize, Vec2) -> Vec3 + Sync),
    /// Metres per model unit of the mesh (which is Y-up).
    pub mesh_meters_per_unit: f64,
    /// Roots farther than this from the surface (model units) are off it.
    pub tolerance: f32,
}

impl std::fmt::Debug for StrandBakeParams<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StrandBakeParams")
            .field("layers", &self.layers)
            .field("mean_length_factor", &self.mean_length_factor)
            .field("mesh_meters_per_unit", &self.mesh_meters_per_unit)
            .field("tolerance", &self.tolerance)
            .finish_non_exhaustive()
    }
}

/// What a bake found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StrandBakeReport {
    /// The file.
    pub file: PathBuf,
    /// `BasisCurves` prims.
    pub curve_sets: usize,
    /// Curves read.
    pub curves: usize,
    /// Curves whose roots lie on the surface (within the tolerance).
    pub on_surface: usize,
    /// Curves whose roots lie farther than the tolerance.
    pub off_surface: usize,
    /// Curves of no length (left out).
    pub degenerate: usize,
    /// The tolerance, model units.
    pub tolerance: f32,
    /// Mean and largest distance of the on-surface roots from the surface, model units.
    pub root_distance_mean: f32,
    /// Largest.
    pub root_distance_max: f32,
    /// Vertices with fur after the bake.
    pub furred_vertices: usize,
    /// Vertices left bald.
    pub bald_vertices: usize,
    /// The stage's up axis and metres per unit, as read.
    pub stage: String,
    /// What the reader read past.
    pub notes: Vec<String>,
}

impl std::fmt::Display for StrandBakeReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {} curves in {} BasisCurves ({}); {} rooted on the surface (root distance mean {:.3e}, max {:.3e})",
            self.file.display(),
            self.curves,
            self.curve_sets,
            self.stage,
            self.on_surface,
            self.root_distance_mean,
            self.root_distance_max,
        )?;
        if self.off_surface > 0 {
            write!(f, ", {} off the surface (farther than {:.3e}) left out", self.off_surface, self.tolerance)?;
        }
        if self.degenerate > 0 {
            write!(f, ", {} of no length left out", self.degenerate)?;
        }
        write!(f, "; {} vertices furred, {} bald", self.furred_vertices, self.bald_vertices)?;
        for note in &self.notes {
            write!(f, "; {note}")?;
        }
        Ok(())
    }
}

/// Bakes `curves` (read from `file`) onto `mesh`.
///
/// # Errors
/// [`GroomError::Strands`] naming the file when it has no curves, when no root lies on the
/// surface, or when the parameters do not fit the mesh.
pub fn bake_strands(
    mesh: &Mesh,
    curves: &UsdCurves,
    file: &Path,
    params: &StrandBakeParams<'_>,
) -> Result<(Groom, StrandBakeReport), GroomError> {
    let fail = |problem: String| GroomError::Strands { file: file.to_path_buf(), problem };
    let v = mesh.vertex_count();
    if params.lengths.len() != v || params.base_colours.len() != v {
        return Err(fail(format!("the preset's lengths and colours need {v} values, one per vertex")));
    }
    if params.expected_strands.len() != mesh.triangles.len() {
        return Err(fail("the expected strand counts need one value per triangle".to_owned()));
    }
    if !(params.tolerance.is_finite() && params.tolerance > 0.0) {
        return Err(fail(format!("the root tolerance must be positive, got {}", params.tolerance)));
    }
    let total: usize = curves.curves.iter().map(|c| c.counts.len()).sum();
    if total == 0 {
        let what = if curves.curves.is_empty() { "no BasisCurves prims" } else { "BasisCurves with no curves" };
        let meshes = if curves.meshes > 0 { format!(" (it has {} meshes)", curves.meshes) } else { String::new() };
        return Err(fail(format!("{what}: nothing to bake{meshes}")));
    }
    let axis = match curves.up_axis {
        UpAxis::Y => "Y up",
        UpAxis::Z => "Z up",
    };
    let mut report = StrandBakeReport {
        file: file.to_path_buf(),
        curve_sets: curves.curves.len(),
        curves: total,
        tolerance: params.tolerance,
        stage: format!("{axis}, {} m per unit", curves.meters_per_unit),
        notes: curves.notes.clone(),
        ..StrandBakeReport::default()
    };
    // The stage's space to the mesh's: metres, then Y up.
    let scale = (curves.meters_per_unit / params.mesh_meters_per_unit) as f32;
    let to_mesh = |p: Vec3| match curves.up_axis {
        UpAxis::Y => p * scale,
        UpAxis::Z => Vec3::new(p.x, p.z, -p.y) * scale,
    };
    let grid = TriangleGrid::new(mesh, params.tolerance);
    let mut sums = Sums::new(mesh);
    let mean_factor = params.mean_length_factor.max(1e-3);
    let mut distance_sum = 0.0f64;
    let mut nearest_off = f32::INFINITY;
    let mut straightened = 0usize;
    for set in &curves.curves {
        let starts = set.offsets();
        for k in 0..set.counts.len() {
            let curve = set.curve(&starts, k);
            // Pelt's own curves say what the shell texture added to each point: the groom is
            // measured on what is left (the preset's texture adds its lean again when it grows).
            let points: Vec<Vec3> = match &set.texture_offsets {
                Some(texture) => {
                    straightened += 1;
                    let texture = &texture[starts[k]..starts[k] + curve.len()];
                    curve.iter().zip(texture).map(|(&p, &o)| to_mesh(p - o)).collect()
                }
                None => curve.iter().map(|&p| to_mesh(p)).collect(),
            };
            let line = set.polyline(&points, SAMPLES_PER_SEGMENT);
            let length: f32 = line.windows(2).map(|w| w[0].distance(w[1])).sum();
            let first = line.windows(2).map(|w| w[1] - w[0]).find(|d| d.length() > length * 1e-4);
            let (Some(first), true) = (first, length.is_finite() && length > 0.0) else {
                report.degenerate += 1;
                continue;
            };
            let root = line[0];
            let Some((triangle, weights, distance)) = grid.closest(mesh, root) else {
                report.off_surface += 1;
                // A few are enough to say how far off they lie (the search is brute force).
                if report.off_surface <= 64 {
                    nearest_off = nearest_off.min(grid.any_distance(mesh, root));
                }
                continue;
            };
            report.on_surface += 1;
            distance_sum += f64::from(distance);
            report.root_distance_max = report.root_distance_max.max(distance);
            let colour = set.colours.as_ref().map(|c| c[k]);
            let tip = line[line.len() - 1];
            let factor = set.length_factors.as_ref().map_or(mean_factor, |f| f[k]);
            sums.add(mesh.triangles[triangle], weights, length / factor, first.normalize(), root, tip, colour);
        }
    }
    if report.on_surface == 0 {
        let nearest = if nearest_off.is_finite() {
            format!("; the nearest lies {nearest_off:.3e} from it")
        } else {
            String::new()
        };
        return Err(fail(format!(
            "none of its {total} curves has its root within {:.3e} of the mesh's surface{nearest} \
             (after the stage's {axis} and {} m per unit; the mesh is Y up at {} m per unit)",
            params.tolerance, curves.meters_per_unit, params.mesh_meters_per_unit
        )));
    }
    if straightened > 0 {
        report
            .notes
            .push(format!("the shell texture's offsets (primvars:pelt:textureOffset) taken off {straightened} curves"));
    }
    report.root_distance_mean = (distance_sum / report.on_surface as f64) as f32;
    let groom = sums.solve(mesh, params, &mut report);
    Ok((groom, report))
}

/// Per-vertex sums over the curves: the least-squares system and the plain means.
struct Sums {
    /// `A^T A` of the barycentric weights, in the mesh's one-ring pattern.
    matrix: Sparse,
    /// `A^T y` for the three components of the curves' length-weighted directions.
    rhs: Vec<[f64; 3]>,
    /// Sum of weights and of squared weights per vertex.
    weight: Vec<f64>,
    weight_sq: Vec<f64>,
    colour: Vec<Vec3>,
    has_colour: bool,
    /// Per nearest vertex: count, root sum and squared sum, tip likewise.
    spread: Vec<(f64, Vec3, f64, Vec3, f64)>,
}

impl Sums {
    fn new(mesh: &Mesh) -> Self {
        let v = mesh.vertex_count();
        Self {
            matrix: Sparse::new(mesh),
            rhs: vec![[0.0; 3]; v],
            weight: vec![0.0; v],
            weight_sq: vec![0.0; v],
            colour: vec![Vec3::ZERO; v],
            has_colour: false,
            spread: vec![(0.0, Vec3::ZERO, 0.0, Vec3::ZERO, 0.0); v],
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn add(
        &mut self,
        corners: [u32; 3],
        weights: [f32; 3],
        length: f32,
        direction: Vec3,
        root: Vec3,
        tip: Vec3,
        colour: Option<Vec3>,
    ) {
        let along = direction * length;
        for (a, &wa) in corners.iter().zip(&weights) {
            let (j, wa) = (*a as usize, f64::from(wa));
            for (b, &wb) in corners.iter().zip(&weights) {
                self.matrix.add(*a, *b, wa * f64::from(wb));
            }
            for (rhs, x) in self.rhs[j].iter_mut().zip(along.to_array()) {
                *rhs += wa * f64::from(x);
            }
            self.weight[j] += wa;
            self.weight_sq[j] += wa * wa;
            if let Some(colour) = colour {
                self.colour[j] += colour * wa as f32;
                self.has_colour = true;
            }
        }
        let nearest = (0..3).max_by(|&a, &b| weights[a].total_cmp(&weights[b])).unwrap_or(0);
        let s = &mut self.spread[corners[nearest] as usize];
        s.0 += 1.0;
        s.1 += root;
        s.2 += f64::from(root.length_squared());
        s.3 += tip;
        s.4 += f64::from(tip.length_squared());
    }

    fn solve(mut self, mesh: &Mesh, params: &StrandBakeParams<'_>, report: &mut StrandBakeReport) -> Groom {
        let v = mesh.vertex_count();
        // Pull each vertex toward its weighted mean by a share of its own weight; a vertex no
        // curve reaches is pinned to 0 (bald).
        let mut rhs = self.rhs.clone();
        for (j, rhs) in rhs.iter_mut().enumerate() {
            let pull = PULL_TO_MEAN * self.weight_sq[j];
            if self.weight[j] > 0.0 {
                for (value, own) in rhs.iter_mut().zip(self.rhs[j]) {
                    *value += pull * own / self.weight[j];
                }
                self.matrix.add_diagonal(j, pull);
            } else {
                self.matrix.add_diagonal(j, 1.0);
            }
        }
        let solved: Vec<Vec<f64>> =
            (0..3).map(|c| self.matrix.solve(&rhs.iter().map(|r| r[c]).collect::<Vec<_>>())).collect();
        let bald_below = 1.0 / params.layers.max(1) as f32;
        let mut length = vec![0.0f32; v];
        let mut direction = vec![Vec2::ZERO; v];
        let mut density = vec![1.0f32; v];
        let mut expected = vec![0.0f32; v];
        for (t, corners) in mesh.triangles.iter().enumerate() {
            for &j in corners {
                expected[j as usize] += params.expected_strands[t] / 3.0;
            }
        }
        for j in 0..v {
            let preset = params.lengths[j];
            // A column is its growth direction times its length: the blend of the corners'
            // columns is what a strand follows, so the fit is of that vector.
            let along = Vec3::new(solved[0][j] as f32, solved[1][j] as f32, solved[2][j] as f32);
            let factor = if self.weight[j] > 0.0 && preset > 0.0 { along.length() / preset } else { 0.0 };
            if !(factor.is_finite() && factor >= bald_below) {
                continue;
            }
            length[j] = factor.min(MAX_LENGTH_FACTOR);
            if let Some(wanted) = along.try_normalize() {
                direction[j] = flow_for(j, wanted, params.grow);
            }
            if expected[j] > 0.0 {
                density[j] = (self.weight[j] as f32 / expected[j]).clamp(0.0, 1.0);
            }
        }
        report.furred_vertices = length.iter().filter(|&&l| l > 0.0).count();
        report.bald_vertices = v - report.furred_vertices;
        let clump: Vec<f32> = self
            .spread
            .iter()
            .map(|&(n, root_sum, root_sq, tip_sum, tip_sq)| {
                if n < 3.0 {
                    return 0.0;
                }
                let variance = |sum: Vec3, sq: f64| (sq / n - f64::from((sum / n as f32).length_squared())).max(0.0);
                let roots = variance(root_sum, root_sq);
                let tips = variance(tip_sum, tip_sq);
                // Tips gathered into a clump spread less about their mean than their roots do.
                if roots <= 0.0 {
                    return 0.0;
                }
                let ratio = (tips / roots).sqrt() as f32;
                ((1.0 - ratio) / params.max_gather.max(1e-3)).clamp(0.0, 1.0)
            })
            .collect();
        let tint = self.has_colour.then(|| {
            (0..v)
                .map(|j| {
                    if self.weight[j] <= 0.0 {
                        return Vec3::ONE;
                    }
                    let colour = self.colour[j] / self.weight[j] as f32;
                    // A tint only darkens: a colour brighter than the preset's keeps its hue.
                    let ratio = (colour / params.base_colours[j].max(Vec3::splat(1e-4))).max(Vec3::ZERO);
                    (ratio / ratio.max_element().max(1.0)).clamp(Vec3::ZERO, Vec3::ONE)
                })
                .collect()
        });
        Groom {
            length: Some(length),
            density: Some(density),
            direction: Some(direction),
            clump: clump.iter().any(|&c| c > 0.02).then_some(clump),
            tint,
        }
    }
}

/// The flow (length at most 1) for which `grow` gives the direction closest to `wanted`,
/// whatever comb and tilt the preset adds: a coarse search over the flow's angle and length,
/// then a pattern search that halves its steps. The preset's comb saturates at a flow of length
/// 1, so the search stays in the unit disc.
fn flow_for(j: usize, wanted: Vec3, grow: &(dyn Fn(usize, Vec2) -> Vec3 + Sync)) -> Vec2 {
    let flow = |angle: f32, radius: f32| Vec2::from_angle(angle) * radius;
    let score = |angle: f32, radius: f32| grow(j, flow(angle, radius)).dot(wanted);
    let mut best = (0.0f32, 0.0f32, score(0.0, 0.0));
    for a in 0..24 {
        for r in 1..=6 {
            let (angle, radius) = (a as f32 * std::f32::consts::TAU / 24.0, r as f32 / 6.0);
            let s = score(angle, radius);
            if s > best.2 {
                best = (angle, radius, s);
            }
        }
    }
    let (mut angle_step, mut radius_step) = (std::f32::consts::TAU / 48.0, 1.0 / 12.0);
    for _ in 0..40 {
        let mut moved = false;
        for (da, dr) in [(angle_step, 0.0), (-angle_step, 0.0), (0.0, radius_step), (0.0, -radius_step)] {
            let (angle, radius) = (best.0 + da, (best.1 + dr).clamp(0.0, 1.0));
            let s = score(angle, radius);
            if s > best.2 {
                best = (angle, radius, s);
                moved = true;
            }
        }
        if !moved {
            angle_step *= 0.5;
            radius_step *= 0.5;
            if angle_step < 1e-4 {
                break;
            }
        }
    }
    flow(best.0, best.1)
}
