//! The top-level modules of pelt-core and pelt-render depend on each other in one direction only.
//!
//! A module is a file or folder directly under `src/` (the crate root, `lib.rs`, is not one). A
//! reference from one module's files to another module is an edge: a `crate::x` path (in a `use`
//! line or inline, `use crate::{..}` groups included), a `super::` path that climbs to the crate
//! root, or a `crate::Name` that the root re-exports from module `x`. Comments, strings and
//! `$crate` in macros are not references. A set of modules that reach each other is a cycle and
//! fails the test with the edges and one file and line for each.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Ident(String),
    /// `::`
    PathSep,
    Punct(char),
}

#[derive(Clone, Debug)]
struct Token {
    tok: Tok,
    line: usize,
}

/// Rust source as identifiers, `::` and punctuation; comments, string, char and number literals
/// and lifetimes dropped.
fn lex(text: &str) -> Vec<Token> {
    let c: Vec<char> = text.chars().collect();
    let at = |i: usize| c.get(i).copied().unwrap_or('\0');
    let (mut i, mut line, mut out) = (0, 1, Vec::new());
    // Skips a quoted literal whose opening quote is at `i`, honouring backslash escapes.
    let skip_quoted = |mut i: usize, quote: char, line: &mut usize| {
        i += 1;
        while i < c.len() && c[i] != quote {
            if c[i] == '\\' {
                i += 1;
            }
            if at(i) == '\n' {
                *line += 1;
            }
            i += 1;
        }
        i + 1
    };
    while i < c.len() {
        let ch = c[i];
        if ch == '\n' {
            line += 1;
            i += 1;
        } else if ch.is_whitespace() {
            i += 1;
        } else if ch == '/' && at(i + 1) == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if ch == '/' && at(i + 1) == '*' {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && at(i + 1) == '*' {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && at(i + 1) == '/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    line += usize::from(c[i] == '\n');
                    i += 1;
                }
            }
        } else if ch == '"' {
            i = skip_quoted(i, '"', &mut line);
        } else if ch == '\'' {
            if at(i + 1) == '\\' || at(i + 2) == '\'' {
                i = skip_quoted(i, '\'', &mut line); // a char literal
            } else {
                i += 1; // a lifetime or label: its name is lexed (and ignored) as an identifier
            }
        } else if ch.is_ascii_digit() {
            while at(i).is_alphanumeric() || at(i) == '_' {
                i += 1;
            }
        } else if ch.is_alphabetic() || ch == '_' {
            let start = i;
            while at(i).is_alphanumeric() || at(i) == '_' {
                i += 1;
            }
            let word: String = c[start..i].iter().collect();
            let raw = matches!(word.as_str(), "r" | "br" | "cr");
            if raw && (at(i) == '"' || (at(i) == '#' && matches!(at(i + 1), '"' | '#'))) {
                let mut hashes = 0;
                while at(i) == '#' {
                    hashes += 1;
                    i += 1;
                }
                i += 1; // the opening quote
                while i < c.len() && !(c[i] == '"' && (1..=hashes).all(|k| at(i + k) == '#')) {
                    line += usize::from(c[i] == '\n');
                    i += 1;
                }
                i += 1 + hashes;
            } else if matches!(word.as_str(), "b" | "c") && at(i) == '"' {
                i = skip_quoted(i, '"', &mut line);
            } else if word == "b" && at(i) == '\'' {
                i = skip_quoted(i, '\'', &mut line);
            } else if word == "r" && at(i) == '#' {
                i += 1; // a raw identifier: `r#type` is the identifier `type`
            } else {
                out.push(Token { tok: Tok::Ident(word), line });
            }
        } else if ch == ':' && at(i + 1) == ':' {
            out.push(Token { tok: Tok::PathSep, line });
            i += 2;
        } else {
            out.push(Token { tok: Tok::Punct(ch), line });
            i += 1;
        }
    }
    out
}

fn ident(tokens: &[Token], i: usize) -> Option<&str> {
    match tokens.get(i).map(|t| &t.tok) {
        Some(Tok::Ident(name)) => Some(name),
        _ => None,
    }
}

fn is(tokens: &[Token], i: usize, tok: &Tok) -> bool {
    tokens.get(i).is_some_and(|t| t.tok == *tok)
}

