//! nom grammar of the line-oriented input languages.
//!
//! ```text
//! file       := physical_line*
//! line       := blank* (token blank*)* ("#" any*)? EOL
//! token      := quoted | bare
//! quoted     := '"' [^"<control characters but tab>]* '"'
//! bare       := [^ #"<control characters>]+
//! comment    := [^<control characters but tab>]*
//! ```
//! A statement ends at the end of a line unless its last token is `&`, in
//! which case it continues on the next line. A control character other
//! than a tab (a NUL of a binary file, a lone carriage return, a terminal
//! escape `\x1b[…`) is an error wherever it stands, comments and quotes
//! included, and a diagnostic never shows one raw (see [`super::error`]).

use std::sync::Arc;

use nom::branch::alt;
use nom::bytes::complete::{tag, take_while, take_while1};
use nom::character::complete::{char, line_ending, space0};
use nom::combinator::{eof, opt};
use nom::multi::many0;
use nom::sequence::{delimited, preceded, terminated};
use nom::{IResult, Parser};
use nom_locate::LocatedSpan;

use super::error::InputError;
use super::file::read_input_file;

type Span<'a> = LocatedSpan<&'a str>;

/// The text of an input file, shared by every token and error taken from it.
#[derive(Debug)]
pub struct SourceFile {
    pub path: String,
    pub text: String,
    /// For a file named by another input (a topology, a force field, an
    /// `include`): the byte offset of its first word and the end of that
    /// word's line. Until that word is accepted the file may not be a cellmd
    /// input at all (`/etc/shadow` named as a topology), so an error there
    /// quotes none of it (see [`InputError::at`]).
    pub(crate) unrecognised: Option<(usize, usize)>,
}

/// A character a diagnostic must not print raw: a control character
/// other than tab and newline, or a bidirectional-text control (which
/// reorders what a terminal shows).
pub(crate) fn is_unprintable(c: char) -> bool {
    (c.is_control() && c != '\t' && c != '\n')
        || matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{061c}')
}

/// Where the first word of `text` starts, and the end of its line.
fn first_word_line(text: &str) -> (usize, usize) {
    let mut start = 0;
    for line in text.split_inclusive('\n') {
        let body = line.trim_end_matches(['\n', '\r']);
        if let Some(k) = body.find(|c: char| c != ' ' && c != '\t') {
            if !body[k..].starts_with('#') {
                return (start + k, start + body.len());
            }
        }
        start += line.len();
    }
    (text.len(), text.len())
}

impl SourceFile {
    pub fn new(path: impl Into<String>, text: impl Into<String>) -> Arc<Self> {
        Arc::new(Self { path: path.into(), text: text.into(), unrecognised: None })
    }

    /// A file named by another input (see [`Self::unrecognised`]).
    fn named(path: String, text: String) -> Arc<Self> {
        let unrecognised = Some(first_word_line(&text));
        Arc::new(Self { path, text, unrecognised })
    }

    /// Reads a file (see [`read_input_file`]); a missing, unreadable,
    /// non-regular or too large file is an error at `requested_by`, a byte
    /// that is not UTF-8 an error at its own line and column.
    pub fn read(path: &std::path::Path, requested_by: Option<&Token>) -> Result<Arc<Self>, InputError> {
        let shown = path.display().to_string();
        let fail = |why: String| {
            let message = format!("cannot read `{shown}`: {why}");
            match requested_by {
                Some(token) => InputError::at(token, message),
                None => InputError::in_file(&shown, message),
            }
        };
        // A restart's recorded copy stands in for the disk when replaying.
        let text = match super::sources::replayed(&shown) {
            Some(replayed) => replayed.map_err(fail)?,
            None => match String::from_utf8(read_input_file(path).map_err(fail)?) {
                Ok(text) => text,
                Err(e) => {
                    let valid = e.utf8_error().valid_up_to();
                    let byte = e.as_bytes()[valid];
                    let text = String::from_utf8_lossy(&e.as_bytes()[..valid]).into_owned();
                    let prefix = if requested_by.is_some() { Self::named(shown, text) } else { Self::new(shown, text) };
                    return Err(InputError::at_offset(
                        &prefix,
                        valid,
                        format!("found byte 0x{byte:02X}, which is not UTF-8; expected a UTF-8 text file"),
                    ));
                }
            },
        };
        super::sources::note(&shown, &text);
        Ok(if requested_by.is_some() { Self::named(shown, text) } else { Self::new(shown, text) })
    }

    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (u32, u32) {
        let before = &self.text[..offset.min(self.text.len())];
        let line = before.matches('\n').count() as u32 + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        (line, before[line_start..].chars().count() as u32 + 1)
    }
}

