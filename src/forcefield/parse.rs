//! Parser of force-field files, with `include`.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::input::{lex, parse_f64, InputError, SourceFile, Statement, Token};
use crate::interactions::{AngleLaw, ContactLaw, Kind, KindLaw, RadialLaw, SurfaceLaw, TetraLaw};
use crate::units::UnitSystem;

use super::params::{parse_kinetics, parse_params, BondTypeKinetics, TermType, Typed};
use super::parse_custom;

/// A particle type: overdamped drag coefficient and radius.
#[derive(Clone, Debug)]
pub struct ParticleType {
    pub name: Token,
    /// γ (drag units): force = γ·velocity; infinite for a `fixed` particle.
    pub drag: f64,
    /// Radius (length units), for Stokes drag, output and export; 0 if not given.
    pub radius: f64,
}

/// A pair rule between two particle types.
#[derive(Clone, Debug)]
pub struct PairRule {
    pub type_a: Token,
    pub type_b: Token,
    pub term: Typed<RadialLaw>,
}

/// A many-body term of every body of a type (`body TYPE INTERACTION ...`).
#[derive(Clone, Debug)]
pub struct BodyRule {
    /// The body type, as named in the topology's `[ bodies ]` section.
    pub body_type: Token,
    pub term: Typed<SurfaceLaw>,
}

/// A contact term between bodies of two types (`contact TYPE_A TYPE_B INTERACTION ...`).
#[derive(Clone, Debug)]
pub struct ContactRule {
    pub type_a: Token,
    pub type_b: Token,
    pub term: Typed<ContactLaw>,
}

/// Everything the force-field files of a deck define.
#[derive(Clone, Debug, Default)]
pub struct ForceField {
    pub particle_types: Vec<ParticleType>,
    pub bond_types: Vec<Typed<RadialLaw>>,
    /// Kinetic rules of each bond type (same order as `bond_types`).
    pub bond_kinetics: Vec<BondTypeKinetics>,
    pub angle_types: Vec<Typed<AngleLaw>>,
    /// Volume element types (`tetra` lines), for the topology's `[ tetrahedra ]`.
    pub tetra_types: Vec<Typed<TetraLaw>>,
    pub pair_rules: Vec<PairRule>,
    /// Surface terms by body type (`body` lines); several lines for one type add up.
    pub body_rules: Vec<BodyRule>,
    /// Contact terms between bodies by body-type pair (`contact` lines).
    pub contact_rules: Vec<ContactRule>,
    /// Bond formation rules (`bind` lines).
    pub bind_lines: Vec<super::BindLine>,
}

impl ForceField {
    pub fn particle_type(&self, name: &str) -> Option<usize> {
        self.particle_types.iter().position(|t| t.name.text == name)
    }

    /// The body types the force field names, in order of first appearance:
    /// those of `body` lines, then those only `contact` lines name.
    pub fn body_type_names(&self) -> Vec<&str> {
        let mut names: Vec<&str> = Vec::new();
        let named = self.body_rules.iter().map(|r| &r.body_type).chain(self.contact_rules.iter().flat_map(|r| [&r.type_a, &r.type_b]));
        for t in named {
            if !names.contains(&t.text.as_str()) {
                names.push(&t.text);
            }
        }
        names
    }
}

fn check_unique<'a>(name: &Token, existing: impl Iterator<Item = &'a Token>, what: &str) -> Result<(), InputError> {
    for other in existing {
        if other.text == name.text {
            return Err(name.error(format!(
                "{what} `{}` is already defined at {}:{}:{}; expected a new name",
                name.text, other.file.path, other.line, other.col
            )));
        }
    }
    Ok(())
}

/// The keys of a `particle` line (besides `fixed`).
const FIELDS: [&str; 7] = ["drag", "radius", "viscosity", "fibre", "points", "hydrodynamic_radius", "hydrodynamic_cutoff"];

