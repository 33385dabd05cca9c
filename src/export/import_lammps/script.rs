//! The commands of a LAMMPS input script that the import reads, in order.
//!
//! Read: `units lj`, `atom_style`, `boundary`, `special_bonds` (`lj`,
//! `lj/coul`, `fene`, and `coul` — which has no meaning without charges and
//! is noted), `timestep`, `*_style`, `*_coeff`, `pair_modify mix|shift`,
//! `mass`, `group NAME type …`, `fix … brownian`, `fix … langevin` (with
//! `fix … nve`), `run`, `thermo`, `neighbor`, `neigh_modify`, `print`,
//! `read_data` and `variable NAME index|string|equal VALUE` with a literal
//! value (substituted into later `${NAME}` and `$N` references). Settings
//! of parallel runs (`comm_modify`, `newton`, `processors`, `package`,
//! `suffix`) and of LAMMPS' own output (`echo`, `log`) change no result and
//! are skipped; every other command is listed as not translated, with its
//! line.

use std::collections::BTreeMap;

use super::coeffs::{parse_style, PairModify, Style};
use super::words::{clip, script_lines, Line, Source, Word};

/// A fix that moves atoms.
#[derive(Clone, Debug)]
pub enum Dynamics {
    /// `fix ID GROUP brownian T SEED gamma_t G [rng none|uniform|gaussian]`.
    Brownian { group: String, temperature: f64, gamma: f64, rng: String },
    /// `fix ID GROUP langevin T0 T1 DAMP SEED [scale TYPE RATIO]...`: in the
    /// overdamped limit, drag m·ratio/damp per type.
    Langevin { group: String, temperature: f64, damp: f64, scale: BTreeMap<usize, f64> },
}

/// A deck command the script's order decides.
#[derive(Clone, Debug, PartialEq)]
pub enum Event {
    Timestep(f64),
    Thermo(u64),
    Run(u64),
    Print(String),
}

/// What the import takes from a script.
#[derive(Clone, Debug, Default)]
pub struct Script {
    pub source: Option<Source>,
    pub atom_style: Option<String>,
    pub periodic: Option<[bool; 3]>,
    pub special: Option<[f64; 3]>,
    /// `bond_style` and the `bond_coeff` lines.
    pub bond: Terms,
    /// `angle_style` and the `angle_coeff` lines.
    pub angle: Terms,
    /// `pair_style` and the `pair_coeff` lines.
    pub pair: Terms,
    pub pair_modify: PairModify,
    /// `mass` commands: (type range word, mass).
    pub masses: Vec<(Word, f64)>,
    /// `group NAME type …`: the type words.
    pub groups: BTreeMap<String, Vec<Word>>,
    pub fixes: Fixes,
    pub events: Vec<Event>,
    pub neighbor: Neighbor,
    /// The data file named by `read_data` (the word, for errors about it).
    pub read_data: Option<Word>,
    pub notes: Vec<String>,
}

/// A kind's style and its coefficient lines (in script order).
#[derive(Clone, Debug, Default)]
pub struct Terms {
    pub style: Style,
    pub coeffs: Vec<(Source, Line)>,
}

/// The `fix` commands of the dynamics that are in force, by fix id.
#[derive(Clone, Debug, Default)]
pub struct Fixes {
    /// `fix … brownian` and `fix … langevin`.
    pub dynamics: Vec<(usize, Dynamics)>,
    /// `fix … nve` ids (with a langevin fix, the pair is overdamped dynamics).
    pub nve: Vec<usize>,
}

/// `neighbor SKIN` and `neigh_modify every N check yes|no`.
#[derive(Clone, Debug, Default)]
pub struct Neighbor {
    pub skin: Option<f64>,
    pub every: Option<u64>,
    pub check: Option<bool>,
}

/// Commands that change no result of a run (parallel settings, LAMMPS' own output).
const SKIPPED: &[&str] = &["comm_modify", "newton", "processors", "package", "suffix", "echo", "log"];

/// `${NAME}` and `$N` replaced by the literal variables defined so far.
fn substitute(text: &str, variables: &BTreeMap<String, String>) -> Option<String> {
    if !text.contains('$') {
        return Some(text.to_string());
    }
    let mut out = String::new();
    let mut rest = text;
    while let Some(k) = rest.find('$') {
        out.push_str(&rest[..k]);
        let after = &rest[k + 1..];
        let (name, len) = if let Some(body) = after.strip_prefix('{') {
            let end = body.find('}')?;
            (&body[..end], end + 2)
        } else {
            (after.get(..1)?, 1)
        };
        out.push_str(variables.get(name)?);
        rest = &after[len..];
    }
    out.push_str(rest);
    Some(out)
}

