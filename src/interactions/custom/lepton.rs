//! A `custom` law's energy tree as a Lepton expression, for its LAMMPS translation (LAMMPS' `bond_style
//! lepton`, `angle_style lepton`, `pair_style lepton`; OpenMM's parser).
//!
//! Parameters are written as their current values (`coeff` may have changed
//! them), so the expression stands alone. Every sub-expression is
//! parenthesised, so precedence never differs.
//!
//! | cellmd | Lepton |
//! |---|---|
//! | `+ - * / ^`, unary `-` | the same |
//! | `sqrt exp sin cos tan asin acos atan atan2 abs floor ceil min max` | the same (`min`, `max` nested pairwise) |
//! | `ln(a)` | `log(a)` (Lepton's `log` is natural) |
//! | `log10(a)` | `log(a)/log(10)` |
//! | `pow(a, b)` | `(a)^(b)` |
//! | `a < b`, `a <= b`, `a > b`, `a >= b` | `1-step(a-b)`, `step(b-a)`, `1-step(b-a)`, `step(a-b)` (`step(x)` = 1 for x ≥ 0) |
//! | `a == b`, `a != b`, `!a` | `delta(a-b)`, `1-delta(a-b)`, `delta(a)` |
//! | `a && b`, `a \|\| b` | `(1-delta(a))*(1-delta(b))`, `1-delta(a)*delta(b)` |
//!
//! `round` has no Lepton equivalent and is an error that says so.

use crate::expr::{BinaryOp, Expr, UnaryOp};
use crate::interactions::lammps::num;

/// The Lepton text of `expr`; `value` gives the number of each parameter
/// name, any other name (the law's variable) is written as it is.
pub fn lepton(expr: &Expr, value: &dyn Fn(&str) -> Option<f64>) -> Result<String, String> {
    let go = |e: &Expr| lepton(e, value);
    Ok(match expr {
        Expr::Number(v, _) => format!("({})", num(*v)),
        Expr::Name(name, _) => value(name).map_or_else(|| name.clone(), |v| format!("({})", num(v))),
        Expr::Thermo(..) | Expr::Previous(..) => return Err(format!("{} has no Lepton equivalent", expr.refs()[0].0.quoted())),
        Expr::Unary { op: UnaryOp::Neg, arg, .. } => format!("(-{})", go(arg)?),
        Expr::Unary { op: UnaryOp::Not, arg, .. } => format!("delta({})", go(arg)?),
        Expr::Binary { op, lhs, rhs, .. } => {
            let (a, b) = (go(lhs)?, go(rhs)?);
            match op {
                BinaryOp::Add => format!("({a}+{b})"),
                BinaryOp::Sub => format!("({a}-{b})"),
                BinaryOp::Mul => format!("({a}*{b})"),
                BinaryOp::Div => format!("({a}/{b})"),
                BinaryOp::Pow => format!("({a}^{b})"),
                BinaryOp::Lt => format!("(1-step({a}-{b}))"),
                BinaryOp::Le => format!("step({b}-{a})"),
                BinaryOp::Gt => format!("(1-step({b}-{a}))"),
                BinaryOp::Ge => format!("step({a}-{b})"),
                BinaryOp::Eq => format!("delta({a}-{b})"),
                BinaryOp::Ne => format!("(1-delta({a}-{b}))"),
                BinaryOp::And => format!("((1-delta({a}))*(1-delta({b})))"),
                BinaryOp::Or => format!("(1-delta({a})*delta({b}))"),
            }
        }
        Expr::Call { function, args, .. } => {
            let args: Vec<String> = args.iter().map(go).collect::<Result<_, _>>()?;
            match function.name {
                "ln" => format!("log({})", args[0]),
                "log10" => format!("(log({})/log(10))", args[0]),
                "pow" => format!("({}^{})", args[0], args[1]),
                "min" | "max" => args[1..].iter().fold(args[0].clone(), |acc, a| format!("{}({acc},{a})", function.name)),
                "round" => return Err("`round` has no Lepton equivalent".into()),
                name => format!("{name}({})", args.join(",")),
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::parse;

    #[test]
    fn lepton_keeps_the_tree_and_substitutes_parameters() {
        let k = |n: &str| (n == "k").then_some(2.5);
        let cases = [
            ("0.5*k*(r-1)^2", "(((0.5)*(2.5))*((r-(1.0))^(2.0)))"),
            ("ln(r) + log10(r)", "(log(r)+(log(r)/log(10)))"),
            ("max(r, 1, k)", "max(max(r,(1.0)),(2.5))"),
            ("(r < 1)*k + !(r >= 2)", "(((1-step(r-(1.0)))*(2.5))+delta(step(r-(2.0))))"),
            ("-pow(r, 3)", "(-(r^(3.0)))"),
        ];
        for (text, expected) in cases {
            assert_eq!(lepton(&parse(text).unwrap(), &k).unwrap(), expected, "{text}");
        }
        assert!(lepton(&parse("round(r)").unwrap(), &k).unwrap_err().contains("round"));
    }
}
