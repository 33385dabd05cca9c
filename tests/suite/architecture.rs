//! The folder-level import graph of `src/` has no cycle: the crate is layered.
//!
//! A node is a top-level module of the library: a folder (`src/system/`) or
//! a file (`src/mesh.rs`); `lib.rs` and `main.rs` only declare or call them.
//! A file of module A depends on module B when its text names a path
//! `crate::B…` (or `$crate::B…` in a macro), including every item of a group
//! `crate::{B::x, C::{y, z}}` written over any number of lines.
//!
//! Comments count: an intra-doc link ``[`x`](crate::B::x)`` is resolved by
//! rustdoc like a `use`, so a lower layer that links up to a higher one ties
//! the two as much as code would (a rename upstairs breaks the docs
//! downstairs). A lower layer that wants to mention a higher one names it in
//! plain text (`` `backend::stiffness` ``), without `crate::`.
//!
//! Not read: `super::` paths (they stay inside one folder, except from a
//! folder's `mod.rs` or a top-level file, where no `super::` path leaves the
//! module today) and `cellmd::` paths (only `main.rs` uses them).
//!
//! When the graph has a cycle the test fails naming it, with the file and
//! line of one reference per edge.
//!
//! Sizes: no file of `src/` over 600 lines and no struct there over 15
//! named fields (past that a struct is regrouped into named sub-states,
//! issue #40), except those allowed, each with its reason, in
//! `LONG_FILES` and `WIDE_STRUCTS`; an allowed entry that no longer needs
//! its place fails too, so the lists only shrink. The test prints the ten
//! longest files and widest structs (`-- --nocapture`).
//!
//! Inside a folder, files may still import each other in a circle where they
//! share one vocabulary; each such circle must be named, with its reason, in
//! the folder's module doc (`mod.rs`), which the second test checks. There a
//! node is a direct child of the folder (`x.rs`, and `x/` with it), and a
//! child depends on another through `super::x…`, `crate::folder::x…`, or an
//! item that `mod.rs` re-exports from `x` (`pub use self::x::Item`); items
//! defined in `mod.rs` itself (a registry's trait) and `#[cfg(test)]` code
//! after the file's first `#[cfg(test)]` are not read. A file nested deeper
//! is read for `crate::folder::` paths only.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Edges A → B with, for each, one place (`file:line`) that makes it.
type Graph = BTreeMap<String, BTreeMap<String, String>>;

/// The top-level module of a file under `src/` (None for the crate roots).
fn module_of(relative: &Path) -> Option<String> {
    let parts: Vec<String> = relative.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect();
    match parts.as_slice() {
        [file] if file == "lib.rs" || file == "main.rs" => None,
        [file] => file.strip_suffix(".rs").map(str::to_owned),
        [folder, ..] => Some(folder.clone()),
        [] => None,
    }
}

/// The top-level module names of the crate that `text` reaches through
/// `crate::` paths, with the line of each first occurrence.
fn crate_references(text: &str) -> Vec<(String, usize)> {
    path_references(text, "crate::")
}

/// The first segment after every `prefix` in `text` (`prefix` not preceded
/// by an identifier character or `:`), each item's first segment for a
/// group `prefix{…}`, with their lines.
fn path_references(text: &str, prefix: &str) -> Vec<(String, usize)> {
    let bytes = text.as_bytes();
    let mut found = Vec::new();
    let mut from = 0;
    while let Some(offset) = text[from..].find(prefix) {
        let at = from + offset;
        from = at + prefix.len();
        let before = at.checked_sub(1).map(|i| bytes[i]);
        if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == b'_' || c == b':') {
            continue; // e.g. `some_crate::`, `super::super::`
        }
        let line = text[..at].matches('\n').count() + 1;
        let rest = &text[from..];
        if let Some(group) = rest.strip_prefix('{') {
            for name in group_heads(group) {
                found.push((name, line));
            }
        } else {
            found.push((leading_identifier(rest), line));
        }
    }
    found
}

