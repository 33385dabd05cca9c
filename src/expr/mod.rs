//! Arithmetic expressions as trees: text → [`Expr`] (with byte spans) → value.
//!
//! Decks use them in `variable NAME equal …`, `loop` bounds and `if`
//! conditions; later consumers (position-dependent forces, symbolic
//! derivatives, code generation) walk the same tree instead of re-reading
//! text. The module is a leaf: it knows nothing of decks or thermo columns;
//! a caller resolves the names a tree refers to ([`Ref`]) through
//! [`Expr::eval`]'s lookup.
//!
//! ```text
//! expr    := or
//! or      := and ("||" and)*
//! and     := eq ("&&" eq)*
//! eq      := cmp (("==" | "!=") cmp)*
//! cmp     := sum (("<" | "<=" | ">" | ">=") sum)*
//! sum     := product (("+" | "-") product)*
//! product := unary (("*" | "/") unary)*
//! unary   := ("-" | "+" | "!") unary | power
//! power   := atom ("^" unary)?            (right-associative: 2^3^2 = 512, -2^2 = -4)
//! atom    := number | "pi" | NAME | NAME "(" expr ("," expr)* ")" | "thermo(" COLUMN ")" | "previous(" COLUMN ")" | "(" expr ")"
//! ```
//! Comparisons and logical operators give 1 (true) or 0 (false); `&&`, `||`
//! and `!` read any non-zero value as true, as LAMMPS does. Every function of
//! [`FUNCTIONS`] checks its arity when parsed and its domain when evaluated
//! (`sqrt(-1)`, `ln(0)`, `asin(2)` are errors at the call), as is a division
//! by zero and any result that is not a finite number. Parsing refuses what
//! would exhaust the stack: nesting deeper than [`MAX_NESTING`] and
//! more than [`MAX_OPERANDS`] operands.
//!
//! ```
//! use cellmd::expr::{parse, Ref};
//! let e = parse("max(2, sqrt(x)) * (t >= 1 && t < 3)").unwrap();
//! let v = e.eval(&mut |r: Ref| match r { Ref::Name("x") => Ok(16.0), Ref::Name("t") => Ok(2.0), _ => Err("unknown".into()) });
//! assert_eq!(v.unwrap(), 4.0);
//! assert!(parse("sqrt(1, 2)").unwrap_err().message.contains("1 argument"));
//! ```

mod deriv;
mod eval;
mod functions;
mod parse;
pub mod tape;
pub mod wgsl;

pub use self::functions::{Function, FUNCTIONS};
pub use self::parse::{parse, MAX_NESTING, MAX_OPERANDS};

/// Byte range of a node in the parsed text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Span {
    pub start: usize,
    pub end: usize,
}

/// A parse or evaluation error inside an expression's text.
#[derive(Clone, Debug, PartialEq)]
pub struct ExprError {
    pub span: Span,
    pub message: String,
}

impl ExprError {
    pub(crate) fn new(span: Span, message: impl Into<String>) -> Self {
        Self { span, message: message.into() }
    }
}

/// A unary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnaryOp {
    Neg,
    Not,
}

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinaryOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    And,
    Or,
}

/// A name an expression reads: a plain name (a deck variable, or `x`, `t`
/// where the caller defines them), a thermo column (`thermo(fx/plate)`), or
/// a thermo column's earlier value (`previous(fx/plate)`, whose meaning the
/// caller defines: a deck `if` gives the value at its last decision).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ref<'a> {
    Name(&'a str),
    Thermo(&'a str),
    Previous(&'a str),
}

impl Ref<'_> {
    /// The reference as written, quoted: `` `x` ``, `` `thermo(pe)` ``, `` `previous(pe)` ``.
    pub fn quoted(&self) -> String {
        match self {
            Ref::Name(name) => format!("`{name}`"),
            Ref::Thermo(column) => format!("`thermo({column})`"),
            Ref::Previous(column) => format!("`previous({column})`"),
        }
    }

    /// Whether it reads a thermo column (now or earlier).
    pub fn is_thermo(&self) -> bool {
        !matches!(self, Ref::Name(_))
    }
}

/// An expression tree; every node knows its span.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    Number(f64, Span),
    Name(String, Span),
    Thermo(String, Span),
    Previous(String, Span),
    Unary { op: UnaryOp, arg: Box<Expr>, span: Span },
    Binary { op: BinaryOp, lhs: Box<Expr>, rhs: Box<Expr>, span: Span },
    Call { function: &'static Function, args: Vec<Expr>, span: Span },
}

impl Expr {
    pub fn span(&self) -> Span {
        match self {
            Expr::Number(_, span) | Expr::Name(_, span) | Expr::Thermo(_, span) | Expr::Previous(_, span) => *span,
            Expr::Unary { span, .. } | Expr::Binary { span, .. } | Expr::Call { span, .. } => *span,
        }
    }

    /// Every name and thermo column the tree reads, in text order, with its span.
    pub fn refs(&self) -> Vec<(Ref<'_>, Span)> {
        let mut out = Vec::new();
        self.collect_refs(&mut out);
        out
    }

    /// The tree with each name that `value` knows replaced by its number
    /// (e.g. deck variables, fixed where a formula is given).
    pub fn substitute(&self, value: &dyn Fn(&str) -> Option<f64>) -> Expr {
        match self {
            Expr::Name(name, span) => value(name).map_or_else(|| self.clone(), |v| Expr::Number(v, *span)),
            Expr::Number(..) | Expr::Thermo(..) | Expr::Previous(..) => self.clone(),
            Expr::Unary { op, arg, span } => Expr::Unary { op: *op, arg: Box::new(arg.substitute(value)), span: *span },
            Expr::Binary { op, lhs, rhs, span } => {
                Expr::Binary { op: *op, lhs: Box::new(lhs.substitute(value)), rhs: Box::new(rhs.substitute(value)), span: *span }
            }
            Expr::Call { function, args, span } => {
                Expr::Call { function, args: args.iter().map(|a| a.substitute(value)).collect(), span: *span }
            }
        }
    }

    fn collect_refs<'a>(&'a self, out: &mut Vec<(Ref<'a>, Span)>) {
        match self {
            Expr::Number(..) => {}
            Expr::Name(name, span) => out.push((Ref::Name(name), *span)),
            Expr::Thermo(column, span) => out.push((Ref::Thermo(column), *span)),
            Expr::Previous(column, span) => out.push((Ref::Previous(column), *span)),
            Expr::Unary { arg, .. } => arg.collect_refs(out),
            Expr::Binary { lhs, rhs, .. } => {
                lhs.collect_refs(out);
                rhs.collect_refs(out);
            }
            Expr::Call { args, .. } => args.iter().for_each(|a| a.collect_refs(out)),
        }
    }
}
