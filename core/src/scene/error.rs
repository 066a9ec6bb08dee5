//! Scene errors that name the file, the line and the field.
//!
//! Validation works on the serde model, which has no positions; it reports a
//! field path (`lenses[0].r1`), and [`Located`] finds that path's line in a
//! span-keeping parse of the same text (`toml_edit`). Parse errors go the
//! other way: their byte offset is turned back into the innermost field path.
//!
//! Text from a file (keys, names, the file's own name) is printed with its
//! control characters escaped ([`escape_controls`]): an ESC sequence in a
//! material name must not reach the terminal.

use std::borrow::Cow;
use std::fmt;
use std::ops::Range;
use toml_edit::{Item, TableLike, Value};

/// One step of a field path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Seg {
    Key(String),
    Index(usize),
}

/// A field path such as `lenses[0].r1`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FieldPath(pub Vec<Seg>);

impl FieldPath {
    pub fn key(&self, k: &str) -> FieldPath {
        let mut v = self.0.clone();
        v.push(Seg::Key(k.to_string()));
        FieldPath(v)
    }
    pub fn index(&self, i: usize) -> FieldPath {
        let mut v = self.0.clone();
        v.push(Seg::Index(i));
        FieldPath(v)
    }
    pub fn root(k: &str) -> FieldPath {
        FieldPath(vec![Seg::Key(k.to_string())])
    }

