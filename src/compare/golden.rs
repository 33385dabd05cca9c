//! Golden reference files (`reference/<interaction>.yaml`), in the spirit of
//! LAMMPS' force-style test files, written and read in a small YAML subset:
//! documents start with `---`; entries are `key: value` or a literal block
//! `key: ! |` followed by lines indented by two blanks; `#` starts a comment
//! line. One document per reference case. Decks whose bonds break or form
//! also record the bound bonds (`init_bonds`, `run_bonds`: `type id id`).
//!
//! ```text
//! ---
//! generator: LAMMPS (22 Jul 2025 - Update 4) via cellmd export-lammps
//! deck: harmonic/small.in
//! epsilon: 1e-10
//! init_energy: 0.125
//! init_forces: ! |
//!   1 0.5 0.0 0.0
//!   2 -0.5 0.0 0.0
//! ```

use std::collections::BTreeMap;

use glam::DVec3;
use nom::branch::alt;
use nom::bytes::complete::{tag, take_till, take_while1};
use nom::character::complete::{line_ending, not_line_ending, space0};
use nom::combinator::{all_consuming, map, opt, value};
use nom::multi::many0;
use nom::sequence::{delimited, preceded, terminated};
use nom::{IResult, Parser};

use super::agreement::Tolerance;
use super::probe::{BondRecord, Probes, Snapshot};

/// One document: its entries in file order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Document {
    pub entries: Vec<(String, String)>,
}

impl Document {
    pub fn get(&self, key: &str) -> Option<&str> {
        self.entries.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }

    fn require(&self, key: &str) -> Result<&str, String> {
        self.get(key).ok_or_else(|| format!("golden document lacks `{key}`"))
    }

    fn number(&self, key: &str) -> Result<f64, String> {
        let v = self.require(key)?;
        v.trim().parse().map_err(|_| format!("`{key}`: `{v}` is not a number"))
    }

    pub fn push(&mut self, key: &str, value: impl Into<String>) {
        self.entries.push((key.to_string(), value.into()));
    }
}

fn comment_or_blank(i: &str) -> IResult<&str, ()> {
    value((), (space0, opt(preceded(tag("#"), not_line_ending)), line_ending)).parse(i)
}

fn block_line(i: &str) -> IResult<&str, &str> {
    terminated(preceded(tag("  "), not_line_ending), line_ending).parse(i)
}

fn entry(i: &str) -> IResult<&str, (String, String)> {
    let key = take_while1(|c: char| c.is_ascii_alphanumeric() || c == '_');
    let block =
        map(preceded((tag(" ! |"), line_ending), many0(block_line)), |lines| lines.iter().map(|l| format!("{l}\n")).collect::<String>());
    let scalar = map(delimited(tag(" "), take_till(|c| c == '\n' || c == '\r'), line_ending), |s: &str| s.trim().to_string());
    map((key, tag(":"), alt((block, scalar))), |(k, _, v)| (k.to_string(), v)).parse(i)
}

fn document(i: &str) -> IResult<&str, Document> {
    let (i, _) = (tag("---"), line_ending).parse(i)?;
    let (i, items) = many0(alt((map(entry, Some), map(comment_or_blank, |_| None)))).parse(i)?;
    Ok((i, Document { entries: items.into_iter().flatten().collect() }))
}

/// Parses a golden file into its documents.
pub fn parse(text: &str) -> Result<Vec<Document>, String> {
    let parsed = all_consuming((many0(comment_or_blank), many0(document))).parse(text);
    match parsed {
        Ok((_, (_, docs))) => Ok(docs),
        Err(e) => {
            let rest = match &e {
                nom::Err::Error(e) | nom::Err::Failure(e) => e.input,
                nom::Err::Incomplete(_) => "",
            };
            let line = text[..text.len() - rest.len()].lines().count() + 1;
            Err(format!("line {line}: not in the golden-file YAML subset: `{}`", rest.lines().next().unwrap_or("")))
        }
    }
}

