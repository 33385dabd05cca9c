//! Text → [`Expr`]: a tokenizer and a precedence-climbing parser.
//!
//! Hand-written rather than nom: every failure knows the exact byte where
//! the text stops making sense (`1 + * 2` points at `*`, `sqrt(1, 2)` at the
//! call), which a chain of nom alternatives reports at the start of the
//! alternative that failed.

use super::functions::{function, names};
use super::{BinaryOp, Expr, ExprError, Span, UnaryOp};

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Number(f64),
    Name(String),
    Thermo(String),
    Previous(String),
    Op(&'static str),
    Open,
    Close,
    Comma,
    End,
}

const OPERATORS: [&str; 16] = ["<=", ">=", "==", "!=", "&&", "||", "<", ">", "+", "-", "*", "/", "^", "!", "(", ")"];

fn tokenize(text: &str) -> Result<Vec<(Tok, Span)>, ExprError> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        let start = i;
        if c.is_ascii_digit() || (c == b'.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                i += 1;
            }
            if i < bytes.len() && (bytes[i] == b'e' || bytes[i] == b'E') {
                let mut j = i + 1;
                if j < bytes.len() && (bytes[j] == b'+' || bytes[j] == b'-') {
                    j += 1;
                }
                if j < bytes.len() && bytes[j].is_ascii_digit() {
                    i = j;
                    while i < bytes.len() && bytes[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let span = Span { start, end: i };
            let value: f64 =
                text[start..i].parse().map_err(|_| ExprError::new(span, format!("found `{}`, expected a number", &text[start..i])))?;
            out.push((Tok::Number(value), span));
        } else if c.is_ascii_alphabetic() || c == b'_' {
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            let name = &text[start..i];
            if (name == "thermo" || name == "previous") && bytes.get(i) == Some(&b'(') {
                let close = text[i..].find(')').map(|k| i + k).ok_or_else(|| {
                    ExprError::new(Span { start, end: text.len() }, format!("unterminated `{name}(`; expected `{name}(COLUMN)`"))
                })?;
                let column = text[i + 1..close].trim().to_string();
                if column.is_empty() {
                    return Err(ExprError::new(Span { start, end: close + 1 }, format!("found `{name}()`, expected `{name}(COLUMN)`")));
                }
                let tok = if name == "thermo" { Tok::Thermo(column) } else { Tok::Previous(column) };
                i = close + 1;
                out.push((tok, Span { start, end: i }));
            } else {
                out.push((Tok::Name(name.to_string()), Span { start, end: i }));
            }
        } else if c == b',' {
            i += 1;
            out.push((Tok::Comma, Span { start, end: i }));
        } else if let Some(op) = OPERATORS.iter().find(|op| text[i..].starts_with(**op)) {
            i += op.len();
            let tok = match *op {
                "(" => Tok::Open,
                ")" => Tok::Close,
                op => Tok::Op(op),
            };
            out.push((tok, Span { start, end: i }));
        } else {
            let found = text[i..].chars().next().unwrap_or(' ');
            return Err(ExprError::new(
                Span { start, end: i + found.len_utf8() },
                format!("found `{found}`, expected a number, a name, a function call, an operator or a parenthesis"),
            ));
        }
    }
    out.push((Tok::End, Span { start: text.len(), end: text.len() }));
    Ok(out)
}

struct Parser {
    toks: Vec<(Tok, Span)>,
    at: usize,
    /// How deep `(`, unary operators and `^` nest at the current token.
    depth: usize,
    /// Numbers, names and thermo values read so far.
    operands: usize,
}

/// How deep `(`, unary `-`, `+`, `!` and `^` may nest in one expression.
pub const MAX_NESTING: usize = 64;
/// The most numbers, names and calls one expression may hold: evaluation
/// walks the tree recursively, and a sum of 500 000 terms is as deep.
pub const MAX_OPERANDS: usize = 4096;

/// Binary operators by precedence level, loosest first.
const LEVELS: [&[(&str, BinaryOp)]; 6] = [
    &[("||", BinaryOp::Or)],
    &[("&&", BinaryOp::And)],
    &[("==", BinaryOp::Eq), ("!=", BinaryOp::Ne)],
    &[("<", BinaryOp::Lt), ("<=", BinaryOp::Le), (">", BinaryOp::Gt), (">=", BinaryOp::Ge)],
    &[("+", BinaryOp::Add), ("-", BinaryOp::Sub)],
    &[("*", BinaryOp::Mul), ("/", BinaryOp::Div)],
];

