//! The outputs of a deck: `thermo` (and its columns), `thermo_file`,
//! `events`, `lifetimes`, `dump`, `undump`, `write_state`, `read_state` and
//! `print`.

use std::path::PathBuf;

use super::output_names::OutputKind;
use super::{expect_len, Validator};
use crate::deck::plan::{Action, CheckpointSpec, DumpSpec, GroupQuantity, ThermoColumn};
use crate::input::{check_input_file, is_replaying, parse_u64, InputError, Token};
use crate::interactions::REGISTRY;
use crate::kinetics_engine::EventKind;
use crate::output::{read_state, AtomColumn, DumpFormat, Encoding, WriterOptions};

impl Validator {
    pub(super) fn thermo(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=usize::MAX, usage)?;
        let every = parse_u64(&s[1], "a thermo interval in steps")?;
        let columns = if s.len() > 2 {
            // Group columns name groups, which exist once the system does.
            if let Some(t) = s[2..].iter().find(|t| t.text.split_once('/').is_some_and(|(p, _)| GroupQuantity::from_prefix(p).is_some())) {
                self.model(t)?;
            }
            self.thermo_columns(&s[2..])?
        } else {
            vec![ThermoColumn::Step, ThermoColumn::Time, ThermoColumn::Pe, ThermoColumn::Fmax, ThermoColumn::Press]
        };
        self.actions.push(Action::Thermo { every, columns });
        Ok(())
    }

    pub(super) fn thermo_file(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=1, usage)?;
        let path = self.outputs.claim(&s[1], OutputKind::ThermoFile)?;
        self.actions.push(Action::ThermoFile(path));
        Ok(())
    }

    pub(super) fn events(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=1, usage)?;
        let path = self.outputs.claim(&s[1], OutputKind::Events)?;
        self.actions.push(Action::EventFile(path));
        Ok(())
    }

    pub(super) fn lifetimes(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=1, usage)?;
        let path = self.outputs.claim(&s[1], OutputKind::Lifetimes)?;
        self.actions.push(Action::LifetimeFile(path));
        Ok(())
    }

    pub(super) fn dump(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 5..=usize::MAX, usage)?;
        if s[2].text != "every" {
            return Err(s[2].error(format!("found `{}`, expected `every`", s[2].text)));
        }
        let every = parse_u64(&s[3], "a dump interval in steps")?;
        if every == 0 {
            return Err(s[3].error("found 0, expected a dump interval >= 1"));
        }
        let format = DumpFormat::from_keyword(&s[4].text).ok_or_else(|| {
            let names: Vec<String> = DumpFormat::ALL.iter().map(|f| format!("`{}`", f.keyword())).collect();
            s[4].error(format!("found format `{}`, expected one of {}", s[4].text, names.join(", ")))
        })?;
        let path = self.outputs.claim(&s[5], OutputKind::Dump)?;
        let options = self.dump_options(format, &s[6..], usage)?;
        if self.outputs.dumps.contains_key(&s[1].text) {
            return Err(s[1].error(format!("dump `{}` is already active; expected a new name or `undump {}` first", s[1].text, s[1].text)));
        }
        if self.outputs.dumps.values().any(|p| *p == path) {
            return Err(s[5].error(format!("`{}` is already written by another dump; expected a different file", s[5].text)));
        }
        self.outputs.dumps.insert(s[1].text.clone(), path.clone());
        self.actions.push(Action::Dump(DumpSpec { name: s[1].text.clone(), every, format, path, options }));
        Ok(())
    }

    pub(super) fn undump(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=1, usage)?;
        if self.outputs.dumps.remove(&s[1].text).is_none() {
            return Err(s[1].error(format!("found `{}`, expected the name of an active dump", s[1].text)));
        }
        self.actions.push(Action::Undump(s[1].text.clone()));
        Ok(())
    }

    pub(super) fn read_state(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        let kw = &s[0];
        expect_len(s, 1..=1, usage)?;
        self.model(kw)?;
        let written = PathBuf::from(&s[1].text);
        let path = if self.outputs.states_written.contains(&written) { written } else { self.input_path(&s[1]) };
        // A continued run starts after this point from its own restart.
        if !self.outputs.states_written.contains(&path) && !is_replaying() {
            if !path.exists() {
                return Err(
                    s[1].error(format!("cannot read `{}`: no such file; expected a restart file written by `write_state`", path.display()))
                );
            }
            check_input_file(&path).map_err(|why| s[1].error(format!("cannot read `{}`: {why}", path.display())))?;
            // Checked now against the system, so a bad restart fails `check`, before any output exists.
            let data = read_state(&path).map_err(|e| s[1].error(e))?;
            let periodic = self.initial.sim_box.as_ref().expect("built with the model").periodic;
            let model = self.model(kw)?;
            data.check_against(model, periodic).map_err(|e| s[1].error(format!("{}: {e}", path.display())))?;
        }
        self.actions.push(Action::ReadState(path));
        Ok(())
    }

    /// `write_state FILE [every N [keep K]]`: once now, or periodically
    /// during runs; `*` in FILE stands for the step.
    pub(super) fn write_state(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=5, usage)?;
        self.model(&s[0])?;
        let path = self.outputs.claim(&s[1], OutputKind::Restart)?;
        if s.len() == 2 {
            self.outputs.states_written.insert(path.clone());
            self.actions.push(Action::WriteState(path));
            return Ok(());
        }
        if s[2].text != "every" {
            return Err(s[2].error(format!("found `{}`, expected `every` or the end of the line (`{usage}`)", s[2].text)));
        }
        let n = s.get(3).ok_or_else(|| s[2].error(format!("`every` has no value; expected `{usage}`")))?;
        let every = parse_u64(n, "a checkpoint interval in steps")?;
        if every == 0 {
            return Err(n.error("found 0, expected a checkpoint interval >= 1"));
        }
        let keep = match s.get(4) {
            None => None,
            Some(k) if k.text != "keep" => {
                return Err(k.error(format!("found `{}`, expected `keep` or the end of the line (`{usage}`)", k.text)))
            }
            Some(k) => {
                let count = s.get(5).ok_or_else(|| k.error(format!("`keep` has no value; expected `{usage}`")))?;
                let keep = parse_u64(count, "a number of checkpoint files to keep")?;
                if keep == 0 {
                    return Err(count.error("found 0, expected keep >= 1"));
                }
                if !s[1].text.contains('*') {
                    return Err(count.error(format!(
                        "`keep` needs a `*` (the step) in the file name; `{}` is one file, overwritten at each checkpoint",
                        s[1].text
                    )));
                }
                Some(keep as usize)
            }
        };
        self.actions.push(Action::Checkpoint(CheckpointSpec { path, every, keep }));
        Ok(())
    }

    pub(in crate::deck) fn thermo_columns(&self, tokens: &[Token]) -> Result<Vec<ThermoColumn>, InputError> {
        const FIXED: &str =
            "step, time, pe, work, pe/NAME, pe/EXTERNAL, fmax, fnorm, press, pxx, pyy, pzz, pxy, pxz, pyz, nbuild, solver_iterations, solver_residual, ctension/BONDTYPE, breaks, rebinds, forms, resets, nbound/BONDTYPE, tension/BONDTYPE, volume/BODYTYPE, area/BODYTYPE, planetension/AXIS/POS, gamma/BODYTYPE, e2e/BONDTYPE, tcorr/BONDTYPE/LAG, fracture/BONDTYPE/QUANTITY, clustering/BONDTYPE/GROUP_A/GROUP_B, fx/GROUP, fy/GROUP, fz/GROUP, fx/EXTERNAL, fy/EXTERNAL, fz/EXTERNAL, xu/GROUP, yu/GROUP, zu/GROUP, xspan/GROUP, yspan/GROUP, zspan/GROUP, fabs/GROUP, hullarea/GROUP, load/INDENTER, depth/INDENTER, mindist, nclamp";
        let bond_type = |t: &Token, name: &str| {
            self.setup.forcefield.bond_types.iter().position(|b| b.label.text == name).ok_or_else(|| {
                let names: Vec<&str> = self.setup.forcefield.bond_types.iter().map(|b| b.label.text.as_str()).collect();
                t.error(format!("found bond type `{name}`, expected one defined in the force field ({})", names.join(", ")))
            })
        };
        let body_type = |t: &Token, name: &str| {
            let names = self.setup.forcefield.body_type_names();
            names.iter().position(|n| *n == name).ok_or_else(|| {
                t.error(format!(
                    "found body type `{name}`, expected one that `body` or `contact` lines of the force field name ({})",
                    names.join(", ")
                ))
            })
        };
        tokens
            .iter()
            .map(|t| {
                Ok(match t.text.as_str() {
                    "step" => ThermoColumn::Step,
                    "time" => ThermoColumn::Time,
                    "pe" => ThermoColumn::Pe,
                    "work" => ThermoColumn::Work,
                    "fmax" => ThermoColumn::Fmax,
                    "fnorm" => ThermoColumn::Fnorm,
                    "press" => ThermoColumn::Press,
                    "pxx" => ThermoColumn::Pressure(0),
                    "pyy" => ThermoColumn::Pressure(1),
                    "pzz" => ThermoColumn::Pressure(2),
                    "pxy" => ThermoColumn::Pressure(3),
                    "pxz" => ThermoColumn::Pressure(4),
                    "pyz" => ThermoColumn::Pressure(5),
                    "nbuild" => ThermoColumn::Nbuild,
                    "solver_iterations" => ThermoColumn::SolverIterations,
                    "solver_residual" => ThermoColumn::SolverResidual,
                    "breaks" => ThermoColumn::Events(EventKind::Break),
                    "rebinds" => ThermoColumn::Events(EventKind::Rebind),
                    "forms" => ThermoColumn::Events(EventKind::Form),
                    "resets" => ThermoColumn::Events(EventKind::Reset),
                    "mindist" | "nclamp" if self.setup.forcefield.contact_rules.is_empty() => {
                        return Err(t.error(format!("found `{}`, which needs `contact` lines in the force field; expected {FIXED}", t.text)))
                    }
                    "mindist" => ThermoColumn::MinDistance,
                    "nclamp" => ThermoColumn::ContactClamps,
                    other => match other.split_once('/') {
                        Some(("pe", name)) => match (REGISTRY.iter().position(|i| i.name() == name), self.externals.contains(name)) {
                            (Some(_), true) => {
                                return Err(t.error(format!(
                                "found `pe/{name}`, which names both an interaction and an active external; expected an external named \
                                 otherwise than every interaction"
                            )))
                            }
                            (Some(k), false) => ThermoColumn::PeOf(k),
                            (None, true) => ThermoColumn::ExternalEnergy(name.to_string()),
                            (None, false) => {
                                return Err(t.error(format!(
                                    "found `pe/{name}`, expected pe/ followed by a registered interaction name (see `cellmd list`) or \
                                 the name of an active external"
                                )))
                            }
                        },
                        Some((prefix @ ("fx" | "fy" | "fz"), name)) if self.externals.contains(name) => {
                            if self.groups.contains_key(name) {
                                return Err(t.error(format!(
                                    "found `{other}`, where `{name}` names both a group and an active external; expected an external \
                                     named otherwise than every group"
                                )));
                            }
                            ThermoColumn::ExternalForce { name: name.to_string(), axis: usize::from(prefix.as_bytes()[1] - b'x') }
                        }
                        Some(("nbound", name)) => ThermoColumn::Bound(bond_type(t, name)?),
                        Some(("tension", name)) => ThermoColumn::Tension(bond_type(t, name)?),
                        Some(("ctension", name)) => ThermoColumn::ConstraintTension(bond_type(t, name)?),
                        Some(("volume", name)) => ThermoColumn::BodyVolume(body_type(t, name)?),
                        Some(("area", name)) => ThermoColumn::BodyArea(body_type(t, name)?),
                        Some(("gamma", name)) => ThermoColumn::CorticalTension(body_type(t, name)?),
                        Some(("e2e", name)) => ThermoColumn::EndToEnd(bond_type(t, name)?),
                        Some((prefix, name)) if GroupQuantity::from_prefix(prefix).is_some() => {
                            let quantity = GroupQuantity::from_prefix(prefix).expect("matched");
                            let group = self.group_named(&t.with_text(name.to_string()))?.clone();
                            ThermoColumn::Group { group, quantity }
                        }
                        Some((kind @ ("load" | "depth"), name)) => self.indenter_column(t, kind, name)?,
                        Some(("planetension", rest)) => {
                            let usage = format!("found `{other}`, expected planetension/AXIS/POS with AXIS x, y or z and POS a number");
                            let (axis, pos) = rest.split_once('/').ok_or_else(|| t.error(usage.clone()))?;
                            let axis = ["x", "y", "z"].iter().position(|a| *a == axis).ok_or_else(|| t.error(usage.clone()))?;
                            let pos = pos.parse::<f64>().ok().filter(|p| p.is_finite()).ok_or_else(|| t.error(usage))?;
                            ThermoColumn::PlaneTension { axis, pos }
                        }
                        Some(("tcorr", rest)) => {
                            let usage = format!("found `{other}`, expected tcorr/BONDTYPE/LAG with LAG a whole number of bonds");
                            let (name, lag) = rest.rsplit_once('/').ok_or_else(|| t.error(usage.clone()))?;
                            let lag = lag.parse::<usize>().map_err(|_| t.error(usage))?;
                            ThermoColumn::TangentCorrelation { bond_type: bond_type(t, name)?, lag }
                        }
                        Some(("fracture", rest)) => {
                            use crate::measure::fracture::FractureQuantity;
                            let names: Vec<&str> = FractureQuantity::ALL.iter().map(|q| q.name()).collect();
                            let usage =
                                format!("found `{other}`, expected fracture/BONDTYPE/QUANTITY with QUANTITY one of {}", names.join(", "));
                            let (name, quantity) = rest.rsplit_once('/').ok_or_else(|| t.error(usage.clone()))?;
                            let quantity = FractureQuantity::from_name(quantity).ok_or_else(|| t.error(usage))?;
                            ThermoColumn::Fracture { bond_type: bond_type(t, name)?, quantity }
                        }
                        Some(("clustering", rest)) => {
                            let usage = || t.error(format!("found `{other}`, expected clustering/BONDTYPE/GROUP_A/GROUP_B"));
                            let [name, a, b] = rest.split('/').collect::<Vec<_>>()[..] else { return Err(usage()) };
                            if a == b {
                                return Err(t.error(format!("found `{other}`, expected two different groups (the two cells)")));
                            }
                            let bond_type = bond_type(t, name)?;
                            let [a, b] = [a, b].map(|g| self.group_named(&t.with_text(g.to_string())).cloned());
                            let (a, b) = (a?, b?);
                            if let Some(empty) = [&a, &b].into_iter().find(|g| g.members.is_empty()) {
                                return Err(t.error(format!(
                                    "found `{other}`, whose group `{}` is empty; expected groups with members",
                                    empty.name
                                )));
                            }
                            ThermoColumn::Clustering { bond_type, a, b }
                        }
                        _ => return Err(t.error(format!("found thermo column `{other}`, expected one of: {FIXED}"))),
                    },
                })
            })
            .collect()
    }

    /// The options after a `dump`'s file: `columns C...` (LAMMPS dumps) or
    /// `encoding protobuf|json` (MCAP).
    fn dump_options(&self, format: DumpFormat, rest: &[Token], usage: &str) -> Result<WriterOptions, InputError> {
        let mut options = WriterOptions::default();
        let Some(first) = rest.first() else { return Ok(options) };
        match (first.text.as_str(), format) {
            ("columns", DumpFormat::Lammps) => {
                if rest.len() < 2 {
                    return Err(first.error("expected at least one column name after `columns`"));
                }
                options.columns = rest[1..]
                    .iter()
                    .map(|t| {
                        AtomColumn::from_name(&t.text).ok_or_else(|| {
                            let names: Vec<String> = AtomColumn::all().iter().map(|c| c.name()).collect();
                            t.error(format!("found dump column `{}`, expected one of: {}", t.text, names.join(" ")))
                        })
                    })
                    .collect::<Result<_, _>>()?;
            }
            ("encoding", DumpFormat::Mcap) => {
                expect_len(rest, 1..=1, usage)?;
                options.encoding = Encoding::from_keyword(&rest[1].text)
                    .ok_or_else(|| rest[1].error(format!("found encoding `{}`, expected `protobuf` or `json`", rest[1].text)))?;
            }
            ("columns", _) => {
                return Err(first.error(format!("`{}` dumps have fixed fields; expected `columns` only after `lammps`", format.keyword())))
            }
            ("encoding", _) => {
                return Err(first.error(format!("`{}` dumps have one encoding; expected `encoding` only after `mcap`", format.keyword())))
            }
            (other, _) => {
                return Err(first.error(format!("found `{other}`, expected `columns`, `encoding` or the end of the line (`{usage}`)")))
            }
        }
        Ok(options)
    }

    pub(super) fn print(&mut self, s: &[Token], _usage: &str) -> Result<(), InputError> {
        self.actions.push(Action::Print(s[1..].iter().map(|t| t.text.as_str()).collect::<Vec<_>>().join(" ")));
        Ok(())
    }
}
