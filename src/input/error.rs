//! `file:line:col` diagnostics for every input language.
//!
//! An error shows one line of its file, clipped to [`SNIPPET_CHARS`]
//! characters around the offending token, and quotes (between backticks) at
//! most [`QUOTE_CHARS`] characters of any token: naming a password file or a
//! process environment as a topology echoes one clipped word and line of it,
//! never more of the file, and an error at column 10⁶ of a 1 MB line renders
//! as quickly and as narrowly as one at column 1.
//!
//! Files named by another input (topologies, force fields, `include`s) show
//! even less until their first word is accepted: an error at that word, or
//! on its line, shows no line and quotes none of it (`/etc/shadow` named as
//! a topology is "not shown: it does not read as a cellmd input"). And no
//! diagnostic prints a control character or a bidirectional-text control
//! raw: the shown line has `?` (or `¿`, `�`: the same number of bytes) in
//! their place, a message their `\u{…}` escape.

use std::fmt;

use miette::{Diagnostic, LabeledSpan, MietteError, MietteSpanContents, SourceCode, SourceSpan, SpanContents};

use super::lexer::{is_unprintable, SourceFile, Token};

/// Characters of the offending line an error shows, at most.
pub const SNIPPET_CHARS: usize = 80;
/// Characters of a quoted token an error message keeps, at most.
pub const QUOTE_CHARS: usize = 80;
/// Characters shown before the offending token when its line is clipped.
const LEAD_CHARS: usize = 20;

/// An input error at a position in a file: what was found and what was expected.
#[derive(Debug, Clone)]
pub struct InputError {
    pub path: String,
    pub line: u32,
    pub col: u32,
    pub message: String,
    snippet: Option<Box<Snippet>>,
}

/// The clipped line an error shows, with the span it underlines (byte
/// offsets into the whole file, as miette expects).
#[derive(Debug, Clone)]
struct Snippet {
    path: String,
    text: String,
    /// Byte offset of `text` in the file, its 0-based line and column (in characters).
    start: usize,
    line: usize,
    col: usize,
    label: (usize, usize),
}

impl Snippet {
    /// The line of `file` around `offset..offset + len`, clipped.
    fn new(file: &SourceFile, offset: usize, len: usize, line: u32) -> Self {
        let text = file.text.as_str();
        let offset = floor_char_boundary(text, offset.min(text.len()));
        let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
        let line_end = text[offset..].find(['\n', '\r']).map_or(text.len(), |i| offset + i);
        let lead = text[line_start..offset].char_indices().rev().nth(LEAD_CHARS - 1).map_or(line_start, |(i, _)| line_start + i);
        let end = text[lead..line_end].char_indices().nth(SNIPPET_CHARS).map_or(line_end, |(i, _)| lead + i);
        let label_end = (offset + len).min(end).max(offset);
        let skipped = text[line_start..lead].chars().count();
        Self {
            path: file.path.clone(),
            text: printable_line(&text[lead..end]),
            start: lead,
            line: line as usize - 1,
            col: skipped,
            label: (offset, label_end - offset),
        }
    }
}

/// `line` with each character a terminal must not get raw replaced by one
/// of the same UTF-8 length, so byte offsets into the line still hold.
fn printable_line(line: &str) -> String {
    line.chars().map(|c| if is_unprintable(c) { ['?', '¿', '�', '�'][c.len_utf8() - 1] } else { c }).collect()
}

/// `message` with each character a terminal must not get raw escaped.
fn printable_message(message: String) -> String {
    if !message.chars().any(is_unprintable) {
        return message;
    }
    message.chars().map(|c| if is_unprintable(c) { c.escape_unicode().to_string() } else { c.to_string() }).collect()
}

fn floor_char_boundary(text: &str, mut i: usize) -> usize {
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

impl SourceCode for Snippet {
    fn read_span<'a>(&'a self, span: &SourceSpan, _: usize, _: usize) -> Result<Box<dyn SpanContents<'a> + 'a>, MietteError> {
        // The whole clipped line is the context of any span in it; the
        // column is that of the span's start.
        let into = span.offset().clamp(self.start, self.start + self.text.len()) - self.start;
        let col = self.col + self.text[..floor_char_boundary(&self.text, into)].chars().count();
        let whole = SourceSpan::new(self.start.into(), self.text.len());
        Ok(Box::new(MietteSpanContents::new_named(self.path.clone(), self.text.as_bytes(), whole, self.line, col, 1)))
    }
}

/// Shortens every backtick-quoted part of a message to [`QUOTE_CHARS`].
fn clip_quotes(message: String) -> String {
    let parts: Vec<&str> = message.split('`').collect();
    if parts.iter().skip(1).step_by(2).all(|quoted| quoted.chars().count() <= QUOTE_CHARS) {
        return message;
    }
    let clipped: Vec<String> = parts
        .iter()
        .enumerate()
        .map(|(i, part)| match part.char_indices().nth(QUOTE_CHARS) {
            Some((cut, _)) if i % 2 == 1 => format!("{}… ({} characters)", &part[..cut], part.chars().count()),
            _ => part.to_string(),
        })
        .collect();
    clipped.join("`")
}

/// Whether an error at `offset` of `file` falls where the file has not yet
/// shown itself to be a cellmd input (see [`SourceFile::unrecognised`]).
fn unrecognised(file: &SourceFile, offset: usize) -> bool {
    file.unrecognised.is_some_and(|(_, line_end)| offset <= line_end)
}