/// Writes documents in the subset [`parse`] reads.
pub fn write(docs: &[Document]) -> String {
    let mut s = String::new();
    for d in docs {
        s += "---\n";
        for (k, v) in &d.entries {
            // Multi-line values, and empty ones (an empty bond list), as blocks.
            if v.contains('\n') || v.is_empty() {
                s += &format!("{k}: ! |\n");
                for line in v.lines() {
                    s += &format!("  {line}\n");
                }
            } else {
                s += &format!("{k}: {v}\n");
            }
        }
    }
    s
}

fn vectors_block(ids: &[u64], v: &[DVec3]) -> String {
    ids.iter().zip(v).map(|(id, x)| format!("{id} {:?} {:?} {:?}\n", x.x, x.y, x.z)).collect()
}

fn put_snapshot(d: &mut Document, prefix: &str, s: &Snapshot) {
    d.push(&format!("{prefix}_step"), s.step.to_string());
    d.push(&format!("{prefix}_energy"), format!("{:?}", s.total_energy()));
    d.push(&format!("{prefix}_energies"), s.energies.iter().map(|(k, e)| format!("{k} {e:?}\n")).collect::<String>());
    d.push(&format!("{prefix}_stress"), format!("{}\n", s.virial.iter().map(|w| format!("{w:?}")).collect::<Vec<_>>().join(" ")));
    d.push(&format!("{prefix}_forces"), vectors_block(&s.ids, &s.forces));
    d.push(&format!("{prefix}_positions"), vectors_block(&s.ids, &s.positions));
    if let Some(bonds) = &s.bonds {
        d.push(
            &format!("{prefix}_bonds"),
            bonds.iter().map(|b| format!("{} {} {}\n", b.bond_type, b.ids[0], b.ids[1])).collect::<String>(),
        );
    }
}

/// A golden document holding a reference run's probes. `header` comes first
/// (generator, date, deck, epsilon, …).
pub fn document_of(header: &[(&str, String)], probes: &Probes) -> Document {
    let mut d = Document::default();
    for (k, v) in header {
        d.push(k, v.clone());
    }
    put_snapshot(&mut d, "init", &probes.init);
    if let Some(last) = &probes.last {
        put_snapshot(&mut d, "run", last);
    }
    d
}

/// The tolerances a document declares (`epsilon`, `run_epsilon`).
pub fn tolerance_of(d: &Document) -> Result<Tolerance, String> {
    Ok(Tolerance { single_point: d.number("epsilon")?, run: d.number("run_epsilon")? })
}

fn read_vectors(block: &str, key: &str) -> Result<(Vec<u64>, Vec<DVec3>), String> {
    let mut ids = Vec::new();
    let mut v = Vec::new();
    for line in block.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        let bad = || format!("`{key}`: expected `id x y z`, found `{line}`");
        if w.len() != 4 {
            return Err(bad());
        }
        ids.push(w[0].parse().map_err(|_| bad())?);
        let x: Vec<f64> = w[1..].iter().map(|s| s.parse()).collect::<Result<_, _>>().map_err(|_| bad())?;
        v.push(DVec3::new(x[0], x[1], x[2]));
    }
    Ok((ids, v))
}

