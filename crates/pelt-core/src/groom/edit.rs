//! [`GroomEditor`]: a groom being painted on its rest mesh, stroke by stroke, with undo and redo.

use glam::{Vec2, Vec3};

use super::brush::{Brush, BrushKind, LENGTH_STEP, flow_of, mix};
use super::{Groom, GroomError, GroomMap, MAX_LENGTH_FACTOR, TangentFrame, tangent_frames};
use crate::mesh::Mesh;

/// Strokes kept for undo; the oldest goes first.
pub const UNDO_DEPTH: usize = 100;
/// A stroke dabs again once the pointer has moved this fraction of the radius since its last dab.
pub const DAB_SPACING: f32 = 0.25;

/// A groom being painted on the rest pose of one mesh. Dabs land on the rest surface (a posed
/// hit maps there with [`rest_point`]); strokes are the unit of undo and redo, and undo restores
/// each map exactly (to the bit, and absent maps absent again).
#[derive(Clone, Debug)]
pub struct GroomEditor {
    groom: Groom,
    rest: Vec<Vec3>,
    frames: Vec<TangentFrame>,
    /// Each vertex's neighbours along the mesh's edges (for smoothing).
    neighbours: Vec<Vec<u32>>,
    /// The preset's comb as a flow in each vertex's frame: what an absent direction map means.
    preset_flow: Vec<Vec2>,
    stroke: Option<Stroke>,
    undo: Vec<Edit>,
    redo: Vec<Edit>,
}

/// A stroke in progress: the groom before it, and where it last dabbed.
#[derive(Clone, Debug)]
struct Stroke {
    before: Groom,
    last: Option<Vec3>,
}

/// One map a stroke touched: its values before and after (`None`: absent).
type MapChange = (GroomMap, Option<Vec<f32>>, Option<Vec<f32>>);

/// One stroke's change: each map it touched, before and after.
#[derive(Clone, Debug)]
struct Edit {
    maps: Vec<MapChange>,
}

impl GroomEditor {
    /// An editor of `groom` (`None`: the uniform fur) on `mesh`'s rest pose; `comb` is the
    /// preset's world comb direction (`direction.comb`), which an absent direction map stands for.
    ///
    /// # Errors
    /// [`GroomError::Size`] or [`GroomError::Value`] for a groom that does not fit `mesh`.
    pub fn new(mesh: &Mesh, groom: Option<Groom>, comb: Vec3) -> Result<Self, GroomError> {
        let groom = groom.unwrap_or_default();
        groom.validate(mesh.vertex_count(), "the groom to paint")?;
        let frames = tangent_frames(mesh);
        let preset_flow = mesh
            .normals
            .iter()
            .zip(&frames)
            .map(|(&n, f)| flow_of(comb - n * comb.dot(n), f.tangent, f.up).unwrap_or(Vec2::ZERO))
            .collect();
        let mut neighbours = vec![Vec::new(); mesh.vertex_count()];
        for &[a, b] in &mesh.edges {
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
        }
        Ok(Self {
            groom,
            rest: mesh.positions.clone(),
            frames,
            neighbours,
            preset_flow,
            stroke: None,
            undo: Vec::new(),
            redo: Vec::new(),
        })
    }

    /// The groom as painted so far.
    #[must_use]
    pub fn groom(&self) -> &Groom {
        &self.groom
    }

    /// The preset's value of `map` at `vertex` (what an absent map means): length 1, density 1,
    /// the preset's comb for direction, clump 0, tint white.
    #[must_use]
    pub fn neutral(&self, map: GroomMap, vertex: usize) -> Vec<f32> {
        match map {
            GroomMap::Length | GroomMap::Density => vec![1.0],
            GroomMap::Direction => self.preset_flow[vertex].to_array().to_vec(),
            GroomMap::Clump => vec![0.0],
            GroomMap::Tint => vec![1.0; 3],
        }
    }

    /// Starts a stroke (ending one still open).
    pub fn begin_stroke(&mut self) {
        self.end_stroke();
        self.stroke = Some(Stroke { before: self.groom.clone(), last: None });
    }