/// `message` with every backtick quote of the text of `line` replaced by
/// `…`, and a note why.
fn without_content(message: String, line: &str) -> String {
    let parts: Vec<&str> = message.split('`').collect();
    let hidden: Vec<&str> =
        parts.iter().enumerate().map(|(i, part)| if i % 2 == 1 && !part.is_empty() && line.contains(part) { "…" } else { part }).collect();
    format!("{} (the file's first line is not shown: it does not read as a cellmd input)", hidden.join("`"))
}

impl InputError {
    /// An error at a token. At the first word of a file named by another
    /// input, nothing of the file is shown (see the module docs).
    pub fn at(token: &Token, message: impl Into<String>) -> Self {
        let file = &token.file;
        let (message, snippet) = match file.unrecognised {
            Some((first, line_end)) if token.offset == first => (without_content(message.into(), &file.text[first..line_end]), None),
            _ => (message.into(), Some(Box::new(Snippet::new(file, token.offset, token.text_len.max(1), token.line)))),
        };
        Self { path: file.path.clone(), line: token.line, col: token.col, message: printable_message(clip_quotes(message)), snippet }
    }

    /// An error at a position of a file (used by the lexer).
    pub fn at_offset(file: &SourceFile, offset: usize, message: impl Into<String>) -> Self {
        let (line, col) = file.line_col(offset);
        let snippet = (!unrecognised(file, offset)).then(|| Box::new(Snippet::new(file, offset, 1, line)));
        Self { path: file.path.clone(), line, col, message: printable_message(clip_quotes(message.into())), snippet }
    }

    /// An error about a whole file (e.g. it cannot be read); reported at 1:1.
    pub fn in_file(path: &str, message: impl Into<String>) -> Self {
        Self { path: path.to_string(), line: 1, col: 1, message: printable_message(clip_quotes(message.into())), snippet: None }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}: {}", self.path, self.line, self.col, self.message)
    }
}

impl std::error::Error for InputError {}

impl Diagnostic for InputError {
    fn source_code(&self) -> Option<&dyn SourceCode> {
        self.snippet.as_deref().map(|s| s as &dyn SourceCode)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        let (offset, len) = self.snippet.as_ref()?.label;
        Some(Box::new(std::iter::once(LabeledSpan::at(offset..offset + len, "here"))))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    /// The error rendered as the CLI prints it (miette's graphical report, no colours).
    fn rendered(error: InputError) -> String {
        let mut out = String::new();
        miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor()).render_report(&mut out, &error).unwrap();
        out
    }

    fn error_at(text: &str, offset: usize) -> InputError {
        let file: Arc<SourceFile> = SourceFile::new("t.in", text);
        InputError::at_offset(&file, offset, "found `x`, expected y")
    }

    #[test]
    fn renders_at_the_limits() {
        // A column beyond 65 536 (it made the renderer panic), an error at the
        // end of a 1 MB line and of the file, an empty file, tabs and
        // multi-byte characters before the error.
        let wide = format!("{}x", " ".repeat(70_000));
        let long_line = "a".repeat(1 << 20);
        let cases: Vec<(String, usize, (u32, u32))> = vec![
            (wide.clone(), 70_000, (1, 70_001)),
            (long_line.clone(), 1 << 20, (1, (1 << 20) + 1)),
            (format!("run 1\n{long_line}\n"), 6 + 1000, (2, 1001)),
            (String::new(), 0, (1, 1)),
            ("run 1\n".into(), 6, (2, 1)),
            ("\t\trun\t1 µm ±\n".into(), 14, (1, 13)),
            ("é".repeat(50_000), 60_000, (1, 30_001)),
        ];
        for (text, offset, (line, col)) in cases {
            let error = error_at(&text, offset);
            assert_eq!((error.line, error.col), (line, col), "{}", text.len());
            let report = rendered(error);
            let widest = report.lines().map(|l| l.chars().count()).max().unwrap();
            assert!(widest < SNIPPET_CHARS + 60, "a {widest}-character line in\n{report}");
            assert!(report.contains(&format!("[t.in:{line}:{col}]")), "{report}");
        }
    }

    #[test]
    fn renders_an_error_at_a_byte_that_is_not_utf8() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.top");
        std::fs::write(&path, [b"[ particles ]\n1 a \t0 0 ".as_slice(), &[0xff, 0xfe], b" 0\n"].concat()).unwrap();
        let error = SourceFile::read(&path, None).unwrap_err();
        assert_eq!((error.line, error.col), (2, 10));
        let report = rendered(error);
        assert!(report.contains(":2:10]") && report.contains("found byte 0xFF, which is not UTF-8"), "{report}");
    }

    #[test]
    fn quotes_at_most_one_clipped_token_and_line() {
        let secret: String = (0..200).map(|i| format!("line{i} secret{i}\n")).collect();
        let file = SourceFile::new("passwd", format!("root:x:0:0:{}\n{secret}", "r".repeat(500)));
        let token = crate::input::lex(&file).unwrap().remove(0).tokens.remove(0);
        let error = InputError::at(&token, format!("found `{}` before any section", token.text));
        assert!(error.to_string().starts_with(&format!("passwd:1:1: found `root:x:0:0:{}… (511 characters)` before", "r".repeat(69))));
        let report = rendered(error);
        assert!(!report.contains("secret"), "{report}");
        assert!(report.lines().all(|l| l.chars().count() < SNIPPET_CHARS + 60 + 40), "{report}");
    }
}