fn get_snapshot(d: &Document, prefix: &str) -> Result<Snapshot, String> {
    let key = |k: &str| format!("{prefix}_{k}");
    let mut energies = BTreeMap::new();
    for line in d.require(&key("energies"))?.lines() {
        let (k, e) = line.split_once(' ').ok_or_else(|| format!("`{}`: bad line `{line}`", key("energies")))?;
        energies.insert(k.to_string(), e.trim().parse().map_err(|_| format!("`{}`: bad number in `{line}`", key("energies")))?);
    }
    let w: Vec<f64> = d
        .require(&key("stress"))?
        .split_whitespace()
        .map(|s| s.parse())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("bad `{}`", key("stress")))?;
    let virial: [f64; 6] = w.try_into().map_err(|_| format!("`{}` needs 6 numbers", key("stress")))?;
    let (ids, forces) = read_vectors(d.require(&key("forces"))?, &key("forces"))?;
    let (position_ids, positions) = read_vectors(d.require(&key("positions"))?, &key("positions"))?;
    if position_ids != ids {
        return Err(format!("`{}` and `{}` list different ids", key("forces"), key("positions")));
    }
    let step = d.number(&key("step"))? as u64;
    let bonds = match d.get(&key("bonds")) {
        None => None,
        Some(block) => Some(
            block
                .lines()
                .map(|line| {
                    let bad = || format!("`{}`: expected `type id id`, found `{line}`", key("bonds"));
                    match line.split_whitespace().collect::<Vec<_>>()[..] {
                        [t, a, b] => Ok(BondRecord::new(t, a.parse().map_err(|_| bad())?, b.parse().map_err(|_| bad())?)),
                        _ => Err(bad()),
                    }
                })
                .collect::<Result<Vec<_>, _>>()?,
        ),
    };
    Ok(Snapshot { step, energies, virial, ids, positions, forces, bonds })
}

/// The probes stored in a golden document.
pub fn probes_of(d: &Document) -> Result<Probes, String> {
    let init = get_snapshot(d, "init")?;
    let last = if d.get("run_step").is_some() { Some(get_snapshot(d, "run")?) } else { None };
    Ok(Probes { init, last })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn documents_round_trip_through_the_subset() {
        let mut s = Snapshot { step: 3, ids: vec![1, 7], ..Default::default() };
        s.energies.insert("harmonic".into(), 0.125);
        s.energies.insert("cosine_angle+wlc_bending".into(), -1e-300);
        s.forces = vec![DVec3::new(0.1, -2.5e-17, 3.0), DVec3::new(1.0 / 3.0, 0.0, -0.0)];
        s.positions = vec![DVec3::new(1.0, 2.0, 3.0), DVec3::new(-4.0, 5.5, 1e10)];
        s.virial = [1.0, 2.0, 3.0, -0.1, 0.2, 0.3];
        let mut last = s.clone();
        s.bonds = Some(vec![BondRecord::new("link", 7, 1)]);
        last.bonds = Some(Vec::new());
        let probes = Probes { init: s, last: Some(last) };
        let doc = document_of(&[("generator", "test".into()), ("epsilon", "1e-10".into())], &probes);
        let text = format!("# a comment\n{}{}", write(std::slice::from_ref(&doc)), write(&[doc]));
        let docs = parse(&text).unwrap();
        assert_eq!(docs.len(), 2);
        assert_eq!(docs[0].get("generator"), Some("test"));
        assert_eq!(probes_of(&docs[1]).unwrap(), probes);
    }

    /// A regenerated document is compared with the committed one
    /// (`reference/regenerate --check`): a grouped energy `a+b` on both
    /// sides is the same row, not a + b looked up separately.
    #[test]
    fn a_document_with_grouped_energies_agrees_with_itself_and_not_with_a_change() {
        let mut s = Snapshot { step: 0, ids: vec![1], forces: vec![DVec3::X], positions: vec![DVec3::ZERO], ..Default::default() };
        s.energies.insert("cable+spring".into(), 2.5);
        s.energies.insert("harmonic".into(), 1.0);
        let probes = Probes { init: s.clone(), last: None };
        assert!(crate::compare::Agreement::new(&probes, &probes).unwrap().agrees(Default::default()));
        s.energies.insert("cable+spring".into(), 2.6);
        let changed = Probes { init: s, last: None };
        assert!(!crate::compare::Agreement::new(&changed, &probes).unwrap().agrees(Default::default()));
    }

    #[test]
    fn text_outside_the_subset_is_an_error_with_its_line() {
        let err = parse("---\nkey: 1\n  stray indented line\n").unwrap_err();
        assert!(err.starts_with("line 3:"), "{err}");
        assert!(parse("---\ninit_forces: ! |\n  1 2 3 4\nnext: x\n").unwrap()[0].get("next") == Some("x"));
    }
}