fn leading_identifier(text: &str) -> String {
    text.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect()
}

/// The first identifier of every top-level item of a `{…}` group (`text`
/// starts after the opening brace).
fn group_heads(text: &str) -> Vec<String> {
    let mut heads = Vec::new();
    let mut depth = 0;
    let mut item_start = true;
    for (i, c) in text.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => break,
            '}' => depth -= 1,
            ',' if depth == 0 => item_start = true,
            c if item_start && (c.is_alphanumeric() || c == '_') => {
                heads.push(leading_identifier(&text[i..]));
                item_start = false;
            }
            _ => {}
        }
    }
    heads
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The folder-level graph of sources given as (path relative to `src/`, text).
fn graph(sources: &[(PathBuf, String)]) -> Graph {
    let modules: BTreeSet<String> = sources.iter().filter_map(|(p, _)| module_of(p)).collect();
    let mut edges = Graph::new();
    for (path, text) in sources {
        let Some(from) = module_of(path) else { continue };
        let targets = edges.entry(from.clone()).or_default();
        for (to, line) in crate_references(text) {
            if to != from && modules.contains(&to) {
                targets.entry(to).or_insert_with(|| format!("src/{}:{line}", path.display()));
            }
        }
    }
    edges
}

/// Every strongly connected component of more than one node, each as a
/// shortest closed path through its first member (a → b → … → a).
fn cycles(graph: &Graph) -> Vec<Vec<String>> {
    components(graph).into_iter().map(|c| cycle_within(graph, &c)).collect()
}

/// The strongly connected components of more than one node.
fn components(graph: &Graph) -> Vec<Vec<String>> {
    // Tarjan's algorithm (recursive: the graph has a few dozen nodes).
    struct Tarjan<'a> {
        graph: &'a Graph,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        components: Vec<Vec<&'a str>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a str) {
            let n = self.index.len();
            self.index.insert(v, n);
            self.low.insert(v, n);
            self.stack.push(v);
            let graph = self.graph;
            for w in graph.get(v).into_iter().flat_map(|t| t.keys()) {
                let w = w.as_str();
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let low = self.low[v].min(self.low[w]);
                    self.low.insert(v, low);
                } else if self.stack.contains(&w) {
                    let low = self.low[v].min(self.index[w]);
                    self.low.insert(v, low);
                }
            }
            if self.low[v] == self.index[v] {
                let at = self.stack.iter().position(|&x| x == v).unwrap();
                self.components.push(self.stack.split_off(at));
            }
        }
    }
    let mut t = Tarjan { graph, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), components: Vec::new() };
    let nodes: BTreeSet<&str> = graph.iter().flat_map(|(a, t)| std::iter::once(a.as_str()).chain(t.keys().map(String::as_str))).collect();
    for v in nodes {
        if !t.index.contains_key(v) {
            t.visit(v);
        }
    }
    let mut found: Vec<Vec<String>> =
        t.components.into_iter().filter(|c| c.len() > 1).map(|c| c.into_iter().map(str::to_owned).collect()).collect();
    found.iter_mut().for_each(|c| c.sort());
    found
}

/// One closed path inside a strongly connected component, from its first
/// member (breadth-first, so the path is a shortest cycle through it).
fn cycle_within(graph: &Graph, component: &[String]) -> Vec<String> {
    let members: BTreeSet<&str> = component.iter().map(String::as_str).collect();
    let start = *members.iter().next().unwrap();
    let mut parent: BTreeMap<&str, &str> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::from([start]);
    while let Some(v) = queue.pop_front() {
        for w in graph[v].keys().map(String::as_str).filter(|w| members.contains(w)) {
            if w == start {
                let mut back = vec![v];
                while let Some(&p) = parent.get(back[back.len() - 1]) {
                    back.push(p);
                }
                // `back` runs v → … → start (start has no parent).
                let mut cycle: Vec<String> = back.iter().rev().map(|s| s.to_string()).collect();
                cycle.push(start.to_owned());
                return cycle;
            }
            if !parent.contains_key(w) && w != start {
                parent.insert(w, v);
                queue.push_back(w);
            }
        }
    }
    unreachable!("a strongly connected component of several modules has a cycle through each member")
}

