//! cellmd's own MCAP channels as typed protobuf messages (the default
//! encoding), their JSON forms (`encoding json`, see [`JsonForm`]) and
//! [`message_json`], which reads either back.
//!
//! The schema of each channel is the encoded `FileDescriptorSet` of the one
//! file below, as the MCAP protobuf profile asks; the schema name is the
//! message's full name (`cellmd.Frame`, …). Foxglove, `mcap cat --json` and
//! the Python `mcap-protobuf-support` decoder read the messages from it with
//! no `.proto` file at hand:
//!
//! ```proto
//! syntax = "proto3";
//! package cellmd;
//! message Topology {
//!   string units = 1;                // "cell" (µm, s, pN) or "lj" (reduced)
//!   repeated uint64 ids = 2;         // user id per particle, internal order
//!   repeated string type_names = 3;
//!   repeated uint32 types = 4;       // type index per particle
//!   repeated double type_radius = 5; // radius per type (0 = not set)
//!   repeated double radii = 6;       // radius per particle
//!   repeated uint64 bonds = 7;       // user ids, flat: [i0, j0, i1, j1, …]
//!   repeated uint64 angles = 8;      // flat triples, vertex in the middle
//!   repeated uint64 triangles = 9;   // flat triples
//! }
//! message Box { repeated double lo = 1; repeated double hi = 2; repeated bool periodic = 3; }
//! message Frame {
//!   uint64 step = 1;
//!   double time = 2;
//!   Box box = 3;
//!   repeated double positions = 4;   // flat [x0, y0, z0, x1, …], Topology.ids order
//!   repeated sint64 images = 5;      // flat [ix0, iy0, iz0, …]
//! }
//! message BondState { uint64 step = 1; double time = 2; repeated bool bound = 3; }
//! message BondEvent {
//!   uint64 step = 1; double time = 2;
//!   string kind = 3;                 // break, rebind, form or reset
//!   uint64 bond = 4; string bond_type = 5;
//!   repeated uint64 particles = 6;   // the two particle ids
//!   double force = 7; double length = 8; double age = 9;
//! }
//! message BondEvents { uint64 step = 1; double time = 2; repeated BondEvent events = 3; }
//! ```
//!
//! Doubles are stored as IEEE bits, so positions decode bit-exactly (NaN
//! included); repeated scalars are packed.

use prost::Message;
use prost_types::field_descriptor_proto::{Label, Type};
use prost_types::{DescriptorProto, FieldDescriptorProto, FileDescriptorProto, FileDescriptorSet};
use serde_json::{json, Value};

use super::scene;

/// `cellmd.Topology`: written once, with the first frame.
#[derive(Clone, PartialEq, Message)]
pub struct Topology {
    #[prost(string, tag = "1")]
    pub units: String,
    #[prost(uint64, repeated, tag = "2")]
    pub ids: Vec<u64>,
    #[prost(string, repeated, tag = "3")]
    pub type_names: Vec<String>,
    #[prost(uint32, repeated, tag = "4")]
    pub types: Vec<u32>,
    #[prost(double, repeated, tag = "5")]
    pub type_radius: Vec<f64>,
    #[prost(double, repeated, tag = "6")]
    pub radii: Vec<f64>,
    #[prost(uint64, repeated, tag = "7")]
    pub bonds: Vec<u64>,
    #[prost(uint64, repeated, tag = "8")]
    pub angles: Vec<u64>,
    #[prost(uint64, repeated, tag = "9")]
    pub triangles: Vec<u64>,
}

/// `cellmd.Box`: the orthorhombic box `[lo, hi)`.
#[derive(Clone, PartialEq, Message)]
pub struct BoxBounds {
    #[prost(double, repeated, tag = "1")]
    pub lo: Vec<f64>,
    #[prost(double, repeated, tag = "2")]
    pub hi: Vec<f64>,
    #[prost(bool, repeated, tag = "3")]
    pub periodic: Vec<bool>,
}

