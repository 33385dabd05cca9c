//! `cellmd import-lammps DATA [INPUT] -o DIR`: a LAMMPS data file (and
//! optionally the input script that reads it) as a cellmd topology, force
//! field and deck skeleton — the inverse of [`super::styles`].
//!
//! What is read:
//! - the data file's box, `Masses`, `Atoms` (styles `atomic`, `bond`,
//!   `angle`, `molecular`, `full`, taken from the `Atoms # STYLE` comment or
//!   the script's `atom_style`; image flags unwrap the positions), `Bonds` and
//!   `Angles`. Particle type N is named by its `Masses` comment (`1 1.0 # actin`)
//!   or `tN`; bond and angle types are `bondN` and `angleN`.
//! - from the script: `units lj`, `atom_style`, `boundary` (p periodic;
//!   f, s, m fixed), `special_bonds lj` with 0/1 weights, `timestep`,
//!   `bond_style`/`bond_coeff`, `angle_style`/`angle_coeff`,
//!   `pair_style`/`pair_coeff`/`pair_modify shift` (plain or `hybrid`,
//!   `hybrid/overlay`), `group NAME type …` and `fix … brownian T SEED
//!   gamma_t G` (temperature and per-type drag).
//!
//! Drags: a type's drag γ is the `gamma_t` of a `fix brownian` on `all` or on
//! a group of that type (cellmd's export writes one per type); without one it
//! is the type's LAMMPS mass (γ = m, i.e. the mass read as a drag: overdamped
//! dynamics has no inertia), and the notes say so.
//!
//! Styles translated (LAMMPS → cellmd): bond `harmonic` K r0 → `harmonic` k = 2K;
//! bond `fene` → `fene`; angle `harmonic` K θ0 → `harmonic_angle` k = 2K;
//! angle `cosine` → `cosine_angle`; pair `lj/cut` → `lj` (with `shift yes`
//! at rc = 2^(1/6)σ: `wca`); pair `harmonic/cut` k rc → `soft_repulsion`
//! k = 2k, σ = rc; pair `soft` → `soft`. Everything else (other styles,
//! fixes, computes, commands, units other than `lj`) is listed in the notes
//! the import writes atop `system.in` and prints, never dropped silently.

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;
use std::path::Path;

use crate::interactions::lammps::num;
use crate::interactions::Kind;

/// The files an import writes, and what it could not translate.
#[derive(Clone, Debug, Default)]
pub struct Imported {
    pub topology: String,
    pub forcefield: String,
    pub deck: String,
    /// What was not translated, one line each.
    pub notes: Vec<String>,
}

/// The script's settings the import uses.
#[derive(Default)]
struct Script {
    atom_style: Option<String>,
    periodic: [bool; 3],
    special: Option<[f64; 3]>,
    timestep: Option<f64>,
    temperature: Option<f64>,
    /// LAMMPS type → drag.
    drag: BTreeMap<usize, f64>,
    bond_lines: Vec<String>,
    angle_lines: Vec<String>,
    pair_lines: Vec<String>,
    notes: Vec<String>,
}

fn numbers(words: &[&str], what: &str) -> Result<Vec<f64>, String> {
    words.iter().map(|w| w.parse::<f64>().map_err(|_| format!("{what}: found `{w}`, expected a number"))).collect()
}

/// The coefficients of a `*_coeff` line after the type(s): (sub-style, numbers).
fn coeffs<'a>(style: &'a str, rest: &[&'a str], what: &str) -> Result<(&'a str, Vec<f64>), String> {
    if style.starts_with("hybrid") {
        let (sub, args) = rest.split_first().ok_or_else(|| format!("{what}: expected a sub-style after the type"))?;
        Ok((sub, numbers(args, what)?))
    } else {
        Ok((style, numbers(rest, what)?))
    }
}

