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

    /// Appends a newly formed bond.
    pub fn push(&mut self, rest: Option<f64>, scale: f64) {
        self.bound.push(true);
        self.age.push(0.0);
        self.rest.push(rest);
        self.scale.push(scale);
    }
}
