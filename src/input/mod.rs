//! Shared front end of the three input languages (deck, topology, force field).
//!
//! All three are line-oriented: one statement per line, `#` starts a comment,
//! a trailing `&` continues a statement on the next line, tokens are separated
//! by blanks, and `"double quoted"` tokens may contain blanks and `#`. The nom
//! grammar in `lexer` turns a file into [`Statement`]s of [`Token`]s that
//! remember their `line:col`, and every later error is an [`InputError`]
//! pointing at the offending token (`file:line:col: message`). Files are read
//! by [`read_input_file`]: regular files of at most [`MAX_INPUT_BYTES`]. Every
//! file read can be recorded, and later served from the record instead of the
//! disk ([`recording`], [`replaying`]): restarts carry a deck's inputs this way.
//!
//! One file-level circle remains, on purpose: `error.rs` ↔ `lexer.rs`. An
//! [`InputError`] points at a [`Token`] of a [`SourceFile`], and tokens make
//! their errors (`Token::error`); the error and the token are one vocabulary,
//! kept in two files for length.

mod error;
mod file;
mod lexer;
mod number;
mod sources;

pub use self::error::InputError;
pub use self::file::{check_input_file, read_input_file, MAX_INPUT_BYTES};
pub use self::lexer::{lex, statements, SourceFile, Statement, Statements, Token};
pub use self::number::{parse_f64, parse_u64};
pub use self::sources::{is_replaying, recording, replaying, DeckInputs, InputFile};
