//! The input files a deck was read from, kept so that a restart can carry
//! them and a run can continue with no file of the original on disk.
//!
//! Every `SourceFile::read` (the lexer's) inside
//! [`recording`] is noted with its path as shown in diagnostics and its
//! text; inside [`replaying`] the same reads are answered from a saved set
//! instead of the disk (a path missing from the set is an error, never a
//! silent fallback to whatever file has that name today). The scope is the
//! current thread and the closure: validation reads files on one thread.
//!
//! ```
//! use cellmd::input::{recording, replaying, SourceFile};
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("a.ff");
//! std::fs::write(&path, "particle p drag 1\n").unwrap();
//! let (_, files) = recording(|| SourceFile::read(&path, None).unwrap());
//! std::fs::remove_file(&path).unwrap();
//! let again = replaying(&files, || SourceFile::read(&path, None)).unwrap();
//! assert_eq!(again.text, "particle p drag 1\n");
//! ```

use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;

use serde::{Deserialize, Serialize};

/// One input file as read: its path (as diagnostics show it) and text.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct InputFile {
    pub path: String,
    pub text: String,
}

struct Scope {
    replay: Option<Rc<HashMap<String, String>>>,
    read: Vec<InputFile>,
}

thread_local! {
    static SCOPES: RefCell<Vec<Scope>> = const { RefCell::new(Vec::new()) };
}

fn scoped<T>(replay: Option<Rc<HashMap<String, String>>>, f: impl FnOnce() -> T) -> (T, Vec<InputFile>) {
    // An inner scope answers from the set of the scope around it.
    let replay = replay.or_else(|| SCOPES.with(|s| s.borrow().last().and_then(|top| top.replay.clone())));
    SCOPES.with(|s| s.borrow_mut().push(Scope { replay, read: Vec::new() }));
    struct Pop;
    impl Drop for Pop {
        fn drop(&mut self) {
            SCOPES.with(|s| s.borrow_mut().pop());
        }
    }
    let pop = Pop;
    let value = f();
    let read = SCOPES.with(|s| std::mem::take(&mut s.borrow_mut().last_mut().expect("pushed above").read));
    drop(pop);
    (value, read)
}

/// Runs `f`, returning what it returned and every input file it read, in
/// order of first reading (a file read twice is listed once).
pub fn recording<T>(f: impl FnOnce() -> T) -> (T, Vec<InputFile>) {
    scoped(None, f)
}

/// Runs `f` with every input read answered from `files` instead of the disk.
pub fn replaying<T>(files: &[InputFile], f: impl FnOnce() -> T) -> T {
    let set = files.iter().map(|file| (file.path.clone(), file.text.clone())).collect();
    scoped(Some(Rc::new(set)), f).0
}

/// The saved text of `path` when replaying: `Some(Ok(text))`, `Some(Err)`
/// when the set lacks the path, `None` when not replaying (read the disk).
pub(crate) fn replayed(path: &str) -> Option<Result<String, String>> {
    SCOPES.with(|s| {
        let scopes = s.borrow();
        let set = scopes.last()?.replay.as_ref()?;
        Some(set.get(path).cloned().ok_or_else(|| format!("`{path}` is not among the input files the restart carries")))
    })
}

/// Whether inputs are being answered from a saved set (`cellmd run
/// --continue`): checks of other files on disk do not apply then.
pub fn is_replaying() -> bool {
    SCOPES.with(|s| s.borrow().last().is_some_and(|top| top.replay.is_some()))
}

/// Notes a file read in the innermost scope, if any.
pub(crate) fn note(path: &str, text: &str) {
    SCOPES.with(|s| {
        if let Some(top) = s.borrow_mut().last_mut() {
            if !top.read.iter().any(|f| f.path == path) {
                top.read.push(InputFile { path: path.to_string(), text: text.to_string() });
            }
        }
    })
}

/// What a deck was made of: its path, the `--var` overrides it was read
/// with, and every input file read (the deck first).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct DeckInputs {
    pub deck: String,
    pub vars: Vec<(String, String)>,
    pub files: Vec<InputFile>,
}