fn describe(tok: &Tok) -> String {
    match tok {
        Tok::Number(v) => format!("the number {v}"),
        Tok::Name(n) => format!("`{n}`"),
        Tok::Thermo(c) => format!("`thermo({c})`"),
        Tok::Previous(c) => format!("`previous({c})`"),
        Tok::Op(op) => format!("`{op}`"),
        Tok::Open => "`(`".into(),
        Tok::Close => "`)`".into(),
        Tok::Comma => "`,`".into(),
        Tok::End => "the end of the expression".into(),
    }
}

impl Parser {
    fn peek(&self) -> &(Tok, Span) {
        &self.toks[self.at]
    }

    fn next(&mut self) -> (Tok, Span) {
        let t = self.toks[self.at].clone();
        if self.at + 1 < self.toks.len() {
            self.at += 1;
        }
        t
    }

    fn unexpected(&self, expected: &str) -> ExprError {
        let (tok, span) = self.peek();
        ExprError::new(*span, format!("found {}, expected {expected}", describe(tok)))
    }

    fn binary(&mut self, level: usize) -> Result<Expr, ExprError> {
        if level == LEVELS.len() {
            return self.unary();
        }
        let mut lhs = self.binary(level + 1)?;
        loop {
            let op = match &self.peek().0 {
                Tok::Op(text) => LEVELS[level].iter().find(|(t, _)| t == text).map(|(_, op)| *op),
                _ => None,
            };
            let Some(op) = op else { return Ok(lhs) };
            self.next();
            let rhs = self.binary(level + 1)?;
            let span = Span { start: lhs.span().start, end: rhs.span().end };
            lhs = Expr::Binary { op, lhs: Box::new(lhs), rhs: Box::new(rhs), span };
        }
    }

    /// A unary term one level deeper: every nesting (a parenthesis, a
    /// function argument, a unary operator, an exponent) passes through here.
    fn unary(&mut self) -> Result<Expr, ExprError> {
        if self.depth >= MAX_NESTING {
            return Err(ExprError::new(
                self.peek().1,
                format!(
                    "found an expression nested more than {MAX_NESTING} deep (parentheses, unary `-` and `^` together); \
                     expected a flatter expression"
                ),
            ));
        }
        self.depth += 1;
        let term = self.unary_term();
        self.depth -= 1;
        term
    }

    fn unary_term(&mut self) -> Result<Expr, ExprError> {
        let (tok, span) = self.peek().clone();
        let op = match tok {
            Tok::Op("-") => Some(UnaryOp::Neg),
            Tok::Op("!") => Some(UnaryOp::Not),
            Tok::Op("+") => None,
            _ => return self.power(),
        };
        self.next();
        let arg = self.unary()?;
        let whole = Span { start: span.start, end: arg.span().end };
        Ok(match op {
            Some(op) => Expr::Unary { op, arg: Box::new(arg), span: whole },
            None => arg,
        })
    }

    fn power(&mut self) -> Result<Expr, ExprError> {
        let base = self.atom()?;
        if self.peek().0 != Tok::Op("^") {
            return Ok(base);
        }
        self.next();
        let exponent = self.unary()?;
        let span = Span { start: base.span().start, end: exponent.span().end };
        Ok(Expr::Binary { op: BinaryOp::Pow, lhs: Box::new(base), rhs: Box::new(exponent), span })
    }