/// Expands the path or use tree at `pos` into full paths (each after `prefix`) with their `as`
/// names: `a::{b, c::{d as e}}` gives `a::b` and `a::c::d` (as `e`).
fn expand(tokens: &[Token], pos: &mut usize, prefix: Vec<String>, out: &mut Vec<(Vec<String>, Option<String>)>) {
    let mut path = prefix;
    loop {
        if let Some(name) = ident(tokens, *pos) {
            path.push(name.to_owned());
            *pos += 1;
            if !is(tokens, *pos, &Tok::PathSep) {
                break;
            }
            *pos += 1;
        } else if is(tokens, *pos, &Tok::Punct('{')) {
            *pos += 1;
            while *pos < tokens.len() && !is(tokens, *pos, &Tok::Punct('}')) {
                let before = *pos;
                expand(tokens, pos, path.clone(), out);
                if is(tokens, *pos, &Tok::Punct(',')) || *pos == before {
                    *pos += 1;
                }
            }
            *pos += 1;
            return;
        } else {
            *pos += usize::from(is(tokens, *pos, &Tok::Punct('*')));
            break;
        }
    }
    let alias = if ident(tokens, *pos) == Some("as") { ident(tokens, *pos + 1).map(str::to_owned) } else { None };
    *pos += if alias.is_some() { 2 } else { 0 };
    out.push((path, alias));
}

/// Every path from the crate root that the file's tokens name, with its line. `module` is the
/// file's own module path (`sim/wind.rs` is `sim::wind`); inline `mod x { .. }` blocks nest it
/// further for `super::`.
fn rooted_paths(tokens: &[Token], module: &[String]) -> Vec<(Vec<String>, usize)> {
    let (mut depth, mut inline, mut out) = (0usize, Vec::<(String, usize)>::new(), Vec::new());
    for k in 0..tokens.len() {
        match &tokens[k].tok {
            Tok::Punct('{') => {
                depth += 1;
                if k >= 2 && ident(tokens, k - 2) == Some("mod") {
                    inline.push((ident(tokens, k - 1).unwrap_or_default().to_owned(), depth));
                }
            }
            Tok::Punct('}') => {
                if inline.last().is_some_and(|(_, d)| *d == depth) {
                    inline.pop();
                }
                depth = depth.saturating_sub(1);
            }
            _ => {}
        }
        let starts_path = k == 0 || !matches!(tokens[k - 1].tok, Tok::PathSep | Tok::Punct('$'));
        if !starts_path || !is(tokens, k + 1, &Tok::PathSep) {
            continue;
        }
        let (base, mut pos) = match ident(tokens, k) {
            Some("crate") => (Vec::new(), k + 2),
            Some("super") => {
                let mut base: Vec<String> =
                    module.iter().cloned().chain(inline.iter().map(|(m, _)| m.clone())).collect();
                let mut pos = k;
                while ident(tokens, pos) == Some("super") && is(tokens, pos + 1, &Tok::PathSep) {
                    base.pop();
                    pos += 2;
                }
                (base, pos)
            }
            _ => continue,
        };
        let mut paths = Vec::new();
        expand(tokens, &mut pos, base, &mut paths);
        out.extend(paths.into_iter().map(|(path, _)| (path, tokens[k].line)));
    }
    out
}

/// One crate's top-level modules and the references between them.
struct ModuleGraph {
    src: PathBuf,
    /// Per module, the modules it references, each with one file and line where it does.
    edges: BTreeMap<String, BTreeMap<String, (PathBuf, usize)>>,
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()));
    for entry in entries {
        let path = entry.unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display())).path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

