//! A one-pass USDA reader that keeps a layer's curves (see the module docs for the grammar).

use std::io::BufRead;
use std::path::Path;

use glam::{Mat4, Vec3};

use super::UsdError;
use super::curves::{CurveBasis, CurveType, CurveWrap, Curves, curve_colours};
use super::lex::{Lexer, Tok, describe};
use super::write::UpAxis;
use super::xform::local_transform;

/// What [`read_curves`] keeps of a layer.
#[derive(Clone, Debug, PartialEq)]
pub struct UsdCurves {
    /// `upAxis` (USD's fallback, Y, when unset).
    pub up_axis: UpAxis,
    /// `metersPerUnit` (USD's fallback, 0.01, when unset).
    pub meters_per_unit: f64,
    /// `defaultPrim`.
    pub default_prim: Option<String>,
    /// Every `BasisCurves` prim, in file order.
    pub curves: Vec<Curves>,
    /// `Mesh` prims seen (read past: the groom lands on the preset's mesh).
    pub meshes: usize,
    /// What was read past that a reader might expect to count (references, variant sets).
    pub notes: Vec<String>,
}

/// Reads the curves of the USDA file `file`.
///
/// # Errors
/// [`UsdError::Io`] when it cannot be read, [`UsdError::Content`] for an empty file, a binary
/// crate file, a `.usdz` archive or curves that do not add up, [`UsdError::Syntax`] (with the
/// line) for text that is not USDA.
pub fn read_curves(file: &Path) -> Result<UsdCurves, UsdError> {
    let opened = std::fs::File::open(file).map_err(|error| UsdError::Io { file: file.to_path_buf(), error })?;
    read_curves_from(std::io::BufReader::with_capacity(1 << 16, opened), file)
}

/// Reads the curves of a USDA layer from `input`; `file` names it in messages.
///
/// # Errors
/// As [`read_curves`].
pub fn read_curves_from(mut input: impl BufRead, file: &Path) -> Result<UsdCurves, UsdError> {
    let content = |problem: &str| UsdError::Content { file: file.to_path_buf(), problem: problem.to_owned() };
    let io = |error| UsdError::Io { file: file.to_path_buf(), error };
    let head = input.fill_buf().map_err(io)?.to_vec();
    if head.is_empty() {
        return Err(content("the file is empty"));
    }
    if head.starts_with(b"PXR-USDC") {
        return Err(content(
            "a binary USD crate file; Pelt reads USD's text format (.usda): convert it with \
             `usdcat FILE -o FILE.usda`, or export it from Blender as .usda",
        ));
    }
    if head.starts_with(b"PK\x03\x04") {
        return Err(content("a .usdz archive; Pelt reads USD's text format (.usda): unzip it or export .usda"));
    }
    if !head.starts_with(b"#usda") {
        return Err(content("not a USD text file: it does not start with `#usda 1.0`"));
    }
    let mut parser =
        Parser { lexer: Lexer::new(input, file), prims: Vec::new(), raw: Vec::new(), meta: Meta::default(), depth: 0 };
    parser.lexer.skip_line()?;
    parser.layer()?;
    parser.finish()
}

/// A value as read: what the reader keeps of it.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Value {
    Num(f64),
    Text(String),
    Path,
    Tuple(Vec<Value>),
    List(Vec<Value>),
    /// An array of numbers or of tuples of `arity` numbers (not 3), flattened.
    Floats {
        flat: Vec<f32>,
        arity: usize,
    },
    /// An array of triples (points, normals, colours), read straight into vectors so a curve
    /// set's points are held once.
    Triples(Vec<Vec3>),
    Other,
}

impl Value {
    /// A number or a (nested) tuple of numbers, flattened.
    pub(super) fn numbers(&self) -> Option<Vec<f64>> {
        match self {
            Value::Num(x) => Some(vec![*x]),
            Value::Tuple(items) => {
                let mut out = Vec::new();
                for item in items {
                    out.extend(item.numbers()?);
                }
                Some(out)
            }
            _ => None,
        }
    }
}

