//! Loading TOML input files (scenes and configurations) with errors a user can act on: one
//! line naming the file, the line and column, and the key path (`light[9999].direction`),
//! for a syntax error, a value of the wrong type or shape, and a value refused by validation
//! after parsing. Also the quoting of a bad line that the messages about other inputs (map
//! files, map streams) share, [`quoted`].

use anyhow::{bail, Result};
use serde::de::DeserializeOwned;
use std::ops::Range;
use std::path::Path;

/// A value refused by validation after parsing: the key path it sits at (as written in the
/// file, e.g. `light[2].direction`, `material.shininess`) and a message that names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Invalid {
    pub key: String,
    pub message: String,
}

impl Invalid {
    pub fn new(key: impl Into<String>, message: impl Into<String>) -> Invalid {
        Invalid {
            key: key.into(),
            message: message.into(),
        }
    }
}

impl std::fmt::Display for Invalid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Invalid {}

/// 1-based line and column (in characters) of byte offset `at` in `text`.
pub fn line_col(text: &str, at: usize) -> (usize, usize) {
    let mut at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[start..].chars().count() + 1)
}

/// The one-line form of any message: newlines and other control characters become spaces.
pub fn one_line(s: &str) -> String {
    let s: String = s
        .trim()
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    s
}

/// Characters of a bad line a message quotes: a line of a file that is not what it should be
/// may be megabytes long.
pub const QUOTED_MAX: usize = 32;

/// A bad line of an input (a map file's, a map stream's), quoted for a one-line message: cut
/// after [`QUOTED_MAX`] characters (`...` and its length in bytes follow).
pub fn quoted(t: &str) -> String {
    match t.char_indices().nth(QUOTED_MAX) {
        None => format!("{t:?}"),
        Some((cut, _)) => format!("{:?}... ({} bytes)", &t[..cut], t.len()),
    }
}

/// `what:line:col: ` (or `what: ` without a position).
fn place(what: &str, text: &str, span: Option<Range<usize>>) -> String {
    match span {
        Some(s) => {
            let (l, c) = line_col(text, s.start);
            format!("{what}:{l}:{c}")
        }
        None => what.to_string(),
    }
}

/// A message of [`place`] without its position (`what: message`): for TOML that rmapgen wrote
/// itself from another form (the Python package's keyword arguments, the explorer's fields),
/// whose lines the user never saw; the message still names the key.
pub fn without_place(msg: &str, what: &str) -> String {
    let Some(rest) = msg.strip_prefix(what) else {
        return msg.to_string();
    };
    let rest = rest.trim_start_matches(|c: char| c == ':' || c.is_ascii_digit());
    format!("{what}: {}", rest.trim_start())
}

/// One path segment: a table key or an array index.
enum Seg<'a> {
    Key(&'a str),
    Index(usize),
}

fn segments(path: &str) -> Option<Vec<Seg<'_>>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (name, mut rest) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if !name.is_empty() {
            out.push(Seg::Key(name));
        }
        while let Some(r) = rest.strip_prefix('[') {
            let end = r.find(']')?;
            out.push(Seg::Index(r[..end].parse().ok()?));
            rest = &r[end + 1..];
        }
    }
    Some(out)
}

/// The byte range of the value at `path` (`light[2].direction`) in the TOML `text`, or of
/// the deepest part of the path that exists.
pub fn span_of(text: &str, path: &str) -> Option<Range<usize>> {
    let root = toml::de::DeTable::parse(text).ok()?;
    let mut span = None;
    let top = toml::de::DeValue::Table(root.into_inner());
    let mut cur = &top;
    for seg in segments(path)? {
        let next = match seg {
            Seg::Key(k) => cur.get(k),
            Seg::Index(i) => cur.get(i),
        };
        match next {
            Some(v) => {
                span = Some(v.span());
                cur = v.get_ref();
            }
            None => break,
        }
    }
    span
}

