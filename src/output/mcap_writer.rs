//! MCAP trajectories, viewable in Foxglove: zstd-compressed chunks, cellmd's
//! own channels as JSON with a JSON Schema, and the 3D scene as Foxglove's
//! protobuf `foxglove.SceneUpdate` (or JSON, when the deck asks).
//!
//! # Channels
//!
//! | topic | schema | encoding | when | contents |
//! |---|---|---|---|---|
//! | `/cellmd/topology` | `cellmd.Topology` | json | once, with the first frame | units, ids, type names, per-particle types and radii, bonds/angles/triangles as user ids |
//! | `/cellmd/frame` | `cellmd.Frame` | json | every frame | step, time, box, flat positions and image counters |
//! | `/cellmd/bond_state` | `cellmd.BondState` | json | with the first frame, then after each step with bond events | per-bond `bound` flags |
//! | `/cellmd/events` | `cellmd.BondEvents` | json | each step with bond events | break / rebind / form / reset events |
//! | `/scene` | `foxglove.SceneUpdate` | protobuf (schema: its `FileDescriptorSet`), or json with `encoding json` | every frame | see [`scene`](super::scene): particles, bound bonds, surfaces, box, walls |
//!
//! cellmd's own schemas are the `*_SCHEMA` constants below (JSON Schema, the
//! form Foxglove's Raw Messages and Plot panels and `mcap cat --json` read).
//! `cellmd.Frame` positions are one flat array `[x0, y0, z0, x1, …]` in
//! internal particle order — the order of `ids` in `cellmd.Topology` — and
//! `images` likewise `[ix0, iy0, iz0, …]`; the unwrapped position is
//! `x + image·(hi − lo)`. JSON numbers are written in shortest round-trip
//! form, so positions decode bit-exactly (non-finite values become `null`).
//! Bond `k` of `cellmd.BondState.bound` is bond `k` of `cellmd.Topology`;
//! the first state is the one at the first frame (a run continued from a
//! restart starts with its broken bonds). Once `bind` rules have formed new
//! bonds the state is no longer written (it would not match the topology):
//! `/cellmd/events` carries every change.
//!
//! # Compression
//!
//! Chunks are compressed with zstd (default level, the MCAP default chunk
//! size of 768 KiB, single-threaded so the bytes do not depend on the
//! machine). The full quickstart (81 frames of 1500 particles) writes
//! 7.2 MB; its messages are 31 MB uncompressed, and 64.7 MB with the scene
//! as JSON (`encoding json`: 6.5 MB compressed). Every MCAP reader (the
//! `mcap` CLI, Foxglove, the Python and Rust libraries) decompresses them.
//!
//! # Time stamps
//!
//! `log_time = publish_time = round(time·10⁹)` ns (clamped at 0), forced to be
//! strictly increasing across frames: a frame whose rounded time does not
//! exceed the previous frame's gets the previous value + 1 ns (e.g. steps
//! shorter than 1 ns of simulated time, or a minimiser with time fixed at 0).
//! The topology and the first bond state share the first frame's stamp.
//! The simulated time itself is exact in the `time` field of `cellmd.Frame`.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

use foxglove::Encode;
use glam::DVec3;
use mcap::records::MessageHeader;
use serde::ser::{SerializeSeq, Serializer};
use serde::Serialize;

use super::scene::{self, Scene, SCENE_UPDATE_SCHEMA};
use super::{check_frame, check_topology, invalid_input, units_keyword, Encoding, FrameView, TopologyView, TrajectoryWriter};
use crate::system::SimBox;

/// Topic of the topology channel.
pub const TOPIC_TOPOLOGY: &str = "/cellmd/topology";
/// Topic of the frame channel.
pub const TOPIC_FRAME: &str = "/cellmd/frame";
/// Topic of the bond-state channel.
pub const TOPIC_BOND_STATE: &str = "/cellmd/bond_state";
/// Topic of the Foxglove 3D scene.
pub const TOPIC_SCENE: &str = "/scene";
/// Bond kinetics events (`cellmd.BondEvents`), one message per step that has any.
pub const TOPIC_EVENTS: &str = "/cellmd/events";

