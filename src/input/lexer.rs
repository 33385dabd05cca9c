//! nom grammar of the line-oriented input languages.
//!
//! ```text
//! file       := physical_line*
//! line       := blank* (token blank*)* ("#" any*)? EOL
//! token      := quoted | bare
//! quoted     := '"' [^"\n]* '"'
//! bare       := [^ \t\r\n#"]+
//! ```
//! A statement ends at the end of a line unless its last token is `&`, in
//! which case it continues on the next line.

use std::sync::Arc;

use miette::NamedSource;
use nom::branch::alt;
use nom::bytes::complete::{is_not, tag, take_while};
use nom::character::complete::{char, line_ending, not_line_ending, space0};
use nom::combinator::{eof, opt};
use nom::multi::many0;
use nom::sequence::{delimited, preceded, terminated};
use nom::{IResult, Parser};
use nom_locate::LocatedSpan;

use super::error::{named_source, InputError};

type Span<'a> = LocatedSpan<&'a str>;

/// The text of an input file, shared by every token and error taken from it.
#[derive(Debug)]
pub struct SourceFile {
    pub path: String,
    pub text: String,
    pub(crate) named: NamedSource<String>,
}

impl SourceFile {
    pub fn new(path: impl Into<String>, text: impl Into<String>) -> Arc<Self> {
        let path = path.into();
        let text = text.into();
        let named = named_source(&path, &text);
        Arc::new(Self { path, text, named })
    }

    /// Reads a file; a missing or unreadable file is an error at `requested_by`.
    pub fn read(path: &std::path::Path, requested_by: Option<&Token>) -> Result<Arc<Self>, InputError> {
        let shown = path.display().to_string();
        match std::fs::read_to_string(path) {
            Ok(text) => Ok(Self::new(shown, text)),
            Err(e) => {
                let message = format!("cannot read `{shown}`: {e}; expected an existing, readable text file");
                Err(match requested_by {
                    Some(token) => InputError::at(token, message),
                    None => InputError::in_file(&shown, message),
                })
            }
        }
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

fn quoted(input: Span) -> IResult<Span, Span> {
    delimited(char('"'), take_while(|c| c != '"' && c != '\n'), char('"')).parse(input)
}

fn bare(input: Span) -> IResult<Span, Span> {
    is_not(" \t\r\n#\"").parse(input)
}

/// A token with a flag telling whether it was quoted.
fn token(input: Span) -> IResult<Span, (Span, bool)> {
    alt((quoted.map(|s| (s, true)), bare.map(|s| (s, false)))).parse(input)
}

/// Tokens of one physical line, then the optional comment (not the line end).
fn physical_line(input: Span) -> IResult<Span, Vec<(Span, bool)>> {
    terminated(preceded(space0, many0(terminated(token, space0))), opt(preceded(tag("#"), not_line_ending))).parse(input)
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
                .and_then(|(after, words)| {
                    let (after, _) = alt((line_ending, eof)).parse(after).map_err(|_: nom::Err<nom::error::Error<Span>>| {
                        let found = after.fragment().chars().next().unwrap_or(' ');
                        let message = if found == '"' {
                            "unterminated quoted string; expected a closing `\"` on the same line".to_string()
                        } else {
                            format!("unexpected `{}`; expected a blank-separated word", found.escape_debug())
                        };
                        InputError::at_offset(file, after.location_offset(), message)
                    })?;
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
            let mut tokens: Vec<Token> = words
                .into_iter()
                .map(|(span, quoted)| {
                    let token_offset = span.location_offset() - usize::from(quoted);
                    // The span knows its line; its column is counted from the line
                    // start only (`line_col` would rescan the file: O(N²) in all).
                    Token {
                        text: span.fragment().to_string(),
                        line: span.location_line(),
                        col: (span.get_utf8_column() - usize::from(quoted)) as u32,
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
    fn unterminated_quote_is_located() {
        let file = SourceFile::new("t.in", "run 1\ndump \"oops\n");
        let err = lex(&file).unwrap_err();
        assert_eq!(err.to_string(), "t.in:2:6: unterminated quoted string; expected a closing `\"` on the same line");
    }
}