impl ModuleGraph {
    fn read(src: &Path) -> Self {
        let mut files = Vec::new();
        rust_files(src, &mut files);
        files.sort();
        let mut modules: BTreeMap<String, Vec<(PathBuf, Vec<String>)>> = BTreeMap::new();
        for file in files {
            let relative = file.strip_prefix(src).expect("listed under src").to_path_buf();
            let mut module: Vec<String> =
                relative.with_extension("").iter().map(|c| c.to_string_lossy().into_owned()).collect();
            if module.len() > 1 && module.last().is_some_and(|m| m == "mod") {
                module.pop();
            }
            if module.len() == 1 && matches!(module[0].as_str(), "lib" | "main") {
                continue;
            }
            modules.entry(module[0].clone()).or_default().push((relative, module));
        }
        // Names the crate root brings in from a module (`pub use fur::{FurParams, ..}`), which
        // the other modules may reach as `crate::FurParams`.
        let mut reexports = BTreeMap::new();
        let root = src.join("lib.rs");
        if root.exists() {
            let tokens = lex(&read(&root));
            let mut depth = 0usize;
            for k in 0..tokens.len() {
                match tokens[k].tok {
                    Tok::Punct('{') => depth += 1,
                    Tok::Punct('}') => depth = depth.saturating_sub(1),
                    _ => {}
                }
                if depth > 0 || ident(&tokens, k) != Some("use") {
                    continue;
                }
                let mut paths = Vec::new();
                expand(&tokens, &mut (k + 1), Vec::new(), &mut paths);
                for (mut path, alias) in paths {
                    if path.first().is_some_and(|s| s == "crate" || s == "self") {
                        path.remove(0);
                    }
                    let (Some(module), Some(name)) = (path.first(), alias.or_else(|| path.last().cloned())) else {
                        continue;
                    };
                    if modules.contains_key(module) && path.len() > 1 && name != "self" {
                        reexports.insert(name, module.clone());
                    }
                }
            }
        }
        let mut edges: BTreeMap<String, BTreeMap<String, (PathBuf, usize)>> = BTreeMap::new();
        for (name, files) in &modules {
            let targets = edges.entry(name.clone()).or_default();
            for (relative, module) in files {
                for (path, line) in rooted_paths(&lex(&read(&src.join(relative))), module) {
                    let Some(first) = path.first() else { continue };
                    let target = if modules.contains_key(first) { Some(first) } else { reexports.get(first) };
                    if let Some(target) = target.filter(|t| *t != name) {
                        targets.entry(target.clone()).or_insert_with(|| (relative.clone(), line));
                    }
                }
            }
        }
        Self { src: src.to_path_buf(), edges }
    }

    /// Sets of more than one module that all reach each other (Tarjan's strongly connected
    /// components), each sorted.
    fn cycles(&self) -> Vec<Vec<String>> {
        struct Walk<'a> {
            graph: &'a ModuleGraph,
            index: BTreeMap<&'a str, usize>,
            low: BTreeMap<&'a str, usize>,
            stack: Vec<&'a str>,
            on_stack: BTreeSet<&'a str>,
            out: Vec<Vec<String>>,
        }
        impl<'a> Walk<'a> {
            fn visit(&mut self, v: &'a str) {
                let n = self.index.len();
                self.index.insert(v, n);
                self.low.insert(v, n);
                self.stack.push(v);
                self.on_stack.insert(v);
                let graph = self.graph;
                for w in graph.edges[v].keys() {
                    let w = w.as_str();
                    if !self.index.contains_key(w) {
                        self.visit(w);
                        self.low.insert(v, self.low[v].min(self.low[w]));
                    } else if self.on_stack.contains(w) {
                        self.low.insert(v, self.low[v].min(self.index[w]));
                    }
                }
                if self.low[v] == self.index[v] {
                    let mut set = Vec::new();
                    while let Some(w) = self.stack.pop() {
                        self.on_stack.remove(w);
                        set.push(w.to_owned());
                        if w == v {
                            break;
                        }
                    }
                    if set.len() > 1 {
                        set.sort();
                        self.out.push(set);
                    }
                }
            }
        }
        let mut walk = Walk {
            graph: self,
            index: BTreeMap::new(),
            low: BTreeMap::new(),
            stack: Vec::new(),
            on_stack: BTreeSet::new(),
            out: Vec::new(),
        };
        for v in self.edges.keys() {
            if !walk.index.contains_key(v.as_str()) {
                walk.visit(v);
            }
        }
        walk.out
    }

    /// One line per cycle: its modules, then each edge inside it with where it is written.
    fn describe_cycles(&self) -> Vec<String> {
        self.cycles()
            .iter()
            .map(|set| {
                let inner: Vec<String> = set
                    .iter()
                    .flat_map(|a| {
                        self.edges[a]
                            .iter()
                            .filter(|(b, _)| set.contains(b))
                            .map(move |(b, (file, line))| format!("{a} -> {b} ({}:{line})", file.display()))
                    })
                    .collect();
                format!(
                    "{}: modules {{{}}} import each other: {}",
                    self.src.display(),
                    set.join(", "),
                    inner.join(", ")
                )
            })
            .collect()
    }

    fn has_edge(&self, from: &str, to: &str) -> bool {
        self.edges.get(from).is_some_and(|targets| targets.contains_key(to))
    }
}

fn crate_src(name: &str) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(name).join("src");
    std::fs::canonicalize(&src).unwrap_or_else(|e| panic!("cannot find {}: {e}", src.display()))
}

