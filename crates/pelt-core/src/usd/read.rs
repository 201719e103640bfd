//! A one-pass USDA reader that keeps a layer's curves (see the module docs for the grammar).

use std::io::BufRead;
use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3};

use super::UsdError;
use super::write::UpAxis;

/// A curve set's `type`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveType {
    /// Straight segments between the points.
    Linear,
    /// Cubic segments in the curve set's [`CurveBasis`].
    Cubic,
}

/// A cubic curve set's `basis`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveBasis {
    /// Four points a segment, the last shared with the next.
    Bezier,
    /// Uniform cubic B-spline.
    Bspline,
    /// Catmull-Rom: through every point but the first and last (unless pinned).
    CatmullRom,
}

/// A curve set's `wrap`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveWrap {
    /// Open curves.
    Nonperiodic,
    /// Closed curves.
    Periodic,
    /// Open curves that start and end at their first and last points.
    Pinned,
}

/// One `BasisCurves` prim.
#[derive(Clone, Debug, PartialEq)]
pub struct Curves {
    /// The prim's path (`/Fur/Strands`).
    pub path: String,
    /// Points per curve.
    pub counts: Vec<u32>,
    /// Every curve's points in the stage's space (its prims' transforms applied), curve after
    /// curve.
    pub points: Vec<Vec3>,
    /// `type`.
    pub curve_type: CurveType,
    /// `basis`.
    pub basis: CurveBasis,
    /// `wrap`.
    pub wrap: CurveWrap,
    /// One linear RGB colour per curve from `primvars:displayColor` (a constant colour repeated,
    /// a per-vertex one read at each curve's first point), if it has one.
    pub colours: Option<Vec<Vec3>>,
    /// Each curve's length over its column's (`primvars:pelt:lengthFactor`, uniform), as Pelt
    /// writes it: a coat's strands end at seeded heights, and this says where.
    pub length_factors: Option<Vec<f32>>,
}

impl Curves {
    /// The points of curve `k` (needs `offsets`: each curve's first point, see [`Self::offsets`]).
    #[must_use]
    pub fn curve<'a>(&'a self, offsets: &[usize], k: usize) -> &'a [Vec3] {
        &self.points[offsets[k]..offsets[k] + self.counts[k] as usize]
    }

    /// Each curve's first point's index in [`Self::points`].
    #[must_use]
    pub fn offsets(&self) -> Vec<usize> {
        let mut at = 0;
        self.counts
            .iter()
            .map(|&n| {
                let first = at;
                at += n as usize;
                first
            })
            .collect()
    }

    /// Samples along curve `points` where this set draws it (cubic segments at `per_segment`
    /// points each, linear ones at their points).
    #[must_use]
    pub fn polyline(&self, points: &[Vec3], per_segment: usize) -> Vec<Vec3> {
        polyline(points, self.curve_type, self.basis, self.wrap, per_segment)
    }
}

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
        Parser { lexer: Lexer::new(input, file), prims: Vec::new(), raw: Vec::new(), meta: Meta::default() };
    parser.lexer.skip_line()?;
    parser.layer()?;
    parser.finish()
}

// ---------------------------------------------------------------------------------------------
// Tokens

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Punct(u8),
    Str(String),
    Num(f64),
    Ident(String),
    Path(String),
    Eof,
}

struct Lexer<R: BufRead> {
    input: R,
    file: PathBuf,
    line: usize,
    peeked: Option<Tok>,
    scratch: String,
}

impl<R: BufRead> Lexer<R> {
    fn new(input: R, file: &Path) -> Self {
        Self { input, file: file.to_path_buf(), line: 1, peeked: None, scratch: String::new() }
    }

    fn error(&self, problem: impl Into<String>) -> UsdError {
        UsdError::Syntax { file: self.file.clone(), line: self.line, problem: problem.into() }
    }

    fn byte(&mut self) -> Result<Option<u8>, UsdError> {
        match self.input.fill_buf() {
            Ok(buffer) => Ok(buffer.first().copied()),
            Err(error) => Err(UsdError::Io { file: self.file.clone(), error }),
        }
    }