fn describe(graph: &Graph, cycle: &[String]) -> String {
    let steps: Vec<String> = cycle.windows(2).map(|w| format!("  {} -> {}   ({})", w[0], w[1], graph[&w[0]][&w[1]])).collect();
    format!("{}\n{}", cycle.join(" -> "), steps.join("\n"))
}

fn crate_sources() -> Vec<(PathBuf, String)> {
    // Read at run time, so the built test can also check another checkout.
    let manifest = std::env::var("CARGO_MANIFEST_DIR").unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned());
    let root = Path::new(&manifest).join("src");
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    files.into_iter().map(|p| (p.strip_prefix(&root).unwrap().to_path_buf(), std::fs::read_to_string(&p).unwrap())).collect()
}

#[test]
fn folder_level_import_graph_has_no_cycle() {
    let graph = graph(&crate_sources());
    assert!(graph.len() > 10, "found {} modules under src/, expected the crate's (is this the repository root?)", graph.len());
    let components = components(&graph);
    let report: Vec<String> = components
        .iter()
        .map(|members| {
            format!(
                "{} modules in a cycle: {}; one of its circles: {}",
                members.len(),
                members.join(", "),
                describe(&graph, &cycle_within(&graph, members))
            )
        })
        .collect();
    assert!(components.is_empty(), "the folder-level import graph of src/ has {} cycle(s):\n{}", components.len(), report.join("\n"));
}

/// A folder under `src/` as the file-level check reads it: its name, its
/// `mod.rs`, and each direct child's files (text, nested deeper than the
/// child's own `x.rs`).
struct Folder {
    name: String,
    root: String,
    children: BTreeMap<String, Vec<(String, bool)>>,
}

/// What `root` (a `mod.rs`) re-exports, by the name it is visible under,
/// with the child it comes from (`pub use self::x::{A, B as C};`).
fn reexports(root: &str) -> BTreeMap<String, String> {
    let mut map = BTreeMap::new();
    let text = format!("\n{root}");
    for (at, _) in text.match_indices("\npub") {
        let statement = &text[at + "\npub".len()..];
        let statement = &statement[..statement.find(';').unwrap_or(statement.len())];
        let statement = match statement.strip_prefix('(') {
            Some(rest) => rest.split_once(')').map_or("", |(_, r)| r),
            None => statement,
        };
        let Some(path) = statement.trim_start().strip_prefix("use ") else { continue };
        let path = path.trim();
        let Some((child, items)) = path.strip_prefix("self::").unwrap_or(path).split_once("::") else { continue };
        for item in items.trim_start_matches('{').trim_end_matches('}').split(',') {
            if let Some(name) = item.split_whitespace().last() {
                map.insert(name.rsplit("::").next().unwrap_or(name).to_owned(), child.to_owned());
            }
        }
    }
    map
}

/// The file-level graph of one folder (see the module doc).
fn folder_graph(folder: &Folder) -> Graph {
    let reexported = reexports(&folder.root);
    let own = format!("crate::{}::", folder.name);
    let mut edges = Graph::new();
    for (child, files) in &folder.children {
        let targets = edges.entry(child.clone()).or_default();
        for (text, nested) in files {
            let code = text.split("#[cfg(test)]").next().unwrap_or_default();
            let mut references = path_references(code, &own);
            if !nested {
                references.extend(path_references(code, "super::"));
            }
            for (name, line) in references {
                let to = if folder.children.contains_key(&name) { Some(name) } else { reexported.get(&name).cloned() };
                if let Some(to) = to.filter(|to| to != child && folder.children.contains_key(to)) {
                    targets.entry(to).or_insert_with(|| format!("src/{}/{child}…:{line}", folder.name));
                }
            }
        }
    }
    edges
}

