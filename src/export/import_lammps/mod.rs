//! `cellmd import-lammps DATA [INPUT] -o DIR`: a LAMMPS data file (and
//! optionally the input script that reads it) as a cellmd topology, force
//! field and deck — the inverse of [`super::styles`]. The imported deck
//! runs as it is: every command it could not translate is listed atop
//! `system.in` with its `file:line`, and printed.
//!
//! What is read:
//! - the data file (`data.rs`): box, `Masses`, `Atoms` (styles `atomic`,
//!   `bond`, `angle`, `molecular`, `charge`, `full`, from the script's
//!   `atom_style` or the `Atoms # STYLE` comment; image flags unwrap the
//!   positions), `Bonds`, `Angles`, and the `Pair`/`Bond`/`Angle Coeffs`
//!   sections (read as the coefficient commands they stand for). Particle
//!   type N is named by its `Masses` comment (`1 1.0 # actin`) or `tN`; bond
//!   and angle types are `bondN` and `angleN`. A box that is not finite, or
//!   with hi ≤ lo, and coordinates that are not finite are errors.
//! - the script (`script.rs`): units, boundaries, `special_bonds`, the styles
//!   and their coefficients with wildcards and mixing (`coeffs.rs`, which
//!   also lists every translation), the dynamics, `timestep`, `thermo`,
//!   `run`, `neighbor`/`neigh_modify` and `print`, in the script's order.
//!
//! Dynamics: a type moved by `fix … brownian T SEED gamma_t G` gets drag G;
//! one moved by `fix … langevin T T DAMP SEED` (with `fix … nve`) gets the
//! overdamped limit of Langevin dynamics, drag m/DAMP (m its mass; `scale
//! TYPE RATIO` gives m·RATIO/DAMP), which LAMMPS' inertial dynamics
//! approaches when DAMP is short against the times of interest. A type that
//! no such fix moves is `fixed` (LAMMPS does not move it either). The
//! temperature is the fixes' (`rng none`: 0), `rng gaussian` becomes `noise
//! gaussian`. LAMMPS never stops a run for a large step, so the deck's
//! `integrator overdamped … max_displacement` is half the box's shortest
//! edge (the largest move the minimum image and the neighbour list's
//! rebuild test allow) instead of cellmd's default of 1: a deck LAMMPS runs
//! to its end runs to its end here too, and a real blow-up (a non-finite
//! force) still stops it.
//!
//! Everything else (other styles, fixes, computes, dumps, units other than
//! `lj`, triclinic boxes, velocities) is listed in the notes the import
//! writes atop `system.in` and prints, never dropped silently. Errors (a
//! bad number, an unknown type, a wildcard out of range) name
//! `file:line:col` and what was expected.

mod coeffs;
mod data;
mod lepton;
mod script;
mod words;

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use self::coeffs::bounds;
use self::script::{Dynamics, Event, Script};
use self::words::{Line, Source, Word};
use crate::interactions::lammps::num;

/// The files an import writes, and what it could not translate.
#[derive(Clone, Debug, Default)]
pub struct Imported {
    pub topology: String,
    pub forcefield: String,
    pub deck: String,
    /// What was not translated, one line each.
    pub notes: Vec<String>,
}

/// The data file's `… Coeffs` lines as the coefficient commands they stand for.
fn data_coeffs(source: &Source, data: &data::Data, section: &str, command: &str) -> Vec<(Source, Line)> {
    let lines = data.coeffs.get(section).map(Vec::as_slice).unwrap_or(&[]);
    lines
        .iter()
        .map(|l| {
            let mut words = vec![Word { text: command.into(), line: l.line, col: 1 }];
            words.push(l.words[0].clone());
            if command == "pair_coeff" {
                words.push(l.words[0].clone());
            }
            words.extend(l.words[1..].iter().cloned());
            (source.clone(), Line { words, text: format!("{command} {}", l.text), comment: String::new(), line: l.line })
        })
        .collect()
}

