//! Restart files: the dynamic state of a run as a JSON document.
//!
//! # Format (version 1)
//!
//! ```json
//! {
//!   "format": "cellmd-restart",
//!   "version": 1,
//!   "units": "cell",
//!   "step": 2000,
//!   "time": 0.2,
//!   "box": {"lo": [0.0, 0.0, -5.0], "hi": [10.0, 10.0, 5.0], "periodic": [true, true, false]},
//!   "ids": [40, 7, 12, 3],
//!   "positions": [[0.30000000000000004, 1e-300, -0.0], ...],
//!   "images": [[0, 0, 0], [-1, 2, 0], ...],
//!   "bonds": {"bound": [true, ...], "age": [0.2, ...], "rest": [0.95, null, ...], "scale": [1.0, ...], "formed": []},
//!   "counters": {"breaks": 12, "rebinds": 3, "forms": 0, "resets": 0, "contact_clamps": 0},
//!   "resume": {"inputs": {"deck": "inputs/a.in", "vars": [["n", "3"]], "files": [{"path": "inputs/a.in", "text": "..."}, ...]},
//!              "action": 9, "run_end": 5000}
//! }
//! ```
//!
//! * `ids` are the user ids by internal index: on restart they are checked
//!   against the topology ([`RestartData::check_ids`]) so a restart is never
//!   applied to a different system or ordering.
//! * `positions` are stored (wrapped) positions, `images` their counters.
//! * `bonds` is the bond state ([`BondState`](crate::system::BondState)),
//!   present when bonds have one (kinetics, or per-bond rest lengths from
//!   the topology): per bond whether it is bound, its age, its own rest
//!   length (`null`: its type's `r0`) and stiffness scale, then the bonds
//!   formed during the run. A restart thus keeps per-bond rest lengths,
//!   including those that kinetic rules have moved.
//! * `counters` are the cumulative thermo counts (`breaks`, `rebinds`,
//!   `forms`, `resets`, `nclamp`), restored by `read_state` and `--continue`.
//! * `resume` carries the model and force field as their sources: the deck's
//!   path, its `--var` overrides and the text of every input file read (deck,
//!   topology, force fields, includes), plus the index of the deck action to
//!   continue with and the last step of the `run` in progress.
//!   `cellmd run --continue FILE` rebuilds the system from these texts alone
//!   (no file of the original needs to exist) and finishes the deck.
//! * Unknown keys are ignored and `counters`/`resume` are optional, so files
//!   of earlier builds still read, and later versions may add fields.
//!
//! Every f64 round-trips bit-exactly: serde_json prints the shortest string
//! that parses back to the same value, and this crate enables serde_json's
//! `float_roundtrip` feature so the parser is correctly rounded (the default
//! parser may be off by one ulp). `-0.0`, subnormals and `1e-300` survive;
//! non-finite values cannot be represented in JSON and are rejected on write.
//!
//! # Atomic writes
//!
//! [`write_state`] writes `<path>.tmp`, flushes it to disk and renames it over
//! `<path>`, so an interrupted write leaves either the old file or the new
//! one, never a truncated mix.

use std::fs::File;
use std::io::{self, BufReader, Write};
use std::path::Path;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::atomic::write_atomically;
use crate::input::DeckInputs;
use crate::system::{SimBox, State};
use crate::units::UnitSystem;

/// The `format` tag of a restart file.
pub const RESTART_FORMAT: &str = "cellmd-restart";
/// The restart format version this build writes and reads.
pub const RESTART_VERSION: u64 = 1;

/// Everything needed to continue a run, besides the deck and topology.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RestartData {
    #[serde(with = "units_keyword")]
    pub units: UnitSystem,
    pub step: u64,
    pub time: f64,
    #[serde(rename = "box")]
    pub sim_box: SimBox,
    /// User id of each particle, by internal index.
    pub ids: Vec<u64>,
    pub positions: Vec<DVec3>,
    pub images: Vec<[i64; 3]>,
    /// Bond state (bound, age, rest length, scale) when bonds have kinetics.
    #[serde(default)]
    pub bonds: Option<crate::system::BondState>,
    /// Cumulative thermo counters, so they go on counting after a restart.
    #[serde(default)]
    pub counters: Counters,
    /// The deck, its inputs and where the run was in it (absent in restarts
    /// of older versions: those continue only through a deck's `read_state`).
    #[serde(default)]
    pub resume: Option<Resume>,
}