/// The members of each file-level circle of `folder` that its module doc
/// does not name (as `` `x.rs` `` or `` `x/` ``), with the circle.
fn unnamed_circles(folder: &Folder) -> Vec<(Vec<String>, Vec<String>)> {
    let doc: Vec<&str> = folder.root.lines().filter_map(|l| l.trim_start().strip_prefix("//!")).collect();
    let doc = doc.join("\n");
    let graph = folder_graph(folder);
    components(&graph)
        .into_iter()
        .filter_map(|members| {
            let missing: Vec<String> =
                members.iter().filter(|m| !doc.contains(&format!("`{m}.rs`")) && !doc.contains(&format!("`{m}/`"))).cloned().collect();
            (!missing.is_empty()).then(|| (missing, cycle_within(&graph, &members)))
        })
        .collect()
}

fn crate_folders() -> Vec<Folder> {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned());
    let src = Path::new(&manifest).join("src");
    let mut dirs: Vec<PathBuf> =
        std::fs::read_dir(&src).unwrap().map(|e| e.unwrap().path()).filter(|p| p.join("mod.rs").is_file()).collect();
    dirs.sort();
    dirs.into_iter()
        .map(|dir| {
            let mut children: BTreeMap<String, Vec<(String, bool)>> = BTreeMap::new();
            let mut files = Vec::new();
            rust_files(&dir, &mut files);
            for file in files {
                let relative = file.strip_prefix(&dir).unwrap();
                let first = relative.components().next().unwrap().as_os_str().to_string_lossy().into_owned();
                if first == "mod.rs" {
                    continue;
                }
                let nested = relative.components().count() > 1;
                let child = first.strip_suffix(".rs").unwrap_or(&first).to_owned();
                children.entry(child).or_default().push((std::fs::read_to_string(&file).unwrap(), nested));
            }
            Folder {
                name: dir.file_name().unwrap().to_string_lossy().into_owned(),
                root: std::fs::read_to_string(dir.join("mod.rs")).unwrap(),
                children,
            }
        })
        .collect()
}

#[test]
fn file_level_circles_are_named_in_their_folders_doc() {
    let folders = crate_folders();
    assert!(folders.len() > 10, "found {} folders under src/", folders.len());
    let mut report = Vec::new();
    for folder in &folders {
        for (missing, cycle) in unnamed_circles(folder) {
            report.push(format!("src/{}/: {} (mod.rs does not name {})", folder.name, cycle.join(" -> "), missing.join(", ")));
        }
    }
    assert!(report.is_empty(), "file-level circles not named, with their reason, in their folder's module doc:\n{}", report.join("\n"));
}

fn sources(files: &[(&str, &str)]) -> Vec<(PathBuf, String)> {
    files.iter().map(|(p, t)| (PathBuf::from(p), t.to_string())).collect()
}

#[test]
fn reads_groups_doc_links_and_qualified_paths() {
    let text = "use crate::{alpha::X,\n    beta::{Y, Z}, gamma};\n/// See [`W`](crate::delta::W).\nfn f() -> crate::epsilon::T { $crate::zeta::g() }\nuse other_crate::eta;";
    let names: Vec<(String, usize)> = crate_references(text);
    let expected = [("alpha", 1), ("beta", 1), ("gamma", 1), ("delta", 3), ("epsilon", 4), ("zeta", 4)];
    assert_eq!(names, expected.map(|(n, l)| (n.to_owned(), l)));
}