/// Parses `text` as a `T`; an error is one line: `what:line:col: key.path: message`.
pub fn parse<T: DeserializeOwned>(text: &str, what: &str) -> Result<T> {
    let de = match toml::de::Deserializer::parse(text) {
        Ok(d) => d,
        Err(e) => bail!(syntax_error(text, what, &e)),
    };
    match serde_path_to_error::deserialize::<_, T>(de) {
        Ok(v) => Ok(v),
        Err(e) => {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let key = if path == "." || path.is_empty() {
                None
            } else {
                Some(path)
            };
            let span = inner
                .span()
                .or_else(|| key.as_deref().and_then(|k| span_of(text, k)));
            let mut msg = place(what, text, span);
            if let Some(k) = key {
                msg.push_str(&format!(": {k}"));
            }
            msg.push_str(&format!(": {}", one_line(inner.message())));
            bail!(msg)
        }
    }
}

/// A syntax error: where, the key whose value holds it, and the parser's message; `key =`
/// with nothing after it and an array item without a comma after it said plainly.
fn syntax_error(text: &str, what: &str, e: &toml::de::Error) -> String {
    let span = e.span();
    if let Some(s) = &span {
        let (l, _) = line_col(text, s.start);
        if let Some(line) = text.lines().nth(l - 1) {
            let code = line.split('#').next().unwrap_or("");
            if let Some((key, value)) = code.split_once('=') {
                let key = key.trim();
                if value.trim().is_empty()
                    && !key.is_empty()
                    && !key.contains(['[', ']', '"', '\''])
                {
                    let col = line.find('=').map_or(1, |i| line[..=i].chars().count() + 1);
                    return format!("{what}:{l}:{col}: {key} has no value; give one after '='");
                }
            }
        }
    }
    // The parser's message, with the key whose value it is about.
    let key = span.as_ref().and_then(|s| key_at(text, s.start));
    let mut msg = place(what, text, span.clone());
    if let Some(k) = &key {
        msg.push_str(&format!(": {}", k.path));
    }
    msg.push_str(&format!(": {}", one_line(e.message())));
    if let (Some(k), Some(s)) = (&key, &span) {
        if let Some((a, b)) = comma_missing(text, k, s) {
            msg.push_str(&format!(" (is a comma missing between {a} and {b}?)"));
        }
    }
    msg
}

/// The key whose value holds a syntax error, found in the text (which does not parse).
#[derive(Debug, PartialEq, Eq)]
struct KeyAt {
    /// As a key path is written elsewhere in messages: `light[0].direction`.
    path: String,
    /// Where its value (or the line of it that holds the error) starts, and how many arrays
    /// are open there.
    from: usize,
    depth: usize,
}

/// The key whose value holds byte `at` of TOML `text`, from the lines up to it: the table in
/// force (`[material]`, or the n-th `[[light]]` as `light[n-1]`) and the key of the value,
/// also when the value is an array over several lines. None when `at` is in no value (a
/// table header, a key).
fn key_at(text: &str, at: usize) -> Option<KeyAt> {
    let mut table = String::new();
    let mut counts: std::collections::HashMap<String, usize> = Default::default();
    // The key of a value that continues past its line (an open array), and its depth.
    let mut open: Option<(String, usize)> = None;
    let mut start = 0;
    for line in text.split_inclusive('\n') {
        let end = start + line.len();
        let here = (start..end).contains(&at);
        match open.take() {
            Some((key, depth)) => {
                if here {
                    return Some(KeyAt {
                        path: key,
                        from: start,
                        depth,
                    });
                }
                let depth = depth_after(&line[..code_len(line)], depth);
                if depth > 0 {
                    open = Some((key, depth));
                }
            }
            None => {
                let code = &line[..code_len(line)];
                let t = code.trim();
                if let Some(name) = t.strip_prefix("[[").and_then(|r| r.strip_suffix("]]")) {
                    let name = unquoted(name);
                    let n = counts.entry(name.clone()).or_insert(0);
                    table = format!("{name}[{n}]");
                    *n += 1;
                } else if let Some(name) = t.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
                    table = unquoted(name);
                } else if let Some(eq) = code.find('=') {
                    let key = unquoted(&code[..eq]);
                    let path = if table.is_empty() {
                        key
                    } else {
                        format!("{table}.{key}")
                    };
                    let value = start + eq + 1;
                    if here && at >= value {
                        return Some(KeyAt {
                            path,
                            from: value,
                            depth: 0,
                        });
                    }
                    let depth = depth_after(&code[eq + 1..], 0);
                    if depth > 0 {
                        open = Some((path, depth));
                    }
                }
                if here {
                    return None;
                }
            }
        }
        start = end;
    }
    None
}