    /// Moves the open stroke to `point` (rest surface, model units), dabbing when it is the
    /// stroke's first point or has moved [`DAB_SPACING`] of the radius since the last dab; the
    /// comb dabs along the way it moved (not on the first point). Opens a stroke if none is.
    /// Returns the map changed, if a dab landed.
    pub fn stroke_to(&mut self, brush: &Brush, point: Vec3) -> Option<GroomMap> {
        if self.stroke.is_none() {
            self.begin_stroke();
        }
        let stroke = self.stroke.as_mut().expect("a stroke was opened above");
        let direction = match stroke.last {
            None => None,
            Some(last) if point.distance(last) < brush.radius * DAB_SPACING => return None,
            Some(last) => Some(point - last),
        };
        stroke.last = Some(point);
        if brush.kind == BrushKind::Comb && direction.is_none() {
            return None;
        }
        self.dab(brush, point, direction.unwrap_or(Vec3::ZERO))
    }

    /// Ends the open stroke; true when it changed the groom (and can be undone).
    pub fn end_stroke(&mut self) -> bool {
        let Some(stroke) = self.stroke.take() else { return false };
        let maps: Vec<_> = GroomMap::ALL
            .into_iter()
            .filter_map(|map| {
                let (before, after) = (stroke.before.values(map), self.groom.values(map));
                let same = match (&before, &after) {
                    (Some(b), Some(a)) => b.iter().map(|x| x.to_bits()).eq(a.iter().map(|x| x.to_bits())),
                    (b, a) => b.is_none() && a.is_none(),
                };
                (!same).then_some((map, before, after))
            })
            .collect();
        if maps.is_empty() {
            return false;
        }
        self.undo.push(Edit { maps });
        if self.undo.len() > UNDO_DEPTH {
            self.undo.remove(0);
        }
        self.redo.clear();
        true
    }

    /// Undoes the last stroke (ending an open one first); the maps it restored.
    pub fn undo(&mut self) -> Option<Vec<GroomMap>> {
        self.end_stroke();
        let edit = self.undo.pop()?;
        let maps = self.restore(&edit, true);
        self.redo.push(edit);
        Some(maps)
    }

    /// Redoes the last undone stroke; the maps it changed.
    pub fn redo(&mut self) -> Option<Vec<GroomMap>> {
        self.end_stroke();
        let edit = self.redo.pop()?;
        let maps = self.restore(&edit, false);
        self.undo.push(edit);
        Some(maps)
    }

    /// Strokes that can be undone and redone.
    #[must_use]
    pub fn history(&self) -> (usize, usize) {
        (self.undo.len(), self.redo.len())
    }

    fn restore(&mut self, edit: &Edit, before: bool) -> Vec<GroomMap> {
        for (map, old, new) in &edit.maps {
            match if before { old } else { new } {
                Some(values) => self.groom.set_values(*map, values.clone()),
                None => self.groom.clear(*map),
            }
        }
        edit.maps.iter().map(|(map, _, _)| *map).collect()
    }

    /// One dab at `point` (rest surface, model units), `direction` being the stroke's way there
    /// (the comb's; others ignore it), mirrored when the brush says. Returns the map changed, if
    /// any vertex was in reach. Outside a stroke, the dab is a stroke of its own.
    pub fn dab(&mut self, brush: &Brush, point: Vec3, direction: Vec3) -> Option<GroomMap> {
        if self.stroke.is_none() {
            self.begin_stroke();
            let changed = self.dab(brush, point, direction);
            self.end_stroke();
            return changed;
        }
        let weights = self.weights(brush, point, direction);
        if weights.is_empty() {
            return None;
        }
        let map = brush.kind.target(brush.map);
        let absent = !self.groom.has(map);
        if absent && matches!(brush.kind, BrushKind::Smooth | BrushKind::Erase) {
            // Smoothing or erasing the preset's uniform value changes nothing.
            return None;
        }
        let n = map.components();
        let mut values = match self.groom.values(map) {
            Some(values) => values,
            None => (0..self.rest.len()).flat_map(|j| self.neutral(map, j)).collect(),
        };
        // Every new value from the values before the dab (smoothing reads the neighbours').
        let updates: Vec<(usize, Vec<f32>)> = weights
            .iter()
            .filter_map(|&(j, w, d)| {
                let old = &values[j * n..j * n + n];
                self.apply(brush, j, w, d, old, &values).map(|new| (j, new))
            })
            .collect();
        for (j, new) in updates {
            values[j * n..j * n + n].copy_from_slice(&new);
        }
        self.groom.set_values(map, values);
        Some(map)
    }