#[derive(Default)]
struct Meta {
    up_axis: Option<String>,
    meters_per_unit: Option<f64>,
    default_prim: Option<String>,
    meshes: usize,
    references: usize,
    variant_sets: usize,
}

/// A prim's place in the hierarchy and its transform's ops.
pub(super) struct PrimInfo {
    pub(super) parent: Option<usize>,
    /// `xformOp:*` values by name.
    pub(super) ops: Vec<(String, Value)>,
    pub(super) order: Vec<String>,
}

struct RawCurves {
    prim: usize,
    path: String,
    counts: Option<Vec<f32>>,
    points: Option<Vec<Vec3>>,
    curve_type: Option<String>,
    basis: Option<String>,
    wrap: Option<String>,
    colour: Option<(Vec<Vec3>, String)>,
    length_factors: Option<Vec<f32>>,
    texture_offsets: Option<Vec<Vec3>>,
}

struct Parser<R: BufRead> {
    lexer: Lexer<R>,
    prims: Vec<PrimInfo>,
    raw: Vec<RawCurves>,
    meta: Meta,
    /// Values and prims being read inside one another (bounded, so a crafted file cannot
    /// exhaust the stack).
    depth: usize,
}

/// The deepest nesting of prims and values read.
const MAX_DEPTH: usize = 128;

impl<R: BufRead> Parser<R> {
    fn layer(&mut self) -> Result<(), UsdError> {
        if *self.lexer.peek()? == Tok::Punct(b'(') {
            for (key, value) in self.metadata()? {
                match (key.as_str(), value) {
                    ("upAxis", Value::Text(axis)) => self.meta.up_axis = Some(axis),
                    ("metersPerUnit", Value::Num(m)) => self.meta.meters_per_unit = Some(m),
                    ("defaultPrim", Value::Text(name)) => self.meta.default_prim = Some(name),
                    _ => {}
                }
            }
        }
        loop {
            match self.lexer.next()? {
                Tok::Eof => return Ok(()),
                Tok::Ident(word) if matches!(word.as_str(), "def" | "over" | "class") => self.prim(None, "")?,
                other => {
                    return Err(self
                        .lexer
                        .error(format!("expected a prim (`def`, `over`, `class`), found {}", describe(&other))));
                }
            }
        }
    }

    /// `( key = value ... )`: returns the entries (list ops and doc strings read past).
    fn metadata(&mut self) -> Result<Vec<(String, Value)>, UsdError> {
        self.lexer.expect(b'(')?;
        let mut entries = Vec::new();
        loop {
            match self.lexer.next()? {
                Tok::Punct(b')') => return Ok(entries),
                Tok::Punct(b';') | Tok::Str(_) => {}
                Tok::Ident(word) => {
                    let key = if matches!(word.as_str(), "prepend" | "append" | "add" | "delete" | "reorder") {
                        match self.lexer.next()? {
                            Tok::Ident(key) => key,
                            other => {
                                return Err(self
                                    .lexer
                                    .error(format!("expected a key after `{word}`, found {}", describe(&other))));
                            }
                        }
                    } else {
                        word
                    };
                    if !self.lexer.eat(b'=')? {
                        continue;
                    }
                    let value = self.value()?;
                    if matches!(key.as_str(), "references" | "payload") {
                        self.meta.references += 1;
                    }
                    entries.push((key, value));
                }
                other => return Err(self.lexer.error(format!("expected metadata or `)`, found {}", describe(&other)))),
            }
        }
    }

    fn value(&mut self) -> Result<Value, UsdError> {
        self.enter()?;
        let value = self.value_inside();
        self.depth -= 1;
        value
    }