/// JSON Schema of `cellmd.Topology`.
pub const TOPOLOGY_SCHEMA: &str = r#"{
  "title": "cellmd.Topology",
  "description": "Particles and bonded terms of a cellmd run; written once, with the first frame",
  "type": "object",
  "properties": {
    "units": {"type": "string", "enum": ["cell", "lj"], "description": "unit system: cell = µm, s, pN; lj = reduced"},
    "ids": {"type": "array", "items": {"type": "integer", "minimum": 0}, "description": "user id of each particle, in internal order (the order of cellmd.Frame arrays)"},
    "type_names": {"type": "array", "items": {"type": "string"}, "description": "particle type names; a type index points into this list"},
    "types": {"type": "array", "items": {"type": "integer", "minimum": 0}, "description": "type index of each particle"},
    "type_radius": {"type": "array", "items": {"type": "number"}, "description": "radius of each type (length units; 0 = not set)"},
    "radii": {"type": "array", "items": {"type": "number"}, "description": "radius of each particle (its type's radius)"},
    "bonds": {"type": "array", "items": {"type": "array", "items": {"type": "integer"}, "minItems": 2, "maxItems": 2}, "description": "bonded pairs as user ids; bond k is entry k of cellmd.BondState.bound"},
    "angles": {"type": "array", "items": {"type": "array", "items": {"type": "integer"}, "minItems": 3, "maxItems": 3}, "description": "angle triples as user ids (vertex in the middle)"},
    "triangles": {"type": "array", "items": {"type": "array", "items": {"type": "integer"}, "minItems": 3, "maxItems": 3}, "description": "surface triangles as user ids"}
  },
  "required": ["units", "ids", "type_names", "types", "type_radius", "radii", "bonds", "angles", "triangles"]
}"#;

/// JSON Schema of `cellmd.Frame`.
pub const FRAME_SCHEMA: &str = r#"{
  "title": "cellmd.Frame",
  "description": "One trajectory frame of a cellmd run",
  "type": "object",
  "properties": {
    "step": {"type": "integer", "minimum": 0, "description": "step number"},
    "time": {"type": "number", "description": "simulated time (time units)"},
    "box": {
      "type": "object",
      "properties": {
        "lo": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3, "description": "lower corner"},
        "hi": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3, "description": "upper corner"},
        "periodic": {"type": "array", "items": {"type": "boolean"}, "minItems": 3, "maxItems": 3, "description": "periodic flag per axis"}
      },
      "required": ["lo", "hi", "periodic"],
      "description": "orthorhombic box [lo, hi)"
    },
    "positions": {"type": "array", "items": {"type": ["number", "null"]}, "description": "flat [x0, y0, z0, x1, ...] in the order of cellmd.Topology ids, wrapped into the box on periodic axes (null = not finite)"},
    "images": {"type": "array", "items": {"type": "integer"}, "description": "flat image counters [ix0, iy0, iz0, ...]; unwrapped x = x + image*(hi - lo)"}
  },
  "required": ["step", "time", "box", "positions", "images"]
}"#;

/// JSON Schema of `cellmd.BondEvents`: the events of one step (see `crate::kinetics_engine::Event`).
pub const BOND_EVENTS_SCHEMA: &str = r#"{
  "title": "cellmd.BondEvents",
  "type": "object",
  "properties": {
    "step": {"type": "integer"},
    "time": {"type": "number"},
    "events": {"type": "array", "items": {"type": "object", "properties": {
      "step": {"type": "integer"}, "time": {"type": "number"},
      "kind": {"type": "string", "enum": ["break", "rebind", "form", "reset"]},
      "bond": {"type": "integer", "description": "bond index, topology order, new bonds appended"},
      "bond_type": {"type": "string"},
      "particles": {"type": "array", "items": {"type": "integer"}, "minItems": 2, "maxItems": 2},
      "force": {"type": "number", "description": "tension dE/dr when decided"},
      "length": {"type": "number"}}}}
  }
}"#;

