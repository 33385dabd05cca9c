//! Bond events: the state changes of one step, as the engine decides them
//! (written by the event log and the MCAP writer of `output`).

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EventKind {
    Break,
    Rebind,
    Form,
    Reset,
}

impl EventKind {
    pub fn name(self) -> &'static str {
        match self {
            EventKind::Break => "break",
            EventKind::Rebind => "rebind",
            EventKind::Form => "form",
            EventKind::Reset => "reset",
        }
    }
}

/// One state change of one bond.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Event {
    pub step: u64,
    pub time: f64,
    pub kind: EventKind,
    pub bond: usize,
    pub bond_type: String,
    /// Particle ids.
    pub particles: [u64; 2],
    pub force: f64,
    pub length: f64,
    /// Time bound through the end of the event's step (0 for rebind and form).
    pub age: f64,
}
