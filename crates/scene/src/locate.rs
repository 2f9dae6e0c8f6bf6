//! Finds where a [`FieldPath`] is written in RON source text, so errors found after parsing can
//! still name a line and column.
//!
//! A small, tolerant reader of RON's structure (values, `name: value` entries, lists, maps,
//! tuples, comments, strings) — not a validator: the source has already been parsed by `ron`.
//! Lookup descends as far as the path can be followed and returns the position of the deepest
//! step found (the field's name, or the list element), so a failed lookup still points at the
//! enclosing object.

use crate::path::{FieldPath, Segment};

/// A 1-based line and column (in characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct LineColumn {
    pub(crate) line: usize,
    pub(crate) column: usize,
}

/// The line and column of byte `offset` in `source`.
pub(crate) fn line_column(source: &str, offset: usize) -> LineColumn {
    let mut offset = offset.min(source.len());
    while !source.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &source[..offset];
    let line = 1 + before.matches('\n').count();
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = 1 + before[line_start..].chars().count();
    LineColumn { line, column }
}

/// Where `path` is written in `source` (see the module doc); the top of the value if nothing of
/// the path can be found.
pub(crate) fn locate(source: &str, path: &FieldPath) -> LineColumn {
    let tokens = tokenize(source);
    let mut reader = Reader {
        tokens: &tokens,
        pos: 0,
        depth: 0,
    };
    reader.skip_attributes();
    let start = reader.peek_offset().unwrap_or(0);
    let offset = match reader.value() {
        Some(root) => find(&root, &path.segments, start),
        None => start,
    };
    line_column(source, offset)
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Ident(String),
    Str(String),
    Punct(char),
    Other,
}

