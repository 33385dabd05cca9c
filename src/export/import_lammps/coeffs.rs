//! LAMMPS styles and their coefficients (`bond_style`/`bond_coeff`,
//! `angle_style`/`angle_coeff`, `pair_style`/`pair_coeff`/`pair_modify`,
//! and the data file's `… Coeffs` sections) as cellmd force-field laws.
//!
//! Types are expanded as LAMMPS' `utils::bounds` does: `*` (all), `n*`,
//! `*n`, `m*n` or a number; a `pair_coeff I J` with both plain numbers and
//! I > J is the pair (J, I); a later line overrides an earlier one for the
//! types it names (under `hybrid/overlay`, per sub-style). Pairs left
//! unset are mixed as LAMMPS' `init_one` mixes them (`pair_modify mix
//! geometric`, the default, or `arithmetic`), where both like pairs use one
//! and the same sub-style of a mixing style:
//!
//! | style | ε or prefactor | σ and cutoff |
//! |---|---|---|
//! | `lj/cut` ε σ [rc] | √(ε_i ε_j) | geometric √(σ_i σ_j), arithmetic (σ_i + σ_j)/2 |
//! | `soft` A [rc] | √(A_i A_j) | cutoff as σ |
//! | `harmonic/cut` k rc | √(k_i k_j) | cutoff as σ |
//!
//! Translations (LAMMPS → cellmd; K and θ0 as LAMMPS writes them, θ0 in degrees):
//!
//! | LAMMPS | cellmd |
//! |---|---|
//! | bond `harmonic` K r0 | `harmonic k 2K r0 r0` |
//! | bond `fene` K R0 ε σ | `fene` (same) |
//! | bond `lepton` r0 "f" | `custom "f(r − r0) − f(0)" r0 r0` (`no_offset`: without − f(0)) |
//! | bond `zero` [r0] | `custom "0*r"` (no force; the bond still excludes its pair by `special_bonds`) |
//! | angle `harmonic` K θ0 | `harmonic_angle k 2K theta0 θ0` |
//! | angle `cosine` K | `cosine_angle K K` |
//! | angle `cosine/squared` K θ0 | `custom "K*(cos(theta) − cos(theta0))^2"` |
//! | angle `lepton` θ0 "f" | `custom "f(θ − θ0) − f(0)" theta0 θ0` (θ0 in radians, as LAMMPS' DEG2RAD·θ0; `no_offset`: without − f(0)) |
//! | angle `zero` [θ0] | `custom "0*theta"` |
//! | pair `lj/cut` ε σ [rc] | `lj`; with `shift yes`: `wca` at rc = 2^(1/6)σ, else `custom` LJ minus its value at rc |
//! | pair `soft` A [rc] | `soft` (E(rc) = 0: a shift changes nothing) |
//! | pair `harmonic/cut` k rc | `soft_repulsion k 2k sigma rc` (E(rc) = 0) |
//! | pair `lepton` "f" [rc] | `custom "f" cutoff rc` (with `shift yes`: minus f(rc)) |
//! | pair `zero` | nothing (no forces) |
//!
//! LAMMPS' Lepton bonds and angles read their variable as the displacement
//! from the rest value (r − r0, θ − θ0) and subtract the energy at zero
//! displacement unless the style says `no_offset`; cellmd's `custom` reads
//! the distance or angle itself, so the import substitutes the displacement
//! and writes the subtraction out (f(0) evaluated once, in f64, as LAMMPS
//! does).

use std::collections::BTreeMap;

use super::lepton::{self, LeptonError};
use super::words::{clip, Line, Source, Word};
use crate::interactions::lammps::num;

/// One sub-style of a `*_style` command and its style-wide arguments.
#[derive(Clone, Debug)]
pub struct SubStyle {
    pub name: String,
    /// 1-based among sub-styles of the same name (`pair_coeff … lj/cut 2 …`).
    pub instance: usize,
    /// The style-wide cutoff (`pair_style lj/cut 2.5`).
    pub cutoff: Option<f64>,
    /// `bond_style lepton no_offset`.
    pub no_offset: bool,
}

