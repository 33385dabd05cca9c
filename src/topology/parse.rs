//! Parser of topology files (second phase after the shared lexer).

use std::collections::HashMap;
use std::sync::Arc;

use glam::DVec3;

use super::types::{BoxAxis, Topology, TypedTerm};
use crate::input::{parse_f64, parse_u64, statements, InputError, SourceFile, Statement, Token};

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Section {
    Box,
    Particles,
    Bonds,
    Angles,
    Bodies,
    Triangles,
    Tetrahedra,
}

const SECTIONS: &str = "[ box ], [ particles ], [ bonds ], [ angles ], [ bodies ], [ triangles ] or [ tetrahedra ]";

fn section_of(statement: &Statement) -> Option<Result<Section, InputError>> {
    let first = statement.keyword();
    if !first.text.starts_with('[') {
        return None;
    }
    let joined: String = statement.tokens.iter().map(|t| t.text.as_str()).collect();
    let section = match joined.as_str() {
        "[box]" => Section::Box,
        "[particles]" => Section::Particles,
        "[bonds]" => Section::Bonds,
        "[angles]" => Section::Angles,
        "[bodies]" => Section::Bodies,
        "[triangles]" => Section::Triangles,
        "[tetrahedra]" => Section::Tetrahedra,
        _ => return Some(Err(first.error(format!("found section `{}`, expected {SECTIONS}", joined)))),
    };
    Some(Ok(section))
}

/// Checks the number of fields of a record; a surplus is reported at the
/// first field too many, a shortfall at the last field.
fn expect_fields(statement: &Statement, allowed: &[usize], layout: &str) -> Result<(), InputError> {
    let n = statement.tokens.len();
    if allowed.contains(&n) {
        return Ok(());
    }
    let most = allowed.iter().copied().max().unwrap_or(0);
    let at = statement.tokens.get(most).unwrap_or(statement.tokens.last().unwrap());
    Err(at.error(format!("found {n} fields, expected `{layout}`")))
}

struct Parser {
    topology: Topology,
    /// Index and byte offset (for errors) of each particle id: no token per
    /// particle is kept, so a large topology parses in little memory.
    index_of_id: HashMap<u64, (u32, usize)>,
    body_ids: HashMap<u64, Token>,
    /// The id token of each body (for errors).
    body_tokens: Vec<Token>,
    /// First line of each bonded term by (type, particles in canonical
    /// order): a term listed twice is counted twice. Type names are interned.
    term_lines: HashMap<(u32, [u32; 4]), u32>,
    term_types: HashMap<String, u32>,
}

impl Parser {
    fn particle_index(&self, token: &Token) -> Result<u32, InputError> {
        let id = parse_u64(token, "a particle id")?;
        self.index_of_id
            .get(&id)
            .map(|(index, _)| *index)
            .ok_or_else(|| token.error(format!("found particle id {id}, expected the id of a particle listed in [ particles ] before it")))
    }

    fn axis(&mut self, s: &Statement, seen: &mut [bool; 3]) -> Result<(), InputError> {
        expect_fields(s, &[4], "axis lo hi p|f")?;
        let axes = self.topology.box_axes.get_or_insert_with(|| std::array::from_fn(|_| BoxAxis { lo: 0.0, hi: 0.0, periodic: false }));
        let index = parse_box_axis(&s.tokens, &mut axes[..])?;
        if seen[index] {
            return Err(s.tokens[0].error(format!("axis `{}` given twice; expected each of x, y, z once", s.tokens[0].text)));
        }
        seen[index] = true;
        Ok(())
    }

    fn particle(&mut self, s: &Statement) -> Result<(), InputError> {
        expect_fields(s, &[5, 6], "id type x y z [body]")?;
        let t = &s.tokens;
        let id = parse_u64(&t[0], "a particle id")?;
        if id == 0 {
            return Err(t[0].error("found particle id 0, expected a positive integer"));
        }
        if let Some(&(_, first)) = self.index_of_id.get(&id) {
            let line = t[0].file.line_col(first).0;
            return Err(t[0].error(format!("particle id {id} is already used at line {line}; expected unique ids")));
        }
        let x = parse_f64(&t[2], "the x coordinate")?;
        let y = parse_f64(&t[3], "the y coordinate")?;
        let z = parse_f64(&t[4], "the z coordinate")?;
        let body = t.get(5).map(|b| parse_u64(b, "a body id")).transpose()?;
        let index = self.topology.ids.len() as u32;
        self.index_of_id.insert(id, (index, t[0].offset));
        self.topology.ids.push(id);
        self.topology.type_names.push(t[1].clone());
        self.topology.positions.push(DVec3::new(x, y, z));
        self.topology.body_of.push(body);
        Ok(())
    }

