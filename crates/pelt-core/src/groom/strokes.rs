//! Stroke lists: brush strokes written down (a small TOML file of model-space points), applied
//! through the same [`GroomEditor`] the viewer paints with, so a groom can be remade exactly.
//!
//! ```toml
//! [[stroke]]
//! brush = "cut"            # a BrushKind name
//! radius = 7.0             # model units
//! strength = 1.0           # default 1
//! falloff = "constant"     # default "smooth"
//! mirror = "x"             # optional
//! points = [[10.0, 57.5, 44.7]]
//! # value = 0.5 (density, clump), colour = [1.0, 0.5, 0.2] (tint), map = "length" (smooth, erase)
//! ```

use std::path::{Path, PathBuf};

use glam::Vec3;

use super::brush::{Axis, Brush, BrushKind, Falloff};
use super::{GroomEditor, GroomError, GroomMap};

/// A list of strokes, in the order they are painted.
#[derive(Clone, Debug, PartialEq)]
pub struct StrokeList {
    /// Each stroke's brush and points.
    pub strokes: Vec<(Brush, Vec<Vec3>)>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    #[serde(default)]
    stroke: Vec<StrokeEntry>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct StrokeEntry {
    brush: String,
    radius: f32,
    #[serde(default = "one")]
    strength: f32,
    #[serde(default)]
    falloff: Option<String>,
    #[serde(default)]
    mirror: Option<String>,
    #[serde(default)]
    value: Option<f32>,
    #[serde(default)]
    colour: Option<[f32; 3]>,
    #[serde(default)]
    map: Option<String>,
    points: Vec<[f32; 3]>,
}

fn one() -> f32 {
    1.0
}

impl StrokeList {
    /// Parses a stroke list; `file` names it in messages.
    ///
    /// # Errors
    /// [`GroomError::Strokes`] naming the file, the stroke (from 1) and the key for bad TOML,
    /// unknown names, or numbers that are not finite or out of range.
    pub fn from_toml_str(text: &str, file: &Path) -> Result<Self, GroomError> {
        let error = |problem: String| GroomError::Strokes { file: file.to_path_buf(), problem };
        let parsed: File = toml::from_str(text).map_err(|e| error(e.to_string()))?;
        let mut strokes = Vec::with_capacity(parsed.stroke.len());
        for (k, entry) in parsed.stroke.into_iter().enumerate() {
            let at = |key: &str, problem: String| error(format!("stroke {}: {key}: {problem}", k + 1));
            let named =
                |key: &str, name: &str, names: &[&str]| at(key, format!("{name:?} is not one of {}", names.join(", ")));
            let kind = BrushKind::from_name(&entry.brush)
                .ok_or_else(|| named("brush", &entry.brush, &BrushKind::ALL.map(BrushKind::name)))?;
            let falloff = match &entry.falloff {
                None => Falloff::Smooth,
                Some(name) => {
                    Falloff::from_name(name).ok_or_else(|| named("falloff", name, &Falloff::ALL.map(Falloff::name)))?
                }
            };
            let mirror = match &entry.mirror {
                None => None,
                Some(name) => {
                    Some(Axis::from_name(name).ok_or_else(|| named("mirror", name, &Axis::ALL.map(Axis::name)))?)
                }
            };
            let map = match &entry.map {
                None => GroomMap::Length,
                Some(name) => GroomMap::ALL
                    .into_iter()
                    .find(|m| m.key() == name)
                    .ok_or_else(|| named("map", name, &GroomMap::ALL.map(GroomMap::key)))?,
            };
            if !(entry.radius.is_finite() && entry.radius > 0.0) {
                return Err(at("radius", format!("must be a positive number, got {}", entry.radius)));
            }
            let unit = |key: &str, x: f32| {
                if (0.0..=1.0).contains(&x) { Ok(x) } else { Err(at(key, format!("must be within 0..=1, got {x}"))) }
            };
            let strength = unit("strength", entry.strength)?;
            let value = unit("value", entry.value.unwrap_or(0.5))?;
            let colour = entry.colour.unwrap_or([1.0; 3]);
            for c in colour {
                unit("colour", c)?;
            }
            let points: Vec<Vec3> = entry.points.iter().map(|p| Vec3::from_array(*p)).collect();
            if let Some(p) = points.iter().find(|p| !p.is_finite()) {
                return Err(at("points", format!("{p} is not a finite point")));
            }
            let brush =
                Brush { kind, radius: entry.radius, strength, falloff, mirror, value, colour: colour.into(), map };
            strokes.push((brush, points));
        }
        Ok(Self { strokes })
    }

