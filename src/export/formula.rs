//! An expression tree ([`crate::expr`]) as a LAMMPS variable formula.
//!
//! | cellmd | LAMMPS |
//! |---|---|
//! | `x`, `y`, `z` (unwrapped) | `x`, `y`, `z` (wrapped: the same on non-periodic axes) |
//! | `t` | `time` |
//! | `+ - * / ^ < <= > >= == != && \|\| !` | the same operators |
//! | `sqrt exp ln abs sin cos tan asin acos atan atan2 floor ceil round` | the same functions |
//! | `log10(a)` | `log(a)` (LAMMPS' `log` is base 10) |
//! | `pow(a, b)` | `(a)^(b)` |
//! | `min(a, b, …)`, `max(a, b, …)` | nested `ternary(a<b, a, b)` |
//!
//! Every sub-expression is parenthesised, so precedence never differs.

use crate::expr::{BinaryOp, Expr, UnaryOp};
use crate::interactions::lammps::num;

/// The formula of a tree whose names are `x`, `y`, `z` and `t` only.
pub fn lammps_formula(expr: &Expr) -> Result<String, String> {
    Ok(match expr {
        Expr::Number(v, _) => num(*v),
        Expr::Name(name, _) => match name.as_str() {
            "x" | "y" | "z" => name.clone(),
            "t" => "time".into(),
            other => return Err(format!("the name `{other}` has no LAMMPS equivalent")),
        },
        Expr::Thermo(..) | Expr::Previous(..) => {
            return Err(format!("{} has no LAMMPS equivalent in an atom-style variable", expr.refs()[0].0.quoted()))
        }
        Expr::Unary { op, arg, .. } => {
            let a = lammps_formula(arg)?;
            match op {
                UnaryOp::Neg => format!("(-{a})"),
                UnaryOp::Not => format!("(!{a})"),
            }
        }
        Expr::Binary { op, lhs, rhs, .. } => {
            let symbol = match op {
                BinaryOp::Add => "+",
                BinaryOp::Sub => "-",
                BinaryOp::Mul => "*",
                BinaryOp::Div => "/",
                BinaryOp::Pow => "^",
                BinaryOp::Lt => "<",
                BinaryOp::Le => "<=",
                BinaryOp::Gt => ">",
                BinaryOp::Ge => ">=",
                BinaryOp::Eq => "==",
                BinaryOp::Ne => "!=",
                BinaryOp::And => "&&",
                BinaryOp::Or => "||",
            };
            format!("({}{symbol}{})", lammps_formula(lhs)?, lammps_formula(rhs)?)
        }
        Expr::Call { function, args, .. } => {
            let args: Vec<String> = args.iter().map(lammps_formula).collect::<Result<_, _>>()?;
            match function.name {
                "log10" => format!("log({})", args[0]),
                "pow" => format!("({}^{})", args[0], args[1]),
                "min" | "max" => {
                    let cmp = if function.name == "min" { "<" } else { ">" };
                    args[1..].iter().fold(args[0].clone(), |acc, a| format!("ternary({acc}{cmp}{a},{acc},{a})"))
                }
                name => format!("{name}({})", args.join(",")),
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formulas_keep_the_tree() {
        let cases = [
            ("-2*(x - 0.5*t)", "((-2.0)*(x-(0.5*time)))"),
            ("log10(z) + pow(y, 2)", "(log(z)+(y^2.0))"),
            ("max(x, 1, y)", "ternary(ternary(x>1.0,x,1.0)>y,ternary(x>1.0,x,1.0),y)"),
            ("t >= 1 && !(x < 0)", "((time>=1.0)&&(!(x<0.0)))"),
            ("atan2(y, x)", "atan2(y,x)"),
        ];
        for (text, expected) in cases {
            assert_eq!(lammps_formula(&crate::expr::parse(text).unwrap()).unwrap(), expected, "{text}");
        }
        assert!(lammps_formula(&crate::expr::parse("g*x").unwrap()).unwrap_err().contains("`g`"));
    }
}
