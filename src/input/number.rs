//! Numbers and the arithmetic of deck `variable ... equal` expressions (nom).
//!
//! ```text
//! expr   := term (("+" | "-") term)*
//! term   := factor (("*" | "/") factor)*
//! factor := unary ("^" factor)?          (right-associative power)
//! unary  := "-" unary | "(" expr ")" | number | pi
//! ```
//! Parentheses, unary minus signs and powers nest at most [`MAX_NESTING`]
//! deep together: the parser is recursive, and 40 000 nested parentheses
//! overflowed the stack.

use nom::branch::alt;
use nom::bytes::complete::tag;
use nom::character::complete::{char, multispace0, one_of};
use nom::combinator::{all_consuming, map};
use nom::multi::many0;
use nom::number::complete::double;
use nom::sequence::{delimited, pair, preceded};
use nom::{IResult, Parser};

use super::{InputError, Token};

/// How deep `(`, unary `-` and `^` may nest in one expression.
pub const MAX_NESTING: usize = 64;

thread_local! {
    /// Nesting depth of the expression being parsed, and whether it went
    /// beyond [`MAX_NESTING`] (the parse then fails).
    static NESTING: std::cell::Cell<(usize, bool)> = const { std::cell::Cell::new((0, false)) };
}

/// Runs a recursive rule one level deeper, failing past [`MAX_NESTING`].
fn nested<'a, O>(input: &'a str, rule: impl FnOnce(&'a str) -> IResult<&'a str, O>) -> IResult<&'a str, O> {
    let (depth, too_deep) = NESTING.get();
    if depth >= MAX_NESTING {
        NESTING.set((depth, true));
        return Err(nom::Err::Failure(nom::error::Error::new(input, nom::error::ErrorKind::TooLarge)));
    }
    NESTING.set((depth + 1, too_deep));
    let result = rule(input);
    NESTING.set((depth, NESTING.get().1));
    result
}

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

fn ws<'a, O>(
    inner: impl Parser<&'a str, Output = O, Error = nom::error::Error<&'a str>>,
) -> impl Parser<&'a str, Output = O, Error = nom::error::Error<&'a str>> {
    delimited(multispace0, inner, multispace0)
}

fn unary(input: &str) -> IResult<&str, f64> {
    nested(input, unary_rule)
}

fn unary_rule(input: &str) -> IResult<&str, f64> {
    alt((
        map(preceded(ws(char('-')), unary), |v| -v),
        delimited(ws(char('(')), expr, ws(char(')'))),
        map(ws(tag("pi")), |_| std::f64::consts::PI),
        ws(double),
    ))
    .parse(input)
}

fn factor(input: &str) -> IResult<&str, f64> {
    let (input, base) = unary(input)?;
    match preceded(ws(char('^')), |i| nested(i, factor)).parse(input) {
        Ok((input, exponent)) => Ok((input, base.powf(exponent))),
        Err(_) => Ok((input, base)),
    }
}

fn term(input: &str) -> IResult<&str, f64> {
    let (input, first) = factor(input)?;
    let (input, rest) = many0(pair(ws(one_of("*/")), factor)).parse(input)?;
    Ok((input, rest.into_iter().fold(first, |acc, (op, v)| if op == '*' { acc * v } else { acc / v })))
}

fn expr(input: &str) -> IResult<&str, f64> {
    let (input, first) = term(input)?;
    let (input, rest) = many0(pair(ws(one_of("+-")), term)).parse(input)?;
    Ok((input, rest.into_iter().fold(first, |acc, (op, v)| if op == '+' { acc + v } else { acc - v })))
}

/// Evaluates an arithmetic expression to a finite number.
pub fn evaluate_expression(text: &str) -> Result<f64, String> {
    NESTING.set((0, false));
    let parsed = all_consuming(expr).parse(text);
    if NESTING.get().1 {
        return Err(format!(
            "found an expression nested more than {MAX_NESTING} deep (parentheses, unary `-` and `^` together); expected a flatter expression"
        ));
    }
    match parsed {
        Ok((_, v)) if v.is_finite() => Ok(v),
        Ok((_, v)) => Err(format!("`{text}` evaluates to {v}; expected a finite number")),
        Err(_) => Err(format!("found `{text}`, expected an arithmetic expression of numbers, + - * / ^ and parentheses")),
    }
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

    #[test]
    fn expressions() {
        assert_eq!(evaluate_expression("1 + 2*3").unwrap(), 7.0);
        assert_eq!(evaluate_expression("(1+2)*3 - -1").unwrap(), 10.0);
        assert_eq!(evaluate_expression("2^3^2").unwrap(), 512.0);
        assert_eq!(evaluate_expression("10/4").unwrap(), 2.5);
        assert!(evaluate_expression("1/0").is_err());
        assert!(evaluate_expression("1 +").is_err());
    }

    #[test]
    fn nesting_is_limited_not_a_stack_overflow() {
        let deep = format!("{}1{}", "(".repeat(MAX_NESTING - 1), ")".repeat(MAX_NESTING - 1));
        assert_eq!(evaluate_expression(&deep).unwrap(), 1.0);
        assert_eq!(evaluate_expression(&format!("{}1", "-".repeat(MAX_NESTING - 1))).unwrap(), -1.0);
        let too_deep =
            "found an expression nested more than 64 deep (parentheses, unary `-` and `^` together); expected a flatter expression";
        for text in [
            format!("{}1{}", "(".repeat(40_000), ")".repeat(40_000)),
            format!("{}1", "-".repeat(60_000)),
            format!("1{}", "^1".repeat(60_000)),
            format!("2 * ({}1", "- (".repeat(30_000)),
        ] {
            assert_eq!(evaluate_expression(&text).unwrap_err(), too_deep);
        }
        // A long flat expression is not deep.
        assert_eq!(evaluate_expression(&format!("{}1", "1+".repeat(100_000))).unwrap(), 100_001.0);
    }
}