/// Cumulative counts that thermo columns report (`breaks`, `rebinds`,
/// `forms`, `resets`, `nclamp`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counters {
    pub breaks: u64,
    pub rebinds: u64,
    pub forms: u64,
    pub resets: u64,
    pub contact_clamps: u64,
}

/// Where a run stood in its deck: what `cellmd run --continue` needs.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Resume {
    /// The deck's path, `--var` overrides and every input file as read.
    pub inputs: DeckInputs,
    /// Index of the deck action to continue with (the `run` in progress, or
    /// the next action when the state was saved between actions).
    pub action: usize,
    /// The step at which the `run` in progress ends (None: between actions).
    pub run_end: Option<u64>,
}

impl RestartData {
    /// Captures a [`State`] with its box and particle ids.
    pub fn from_state(units: UnitSystem, state: &State, sim_box: &SimBox, ids: &[u64]) -> Self {
        Self {
            units,
            step: state.step,
            time: state.time,
            sim_box: *sim_box,
            ids: ids.to_vec(),
            positions: state.positions.clone(),
            images: state.images.clone(),
            bonds: state.bonds.clone(),
            counters: Counters::default(),
            resume: None,
        }
    }

    /// The [`State`] to continue from.
    pub fn to_state(&self) -> State {
        State {
            step: self.step,
            time: self.time,
            positions: self.positions.clone(),
            images: self.images.clone(),
            bonds: self.bonds.clone(),
        }
    }

    /// Checks that the restart belongs to a topology with these ids, in this order.
    pub fn check_ids(&self, ids: &[u64]) -> Result<(), String> {
        if self.ids.len() != ids.len() {
            return Err(format!("the restart file has {} particles but the topology has {}", self.ids.len(), ids.len()));
        }
        if let Some(i) = (0..ids.len()).find(|&i| self.ids[i] != ids[i]) {
            return Err(format!(
                "particle {i} has id {} in the restart file but id {} in the topology \
                 (the restart belongs to a different system or particle order)",
                self.ids[i], ids[i]
            ));
        }
        Ok(())
    }

    fn check_consistent(&self) -> Result<(), String> {
        let n = self.ids.len();
        if self.positions.len() != n || self.images.len() != n {
            return Err(format!(
                "{} ids, {} positions and {} image counters; they must all have the same length",
                n,
                self.positions.len(),
                self.images.len()
            ));
        }
        Ok(())
    }
}

/// Writes `data` to `path` atomically (via `<path>.tmp` and a rename).
pub fn write_state(path: &Path, data: &RestartData) -> Result<(), String> {
    data.check_consistent().map_err(|e| format!("cannot write restart file '{}': {e}", path.display()))?;
    let finite = data.time.is_finite()
        && data.positions.iter().all(|x| x.is_finite())
        && data.sim_box.lo.is_finite()
        && data.sim_box.hi.is_finite()
        && data.bonds.as_ref().is_none_or(|b| b.age.iter().chain(&b.scale).chain(b.rest.iter().flatten()).all(|v| v.is_finite()));
    if !finite {
        return Err(format!("cannot write restart file '{}': the state contains a non-finite number", path.display()));
    }
    #[derive(Serialize)]
    struct Document<'a> {
        format: &'static str,
        version: u64,
        #[serde(flatten)]
        data: &'a RestartData,
    }
    write_atomically(path, |out| {
        serde_json::to_writer(&mut *out, &Document { format: RESTART_FORMAT, version: RESTART_VERSION, data }).map_err(io::Error::other)?;
        out.write_all(b"\n")
    })
    .map_err(|e| format!("cannot write restart file '{}': {e}", path.display()))
}