    /// A bonded term of `N` particles; `extra` more fields are allowed after
    /// them (read by the caller).
    fn term<const N: usize>(&mut self, s: &Statement, extra: usize, layout: &str) -> Result<TypedTerm<N>, InputError> {
        let allowed: Vec<usize> = (N + 1..=N + 1 + extra).collect();
        expect_fields(s, &allowed, layout)?;
        let mut particles = [0u32; N];
        for (k, slot) in particles.iter_mut().enumerate() {
            *slot = self.particle_index(&s.tokens[k + 1])?;
        }
        for a in 0..N {
            for b in a + 1..N {
                if particles[a] == particles[b] {
                    return Err(s.tokens[b + 1].error(format!(
                        "particle id {} appears twice in this term; expected {N} distinct particles",
                        s.tokens[b + 1].text
                    )));
                }
            }
        }
        match self.earlier_line(s, particles) {
            Some(first) if N > 2 => {
                let ids: Vec<&str> = s.tokens[1..=N].iter().map(|t| t.text.as_str()).collect();
                let what = if N == 3 { "angle" } else { "tetrahedron" };
                return Err(s.tokens[0].error(format!(
                    "{what} `{}` {} is already listed at line {first}; expected each {what} once",
                    s.tokens[0].text,
                    ids.join("–")
                )));
            }
            Some(first) => self.topology.parallel_bonds.push((self.topology.bonds.len(), first)),
            None => {}
        }
        Ok(TypedTerm { type_name: s.tokens[0].clone(), particles })
    }

    /// The line of an earlier term of the same type on the same particles
    /// (a bond `i j` is `j i`, an angle `i j k` is `k j i`, a tetrahedron
    /// is any order of its corners).
    fn earlier_line<const N: usize>(&mut self, s: &Statement, particles: [u32; N]) -> Option<u32> {
        let mut key = [u32::MAX; 4];
        key[..N].copy_from_slice(&particles);
        if N == 4 {
            key.sort_unstable();
        } else if key[0] > key[N - 1] {
            key[..N].reverse();
        }
        let types = self.term_types.len() as u32;
        let ty = *self.term_types.entry(s.tokens[0].text.clone()).or_insert(types);
        let line = s.tokens[0].line;
        let first = *self.term_lines.entry((ty, key)).or_insert(line);
        (first != line).then_some(first)
    }

    fn body(&mut self, s: &Statement) -> Result<(), InputError> {
        expect_fields(s, &[2], "id type")?;
        let id = parse_u64(&s.tokens[0], "a body id")?;
        if let Some(first) = self.body_ids.get(&id) {
            return Err(s.tokens[0].error(format!("body id {id} is already used at line {}; expected unique ids", first.line)));
        }
        self.body_ids.insert(id, s.tokens[0].clone());
        self.body_tokens.push(s.tokens[0].clone());
        self.topology.bodies.push((id, s.tokens[1].clone()));
        Ok(())
    }

    fn triangle(&mut self, s: &Statement) -> Result<(), InputError> {
        expect_fields(s, &[4], "body i j k")?;
        let body = parse_u64(&s.tokens[0], "a body id")?;
        if !self.body_ids.contains_key(&body) {
            return Err(s.tokens[0].error(format!("found body id {body}, expected a body listed in [ bodies ] before it")));
        }
        let mut particles = [0u32; 3];
        for (k, slot) in particles.iter_mut().enumerate() {
            *slot = self.particle_index(&s.tokens[k + 1])?;
        }
        if particles[0] == particles[1] || particles[1] == particles[2] || particles[0] == particles[2] {
            return Err(s.tokens[1].error("a triangle repeats a particle; expected three distinct particles"));
        }
        self.topology.triangles.push((body, particles));
        self.topology.face_tokens.push(s.tokens[0].clone());
        Ok(())
    }
}

/// A bond's own rest length: a positive finite length.
fn parse_rest_length(token: &Token) -> Result<f64, InputError> {
    let r0 = parse_f64(token, "the bond's own rest length r0")?;
    if r0 > 0.0 {
        Ok(r0)
    } else {
        Err(token.error(format!("found rest length r0 = {r0}, expected a positive length (r0 > 0)")))
    }
}