/// The drag of each of the N points of a fibre of length L in a fluid of
/// viscosity η (`particle NAME viscosity η fibre L points N
/// [hydrodynamic_radius r] [hydrodynamic_cutoff c]`), as Cytosim computes it
/// (Nédélec & Foethke 2007), the cylinder's averaged translational friction
/// of Tirado & García de la Torre (1979) shared equally by the points, never
/// below the Stokes drag of a sphere of the fibre's radius (which a fibre
/// shorter than its diameter takes):
///
/// γ = πη·max(3L / (ln(min(L, c)/2r) + 0.312), 6r) / N,
///
/// r = 0.0125 µm and c = 10 µm by default (Cytosim's), in the file's length
/// units. `radius` stays the points' contact radius.
fn fibre_point_drag(eta: f64, at: &Token, fields: &HashMap<&str, (f64, &Token)>) -> Result<f64, InputError> {
    let length = fields["fibre"].0;
    let Some(&(points, points_key)) = fields.get("points") else {
        return Err(at.error("a fibre's drag is shared by its points; expected `points N` (the fibre's number of points)"));
    };
    if points.fract() != 0.0 || points < 2.0 {
        return Err(points_key.error(format!("found points {points}, expected a whole number ≥ 2")));
    }
    let radius = fields.get("hydrodynamic_radius").map_or(0.0125, |f| f.0);
    let cutoff = fields.get("hydrodynamic_cutoff").map_or(10.0, |f| f.0);
    let log = (length.min(cutoff) / (2.0 * radius)).ln() + 0.312;
    // A fibre shorter than its diameter (log ≤ 0) takes the sphere's drag, as in Cytosim.
    let cylinder = if log > 0.0 { 3.0 * length / log } else { 0.0 };
    Ok(std::f64::consts::PI * eta * cylinder.max(6.0 * radius) / points)
}

fn particle(s: &Statement) -> Result<ParticleType, InputError> {
    let t = &s.tokens;
    let Some(name) = t.get(1) else {
        return Err(t[0].error(
            "expected `particle NAME drag G [radius A]`, `particle NAME radius A viscosity ETA`, \
             `particle NAME viscosity ETA fibre L points N [hydrodynamic_radius R]` or `particle NAME fixed [radius A]`",
        ));
    };
    let fixed = t[2..].iter().find(|x| x.text == "fixed");
    let mut fields: HashMap<&str, (f64, &Token)> = HashMap::new();
    let values: Vec<&Token> = t[2..].iter().filter(|x| x.text != "fixed").collect();
    for pair in values.chunks(2) {
        let key = pair[0];
        if !FIELDS.contains(&key.text.as_str()) {
            return Err(key.error(format!(
                "found `{}`, expected one of {} or `fixed`",
                key.text,
                FIELDS.map(|f| format!("`{f}`")).join(", ")
            )));
        }
        let Some(value) = pair.get(1) else {
            return Err(key.error(format!("`{}` has no value; expected `{} VALUE`", key.text, key.text)));
        };
        let v = parse_f64(value, &format!("a value for `{}`", key.text))?;
        if v < 0.0 || (v == 0.0 && key.text != "radius") {
            return Err(value.error(format!("found {v}, expected `{}` > 0", key.text)));
        }
        if fields.insert(key.text.as_str(), (v, key)).is_some() {
            return Err(key.error(format!("`{}` is given twice; expected it once", key.text)));
        }
    }
    let radius = fields.get("radius").map_or(0.0, |f| f.0);
    let fibre_keys = ["fibre", "points", "hydrodynamic_radius", "hydrodynamic_cutoff"];
    if let Some((_, extra)) = fibre_keys.iter().find_map(|f| fields.get(f)) {
        if !fields.contains_key("fibre") || !fields.contains_key("viscosity") {
            return Err(
                extra.error(format!("`{}` belongs to a fibre's drag; expected `viscosity ETA fibre L points N` with it", extra.text))
            );
        }
    }
    let drag = match (fixed, fields.get("drag"), fields.get("viscosity")) {
        (Some(_), Some((_, key)), _) | (Some(_), _, Some((_, key))) => {
            return Err(key.error("a `fixed` particle does not move; expected no `drag` or `viscosity`"))
        }
        (Some(_), None, None) => f64::INFINITY,
        (None, Some(_), Some((_, key))) => return Err(key.error("give either `drag` or `radius` + `viscosity`, not both")),
        (None, Some((g, _)), None) => *g,
        (None, None, Some((eta, key))) if fields.contains_key("fibre") => fibre_point_drag(*eta, key, &fields)?,
        (None, None, Some((eta, key))) => {
            if radius <= 0.0 {
                return Err(key.error("`viscosity` needs `radius` > 0 for the Stokes drag 6πηa"));
            }
            6.0 * std::f64::consts::PI * eta * radius
        }
        (None, None, None) => {
            return Err(
                name.error(format!("particle type `{}` has no drag; expected `drag G`, `radius A viscosity ETA` or `fixed`", name.text))
            )
        }
    };
    Ok(ParticleType { name: name.clone(), drag, radius })
}