/// Reads a restart file, checking its format tag, version and array lengths.
pub fn read_state(path: &Path) -> Result<RestartData, String> {
    let shown = path.display();
    let file = File::open(path).map_err(|e| match e.kind() {
        io::ErrorKind::NotFound => format!("restart file '{shown}' not found"),
        _ => format!("cannot open restart file '{shown}': {e}"),
    })?;
    let value: serde_json::Value =
        serde_json::from_reader(BufReader::new(file)).map_err(|e| format!("restart file '{shown}' is not valid JSON: {e}"))?;
    match value.get("format").and_then(|f| f.as_str()) {
        Some(RESTART_FORMAT) => {}
        Some(other) => {
            return Err(format!("'{shown}' is not a cellmd restart file (format is \"{other}\", expected \"{RESTART_FORMAT}\")"))
        }
        None => return Err(format!("'{shown}' is not a cellmd restart file (no \"format\": \"{RESTART_FORMAT}\" entry)")),
    }
    match value.get("version").and_then(|v| v.as_u64()) {
        Some(RESTART_VERSION) => {}
        Some(v) => return Err(format!("restart file '{shown}' has format version {v}; this cellmd reads version {RESTART_VERSION}")),
        None => return Err(format!("restart file '{shown}' has no valid \"version\" entry")),
    }
    let data: RestartData = serde_json::from_value(value).map_err(|e| format!("restart file '{shown}' is malformed: {e}"))?;
    data.check_consistent().map_err(|e| format!("restart file '{shown}' is inconsistent: {e}"))?;
    Ok(data)
}

/// Serializes a [`UnitSystem`] as its deck keyword (`cell`, `lj`).
mod units_keyword {
    use serde::{de::Error, Deserialize, Deserializer, Serializer};

    use crate::units::UnitSystem;

    pub fn serialize<S: Serializer>(units: &UnitSystem, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(super::super::units_keyword(*units))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<UnitSystem, D::Error> {
        let word = String::deserialize(d)?;
        UnitSystem::from_keyword(&word).ok_or_else(|| D::Error::custom(format!("unknown unit system \"{word}\" (expected cell or lj)")))
    }
}

#[cfg(test)]
mod tests {
    use std::fs;

    use super::*;
    use crate::output::atomic::tmp_path;

    fn sample() -> RestartData {
        RestartData {
            units: UnitSystem::Cell,
            step: 123_456_789_012,
            time: 0.1 + 0.2,
            sim_box: SimBox::new(DVec3::new(-0.0, 0.0, -5.0), DVec3::new(10.0, 1.0 / 3.0, 5.0), [true, false, true]),
            ids: vec![40, 7, u64::MAX],
            positions: vec![
                DVec3::new(0.1 + 0.2, 1e-300, -0.0),
                DVec3::new(5e-324, f64::MAX, -f64::MIN_POSITIVE),
                DVec3::new(std::f64::consts::PI, 1e22, 9007199254740993.0),
            ],
            images: vec![[0, 0, 0], [-1, 2, 0], [i64::MIN, i64::MAX, 3]],
            bonds: Some(crate::system::BondState {
                bound: vec![true, false],
                age: vec![0.1 + 0.2, 5e-324],
                rest: vec![Some(0.8), None],
                scale: vec![1e-17, 1.0],
                formed: Vec::new(),
            }),
            counters: Counters { breaks: 3, rebinds: 2, forms: 1, resets: 0, contact_clamps: u64::MAX },
            resume: Some(Resume {
                inputs: DeckInputs {
                    deck: "d/deck.in".into(),
                    vars: vec![("n".into(), "3".into())],
                    files: vec![crate::input::InputFile { path: "d/deck.in".into(), text: "run ${n}\n\"é\"".into() }],
                },
                action: 4,
                run_end: Some(200),
            }),
        }
    }

    fn bits(d: &RestartData) -> Vec<u64> {
        let mut v = vec![d.time.to_bits()];
        v.extend(d.sim_box.lo.to_array().map(f64::to_bits));
        v.extend(d.sim_box.hi.to_array().map(f64::to_bits));
        for x in &d.positions {
            v.extend(x.to_array().map(f64::to_bits));
        }
        if let Some(b) = &d.bonds {
            v.extend(b.age.iter().chain(&b.scale).chain(b.rest.iter().flatten()).map(|x| x.to_bits()));
            v.extend(b.bound.iter().map(|&x| x as u64));
        }
        v
    }

