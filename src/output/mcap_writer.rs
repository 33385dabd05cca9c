//! MCAP trajectories with JSON messages, viewable in Foxglove.
//!
//! # Channels
//!
//! Every channel uses `json` message encoding with a `jsonschema` schema (the
//! schema texts are the `*_SCHEMA` constants below).
//!
//! | topic | schema | when | contents |
//! |---|---|---|---|
//! | `/cellmd/topology` | `cellmd.Topology` | once, with the first frame | units, ids, type names, per-particle types and radii, bonds/angles/triangles as user ids |
//! | `/cellmd/frame` | `cellmd.Frame` | every frame | step, time, box, flat positions and image counters |
//! | `/cellmd/bond_state` | `cellmd.BondState` | with the first frame, then on [`McapWriter::write_bond_state`] | per-bond `bound` flags |
//! | `/scene` | `foxglove.SceneUpdate` | every frame | spheres per particle + bond lines for the 3D panel |
//!
//! `cellmd.Frame` positions are one flat array `[x0, y0, z0, x1, …]` in
//! internal particle order — the order of `ids` in `cellmd.Topology` — and
//! `images` likewise `[ix0, iy0, iz0, …]`; the unwrapped position is
//! `x + image·(hi − lo)`. JSON numbers are written in shortest round-trip
//! form, so positions decode bit-exactly (non-finite values become `null`).
//!
//! In this version bonds do not change during a run, so the bond state is
//! written once (all bound) with the first frame. Bond kinetics will call
//! [`McapWriter::write_bond_state`] whenever bonds break or form.
//!
//! # Foxglove scene
//!
//! `/scene` carries one `SceneEntity` (frame `world`, id `particles`) that
//! replaces the previous one each frame: a `SpherePrimitive` per particle
//! (diameter `2·radius` of its type, or `2·DEFAULT_RADIUS` when the
//! radius is 0; colour by type from a fixed ten-colour palette) and one
//! `LinePrimitive` of type `LINE_LIST` (2) with a segment per bond. A bond
//! segment runs from particle `a` to `a + minimum_image(x_b − x_a)`, so bonds
//! across a periodic face do not span the box. Lines are 2 px wide
//! (`scale_invariant`). The scene costs ~250 bytes per particle and frame; it
//! can be turned off with [`McapWriter::set_scene`].
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

use glam::DVec3;
use mcap::records::MessageHeader;
use serde::ser::{SerializeSeq, Serializer};
use serde::Serialize;

use super::{check_frame, check_topology, invalid_input, units_keyword, FrameView, TopologyView, TrajectoryWriter};
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

/// Sphere radius drawn for types whose radius is 0 (length units).
pub const DEFAULT_RADIUS: f64 = 0.05;

/// Type colours (matplotlib's tab10), cycled by type index.
pub const PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

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

/// JSON Schema of `cellmd.BondEvents`: the events of one step (see `crate::kinetics::Event`).
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

macro_rules! fox_vector3 {
    () => {
        r#"{"title": "foxglove.Vector3", "type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}}, "required": ["x", "y", "z"]}"#
    };
}
macro_rules! fox_point3 {
    () => {
        r#"{"title": "foxglove.Point3", "type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}}, "required": ["x", "y", "z"]}"#
    };
}
macro_rules! fox_pose {
    () => {
        concat!(
            r#"{"title": "foxglove.Pose", "type": "object", "properties": {"position": "#,
            fox_vector3!(),
            r#", "orientation": {"title": "foxglove.Quaternion", "type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}, "w": {"type": "number"}}, "required": ["x", "y", "z", "w"]}}, "required": ["position", "orientation"]}"#
        )
    };
}
macro_rules! fox_color {
    () => {
        r#"{"title": "foxglove.Color", "type": "object", "properties": {"r": {"type": "number"}, "g": {"type": "number"}, "b": {"type": "number"}, "a": {"type": "number"}}, "required": ["r", "g", "b", "a"]}"#
    };
}
macro_rules! fox_time {
    () => {
        r#"{"type": "object", "title": "time", "properties": {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}}}"#
    };
}