    /// Reads a stroke list file.
    ///
    /// # Errors
    /// [`GroomError::Io`] for a file that cannot be read, else as [`StrokeList::from_toml_str`].
    pub fn load(file: &Path) -> Result<Self, GroomError> {
        let text =
            std::fs::read_to_string(file).map_err(|error| GroomError::Io { file: PathBuf::from(file), error })?;
        Self::from_toml_str(&text, file)
    }

    /// Paints every stroke with `editor`, one undo step each, as a pointer would: each point in
    /// turn through [`GroomEditor::stroke_to`].
    pub fn apply(&self, editor: &mut GroomEditor) {
        for (brush, points) in &self.strokes {
            editor.begin_stroke();
            for &point in points {
                editor.stroke_to(brush, point);
            }
            editor.end_stroke();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::builtin::Builtin;

    fn problem(text: &str) -> String {
        StrokeList::from_toml_str(text, Path::new("brushes/fox.strokes")).unwrap_err().to_string()
    }

    const GOOD: &str = "[[stroke]]\nbrush = \"cut\"\nradius = 0.3\npoints = [[0.0, 1.0, 0.0]]\n";

    #[test]
    fn parse_errors_name_the_file_the_stroke_and_the_key() {
        let cases = [
            ("[[stroke]]\nbrush = \"paint\"\nradius = 0.3\npoints = []\n", "stroke 1: brush: \"paint\" is not one of"),
            (&format!("{GOOD}[[stroke]]\nbrush = \"grow\"\nradius = -1.0\npoints = []\n"), "stroke 2: radius"),
            (&format!("{GOOD}falloff = \"sharp\"\n"), "stroke 1: falloff: \"sharp\""),
            (&format!("{GOOD}mirror = \"w\"\n"), "stroke 1: mirror: \"w\""),
            (&format!("{GOOD}map = \"colour\"\n"), "stroke 1: map: \"colour\""),
            (&format!("{GOOD}strength = 1.5\n"), "stroke 1: strength: must be within 0..=1, got 1.5"),
            (&format!("{GOOD}colour = [0.5, 2.0, 0.0]\n"), "stroke 1: colour"),
            ("[[stroke]]\nbrush = \"cut\"\nradius = 0.3\npoints = [[nan, 0.0, 0.0]]\n", "stroke 1: points"),
            ("[[stroke]]\nbrush = \"cut\"\nradius = 0.3\npoints = [[0.0, 0.0, 0.0]]\nsize = 2\n", "size"),
            ("[[stroke]\n", "brushes/fox.strokes"),
        ];
        for (text, expected) in cases {
            let message = problem(text);
            assert!(message.starts_with("brushes/fox.strokes: "), "{message}");
            assert!(message.contains(expected), "{expected:?} not in {message:?}");
        }
        let missing = StrokeList::load(Path::new("no/such.strokes")).unwrap_err().to_string();
        assert!(missing.starts_with("no/such.strokes: "), "{missing}");
    }

    #[test]
    fn a_list_replays_to_the_same_groom_bytes() {
        let (mesh, _) = Builtin::Sphere.mesh();
        let p = |j: usize| mesh.positions[j].to_array();
        let text = format!(
            "[[stroke]]\nbrush = \"cut\"\nradius = 0.4\nfalloff = \"constant\"\nmirror = \"x\"\npoints = [{:?}, {:?}]\n\
             [[stroke]]\nbrush = \"comb\"\nradius = 0.5\nstrength = 0.7\npoints = [{:?}, {:?}, {:?}]\n\
             [[stroke]]\nbrush = \"tint\"\nradius = 0.5\ncolour = [0.9, 0.4, 0.1]\npoints = [{:?}]\n",
            p(3),
            p(40),
            p(100),
            p(101),
            p(140),
            p(200)
        );
        let list = StrokeList::from_toml_str(&text, Path::new("three.strokes")).unwrap();
        assert_eq!(list.strokes.len(), 3);
        assert_eq!(list.strokes[0].0.mirror, Some(Axis::X));
        let replay = || {
            let mut editor = GroomEditor::new(&mesh, None, Vec3::Y).unwrap();
            list.apply(&mut editor);
            assert_eq!(editor.history(), (3, 0), "one undo step per stroke");
            editor.groom().to_file_bytes(&mesh).unwrap()
        };
        let first = replay();
        assert_eq!(first, replay());
        let uniform = GroomEditor::new(&mesh, None, Vec3::Y).unwrap().groom().to_file_bytes(&mesh).unwrap();
        assert_ne!(first, uniform, "the strokes painted");
    }
}