#[test]
fn finds_a_cycle_through_files_of_three_folders() {
    let tree = sources(&[
        ("lib.rs", "pub mod a; pub mod b; pub mod c; pub mod leaf;"),
        ("a/mod.rs", "use crate::b::B;"),
        ("a/deep.rs", "use crate::leaf::L;"),
        ("b/mod.rs", "//! Uses [`C`](crate::c::C).\n"),
        ("c/x.rs", "use crate::{leaf::L, a::A};"),
        ("leaf.rs", "use crate::unknown::U;"),
    ]);
    let g = graph(&tree);
    assert_eq!(g["b"]["c"], "src/b/mod.rs:1");
    let found = cycles(&g);
    assert_eq!(found, vec![vec!["a", "b", "c", "a"]]);
    assert!(describe(&g, &found[0]).contains("c -> a   (src/c/x.rs:1)"));
    let acyclic = sources(&[("a/mod.rs", "use crate::b::B;"), ("b/mod.rs", "use crate::leaf::L;"), ("leaf.rs", "")]);
    assert!(cycles(&graph(&acyclic)).is_empty());
}

#[test]
fn finds_a_file_level_circle_through_a_reexport_and_checks_the_doc() {
    let folder = |root: &str| Folder {
        name: "f".into(),
        root: root.into(),
        children: BTreeMap::from([
            ("a".to_owned(), vec![("use super::b::B;\n#[cfg(test)]\nuse super::c::C;".to_owned(), false)]),
            ("b".to_owned(), vec![("fn g() -> super::A { todo!() }".to_owned(), false)]),
            ("c".to_owned(), vec![("use super::a::A;".to_owned(), false), ("use super::b::B;".to_owned(), true)]),
        ]),
    };
    let root = "//! The folder.\n\nmod a;\nmod b;\nmod c;\n\npub use self::a::{A, Other as Renamed};\n";
    let g = folder_graph(&folder(root));
    assert_eq!(g["b"]["a"], "src/f/b…:1");
    assert!(!g["a"].contains_key("c") && !g["c"].contains_key("b"), "{g:?}");
    assert_eq!(reexports(root).get("Renamed").map(String::as_str), Some("a"));
    let unnamed = unnamed_circles(&folder(root));
    assert_eq!(unnamed, vec![(vec!["a".to_owned(), "b".to_owned()], vec!["a".to_owned(), "b".to_owned(), "a".to_owned()])]);
    let named = format!("//! `a.rs` and `b.rs` share one type.\n{root}");
    assert!(unnamed_circles(&folder(&named)).is_empty());
}

/// The most lines a file of `src/` may have (the project's standard).
const MAX_LINES: usize = 600;

/// The most named fields a struct of `src/` may have: past it, a struct is
/// regrouped into named sub-states, each with its own methods.
const MAX_FIELDS: usize = 15;

/// Files of `src/` (relative paths) allowed more than [`MAX_LINES`], with why.
const LONG_FILES: &[(&str, &str)] = &[];

/// Structs of `src/` (file relative to `src/`, name) allowed more than
/// [`MAX_FIELDS`], with why. An entry that no longer needs its place fails
/// the test, so the list only shrinks.
const WIDE_STRUCTS: &[(&str, &str, &str)] = &[(
    "system/model.rs",
    "Model",
    "the system's per-particle and per-term tables, read by every layer (backends, GPU packing, kinetics, outputs): \
     not regrouped yet (issue #40)",
)];

