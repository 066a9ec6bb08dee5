//! Reading a valid scene file without a tree of the whole document (issue
//! 19 item 6): `toml`'s tree costs about 3.4 KB an object while it exists,
//! three times what the scene keeps. The objects, which is where a large
//! scene is large, are read one at a time instead: the text is scanned with
//! `toml_parser`'s lexer (which knows strings, comments and brackets), each
//! object (an element of the root array `objects = [ … ]` or the body of a
//! `[[objects]]` table) is parsed on its own into an [`ObjectFile`] and its
//! tree dropped, and the rest of the document, small, is parsed as a whole.
//!
//! Only for valid scenes: anything this reader does not take in (another
//! way of writing objects, a parse or type error) gives `None`, and the
//! caller goes on exactly as before (the whole-document parse, then the
//! span-keeping one that places the error). `check_scene_bytes` (the fuzz
//! oracle) checks that whatever this returns is what the whole-document
//! parse gives.

use super::file::{ObjectFile, SceneFile};
use serde::Deserialize;
use toml::de::{DeTable, DeValue};
use toml_parser::lexer::{Token, TokenKind};

/// One object as written in the file.
enum Piece<'a> {
    /// An element of `objects = [ … ]`: an inline table.
    Value(&'a str),
    /// The body of a `[[objects]]` table (the lines after its header).
    Table(&'a str),
}

/// The scene file in `text`, read object by object; `None` when the text
/// is not a valid scene file in the forms read here.
pub(super) fn scene_file(text: &str) -> Option<SceneFile> {
    let mut objects = Vec::new();
    let rest = split(text, &mut |piece| {
        objects.push(object(piece)?);
        Some(())
    })?;
    let table = DeTable::parse(&rest).ok()?;
    // Objects written any other way (`[objects]`, `objects.x = …`, a quoted
    // key) are left to the whole-document parse.
    if !all_finite(table.get_ref()) || table.get_ref().keys().any(|k| k.get_ref() == "objects") {
        return None;
    }
    let mut sf = SceneFile::deserialize(toml::de::Deserializer::from(table)).ok()?;
    objects.shrink_to_fit();
    sf.objects = objects;
    Some(sf)
}

/// The scene file in `text` parsed as one document, as `toml` reads it;
/// `None` when it does not parse or holds a non-finite number.
pub(super) fn whole_document(text: &str) -> Option<SceneFile> {
    let table = DeTable::parse(text).ok()?;
    if !all_finite(table.get_ref()) {
        return None;
    }
    SceneFile::deserialize(toml::de::Deserializer::from(table)).ok()
}

fn object(piece: Piece) -> Option<ObjectFile> {
    match piece {
        Piece::Value(text) => {
            let value = DeValue::parse(text).ok()?;
            if !finite_value(value.get_ref()) {
                return None;
            }
            ObjectFile::deserialize(toml::de::ValueDeserializer::from(value)).ok()
        }
        Piece::Table(text) => {
            let table = DeTable::parse(text).ok()?;
            if !all_finite(table.get_ref()) {
                return None;
            }
            ObjectFile::deserialize(toml::de::Deserializer::from(table)).ok()
        }
    }
}

/// Whether every float in `table` is finite: written neither `inf` nor
/// `nan` nor too large for an f64 (what `Located::non_finite` refuses).
/// A float that does not read back as an f64 counts as not finite, so
/// that the careful path decides.
pub(super) fn all_finite(table: &DeTable) -> bool {
    table.values().all(|v| finite_value(v.get_ref()))
}

fn finite_value(v: &DeValue) -> bool {
    match v {
        DeValue::Float(f) => f.as_str().parse::<f64>().is_ok_and(f64::is_finite),
        DeValue::Array(a) => a.iter().all(|v| finite_value(v.get_ref())),
        DeValue::Table(t) => all_finite(t),
        _ => true,
    }
}

/// A token: its kind and byte span.
#[derive(Clone, Copy)]
struct Tok {
    kind: TokenKind,
    start: usize,
    end: usize,
}

/// The tokens of a text without its whitespace, and the text.
struct Tokens<'a> {
    text: &'a str,
    lexer: std::iter::Peekable<toml_parser::lexer::Lexer<'a>>,
}

impl<'a> Tokens<'a> {
    /// The next token; at the end, `Eof` for ever.
    fn next(&mut self) -> Tok {
        self.peek_kind();
        match self.lexer.next() {
            Some(t) => Tok {
                kind: t.kind(),
                start: t.span().start(),
                end: t.span().end(),
            },
            None => Tok {
                kind: TokenKind::Eof,
                start: self.text.len(),
                end: self.text.len(),
            },
        }
    }

    fn peek_kind(&mut self) -> TokenKind {
        while self.lexer.peek().is_some_and(|t| t.kind() == TokenKind::Whitespace) {
            self.lexer.next();
        }
        self.lexer.peek().map_or(TokenKind::Eof, Token::kind)
    }

    fn is(&self, t: Tok, s: &str) -> bool {
        t.kind == TokenKind::Atom && &self.text[t.start..t.end] == s
    }

