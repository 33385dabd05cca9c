//! MCAP trajectories, viewable in Foxglove: zstd-compressed chunks, cellmd's
//! own channels as typed protobuf messages (see
//! [`mcap_messages`](super::mcap_messages)) and the 3D scene as Foxglove's
//! protobuf `foxglove.SceneUpdate`; every channel as JSON with a JSON Schema
//! when the deck asks (`encoding json`).
//!
//! # Channels
//!
//! | topic | schema | encoding | when | contents |
//! |---|---|---|---|---|
//! | `/cellmd/topology` | `cellmd.Topology` | protobuf or json | once, with the first frame | units, ids, type names, per-particle types and radii, bonds/angles/triangles as user ids |
//! | `/cellmd/frame` | `cellmd.Frame` | protobuf or json | every frame | step, time, box, flat positions and image counters |
//! | `/cellmd/bond_state` | `cellmd.BondState` | protobuf or json | with the first frame, then after each step with bond events | per-bond `bound` flags |
//! | `/cellmd/events` | `cellmd.BondEvents` | protobuf or json | each step with bond events | break / rebind / form / reset events |
//! | `/scene` | `foxglove.SceneUpdate` | protobuf (schema: its `FileDescriptorSet`) or json | every frame | see [`scene`](super::scene): particles, bound bonds, surfaces, box, walls |
//!
//! In protobuf (the default) cellmd's own schemas are the descriptor set of
//! [`mcap_messages`](super::mcap_messages), whose module doc gives the
//! `.proto` text. With `encoding json` they are the `*_SCHEMA` constants
//! below (JSON Schema); the JSON forms carry the same fields, with bonds,
//! angles and triangles as nested arrays (`[[i, j], …]`) where protobuf
//! flattens them. Foxglove's Raw Messages and Plot panels and
//! `mcap cat --json` read both. `cellmd.Frame` positions are one flat array `[x0, y0, z0, x1, …]` in
//! internal particle order — the order of `ids` in `cellmd.Topology` — and
//! `images` likewise `[ix0, iy0, iz0, …]`; the unwrapped position is
//! `x + image·(hi − lo)`. Positions decode bit-exactly from either encoding
//! (JSON numbers are written in shortest round-trip form; non-finite values
//! become `null` in JSON and stay themselves in protobuf).
//! Bond `k` of `cellmd.BondState.bound` is bond `k` of `cellmd.Topology`;
//! the first state is the one at the first frame (a run continued from a
//! restart starts with its broken bonds). Once `bind` rules have formed new
//! bonds the state is no longer written (it would not match the topology):
//! `/cellmd/events` carries every change.
//!
//! # Chunks: what survives a kill
//!
//! Each frame ends its chunk: the chunk is assembled in memory, compressed,
//! and written to the file with its message indexes in one write when the
//! frame is complete (see [`records`](super::records)), so after a SIGKILL
//! or a full disk the file is the header and whole chunks, and only the
//! summary and footer, which a clean end writes, are missing. Readers that
//! stream the file recover every message of every frame written before:
//! Python's `mcap.reader.NonSeekingReader(f).iter_messages(log_time_order=False)`
//! (or `mcap.stream_reader.StreamReader(f).records`) and Rust's
//! `mcap::MessageStream::new_with_options(bytes, Options::IgnoreEndMagic.into())`
//! yield them all before they report the missing footer; indexed readers
//! (`make_reader`, which starts from the footer) need the file finished
//! (or rewritten by `mcap recover`). Bond events between frames go into the
//! next frame's chunk, or into a chunk of their own once the oldest of them
//! has waited [`BATCH_INTERVAL`] (1 s; checked every step), so a kill loses
//! at most the last second of them.
//!
//! # Compression
//!
//! Chunks are compressed with zstd (default level, single-threaded so the
//! bytes do not depend on the machine); a frame larger than the MCAP default
//! chunk size of 768 KiB spans several chunks. The quickstart shortened to 9 frames of 1500 particles
//! (`--var steps=2000`) writes 0.73 MB for 2.98 MB of messages; its frames
//! take 365 kB in protobuf and 874 kB as JSON, and with `encoding json`
//! 7.25 MB of messages compress to 0.75 MB. Every MCAP reader (the `mcap`
//! CLI, Foxglove, the Python and Rust libraries) decompresses them.
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
use std::io;
use std::time::Instant;

use foxglove::Encode;
use mcap::records::MessageHeader;

use super::mcap_messages::{self as proto, descriptor_set, JsonForm};
use super::records::{RecordFile, BATCH_INTERVAL};
use super::scene::{Scene, SCENE_UPDATE_SCHEMA};
use super::{check_frame, check_topology, invalid_input, units_keyword, Encoding, FrameView, TopologyView, TrajectoryWriter};

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
    channels: Channels,
    /// Stamp of the previous frame (ns).
    last_frame_ns: Option<u64>,
    scene: Scene,
    scene_enabled: bool,
    /// The `/topology` message, written with the first frame.
    topology: proto::Topology,
}

