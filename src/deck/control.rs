//! Deck control flow: `loop` … `endloop`, `if` … [`else` …] `endif`, `break`.
//!
//! ```text
//! loop VAR FIRST LAST        # VAR = FIRST, FIRST+1, …, LAST (integers; expressions allowed)
//!   …                        # ${VAR} or VAR (in an expression) is the iteration's value
//! endloop
//! if CONDITION then          # CONDITION: an expression, true when non-zero
//!   …
//! else                       # optional
//!   …
//! endif
//! break                      # leaves the innermost loop
//! ```
//!
//! Why blocks rather than LAMMPS' `label`/`next`/`jump`: a block has one
//! entry and one exit, so the deck can be unrolled and validated whole before
//! anything runs. A `loop` is unrolled when the deck is validated: every
//! iteration's `${VAR}` substitutions are checked as the commands they make.
//! An `if` whose condition reads only variables is decided then too — the
//! branch not taken is still validated, on a copy of the deck's state that
//! is thrown away. An `if` whose condition reads a thermo column
//! (`thermo(fx/plate)`) is decided during the run, on the state after the
//! commands before it; both of its branches are validated against the state
//! before the `if`, and may not declare or remove names (`group`, `dump`,
//! `undump`, `external`, `unexternal`, `variable`), so every later command is
//! valid whichever branch ran. A `break` inside such an `if` ends the
//! innermost loop during the run; elsewhere it ends the unrolling.
//!
//! # Limits
//!
//! Unrolling is bounded for the whole deck, so `check` always ends quickly
//! and in bounded memory, whatever the deck: blocks nest at most
//! [`MAX_NESTING`] deep; all loops together run at most [`MAX_ITERATIONS`]
//! iterations (nested loops multiply: every iteration of an inner loop
//! counts, each time); at most [`MAX_STATEMENTS`] commands are validated
//! (after unrolling, both branches of every `if` included); and those
//! commands after `${…}` substitution, with the member lists of the groups
//! they define, hold at most [`MAX_UNROLLED_BYTES`]. Each limit fails with
//! `file:line:col` at the command that crossed it.

use super::expression::{Condition, DeckExpr};
use super::plan::Action;
use super::validate::Validator;
use crate::expr::Ref;
use crate::input::{InputError, Statement, Token};

/// The most `loop`/`if` blocks nested inside each other.
pub const MAX_NESTING: usize = 100;
/// The most loop iterations a deck may unroll to, all loops together.
pub const MAX_ITERATIONS: u64 = 100_000;
/// The most commands a deck may validate, loops unrolled.
pub const MAX_STATEMENTS: u64 = 1_000_000;
/// The most bytes the unrolled commands and their groups' members may hold: 256 MiB.
pub const MAX_UNROLLED_BYTES: u64 = 256 << 20;

/// Commands refused inside an `if` decided during the run.
const DECLARING: [&str; 6] = ["group", "dump", "undump", "external", "unexternal", "variable"];

/// A deck as blocks.
#[derive(Debug)]
pub(super) enum Node {
    Command(Statement),
    Loop { head: Statement, body: Vec<Node> },
    If { head: Statement, then: Vec<Node>, otherwise: Vec<Node> },
}

/// How a block ended.
pub(super) enum Flow {
    Next,
    /// A `break` decided while validating: stop unrolling the loop.
    Break,
}

/// Nests the statements of a deck into blocks.
pub(super) fn blocks(statements: Vec<Statement>) -> Result<Vec<Node>, InputError> {
    let mut iter = statements.into_iter();
    let (nodes, end) = block(&mut iter, None, 0)?;
    match end {
        None => Ok(nodes),
        Some(s) => Err(s.keyword().error(format!("found `{}` without an opening `loop` or `if`", s.keyword().text))),
    }
}

