//! A streaming USDA writer: indentation, prims, attributes and arrays written item by item.

use std::io::{self, Write};

/// The stage's up axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpAxis {
    /// `+Y` up (glTF's and Pelt's convention).
    Y,
    /// `+Z` up (Blender's, Houdini's default is Y).
    Z,
}

impl UpAxis {
    /// The token USD writes.
    #[must_use]
    pub fn token(self) -> &'static str {
        match self {
            Self::Y => "Y",
            Self::Z => "Z",
        }
    }
}

/// A layer's metadata: what tools need to place it (`defaultPrim`, `upAxis`, `metersPerUnit`)
/// and, for an animated stage, its time range.
#[derive(Clone, Debug, PartialEq)]
pub struct StageMetadata {
    /// The prim a reference to the layer picks.
    pub default_prim: String,
    /// The up axis.
    pub up_axis: UpAxis,
    /// Metres per scene unit.
    pub meters_per_unit: f64,
    /// A line saying what wrote the layer.
    pub doc: String,
    /// First and last time code and time codes per second, for time-sampled layers.
    pub time: Option<(f64, f64, f64)>,
}

/// Writes one USDA layer to `out`, indenting prims and properties.
pub struct UsdaWriter<W: Write> {
    out: W,
    depth: usize,
}

impl<W: Write> std::fmt::Debug for UsdaWriter<W> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("UsdaWriter").field("depth", &self.depth).finish_non_exhaustive()
    }
}

impl<W: Write> UsdaWriter<W> {
    /// Starts a layer: the header and `metadata`.
    ///
    /// # Errors
    /// The writer's error.
    pub fn new(mut out: W, metadata: &StageMetadata) -> io::Result<Self> {
        writeln!(out, "#usda 1.0")?;
        writeln!(out, "(")?;
        writeln!(out, "    defaultPrim = {}", quoted(&metadata.default_prim))?;
        writeln!(out, "    doc = {}", quoted(&metadata.doc))?;
        if let Some((start, end, per_second)) = metadata.time {
            writeln!(out, "    endTimeCode = {end}")?;
            writeln!(out, "    framesPerSecond = {per_second}")?;
            writeln!(out, "    startTimeCode = {start}")?;
            writeln!(out, "    timeCodesPerSecond = {per_second}")?;
        }
        writeln!(out, "    metersPerUnit = {}", metadata.meters_per_unit)?;
        writeln!(out, "    upAxis = \"{}\"", metadata.up_axis.token())?;
        writeln!(out, ")")?;
        Ok(Self { out, depth: 0 })
    }

    fn indent(&mut self) -> io::Result<()> {
        for _ in 0..self.depth {
            self.out.write_all(b"    ")?;
        }
        Ok(())
    }

    /// Opens `def TYPE "name"` (`kind` as prim metadata when given); [`Self::end_prim`] closes it.
    ///
    /// # Errors
    /// The writer's error.
    pub fn begin_prim(&mut self, type_name: &str, name: &str, kind: Option<&str>) -> io::Result<()> {
        writeln!(self.out)?;
        self.indent()?;
        write!(self.out, "def {type_name} {}", quoted(name))?;
        if let Some(kind) = kind {
            writeln!(self.out, " (")?;
            self.depth += 1;
            self.indent()?;
            writeln!(self.out, "kind = {}", quoted(kind))?;
            self.depth -= 1;
            self.indent()?;
            write!(self.out, ")")?;
        }
        writeln!(self.out)?;
        self.indent()?;
        writeln!(self.out, "{{")?;
        self.depth += 1;
        Ok(())
    }

    /// Closes the innermost prim.
    ///
    /// # Errors
    /// The writer's error.
    pub fn end_prim(&mut self) -> io::Result<()> {
        self.depth = self.depth.saturating_sub(1);
        self.indent()?;
        writeln!(self.out, "}}")
    }

    /// `declaration name = value` with the value as already formatted text.
    ///
    /// # Errors
    /// The writer's error.
    pub fn attribute(&mut self, declaration: &str, name: &str, value: &str) -> io::Result<()> {
        self.indent()?;
        writeln!(self.out, "{declaration} {name} = {value}")
    }

    /// `declaration name` with `interpolation` metadata and no value (its time samples follow).
    ///
    /// # Errors
    /// The writer's error.
    pub fn declare(&mut self, declaration: &str, name: &str, interpolation: Option<&str>) -> io::Result<()> {
        self.indent()?;
        write!(self.out, "{declaration} {name}")?;
        self.close_with_interpolation(interpolation)
    }