/// Parses `x|y|z lo hi p|f` into `axes` and returns the axis index.
pub fn parse_box_axis(t: &[Token], axes: &mut [BoxAxis]) -> Result<usize, InputError> {
    let index = match t[0].text.as_str() {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        other => return Err(t[0].error(format!("found `{other}`, expected an axis name x, y or z"))),
    };
    let lo = parse_f64(&t[1], "the lower bound")?;
    let hi = parse_f64(&t[2], "the upper bound")?;
    if hi <= lo {
        return Err(t[2].error(format!("upper bound {hi} is not above lower bound {lo}; expected hi > lo")));
    }
    let edge = hi - lo;
    if !edge.is_finite() || !(1.0 / edge).is_finite() {
        return Err(t[2].error(format!("found box edge hi − lo = {edge:e}, expected a finite length whose inverse is finite")));
    }
    let periodic = match t[3].text.as_str() {
        "p" => true,
        "f" => false,
        other => return Err(t[3].error(format!("found `{other}`, expected `p` (periodic) or `f` (fixed)"))),
    };
    axes[index] = BoxAxis { lo, hi, periodic };
    Ok(index)
}

/// Reads and parses a topology file, one statement at a time.
pub fn parse_topology(file: &Arc<SourceFile>) -> Result<Topology, InputError> {
    let mut parser = Parser {
        topology: Topology { path: file.path.clone(), ..Default::default() },
        index_of_id: HashMap::new(),
        body_ids: HashMap::new(),
        body_tokens: Vec::new(),
        term_lines: HashMap::new(),
        term_types: HashMap::new(),
    };
    let mut section: Option<Section> = None;
    let mut seen_sections: Vec<Section> = Vec::new();
    let mut seen_axes = [false; 3];
    for s in statements(file) {
        let s = &s?;
        if let Some(next) = section_of(s) {
            let next = next?;
            if seen_sections.contains(&next) {
                return Err(s.keyword().error("this section appears twice; expected each section at most once"));
            }
            seen_sections.push(next);
            section = Some(next);
            continue;
        }
        match section {
            None => {
                return Err(s
                    .keyword()
                    .error(format!("found `{}` before any section, expected a section header {SECTIONS}", s.keyword().text)))
            }
            Some(Section::Box) => parser.axis(s, &mut seen_axes)?,
            Some(Section::Particles) => parser.particle(s)?,
            Some(Section::Bonds) => {
                let bond = parser.term::<2>(s, 1, "type i j [r0]")?;
                parser.topology.bonds.push(bond);
                let rest = s.tokens.get(3).map(|t| Ok::<_, InputError>((parse_rest_length(t)?, t.clone()))).transpose()?;
                parser.topology.bond_rest.push(rest);
            }
            Some(Section::Angles) => {
                let angle = parser.term::<3>(s, 0, "type i j k")?;
                parser.topology.angles.push(angle);
            }
            Some(Section::Bodies) => parser.body(s)?,
            Some(Section::Triangles) => parser.triangle(s)?,
            Some(Section::Tetrahedra) => {
                let element = parser.term::<4>(s, 0, "type i j k l")?;
                parser.topology.tetrahedra.push(element);
            }
        }
    }
    if parser.topology.box_axes.is_some() && seen_axes != [true; 3] {
        return Err(InputError::in_file(&file.path, "the [ box ] section must give all three axes x, y and z"));
    }
    // Bodies referenced by particles must exist.
    for (index, body) in parser.topology.body_of.iter().enumerate() {
        if let Some(body) = body {
            if !parser.body_ids.contains_key(body) && !parser.topology.bodies.is_empty() {
                let id = parser.topology.ids[index];
                let (_, offset) = parser.index_of_id[&id];
                return Err(InputError::at_offset(
                    file,
                    offset,
                    format!("particle {id} names body {body}, expected a body listed in [ bodies ]"),
                ));
            }
        }
    }
    super::surface::check_bodies(&parser.topology, &parser.topology.face_tokens, &parser.body_tokens)?;
    Ok(parser.topology)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Topology, String> {
        parse_topology(&SourceFile::new("t.top", text)).map_err(|e| e.to_string())
    }

    #[test]
    fn reads_all_sections() {
        let top = parse(
            "[ box ]\nx 0 10 p\ny 0 10 p\nz 0 5 f\n[ particles ]\n10 a 0 0 0\n20 a 1 0 0 1\n30 b 1 1 0\n40 b 0 0 1\n[ bonds ]\ns 10 20\n[ angles ]\nbend 10 20 30\n[ bodies ]\n1 cell\n[ triangles ]\n1 10 30 20\n1 10 20 40\n1 20 30 40\n1 30 10 40\n",
        )
        .unwrap();
        assert_eq!(top.ids, vec![10, 20, 30, 40]);
        assert_eq!(top.bonds[0].particles, [0, 1]);
        assert_eq!(top.angles[0].particles, [0, 1, 2]);
        assert_eq!(top.triangles[0], (1, [0, 2, 1]));
        assert_eq!(top.body_of[1], Some(1));
        let axes = top.box_axes.unwrap();
        assert!(axes[0].periodic && !axes[2].periodic && axes[2].hi == 5.0);
    }

    #[test]
    fn errors_are_located_and_say_what_was_expected() {
        assert_eq!(parse("[ particles ]\n1 a 0 0\n").unwrap_err(), "t.top:2:7: found 4 fields, expected `id type x y z [body]`");
        assert_eq!(
            parse("[ particles ]\n1 a 0 0 0\n[ bonds ]\ns 1 2\n").unwrap_err(),
            "t.top:4:5: found particle id 2, expected the id of a particle listed in [ particles ] before it"
        );
        assert_eq!(parse("1 a 0 0 0\n").unwrap_err(), "t.top:1:1: found `1` before any section, expected a section header [ box ], [ particles ], [ bonds ], [ angles ], [ bodies ], [ triangles ] or [ tetrahedra ]");
        assert!(parse("[ atoms ]\n").unwrap_err().starts_with("t.top:1:1: found section `[atoms]`"));
        assert!(parse("[ particles ]\n1 a 0 0 0\n1 a 1 0 0\n").unwrap_err().contains("already used at line 2"));
        assert!(parse("[ particles ]\n1 a 0 zero 0\n").unwrap_err().starts_with("t.top:2:7: found `zero`, expected the y coordinate"));
    }

    #[test]
    fn a_bond_may_end_with_its_own_rest_length() {
        let two = "[ particles ]\n1 a 0 0 0\n2 a 1 0 0\n3 a 2 0 0\n[ bonds ]\n";
        let top = parse(&format!("{two}s 1 2 0.75\ns 2 3\n")).unwrap();
        assert_eq!(top.bond_rest.len(), 2);
        assert_eq!(top.bond_rest[0].as_ref().map(|(r0, t)| (*r0, t.col)), Some((0.75, 7)));
        assert!(top.bond_rest[1].is_none());
        for (line, expected) in [
            ("s 1 2 -0.5", "t.top:6:7: found rest length r0 = -0.5, expected a positive length (r0 > 0)"),
            ("s 1 2 0", "t.top:6:7: found rest length r0 = 0, expected a positive length (r0 > 0)"),
            ("s 1 2 long", "t.top:6:7: found `long`, expected the bond's own rest length r0 (a number)"),
            ("s 1 2 inf", "t.top:6:7: found `inf`, expected the bond's own rest length r0 (a finite number)"),
            ("s 1 2 1.0 3", "t.top:6:11: found 5 fields, expected `type i j [r0]`"),
            ("s 1", "t.top:6:3: found 2 fields, expected `type i j [r0]`"),
        ] {
            assert_eq!(parse(&format!("{two}{line}\n")).unwrap_err(), expected, "{line}");
        }
        // A term listed twice, in either direction, is counted twice: an
        // error for an angle; for a bond, only without kinetic rules (checked
        // with the force field, so only recorded here).
        let parallel = |bonds: &str| parse_topology(&SourceFile::new("t.top", format!("{two}{bonds}"))).unwrap().parallel_bonds;
        assert_eq!(parallel("s 1 2\ns 2 1\ns 1 2\n"), [(1, 6), (2, 6)]);
        assert!(parallel("s 1 2\nt 2 1\n").is_empty(), "two bond types on one pair");
        assert_eq!(
            parse(&format!("{two}[ angles ]\nb 1 2 3\nb 3 2 1\n")).unwrap_err(),
            "t.top:8:1: angle `b` 3–2–1 is already listed at line 7; expected each angle once"
        );
        assert!(parse(&format!("{two}[ angles ]\nb 1 2 3\nb 2 1 3\n")).is_ok(), "another vertex");
        // Angles take no extra field.
        assert_eq!(parse(&format!("{two}[ angles ]\nb 1 2 3 1.0\n")).unwrap_err(), "t.top:7:9: found 5 fields, expected `type i j k`");
    }
}
