//! Shared front end of the three input languages (deck, topology, force field).
//!
//! All three are line-oriented: one statement per line, `#` starts a comment,
//! a trailing `&` continues a statement on the next line, tokens are separated
//! by blanks, and `"double quoted"` tokens may contain blanks and `#`. The nom
//! grammar in [`lexer`] turns a file into [`Statement`]s of [`Token`]s that
//! remember their `line:col`, and every later error is an [`InputError`]
//! pointing at the offending token (`file:line:col: message`).

mod error;
mod lexer;
mod number;

pub use self::error::InputError;
pub use self::lexer::{lex, statements, SourceFile, Statement, Statements, Token};
pub use self::number::{parse_f64, parse_u64};