/// `cellmd.Frame`: one trajectory frame.
#[derive(Clone, PartialEq, Message)]
pub struct Frame {
    #[prost(uint64, tag = "1")]
    pub step: u64,
    #[prost(double, tag = "2")]
    pub time: f64,
    #[prost(message, optional, tag = "3")]
    pub sim_box: Option<BoxBounds>,
    #[prost(double, repeated, tag = "4")]
    pub positions: Vec<f64>,
    #[prost(sint64, repeated, tag = "5")]
    pub images: Vec<i64>,
}

/// `cellmd.BondState`: one `bound` flag per topology bond.
#[derive(Clone, PartialEq, Message)]
pub struct BondState {
    #[prost(uint64, tag = "1")]
    pub step: u64,
    #[prost(double, tag = "2")]
    pub time: f64,
    #[prost(bool, repeated, tag = "3")]
    pub bound: Vec<bool>,
}

/// `cellmd.BondEvent`: one row of the event log.
#[derive(Clone, PartialEq, Message)]
pub struct BondEvent {
    #[prost(uint64, tag = "1")]
    pub step: u64,
    #[prost(double, tag = "2")]
    pub time: f64,
    #[prost(string, tag = "3")]
    pub kind: String,
    #[prost(uint64, tag = "4")]
    pub bond: u64,
    #[prost(string, tag = "5")]
    pub bond_type: String,
    #[prost(uint64, repeated, tag = "6")]
    pub particles: Vec<u64>,
    #[prost(double, tag = "7")]
    pub force: f64,
    #[prost(double, tag = "8")]
    pub length: f64,
    #[prost(double, tag = "9")]
    pub age: f64,
}

/// `cellmd.BondEvents`: the events of one step.
#[derive(Clone, PartialEq, Message)]
pub struct BondEvents {
    #[prost(uint64, tag = "1")]
    pub step: u64,
    #[prost(double, tag = "2")]
    pub time: f64,
    #[prost(message, repeated, tag = "3")]
    pub events: Vec<BondEvent>,
}

impl From<&crate::kinetics_engine::Event> for BondEvent {
    fn from(e: &crate::kinetics_engine::Event) -> Self {
        Self {
            step: e.step,
            time: e.time,
            kind: e.kind.name().to_string(),
            bond: e.bond as u64,
            bond_type: e.bond_type.clone(),
            particles: e.particles.to_vec(),
            force: e.force,
            length: e.length,
            age: e.age,
        }
    }
}

/// A message's JSON form: the object `encoding json` writes, described by
/// the JSON Schemas of `mcap_writer` — the protobuf
/// fields by name, with bonds, angles and triangles as nested arrays and
/// non-finite numbers as `null`.
pub trait JsonForm {
    fn to_json(&self) -> Value;
}

impl JsonForm for Topology {
    fn to_json(&self) -> Value {
        let nested = |flat: &[u64], n: usize| flat.chunks(n).map(<[u64]>::to_vec).collect::<Vec<_>>();
        json!({
            "units": self.units,
            "ids": self.ids,
            "type_names": self.type_names,
            "types": self.types,
            "type_radius": self.type_radius,
            "radii": self.radii,
            "bonds": nested(&self.bonds, 2),
            "angles": nested(&self.angles, 3),
            "triangles": nested(&self.triangles, 3),
        })
    }
}

impl JsonForm for Frame {
    fn to_json(&self) -> Value {
        let b = self.sim_box.clone().unwrap_or_default();
        json!({
            "step": self.step,
            "time": self.time,
            "box": {"lo": b.lo, "hi": b.hi, "periodic": b.periodic},
            "positions": self.positions,
            "images": self.images,
        })
    }
}

impl JsonForm for BondState {
    fn to_json(&self) -> Value {
        json!({"step": self.step, "time": self.time, "bound": self.bound})
    }
}

impl JsonForm for BondEvents {
    fn to_json(&self) -> Value {
        let events: Vec<Value> = self
            .events
            .iter()
            .map(|e| {
                json!({
                    "step": e.step,
                    "time": e.time,
                    "kind": e.kind,
                    "bond": e.bond,
                    "bond_type": e.bond_type,
                    "particles": e.particles,
                    "force": e.force,
                    "length": e.length,
                    "age": e.age,
                })
            })
            .collect();
        json!({"step": self.step, "time": self.time, "events": events})
    }
}

