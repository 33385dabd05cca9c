//! `cellmd build merge A.top B.top … -o OUT.top`: several topology files
//! composed into one by the rule of a deck with several `topology` lines
//! ([`Topology::append_at`]: particle ids shifted by `--offset`, by default
//! the largest id so far; body ids after the largest so far; the same type
//! name is the same type; the first `[ box ]` given), written back as an
//! ordinary topology file. Positions, box bounds and per-bond r0 are written
//! in Rust's shortest round-trip form, so the file parses to exactly the
//! composed system.

use std::fmt::Write;
use std::path::PathBuf;

use crate::input::SourceFile;
use crate::topology::{parse_topology, Topology};

use super::Built;

/// Options of `cellmd build merge`.
#[derive(clap::Args, Clone, Debug)]
pub struct MergeArgs {
    /// The topology files, in order (at least two).
    #[arg(required = true, num_args = 2..)]
    pub files: Vec<PathBuf>,
    /// Particle id offset of each file, in the files' order: `auto` (the
    /// largest id so far) or a whole number; give it once per file or not at
    /// all [auto for every file].
    #[arg(long = "offset", value_name = "auto|N")]
    pub offsets: Vec<String>,
    /// The topology file to write.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// `None` for `auto`, else the whole number.
fn parse_offset(text: &str) -> Result<Option<u64>, String> {
    match text {
        "auto" => Ok(None),
        _ => text.parse().map(Some).map_err(|_| format!("found --offset `{text}`, expected `auto` or a whole number >= 0")),
    }
}

/// Reads, composes and renders the files.
pub fn merge(args: &MergeArgs) -> Result<Built, String> {
    let offsets: Vec<Option<u64>> = match args.offsets.len() {
        0 => vec![None; args.files.len()],
        n if n == args.files.len() => args.offsets.iter().map(|o| parse_offset(o)).collect::<Result<_, _>>()?,
        n => return Err(format!("found {n} --offset values for {} files, expected one per file or none", args.files.len())),
    };
    let mut top = Topology::default();
    let mut lines = Vec::new();
    for (path, offset) in args.files.iter().zip(offsets) {
        let file = SourceFile::read(path, None).map_err(|e| e.to_string())?;
        let part = parse_topology(&file).map_err(|e| e.to_string())?;
        let bodies = top.bodies.iter().map(|b| b.0).max().unwrap_or(0);
        let first = top.ids.len();
        let offset = top.append_at(part, offset).map_err(|c| {
            format!(
                "particle id {} of `{}` plus offset {} is already used by an earlier topology; expected `--offset auto` or an offset >= {}",
                c.id,
                path.display(),
                c.offset,
                c.used
            )
        })?;
        let ids = &top.ids[first..];
        let range = match (ids.iter().min(), ids.iter().max()) {
            (Some(lo), Some(hi)) => format!("ids {lo}–{hi}"),
            _ => "no particles".into(),
        };
        lines.push(format!("{}: {} particles, {range} (id offset {offset}, body ids shifted by {bodies})", path.display(), ids.len()));
    }
    Ok(render(&top, args, lines))
}

/// The distinct names, in order of first appearance.
fn distinct<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let mut seen: Vec<&str> = Vec::new();
    for name in names {
        if !seen.contains(&name) {
            seen.push(name);
        }
    }
    if seen.is_empty() {
        "none".into()
    } else {
        seen.join(" ")
    }
}