    /// `declaration name = [items]` (each item formatted by `item`), then `interpolation`
    /// metadata when given.
    ///
    /// # Errors
    /// The writer's error.
    pub fn array<T>(
        &mut self,
        declaration: &str,
        name: &str,
        items: impl IntoIterator<Item = T>,
        interpolation: Option<&str>,
        mut item: impl FnMut(&mut W, T) -> io::Result<()>,
    ) -> io::Result<()> {
        self.indent()?;
        write!(self.out, "{declaration} {name} = ")?;
        self.array_value(items, &mut item)?;
        self.close_with_interpolation(interpolation)
    }

    fn array_value<T>(
        &mut self,
        items: impl IntoIterator<Item = T>,
        item: &mut impl FnMut(&mut W, T) -> io::Result<()>,
    ) -> io::Result<()> {
        self.out.write_all(b"[")?;
        for (k, value) in items.into_iter().enumerate() {
            if k > 0 {
                self.out.write_all(b", ")?;
            }
            item(&mut self.out, value)?;
        }
        self.out.write_all(b"]")
    }

    fn close_with_interpolation(&mut self, interpolation: Option<&str>) -> io::Result<()> {
        match interpolation {
            Some(interpolation) => {
                writeln!(self.out, " (")?;
                self.depth += 1;
                self.indent()?;
                writeln!(self.out, "interpolation = {}", quoted(interpolation))?;
                self.depth -= 1;
                self.indent()?;
                writeln!(self.out, ")")
            }
            None => writeln!(self.out),
        }
    }

    /// `declaration name.timeSamples = { time: [items], ... }`: `samples` yields each time and
    /// its items, formatted by `item`.
    ///
    /// # Errors
    /// The writer's error, or the first error `samples` yields.
    pub fn time_sampled_array<T, I: IntoIterator<Item = T>>(
        &mut self,
        declaration: &str,
        name: &str,
        samples: impl IntoIterator<Item = io::Result<(f64, I)>>,
        mut item: impl FnMut(&mut W, T) -> io::Result<()>,
    ) -> io::Result<()> {
        self.indent()?;
        writeln!(self.out, "{declaration} {name}.timeSamples = {{")?;
        self.depth += 1;
        for sample in samples {
            let (time, items) = sample?;
            self.indent()?;
            write!(self.out, "{time}: ")?;
            self.array_value(items, &mut item)?;
            writeln!(self.out, ",")?;
        }
        self.depth -= 1;
        self.indent()?;
        writeln!(self.out, "}}")
    }

    /// Flushes and hands back the output.
    ///
    /// # Errors
    /// The writer's error.
    pub fn finish(mut self) -> io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}

/// A string as a USDA string literal.
fn quoted(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2);
    out.push('"');
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// An `f32` as USDA text: the shortest decimal that reads back to the same bits (never an
/// exponent, which every USD reader takes, nor `-0`).
#[must_use]
pub fn format_f32(x: f32) -> String {
    if x == 0.0 { "0".to_owned() } else { format!("{x}") }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_layer_reads_as_written() {
        let metadata = StageMetadata {
            default_prim: "Fur".to_owned(),
            up_axis: UpAxis::Y,
            meters_per_unit: 1.0,
            doc: "a \"test\"".to_owned(),
            time: None,
        };
        let mut writer = UsdaWriter::new(Vec::new(), &metadata).unwrap();
        writer.begin_prim("Xform", "Fur", Some("component")).unwrap();
        writer.begin_prim("BasisCurves", "Strands", None).unwrap();
        writer.array("int[]", "curveVertexCounts", [2, 3], None, |w, n: i32| write!(w, "{n}")).unwrap();
        writer.end_prim().unwrap();
        writer.end_prim().unwrap();
        let text = String::from_utf8(writer.finish().unwrap()).unwrap();
        assert!(text.starts_with("#usda 1.0\n(\n    defaultPrim = \"Fur\"\n    doc = \"a \\\"test\\\"\"\n"), "{text}");
        assert!(text.contains("def Xform \"Fur\" (\n    kind = \"component\"\n)\n{\n"), "{text}");
        assert!(text.contains("        int[] curveVertexCounts = [2, 3]\n    }\n}\n"), "{text}");
        assert_eq!(format_f32(-0.0), "0");
        assert_eq!(format_f32(0.1).parse::<f32>().unwrap(), 0.1);
    }
}