/// A key as written (`direction`, `"a b"`, ` a . b `), without its quotes and spaces.
fn unquoted(key: &str) -> String {
    key.split('.')
        .map(|k| k.trim().trim_matches(|c| c == '"' || c == '\''))
        .collect::<Vec<_>>()
        .join(".")
}

/// The bytes of a line before its comment (a `#` outside a string).
fn code_len(line: &str) -> usize {
    let mut quote = None;
    for (i, c) in line.char_indices() {
        match (quote, c) {
            (None, '#') => return i,
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), _) if c == q => quote = None,
            _ => {}
        }
    }
    line.len()
}

/// The depth of open arrays after `code`, starting at `depth` (brackets in strings skipped).
fn depth_after(code: &str, mut depth: usize) -> usize {
    let mut quote = None;
    for c in code.chars() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), _) if c == q => quote = None,
            (None, '[') => depth += 1,
            (None, ']') => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    depth
}

/// The two items a syntax error at `span` runs together inside an array of the value of
/// `key`, when a comma between them is what is missing: the parser reads `[1.0 1.0, 2.0]` as
/// a bare string `1.0 1.0` ("string values must be quoted"), whose words are each a value.
fn comma_missing(text: &str, key: &KeyAt, span: &Range<usize>) -> Option<(String, String)> {
    let inside = depth_after(&text[key.from..span.start], key.depth) > 0;
    let words: Vec<&str> = text[span.clone()].split_whitespace().collect();
    let value = |w: &str| toml::from_str::<toml::Table>(&format!("v = {w}")).is_ok();
    (inside && words.len() >= 2 && words.iter().all(|w| value(w)))
        .then(|| (words[0].to_string(), words[1].to_string()))
}

/// A validation error located in the file: `what:line:col: message`.
pub fn invalid(text: &str, what: &str, e: &Invalid) -> anyhow::Error {
    let span = span_of(text, &e.key);
    anyhow::anyhow!("{}: {}", place(what, text, span), one_line(&e.message))
}

/// The largest TOML input read: a scene with 10,000 lights is about 1 MB, and parsing holds
/// several times the text in memory, so this keeps a wrong file (a volume, a log) from being
/// read whole.
pub const MAX_BYTES: u64 = 16 << 20;