impl JsonForm for foxglove::schemas::SceneUpdate {
    fn to_json(&self) -> Value {
        scene::to_json(self)
    }
}

/// Any message of a cellmd MCAP file as its JSON form, whichever the
/// encoding it was written in: the reader's side of [`JsonForm`].
pub fn message_json(message: &mcap::Message) -> Result<Value, String> {
    fn decoded<M: Message + Default + JsonForm>(data: &[u8]) -> Result<Value, String> {
        M::decode(data).map(|m| m.to_json()).map_err(|e| e.to_string())
    }
    let schema = message.channel.schema.as_ref().map_or("", |s| s.name.as_str());
    match (message.channel.message_encoding.as_str(), schema) {
        ("json", _) => serde_json::from_slice(&message.data).map_err(|e| e.to_string()),
        ("protobuf", "cellmd.Topology") => decoded::<Topology>(&message.data),
        ("protobuf", "cellmd.Frame") => decoded::<Frame>(&message.data),
        ("protobuf", "cellmd.BondState") => decoded::<BondState>(&message.data),
        ("protobuf", "cellmd.BondEvents") => decoded::<BondEvents>(&message.data),
        ("protobuf", "foxglove.SceneUpdate") => decoded::<foxglove::schemas::SceneUpdate>(&message.data),
        (encoding, schema) => Err(format!("not a cellmd channel: `{schema}` in {encoding}")),
    }
}

/// The encoded `FileDescriptorSet` describing every message above: the
/// `schema.data` of each protobuf channel.
pub fn descriptor_set() -> Vec<u8> {
    use Type::{Bool, Double, Message as Msg, Sint64, String as Str, Uint32, Uint64};
    let scalar = |name: &str, number: i32, kind: Type| field(name, number, kind, Label::Optional, None);
    let repeated = |name: &str, number: i32, kind: Type| field(name, number, kind, Label::Repeated, None);
    let step_time = || vec![scalar("step", 1, Uint64), scalar("time", 2, Double)];
    let messages = vec![
        message(
            "Topology",
            vec![
                scalar("units", 1, Str),
                repeated("ids", 2, Uint64),
                repeated("type_names", 3, Str),
                repeated("types", 4, Uint32),
                repeated("type_radius", 5, Double),
                repeated("radii", 6, Double),
                repeated("bonds", 7, Uint64),
                repeated("angles", 8, Uint64),
                repeated("triangles", 9, Uint64),
            ],
        ),
        message("Box", vec![repeated("lo", 1, Double), repeated("hi", 2, Double), repeated("periodic", 3, Bool)]),
        message(
            "Frame",
            [
                step_time(),
                vec![
                    field("box", 3, Msg, Label::Optional, Some(".cellmd.Box")),
                    repeated("positions", 4, Double),
                    repeated("images", 5, Sint64),
                ],
            ]
            .concat(),
        ),
        message("BondState", [step_time(), vec![repeated("bound", 3, Bool)]].concat()),
        message(
            "BondEvent",
            [
                step_time(),
                vec![
                    scalar("kind", 3, Str),
                    scalar("bond", 4, Uint64),
                    scalar("bond_type", 5, Str),
                    repeated("particles", 6, Uint64),
                    scalar("force", 7, Double),
                    scalar("length", 8, Double),
                    scalar("age", 9, Double),
                ],
            ]
            .concat(),
        ),
        message("BondEvents", [step_time(), vec![field("events", 3, Msg, Label::Repeated, Some(".cellmd.BondEvent"))]].concat()),
    ];
    let file = FileDescriptorProto {
        name: Some("cellmd/trajectory.proto".into()),
        package: Some("cellmd".into()),
        message_type: messages,
        syntax: Some("proto3".into()),
        ..Default::default()
    };
    FileDescriptorSet { file: vec![file] }.encode_to_vec()
}

