//! A compiled form of one or more [`Expr`]s: a flat tape of stack-machine
//! instructions stored as `f64` words, run without walking a tree.
//!
//! [`compile`] resolves every name once (to a parameter or a variable slot,
//! by the caller's rule) and lowers each output's tree in postfix order,
//! ending it with an `OUT k` instruction; [`run`] executes the words with a
//! fixed-size stack on the machine stack. The words are plain numbers, so a
//! tape can travel inside a parameter vector (custom interactions keep theirs
//! behind their parameter values: the interaction laws are plain
//! `fn` pointers that receive only that vector). An integer power `x^n`
//! (|n| ≤ 16) becomes `powi`, as a hand-written law would multiply.
//!
//! The tape checks nothing at run time: a value outside a function's domain
//! gives NaN, which the step loop's blow-up report catches; the tree's
//! [`Expr::eval`] is the checked oracle the tests compare against.
//!
//! ```
//! use cellmd::expr::{parse, tape};
//! let e = parse("k*(r - r0)^2").unwrap();
//! let words = tape::compile(&[&e], &|n| match n { "k" => Some(tape::Slot::Param(0)), "r0" => Some(tape::Slot::Param(1)), "r" => Some(tape::Slot::Var(0)), _ => None }).unwrap();
//! let mut out = [0.0];
//! tape::run(&words, &[2.0, 1.0], &[4.0], &mut out);
//! assert_eq!(out[0], 18.0);
//! ```

use super::{BinaryOp, Expr, ExprError, UnaryOp};

/// Where a name's value comes from when the tape runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// `params[i]`.
    Param(usize),
    /// `vars[i]`.
    Var(usize),
}

/// The deepest stack a tape may use.
pub const STACK: usize = 32;

const CONST: u32 = 0;
const PARAM: u32 = 1;
const VAR: u32 = 2;
const OUT: u32 = 3;
const POWI: u32 = 4;
const NEG: u32 = 10;
const NOT: u32 = 11;
const ADD: u32 = 20;
const SUB: u32 = 21;
const MUL: u32 = 22;
const DIV: u32 = 23;
const POW: u32 = 24;
const LT: u32 = 25;
const LE: u32 = 26;
const GT: u32 = 27;
const GE: u32 = 28;
const EQ: u32 = 29;
const NE: u32 = 30;
const AND: u32 = 31;
const OR: u32 = 32;
const MIN: u32 = 33;
const MAX: u32 = 34;
const ATAN2: u32 = 35;
/// One-argument functions, in this order, from `FIRST_CALL`.
const CALLS: [&str; 14] = ["sqrt", "exp", "ln", "log10", "sin", "cos", "tan", "asin", "acos", "atan", "abs", "floor", "ceil", "round"];
const FIRST_CALL: u32 = 40;

struct Emitter<'a> {
    words: Vec<f64>,
    depth: usize,
    deepest: usize,
    resolve: &'a dyn Fn(&str) -> Option<Slot>,
}