/// The composed topology as a file, its summary atop.
fn render(top: &Topology, args: &MergeArgs, mut lines: Vec<String>) -> Built {
    let own_r0 = top.bond_rest.iter().filter(|r| r.is_some()).count();
    lines.push(format!(
        "{} particles, {} bonds ({own_r0} with their own r0), {} angles, {} bodies, {} triangles",
        top.ids.len(),
        top.bonds.len(),
        top.angles.len(),
        top.bodies.len(),
        top.triangles.len()
    ));
    lines.push(format!(
        "type names (shared across files): particles {}; bonds {}; angles {}; bodies {}",
        distinct(top.type_names.iter().map(|t| t.text.as_str())),
        distinct(top.bonds.iter().map(|b| b.type_name.text.as_str())),
        distinct(top.angles.iter().map(|a| a.type_name.text.as_str())),
        distinct(top.bodies.iter().map(|b| b.1.text.as_str()))
    ));
    if !top.tetrahedra.is_empty() {
        let types = distinct(top.tetrahedra.iter().map(|e| e.type_name.text.as_str()));
        lines.push(format!("{} tetrahedra; tetra types {types}", top.tetrahedra.len()));
    }
    lines.push(match top.box_axes {
        Some(_) => "box: the first [ box ] given (a deck's `box` command overrides it)".into(),
        None => "box: none given (the deck's `box` command sets it)".into(),
    });
    let files: Vec<String> = args.files.iter().map(|f| f.display().to_string()).collect();
    let offsets: String = args.offsets.iter().map(|o| format!(" --offset {o}")).collect();
    let id = |index: u32| top.ids[index as usize];
    let mut t = String::new();
    writeln!(t, "# merged topology of {}\n# (written by `cellmd build merge {}{offsets}`)", files.join(", "), files.join(" ")).unwrap();
    for line in &lines {
        writeln!(t, "# {line}").unwrap();
    }
    if let Some(axes) = &top.box_axes {
        writeln!(t, "[ box ]").unwrap();
        for (name, a) in ["x", "y", "z"].iter().zip(axes) {
            writeln!(t, "{name} {:?} {:?} {}", a.lo, a.hi, if a.periodic { "p" } else { "f" }).unwrap();
        }
    }
    writeln!(t, "[ particles ]\n# id  type  x  y  z  [body]").unwrap();
    for (k, x) in top.positions.iter().enumerate() {
        write!(t, "{} {} {:?} {:?} {:?}", top.ids[k], top.type_names[k].text, x.x, x.y, x.z).unwrap();
        match top.body_of[k] {
            Some(b) => writeln!(t, " {b}").unwrap(),
            None => writeln!(t).unwrap(),
        }
    }
    if !top.bonds.is_empty() {
        writeln!(t, "[ bonds ]\n# type  i  j  [r0]").unwrap();
        for (bond, rest) in top.bonds.iter().zip(&top.bond_rest) {
            let [i, j] = bond.particles.map(id);
            match rest {
                Some((r0, _)) => writeln!(t, "{} {i} {j} {r0:?}", bond.type_name.text).unwrap(),
                None => writeln!(t, "{} {i} {j}", bond.type_name.text).unwrap(),
            }
        }
    }
    if !top.angles.is_empty() {
        writeln!(t, "[ angles ]\n# type  i  j  k   (vertex j)").unwrap();
        for angle in &top.angles {
            let [i, j, k] = angle.particles.map(id);
            writeln!(t, "{} {i} {j} {k}", angle.type_name.text).unwrap();
        }
    }
    if !top.bodies.is_empty() {
        writeln!(t, "[ bodies ]").unwrap();
        for (body, type_name) in &top.bodies {
            writeln!(t, "{body} {}", type_name.text).unwrap();
        }
    }
    if !top.triangles.is_empty() {
        writeln!(t, "[ triangles ]\n# body  i  j  k   (counter-clockwise seen from outside)").unwrap();
        for (body, face) in &top.triangles {
            let [i, j, k] = face.map(id);
            writeln!(t, "{body} {i} {j} {k}").unwrap();
        }
    }
    if !top.tetrahedra.is_empty() {
        writeln!(t, "[ tetrahedra ]\n# type  i  j  k  l").unwrap();
        for element in &top.tetrahedra {
            let [i, j, k, l] = element.particles.map(id);
            writeln!(t, "{} {i} {j} {k} {l}", element.type_name.text).unwrap();
        }
    }
    Built {
        text: t,
        lines,
        particles: top.ids.len(),
        bonds: top.bonds.len(),
        angles: top.angles.len(),
        bodies: top.bodies.len(),
        triangles: top.triangles.len(),
        tetrahedra: top.tetrahedra.len(),
        shells: Vec::new(),
    }
}