/// Reads a script.
pub fn read(name: &str, text: &str) -> Result<Script, String> {
    let source = Source { name: name.to_string() };
    let lines = script_lines(text).map_err(|(line, col, m)| format!("{name}:{line}:{col}: {m}"))?;
    let mut s = Script { source: Some(source.clone()), ..Script::default() };
    let mut variables: BTreeMap<String, String> = BTreeMap::new();
    let mut fix_ids: BTreeMap<String, usize> = BTreeMap::new();
    for mut line in lines {
        // Literal variables are substituted; a reference to anything else leaves the line untranslated.
        if line.text.contains('$') {
            let mut ok = true;
            for w in &mut line.words {
                match substitute(&w.text, &variables) {
                    Some(t) => w.text = t,
                    None => ok = false,
                }
            }
            if !ok {
                s.notes.push(
                    source
                        .at_line(line.line, format!("`{}`: uses a variable that is not a literal value; not translated", clip(&line.text))),
                );
                continue;
            }
        }
        let w = &line.words;
        let at = |k: usize| w.get(k).ok_or_else(|| source.error(&w[w.len() - 1], format!("`{}` needs more arguments", w[0].text)));
        let note = |s: &mut Script, why: &str| s.notes.push(source.at_line(line.line, format!("`{}`: {why}", clip(&line.text))));
        match w[0].text.as_str() {
            "units" if w.get(1).is_some_and(|u| u.text == "lj") => {}
            "units" => note(&mut s, "only `units lj` is translated; the deck says `units lj`, convert the values"),
            "atom_style" => s.atom_style = Some(at(1)?.text.clone()),
            "dimension" if w.get(1).is_some_and(|d| d.text == "3") => {}
            "boundary" => {
                let mut p = [true; 3];
                for (a, flag) in p.iter_mut().enumerate() {
                    let b = at(a + 1)?;
                    *flag = match b.text.as_str() {
                        "p" => true,
                        "f" | "s" | "m" | "fs" | "fm" | "sf" | "mf" | "ss" | "mm" | "sm" | "ms" => false,
                        _ => return Err(source.error(b, format!("found `{}`, expected a boundary p, f, s or m", clip(&b.text)))),
                    };
                }
                if w[1..].iter().any(|b| b.text != "p" && b.text != "f") {
                    note(&mut s, "shrink-wrapped boundaries (s, m) are fixed walls of the data file's box in cellmd");
                }
                s.periodic = Some(p);
            }
            "special_bonds" => special_bonds(&source, &line, &mut s)?,
            "timestep" => {
                let dt = source.number(at(1)?, "a timestep")?;
                if dt <= 0.0 {
                    return Err(source.error(at(1)?, format!("found timestep {dt}, expected a timestep > 0")));
                }
                s.events.push(Event::Timestep(dt));
            }
            "bond_style" => s.bond.style = parse_style(&source, &w[1..])?,
            "angle_style" => s.angle.style = parse_style(&source, &w[1..])?,
            "pair_style" => s.pair.style = parse_style(&source, &w[1..])?,
            "bond_coeff" => s.bond.coeffs.push((source.clone(), line.clone())),
            "angle_coeff" => s.angle.coeffs.push((source.clone(), line.clone())),
            "pair_coeff" => s.pair.coeffs.push((source.clone(), line.clone())),
            "pair_modify" => pair_modify(&source, &line, &mut s)?,
            "mass" => s.masses.push((at(1)?.clone(), source.number(at(2)?, "a mass")?)),
            "group" if w.get(2).is_some_and(|k| k.text == "type") => {
                s.groups.insert(at(1)?.text.clone(), w[3..].to_vec());
            }
            "fix" => fix(&source, &line, &mut s, &mut fix_ids)?,
            "unfix" => {
                if let Some(k) = fix_ids.remove(&at(1)?.text) {
                    s.fixes.dynamics.retain(|(id, _)| *id != k);
                    s.fixes.nve.retain(|id| *id != k);
                    if s.events.iter().any(|e| matches!(e, Event::Run(_))) {
                        note(&mut s, "a fix removed after a run: the deck runs every `run` with the fixes defined before the first");
                    }
                }
            }
            "run" => {
                let n = source.count(at(1)?, "a number of steps")?;
                if w[2..].iter().any(|x| x.text == "upto") {
                    let done: u64 = s.events.iter().map(|e| if let Event::Run(k) = e { *k } else { 0 }).sum();
                    s.events.push(Event::Run(n.saturating_sub(done)));
                } else {
                    s.events.push(Event::Run(n));
                }
                if w[2..].iter().any(|x| x.text == "every") {
                    note(&mut s, "`run … every` runs its commands between chunks; the deck runs the steps without them");
                }
            }
            "thermo" => s.events.push(Event::Thermo(source.count(at(1)?, "a thermo interval")?)),
            "neighbor" => s.neighbor.skin = Some(source.number(at(1)?, "a skin")?),
            "neigh_modify" => {
                for pair in w[1..].windows(2) {
                    match pair[0].text.as_str() {
                        "every" => s.neighbor.every = Some(source.count(&pair[1], "a rebuild interval")?),
                        "check" => s.neighbor.check = Some(pair[1].text == "yes"),
                        _ => {}
                    }
                }
            }
            "print" => s.events.push(Event::Print(w[1..].iter().map(|x| x.text.as_str()).collect::<Vec<_>>().join(" "))),
            "read_data" => s.read_data = Some(at(1)?.clone()),
            "variable" => {
                let (name, style) = (at(1)?.text.clone(), at(2)?.text.as_str());
                let value = w.get(3).map(|v| v.text.clone());
                let literal = value.as_ref().filter(|v| matches!(style, "index" | "string") || v.parse::<f64>().is_ok());
                match literal {
                    Some(v) if w.len() == 4 => {
                        variables.insert(name, v.clone());
                    }
                    _ => note(&mut s, "only variables with one literal value are read (substituted into later lines)"),
                }
            }
            cmd if SKIPPED.contains(&cmd) => {}
            "thermo_style" | "thermo_modify" => note(
                &mut s,
                "not translated: cellmd's `thermo N` prints step, time, energies and fmax (`thermo N COLUMN...` chooses others)",
            ),
            "minimize" => note(&mut s, "not translated: cellmd's `minimize` is FIRE with drag-scaled masses, not LAMMPS' minimizers"),
            "velocity" => note(&mut s, "not translated: overdamped dynamics has no velocities"),
            _ => note(&mut s, "not translated"),
        }
    }
    Ok(s)
}

