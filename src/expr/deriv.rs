//! Symbolic derivatives of an [`Expr`], simplified as they are built.
//!
//! `e.derivative("r")` is the tree of ∂e/∂r: the chain rule applied node by
//! node, every new node carrying the span of the node it derives from, and
//! each product, sum or power with a 0 or 1 operand (and each operation on
//! two numbers) folded as it is made, so that `0.5*k*(r-r0)^2` derives to
//! `0.5*k*(2*(r-r0))` rather than a sum of zero terms. Piecewise-constant
//! nodes (comparisons, logic, `floor`, `ceil`, `round`) derive to 0; `abs`,
//! `min` and `max` derive branch-wise through comparisons, as the value
//! they select does.
//!
//! ```
//! use cellmd::expr::{parse, Ref};
//! let e = parse("0.5*k*(r-r0)^2").unwrap();
//! let d = e.derivative("r");
//! let at = |r: Ref| match r { Ref::Name("k") => Ok(10.0), Ref::Name("r0") => Ok(1.0), Ref::Name("r") => Ok(1.5), _ => Err("?".into()) };
//! assert_eq!(d.eval(&mut at.clone()).unwrap(), 5.0);
//! assert_eq!(d.derivative("r").eval(&mut at.clone()).unwrap(), 10.0);
//! ```

use super::functions::function;
use super::{BinaryOp, Expr, Span, UnaryOp};

fn number(value: f64, span: Span) -> Expr {
    Expr::Number(value, span)
}

fn value_of(e: &Expr) -> Option<f64> {
    match e {
        Expr::Number(v, _) => Some(*v),
        _ => None,
    }
}

/// A binary node, folded when an operand makes it trivial.
pub(crate) fn binary(op: BinaryOp, lhs: Expr, rhs: Expr, span: Span) -> Expr {
    use BinaryOp::*;
    let (a, b) = (value_of(&lhs), value_of(&rhs));
    if let (Some(x), Some(y)) = (a, b) {
        let folded = match op {
            Add => Some(x + y),
            Sub => Some(x - y),
            Mul => Some(x * y),
            Div if y != 0.0 => Some(x / y),
            Pow => super::functions::power(x, y).ok(),
            _ => None,
        };
        if let Some(v) = folded.filter(|v| v.is_finite()) {
            return number(v, span);
        }
    }
    match (op, a, b) {
        (Add, Some(0.0), _) => rhs,
        (Add | Sub, _, Some(0.0)) => lhs,
        (Sub, Some(0.0), _) => negate(rhs, span),
        (Mul, Some(0.0), _) | (Mul, _, Some(0.0)) => number(0.0, span),
        (Mul, Some(1.0), _) => rhs,
        (Mul | Div, _, Some(1.0)) => lhs,
        (Div, Some(0.0), _) => number(0.0, span),
        (Pow, _, Some(1.0)) => lhs,
        (Pow, _, Some(0.0)) => number(1.0, span),
        _ => Expr::Binary { op, lhs: Box::new(lhs), rhs: Box::new(rhs), span },
    }
}

/// −e, folded for a number and a double negation.
pub(crate) fn negate(e: Expr, span: Span) -> Expr {
    match e {
        Expr::Number(v, _) => number(-v, span),
        Expr::Unary { op: UnaryOp::Neg, arg, .. } => *arg,
        other => Expr::Unary { op: UnaryOp::Neg, arg: Box::new(other), span },
    }
}

fn call(name: &str, args: Vec<Expr>, span: Span) -> Expr {
    Expr::Call { function: function(name).expect("a function of the table"), args, span }
}

impl Expr {
    /// Whether the tree reads the name `var`.
    pub fn depends_on(&self, var: &str) -> bool {
        self.refs().iter().any(|(r, _)| *r == super::Ref::Name(var))
    }

