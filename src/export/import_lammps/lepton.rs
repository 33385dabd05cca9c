//! A LAMMPS Lepton expression (`bond_style lepton`, `angle_style lepton`,
//! `pair_style lepton`) as a cellmd expression (`custom` law), the inverse
//! of `interactions::custom::lepton`.
//!
//! Lepton's grammar is the usual one (`+ - * / ^`, `^` binding tightest and
//! to the right, unary minus, function calls); an expression may end in
//! definitions `EXPR; a=…; b=…`, which are substituted (parenthesised) into
//! it. Functions:
//!
//! | Lepton | cellmd |
//! |---|---|
//! | `sqrt exp sin cos tan asin acos atan atan2 abs min max floor ceil` | the same |
//! | `log(x)` (natural) | `ln(x)` |
//! | `square(x)`, `cube(x)`, `recip(x)` | `(x)^2`, `(x)^3`, `1/(x)` |
//! | `step(x)` (1 for x ≥ 0), `delta(x)` (1 for x = 0) | `(x >= 0)`, `(x == 0)` |
//! | `sinh cosh tanh` | through `exp` |
//! | `sec csc cot` | `1/cos`, `1/sin`, `cos/sin` |
//! | `select(c, a, b)` | `(c != 0)*(a) + (c == 0)*(b)` |
//!
//! Any other function (`erf`, `erfc`, …) is an error naming it. Names are
//! the style's variable (`r` or `theta`) and the definitions; numbers are
//! written as they were.

use std::collections::BTreeMap;

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Number(String),
    Name(String),
    Op(char),
}

fn tokens(text: &str) -> Result<Vec<Token>, String> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut k = 0;
    while k < chars.len() {
        let c = chars[k];
        if c.is_whitespace() {
            k += 1;
        } else if c.is_ascii_digit() || (c == '.' && chars.get(k + 1).is_some_and(char::is_ascii_digit)) {
            let start = k;
            while k < chars.len() && (chars[k].is_ascii_digit() || chars[k] == '.') {
                k += 1;
            }
            if k < chars.len() && (chars[k] == 'e' || chars[k] == 'E') {
                let exponent = k + 1 + usize::from(matches!(chars.get(k + 1), Some('+' | '-')));
                if chars.get(exponent).is_some_and(char::is_ascii_digit) {
                    k = exponent;
                    while k < chars.len() && chars[k].is_ascii_digit() {
                        k += 1;
                    }
                }
            }
            out.push(Token::Number(chars[start..k].iter().collect()));
        } else if c.is_ascii_alphabetic() || c == '_' {
            let start = k;
            while k < chars.len() && (chars[k].is_ascii_alphanumeric() || chars[k] == '_') {
                k += 1;
            }
            out.push(Token::Name(chars[start..k].iter().collect()));
        } else if "+-*/^(),".contains(c) {
            out.push(Token::Op(c));
            k += 1;
        } else {
            return Err(format!("found `{c}` in the Lepton expression, expected a number, a name, an operator or a parenthesis"));
        }
    }
    Ok(out)
}

struct Parser<'a> {
    tokens: Vec<Token>,
    at: usize,
    variable: &'a str,
    definitions: &'a BTreeMap<String, String>,
}