/// Reads a crate's module graph and checks the reader found `expected_edge` in it, so a broken
/// reader cannot pass.
fn read_checked(name: &str, expected_edge: (&str, &str)) -> ModuleGraph {
    let graph = ModuleGraph::read(&crate_src(name));
    assert!(
        graph.has_edge(expected_edge.0, expected_edge.1),
        "{name}: the module reader did not find {} -> {}; it is broken",
        expected_edge.0,
        expected_edge.1
    );
    graph
}

#[test]
fn pelt_core_modules_have_no_import_cycle() {
    let cycles = read_checked("pelt-core", ("sim", "fur")).describe_cycles();
    assert!(cycles.is_empty(), "import cycles between top-level modules:\n{}", cycles.join("\n"));
}

#[test]
fn pelt_render_modules_have_no_import_cycle() {
    let graph = read_checked("pelt-render", ("simulation", "error"));
    let cycles = graph.describe_cycles();
    assert!(cycles.is_empty(), "import cycles between top-level modules:\n{}", cycles.join("\n"));
}

/// The order `lib.rs` states: a module may use those before it, never those after.
#[test]
fn pelt_core_data_flows_mesh_fur_texture_sim() {
    let graph = ModuleGraph::read(&crate_src("pelt-core"));
    let order = ["mesh", "fur", "texture", "sim"];
    let mut upward = Vec::new();
    for (i, from) in order.iter().enumerate() {
        for to in &order[i + 1..] {
            if let Some((file, line)) = graph.edges[*from].get(*to) {
                upward.push(format!("{from} -> {to} ({}:{line})", file.display()));
            }
        }
    }
    assert!(graph.has_edge("fur", "mesh"), "the module reader did not find fur -> mesh; it is broken");
    assert!(upward.is_empty(), "pelt-core modules import against the order mesh, fur, texture, sim: {upward:?}");
}

/// Writes `files` (path under `src/`, text) into a fresh folder and returns its `src`.
fn fixture(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let src = Path::new(env!("CARGO_TARGET_TMPDIR")).join("module_order").join(name).join("src");
    let _ = std::fs::remove_dir_all(&src);
    for (path, text) in files {
        let path = src.join(path);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }
    src
}

#[test]
fn two_modules_importing_each_other_are_a_cycle() {
    let src = fixture(
        "pair",
        &[
            ("lib.rs", "mod a;\nmod b;\nmod c;\n"),
            ("a.rs", "use crate::b::B;\npub struct A;\n"),
            ("b/mod.rs", "mod inner;\npub struct B;\n"),
            ("b/inner.rs", "// below b\n\nuse super::super::a::A;\n"),
            ("c.rs", "use crate::a::A;\n"),
        ],
    );
    let graph = ModuleGraph::read(&src);
    assert_eq!(graph.cycles(), vec![vec!["a".to_owned(), "b".to_owned()]]);
    let described = graph.describe_cycles();
    assert_eq!(described.len(), 1);
    assert!(
        described[0].ends_with("{a, b} import each other: a -> b (a.rs:1), b -> a (b/inner.rs:3)"),
        "{described:?}"
    );
}

#[test]
fn groups_reexports_and_inline_modules_are_followed_and_text_is_not() {
    let src = fixture(
        "reader",
        &[
            ("lib.rs", "mod a;\nmod b;\nmod c;\nmod d;\nmod helper;\npub use d::{Thing as Renamed, other::Deep};\n"),
            (
                "a.rs",
                r##"use crate::{b::{self, X}, c};
fn f() -> u32 { crate::Renamed::new(); 0 }
mod tests {
    use super::helper; // this module's own helper, not the crate's
}
"##,
            ),
            ("b.rs", "fn g() { let _ = crate::Deep; }\n"),
            (
                "c.rs",
                r##"// use crate::a;
/* crate::a /* nested */ crate::a */
const S: &str = "crate::a::X";
const R: &str = r#"crate::a "quoted" "#;
const C: char = '"';
macro_rules! m { () => { $crate::a::f() }; }
fn lifetime<'a>(x: &'a str) -> &'a str { x }
"##,
            ),
            ("d/mod.rs", "pub mod other;\npub struct Thing;\n"),
            ("d/other.rs", "pub struct Deep;\n"),
            ("helper.rs", ""),
        ],
    );
    let graph = ModuleGraph::read(&src);
    let targets = |m: &str| graph.edges[m].keys().cloned().collect::<Vec<_>>();
    assert_eq!(targets("a"), ["b", "c", "d"]);
    assert_eq!(targets("b"), ["d"]);
    assert_eq!(targets("c"), Vec::<String>::new());
    assert!(graph.cycles().is_empty());
}