/// JSON Schema of `cellmd.BondState`.
pub const BOND_STATE_SCHEMA: &str = r#"{
  "title": "cellmd.BondState",
  "description": "Which bonds of cellmd.Topology are currently bound",
  "type": "object",
  "properties": {
    "step": {"type": "integer", "minimum": 0, "description": "step number"},
    "time": {"type": "number", "description": "simulated time (time units)"},
    "bound": {"type": "array", "items": {"type": "boolean"}, "description": "one flag per bond, in cellmd.Topology bond order"}
  },
  "required": ["step", "time", "bound"]
}"#;

fn mcap_err(e: mcap::McapError) -> io::Error {
    match e {
        mcap::McapError::Io(e) => e,
        other => io::Error::other(other),
    }
}

/// Writes an MCAP trajectory (see the module docs for the channels).
pub struct McapWriter {
    sink: Sink,
    channel_topology: u16,
    channel_frame: u16,
    channel_bond_state: u16,
    channel_scene: u16,
    channel_events: u16,
    /// Stamp of the previous frame (ns).
    last_frame_ns: Option<u64>,
    scene: Scene,
    scene_enabled: bool,
    encoding: Encoding,
    units: &'static str,
    ids: Vec<u64>,
    types: Vec<u32>,
    type_names: Vec<String>,
    type_radius: Vec<f64>,
    bonds: Vec<[u32; 2]>,
    angles: Vec<[u32; 3]>,
    triangles: Vec<[u32; 3]>,
}

/// The MCAP writer with per-channel sequence numbers and a reused buffer.
struct Sink {
    writer: mcap::Writer<BufWriter<File>>,
    sequence: BTreeMap<u16, u32>,
    buffer: Vec<u8>,
}

impl Sink {
    /// Publishes `message` as JSON.
    fn publish<T: Serialize>(&mut self, channel_id: u16, ns: u64, message: &T) -> io::Result<()> {
        self.publish_with(channel_id, ns, |buf| serde_json::to_writer(buf, message).map_err(io::Error::other))
    }

    /// Publishes what `encode` writes into the (cleared) buffer.
    fn publish_with(&mut self, channel_id: u16, ns: u64, encode: impl FnOnce(&mut Vec<u8>) -> io::Result<()>) -> io::Result<()> {
        self.buffer.clear();
        encode(&mut self.buffer)?;
        let sequence = self.sequence.entry(channel_id).or_insert(0);
        *sequence += 1;
        let header = MessageHeader { channel_id, sequence: *sequence, log_time: ns, publish_time: ns };
        self.writer.write_to_known_channel(&header, &self.buffer).map_err(mcap_err)
    }
}

#[derive(Serialize)]
struct BondState<'a> {
    step: u64,
    time: f64,
    bound: &'a [bool],
}

impl McapWriter {
    /// Creates (or truncates) `path` with the protobuf scene.
    pub fn create(path: &Path, topology: &TopologyView) -> io::Result<Self> {
        Self::create_with(path, topology, Encoding::Protobuf)
    }