/// A word of input with its position.
#[derive(Debug, Clone)]
pub struct Token {
    pub text: String,
    pub line: u32,
    pub col: u32,
    pub(crate) offset: usize,
    pub(crate) text_len: usize,
    pub file: Arc<SourceFile>,
}

impl Token {
    /// A copy of this token with replaced text (after `${var}` substitution);
    /// it keeps pointing at the original position.
    pub fn with_text(&self, text: String) -> Token {
        Token { text, ..self.clone() }
    }

    pub fn error(&self, message: impl Into<String>) -> InputError {
        InputError::at(self, message)
    }

    /// An error at byte `at` of this token's text: at that very column when
    /// the text is still the file's (not changed by `${var}` substitution),
    /// else at the token.
    pub fn error_within(&self, at: usize, message: impl Into<String>) -> InputError {
        let quoted = usize::from(self.text_len == self.text.len() + 2);
        let start = self.offset + quoted;
        let unchanged = self.file.text.get(start..start + self.text.len()) == Some(self.text.as_str());
        if unchanged && at <= self.text.len() {
            InputError::at_offset(&self.file, start + at, message)
        } else {
            InputError::at(self, message)
        }
    }
}

/// One logical statement: its tokens, never empty.
#[derive(Debug, Clone)]
pub struct Statement {
    pub tokens: Vec<Token>,
}

impl Statement {
    pub fn keyword(&self) -> &Token {
        &self.tokens[0]
    }
}

/// What may stand in quotes and comments: anything but control characters (tab is fine).
fn printable(c: char) -> bool {
    c == '\t' || !c.is_control()
}

fn quoted(input: Span) -> IResult<Span, Span> {
    delimited(char('"'), take_while(|c| c != '"' && printable(c)), char('"')).parse(input)
}

/// Control characters (a NUL of a binary file, a lone carriage return)
/// end a word and are then refused by the line's end.
fn bare(input: Span) -> IResult<Span, Span> {
    take_while1(|c: char| !c.is_control() && !matches!(c, ' ' | '#' | '"')).parse(input)
}

/// A token with a flag telling whether it was quoted.
fn token(input: Span) -> IResult<Span, (Span, bool)> {
    alt((quoted.map(|s| (s, true)), bare.map(|s| (s, false)))).parse(input)
}

/// Tokens of one physical line, then the optional comment (not the line
/// end), and whether there was one.
fn physical_line(input: Span) -> IResult<Span, (Vec<(Span, bool)>, bool)> {
    (preceded(space0, many0(terminated(token, space0))), opt(preceded(tag("#"), take_while(printable))))
        .map(|(words, comment)| (words, comment.is_some()))
        .parse(input)
}

/// Why a line stops short of its end at `after` (its first unread character).
fn stopped_at(file: &Arc<SourceFile>, after: Span, in_comment: bool) -> InputError {
    let rest = *after.fragment();
    let found = rest.chars().next().unwrap_or(' ');
    let control = |what: &str, c: char, offset: usize| {
        InputError::at_offset(
            file,
            offset,
            format!(
                "found control character `{}` {what}; expected printable text (control characters other than tab are an error)",
                c.escape_unicode()
            ),
        )
    };
    if found == '"' {
        let body = &rest[1..];
        if let Some((k, c)) = body.char_indices().find(|&(_, c)| c == '"' || !printable(c)) {
            if c != '"' && c != '\n' && !body[k..].starts_with("\r\n") {
                return control("inside quotes", c, after.location_offset() + 1 + k);
            }
        }
        return InputError::at_offset(
            file,
            after.location_offset(),
            "unterminated quoted string; expected a closing `\"` on the same line",
        );
    }
    if in_comment {
        return control("in a comment", found, after.location_offset());
    }
    InputError::at_offset(file, after.location_offset(), format!("unexpected `{}`; expected a blank-separated word", found.escape_debug()))
}

/// Splits a file into statements.
pub fn lex(file: &Arc<SourceFile>) -> Result<Vec<Statement>, InputError> {
    statements(file).collect()
}

/// The statements of a file, lexed one at a time as the caller asks for
/// them: a large topology is parsed without ever holding all its tokens
/// (about 14 per bead of a network, ~90 bytes each).
pub fn statements(file: &Arc<SourceFile>) -> Statements<'_> {
    Statements { file, input: Span::new(file.text.as_str()), failed: false }
}

/// Iterator of [`statements`]; it stops after the first error.
pub struct Statements<'a> {
    file: &'a Arc<SourceFile>,
    input: Span<'a>,
    failed: bool,
}