fn parse_script(text: &str) -> Result<Script, String> {
    let mut s = Script { periodic: [true; 3], ..Script::default() };
    let (mut bond_style, mut angle_style, mut pair_style) = (String::new(), String::new(), String::new());
    let mut shifted: Vec<String> = Vec::new();
    let mut groups: HashMap<String, Vec<usize>> = HashMap::new();
    let mut pair_coeffs = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        let w: Vec<&str> = line.split_whitespace().collect();
        let Some(&cmd) = w.first() else { continue };
        let at = format!("INPUT:{}", n + 1);
        match cmd {
            "units" if w.get(1) == Some(&"lj") => {}
            "units" => s.notes.push(format!("{at}: `{line}`: only `units lj` is translated; the deck says `units lj`, convert the values")),
            "atom_style" => s.atom_style = w.get(1).map(|x| x.to_string()),
            "boundary" => {
                for a in 0..3 {
                    s.periodic[a] = w.get(a + 1).is_some_and(|b| *b == "p");
                }
            }
            "special_bonds" if w.get(1) == Some(&"lj") && w.len() == 5 => {
                let v = numbers(&w[2..5], &at)?;
                s.special = Some([v[0], v[1], v[2]]);
            }
            "timestep" => s.timestep = Some(numbers(&w[1..2], &at)?[0]),
            "bond_style" => bond_style = w[1..].join(" "),
            "angle_style" => angle_style = w[1..].join(" "),
            "pair_style" => pair_style = w[1..].join(" "),
            "bond_coeff" | "angle_coeff" => {
                let (kind, style) = if cmd == "bond_coeff" { (Kind::Bond, &bond_style) } else { (Kind::Angle, &angle_style) };
                let (sub, v) = coeffs(style.split_whitespace().next().unwrap_or(""), &w[2..], &at)?;
                let name = format!("{}{}", kind.keyword(), w[1]);
                let translated = match (kind, sub, v.as_slice()) {
                    (Kind::Bond, "harmonic", [k, r0]) => Some(format!("bond {name} harmonic k {} r0 {}", num(2.0 * k), num(*r0))),
                    (Kind::Bond, "fene", [k, r0, e, sg]) => {
                        Some(format!("bond {name} fene K {} R0 {} epsilon {} sigma {}", num(*k), num(*r0), num(*e), num(*sg)))
                    }
                    (Kind::Angle, "harmonic", [k, t0]) => {
                        Some(format!("angle {name} harmonic_angle k {} theta0 {}", num(2.0 * k), num(*t0)))
                    }
                    (Kind::Angle, "cosine", [k]) => Some(format!("angle {name} cosine_angle K {}", num(*k))),
                    _ => None,
                };
                match translated {
                    Some(l) if kind == Kind::Bond => s.bond_lines.push(l),
                    Some(l) => s.angle_lines.push(l),
                    None => {
                        s.notes.push(format!("{at}: `{line}`: {} style `{sub}` is not translated; `{name}` has no law", kind.keyword()))
                    }
                }
            }
            "pair_coeff" => pair_coeffs.push((at, line.to_string())),
            "pair_modify" => {
                // `pair_modify [pair STYLE] shift yes`
                if let Some(k) = w.iter().position(|x| *x == "shift") {
                    if w.get(k + 1) == Some(&"yes") {
                        shifted.push(if w.get(1) == Some(&"pair") { w[2].to_string() } else { "*".into() });
                    }
                }
            }
            "group" if w.get(2) == Some(&"type") => {
                let types = w[3..].iter().filter_map(|t| t.parse::<usize>().ok()).collect();
                groups.insert(w[1].to_string(), types);
            }
            "fix" if w.get(3) == Some(&"brownian") => {
                // `rng none`: LAMMPS runs without noise whatever T says.
                let t = if w.windows(2).any(|p| p == ["rng", "none"]) { 0.0 } else { numbers(&w[4..5], &at)?[0] };
                s.temperature = Some(t);
                let gamma = w.iter().position(|x| *x == "gamma_t").and_then(|k| w.get(k + 1)).map(|g| numbers(&[g], &at)).transpose()?;
                match (gamma, w[2]) {
                    (Some(g), "all") => {
                        s.drag.insert(0, g[0]);
                    }
                    (Some(g), group) if groups.contains_key(group) => groups[group].iter().for_each(|&ty| {
                        s.drag.insert(ty, g[0]);
                    }),
                    _ => s.notes.push(format!("{at}: `{line}`: no per-type gamma_t read from it")),
                }
            }
            "read_data" | "neighbor" | "neigh_modify" | "comm_modify" | "thermo" | "thermo_style" | "thermo_modify" | "run" | "print"
            | "write_dump" | "compute" | "unfix" | "variable" => {}
            _ => s.notes.push(format!("{at}: `{line}`: not translated")),
        }
    }
    let default_style = pair_style.split_whitespace().next().unwrap_or("").to_string();
    for (at, line) in pair_coeffs {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.len() < 3 || w[3..].first() == Some(&"none") || w.len() == 3 {
            continue;
        }
        let (sub, v) = coeffs(&default_style, &w[3..], &at)?;
        let (a, b) = (w[1], w[2]);
        if a.parse::<usize>().is_err() || b.parse::<usize>().is_err() {
            s.notes.push(format!("{at}: `{line}`: type ranges and wildcards are not translated; give one line per type pair"));
            continue;
        }
        let shift = shifted.iter().any(|x| x == sub || x == "*");
        let translated = match (sub, v.as_slice()) {
            ("lj/cut", [e, sg, rc]) if shift && (rc / sg - 2f64.powf(1.0 / 6.0)).abs() < 1e-12 => {
                Some(format!("pair t{a} t{b} wca epsilon {} sigma {}", num(*e), num(*sg)))
            }
            ("lj/cut", [e, sg, rc]) if !shift => Some(format!("pair t{a} t{b} lj epsilon {} sigma {} rc {}", num(*e), num(*sg), num(*rc))),
            ("harmonic/cut", [k, rc]) => Some(format!("pair t{a} t{b} soft_repulsion k {} sigma {}", num(2.0 * k), num(*rc))),
            ("soft", [amp, rc]) => Some(format!("pair t{a} t{b} soft A {} rc {}", num(*amp), num(*rc))),
            _ => None,
        };
        match translated {
            Some(l) => s.pair_lines.push(l),
            None => s.notes.push(format!("{at}: `{line}`: pair style `{sub}`{} is not translated", if shift { " (shifted)" } else { "" })),
        }
    }
    Ok(s)
}