impl Emitter<'_> {
    fn push(&mut self, op: u32, operand: Option<f64>) {
        self.words.push(op as f64);
        self.words.extend(operand);
    }

    fn grow(&mut self, by: isize, at: &Expr) -> Result<(), ExprError> {
        self.depth = (self.depth as isize + by) as usize;
        self.deepest = self.deepest.max(self.depth);
        if self.depth > STACK {
            return Err(ExprError::new(
                at.span(),
                format!("found an expression that needs more than {STACK} stack slots; expected a flatter one"),
            ));
        }
        Ok(())
    }

    fn emit(&mut self, e: &Expr) -> Result<(), ExprError> {
        match e {
            Expr::Number(v, _) => {
                self.push(CONST, Some(*v));
                self.grow(1, e)?;
            }
            Expr::Name(name, span) => {
                let slot = (self.resolve)(name).ok_or_else(|| ExprError::new(*span, format!("found unknown name `{name}`")))?;
                match slot {
                    Slot::Param(i) => self.push(PARAM, Some(i as f64)),
                    Slot::Var(i) => self.push(VAR, Some(i as f64)),
                }
                self.grow(1, e)?;
            }
            Expr::Thermo(_, span) | Expr::Previous(_, span) => {
                let found = e.refs()[0].0.quoted();
                return Err(ExprError::new(*span, format!("found {found}, expected no thermo column in a compiled expression")));
            }
            Expr::Unary { op, arg, .. } => {
                self.emit(arg)?;
                self.push(if *op == UnaryOp::Neg { NEG } else { NOT }, None);
            }
            Expr::Binary { op: BinaryOp::Pow, lhs, rhs, .. } if matches!(**rhs, Expr::Number(n, _) if n.fract() == 0.0 && n.abs() <= 16.0) =>
            {
                let Expr::Number(n, _) = **rhs else { unreachable!("matched above") };
                self.emit(lhs)?;
                self.push(POWI, Some(n));
            }
            Expr::Binary { op, lhs, rhs, .. } => {
                self.emit(lhs)?;
                self.emit(rhs)?;
                let code = match op {
                    BinaryOp::Add => ADD,
                    BinaryOp::Sub => SUB,
                    BinaryOp::Mul => MUL,
                    BinaryOp::Div => DIV,
                    BinaryOp::Pow => POW,
                    BinaryOp::Lt => LT,
                    BinaryOp::Le => LE,
                    BinaryOp::Gt => GT,
                    BinaryOp::Ge => GE,
                    BinaryOp::Eq => EQ,
                    BinaryOp::Ne => NE,
                    BinaryOp::And => AND,
                    BinaryOp::Or => OR,
                };
                self.push(code, None);
                self.grow(-1, e)?;
            }
            Expr::Call { function, args, .. } => {
                self.emit(&args[0])?;
                let binary = match function.name {
                    "min" => Some(MIN),
                    "max" => Some(MAX),
                    "atan2" => Some(ATAN2),
                    "pow" => Some(POW),
                    _ => None,
                };
                match binary {
                    Some(code) => {
                        for a in &args[1..] {
                            self.emit(a)?;
                            self.push(code, None);
                            self.grow(-1, e)?;
                        }
                    }
                    None => {
                        let k = CALLS.iter().position(|c| *c == function.name).expect("every one-argument function has an opcode");
                        self.push(FIRST_CALL + k as u32, None);
                    }
                }
            }
        }
        Ok(())
    }
}

/// The tape computing `outputs[k]` into `out[k]`; a name `resolve` does not
/// know is an error at its span.
pub fn compile(outputs: &[&Expr], resolve: &dyn Fn(&str) -> Option<Slot>) -> Result<Vec<f64>, ExprError> {
    let mut emitter = Emitter { words: Vec::new(), depth: 0, deepest: 0, resolve };
    for (k, e) in outputs.iter().enumerate() {
        emitter.emit(e)?;
        emitter.push(OUT, Some(k as f64));
        emitter.grow(-1, e)?;
    }
    Ok(emitter.words)
}

fn truth(b: bool) -> f64 {
    if b {
        1.0
    } else {
        0.0
    }
}