fn message(name: &str, field: Vec<FieldDescriptorProto>) -> DescriptorProto {
    DescriptorProto { name: Some(name.into()), field, ..Default::default() }
}

fn field(name: &str, number: i32, kind: Type, label: Label, type_name: Option<&str>) -> FieldDescriptorProto {
    FieldDescriptorProto {
        name: Some(name.into()),
        number: Some(number),
        label: Some(label as i32),
        r#type: Some(kind as i32),
        type_name: type_name.map(Into::into),
        json_name: Some(name.into()),
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The descriptor names every field of every message with the number and
    /// wire type the derived encoder uses: an encoded message whose fields
    /// are all set shows each (number, wire type) pair, and every one is in
    /// the descriptor with a type of that wire type.
    #[test]
    fn the_descriptor_matches_the_encoders() {
        let set = FileDescriptorSet::decode(&descriptor_set()[..]).unwrap();
        let file = &set.file[0];
        let described = |message: &str| -> Vec<(u32, u32)> {
            let m = file.message_type.iter().find(|m| m.name() == message).unwrap_or_else(|| panic!("{message} described"));
            m.field
                .iter()
                .map(|f| {
                    let packed = f.label() == Label::Repeated && !matches!(f.r#type(), Type::String | Type::Message);
                    let wire = match f.r#type() {
                        _ if packed => 2,
                        Type::Double => 1,
                        Type::String | Type::Message => 2,
                        _ => 0,
                    };
                    (f.number() as u32, wire)
                })
                .collect()
        };
        let on_wire = |bytes: Vec<u8>| -> Vec<(u32, u32)> {
            let mut buf = &bytes[..];
            let mut seen = Vec::new();
            while !buf.is_empty() {
                let (tag, wire) = prost::encoding::decode_key(&mut buf).unwrap();
                prost::encoding::skip_field(wire, tag, &mut buf, Default::default()).unwrap();
                seen.push((tag, wire as u32));
            }
            seen.dedup();
            seen
        };
        let event = BondEvent {
            step: 1,
            time: 0.5,
            kind: "break".into(),
            bond: 2,
            bond_type: "j".into(),
            particles: vec![3, 4],
            force: 1.0,
            length: 2.0,
            age: 3.0,
        };
        let cases = [
            (
                "Topology",
                Topology {
                    units: "cell".into(),
                    ids: vec![1],
                    type_names: vec!["a".into()],
                    types: vec![1],
                    type_radius: vec![1.0],
                    radii: vec![1.0],
                    bonds: vec![1, 2],
                    angles: vec![1, 2, 3],
                    triangles: vec![1, 2, 3],
                }
                .encode_to_vec(),
            ),
            ("Box", BoxBounds { lo: vec![0.0; 3], hi: vec![1.0; 3], periodic: vec![true; 3] }.encode_to_vec()),
            (
                "Frame",
                Frame { step: 1, time: 1.0, sim_box: Some(BoxBounds::default()), positions: vec![1.0, 2.0, 3.0], images: vec![-1, 0, 1] }
                    .encode_to_vec(),
            ),
            ("BondState", BondState { step: 1, time: 1.0, bound: vec![true, false] }.encode_to_vec()),
            ("BondEvent", event.encode_to_vec()),
            ("BondEvents", BondEvents { step: 1, time: 1.0, events: vec![event.clone()] }.encode_to_vec()),
        ];
        for (name, bytes) in cases {
            assert_eq!(on_wire(bytes), described(name), "{name}");
        }
    }

    /// Every message type nests only types the file defines.
    #[test]
    fn nested_types_resolve_within_the_file() {
        let set = FileDescriptorSet::decode(&descriptor_set()[..]).unwrap();
        let names: Vec<String> = set.file[0].message_type.iter().map(|m| format!(".cellmd.{}", m.name())).collect();
        for m in &set.file[0].message_type {
            for f in m.field.iter().filter(|f| f.r#type() == Type::Message) {
                assert!(names.contains(&f.type_name().to_string()), "{}.{}", m.name(), f.name());
            }
        }
    }
}