    /// The dab's weight and stroke direction at each vertex in reach: the dab itself and, with a
    /// mirror, its reflection (a vertex reached by both takes the larger weight, and on a tie
    /// the one from its own side of the plane).
    fn weights(&self, brush: &Brush, point: Vec3, direction: Vec3) -> Vec<(usize, f32, Vec3)> {
        let mirror = brush.mirror.map(|axis| (axis, axis.reflect(point), axis.reflect(direction)));
        self.rest
            .iter()
            .enumerate()
            .filter_map(|(j, &p)| {
                let direct = brush.weight(p.distance(point)).map(|w| (w, direction));
                let Some((axis, centre, reflected)) = mirror else { return direct.map(|(w, d)| (j, w, d)) };
                let mirrored = brush.weight(p.distance(centre)).map(|w| (w, reflected));
                let own_side = (axis.of(p) >= 0.0) == (axis.of(point) >= 0.0);
                let chosen = match (direct, mirrored) {
                    (Some(a), Some(b)) if b.0 > a.0 || (b.0 == a.0 && !own_side) => Some(b),
                    (Some(a), _) => Some(a),
                    (None, b) => b,
                };
                chosen.map(|(w, d)| (j, w, d))
            })
            .collect()
    }

    /// The new value of vertex `j` (`old`, from `values`) under a dab of weight `w` with stroke
    /// direction `d`; `None` to leave it.
    fn apply(&self, brush: &Brush, j: usize, w: f32, d: Vec3, old: &[f32], values: &[f32]) -> Option<Vec<f32>> {
        let toward = |target: &[f32]| old.iter().zip(target).map(|(&a, &b)| mix(a, b, w)).collect::<Vec<f32>>();
        let new = match brush.kind {
            BrushKind::Grow => vec![(old[0] + w * LENGTH_STEP).min(MAX_LENGTH_FACTOR)],
            BrushKind::Shorten => vec![(old[0] - w * LENGTH_STEP).max(0.0)],
            BrushKind::Cut => vec![old[0] * (1.0 - w)],
            BrushKind::Density | BrushKind::Clump => toward(&[brush.target_value()]),
            BrushKind::Tint => toward(&brush.target_colour().to_array()),
            BrushKind::Comb => {
                let frame = self.frames[j];
                let flow = flow_of(d, frame.tangent, frame.up)?;
                let new = toward(&flow.to_array());
                new.into_iter().map(|x| x.clamp(-1.0, 1.0)).collect()
            }
            BrushKind::Smooth => {
                let around = &self.neighbours[j];
                if around.is_empty() {
                    return None;
                }
                let n = old.len();
                let mean: Vec<f32> = (0..n)
                    .map(|c| around.iter().map(|&k| values[k as usize * n + c]).sum::<f32>() / around.len() as f32)
                    .collect();
                toward(&mean)
            }
            BrushKind::Erase => toward(&self.neutral(brush.kind.target(brush.map), j)),
        };
        Some(new)
    }
}

/// The rest-pose point under a hit on the posed mesh: triangle `triangle`'s rest corners
/// weighted by `barycentric` (the posed hit's weights). `None` for a triangle `mesh` lacks.
#[must_use]
pub fn rest_point(mesh: &Mesh, triangle: u32, barycentric: Vec3) -> Option<Vec3> {
    let corners = mesh.triangles.get(triangle as usize)?;
    let [a, b, c] = corners.map(|j| mesh.positions[j as usize]);
    Some(a * barycentric.x + b * barycentric.y + c * barycentric.z)
}
