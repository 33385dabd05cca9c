//! A validated deck as a LAMMPS data file and input script.
//!
//! Units: a `units lj` deck becomes LAMMPS `units lj` verbatim. A `cell` deck
//! (µm, s, pN) is also written as LAMMPS `units lj`, where every conversion
//! factor is 1: σ = 1 µm, τ = 1 s, ε = 1 pN·µm, and the LAMMPS temperature is
//! kT in pN·µm. Overdamped dynamics is `fix brownian` per particle type with
//! `gamma_t` = the type's drag (LAMMPS moves x by dt·F/γ_t, with no mass
//! dependence). A deterministic deck (temperature 0) gets `rng none` with
//! T = 1: LAMMPS refuses T = 0, and `rng none` drops the noise whatever T is.
//!
//! Styles are always `hybrid` (`hybrid/overlay` for pairs) so that LAMMPS'
//! `compute bond|angle|pair` report the energy of each style. With probes on,
//! the script writes `cellmd_probe.txt` (step, energy by interaction, virial
//! W = P·V) and `cellmd_probe_init.dump` / `cellmd_probe_final.dump` (id,
//! unwrapped positions and forces, 17 digits) before the first and after the
//! last run; `cellmd compare` (module `compare`) reads them back. Decks with kinetics also
//! get `cellmd_probe_init.bonds` / `cellmd_probe_final.bonds` (the bound
//! bonds: type, atom, atom).
//!
//! Bonds with their own rest length (the topology's `type i j r0`) become
//! LAMMPS bond types of their own, one per distinct (type, r0)
//! ([`LammpsBondTypes`]); LAMMPS type t + 1 remains cellmd type t.
//!
//! Bond kinetics: LAMMPS has no force-dependent bond kinetics, but two
//! cellmd rules have an exact counterpart, and only these are exported:
//! - a `threshold` with a `strain` S only (no `force`, `spread` or `rate`) on
//!   a law with `r0` becomes `fix bond/break 1 TYPE r0·(1 + S)`;
//! - `bind A B TYPE … partner nearest` whose binding is certain in one step
//!   (1 − exp(−k_on·dt) = 1 in f64, k_on·dt ≳ 37) becomes `fix bond/create 1
//!   A B capture TYPE iparam N A jparam N B` (N = `max_bonds`), with a `zero`
//!   pair style reaching the capture radius so that LAMMPS sees the pairs.
//!
//! The final bond sets agree when the bonded particles do not move (`fixed`
//! types, as in `reference/threshold` and `reference/bind`); what differs
//! per step is documented with the reference cases: LAMMPS breaks at most one
//! bond per atom per step (the longest, if it is its partner's longest too)
//! and only stretched ones, while cellmd breaks every bond beyond its
//! threshold at once, compressed ones included; LAMMPS tests lengths after the
//! step's move, cellmd those of the step's force pass. Formation is the same
//! rule in both (each particle's nearest eligible partner, bonded when that
//! choice is mutual, one new bond per particle and rule per step), except
//! that LAMMPS never bonds a pair already bonded by another bond type.

use super::bond_types::LammpsBondTypes;
use super::data_file::{bonded_extent, data_file};
use super::formula;
use super::hybrid::{Hybrid, Pairs};
use super::kinetic_fixes::{bond_break_length, extra_per_atom, kinetic_fixes, KineticFixes};
use super::styles::{self, ExternalStyle};
use crate::deck::{Action, CoeffTarget, Plan};
use crate::expr::{Expr, UnaryOp};
use crate::forcefield::{TermType, Typed};
use crate::integrate::Integrator;
use crate::interactions::lammps::num;
use crate::rng::Noise;
use crate::system::{External, Model};
use crate::units::UnitSystem;

/// The two files of an exported deck.
#[derive(Clone, Debug)]
pub struct LammpsDeck {
    /// `data.lammps`: box, types, atoms, bonds, angles.
    pub data: String,
    /// `in.lammps`: reads `data.lammps` from its own directory.
    pub input: String,
}