    fn bump(&mut self) {
        self.input.consume(1);
    }

    fn skip_line(&mut self) -> Result<(), UsdError> {
        while let Some(b) = self.byte()? {
            self.bump();
            if b == b'\n' {
                self.line += 1;
                break;
            }
        }
        Ok(())
    }

    fn peek(&mut self) -> Result<&Tok, UsdError> {
        if self.peeked.is_none() {
            let token = self.lex()?;
            self.peeked = Some(token);
        }
        Ok(self.peeked.as_ref().expect("just filled"))
    }

    fn next(&mut self) -> Result<Tok, UsdError> {
        match self.peeked.take() {
            Some(token) => Ok(token),
            None => self.lex(),
        }
    }

    fn expect(&mut self, punct: u8) -> Result<(), UsdError> {
        match self.next()? {
            Tok::Punct(p) if p == punct => Ok(()),
            other => Err(self.error(format!("expected `{}`, found {}", punct as char, describe(&other)))),
        }
    }

    /// Consumes `punct` if it comes next.
    fn eat(&mut self, punct: u8) -> Result<bool, UsdError> {
        if *self.peek()? == Tok::Punct(punct) {
            self.peeked = None;
            return Ok(true);
        }
        Ok(false)
    }

    fn lex(&mut self) -> Result<Tok, UsdError> {
        loop {
            let Some(b) = self.byte()? else { return Ok(Tok::Eof) };
            match b {
                b'\n' => {
                    self.line += 1;
                    self.bump();
                }
                b' ' | b'\t' | b'\r' => self.bump(),
                b'#' => self.skip_line()?,
                b'"' | b'\'' => return self.string(b),
                b'<' => return self.delimited(b'>').map(Tok::Path),
                b'@' => return self.asset(),
                b'0'..=b'9' | b'-' | b'+' | b'.' => return self.number(),
                b'(' | b')' | b'[' | b']' | b'{' | b'}' | b'=' | b',' | b':' | b';' | b'&' => {
                    self.bump();
                    return Ok(Tok::Punct(b));
                }
                b if b.is_ascii_alphabetic() || b == b'_' || b == b'!' => {
                    let word = self.word()?;
                    return Ok(match word.as_str() {
                        "inf" => Tok::Num(f64::INFINITY),
                        "nan" => Tok::Num(f64::NAN),
                        _ => Tok::Ident(word),
                    });
                }
                other => return Err(self.error(format!("unexpected character {:?}", other as char))),
            }
        }
    }

    fn word(&mut self) -> Result<String, UsdError> {
        let mut word = String::new();
        while let Some(b) = self.byte()? {
            if b.is_ascii_alphanumeric() || matches!(b, b'_' | b':' | b'.' | b'!') {
                word.push(b as char);
                self.bump();
            } else {
                break;
            }
        }
        Ok(word)
    }

    fn number(&mut self) -> Result<Tok, UsdError> {
        self.scratch.clear();
        while let Some(b) = self.byte()? {
            if b.is_ascii_digit() || matches!(b, b'-' | b'+' | b'.' | b'e' | b'E') {
                self.scratch.push(b as char);
                self.bump();
            } else {
                break;
            }
        }
        // `-inf`
        if (self.scratch == "-" || self.scratch == "+") && self.byte()?.is_some_and(|b| b.is_ascii_alphabetic()) {
            let sign = if self.scratch == "-" { -1.0 } else { 1.0 };
            return match self.word()?.as_str() {
                "inf" => Ok(Tok::Num(sign * f64::INFINITY)),
                "nan" => Ok(Tok::Num(f64::NAN)),
                other => Err(self.error(format!("{}{other} is not a number", self.scratch))),
            };
        }
        let text = std::mem::take(&mut self.scratch);
        let value = text.parse::<f64>().map_err(|_| self.error(format!("{text:?} is not a number")));
        self.scratch = text;
        value.map(Tok::Num)
    }

