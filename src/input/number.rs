//! Numbers in tokens (nom). Expressions are [`crate::expr`]'s.

use nom::combinator::all_consuming;
use nom::number::complete::double;
use nom::{IResult, Parser};

use super::{InputError, Token};

/// A finite real number; `what` says what the token should be.
pub fn parse_f64(token: &Token, what: &str) -> Result<f64, InputError> {
    let parsed: IResult<&str, f64> = all_consuming(double).parse(token.text.as_str());
    match parsed {
        Ok((_, v)) if v.is_finite() && !token.text.to_ascii_lowercase().contains("inf") => Ok(v),
        Ok(_) => Err(token.error(format!("found `{}`, expected {what} (a finite number)", token.text))),
        Err(_) => Err(token.error(format!("found `{}`, expected {what} (a number)", token.text))),
    }
}

/// A non-negative integer; `what` says what the token should be.
pub fn parse_u64(token: &Token, what: &str) -> Result<u64, InputError> {
    let parsed: IResult<&str, u64> = all_consuming(nom::character::complete::u64).parse(token.text.as_str());
    parsed.map(|(_, v)| v).map_err(|_| token.error(format!("found `{}`, expected {what} (a non-negative integer)", token.text)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::SourceFile;

    fn token(text: &str) -> Token {
        let file = SourceFile::new("t", text);
        crate::input::lex(&file).unwrap()[0].tokens[0].clone()
    }

    #[test]
    fn numbers() {
        assert_eq!(parse_f64(&token("1.5e-3"), "x").unwrap(), 1.5e-3);
        assert!(parse_f64(&token("nan"), "x").unwrap_err().to_string().contains("finite"));
        assert!(parse_f64(&token("inf"), "x").is_err());
        assert!(parse_f64(&token("1.0x"), "a timestep").unwrap_err().to_string().contains("expected a timestep"));
        assert_eq!(parse_u64(&token("42"), "n").unwrap(), 42);
        assert!(parse_u64(&token("-1"), "n").is_err());
    }
}
