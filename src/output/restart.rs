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
//!   against the topology ([`RestartData::check_against`]) so a restart is never
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
//! # Checked before use
//!
//! A restart is data from disk, so it is checked before anything uses it —
//! when `cellmd check` validates a deck's `read_state`, and before
//! `--continue` opens any output — and an error names the file and the
//! field, `s.restart: bonds.age: found an array of 9, expected 10 entries (…)`:
//! [`RestartData::check`] on its own (array lengths, a finite box with
//! `lo < hi`, positions in it, image counters, `0 <= time` finite, `step <=
//! 2^53`, `run_end >= step`) and [`RestartData::check_against`] against the
//! deck (units, ids and their order, periodic axes, one bond state entry
//! per bond with finite ages and scales and rest lengths > 0). A file that
//! is not a cellmd restart is named so without quoting any of it.
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

use std::io::{self, Write};
use std::path::Path;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::files::write_atomically;
use crate::input::{read_input_file, DeckInputs};
use crate::system::{Model, SimBox, State};
use crate::units::UnitSystem;

/// The `format` tag of a restart file.
pub const RESTART_FORMAT: &str = "cellmd-restart";
/// The restart format version this build writes and reads.
pub const RESTART_VERSION: u64 = 1;
/// The largest step a restart may hold (2⁵³): step counts stay exact in
/// the f64 arithmetic that derives times and intervals from them.
pub const MAX_STEP: u64 = 1 << 53;

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

    /// Why the restart is not a state a run can continue from, whatever the
    /// deck: array lengths, a box that cannot hold a system, positions
    /// outside it, image counters, step and time, the step its `run` ends
    /// at (`field: found …, expected …`).
    pub fn check(&self) -> Result<(), String> {
        self.check_lengths()?;
        if self.step > MAX_STEP {
            return Err(format!("step: found {}, expected at most {MAX_STEP} (2^53)", self.step));
        }
        if !(self.time.is_finite() && self.time >= 0.0) {
            return Err(format!("time: found {:e}, expected a finite time >= 0", self.time));
        }
        self.sim_box.check()?;
        let b = &self.sim_box;
        if let Some(i) = self.positions.iter().position(|&x| b.misplaced_axis(x).is_some()) {
            let x = self.positions[i];
            let why = b.misplacement(x, b.misplaced_axis(x).expect("found above"));
            return Err(format!("positions[{i}]: {why}; expected a position in the box"));
        }
        let bad_image = |im: &[i64; 3]| (0..3).any(|a| if b.periodic[a] { im[a].unsigned_abs() > 1 << 62 } else { im[a] != 0 });
        if let Some(i) = self.images.iter().position(bad_image) {
            return Err(format!(
                "images[{i}]: found {:?}, expected 0 on fixed axes and at most 2^62 in magnitude on periodic ones",
                self.images[i]
            ));
        }
        match self.resume.as_ref().and_then(|r| r.run_end) {
            Some(end) if end < self.step => Err(format!("resume.run_end: found {end}, expected at least the restart's step {}", self.step)),
            _ => Ok(()),
        }
    }

    /// Why the restart does not belong to `model` in a box with these
    /// periodic flags (the deck's): units, particle ids and their order,
    /// periodic axes, and the bond state against the model's bonds.
    pub fn check_against(&self, model: &Model, periodic: [bool; 3]) -> Result<(), String> {
        if self.units != model.units {
            return Err(format!("units: found {}, expected {} (the deck's)", units_name(self.units), units_name(model.units)));
        }
        let ids = &model.ids;
        if self.ids.len() != ids.len() {
            return Err(format!("ids: found {} particles, expected {} (the topology's)", self.ids.len(), ids.len()));
        }
        if let Some(i) = (0..ids.len()).find(|&i| self.ids[i] != ids[i]) {
            return Err(format!(
                "ids[{i}]: found id {}, expected id {} (the topology's order; the restart belongs to a different system or particle order)",
                self.ids[i], ids[i]
            ));
        }
        if self.sim_box.periodic != periodic {
            return Err(format!("box.periodic: found {:?}, expected {periodic:?} (the deck's box)", self.sim_box.periodic));
        }
        match &self.bonds {
            Some(bonds) => bonds.check(model.len(), model.topology_bonds, model.bond_types.len()),
            None => Ok(()),
        }
    }

    fn check_lengths(&self) -> Result<(), String> {
        let n = self.ids.len();
        for (field, len) in [("positions", self.positions.len()), ("images", self.images.len())] {
            if len != n {
                return Err(format!("{field}: found an array of {len}, expected {n} entries (one per id)"));
            }
        }
        Ok(())
    }
}