/// A `*_style` command.
#[derive(Clone, Debug, Default)]
pub struct Style {
    pub subs: Vec<SubStyle>,
    pub hybrid: bool,
    pub overlay: bool,
}

/// Styles whose arguments are a cutoff.
fn takes_cutoff(name: &str) -> bool {
    matches!(
        name,
        "lj/cut"
            | "soft"
            | "lepton"
            | "zero"
            | "lj/cut/coul/cut"
            | "lj/cut/coul/long"
            | "lj/cut/coul/debye"
            | "coul/cut"
            | "morse"
            | "yukawa"
    )
}

/// Parses the words after `bond_style`, `angle_style` or `pair_style`.
pub fn parse_style(source: &Source, words: &[Word]) -> Result<Style, String> {
    let Some(first) = words.first() else { return Ok(Style::default()) };
    let (hybrid, overlay) = match first.text.as_str() {
        "hybrid" => (true, false),
        "hybrid/overlay" | "hybrid/scaled" => (true, true),
        _ => (false, false),
    };
    let rest = if hybrid { &words[1..] } else { words };
    let mut style = Style { subs: Vec::new(), hybrid, overlay };
    let mut k = 0;
    while k < rest.len() {
        let name = rest[k].text.clone();
        k += 1;
        let instance = style.subs.iter().filter(|s| s.name == name).count() + 1;
        let mut sub = SubStyle { name, instance, cutoff: None, no_offset: false };
        // Arguments: numbers and keywords up to the next sub-style name.
        while k < rest.len() {
            let w = &rest[k];
            if w.text.parse::<f64>().is_ok() {
                if takes_cutoff(&sub.name) && sub.cutoff.is_none() {
                    sub.cutoff = Some(source.number(w, "a cutoff")?);
                }
                k += 1;
            } else if matches!(w.text.as_str(), "no_offset" | "nocoeff" | "auto_offset") {
                sub.no_offset |= w.text == "no_offset";
                k += 1;
            } else {
                break;
            }
        }
        style.subs.push(sub);
        if !hybrid {
            break;
        }
    }
    Ok(style)
}

/// Types `lo..=hi` named by `w` (LAMMPS' `utils::bounds`) among 1..=n.
pub fn bounds(source: &Source, w: &Word, n: usize) -> Result<(usize, usize), String> {
    let bad = || source.error(w, format!("found `{}`, expected a type from 1 to {n} or a range (`*`, `n*`, `*n`, `m*n`)", clip(&w.text)));
    let number = |s: &str| s.parse::<usize>().map_err(|_| bad());
    let (lo, hi) = match w.text.split_once('*') {
        None => {
            let t = number(&w.text)?;
            (t, t)
        }
        Some((a, b)) => (if a.is_empty() { 1 } else { number(a)? }, if b.is_empty() { n } else { number(b)? }),
    };
    if lo < 1 || hi > n || lo > hi {
        return Err(bad());
    }
    Ok((lo, hi))
}

/// The sub-style a coefficient line names (hybrid) and its coefficients.
fn sub_style<'a>(source: &Source, style: &'a Style, words: &'a [Word]) -> Result<(Option<&'a SubStyle>, &'a [Word]), String> {
    if !style.hybrid {
        return Ok((style.subs.first(), words));
    }
    let name = words.first().ok_or_else(|| source.error(&words[0], "expected a sub-style after the types"))?;
    if name.text == "none" {
        return Ok((None, &words[1..]));
    }
    let same: Vec<&SubStyle> = style.subs.iter().filter(|s| s.name == name.text).collect();
    match same.as_slice() {
        [] => Err(source.error(
            name,
            format!(
                "found sub-style `{}`, expected one of the style's: {}",
                clip(&name.text),
                style.subs.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")
            ),
        )),
        [one] => Ok((Some(one), &words[1..])),
        many => {
            let k = words.get(1).and_then(|w| w.text.parse::<usize>().ok()).filter(|k| (1..=many.len()).contains(k)).ok_or_else(|| {
                source.error(
                    name,
                    format!("`{}` appears {} times in the style: expected its instance number after it", name.text, many.len()),
                )
            })?;
            Ok((Some(many[k - 1]), &words[2..]))
        }
    }
}

