//! The function table: name, arity and a domain-checked evaluator.

/// How many arguments a function takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arity {
    Exactly(usize),
    AtLeast(usize),
}

/// A built-in function.
#[derive(Debug)]
pub struct Function {
    pub name: &'static str,
    pub arity: Arity,
    /// The value, or what is outside the domain ("expected …").
    pub eval: fn(&[f64]) -> Result<f64, String>,
}

impl PartialEq for Function {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

impl Function {
    /// "1 argument", "2 arguments", "at least 2 arguments".
    pub fn arity_text(&self) -> String {
        match self.arity {
            Arity::Exactly(1) => "1 argument".into(),
            Arity::Exactly(n) => format!("{n} arguments"),
            Arity::AtLeast(n) => format!("at least {n} arguments"),
        }
    }

    pub fn accepts(&self, n: usize) -> bool {
        match self.arity {
            Arity::Exactly(k) => n == k,
            Arity::AtLeast(k) => n >= k,
        }
    }
}

fn domain(ok: bool, value: f64, expected: &str) -> Result<f64, String> {
    if ok {
        Ok(value)
    } else {
        Err(expected.to_string())
    }
}

const fn f1(name: &'static str, eval: fn(&[f64]) -> Result<f64, String>) -> Function {
    Function { name, arity: Arity::Exactly(1), eval }
}

/// Every function an expression may call.
pub static FUNCTIONS: &[Function] = &[
    f1("sqrt", |a| domain(a[0] >= 0.0, a[0].sqrt(), "an argument >= 0")),
    f1("exp", |a| Ok(a[0].exp())),
    f1("ln", |a| domain(a[0] > 0.0, a[0].ln(), "an argument > 0")),
    f1("log10", |a| domain(a[0] > 0.0, a[0].log10(), "an argument > 0")),
    f1("sin", |a| Ok(a[0].sin())),
    f1("cos", |a| Ok(a[0].cos())),
    f1("tan", |a| Ok(a[0].tan())),
    f1("asin", |a| domain(a[0].abs() <= 1.0, a[0].asin(), "an argument in [-1, 1]")),
    f1("acos", |a| domain(a[0].abs() <= 1.0, a[0].acos(), "an argument in [-1, 1]")),
    f1("atan", |a| Ok(a[0].atan())),
    Function { name: "atan2", arity: Arity::Exactly(2), eval: |a| Ok(a[0].atan2(a[1])) },
    f1("abs", |a| Ok(a[0].abs())),
    Function { name: "min", arity: Arity::AtLeast(2), eval: |a| Ok(a.iter().copied().fold(f64::INFINITY, f64::min)) },
    Function { name: "max", arity: Arity::AtLeast(2), eval: |a| Ok(a.iter().copied().fold(f64::NEG_INFINITY, f64::max)) },
    f1("floor", |a| Ok(a[0].floor())),
    f1("ceil", |a| Ok(a[0].ceil())),
    f1("round", |a| Ok(a[0].round())),
    Function { name: "pow", arity: Arity::Exactly(2), eval: |a| power(a[0], a[1]) },
];

/// x^y, refusing a negative base with a fractional exponent and 0 to a negative power.
pub(crate) fn power(x: f64, y: f64) -> Result<f64, String> {
    if x < 0.0 && y.fract() != 0.0 {
        return Err(format!("a base >= 0 or an integer exponent (found {x}^{y})"));
    }
    if x == 0.0 && y < 0.0 {
        return Err(format!("a base != 0 for a negative exponent (found 0^{y})"));
    }
    Ok(x.powf(y))
}

/// The function of a name, if any.
pub fn function(name: &str) -> Option<&'static Function> {
    FUNCTIONS.iter().find(|f| f.name == name)
}

/// The names of all functions, for "expected …" messages.
pub fn names() -> String {
    FUNCTIONS.iter().map(|f| f.name).collect::<Vec<_>>().join(", ")
}
