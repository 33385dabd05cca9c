//! Deck variables: `variable NAME equal EXPR` / `variable NAME string TEXT`,
//! used as `${NAME}` anywhere in a later token. Values given on the command
//! line (`--var NAME=VALUE`) take precedence over the deck's definitions.
//!
//! Memory is bounded: a value, and the substituted words of one statement
//! together, hold at most `MAX_VARIABLE_BYTES`, and all values together at
//! most [`MAX_VARIABLES_BYTES`] (28 string variables that each doubled the
//! last took 3.1 GB before these caps).
//!
//! An `equal` expression ([`crate::expr`]) may also read a numeric variable
//! by its bare name (`variable dx equal (g2 - g)*height`).

use std::collections::HashMap;

use super::expression::DeckExpr;
use crate::input::{InputError, Token};

/// The longest value of a variable, and of the substituted words of one statement: 1 MiB.
pub const MAX_VARIABLE_BYTES: usize = 1 << 20;
/// The most bytes all variables' values hold together: 64 MiB.
pub const MAX_VARIABLES_BYTES: usize = 64 << 20;

fn too_long(at: &Token, len: usize) -> InputError {
    at.error(format!("found {len} bytes after substituting variables, expected at most {MAX_VARIABLE_BYTES} (1 MiB)"))
}

#[derive(Clone, Debug, Default)]
pub struct Variables {
    values: HashMap<String, String>,
    from_command_line: HashMap<String, String>,
    /// Bytes of all values together.
    total: usize,
}

impl Variables {
    /// Variables fixed on the command line.
    pub fn with_overrides(overrides: &[(String, String)]) -> Self {
        let from_command_line: HashMap<String, String> = overrides.iter().cloned().collect();
        let total = from_command_line.values().map(String::len).sum();
        Self { values: from_command_line.clone(), from_command_line, total }
    }

    /// Handles `variable NAME equal|string VALUE...` (tokens after `variable`).
    pub fn define(&mut self, keyword: &Token, tokens: &[Token]) -> Result<(), InputError> {
        if tokens.len() < 3 {
            return Err(keyword.error("expected `variable NAME equal EXPRESSION` or `variable NAME string TEXT`"));
        }
        let name = &tokens[0];
        if !name.text.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(name.error(format!("found variable name `{}`, expected letters, digits and `_`", name.text)));
        }
        let rest: Vec<&str> = tokens[2..].iter().map(|t| t.text.as_str()).collect();
        let value = match tokens[1].text.as_str() {
            "equal" => format!("{}", DeckExpr::parse(&tokens[2..])?.eval(self)?),
            "string" => rest.join(" "),
            other => return Err(tokens[1].error(format!("found `{other}`, expected `equal` or `string`"))),
        };
        if value.len() > MAX_VARIABLE_BYTES {
            return Err(too_long(&tokens[2], value.len()));
        }
        if !self.from_command_line.contains_key(&name.text) {
            let total = self.total + value.len() - self.values.get(&name.text).map_or(0, String::len);
            if total > MAX_VARIABLES_BYTES {
                return Err(
                    name.error(format!("found {total} bytes in all variables' values, expected at most {MAX_VARIABLES_BYTES} (64 MiB)"))
                );
            }
            self.total = total;
            self.values.insert(name.text.clone(), value);
        }
        Ok(())
    }

    /// The number a variable holds (for a bare name in an expression).
    pub(super) fn number(&self, name: &str) -> Result<f64, String> {
        let value = self.values.get(name).ok_or_else(|| {
            format!("found undefined variable `{name}`, expected a `variable {name} ...` line before this one or `--var {name}=VALUE`")
        })?;
        value
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("variable `{name}` holds `{value}`; expected a number (a string variable is used as `${{{name}}}`)"))
    }

    /// Sets a loop's variable (a command-line value does not hold it) and
    /// returns its previous value, for [`restore`](Self::restore).
    pub(super) fn set_loop(&mut self, name: &str, value: String) -> Option<String> {
        self.values.insert(name.to_string(), value)
    }

    /// Puts back what a variable held before a loop.
    pub(super) fn restore(&mut self, name: &str, previous: Option<String>) {
        match previous {
            Some(v) => self.values.insert(name.to_string(), v),
            None => self.values.remove(name),
        };
    }

    /// Replaces every `${NAME}` in a token.
    pub fn substitute(&self, token: &Token) -> Result<Token, InputError> {
        self.substitute_after(token, 0)
    }

    /// Substitutes every token of a statement; the substituted ones may hold
    /// `MAX_VARIABLE_BYTES` together.
    pub fn substitute_all(&self, tokens: &[Token]) -> Result<Vec<Token>, InputError> {
        let mut grown = 0;
        tokens
            .iter()
            .map(|t| {
                let out = self.substitute_after(t, grown)?;
                if t.text.contains("${") {
                    grown += out.text.len();
                }
                Ok(out)
            })
            .collect()
    }

    /// Replaces every `${NAME}` in a token, after `before` substituted bytes
    /// of the same statement.
    fn substitute_after(&self, token: &Token, before: usize) -> Result<Token, InputError> {
        if !token.text.contains("${") {
            return Ok(token.clone());
        }
        let mut out = String::new();
        let mut rest = token.text.as_str();
        while let Some(start) = rest.find("${") {
            out.push_str(&rest[..start]);
            let after = &rest[start + 2..];
            let end = after.find('}').ok_or_else(|| token.error("unterminated `${`; expected `${NAME}`"))?;
            let name = &after[..end];
            let value = self.values.get(name).ok_or_else(|| {
                token.error(format!(
                    "found undefined variable `{name}`, expected a `variable {name} ...` line before this one or `--var {name}=VALUE`"
                ))
            })?;
            if before + out.len() + value.len() > MAX_VARIABLE_BYTES {
                return Err(too_long(token, before + out.len() + value.len()));
            }
            out.push_str(value);
            rest = &after[end + 1..];
        }
        if before + out.len() + rest.len() > MAX_VARIABLE_BYTES {
            return Err(too_long(token, before + out.len() + rest.len()));
        }
        out.push_str(rest);
        Ok(token.with_text(out))
    }
}