/// The channel ids of the topics (see the module docs).
struct Channels {
    topology: u16,
    frame: u16,
    bond_state: u16,
    scene: u16,
    events: u16,
}

/// The MCAP writer with its message encoding, per-channel sequence numbers
/// and a reused buffer.
struct Sink {
    writer: mcap::Writer<RecordFile>,
    encoding: Encoding,
    sequence: BTreeMap<u16, u32>,
    buffer: Vec<u8>,
    /// When the oldest message not yet in a written chunk was published.
    unwritten_since: Option<Instant>,
}

impl Sink {
    /// Publishes `message` in the sink's encoding.
    fn publish(&mut self, channel_id: u16, ns: u64, message: &(impl prost::Message + JsonForm)) -> io::Result<()> {
        self.buffer.clear();
        match self.encoding {
            Encoding::Protobuf => message.encode(&mut self.buffer).map_err(io::Error::other)?,
            Encoding::Json => serde_json::to_writer(&mut self.buffer, &message.to_json()).map_err(io::Error::other)?,
        }
        let sequence = self.sequence.entry(channel_id).or_insert(0);
        *sequence += 1;
        let header = MessageHeader { channel_id, sequence: *sequence, log_time: ns, publish_time: ns };
        self.unwritten_since.get_or_insert_with(Instant::now);
        self.writer.write_to_known_channel(&header, &self.buffer).map_err(mcap_err)
    }

    /// Ends the chunk and writes it whole (see the module docs).
    fn end_chunk(&mut self) -> io::Result<()> {
        self.unwritten_since = None;
        self.writer.flush().map_err(mcap_err)
    }
}

impl McapWriter {
    /// Writes to `file` (empty, as opened for output) and registers the
    /// schemas and channels in `encoding`.
    pub fn new(file: File, topology: &TopologyView, encoding: Encoding) -> io::Result<Self> {
        check_topology(topology)?;
        let options = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            // One thread: the bytes then never depend on the machine's core count.
            .compression_threads(0)
            // Chunks assembled in memory and written whole (see the module docs).
            .disable_seeking(true)
            .profile("")
            .library(format!("cellmd {}", env!("CARGO_PKG_VERSION")));
        let mut writer = options.create(RecordFile::new(file)).map_err(mcap_err)?;
        let no_metadata = BTreeMap::new();
        let mut channel =
            |schema_name: &str, schema_encoding: &str, schema: &[u8], topic: &str, message_encoding: &str| -> io::Result<u16> {
                let schema_id = writer.add_schema(schema_name, schema_encoding, schema).map_err(mcap_err)?;
                writer.add_channel(schema_id, topic, message_encoding, &no_metadata).map_err(mcap_err)
            };
        let channels = match encoding {
            Encoding::Json => {
                let mut json_channel =
                    |name: &str, schema: &str, topic: &str| channel(name, "jsonschema", schema.as_bytes(), topic, "json");
                [
                    json_channel("cellmd.Topology", TOPOLOGY_SCHEMA, TOPIC_TOPOLOGY)?,
                    json_channel("cellmd.Frame", FRAME_SCHEMA, TOPIC_FRAME)?,
                    json_channel("cellmd.BondState", BOND_STATE_SCHEMA, TOPIC_BOND_STATE)?,
                    json_channel("cellmd.BondEvents", BOND_EVENTS_SCHEMA, TOPIC_EVENTS)?,
                    json_channel("foxglove.SceneUpdate", SCENE_UPDATE_SCHEMA, TOPIC_SCENE)?,
                ]
            }
            Encoding::Protobuf => {
                let ours = descriptor_set();
                let mut proto_channel = |name: &str, topic: &str| channel(name, "protobuf", &ours, topic, "protobuf");
                let own = [
                    proto_channel("cellmd.Topology", TOPIC_TOPOLOGY)?,
                    proto_channel("cellmd.Frame", TOPIC_FRAME)?,
                    proto_channel("cellmd.BondState", TOPIC_BOND_STATE)?,
                    proto_channel("cellmd.BondEvents", TOPIC_EVENTS)?,
                ];
                let schema = foxglove::schemas::SceneUpdate::get_schema().expect("Foxglove's schemas carry their descriptors");
                let scene = channel(
                    &schema.name,
                    &schema.encoding,
                    &schema.data,
                    TOPIC_SCENE,
                    &foxglove::schemas::SceneUpdate::get_message_encoding(),
                )?;
                [own[0], own[1], own[2], own[3], scene]
            }
        };
        let [topology_channel, frame, bond_state, events, scene] = channels;
        let mut sink = Sink { writer, encoding, sequence: BTreeMap::new(), buffer: Vec::new(), unwritten_since: None };
        // The header and a first chunk with the schemas and channels.
        sink.end_chunk()?;
        Ok(Self {
            sink,
            channels: Channels { topology: topology_channel, frame, bond_state, scene, events },
            last_frame_ns: None,
            scene: Scene::new(topology),
            scene_enabled: true,
            topology: topology_message(topology),
        })
    }