    /// The tree of ∂self/∂var (see the module docs).
    pub fn derivative(&self, var: &str) -> Expr {
        let span = self.span();
        let zero = || number(0.0, span);
        if !self.depends_on(var) {
            return zero();
        }
        let mul = |a: Expr, b: Expr| binary(BinaryOp::Mul, a, b, span);
        let add = |a: Expr, b: Expr| binary(BinaryOp::Add, a, b, span);
        let sub = |a: Expr, b: Expr| binary(BinaryOp::Sub, a, b, span);
        let div = |a: Expr, b: Expr| binary(BinaryOp::Div, a, b, span);
        let pow = |a: Expr, b: Expr| binary(BinaryOp::Pow, a, b, span);
        let square = |a: Expr| pow(a, number(2.0, span));
        let indicator = |op: BinaryOp, a: &Expr, b: &Expr| binary(op, a.clone(), b.clone(), span);
        match self {
            Expr::Number(..) | Expr::Thermo(..) | Expr::Previous(..) => zero(),
            Expr::Name(..) => number(1.0, span),
            Expr::Unary { op: UnaryOp::Neg, arg, .. } => negate(arg.derivative(var), span),
            Expr::Unary { op: UnaryOp::Not, .. } => zero(),
            Expr::Binary { op, lhs, rhs, .. } => {
                let (a, b) = (lhs.as_ref(), rhs.as_ref());
                match op {
                    BinaryOp::Add => add(a.derivative(var), b.derivative(var)),
                    BinaryOp::Sub => sub(a.derivative(var), b.derivative(var)),
                    BinaryOp::Mul => add(mul(a.derivative(var), b.clone()), mul(a.clone(), b.derivative(var))),
                    BinaryOp::Div => sub(div(a.derivative(var), b.clone()), div(mul(a.clone(), b.derivative(var)), square(b.clone()))),
                    BinaryOp::Pow => power_derivative(a, b, var, span),
                    _ => zero(),
                }
            }
            Expr::Call { function, args, .. } => {
                let a = &args[0];
                let da = || a.derivative(var);
                match function.name {
                    "sqrt" => div(da(), mul(number(2.0, span), self.clone())),
                    "exp" => mul(self.clone(), da()),
                    "ln" => div(da(), a.clone()),
                    "log10" => div(da(), mul(a.clone(), number(std::f64::consts::LN_10, span))),
                    "sin" => mul(call("cos", vec![a.clone()], span), da()),
                    "cos" => negate(mul(call("sin", vec![a.clone()], span), da()), span),
                    "tan" => div(da(), square(call("cos", vec![a.clone()], span))),
                    "asin" | "acos" => {
                        let d = div(da(), call("sqrt", vec![sub(number(1.0, span), square(a.clone()))], span));
                        if function.name == "asin" {
                            d
                        } else {
                            negate(d, span)
                        }
                    }
                    "atan" => div(da(), add(number(1.0, span), square(a.clone()))),
                    "atan2" => {
                        let (y, x) = (a, &args[1]);
                        div(
                            sub(mul(x.clone(), y.derivative(var)), mul(y.clone(), x.derivative(var))),
                            add(square(x.clone()), square(y.clone())),
                        )
                    }
                    "abs" => {
                        let zero_e = number(0.0, span);
                        let sign = sub(indicator(BinaryOp::Gt, a, &zero_e), indicator(BinaryOp::Lt, a, &zero_e));
                        mul(sign, da())
                    }
                    "min" | "max" => {
                        // Fold to binary: m = f(rest), then f(m, last) picks by a comparison.
                        let (picks_first, name) = if function.name == "min" { (BinaryOp::Le, "min") } else { (BinaryOp::Ge, "max") };
                        let other = if picks_first == BinaryOp::Le { BinaryOp::Gt } else { BinaryOp::Lt };
                        let head = if args.len() == 2 { args[0].clone() } else { call(name, args[..args.len() - 1].to_vec(), span) };
                        let last = &args[args.len() - 1];
                        add(
                            mul(indicator(picks_first, &head, last), head.derivative(var)),
                            mul(indicator(other, &head, last), last.derivative(var)),
                        )
                    }
                    "pow" => power_derivative(a, &args[1], var, span),
                    _ => zero(), // floor, ceil, round: piecewise constant
                }
            }
        }
    }
}