    /// The rest of a line, `depth` brackets open where it starts; `None` at
    /// a closing bracket that was never opened.
    fn skip_line(&mut self, mut depth: usize) -> Option<()> {
        loop {
            match self.next().kind {
                TokenKind::LeftSquareBracket | TokenKind::LeftCurlyBracket => depth += 1,
                TokenKind::RightSquareBracket | TokenKind::RightCurlyBracket => depth = depth.checked_sub(1)?,
                TokenKind::Newline if depth == 0 => return Some(()),
                TokenKind::Eof => return Some(()),
                _ => {}
            }
        }
    }

    /// Whether the header whose first `[` is `open` is exactly
    /// `[[objects]]`; reads to the end of its line and returns the offset
    /// after it.
    fn header(&mut self, open: Tok) -> (bool, usize) {
        let mut toks = vec![open];
        let end = loop {
            let t = self.next();
            match t.kind {
                TokenKind::Newline | TokenKind::Eof => break t.end,
                TokenKind::Comment => {}
                _ => toks.push(t),
            }
        };
        use TokenKind::{Atom, LeftSquareBracket as L, RightSquareBracket as R};
        let objects = match toks.as_slice() {
            [a, b, key, c, d] if (a.kind, b.kind, key.kind, c.kind, d.kind) == (L, L, Atom, R, R) => {
                a.end == b.start && c.end == d.start && self.is(*key, "objects")
            }
            _ => false,
        };
        (objects, end)
    }

    /// The elements of an array whose `[` was just read, each given to
    /// `each`; returns the offset after the line that closes it.
    fn array(&mut self, each: &mut dyn FnMut(Piece<'a>) -> Option<()>) -> Option<usize> {
        let mut depth = 1;
        let mut element: Option<(usize, usize)> = None;
        loop {
            let t = self.next();
            match t.kind {
                TokenKind::Newline | TokenKind::Comment => continue,
                TokenKind::Eof => return None,
                TokenKind::Comma | TokenKind::RightSquareBracket if depth == 1 => {
                    match element.take() {
                        Some((a, b)) => each(Piece::Value(&self.text[a..b]))?,
                        // `[1,,2]` or `[,]`: not valid.
                        None if t.kind == TokenKind::Comma => return None,
                        None => {}
                    }
                    if t.kind == TokenKind::RightSquareBracket {
                        break;
                    }
                    continue;
                }
                TokenKind::LeftSquareBracket | TokenKind::LeftCurlyBracket => depth += 1,
                TokenKind::RightSquareBracket | TokenKind::RightCurlyBracket => depth -= 1,
                _ => {}
            }
            element = Some((element.map_or(t.start, |e| e.0), t.end));
        }
        // Only a comment may follow on the closing line.
        let mut t = self.next();
        if t.kind == TokenKind::Comment {
            t = self.next();
        }
        matches!(t.kind, TokenKind::Newline | TokenKind::Eof).then_some(t.end)
    }
}

/// The start of the line holding byte `at`.
fn line_start(text: &str, at: usize) -> usize {
    text[..at].rfind('\n').map_or(0, |i| i + 1)
}

/// Gives each object written in `text` to `each` and returns the text
/// without them; `None` when the objects are not written in the two forms
/// read here or the text cannot be scanned.
fn split<'a>(text: &'a str, each: &mut dyn FnMut(Piece<'a>) -> Option<()>) -> Option<String> {
    let mut tokens = Tokens {
        text,
        lexer: toml_parser::Source::new(text).lex().peekable(),
    };
    let mut rest = String::new();
    let mut kept_from = 0; // the text from here on is not yet in `rest`
    let mut section: Option<usize> = None; // body of the `[[objects]]` being read
    let (mut in_root, mut inline, mut tables) = (true, false, false);
    loop {
        // At the start of a line, outside any bracket.
        let t = tokens.next();
        match t.kind {
            TokenKind::Eof => break,
            TokenKind::Newline | TokenKind::Comment => {}
            TokenKind::LeftSquareBracket => {
                let line = line_start(text, t.start);
                if let Some(body) = section.take() {
                    each(Piece::Table(&text[body..line]))?;
                    kept_from = line;
                }
                in_root = false;
                let (objects, end) = tokens.header(t);
                if objects {
                    rest.push_str(&text[kept_from..line]);
                    section = Some(end);
                    tables = true;
                }
            }
            _ if section.is_some() => tokens.skip_line(0)?,
            _ if in_root && tokens.is(t, "objects") && tokens.peek_kind() == TokenKind::Equals => {
                tokens.next();
                if tokens.next().kind != TokenKind::LeftSquareBracket || inline {
                    return None;
                }
                inline = true;
                rest.push_str(&text[kept_from..line_start(text, t.start)]);
                kept_from = tokens.array(each)?;
            }
            _ => tokens.skip_line(0)?,
        }
    }
    if inline && tables {
        return None;
    }
    match section {
        Some(body) => each(Piece::Table(&text[body..]))?,
        None => rest.push_str(&text[kept_from..]),
    }
    Some(rest)
}
