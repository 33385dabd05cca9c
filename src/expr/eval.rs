//! Evaluation of an [`Expr`] with the caller's names.

use super::functions::power;
use super::{BinaryOp, Expr, ExprError, Ref, UnaryOp};

fn truth(v: f64) -> bool {
    v != 0.0
}

fn boolean(b: bool) -> f64 {
    if b {
        1.0
    } else {
        0.0
    }
}

impl Expr {
    /// The value of the tree; `lookup` gives the value of each name it
    /// reads or says what was expected instead. Errors point at the node
    /// that failed: an unknown name, a function outside its domain, a
    /// division by zero, or any non-finite intermediate value.
    pub fn eval(&self, lookup: &mut dyn FnMut(Ref) -> Result<f64, String>) -> Result<f64, ExprError> {
        let value = match self {
            Expr::Number(v, _) => *v,
            Expr::Name(name, span) => lookup(Ref::Name(name)).map_err(|m| ExprError::new(*span, m))?,
            Expr::Thermo(column, span) => lookup(Ref::Thermo(column)).map_err(|m| ExprError::new(*span, m))?,
            Expr::Previous(column, span) => lookup(Ref::Previous(column)).map_err(|m| ExprError::new(*span, m))?,
            Expr::Unary { op, arg, .. } => {
                let a = arg.eval(lookup)?;
                match op {
                    UnaryOp::Neg => -a,
                    UnaryOp::Not => boolean(!truth(a)),
                }
            }
            Expr::Binary { op: BinaryOp::And, lhs, rhs, .. } => boolean(truth(lhs.eval(lookup)?) && truth(rhs.eval(lookup)?)),
            Expr::Binary { op: BinaryOp::Or, lhs, rhs, .. } => boolean(truth(lhs.eval(lookup)?) || truth(rhs.eval(lookup)?)),
            Expr::Binary { op, lhs, rhs, span } => {
                let (a, b) = (lhs.eval(lookup)?, rhs.eval(lookup)?);
                match op {
                    BinaryOp::Add => a + b,
                    BinaryOp::Sub => a - b,
                    BinaryOp::Mul => a * b,
                    BinaryOp::Div if b == 0.0 => {
                        return Err(ExprError::new(rhs.span(), format!("division by zero in {a}/{b}; expected a non-zero divisor")))
                    }
                    BinaryOp::Div => a / b,
                    BinaryOp::Pow => power(a, b).map_err(|m| ExprError::new(*span, format!("`^` outside its domain: expected {m}")))?,
                    BinaryOp::Lt => boolean(a < b),
                    BinaryOp::Le => boolean(a <= b),
                    BinaryOp::Gt => boolean(a > b),
                    BinaryOp::Ge => boolean(a >= b),
                    BinaryOp::Eq => boolean(a == b),
                    BinaryOp::Ne => boolean(a != b),
                    BinaryOp::And | BinaryOp::Or => unreachable!("short-circuited above"),
                }
            }
            Expr::Call { function, args, span } => {
                let values: Vec<f64> = args.iter().map(|a| a.eval(lookup)).collect::<Result<_, _>>()?;
                (function.eval)(&values).map_err(|expected| {
                    let shown: Vec<String> = values.iter().map(|v| format!("{v}")).collect();
                    ExprError::new(*span, format!("found {}({}), expected {expected}", function.name, shown.join(", ")))
                })?
            }
        };
        if value.is_finite() {
            Ok(value)
        } else {
            Err(ExprError::new(self.span(), format!("evaluates to {value}; expected a finite number")))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{parse, Ref};

    fn value(text: &str) -> Result<f64, String> {
        let e = parse(text).map_err(|e| format!("{}..{}: {}", e.span.start, e.span.end, e.message))?;
        e.eval(&mut |r| match r {
            Ref::Name("x") => Ok(3.0),
            Ref::Thermo("fx/plate") => Ok(-2.5),
            other => Err(format!("unknown {other:?}")),
        })
        .map_err(|e| format!("{}..{}: {}", e.span.start, e.span.end, e.message))
    }

    #[test]
    fn arithmetic_precedence_and_associativity() {
        assert_eq!(value("1 + 2*3").unwrap(), 7.0);
        assert_eq!(value("(1+2)*3 - -1").unwrap(), 10.0);
        assert_eq!(value("2^3^2").unwrap(), 512.0);
        assert_eq!(value("-2^2").unwrap(), -4.0);
        assert_eq!(value("2^-1").unwrap(), 0.5);
        assert_eq!(value("10/4/5").unwrap(), 0.5);
        assert_eq!(value("1.5e-3*2e3").unwrap(), 3.0);
        assert_eq!(value("pi").unwrap(), std::f64::consts::PI);
        assert_eq!(value("x*x").unwrap(), 9.0);
    }

    #[test]
    fn functions() {
        let cases = [
            ("sqrt(16)", 4.0),
            ("exp(0)", 1.0),
            ("ln(exp(2))", 2.0),
            ("log10(1000)", 3.0),
            ("sin(0)", 0.0),
            ("cos(0)", 1.0),
            ("tan(0)", 0.0),
            ("asin(1)", std::f64::consts::FRAC_PI_2),
            ("acos(1)", 0.0),
            ("atan(1)", std::f64::consts::FRAC_PI_4),
            ("atan2(1, -1)", 3.0 * std::f64::consts::FRAC_PI_4),
            ("abs(-3)", 3.0),
            ("min(4, x, 7)", 3.0),
            ("max(4, x)", 4.0),
            ("floor(-1.5)", -2.0),
            ("ceil(1.2)", 2.0),
            ("round(2.5)", 3.0),
            ("pow(2, 10)", 1024.0),
            ("pow(-2, 3)", -8.0),
        ];
        for (text, expected) in cases {
            let got = value(text).unwrap();
            assert!((got - expected).abs() < 1e-15, "{text} = {got}, expected {expected}");
        }
    }

    #[test]
    fn comparisons_and_logic() {
        let cases = [
            ("1 < 2", 1.0),
            ("2 <= 2", 1.0),
            ("1 > 2", 0.0),
            ("2 >= 3", 0.0),
            ("x == 3", 1.0),
            ("x != 3", 0.0),
            ("1 < 2 && 3 < 2", 0.0),
            ("1 < 2 || 3 < 2", 1.0),
            ("!0", 1.0),
            ("!(x > 1)", 0.0),
            ("1 + 1 == 2 && x*2 > 5", 1.0),
            ("thermo(fx/plate) < -2", 1.0),
        ];
        for (text, expected) in cases {
            assert_eq!(value(text).unwrap(), expected, "{text}");
        }
        // `||` does not evaluate its right side when the left is true.
        assert_eq!(value("1 || sqrt(-1)").unwrap(), 1.0);
    }

    #[test]
    fn errors_point_inside_the_text() {
        let cases = [
            ("sqrt(-1)", "0..8: found sqrt(-1), expected an argument >= 0"),
            ("1 + ln(0)", "4..9: found ln(0), expected an argument > 0"),
            ("asin(2)", "0..7: found asin(2), expected an argument in [-1, 1]"),
            ("2 * foo(1)", "4..7: found unknown function `foo`, expected one of: sqrt"),
            ("sqrt(1, 2)", "0..10: found 2 argument(s) to `sqrt`, expected 1 argument"),
            ("min(1)", "0..6: found 1 argument(s) to `min`, expected at least 2 arguments"),
            ("1 + * 2", "4..5: found `*`, expected a number"),
            ("(1 + 2", "6..6: found the end of the expression, expected `)`"),
            ("1 2", "2..3: found the number 2, expected an operator"),
            ("1 / (x - 3)", "4..11: division by zero"),
            ("(-8)^(1/3)", "0..10: `^` outside its domain"),
            ("exp(1000)", "0..9: evaluates to inf"),
            ("y + 1", "0..1: unknown Name(\"y\")"),
            ("1 $ 2", "2..3: found `$`, expected a number"),
            ("", "0..0: found an empty expression"),
            ("thermo(pe", "0..9: unterminated `thermo(`"),
        ];
        for (text, expected) in cases {
            let got = value(text).unwrap_err();
            assert!(got.starts_with(expected), "{text}: {got}\n  expected it to start with {expected}");
        }
    }

    #[test]
    fn refs_lists_names_and_thermo_columns() {
        let e = parse("x + thermo(pe) * max(y, 2)").unwrap();
        let refs: Vec<Ref> = e.refs().into_iter().map(|(r, _)| r).collect();
        assert_eq!(refs, vec![Ref::Name("x"), Ref::Thermo("pe"), Ref::Name("y")]);
    }
}