/// Reads nodes up to a closing word (`endloop`, `else`, `endif`), which is
/// returned; `depth` blocks enclose them.
fn block(
    iter: &mut impl Iterator<Item = Statement>,
    opened_by: Option<&Token>,
    depth: usize,
) -> Result<(Vec<Node>, Option<Statement>), InputError> {
    let mut nodes = Vec::new();
    while let Some(s) = iter.next() {
        let kw = s.keyword();
        if matches!(kw.text.as_str(), "loop" | "if") && depth == MAX_NESTING {
            return Err(kw.error(format!(
                "found `{}` at nesting depth {}, expected at most {MAX_NESTING} `loop`/`if` blocks nested in each other",
                kw.text,
                depth + 1
            )));
        }
        match kw.text.as_str() {
            "endloop" | "else" | "endif" => return Ok((nodes, Some(s))),
            "loop" => {
                let (body, end) = block(iter, Some(s.keyword()), depth + 1)?;
                closed_by(&s, end.as_ref(), "endloop")?;
                nodes.push(Node::Loop { head: s, body });
            }
            "if" => {
                let (then, end) = block(iter, Some(s.keyword()), depth + 1)?;
                let end = end.expect("an unclosed block is an error");
                let otherwise = if end.keyword().text == "else" {
                    only_word(&end)?;
                    let (otherwise, end) = block(iter, Some(s.keyword()), depth + 1)?;
                    closed_by(&s, end.as_ref(), "endif")?;
                    otherwise
                } else {
                    closed_by(&s, Some(&end), "endif")?;
                    Vec::new()
                };
                nodes.push(Node::If { head: s, then, otherwise });
            }
            _ => nodes.push(Node::Command(s)),
        }
    }
    match opened_by {
        Some(open) => Err(open.error(format!(
            "this `{}` is never closed; expected `{}` before the end of the deck",
            open.text,
            if open.text == "loop" { "endloop" } else { "endif" }
        ))),
        None => Ok((nodes, None)),
    }
}

fn only_word(s: &Statement) -> Result<(), InputError> {
    match s.tokens.get(1) {
        Some(extra) => Err(extra.error(format!("found `{}` after `{}`, expected the end of the line", extra.text, s.keyword().text))),
        None => Ok(()),
    }
}

fn closed_by(open: &Statement, end: Option<&Statement>, expected: &str) -> Result<(), InputError> {
    let end = end.expect("an unclosed block is an error");
    if end.keyword().text != expected {
        return Err(end.keyword().error(format!(
            "found `{}` inside the `{}` of line {}, expected `{expected}` first",
            end.keyword().text,
            open.keyword().text,
            open.keyword().line
        )));
    }
    only_word(end)
}

/// An integer loop bound: an expression of one token.
fn bound(vars: &super::variables::Variables, token: &Token) -> Result<i64, InputError> {
    let value = DeckExpr::parse(std::slice::from_ref(token))?.eval(vars)?;
    if value.fract() != 0.0 || value.abs() > 1e15 {
        return Err(token.error(format!("found {value}, expected an integer loop bound")));
    }
    Ok(value as i64)
}

impl Validator {
    /// Validates a block; substitutes each command's `${NAME}`s first.
    pub(super) fn block(&mut self, nodes: &[Node]) -> Result<Flow, InputError> {
        for node in nodes {
            let flow = match node {
                Node::Command(s) => self.statement(s)?,
                Node::Loop { head, body } => self.unroll(head, body)?,
                Node::If { head, then, otherwise } => self.branch(head, then, otherwise)?,
            };
            if let Flow::Break = flow {
                return Ok(Flow::Break);
            }
        }
        Ok(Flow::Next)
    }

