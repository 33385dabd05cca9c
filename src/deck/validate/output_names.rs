//! One file, one writer: the output files a deck names, checked against
//! each other across kinds (`thermo_file`, `events`, `lifetimes`, `dump`,
//! `write_state`) and against the files cellmd itself writes for the deck
//! (`NAME.log`, `NAME.restart`, `NAME.lastgood.restart`), so that no output
//! silently overwrites another. Whole-file outputs (restarts, the lifetime
//! table) also hold `FILE.tmp`, through which they are written; a `*` in a
//! restart's name stands for any step.
//!
//! Within one kind a name may come back: `write_state` replaces its file,
//! a later `thermo_file` or `events` reopens it, and a dump may reuse the
//! file of an undumped one (two active dumps on one file are refused by
//! `dump` itself).

use std::path::{Component, Path, PathBuf};

use crate::input::{InputError, Token};

/// What writes an output file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum OutputKind {
    ThermoFile,
    Events,
    Lifetimes,
    Dump,
    Restart,
    RunLog,
}

impl OutputKind {
    fn what(self) -> &'static str {
        match self {
            Self::ThermoFile => "`thermo_file`",
            Self::Events => "`events`",
            Self::Lifetimes => "`lifetimes`",
            Self::Dump => "a `dump`",
            Self::Restart => "a restart (`write_state`, or the one a stopped run writes)",
            Self::RunLog => "the run log",
        }
    }

    /// Written through `FILE.tmp` and a rename.
    fn atomic(self) -> bool {
        matches!(self, Self::Restart | Self::Lifetimes)
    }
}

/// One claimed name: the path (normalised), its kind and where it was named.
#[derive(Clone, Debug)]
struct Claim {
    path: PathBuf,
    kind: OutputKind,
    place: String,
}

/// The output names of a deck so far.
#[derive(Clone, Debug, Default)]
pub(super) struct OutputNames {
    claims: Vec<Claim>,
}

/// `path` without `.` components, so `./t.csv` and `t.csv` compare equal.
fn normalised(path: &Path) -> PathBuf {
    path.components().filter(|c| !matches!(c, Component::CurDir)).collect()
}

/// Whether `name` matches `pattern`, where a `*` stands for a step (digits).
fn matches_step_pattern(pattern: &str, name: &str) -> bool {
    match pattern.split_once('*') {
        None => pattern == name,
        Some((head, tail)) => name.strip_prefix(head).is_some_and(|rest| {
            (1..=rest.len()).any(|k| rest[..k].bytes().all(|b| b.is_ascii_digit()) && matches_step_pattern(tail, &rest[k..]))
        }),
    }
}

/// Whether two names (either may hold `*`s) can be one file.
fn same_file(a: &Path, b: &Path) -> bool {
    let (a, b) = (a.to_string_lossy(), b.to_string_lossy());
    let stepped = |p: &str| p.replace('*', "1");
    a == b || matches_step_pattern(&a, &stepped(&b)) || matches_step_pattern(&b, &stepped(&a))
}

impl OutputNames {
    /// The files cellmd writes for a deck named `deck` (its run log, the
    /// restart of a stop and of a blow-up).
    pub(super) fn reserve_for_deck(&mut self, deck: &str) {
        let stem = Path::new(deck).file_stem().map_or("cellmd".into(), |s| s.to_string_lossy().into_owned());
        let place = "which cellmd writes for this deck".to_string();
        let mut claim = |name: String, kind: OutputKind| self.push(PathBuf::from(name), kind, place.clone());
        claim(format!("{stem}.log"), OutputKind::RunLog);
        claim(format!("{stem}.restart"), OutputKind::Restart);
        claim(format!("{stem}.lastgood.restart"), OutputKind::Restart);
    }

    fn push(&mut self, path: PathBuf, kind: OutputKind, place: String) {
        if kind.atomic() {
            let mut tmp = path.clone().into_os_string();
            tmp.push(".tmp");
            self.claims.push(Claim { path: tmp.into(), kind, place: place.clone() });
        }
        self.claims.push(Claim { path, kind, place });
    }

    /// Claims `path` (named by `token`) for `kind`: an error if a writer of
    /// another kind already has it.
    pub(super) fn claim(&mut self, token: &Token, path: &Path, kind: OutputKind) -> Result<(), InputError> {
        let path = normalised(path);
        let mut mine = vec![path.clone()];
        if kind.atomic() {
            let mut tmp = path.clone().into_os_string();
            tmp.push(".tmp");
            mine.push(tmp.into());
        }
        let taken = self.claims.iter().find(|c| c.kind != kind && mine.iter().any(|p| same_file(&c.path, p)));
        if let Some(c) = taken {
            return Err(token.error(format!(
                "`{}` is already written by {} ({}); expected a different file for {}",
                token.text,
                c.kind.what(),
                c.place,
                kind.what()
            )));
        }
        self.push(path, kind, format!("named at {}:{}", token.file.path, token.line));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_with_steps_match_the_files_they_stand_for() {
        assert!(matches_step_pattern("ck.*.restart", "ck.100.restart"));
        assert!(!matches_step_pattern("ck.*.restart", "ck..restart"));
        assert!(!matches_step_pattern("ck.*.restart", "ck.1a.restart"));
        assert!(same_file(Path::new("ck.*.restart"), Path::new("ck.5.restart")));
        assert!(same_file(Path::new("ck.5.restart.tmp"), Path::new("ck.*.restart.tmp")));
        assert!(same_file(Path::new("a/*.r"), Path::new("a/*.r")));
        assert!(!same_file(Path::new("t.csv"), Path::new("u.csv")));
        assert_eq!(normalised(Path::new("./out/./t.csv")), PathBuf::from("out/t.csv"));
    }
}