/// A term of a registered law, or a `custom` expression, with its law of family `L`.
fn term_type<L: KindLaw>(label: &Token, law: &Token, tokens: &[Token], kind: Kind, units: UnitSystem) -> Result<Typed<L>, InputError> {
    let term =
        if law.text == "custom" { parse_custom(label, law, tokens, kind, units) } else { parse_params(label, law, tokens, kind, units) };
    typed(term?, law)
}

/// `term` with its law taken out, or an error at `at` if the law is not of family `L`.
pub fn typed<L: KindLaw>(term: TermType, at: &Token) -> Result<Typed<L>, InputError> {
    Typed::new(term).map_err(|t| {
        at.error(format!(
            "`{}` has no {} law; expected {} interaction",
            t.interaction.name(),
            t.interaction.kind().keyword(),
            t.interaction.kind().with_article()
        ))
    })
}

/// Reads a force-field file (and its includes) into `ff`.
///
/// `requested_by` is the deck token naming the file (for a missing-file error);
/// `stack` guards against include cycles.
pub fn load_forcefield(
    path: &Path,
    requested_by: Option<&Token>,
    units: UnitSystem,
    ff: &mut ForceField,
    stack: &mut Vec<PathBuf>,
) -> Result<(), InputError> {
    let file = SourceFile::read(path, requested_by)?;
    let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
    if stack.contains(&canonical) {
        let message = format!("include cycle: `{}` includes itself; expected an acyclic include graph", path.display());
        return Err(match requested_by {
            Some(t) => t.error(message),
            None => InputError::in_file(&file.path, message),
        });
    }
    stack.push(canonical);
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    for s in lex(&file)? {
        let t = &s.tokens;
        let kw = &t[0];
        match kw.text.as_str() {
            "include" => {
                if t.len() != 2 {
                    return Err(kw.error("expected `include FILE`"));
                }
                load_forcefield(&dir.join(&t[1].text), Some(&t[1]), units, ff, stack)?;
            }
            "particle" => {
                let p = particle(&s)?;
                check_unique(&p.name, ff.particle_types.iter().map(|x| &x.name), "particle type")?;
                ff.particle_types.push(p);
            }
            "bond" => {
                if t.len() < 3 {
                    return Err(kw.error("expected `bond NAME INTERACTION [param value]... [kinetics RULE [param value]...]...`"));
                }
                check_unique(&t[1], ff.bond_types.iter().map(|x| &x.label), "bond type")?;
                // Kinetic rules follow the interaction and its parameters (a
                // bond named or typed `kinetics` is not one).
                let law_end = t[3..].iter().position(|x| x.text == "kinetics").map_or(t.len(), |k| k + 3);
                let law = term_type(&t[1], &t[2], &t[3..law_end], Kind::Bond, units)?;
                ff.bond_kinetics.push(parse_kinetics(&law, &t[law_end..], units)?);
                ff.bond_types.push(law);
            }
            "angle" => {
                if t.len() < 3 {
                    return Err(kw.error("expected `angle NAME INTERACTION [param value]...`"));
                }
                check_unique(&t[1], ff.angle_types.iter().map(|x| &x.label), "angle type")?;
                ff.angle_types.push(term_type(&t[1], &t[2], &t[3..], Kind::Angle, units)?);
            }
            "tetra" => {
                if t.len() < 3 {
                    return Err(kw.error("expected `tetra NAME INTERACTION [param value]...`"));
                }
                check_unique(&t[1], ff.tetra_types.iter().map(|x| &x.label), "tetra type")?;
                ff.tetra_types.push(term_type(&t[1], &t[2], &t[3..], Kind::Tetra, units)?);
            }
            "pair" => {
                if t.len() < 4 {
                    return Err(kw.error("expected `pair TYPE_A TYPE_B INTERACTION [param value]...`"));
                }
                let term = term_type(&t[1], &t[3], &t[4..], Kind::Pair, units)?;
                ff.pair_rules.push(PairRule { type_a: t[1].clone(), type_b: t[2].clone(), term });
            }
            "body" => {
                if t.len() < 3 {
                    return Err(kw.error("expected `body TYPE INTERACTION [param value]...`"));
                }
                let term = term_type(&t[1], &t[2], &t[3..], Kind::Body, units)?;
                ff.body_rules.push(BodyRule { body_type: t[1].clone(), term });
            }
            "contact" => {
                if t.len() < 4 {
                    return Err(kw.error("expected `contact BODYTYPE_A BODYTYPE_B INTERACTION [param value]...`"));
                }
                let term = term_type(&t[1], &t[3], &t[4..], Kind::Contact, units)?;
                ff.contact_rules.push(ContactRule { type_a: t[1].clone(), type_b: t[2].clone(), term });
            }
            "bind" => ff.bind_lines.push(super::parse_bind(kw, &t[1..], units)?),
            other => {
                return Err(kw.error(format!(
                    "found `{other}`, expected `include`, `particle`, `bond`, `angle`, `tetra`, `pair`, `body`, `contact` or `bind`"
                )))
            }
        }
    }
    stack.pop();
    Ok(())
}