fn numbers(source: &Source, words: &[Word], what: &str) -> Result<Vec<f64>, String> {
    words.iter().map(|w| source.number(w, what)).collect()
}

/// A translation: the law, or why there is none (a note); the outer error
/// is bad input (an error at its place).
type Translated = Result<Result<String, String>, String>;

/// A Lepton expression's translation at the word that holds it: a function
/// cellmd lacks is a note, an invalid expression an error.
fn lepton_at(source: &Source, w: &Word, variable: &str) -> Result<Result<String, String>, String> {
    match lepton::translate(&w.text, variable) {
        Ok(text) => Ok(Ok(text)),
        Err(LeptonError::Untranslatable(m)) => Ok(Err(m)),
        Err(LeptonError::Invalid(m)) => Err(source.error(w, m)),
    }
}

/// A Lepton expression of `variable` with the displacement substituted for
/// it, minus its value at zero displacement unless `no_offset`.
fn lepton_displaced(source: &Source, w: &Word, variable: &str, no_offset: bool) -> Translated {
    let f = match lepton_at(source, w, variable)? {
        Ok(f) => f,
        Err(why) => return Ok(Err(why)),
    };
    let zero = if no_offset { 0.0 } else { evaluate(&f, variable, 0.0).map_err(|m| source.error(w, m))? };
    let shifted = substitute(&f, variable, &format!("({variable} - {variable}0)"));
    Ok(Ok(if zero == 0.0 { shifted } else { format!("({shifted}) - ({})", num(zero)) }))
}

/// `text` (cellmd expression) at `variable` = `at`.
pub fn evaluate(text: &str, variable: &str, at: f64) -> Result<f64, String> {
    let expr = crate::expr::parse(text).map_err(|e| format!("{e:?}"))?;
    expr.eval(&mut |r| match r {
        crate::expr::Ref::Name(n) if n == variable => Ok(at),
        other => Err(format!("{} is not the variable `{variable}`", other.quoted())),
    })
    .map_err(|e| format!("the expression cannot be evaluated at {variable} = {at}: {e:?}"))
}

/// `text` with every whole-word `name` replaced by `by`.
fn substitute(text: &str, name: &str, by: &str) -> String {
    let mut out = String::new();
    let chars: Vec<char> = text.chars().collect();
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let mut k = 0;
    while k < chars.len() {
        if ident(chars[k]) {
            let start = k;
            while k < chars.len() && ident(chars[k]) {
                k += 1;
            }
            let word: String = chars[start..k].iter().collect();
            out.push_str(if word == name { by } else { &word });
        } else {
            out.push(chars[k]);
            k += 1;
        }
    }
    out
}