/// Splits the source into tokens with their byte offsets. Never fails: anything unrecognised
/// becomes [`Tok::Other`].
fn tokenize(src: &str) -> Vec<(Tok, usize)> {
    let bytes = src.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if bytes[i..].starts_with(b"//") {
            i = src[i..].find('\n').map_or(bytes.len(), |k| i + k);
        } else if bytes[i..].starts_with(b"/*") {
            // Block comments nest in RON.
            let mut depth = 0usize;
            while i < bytes.len() {
                if bytes[i..].starts_with(b"/*") {
                    depth += 1;
                    i += 2;
                } else if bytes[i..].starts_with(b"*/") {
                    depth = depth.saturating_sub(1);
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if c == b'"' || ((c == b'r' || c == b'b') && raw_or_byte_string_at(src, i)) {
            let start = i;
            let (text, end) = string_at(src, i);
            out.push((Tok::Str(text), start));
            i = end;
        } else if c == b'\'' {
            // A char literal: skip to the closing quote, honouring escapes.
            let start = i;
            i += 1;
            while i < bytes.len() && bytes[i] != b'\'' {
                i += if bytes[i] == b'\\' { 2 } else { 1 };
            }
            i = (i + 1).min(bytes.len());
            out.push((Tok::Other, start));
        } else if matches!(
            c,
            b'(' | b')' | b'[' | b']' | b'{' | b'}' | b':' | b',' | b'#' | b'!'
        ) {
            out.push((Tok::Punct(c as char), i));
            i += 1;
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            if bytes[i..].starts_with(b"r#") {
                i += 2;
            }
            let name_start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            out.push((Tok::Ident(src[name_start..i].to_owned()), start));
        } else if c.is_ascii_digit() || matches!(c, b'+' | b'-' | b'.') {
            let start = i;
            i += 1;
            while i < bytes.len()
                && (bytes[i].is_ascii_alphanumeric()
                    || matches!(bytes[i], b'_' | b'.' | b'+' | b'-'))
            {
                i += 1;
            }
            out.push((Tok::Other, start));
        } else {
            let start = i;
            i += src[i..].chars().next().map_or(1, char::len_utf8);
            out.push((Tok::Other, start));
        }
    }
    out
}

/// Whether a raw (`r"…"`, `r#"…"#`) or byte (`b"…"`, `br"…"`) string starts at `i`.
fn raw_or_byte_string_at(src: &str, i: usize) -> bool {
    let rest = &src[i..];
    let rest = rest.strip_prefix('b').unwrap_or(rest);
    if rest.starts_with('"') {
        return true;
    }
    match rest.strip_prefix('r') {
        Some(r) => r.trim_start_matches('#').starts_with('"'),
        None => false,
    }
}

/// The text of the string starting at `i` (escapes kept as written) and the offset after it.
fn string_at(src: &str, mut i: usize) -> (String, usize) {
    let bytes = src.as_bytes();
    if bytes.get(i) == Some(&b'b') {
        i += 1;
    }
    if bytes.get(i) == Some(&b'r') {
        i += 1;
        let hashes = src[i..].chars().take_while(|&c| c == '#').count();
        i += hashes + 1; // the hashes and the opening quote
        let close = format!("\"{}", "#".repeat(hashes));
        return match src.get(i..).and_then(|s| s.find(&close)) {
            Some(k) => (src[i..i + k].to_owned(), i + k + close.len()),
            None => (src.get(i..).unwrap_or("").to_owned(), bytes.len()),
        };
    }
    i += 1; // the opening quote
    let start = i;
    while i < bytes.len() && bytes[i] != b'"' {
        i += if bytes[i] == b'\\' { 2 } else { 1 };
    }
    let end = i.min(bytes.len());
    let text = src.get(start..end).unwrap_or("").to_owned();
    (text, (end + 1).min(bytes.len()))
}

/// A value's structure: where it starts and, for compounds, its entries.
#[derive(Debug)]
struct Node {
    offset: usize,
    /// The bracket that opened it (`(`, `[`, `{`), if it is a compound.
    bracket: Option<char>,
    /// Whether an identifier precedes the bracket (`Sphere(…)`, `Some(…)`).
    named: bool,
    entries: Vec<Entry>,
}

#[derive(Debug)]
struct Entry {
    /// The key (`name:` in a struct, `"key":` in a map) and its offset.
    key: Option<(String, usize)>,
    value: Node,
}

struct Reader<'t> {
    tokens: &'t [(Tok, usize)],
    pos: usize,
    depth: usize,
}

/// Deeper than any file `ron` accepts (its recursion limit is 128).
const MAX_DEPTH: usize = 512;

impl Reader<'_> {
    fn peek(&self) -> Option<&Tok> {
        self.tokens.get(self.pos).map(|(t, _)| t)
    }

    fn peek_offset(&self) -> Option<usize> {
        self.tokens.get(self.pos).map(|(_, o)| *o)
    }

    fn peek_at(&self, k: usize) -> Option<&Tok> {
        self.tokens.get(self.pos + k).map(|(t, _)| t)
    }

    /// Skips `#![enable(…)]` attributes.
    fn skip_attributes(&mut self) {
        while self.peek() == Some(&Tok::Punct('#')) {
            self.pos += 1;
            if self.peek() == Some(&Tok::Punct('!')) {
                self.pos += 1;
            }
            if self.peek() != Some(&Tok::Punct('[')) {
                return;
            }
            let mut depth = 0usize;
            while let Some(t) = self.peek().cloned() {
                self.pos += 1;
                match t {
                    Tok::Punct('[') | Tok::Punct('(') => depth += 1,
                    Tok::Punct(']') | Tok::Punct(')') => {
                        depth = depth.saturating_sub(1);
                        if depth == 0 {
                            break;
                        }
                    }
                    _ => {}
                }
            }
        }
    }

    fn value(&mut self) -> Option<Node> {
        let offset = self.peek_offset()?;
        let mut named = false;
        if let Some(Tok::Ident(_)) = self.peek() {
            self.pos += 1;
            if !matches!(self.peek(), Some(Tok::Punct('('))) {
                return Some(Node {
                    offset,
                    bracket: None,
                    named: false,
                    entries: Vec::new(),
                });
            }
            named = true;
        }
        let open = match self.peek()? {
            Tok::Punct(c @ ('(' | '[' | '{')) => *c,
            Tok::Str(_) | Tok::Other => {
                self.pos += 1;
                return Some(Node {
                    offset,
                    bracket: None,
                    named: false,
                    entries: Vec::new(),
                });
            }
            _ => return None,
        };
        let close = match open {
            '(' => ')',
            '[' => ']',
            _ => '}',
        };
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return None;
        }
        self.pos += 1;
        let mut entries = Vec::new();
        loop {
            match self.peek()? {
                Tok::Punct(c) if *c == close => {
                    self.pos += 1;
                    break;
                }
                Tok::Punct(',') => {
                    self.pos += 1;
                    continue;
                }
                _ => {}
            }
            let key = match (self.peek(), self.peek_at(1)) {
                (Some(Tok::Ident(k) | Tok::Str(k)), Some(Tok::Punct(':'))) => {
                    let k = (k.clone(), self.peek_offset().unwrap_or(offset));
                    self.pos += 2;
                    Some(k)
                }
                _ => None,
            };
            let before = self.pos;
            let value = self.value()?;
            if self.pos == before {
                return None; // no progress: not RON we understand
            }
            entries.push(Entry { key, value });
        }
        self.depth -= 1;
        Some(Node {
            offset,
            bracket: Some(open),
            named,
            entries,
        })
    }
}