    fn atom(&mut self) -> Result<Expr, ExprError> {
        const OPERAND: &str = "a number, a name, a function call or `(`";
        let (tok, span) = self.peek().clone();
        if matches!(tok, Tok::Number(_) | Tok::Name(_) | Tok::Thermo(_) | Tok::Previous(_)) {
            self.operands += 1;
            if self.operands > MAX_OPERANDS {
                return Err(ExprError::new(
                    span,
                    format!("found more than {MAX_OPERANDS} numbers and names in one expression; expected a shorter one"),
                ));
            }
        }
        match tok {
            Tok::Number(v) => {
                self.next();
                Ok(Expr::Number(v, span))
            }
            Tok::Thermo(column) => {
                self.next();
                Ok(Expr::Thermo(column, span))
            }
            Tok::Previous(column) => {
                self.next();
                Ok(Expr::Previous(column, span))
            }
            Tok::Open => {
                self.next();
                let mut inner = self.binary(0)?;
                if self.peek().0 != Tok::Close {
                    return Err(self.unexpected("`)` or an operator"));
                }
                let (_, close) = self.next();
                // The parentheses belong to the node: errors underline them too.
                let whole = Span { start: span.start, end: close.end };
                match &mut inner {
                    Expr::Number(_, s) | Expr::Name(_, s) | Expr::Thermo(_, s) | Expr::Previous(_, s) => *s = whole,
                    Expr::Unary { span: s, .. } | Expr::Binary { span: s, .. } | Expr::Call { span: s, .. } => *s = whole,
                }
                Ok(inner)
            }
            Tok::Name(name) => {
                self.next();
                if self.peek().0 != Tok::Open {
                    return Ok(if name == "pi" { Expr::Number(std::f64::consts::PI, span) } else { Expr::Name(name, span) });
                }
                let function = function(&name)
                    .ok_or_else(|| ExprError::new(span, format!("found unknown function `{name}`, expected one of: {}", names())))?;
                self.next();
                let mut args = Vec::new();
                if self.peek().0 != Tok::Close {
                    loop {
                        args.push(self.binary(0)?);
                        match self.peek().0 {
                            Tok::Comma => {
                                self.next();
                            }
                            Tok::Close => break,
                            _ => return Err(self.unexpected("`,` or `)`")),
                        }
                    }
                }
                let (_, close) = self.next();
                let call = Span { start: span.start, end: close.end };
                if !function.accepts(args.len()) {
                    return Err(ExprError::new(
                        call,
                        format!("found {} argument(s) to `{name}`, expected {}", args.len(), function.arity_text()),
                    ));
                }
                Ok(Expr::Call { function, args, span: call })
            }
            _ => Err(self.unexpected(OPERAND)),
        }
    }
}

/// Parses an expression (the grammar is in the [module docs](super)).
pub fn parse(text: &str) -> Result<Expr, ExprError> {
    let mut parser = Parser { toks: tokenize(text)?, at: 0, depth: 0, operands: 0 };
    if parser.peek().0 == Tok::End {
        return Err(ExprError::new(Span { start: 0, end: text.len() }, "found an empty expression, expected a number or a formula"));
    }
    let expr = parser.binary(0)?;
    if parser.peek().0 != Tok::End {
        return Err(parser.unexpected("an operator or the end of the expression"));
    }
    Ok(expr)
}

#[cfg(test)]
mod tests {
    use super::{parse, MAX_NESTING, MAX_OPERANDS};

    fn value(text: &str) -> f64 {
        parse(text).unwrap().eval(&mut |_| Err("no names".into())).unwrap()
    }

    /// 40 000 nested parentheses overflowed the stack of a recursive parser;
    /// now nesting is refused past its limit, at any mix of `(`, `-` and `^`.
    #[test]
    fn nesting_is_limited_not_a_stack_overflow() {
        assert_eq!(value(&format!("{}1{}", "(".repeat(MAX_NESTING - 1), ")".repeat(MAX_NESTING - 1))), 1.0);
        assert_eq!(value(&format!("{}1", "-".repeat(MAX_NESTING - 1))), -1.0);
        for text in [
            format!("{}1{}", "(".repeat(40_000), ")".repeat(40_000)),
            format!("{}1", "-".repeat(60_000)),
            format!("1{}", "^1".repeat(60_000)),
            format!("2 * ({}1", "- (".repeat(30_000)),
            format!("{}1{}", "max(1, ".repeat(1000), ")".repeat(1000)),
        ] {
            let e = parse(&text).unwrap_err();
            assert!(e.message.starts_with("found an expression nested more than 64 deep"), "{}", e.message);
        }
    }

    /// A long flat sum makes a tree as deep as it is long: refused past the
    /// operand limit, evaluated below it.
    #[test]
    fn operands_are_limited() {
        assert_eq!(value(&format!("{}1", "1+".repeat(MAX_OPERANDS - 1))), MAX_OPERANDS as f64);
        let e = parse(&format!("{}1", "1+".repeat(500_000))).unwrap_err();
        assert_eq!(e.message, "found more than 4096 numbers and names in one expression; expected a shorter one");
        assert_eq!(e.span.start, 2 * MAX_OPERANDS, "at the first operand beyond the limit");
    }
}