    fn string(&mut self, quote: u8) -> Result<Tok, UsdError> {
        self.bump();
        // A triple quote opens a string that may span lines.
        let mut triple = false;
        if self.byte()? == Some(quote) {
            self.bump();
            if self.byte()? == Some(quote) {
                self.bump();
                triple = true;
            } else {
                return Ok(Tok::Str(String::new()));
            }
        }
        let mut bytes = Vec::new();
        let mut run = 0;
        loop {
            let Some(b) = self.byte()? else { return Err(self.error("the file ends inside a string")) };
            self.bump();
            match b {
                b'\\' => {
                    let Some(escaped) = self.byte()? else { return Err(self.error("the file ends inside a string")) };
                    self.bump();
                    bytes.push(match escaped {
                        b'n' => b'\n',
                        b't' => b'\t',
                        other => other,
                    });
                    run = 0;
                    continue;
                }
                b'\n' if !triple => return Err(self.error("a line ends inside a string")),
                b'\n' => self.line += 1,
                _ => {}
            }
            if b == quote {
                run += 1;
                if !triple || run == 3 {
                    if triple {
                        bytes.truncate(bytes.len() - 2);
                    }
                    break;
                }
            } else {
                run = 0;
            }
            bytes.push(b);
        }
        Ok(Tok::Str(String::from_utf8_lossy(&bytes).into_owned()))
    }

    fn delimited(&mut self, close: u8) -> Result<String, UsdError> {
        self.bump();
        let mut bytes = Vec::new();
        loop {
            match self.byte()? {
                None | Some(b'\n') => return Err(self.error(format!("expected `{}`", close as char))),
                Some(b) if b == close => {
                    self.bump();
                    return Ok(String::from_utf8_lossy(&bytes).into_owned());
                }
                Some(b) => {
                    bytes.push(b);
                    self.bump();
                }
            }
        }
    }

    fn asset(&mut self) -> Result<Tok, UsdError> {
        // `@path@`, or `@@@path@@@` for paths holding `@`.
        self.bump();
        if self.byte()? == Some(b'@') {
            self.bump();
            self.bump();
            let mut bytes = Vec::new();
            let mut run = 0;
            loop {
                let Some(b) = self.byte()? else { return Err(self.error("the file ends inside an asset path")) };
                self.bump();
                bytes.push(b);
                run = if b == b'@' { run + 1 } else { 0 };
                if run == 3 {
                    bytes.truncate(bytes.len() - 3);
                    return Ok(Tok::Str(String::from_utf8_lossy(&bytes).into_owned()));
                }
            }
        }
        let mut bytes = Vec::new();
        loop {
            match self.byte()? {
                None | Some(b'\n') => return Err(self.error("expected `@` closing an asset path")),
                Some(b'@') => {
                    self.bump();
                    return Ok(Tok::Str(String::from_utf8_lossy(&bytes).into_owned()));
                }
                Some(b) => {
                    bytes.push(b);
                    self.bump();
                }
            }
        }
    }
}

fn describe(token: &Tok) -> String {
    match token {
        Tok::Punct(p) => format!("`{}`", *p as char),
        Tok::Str(s) => format!("the string {s:?}"),
        Tok::Num(x) => format!("the number {x}"),
        Tok::Ident(word) => format!("`{word}`"),
        Tok::Path(path) => format!("the path <{path}>"),
        Tok::Eof => "the end of the file".to_owned(),
    }
}

// ---------------------------------------------------------------------------------------------
// Values