/// The offset of the deepest step of `path` found below `node` (`here` if none).
fn find(node: &Node, path: &[Segment], here: usize) -> usize {
    let Some((first, rest)) = path.split_first() else {
        return here;
    };
    match first {
        Segment::Field(name) => {
            if let Some(e) = node
                .entries
                .iter()
                .find(|e| e.key.as_ref().is_some_and(|(k, _)| k == name))
            {
                let at = e.key.as_ref().map_or(e.value.offset, |(_, o)| *o);
                return find(&e.value, rest, at);
            }
            // `Some(…)` and other one-element wrappers: look inside.
            match single_unkeyed(node) {
                Some(inner) if inner.bracket.is_some() => find(inner, path, here),
                _ => here,
            }
        }
        Segment::Index(i) => {
            // `Union([a, b])`, `Some([…])`: the list is inside a one-element wrapper.
            if let Some(inner) = single_unkeyed(node)
                && (inner.bracket == Some('[') || (inner.bracket == Some('(') && !inner.named))
            {
                return find(inner, path, here);
            }
            match node.entries.get(*i) {
                Some(e) if e.key.is_none() => find(&e.value, rest, e.value.offset),
                _ => here,
            }
        }
    }
}

/// The value of a compound that holds exactly one entry without a key.
fn single_unkeyed(node: &Node) -> Option<&Node> {
    match node.entries.as_slice() {
        [e] if e.key.is_none() && node.bracket == Some('(') => Some(&e.value),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SRC: &str = r#"#![enable(implicit_some)]
Scene(
    // a comment with ( brackets ]
    materials: { "red": (diffuse: (1, 0, 0)) },
    objects: [
        (shape: Sphere(radius: 1)),
        (
            name: "x /* not a comment */",
            shape: Union([
                Sphere(radius: 1),
                FreeForm(
                    base: Sphere(radius: 2),
                    perturbations: [(form_factor: 1, quadric: Sphere(radius: -1))],
                ),
            ]),
        ),
    ],
)"#;

    fn at(path: FieldPath) -> (usize, usize) {
        let lc = locate(SRC, &path);
        (lc.line, lc.column)
    }

    #[test]
    fn finds_fields_elements_and_map_keys() {
        let objects = FieldPath::root().field("objects");
        assert_eq!(at(objects.clone()), (5, 5));
        assert_eq!(at(objects.index(0).field("shape").field("radius")), (6, 24));
        let union = objects.index(1).field("shape");
        assert_eq!(at(union.index(1).field("base").field("radius")), (12, 34));
        let pert = union
            .index(1)
            .field("perturbations")
            .index(0)
            .field("quadric")
            .field("radius");
        assert_eq!(at(pert), (13, 70));
        assert_eq!(
            at(FieldPath::root()
                .field("materials")
                .field("red")
                .field("diffuse")),
            (4, 26)
        );
    }

    #[test]
    fn stops_at_the_deepest_step_found() {
        let missing = FieldPath::root()
            .field("objects")
            .index(1)
            .field("nope")
            .field("deeper");
        assert_eq!(at(missing), (7, 9));
        assert_eq!(at(FieldPath::root().field("camera")), (2, 1));
    }

    #[test]
    fn survives_garbage() {
        for src in [
            "",
            "(",
            "Scene(a: [1, 2",
            "\"unterminated",
            "'",
            "r#\"x",
            "/* open",
            "#![",
            "é: (ü",
            "/* é */ (a: [1, 2, 3, 4])",
            "(a: \"\\é\", b: 'é', c: '\\é', d: [0, 1, 2, 3])",
            "// ü\n(a: [0, 1, 2, 3])",
        ] {
            let _ = locate(src, &FieldPath::root().field("a").index(3));
            let _ = locate(src, &FieldPath::root().field("d").index(3));
        }
    }

    proptest::proptest! {
        #[test]
        fn never_panics_on_any_text(src in "\\PC{0,120}", i in 0usize..4) {
            let _ = locate(&src, &FieldPath::root().field("a").index(i).field("b"));
        }
    }
}