/// A bond or angle law: `harmonic k … r0 …` (the text after the type name).
fn bonded_law(kind: &str, sub: &SubStyle, w: &[Word], source: &Source, line: &Line) -> Translated {
    let expect = |n: usize, form: &str| -> Result<Vec<f64>, String> {
        if w.len() != n {
            let at = w.first().unwrap_or(&line.words[0]);
            return Err(source.error(at, format!("{kind} style `{}` takes {form}, found {} value(s)", sub.name, w.len())));
        }
        numbers(source, w, "a coefficient")
    };
    let quoted = |k: usize| -> Result<&Word, String> {
        w.get(k).ok_or_else(|| {
            source.error(&line.words[0], format!("{kind} style `{}` takes a rest value and a quoted Lepton expression", sub.name))
        })
    };
    Ok(Ok(match (kind, sub.name.as_str()) {
        ("bond", "harmonic") => {
            let v = expect(2, "K r0")?;
            format!("harmonic k {} r0 {}", num(2.0 * v[0]), num(v[1]))
        }
        ("bond", "fene") => {
            let v = expect(4, "K R0 epsilon sigma")?;
            format!("fene K {} R0 {} epsilon {} sigma {}", num(v[0]), num(v[1]), num(v[2]), num(v[3]))
        }
        ("bond", "zero") => "custom \"0*r\"".to_string(),
        ("bond", "lepton") => {
            let r0 = source.number(quoted(0)?, "the rest length r0")?;
            let e = quoted(1)?;
            match lepton_displaced(source, e, "r", sub.no_offset)? {
                Ok(text) => format!("custom \"{text}\" r0 {}", num(r0)),
                Err(why) => return Ok(Err(why)),
            }
        }
        ("angle", "harmonic") => {
            let v = expect(2, "K theta0")?;
            format!("harmonic_angle k {} theta0 {}", num(2.0 * v[0]), num(v[1]))
        }
        ("angle", "cosine") => format!("cosine_angle K {}", num(expect(1, "K")?[0])),
        ("angle", "cosine/squared") => {
            let v = expect(2, "K theta0")?;
            format!("custom \"K*(cos(theta) - cos(theta0))^2\" K {} theta0 {}", num(v[0]), num(deg2rad(v[1])))
        }
        ("angle", "zero") => "custom \"0*theta\"".to_string(),
        ("angle", "lepton") => {
            let theta0 = source.number(quoted(0)?, "the rest angle theta0 (degrees)")?;
            let e = quoted(1)?;
            match lepton_displaced(source, e, "theta", sub.no_offset)? {
                Ok(text) => format!("custom \"{text}\" theta0 {}", num(deg2rad(theta0))),
                Err(why) => return Ok(Err(why)),
            }
        }
        _ => return Ok(Err(format!("{kind} style `{}` is not translated", sub.name))),
    }))
}

/// LAMMPS' DEG2RAD·θ0 (MathConst::DEG2RAD = π/180), the same f64.
fn deg2rad(degrees: f64) -> f64 {
    std::f64::consts::PI / 180.0 * degrees
}

/// The laws of the bond or angle types 1..=n (`kind` "bond" or "angle"),
/// from their coefficient lines in order; a type without a law has the
/// reason instead (a note). Bad input is an error at its place.
pub fn bonded(kind: &str, style: &Style, lines: &[(Source, Line)], n: usize) -> Result<BTreeMap<usize, Result<String, String>>, String> {
    let mut laws: BTreeMap<usize, Result<String, String>> = BTreeMap::new();
    for (source, line) in lines {
        let types = line.words.get(1).ok_or_else(|| source.error(&line.words[0], "expected a type"))?;
        let (lo, hi) = bounds(source, types, n)?;
        let (sub, coeffs) = sub_style(source, style, &line.words[2..])?;
        let law = match sub {
            Some(sub) => bonded_law(kind, sub, coeffs, source, line)?,
            None if style.subs.is_empty() => return Err(source.error(&line.words[0], format!("`{kind}_coeff` before any `{kind}_style`"))),
            None => Err(format!("`{kind}_coeff … none`")),
        };
        let law = law.map_err(|why| format!("{}:{}: `{}`: {why}", source.name, line.line, clip(&line.text)));
        (lo..=hi).for_each(|t| {
            laws.insert(t, law.clone());
        });
    }
    Ok(laws)
}

/// Pair settings of `pair_modify`.
#[derive(Clone, Debug, Default)]
pub struct PairModify {
    /// `mix arithmetic` (else geometric).
    pub arithmetic: bool,
    /// `shift yes` for every sub-style, or for these (name, instance).
    pub shift_all: bool,
    pub shift: Vec<(String, usize)>,
}

/// One pair's coefficients under one sub-style.
#[derive(Clone, Debug)]
struct PairCoeff {
    sub: SubStyle,
    values: Vec<Word>,
    source: Source,
    line: usize,
    col: usize,
    text: String,
}

/// Pair laws `(i, j, law)` with i ≤ j, and notes for the pairs that have none.
pub type PairLaws = (Vec<(usize, usize, String)>, Vec<String>);

