//! Per-particle dynamic state in f64.

use glam::DVec3;

/// Positions (wrapped on periodic axes), image counters and the clock.
///
/// Particles are stored by internal index `0..n`; the user-facing id of a
/// particle lives in the topology.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct State {
    /// Steps taken since the start of the deck (the key of the noise stream).
    pub step: u64,
    /// Simulated time (time units).
    pub time: f64,
    pub positions: Vec<DVec3>,
    pub images: Vec<[i64; 3]>,
    /// Bond state, when some bond type has kinetic rules.
    #[serde(default)]
    pub bonds: Option<crate::system::BondState>,
}

impl State {
    pub fn new(positions: Vec<DVec3>) -> Self {
        let images = vec![[0; 3]; positions.len()];
        Self { step: 0, time: 0.0, positions, images, bonds: None }
    }

    pub fn len(&self) -> usize {
        self.positions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }
}