/// JSON Schema of `foxglove.SceneUpdate`: the subset of Foxglove's published
/// schema that cellmd fills (primitive kinds it never writes are declared as
/// arrays and always empty).
pub const SCENE_UPDATE_SCHEMA: &str = concat!(
    r#"{"title": "foxglove.SceneUpdate", "description": "An update to the entities displayed in a 3D scene (subset used by cellmd)", "type": "object", "properties": {"#,
    r#""deletions": {"type": "array", "items": {"title": "foxglove.SceneEntityDeletion", "type": "object", "properties": {"timestamp": "#,
    fox_time!(),
    r#", "type": {"type": "integer", "description": "0 = MATCHING_ID, 1 = ALL"}, "id": {"type": "string"}}, "required": ["timestamp", "type", "id"]}}, "#,
    r#""entities": {"type": "array", "items": {"title": "foxglove.SceneEntity", "type": "object", "properties": {"#,
    r#""timestamp": "#,
    fox_time!(),
    r#", "frame_id": {"type": "string"}, "id": {"type": "string"}, "#,
    r#""lifetime": {"type": "object", "title": "duration", "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}}}, "#,
    r#""frame_locked": {"type": "boolean"}, "#,
    r#""metadata": {"type": "array", "items": {"title": "foxglove.KeyValuePair", "type": "object", "properties": {"key": {"type": "string"}, "value": {"type": "string"}}, "required": ["key", "value"]}}, "#,
    r#""arrows": {"type": "array", "description": "unused (always empty)"}, "#,
    r#""cubes": {"type": "array", "description": "unused (always empty)"}, "#,
    r#""spheres": {"type": "array", "items": {"title": "foxglove.SpherePrimitive", "type": "object", "properties": {"pose": "#,
    fox_pose!(),
    r#", "size": "#,
    fox_vector3!(),
    r#", "color": "#,
    fox_color!(),
    r#"}, "required": ["pose", "size", "color"]}}, "#,
    r#""cylinders": {"type": "array", "description": "unused (always empty)"}, "#,
    r#""lines": {"type": "array", "items": {"title": "foxglove.LinePrimitive", "type": "object", "properties": {"#,
    r#""type": {"title": "foxglove.LineType", "type": "integer", "description": "0 = LINE_STRIP, 1 = LINE_LOOP, 2 = LINE_LIST"}, "pose": "#,
    fox_pose!(),
    r#", "thickness": {"type": "number"}, "scale_invariant": {"type": "boolean"}, "points": {"type": "array", "items": "#,
    fox_point3!(),
    r#"}, "color": "#,
    fox_color!(),
    r#", "colors": {"type": "array", "items": "#,
    fox_color!(),
    r#"}, "indices": {"type": "array", "items": {"type": "integer", "minimum": 0}}}, "required": ["type", "pose", "thickness", "scale_invariant", "points", "color", "colors", "indices"]}}, "#,
    r#""triangles": {"type": "array", "items": {"title": "foxglove.TriangleListPrimitive", "type": "object", "properties": {"pose": "#,
    fox_pose!(),
    r#", "points": {"type": "array", "items": "#,
    fox_point3!(),
    r#"}, "color": "#,
    fox_color!(),
    r#", "colors": {"type": "array", "items": "#,
    fox_color!(),
    r#"}, "indices": {"type": "array", "items": {"type": "integer", "minimum": 0}}}, "required": ["pose", "points", "color", "colors", "indices"]}}, "#,
    r#""texts": {"type": "array", "description": "unused (always empty)"}, "#,
    r#""models": {"type": "array", "description": "unused (always empty)"}"#,
    r#"}, "required": ["timestamp", "frame_id", "id", "lifetime", "frame_locked", "metadata", "arrows", "cubes", "spheres", "cylinders", "lines", "triangles", "texts", "models"]}}"#,
    r#"}, "required": ["deletions", "entities"]}"#
);

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
    scene: bool,
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
    fn publish<T: Serialize>(&mut self, channel_id: u16, ns: u64, message: &T) -> io::Result<()> {
        self.buffer.clear();
        serde_json::to_writer(&mut self.buffer, message).map_err(io::Error::other)?;
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
    /// Creates (or truncates) `path` and registers the schemas and channels.
    pub fn create(path: &Path, topology: &TopologyView) -> io::Result<Self> {
        check_topology(topology)?;
        let options = mcap::WriteOptions::new().compression(None).profile("").library(format!("cellmd {}", env!("CARGO_PKG_VERSION")));
        let mut writer = options.create(BufWriter::new(File::create(path)?)).map_err(mcap_err)?;
        let no_metadata = BTreeMap::new();
        let mut channel = |schema_name: &str, schema: &str, topic: &str| -> io::Result<u16> {
            let schema_id = writer.add_schema(schema_name, "jsonschema", schema.as_bytes()).map_err(mcap_err)?;
            writer.add_channel(schema_id, topic, "json", &no_metadata).map_err(mcap_err)
        };
        let channel_topology = channel("cellmd.Topology", TOPOLOGY_SCHEMA, TOPIC_TOPOLOGY)?;
        let channel_frame = channel("cellmd.Frame", FRAME_SCHEMA, TOPIC_FRAME)?;
        let channel_bond_state = channel("cellmd.BondState", BOND_STATE_SCHEMA, TOPIC_BOND_STATE)?;
        let channel_scene = channel("foxglove.SceneUpdate", SCENE_UPDATE_SCHEMA, TOPIC_SCENE)?;
        let channel_events = channel("cellmd.BondEvents", BOND_EVENTS_SCHEMA, TOPIC_EVENTS)?;
        Ok(Self {
            sink: Sink { writer, sequence: BTreeMap::new(), buffer: Vec::new() },
            channel_topology,
            channel_frame,
            channel_bond_state,
            channel_scene,
            channel_events,
            last_frame_ns: None,
            scene: true,
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
        self.scene = enabled;
    }

    /// Records which bonds (in topology order) are bound at `step`/`time`.
    ///
    /// Written automatically (all bound) with the first frame; bond kinetics
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
        let identity = Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 };
        let colors: Vec<Color> = (0..self.type_names.len()).map(type_color).collect();
        let spheres = frame
            .positions
            .iter()
            .zip(&self.types)
            .map(|(x, &t)| {
                let r = self.type_radius.get(t as usize).copied().filter(|&r| r > 0.0).unwrap_or(DEFAULT_RADIUS);
                Sphere {
                    pose: Pose { position: Vector3::from(*x), orientation: identity },
                    size: Vector3 { x: 2.0 * r, y: 2.0 * r, z: 2.0 * r },
                    color: colors[t as usize],
                }
            })
            .collect();
        let points = bond_segments(frame.sim_box, frame.positions, &self.bonds).into_iter().map(Vector3::from).collect();
        let lines = vec![Line {
            kind: 2,
            pose: Pose { position: Vector3 { x: 0.0, y: 0.0, z: 0.0 }, orientation: identity },
            thickness: 2.0,
            scale_invariant: true,
            points,
            color: Color { r: 0.8, g: 0.8, b: 0.8, a: 1.0 },
            colors: [],
            indices: [],
        }];
        // Surfaces of bodies: one triangle list, each face drawn whole at its first corner's image.
        let triangles = if self.triangles.is_empty() {
            Vec::new()
        } else {
            let mut points = Vec::with_capacity(3 * self.triangles.len());
            for &[a, b, c] in &self.triangles {
                let xa = frame.positions[a as usize];
                points.push(Vector3::from(xa));
                for p in [b, c] {
                    points.push(Vector3::from(xa + frame.sim_box.minimum_image(frame.positions[p as usize] - xa)));
                }
            }
            vec![TriangleList {
                pose: Pose { position: Vector3 { x: 0.0, y: 0.0, z: 0.0 }, orientation: identity },
                points,
                color: Color { r: 0.95, g: 0.55, b: 0.35, a: 0.6 },
                colors: [],
                indices: [],
            }]
        };
        let stamp = Stamp { sec: ns / 1_000_000_000, nsec: (ns % 1_000_000_000) as u32 };
        let update = SceneUpdate {
            deletions: [],
            entities: [Entity {
                timestamp: stamp,
                frame_id: "world",
                id: "particles",
                lifetime: Stamp { sec: 0, nsec: 0 },
                frame_locked: false,
                metadata: [],
                arrows: [],
                cubes: [],
                spheres,
                cylinders: [],
                lines,
                triangles,
                texts: [],
                models: [],
            }],
        };
        self.sink.publish(self.channel_scene, ns, &update)
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
            let all_bound = vec![true; self.bonds.len()];
            let state = BondState { step: frame.step, time: frame.time, bound: &all_bound };
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
        if self.scene {
            self.write_scene(ns, frame)?;
        }
        Ok(())
    }

    fn write_bond_events(&mut self, events: &[crate::kinetics::Event], bound: &[bool]) -> io::Result<()> {
        let Some(first) = events.first() else { return Ok(()) };
        #[derive(Serialize)]
        struct BondEvents<'a> {
            step: u64,
            time: f64,
            events: &'a [crate::kinetics::Event],
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

/// Segment end points `[a, a + minimum_image(x_b − x_a)]` for every bond.
fn bond_segments(sim_box: &SimBox, positions: &[DVec3], bonds: &[[u32; 2]]) -> Vec<DVec3> {
    let mut points = Vec::with_capacity(2 * bonds.len());
    for &[a, b] in bonds {
        let xa = positions[a as usize];
        points.push(xa);
        points.push(xa + sim_box.minimum_image(positions[b as usize] - xa));
    }
    points
}

fn type_color(t: usize) -> Color {
    let [r, g, b] = PALETTE[t % PALETTE.len()];
    Color { r: r as f64 / 255.0, g: g as f64 / 255.0, b: b as f64 / 255.0, a: 1.0 }
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

#[derive(Serialize, Clone, Copy)]
struct Vector3 {
    x: f64,
    y: f64,
    z: f64,
}

impl From<DVec3> for Vector3 {
    fn from(v: DVec3) -> Self {
        Self { x: v.x, y: v.y, z: v.z }
    }
}

#[derive(Serialize, Clone, Copy)]
struct Quaternion {
    x: f64,
    y: f64,
    z: f64,
    w: f64,
}

#[derive(Serialize, Clone, Copy)]
struct Pose {
    position: Vector3,
    orientation: Quaternion,
}

#[derive(Serialize, Clone, Copy)]
struct Color {
    r: f64,
    g: f64,
    b: f64,
    a: f64,
}

#[derive(Serialize)]
struct Sphere {
    pose: Pose,
    size: Vector3,
    color: Color,
}

#[derive(Serialize)]
struct Line {
    #[serde(rename = "type")]
    kind: u8,
    pose: Pose,
    thickness: f64,
    scale_invariant: bool,
    points: Vec<Vector3>,
    color: Color,
    colors: [Color; 0],
    indices: [u32; 0],
}

#[derive(Serialize)]
struct Stamp {
    sec: u64,
    nsec: u32,
}

#[derive(Serialize)]
struct TriangleList {
    pose: Pose,
    /// Three points per face (outward-wound).
    points: Vec<Vector3>,
    color: Color,
    colors: [Color; 0],
    indices: [u32; 0],
}

#[derive(Serialize)]
struct Entity {
    timestamp: Stamp,
    frame_id: &'static str,
    id: &'static str,
    lifetime: Stamp,
    frame_locked: bool,
    metadata: [u8; 0],
    arrows: [u8; 0],
    cubes: [u8; 0],
    spheres: Vec<Sphere>,
    cylinders: [u8; 0],
    lines: Vec<Line>,
    triangles: Vec<TriangleList>,
    texts: [u8; 0],
    models: [u8; 0],
}

#[derive(Serialize)]
struct SceneUpdate {
    deletions: [u8; 0],
    entities: [Entity; 1],
}

#[cfg(test)]
mod tests {
    use super::super::test_support::Sample;
    use super::*;
    use serde_json::Value;

    fn write_sample(path: &Path, s: &Sample, times: &[f64]) {
        let mut w = McapWriter::create(path, &s.topology()).unwrap();
        for (f, &t) in times.iter().enumerate() {
            let mut frame = s.frame(f);
            frame.time = t;
            w.write_frame(&frame).unwrap();
        }
        Box::new(w).finish().unwrap();
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

    #[test]
    fn three_frames_read_back() {
        let s = Sample::new(3);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.mcap");
        // The second and third times collide at ns resolution: stamps are forced up.
        let times = [0.1, 0.2, 0.2 + 1e-12];
        write_sample(&path, &s, &times);
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
            assert_eq!(channel.message_encoding, "json");
            assert_eq!(schema.encoding, "jsonschema");
            let expected_schema = match channel.topic.as_str() {
                TOPIC_TOPOLOGY => ("cellmd.Topology", TOPOLOGY_SCHEMA),
                TOPIC_FRAME => ("cellmd.Frame", FRAME_SCHEMA),
                TOPIC_BOND_STATE => ("cellmd.BondState", BOND_STATE_SCHEMA),
                TOPIC_SCENE => ("foxglove.SceneUpdate", SCENE_UPDATE_SCHEMA),
                other => panic!("unexpected topic {other}"),
            };
            assert_eq!(schema.name, expected_schema.0);
            assert_eq!(&schema.data[..], expected_schema.1.as_bytes());
            assert_eq!(message.log_time, message.publish_time);
            *counts.entry(channel.topic.clone()).or_default() += 1;
            let value: Value = serde_json::from_slice(&message.data).unwrap();
            match channel.topic.as_str() {
                TOPIC_TOPOLOGY => topology = Some(value),
                TOPIC_BOND_STATE => bond_state = Some(value),
                TOPIC_FRAME => {
                    frame_stamps.push(message.log_time);
                    frames.push(value);
                }
                _ => scenes.push((message.log_time, value)),
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
        assert_eq!(spheres[1]["size"]["x"], 2.0 * DEFAULT_RADIUS);
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