fn units_name(units: UnitSystem) -> &'static str {
    super::units_keyword(units)
}

/// Writes `data` to `path` atomically (via `<path>.tmp` and a rename),
/// through no link below `root` (the output directory, see [`files`](super::files)).
pub fn write_state(root: &Path, path: &Path, data: &RestartData) -> Result<(), String> {
    data.check_lengths().map_err(|e| format!("cannot write restart file '{}': {e}", path.display()))?;
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
    write_atomically(root, path, |out| {
        serde_json::to_writer(&mut *out, &Document { format: RESTART_FORMAT, version: RESTART_VERSION, data }).map_err(io::Error::other)?;
        out.write_all(b"\n")
    })
    .map_err(|e| format!("cannot write restart file '{}': {e}", path.display()))
}

/// Reads a restart file (a regular file of at most 1 GiB, see
/// [`read_input_file`]) and checks it ([`RestartData::check`]). Errors start
/// with the path; a file that is not a cellmd restart is named so, and no
/// byte of it is quoted.
pub fn read_state(path: &Path) -> Result<RestartData, String> {
    let data = parse_state(path)?;
    data.check().map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(data)
}

/// The restart in `path`, as written (its tag and version checked).
fn parse_state(path: &Path) -> Result<RestartData, String> {
    let shown = path.display();
    let bytes = read_input_file(path).map_err(|why| format!("{shown}: cannot read it: {why}"))?;
    let not_restart = |why: &str| format!("{shown}: not a cellmd restart file ({why}; expected one written by `write_state`)");
    // serde_json's syntax errors name a position, not the bytes there.
    let value: serde_json::Value = serde_json::from_slice(&bytes).map_err(|e| not_restart(&format!("not JSON: {e}")))?;
    if value.get("format").and_then(|f| f.as_str()) != Some(RESTART_FORMAT) {
        return Err(not_restart(&format!("no \"format\": \"{RESTART_FORMAT}\" entry")));
    }
    match value.get("version").and_then(|v| v.as_u64()) {
        Some(RESTART_VERSION) => {}
        Some(v) => return Err(format!("{shown}: version: found {v}, expected {RESTART_VERSION} (the restart version this cellmd reads)")),
        None => return Err(format!("{shown}: version: found no valid entry, expected {RESTART_VERSION}")),
    }
    serde_json::from_value(value).map_err(|e| format!("{shown}: malformed restart: {e}"))
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
    use crate::output::files::tmp_path;

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
        write_state(dir.path(), &path, &data).unwrap();
        assert!(!tmp_path(&path).exists());
        let back = parse_state(&path).unwrap();
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
        write_state(dir.path(), &path, &data).unwrap();
        assert_eq!(bits(&parse_state(&path).unwrap()), bits(&data));
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
        assert_eq!(data.check(), Ok(()));
    }

    #[test]
    fn clear_errors() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing.json");
        let err = read_state(&path).unwrap_err();
        assert!(err.starts_with(&format!("{}: cannot read it: ", path.display())), "{err}");

        let write = |name: &str, text: &str| {
            let p = dir.path().join(name);
            fs::write(&p, text).unwrap();
            p
        };
        let err = read_state(&write("garbage.json", "root:secret:0:0\n")).unwrap_err();
        assert!(err.contains("garbage.json: not a cellmd restart file (not JSON: expected value at line 1 column 1;"), "{err}");
        assert!(!err.contains("secret"), "{err}");
        let err = read_state(&write("other.json", r#"{"format": "secret", "version": 1}"#)).unwrap_err();
        assert!(err.contains("not a cellmd restart file (no \"format\": \"cellmd-restart\" entry") && !err.contains("secret"), "{err}");
        let err = read_state(&write("v2.json", r#"{"format": "cellmd-restart", "version": 2}"#)).unwrap_err();
        assert!(err.ends_with("v2.json: version: found 2, expected 1 (the restart version this cellmd reads)"), "{err}");
        let err = read_state(&write("partial.json", r#"{"format": "cellmd-restart", "version": 1, "step": 3}"#)).unwrap_err();
        assert!(err.contains("malformed restart") && err.contains("missing field"), "{err}");

        // Inconsistent lengths are refused on write and on read.
        let mut bad = sample();
        bad.images.pop();
        let p = dir.path().join("bad.json");
        assert!(write_state(dir.path(), &p, &bad).unwrap_err().contains("images: found an array of 2, expected 3 entries (one per id)"));
        let mut nan = sample();
        nan.positions[0].x = f64::NAN;
        assert!(write_state(dir.path(), &p, &nan).unwrap_err().contains("non-finite"));
        assert!(!p.exists());
    }

    /// Each way a restart can be unusable is refused by field.
    #[test]
    fn unusable_states_are_named_by_field() {
        let good = || {
            let b = SimBox::new(DVec3::ZERO, DVec3::splat(4.0), [true, true, false]);
            let mut d = RestartData::from_state(UnitSystem::Lj, &State::new(vec![DVec3::ONE, DVec3::splat(2.0)]), &b, &[5, 6]);
            d.resume = Some(Resume { inputs: DeckInputs::default(), action: 3, run_end: Some(100) });
            d.step = 10;
            d
        };
        assert_eq!(good().check(), Ok(()));
        type Spoil = Box<dyn Fn(&mut RestartData)>;
        let cases: Vec<(Spoil, &str)> = vec![
            (Box::new(|d| d.positions.pop().map(|_| ()).unwrap()), "positions: found an array of 1, expected 2 entries (one per id)"),
            (Box::new(|d| d.time = -1e308), "time: found -1e308, expected a finite time >= 0"),
            (Box::new(|d| d.time = f64::INFINITY), "time: found inf"),
            (Box::new(|d| d.step = u64::MAX), "step: found 18446744073709551615, expected at most 9007199254740992"),
            (Box::new(|d| d.sim_box.lo.x = -f64::INFINITY), "box: found x from -inf to 4e0"),
            (Box::new(|d| (d.sim_box.lo.z, d.sim_box.hi.z) = (-1e308, 1e308)), "box: found z from"),
            (Box::new(|d| d.positions[1].z = 5.0), "positions[1]: z = 5e0 is outside the fixed box"),
            (Box::new(|d| d.images[0] = [0, 0, 1]), "images[0]: found [0, 0, 1], expected 0 on fixed axes"),
            (
                Box::new(|d| d.resume.as_mut().unwrap().run_end = Some(5)),
                "resume.run_end: found 5, expected at least the restart's step 10",
            ),
        ];
        for (spoil, expected) in cases {
            let mut d = good();
            spoil(&mut d);
            let err = d.check().unwrap_err();
            assert!(err.starts_with(expected), "{err}\n  expected {expected}");
        }
    }

    #[test]
    fn overwrite_replaces_the_old_file_atomically() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("state.json");
        let mut data = sample();
        write_state(dir.path(), &path, &data).unwrap();
        data.step += 1;
        // A stale temporary from an interrupted earlier write is simply replaced.
        fs::write(tmp_path(&path), "partial garbage").unwrap();
        write_state(dir.path(), &path, &data).unwrap();
        assert_eq!(parse_state(&path).unwrap().step, data.step);
        assert!(!tmp_path(&path).exists());
    }
}
