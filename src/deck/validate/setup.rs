//! The commands that define the system before it is first used: `units`,
//! `forcefield`, `box` and `special_bonds` (`topology` is in `compose`).

use super::{expect_len, Validator};
use crate::forcefield::load_forcefield;
use crate::input::{parse_f64, InputError, Token};
use crate::system::SpecialBonds;
use crate::topology::{parse_box_axis, BoxAxis};
use crate::units::UnitSystem;

impl Validator {
    pub(super) fn units(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=1, usage)?;
        if self.setup.topology.is_some() || self.setup.forcefield_seen {
            return Err(s[0].error("`units` must come before `topology` and `forcefield`"));
        }
        self.setup.units = UnitSystem::from_keyword(&s[1].text)
            .ok_or_else(|| s[1].error(format!("found `{}`, expected `cell` (µm, s, pN) or `lj`", s[1].text)))?;
        Ok(())
    }

    pub(super) fn forcefield(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=1, usage)?;
        let path = self.input_path(&s[1]);
        load_forcefield(&path, Some(&s[1]), self.setup.units, &mut self.setup.forcefield, &mut Vec::new())?;
        self.setup.forcefield_seen = true;
        Ok(())
    }

    pub(super) fn box_command(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 12..=12, usage)?;
        let mut axes: [BoxAxis; 3] = std::array::from_fn(|_| BoxAxis { lo: 0.0, hi: 0.0, periodic: false });
        let mut seen = [false; 3];
        for chunk in s[1..].chunks(4) {
            let index = parse_box_axis(chunk, &mut axes)?;
            if seen[index] {
                return Err(chunk[0].error("axis given twice; expected x, y and z once each"));
            }
            seen[index] = true;
        }
        self.setup.box_axes = Some(axes);
        Ok(())
    }

    pub(super) fn special_bonds(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        // LAMMPS' own form names the pair style family first: `special_bonds lj W12 W13 W14`.
        let s = if s.get(1).is_some_and(|t| t.text == "lj") { [&s[..1], &s[2..]].concat() } else { s.to_vec() };
        expect_len(&s, 3..=3, usage)?;
        let mut weights = [0.0; 3];
        for (k, t) in s[1..].iter().enumerate() {
            weights[k] = parse_f64(t, "a weight")?;
            if !(0.0..=1.0).contains(&weights[k]) {
                return Err(t.error(format!("found weight {}, expected a weight from 0 (pair left out) to 1 (pair in full)", weights[k])));
            }
        }
        self.setup.special_bonds = SpecialBonds { weights };
        Ok(())
    }
}