impl Parser<'_> {
    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.at)
    }

    fn eat(&mut self, op: char) -> bool {
        if self.peek() == Some(&Token::Op(op)) {
            self.at += 1;
            true
        } else {
            false
        }
    }

    fn expect(&mut self, op: char) -> Result<(), String> {
        if self.eat(op) {
            Ok(())
        } else {
            Err(format!("expected `{op}` in the Lepton expression, found {}", self.describe()))
        }
    }

    fn describe(&self) -> String {
        match self.peek() {
            None => "its end".into(),
            Some(Token::Number(n) | Token::Name(n)) => format!("`{n}`"),
            Some(Token::Op(c)) => format!("`{c}`"),
        }
    }

    /// sum := product (("+" | "-") product)*
    fn sum(&mut self) -> Result<String, String> {
        let mut out = self.product()?;
        loop {
            if self.eat('+') {
                out = format!("{out} + {}", self.product()?);
            } else if self.eat('-') {
                out = format!("{out} - {}", self.product()?);
            } else {
                return Ok(out);
            }
        }
    }

    /// product := unary (("*" | "/") unary)*
    fn product(&mut self) -> Result<String, String> {
        let mut out = self.unary()?;
        loop {
            if self.eat('*') {
                out = format!("{out}*{}", self.unary()?);
            } else if self.eat('/') {
                out = format!("{out}/{}", self.unary()?);
            } else {
                return Ok(out);
            }
        }
    }

    /// unary := "-" unary | power
    fn unary(&mut self) -> Result<String, String> {
        if self.eat('-') {
            return Ok(format!("(-{})", self.unary()?));
        }
        self.power()
    }

    /// power := atom ("^" unary)?   (right-associative)
    fn power(&mut self) -> Result<String, String> {
        let base = self.atom()?;
        if self.eat('^') {
            let exponent = self.unary()?;
            return Ok(format!("({base}^{exponent})"));
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<String, String> {
        match self.peek().cloned() {
            Some(Token::Number(n)) => {
                self.at += 1;
                Ok(n)
            }
            Some(Token::Op('(')) => {
                self.at += 1;
                let inner = self.sum()?;
                self.expect(')')?;
                Ok(format!("({inner})"))
            }
            Some(Token::Name(name)) => {
                self.at += 1;
                if self.eat('(') {
                    let mut args = vec![self.sum()?];
                    while self.eat(',') {
                        args.push(self.sum()?);
                    }
                    self.expect(')')?;
                    return call(&name, &args);
                }
                if name == self.variable {
                    Ok(name)
                } else if let Some(value) = self.definitions.get(&name) {
                    Ok(format!("({value})"))
                } else {
                    Err(format!(
                        "found `{name}` in the Lepton expression, expected the variable `{}` or a name defined after `;`",
                        self.variable
                    ))
                }
            }
            _ => Err(format!("expected a number, a name or `(` in the Lepton expression, found {}", self.describe())),
        }
    }
}

/// A Lepton function call in cellmd's expression language.
fn call(name: &str, args: &[String]) -> Result<String, String> {
    let arity = match name {
        "atan2" | "min" | "max" => 2,
        "select" => 3,
        _ => 1,
    };
    if args.len() != arity {
        return Err(format!("Lepton's `{name}` takes {arity} argument(s), found {}", args.len()));
    }
    let x = &args[0];
    Ok(match name {
        "sqrt" | "exp" | "sin" | "cos" | "tan" | "asin" | "acos" | "atan" | "abs" | "floor" | "ceil" => format!("{name}({x})"),
        "atan2" | "min" | "max" => format!("{name}({x}, {})", args[1]),
        "log" => format!("ln({x})"),
        "square" => format!("(({x})^2)"),
        "cube" => format!("(({x})^3)"),
        "recip" => format!("(1/({x}))"),
        "step" => format!("(({x}) >= 0)"),
        "delta" => format!("(({x}) == 0)"),
        "sinh" => format!("((exp({x}) - exp(-({x})))/2)"),
        "cosh" => format!("((exp({x}) + exp(-({x})))/2)"),
        "tanh" => format!("(1 - 2/(exp(2*({x})) + 1))"),
        "sec" => format!("(1/cos({x}))"),
        "csc" => format!("(1/sin({x}))"),
        "cot" => format!("(cos({x})/sin({x}))"),
        "select" => format!("((({x}) != 0)*({}) + (({x}) == 0)*({}))", args[1], args[2]),
        other => return Err(format!("Lepton's `{other}` has no cellmd equivalent (functions: sqrt exp log sin cos tan asin acos atan atan2 abs min max floor ceil square cube recip step delta sinh cosh tanh sec csc cot select)")),
    })
}

/// Why an expression has no translation.
#[derive(Clone, Debug, PartialEq)]
pub enum LeptonError {
    /// Valid Lepton that cellmd cannot express (a function it lacks).
    Untranslatable(String),
    /// Not a valid expression.
    Invalid(String),
}

#[cfg(test)]
impl LeptonError {
    pub fn message(&self) -> &str {
        match self {
            LeptonError::Untranslatable(m) | LeptonError::Invalid(m) => m,
        }
    }
}

/// The cellmd text of a Lepton expression of `variable`, its definitions
/// (`EXPR; a=1; b=2*a`) substituted.
pub fn translate(text: &str, variable: &str) -> Result<String, LeptonError> {
    translate_text(text, variable).map_err(|m| {
        if m.contains("has no cellmd equivalent") {
            LeptonError::Untranslatable(m)
        } else {
            LeptonError::Invalid(m)
        }
    })
}

fn translate_text(text: &str, variable: &str) -> Result<String, String> {
    let mut parts = text.split(';');
    let main = parts.next().unwrap_or("");
    let mut raw: Vec<(String, String)> = Vec::new();
    for part in parts.filter(|p| !p.trim().is_empty()) {
        let (name, value) =
            part.split_once('=').ok_or_else(|| format!("found `{}` after `;`, expected a definition NAME=EXPR", part.trim()))?;
        raw.push((name.trim().to_string(), value.trim().to_string()));
    }
    // Definitions may use each other (in any order): resolve until none is left.
    let mut definitions: BTreeMap<String, String> = BTreeMap::new();
    for _ in 0..=raw.len() {
        let mut progress = false;
        for (name, value) in &raw {
            if definitions.contains_key(name) {
                continue;
            }
            if let Ok(done) = parse(value, variable, &definitions) {
                definitions.insert(name.clone(), done);
                progress = true;
            }
        }
        if !progress {
            break;
        }
    }
    if let Some((name, value)) = raw.iter().find(|(n, _)| !definitions.contains_key(n)) {
        let why = parse(value, variable, &definitions).err().unwrap_or_default();
        return Err(format!("definition `{name}={value}`: {why}"));
    }
    parse(main, variable, &definitions)
}

fn parse(text: &str, variable: &str, definitions: &BTreeMap<String, String>) -> Result<String, String> {
    let mut p = Parser { tokens: tokens(text)?, at: 0, variable, definitions };
    if p.tokens.is_empty() {
        return Err("the Lepton expression is empty".into());
    }
    let out = p.sum()?;
    if p.at < p.tokens.len() {
        return Err(format!("expected an operator in the Lepton expression, found {}", p.describe()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn value(text: &str, variable: &str, at: f64) -> f64 {
        let expr = crate::expr::parse(text).unwrap_or_else(|e| panic!("{text}: {e:?}"));
        expr.eval(&mut |r| match r {
            crate::expr::Ref::Name(n) if n == variable => Ok(at),
            other => Err(format!("unexpected {}", other.quoted())),
        })
        .unwrap()
    }

    #[test]
    fn lepton_expressions_mean_the_same_in_cellmd() {
        for (lepton, variable, at, want) in [
            ("k*r^2; k=2", "r", 0.5, 0.5),
            ("-2^2", "r", 0.0, -4.0),
            ("2^3^2", "r", 0.0, 512.0),
            ("a*b; a=b+1; b=3", "r", 0.0, 12.0),
            ("log(r)+square(r)-recip(r)", "r", 2.0, 2f64.ln() + 4.0 - 0.5),
            ("step(theta)*3 + delta(theta - 1)", "theta", 1.0, 4.0),
            ("select(step(r-1), 5, 7)", "r", 0.5, 7.0),
            ("tanh(r) + cosh(r) - sinh(r)", "r", 0.3, 0.3f64.tanh() + 0.3f64.cosh() - 0.3f64.sinh()),
            ("1.5e-1*min(r, 2)/ 2.", "r", 1.0, 0.075),
        ] {
            let text = translate(lepton, variable).unwrap();
            let got = value(&text, variable, at);
            assert!((got - want).abs() <= 1e-14 * want.abs().max(1.0), "{lepton} -> {text} = {got}, expected {want}");
        }
    }

    #[test]
    fn what_cellmd_cannot_express_is_an_error_naming_it() {
        assert!(matches!(translate("erf(r)", "r").unwrap_err(), LeptonError::Untranslatable(m) if m.contains("`erf`")));
        assert!(translate("k*r", "r").unwrap_err().message().contains("found `k`"));
        assert!(matches!(translate("r*(2", "r").unwrap_err(), LeptonError::Invalid(m) if m.contains("expected `)`")));
        assert!(translate("r; k", "r").unwrap_err().message().contains("definition"));
    }
}