    /// Creates (or truncates) `path` and registers the schemas and channels;
    /// `encoding` is the scene's.
    pub fn create_with(path: &Path, topology: &TopologyView, encoding: Encoding) -> io::Result<Self> {
        check_topology(topology)?;
        let options = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            // One thread: the bytes then never depend on the machine's core count.
            .compression_threads(0)
            .profile("")
            .library(format!("cellmd {}", env!("CARGO_PKG_VERSION")));
        let mut writer = options.create(BufWriter::new(File::create(path)?)).map_err(mcap_err)?;
        let no_metadata = BTreeMap::new();
        let mut channel =
            |schema_name: &str, schema_encoding: &str, schema: &[u8], topic: &str, message_encoding: &str| -> io::Result<u16> {
                let schema_id = writer.add_schema(schema_name, schema_encoding, schema).map_err(mcap_err)?;
                writer.add_channel(schema_id, topic, message_encoding, &no_metadata).map_err(mcap_err)
            };
        let mut json_channel = |name: &str, schema: &str, topic: &str| channel(name, "jsonschema", schema.as_bytes(), topic, "json");
        let channel_topology = json_channel("cellmd.Topology", TOPOLOGY_SCHEMA, TOPIC_TOPOLOGY)?;
        let channel_frame = json_channel("cellmd.Frame", FRAME_SCHEMA, TOPIC_FRAME)?;
        let channel_bond_state = json_channel("cellmd.BondState", BOND_STATE_SCHEMA, TOPIC_BOND_STATE)?;
        let channel_events = json_channel("cellmd.BondEvents", BOND_EVENTS_SCHEMA, TOPIC_EVENTS)?;
        let channel_scene = match encoding {
            Encoding::Json => json_channel("foxglove.SceneUpdate", SCENE_UPDATE_SCHEMA, TOPIC_SCENE)?,
            Encoding::Protobuf => {
                let schema = foxglove::schemas::SceneUpdate::get_schema().expect("Foxglove's schemas carry their descriptors");
                channel(&schema.name, &schema.encoding, &schema.data, TOPIC_SCENE, &foxglove::schemas::SceneUpdate::get_message_encoding())?
            }
        };
        Ok(Self {
            sink: Sink { writer, sequence: BTreeMap::new(), buffer: Vec::new() },
            channel_topology,
            channel_frame,
            channel_bond_state,
            channel_scene,
            channel_events,
            last_frame_ns: None,
            scene: Scene::new(topology),
            scene_enabled: true,
            encoding,
            units: units_keyword(topology.units),
            ids: topology.ids.to_vec(),
            types: topology.types.to_vec(),
            type_names: topology.type_names.to_vec(),
            type_radius: topology.type_radius.to_vec(),
            bonds: topology.bonds.to_vec(),
            angles: topology.angles.to_vec(),
            triangles: topology.triangles.to_vec(),
        })
    }

    /// Turns the `/scene` channel on (the default) or off for later frames.
    pub fn set_scene(&mut self, enabled: bool) {
        self.scene_enabled = enabled;
    }

    /// Records which bonds (in topology order) are bound at `step`/`time`.
    ///
    /// Written automatically with the first frame; bond kinetics
    /// calls this after each batch of binding/unbinding events. The stamp is
    /// `round(time·10⁹)` ns, not forced monotone.
    pub fn write_bond_state(&mut self, step: u64, time: f64, bound: &[bool]) -> io::Result<()> {
        if bound.len() != self.bonds.len() {
            return Err(invalid_input(format!("bond state at step {step} has {} flags for {} bonds", bound.len(), self.bonds.len())));
        }
        self.sink.publish(self.channel_bond_state, time_ns(time), &BondState { step, time, bound })
    }

    fn write_topology(&mut self, ns: u64) -> io::Result<()> {
        #[derive(Serialize)]
        struct Topology<'a> {
            units: &'a str,
            ids: &'a [u64],
            type_names: &'a [String],
            types: &'a [u32],
            type_radius: &'a [f64],
            radii: Vec<f64>,
            bonds: Vec<[u64; 2]>,
            angles: Vec<[u64; 3]>,
            triangles: Vec<[u64; 3]>,
        }
        let ids = &self.ids;
        let message = Topology {
            units: self.units,
            ids,
            type_names: &self.type_names,
            types: &self.types,
            type_radius: &self.type_radius,
            radii: self.types.iter().map(|&t| self.type_radius.get(t as usize).copied().unwrap_or(0.0)).collect(),
            bonds: self.bonds.iter().map(|b| b.map(|i| ids[i as usize])).collect(),
            angles: self.angles.iter().map(|a| a.map(|i| ids[i as usize])).collect(),
            triangles: self.triangles.iter().map(|t| t.map(|i| ids[i as usize])).collect(),
        };
        self.sink.publish(self.channel_topology, ns, &message)
    }

    fn write_scene(&mut self, ns: u64, frame: &FrameView) -> io::Result<()> {
        let update = self.scene.update(frame, ns);
        match self.encoding {
            Encoding::Protobuf => self.sink.publish_with(self.channel_scene, ns, |buf| update.encode(buf).map_err(io::Error::other)),
            Encoding::Json => self.sink.publish(self.channel_scene, ns, &scene::to_json(&update)),
        }
    }
}