/// A data file's sections: `Name` → (its `# comment`, its body lines).
type Sections = BTreeMap<String, (String, Vec<String>)>;

/// The sections of a data file: header lines, then the sections.
fn sections(text: &str) -> (Vec<String>, Sections) {
    let mut header = Vec::new();
    let mut out = Sections::new();
    let mut current: Option<String> = None;
    for raw in text.lines().skip(1) {
        let (body, comment) = raw.split_once('#').map_or((raw, ""), |(b, c)| (b, c.trim()));
        let body = body.trim();
        if body.is_empty() {
            continue;
        }
        if body.chars().next().is_some_and(|c| c.is_ascii_alphabetic()) {
            out.insert(body.to_string(), (comment.to_string(), Vec::new()));
            current = Some(body.to_string());
        } else if let Some(name) = &current {
            out.get_mut(name).expect("opened").1.push(raw.to_string());
        } else {
            header.push(body.to_string());
        }
    }
    (header, out)
}

/// Translates a data file (and the script that reads it, if any).
pub fn import(data_name: &str, data: &str, script: Option<&str>) -> Result<Imported, String> {
    let script = script.map(parse_script).transpose()?.unwrap_or_else(|| Script { periodic: [true; 3], ..Script::default() });
    let mut notes = script.notes.clone();
    let (header, sections) = sections(data);
    let mut lo = [0.0; 3];
    let mut hi = [0.0; 3];
    for line in &header {
        let w: Vec<&str> = line.split_whitespace().collect();
        for (a, axis) in ["x", "y", "z"].iter().enumerate() {
            if w.len() == 4 && w[2] == format!("{axis}lo") {
                let v = numbers(&w[..2], data_name)?;
                (lo[a], hi[a]) = (v[0], v[1]);
            }
        }
        if w.len() == 6 && w[3] == "xy" {
            notes.push(format!("{data_name}: a triclinic box (`{line}`) is not translated; the box is orthogonal"));
        }
    }
    for name in sections.keys().filter(|k| !["Masses", "Atoms", "Bonds", "Angles"].contains(&k.as_str())) {
        notes.push(format!("{data_name}: section `{name}` is not translated (coefficients come from the script's *_coeff lines; velocities have no meaning in overdamped dynamics)"));
    }
    let mut names: BTreeMap<usize, String> = BTreeMap::new();
    let mut masses: BTreeMap<usize, f64> = BTreeMap::new();
    for line in sections.get("Masses").map(|s| s.1.as_slice()).unwrap_or(&[]) {
        let (body, comment) = line.split_once('#').map_or((line.as_str(), ""), |(b, c)| (b, c.trim()));
        let w: Vec<&str> = body.split_whitespace().collect();
        let t: usize = w[0].parse().map_err(|_| format!("{data_name}: Masses: found `{}`, expected a type number", w[0]))?;
        masses.insert(t, numbers(&w[1..2], data_name)?[0]);
        let name = if comment.is_empty() { format!("t{t}") } else { comment.split_whitespace().next().unwrap().to_string() };
        names.insert(t, name);
    }
    let (atoms_comment, atoms) = sections.get("Atoms").cloned().ok_or_else(|| format!("{data_name}: no `Atoms` section"))?;
    let style =
        script.atom_style.clone().or_else(|| (!atoms_comment.is_empty()).then_some(atoms_comment)).unwrap_or_else(|| "atomic".into());
    let (type_col, x_col) = match style.as_str() {
        "atomic" => (1, 2),
        "bond" | "angle" | "molecular" => (2, 3),
        "full" => (2, 4),
        other => {
            return Err(format!("{data_name}: atom style `{other}` is not translated; expected atomic, bond, angle, molecular or full"))
        }
    };
    let length = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let mut top = format!("# imported by `cellmd import-lammps` from {data_name} (atom style {style})\n[ box ]\n");
    for (a, axis) in ["x", "y", "z"].iter().enumerate() {
        writeln!(top, "{axis} {} {} {}", num(lo[a]), num(hi[a]), if script.periodic[a] { "p" } else { "f" }).unwrap();
    }
    top.push_str("[ particles ]\n# id  type  x  y  z\n");
    let mut used_types: BTreeMap<usize, ()> = BTreeMap::new();
    for line in &atoms {
        let w: Vec<&str> = line.split('#').next().unwrap_or("").split_whitespace().collect();
        let t: usize = w
            .get(type_col)
            .and_then(|t| t.parse().ok())
            .ok_or_else(|| format!("{data_name}: Atoms: `{line}`: expected a type in column {}", type_col + 1))?;
        let x = numbers(w.get(x_col..x_col + 3).ok_or_else(|| format!("{data_name}: Atoms: `{line}`: too few columns"))?, data_name)?;
        let images = w.get(x_col + 3..x_col + 6).map(|i| numbers(i, data_name)).transpose()?.unwrap_or(vec![0.0; 3]);
        let name = names.entry(t).or_insert_with(|| format!("t{t}")).clone();
        used_types.insert(t, ());
        let u: Vec<String> = (0..3).map(|a| num(x[a] + images[a] * length[a])).collect();
        writeln!(top, "{} {name} {} {} {}", w[0], u[0], u[1], u[2]).unwrap();
    }
    for (section, kind, n) in [("Bonds", "bond", 2), ("Angles", "angle", 3)] {
        let Some((_, lines)) = sections.get(section) else { continue };
        writeln!(top, "[ {} ]", section.to_lowercase()).unwrap();
        for line in lines {
            let w: Vec<&str> = line.split_whitespace().collect();
            if w.len() < 2 + n {
                return Err(format!("{data_name}: {section}: `{line}`: expected an id, a type and {n} atom ids"));
            }
            writeln!(top, "{kind}{} {}", w[1], w[2..2 + n].join(" ")).unwrap();
        }
    }
    let mut ff = format!("# imported by `cellmd import-lammps` from {data_name}\n");
    for (t, name) in &names {
        let drag = script.drag.get(t).or(script.drag.get(&0)).copied();
        let drag = drag.unwrap_or_else(|| {
            let m = masses.get(t).copied().unwrap_or(1.0);
            notes.push(format!("type {t} (`{name}`): no fix brownian gamma_t; its drag is its mass {}", num(m)));
            m
        });
        writeln!(ff, "particle {name} drag {}", num(drag)).unwrap();
    }
    for line in script.bond_lines.iter().chain(&script.angle_lines) {
        writeln!(ff, "{line}").unwrap();
    }
    for line in &script.pair_lines {
        // Pair lines name LAMMPS types as tN: give them the particle type names.
        let mut w: Vec<String> = line.split_whitespace().map(str::to_string).collect();
        for k in [1, 2] {
            let t: usize = w[k][1..].parse().expect("written as tN");
            w[k] = names.get(&t).cloned().unwrap_or_else(|| format!("t{t}"));
        }
        writeln!(ff, "{}", w.join(" ")).unwrap();
    }
    let mut deck = String::from("# imported by `cellmd import-lammps`; not translated:\n");
    if notes.is_empty() {
        deck.push_str("#   (nothing)\n");
    }
    for n in &notes {
        writeln!(deck, "#   {n}").unwrap();
    }
    deck.push_str("units lj\ntopology system.top\nforcefield system.ff\n");
    if let Some(w) = script.special {
        writeln!(deck, "special_bonds {} {} {}", num(w[0]), num(w[1]), num(w[2])).unwrap();
    }
    writeln!(deck, "temperature {}", num(script.temperature.unwrap_or(0.0))).unwrap();
    writeln!(deck, "timestep {}", num(script.timestep.unwrap_or(0.005))).unwrap();
    deck.push_str("run 0\n");
    Ok(Imported { topology: top, forcefield: ff, deck, notes })
}

/// Reads the files, translates them and writes `system.top`, `system.ff` and
/// `system.in` into `dir`.
pub fn import_files(data: &Path, script: Option<&Path>, dir: &Path) -> Result<Imported, String> {
    let read = |p: &Path| std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()));
    let script_text = script.map(read).transpose()?;
    let imported = import(&data.display().to_string(), &read(data)?, script_text.as_deref())?;
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for (name, text) in [("system.top", &imported.topology), ("system.ff", &imported.forcefield), ("system.in", &imported.deck)] {
        std::fs::write(dir.join(name), text).map_err(|e| format!("{}: {e}", dir.join(name).display()))?;
    }
    Ok(imported)
}