impl Iterator for Statements<'_> {
    type Item = Result<Statement, InputError>;

    fn next(&mut self) -> Option<Self::Item> {
        let file = self.file;
        let mut pending: Vec<Token> = Vec::new();
        while !self.failed && !self.input.fragment().is_empty() {
            let input = self.input;
            let line = physical_line(input)
                .map_err(|_| InputError::at_offset(file, input.location_offset(), "unreadable line; expected blank-separated words"))
                .and_then(|(after, (words, comment))| {
                    let (after, _) = alt((line_ending, eof))
                        .parse(after)
                        .map_err(|_: nom::Err<nom::error::Error<Span>>| stopped_at(file, after, comment))?;
                    Ok((after, words))
                });
            let (after, words) = match line {
                Ok(line) => line,
                Err(e) => {
                    self.failed = true;
                    return Some(Err(e));
                }
            };
            self.input = after;
            // Columns are counted from the previous token on the line, so a
            // line is scanned once however many tokens it has (nom_locate's
            // column rescans from the line start: quadratic in its length).
            let (mut at, mut col) = (input.location_offset(), 1usize);
            let mut tokens: Vec<Token> = words
                .into_iter()
                .map(|(span, quoted)| {
                    let token_offset = span.location_offset() - usize::from(quoted);
                    col += file.text[at..token_offset].chars().count();
                    at = token_offset;
                    Token {
                        text: span.fragment().to_string(),
                        line: span.location_line(),
                        col: col as u32,
                        offset: token_offset,
                        text_len: span.fragment().len() + 2 * usize::from(quoted),
                        file: file.clone(),
                    }
                })
                .collect();
            let continues = tokens.last().is_some_and(|t| t.text == "&");
            if continues {
                tokens.pop();
            }
            pending.extend(tokens);
            if !continues && !pending.is_empty() {
                return Some(Ok(Statement { tokens: pending }));
            }
        }
        (!pending.is_empty()).then_some(Ok(Statement { tokens: pending }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(text: &str) -> Vec<Vec<(String, u32, u32)>> {
        let file = SourceFile::new("t.in", text);
        lex(&file).unwrap().into_iter().map(|s| s.tokens.into_iter().map(|t| (t.text, t.line, t.col)).collect()).collect()
    }

    #[test]
    fn comments_blanks_quotes_and_continuations() {
        let got = words("# header\nrun 100  # go\n\n  dump a every 10 &\n   xyz \"my file.xyz\"\n");
        assert_eq!(
            got,
            vec![
                vec![("run".into(), 2, 1), ("100".into(), 2, 5)],
                vec![
                    ("dump".into(), 4, 3),
                    ("a".into(), 4, 8),
                    ("every".into(), 4, 10),
                    ("10".into(), 4, 16),
                    ("xyz".into(), 5, 4),
                    ("my file.xyz".into(), 5, 8),
                ],
            ]
        );
    }

    #[test]
    fn a_long_line_lexes_in_linear_time() {
        // 1 MB of one-character words on one line took 26 s when each token's
        // column was counted from the line start; now well under a second.
        let line = "x ".repeat(500_000);
        let file = SourceFile::new("t.in", format!("{line}y\n"));
        let started = std::time::Instant::now();
        let statements = lex(&file).unwrap();
        let seconds = started.elapsed().as_secs_f64();
        let last = statements[0].tokens.last().unwrap();
        assert_eq!((last.text.as_str(), last.line, last.col), ("y", 1, 1_000_001));
        assert!(seconds < 2.0, "lexing a 1 MB line took {seconds} s");
    }

    #[test]
    fn control_characters_and_bad_bytes_are_located() {
        let file = SourceFile::new("t.in", "run 1\nrun\u{0}1\n");
        assert_eq!(lex(&file).unwrap_err().to_string(), "t.in:2:4: unexpected `\\0`; expected a blank-separated word");
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.in");
        std::fs::write(&path, b"run 1\nrun 2\xff\n").unwrap();
        let err = SourceFile::read(&path, None).unwrap_err();
        assert_eq!(err.to_string(), format!("{}:2:6: found byte 0xFF, which is not UTF-8; expected a UTF-8 text file", path.display()));
    }

    #[test]
    fn unterminated_quote_is_located() {
        let file = SourceFile::new("t.in", "run 1\ndump \"oops\n");
        let err = lex(&file).unwrap_err();
        assert_eq!(err.to_string(), "t.in:2:6: unterminated quoted string; expected a closing `\"` on the same line");
    }
}