/// The pair laws: `(i, j, law)` with i ≤ j, and notes for what has none.
pub fn pairs(style: &Style, modify: &PairModify, lines: &[(Source, Line)], n: usize) -> Result<PairLaws, String> {
    // (i, j) → assigned sub-styles (one, or several under overlay).
    let mut set: BTreeMap<(usize, usize), Vec<PairCoeff>> = BTreeMap::new();
    for (source, line) in lines {
        let w = &line.words;
        if w.len() < 3 {
            return Err(source.error(&w[0], "expected two types and coefficients"));
        }
        let (mut a, mut b) = (bounds(source, &w[1], n)?, bounds(source, &w[2], n)?);
        if !w[1].text.contains('*') && !w[2].text.contains('*') && a.0 > b.0 {
            std::mem::swap(&mut a, &mut b);
        }
        let (sub, values) = sub_style(source, style, &w[3..])?;
        for i in a.0..=a.1 {
            for j in i.max(b.0)..=b.1 {
                let entry = set.entry((i, j)).or_default();
                match sub {
                    None => entry.clear(),
                    Some(sub) => {
                        if !style.overlay {
                            entry.clear();
                        }
                        entry.retain(|c| !(c.sub.name == sub.name && c.sub.instance == sub.instance));
                        entry.push(PairCoeff {
                            sub: sub.clone(),
                            values: values.to_vec(),
                            source: source.clone(),
                            line: line.line,
                            col: w[0].col,
                            text: line.text.clone(),
                        });
                    }
                }
            }
        }
    }
    let mut laws = Vec::new();
    let mut notes = Vec::new();
    for i in 1..=n {
        for j in i..=n {
            let coeffs = match set.get(&(i, j)) {
                Some(c) => c.clone(),
                None => match mixed(modify, set.get(&(i, i)), set.get(&(j, j))) {
                    Ok(Some(c)) => vec![c],
                    Ok(None) => continue,
                    Err(why) => {
                        notes.push(format!("pair {i} {j}: no pair_coeff and {why} (LAMMPS stops: \"All pair coeffs are not set\")"));
                        continue;
                    }
                },
            };
            for c in coeffs {
                match pair_law(&c, modify)? {
                    Ok(Some(law)) => laws.push((i, j, law)),
                    Ok(None) => {}
                    Err(why) => {
                        let note = format!("{}:{}: `{}`: {why}", c.source.name, c.line, clip(&c.text));
                        if !notes.contains(&note) {
                            notes.push(note);
                        }
                    }
                }
            }
        }
    }
    Ok((laws, notes))
}

fn shifted(modify: &PairModify, sub: &SubStyle) -> bool {
    modify.shift_all || modify.shift.iter().any(|(name, k)| *name == sub.name && (*k == 0 || *k == sub.instance))
}

/// A pair's cutoff: its own (`values[k]`) or the style-wide one.
fn cutoff(c: &PairCoeff, k: usize) -> Result<f64, String> {
    match c.values.get(k) {
        Some(w) => c.source.number(w, "a cutoff"),
        None => c.sub.cutoff.ok_or_else(|| format!("pair style `{}` has no cutoff (neither in pair_style nor in pair_coeff)", c.sub.name)),
    }
}