/// Every struct with named fields in `text`: its name, line and the number
/// of its fields. A field is a line at the body's top level that starts
/// (after `pub`, `pub(…)`) with a lower-case name and one `:`; comments and
/// attributes are skipped, and braces inside them are not counted.
fn struct_fields(text: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let strip_visibility = |s: &str| -> String {
        let s = s.trim_start();
        let s = match s.strip_prefix("pub(") {
            Some(rest) => rest.split_once(')').map_or(rest, |(_, r)| r),
            None => s.strip_prefix("pub ").unwrap_or(s),
        };
        s.trim_start().to_owned()
    };
    let mut found = Vec::new();
    for (at, line) in lines.iter().enumerate() {
        let head = strip_visibility(line);
        let Some(rest) = head.strip_prefix("struct ") else { continue };
        if !line.trim_end().ends_with('{') {
            continue; // a unit or tuple struct, or a `where` clause on the next lines
        }
        let name = leading_identifier(rest);
        let (mut depth, mut fields) = (1i32, 0);
        for body in &lines[at + 1..] {
            let trimmed = body.trim_start();
            if trimmed.starts_with("//") {
                continue;
            }
            let field = strip_visibility(trimmed);
            let ident = leading_identifier(field.strip_prefix("r#").unwrap_or(&field));
            let after = &field[field.find(&ident).unwrap_or(0) + ident.len()..];
            let after = after.trim_start();
            if depth == 1
                && !trimmed.starts_with('#')
                && ident.starts_with(|c: char| c.is_ascii_lowercase() || c == '_')
                && after.starts_with(':')
                && !after.starts_with("::")
            {
                fields += 1;
            }
            depth += body.matches('{').count() as i32 - body.matches('}').count() as i32;
            if depth <= 0 {
                break;
            }
        }
        found.push((name, at + 1, fields));
    }
    found
}

#[test]
fn no_file_is_longer_or_struct_wider_than_the_standard_without_a_reason() {
    let sources = crate_sources();
    let mut files: Vec<(usize, String)> = sources.iter().map(|(p, t)| (t.lines().count(), p.display().to_string())).collect();
    let mut structs: Vec<(usize, String, String)> = (sources.iter())
        .flat_map(|(p, t)| struct_fields(t).into_iter().map(move |(name, line, n)| (n, name, format!("{}:{line}", p.display()))))
        .collect();
    files.sort_by(|a, b| b.cmp(a));
    structs.sort_by(|a, b| b.cmp(a));
    println!("largest files of src/ (lines):");
    files.iter().take(10).for_each(|(n, p)| println!("  {n:5} {p}"));
    println!("widest structs of src/ (named fields):");
    structs.iter().take(10).for_each(|(n, name, at)| println!("  {n:3} {name} ({at})"));
    let mut report = Vec::new();
    for (n, path) in &files {
        match (*n > MAX_LINES, LONG_FILES.iter().any(|(p, _)| p == path)) {
            (true, false) => report.push(format!("src/{path}: {n} lines, more than {MAX_LINES}")),
            (false, true) => {
                report.push(format!("src/{path}: {n} lines, allowed more than {MAX_LINES} in LONG_FILES but needs it no longer"))
            }
            _ => {}
        }
    }
    for (file, name, _) in WIDE_STRUCTS {
        if !structs.iter().any(|(n, s, at)| s == name && at.starts_with(&format!("{file}:")) && *n > MAX_FIELDS) {
            report.push(format!("src/{file}: struct {name} is in WIDE_STRUCTS but has at most {MAX_FIELDS} fields (or is gone)"));
        }
    }
    for (n, name, at) in structs.iter().filter(|(n, _, _)| *n > MAX_FIELDS) {
        if !WIDE_STRUCTS.iter().any(|(file, s, _)| s == name && at.starts_with(&format!("{file}:"))) {
            report.push(format!("src/{at}: struct {name} has {n} fields, more than {MAX_FIELDS}"));
        }
    }
    assert!(report.is_empty(), "group what grew past the standard, or allow it here with its reason:\n{}", report.join("\n"));
}

#[test]
fn counts_the_named_fields_of_structs() {
    let text =
        "pub(crate) struct A<'a, T> {\n    /// a: doc\n    pub x: Vec<T>,\n    #[allow(dead_code)]\n    pub(super) r#type: &'a str,\n    \
                nested: Option<Box<dyn Fn(u32) -> u32>>,\n    map: std::collections::HashMap<\n        u32,\n        crate::B,\n    >,\n}\n\
                struct Tuple(u32, u32);\nstruct Unit;\nstruct Empty {}\nimpl A { fn f() { let s = S { a: 1 }; } }\n";
    assert_eq!(struct_fields(text), vec![("A".to_owned(), 1, 4)]);
}