impl TrajectoryWriter for McapWriter {
    fn write_frame(&mut self, frame: &FrameView) -> io::Result<()> {
        check_frame(self.ids.len(), frame)?;
        let mut ns = time_ns(frame.time);
        let first = self.last_frame_ns.is_none();
        if let Some(last) = self.last_frame_ns {
            if ns <= last {
                ns = last.checked_add(1).ok_or_else(|| io::Error::other("MCAP log time overflow"))?;
            }
        }
        self.last_frame_ns = Some(ns);
        if first {
            self.write_topology(ns)?;
            let bound: Vec<bool> = (0..self.bonds.len()).map(|k| frame.is_bound(k)).collect();
            let state = BondState { step: frame.step, time: frame.time, bound: &bound };
            self.sink.publish(self.channel_bond_state, ns, &state)?;
        }
        let message = Frame {
            step: frame.step,
            time: frame.time,
            sim_box: BoxMessage::from(frame.sim_box),
            positions: FlatPositions(frame.positions),
            images: FlatImages { images: frame.images, n: frame.positions.len() },
        };
        self.sink.publish(self.channel_frame, ns, &message)?;
        if self.scene_enabled {
            self.write_scene(ns, frame)?;
        }
        Ok(())
    }

    fn write_bond_events(&mut self, events: &[crate::kinetics_engine::Event], bound: &[bool]) -> io::Result<()> {
        let Some(first) = events.first() else { return Ok(()) };
        #[derive(Serialize)]
        struct BondEvents<'a> {
            step: u64,
            time: f64,
            events: &'a [crate::kinetics_engine::Event],
        }
        let ns = time_ns(first.time);
        self.sink.publish(self.channel_events, ns, &BondEvents { step: first.step, time: first.time, events })?;
        if bound.len() == self.bonds.len() {
            self.write_bond_state(first.step, first.time, bound)?;
        }
        Ok(())
    }

    fn finish(mut self: Box<Self>) -> io::Result<()> {
        self.sink.writer.finish().map_err(mcap_err)?;
        let mut out = self.sink.writer.into_inner();
        out.flush()?;
        out.get_ref().sync_data()
    }
}

/// `round(time·10⁹)` ns, clamped to `[0, u64::MAX]` (NaN gives 0).
fn time_ns(time: f64) -> u64 {
    let ns = (time * 1e9).round();
    if ns > 0.0 {
        ns as u64
    } else {
        0
    }
}

#[derive(Serialize)]
struct Frame<'a> {
    step: u64,
    time: f64,
    #[serde(rename = "box")]
    sim_box: BoxMessage,
    positions: FlatPositions<'a>,
    images: FlatImages<'a>,
}

#[derive(Serialize)]
struct BoxMessage {
    lo: [f64; 3],
    hi: [f64; 3],
    periodic: [bool; 3],
}

impl From<&SimBox> for BoxMessage {
    fn from(b: &SimBox) -> Self {
        Self { lo: b.lo.to_array(), hi: b.hi.to_array(), periodic: b.periodic }
    }
}

/// Serializes positions as one flat array `[x0, y0, z0, x1, …]`.
struct FlatPositions<'a>(&'a [DVec3]);

impl Serialize for FlatPositions<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(3 * self.0.len()))?;
        for x in self.0 {
            seq.serialize_element(&x.x)?;
            seq.serialize_element(&x.y)?;
            seq.serialize_element(&x.z)?;
        }
        seq.end()
    }
}

/// Serializes image counters flat, zeros when none are given.
struct FlatImages<'a> {
    images: &'a [[i64; 3]],
    n: usize,
}