/// `special_bonds` keywords: `lj W W W`, `lj/coul W W W`, `coul W W W`, `fene`, and options.
fn special_bonds(source: &Source, line: &Line, s: &mut Script) -> Result<(), String> {
    let w = &line.words;
    let mut k = 1;
    while k < w.len() {
        let three = |k: usize| -> Result<[f64; 3], String> {
            let mut v = [0.0; 3];
            for (m, x) in v.iter_mut().enumerate() {
                let word = w.get(k + 1 + m).ok_or_else(|| source.error(&w[k], format!("`{}` takes three weights", w[k].text)))?;
                *x = source.number(word, "a special-bond weight")?;
                if !(0.0..=1.0).contains(x) {
                    return Err(source.error(word, format!("found weight {x}, expected a weight from 0 to 1")));
                }
            }
            Ok(v)
        };
        match w[k].text.as_str() {
            "lj" | "lj/coul" => {
                s.special = Some(three(k)?);
                k += 4;
            }
            "coul" => {
                three(k)?;
                s.notes.push(
                    source.at_line(
                        line.line,
                        "`special_bonds coul …`: ignored (cellmd has no charges; `lj` weights apply to every pair law)",
                    ),
                );
                k += 4;
            }
            "fene" => {
                s.special = Some([0.0, 1.0, 1.0]);
                k += 1;
            }
            "charmm" | "amber" | "dreiding" => {
                s.special = Some(match w[k].text.as_str() {
                    "amber" => [0.0, 0.0, 0.5],
                    _ => [0.0, 0.0, 0.0],
                });
                k += 1;
            }
            "angle" | "dihedral" | "one/five" => {
                if w.get(k + 1).is_some_and(|v| v.text == "yes") {
                    s.notes.push(source.at_line(
                        line.line,
                        format!("`special_bonds … {} yes`: not translated (cellmd counts 1-3 and 1-4 neighbours along bonds)", w[k].text),
                    ));
                }
                k += 2;
            }
            _ => {
                return Err(source.error(
                    &w[k],
                    format!("found `{}`, expected lj, lj/coul, coul, fene, charmm, amber, angle or dihedral", clip(&w[k].text)),
                ))
            }
        }
    }
    Ok(())
}

