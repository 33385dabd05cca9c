//! Per-bond dynamic state, part of the simulation state (`State::bonds`) and
//! of restart files.

/// State of every bond (indexed like `Model::bonds`).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BondState {
    pub bound: Vec<bool>,
    /// Time bound since the bond formed or last rebound.
    pub age: Vec<f64>,
    /// Current rest length, for bonds whose type changes it; `None`: the
    /// type's `r0` applies.
    pub rest: Vec<Option<f64>>,
    /// Stiffness scale (maturation); 1 otherwise.
    pub scale: Vec<f64>,
    /// Bonds formed during the run (by `bind` rules), appended after the
    /// topology's bonds in this order.
    #[serde(default)]
    pub formed: Vec<FormedBond>,
}

/// A bond created by a `bind` rule (internal particle indices).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FormedBond {
    pub bond_type: u32,
    pub particles: [u32; 2],
}

impl BondState {
    /// All bonds bound, age 0, rest lengths from `initial_rest`.
    pub fn new(initial_rest: Vec<Option<f64>>) -> Self {
        let n = initial_rest.len();
        Self { bound: vec![true; n], age: vec![0.0; n], rest: initial_rest, scale: vec![1.0; n], formed: Vec::new() }
    }

    pub fn len(&self) -> usize {
        self.bound.len()
    }

    pub fn is_empty(&self) -> bool {
        self.bound.is_empty()
    }

    /// Why this state cannot belong to a system of `particles` particles,
    /// `topology_bonds` bonds in its topology and `bond_types` bond types
    /// (a restart read from disk is checked so before use); `field: found
    /// …, expected …`.
    pub fn check(&self, particles: usize, topology_bonds: usize, bond_types: usize) -> Result<(), String> {
        for (k, f) in self.formed.iter().enumerate() {
            if f.bond_type as usize >= bond_types {
                return Err(format!("bonds.formed[{k}].bond_type: found {}, expected a bond type index below {bond_types}", f.bond_type));
            }
            let [i, j] = f.particles.map(|p| p as usize);
            if i >= particles || j >= particles || i == j {
                return Err(format!(
                    "bonds.formed[{k}].particles: found [{i}, {j}], expected two different particle indices below {particles}"
                ));
            }
        }
        let n = topology_bonds + self.formed.len();
        for (field, len) in [("bound", self.bound.len()), ("age", self.age.len()), ("rest", self.rest.len()), ("scale", self.scale.len())] {
            if len != n {
                return Err(format!(
                    "bonds.{field}: found an array of {len}, expected {n} entries (the topology's {topology_bonds} bonds and {} formed)",
                    self.formed.len()
                ));
            }
        }
        if let Some(k) = self.age.iter().position(|a| !(a.is_finite() && *a >= 0.0)) {
            return Err(format!("bonds.age[{k}]: found {:e}, expected a finite age >= 0", self.age[k]));
        }
        if let Some(k) = self.rest.iter().position(|r| r.is_some_and(|r| !(r.is_finite() && r > 0.0))) {
            return Err(format!(
                "bonds.rest[{k}]: found {:e}, expected a finite rest length > 0 (or null)",
                self.rest[k].unwrap_or_default()
            ));
        }
        if let Some(k) = self.scale.iter().position(|c| !(c.is_finite() && *c >= 0.0)) {
            return Err(format!("bonds.scale[{k}]: found {:e}, expected a finite stiffness scale >= 0", self.scale[k]));
        }
        Ok(())
    }

    /// Appends a newly formed bond.
    pub fn push(&mut self, rest: Option<f64>, scale: f64) {
        self.bound.push(true);
        self.age.push(0.0);
        self.rest.push(rest);
        self.scale.push(scale);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_state_that_does_not_fit_its_system_is_named_by_field() {
        let mut s = BondState::new(vec![Some(1.0), None]);
        assert_eq!(s.check(3, 2, 1), Ok(()));
        assert_eq!(
            s.check(3, 3, 1).unwrap_err(),
            "bonds.bound: found an array of 2, expected 3 entries (the topology's 3 bonds and 0 formed)"
        );
        s.age.pop();
        assert!(s.check(3, 2, 1).unwrap_err().starts_with("bonds.age: found an array of 1, expected 2 entries"));
        let mut s = BondState::new(vec![Some(0.0), None]);
        assert_eq!(s.check(3, 2, 1).unwrap_err(), "bonds.rest[0]: found 0e0, expected a finite rest length > 0 (or null)");
        s.rest[0] = Some(-5.0);
        assert!(s.check(3, 2, 1).unwrap_err().starts_with("bonds.rest[0]: found -5e0"));
        let mut s = BondState::new(vec![None]);
        s.scale[0] = f64::NAN;
        assert!(s.check(3, 1, 1).unwrap_err().starts_with("bonds.scale[0]: found NaN"));
        s.scale[0] = 1.0;
        s.age[0] = -1.0;
        assert!(s.check(3, 1, 1).unwrap_err().starts_with("bonds.age[0]"));
        let mut s = BondState::new(vec![None]);
        s.formed.push(FormedBond { bond_type: 0, particles: [1, 1] });
        s.push(None, 1.0);
        assert!(s.check(3, 1, 1).unwrap_err().starts_with("bonds.formed[0].particles: found [1, 1]"));
        s.formed[0] = FormedBond { bond_type: 4, particles: [0, 1] };
        assert!(s.check(3, 1, 1).unwrap_err().starts_with("bonds.formed[0].bond_type: found 4"));
        s.formed[0].bond_type = 0;
        assert_eq!(s.check(3, 1, 1), Ok(()));
    }
}