    /// One level deeper, or an error past [`MAX_DEPTH`].
    fn enter(&mut self) -> Result<(), UsdError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            self.depth -= 1;
            return Err(self.lexer.error(format!("prims or values nested more than {MAX_DEPTH} deep")));
        }
        Ok(())
    }

    fn value_inside(&mut self) -> Result<Value, UsdError> {
        match self.lexer.next()? {
            Tok::Num(x) => Ok(Value::Num(x)),
            Tok::Str(s) => Ok(Value::Text(s)),
            Tok::Ident(word) => Ok(if word == "None" { Value::Other } else { Value::Text(word) }),
            Tok::Path(_) => Ok(Value::Path),
            Tok::Punct(b'(') => {
                let mut items = Vec::new();
                loop {
                    if self.lexer.eat(b')')? {
                        return Ok(Value::Tuple(items));
                    }
                    items.push(self.value()?);
                    if !self.lexer.eat(b',')? {
                        self.lexer.expect(b')')?;
                        return Ok(Value::Tuple(items));
                    }
                }
            }
            Tok::Punct(b'[') => self.array(),
            Tok::Punct(b'{') => {
                self.skip_braces()?;
                Ok(Value::Other)
            }
            other => Err(self.lexer.error(format!("expected a value, found {}", describe(&other)))),
        }
    }

    /// An array after its `[`: numbers and tuples of numbers flattened as they are read.
    fn array(&mut self) -> Result<Value, UsdError> {
        if self.lexer.eat(b']')? {
            return Ok(Value::List(Vec::new()));
        }
        let first = self.value()?;
        let Some(numbers) = first.numbers() else {
            let mut items = vec![first];
            while self.lexer.eat(b',')? {
                if *self.lexer.peek()? == Tok::Punct(b']') {
                    break;
                }
                items.push(self.value()?);
            }
            self.lexer.expect(b']')?;
            return Ok(Value::List(items));
        };
        let tuple = matches!(first, Value::Tuple(_));
        let arity = numbers.len();
        if tuple && arity == 3 {
            let mut triples = vec![Vec3::new(numbers[0] as f32, numbers[1] as f32, numbers[2] as f32)];
            while self.lexer.eat(b',')? {
                if *self.lexer.peek()? == Tok::Punct(b']') {
                    break;
                }
                self.lexer.expect(b'(')?;
                let x = self.number()?;
                self.lexer.expect(b',')?;
                let y = self.number()?;
                self.lexer.expect(b',')?;
                let z = self.number()?;
                self.lexer.expect(b')')?;
                triples.push(Vec3::new(x as f32, y as f32, z as f32));
            }
            self.lexer.expect(b']')?;
            return Ok(Value::Triples(triples));
        }
        let mut flat: Vec<f32> = numbers.iter().map(|&x| x as f32).collect();
        while self.lexer.eat(b',')? {
            if *self.lexer.peek()? == Tok::Punct(b']') {
                break;
            }
            if tuple {
                self.lexer.expect(b'(')?;
                for k in 0..arity {
                    if k > 0 {
                        self.lexer.expect(b',')?;
                    }
                    flat.push(self.number()? as f32);
                }
                self.lexer.expect(b')')?;
            } else {
                flat.push(self.number()? as f32);
            }
        }
        self.lexer.expect(b']')?;
        Ok(Value::Floats { flat, arity })
    }

    fn number(&mut self) -> Result<f64, UsdError> {
        match self.lexer.next()? {
            Tok::Num(x) => Ok(x),
            other => Err(self.lexer.error(format!("expected a number, found {}", describe(&other)))),
        }
    }

    /// Reads past a `{ ... }` block after its `{`.
    fn skip_braces(&mut self) -> Result<(), UsdError> {
        let mut depth = 1;
        while depth > 0 {
            match self.lexer.next()? {
                Tok::Punct(b'{') => depth += 1,
                Tok::Punct(b'}') => depth -= 1,
                Tok::Eof => return Err(self.lexer.error("the file ends inside `{ ... }`")),
                _ => {}
            }
        }
        Ok(())
    }

    /// `{ time: value, ... }` after its `{`: the sample at the earliest time.
    fn earliest_sample(&mut self) -> Result<Option<Value>, UsdError> {
        let mut best: Option<(f64, Value)> = None;
        loop {
            if self.lexer.eat(b'}')? {
                return Ok(best.map(|(_, v)| v));
            }
            let time = self.number()?;
            self.lexer.expect(b':')?;
            let value = self.value()?;
            if best.as_ref().is_none_or(|(t, _)| time < *t) {
                best = Some((time, value));
            }
            if !self.lexer.eat(b',')? {
                self.lexer.expect(b'}')?;
                return Ok(best.map(|(_, v)| v));
            }
        }
    }

    /// A prim after its specifier.
    fn prim(&mut self, parent: Option<usize>, parent_path: &str) -> Result<(), UsdError> {
        self.enter()?;
        let prim = self.prim_inside(parent, parent_path);
        self.depth -= 1;
        prim
    }

    fn prim_inside(&mut self, parent: Option<usize>, parent_path: &str) -> Result<(), UsdError> {
        let (type_name, name) = match self.lexer.next()? {
            Tok::Str(name) => (String::new(), name),
            Tok::Ident(type_name) => match self.lexer.next()? {
                Tok::Str(name) => (type_name, name),
                other => return Err(self.lexer.error(format!("expected the prim's name, found {}", describe(&other)))),
            },
            other => return Err(self.lexer.error(format!("expected a prim type or name, found {}", describe(&other)))),
        };
        let path = format!("{parent_path}/{name}");
        if *self.lexer.peek()? == Tok::Punct(b'(') {
            self.metadata()?;
        }
        self.lexer.expect(b'{')?;
        let index = self.prims.len();
        self.prims.push(PrimInfo { parent, ops: Vec::new(), order: Vec::new() });
        let curves = match type_name.as_str() {
            "BasisCurves" => {
                self.raw.push(RawCurves {
                    prim: index,
                    path: path.clone(),
                    counts: None,
                    points: None,
                    curve_type: None,
                    basis: None,
                    wrap: None,
                    colour: None,
                    length_factors: None,
                    texture_offsets: None,
                });
                Some(self.raw.len() - 1)
            }
            "Mesh" => {
                self.meta.meshes += 1;
                None
            }
            _ => None,
        };
        loop {
            let word = match self.lexer.next()? {
                Tok::Punct(b'}') => return Ok(()),
                Tok::Punct(b';') => continue,
                Tok::Ident(word) => word,
                other => {
                    return Err(self
                        .lexer
                        .error(format!("expected a property, a prim or `}}` in {path}, found {}", describe(&other))));
                }
            };
            match word.as_str() {
                "def" | "over" | "class" => self.prim(Some(index), &path)?,
                "variantSet" => {
                    self.meta.variant_sets += 1;
                    self.lexer.next()?;
                    self.lexer.expect(b'=')?;
                    self.lexer.expect(b'{')?;
                    self.skip_braces()?;
                }
                "reorder" => {
                    self.lexer.next()?;
                    self.lexer.expect(b'=')?;
                    self.value()?;
                }
                _ => self.property(word, index, curves)?,
            }
        }
    }

    /// A property from its first word.
    fn property(&mut self, first: String, prim: usize, curves: Option<usize>) -> Result<(), UsdError> {
        let mut word = first;
        while matches!(
            word.as_str(),
            "custom" | "uniform" | "varying" | "config" | "prepend" | "append" | "add" | "delete"
        ) {
            word = match self.lexer.next()? {
                Tok::Ident(next) => next,
                other => {
                    return Err(self
                        .lexer
                        .error(format!("expected a property after `{word}`, found {}", describe(&other))));
                }
            };
        }
        let relationship = word == "rel";
        if !relationship && self.lexer.eat(b'[')? {
            self.lexer.expect(b']')?;
        }
        let name = match self.lexer.next()? {
            Tok::Ident(name) => name,
            other => {
                return Err(self
                    .lexer
                    .error(format!("expected the property's name after `{word}`, found {}", describe(&other))));
            }
        };
        let mut value = None;
        if self.lexer.eat(b'=')? {
            value = if let Some(base) = name.strip_suffix(".timeSamples") {
                self.lexer.expect(b'{')?;
                let earliest = self.earliest_sample()?;
                earliest.map(|v| (base.to_owned(), v))
            } else {
                Some((name.clone(), self.value()?))
            };
        }
        let mut interpolation = None;
        if *self.lexer.peek()? == Tok::Punct(b'(') {
            for (key, value) in self.metadata()? {
                if let ("interpolation", Value::Text(text)) = (key.as_str(), value) {
                    interpolation = Some(text);
                }
            }
        }
        let Some((name, value)) = value else { return Ok(()) };
        if name.starts_with("xformOp:") {
            self.prims[prim].ops.push((name, value));
        } else if name == "xformOpOrder" {
            if let Value::List(items) = value {
                self.prims[prim].order =
                    items.into_iter().filter_map(|v| if let Value::Text(t) = v { Some(t) } else { None }).collect();
            }
        } else if let Some(k) = curves {
            let raw = &mut self.raw[k];
            let floats = |value: Value| match value {
                Value::Floats { flat, .. } => Some(flat),
                Value::List(items) if items.is_empty() => Some(Vec::new()),
                _ => None,
            };
            let text = |value: Value| if let Value::Text(t) = value { Some(t) } else { None };
            let triples = |value: Value| match value {
                Value::Triples(triples) => Some(triples),
                Value::List(items) if items.is_empty() => Some(Vec::new()),
                _ => None,
            };
            match name.as_str() {
                "points" => raw.points = triples(value),
                "curveVertexCounts" => raw.counts = floats(value),
                "type" => raw.curve_type = text(value),
                "basis" => raw.basis = text(value),
                "wrap" => raw.wrap = text(value),
                "primvars:pelt:lengthFactor" => raw.length_factors = floats(value),
                "primvars:pelt:textureOffset" => raw.texture_offsets = triples(value),
                "primvars:displayColor" => {
                    raw.colour = triples(value).map(|c| (c, interpolation.unwrap_or_else(|| "constant".to_owned())));
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn finish(self) -> Result<UsdCurves, UsdError> {
        let file = self.lexer.file.clone();
        let content = |problem: String| UsdError::Content { file: file.clone(), problem };
        let up_axis = match self.meta.up_axis.as_deref() {
            None | Some("Y") => UpAxis::Y,
            Some("Z") => UpAxis::Z,
            Some(other) => return Err(content(format!("upAxis {other:?}: USD's up axis is \"Y\" or \"Z\""))),
        };
        let meters_per_unit = self.meta.meters_per_unit.unwrap_or(0.01);
        if !(meters_per_unit.is_finite() && meters_per_unit > 0.0) {
            return Err(content(format!("metersPerUnit {meters_per_unit}: must be a positive number")));
        }
        let mut locals = Vec::with_capacity(self.prims.len());
        for info in &self.prims {
            locals.push(local_transform(info).map_err(&content)?);
        }
        let world = |mut prim: usize| {
            let mut matrix = Mat4::IDENTITY;
            loop {
                let (local, reset) = locals[prim];
                matrix = local * matrix;
                match self.prims[prim].parent {
                    Some(parent) if !reset => prim = parent,
                    _ => return matrix,
                }
            }
        };
        let mut curves = Vec::with_capacity(self.raw.len());
        for raw in self.raw {
            let path = raw.path;
            let problem = |text: String| content(format!("{path}: {text}"));
            let counts = raw.counts.ok_or_else(|| problem("the BasisCurves has no curveVertexCounts".to_owned()))?;
            let mut points =
                raw.points.ok_or_else(|| problem("the BasisCurves has no points as (x, y, z) triples".to_owned()))?;
            let curve_type = match raw.curve_type.as_deref() {
                None | Some("cubic") => CurveType::Cubic,
                Some("linear") => CurveType::Linear,
                Some(other) => return Err(problem(format!("type {other:?} is not \"linear\" or \"cubic\""))),
            };
            let basis = match raw.basis.as_deref() {
                None | Some("bezier") => CurveBasis::Bezier,
                Some("bspline") => CurveBasis::Bspline,
                Some("catmullRom") => CurveBasis::CatmullRom,
                Some(other) => return Err(problem(format!("basis {other:?} is not bezier, bspline or catmullRom"))),
            };
            let wrap = match raw.wrap.as_deref() {
                None | Some("nonperiodic") => CurveWrap::Nonperiodic,
                Some("periodic") => CurveWrap::Periodic,
                Some("pinned") => CurveWrap::Pinned,
                Some(other) => return Err(problem(format!("wrap {other:?} is not nonperiodic, periodic or pinned"))),
            };
            let least = match (curve_type, wrap) {
                (CurveType::Linear, _) | (_, CurveWrap::Pinned) => 2,
                (CurveType::Cubic, _) => 4,
            };
            let mut total = 0usize;
            let mut integer_counts = Vec::with_capacity(counts.len());
            for (k, &n) in counts.iter().enumerate() {
                if !(n.is_finite() && n.fract() == 0.0 && n >= least as f32) {
                    return Err(problem(format!(
                        "curve {k} has {n} points; a {curve_type:?} {wrap:?} curve needs {least} or more"
                    )));
                }
                integer_counts.push(n as u32);
                total += n as usize;
            }
            if total != points.len() {
                return Err(problem(format!(
                    "curveVertexCounts add up to {total} points, but there are {}",
                    points.len()
                )));
            }
            if let Some(at) = points.iter().position(|p| !p.is_finite()) {
                return Err(problem(format!("point {at} is not finite")));
            }
            let matrix = world(raw.prim);
            for point in &mut points {
                *point = matrix.transform_point3(*point);
            }
            let colours = match raw.colour {
                None => None,
                Some((flat, interpolation)) => {
                    Some(curve_colours(&flat, &interpolation, &integer_counts).map_err(problem)?)
                }
            };
            let length_factors = match raw.length_factors {
                Some(factors) if factors.len() != integer_counts.len() => {
                    return Err(problem(format!(
                        "primvars:pelt:lengthFactor has {} values for {} curves",
                        factors.len(),
                        integer_counts.len()
                    )));
                }
                Some(factors) if factors.iter().any(|f| !(f.is_finite() && *f > 0.0)) => {
                    return Err(problem("primvars:pelt:lengthFactor must be positive numbers".to_owned()));
                }
                other => other,
            };
            let texture_offsets = match raw.texture_offsets {
                Some(offsets) if offsets.len() != points.len() => {
                    return Err(problem(format!(
                        "primvars:pelt:textureOffset has {} offsets for {} points (one per point)",
                        offsets.len(),
                        points.len()
                    )));
                }
                Some(offsets) if offsets.iter().any(|o| !o.is_finite()) => {
                    return Err(problem("primvars:pelt:textureOffset must be finite (x, y, z) triples".to_owned()));
                }
                // Offsets are vectors: the prims' transforms turn and scale them, never move them.
                Some(offsets) => Some(offsets.into_iter().map(|o| matrix.transform_vector3(o)).collect()),
                None => None,
            };
            curves.push(Curves {
                path,
                counts: integer_counts,
                points,
                curve_type,
                basis,
                wrap,
                colours,
                length_factors,
                texture_offsets,
            });
        }
        let mut notes = Vec::new();
        if self.meta.references > 0 {
            notes.push(format!("{} references or payloads were not followed", self.meta.references));
        }
        if self.meta.variant_sets > 0 {
            notes.push(format!("{} variant sets were read past", self.meta.variant_sets));
        }
        Ok(UsdCurves {
            up_axis,
            meters_per_unit,
            default_prim: self.meta.default_prim,
            curves,
            meshes: self.meta.meshes,
            notes,
        })
    }
}