/// Reads a TOML input file: refuses a directory, a file over [`MAX_BYTES`] or an unreadable
/// file in one line. `kind` is what the file holds ("scene", "config").
pub fn read(path: &Path, kind: &str) -> Result<String> {
    use std::io::Read;
    if path.is_dir() {
        bail!("{kind} {} is a directory, not a TOML file", path.display());
    }
    // Read one byte past the limit, so a file that grows while read is caught too.
    let read = std::fs::File::open(path).and_then(|f| {
        let mut bytes = Vec::new();
        f.take(MAX_BYTES + 1).read_to_end(&mut bytes).map(|_| bytes)
    });
    if read.as_ref().is_ok_and(|b| b.len() as u64 > MAX_BYTES) {
        bail!(
            "{kind} {} is larger than {} MiB, the limit for a TOML input",
            path.display(),
            MAX_BYTES >> 20
        );
    }
    match read {
        Ok(bytes) => match String::from_utf8(bytes) {
            Ok(s) => Ok(s),
            Err(e) => {
                let at = e.utf8_error().valid_up_to();
                let (l, c) = line_col(&String::from_utf8_lossy(e.as_bytes()), at);
                bail!(
                    "{kind} {}:{l}:{c}: not UTF-8 text (TOML files are UTF-8)",
                    path.display()
                )
            }
        },
        Err(e) => bail!("cannot read {kind} {}: {e}", path.display()),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_message_loses_its_position_and_keeps_its_key() {
        let what = "config";
        assert_eq!(
            super::without_place("config:3:1: grad_bits = 40 is out of range", what),
            "config: grad_bits = 40 is out of range"
        );
        assert_eq!(super::without_place("config: x", what), "config: x");
        assert_eq!(super::without_place("scene:2:5: y", what), "scene:2:5: y");
    }

    use super::*;

    #[test]
    fn lines_and_columns() {
        assert_eq!(line_col("ab\ncd\n", 0), (1, 1));
        assert_eq!(line_col("ab\ncd\n", 4), (2, 2));
        assert_eq!(line_col("é\nx", 3), (2, 1));
        assert_eq!(line_col("ab", 99), (1, 3));
    }

    /// A syntax error names the key whose value holds it, from the text that does not parse:
    /// through tables, the n-th array table, multi-line arrays, comments and quotes.
    #[test]
    fn a_syntax_error_names_its_key() {
        let err = |t: &str| {
            parse::<toml::Table>(t, "scene s.toml")
                .unwrap_err()
                .to_string()
        };
        let m = "[material]\nambient = 0.1\n";
        assert_eq!(
            err(&format!("{m}[[light]]\ndirection = [1.0, 1.0, 2.0]\n[[light]]\ndirection = [1.0 1.0, 2.0]\n")),
            "scene s.toml:6:14: light[1].direction: string values must be quoted, expected literal string (is a comma missing between 1.0 and 1.0?)"
        );
        // Over several lines, a comment with a bracket and a string with one on the way.
        assert_eq!(
            err(&format!("{m}[[light]] # [x]\nname = \"[a\"\ndirection = [\n  1.0, # ]\n  1.0 2.0,\n]\n")),
            "scene s.toml:7:3: light[0].direction: string values must be quoted, expected literal string (is a comma missing between 1.0 and 2.0?)"
        );
        // The parser's own missing-comma message; a key at the top; a table's key.
        assert_eq!(
            err("a = [\"x\" \"y\"]\n"),
            "scene s.toml:1:10: a: missing comma between array elements, expected `,`"
        );
        assert_eq!(
            err(&format!("{m}shininess = [1 2 3]\n")),
            "scene s.toml:3:14: material.shininess: string values must be quoted, expected literal string (is a comma missing between 1 and 2?)"
        );
        // Words that are no values are not a missing comma; outside an array neither.
        assert_eq!(
            err("v = [a b]\n"),
            "scene s.toml:1:6: v: string values must be quoted, expected literal string"
        );
        assert_eq!(
            err("v = 1 2\n"),
            "scene s.toml:1:5: v: string values must be quoted, expected literal string"
        );
        // In a header or a key: no key named.
        assert_eq!(
            err("a = 1\n[foo\n"),
            "scene s.toml:2:5: unclosed table, expected `]`"
        );
        assert_eq!(
            err("[t]\nb c = 1\n"),
            "scene s.toml:2:3: key with no value, expected `=`"
        );
        // Quoted and dotted keys as written, without quotes or spaces.
        assert_eq!(
            err("[\"my t\"]\n \"k\" . x = [1 2]\n"),
            "scene s.toml:2:13: my t.k.x: string values must be quoted, expected literal string (is a comma missing between 1 and 2?)"
        );
    }

    #[test]
    fn spans_of_key_paths() {
        let t = "a = 1\n[[light]]\nd = [1, 2]\n[[light]]\nd = [3]\n[m]\nx = 2\n";
        let s = span_of(t, "light[1].d").unwrap();
        assert_eq!(&t[s], "[3]");
        let s = span_of(t, "m.x").unwrap();
        assert_eq!(line_col(t, s.start), (7, 5));
        assert!(span_of(t, "nothing").is_none());
    }
}