/// The types a fix's group holds, or `None` for a group not defined by type.
fn group_types(script: &Script, group: &str, n: usize) -> Option<Result<Vec<usize>, String>> {
    if group == "all" {
        return Some(Ok((1..=n).collect()));
    }
    let words = script.groups.get(group)?;
    let source = script.source.clone().expect("a script");
    let mut types = Vec::new();
    for w in words {
        // `group g type 1 2`, `1*3`, or `1:3`.
        let text = w.text.replace(':', "*");
        match bounds(&source, &Word { text, ..w.clone() }, n) {
            Ok((lo, hi)) => types.extend(lo..=hi),
            Err(e) => return Some(Err(e)),
        }
    }
    Some(Ok(types))
}

/// Translates a data file and the script that reads it (name, text), if any.
pub fn import(data_name: &str, data_text: &str, script_text: Option<(&str, &str)>) -> Result<Imported, String> {
    let script = match script_text {
        Some((name, text)) => script::read(name, text)?,
        None => Script::default(),
    };
    let data_source = Source { name: data_name.to_string() };
    let data = data::read(&data_source, data_text, script.atom_style.as_deref())?;
    let mut notes = script.notes.clone();
    notes.extend(data.notes.iter().cloned());
    let periodic = script.periodic.unwrap_or([true; 3]);
    let n = data.atom_types;

    // Masses: the data file's, then the script's `mass` commands.
    let mut masses = data.masses.clone();
    for (w, m) in &script.masses {
        let source = script.source.clone().expect("a script");
        let (lo, hi) = bounds(&source, w, n)?;
        (lo..=hi).for_each(|t| {
            masses.insert(t, *m);
        });
    }
    let names: BTreeMap<usize, String> = (1..=n).map(|t| (t, data.names.get(&t).cloned().unwrap_or_else(|| format!("t{t}")))).collect();

    // Dynamics: drag per type and the temperature.
    let mut drag: BTreeMap<usize, f64> = BTreeMap::new();
    let mut temperature: Option<f64> = None;
    let mut gaussian = false;
    let has_langevin = script.fixes.dynamics.iter().any(|(_, d)| matches!(d, Dynamics::Langevin { .. }));
    if !script.fixes.nve.is_empty() && !has_langevin {
        let name = script.source.as_ref().map_or("INPUT", |s| s.name.as_str());
        notes.push(format!("{name}:{}: `fix … nve` without `fix … langevin` (inertial dynamics) is not translated", script.fixes.nve[0]));
    }
    for (line, d) in &script.fixes.dynamics {
        let name = script.source.as_ref().map_or("INPUT", |s| s.name.as_str());
        let (group, t) = match d {
            Dynamics::Brownian { group, temperature, rng, .. } => {
                gaussian |= rng == "gaussian";
                (group, if rng == "none" { 0.0 } else { *temperature })
            }
            Dynamics::Langevin { group, temperature, .. } => (group, *temperature),
        };
        if temperature.is_some_and(|old| old != t) {
            notes.push(format!("{name}:{line}: a second temperature ({t}): the deck runs at {}", num(temperature.unwrap_or(0.0))));
        }
        temperature.get_or_insert(t);
        let types = match group_types(&script, group, n) {
            Some(Ok(types)) => types,
            Some(Err(e)) => return Err(e),
            None => {
                notes
                    .push(format!("{name}:{line}: group `{group}` is not defined by `group {group} type …`: its drags are not translated"));
                continue;
            }
        };
        for t in types {
            let g = match d {
                Dynamics::Brownian { gamma, .. } => *gamma,
                Dynamics::Langevin { damp, scale, .. } => {
                    masses.get(&t).copied().unwrap_or(1.0) * scale.get(&t).copied().unwrap_or(1.0) / damp
                }
            };
            drag.insert(t, g);
        }
    }

    // Topology.
    let style = script
        .atom_style
        .clone()
        .or_else(|| (!data.style_comment.is_empty()).then(|| data.style_comment.clone()))
        .unwrap_or_else(|| "atomic".into());
    let mut top = format!("# imported by `cellmd import-lammps` from {data_name} (atom style {style})\n[ box ]\n");
    for (a, axis) in ["x", "y", "z"].iter().enumerate() {
        writeln!(top, "{axis} {} {} {}", num(data.lo[a]), num(data.hi[a]), if periodic[a] { "p" } else { "f" }).unwrap();
    }
    top.push_str("[ particles ]\n# id  type  x  y  z\n");
    for a in &data.atoms {
        writeln!(top, "{} {} {} {} {}", a.id, names[&a.type_], num(a.x[0]), num(a.x[1]), num(a.x[2])).unwrap();
    }
    if !data.bonds.is_empty() {
        top.push_str("[ bonds ]\n");
        for (t, [i, j]) in &data.bonds {
            writeln!(top, "bond{t} {i} {j}").unwrap();
        }
    }
    if !data.angles.is_empty() {
        top.push_str("[ angles ]\n");
        for (t, [i, j, k]) in &data.angles {
            writeln!(top, "angle{t} {i} {j} {k}").unwrap();
        }
    }

    // Force field.
    let mut ff = format!("# imported by `cellmd import-lammps` from {data_name}\n");
    for (t, name) in &names {
        match drag.get(t) {
            Some(g) => writeln!(ff, "particle {name} drag {}", num(*g)).unwrap(),
            None => {
                if script_text.is_some() {
                    notes.push(format!(
                        "type {t} (`{name}`): no fix brownian or langevin moves it, so it is `fixed` (LAMMPS does not move it either)"
                    ));
                }
                writeln!(ff, "particle {name} fixed").unwrap();
            }
        }
    }
    let bond_lines: Vec<_> =
        data_coeffs(&data_source, &data, "Bond Coeffs", "bond_coeff").into_iter().chain(script.bond.coeffs.iter().cloned()).collect();
    let angle_lines: Vec<_> =
        data_coeffs(&data_source, &data, "Angle Coeffs", "angle_coeff").into_iter().chain(script.angle.coeffs.iter().cloned()).collect();
    for (kind, style, lines, count, used) in [
        ("bond", &script.bond.style, &bond_lines, data.bond_types, !data.bonds.is_empty()),
        ("angle", &script.angle.style, &angle_lines, data.angle_types, !data.angles.is_empty()),
    ] {
        let laws = coeffs::bonded(kind, style, lines, count)?;
        for t in 1..=count {
            match laws.get(&t) {
                Some(Ok(law)) => writeln!(ff, "{kind} {kind}{t} {law}").unwrap(),
                Some(Err(e)) => notes.push(format!("{e}; `{kind}{t}` has no law")),
                None if used => notes.push(format!("{kind} type {t} has no {kind}_coeff; `{kind}{t}` has no law")),
                None => {}
            }
        }
    }
    let pair_lines: Vec<_> =
        data_coeffs(&data_source, &data, "Pair Coeffs", "pair_coeff").into_iter().chain(script.pair.coeffs.iter().cloned()).collect();
    let (pairs, pair_notes) = coeffs::pairs(&script.pair.style, &script.pair_modify, &pair_lines, n)?;
    notes.extend(pair_notes);
    for (i, j, law) in &pairs {
        writeln!(ff, "pair {} {} {law}", names[i], names[j]).unwrap();
    }

    // Deck.
    let mut deck = String::from("# imported by `cellmd import-lammps`; not translated, or translated with the caveat given:\n");
    if notes.is_empty() {
        deck.push_str("#   (nothing)\n");
    }
    for n in &notes {
        // A control character in an untranslated line would make the comment itself bad input.
        let printable: String = n.chars().map(|c| if c.is_control() { format!("{}", c.escape_unicode()) } else { c.to_string() }).collect();
        writeln!(deck, "#   {printable}").unwrap();
    }
    deck.push_str("units lj\ntopology system.top\nforcefield system.ff\n");
    let w = script.special.unwrap_or([0.0; 3]);
    writeln!(deck, "special_bonds {} {} {}", num(w[0]), num(w[1]), num(w[2])).unwrap();
    if script.neighbor.skin.is_some() || script.neighbor.every.is_some() || script.neighbor.check.is_some() {
        // LAMMPS' default skin in lj units is 0.3σ.
        let mut line = format!("neighbor skin {}", num(script.neighbor.skin.unwrap_or(0.3)));
        if let Some(every) = script.neighbor.every {
            write!(line, " every {}", every.max(1)).unwrap();
        }
        if let Some(check) = script.neighbor.check {
            write!(line, " check {}", if check { "yes" } else { "no" }).unwrap();
        }
        writeln!(deck, "{line}").unwrap();
    }
    let shortest = (0..3).map(|a| data.hi[a] - data.lo[a]).fold(f64::INFINITY, f64::min);
    let noise = if gaussian { " noise gaussian" } else { "" };
    writeln!(deck, "integrator overdamped{noise} max_displacement {}", num(0.5 * shortest)).unwrap();
    writeln!(deck, "temperature {}", num(temperature.unwrap_or(0.0))).unwrap();
    if !script.events.iter().take_while(|e| !matches!(e, Event::Run(_))).any(|e| matches!(e, Event::Timestep(_))) {
        // LAMMPS' default time step in lj units.
        deck.push_str("timestep 0.005\n");
    }
    for e in &script.events {
        match e {
            Event::Timestep(dt) => writeln!(deck, "timestep {}", num(*dt)).unwrap(),
            Event::Thermo(n) => writeln!(deck, "thermo {n}").unwrap(),
            Event::Run(n) => writeln!(deck, "run {n}").unwrap(),
            Event::Print(text) => writeln!(deck, "print {}", text.replace('"', "'")).unwrap(),
        }
    }
    Ok(Imported { topology: top, forcefield: ff, deck, notes })
}