    #[test]
    fn round_trips_bit_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("state.json");
        let data = sample();
        write_state(&path, &data).unwrap();
        assert!(!tmp_path(&path).exists());
        let back = read_state(&path).unwrap();
        assert_eq!(back, data);
        assert_eq!(bits(&back), bits(&data), "-0.0 and every other value keep their bits");
        let text = fs::read_to_string(&path).unwrap();
        assert!(text.starts_with(r#"{"format":"cellmd-restart","version":1,"units":"cell","#), "{text}");
    }

    #[test]
    fn random_bit_patterns_round_trip() {
        // splitmix64 over raw bit patterns: every finite f64 class, all exponents.
        let mut s = 0x1234_5678u64;
        let mut positions = Vec::new();
        while positions.len() < 20_000 {
            let mut v = [0.0; 3];
            for x in &mut v {
                loop {
                    s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
                    let mut z = s;
                    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
                    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
                    let candidate = f64::from_bits(z ^ (z >> 31));
                    if candidate.is_finite() {
                        *x = candidate;
                        break;
                    }
                }
            }
            positions.push(DVec3::from_array(v));
        }
        let data = RestartData { ids: (0..positions.len() as u64).collect(), images: vec![[0; 3]; positions.len()], positions, ..sample() };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("state.json");
        write_state(&path, &data).unwrap();
        assert_eq!(bits(&read_state(&path).unwrap()), bits(&data));
    }

    #[test]
    fn state_conversion_and_id_check() {
        let mut state = State::new(vec![DVec3::ONE, DVec3::ZERO]);
        state.step = 7;
        state.time = 0.7;
        state.images[1] = [1, 0, -1];
        let b = SimBox::new(DVec3::ZERO, DVec3::splat(4.0), [true; 3]);
        let data = RestartData::from_state(UnitSystem::Lj, &state, &b, &[5, 6]);
        assert_eq!(data.to_state(), state);
        assert!(data.check_ids(&[5, 6]).is_ok());
        assert!(data.check_ids(&[5]).unwrap_err().contains("2 particles but the topology has 1"));
        let err = data.check_ids(&[5, 9]).unwrap_err();
        assert!(err.contains("particle 1 has id 6 in the restart file but id 9"), "{err}");
    }

    #[test]
    fn clear_errors() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing.json");
        let err = read_state(&path).unwrap_err();
        assert!(err.contains("not found") && err.contains("missing.json"), "{err}");

        let write = |name: &str, text: &str| {
            let p = dir.path().join(name);
            fs::write(&p, text).unwrap();
            p
        };
        let err = read_state(&write("garbage.json", "{ not json")).unwrap_err();
        assert!(err.contains("not valid JSON"), "{err}");
        let err = read_state(&write("other.json", r#"{"format": "xyz", "version": 1}"#)).unwrap_err();
        assert!(err.contains("not a cellmd restart file") && err.contains("\"xyz\""), "{err}");
        let err = read_state(&write("untagged.json", r#"{"version": 1}"#)).unwrap_err();
        assert!(err.contains("not a cellmd restart file"), "{err}");
        let err = read_state(&write("v2.json", r#"{"format": "cellmd-restart", "version": 2}"#)).unwrap_err();
        assert!(err.contains("version 2") && err.contains("reads version 1"), "{err}");
        let err = read_state(&write("partial.json", r#"{"format": "cellmd-restart", "version": 1, "step": 3}"#)).unwrap_err();
        assert!(err.contains("malformed") && err.contains("missing field"), "{err}");

        // Inconsistent lengths are refused on write and on read.
        let mut bad = sample();
        bad.images.pop();
        let p = dir.path().join("bad.json");
        assert!(write_state(&p, &bad).unwrap_err().contains("same length"));
        let mut text = serde_json::to_value(sample()).unwrap();
        text["format"] = RESTART_FORMAT.into();
        text["version"] = 1.into();
        text["images"].as_array_mut().unwrap().pop();
        let err = read_state(&write("short.json", &text.to_string())).unwrap_err();
        assert!(err.contains("inconsistent"), "{err}");

        let mut nan = sample();
        nan.positions[0].x = f64::NAN;
        assert!(write_state(&p, &nan).unwrap_err().contains("non-finite"));
        assert!(!p.exists());
    }

    #[test]
    fn overwrite_replaces_the_old_file_atomically() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("state.json");
        let mut data = sample();
        write_state(&path, &data).unwrap();
        data.step += 1;
        // A stale temporary from an interrupted earlier write is simply replaced.
        fs::write(tmp_path(&path), "partial garbage").unwrap();
        write_state(&path, &data).unwrap();
        assert_eq!(read_state(&path).unwrap().step, data.step);
        assert!(!tmp_path(&path).exists());
    }
}