/// A pair's law: `Ok(Ok(None))` for a style without forces (`zero`).
fn pair_law(c: &PairCoeff, modify: &PairModify) -> Result<Result<Option<String>, String>, String> {
    let shift = shifted(modify, &c.sub);
    let place = || format!("{}:{}:{}: `{}`: ", c.source.name, c.line, c.col, clip(&c.text));
    let v = |k: usize| -> Result<f64, String> {
        let w = c.values.get(k).ok_or_else(|| format!("{}pair style `{}` needs more coefficients", place(), c.sub.name))?;
        c.source.number(w, "a coefficient")
    };
    let most = |n: usize| -> Result<(), String> {
        if c.values.len() > n {
            return Err(c
                .source
                .error(&c.values[n], format!("pair style `{}` takes at most {n} coefficients, found {}", c.sub.name, c.values.len())));
        }
        Ok(())
    };
    let cutoff = |k: usize| cutoff(c, k).map_err(|m| format!("{}{m}", place()));
    Ok(Ok(Some(match c.sub.name.as_str() {
        "lj/cut" => {
            most(3)?;
            let (e, s, rc) = (v(0)?, v(1)?, cutoff(2)?);
            if shift && (rc / s - 2f64.powf(1.0 / 6.0)).abs() < 1e-12 {
                format!("wca epsilon {} sigma {}", num(e), num(s))
            } else if shift {
                format!(
                    "custom \"4*epsilon*((sigma/r)^12 - (sigma/r)^6) - 4*epsilon*((sigma/cutoff)^12 - (sigma/cutoff)^6)\" cutoff {} epsilon {} sigma {}",
                    num(rc),
                    num(e),
                    num(s)
                )
            } else {
                format!("lj epsilon {} sigma {} rc {}", num(e), num(s), num(rc))
            }
        }
        "soft" => {
            most(2)?;
            format!("soft A {} rc {}", num(v(0)?), num(cutoff(1)?))
        }
        "harmonic/cut" => {
            most(2)?;
            format!("soft_repulsion k {} sigma {}", num(2.0 * v(0)?), num(v(1)?))
        }
        "lepton" => {
            let e = c.values.first().ok_or_else(|| format!("{}pair style `lepton` takes a quoted expression", place()))?;
            most(2)?;
            let rc = cutoff(1)?;
            let f = match lepton_at(&c.source, e, "r")? {
                Ok(f) => f,
                Err(why) => return Ok(Err(why)),
            };
            let text = if shift { format!("({f}) - ({})", num(evaluate(&f, "r", rc).map_err(|m| c.source.error(e, m))?)) } else { f };
            format!("custom \"{text}\" cutoff {}", num(rc))
        }
        "zero" => return Ok(Ok(None)),
        other => return Ok(Err(format!("pair style `{other}`{} is not translated", if shift { " (shifted)" } else { "" }))),
    })))
}