    fn statement(&mut self, statement: &Statement) -> Result<Flow, InputError> {
        let kw = statement.keyword();
        self.control.budget.statements += 1;
        if self.control.budget.statements > MAX_STATEMENTS {
            return Err(kw.error(format!(
                "found more than {MAX_STATEMENTS} commands to validate (loops unrolled, both branches of every `if`), expected at most \
                 {MAX_STATEMENTS} in all"
            )));
        }
        if self.control.runtime_branch && DECLARING.contains(&kw.text.as_str()) {
            return Err(kw.error(format!(
                "found `{}` inside an `if` decided during the run (its condition reads thermo); expected commands that declare or \
                 remove no names (not {})",
                kw.text,
                DECLARING.join(", ")
            )));
        }
        if kw.text == "break" {
            only_word(statement)?;
            if self.control.loop_depth == 0 {
                return Err(kw.error("found `break` outside a loop; expected it between `loop` and `endloop`"));
            }
            if !self.control.runtime_in_loop {
                return Ok(Flow::Break);
            }
            self.control.breaks.push(self.actions.len());
            self.actions.push(Action::Skip(0));
            return Ok(Flow::Next);
        }
        if kw.text == "variable" {
            let rest = self.vars.substitute_all(&statement.tokens[1..])?;
            self.vars.define(kw, &rest)?;
            return Ok(Flow::Next);
        }
        let tokens = self.vars.substitute_all(&statement.tokens)?;
        self.spend_bytes(kw, tokens.iter().map(|t| t.text.len() as u64 + 1).sum())?;
        self.command(&tokens)?;
        self.last = Some(kw.clone());
        Ok(Flow::Next)
    }

    /// `loop VAR FIRST LAST`: validates the body once per iteration.
    fn unroll(&mut self, head: &Statement, body: &[Node]) -> Result<Flow, InputError> {
        let s = self.vars.substitute_all(&head.tokens)?;
        if s.len() != 4 {
            let at = s.get(4).unwrap_or(&s[s.len() - 1]);
            return Err(at.error(format!("found {} arguments, expected `loop VAR FIRST LAST`", s.len() - 1)));
        }
        let name = &s[1].text;
        if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') || name.starts_with(|c: char| c.is_ascii_digit()) {
            return Err(s[1].error(format!("found loop variable `{name}`, expected a name of letters, digits and `_`")));
        }
        let (first, last) = (bound(&self.vars, &s[2])?, bound(&self.vars, &s[3])?);
        if last < first {
            return Err(s[3].error(format!("found the empty range {first} … {last}, expected LAST >= FIRST")));
        }
        if (last - first) as u64 >= MAX_ITERATIONS {
            return Err(s[3].error(format!("found {} iterations, expected at most {MAX_ITERATIONS}", last - first + 1)));
        }
        let outer_breaks = std::mem::take(&mut self.control.breaks);
        let outer_runtime = std::mem::replace(&mut self.control.runtime_in_loop, false);
        self.control.loop_depth += 1;
        let previous = self.vars.set_loop(name, first.to_string());
        for i in first..=last {
            self.control.budget.iterations += 1;
            if self.control.budget.iterations > MAX_ITERATIONS {
                return Err(s[3].error(format!(
                    "found more than {MAX_ITERATIONS} loop iterations in this deck (every iteration of every loop counts, so nested loops \
                     multiply), expected at most {MAX_ITERATIONS} in all"
                )));
            }
            self.vars.set_loop(name, i.to_string());
            let flow = self.block(body).map_err(|mut e| {
                e.message.push_str(&format!(" (in the iteration {name} = {i} of the loop at line {})", head.keyword().line));
                e
            })?;
            if let Flow::Break = flow {
                break;
            }
        }
        self.vars.restore(name, previous);
        let end = self.actions.len();
        for at in std::mem::replace(&mut self.control.breaks, outer_breaks) {
            self.actions[at] = Action::Skip(end - at - 1);
        }
        self.control.runtime_in_loop = outer_runtime;
        self.control.loop_depth -= 1;
        Ok(Flow::Next)
    }

    /// A copy of the validator with no actions, for validating a branch.
    fn shadow(&mut self) -> Validator {
        let actions = std::mem::take(&mut self.actions);
        let breaks = std::mem::take(&mut self.control.breaks);
        let copy = self.clone();
        self.actions = actions;
        self.control.breaks = breaks;
        copy
    }

    /// `if CONDITION then … [else …] endif`.
    fn branch(&mut self, head: &Statement, then: &[Node], otherwise: &[Node]) -> Result<Flow, InputError> {
        let kw = head.keyword();
        let s = self.vars.substitute_all(&head.tokens[1..])?;
        let Some((_, condition)) = s.split_last().filter(|(t, c)| t.text == "then" && !c.is_empty()) else {
            let at = s.last().unwrap_or(kw);
            return Err(at.error(format!("found `{}`, expected `if CONDITION then`", at.text)));
        };
        let condition = DeckExpr::parse(condition)?;
        if !condition.reads_thermo() {
            let taken = condition.eval(&self.vars)? != 0.0;
            let (run, skipped) = if taken { (then, otherwise) } else { (otherwise, then) };
            let mut shadow = self.shadow();
            shadow.block(skipped)?;
            self.control.budget = shadow.control.budget;
            return self.block(run);
        }
        self.model(kw)?;
        let condition = self.condition(condition, kw)?;
        let mut arms = [then, otherwise].map(|_| (Vec::new(), Vec::new()));
        for (arm, nodes) in arms.iter_mut().zip([then, otherwise]) {
            let mut shadow = self.shadow();
            shadow.control.runtime_branch = true;
            shadow.control.runtime_in_loop = self.control.loop_depth > 0;
            shadow.block(nodes)?;
            self.control.budget = shadow.control.budget;
            // Either arm may run: the files it writes are taken.
            self.take_output_names(&shadow);
            *arm = (shadow.actions, shadow.control.breaks);
        }
        let [(then_actions, then_breaks), (else_actions, else_breaks)] = arms;
        let jump = usize::from(!else_actions.is_empty());
        self.actions.push(Action::Branch { condition, skip: then_actions.len() + jump });
        let base = self.actions.len();
        self.control.breaks.extend(then_breaks.iter().map(|b| b + base));
        self.actions.extend(then_actions);
        if jump == 1 {
            self.actions.push(Action::Skip(else_actions.len()));
        }
        let base = self.actions.len();
        self.control.breaks.extend(else_breaks.iter().map(|b| b + base));
        self.actions.extend(else_actions);
        Ok(Flow::Next)
    }

    /// Resolves a run-time condition's variables (now) and thermo columns.
    fn condition(&mut self, condition: DeckExpr, at: &Token) -> Result<Condition, InputError> {
        let mut names = Vec::new();
        let mut columns = Vec::new();
        for (r, span) in condition.expr.refs() {
            let located = |message: String| condition.error(&crate::expr::ExprError { span, message });
            match r {
                Ref::Name(name) => names.push((name.to_string(), self.vars.number(name).map_err(located)?)),
                Ref::Thermo(text) | Ref::Previous(text) => {
                    let column = self.thermo_columns(&[at.with_text(text.to_string())]).map_err(|e| located(e.message))?;
                    if !columns.iter().any(|(t, _)| t == text) {
                        columns.push((text.to_string(), column[0].clone()));
                    }
                }
            }
        }
        let place = format!("{}:{}:{}", at.file.path, at.line, at.col);
        Ok(Condition { expr: condition.expr, names, columns, at: place })
    }
}