    /// The number of bonds of the topology.
    fn bond_count(&self) -> usize {
        self.topology.bonds.len() / 2
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
        if bound.len() != self.bond_count() {
            return Err(invalid_input(format!("bond state at step {step} has {} flags for {} bonds", bound.len(), self.bond_count())));
        }
        self.publish_bond_state(time_ns(time), step, time, bound)
    }

    fn publish_bond_state(&mut self, ns: u64, step: u64, time: f64, bound: &[bool]) -> io::Result<()> {
        self.sink.publish(self.channels.bond_state, ns, &proto::BondState { step, time, bound: bound.to_vec() })
    }

    fn write_scene(&mut self, ns: u64, frame: &FrameView) -> io::Result<()> {
        let update = self.scene.update(frame, ns);
        self.sink.publish(self.channels.scene, ns, &update)
    }
}

/// The `/topology` message of `topology` (its terms by particle id).
fn topology_message(topology: &TopologyView) -> proto::Topology {
    let ids = topology.ids;
    proto::Topology {
        units: units_keyword(topology.units).to_string(),
        ids: ids.to_vec(),
        type_names: topology.type_names.to_vec(),
        types: topology.types.to_vec(),
        type_radius: topology.type_radius.to_vec(),
        radii: topology.types.iter().map(|&t| topology.type_radius.get(t as usize).copied().unwrap_or(0.0)).collect(),
        bonds: topology.bonds.iter().flat_map(|b| b.map(|i| ids[i as usize])).collect(),
        angles: topology.angles.iter().flat_map(|a| a.map(|i| ids[i as usize])).collect(),
        triangles: topology.triangles.iter().flat_map(|t| t.map(|i| ids[i as usize])).collect(),
    }
}

impl TrajectoryWriter for McapWriter {
    fn write_frame(&mut self, frame: &FrameView) -> io::Result<()> {
        check_frame(self.topology.ids.len(), frame)?;
        let mut ns = time_ns(frame.time);
        let first = self.last_frame_ns.is_none();
        if let Some(last) = self.last_frame_ns {
            if ns <= last {
                ns = last.checked_add(1).ok_or_else(|| io::Error::other("MCAP log time overflow"))?;
            }
        }
        self.last_frame_ns = Some(ns);
        if first {
            self.sink.publish(self.channels.topology, ns, &self.topology)?;
            let bound: Vec<bool> = (0..self.bond_count()).map(|k| frame.is_bound(k)).collect();
            self.publish_bond_state(ns, frame.step, frame.time, &bound)?;
        }
        let b = frame.sim_box;
        let message = proto::Frame {
            step: frame.step,
            time: frame.time,
            sim_box: Some(proto::BoxBounds { lo: b.lo.to_array().into(), hi: b.hi.to_array().into(), periodic: b.periodic.into() }),
            positions: frame.positions.iter().flat_map(|x| x.to_array()).collect(),
            images: (0..frame.positions.len()).flat_map(|i| frame.images.get(i).copied().unwrap_or([0; 3])).collect(),
        };
        self.sink.publish(self.channels.frame, ns, &message)?;
        if self.scene_enabled {
            self.write_scene(ns, frame)?;
        }
        // The frame ends its chunk, which goes to the file whole.
        self.sink.end_chunk()
    }

    fn write_bond_events(&mut self, events: &[crate::kinetics_engine::Event], bound: &[bool]) -> io::Result<()> {
        let Some(first) = events.first() else { return Ok(()) };
        let message = proto::BondEvents { step: first.step, time: first.time, events: events.iter().map(proto::BondEvent::from).collect() };
        self.sink.publish(self.channels.events, time_ns(first.time), &message)?;
        if bound.len() == self.bond_count() {
            self.write_bond_state(first.step, first.time, bound)?;
        }
        Ok(())
    }

    fn flush_due(&mut self) -> io::Result<()> {
        match self.sink.unwritten_since {
            Some(since) if since.elapsed() >= BATCH_INTERVAL => self.sink.end_chunk(),
            _ => Ok(()),
        }
    }

    fn finish(mut self: Box<Self>) -> io::Result<()> {
        self.sink.writer.finish().map_err(mcap_err)?;
        self.sink.writer.into_inner().finish()
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

#[cfg(test)]
mod tests;