/// The mixed coefficients of an unset pair from its like pairs, `None`
/// when neither like pair has a style (nothing to mix), or why not.
fn mixed(modify: &PairModify, ii: Option<&Vec<PairCoeff>>, jj: Option<&Vec<PairCoeff>>) -> Result<Option<PairCoeff>, String> {
    let (ii, jj) = match (ii, jj) {
        (Some(a), Some(b)) => (a, b),
        (None, None) => return Ok(None),
        _ => return Err("one of its like pairs has no coefficients to mix".into()),
    };
    let (a, b) = match (ii.as_slice(), jj.as_slice()) {
        ([a], [b]) if a.sub.name == b.sub.name && a.sub.instance == b.sub.instance => (a, b),
        ([], []) => return Ok(None),
        _ => return Err("its like pairs do not use one and the same sub-style, so LAMMPS does not mix them".into()),
    };
    let get = |c: &PairCoeff, k: usize| -> Result<f64, String> {
        c.values.get(k).map(|w| c.source.number(w, "a coefficient")).ok_or_else(|| "a like pair lacks a coefficient".to_string())?
    };
    let energy = |x: f64, y: f64| (x * y).sqrt();
    let distance = |x: f64, y: f64| if modify.arithmetic { 0.5 * (x + y) } else { (x * y).sqrt() };
    let values: Vec<f64> = match a.sub.name.as_str() {
        "lj/cut" => vec![energy(get(a, 0)?, get(b, 0)?), distance(get(a, 1)?, get(b, 1)?), distance(cutoff(a, 2)?, cutoff(b, 2)?)],
        "soft" => vec![energy(get(a, 0)?, get(b, 0)?), distance(cutoff(a, 1)?, cutoff(b, 1)?)],
        "harmonic/cut" => vec![energy(get(a, 0)?, get(b, 0)?), distance(get(a, 1)?, get(b, 1)?)],
        "zero" => return Ok(None),
        other => return Err(format!("pair style `{other}` has no mixing rule")),
    };
    // The mixed values as words of a coefficient line (exact: shortest round trip).
    let words = values.iter().map(|v| Word { text: num(*v), line: a.line, col: 1 }).collect();
    Ok(Some(PairCoeff {
        sub: a.sub.clone(),
        values: words,
        source: a.source.clone(),
        line: a.line,
        col: a.col,
        text: format!("{} (mixed)", a.text),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::import_lammps::words::script_lines;

    fn lines(text: &str) -> Vec<(Source, Line)> {
        script_lines(text).unwrap().into_iter().map(|l| (Source { name: "in".into() }, l)).collect()
    }

    fn style(text: &str) -> Style {
        let l = &script_lines(text).unwrap()[0];
        parse_style(&Source { name: "in".into() }, &l.words[1..]).unwrap()
    }

    #[test]
    fn wildcards_expand_as_lammps_bounds() {
        let s = Source { name: "in".into() };
        let w = |t: &str| Word { text: t.into(), line: 1, col: 1 };
        assert_eq!(bounds(&s, &w("*"), 5).unwrap(), (1, 5));
        assert_eq!(bounds(&s, &w("4*5"), 5).unwrap(), (4, 5));
        assert_eq!(bounds(&s, &w("*3"), 5).unwrap(), (1, 3));
        assert_eq!(bounds(&s, &w("2*"), 5).unwrap(), (2, 5));
        assert!(bounds(&s, &w("6"), 5).unwrap_err().contains("expected a type from 1 to 5"));
        let laws = bonded("bond", &style("bond_style harmonic"), &lines("bond_coeff * 10 1.0\nbond_coeff 2* 20 1.5\n"), 3).unwrap();
        assert_eq!(laws[&1].as_ref().unwrap(), "harmonic k 20.0 r0 1.0");
        assert_eq!(laws[&3].as_ref().unwrap(), "harmonic k 40.0 r0 1.5");
    }

    #[test]
    fn unset_pairs_mix_geometrically_or_arithmetically() {
        let st = style("pair_style lj/cut 2.5");
        let coeffs = lines("pair_coeff 1 1 1.0 1.0\npair_coeff 2 2 4.0 2.0 3.0\n");
        let (laws, notes) = pairs(&st, &PairModify::default(), &coeffs, 2).unwrap();
        assert!(notes.is_empty(), "{notes:?}");
        let geometric = format!("lj epsilon 2.0 sigma {} rc {}", num(2f64.sqrt()), num((2.5f64 * 3.0).sqrt()));
        assert_eq!(laws[1], (1, 2, geometric));
        let (laws, _) = pairs(&st, &PairModify { arithmetic: true, ..Default::default() }, &coeffs, 2).unwrap();
        assert_eq!(laws[1], (1, 2, "lj epsilon 2.0 sigma 1.5 rc 2.75".to_string()));
        assert_eq!(laws[0], (1, 1, "lj epsilon 1.0 sigma 1.0 rc 2.5".to_string()));
    }

    #[test]
    fn lepton_bonds_and_angles_read_the_displacement_and_subtract_the_energy_at_rest() {
        let laws = bonded("bond", &style("bond_style lepton"), &lines("bond_coeff 1 1.5 \"k*r^2+1; k=2\"\n"), 1).unwrap();
        assert_eq!(laws[&1].as_ref().unwrap(), "custom \"((2)*((r - r0)^2) + 1) - (1.0)\" r0 1.5");
        let laws =
            bonded("angle", &style("angle_style hybrid lepton no_offset harmonic"), &lines("angle_coeff 1 lepton 90 \"cos(theta)\"\n"), 1)
                .unwrap();
        assert_eq!(
            laws[&1].as_ref().unwrap(),
            &format!("custom \"cos((theta - theta0))\" theta0 {}", num(std::f64::consts::PI / 180.0 * 90.0))
        );
    }
}