/// Export options.
#[derive(Clone, Copy, Debug, Default)]
pub struct ExportOptions {
    /// Write the probe files that `cellmd compare` reads.
    pub probes: bool,
}

/// Name of the data file the input script reads.
pub const DATA_FILE: &str = "data.lammps";
/// Name of the input script.
pub const INPUT_FILE: &str = "in.lammps";
/// Name of the probe text file.
pub const PROBE_FILE: &str = "cellmd_probe.txt";

/// A LAMMPS identifier from a user name (letters, digits, underscores).
fn ident(prefix: &str, name: &str) -> String {
    let clean: String = name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }).collect();
    format!("{prefix}{clean}")
}

/// Ids as LAMMPS `group ... id` arguments, consecutive runs as `a:b`.
fn id_ranges(ids: &mut [u64]) -> String {
    ids.sort_unstable();
    let mut out = Vec::new();
    let mut k = 0;
    while k < ids.len() {
        let start = ids[k];
        while k + 1 < ids.len() && ids[k + 1] == ids[k] + 1 {
            k += 1;
        }
        out.push(if ids[k] == start { start.to_string() } else { format!("{start}:{}", ids[k]) });
        k += 1;
    }
    out.join(" ")
}

/// State of the script being written.
struct Writer<'a> {
    plan: &'a Plan,
    model: Model,
    options: ExportOptions,
    out: String,
    bonds: Hybrid,
    /// LAMMPS bond types: one per (cellmd type, r0).
    bond_types: LammpsBondTypes,
    angles: Hybrid,
    pairs: Pairs,
    /// Active externals: LAMMPS fix id and cellmd interaction name.
    fixes: Vec<(String, &'static str)>,
    /// `fix bond/break` and `fix bond/create` standing for the kinetics.
    kinetic: KineticFixes,
    kt: f64,
    seed: u64,
    noise: Noise,
    dt_set: bool,
}