fn pair_modify(source: &Source, line: &Line, s: &mut Script) -> Result<(), String> {
    let w = &line.words;
    let mut k = 1;
    // `pair_modify pair STYLE [N] …` restricts to one sub-style.
    let mut only: Option<(String, usize)> = None;
    while k < w.len() {
        match w[k].text.as_str() {
            "pair" => {
                let name = w.get(k + 1).ok_or_else(|| source.error(&w[k], "`pair` needs a sub-style"))?.text.clone();
                let instance = w.get(k + 2).and_then(|x| x.text.parse::<usize>().ok());
                k += if instance.is_some() { 3 } else { 2 };
                only = Some((name, instance.unwrap_or(0)));
            }
            "mix" => {
                let rule = w.get(k + 1).ok_or_else(|| source.error(&w[k], "`mix` needs a rule"))?;
                match rule.text.as_str() {
                    "geometric" => s.pair_modify.arithmetic = false,
                    "arithmetic" => s.pair_modify.arithmetic = true,
                    _ => {
                        return Err(source.error(
                            rule,
                            format!(
                                "found mixing rule `{}`, expected geometric or arithmetic (sixthpower is not translated)",
                                clip(&rule.text)
                            ),
                        ))
                    }
                }
                k += 2;
            }
            "shift" => {
                let yes = w.get(k + 1).is_some_and(|v| v.text == "yes");
                match (&only, yes) {
                    (Some(sub), true) => s.pair_modify.shift.push(sub.clone()),
                    (None, yes) => s.pair_modify.shift_all = yes,
                    (Some(sub), false) => s.pair_modify.shift.retain(|x| x != sub),
                }
                k += 2;
            }
            other => {
                s.notes.push(source.at_line(line.line, format!("`{}`: `{other}` not translated", clip(&line.text))));
                k += 2;
            }
        }
    }
    Ok(())
}

fn fix(source: &Source, line: &Line, s: &mut Script, ids: &mut BTreeMap<String, usize>) -> Result<(), String> {
    let w = &line.words;
    let at = |k: usize| w.get(k).ok_or_else(|| source.error(&w[w.len() - 1], "`fix` needs more arguments"));
    let (id, group, style) = (at(1)?.text.clone(), at(2)?.text.clone(), at(3)?.text.as_str());
    let k = line.line;
    ids.insert(id, k);
    let keyword = |name: &str| w.iter().position(|x| x.text == name).and_then(|p| w.get(p + 1));
    match style {
        "brownian" => {
            let temperature = source.number(at(4)?, "a temperature")?;
            let gamma = keyword("gamma_t").ok_or_else(|| source.error(&w[3], "`fix brownian` without `gamma_t` is not translated"))?;
            let gamma = source.number(gamma, "a drag gamma_t")?;
            let rng = keyword("rng").map_or("uniform".to_string(), |r| r.text.clone());
            s.fixes.dynamics.push((k, Dynamics::Brownian { group, temperature, gamma, rng }));
        }
        "langevin" => {
            let (t0, t1) = (source.number(at(4)?, "a start temperature")?, source.number(at(5)?, "a stop temperature")?);
            let damp = source.number(at(6)?, "a damping time")?;
            if t0 != t1 {
                s.notes.push(source.at_line(
                    k,
                    format!("`{}`: a temperature ramp is not translated; the deck runs at the start temperature", clip(&line.text)),
                ));
            }
            let mut scale = BTreeMap::new();
            for (p, x) in w.iter().enumerate().skip(8) {
                if x.text == "scale" {
                    let t = at(p + 1)?;
                    let ty = source.count(t, "an atom type")? as usize;
                    scale.insert(ty, source.number(at(p + 2)?, "a damping ratio")?);
                }
            }
            s.notes.push(source.at_line(
                k,
                format!("`{}`: translated in the overdamped limit (drag m/damp per type); LAMMPS' inertial dynamics agrees where damp = {damp} is short against the times of interest", clip(&line.text)),
            ));
            s.fixes.dynamics.push((k, Dynamics::Langevin { group, temperature: t0, damp, scale }));
        }
        "nve" => s.fixes.nve.push(k),
        _ => s.notes.push(source.at_line(k, format!("`{}`: not translated", clip(&line.text)))),
    }
    Ok(())
}
