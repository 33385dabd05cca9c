//! An [`Expr`] as WGSL source in `f32`, for GPU evaluators generated from
//! the same tree the CPU compiles (issue: custom force fields).
//!
//! Every sub-expression is parenthesised; numbers become `f32` literals
//! (refused beyond `f32`'s range); names are what `name` returns (a
//! parameter slot `p[3]`, a variable `r`), an unknown one is an error at its
//! span. Comparisons and logic give `select(0.0, 1.0, …)`; `ln` is WGSL's
//! natural `log`, `log10(a)` is `log(a) * log10(e)`; an integer power `a^n`
//! (|n| ≤ 16) is a product, since WGSL's `pow` is undefined for a negative
//! base; `min` and `max` nest pairwise.

use super::{BinaryOp, Expr, ExprError, UnaryOp};

fn literal(v: f64, at: &Expr) -> Result<String, ExprError> {
    let single = v as f32;
    if !single.is_finite() || (v != 0.0 && single == 0.0) {
        return Err(ExprError::new(at.span(), format!("found the number {v}, expected one that f32 holds (for the GPU)")));
    }
    Ok(format!("({single:?})"))
}

fn select(condition: String) -> String {
    format!("select(0.0, 1.0, {condition})")
}

/// The WGSL `f32` expression of `expr`.
pub fn wgsl(expr: &Expr, name: &dyn Fn(&str) -> Option<String>) -> Result<String, ExprError> {
    let go = |e: &Expr| wgsl(e, name);
    Ok(match expr {
        Expr::Number(v, _) => literal(*v, expr)?,
        Expr::Name(n, span) => name(n).ok_or_else(|| ExprError::new(*span, format!("found unknown name `{n}`")))?,
        Expr::Thermo(_, span) | Expr::Previous(_, span) => {
            return Err(ExprError::new(*span, format!("found {}, expected no thermo column on the GPU", expr.refs()[0].0.quoted())))
        }
        Expr::Unary { op: UnaryOp::Neg, arg, .. } => format!("(-{})", go(arg)?),
        Expr::Unary { op: UnaryOp::Not, arg, .. } => select(format!("{} == 0.0", go(arg)?)),
        Expr::Binary { op: BinaryOp::Pow, lhs, rhs, .. } if matches!(**rhs, Expr::Number(n, _) if n.fract() == 0.0 && n.abs() <= 16.0) => {
            let Expr::Number(n, _) = **rhs else { unreachable!("matched above") };
            let base = go(lhs)?;
            let product = if n == 0.0 { "1.0".to_string() } else { vec![base; n.abs() as usize].join(" * ") };
            if n < 0.0 {
                format!("(1.0 / ({product}))")
            } else {
                format!("({product})")
            }
        }
        Expr::Binary { op, lhs, rhs, .. } => {
            let (a, b) = (go(lhs)?, go(rhs)?);
            match op {
                BinaryOp::Add => format!("({a} + {b})"),
                BinaryOp::Sub => format!("({a} - {b})"),
                BinaryOp::Mul => format!("({a} * {b})"),
                BinaryOp::Div => format!("({a} / {b})"),
                BinaryOp::Pow => format!("pow({a}, {b})"),
                BinaryOp::Lt => select(format!("{a} < {b}")),
                BinaryOp::Le => select(format!("{a} <= {b}")),
                BinaryOp::Gt => select(format!("{a} > {b}")),
                BinaryOp::Ge => select(format!("{a} >= {b}")),
                BinaryOp::Eq => select(format!("{a} == {b}")),
                BinaryOp::Ne => select(format!("{a} != {b}")),
                BinaryOp::And => select(format!("({a} != 0.0) && ({b} != 0.0)")),
                BinaryOp::Or => select(format!("({a} != 0.0) || ({b} != 0.0)")),
            }
        }
        Expr::Call { function, args, .. } => {
            let args: Vec<String> = args.iter().map(go).collect::<Result<_, _>>()?;
            match function.name {
                "ln" => format!("log({})", args[0]),
                "log10" => format!("(log({}) * 0.4342944819032518)", args[0]),
                "min" | "max" => args[1..].iter().fold(args[0].clone(), |acc, a| format!("{}({acc}, {a})", function.name)),
                "pow" => format!("pow({}, {})", args[0], args[1]),
                n => format!("{n}({})", args.join(", ")),
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::super::parse;
    use super::*;

    /// Every operator and function becomes WGSL that naga accepts, in a
    /// function of a variable `r` and parameter slots `p[k]`, together with
    /// its symbolic derivative.
    #[test]
    fn generated_wgsl_validates_with_naga() {
        let texts = [
            "0.5*k*(r-r0)^2",
            "A*(1+cos(pi*r/rc))",
            "(r < 1) + (r <= 1) + (r > 1) + (r >= 1) + (r == 1) + (r != 1) + !(r > 1) + (r > 0 && r < 5) + (r < 0 || r > 1)",
            "sqrt(r) + exp(r) + ln(r) + log10(r) + sin(r) + cos(r) + tan(r) + asin(r/9) + acos(r/9) + atan(r) + atan2(r, 2)",
            "abs(-r) + floor(r) + ceil(r) + round(r) + min(r, 2, 3*r) + max(1, r) + pow(r, 2.5) + r^-2 + r^k",
        ];
        let name = |n: &str| match n {
            "r" => Some("r".to_string()),
            "k" => Some("p[0]".into()),
            "r0" => Some("p[1]".into()),
            "A" => Some("p[2]".into()),
            "rc" => Some("p[3]".into()),
            _ => None,
        };
        let mut module = String::new();
        for (i, text) in texts.iter().enumerate() {
            let e = parse(text).unwrap();
            let (value, slope) = (wgsl(&e, &name).unwrap(), wgsl(&e.derivative("r"), &name).unwrap());
            module += &format!("fn law_{i}(p: array<f32, 8>, r: f32) -> vec2<f32> {{\n    return vec2<f32>({value}, {slope});\n}}\n");
        }
        let parsed = naga::front::wgsl::parse_str(&module).unwrap_or_else(|e| panic!("{}\n{module}", e.emit_to_string(&module)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
            .validate(&parsed)
            .unwrap_or_else(|e| panic!("{e:?}\n{module}"));
        assert_eq!(wgsl(&parse("r^3").unwrap(), &name).unwrap(), "(r * r * r)");
        assert!(wgsl(&parse("1e300*r").unwrap(), &name).unwrap_err().message.contains("f32"));
        assert_eq!(wgsl(&parse("q").unwrap(), &name).unwrap_err().message, "found unknown name `q`");
    }
}
