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
#[derive(Clone, Copy)]
pub(super) enum Piece<'a> {
    /// An element of `objects = [ … ]`: an inline table.
    Value(&'a str),
    /// The body of a `[[objects]]` table (the lines after its header).
    Table(&'a str),
}

impl<'a> Piece<'a> {
    fn text(self) -> &'a str {
        match self {
            Piece::Value(s) | Piece::Table(s) => s,
        }
    }
}

/// What [`scene_file`] makes of a text (made once a load: its size does
/// not matter).
#[allow(clippy::large_enum_variant)]
pub(super) enum Read {
    /// A scene file, every number finite.
    Scene(SceneFile),
    /// Objects written in the forms read here, and something wrong.
    Invalid,
    /// Objects written in another form, or a text that cannot be scanned:
    /// for the whole-document parse to decide.
    OtherForm,
}

/// The scene file in `text`, read object by object.
pub(super) fn scene_file(text: &str) -> Read {
    let mut objects = Vec::new();
    let mut invalid = false;
    let Some(rest) = split(text, &mut |piece| {
        objects.push(object(piece).or_else(|| {
            invalid = true;
            None
        })?);
        Some(())
    }) else {
        return if invalid { Read::Invalid } else { Read::OtherForm };
    };
    let Ok(table) = DeTable::parse(&rest) else {
        return Read::Invalid;
    };
    // Objects written any other way (`[objects]`, `objects.x = …`, a quoted
    // key) are left to the whole-document parse.
    if table.get_ref().keys().any(|k| k.get_ref() == "objects") {
        return Read::OtherForm;
    }
    if !all_finite(table.get_ref()) {
        return Read::Invalid;
    }
    match SceneFile::deserialize(toml::de::Deserializer::from(table)) {
        Ok(mut sf) => {
            objects.shrink_to_fit();
            sf.objects = objects;
            Read::Scene(sf)
        }
        Err(_) => Read::Invalid,
    }
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

/// Whether an object, as written, parses and reads as an [`ObjectFile`]
/// on its own (no non-finite number): what cannot be the fault when the
/// file is refused.
pub(super) fn parses(piece: Piece) -> bool {
    object(piece).is_some()
}

/// The smallest object: a stub needs no more room than any object that
/// reads (`type` and a kind are needed).
const STUB: &str = "type=\"prism\"";

/// What replaces an object in [`stubbed`].
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Stub {
    /// [`STUB`], an object that reads: the text parses as the original
    /// would but for the objects replaced.
    Object,
    /// The cheapest placeholder for the span-keeping parse, which only
    /// places errors: `0` for an element, nothing for a table's body (each
    /// object keeps its number).
    Place,
}

/// `text` with each object that `stub` picks (given its number) replaced by
/// `kind` padded with spaces, every other byte and every line break in
/// place: errors in what is left are found at the same line and column.
/// An object too short for the stub, or an element over several lines,
/// is kept. `None` when the objects cannot be found ([`split`]).
pub(super) fn stubbed(text: &str, kind: Stub, stub: &mut dyn FnMut(usize, Piece) -> bool) -> Option<String> {
    let mut out = String::with_capacity(text.len());
    let (mut copied, mut i) = (0, 0);
    split(text, &mut |piece| {
        let s = piece.text();
        let at = s.as_ptr() as usize - text.as_ptr() as usize;
        if stub(i, piece)
            && let Some(r) = stub_for(piece, kind)
        {
            out.push_str(&text[copied..at]);
            out.push_str(&r);
            copied = at + s.len();
        }
        i += 1;
        Some(())
    })?;
    out.push_str(&text[copied..]);
    Some(out)
}

/// The stub `kind` in the room of `piece`, or `None` where it does not fit.
fn stub_for(piece: Piece, kind: Stub) -> Option<String> {
    let stub = if kind == Stub::Object { STUB } else { "" };
    match piece {
        Piece::Value(s) if !s.contains('\n') && s.len() >= STUB.len() + 2 => Some(match kind {
            Stub::Object => format!("{{{STUB}}}{}", " ".repeat(s.len() - STUB.len() - 2)),
            Stub::Place => format!("0{}", " ".repeat(s.len() - 1)),
        }),
        Piece::Value(_) => None,
        Piece::Table(s) => {
            // The stub on the first line long enough; spaces elsewhere.
            let line = s.split('\n').scan(0, |at, l| {
                let start = *at;
                *at += l.len() + 1;
                Some((start, l.len()))
            });
            let (start, _) = line.into_iter().find(|&(_, len)| len >= STUB.len())?;
            let mut b: Vec<u8> = s.bytes().map(|c| if c == b'\n' { c } else { b' ' }).collect();
            b[start..start + stub.len()].copy_from_slice(stub.as_bytes());
            String::from_utf8(b).ok()
        }
    }
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
    /// A comment held a control character TOML forbids there: the text is
    /// left to the whole-document parse (the comments between and after
    /// objects are parsed by nobody here).
    bad_comment: bool,
}

impl<'a> Tokens<'a> {
    /// The next token; at the end, `Eof` for ever.
    fn next(&mut self) -> Tok {
        self.peek_kind();
        match self.lexer.next() {
            Some(t) => {
                let (start, end) = (t.span().start(), t.span().end());
                if t.kind() == TokenKind::Comment {
                    let forbidden = |c: char| c.is_control() && c != '\t';
                    self.bad_comment |= self.text.get(start..end).is_none_or(|c| c.chars().any(forbidden));
                }
                Tok {
                    kind: t.kind(),
                    start,
                    end,
                }
            }
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
                        Some((a, b)) => each(Piece::Value(self.text.get(a..b)?))?,
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
    text.get(..at).and_then(|t| t.rfind('\n')).map_or(0, |i| i + 1)
}

/// Gives each object written in `text` to `each` and returns the text
/// without them; `None` when the objects are not written in the two forms
/// read here or the text cannot be scanned.
fn split<'a>(text: &'a str, each: &mut dyn FnMut(Piece<'a>) -> Option<()>) -> Option<String> {
    // A carriage return without its line feed ends no line in TOML (the
    // whole-document parse refuses it, and says where), though the lexer
    // breaks a line there and `line_start` does not: left to that parse.
    let bytes = text.as_bytes();
    if (0..bytes.len()).any(|i| bytes[i] == b'\r' && bytes.get(i + 1) != Some(&b'\n')) {
        return None;
    }
    // A byte-order mark is allowed at the start of a document only: an
    // object read alone would take one at its own start (found by
    // `cargo fuzz`), so any after the first byte is left to that parse too.
    if text.char_indices().any(|(i, c)| c == '\u{feff}' && i > 0) {
        return None;
    }
    let mut tokens = Tokens {
        text,
        lexer: toml_parser::Source::new(text).lex().peekable(),
        bad_comment: false,
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
                    // (Every slice taken here is checked: a text scanned
                    // otherwise than expected is left to the whole parse.)
                    each(Piece::Table(text.get(body..line)?))?;
                    kept_from = line;
                }
                in_root = false;
                let (objects, end) = tokens.header(t);
                if objects {
                    rest.push_str(text.get(kept_from..line)?);
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
                rest.push_str(text.get(kept_from..line_start(text, t.start))?);
                kept_from = tokens.array(each)?;
            }
            _ => tokens.skip_line(0)?,
        }
    }
    if (inline && tables) || tokens.bad_comment {
        return None;
    }
    match section {
        Some(body) => each(Piece::Table(text.get(body..)?))?,
        None => rest.push_str(text.get(kept_from..)?),
    }
    Some(rest)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    const HEAD: &str = "[camera]\nposition = [0, 1, 5]\n[materials.m]\ncolor = [0.5, 0.5, 0.5]\n";

    /// Texts in both forms read here, with comments, strings holding
    /// brackets and `#`, multi-line values and arrays, read object by
    /// object into exactly what the whole-document parse gives.
    #[test]
    fn objects_read_one_at_a_time_are_the_whole_documents() {
        let cases = [
            "objects = [\n  {type=\"cuboid\", size=[1,2,3]}, # a [comment], {x\n  {type = 'sphere', radius = 2, name = \"a],}[{\" },\n]\n",
            "objects = [{type=\"sphere\",radius=1,position=[\n 1, 2,\n 3]},{type=\"prism\",side=1,height=2,material=\"m\"}] # end\n",
            "objects = []\n",
            "objects = [ # none\n]\n",
            "title = \"\"\"\nobjects = [ {type=\"x\"} ]\n\"\"\"\n",
            "[[objects]]\ntype = \"cuboid\"\nsize = [1, 1, 1]\n\n# between\n[[objects]] # a comment\ntype = \"sphere\"\nname = \"\"\"two\n[[lines]]\"\"\"\nradius = 1\n",
            "[[ objects ]]\ntype = \"pyramid\"\nside = 1\nheight = 1\n[[objects]]\ntype = \"sphere\"\nradius = 3\n",
        ];
        for (i, body) in cases.iter().enumerate() {
            // The objects first (the root array must be), then the rest;
            // and the tables also before the other tables.
            for text in [format!("{body}{HEAD}"), format!("{HEAD}{body}")] {
                let whole = whole_document(&text);
                match scene_file(&text) {
                    Read::Scene(sf) => assert_eq!(Some(sf), whole, "case {i}:\n{text}"),
                    // A root array after a table belongs to that table.
                    _ => assert!(whole.is_none() || body.starts_with("title"), "case {i}:\n{text}"),
                }
            }
        }
        // Each case read object by object at least once.
        let read = |t: &str| matches!(scene_file(t), Read::Scene(_));
        let unread: Vec<_> = cases.iter().filter(|b| !read(&format!("{b}{HEAD}"))).collect();
        // Only the one whose `objects` is inside a string (and `title` is
        // not a key of a scene).
        assert_eq!(unread, [&cases[4]]);
    }

    /// Objects written otherwise, or both forms, or the key twice, are not
    /// taken in here; the scene (or the refusal) is the whole document's.
    #[test]
    fn other_forms_are_left_to_the_whole_document() {
        let other = [
            "objects = [{type=\"sphere\",radius=1}]\n[[objects]]\ntype=\"sphere\"\nradius=1\n",
            "objects = [{type=\"sphere\",radius=1}]\nobjects = []\n",
            "\"objects\" = [{type=\"sphere\",radius=1}]\n",
            "[[objects]]\ntype=\"sphere\"\nradius=1\n[objects.x]\n",
            "objects = [{type=\"sphere\",radius=1} {type=\"sphere\",radius=1}]\n",
            "objects = [{type=\"sphere\",radius=1},,]\n",
            "objects = [{type=\"sphere\",radius=1}] x\n",
            "objects = [{type=\"sphere\",radius=1}\n",
        ];
        for (i, body) in other.iter().enumerate() {
            let text = format!("{body}{HEAD}");
            assert!(!matches!(scene_file(&text), Read::Scene(_)), "case {i}");
            let e = Scene::parse("x.toml", &text).map(|_| ()).map_err(|e| e.to_string());
            let whole = Scene::refusal("x.toml", &text, false)
                .map(|_| ())
                .map_err(|e| e.to_string());
            assert_eq!(e, whole, "case {i}");
        }
    }

    /// A refusal found in the text with stubs names the same file, line,
    /// column, field and message as in the whole text, wherever the fault
    /// is: in an object among many, in the rest, in validation.
    #[test]
    fn refusals_with_stubs_are_the_whole_texts() {
        let objects: String = (0..40)
            .map(|i| format!("  {{type=\"cuboid\", position=[{i}, 0, 0], size=[0.5, 0.5, 0.5], material=\"m\"}},\n"))
            .collect();
        let tables: String = (0..40)
            .map(|i| format!("[[objects]]\ntype = \"sphere\"\nposition = [{i}, 0, 0]\nradius = 0.25\n"))
            .collect();
        let inline = format!("objects = [\n{objects}]\n{HEAD}");
        let aot = format!("{HEAD}{tables}");
        let faults = [
            ("position=[17, 0, 0]", "position=[17, 0, nan]"),
            ("position=[17, 0, 0]", "position=[17, 0, 0], colour=1"),
            (
                "size=[0.5, 0.5, 0.5], material=\"m\"}},\n  {type=\"cuboid\", position=[9,",
                "size=[0.5, -0.5, 0.5], material=\"q\"}},\n  {type=\"cuboid\", position=[9,",
            ),
            ("position = [17, 0, 0]", "position = [17, 0, 1e999]"),
            ("position = [17, 0, 0]", "position = [17, 0]"),
            (
                "radius = 0.25\n[[objects]]\ntype = \"sphere\"\nposition = [30",
                "radius = -1\n[[objects]]\ntype = \"sphere\"\nposition = [30",
            ),
            (
                "radius = 0.25\n[[objects]]\ntype = \"sphere\"\nposition = [30",
                "radius = 0.25\nradius = 1\n[[objects]]\ntype = \"sphere\"\nposition = [30",
            ),
            ("position = [0, 1, 5]", "position = [0, 1, 5]\nfov = nan"),
            ("position = [0, 1, 5]", "position = [0, 1, 5]\nposition = 2"),
            ("position = [0, 1, 5]", "position = [3.25, 0, 0]"),
            ("color = [0.5, 0.5, 0.5]", "color = [0.5, 0.5, -1]"),
        ];
        let mut checked = 0;
        for (from, to) in faults {
            for base in [&inline, &aot] {
                if !base.contains(from) {
                    continue;
                }
                let text = base.replacen(from, to, 1);
                let e = Scene::parse("x.toml", &text).err().map(|e| e.to_string());
                let whole = Scene::refusal("x.toml", &text, false).err().map(|e| e.to_string());
                assert_eq!(e, whole, "{to}");
                checked += usize::from(e.is_some());
            }
        }
        // Every fault refused at least once (the camera's in both forms).
        assert!(checked >= faults.len(), "{checked}");
    }
}