/// Runs a tape made by [`compile`] (any other words may panic).
#[inline]
pub fn run(tape: &[f64], params: &[f64], vars: &[f64], out: &mut [f64]) {
    let mut stack = [0.0f64; STACK];
    let mut sp = 0usize;
    let mut pc = 0usize;
    while pc < tape.len() {
        let op = tape[pc] as u32;
        pc += 1;
        if op < NEG {
            let operand = tape[pc];
            pc += 1;
            match op {
                CONST => {
                    stack[sp] = operand;
                    sp += 1;
                }
                PARAM => {
                    stack[sp] = params[operand as usize];
                    sp += 1;
                }
                VAR => {
                    stack[sp] = vars[operand as usize];
                    sp += 1;
                }
                OUT => {
                    sp -= 1;
                    out[operand as usize] = stack[sp];
                }
                _ => stack[sp - 1] = stack[sp - 1].powi(operand as i32),
            }
        } else if op < ADD {
            let a = &mut stack[sp - 1];
            *a = if op == NEG { -*a } else { truth(*a == 0.0) };
        } else if op < FIRST_CALL {
            sp -= 1;
            let b = stack[sp];
            let a = &mut stack[sp - 1];
            *a = match op {
                ADD => *a + b,
                SUB => *a - b,
                MUL => *a * b,
                DIV => *a / b,
                POW => a.powf(b),
                LT => truth(*a < b),
                LE => truth(*a <= b),
                GT => truth(*a > b),
                GE => truth(*a >= b),
                EQ => truth(*a == b),
                NE => truth(*a != b),
                AND => truth(*a != 0.0 && b != 0.0),
                OR => truth(*a != 0.0 || b != 0.0),
                MIN => a.min(b),
                MAX => a.max(b),
                _ => a.atan2(b),
            };
        } else {
            let a = &mut stack[sp - 1];
            *a = match op - FIRST_CALL {
                0 => a.sqrt(),
                1 => a.exp(),
                2 => a.ln(),
                3 => a.log10(),
                4 => a.sin(),
                5 => a.cos(),
                6 => a.tan(),
                7 => a.asin(),
                8 => a.acos(),
                9 => a.atan(),
                10 => a.abs(),
                11 => a.floor(),
                12 => a.ceil(),
                _ => a.round(),
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{parse, Ref};
    use super::*;

    /// Every operator and function: the tape gives the tree's value to the
    /// last bit (`powi` aside, which may differ from `powf` by an ulp).
    #[test]
    fn tape_equals_the_tree() {
        let texts = [
            "1 + 2*r - r/3 + -r^2 + r^2.5 + 2^r + pow(r, 3)",
            "(r < 1) + (r <= 1) + (r > 1) + (r >= 1) + (r == 1) + (r != 1) + !(r > 1) + (r > 0 && r < 5) + (r < 0 || r > 1)",
            "sqrt(r) + exp(r) + ln(r) + log10(r) + sin(r) + cos(r) + tan(r) + asin(r/9) + acos(r/9) + atan(r)",
            "abs(-r) + floor(r) + ceil(r) + round(r) + min(r, 2, 3*r) + max(1, r) + atan2(r, 2) + a*b",
        ];
        let resolve = |n: &str| match n {
            "r" => Some(Slot::Var(0)),
            "a" => Some(Slot::Param(0)),
            "b" => Some(Slot::Param(1)),
            _ => None,
        };
        for text in texts {
            let e = parse(text).unwrap();
            let words = compile(&[&e, &e.derivative("r")], &resolve).unwrap();
            for r in [0.3, 1.0, 2.7] {
                let mut out = [0.0; 2];
                run(&words, &[1.5, -2.0], &[r], &mut out);
                let mut names = |x: Ref| match x {
                    Ref::Name("r") => Ok(r),
                    Ref::Name("a") => Ok(1.5),
                    Ref::Name("b") => Ok(-2.0),
                    _ => Err("?".to_string()),
                };
                let tree = e.eval(&mut names).unwrap();
                let slope = e.derivative("r").eval(&mut names).unwrap();
                assert!((out[0] - tree).abs() <= 1e-15 * tree.abs().max(1.0), "{text} at {r}: {} vs {tree}", out[0]);
                assert!((out[1] - slope).abs() <= 1e-15 * slope.abs().max(1.0), "{text}' at {r}: {} vs {slope}", out[1]);
            }
        }
    }

    #[test]
    fn unknown_names_and_deep_stacks_are_errors_at_their_span() {
        let e = parse("r + q").unwrap();
        let err = compile(&[&e], &|n| (n == "r").then_some(Slot::Var(0))).unwrap_err();
        assert_eq!((err.span.start, err.span.end, err.message.as_str()), (4, 5, "found unknown name `q`"));
        let deep = parse(&format!("{}r{}", "(".repeat(40), "+1)".repeat(40))).unwrap();
        assert!(compile(&[&deep], &|_| Some(Slot::Var(0))).is_ok(), "left operands are pushed one at a time");
        let right = parse(&format!("{}1{}", "r+(".repeat(40), ")".repeat(40))).unwrap();
        assert!(compile(&[&right], &|_| Some(Slot::Var(0))).unwrap_err().message.contains("stack slots"));
    }
}
