//! Deck expressions: the [`crate::expr`] tree of one or more deck tokens,
//! with its errors placed at `file:line:col` inside the token they concern.
//!
//! A name in a deck expression is a deck variable holding a number (`i` of
//! a `loop`, or any `variable … equal`); `thermo(COLUMN)` reads a thermo
//! column of the current state and `previous(COLUMN)` its value when the
//! same `if` (the same place in the deck, in any iteration) was last
//! decided; both are only allowed where the expression is
//! decided during the run (an `if` condition, see [`Condition`]).

use crate::expr::{parse, Expr, ExprError, Ref};
use crate::input::{InputError, Token};

use super::plan::ThermoColumn;
use super::variables::Variables;

/// An expression parsed from deck tokens joined by single blanks.
#[derive(Clone, Debug)]
pub(super) struct DeckExpr {
    pub expr: Expr,
    /// Start of each token in the joined text, with the token.
    pieces: Vec<(usize, Token)>,
}

impl DeckExpr {
    pub fn parse(tokens: &[Token]) -> Result<Self, InputError> {
        let mut text = String::new();
        let mut pieces = Vec::new();
        for t in tokens {
            if !text.is_empty() {
                text.push(' ');
            }
            pieces.push((text.len(), t.clone()));
            text.push_str(&t.text);
        }
        match parse(&text) {
            Ok(expr) => Ok(Self { expr, pieces }),
            Err(e) => Err(locate(&pieces, &e)),
        }
    }

    /// An expression error at its place in the deck.
    pub fn error(&self, e: &ExprError) -> InputError {
        locate(&self.pieces, e)
    }

    /// The value now; every name must be a numeric deck variable.
    pub fn eval(&self, vars: &Variables) -> Result<f64, InputError> {
        self.expr
            .eval(&mut |r| match r {
                Ref::Name(name) => vars.number(name),
                thermo => Err(format!("found {}, which is known only during a run; expected it in an `if` condition", thermo.quoted())),
            })
            .map_err(|e| self.error(&e))
    }

    /// Whether the expression reads thermo columns (is decided during the run).
    pub fn reads_thermo(&self) -> bool {
        self.expr.refs().iter().any(|(r, _)| r.is_thermo())
    }
}

/// The deck position of an error: the token its span starts in, and the
/// column inside it.
fn locate(pieces: &[(usize, Token)], e: &ExprError) -> InputError {
    let (start, token) = pieces.iter().rev().find(|(start, _)| *start <= e.span.start).unwrap_or(&pieces[0]);
    token.error_within(e.span.start - start, e.message.clone())
}

/// An `if` condition decided during the run: the tree, the values its deck
/// variables had where the `if` stands, and the thermo columns it reads
/// (each once, whether as `thermo(…)` or `previous(…)`).
#[derive(Clone, Debug)]
pub struct Condition {
    pub(super) expr: Expr,
    pub(super) names: Vec<(String, f64)>,
    pub(super) columns: Vec<(String, ThermoColumn)>,
    /// `file:line:col` of the condition, for errors during the run.
    pub(super) at: String,
}

impl Condition {
    /// `file:line:col` of the condition: the same for every iteration of
    /// an unrolled `loop`, so it names the `if` whose decisions `previous`
    /// remembers.
    pub fn place(&self) -> &str {
        &self.at
    }

    /// Whether the condition holds; `column` measures a thermo column now,
    /// and `last` holds the columns' values at this condition's previous
    /// decision (empty before the first), which this decision replaces.
    /// A condition that reads `previous(…)` does not hold at its first
    /// decision: there is no earlier value. A value outside a function's
    /// domain is an error at the `if`, never silently false.
    pub fn holds(&self, column: &mut dyn FnMut(&ThermoColumn) -> Result<f64, String>, last: &mut Vec<f64>) -> Result<bool, String> {
        let failed = |message: String| format!("{}: the `if` condition: {message}", self.at);
        let now = self.columns.iter().map(|(_, c)| column(c)).collect::<Result<Vec<f64>, String>>().map_err(failed)?;
        let earlier = std::mem::replace(last, now.clone());
        let reads_previous = self.expr.refs().iter().any(|(r, _)| matches!(r, Ref::Previous(_)));
        if reads_previous && earlier.is_empty() {
            return Ok(false);
        }
        let slot = |text: &str| self.columns.iter().position(|(t, _)| t == text).expect("resolved when validated");
        let value = self.expr.eval(&mut |r| match r {
            Ref::Name(name) => Ok(self.names.iter().find(|(n, _)| n == name).expect("resolved when validated").1),
            Ref::Thermo(text) => Ok(now[slot(text)]),
            Ref::Previous(text) => Ok(earlier[slot(text)]),
        });
        value.map(|v| v != 0.0).map_err(|e| failed(e.message))
    }
}