/// What the deck has spent of its limits so far (see the module docs).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Budget {
    pub iterations: u64,
    pub statements: u64,
    pub bytes: u64,
}

impl Validator {
    /// Charges `bytes` held by the plan or the validator (substituted
    /// commands, group members) to the deck's budget.
    pub(super) fn spend_bytes(&mut self, at: &Token, bytes: u64) -> Result<(), InputError> {
        self.control.budget.bytes += bytes;
        if self.control.budget.bytes > MAX_UNROLLED_BYTES {
            return Err(at.error(format!(
                "found more than {MAX_UNROLLED_BYTES} bytes in the unrolled deck's commands and the members of its groups, expected at \
                 most 256 MiB in all"
            )));
        }
        Ok(())
    }
}

/// Control-flow state of the validator.
#[derive(Clone, Debug, Default)]
pub(super) struct ControlState {
    /// Limits spent so far (carried back from the copies that validate branches).
    pub budget: Budget,
    /// Loops around the command being validated.
    pub loop_depth: usize,
    /// Inside an `if` decided during the run (of any enclosing loop).
    pub runtime_branch: bool,
    /// Inside such an `if` within the innermost loop: a `break` is decided during the run.
    pub runtime_in_loop: bool,
    /// Positions of the run-time `break` jumps of the innermost loop, patched at its end.
    pub breaks: Vec<usize>,
}