/// Checks that pair rules name defined particle types (after all files are read).
pub fn check_pair_types(ff: &ForceField) -> Result<(), InputError> {
    let pairs = ff.pair_rules.iter().map(|r| [&r.type_a, &r.type_b]).chain(ff.bind_lines.iter().map(|b| [&b.type_a, &b.type_b]));
    for types in pairs {
        for t in types {
            if ff.particle_type(&t.text).is_none() {
                let names: Vec<&str> = ff.particle_types.iter().map(|p| p.name.text.as_str()).collect();
                return Err(t.error(format!("found particle type `{}`, expected a defined particle type: {}", t.text, names.join(", "))));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(files: &[(&str, &str)]) -> Result<ForceField, String> {
        let dir = tempfile::tempdir().unwrap();
        for (name, text) in files {
            std::fs::write(dir.path().join(name), text).unwrap();
        }
        let mut ff = ForceField::default();
        load_forcefield(&dir.path().join(files[0].0), None, UnitSystem::Cell, &mut ff, &mut Vec::new())
            .and_then(|_| check_pair_types(&ff))
            .map(|_| ff)
            .map_err(|e| e.to_string().replace(&format!("{}/", dir.path().display()), ""))
    }

    /// Cytosim's drag of a 5 µm fibre of 51 points in a 1 Pa·s fluid:
    /// 3π·5/(ln(5/0.025) + 0.312) = 47.1239/5.61033 = 8.39951 pN·s/µm in all, shared by the points.
    #[test]
    fn a_fibre_points_drag_is_cytosims_fibre_drag_shared_by_its_points() {
        let ff = load(&[(
            "main.ff",
            "particle a viscosity 1 fibre 5 points 51
particle b viscosity 1 fibre 0.01 points 2 hydrodynamic_radius 0.0125
",
        )])
        .unwrap();
        let total = 3.0 * std::f64::consts::PI * 5.0 / ((5.0f64 / 0.025).ln() + 0.312);
        assert!((total - 8.39951).abs() < 1e-5, "{total}");
        assert!((ff.particle_types[0].drag - total / 51.0).abs() < 1e-15);
        // Shorter than its diameter: the sphere's 6πηr.
        assert!((ff.particle_types[1].drag - 6.0 * std::f64::consts::PI * 0.0125 / 2.0).abs() < 1e-15);
        for (text, message) in [
            (
                "particle a drag 1 fibre 5 points 51",
                "m.ff:1:19: `fibre` belongs to a fibre's drag; expected `viscosity ETA fibre L points N` with it",
            ),
            (
                "particle a viscosity 1 fibre 5",
                "m.ff:1:12: a fibre's drag is shared by its points; expected `points N` (the fibre's number of points)",
            ),
            ("particle a viscosity 1 fibre 5 points 2.5", "m.ff:1:32: found points 2.5, expected a whole number ≥ 2"),
        ] {
            assert_eq!(load(&[("m.ff", text)]).unwrap_err(), message);
        }
    }

    #[test]
    fn reads_types_with_includes_and_stokes_drag() {
        let ff = load(&[
            ("main.ff", "include types.ff\nbond s harmonic k 1 r0 2\n"),
            ("types.ff", "particle a drag 2\nparticle b radius 0.5 viscosity 1\n"),
        ])
        .unwrap();
        assert_eq!(ff.particle_types[0].drag, 2.0);
        assert!((ff.particle_types[1].drag - 3.0 * std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(ff.bond_types[0].params, vec![1.0, 2.0]);
    }

    #[test]
    fn body_lines_name_a_body_type_and_a_surface_interaction() {
        let ff = load(&[("m.ff", "particle a drag 1\nbody cell turgor k 100 v0 4\nbody cell surface_tension gamma 2\n")]).unwrap();
        assert_eq!(ff.body_rules.len(), 2);
        assert_eq!(ff.body_rules[0].body_type.text, "cell");
        assert_eq!(ff.body_rules[0].term.params, vec![100.0, 0.0, 4.0]);
        assert_eq!(
            load(&[("m.ff", "body cell harmonic k 1 r0 1\n")]).unwrap_err(),
            "m.ff:1:11: `harmonic` is a bond interaction, expected a body interaction here"
        );
        assert!(load(&[("m.ff", "bond s turgor k 1 v0 1\n")])
            .unwrap_err()
            .contains("`turgor` is a body interaction, expected a bond interaction"));
        assert!(load(&[("m.ff", "body cell\n")]).unwrap_err().contains("expected `body TYPE INTERACTION"));
    }

    #[test]
    fn contact_lines_name_two_body_types_and_a_contact_interaction() {
        let ff = load(&[("m.ff", "body cell turgor k 1 v0 1\ncontact cell nucleus contact_barrier dhat 0.1 kappa 10\n")]).unwrap();
        assert_eq!((ff.contact_rules[0].type_a.text.as_str(), ff.contact_rules[0].type_b.text.as_str()), ("cell", "nucleus"));
        assert_eq!(ff.contact_rules[0].term.params, vec![0.1, 10.0]);
        assert_eq!(ff.body_type_names(), ["cell", "nucleus"]);
        assert_eq!(
            load(&[("m.ff", "contact cell cell turgor k 1 v0 1\n")]).unwrap_err(),
            "m.ff:1:19: `turgor` is a body interaction, expected a contact interaction here"
        );
        assert!(load(&[("m.ff", "body cell contact_barrier dhat 1 kappa 1\n")])
            .unwrap_err()
            .contains("is a contact interaction, expected a body"));
        assert!(load(&[("m.ff", "contact cell cell\n")]).unwrap_err().contains("expected `contact BODYTYPE_A BODYTYPE_B INTERACTION"));
        assert!(load(&[("m.ff", "contact a b contact_barrier dhat 0 kappa 1\n")]).unwrap_err().contains("`dhat` > 0"));
    }

    #[test]
    fn errors() {
        assert_eq!(
            load(&[("m.ff", "particle a\n")]).unwrap_err(),
            "m.ff:1:10: particle type `a` has no drag; expected `drag G`, `radius A viscosity ETA` or `fixed`"
        );
        assert!(load(&[("m.ff", "particle a drag 1\nparticle a drag 2\n")]).unwrap_err().contains("already defined at"));
        assert!(load(&[("m.ff", "include m.ff\n")]).unwrap_err().contains("include cycle"));
        assert!(load(&[("m.ff", "include missing.ff\n")]).unwrap_err().starts_with("m.ff:1:9: cannot read"));
        assert!(load(&[("m.ff", "angle x harmonic k 1 r0 1\n")])
            .unwrap_err()
            .contains("is a bond interaction, expected an angle interaction"));
        assert!(load(&[("m.ff", "bnd x harmonic\n")]).unwrap_err().contains("expected `include`, `particle`"));
        assert!(load(&[("m.ff", "particle a drag 1\nbind a b s k_on 1 capture 1\n")]).unwrap_err().contains("found particle type `b`"));
    }
}