/// Reads the files and translates them. `first` is the data file, or —
/// alone, when it holds a `read_data` command — the input script, whose
/// `read_data` then names the data file (relative to the script). Each is
/// read as every cellmd input is (`input::read_input_file`: a regular file
/// of bounded size, so a FIFO or `/dev/zero` is refused at once) and must be
/// UTF-8 (a stray byte is an error at its line and column).
pub fn read_files(first: &Path, script: Option<&Path>) -> Result<Imported, String> {
    let read = |p: &Path| crate::input::SourceFile::read(p, None).map(|f| f.text.clone());
    let first_text = read(first).map_err(|e| e.to_string())?;
    let shown = first.display().to_string();
    let read_data = |text: &str| {
        text.lines()
            .enumerate()
            .find_map(|(k, l)| Some((k + 1, l.find("read_data")? + 1)).filter(|_| l.split_whitespace().next() == Some("read_data")))
    };
    let (data, script, script_text, named_at) = match script {
        Some(s) => (first.to_path_buf(), Some(s.to_path_buf()), Some(read(s).map_err(|e| e.to_string())?), None),
        None => match read_data(&first_text) {
            Some((line, col)) => {
                let parsed = script::read(&shown, &first_text)?;
                let at = |message: &str| words::Source { name: shown.clone() }.at(line, col, message);
                let name =
                    parsed.read_data.ok_or_else(|| at("found `read_data` with a file name cellmd cannot read, expected a literal name"))?;
                let path = first.parent().unwrap_or(Path::new(".")).join(&name.text);
                (path, Some(first.to_path_buf()), Some(first_text.clone()), Some(name))
            }
            None => (first.to_path_buf(), None, None, None),
        },
    };
    let data_text = if script.is_some() && data == first {
        first_text
    } else {
        // A data file the script names and cellmd cannot read is an error at its name.
        read(&data).map_err(|e| match &named_at {
            Some(word) if e.path == data.display().to_string() && e.message.starts_with("cannot read") => {
                words::Source { name: shown.clone() }.error(word, &e.message)
            }
            _ => e.to_string(),
        })?
    };
    let script_name = script.as_ref().map(|p| p.display().to_string());
    import(&data.display().to_string(), &data_text, script_name.as_deref().zip(script_text.as_deref()))
}

impl Imported {
    /// Writes `system.top`, `system.ff` and last `system.in` (which names
    /// them) into `dir`, each atomically and through no link inside `dir`
    /// (`output::files`): a kill or a full disk leaves each name whole.
    pub fn write(&self, dir: &Path) -> std::io::Result<()> {
        crate::output::files::write_all_atomically(
            dir,
            &[("system.top", &self.topology), ("system.ff", &self.forcefield), ("system.in", &self.deck)],
        )
    }
}

/// [`read_files`], then [`Imported::write`] into `dir`.
pub fn import_files(first: &Path, script: Option<&Path>, dir: &Path) -> Result<Imported, String> {
    let imported = read_files(first, script)?;
    imported.write(dir).map_err(|e| e.to_string())?;
    Ok(imported)
}
