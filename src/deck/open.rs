//! A deck kept open after validation, for callers that go on issuing
//! commands to the live simulation (the Python API's `command`). Later
//! commands are validated in the deck's context — its units, force field,
//! groups, dumps and variables, the parameter values its `coeff` lines left —
//! by the same code as the deck's own lines, so they fail with the same
//! `file:line:col: found …, expected …` messages (the file being the name the
//! caller gives the text), and come back as [`Action`]s to apply.
//!
//! ```
//! # fn demo(deck: &std::path::Path) -> Result<(), cellmd::input::InputError> {
//! use cellmd::deck::OpenDeck;
//! use cellmd::input::SourceFile;
//! let (mut open, plan) = OpenDeck::open_file(deck, &[("steps".into(), "100".into())])?;
//! let actions = open.commands(&SourceFile::new("<python>", "temperature 300\nrun 10\n"))?;
//! # Ok(()) }
//! ```

use std::path::Path;
use std::sync::Arc;

use super::plan::{Action, Plan, ThermoColumn};
use super::validate::{validate_in, ValidateOptions, Validator};
use crate::input::{lex, InputError, SourceFile};

/// A validated deck whose context later commands are validated in.
pub struct OpenDeck {
    validator: Validator,
}

impl OpenDeck {
    /// Validates a deck given as text (inputs relative to `deck_dir`), as
    /// [`super::validate`] does, and keeps its context.
    pub fn open(file: &Arc<SourceFile>, deck_dir: &Path, overrides: &[(String, String)]) -> Result<(OpenDeck, Plan), InputError> {
        let mut validator = Validator::new(deck_dir, overrides, ValidateOptions::default());
        let plan = validate_in(&mut validator, file)?;
        Ok((OpenDeck { validator }, plan))
    }

    /// Reads and opens a deck file.
    pub fn open_file(path: &Path, overrides: &[(String, String)]) -> Result<(OpenDeck, Plan), InputError> {
        let file = SourceFile::read(path, None)?;
        Self::open(&file, &path.parent().map(Path::to_path_buf).unwrap_or_default(), overrides)
    }

    /// Validates every line of `file` after the deck's own; the actions of
    /// all its lines, or the first line's error (then none is returned).
    /// Setup commands (`topology`, `box`, …) are refused as after a deck's
    /// first `run`.
    pub fn commands(&mut self, file: &Arc<SourceFile>) -> Result<Vec<Action>, InputError> {
        let before = self.validator.actions.len();
        let result = self.validator.statements(file);
        let actions = self.validator.actions.split_off(before);
        result.map(|_| actions)
    }

    /// The thermo column a name such as `pe`, `volume/cell` or
    /// `nbound/link` denotes (`file` holds the name, for the error's position).
    pub fn thermo_column(&self, file: &Arc<SourceFile>) -> Result<ThermoColumn, InputError> {
        let statements = lex(file)?;
        let tokens: Vec<_> = statements.iter().flat_map(|s| s.tokens.iter().cloned()).collect();
        match tokens.as_slice() {
            [one] => Ok(self.validator.thermo_columns(std::slice::from_ref(one))?.remove(0)),
            [] => Err(InputError::in_file(&file.path, "found no column name, expected one thermo column name")),
            [_, second, ..] => Err(second.error(format!("found `{}` after the column name, expected one thermo column name", second.text))),
        }
    }
}