    /// `i` when the path is in `objects[i]`.
    pub fn object_index(&self) -> Option<usize> {
        match self.0.as_slice() {
            [Seg::Key(k), Seg::Index(i), ..] if k == "objects" => Some(*i),
            _ => None,
        }
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        if self.0.is_empty() {
            return f.write_str("(document)");
        }
        for (i, s) in self.0.iter().enumerate() {
            match s {
                Seg::Key(k) if i == 0 => write!(f, "{}", escape_controls(k))?,
                Seg::Key(k) => write!(f, ".{}", escape_controls(k))?,
                Seg::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

/// Whether `c` is printed escaped: a control character (C0, DEL, C1) or a
/// bidirectional override, which could reorder what the reader sees.
fn needs_escape(c: char) -> bool {
    c.is_control() || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// `s` with each control character written as `\u{1b}` (Rust's escape), so
/// that text from a file cannot drive the terminal it is printed on.
/// Escaping twice changes nothing: the escape has no control character.
pub fn escape_controls(s: &str) -> Cow<'_, str> {
    if !s.chars().any(needs_escape) {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        if needs_escape(c) {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// A byte count as a reader states a limit: `16 MiB`, else in bytes.
pub fn size_text(bytes: u64) -> String {
    if bytes >= 1 << 20 && bytes % (1 << 20) == 0 {
        format!("{} MiB", bytes >> 20)
    } else {
        format!("{bytes} bytes")
    }
}

/// A scene that cannot be loaded. Every message is one line, its text from
/// the file escaped.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{}: cannot read: {err}", escape_controls(.file))]
    Io { file: String, err: std::io::Error },
    /// The file is longer than the limit for its kind (read no further).
    #[error("{}: not read: larger than the {} limit for this input", escape_controls(.file), size_text(*.cap))]
    TooLarge { file: String, cap: u64 },
    /// `file:line:column: field: message`, all on one line.
    #[error("{}:{line}:{column}: {}: {}", escape_controls(.file), escape_controls(.field), escape_controls(.message))]
    Invalid {
        file: String,
        line: usize,
        column: usize,
        field: String,
        message: String,
    },
}

/// A validation problem before it is given a position.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    pub path: FieldPath,
    pub message: String,
}

impl Problem {
    /// A problem whose message, which may quote names from the file, has
    /// its control characters escaped.
    pub fn new(path: FieldPath, message: impl Into<String>) -> Self {
        let message = message.into();
        Problem {
            path,
            message: escape_controls(&message).into_owned(),
        }
    }
}

/// Arrays and inline tables nested deeper than this are not given to
/// `toml_parser`'s recursive parser ([`numbers_in_range`]); `toml_edit`
/// and `toml` refuse a document nested 100 deep already.
const MAX_NESTING: usize = 128;

/// The deepest nesting of brackets and braces among `tokens` (a table
/// header's brackets close on their line; brackets in strings are not
/// tokens).
fn nesting(tokens: &[toml_parser::lexer::Token]) -> usize {
    use toml_parser::lexer::TokenKind;
    let (mut depth, mut most) = (0usize, 0);
    for t in tokens {
        match t.kind() {
            TokenKind::LeftSquareBracket | TokenKind::LeftCurlyBracket => {
                depth += 1;
                most = most.max(depth);
            }
            TokenKind::RightSquareBracket | TokenKind::RightCurlyBracket => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    most
}

/// `text` with every number out of range for TOML (an integer that does
/// not fit 64 bits, a float too large for an f64) replaced by `0` padded
/// with spaces to its length, every other byte in place; `None` when there
/// is none. The values are found by `toml_parser`'s own parser (a key made
/// of digits is not a value) and decoded as `toml_edit` decodes them.
/// `None` too for arrays or inline tables nested deeper than
/// [`MAX_NESTING`]: that parser recurses once a level without a limit of
/// its own (10 000 levels overflowed the main thread's stack), and
/// `toml_edit` refuses such a document anyway.
fn numbers_in_range(text: &str) -> Option<String> {
    use toml_parser::decoder::{Encoding, ScalarKind};
    use toml_parser::{ErrorSink, ParseError, Source, Span, parser::EventReceiver};
    struct Unquoted(Vec<Span>);
    impl EventReceiver for Unquoted {
        fn scalar(&mut self, span: Span, encoding: Option<Encoding>, _error: &mut dyn ErrorSink) {
            if encoding.is_none() {
                self.0.push(span);
            }
        }
    }
    let source = Source::new(text);
    let mut values = Unquoted(Vec::new());
    let tokens: Vec<_> = source.lex().collect();
    if nesting(&tokens) > MAX_NESTING {
        return None;
    }
    toml_parser::parser::parse_document(&tokens, &mut values, &mut ());
    drop(tokens);
    let (mut out, mut copied) = (String::new(), 0);
    for span in values.0 {
        let (Some(raw), Some(before)) = (source.get(span), text.get(copied..span.start())) else {
            continue;
        };
        let (mut decoded, mut error) = (String::new(), None::<ParseError>);
        let out_of_range = match raw.decode_scalar(&mut decoded, &mut error) {
            _ if error.is_some() => false,
            ScalarKind::Integer(radix) => i64::from_str_radix(&decoded, radix.value()).is_err(),
            ScalarKind::Float => {
                let named = decoded
                    .trim_start_matches(['+', '-'])
                    .chars()
                    .all(|c| c.is_ascii_alphabetic());
                !named && decoded.parse::<f64>().is_ok_and(f64::is_infinite)
            }
            _ => false,
        };
        if out_of_range && !span.is_empty() {
            out.push_str(before);
            out.push('0');
            out.extend(std::iter::repeat_n(' ', span.len() - 1));
            copied = span.end();
        }
    }
    if copied == 0 {
        return None;
    }
    out.push_str(text.get(copied..)?);
    Some(out)
}

/// 1-based line and column of byte `offset` in `text`.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    // An offset inside a character (no parser should give one) counts as
    // that character's start: never a slice that panics.
    let offset = (0..=offset.min(text.len()))
        .rev()
        .find(|&i| text.is_char_boundary(i))
        .unwrap_or(0);
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let col = before.rfind('\n').map_or(offset, |i| offset - i - 1) + 1;
    (line, col)
}

enum Node<'a> {
    Item(&'a Item),
    Value(&'a Value),
    Table(&'a toml_edit::Table),
}

impl<'a> Node<'a> {
    fn table_like(&self) -> Option<&'a dyn TableLike> {
        match *self {
            Node::Item(i) => i.as_table_like(),
            Node::Value(v) => v.as_inline_table().map(|t| t as &dyn TableLike),
            Node::Table(t) => Some(t as &dyn TableLike),
        }
    }

    fn child(&self, seg: &Seg) -> Option<(Node<'a>, Option<Range<usize>>)> {
        match seg {
            Seg::Key(k) => {
                let (key, item) = self.table_like()?.get_key_value(k)?;
                Some((Node::Item(item), key.span().or_else(|| item.span())))
            }
            Seg::Index(n) => match *self {
                Node::Item(Item::ArrayOfTables(a)) => {
                    let t = a.get(*n)?;
                    Some((Node::Table(t), t.span()))
                }
                Node::Item(Item::Value(Value::Array(a))) | Node::Value(Value::Array(a)) => {
                    let v = a.get(*n)?;
                    Some((Node::Value(v), v.span()))
                }
                _ => None,
            },
        }
    }
}

/// The text of a scene with its span-keeping parse, for placing errors.
pub struct Located<'a> {
    pub file: &'a str,
    pub text: &'a str,
    pub doc: Option<toml_edit::Document<Cow<'a, str>>>,
}

impl<'a> Located<'a> {
    /// `text` and its span-keeping parse. A number out of range for TOML
    /// (an integer beyond 64 bits, a float beyond an f64) leaves `toml_edit`
    /// no document: it is then the parse of the same text with every such
    /// number replaced by `0` padded to its length, so that the field of
    /// that number, and of anything else, is found where it is.
    pub fn new(file: &'a str, text: &'a str) -> Self {
        let doc = toml_edit::Document::parse(Cow::Borrowed(text))
            .ok()
            .or_else(|| toml_edit::Document::parse(Cow::Owned(numbers_in_range(text)?)).ok());
        Located { file, text, doc }
    }

    /// Byte span of the deepest existing prefix of `path` (the key where
    /// there is one, else its table).
    pub fn span_of(&self, path: &FieldPath) -> Option<Range<usize>> {
        self.find(path).0
    }

    /// [`Located::span_of`] and how many segments of `path` exist.
    fn find(&self, path: &FieldPath) -> (Option<Range<usize>>, usize) {
        let Some(doc) = self.doc.as_ref() else {
            return (None, 0);
        };
        let mut node = Node::Item(doc.as_item());
        let mut span = None;
        for (depth, seg) in path.0.iter().enumerate() {
            match node.child(seg) {
                Some((n, s)) => {
                    node = n;
                    if s.is_some() {
                        span = s;
                    }
                }
                None => return (span, depth),
            }
        }
        (span, path.0.len())
    }

    /// The innermost field whose key or value contains byte `offset`.
    pub fn path_at(&self, offset: usize) -> FieldPath {
        fn walk(node: &Node, offset: usize, path: &mut FieldPath) {
            if let Some(t) = node.table_like() {
                for (k, _) in t.iter() {
                    let Some((key, item)) = t.get_key_value(k) else {
                        continue;
                    };
                    let inside = |r: Option<Range<usize>>| {
                        r.is_some_and(|r| r.start <= offset && offset < r.end.max(r.start + 1))
                    };
                    let in_item = match item {
                        // A [[table]] array has no span of its own; look inside each table.
                        Item::ArrayOfTables(a) => a
                            .iter()
                            .any(|t| inside(t.span()) || contains_deep(&Node::Table(t), offset)),
                        Item::Table(t) => inside(t.span()) || contains_deep(&Node::Table(t), offset),
                        _ => inside(item.span()),
                    };
                    if inside(key.span()) || in_item {
                        path.0.push(Seg::Key(k.to_string()));
                        walk_item(item, offset, path);
                        return;
                    }
                }
            }
        }
        fn contains_deep(node: &Node, offset: usize) -> bool {
            let mut p = FieldPath::default();
            walk(node, offset, &mut p);
            !p.0.is_empty()
        }
        fn walk_item(item: &Item, offset: usize, path: &mut FieldPath) {
            match item {
                Item::ArrayOfTables(a) => {
                    for (i, t) in a.iter().enumerate() {
                        let n = Node::Table(t);
                        if t.span().is_some_and(|r| r.contains(&offset)) || contains_deep(&n, offset) {
                            path.0.push(Seg::Index(i));
                            walk(&n, offset, path);
                            return;
                        }
                    }
                }
                Item::Value(Value::Array(a)) => {
                    for (i, v) in a.iter().enumerate() {
                        if v.span().is_some_and(|r| r.contains(&offset)) {
                            path.0.push(Seg::Index(i));
                            walk(&Node::Value(v), offset, path);
                            return;
                        }
                    }
                }
                other => walk(&Node::Item(other), offset, path),
            }
        }
        let mut path = FieldPath::default();
        if let Some(doc) = &self.doc {
            walk(&Node::Item(doc.as_item()), offset, &mut path);
        }
        path
    }

    /// An error at `path`, placed at its line (line 1 if the path is absent).
    pub fn error(&self, problem: &Problem) -> SceneError {
        let (line, column) = self
            .span_of(&problem.path)
            .map_or((1, 1), |s| line_col(self.text, s.start));
        SceneError::Invalid {
            file: self.file.to_string(),
            line,
            column,
            field: problem.path.to_string(),
            message: problem.message.clone(),
        }
    }

    /// An error at a byte span (from a parser), naming the field there.
    pub fn error_at(&self, span: Range<usize>, message: &str) -> SceneError {
        let (line, column) = line_col(self.text, span.start);
        let mut message = message.trim().replace('\n', " ");
        let mut field = self.path_at(span.start);
        if let Some(missing) = self.missing_root_field(&message) {
            // A required table of the document's root is missing: name it,
            // not the table that happens to start where the document does.
            field = FieldPath::root(missing);
            message = format!("missing table [{missing}]");
        }
        if self.doc.is_none() && message == "duplicate key" {
            match self.duplicate(span.clone()) {
                Some((path, why)) => (field, message) = (path, why),
                None => message = format!("duplicate key `{}`", self.text.get(span).unwrap_or("")),
            }
        }
        SceneError::Invalid {
            file: self.file.to_string(),
            line,
            column,
            field: field.to_string(),
            message: escape_controls(&message).into_owned(),
        }
    }

    /// The key a "missing field `KEY`" message names, when it is a key of
    /// the document's root that the root lacks (the scene's `camera`).
    fn missing_root_field(&self, message: &str) -> Option<&'static str> {
        const ROOT: [&str; 7] = [
            "render",
            "camera",
            "ambient",
            "lights",
            "materials",
            "objects",
            "lenses",
        ];
        let name = message.strip_prefix("missing field `")?.split('`').next()?;
        let key = ROOT.into_iter().find(|k| *k == name)?;
        let doc = self.doc.as_ref()?;
        (!doc.as_table().contains_key(key)).then_some(key)
    }

    /// A duplicate key or table at `span`, which leaves no parsed document
    /// to find its path in. The text is parsed again with this second key
    /// renamed: the renamed key's path is the duplicate's, and the original
    /// key in that document is where it was first given. Returns the path
    /// and the message.
    fn duplicate(&self, span: Range<usize>) -> Option<(FieldPath, String)> {
        let key: toml_edit::Key = self.text.get(span.clone())?.trim().parse().ok()?;
        let fresh = (0..)
            .map(|i| format!("lensview_renamed_{i}"))
            .find(|n| !self.text.contains(n.as_str()))?;
        let renamed = format!("{}{fresh}{}", &self.text[..span.start], &self.text[span.end..]);
        let attempt = |text: &str| {
            let tmp = Located::new(self.file, text);
            let mut path = tmp.path_at(span.start);
            let at = path.0.iter().position(|s| *s == Seg::Key(fresh.clone()))?;
            path.0.truncate(at + 1);
            path.0[at] = Seg::Key(key.get().to_string());
            let first = match tmp.find(&path) {
                (Some(s), depth) if depth == path.0.len() => {
                    format!(", first given on line {}", line_col(text, s.start).0)
                }
                _ => String::new(),
            };
            Some((path, first))
        };
        // A later error must not hide this one: else parse up to this line.
        let line_end = renamed[span.start..]
            .find('\n')
            .map_or(renamed.len(), |i| span.start + i);
        let (path, first) = attempt(&renamed).or_else(|| attempt(&renamed[..line_end]))?;
        let line = &self.text[self.text[..span.start].rfind('\n').map_or(0, |i| i + 1)..];
        let what = if line.trim_start().starts_with('[') {
            "table"
        } else {
            "key"
        };
        let name = escape_controls(key.get());
        Some((path, format!("duplicate {what} `{name}`{first}")))
    }

    /// Every non-finite float (`nan`, `inf`) in the document.
    pub fn non_finite(&self) -> Vec<Problem> {
        fn walk_value(v: &Value, path: &FieldPath, out: &mut Vec<Problem>) {
            match v {
                Value::Float(f) if !f.value().is_finite() => {
                    out.push(Problem::new(
                        path.clone(),
                        format!("{} is not a finite number", f.value()),
                    ));
                }
                Value::Array(a) => {
                    for (i, x) in a.iter().enumerate() {
                        walk_value(x, &path.index(i), out);
                    }
                }
                Value::InlineTable(t) => {
                    for (k, x) in t.iter() {
                        walk_value(x, &path.key(k), out);
                    }
                }
                _ => {}
            }
        }
        fn walk_item(item: &Item, path: &FieldPath, out: &mut Vec<Problem>) {
            match item {
                Item::Value(v) => walk_value(v, path, out),
                Item::Table(t) => {
                    for (k, x) in t.iter() {
                        walk_item(x, &path.key(k), out);
                    }
                }
                Item::ArrayOfTables(a) => {
                    for (i, t) in a.iter().enumerate() {
                        for (k, x) in t.iter() {
                            walk_item(x, &path.index(i).key(k), out);
                        }
                    }
                }
                Item::None => {}
            }
        }
        let mut out = Vec::new();
        if let Some(doc) = &self.doc {
            walk_item(doc.as_item(), &FieldPath::default(), &mut out);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "[camera]\nposition = [0, 1, 2]\n\n[[lenses]]\nd = 1\n\n[[lenses]]\nd = 2\nr1 = nan\n";

    #[test]
    fn paths_find_lines_and_lines_find_paths() {
        let l = Located::new("x.toml", TEXT);
        let p = FieldPath::root("lenses").index(1).key("r1");
        assert_eq!(p.to_string(), "lenses[1].r1");
        let span = l.span_of(&p).unwrap();
        assert_eq!(line_col(TEXT, span.start), (9, 1));
        assert_eq!(l.path_at(span.start + 6), p);
        let cam = FieldPath::root("camera").key("position").index(2);
        assert_eq!(line_col(TEXT, l.span_of(&cam).unwrap().start).0, 2);
        let nf = l.non_finite();
        assert_eq!(nf.len(), 1);
        assert_eq!(nf[0].path, p);
    }

    #[test]
    fn control_characters_are_escaped_once() {
        let raw = "a\u{1b}[2J\t\u{7f}\u{9b}\u{202e}é";
        let once = escape_controls(raw);
        assert_eq!(once, "a\\u{1b}[2J\\u{9}\\u{7f}\\u{9b}\\u{202e}é");
        assert_eq!(escape_controls(&once), once);
        assert!(matches!(escape_controls("plain é"), Cow::Borrowed(_)));
        let path = FieldPath::root("materials").key("x\u{1b}");
        assert_eq!(path.to_string(), "materials.x\\u{1b}");
        assert_eq!(size_text(16 << 20), "16 MiB");
        assert_eq!(size_text(1000), "1000 bytes");
    }
}