/// ∂(a^b)/∂var: b·a^(b−1)·a′ when b does not depend on var, else
/// a^b·(b′·ln a + b·a′/a).
fn power_derivative(a: &Expr, b: &Expr, var: &str, span: Span) -> Expr {
    let da = a.derivative(var);
    if !b.depends_on(var) {
        let lowered = binary(BinaryOp::Sub, b.clone(), number(1.0, span), span);
        let inner = binary(BinaryOp::Mul, b.clone(), binary(BinaryOp::Pow, a.clone(), lowered, span), span);
        return binary(BinaryOp::Mul, inner, da, span);
    }
    let whole = binary(BinaryOp::Pow, a.clone(), b.clone(), span);
    let log_part = binary(BinaryOp::Mul, b.derivative(var), call("ln", vec![a.clone()], span), span);
    let base_part = binary(BinaryOp::Div, binary(BinaryOp::Mul, b.clone(), da, span), a.clone(), span);
    binary(BinaryOp::Mul, whole, binary(BinaryOp::Add, log_part, base_part, span), span)
}

#[cfg(test)]
mod tests {
    use super::super::{parse, Ref};

    fn at<'a>(vars: &'a [(&'static str, f64)]) -> impl FnMut(Ref) -> Result<f64, String> + Clone + 'a {
        move |r| match r {
            Ref::Name(n) => vars.iter().find(|(k, _)| *k == n).map(|(_, v)| *v).ok_or(format!("unknown {n}")),
            Ref::Thermo(_) | Ref::Previous(_) => Err("thermo".into()),
        }
    }

    /// Every function and operator: the symbolic derivative against central
    /// differences of the value, at points away from kinks.
    #[test]
    fn derivatives_agree_with_central_differences() {
        let texts = [
            "0.5*k*(r-r0)^2",
            "k*(1+cos(pi*r/rc))",
            "exp(-r/2)/r + ln(r) - log10(3*r)",
            "sqrt(r^2+1) * sin(r) * tan(r/3)",
            "asin(r/4) + acos(r/5) + atan(2*r)",
            "atan2(r, 1+r^2) + abs(r-3) + abs(1-r)",
            "min(r, 2*r, 3) + max(r^2, 1.5, r) + min(5, r^3)",
            "r^r + pow(r, 2.5) + 2^r + (r > 1)*r^3 + floor(r)",
            "(r-1)/(r+2) - -r^-2 + r^0.5",
        ];
        let h = 1e-6;
        for text in texts {
            let e = parse(text).unwrap();
            let d = e.derivative("r");
            let d2 = d.derivative("r");
            for r in [0.7, 1.3, 2.2] {
                let vars = [("r", r), ("k", 3.0), ("r0", 0.9), ("rc", 2.5)];
                let value = |r: f64| e.eval(&mut at(&[("r", r), ("k", 3.0), ("r0", 0.9), ("rc", 2.5)])).unwrap();
                let slope = |r: f64| d.eval(&mut at(&[("r", r), ("k", 3.0), ("r0", 0.9), ("rc", 2.5)])).unwrap();
                let fd = (value(r + h) - value(r - h)) / (2.0 * h);
                let fd2 = (slope(r + h) - slope(r - h)) / (2.0 * h);
                let exact = d.eval(&mut at(&vars)).unwrap();
                let exact2 = d2.eval(&mut at(&vars)).unwrap();
                assert!((exact - fd).abs() < 1e-7 * (1.0 + fd.abs()), "{text} at {r}: {exact} vs {fd}");
                assert!((exact2 - fd2).abs() < 1e-6 * (1.0 + fd2.abs()), "{text}'' at {r}: {exact2} vs {fd2}");
            }
        }
    }

    /// Zero and one terms fold away: the derivative of a quadratic is linear
    /// with no `*0`, `+0`, `^1` left, and a constant derives to the number 0.
    #[test]
    fn simplification_folds_zero_and_one_terms() {
        let d = parse("0.5*k*(r-r0)^2").unwrap().derivative("r");
        let text = format!("{d:?}");
        assert!(!text.contains("Number(0.0") && !text.contains("Number(1.0"), "{text}");
        assert!(matches!(parse("k*sin(r0)").unwrap().derivative("r"), super::Expr::Number(v, _) if v == 0.0));
        assert!(matches!(parse("3*r").unwrap().derivative("r"), super::Expr::Number(v, _) if v == 3.0));
    }
}
