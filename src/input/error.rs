//! `file:line:col` diagnostics for every input language.

use std::fmt;
use std::sync::Arc;

use miette::{Diagnostic, LabeledSpan, NamedSource, SourceCode};

use super::lexer::{SourceFile, Token};

/// An input error at a position in a file: what was found and what was expected.
#[derive(Debug, Clone)]
pub struct InputError {
    pub path: String,
    pub line: u32,
    pub col: u32,
    pub message: String,
    source: Option<(Arc<SourceFile>, usize, usize)>,
}

impl InputError {
    /// An error at a token.
    pub fn at(token: &Token, message: impl Into<String>) -> Self {
        Self {
            path: token.file.path.clone(),
            line: token.line,
            col: token.col,
            message: message.into(),
            source: Some((token.file.clone(), token.offset, token.text_len.max(1))),
        }
    }

    /// An error at a position of a file (used by the lexer).
    pub fn at_offset(file: &Arc<SourceFile>, offset: usize, message: impl Into<String>) -> Self {
        let (line, col) = file.line_col(offset);
        Self { path: file.path.clone(), line, col, message: message.into(), source: Some((file.clone(), offset, 1)) }
    }

    /// An error about a whole file (e.g. it cannot be read); reported at 1:1.
    pub fn in_file(path: &str, message: impl Into<String>) -> Self {
        Self { path: path.to_string(), line: 1, col: 1, message: message.into(), source: None }
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
        self.source.as_ref().map(|(file, _, _)| &file.named as &dyn SourceCode)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        let (_, offset, len) = self.source.as_ref()?;
        Some(Box::new(std::iter::once(LabeledSpan::at(*offset..*offset + *len, "here"))))
    }
}

/// Convenience for building a [`NamedSource`] for a file's text.
pub(crate) fn named_source(path: &str, text: &str) -> NamedSource<String> {
    NamedSource::new(path, text.to_string())
}