impl Serialize for FlatImages<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(3 * self.n))?;
        for i in 0..self.n {
            for v in self.images.get(i).copied().unwrap_or([0; 3]) {
                seq.serialize_element(&v)?;
            }
        }
        seq.end()
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::Sample;
    use super::*;
    use serde_json::Value;

    fn write_sample(path: &Path, s: &Sample, times: &[f64], encoding: Encoding) {
        let mut w = McapWriter::create_with(path, &s.topology(), encoding).unwrap();
        for (f, &t) in times.iter().enumerate() {
            let mut frame = s.frame(f);
            frame.time = t;
            w.write_frame(&frame).unwrap();
        }
        Box::new(w).finish().unwrap();
    }

    /// A `/scene` message as the JSON of [`SCENE_UPDATE_SCHEMA`], whichever its encoding.
    pub(crate) fn scene_json(message: &mcap::Message) -> Value {
        match message.channel.message_encoding.as_str() {
            "protobuf" => scene::to_json(&<foxglove::schemas::SceneUpdate as prost::Message>::decode(&message.data[..]).unwrap()),
            "json" => serde_json::from_slice(&message.data).unwrap(),
            other => panic!("unexpected scene encoding {other}"),
        }
    }

    #[test]
    fn schemas_are_valid_json() {
        for (name, schema) in [
            ("cellmd.Topology", TOPOLOGY_SCHEMA),
            ("cellmd.Frame", FRAME_SCHEMA),
            ("cellmd.BondState", BOND_STATE_SCHEMA),
            ("cellmd.BondEvents", BOND_EVENTS_SCHEMA),
            ("foxglove.SceneUpdate", SCENE_UPDATE_SCHEMA),
        ] {
            let v: Value = serde_json::from_str(schema).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(v["title"], name);
        }
    }

    /// The file is chunked with zstd, and both scene encodings carry the
    /// same scene: protobuf decoded equals the JSON written.
    #[test]
    fn chunks_are_zstd_and_both_scene_encodings_agree() {
        let s = Sample::new(2);
        let dir = tempfile::tempdir().unwrap();
        let mut scenes = Vec::new();
        for (encoding, name) in [(Encoding::Protobuf, "p.mcap"), (Encoding::Json, "j.mcap")] {
            let path = dir.path().join(name);
            write_sample(&path, &s, &[0.1, 0.2], encoding);
            let bytes = std::fs::read(&path).unwrap();
            let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
            assert!(!summary.chunk_indexes.is_empty());
            assert!(summary.chunk_indexes.iter().all(|c| c.compression == "zstd"), "{:?}", summary.chunk_indexes);
            let scene = summary.channels.values().find(|c| c.topic == TOPIC_SCENE).unwrap();
            let schema = scene.schema.as_ref().unwrap();
            assert_eq!(schema.name, "foxglove.SceneUpdate");
            let want = match encoding {
                Encoding::Protobuf => ("protobuf", "protobuf"),
                Encoding::Json => ("json", "jsonschema"),
            };
            assert_eq!((scene.message_encoding.as_str(), schema.encoding.as_str()), want);
            if encoding == Encoding::Protobuf {
                // The schema is a FileDescriptorSet that declares foxglove.SceneUpdate.
                let set = <prost_types::FileDescriptorSet as prost::Message>::decode(&schema.data[..]).unwrap();
                assert!(set.file.iter().any(|f| f.package() == "foxglove" && f.message_type.iter().any(|m| m.name() == "SceneUpdate")));
            }
            let mut stream = mcap::MessageStream::new(&bytes).unwrap().map(|m| m.unwrap());
            scenes.push(stream.by_ref().filter(|m| m.channel.topic == TOPIC_SCENE).map(|m| scene_json(&m)).collect::<Vec<_>>());
        }
        assert_eq!(scenes[0].len(), 2);
        assert_eq!(scenes[0], scenes[1]);
    }

    #[test]
    fn three_frames_read_back() {
        let s = Sample::new(3);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.mcap");
        // The second and third times collide at ns resolution: stamps are forced up.
        let times = [0.1, 0.2, 0.2 + 1e-12];
        write_sample(&path, &s, &times, Encoding::Protobuf);
        let bytes = std::fs::read(&path).unwrap();

        let summary = mcap::Summary::read(&bytes).unwrap().expect("summary section");
        let stats = summary.stats.expect("statistics");
        assert_eq!(stats.message_count, 1 + 1 + 3 + 3);
        // topology, frame, bond state, scene and (empty here) bond events.
        assert_eq!(summary.channels.len(), 5);

        let mut counts: BTreeMap<String, usize> = BTreeMap::new();
        let mut frame_stamps = Vec::new();
        let mut frames = Vec::new();
        let mut scenes = Vec::new();
        let mut topology = None;
        let mut bond_state = None;
        for message in mcap::MessageStream::new(&bytes).unwrap() {
            let message = message.unwrap();
            let channel = &message.channel;
            let schema = channel.schema.as_ref().expect("every channel has a schema");
            let expected_schema = match channel.topic.as_str() {
                TOPIC_TOPOLOGY => ("cellmd.Topology", TOPOLOGY_SCHEMA),
                TOPIC_FRAME => ("cellmd.Frame", FRAME_SCHEMA),
                TOPIC_BOND_STATE => ("cellmd.BondState", BOND_STATE_SCHEMA),
                TOPIC_SCENE => ("foxglove.SceneUpdate", ""),
                other => panic!("unexpected topic {other}"),
            };
            assert_eq!(schema.name, expected_schema.0);
            if channel.topic != TOPIC_SCENE {
                assert_eq!(channel.message_encoding, "json");
                assert_eq!(schema.encoding, "jsonschema");
                assert_eq!(&schema.data[..], expected_schema.1.as_bytes());
            }
            assert_eq!(message.log_time, message.publish_time);
            *counts.entry(channel.topic.clone()).or_default() += 1;
            match channel.topic.as_str() {
                TOPIC_TOPOLOGY => topology = Some(serde_json::from_slice::<Value>(&message.data).unwrap()),
                TOPIC_BOND_STATE => bond_state = Some(serde_json::from_slice::<Value>(&message.data).unwrap()),
                TOPIC_FRAME => {
                    frame_stamps.push(message.log_time);
                    frames.push(serde_json::from_slice::<Value>(&message.data).unwrap());
                }
                _ => scenes.push((message.log_time, scene_json(&message))),
            }
        }
        assert_eq!(counts[TOPIC_TOPOLOGY], 1);
        assert_eq!(counts[TOPIC_BOND_STATE], 1);
        assert_eq!(counts[TOPIC_FRAME], 3);
        assert_eq!(counts[TOPIC_SCENE], 3);
        assert_eq!(frame_stamps, vec![100_000_000, 200_000_000, 200_000_001]);

        let topology = topology.unwrap();
        assert_eq!(topology["units"], "cell");
        assert_eq!(topology["ids"], serde_json::json!([40, 7, 12, 3]));
        assert_eq!(topology["type_names"], serde_json::json!(["cortex", "adhesion site"]));
        assert_eq!(topology["types"], serde_json::json!([0, 1, 1, 0]));
        assert_eq!(topology["radii"], serde_json::json!([0.25, 0.0, 0.0, 0.25]));
        assert_eq!(topology["bonds"], serde_json::json!([[7, 12], [40, 3]]));
        assert_eq!(topology["angles"], serde_json::json!([[40, 7, 12]]));
        assert_eq!(topology["triangles"], serde_json::json!([[40, 7, 3]]));
        let bond_state = bond_state.unwrap();
        assert_eq!(bond_state["bound"], serde_json::json!([true, true]));
        assert_eq!(bond_state["step"], 0);

        for (f, frame) in frames.iter().enumerate() {
            assert_eq!(frame["step"], 100 * f as u64);
            assert_eq!(frame["time"].as_f64().unwrap().to_bits(), times[f].to_bits());
            assert_eq!(frame["box"]["lo"], serde_json::json!([0.0, 0.0, -5.0]));
            assert_eq!(frame["box"]["periodic"], serde_json::json!([true, true, false]));
            let flat: Vec<f64> = frame["positions"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            assert_eq!(flat.len(), 12);
            for (i, x) in s.frames[f].iter().enumerate() {
                for a in 0..3 {
                    assert_eq!(flat[3 * i + a].to_bits(), x[a].to_bits(), "frame {f} particle {i} axis {a}");
                }
            }
            let images: Vec<i64> = frame["images"].as_array().unwrap().iter().map(|v| v.as_i64().unwrap()).collect();
            assert_eq!(images, s.images.iter().flatten().map(|&v| v as i64).collect::<Vec<_>>());
        }

        let (stamp, scene) = &scenes[0];
        assert_eq!(*stamp, 100_000_000);
        let entity = &scene["entities"][0];
        assert_eq!(entity["frame_id"], "world");
        assert_eq!(entity["id"], "particles");
        assert_eq!(entity["timestamp"], serde_json::json!({"sec": 0, "nsec": 100_000_000}));
        let spheres = entity["spheres"].as_array().unwrap();
        assert_eq!(spheres.len(), 4);
        assert_eq!(spheres[0]["size"]["x"], 0.5);
        assert_eq!(spheres[1]["size"]["x"], 2.0 * scene::DEFAULT_RADIUS);
        assert_eq!(spheres[1]["pose"]["position"]["x"], 9.95);
        assert_ne!(spheres[0]["color"], spheres[1]["color"]);
        assert_eq!(spheres[1]["color"], spheres[2]["color"]);
        let lines = entity["lines"].as_array().unwrap();
        assert_eq!(lines.len(), 1);
        assert_eq!(lines[0]["type"], 2);
        let points = lines[0]["points"].as_array().unwrap();
        assert_eq!(points.len(), 4);
        // Bond 7–12 crosses the periodic x face: 9.95 → 9.95 + 0.1, not 0.05.
        assert_eq!(points[0]["x"], 9.95);
        assert!((points[1]["x"].as_f64().unwrap() - 10.05).abs() < 1e-12);
        // The surface: one triangle list, three points per face, each face whole.
        let triangles = entity["triangles"].as_array().unwrap();
        assert_eq!(triangles.len(), 1);
        let corners = triangles[0]["points"].as_array().unwrap();
        assert_eq!(corners.len(), 3 * s.triangles.len());
        let xs: Vec<f64> = corners.iter().map(|p| p["x"].as_f64().unwrap()).collect();
        assert!(xs.iter().all(|x| (x - xs[0]).abs() < 5.0), "a face split across the periodic box: {xs:?}");
        for key in ["arrows", "cubes", "cylinders", "texts", "models", "metadata"] {
            assert_eq!(entity[key], serde_json::json!([]), "{key}");
        }
        // The box: its 12 edges, and no walls in this frame.
        let frame_box = &scene["entities"][1];
        assert_eq!(frame_box["id"], "box");
        assert_eq!(frame_box["lines"][0]["points"].as_array().unwrap().len(), 24);
        assert_eq!(frame_box["triangles"], serde_json::json!([]));
    }

    #[test]
    fn later_bond_states_and_scene_toggle() {
        let s = Sample::new(2);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.mcap");
        let mut w = McapWriter::create(&path, &s.topology()).unwrap();
        w.write_frame(&s.frame(0)).unwrap();
        w.write_bond_state(50, 0.05, &[true, false]).unwrap();
        assert!(w.write_bond_state(50, 0.05, &[true]).is_err());
        w.set_scene(false);
        w.write_frame(&s.frame(1)).unwrap();
        Box::new(w).finish().unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let mut states = Vec::new();
        let mut scenes = 0;
        for message in mcap::MessageStream::new(&bytes).unwrap() {
            let message = message.unwrap();
            match message.channel.topic.as_str() {
                TOPIC_BOND_STATE => {
                    assert_eq!(message.sequence as usize, states.len() + 1);
                    states.push(serde_json::from_slice::<Value>(&message.data).unwrap()["bound"].clone());
                }
                TOPIC_SCENE => scenes += 1,
                _ => {}
            }
        }
        assert_eq!(states, vec![serde_json::json!([true, true]), serde_json::json!([true, false])]);
        assert_eq!(scenes, 1);
    }

    #[test]
    fn time_stamps_round_and_clamp() {
        assert_eq!(time_ns(1.5e-9), 2);
        assert_eq!(time_ns(-3.0), 0);
        assert_eq!(time_ns(f64::NAN), 0);
        assert_eq!(time_ns(1e30), u64::MAX);
    }
}