#[derive(Clone, Debug, PartialEq)]
enum Value {
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
    fn numbers(&self) -> Option<Vec<f64>> {
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

// ---------------------------------------------------------------------------------------------
// The parser

#[derive(Default)]
struct Meta {
    up_axis: Option<String>,
    meters_per_unit: Option<f64>,
    default_prim: Option<String>,
    meshes: usize,
    references: usize,
    variant_sets: usize,
}

struct PrimInfo {
    parent: Option<usize>,
    /// `xformOp:*` values by name.
    ops: Vec<(String, Value)>,
    order: Vec<String>,
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
}

struct Parser<R: BufRead> {
    lexer: Lexer<R>,
    prims: Vec<PrimInfo>,
    raw: Vec<RawCurves>,
    meta: Meta,
}

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
            curves.push(Curves {
                path,
                counts: integer_counts,
                points,
                curve_type,
                basis,
                wrap,
                colours,
                length_factors,
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

/// One colour per curve from `primvars:displayColor`'s values and interpolation.
fn curve_colours(colours: &[Vec3], interpolation: &str, counts: &[u32]) -> Result<Vec<Vec3>, String> {
    if colours.iter().any(|c| !c.is_finite()) {
        return Err("primvars:displayColor must be finite (r, g, b) triples".to_owned());
    }
    let wrong = |expected: usize| {
        format!(
            "primvars:displayColor has {} colours, but {interpolation} interpolation needs {expected}",
            colours.len()
        )
    };
    match interpolation {
        "constant" => colours.first().map(|c| vec![*c; counts.len()]).ok_or_else(|| wrong(1)),
        "uniform" if colours.len() == counts.len() => Ok(colours.to_vec()),
        "uniform" => Err(wrong(counts.len())),
        "vertex" | "varying" => {
            let total: usize = counts.iter().map(|&n| n as usize).sum();
            if colours.len() != total {
                // Varying counts segment ends; take each curve's first colour either way.
                if interpolation == "vertex" {
                    return Err(wrong(total));
                }
            }
            let mut at = 0usize;
            let mut out = Vec::with_capacity(counts.len());
            for &n in counts {
                out.push(*colours.get(at).ok_or_else(|| wrong(total))?);
                at += if colours.len() == total { n as usize } else { (colours.len() / counts.len()).max(1) };
            }
            Ok(out)
        }
        other => Err(format!("primvars:displayColor: unknown interpolation {other:?}")),
    }
}

/// A prim's own transform from its `xformOpOrder`, and whether it resets its parents'.
fn local_transform(info: &PrimInfo) -> Result<(Mat4, bool), String> {
    let mut matrix = Mat4::IDENTITY;
    let mut reset = false;
    for entry in &info.order {
        if entry == "!resetXformStack!" {
            reset = true;
            matrix = Mat4::IDENTITY;
            continue;
        }
        let (invert, name) = match entry.strip_prefix("!invert!") {
            Some(name) => (true, name),
            None => (false, entry.as_str()),
        };
        let Some((_, value)) = info.ops.iter().find(|(n, _)| n == name) else {
            return Err(format!("xformOpOrder names {name}, which the prim does not have"));
        };
        let numbers = value.numbers().ok_or_else(|| format!("{name} is not a number or tuple"))?;
        let op = name.trim_start_matches("xformOp:");
        let kind = op.split(':').next().unwrap_or(op);
        let v = |k: usize| numbers.get(k).copied().unwrap_or(0.0) as f32;
        let vec3 = || Vec3::new(v(0), v(1), v(2));
        let wanted = |n: usize| {
            if numbers.len() == n { Ok(()) } else { Err(format!("{name} has {} numbers, expected {n}", numbers.len())) }
        };
        let op_matrix = match kind {
            "translate" => {
                wanted(3)?;
                Mat4::from_translation(vec3())
            }
            "scale" => {
                wanted(3)?;
                Mat4::from_scale(vec3())
            }
            "rotateX" | "rotateY" | "rotateZ" => {
                wanted(1)?;
                let angle = v(0).to_radians();
                match kind {
                    "rotateX" => Mat4::from_rotation_x(angle),
                    "rotateY" => Mat4::from_rotation_y(angle),
                    _ => Mat4::from_rotation_z(angle),
                }
            }
            "orient" => {
                wanted(4)?;
                // USDA writes the real part first.
                Mat4::from_quat(Quat::from_xyzw(v(1), v(2), v(3), v(0)).normalize())
            }
            "transform" => {
                wanted(16)?;
                // USD's rows (row vectors, translation last) are glam's columns.
                let flat: Vec<f32> = numbers.iter().map(|&x| x as f32).collect();
                Mat4::from_cols_slice(&flat)
            }
            rotate if rotate.len() == 9 && rotate.starts_with("rotate") => {
                wanted(3)?;
                // rotateXYZ turns about X first: the matrix is Z * Y * X.
                let mut rotation = Mat4::IDENTITY;
                for axis in rotate[6..].chars() {
                    let (k, turn): (usize, fn(f32) -> Mat4) = match axis {
                        'X' => (0, Mat4::from_rotation_x),
                        'Y' => (1, Mat4::from_rotation_y),
                        'Z' => (2, Mat4::from_rotation_z),
                        _ => return Err(format!("{name}: unknown rotation order")),
                    };
                    rotation = turn(v(k).to_radians()) * rotation;
                }
                rotation
            }
            _ => return Err(format!("{name}: an xformOp Pelt does not read")),
        };
        let op_matrix = if invert { op_matrix.inverse() } else { op_matrix };
        matrix *= op_matrix;
    }
    if !matrix.is_finite() {
        return Err("the prim's transform is not finite".to_owned());
    }
    Ok((matrix, reset))
}

/// The drawn curve through `points` as a polyline.
fn polyline(
    points: &[Vec3],
    curve_type: CurveType,
    basis: CurveBasis,
    wrap: CurveWrap,
    per_segment: usize,
) -> Vec<Vec3> {
    let n = points.len();
    if curve_type == CurveType::Linear || n < 2 {
        let mut out = points.to_vec();
        if wrap == CurveWrap::Periodic && n > 2 {
            out.push(points[0]);
        }
        return out;
    }
    let per_segment = per_segment.max(1);
    let at = |k: isize| -> Vec3 {
        match wrap {
            CurveWrap::Periodic => points[k.rem_euclid(n as isize) as usize],
            // Pinned curves extend past their ends by reflection, so they start and end there.
            _ if k < 0 => points[0] * 2.0 - points[1],
            _ if k >= n as isize => points[n - 1] * 2.0 - points[n - 2],
            _ => points[k as usize],
        }
    };
    let mut out = Vec::new();
    match basis {
        CurveBasis::Bezier => {
            let segments = if wrap == CurveWrap::Periodic { n / 3 } else { (n - 1) / 3 };
            for s in 0..segments {
                let [p0, p1, p2, p3] = [0, 1, 2, 3].map(|k| at((3 * s + k) as isize));
                for k in usize::from(s > 0)..=per_segment {
                    let t = k as f32 / per_segment as f32;
                    let u = 1.0 - t;
                    out.push(p0 * (u * u * u) + p1 * (3.0 * u * u * t) + p2 * (3.0 * u * t * t) + p3 * (t * t * t));
                }
            }
        }
        CurveBasis::Bspline | CurveBasis::CatmullRom => {
            let (first, segments): (isize, isize) = match wrap {
                CurveWrap::Periodic => (0, n as isize),
                CurveWrap::Pinned => (-1, n as isize - 1),
                CurveWrap::Nonperiodic => (0, n as isize - 3),
            };
            for s in 0..segments {
                let [p0, p1, p2, p3] = [0, 1, 2, 3].map(|k| at(first + s + k));
                for k in usize::from(s > 0)..=per_segment {
                    let t = k as f32 / per_segment as f32;
                    let (t2, t3) = (t * t, t * t * t);
                    out.push(if basis == CurveBasis::Bspline {
                        (p0 * (1.0 - t).powi(3)
                            + p1 * (3.0 * t3 - 6.0 * t2 + 4.0)
                            + p2 * (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0)
                            + p3 * t3)
                            / 6.0
                    } else {
                        (p1 * 2.0
                            + (p2 - p0) * t
                            + (p0 * 2.0 - p1 * 5.0 + p2 * 4.0 - p3) * t2
                            + (p1 * 3.0 - p0 - p2 * 3.0 + p3) * t3)
                            * 0.5
                    });
                }
            }
        }
    }
    out
}
