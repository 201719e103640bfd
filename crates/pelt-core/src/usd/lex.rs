//! USDA's tokens, read from a `BufRead` a byte at a time with one token of lookahead.

use std::io::BufRead;
use std::path::{Path, PathBuf};

use super::UsdError;

#[derive(Clone, Debug, PartialEq)]
pub(super) enum Tok {
    Punct(u8),
    Str(String),
    Num(f64),
    Ident(String),
    Path(String),
    Eof,
}

pub(super) struct Lexer<R: BufRead> {
    input: R,
    pub(super) file: PathBuf,
    line: usize,
    peeked: Option<Tok>,
    scratch: String,
}

impl<R: BufRead> Lexer<R> {
    pub(super) fn new(input: R, file: &Path) -> Self {
        Self { input, file: file.to_path_buf(), line: 1, peeked: None, scratch: String::new() }
    }

    pub(super) fn error(&self, problem: impl Into<String>) -> UsdError {
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

    pub(super) fn skip_line(&mut self) -> Result<(), UsdError> {
        while let Some(b) = self.byte()? {
            self.bump();
            if b == b'\n' {
                self.line += 1;
                break;
            }
        }
        Ok(())
    }

    pub(super) fn peek(&mut self) -> Result<&Tok, UsdError> {
        if self.peeked.is_none() {
            let token = self.lex()?;
            self.peeked = Some(token);
        }
        Ok(self.peeked.as_ref().expect("just filled"))
    }

    pub(super) fn next(&mut self) -> Result<Tok, UsdError> {
        match self.peeked.take() {
            Some(token) => Ok(token),
            None => self.lex(),
        }
    }

    pub(super) fn expect(&mut self, punct: u8) -> Result<(), UsdError> {
        match self.next()? {
            Tok::Punct(p) if p == punct => Ok(()),
            other => Err(self.error(format!("expected `{}`, found {}", punct as char, describe(&other)))),
        }
    }

    /// Consumes `punct` if it comes next.
    pub(super) fn eat(&mut self, punct: u8) -> Result<bool, UsdError> {
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

pub(super) fn describe(token: &Tok) -> String {
    match token {
        Tok::Punct(p) => format!("`{}`", *p as char),
        Tok::Str(s) => format!("the string {s:?}"),
        Tok::Num(x) => format!("the number {x}"),
        Tok::Ident(word) => format!("`{word}`"),
        Tok::Path(path) => format!("the path <{path}>"),
        Tok::Eof => "the end of the file".to_owned(),
    }
}