impl Writer<'_> {
    fn line(&mut self, text: impl AsRef<str>) {
        self.out += text.as_ref();
        self.out.push('\n');
    }

    fn setup(&mut self) -> Result<(), String> {
        let b = self.plan.sim_box;
        let letters: Vec<&str> = (0..3).map(|a| if b.periodic[a] { "p" } else { "m" }).collect();
        self.line("units lj");
        self.line("atom_style angle");
        self.line(format!("boundary {}", letters.join(" ")));
        if self.kinetic.creates.is_empty() {
            self.line(format!("read_data {DATA_FILE}"));
        } else {
            let (bonds, special) = extra_per_atom(&self.model, &self.kinetic);
            self.line(format!("read_data {DATA_FILE} extra/bond/per/atom {bonds} extra/special/per/atom {special}"));
        }
        let sb = self.model.special_bonds;
        self.line(format!("special_bonds lj {} {} {}", num(sb.weights[0]), num(sb.weights[1]), num(sb.weights[2])));
        if !self.bonds.styles.is_empty() {
            // LAMMPS shifts a lepton bond's energy to zero at r0 unless told not to.
            let list: Vec<&str> = self.bonds.styles.iter().map(|&s| if s == "lepton" { "lepton no_offset" } else { s }).collect();
            self.line(format!("bond_style hybrid {}", list.join(" ")));
            for (t, s) in self.bonds.per_type.iter().enumerate() {
                self.out += &format!("bond_coeff {} {} {}\n", t + 1, s.style, s.coeffs);
            }
        }
        if !self.angles.styles.is_empty() {
            // Like bonds, a lepton angle's energy is shifted to zero at θ0 unless told not to.
            let list: Vec<&str> = self.angles.styles.iter().map(|&s| if s == "lepton" { "lepton no_offset" } else { s }).collect();
            self.line(format!("angle_style hybrid {}", list.join(" ")));
            for (t, s) in self.angles.per_type.iter().enumerate() {
                self.out += &format!("angle_coeff {} {} {}\n", t + 1, s.style, s.coeffs);
            }
        }
        // `fix bond/create` looks for partners in a pair neighbour list: a
        // `zero` style (no forces) makes it reach the capture radius.
        let capture = self.kinetic.capture(&self.model);
        if self.pairs.instances.is_empty() && capture > 0.0 {
            self.line(format!("pair_style zero {}", num(capture)));
            self.line("pair_coeff * *");
        }
        if !self.pairs.instances.is_empty() {
            let cut = num(self.pairs.max_cutoff);
            let mut list: Vec<String> = self
                .pairs
                .instances
                .iter()
                .map(|i| if i.style == "harmonic/cut" { i.style.to_string() } else { format!("{} {cut}", i.style) })
                .collect();
            if capture > 0.0 {
                list.push(format!("zero {}", num(capture)));
            }
            self.line(format!("pair_style hybrid/overlay {}", list.join(" ")));
            self.line("pair_coeff * * none");
            if capture > 0.0 {
                self.line("pair_coeff * * zero");
            }
            for (rule, term) in self.model.pair_rules.clone().iter().enumerate() {
                let line = self.pairs.coeff_line(&self.model, rule, term)?;
                self.line(line);
            }
            for inst in self.pairs.instances.iter().filter(|i| i.shift).map(|i| i.reference.clone()).collect::<Vec<_>>() {
                self.line(format!("pair_modify pair {inst} shift yes"));
            }
        }
        let skin = self.plan_skin();
        self.line(format!("neighbor {} bin", num(skin)));
        self.line("neigh_modify every 1 delay 0 check yes");
        let ghost = (self.pairs.max_cutoff.max(capture) + skin).max(2.0 * bonded_extent(self.plan) + skin);
        self.line(format!("comm_modify cutoff {}", num(ghost)));
        for t in 0..self.model.type_names.len() {
            self.line(format!("group cellmd_t{} type {}", t + 1, t + 1));
        }
        for t in self.kinetic.breaks.clone() {
            self.bond_break(t)?;
        }
        for k in self.kinetic.creates.clone() {
            let r = &self.model.bind_rules[k];
            let (a, b, bt, n) = (r.type_a + 1, r.type_b + 1, r.bond_type + 1, r.max_bonds);
            self.line(format!("fix cellmd_bind{} all bond/create 1 {a} {b} {} {bt} iparam {n} {a} jparam {n} {b}", k + 1, num(r.capture)));
        }
        if self.options.probes {
            if !self.bonds.styles.is_empty() {
                self.line("compute cellmd_bond all bond");
            }
            if !self.angles.styles.is_empty() {
                self.line("compute cellmd_angle all angle");
            }
            for (k, inst) in self.pairs.instances.iter().enumerate().map(|(k, i)| (k, i.reference.clone())).collect::<Vec<_>>() {
                self.line(format!("compute cellmd_pair{k} all pair {inst}"));
            }
            self.line("compute cellmd_virial all pressure NULL virial");
            if self.model.has_kinetics() {
                self.line("compute cellmd_bonds all property/local btype batom1 batom2");
            }
        }
        self.thermo_style();
        Ok(())
    }

    fn plan_skin(&self) -> f64 {
        let skin =
            self.plan.actions.iter().rev().find_map(|a| if let Action::Neighbor(n) = a { Some(n.skin) } else { None }).unwrap_or(0.0);
        if skin > 0.0 {
            skin
        } else {
            0.3 * self.pairs.max_cutoff.max(1.0)
        }
    }

    /// Energy terms: (key of cellmd interactions, LAMMPS reference).
    fn energy_terms(&self) -> Vec<(String, String)> {
        let mut terms = Vec::new();
        for (k, names) in self.bonds.interactions.iter().enumerate() {
            terms.push((names.join("+"), format!("c_cellmd_bond[{}]", k + 1)));
        }
        for (k, names) in self.angles.interactions.iter().enumerate() {
            terms.push((names.join("+"), format!("c_cellmd_angle[{}]", k + 1)));
        }
        for (k, inst) in self.pairs.instances.iter().enumerate() {
            terms.push((inst.interaction.to_string(), format!("c_cellmd_pair{k}")));
        }
        for (id, name) in &self.fixes {
            terms.push((name.to_string(), format!("f_{id}")));
        }
        terms
    }

    /// Thermo output that keeps every probed compute current.
    fn thermo_style(&mut self) {
        let mut columns = vec!["step".to_string(), "pe".into()];
        if self.options.probes {
            columns.extend(self.energy_terms().into_iter().map(|(_, r)| r));
            columns.extend((1..=6).map(|k| format!("c_cellmd_virial[{k}]")));
            columns.push("vol".into());
        }
        self.line(format!("thermo_style custom {}", columns.join(" ")));
        self.line("thermo_modify norm no format float %.17g");
    }

    fn probe(&mut self, tag: &str, first: bool) {
        let mut lines = vec![format!("step $(step) {tag}")];
        for (key, reference) in self.energy_terms() {
            lines.push(format!("energy {key} $({reference}:%.17g)"));
        }
        let virial: Vec<String> = (1..=6).map(|k| format!("$(c_cellmd_virial[{k}]*vol:%.17g)")).collect();
        lines.push(format!("virial {}", virial.join(" ")));
        for (k, text) in lines.iter().enumerate() {
            let mode = if first && k == 0 { "file" } else { "append" };
            self.line(format!("print \"{text}\" {mode} {PROBE_FILE} screen no"));
        }
        self.line(format!("write_dump all custom cellmd_probe_{tag}.dump id xu yu zu fx fy fz modify format float %.17g sort id"));
        if self.model.has_kinetics() {
            self.line(format!("write_dump all local cellmd_probe_{tag}.bonds index c_cellmd_bonds[1] c_cellmd_bonds[2] c_cellmd_bonds[3]"));
        }
    }

    /// `fix bond/break` for LAMMPS bond type `l` at its current r0.
    fn bond_break(&mut self, l: usize) -> Result<(), String> {
        let rmax = bond_break_length(&self.model, &self.bond_types, l)?;
        self.line(format!("fix cellmd_break{} all bond/break 1 {} {}", l + 1, l + 1, num(rmax)));
        Ok(())
    }

    fn brownian(&mut self) {
        let (temperature, rng) = if self.kt > 0.0 {
            (
                self.kt,
                match self.noise {
                    Noise::Uniform => "uniform",
                    Noise::Gaussian => "gaussian",
                },
            )
        } else {
            (1.0, "none")
        };
        let seed = (self.seed % 900_000_000).max(1);
        for t in 0..self.model.type_names.len() {
            let gamma = self.model.type_drag[t];
            if gamma.is_infinite() {
                // A `fixed` type gets no integrator: it never moves.
                continue;
            }
            self.line(format!(
                "fix cellmd_bd{} cellmd_t{} brownian {} {seed} gamma_t {} rng {rng}",
                t + 1,
                t + 1,
                num(temperature),
                num(gamma)
            ));
        }
    }

    fn external(&mut self, external: &External) -> Result<(), String> {
        let b = self.plan.sim_box;
        let id = ident("x_", &external.term.label.text);
        let args = match styles::external(external, b.lengths().to_array(), b.periodic, &format!("{id}_face"))? {
            ExternalStyle::ParameterVariables => self.field_variables(external, &id)?,
            ExternalStyle::ExpressionVariables => self.custom_variables(external, &id, b.periodic)?,
            ExternalStyle::Fix { args, variable } => {
                if let Some(line) = variable {
                    self.line(line);
                }
                args
            }
        };
        let mut ids: Vec<u64> = external.members.iter().map(|&m| self.model.ids[m as usize]).collect();
        let group = ident("g_", &external.term.label.text);
        if ids.is_empty() {
            return Err(format!("external `{}` acts on an empty group", external.term.label.text));
        }
        self.unexternal(&external.term.label.text);
        self.line(format!("group {group} id {}", id_ranges(&mut ids)));
        self.line(format!("fix {id} {group} {args}"));
        self.fixes.push((id, external.term.interaction.name()));
        self.thermo_style();
        Ok(())
    }

    /// A `field` as `fix addforce` with one atom-style variable per parameter
    /// (its arguments after the group).
    fn field_variables(&mut self, external: &External, id: &str) -> Result<String, String> {
        let mut variables = Vec::new();
        for (k, spec) in external.term.interaction.params().iter().enumerate() {
            let formula = match external.expressions.iter().find(|(p, _)| *p == k) {
                Some((_, expr)) => formula::lammps_formula(expr).map_err(|e| format!("external `{}`: {e}", external.term.label.text))?,
                None => num(external.term.params[k]),
            };
            variables.push((spec.name, formula));
        }
        Ok(self.addforce(id, &variables))
    }

    /// Writes one atom-style variable `ID_NAME` per (name, formula) — the
    /// force components, then the energy — and returns the `fix addforce`
    /// arguments that read them.
    fn addforce(&mut self, id: &str, variables: &[(&str, String)]) -> String {
        let names: Vec<String> = variables.iter().map(|(name, _)| format!("{id}_{name}")).collect();
        for (name, (_, formula)) in names.iter().zip(variables) {
            self.line(format!("variable {name} atom \"{formula}\""));
        }
        format!("addforce v_{} v_{} v_{} energy v_{}", names[0], names[1], names[2], names[3])
    }

    /// A `custom` external as `fix addforce` with atom-style variables: the
    /// components of −∇E from the expression's symbolic derivatives and the
    /// energy E, its parameters written as numbers and `t` as LAMMPS' `time`.
    /// LAMMPS' `x`, `y`, `z` are wrapped into the box, so an energy that reads
    /// the coordinate of a periodic axis is refused.
    fn custom_variables(&mut self, external: &External, id: &str, periodic: [bool; 3]) -> Result<String, String> {
        let term = &external.term;
        let label = &term.label.text;
        let energy = term.interaction.expression().ok_or_else(|| format!("external `{label}` has no expression"))?;
        for (axis, name) in ["x", "y", "z"].into_iter().enumerate() {
            if periodic[axis] && energy.depends_on(name) {
                return Err(format!(
                    "external `{label}` reads `{name}` on a periodic axis: LAMMPS' atom-style `{name}` is wrapped into the box where cellmd's is unwrapped"
                ));
            }
        }
        let specs = term.interaction.params();
        let energy =
            energy.substitute(&|name| (name != "t").then(|| specs.iter().position(|p| p.name == name)).flatten().map(|k| term.params[k]));
        let minus = |e: Expr| Expr::Unary { op: UnaryOp::Neg, span: e.span(), arg: Box::new(e) };
        let mut variables = Vec::new();
        for (suffix, expr) in [
            ("fx", minus(energy.derivative("x"))),
            ("fy", minus(energy.derivative("y"))),
            ("fz", minus(energy.derivative("z"))),
            ("e", energy),
        ] {
            variables.push((suffix, formula::lammps_formula(&expr).map_err(|e| format!("external `{label}`: {e}"))?));
        }
        Ok(self.addforce(id, &variables))
    }

    fn unexternal(&mut self, name: &str) {
        let id = ident("x_", name);
        if let Some(k) = self.fixes.iter().position(|(f, _)| *f == id) {
            self.fixes.remove(k);
            self.line(format!("unfix {id}"));
            self.line(format!("group {} delete", ident("g_", name)));
            self.thermo_style();
        }
    }

    fn coeff(&mut self, target: &CoeffTarget, param: usize, value: f64) -> Result<(), String> {
        match target {
            CoeffTarget::BondType(k) => {
                target.set(&mut self.model, param, value);
                for l in self.bond_types.of_cellmd_type(*k).collect::<Vec<_>>() {
                    let s = styles::bonded(&self.bond_types.term(&self.model, l))?;
                    self.line(format!("bond_coeff {} {} {}", l + 1, s.style, s.coeffs));
                    if self.kinetic.breaks.contains(&l) {
                        // A new r0 moves the break length.
                        self.line(format!("unfix cellmd_break{}", l + 1));
                        self.bond_break(l)?;
                    }
                }
            }
            CoeffTarget::AngleType(k) => {
                target.set(&mut self.model, param, value);
                let s = styles::bonded(&self.model.angle_types[*k])?;
                self.line(format!("angle_coeff {} {} {}", k + 1, s.style, s.coeffs));
            }
            CoeffTarget::PairRule(k) => {
                target.set(&mut self.model, param, value);
                let term = self.model.pair_rules[*k].clone();
                let line = self.pairs.coeff_line(&self.model, *k, &term)?;
                self.line(line);
            }
            CoeffTarget::BodyRule(_) => return Err("`coeff body` is not exported: LAMMPS has no surface terms of bodies".into()),
            CoeffTarget::External(name) => {
                return Err(format!(
                    "`coeff external {name}` is not exported; give the external its new parameters with a new `external {name}` line"
                ))
            }
        }
        Ok(())
    }

    fn actions(&mut self) -> Result<(), String> {
        let actions = &self.plan.actions;
        let first_run = actions.iter().position(|a| matches!(a, Action::Run(_)));
        let last_run = actions.iter().rposition(|a| matches!(a, Action::Run(_)));
        for (k, action) in actions.iter().enumerate() {
            if Some(k) == first_run && self.options.probes {
                self.initial_probe();
            }
            match action {
                Action::Temperature(kt) => self.kt = *kt,
                Action::Timestep(dt) => {
                    self.dt_set = true;
                    self.line(format!("timestep {}", num(*dt)));
                }
                Action::Seed(seed) => self.seed = *seed,
                Action::Integrator(s) => {
                    if matches!(s, Integrator::Implicit(..)) {
                        return Err("`integrator implicit` has no LAMMPS counterpart (LAMMPS' fix brownian is the explicit step)".into());
                    }
                    self.noise = s.common().noise;
                }
                Action::Neighbor(_) | Action::Device(_) => {}
                Action::Protocol(_) => {
                    return Err("protocols (`ramp`, `move`, `freeze`, `reset_rest`, `indent`) are not exported to LAMMPS".into())
                }
                Action::Constrain { .. } | Action::Unconstrain(_) => {
                    return Err("`constrain` (overdamped SHAKE) is not exported: LAMMPS' fix shake needs velocities and masses".into())
                }
                Action::Thermo { every, .. } => self.line(format!("thermo {every}")),
                Action::ThermoFile(path) => self.line(format!("# thermo_file {}: the LAMMPS log holds the thermo table", path.display())),
                Action::EventFile(path) => self.line(format!("# events {}: bond kinetics are not exported", path.display())),
                Action::LifetimeFile(path) => self.line(format!("# lifetimes {}: bond kinetics are not exported", path.display())),
                Action::Dump(spec) => self.line(format!(
                    "dump {} all custom {} {} id type xu yu zu",
                    ident("d_", &spec.name),
                    spec.every,
                    spec.path.display()
                )),
                Action::Undump(name) => self.line(format!("undump {}", ident("d_", name))),
                Action::External(e) => self.external(e)?,
                Action::Unexternal(name) => self.unexternal(name),
                Action::Coeff { target, param, value } => self.coeff(target, *param, *value)?,
                Action::Displace { group, delta } => {
                    let name = ident("m_", &group.name);
                    let mut ids: Vec<u64> = group.members.iter().map(|&m| self.model.ids[m as usize]).collect();
                    self.line(format!("group {name} id {}", id_ranges(&mut ids)));
                    self.line(format!("displace_atoms {name} move {} {} {} units box", num(delta.x), num(delta.y), num(delta.z)));
                    self.line(format!("group {name} delete"));
                }
                Action::Minimize(_) => {
                    return Err(
                        "`minimize` (FIRE with drag-scaled masses) has no exact LAMMPS equivalent; export the deck without it".into()
                    )
                }
                Action::Branch { .. } | Action::Skip(_) => {
                    return Err("an `if` that reads thermo values cannot be exported: LAMMPS would need it as an `if` on a variable of \
                                thermo keywords, which this exporter does not write"
                        .into())
                }
                Action::ReadState(_) => return Err("`read_state` cannot be exported: LAMMPS cannot read cellmd restart files".into()),
                Action::WriteState(path) => self.line(format!("# write_state {}: not exported", path.display())),
                Action::Checkpoint(spec) => self.line(format!("# write_state {} every {}: not exported", spec.path.display(), spec.every)),
                Action::Print(text) => self.line(format!("print \"{}\"", text.replace('"', "'"))),
                Action::Run(steps) => {
                    self.brownian();
                    self.line(format!("run {steps} post no"));
                }
            }
            if Some(k) == last_run && self.options.probes {
                self.probe("final", false);
            }
        }
        if first_run.is_none() && self.options.probes {
            self.initial_probe();
        }
        Ok(())
    }

    fn initial_probe(&mut self) {
        if !self.dt_set {
            self.line("timestep 0.0");
        }
        self.brownian();
        self.line("run 0 post no");
        self.probe("init", true);
    }
}

/// Exports a validated deck. Interactions or commands LAMMPS cannot express
/// are errors naming them.
pub fn export(plan: &Plan, options: ExportOptions) -> Result<LammpsDeck, String> {
    let model = plan.model.clone();
    let element = model.tetra_type.first().map(|&t| model.tetra_types[t as usize].term());
    let body = model.body_rules.first().map(Typed::term);
    if let Some(term) = body.or(model.contact_rules.first().map(Typed::term)).or(element) {
        return Err(styles::unsupported(term));
    }
    let bond_types = LammpsBondTypes::new(&model);
    let kinetic = kinetic_fixes(plan, &bond_types)?;
    let terms: Vec<TermType> = (0..bond_types.count()).map(|l| bond_types.term(&model, l)).collect();
    let bonds = Hybrid::new(&terms, styles::bonded)?;
    let angle_types: Vec<TermType> = model.angle_types.iter().map(|t| t.term().clone()).collect();
    let angles = Hybrid::new(&angle_types, styles::bonded)?;
    let pairs = Pairs::new(&model)?;
    // Externals and coefficients that only appear later are checked when written.
    let title = format!("cellmd export of {}", plan.deck_path.display());
    let mut w = Writer {
        plan,
        model,
        options,
        out: String::new(),
        bonds,
        bond_types,
        angles,
        pairs,
        fixes: Vec::new(),
        kinetic,
        kt: 0.0,
        seed: 1,
        noise: Noise::Uniform,
        dt_set: false,
    };
    let units = match plan.model.units {
        UnitSystem::Lj => "units lj (identical)".to_string(),
        UnitSystem::Cell => {
            "cell units (µm, s, pN) written as LAMMPS units lj: sigma = 1 µm, tau = 1 s, epsilon = 1 pN·µm, T = kT in pN·µm".to_string()
        }
    };
    w.line(format!("# {title} ({units})"));
    w.line("# Overdamped dynamics: fix brownian per particle type, gamma_t = the type's drag.");
    w.setup()?;
    w.actions()?;
    Ok(LammpsDeck { data: data_file(plan, &w.bond_types, &title), input: w.out })
}

/// Writes `data.lammps` and then `in.lammps` (which reads it) into `dir`
/// (created if needed), each atomically and through no link inside `dir`
/// (`output::files`): a kill or a full disk leaves each name whole, old or
/// new. The error names the file.
pub fn write(deck: &LammpsDeck, dir: &std::path::Path) -> std::io::Result<()> {
    crate::output::files::write_all_atomically(dir, &[(DATA_FILE, &deck.data), (INPUT_FILE, &deck.input)])
}
